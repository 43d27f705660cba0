"""A scene that starts at its static equilibrium (`initial: equilibrium`) run from Python: the
mass of a spring-mass-damper under a constant force starts at x* = f / k and stays there, its
sensitivity is the closed form's dx*/dk = -f / k^2, and a parameter set from Python moves the
start (computed again for the new value)."""
import numpy as np

import dydp

SCENE = """scene: still_mass
time: {stop: 2.0, output_step: 0.1}
initial: equilibrium
parameters:
  k: {value: 4.0, unit: N/m, range: [1.0, 10.0]}
sensitivities: [k]
blocks:
  f: {type: source.constant, value: 2.0}
  m: {type: mass_spring_damper, m: 1.5, k: $k, c: 0.8, x0: 0.3}
connections: [f.y -> m.f]
outputs: [m.x, m.v]
"""


def test_the_run_starts_at_the_equilibrium_and_follows_the_parameter(tmp_path):
    path = tmp_path / "still.yaml"
    path.write_text(SCENE)
    scene = dydp.load(path)
    r = scene.run()
    x = r.signals[:, r.signal_names.index("m.x")]
    v = r.signals[:, r.signal_names.index("m.v")]
    np.testing.assert_allclose(x, 2.0 / 4.0, rtol=1e-12, atol=0)
    np.testing.assert_allclose(v, 0.0, rtol=0, atol=1e-12)
    dx_dk = r.sensitivities[:, r.signal_names.index("m.x"), r.sensitivity_names.index("k")]
    np.testing.assert_allclose(dx_dk, -2.0 / 16.0, rtol=1e-9, atol=0)
    scene.set_parameter("k", 8.0)
    again = scene.run()
    np.testing.assert_allclose(again.signals[:, again.signal_names.index("m.x")], 2.0 / 8.0, rtol=1e-12, atol=0)
