"""dydp.sweep against the dydp program's sweep.json, and dydp.blocks against `dydp blocks`."""
import math

import numpy as np

import dydp
from conftest import dydp_cli, read_json


def test_sweep_equals_the_cli(tmp_path, short_msd):
    dydp_cli("sweep", short_msd, "--param", "stiffness", "--range", "30:50:3", "--fd", "0.2", "--out", tmp_path)
    cli = read_json(tmp_path / "sweep.json")
    s = dydp.sweep(short_msd, "stiffness", 30.0, 50.0, 3, fd_steps=[0.2], threads=1)
    assert s.parameter == cli["parameter"] and s.unit == cli["unit"] == "N/m"
    assert s.objective_names == cli["objectives"]
    assert s.objective_units == cli["objective_units"]
    assert s.values.shape == (3, 1) and s.gradients.shape == (3, 1) and s.fd.shape == (3, 1, 1)
    for k, point in enumerate(cli["points"]):
        assert s.p[k] == point["p"]
        o = point["objectives"]["x_rms"]
        assert s.values[k, 0] == o["value"]
        assert s.gradients[k, 0] == o["sensitivity"]
        # each point's own error estimate, as the CLI's
        assert s.error_estimate_signals[k] == point["error_estimate"]["signals"]
        assert s.error_estimate_sensitivities[k] == point["error_estimate"]["sensitivities"]
        assert 0 < s.error_estimate_signals[k] < 0.01
        assert s.fd[k, 0, 0] == o["fd"][0]["value"]
    # The exact derivative against the central difference at each point.
    np.testing.assert_allclose(s.fd[:, 0, 0], s.gradients[:, 0], rtol=1e-3)


def test_blocks_list_what_dydp_blocks_prints():
    text = dydp_cli("blocks").stdout
    listed = [line.split("  [")[0] for line in text.splitlines() if not line.startswith(" ")]
    blocks = dydp.blocks()
    assert [b["name"] for b in blocks] == listed
    msd = next(b for b in blocks if b["name"] == "mass_spring_damper")
    params = {p["name"]: p for p in msd["parameters"]}
    assert params["k"]["unit"] == "N/m"
    # Every parameter line of `dydp blocks` for this type carries the same default and unit.
    section = text.split("\nmass_spring_damper  [")[1].split("\n")
    for line in section[1:]:
        if not line.startswith("    "):
            break
        if line.strip().startswith("param"):
            fields = line.split()
            name, default = fields[1], float(fields[3])
            assert math.isclose(params[name]["default"], default, rel_tol=1e-5), name
    outputs = [p["name"] for p in msd["outputs"]]
    assert {"x", "v", "a"} <= set(outputs)
