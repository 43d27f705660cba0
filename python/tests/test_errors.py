"""Bad input arrives as dydp.InputError (a ValueError) with file, line and field, as the dydp
program prints them; a solver failure as dydp.SolverError with time and block."""
import pytest

import dydp
from conftest import dydp_cli, scene_path


def test_a_bad_block_parameter_names_file_line_and_field(tmp_path, short_msd):
    text = open(short_msd).read().replace("x0: 0.05", "x0: fast")
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    line = text.splitlines().index(next(l for l in text.splitlines() if "x0: fast" in l)) + 1
    with pytest.raises(dydp.InputError) as caught:
        dydp.load(str(bad))
    e = caught.value
    assert isinstance(e, ValueError)
    assert e.file == str(bad)
    assert e.line == line
    assert "x0" in e.field
    # The same message the dydp program prints, exit status 2.
    p = dydp_cli("run", bad, "--out", tmp_path / "out", expect=2)
    assert p.stderr.strip() == str(e)


def test_an_unknown_override_is_refused(short_msd):
    with pytest.raises(dydp.InputError) as caught:
        dydp.load(short_msd, {"no_such_parameter": 1.0})
    e = caught.value
    assert (e.file, e.line, e.field) == ("overrides", 0, "no_such_parameter")
    assert str(e).startswith("overrides: no_such_parameter: no scene parameter of that name"), str(e)


def test_an_override_out_of_range_is_refused(short_msd):
    with pytest.raises(dydp.InputError) as caught:
        dydp.load(short_msd, {"stiffness": 5000.0})
    # The range is written in the scene: the error points there.
    assert caught.value.file == short_msd and caught.value.field == "parameters.stiffness"
    assert caught.value.line == 9
    assert "outside its range" in str(caught.value)


def test_a_missing_scene_file(tmp_path):
    missing = str(tmp_path / "missing.yaml")
    with pytest.raises(dydp.InputError) as caught:
        dydp.load(missing)
    assert caught.value.file == missing


def test_an_override_of_the_wrong_type(short_msd):
    with pytest.raises(dydp.InputError) as caught:
        dydp.load(short_msd, {"stiffness": [1, 2]})
    assert caught.value.field == "stiffness"


def test_a_solver_failure_carries_time_and_block():
    # tiny_chambers stops within its first 10 ms, out of stroke (tests/apps/stress_outcomes_test.cpp).
    scene = dydp.load(scene_path("stress/tiny_chambers.yaml"))
    with pytest.raises(dydp.SolverError) as caught:
        scene.run()
    e = caught.value
    assert isinstance(e, RuntimeError)
    assert 0 < e.time < 0.01
    assert e.block != ""
    assert str(e).startswith(f"t = ")
