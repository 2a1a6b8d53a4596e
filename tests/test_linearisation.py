"""Equivalent linearisation under white noise (:mod:`randvib.analytic.linearisation`, paper Eq. 19-32).

Eq. 30 by hand, the general fixed point of Eq. 19-20 with Gaussian expectations
by quadrature (:mod:`randvib._quadrature`), broadcasting over parameters and
levels, the energy balance, and the optimal load of
:mod:`randvib.analytic.prediction` against its closed form.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import randvib as rv

BASE = rv.preset("figure9")


def test_section5_numbers_eq30_by_hand():
    # Eq. 30 for c = 0.2, Fc = 0.0058, S = 1, m = 0.0226, written out independently
    c, fc, s, m = 0.2, 0.0058, 1.0, 0.0226
    b = -2 * c - 8 * fc**2 / (np.pi * s * m)
    c_eq = c + 4 * fc**2 / (np.pi * s * m) + 0.5 * np.sqrt(b**2 - 4 * c**2)
    assert rv.equivalent_damping(BASE, 1.0) == pytest.approx(c_eq, rel=1e-13)
    assert rv.expected_power(BASE, 1.0) == pytest.approx(0.1 * s * m / (4 * c_eq), rel=1e-13)


@given(
    fc=st.floats(0.0, 0.5),
    c=st.floats(1e-3, 10.0),
    psd=st.floats(1e-3, 1e3),
    m=st.floats(1e-3, 10.0),
)
@settings(max_examples=60, deadline=None)
def test_eq30_equals_general_fixed_point(fc, c, psd, m):
    h = rv.Harvester(m=m, c_m=c / 2, c_e=c / 2, k=50.0, friction=rv.Coulomb(fc))
    closed = rv.equivalent_damping(h, psd, expectation="closed-form")
    fixed = rv.equivalent_damping(h, psd, expectation="fixed-point")
    assert fixed == pytest.approx(closed, rel=1e-10)


def test_expectation_is_one_of_its_choices():
    # `expectation` says how E[v F(v)] is taken (not an analytic method as in predict)
    h = BASE.updated(friction=rv.Tanh(0.0058, 300.0))
    with pytest.raises(ValueError, match="`expectation` must be one of"):
        rv.equivalent_damping(h, 0.5, expectation="magic")


def test_zero_friction_gives_viscous_damping():
    for fc in (0.0, 1e-12):
        h = BASE.updated(fc=fc)
        assert rv.equivalent_damping(h, 0.3) == pytest.approx(h.c, rel=1e-9)
    assert rv.equivalent_damping(BASE.updated(friction=None), 0.3) == pytest.approx(0.2, rel=1e-15)
    # Eq. 20: linear oscillator E[v^2] = S m / (4c), for any k3
    assert rv.velocity_variance(BASE.updated(friction=None), 0.3) == pytest.approx(
        0.3 * 0.0226 / 0.8
    )


def test_tanh_with_large_beta_tends_to_coulomb():
    coulomb = rv.expected_power(BASE, 0.5)
    errors = [
        abs(rv.expected_power(BASE.updated(friction=rv.Tanh(0.0058, b)), 0.5) - coulomb) / coulomb
        for b in (10.0, 1e2, 1e3, 1e5, 4.8e8)
    ]
    assert all(a > b for a, b in zip(errors, errors[1:], strict=False))
    assert errors[-1] < 1e-12


def test_broadcasts_over_parameters_and_psd():
    fc = np.linspace(0, 0.03, 7)
    psd = np.array([[1.0], [0.5], [0.1]])
    p = rv.expected_power(BASE.updated(fc=fc), psd)
    assert p.shape == (3, 7)
    for i, s in enumerate(psd[:, 0]):
        for j, f in enumerate(fc):
            assert p[i, j] == pytest.approx(rv.expected_power(BASE.updated(fc=f), s), rel=1e-14)
    # the fixed point broadcasts too (tanh has no closed form)
    pt = rv.expected_power(BASE.updated(friction=rv.Tanh(fc, 1e3)), psd)
    assert pt.shape == (3, 7)
    assert pt[1, 3] == pytest.approx(
        rv.expected_power(BASE.updated(friction=rv.Tanh(fc[3], 1e3)), 0.5), rel=1e-12
    )


@given(psd=st.floats(1e-3, 1e3), c=st.floats(1e-3, 5.0), m=st.floats(1e-3, 5.0))
@settings(max_examples=40, deadline=None)
def test_power_decreases_monotonically_in_fc(psd, c, m):
    h = rv.Harvester(m=m, c_m=c / 2, c_e=c / 2, k=10.0, friction=rv.Coulomb(np.linspace(0, 1, 40)))
    p = rv.expected_power(h, psd)
    assert np.all(np.diff(p) < 0)
    assert p[0] == pytest.approx((c / 2) * psd * m / (4 * c), rel=1e-12)


@given(fc=st.floats(0, 0.1), psd=st.floats(1e-2, 10), beta=st.floats(1.0, 1e9))
@settings(max_examples=40, deadline=None)
def test_energy_balance_identity_holds_for_the_solution(fc, psd, beta):
    # c sigma^2 + E[v F(v)] = S m / 4 under the Gaussian closure (Eq. 19-20)
    h = BASE.updated(friction=rv.Tanh(fc, beta))
    sigma2 = rv.velocity_variance(h, psd)
    lhs = h.c * sigma2 + h.friction.mean_velocity_force(np.sqrt(sigma2))
    assert lhs == pytest.approx(psd * h.m / 4, rel=1e-10)


def test_optimal_load_matches_closed_form_without_friction():
    h = rv.Harvester.from_electrical(
        m=0.0226, c_m=0.049, k=57.4, alpha=0.1992, r_load=1.0, r_coil=0.48
    )
    r_opt, p_opt = rv.optimal_load_resistance(h, 1.0)
    r_closed = rv.optimal_load_resistance_linear(0.049, 0.1992, 0.48)
    assert r_closed == pytest.approx(np.sqrt(0.48**2 + 0.48 * 0.1992**2 / 0.049))
    assert r_opt == pytest.approx(r_closed, rel=1e-6)
    assert p_opt == pytest.approx(
        rv.expected_power(h.updated(r_load=r_closed), 1.0, into="load"), rel=1e-12
    )


def test_friction_moves_the_optimal_load():
    h = rv.Harvester.from_electrical(
        m=0.0226,
        c_m=0.049,
        k=57.4,
        alpha=0.1992,
        r_load=1.0,
        r_coil=0.48,
        friction=rv.Coulomb(0.0058),
    )
    r_f, p_f = rv.optimal_load_resistance(h, 0.1)
    # it is a maximum: neighbours deliver less
    for r in (r_f * 0.9, r_f * 1.1):
        assert rv.expected_power(h.updated(r_load=r), 0.1, into="load") < p_f
    assert abs(r_f - rv.optimal_load_resistance_linear(0.049, 0.1992, 0.48)) > 1e-3


@pytest.mark.parametrize("psd", [0.0, -1.0, float("nan"), float("inf")])
def test_bad_psd(psd):
    with pytest.raises(ValueError, match="`psd`"):
        rv.expected_power(BASE, psd)


def test_lugre_has_no_linearisation_and_unknown_method():
    with pytest.raises(ValueError, match="memoryless"):
        rv.expected_power(rv.preset("lugre-td1"), 1.0)
    with pytest.raises(ValueError, match="`method`"):
        rv.expected_power(BASE, 1.0, method="magic")
