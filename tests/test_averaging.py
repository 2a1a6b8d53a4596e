"""Stochastic averaging (randvib.analytic.averaging): exact limits, identities, validation."""

import warnings

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy import integrate, optimize

import randvib as rv
from randvib.analytic.averaging import AVERAGING_ZETA_LIMIT, averaging_statistics, orbit_averages
from randvib.analytic.exact_solutions import gibbs_displacement_moment

BASE = rv.preset("figure9")  # m = 0.0226, c = 0.2, k = 57.4, k3 = 70742, Fc = 0.0058
K3_GRID = (0.0, 7.07e4, 5e5, 7e6)


def quiet(harvester, psd):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rv.AveragingValidityWarning)
        return averaging_statistics(harvester, psd)


# ------------------------------------------------------------- orbit integrals
def _orbit_by_quad(m, k, k3, energy):
    """Period and orbit averages straight from the definition, with scipy.quad.

    T = 4 int_0^A dz / v(z) has an inverse-square-root endpoint singularity,
    which quad's algebraic weight (A - z)^(-1/2) takes exactly.
    """
    amp = optimize.brentq(
        lambda a: (k * a * a / 2 + k3 * a**4 / 4) / energy - 1.0,
        0.0,
        1.01 * np.sqrt(2 * energy / k),
        xtol=1e-300,
        rtol=1e-15,
    )

    def regular(z):  # v(z) / sqrt(A - z), from E - U(z) = (A^2 - z^2)(k/2 + k3 (A^2 + z^2)/4)
        return np.sqrt(2 * (amp + z) * (k / 2 + k3 * (amp * amp + z * z) / 4) / m)

    def q(f):
        opts = dict(weight="alg", wvar=(0, -0.5), epsabs=0, epsrel=1e-13, limit=200)
        return integrate.quad(lambda z: f(z) / regular(z), 0, amp, **opts)[0]

    period = 4 * q(lambda z: 1.0)
    t_z2 = 4 * q(lambda z: z * z)
    area = (
        4
        * integrate.quad(
            lambda z: np.sqrt(amp - z) * regular(z), 0, amp, epsabs=0, epsrel=1e-13, limit=200
        )[0]
    )
    return amp, period, area / period, t_z2 / period


@pytest.mark.parametrize("k3", K3_GRID)
@pytest.mark.parametrize("energy", [1e-12, 1e-6, 1e-4, 1e-2, 1.0])
def test_orbit_averages_match_direct_quadrature(k3, energy):
    h = BASE.updated(k3=k3)
    got = orbit_averages(h, energy)
    amp, period, vv, zz = _orbit_by_quad(h.m, h.k, k3, energy)
    assert got.amplitude == pytest.approx(amp, rel=1e-13)
    assert got.period == pytest.approx(period, rel=1e-10)
    assert got.mean_square_velocity == pytest.approx(vv, rel=1e-10)
    assert got.mean_square_displacement == pytest.approx(zz, rel=1e-10)
    assert got.mean_abs_velocity == pytest.approx(4 * amp / period, rel=1e-14)


def test_orbit_averages_linear_and_quartic_limits():
    h = BASE.updated(k3=0.0)
    e = np.geomspace(1e-15, 1e3, 19)
    o = orbit_averages(h, e)
    omega = np.sqrt(h.k / h.m)
    # Linear spring: T = 2 pi / omega, equipartition <m v^2> = <k z^2> = E.
    np.testing.assert_allclose(o.period, 2 * np.pi / omega, rtol=1e-14)
    np.testing.assert_allclose(h.m * o.mean_square_velocity, e, rtol=1e-13)
    np.testing.assert_allclose(h.k * o.mean_square_displacement, e, rtol=1e-13)
    # Pure-quartic limit (huge energy): T E^(1/4) tends to the constant
    # 4 sqrt(m/2) (4/k3)^(1/4) int_0^1 du / sqrt(1 - u^4) = ... Gamma(1/4)^2/(2 sqrt(2 pi)).
    k3 = 7e6
    big = orbit_averages(BASE.updated(k3=k3), 1e12)
    i4 = 1.3110287771460599  # int_0^1 (1 - u^4)^(-1/2) du = Gamma(1/4)^2 / (4 sqrt(2 pi))
    limit = 4 * np.sqrt(BASE.m / 2) * (4 / k3) ** 0.25 * i4 * 1e12**-0.25
    assert big.period == pytest.approx(limit, rel=1e-4)
    # Virial theorem for the quartic: <m v^2> = 4 <k3 z^4 / 4> -> (4/3) E.
    assert BASE.m * big.mean_square_velocity == pytest.approx(4 / 3 * 1e12, rel=1e-4)


