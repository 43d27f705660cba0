#!/usr/bin/python3
"""The replay benchmark recordings of kinds other than the shaker file (docs/accuracy.md).

    /usr/bin/python3 make_recordings.py OUT_DIR [SECONDS]   (Debian's python3-numpy)

Writes, 20 s each by default, pad displacements [m] in columns t, fl, fr, rl, rr:
- road_A.csv .. road_D.csv: ISO 8608 roads of classes A to D at 20 m/s, sampled at 1 kHz.
  Displacement PSD Gd(n) = Gd(n0) (n / n0)^-2 with n0 = 0.1 cycles/m and Gd(n0) = 16e-6,
  64e-6, 256e-6, 1024e-6 m^3 (the classes' geometric means), n from 0.011 to 10 cycles/m
  (0.22 to 200 Hz at 20 m/s); left and right independent, each rear the front delayed by the
  wheelbase (2.776 m, shared/reference/sedan.md).
- cleat.csv: a 10 mm high, 0.1 m long half-cosine cleat crossed at 15 m/s by both fronts at 5 s
  (the rears a wheelbase later), on a class A road, 1 kHz.
- chirp.csv: a logarithmic chirp from 0.5 to 25 Hz over the run, 2 mm amplitude, the right
  pads a quarter period behind the left (heave and roll together), 1 kHz.
- noise.csv: white noise of 1 mm rms on each pad, independent, sampled at 2 kHz.
Also OUT_DIR/sedan<SECONDS>.yaml, the scene they are replayed on (as make_shaker.py writes it).
Seeded: the same files on every machine.
"""
import math
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
WHEELBASE = 2.776
PADS = ["fl", "fr", "rl", "rr"]


def write(path, t, columns):
    data = np.column_stack([t] + [columns[p] for p in PADS])
    np.savetxt(path, data, delimiter=",", header="t," + ",".join(PADS), comments="", fmt="%.9e")


def road_profile(rng, gd0, length, dx):
    """A profile of the ISO 8608 class with Gd(n0) = gd0 over [0, length] m, every dx m."""
    n0 = 0.1
    n = np.arange(0.011, 10.0, 0.001)  # spatial frequencies [cycles/m]
    amplitude = np.sqrt(2.0 * gd0 * (n / n0) ** -2 * 0.001)
    phase = rng.uniform(0.0, 2.0 * math.pi, n.size)
    x = np.arange(0.0, length + dx / 2, dx)
    z = np.zeros_like(x)
    for k in range(0, n.size, 500):  # in slices: x.size x 500 at a time
        z += (amplitude[k:k + 500] * np.sin(2 * math.pi * np.outer(x, n[k:k + 500]) + phase[k:k + 500])).sum(axis=1)
    return x, z - z[0]


def road_columns(rng, gd0, speed, t):
    """Left and right tracks independent; each rear the front a wheelbase behind."""
    lead = WHEELBASE + 1.0
    x, left = road_profile(rng, gd0, speed * t[-1] + lead, speed * (t[1] - t[0]))
    _, right = road_profile(rng, gd0, speed * t[-1] + lead, speed * (t[1] - t[0]))
    front = speed * t + lead
    rear = front - WHEELBASE
    return {"fl": np.interp(front, x, left), "fr": np.interp(front, x, right),
            "rl": np.interp(rear, x, left), "rr": np.interp(rear, x, right)}


def main():
    out = pathlib.Path(sys.argv[1])
    seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 20.0
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(2026)

    t = np.arange(0.0, seconds + 5e-4, 1e-3)
    for name, gd0 in zip("ABCD", [16e-6, 64e-6, 256e-6, 1024e-6]):
        write(out / f"road_{name}.csv", t, road_columns(rng, gd0, 20.0, t))

    speed, height, length, t_hit = 15.0, 0.010, 0.1, 5.0
    cols = road_columns(rng, 16e-6, speed, t)
    for pad, delay in zip(PADS, [0.0, 0.0, WHEELBASE / speed, WHEELBASE / speed]):
        s = (t - t_hit - delay) * speed  # distance over the cleat [m]
        on = (s >= 0) & (s <= length)
        cols[pad] = cols[pad] + np.where(on, height * 0.5 * (1 - np.cos(2 * math.pi * s / length)), 0.0)
    write(out / "cleat.csv", t, cols)

    f0, f1 = 0.5, 25.0
    rate = math.log(f1 / f0) / seconds
    phase = 2 * math.pi * f0 * (np.exp(rate * t) - 1) / rate
    left, right = 0.002 * np.sin(phase), 0.002 * np.sin(phase - math.pi / 2)
    write(out / "chirp.csv", t, {"fl": left, "fr": right, "rl": left, "rr": right})

    tn = np.arange(0.0, seconds + 2.5e-4, 5e-4)
    write(out / "noise.csv", tn, {p: 0.001 * rng.standard_normal(tn.size) for p in PADS})

    tag = f"{seconds:g}"
    scene = (ROOT / "scenarios" / "fourposter_comfort.yaml").read_text()
    scene = scene.replace("stop: 20.0", f"stop: {seconds}")
    scene = scene.replace("window: [2.0, 20.0]", f"window: [2.0, {seconds}]")
    scene = scene.replace("file: subsystems/", f"file: {ROOT / 'scenarios' / 'subsystems'}/")
    (out / f"sedan{tag}.yaml").write_text(scene)


if __name__ == "__main__":
    main()
