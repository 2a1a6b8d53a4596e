"""The Monte Carlo estimators: :mod:`randvib.statistics`.

:func:`~randvib.statistics.estimate`'s 95 % interval, with cross-fitted
control variates, covers at its nominal rate (synthetic data and real
simulation output; in-sample fitting is shown to under-cover); first-passage
times censored at the end of the run (:class:`~randvib.statistics.FirstPassage`,
:func:`~randvib.statistics.median_first_passage`); Holm's step-down
(:func:`~randvib.statistics.holm_significant`), against its adjusted p-values.
Coverage is counted against an exact binomial acceptance region;
``tests/calibration/simulation.py`` reruns the coverage over seeds.
"""

import numpy as np
import pytest
from scipy import special, stats

import randvib as rv
from randvib.montecarlo import integrators
from randvib.montecarlo.simulation import simulate
from randvib.statistics import FirstPassage, estimate, holm_significant, median_first_passage

#: The linear device of the schemes' exact discrete covariance (tests/test_simulation.py).
SCHEME_DEVICE = rv.Harvester(m=1.0, c_m=1.0, c_e=0.0, k=4.0)


def binomial_acceptance(n, p=0.95, false_failure=1e-3):
    """[lo, hi] holding Binomial(n, p) with probability >= 1 - false_failure."""
    lo = int(stats.binom.ppf(false_failure / 2, n, p))  # P(X < lo) <= false_failure / 2
    hi = int(stats.binom.isf(false_failure / 2, n, p))  # P(X > hi) <= false_failure / 2
    return lo, hi


def _in_sample_estimate(y, x):
    """Controlled mean with beta fitted on the same paths (what ``estimate`` avoids)."""
    n = y.size
    coef, *_ = np.linalg.lstsq(np.column_stack([np.ones(n), x]), y, rcond=None)
    r = y - x @ coef[1:]
    return r.mean(), special.stdtrit(n - 1, 0.975) * np.sqrt(np.var(r, ddof=1) / n)


def synthetic_coverage(seed, reps, n, p, in_sample=False):
    """Hits of the 95 % interval over ``reps`` data sets y = 3 + X beta + eps.

    X has p equicorrelated (rho = 0.5) standard normal controls; R^2 is about 0.97.
    """
    rng = np.random.default_rng(seed)
    chol = np.linalg.cholesky(np.full((p, p), 0.5) + 0.5 * np.eye(p))
    beta = np.linspace(1.0, 2.0, p)
    hits = 0
    for _ in range(reps):
        x = rng.standard_normal((n, p)) @ chol.T
        y = 3.0 + x @ beta + rng.standard_normal(n)
        if in_sample:
            mean, half = _in_sample_estimate(y, x)
        else:
            s = estimate(y, x)
            mean, half = s.mean, s.ci95
        hits += abs(mean - 3.0) <= half
    return hits


def simulation_coverage(seed, groups=600, group_size=24):
    """Hits of the controlled 95 % interval of E[v_n^2] over independent groups of paths.

    One run of the coarse linear scheme device, split into ``groups`` groups of
    ``group_size`` paths; the reference is the exact discrete stationary value.
    """
    dt, psd = 0.05, 2.0
    cov = integrators.scheme_stationary_covariance("heun", 1.0, 1.0, 4.0, psd, dt)
    r = simulate(
        SCHEME_DEVICE,
        psd,
        t_end=30.0,
        dt=dt,
        n_paths=groups * group_size,
        burn_in=10.0,
        seed=seed,
        check_step=False,
    )
    y, x = r.column(0), r.controls()
    hits = 0
    for g in range(groups):
        s = estimate(
            y[g * group_size : (g + 1) * group_size], x[g * group_size : (g + 1) * group_size]
        )
        hits += abs(s.mean - cov[1, 1]) <= s.ci95
    return hits