def test_orbit_averages_at_zero_energy_and_bad_energy():
    o = orbit_averages(BASE, 0.0)
    assert o.period == pytest.approx(2 * np.pi * np.sqrt(BASE.m / BASE.k), rel=1e-14)
    assert o.mean_square_velocity == 0 and o.mean_abs_velocity == 0
    with pytest.raises(ValueError, match="`energy` must be >= 0"):
        orbit_averages(BASE, -1.0)


# --------------------------------------------------------- exact Gibbs limit
@pytest.mark.parametrize("k3", K3_GRID)
@pytest.mark.parametrize("psd", [1.0, 0.1])
def test_no_friction_reproduces_exact_gibbs_density(k3, psd):
    h = BASE.updated(friction=None, k3=k3)
    r = averaging_statistics(h, psd)
    # E[v^2] = S m / (4 c) for any k3 (paper Eq. 20 holds exactly here).
    assert r.velocity_variance == pytest.approx(psd * h.m / (4 * h.c), rel=1e-12)
    exact_z2 = gibbs_displacement_moment(h.m, h.c, h.k, h.k3, psd)
    assert r.displacement_variance == pytest.approx(exact_z2, rel=1e-10)
    # v is exactly Gaussian: E|v| = sqrt(2/pi) sigma_v.
    assert r.mean_abs_velocity == pytest.approx(np.sqrt(2 / np.pi * r.velocity_variance), rel=1e-12)
    assert r.friction_power == 0


def test_tanh_at_small_beta_is_viscous_damping():
    # Fc tanh(beta v) ~ Fc beta v when beta v << 1: extra viscous damping
    # Fc beta, for which averaging is exact (Gibbs) again.
    fc, beta = 10.0, 1e-3
    h = BASE.updated(friction=rv.Tanh(fc, beta))
    r = averaging_statistics(h, 1.0)
    assert r.velocity_variance == pytest.approx(1.0 * h.m / (4 * (h.c + fc * beta)), rel=1e-6)


def test_tanh_tends_to_coulomb_as_beta_grows():
    coulomb = averaging_statistics(BASE.updated(fc=0.03), 0.5).velocity_variance
    errors = [
        abs(
            averaging_statistics(BASE.updated(friction=rv.Tanh(0.03, b)), 0.5).velocity_variance
            / coulomb
            - 1
        )
        for b in (10.0, 1e2, 1e3, 1e4, 4.8e8)
    ]
    assert all(a > b for a, b in zip(errors, errors[1:], strict=False))
    assert errors[-1] < 1e-12


# ------------------------------------------------------------ energy balance
@given(
    fc=st.floats(0.0, 0.1),
    c=st.floats(0.0, 1.0),
    psd=st.floats(1e-2, 10.0),
    k3=st.sampled_from(K3_GRID),
    beta=st.sampled_from([None, 30.0, 3e3, 4.8e8]),
)
@settings(max_examples=60, deadline=None)
def test_exact_energy_balance_holds_to_quadrature_accuracy(fc, c, psd, k3, beta):
    # c E[v^2] + E[v F] = S m / 4 (Ito's rule on the energy) for the averaged
    # density too: E[drift(H)] = 0 for any zero-flux stationary density.
    assume(c > 1e-4 or fc > 1e-4)  # else the variance is astronomically large
    friction = rv.Coulomb(fc) if beta is None else rv.Tanh(fc, beta)
    h = BASE.updated(c=c, k3=k3, friction=friction) if c > 0 else None
    if h is None:
        h = rv.Harvester(m=BASE.m, c_m=0.0, c_e=0.0, k=BASE.k, k3=k3, friction=friction)
    r = quiet(h, psd)
    balance = h.c * r.velocity_variance + r.friction_power
    assert balance == pytest.approx(psd * h.m / 4, rel=1e-8)
    if beta is None:
        assert r.friction_power == pytest.approx(fc * r.mean_abs_velocity, rel=1e-13)


