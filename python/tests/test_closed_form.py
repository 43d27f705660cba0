"""The module's run of scenarios/msd_sensitivity.yaml against the closed form of
m x'' + c x' + k x = A sin(w t), x(0) = x0, x'(0) = v0 (the C++ oracle in
tests/engine/msd_closed_form.hpp, mirrored here): position and velocity, their sensitivities to
m, k and c (complex-step derivatives of the closed form, exact to rounding) and the rms
objective with its gradient (Gauss-Legendre over the window). Independent of the CLI and of
differences of runs, which the other tests compare with."""
import pathlib

import numpy as np
import pytest

import dydp
from conftest import scene_path

# The scene's values (checked against its file below).
MASS, STIFFNESS, DAMPING = 1.5, 40.0, 1.2
AMPLITUDE, OMEGA, X0, V0 = 2.0, 2 * np.pi * 0.8, 0.05, 0.0
WINDOW = (2.0, 10.0)
PARAMETERS = ("mass", "stiffness", "damping")


def position(m, k, c, t):
    """x(t): the steady-state particular solution plus the decaying homogeneous one
    (underdamped); complex m, k, c or t give complex-step derivatives."""
    w = OMEGA
    d, e = k - m * w * w, c * w
    den = d * d + e * e
    xp = AMPLITUDE * (d * np.sin(w * t) - e * np.cos(w * t)) / den
    xp0, vp0 = -AMPLITUDE * e / den, AMPLITUDE * d * w / den
    alpha = c / (2 * m)
    beta = np.sqrt(k / m - alpha * alpha)
    c1 = X0 - xp0
    c2 = (V0 - vp0 + alpha * c1) / beta
    return xp + np.exp(-alpha * t) * (c1 * np.cos(beta * t) + c2 * np.sin(beta * t))


H = 1e-30  # complex step: Im f(p + i H) / H, no subtraction, exact to rounding


def velocity(m, k, c, t):
    return position(m, k, c, t + 1j * H).imag / H


def by_parameter(f, j, t):
    """d f / d(parameter j) at the scene's values, by complex step."""
    p = [complex(MASS), complex(STIFFNESS), complex(DAMPING)]
    p[j] += 1j * H
    return f(*p, t).imag / H


def velocity_by_parameter(j, t):
    """d x' / d(parameter j): x is analytic in t and in the parameters, so the complex step in the
    parameter of a central difference in t (step 1e-6 s, error ~1e-12 relative) gives it."""
    h = 1e-6
    return (by_parameter(position, j, t + h) - by_parameter(position, j, t - h)) / (2 * h)


def rms(m, k, c, t=None):
    """sqrt(1/T integral of x^2 over the window), 5-point Gauss-Legendre on 4000 panels."""
    nodes, weights = np.polynomial.legendre.leggauss(5)
    edges = np.linspace(*WINDOW, 4001)
    mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * np.diff(edges)
    ts = (mid[:, None] + half[:, None] * nodes[None, :]).ravel()
    ws = (half[:, None] * weights[None, :]).ravel()
    x = position(m, k, c, ts)
    return np.sqrt(np.sum(ws * x * x) / (WINDOW[1] - WINDOW[0]))


def grid_error(values, reference):
    """The largest difference relative to the reference's largest magnitude."""
    return np.abs(values - reference).max() / np.abs(reference).max()


@pytest.fixture(scope="module")
def tight_scene(tmp_path_factory):
    """The shipped scene at rtol 1e-10, atol 1e-12 (its own 1e-8, 1e-10 leave errors of ~1e-6)."""
    text = pathlib.Path(scene_path("msd_sensitivity.yaml")).read_text()
    for line in ("mass:      {value: 1.5,", "stiffness: {value: 40.0,", "damping:   {value: 1.2,",
                 "force: {type: source.sine, amplitude: 2.0, frequency: 0.8}", "x0: 0.05, v0: 0.0",
                 "x_rms: {type: objective.rms, window: [2.0, 10.0]}"):
        assert line in text, line
    solver = "solver: {method: bdf, rtol: 1.0e-8, atol: 1.0e-10}"
    assert solver in text
    path = tmp_path_factory.mktemp("msd") / "msd_tight.yaml"
    path.write_text(text.replace(solver, "solver: {method: bdf, rtol: 1.0e-10, atol: 1.0e-12}"))
    return str(path)


@pytest.fixture(scope="module")
def tight_run(tight_scene):
    return dydp.run(tight_scene)


def test_position_and_velocity_match_the_closed_form(tight_run):
    r = tight_run
    assert len(r.t) == 1001
    assert grid_error(r.signal("body.x"), position(MASS, STIFFNESS, DAMPING, r.t)) < 1e-6
    assert grid_error(r.signal("body.v"), velocity(MASS, STIFFNESS, DAMPING, r.t)) < 1e-6


@pytest.mark.parametrize("j", range(3), ids=PARAMETERS)
def test_sensitivities_match_the_closed_form(tight_run, j):
    r = tight_run
    assert r.sensitivity_names == list(PARAMETERS)
    p = PARAMETERS[j]
    dx_ref = by_parameter(position, j, r.t)
    assert np.abs(dx_ref).max() > 1e-3, "the direction must move x"
    assert grid_error(r.sensitivity("body.x", p), dx_ref) < 1e-6, p
    assert grid_error(r.sensitivity("body.v", p), velocity_by_parameter(j, r.t)) < 1e-6, p


def test_rms_objective_and_gradient_match_the_closed_form(tight_run):
    o = tight_run.objectives["x_rms"]
    psi = rms(MASS, STIFFNESS, DAMPING)
    assert o["value"] == pytest.approx(psi, rel=1e-6)
    assert list(o["gradient"]) == list(PARAMETERS)
    for j, p in enumerate(PARAMETERS):
        assert o["gradient"][p] == pytest.approx(by_parameter(rms, j, None), rel=1e-6), p



def test_adjoint_gradient_matches_the_closed_form(tight_scene):
    """run(adjoint=True): the rms objective's gradient for every declared parameter from one
    backward run, against the closed form (measured: within 8e-9 relative); the signals without
    sensitivities."""
    scene = dydp.load(tight_scene)
    r = scene.run(adjoint=True, estimate=False)
    assert r.sensitivities.shape == (len(r.t), len(r.signal_names), 0)
    assert r.stats["adjoint"]["checkpoints"] >= 1
    assert r.stats["adjoint"]["backward_steps"] > 0
    o = r.objectives["x_rms"]
    assert o["value"] == pytest.approx(rms(MASS, STIFFNESS, DAMPING), rel=1e-6)
    assert list(o["gradient"]) == list(PARAMETERS)
    for j, p in enumerate(PARAMETERS):
        assert o["gradient"][p] == pytest.approx(by_parameter(rms, j, None), rel=1e-7), p
    assert scene.sensitivities == list(PARAMETERS)
    # without sensitivities there is nothing for the adjoint to compute
    with pytest.raises(dydp.InputError, match="sensitivities"):
        scene.run(adjoint=True, sensitivities=False)