def test_cross_fitted_intervals_cover_at_95_percent():
    """Empirical coverage of ``estimate``'s 95 % interval with cross-fitted controls.

    Synthetic data (known mean, 4 correlated controls, 100 paths, 3000 data
    sets) and real simulation output (600 independent groups of 24 paths, 2
    controls, exact discrete reference): the number of hits must lie in the
    exact Binomial(N, 0.95) acceptance region of false-failure rate 1e-3.
    In-sample fitting (6 controls, 24 paths) is shown to under-cover: its hits
    fall below that region. Calibration (20 seeds each): synthetic hits
    0.9437-0.9553 (mean 0.9503; 40 000 data sets at one seed: 0.9496 +-
    0.0011), region [0.9363, 0.9627]; simulation groups 0.9383-0.9600 (mean
    0.9500), region [0.9183, 0.9767]; in-sample 0.830-0.869 (mean 0.855),
    region from 0.9335: all 20 seeds detected.
    """
    reps = 3000
    lo, hi = binomial_acceptance(reps)
    hits = synthetic_coverage(seed=1, reps=reps, n=100, p=4)
    assert lo <= hits <= hi, (hits / reps, lo / reps, hi / reps)
    groups = 600
    lo, hi = binomial_acceptance(groups)
    hits = simulation_coverage(seed=2, groups=groups)
    assert lo <= hits <= hi, (hits / groups, lo / groups, hi / groups)
    # without cross-fitting the interval is too short: detectably under-covers
    reps = 2000
    lo, _ = binomial_acceptance(reps)
    hits = synthetic_coverage(seed=3, reps=reps, n=24, p=6, in_sample=True)
    assert hits < lo, (hits / reps, lo / reps)


def test_first_passage_is_censored_at_the_horizon():
    """Paths that never reach the stroke (time -1) count as the horizon in the
    restricted mean; the mean itself only when every path reached it."""
    censored = FirstPassage.from_times([0.5, -1.0, 1.5, 0.0], horizon=2.0)
    assert censored.mean is None and censored.paths_reached == 3 and censored.n_paths == 4
    assert censored.restricted_mean.mean == pytest.approx((0.5 + 2.0 + 1.5 + 0.0) / 4, rel=1e-15)
    assert censored.to_dict()["mean"] is None and censored.to_dict()["horizon"] == 2.0
    reached = FirstPassage.from_times([0.5, 1.0, 1.5], horizon=2.0)
    assert reached.mean.mean == pytest.approx(1.0, rel=1e-15)
    # the restricted mean of three reached paths is their mean, with the same interval
    assert reached.restricted_mean == reached.mean


def test_median_first_passage_needs_more_than_half_the_paths():
    assert median_first_passage([0.2, 0.4, 0.6, -1.0, -1.0], horizon=1.0) == pytest.approx(0.6)
    assert np.isnan(median_first_passage([0.2, 0.4, -1.0, -1.0], horizon=1.0))


def holm_adjusted(p):
    """Holm's adjusted p-values: max over j <= i of min(1, (m - j) p_(j)) in ascending order
    (0-based j); a hypothesis is rejected at family level alpha iff its value is <= alpha."""
    p = np.asarray(p, dtype=float)
    order = np.argsort(p)
    steps = np.minimum(1.0, (p.size - np.arange(p.size)) * p[order])
    adjusted = np.empty_like(p)
    adjusted[order] = np.maximum.accumulate(steps)
    return adjusted


def test_holm():
    assert list(holm_significant([0.001, 0.04, 0.2])) == [True, False, False]
    assert list(holm_significant([0.01, 0.02])) == [True, True]
    # on the boundary p_(i) = level / (m - i) Holm rejects (<=)
    assert list(holm_significant([0.025, 0.05], 0.05)) == [True, True]


# ------------------------------------------------------------ probabilities (issue 35, item 10)
@pytest.mark.parametrize("n, k", [(1000, 0), (1000, 1), (1000, 37), (50, 49), (50, 50), (20, 7)])
def test_wilson_interval_is_the_score_test_inverted(n, k):
    """The interval is exactly the set of p the score test |k/n - p| / sqrt(p (1-p) / n) <= z
    does not reject (Wilson 1927): at each finite end strictly inside (0, 1) the statistic
    is z, to rounding; with k = 0 the upper end is z^2 / (n + z^2) in closed form."""
    from randvib.statistics import Z95, proportion, wilson_interval

    lower, upper = (float(x) for x in wilson_interval(k / n, n))
    for end in (lower, upper):
        if 0.0 < end < 1.0:
            score = abs(k / n - end) / np.sqrt(end * (1.0 - end) / n)
            assert score == pytest.approx(Z95, rel=1e-10)
    if k == 0:
        assert lower == 0.0 and upper == pytest.approx(Z95**2 / (n + Z95**2), rel=1e-12)
    outcomes = np.zeros(n)
    outcomes[:k] = 1.0
    stat = proportion(outcomes)
    assert (stat.lower, stat.upper) == (lower, upper) and stat.mean == k / n
    assert stat.ci95 == max(k / n - lower, upper - k / n)


