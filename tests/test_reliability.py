"""Rare events: the estimators against exact stationary exceedances and crossing rates.

Covers :mod:`randvib.montecarlo.path_simulator` (rows of standard normals to
paths: the exact stationary starts, the kernel's peak and up-crossing
accumulators of :mod:`randvib.montecarlo.kernel`, checked path by path against a
plain numpy Heun loop), :mod:`randvib.montecarlo.subset_simulation`,
:mod:`randvib.montecarlo.importance_sampling`, :mod:`randvib.montecarlo.reliability`
(``first_passage``), the anchors :mod:`randvib.analytic.gibbs_marginal` and
:mod:`randvib.analytic.crossings`, and ``randvib reliability``
(:mod:`randvib.cli.reliability`).

The references are exact: for a linear device the scheme's own discrete
stationary law is Gaussian with the discrete Lyapunov covariance P, so
P(|z| > D) = erfc(D / sqrt(2 P_zz)) and the rate of steps on which |z| rises
through D is P(|z_n| <= D, |z_(n+1)| > D) / dt
(:func:`randvib.analytic.crossings.gaussian_chain_upcrossing_rate`, with
E[z_n z_(n+1)] = (A P)_zz) at any dt; for the Duffing device the Gibbs density.
Tolerances are 4 standard errors of the estimates (tests/_stats.py), whose
z-scores and the intervals' coverage were measured over seeds by
tests/calibration/rare_event_coverage.py (results in
rare_event_coverage_results.txt beside it). Subset simulation on the devices
without an exact anchor (a diode bridge, the bistable device with Coulomb
friction, LuGre with a piezo under band-pass input, a recorded input) is
compared with crude Monte Carlo by tests/calibration/rare_event_devices.py.
"""

import json
import math
import warnings

import numpy as np
import pytest
from _cli import one_line_error, run
from _stats import assert_matches
from scipy import linalg, special, stats

import randvib as rv
from randvib.analytic import exact_solutions as exact
from randvib.analytic.crossings import (
    CROSSING_METHODS,
    crossing_prediction,
    gaussian_chain_upcrossing_rate,
)
from randvib.analytic.gibbs_marginal import GibbsDisplacement
from randvib.montecarlo.integrators import scheme_matrices, scheme_stationary_covariance
from randvib.montecarlo.path_simulator import HarvesterPaths
from randvib.montecarlo.reliability import estimate_first_passage, pooled_runs
from randvib.montecarlo.subset_simulation import chain_mean_variance
from randvib.statistics import Statistic

M, C_M, C_E, K = 0.0226, 0.1, 0.1, 57.4
LINEAR = rv.Harvester(m=M, c_m=C_M, c_e=C_E, k=K)
DUFFING = LINEAR.updated(k3=5e5)
DT = 2e-3


def scheme_law(dt=DT, scheme="heun"):
    """(P, A): the scheme's exact stationary covariance of (z, v) and its transition."""
    c = C_M + C_E
    p = scheme_stationary_covariance(scheme, M, c, K, 1.0, dt)
    a, _ = scheme_matrices(scheme, M, c, K, 1.0, dt)
    return p, a


def exact_linear(u, dt=DT):
    """(D, P(|z| > D), up-crossing rate) of the linear device's discrete paths at D = u sigma_z."""
    p, a = scheme_law(dt)
    d = u * math.sqrt(p[0, 0])
    rate = gaussian_chain_upcrossing_rate(p[0, 0], (a @ p)[0, 0], dt, d)
    return d, float(special.erfc(u / math.sqrt(2.0))), rate


# ------------------------------------------------------------ the anchors
def test_gibbs_tail_and_quantiles_to_full_relative_precision():
    """The tabulated tail equals exact_solutions.gibbs_exceedance's adaptive quadrature to
    1e-9 at 0.6 down to 1e-30, for every kind of confining potential; the quantile
    transform inverts it: P(|z| > z(xi)) = 2 Phi(-xi) to 1e-8."""
    for k, k3 in ((K, 0.0), (K, 5e5), (-100.0, 2.5e7), (0.0, 5e5)):
        g = GibbsDisplacement(M, 0.2, k, k3, 1.0)
        sigma = math.sqrt(exact.gibbs_displacement_moment(M, 0.2, k, k3, 1.0))
        for u in (0.5, 2.0, 3.5):
            d = u * sigma
            reference = exact.gibbs_exceedance(M, 0.2, k, k3, 1.0, d)
            if reference < 1e-30:
                continue
            assert float(g.exceedance(d)) == pytest.approx(reference, rel=1e-9), (k, k3, u)
        xi = np.array([0.3, 2.0, 5.0, 8.0, -6.0])
        tails = g.exceedance(g.from_normal(xi))
        np.testing.assert_allclose(tails, 2.0 * special.ndtr(-np.abs(xi)), rtol=1e-8)
        assert np.all(np.sign(g.from_normal(xi)) == np.sign(xi))


