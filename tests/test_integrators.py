"""The integrator table: each scheme is data (orders, calculus, stage weights).

The compiled step and the exact linear recursions both read the weights; the
hand-written recursions below are the independent check that the table says
what the schemes are.

Covers :mod:`randvib.montecarlo.integrators`.
"""

import numpy as np
import pytest

from randvib.montecarlo.integrators import EULER_MARUYAMA, HEUN, INTEGRATORS, integrator


@pytest.mark.parametrize("scheme", list(INTEGRATORS.values()), ids=list(INTEGRATORS))
def test_weights_are_consistent(scheme):
    # consistency of the drift: the weights sum to one
    assert sum(scheme.weights) == pytest.approx(1.0, abs=1e-15)
    assert scheme.drift_evaluations == len(scheme.weights)
    assert scheme.calculus in ("ito", "stratonovich")


def test_linear_recursions_are_the_schemes_written_out():
    rng = np.random.default_rng(0)
    f = rng.normal(size=(3, 3))
    g = rng.normal(size=(3, 1))
    dt = 0.01
    eye = np.eye(3)
    a, b = EULER_MARUYAMA.linear_recursion(f, g, dt)
    np.testing.assert_allclose(a, eye + dt * f, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(b, g, rtol=1e-14)
    # Heun: x_p = x + dt F x + G dW; x' = x + dt/2 (F x + F x_p) + G dW
    a, b = HEUN.linear_recursion(f, g, dt)
    np.testing.assert_allclose(a, eye + dt * f + 0.5 * dt**2 * f @ f, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(b, (eye + 0.5 * dt * f) @ g, rtol=1e-14, atol=1e-15)


def test_unknown_method_is_refused_by_name():
    with pytest.raises(ValueError, match="`scheme`"):
        integrator("runge-kutta")
