"""--format mat on run, sweep and replay: the MAT v5 files read back with scipy.io.loadmat (an
independent reader) against signals.csv, sweep.csv and the JSON files of the same command."""
import numpy as np
import scipy.io

import rpc3_file
from conftest import dydp_cli, read_json, read_signals_csv
from test_rpc3 import DT, RIG, recorded_channels


def cells(a):
    return [str(x[0]) if x.size else "" for x in a.ravel()]


def check_signals(mat, folder):
    names, table = read_signals_csv(folder / "signals.csv")
    assert cells(mat["names"]) == names
    signals = mat["signals"]
    assert signals.shape == table.shape
    # signals.csv holds 12 significant digits, the MAT file the doubles themselves.
    for c in range(table.shape[1]):
        col = table[:, c]
        np.testing.assert_allclose(signals[:, c], col, rtol=1e-11, atol=1e-11 * max(np.abs(col).max(), 1e-300))
    return names


def check_json_struct(value, expected):
    """A struct read with squeeze_me / struct_as_record=False against the JSON it came from."""
    if isinstance(expected, dict):
        for key, item in expected.items():
            check_json_struct(getattr(value, key), item)
    elif isinstance(expected, list) and all(isinstance(x, (int, float)) for x in expected) and expected:
        np.testing.assert_array_equal(np.atleast_1d(value), expected)
    elif isinstance(expected, list):
        assert len(np.atleast_1d(value)) == len(expected)
        for v, e in zip(np.atleast_1d(value), expected):
            check_json_struct(v, e)
    elif isinstance(expected, bool):
        assert float(value) == float(expected)
    elif isinstance(expected, (int, float)):
        assert float(value) == float(expected)
    elif expected == "":
        assert np.size(value) == 0 or str(value) == ""
    else:
        assert str(value) == expected


def test_run_mat_holds_signals_csv_objectives_and_run_json(tmp_path, short_msd):
    dydp_cli("run", short_msd, "--format", "mat", "--out", tmp_path)
    mat = scipy.io.loadmat(tmp_path / "run.mat")
    names = check_signals(mat, tmp_path)
    units = cells(mat["units"])
    assert units[0] == "s"
    assert units[names.index("body.x")] == "m"
    assert units[names.index("d(body.x)/d(stiffness)")] == "m / N/m"
    assert units[names.index("d(body.v)/d(damping)")] == "m/s / (N s/m)"
    structs = scipy.io.loadmat(tmp_path / "run.mat", squeeze_me=True, struct_as_record=False)
    check_json_struct(structs["objectives"], read_json(tmp_path / "objectives.json")["objectives"])
    run_json = read_json(tmp_path / "run.json")
    check_json_struct(structs["run"], run_json)
    assert structs["objectives"].x_rms.unit == "m"


def test_sweep_mat_holds_sweep_csv_and_sweep_json(tmp_path, short_msd):
    dydp_cli("sweep", short_msd, "--param", "damping", "--range", "0.5:2.0:3", "--fd", "0.01",
             "--format", "mat", "--out", tmp_path)
    mat = scipy.io.loadmat(tmp_path / "sweep.mat")
    with open(tmp_path / "sweep.csv") as f:
        header = f.readline().strip().split(",")
    table = np.loadtxt(tmp_path / "sweep.csv", delimiter=",", skiprows=1, ndmin=2)
    assert cells(mat["names"]) == header
    np.testing.assert_array_equal(mat["table"], table)
    structs = scipy.io.loadmat(tmp_path / "sweep.mat", squeeze_me=True, struct_as_record=False)
    check_json_struct(structs["sweep"], read_json(tmp_path / "sweep.json"))
    assert structs["sweep"].unit == "N s/m"


def test_replay_mat_holds_the_streamed_signals_csv(tmp_path):
    rig = tmp_path / "rig.yaml"
    rig.write_text(RIG)
    rsp = tmp_path / "drive.rsp"
    rpc3_file.write(rsp, recorded_channels(), DT, "FLOATING_POINT", pts_per_frame=32)
    out = tmp_path / "out"
    dydp_cli("replay", rig, "--input", rsp, "--format", "mat", "--out", out)
    mat = scipy.io.loadmat(out / "replay.mat")
    check_signals(mat, out)
    structs = scipy.io.loadmat(out / "replay.mat", squeeze_me=True, struct_as_record=False)
    replay_json = read_json(out / "replay.json")
    assert structs["replay"].input == replay_json["input"]
    assert float(structs["replay"].simulated_seconds) == replay_json["simulated_seconds"]
    check_json_struct(structs["objectives"], read_json(out / "objectives.json")["objectives"])
