"""Friction laws of paper Eq. 4-10 (:mod:`randvib.models.friction`).

The sign convention (Coulomb's force zero at rest), E[v F(v)] in closed form
against Gaussian quadrature (:mod:`randvib._quadrature`), tanh tending to
Coulomb, LuGre's steady state, the compiled force against the numpy law, and
bad parameters named.
"""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import randvib as rv
from randvib.models.friction import friction_force_and_rate


def test_coulomb_sign_convention_zero_at_rest():
    f = rv.Coulomb(0.01)
    assert np.array_equal(f.force(np.array([-2.0, 0.0, 3.0])), [-0.01, 0.0, 0.01])


@given(st.floats(1e-6, 10), st.floats(1e-4, 10))
def test_coulomb_mean_velocity_force_matches_quadrature(fc, sigma):
    # closed form sqrt(2/pi) Fc sigma against the generic quadrature route
    f = rv.Coulomb(fc)
    generic = rv.FrictionModel.mean_velocity_force(f, sigma)
    assert generic == pytest.approx(f.mean_velocity_force(sigma), rel=1e-12)


def test_tanh_tends_to_coulomb_for_large_beta():
    sigma = 0.1
    coulomb = rv.Coulomb(0.005).mean_velocity_force(sigma)
    gaps = [
        abs(rv.Tanh(0.005, b).mean_velocity_force(sigma) - coulomb) / coulomb
        for b in (1e2, 1e4, 1e6, 1e9)
    ]
    assert all(a > b for a, b in zip(gaps, gaps[1:], strict=False))
    # boundary layer of width 1/beta: relative gap ~ (pi^2/12) / (beta sigma)^2
    assert gaps[-1] < 1e-12


def test_tanh_quadrature_resolves_boundary_layer():
    # E[v tanh(beta v)] for beta sigma = 1 against scipy.integrate.quad
    from scipy import integrate

    sigma, beta = 0.2, 5.0
    exact = (
        2
        * integrate.quad(
            lambda v: (
                v * np.tanh(beta * v) * np.exp(-v * v / (2 * sigma**2)) / np.sqrt(2 * np.pi) / sigma
            ),
            0,
            40 * sigma,
            epsabs=0,
            epsrel=1e-13,
        )[0]
    )
    assert rv.Tanh(1.0, beta).mean_velocity_force(sigma) == pytest.approx(exact, rel=1e-11)


def test_lugre_steady_state_and_no_equivalent_damping():
    f = rv.LuGre(1.98, 0.18, 0.0008, 0.008, 0.007)
    v = np.array([-0.5, -1e-3, 1e-3, 0.5])
    theta = np.sign(v) * f.g(v)  # steady state: theta' = 0
    assert np.allclose(f.bristle_rate(v, theta), 0.0, atol=1e-15)
    assert np.allclose(f.force(v, theta), f.steady_state_force(v))
    with pytest.raises(NotImplementedError, match="memory"):
        f.mean_velocity_force(0.1)


@pytest.mark.parametrize(
    "model",
    [rv.Coulomb(0.006), rv.Tanh(0.006, 300.0), rv.LuGre(1.98, 0.18, 0.0008, 0.008, 0.007)],
)
def test_kernel_matches_numpy_force(model):
    rng = np.random.default_rng(1)
    params = model.kernel_parameters()
    for v, theta in zip(rng.normal(0, 0.1, 20), rng.normal(0, 1e-4, 20), strict=True):
        force, rate = friction_force_and_rate(model.kernel_code, params, v, theta)
        assert force == pytest.approx(float(model.force(v, theta)), rel=1e-13, abs=1e-18)
        if model.n_states:
            assert rate == pytest.approx(float(model.bristle_rate(v, theta)), rel=1e-13)


@pytest.mark.parametrize(
    ("factory", "name", "value"),
    [
        (lambda x: rv.Coulomb(x), "fc", -1.0),
        (lambda x: rv.Tanh(0.01, x), "beta", 0.0),
        (lambda x: rv.Tanh(x, 1.0), "fc", float("nan")),
        (lambda x: rv.LuGre(x, 0.1, 0.001, 0.002, 0.01), "sigma0", -2.0),
        (lambda x: rv.LuGre(1.0, 0.1, 0.001, 0.002, x), "vs", float("inf")),
    ],
)
def test_bad_parameters_name_argument_and_value(factory, name, value):
    with pytest.raises(ValueError, match=f"`{name}`") as err:
        factory(value)
    assert str(value) in str(err.value) or "finite" in str(err.value)