def test_a_rare_probability_never_reads_below_zero():
    """One path of 1000 past the stroke: mean +- t SE was 0.0010 +- 0.0020 (below zero);
    the Wilson interval is [0.00018, 0.0056] and prints so."""
    from randvib.statistics import proportion

    outcomes = np.zeros(1000)
    outcomes[0] = 1.0
    wald = estimate(outcomes)
    assert wald.mean - wald.ci95 < 0  # what was reported
    stat = proportion(outcomes)
    assert 0.0 < stat.lower < stat.mean < stat.upper < 1.0
    assert f"{stat}" == "0.0010 [0.0002, 0.0056]"
    assert stat.to_dict() == {"mean": 0.001, "ci95": stat.ci95, "ci95_lower": stat.lower,
                              "ci95_upper": stat.upper}  # fmt: skip
    scaled = 100 * stat  # per cent: the interval scales with it
    assert (scaled.lower, scaled.upper) == pytest.approx((100 * stat.lower, 100 * stat.upper))


def test_wilson_interval_covers_where_wald_fails():
    """Exact coverage (a sum over the binomial law, no sampling) at rare-event levels: the
    Wilson interval's average coverage over p in [0.001, 0.02] at n = 1000 is within 1.5
    points of 95 % (Brown, Cai and DasGupta 2001, Fig. 5: 0.94-0.96), Wald's is far below."""
    from randvib.statistics import Z95, wilson_interval

    n = 1000
    k = np.arange(n + 1)
    lower, upper = wilson_interval(k / n, n)
    wald_half = Z95 * np.sqrt(k / n * (1 - k / n) / n)
    wilson, wald = [], []
    for p in np.linspace(0.001, 0.02, 40):
        weight = stats.binom.pmf(k, n, p)
        wilson.append(weight[(lower <= p) & (p <= upper)].sum())
        wald.append(weight[np.abs(k / n - p) <= wald_half].sum())
    assert abs(np.mean(wilson) - 0.95) < 0.015, np.mean(wilson)
    assert np.mean(wald) < 0.93, np.mean(wald)


def test_a_fraction_of_time_counts_its_effective_trials():
    """Per-path fractions of time beyond a level vary less than 0/1 outcomes: the interval
    uses n_eff = p (1 - p) / SE^2 >= n_paths (Korn and Graubard 1998); 0/1 outcomes give
    n_paths exactly, paths that never vary n_paths."""
    from randvib.statistics import effective_trials, proportion

    rng = np.random.default_rng(5)
    fractions = rng.beta(2.0, 38.0, size=200)  # mean 0.05, far less spread than 0/1
    p, se = fractions.mean(), fractions.std(ddof=1) / np.sqrt(200)
    n_eff = float(effective_trials(p, se, 200))
    assert n_eff == pytest.approx(p * (1 - p) / se**2) and n_eff > 200
    binary = (rng.random(200) < 0.05).astype(float)
    assert float(effective_trials(binary.mean(), estimate(binary).std_error, 200)) == 200
    assert float(effective_trials(0.0, 0.0, 200)) == 200
    stat = proportion(fractions)
    half = stat.upper - stat.lower
    assert half < 2 * 1.96 * np.sqrt(p * (1 - p) / 200)  # narrower than 200 coin flips


def test_holm_is_the_rule_of_adjusted_p_values():
    """Holm's step-down against its adjusted p-values (Holm 1979), computed by another
    route (:func:`holm_adjusted`), on 800 families of 1 to 8 p-values spread over the
    region where the steps decide (0 to 2 level): the same rejections. Among them are
    families where Bonferroni (level / m at every step) and a step-down that does not
    stop at its first acceptance reject otherwise, so the comparison sees both errors."""
    rng = np.random.default_rng(0)
    level = 0.05
    bonferroni_differs = no_stop_differs = False
    for m in range(1, 9):
        for p in rng.uniform(0.0, 2 * level, (100, m)):
            holm = holm_adjusted(p) <= level
            np.testing.assert_array_equal(holm_significant(p, level), holm)
            bonferroni_differs |= not np.array_equal(p <= level / m, holm)
            steps = np.empty(m, dtype=bool)
            steps[np.argsort(p)] = np.sort(p) <= level / (m - np.arange(m))
            no_stop_differs |= not np.array_equal(steps, holm)
    assert bonferroni_differs and no_stop_differs
