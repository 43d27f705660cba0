#!/usr/bin/env python3
"""Errors of dydp run folders against a reference run folder (a converged run of the same scene):
for signals, sensitivities and objectives. Used for the step-count studies in docs/accuracy.md.

    python3 bench/accuracy/compare_runs.py REFERENCE_DIR RUN_DIR [RUN_DIR ...]

For every run: steps and CPU seconds (run.json); the largest error over the output grid of each
logged signal and of each d(S)/d(P) column, relative to that column's largest magnitude in the
reference; and the relative error of every objective and of its sensitivities."""
import csv
import json
import sys


def read_signals(folder):
    with open(f"{folder}/signals.csv") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    columns = {name: [float(r[i]) for r in rows[1:]] for i, name in enumerate(header)}
    return columns


def relative(a, b):
    return abs(a - b) / max(abs(b), 1e-300)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    reference = sys.argv[1]
    ref_signals = read_signals(reference)
    ref_objectives = json.load(open(f"{reference}/objectives.json"))["objectives"]
    for folder in sys.argv[2:]:
        run = json.load(open(f"{folder}/run.json"))
        signals = read_signals(folder)
        if signals["t"] != ref_signals["t"]:
            sys.exit(f"{folder}: output grid differs from the reference's")
        worst_signal = worst_sensitivity = (0.0, "")
        for name, ref in ref_signals.items():
            if name == "t":
                continue
            scale = max(abs(v) for v in ref) or 1.0
            error = max(abs(a - b) for a, b in zip(signals[name], ref)) / scale
            if name.startswith("d("):
                worst_sensitivity = max(worst_sensitivity, (error, name))
            else:
                worst_signal = max(worst_signal, (error, name))
        objectives = json.load(open(f"{folder}/objectives.json"))["objectives"]
        worst_objective = worst_objective_sensitivity = (0.0, "")
        for name, ref in ref_objectives.items():
            got = objectives[name]
            worst_objective = max(worst_objective, (relative(got["value"], ref["value"]), name))
            for p, g in ref["sensitivity"].items():
                worst_objective_sensitivity = max(worst_objective_sensitivity,
                                                  (relative(got["sensitivity"][p], g), f"d({name})/d({p})"))
        print(f"{folder}: steps {run['steps']}, CPU {run['cpu_seconds']:.2f} s, "
              f"sens_error_test {run.get('sens_error_test')}")
        print(f"  signals       {worst_signal[0]:.2e} ({worst_signal[1]})")
        print(f"  sensitivities {worst_sensitivity[0]:.2e} ({worst_sensitivity[1]})")
        print(f"  objectives    {worst_objective[0]:.2e} ({worst_objective[1]})")
        print(f"  objective sensitivities {worst_objective_sensitivity[0]:.2e} ({worst_objective_sensitivity[1]})")


if __name__ == "__main__":
    main()