def test_discrete_crossing_rate_is_the_bivariate_normal_probability_and_tends_to_rice():
    """P(|x_n| <= D, |x_(n+1)| > D) by quadrature equals the bivariate normal rectangle
    probabilities (scipy, Genz) at a moderate level; as dt -> 0 the discrete rate of the
    linear device tends to Rice's continuous rate (2 sigma_v / (2 pi sigma_z)) e^(-u^2/2)."""
    var, lag, dt, d = 2.0, 1.6, 0.01, 2.5
    cov = [[var, lag], [lag, var]]
    mvn = stats.multivariate_normal(mean=[0, 0], cov=cov)
    # P(|X| <= d, Y > d) twice (symmetry): P(X <= d, Y > d) - P(X <= -d, Y > d)
    inside_up = (stats.norm.cdf(d, scale=math.sqrt(var)) - mvn.cdf([d, d])) - (
        stats.norm.cdf(-d, scale=math.sqrt(var)) - mvn.cdf([-d, d])
    )
    expected = 2.0 * inside_up / dt
    assert gaussian_chain_upcrossing_rate(var, lag, dt, d) == pytest.approx(expected, rel=1e-6)
    p, a = scheme_law(dt=1e-5)
    u = 4.0
    d = u * math.sqrt(p[0, 0])
    rice = math.sqrt(p[1, 1] / p[0, 0]) / math.pi * math.exp(-0.5 * u * u)
    discrete = gaussian_chain_upcrossing_rate(p[0, 0], (a @ p)[0, 0], 1e-5, d)
    assert discrete == pytest.approx(rice, rel=2e-3)


def test_anchors_gibbs_and_rice_agree_on_the_linear_device_and_declare_their_cases():
    """Two routes to the same exact numbers (Gibbs quadrature, Gaussian erfc and Rice);
    the first-passage bounds hold around Poisson and Vanmarcke; refusals name the reason."""
    sigma = math.sqrt(exact.linear_displacement_variance(M, C_M + C_E, K, 1.0))
    gibbs = CROSSING_METHODS["gibbs"].solve(LINEAR, 1.0, 5 * sigma, 1.0)
    rice = CROSSING_METHODS["rice"].solve(LINEAR, 1.0, 5 * sigma, 1.0)
    assert gibbs.stationary_exceedance == pytest.approx(rice.stationary_exceedance, rel=1e-10)
    assert gibbs.upcrossing_rate == pytest.approx(rice.upcrossing_rate, rel=1e-10)
    lo, hi = rice.first_passage_bounds
    assert lo <= rice.first_passage_vanmarcke <= rice.first_passage_poisson <= hi
    assert crossing_prediction(DUFFING, 1.0, 0.01, 1.0).method == "gibbs"
    band = rv.BandPass(1.0, 8.0, 0.1)
    assert crossing_prediction(LINEAR, band, 0.01, 1.0).method == "rice"
    coulomb = LINEAR.updated(friction=rv.Coulomb(0.0058))
    assert crossing_prediction(coulomb, 1.0, 0.008, 1.0).method == "gaussian"
    with pytest.warns(RuntimeWarning, match="outside its validity"):
        crossing_prediction(coulomb, 1.0, 0.02, 1.0)
    with pytest.raises(ValueError, match="friction"):
        CROSSING_METHODS["gibbs"].solve(coulomb, 1.0, 0.01, 1.0)
    with pytest.raises(ValueError, match="linear spring"):
        CROSSING_METHODS["rice"].solve(DUFFING, 1.0, 0.01, 1.0)