def test_energy_density_is_normalised_and_gives_the_moments():
    h, psd = BASE.updated(fc=0.03, k3=5e5), 0.5
    r = averaging_statistics(h, psd)
    # p(E) has a square-root kink at E = 0 (Psi ~ sqrt(E) with friction):
    # integrate over x = sqrt(E), where everything is smooth.
    x = np.linspace(0.0, np.sqrt(40 * psd * h.m**2 / (4 * h.c)), 4001)
    e = x * x
    p = rv.energy_density(h, psd, e)
    assert p[0] > 0 and np.all(np.isfinite(p))
    assert integrate.simpson(p * 2 * x, x=x) == pytest.approx(1.0, rel=1e-9)
    vv = orbit_averages(h, e).mean_square_velocity
    assert integrate.simpson(p * vv * 2 * x, x=x) == pytest.approx(r.velocity_variance, rel=1e-9)


# ------------------------------------------------ physics beyond linearisation
def test_friction_makes_velocity_non_gaussian_and_power_depends_on_k3():
    fc = np.array([1e-4, 0.01, 0.03, 0.05])
    psd = 1.0
    lin = rv.expected_power(BASE.updated(fc=fc), psd)
    avg = rv.expected_power(BASE.updated(fc=fc), psd, method="averaging")
    rel = avg / lin - 1
    # Tiny friction: the two agree; the Gaussian closure underestimates E[P_e]
    # more and more as friction grows (velocity density is more peaked).
    assert abs(rel[0]) < 1e-4
    assert np.all(np.diff(rel) > 0) and rel[-1] > 0.02
    # Linearisation cannot see k3; averaging predicts more power for a stiffer spring.
    by_k3 = [rv.expected_power(BASE.updated(k3=k3, fc=0.03), psd, "averaging") for k3 in K3_GRID]
    assert np.all(np.diff(by_k3) > 0)
    lin_k3 = [rv.expected_power(BASE.updated(k3=k3, fc=0.03), psd) for k3 in K3_GRID]
    assert np.ptp(lin_k3) == 0


def test_broadcasts_like_linearisation():
    fc = np.linspace(0, 0.03, 7)
    psd = np.array([[1.0], [0.5], [0.1]])
    p = rv.expected_power(BASE.updated(fc=fc), psd, method="averaging")
    assert p.shape == (3, 7)
    for i, s in enumerate(psd[:, 0]):
        for j, f in enumerate(fc):
            assert p[i, j] == pytest.approx(
                rv.expected_power(BASE.updated(fc=f), s, method="averaging"), rel=1e-13
            )
    pred = rv.predict(BASE.updated(k3=np.array(K3_GRID)), 0.5, method="averaging")
    assert pred.method == "averaging" and pred.velocity_variance.shape == (4,)
    assert np.all(np.diff(pred.displacement_variance) < 0)
    # power into the load with a circuit
    wired = rv.Harvester.from_electrical(
        m=0.0226, c_m=0.049, k=57.4, k3=70742, alpha=0.1992, r_load=2.0, r_coil=0.48,
        friction=rv.Coulomb(0.0058),
    )  # fmt: skip
    pe = rv.expected_power(wired, 1.0, "averaging")
    assert rv.expected_power(wired, 1.0, "averaging", into="load") == pytest.approx(
        pe * 2.0 / 2.48, rel=1e-14
    )


