"""Residual diagnostics of a fit: is what the model leaves white and unrelated to the input?

As a system-identification user checks a model (Ljung, *System
Identification*, Sec. 16.6; MATLAB's ``resid``): the residual
``e_i = z_i - zhat_i`` (measured less simulated output) of a model that
explains the record is white noise independent of the input. Two tests:

* **whiteness**: the sample autocorrelation ``r_ee(k)``, k = 1..M, against
  the band ``+-z / sqrt(N)`` of white noise, and the Ljung-Box statistic
  ``Q = N (N + 2) sum_k r_ee(k)^2 / (N - k)``, chi-squared with M degrees of
  freedom under whiteness;
* **independence of the input**: the sample cross-correlation ``r_eu(k)``,
  k = -M..M, against the band of two independent series,
  ``+-z sqrt(sum_j r_ee(j) r_uu(j)) / sqrt(N)`` (Bartlett's formula; a
  coloured input widens the band a white one would have).

The verdict is ``white`` when neither test rejects at the level
:data:`LEVEL` (the cross-correlation test with Holm's correction over its
2M + 1 lags, :func:`randvib.statistics.holm_significant`), else ``structured``: the
model misses dynamics, the noise is coloured, or both, and the least-squares
intervals that assume white noise are too narrow.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

#: Significance level of both tests (as MATLAB's ``resid``: 99 % bands).
LEVEL = 0.01
#: Default number of lags M.
MAX_LAG = 25


@dataclass(frozen=True)
class ResidualDiagnostics:
    """Auto- and cross-correlation of a fit's residual, with bands and a verdict.

    Attributes
    ----------
    lags : ndarray
        0..M for the autocorrelation.
    autocorrelation : ndarray
        ``r_ee(k)``, k = 0..M (``r_ee(0) = 1``).
    cross_lags : ndarray
        -M..M; a positive lag is the input leading the residual.
    cross_correlation : ndarray
        ``r_eu(k)`` of the residual and the input.
    auto_band, cross_band : float
        Half-widths of the (1 - LEVEL) bands of a white residual and of an
        independent one.
    ljung_box : float
        Q statistic; ``ljung_box_p`` its chi-squared(M) p-value.
    cross_p : float
        Smallest Holm-adjusted p-value of the cross-correlation lags.
    verdict : {'white', 'structured'}
    samples : int
        N, the residual's length.
    """

    lags: np.ndarray
    autocorrelation: np.ndarray
    cross_lags: np.ndarray
    cross_correlation: np.ndarray
    auto_band: float
    cross_band: float
    ljung_box: float
    ljung_box_p: float
    cross_p: float
    verdict: str
    samples: int

    @property
    def white(self) -> bool:
        return self.verdict == "white"

    def summary(self) -> str:
        """One line for a report."""
        outside = int(np.sum(np.abs(self.autocorrelation[1:]) > self.auto_band))
        return (
            f"residual {self.verdict}: Ljung-Box Q = {self.ljung_box:.4g} over "
            f"{self.lags[-1]} lags (p = {self.ljung_box_p:.3g}), {outside} autocorrelation "
            f"lags outside the {100 * (1 - LEVEL):g} % band; input cross-correlation "
            f"p = {self.cross_p:.3g} (Holm)"
        )

    def __repr__(self) -> str:  # the verdict and its tests, not the correlation arrays
        return f"ResidualDiagnostics({self.summary()}; N = {self.samples})"

    def to_dict(self) -> dict:
        return {
            "verdict": self.verdict,
            "level": LEVEL,
            "ljung_box": float(self.ljung_box),
            "ljung_box_p": float(self.ljung_box_p),
            "cross_correlation_p": float(self.cross_p),
            "autocorrelation_band": float(self.auto_band),
            "cross_correlation_band": float(self.cross_band),
            "autocorrelation": [float(x) for x in self.autocorrelation],
            "cross_correlation": [float(x) for x in self.cross_correlation],
            "max_lag": int(self.lags[-1]),
            "samples": int(self.samples),
        }

    @classmethod
    def from_dict(cls, d: dict) -> ResidualDiagnostics:
        """The diagnostics that :meth:`to_dict` wrote."""
        m = int(d["max_lag"])
        return cls(
            lags=np.arange(m + 1),
            autocorrelation=np.array(d["autocorrelation"], dtype=float),
            cross_lags=np.arange(-m, m + 1),
            cross_correlation=np.array(d["cross_correlation"], dtype=float),
            auto_band=float(d["autocorrelation_band"]),
            cross_band=float(d["cross_correlation_band"]),
            ljung_box=float(d["ljung_box"]),
            ljung_box_p=float(d["ljung_box_p"]),
            cross_p=float(d["cross_correlation_p"]),
            verdict=d["verdict"],
            samples=int(d["samples"]),
        )


def ljung_box(residual, max_lag: int = MAX_LAG) -> tuple[float, float]:
    """Ljung-Box statistic of ``residual`` over lags 1..M and its chi-squared(M) p-value."""
    e = np.asarray(residual, dtype=float)
    n = e.shape[0]
    m = int(min(max_lag, n // 4))
    if m < 1 or np.std(e) == 0:
        return 0.0, 1.0
    r = _correlation(e, e, m)[m + 1 :]
    q = float(n * (n + 2) * np.sum(r**2 / (n - np.arange(1, m + 1))))
    return q, float(stats.chi2.sf(q, m))


def _correlation(a, b, max_lag):
    """Biased sample cross-correlation ``sum_i a_{i+k} b_i / (N s_a s_b)``, k = -M..M."""
    n = a.shape[0]
    a = a - a.mean()
    b = b - b.mean()
    scale = n * a.std() * b.std()
    size = 1 << int(np.ceil(np.log2(2 * n)))
    full = np.fft.irfft(np.fft.rfft(a, size) * np.conj(np.fft.rfft(b, size)), size)
    k = np.arange(-max_lag, max_lag + 1)
    return full[k % size] / scale if scale > 0 else np.zeros(k.shape)


def residual_diagnostics(residual, input_signal, max_lag: int = MAX_LAG) -> ResidualDiagnostics:
    """Whiteness of ``residual`` and its independence of ``input_signal``.

    Parameters
    ----------
    residual : array_like, shape (N,)
        Measured less simulated output (units of z).
    input_signal : array_like, shape (N,)
        The record's input (m/s^2, m or N) at the same samples.
    max_lag : int
        M, the largest lag tested (default :data:`MAX_LAG`, at most N / 4).

    Returns
    -------
    ResidualDiagnostics
    """
    from randvib.statistics import holm_significant

    e = np.asarray(residual, dtype=float)
    u = np.asarray(input_signal, dtype=float)
    if e.shape != u.shape or e.ndim != 1:
        raise ValueError(
            f"`residual` and `input_signal` must be 1-D of one length, got {e.shape} and {u.shape}"
        )
    n = e.shape[0]
    if n < 16:
        raise ValueError(f"residual diagnostics need at least 16 samples, got {n}")
    m = int(min(max_lag, n // 4))
    r_ee = _correlation(e, e, m)[m:]
    r_uu = _correlation(u, u, m)[m:]
    r_eu = _correlation(e, u, m)
    z = stats.norm.ppf(1 - LEVEL / 2)
    q, q_p = ljung_box(e, m)
    # Bartlett: var r_eu(k) = (1/N) sum_j r_ee(j) r_uu(j) for independent series
    var = max(float(1 + 2 * np.sum(r_ee[1:] * r_uu[1:])), 1e-12) / n
    p_cross = 2 * stats.norm.sf(np.abs(r_eu) / np.sqrt(var))
    # Holm's smallest adjusted p-value is (2M + 1) times the smallest p-value
    cross_p = float(min(1.0, p_cross.size * np.min(p_cross)))
    related = bool(np.any(holm_significant(p_cross, LEVEL)))
    verdict = "white" if q_p >= LEVEL and not related else "structured"
    return ResidualDiagnostics(
        lags=np.arange(m + 1),
        autocorrelation=r_ee,
        cross_lags=np.arange(-m, m + 1),
        cross_correlation=r_eu,
        auto_band=float(z / np.sqrt(n)),
        cross_band=float(z * np.sqrt(var)),
        ljung_box=q,
        ljung_box_p=q_p,
        cross_p=cross_p,
        verdict=verdict,
        samples=n,
    )