# ------------------------------------------------------------ paths from normals
def numpy_heun_outcome(start, increments, stroke, k3=0.0):
    """Peak, up-crossings and fraction beyond of a plain numpy Heun loop (white noise)."""
    c, amp = C_M + C_E, math.sqrt(1.0 / 2.0)
    z, v = start[:, 0].copy(), start[:, 1].copy()
    peak = np.abs(z)
    ups = np.zeros(z.size)
    beyond = np.zeros(z.size)

    def acc(z, v):
        return -(c * v + K * z + k3 * z**3) / M

    for n in range(increments.shape[1]):
        noise = amp * increments[:, n]
        beyond += np.abs(z) > stroke
        zp, vp = z + v * DT, v + acc(z, v) * DT + noise
        zn = z + 0.5 * (v + vp) * DT
        vn = v + 0.5 * (acc(z, v) + acc(zp, vp)) * DT + noise
        ups += (np.abs(z) <= stroke) & (np.abs(zn) > stroke)
        z, v = zn, vn
        peak = np.maximum(peak, np.abs(z))
    return peak, ups, beyond / increments.shape[1]


@pytest.mark.parametrize("device", ["linear", "duffing"])
def test_paths_equal_a_numpy_heun_loop_from_the_exact_start(device):
    """Row -> path, pathwise: the start (the scheme's Gaussian law by its Cholesky factor;
    Gibbs's z by its quantile transform and a Gaussian v), the increments sqrt(dt) xi,
    and the kernel's new peak and up-crossing accumulators, against numpy to 1e-10."""
    h = LINEAR if device == "linear" else DUFFING
    sim = HarvesterPaths(h, 1.0, stroke=0.008, duration=0.1, dt=DT)
    rows = np.random.default_rng(3).standard_normal((40, sim.dimension))
    rows[:5, :2] *= 3.0  # starts far out in the tails
    if device == "linear":
        p, _ = scheme_law()
        start = rows[:, :2] @ np.linalg.cholesky(p).T
    else:
        g = GibbsDisplacement(M, C_M + C_E, K, 5e5, 1.0)
        start = np.column_stack([g.from_normal(rows[:, 0]), g.velocity_std * rows[:, 1]])
    peak, ups, beyond = numpy_heun_outcome(start, math.sqrt(DT) * rows[:, 2:], 0.008, h.k3)
    out = sim(rows)
    np.testing.assert_allclose(out.peak, peak, rtol=1e-10)
    np.testing.assert_array_equal(out.upcrossings, ups)
    np.testing.assert_allclose(out.beyond, beyond, rtol=1e-12)
    assert ups.sum() > 0 and (peak > 0.008).sum() > 3  # the case has crossings to count
    if device == "linear":  # the linear surrogate is the device itself
        z = sim.linear_surrogate.responses(rows)
        np.testing.assert_allclose(np.abs(z).max(axis=1), peak, rtol=1e-10)
        a = sim.linear_surrogate.gradient(17)
        np.testing.assert_allclose(rows @ a, z[:, 17], rtol=1e-9, atol=1e-15)


CASES = {  # device, excitation, paths, window (s), relative bias to detect
    "band-pass (exact start)": (LINEAR, rv.BandPass(1.0, 8.0, 0.2), 20000, 0.05, 0.06),
    "coil (exact start)": (
        rv.Harvester.with_coupling(M, C_M, K, rv.Inductive(0.1992, 1.0, 0.48, 0.05)), 1.0,
        20000, 0.05, 0.06,
    ),
    "band-limited (burn-in)": (LINEAR, rv.BandLimited(1.0, 4.0, 20.0), 2000, 0.5, 0.12),
}  # fmt: skip


@pytest.mark.parametrize("name", ["band-pass (exact start)", "coil (exact start)"])
def test_linear_surrogate_is_the_device_itself_with_a_filter_or_a_circuit(name):
    """Importance sampling's linear response (the scheme's recursion on the augmented
    system: filter, device, circuit) is the kernel's path of a linear device, row by row:
    same start, same sign of the input, to rounding."""
    h, excitation = CASES[name][:2]
    sim = HarvesterPaths(h, excitation, stroke=0.01, duration=0.05, dt=5e-4)
    rows = np.random.default_rng(0).standard_normal((20, sim.dimension))
    z = sim.linear_surrogate.responses(rows)
    assert sim.exactly_linear
    np.testing.assert_allclose(np.abs(z).max(axis=1), sim(rows).peak, rtol=1e-10)