# ------------------------------------------------------------- bad input
def test_bad_input_is_refused_with_named_arguments():
    with pytest.raises(ValueError, match="`psd` must be > 0"):
        rv.expected_power(BASE, -1.0, method="averaging")
    with pytest.raises(ValueError, match="`psd` must be finite"):
        rv.expected_power(BASE, np.nan, method="averaging")
    with pytest.raises(ValueError, match="`method` must be one of"):
        rv.expected_power(BASE, 1.0, method="averagin")
    lugre = rv.preset("lugre-td1")
    with pytest.raises(ValueError, match="memoryless friction.*'lugre'"):
        rv.expected_power(lugre, 1.0, method="averaging")
    undamped = rv.Harvester(m=0.02, c_m=0.0, c_e=0.0, k=50.0, friction=rv.Coulomb(0.0))
    with pytest.raises(ValueError, match="no stationary state"):
        averaging_statistics(undamped, 1.0)


def test_validity_warning_names_the_ratio():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        light = averaging_statistics(BASE, 1.0)  # Fc = 0.0058: no warning
    assert light.zeta_friction < AVERAGING_ZETA_LIMIT
    heavy = BASE.updated(fc=0.2)
    with pytest.warns(rv.AveragingValidityWarning, match=r"zeta_f = .* exceeds 0\.5"):
        r = averaging_statistics(heavy, 1.0)
    assert r.zeta_friction > AVERAGING_ZETA_LIMIT
    with pytest.warns(rv.AveragingValidityWarning):
        rv.expected_power(BASE.updated(fc=np.array([0.0, 0.2])), 1.0, method="averaging")


# ------------------------------------------------------------- CLI and study
def test_cli_power_method_averaging(capsys):
    import json

    from randvib.cli import main

    code = main(["power", "--preset", "figure9", "--psd", "0.5", "--method", "averaging", "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0 and data["method"] == "averaging"
    assert data["power_electrical"] == pytest.approx(
        rv.expected_power(BASE, 0.5, method="averaging"), rel=1e-14
    )


def test_quick_study_meets_the_accuracy_criteria(tmp_path, monkeypatch):
    """The quick study, with its FPK reference on a 64-cell grid instead of 160.

    Nothing here asserts the FPK reference's column (its accuracy is
    tests/test_fokker_planck.py's); at 160 cells its solutions were 90 % of the
    test's time (31 of 33 CPU-s, the run and a resume). The resume, which
    recomputes every analytic column and figure, is checked on a tiny grid
    through the command line (tests/test_cli_paths.py,
    ``test_study_linearisation_vs_averaging_cli``); other settings' refusal here.
    """
    import pandas as pd

    from randvib.studies import load, methods

    monkeypatch.setattr(methods, "FPK_REFERENCE_CELLS", 64)
    study = load("linearisation-vs-averaging")  # studies/linearisation_vs_averaging.py
    run_study, verdicts = study.run_study, study.verdicts

    report = run_study(tmp_path / "lva", quick=True, seed=0, progress=False)
    assert report.name == "report.md" and report.exists()
    assert (report.parent / "error_vs_friction.png").exists()
    assert (report.parent / "interaction.png").exists()
    df = pd.read_csv(report.parent / "results.csv")
    v = verdicts(df)
    assert v["lin_over_3pct"] > 0 and v["avg_third_where_lin_over_3pct"]
    assert v["avg_within_5pct"]
    # The fast FPK grids meet every accuracy criterion, the interaction included.
    assert v["fpk_fast_third_where_lin_over_3pct"] and v["fpk_fast_within_5pct"]
    assert v["fpk_fast_interaction_met"]
    assert v["interaction_fpk_fast_inside"] == v["interaction_points"]
    assert "power_fpk_fast" in df and "dk3_fpk_fast" in df
    text = report.read_text()
    assert "fast FPK" in text and "one point < 10 ms" in text
    # Other settings are refused (a rerun with the same settings resumes: test_cli_paths.py).
    with pytest.raises(FileExistsError):
        run_study(tmp_path / "lva", quick=True, seed=1, progress=False)
