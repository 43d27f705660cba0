"""Shared fixtures of the Python tests: the dydp program the module is compared with, the
source tree's scenes, and short scenes made from them (CI time)."""
import json
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("DYDP_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
DYDP_EXE = os.environ.get("DYDP_EXE", "dydp")


def scene_path(name):
    return str(SOURCE_DIR / "scenarios" / name)


def dydp_cli(*args, expect=0, cwd=None):
    """Runs the dydp program; checks its exit status; returns the completed process."""
    p = subprocess.run([DYDP_EXE, *map(str, args)], capture_output=True, text=True, cwd=cwd)
    assert p.returncode == expect, f"dydp {' '.join(map(str, args))}: exit {p.returncode}\n{p.stdout}\n{p.stderr}"
    return p


def read_json(path):
    with open(path) as f:
        return json.load(f)


def read_signals_csv(path):
    """signals.csv as (header names, rows x columns array), read with numpy alone."""
    import numpy as np
    with open(path) as f:
        names = f.readline().strip().split(",")
    return names, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


@pytest.fixture
def short_msd(tmp_path):
    """scenarios/msd_sensitivity.yaml over 2 s instead of 10 (objective window [0.5, 2])."""
    text = pathlib.Path(scene_path("msd_sensitivity.yaml")).read_text()
    text = text.replace("stop: 10.0", "stop: 2.0").replace("window: [2.0, 10.0]", "window: [0.5, 2.0]")
    assert "stop: 2.0" in text and "window: [0.5, 2.0]" in text
    path = tmp_path / "msd_short.yaml"
    path.write_text(text)
    return str(path)


@pytest.fixture
def short_quarter_car(tmp_path):
    """scenarios/quarter_car_cdc.yaml over 3 s instead of 10 (objective windows [1, 3])."""
    text = pathlib.Path(scene_path("quarter_car_cdc.yaml")).read_text()
    text = text.replace("stop: 10.0", "stop: 3.0").replace("window: [2.0, 10.0]", "window: [1.0, 3.0]")
    assert "stop: 3.0" in text and "window: [2.0, 10.0]" not in text
    path = tmp_path / "quarter_car_short.yaml"
    path.write_text(text)
    return str(path)