def linear_displacement_variance(sim, h, excitation):
    """E[z^2] of the linear device: Lyapunov (filter, coil); for the synthesised input the
    lines of its periodic synthesis, sum_k P_k |H_z(f_k)|^2 (the input the paths get)."""
    excitation = rv.as_excitation(excitation)
    if excitation.shaping_filter() is not None:
        return float(rv.predict(h, excitation).displacement_variance)
    from randvib.analytic.linear_response import mechanical_block
    from randvib.models.excitation import synthesis_power

    f, power = synthesis_power(excitation, sim.steps_per_path, sim.dt)
    block = mechanical_block(M, C_M + C_E, K)
    response = block.frequency_response(f)[block.output("z")]
    return float(np.sum(power * np.abs(response) ** 2))


@pytest.mark.parametrize("name", list(CASES))
def test_the_start_is_stationary_under_filtered_synthesised_and_circuit_inputs(name):
    """Crude paths from the rows keep the exact stationary exceedance of one standard
    deviation, P(|z| > sigma_z) = erfc(1 / sqrt 2), through the window: the linear
    device's z is Gaussian. The exact starts (filter and device, coil and device: the
    scheme's discrete Lyapunov law) are seen on a short window, the burn-in of the
    synthesised input on a long one. The scheme's variance bias (dt = 5e-4; 1e-3 for the
    band-limited input) is below 1e-3 (the step check), far under the bias the test detects."""
    h, excitation, n_paths, window, detect = CASES[name]
    dt = 1e-3 if name.startswith("band-limited") else 5e-4  # band-limited: 20 Hz at most
    sim = HarvesterPaths(h, excitation, stroke=1.0, duration=window, dt=dt)
    d = math.sqrt(linear_displacement_variance(sim, h, excitation))
    sim = HarvesterPaths(h, excitation, stroke=d, duration=window, dt=dt)
    out = sim(np.random.default_rng(11).standard_normal((n_paths, sim.dimension)))
    reference = float(special.erfc(1.0 / math.sqrt(2.0)))
    assert_matches(rv.estimate(out.beyond), reference, detect=detect, what=name)


# ------------------------------------------------------------ estimators against exact values
@pytest.mark.parametrize("u", [4.9, 6.1])  # P(|z| > D) = 1e-6 and 1e-9
def test_importance_sampling_matches_the_schemes_exact_exceedance_and_rate(u):
    """Linear device, white noise, dt = 2e-3 (coarse: the reference is the scheme's own):
    the exact design points, the weights' diagnostics far from degenerate."""
    d, exceedance, rate = exact_linear(u)
    sim = HarvesterPaths(LINEAR, 1.0, stroke=d, duration=0.1, dt=DT)
    r = estimate_first_passage(sim, method="importance", target_cov=0.03, seed=2, progress=False)
    assert_matches(r.stationary_exceedance, exceedance, detect=0.2, what="exceedance")
    assert_matches(r.upcrossing_rate, rate, detect=0.2, what="crossing rate")
    assert r.details["max_weight_share"] < 0.05 and r.details["amplitude"] == 1.0
    lo, hi = exceedance, exceedance + rate * r.duration
    assert lo < r.probability_first_passage.mean < hi * 1.1


def test_subset_simulation_matches_exact_anchors_at_one_in_a_million():
    """A few hundred samples per level, a short window: the linear device against its
    scheme's exact values, and the Duffing device against the Gibbs density (dt = 1e-3,
    whose scheme bias, under 10 % at this level, is far below the factor the test detects:
    the precise checks are importance sampling's above and the calibration campaign)."""
    d, exceedance, rate = exact_linear(4.9)
    sim = HarvesterPaths(LINEAR, 1.0, stroke=d, duration=0.1, dt=DT)
    r = estimate_first_passage(sim, target_cov=0.2, seed=1, samples_per_level=300, progress=False)
    assert_matches(r.stationary_exceedance, exceedance, detect=2.0, what="linear exceedance")
    assert_matches(r.upcrossing_rate, rate, detect=2.0, what="linear crossing rate")
    g = GibbsDisplacement(M, C_M + C_E, K, 5e5, 1.0)
    stroke = float(g.from_normal(-special.ndtri(0.5e-6)))  # P(|z| > D) = 1e-6
    r = rv.first_passage(DUFFING, 1.0, stroke=stroke, duration=0.1, dt=1e-3, target_cov=0.2,
                         seed=1, samples_per_level=300, progress=False)  # fmt: skip
    assert r.start.startswith("exact: the Gibbs law")
    assert_matches(r.stationary_exceedance, 1e-6, detect=2.0, what="Duffing exceedance")
    assert_matches(r.upcrossing_rate, float(g.upcrossing_rate(stroke)), detect=2.0,
                   what="Duffing crossing rate")  # fmt: skip


