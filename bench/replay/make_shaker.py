#!/usr/bin/env python3
"""The shaker recording and scene of the replay benchmarks (docs/performance.md).

    make_shaker.py SECONDS OUT_DIR

Writes OUT_DIR/shaker_<SECONDS>s.csv: 500 Hz samples of the four pads (columns t, fl, fr, rl,
rr), left and right out of phase at 1 Hz, +-10 mm, plus 0.5 mm rms of noise from 0.5 to 10 Hz
(per pad 40 sines at frequencies drawn uniformly in [0.5, 10] Hz with random phases, seed 2026);
and OUT_DIR/sedan<SECONDS>.yaml: scenarios/fourposter_comfort.yaml run for SECONDS with the
objective windows [2, SECONDS].
"""
import math
import pathlib
import random
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main():
    seconds, out = float(sys.argv[1]), pathlib.Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    tag = f"{seconds:g}"
    random.seed(2026)
    pads = ["fl", "fr", "rl", "rr"]
    phase = {"fl": 0.0, "fr": math.pi, "rl": 0.0, "rr": math.pi}
    a = 0.0005 / math.sqrt(20.0)  # 40 sines of amplitude a: rms a sqrt(40 / 2) = 0.5 mm
    sines = {p: [(random.uniform(0.5, 10.0), random.uniform(0, 2 * math.pi)) for _ in range(40)] for p in pads}
    fs = 500.0
    with open(out / f"shaker_{tag}s.csv", "w") as f:
        f.write("t,fl,fr,rl,rr\n")
        for k in range(int(round(seconds * fs)) + 1):
            t = k / fs
            row = [0.01 * math.sin(2 * math.pi * t + phase[p]) +
                   sum(a * math.sin(2 * math.pi * fk * t + ph) for fk, ph in sines[p]) for p in pads]
            f.write("%.4f,%s\n" % (t, ",".join("%.9e" % v for v in row)))
    scene = (ROOT / "scenarios" / "fourposter_comfort.yaml").read_text()
    scene = scene.replace("stop: 20.0", f"stop: {seconds}")
    scene = scene.replace("window: [2.0, 20.0]", f"window: [2.0, {seconds}]")
    scene = scene.replace("file: subsystems/", f"file: {ROOT / 'scenarios' / 'subsystems'}/")
    (out / f"sedan{tag}.yaml").write_text(scene)


if __name__ == "__main__":
    main()
