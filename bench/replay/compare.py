#!/usr/bin/env python3
"""Errors of replay (or run) outputs against a reference run of the same scene and input.

    compare.py REF_DIR RUN_DIR [RUN_DIR ...]

For each run: the worst error over the output grid of each logged signal, over that signal's
largest magnitude in the reference, taken over the signals and, apart, over their sensitivity
columns; and the relative errors of the objectives and of their sensitivities. Also the run's
CPU seconds, real-time factor and steps (run.json).
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


def worst(ref, run, names):
    err = 0.0
    for n in names:
        scale = max(abs(v) for v in ref[n]) or 1.0
        err = max(err, max(abs(a - b) for a, b in zip(ref[n], run[n])) / scale)
    return err


def main():
    ref_dir, runs = sys.argv[1], sys.argv[2:]
    head, ref = read_signals(ref_dir + "/signals.csv")
    ref_obj = json.load(open(ref_dir + "/objectives.json"))["objectives"]
    values = [n for n in head[1:] if not n.startswith("d(")]
    sens = [n for n in head[1:] if n.startswith("d(")]
    print("| run | CPU s | real-time factor | steps | signals | d(signals)/dp | objectives | d(psi)/dp |")
    print("|---|---|---|---|---|---|---|---|")
    for d in runs:
        _, run = read_signals(d + "/signals.csv")
        info = json.load(open(d + "/run.json"))
        obj = json.load(open(d + "/objectives.json"))["objectives"]
        e_obj = max(abs(obj[k]["value"] - v["value"]) / abs(v["value"]) for k, v in ref_obj.items())
        e_dobj = 0.0
        for k, v in ref_obj.items():
            for p, s in v["sensitivity"].items():
                if p in obj[k]["sensitivity"]:
                    e_dobj = max(e_dobj, abs(obj[k]["sensitivity"][p] - s) / abs(s))
        s_err = worst(ref, run, [n for n in sens if n in run])
        print(f"| {d} | {info['cpu_seconds']:.3f} | {info['realtime_factor']:.1f} | {info['steps']} | "
              f"{worst(ref, run, values):.1e} | {s_err if any(n in run for n in sens) else float('nan'):.1e} | "
              f"{e_obj:.1e} | {e_dobj if sens and sens[0] in run else float('nan'):.1e} |")


if __name__ == "__main__":
    main()