def test_first_passage_with_friction_agrees_with_crude_monte_carlo_at_one_in_a_thousand():
    """The paper's device (Coulomb friction, Duffing spring): a linearised start and a
    burn-in (0.3 s, shortened for the test's cost); subset simulation against independent
    crude paths of the same simulator."""
    device = rv.preset("figure9")
    sim = HarvesterPaths(device, 1.0, stroke=0.0125, duration=0.2, dt=1e-3, burn_in=0.3)
    sub = estimate_first_passage(sim, target_cov=0.2, seed=4, samples_per_level=300,
                                 progress=False).probability_first_passage  # fmt: skip
    crude = estimate_first_passage(sim, method="crude", target_cov=0.25, seed=5,
                                   progress=False).probability_first_passage  # fmt: skip
    assert 3e-4 < crude.mean < 3e-3  # the level the test is about
    difference = Statistic(sub.mean - crude.mean, 0.0,
                           math.hypot(sub.std_error, crude.std_error), 0)  # fmt: skip
    assert_matches(difference + crude.mean, crude.mean, detect=2.0, what="subset - crude")
    assert sim.burn_in > 0 and sim.start.startswith("linearised")


def test_importance_sampling_refuses_degenerate_weights():
    """A strongly stiffening spring at 1e-13: the linearisation's design points miss the
    device's failure paths, the effective sample size collapses, and the estimate is refused."""
    p, _ = scheme_law()
    sim = HarvesterPaths(DUFFING, 1.0, stroke=5 * math.sqrt(p[0, 0]), duration=0.25, dt=DT)
    with pytest.raises(ValueError, match="weights have degenerated.*method='subset'"):
        with pytest.warns(RuntimeWarning, match="spent its budget"):
            estimate_first_passage(sim, method="importance", target_cov=0.1, seed=0,
                                   max_path_steps=1e6, progress=False)  # fmt: skip


def test_chain_variance_counts_the_correlation_along_the_chains():
    """Au & Beck's variance of a mean over Nc chains of Ns states: chains that never move
    (each a constant) hold Nc independent values, Var = R(0) / Nc exactly (gamma = Ns - 1);
    chains of independent states give gamma near 0 (taken as 0 when negative)."""
    rng = np.random.default_rng(8)
    constant = np.repeat(rng.standard_normal((50, 1)), 10, axis=1)
    mean, var, gamma = chain_mean_variance(constant)
    r0 = np.mean(constant**2) - mean**2
    assert gamma == pytest.approx(9.0, rel=1e-12)
    assert var == pytest.approx(r0 / 50, rel=1e-12)
    independent = rng.standard_normal((50, 10))
    mean, var, gamma = chain_mean_variance(independent)
    assert 0.0 <= gamma < 0.5
    assert var == pytest.approx(independent.var() / 500 * (1 + gamma), rel=1e-12)


def test_pooled_runs_mean_and_spread_by_hand():
    """The c.o.v. of independent runs' mean (subset simulation's interval in long windows):
    equal runs give the sample SD / sqrt(R) / mean; runs of different sizes (variance
    sigma^2 / size) the size-weighted mean and sigma^2 / sum(size), written out here."""
    values = np.array([1.0, 3.0, 2.0, 6.0])
    mean, cov = pooled_runs(values, np.ones(4))
    assert mean == 3.0
    assert cov == pytest.approx(np.std(values, ddof=1) / 2.0 / 3.0, rel=1e-12)
    sizes = np.array([1.0, 2.0, 1.0, 4.0])
    mean, cov = pooled_runs(values, sizes)
    m = (1.0 + 6.0 + 2.0 + 24.0) / 8.0
    s2 = ((1 - m) ** 2 + 2 * (3 - m) ** 2 + (2 - m) ** 2 + 4 * (6 - m) ** 2) / 3.0
    assert mean == pytest.approx(m, rel=1e-12)
    assert cov == pytest.approx(math.sqrt(s2 / 8.0) / m, rel=1e-12)
    assert (
        math.isnan(pooled_runs([2.0], [1.0])[1]) and pooled_runs([0.0, 0.0], [1, 1])[1] == math.inf
    )


