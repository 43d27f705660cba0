#!/usr/bin/env python3
"""Errors of replay (or run) outputs against a reference run of the same scene and input.

    compare.py REF_DIR RUN_DIR [RUN_DIR ...]

For each run: the worst error over the output grid of each logged signal, over that signal's
largest magnitude in the reference, taken over the signals and, apart, over their sensitivity
columns; and the relative errors of the objectives and of their sensitivities. Also the run's
CPU seconds, real-time factor and steps, and its own error estimate (run.json). Columns whose
reference is zero within 1e-12 (roll on a symmetric input) are listed apart, not divided by.
"""
import csv
import json
import sys


def read_signals(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    head, data = rows[0], rows[1:]
    cols = {name: [float(r[i]) for r in data] for i, name in enumerate(head)}
    return head, cols


ZERO = 1e-12  # a reference column within this of zero everywhere has no scale to be relative to


def worst(ref, run, names):
    """Worst over the grid of |run - ref| over the reference column's largest magnitude, over the
    columns whose reference is not zero; and the names of those that are (reported apart)."""
    err, zero = 0.0, []
    for n in names:
        scale = max(abs(v) for v in ref[n])
        if scale <= ZERO:
            zero.append(n)
            continue
        err = max(err, max(abs(a - b) for a, b in zip(ref[n], run[n])) / scale)
    return err, zero


def main():
    ref_dir, runs = sys.argv[1], sys.argv[2:]
    head, ref = read_signals(ref_dir + "/signals.csv")
    ref_obj = json.load(open(ref_dir + "/objectives.json"))["objectives"]
    values = [n for n in head[1:] if not n.startswith("d(")]
    sens = [n for n in head[1:] if n.startswith("d(")]
    print("| run | CPU s | real-time factor | steps | signals | estimated | d(signals)/dp | estimated | "
          "objectives | d(psi)/dp |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    zero_columns = set()
    for d in runs:
        try:
            _, run = read_signals(d + "/signals.csv")
            info = json.load(open(d + "/run.json"))
            obj = json.load(open(d + "/objectives.json"))["objectives"]
        except (OSError, ValueError, IndexError):
            print(f"| {d} | failed (no complete outputs) | | | | | | | | |")
            continue
        e_obj = max(abs(obj[k]["value"] - v["value"]) / abs(v["value"]) for k, v in ref_obj.items())
        e_dobj = 0.0
        for k, v in ref_obj.items():
            for p, s in v["sensitivity"].items():
                if p in obj[k]["sensitivity"] and s != 0:
                    e_dobj = max(e_dobj, abs(obj[k]["sensitivity"][p] - s) / abs(s))
        e_sig, z1 = worst(ref, run, values)
        have_sens = any(n in run for n in sens)
        e_sens, z2 = worst(ref, run, [n for n in sens if n in run])
        zero_columns.update(z1 + z2)
        est = info.get("error_estimate") or {}
        est_sig = f"{est['signals']:.1e}" if est else ""
        est_sens = f"{est['sensitivities']:.1e}" if est and have_sens else ""
        nan = float("nan")
        print(f"| {d} | {info['cpu_seconds']:.3f} | {info['realtime_factor']:.1f} | {info['steps']} | "
              f"{e_sig:.1e} | {est_sig} | {e_sens if have_sens else nan:.1e} | {est_sens} | "
              f"{e_obj:.1e} | {e_dobj if have_sens else nan:.1e} |")
    if zero_columns:
        print("\ncolumns whose reference is zero within %g, left out of the errors: %s"
              % (ZERO, ", ".join(sorted(zero_columns))))


if __name__ == "__main__":
    main()
