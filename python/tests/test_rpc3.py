"""RPC III files as replay input and output: files written here from the format description
(both data types, several frames, a padded last frame and a padded last group, little-endian)
replayed through a rig scene, against the same samples given as CSV; malformed headers refused
with exit status 2 naming file and key; a replay's signals written back as RPC III."""
import math
import pathlib

import numpy as np
import pytest

import rpc3_file
from conftest import dydp_cli, read_json, read_signals_csv

DT = 0.005       # [s] 200 Hz recording
SAMPLES = 230    # 1.145 s: 8 frames of 32 points, the last one padded (26 points)

# A rig scene whose pads follow the recording's channels named in pad_columns (their
# descriptions), with two bodies on springs; 1 s, so the padded samples after 1.145 s never
# reach the run.
RIG = """scene: rig
time: {start: 0.0, stop: 1.0, output_step: 0.004}
solver: {method: bdf, rtol: 1.0e-7, atol: 1.0e-10}
parameters:
  stiffness: {value: 40000.0, unit: N/m, range: [1000.0, 1.0e6]}
sensitivities: [stiffness]
blocks:
  rig: {type: road.fourposter, pad_columns: [front_left, front_right, rear_left, rear_right]}
  pad_fl: {type: math.demux, width: 4, indices: [0]}
  pad_rr: {type: math.demux, width: 4, indices: [3]}
  spring_front: {type: math.gain, k: 40000.0}
  spring_rear: {type: math.gain, k: 40000.0}
  body_front: {type: mass_spring_damper, m: 100.0, k: $stiffness, c: 800.0}
  body_rear: {type: mass_spring_damper, m: 80.0, k: $stiffness, c: 800.0}
  x_rms: {type: objective.rms, window: [0.2, 1.0]}
connections:
  - rig.z -> pad_fl.u
  - rig.z -> pad_rr.u
  - pad_fl.y -> spring_front.u
  - pad_rr.y -> spring_rear.u
  - spring_front.y -> body_front.f
  - spring_rear.y -> body_rear.f
  - body_front.x -> x_rms.in
outputs: [pad_fl.y, pad_rr.y, body_front.x, body_rear.x, x_rms]
"""


def recorded_channels():
    """Five channels in another order than the pads', one of them not a pad."""
    t = np.arange(SAMPLES) * DT
    return [
        ("rear_right", "m", 0.008 * np.sin(2 * math.pi * 3.1 * t - 0.6)),
        ("front_left", "m", 0.012 * np.sin(2 * math.pi * 2.3 * t + 0.4)),
        ("body_acc_measured", "m/s^2", 0.5 * np.cos(2 * math.pi * 1.7 * t)),
        ("front_right", "m", 0.004 * np.sin(2 * math.pi * 1.1 * t)),
        ("rear_left", "m", 0.006 * np.sin(2 * math.pi * 0.7 * t + 1.0)),
    ]


def write_csv(path, channels, decoded, samples):
    """The decoded samples (the first `samples` of them) as the replay's CSV input."""
    t = np.arange(samples) * DT
    with open(path, "w") as f:
        f.write(",".join(["t"] + [c[0] for c in channels]) + "\n")
        for k in range(samples):
            f.write(",".join(repr(float(v)) for v in [t[k]] + [d[k] for d in decoded]) + "\n")


@pytest.fixture
def rig(tmp_path):
    path = tmp_path / "rig.yaml"
    path.write_text(RIG)
    return path