def test_subset_intervals_cover_the_exact_exceedance():
    """40 independent single runs (200 samples per level, P(|z| > D) = 1e-3, linear device):
    the 95 % intervals of the exceedance and the crossing rate cover the exact values at
    least as often as Bin(40, 0.95) does with probability 0.999 (>= 33 times). Measured
    over 400 such runs (tests/calibration/rare_event_coverage.py, single-1e-3): 94.2 %
    (exceedance), 94.8 % (rate), 94.0 % (first passage); Au & Beck's gamma is checked
    exactly by the test above."""
    d, exceedance, rate = exact_linear(3.29)
    sim = HarvesterPaths(LINEAR, 1.0, stroke=d, duration=0.1, dt=DT)
    hits = np.zeros(2)
    for seed in range(40):
        r = estimate_first_passage(sim, target_cov=0.99, seed=100 + seed, samples_per_level=200,
                                   progress=False)  # fmt: skip
        for i, (stat, ref) in enumerate(((r.stationary_exceedance, exceedance),
                                         (r.upcrossing_rate, rate))):  # fmt: skip
            hits[i] += abs(stat.mean - ref) <= stat.ci95
    floor = stats.binom.ppf(1e-3, 40, 0.95)
    assert np.all(hits >= floor), (hits, floor)


# ------------------------------------------------------------ the command line
def test_reliability_table_marks_only_the_approximate_analytic_values(capsys):
    """The table beside each estimate: for a linear device the exceedance and the
    up-crossing rate are exact (unmarked), the Poisson first passage approximate (*)."""
    code, out, _ = run(capsys, "reliability", "--m", M, "--c-m", C_M, "--c-e", C_E, "--k", K,
                       "--psd", 1, "--stroke", 0.012, "--duration", 0.05, "--dt", DT,
                       "--method", "importance", "--target-cov", 0.2)  # fmt: skip
    assert code == 0
    cells = {line.split()[0]: line.split() for line in out.splitlines() if line.strip()}
    assert cells["probability_first_passage"][3].endswith("*")
    for name in ("upcrossing_rate", "stationary_exceedance"):
        assert not cells[name][3].endswith("*") and float(cells[name][3]) > 0
    assert "* approximate (Poisson crossings)" in out


def test_reliability_json_keys(capsys):
    code, out, _ = run(capsys, "reliability", "--m", M, "--c-m", C_M, "--c-e", C_E, "--k", K,
                       "--psd", 1, "--stroke", 0.012, "--duration", 0.05, "--dt", DT,
                       "--method", "importance", "--target-cov", 0.2, "--json")  # fmt: skip
    assert code == 0
    result = json.loads(out)
    for key in ("probability_first_passage", "upcrossing_rate", "stationary_exceedance"):
        assert set(result[key]) == {"mean", "ci95"} and result[key]["mean"] > 0
    assert result["method"] == "importance" and result["path_steps"] > 0
    assert result["units"]["upcrossing_rate"] == "1/s"


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--duration", "1"], "`--stroke` is required"),
        (["--duration", "1", "--stroke", "0.01", "--target-cov", "2"], "`--target-cov` must be"),
        (["--duration", "1", "--stroke", "0.01", "--method", "x"], "`--method` must be one of"),
        (["--duration", "-1", "--stroke", "0.01"], "`--duration` must be"),
    ],
)
def test_reliability_errors_are_one_line(capsys, extra, fragment):
    base = ["reliability", "--preset", "figure9", "--psd", "1", "--no-progress"]
    one_line_error(capsys, base + extra, fragment)


def test_importance_refused_under_a_synthesised_input():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match="method='subset'"):
            rv.first_passage(LINEAR, rv.BandLimited(1.0, 4.0, 20.0), stroke=0.01, duration=0.1,
                             dt=1e-3, method="importance", progress=False)  # fmt: skip


def test_free_mass_refused():
    with pytest.raises(ValueError, match="free mass"):
        rv.first_passage(LINEAR.updated(k=0.0), 1.0, stroke=0.01, duration=0.1, dt=1e-3)


def test_lyapunov_start_of_a_linear_device_is_the_schemes_own():
    """The discrete Lyapunov solution the exact start draws from is stationary under the
    scheme: A P A^T + dt B B^T = P (so a window's statistics do not drift)."""
    p, a = scheme_law()
    _, b = scheme_matrices("heun", M, C_M + C_E, K, 1.0, DT)
    np.testing.assert_allclose(a @ p @ a.T + DT * b @ b.T, p, rtol=1e-10)
    assert np.all(linalg.eigvals(p).real > 0)
