"""Residual diagnostics of a fit (randvib.identification.residuals): whiteness and
independence of the input, the verdict, and its place in an IdentificationResult.

The numbers are checked against the definitions computed here (correlations as
plain sums, the Ljung-Box Q and its chi-squared(M) p-value, Bartlett's band,
Holm's smallest adjusted p-value); the false-alarm rates of the Ljung-Box test,
of the cross-correlation band and of its Holm-corrected test, and of the
verdict over seeds against their nominal levels with exact binomial bounds
(their finite-sample levels are measured by tests/calibration/residual_levels.py);
the power on an MA(2) residual and on an input leaking into the residual.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal, stats
from test_statistics import holm_adjusted

from randvib.identification.residuals import LEVEL, MAX_LAG, ljung_box, residual_diagnostics


def coloured(rng, n):
    return signal.lfilter([1.0], [1.0, -0.8], rng.standard_normal(n))


def coloured_rows(rng, count, n, phi=0.8):
    """``count`` independent AR(1) series of length ``n``, stationary (200 samples of burn-in)."""
    return signal.lfilter([1.0], [1.0, -phi], rng.standard_normal((count, n + 200)), axis=1)[
        :, 200:
    ]


def correlation(a, b, k):
    """``sum_i (a_{i+k} - mean a) (b_i - mean b) / (N s_a s_b)``: the biased sample
    correlation at lag k (a positive k: b leads a), as a plain sum."""
    a = a - a.mean()
    b = b - b.mean()
    n = a.size
    total = np.sum(a[k:] * b[: n - k]) if k >= 0 else np.sum(a[: n + k] * b[-k:])
    return total / (n * a.std() * b.std())


def ljung_box_by_definition(e, max_lag):
    """Ljung and Box (1978): Q = N (N + 2) sum_{k=1}^M r_k^2 / (N - k), chi-squared(M),
    with M = min(max_lag, N // 4) (the module's rule)."""
    n = e.size
    m = min(max_lag, n // 4)
    q = n * (n + 2) * sum(correlation(e, e, k) ** 2 / (n - k) for k in range(1, m + 1))
    return q, stats.chi2.sf(q, m)


def acceptance(n, p, false_failure, sided="two-sided"):
    """[lo, hi] holding Binomial(n, p) with probability >= 1 - false_failure (exact):
    two-sided, or ``"at most"`` (lo = 0) for a rate claimed to be at most p."""
    if sided == "at most":
        return 0.0, stats.binom.isf(false_failure, n, p)
    return stats.binom.ppf(false_failure / 2, n, p), stats.binom.isf(false_failure / 2, n, p)


@pytest.mark.parametrize(("n", "max_lag"), [(200, MAX_LAG), (200, 7), (60, MAX_LAG)])
def test_ljung_box_is_its_definition(n, max_lag):
    """Q and its chi-squared(M) p-value against the definition, for a white and a
    coloured series (60 samples: M is capped at N / 4 = 15)."""
    rng = np.random.default_rng(n + max_lag)
    for e in (rng.standard_normal(n), coloured(rng, n)):
        q, p = ljung_box(e, max_lag)
        q_def, p_def = ljung_box_by_definition(e, max_lag)
        assert q == pytest.approx(q_def, rel=1e-12)
        assert p == pytest.approx(p_def, rel=1e-9)
    assert ljung_box(np.ones(n), max_lag) == (0.0, 1.0)  # a constant: nothing to test


def test_bands_and_p_values_are_their_definitions():
    """A coloured residual and a coloured input (so that Bartlett's sum matters), with
    half the input two samples late in the residual (so that Holm's adjusted p-value
    lies inside (0, 1)): the correlations, the (1 - LEVEL) bands +-z/sqrt(N) and
    +-z sqrt(sum_j r_ee r_uu / N), the cross-correlation's Holm-adjusted smallest
    p-value, the Ljung-Box Q and the verdict, each from its definition."""
    rng = np.random.default_rng(3)
    n, m = 300, MAX_LAG
    e, u = coloured(rng, n), coloured(rng, n)
    e = e + 0.5 * np.roll(u, 2)
    d = residual_diagnostics(e, u)
    assert 0.0 < d.cross_p < 1.0
    r_ee = np.array([correlation(e, e, k) for k in range(m + 1)])
    r_uu = np.array([correlation(u, u, k) for k in range(m + 1)])
    r_eu = np.array([correlation(e, u, k) for k in range(-m, m + 1)])
    np.testing.assert_allclose(d.autocorrelation, r_ee, rtol=0, atol=1e-12)
    np.testing.assert_allclose(d.cross_correlation, r_eu, rtol=0, atol=1e-12)
    z = stats.norm.isf(LEVEL / 2)  # two-sided
    assert d.auto_band == pytest.approx(z / np.sqrt(n), rel=1e-12)
    variance = (1.0 + 2.0 * np.sum(r_ee[1:] * r_uu[1:])) / n  # Bartlett, j = -M..M
    assert variance > 2.0 / n  # the colour of both widens the band
    assert d.cross_band == pytest.approx(z * np.sqrt(variance), rel=1e-12)
    p_lags = 2.0 * stats.norm.sf(np.abs(r_eu) / np.sqrt(variance))
    assert d.cross_p == pytest.approx(np.min(holm_adjusted(p_lags)), rel=1e-9)
    q, p = ljung_box_by_definition(e, m)
    assert (d.ljung_box, d.ljung_box_p) == (pytest.approx(q, rel=1e-12), pytest.approx(p, rel=1e-9))
    white = p >= LEVEL and np.min(holm_adjusted(p_lags)) > LEVEL
    assert d.verdict == ("white" if white else "structured")


#: White residual and white input: N samples, pairs, and the lags M tested. M = 10,
#: not the default 25, so that Ljung-Box's chi-squared(M), which is asymptotic, holds
#: at 2048 samples (at LEVEL it rejects 1.0 % of white series with M = 10, 1.1 % to
#: 1.2 % with M = 25, 1.8 % with M = 25 at 256 samples; see the calibration).
WHITE_SAMPLES, WHITE_PAIRS, WHITE_LAGS = 2048, 1000, 10
#: What :func:`white_alarm_counts` counts -> its nominal probability and the claim:
#: the Ljung-Box p-value is uniform (its rate below LEVEL, and below 0.5, where
#: M - 1 degrees of freedom would give 0.60); Holm's family-wise level is at most
#: LEVEL; the verdict's at most 2 LEVEL (two tests at LEVEL, the union bound).
WHITE_NOMINAL = {
    "ljung_box": (LEVEL, "two-sided"),
    "ljung_box_median": (0.5, "two-sided"),
    "cross": (LEVEL, "at most"),
    "verdict": (2 * LEVEL, "at most"),
}


def white_alarm_counts(seed, pairs, n=WHITE_SAMPLES, max_lag=WHITE_LAGS):
    """Counts over ``pairs`` independent white (residual, input) pairs: Ljung-Box p
    below LEVEL and below 0.5, Holm's cross test rejecting, verdict 'structured'."""
    rng = np.random.default_rng(seed)
    e, u = rng.standard_normal((2, pairs, n))
    found = [residual_diagnostics(a, b, max_lag) for a, b in zip(e, u, strict=True)]
    return {
        "ljung_box": sum(d.ljung_box_p < LEVEL for d in found),
        "ljung_box_median": sum(d.ljung_box_p < 0.5 for d in found),
        "cross": sum(d.cross_p <= LEVEL for d in found),
        "verdict": sum(not d.white for d in found),
        # 'white' exactly when Ljung-Box's p >= LEVEL and Holm rejects no lag
        "verdict_not_its_rule": sum(
            d.white != (d.ljung_box_p >= LEVEL and d.cross_p > LEVEL) for d in found
        ),
    }


def test_false_alarm_rates_of_white_residuals_hold_their_levels():
    """1000 white residuals of 2048 samples with independent white inputs, M = 10 lags:
    each count inside the exact binomial region of its nominal rate
    (:data:`WHITE_NOMINAL`; false failure 1e-3 over the four), and every verdict by its
    rule. The finite-sample rates over 40 000 pairs are in
    tests/calibration/residual_levels_results.txt."""
    counts = white_alarm_counts(seed=11, pairs=WHITE_PAIRS)
    for name, (p, sided) in WHITE_NOMINAL.items():
        lo, hi = acceptance(WHITE_PAIRS, p, 1e-3 / len(WHITE_NOMINAL), sided)
        assert lo <= counts[name] <= hi, (name, counts[name], (lo, hi))
    assert counts["verdict_not_its_rule"] == 0


#: Coloured residual and coloured input, independent (AR(1), phi = 0.8 both):
#: Bartlett's variance is (1 + phi^2) / (1 - phi^2) / N = 4.6 / N.
COLOURED_SAMPLES, COLOURED_PAIRS = 1024, 600
#: What :func:`band_alarm_counts` counts -> its nominal probability and the claim.
COLOURED_NOMINAL = {"band": (LEVEL, "two-sided"), "cross": (LEVEL, "at most")}


def band_alarm_counts(seed, pairs, n=COLOURED_SAMPLES, lag=0):
    """Over ``pairs`` independent coloured pairs: |r_eu(lag)| outside the cross band,
    and Holm's cross test rejecting."""
    rng = np.random.default_rng(seed)
    e, u = coloured_rows(rng, pairs, n), coloured_rows(rng, pairs, n)
    found = [residual_diagnostics(a, b) for a, b in zip(e, u, strict=True)]
    index = MAX_LAG + lag
    return {
        "band": sum(abs(d.cross_correlation[index]) > d.cross_band for d in found),
        "cross": sum(d.cross_p <= LEVEL for d in found),
    }


def test_cross_correlation_band_holds_its_level_for_coloured_series():
    """600 pairs of independent AR(1) series of 1024 samples: r_eu(0) outside the
    (1 - LEVEL) band inside the exact binomial region of LEVEL (without Bartlett's
    correction it would be outside in 23 % of pairs, a band without the 2 in
    1 + 2 sum in 4.4 %); Holm's family-wise rate at most LEVEL (the lags are
    correlated: Holm is conservative). False failure 1e-3 over both at the nominal
    rates; the finite-sample rates over 20 000 pairs are in
    tests/calibration/residual_levels_results.txt."""
    counts = band_alarm_counts(seed=12, pairs=COLOURED_PAIRS)
    for name, (p, sided) in COLOURED_NOMINAL.items():
        lo, hi = acceptance(COLOURED_PAIRS, p, 1e-3 / len(COLOURED_NOMINAL), sided)
        assert lo <= counts[name] <= hi, (name, counts[name], (lo, hi))


def test_false_alarm_rate_of_a_white_residual_with_a_coloured_input():
    """200 white residuals, each with an independent AR(1) input: the verdict is
    'structured' with probability at most 2 LEVEL (two tests at LEVEL; Bartlett's
    band accounts for the input's colour). Bound: the binomial 99.9 % upper
    quantile of 200 draws at 2 LEVEL."""
    rng = np.random.default_rng(0)
    alarms = sum(
        not residual_diagnostics(rng.standard_normal(1000), coloured(rng, 1000)).white
        for _ in range(200)
    )
    assert alarms <= stats.binom.ppf(0.999, 200, 2 * LEVEL)


def test_coloured_residual_is_structured():
    rng = np.random.default_rng(1)
    e = signal.lfilter([1.0, 0.6, 0.3], [1.0], rng.standard_normal(2000))
    d = residual_diagnostics(e, rng.standard_normal(2000))
    assert d.verdict == "structured" and d.ljung_box_p < 1e-6
    assert np.sum(np.abs(d.autocorrelation[1:]) > d.auto_band) >= 2
    assert d.autocorrelation[0] == pytest.approx(1.0)


def test_input_leaking_into_the_residual_is_structured():
    """A white residual plus 0.2 of the input delayed by 3 samples: the
    cross-correlation at lag 3 is 0.2 / sqrt(1.04), 12 standard errors at N = 4000."""
    rng = np.random.default_rng(2)
    u = rng.standard_normal(4003)
    e = rng.standard_normal(4000) + 0.2 * u[:4000]
    d = residual_diagnostics(e, u[3:])
    assert d.verdict == "structured" and d.cross_p < 1e-6
    lag = d.cross_lags[np.argmax(np.abs(d.cross_correlation))]
    assert abs(lag) == 3
    assert d.to_dict()["verdict"] == "structured"


def test_refuses_mismatched_or_short_series():
    with pytest.raises(ValueError, match="one length"):
        residual_diagnostics(np.zeros(100), np.zeros(99))
    with pytest.raises(ValueError, match="at least 16"):
        residual_diagnostics(np.ones(8), np.ones(8))
