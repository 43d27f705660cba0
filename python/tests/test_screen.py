"""dydp.screen against the dydp program's screen.json and samples.csv for the same study, and a
resumed study that keeps every record."""
import numpy as np

import dydp
from conftest import dydp_cli, read_json


def test_screen_equals_the_cli(tmp_path, short_msd):
    params = ["mass", "stiffness", "damping"]
    dydp_cli("screen", short_msd, "--params", ",".join(params), "--samples", "8", "--out", tmp_path / "cli")
    cli = read_json(tmp_path / "cli" / "screen.json")
    s = dydp.screen(short_msd, params, 8, str(tmp_path / "py"), threads=1)
    assert s.parameter_names == params and s.parameter_units == ["kg", "N/m", "N s/m"]
    assert s.objective_names == list(cli["objectives"])
    assert s.p.shape == (8, 3) and s.values.shape == (8, 1) and s.gradients.shape == (8, 1, 3)
    assert list(s.lower) == [p["lower"] for p in cli["parameters"]]
    assert list(s.nominal) == [p["nominal"] for p in cli["parameters"]]
    x = cli["objectives"]["x_rms"]
    assert s.mean[0] == x["mean"] and s.variance[0] == x["variance"]
    assert s.nominal_values[0] == x["nominal"]["value"]
    for i, name in enumerate(params):
        m = x["parameters"][name]
        assert s.nu[0, i] == m["nu"] and s.total_index_bound[0, i] == m["total_index_bound"]
        assert s.normalised[0, i] == m["normalised"] and s.rank[0, i] == m["rank"]
        assert s.local_normalised[0, i] == m["local_normalised"]
    # The measures from the arrays, by numpy: nu is the mean square of the gradients.
    np.testing.assert_allclose(s.nu[0], np.mean(s.gradients[:, 0, :] ** 2, axis=0), rtol=1e-14)
    width = s.upper - s.lower
    np.testing.assert_allclose(s.total_index_bound[0], width**2 * s.nu[0] / (np.pi**2 * np.var(s.values[:, 0], ddof=1)),
                               rtol=1e-12)
    # The samples are the program's (run 0 of samples.csv is the nominal point).
    table = np.loadtxt(tmp_path / "cli" / "samples.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(table[1:, 1:4], s.p)
    np.testing.assert_array_equal(table[1:, 4], s.values[:, 0])


def test_screen_resumes_from_its_records(tmp_path, short_msd):
    first = dydp.screen(short_msd, ["stiffness", "damping"], 4, str(tmp_path), threads=1)
    again = dydp.screen(short_msd, ["stiffness", "damping"], 6, str(tmp_path), resume=True, threads=1)
    assert first.recorded_before == 0 and again.recorded_before == 5
    np.testing.assert_array_equal(again.values[:4], first.values)
    np.testing.assert_array_equal(again.gradients[:4], first.gradients)


def test_screen_by_the_adjoint_equals_the_cli_and_the_forward_gradients(tmp_path, short_msd):
    """screen(adjoint=True) as `dydp screen --adjoint`: the same Sobol' points and values, the
    gradients of the adjoint runs equal to the CLI's bit for bit and to the forward sensitivities'
    within the runs' tolerances."""
    params = ["mass", "stiffness", "damping"]
    dydp_cli("screen", short_msd, "--params", ",".join(params), "--samples", "4", "--adjoint", "--no-estimate",
             "--out", tmp_path / "cli")
    table = np.loadtxt(tmp_path / "cli" / "samples.csv", delimiter=",", skiprows=1)
    adjoint = dydp.screen(short_msd, params, 4, str(tmp_path / "adjoint"), threads=1, estimate=False, adjoint=True)
    forward = dydp.screen(short_msd, params, 4, str(tmp_path / "forward"), threads=1, estimate=False)
    np.testing.assert_array_equal(table[1:, 1:4], adjoint.p)
    np.testing.assert_array_equal(table[1:, 4], adjoint.values[:, 0])
    cli = read_json(tmp_path / "cli" / "screen.json")
    for i, name in enumerate(params):
        assert adjoint.nu[0, i] == cli["objectives"]["x_rms"]["parameters"][name]["nu"]
    np.testing.assert_array_equal(adjoint.p, forward.p)
    np.testing.assert_allclose(adjoint.values, forward.values, rtol=1e-6)
    scale = np.abs(forward.gradients).max(axis=0, keepdims=True)
    assert np.all(scale > 0)
    np.testing.assert_allclose(adjoint.gradients / scale, forward.gradients / scale, rtol=0, atol=1e-4)
    assert not np.array_equal(adjoint.gradients, forward.gradients)  # two methods, not one run twice
