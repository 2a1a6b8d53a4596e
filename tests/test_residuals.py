"""Residual diagnostics of a fit (randvib.identification.residuals): whiteness and
independence of the input, the verdict, and its place in an IdentificationResult.

The false-alarm rate is checked on independent white and coloured series, the
power on an AR(2) residual and on an input leaking into the residual.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal, stats

from randvib.identification.residuals import LEVEL, residual_diagnostics


def coloured(rng, n):
    return signal.lfilter([1.0], [1.0, -0.8], rng.standard_normal(n))


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