@pytest.mark.parametrize("data_type", ["FLOATING_POINT", "SHORT_INTEGER"])
def test_an_rpc3_recording_replays_as_its_samples_in_csv(tmp_path, rig, data_type):
    channels = recorded_channels()
    rsp = tmp_path / "drive.rsp"
    # 32-point frames, three frames per group: 8 frames, the last padded; 3 groups, the last
    # holding one frame of data and two of padding.
    decoded = rpc3_file.write(rsp, channels, DT, data_type, pts_per_frame=32, frames_per_group=3)
    assert len(decoded[0]) == 256
    header, samples = rpc3_file.read(rsp)  # the independent reader finds what was written
    assert header["FRAMES"] == "8" and header["PTS_PER_GROUP"] == "96"
    csv = tmp_path / "drive.csv"
    write_csv(csv, channels, decoded, SAMPLES)

    dydp_cli("replay", rig, "--input", rsp, "--out", tmp_path / "from_rpc")
    dydp_cli("replay", rig, "--input", csv, "--out", tmp_path / "from_csv")
    rpc_text = (tmp_path / "from_rpc" / "signals.csv").read_text()
    csv_text = (tmp_path / "from_csv" / "signals.csv").read_text()
    assert rpc_text == csv_text
    assert read_json(tmp_path / "from_rpc" / "objectives.json") == read_json(tmp_path / "from_csv" / "objectives.json")
    # The pads are the recorded channels found by description, not by position.
    names, table = read_signals_csv(tmp_path / "from_rpc" / "signals.csv")
    on_grid = np.round(table[:, 0] / DT).astype(int)
    exact = np.isclose(table[:, 0], on_grid * DT, rtol=0, atol=1e-12)
    assert exact.sum() == 51  # every 0.02 s over [0, 1]
    np.testing.assert_allclose(table[exact, names.index("pad_fl.y")], decoded[1][on_grid[exact]], rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(table[exact, names.index("pad_rr.y")], decoded[0][on_grid[exact]], rtol=1e-10, atol=1e-14)
    if data_type == "SHORT_INTEGER":
        # 16-bit samples: within one step of the scale of the original sines.
        np.testing.assert_allclose(decoded[1][:SAMPLES], channels[1][2], rtol=0, atol=0.012 / 32000 * 0.51)


def malformed(records, key, value=None, drop=False):
    out = []
    for k, v in records:
        if k == key:
            if drop:
                continue
            v = value
        out.append((k, v))
    return out


CASES = [
    ("FORMAT", lambda r: [r[1], r[0]] + r[2:]),
    ("FORMAT", lambda r: malformed(r, "FORMAT", "BINARY_IEEE_BIG_END")),
    ("FORMAT", lambda r: malformed(r, "FORMAT", "ASCII")),
    ("NUM_PARAMS", lambda r: malformed(r, "NUM_PARAMS", "many")),
    ("NUM_PARAMS", lambda r: malformed(r, "NUM_PARAMS", "200")),
    ("DATA_TYPE", lambda r: malformed(r, "DATA_TYPE", "DOUBLE")),
    ("DELTA_T", lambda r: malformed(r, "DELTA_T", drop=True)),
    ("DELTA_T", lambda r: malformed(r, "DELTA_T", "-0.005")),
    ("CHANNELS", lambda r: malformed(r, "CHANNELS", "2.5")),
    ("PTS_PER_GROUP", lambda r: malformed(r, "PTS_PER_GROUP", "48")),
    ("FRAMES", lambda r: malformed(r, "FRAMES", "40")),
    ("FRAMES", lambda r: malformed(r, "FRAMES", "1000000000")),
    ("SCALE.CHAN_2", lambda r: malformed(r, "SCALE.CHAN_2", drop=True)),
    ("FILE_TYPE", lambda r: malformed(r, "FILE_TYPE", "FATIGUE")),
    ("DESC.CHAN_4", lambda r: malformed(r, "DESC.CHAN_4", "front_left")),
]


@pytest.mark.parametrize("key,edit", CASES)
def test_a_malformed_header_is_refused_naming_file_and_key(tmp_path, rig, key, edit):
    rsp = tmp_path / "bad.rsp"
    rpc3_file.write(rsp, recorded_channels(), DT, "SHORT_INTEGER", pts_per_frame=32, frames_per_group=1, edit=edit)
    out = tmp_path / "out"
    p = dydp_cli("replay", rig, "--input", rsp, "--out", out, expect=2)
    assert str(rsp) in p.stderr and key in p.stderr, p.stderr
    assert not (out / "signals.csv").exists()


def test_a_replay_is_written_back_as_rpc3(tmp_path, rig):
    channels = recorded_channels()
    rsp = tmp_path / "drive.rsp"
    rpc3_file.write(rsp, channels, DT, "FLOATING_POINT", pts_per_frame=32)
    out = tmp_path / "out"
    dydp_cli("replay", rig, "--input", rsp, "--out", out, "--format", "rpc")
    header, written = rpc3_file.read(out / "signals.rsp")
    names, table = read_signals_csv(out / "signals.csv")
    n = len(table)
    assert header["FILE_TYPE"] == "TIME_HISTORY" and header["DATA_TYPE"] == "FLOATING_POINT"
    assert float(header["DELTA_T"]) == 0.004
    assert int(header["FRAMES"]) * int(header["PTS_PER_FRAME"]) >= n
    signals = [s for s in names[1:] if not s.startswith("d(")]
    assert list(written) == signals
    for c, s in enumerate(signals, start=1):
        col = table[:, names.index(s)]
        np.testing.assert_allclose(written[s][:n], col, rtol=1e-6, atol=1e-7 * np.abs(col).max())
        # The last frame is padded with the last sample.
        assert np.all(written[s][n:] == written[s][n - 1])
    assert header["UNITS.CHAN_3"] == "m"  # body_front.x
    # And it reads back as a replay input: its channels are named after the signals.
    again = RIG.replace("pad_columns: [front_left, front_right, rear_left, rear_right]",
                        "pad_columns: [pad_fl.y, pad_fl.y, pad_rr.y, pad_rr.y]")
    scene = tmp_path / "again.yaml"
    scene.write_text(again)
    p = dydp_cli("replay", scene, "--input", out / "signals.rsp", "--out", tmp_path / "again", "--no-sens")
    names2, table2 = read_signals_csv(tmp_path / "again" / "signals.csv")
    np.testing.assert_allclose(table2[:, names2.index("pad_fl.y")], table[:, names.index("pad_fl.y")],
                               rtol=1e-6, atol=1e-7)
