"""FPK reference solver: convergence study, exact limits, agreement with averaging and MC."""

import warnings

import numpy as np
import pytest

import randvib as rv
from randvib.averaging import AVERAGING_ZETA_LIMIT, averaging_statistics
from randvib.exact import gibbs_displacement_moment
from randvib.fokker_planck import fpk_statistics, solve_fpk

BASE = rv.preset("figure9")


def _order(errors, ratio=2.0):
    errors = np.abs(np.asarray(errors))
    return np.log(errors[:-1] / errors[1:]) / np.log(ratio)


@pytest.mark.parametrize("k3", [0.0, 7.07e4, 7e6])
def test_convergence_study_against_exact_gibbs_density(k3):
    # Table-driven grid refinement: error of E[v^2] and E[z^2] against the
    # exact frictionless values must fall as h^2 (the scheme's order).
    h, psd = BASE.updated(friction=None, k3=k3), 1.0
    exact_v = psd * h.m / (4 * h.c)
    exact_z = gibbs_displacement_moment(h.m, h.c, h.k, h.k3, psd)
    sols = [solve_fpk(h, psd, n) for n in (30, 60, 120)]
    err_v = [s.velocity_variance / exact_v - 1 for s in sols]
    err_z = [s.displacement_variance / exact_z - 1 for s in sols]
    assert np.all(np.abs(np.diff(np.abs(err_v))) > 0) and abs(err_v[-1]) < 2e-3
    np.testing.assert_allclose(_order(err_v), 2.0, atol=0.15)
    np.testing.assert_allclose(_order(err_z), 2.0, atol=0.25)
    # Richardson extrapolation removes the h^2 term.
    assert fpk_statistics(h, psd, 120)[0] == pytest.approx(exact_v, rel=2e-5)


def test_density_is_normalised_symmetric_and_nonnegative():
    h, psd = BASE.updated(fc=0.03), 0.5
    s = solve_fpk(h, psd, 60)
    cell = (s.z[1] - s.z[0]) * (s.v[1] - s.v[0])
    assert s.density.sum() * cell == pytest.approx(1.0, rel=1e-12)
    # Central Liouville fluxes are not positivity-preserving: tiny undershoots
    # (about 1e-8 of the peak) in the far tails are expected.
    assert s.density.min() > -1e-6 * s.density.max()
    # p(z, v) = p(-z, -v): the system is odd-symmetric.
    np.testing.assert_allclose(s.density, s.density[::-1, ::-1], atol=1e-10 * s.density.max())
    assert np.sum(s.v == 0) == 0  # v = 0 lies on a cell face (Coulomb jump)


def test_energy_balance_residual_converges_at_second_order():
    h, psd = BASE.updated(fc=0.04, k3=5e5), 1.0
    target = psd * h.m / 4
    res = [
        (h.c * s.velocity_variance + s.friction_power) / target - 1
        for s in (solve_fpk(h, psd, n) for n in (30, 60, 120))
    ]
    np.testing.assert_allclose(_order(res), 2.0, atol=0.2)
    assert abs(res[-1]) < 2e-3


@pytest.mark.parametrize(
    "c, kappa",
    [(0.2, 0.25), (0.2, 1.0), (0.05, 3.0), (0.5, 1.0)],
)
def test_averaging_beats_linearisation_against_fpk(c, kappa):
    # kappa = 4 Fc^2 / (pi S m c): the friction level of paper Eq. 30.
    psd = 1.0
    fc = np.sqrt(kappa * np.pi * psd * BASE.m * c / 4)
    h = BASE.updated(c=c, fc=fc)
    ref = fpk_statistics(h, psd, 120)[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rv.AveragingValidityWarning)
        avg = averaging_statistics(h, psd)
    lin = rv.velocity_variance(h, psd)
    err_avg, err_lin = avg.velocity_variance / ref - 1, lin / ref - 1
    # Both underestimate; averaging by at most a third of linearisation's error.
    assert err_lin < 0 and err_avg < 0
    assert abs(err_avg) < abs(err_lin) / 3
    # Where averaging does not warn, it is within 2.5 % (AVERAGING_ZETA_LIMIT).
    if avg.zeta_friction <= AVERAGING_ZETA_LIMIT:
        assert abs(err_avg) < 0.025


def test_fpk_method_broadcasts_and_refuses_bad_input():
    pred = rv.predict(BASE.updated(fc=np.array([0.0, 0.01])), 1.0, method="fpk")
    assert pred.method == "fpk" and pred.power_electrical.shape == (2,)
    assert pred.velocity_variance[0] == pytest.approx(1.0 * BASE.m / (4 * BASE.c), rel=1e-4)
    with pytest.raises(ValueError, match="memoryless friction.*'lugre'"):
        solve_fpk(rv.preset("lugre-td1"), 1.0, 40)
    with pytest.raises(ValueError, match="scalar"):
        solve_fpk(BASE.updated(fc=np.array([0.0, 0.01])), 1.0, 40)
    with pytest.raises(ValueError, match="`psd` must be > 0"):
        solve_fpk(BASE, 0.0, 40)
    with pytest.raises(ValueError, match="`nz` must be an integer >= 8"):
        solve_fpk(BASE, 1.0, 4)


def test_fpk_agrees_with_monte_carlo():
    # One moderately frictional point; MC with the engine's control variates.
    # Agreement is required within the 95 % interval widened by the time-step
    # bias bound that simulate() itself enforces for this dt.
    h, psd = BASE.updated(fc=0.04, k3=5e5), 1.0
    ref = fpk_statistics(h, psd, 120)
    mc = rv.simulate(
        h, psd, t_end=60.0, dt=5e-4, n_paths=64, burn_in=2.0, seed=3, companion=True,
        control_variates=True, progress=False,
    )  # fmt: skip
    from randvib.simulation import step_bias

    bias = abs(step_bias("heun", h, psd, 5e-4)) * ref[0]
    vv = mc.velocity_variance
    assert abs(vv.mean - ref[0]) < vv.ci95 + bias
