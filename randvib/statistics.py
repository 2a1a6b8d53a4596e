"""Monte Carlo statistics over independent paths: one home for every estimator.

Every Monte Carlo number randvib reports is a mean over independent paths
(each path's time average, or one path's value such as its first-passage
time) with a 95 % confidence half-width from the spread between paths. This
module holds the estimators behind them, shared by :func:`randvib.simulate`,
the sweeps, the response spectra and every study:

- :class:`Statistic` and :func:`estimate`: a mean with its Student-t 95 %
  half-width, optionally with cross-fitted zero-mean control variates;
- :func:`mean_and_half_width`: the same, column by column (spectra);
- :func:`paired_ratio`: the ratio of two ensembles that share their paths
  (common random numbers), where the paired spread sets the interval;
- :func:`two_sided_p_value` and :func:`holm_significant`: a test of a zero
  mean and Holm's step-down correction for a family of them;
- :class:`FirstPassage` and :func:`median_first_passage`: first-passage times
  censored at the end of the run;
- :class:`TimeStatistics`: one estimate per time of a transient ensemble;
- :func:`proportion` and :func:`wilson_interval`: a probability over paths
  with the Wilson score interval, which stays in [0, 1] (a mean +- t SE of a
  rare event goes below zero: ``0.0010 +- 0.0020``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special  # Student t quantile; lighter than scipy.stats

from randvib import formatting


@dataclass(frozen=True)
class Statistic:
    """A Monte Carlo estimate with its 95 % confidence half-width.

    Attributes
    ----------
    mean : float
        Estimate (mean over paths of per-path time averages).
    ci95 : float
        Half-width of the 95 % confidence interval (Student t over paths).
    std_error : float
        Standard error of ``mean``.
    n_paths : int
        Number of independent paths behind it.

    ``float(stat)`` is the mean. Multiplying or dividing by a number, or adding
    or subtracting one, gives a Statistic with the interval mapped exactly
    (``stat * 1e3`` for mW); arithmetic between two Statistics is refused, since
    it needs their correlation (:func:`paired_ratio` for a ratio of paired
    ensembles). ``str(stat)`` and ``f"{stat}"`` round the mean to its interval.
    """

    mean: float
    ci95: float
    std_error: float
    n_paths: int
    #: The 95 % interval's ends when it is not mean +- ci95 (a probability's
    #: Wilson interval, :func:`proportion`); None otherwise. ``ci95`` is then
    #: the longer side, so that mean +- ci95 still covers the interval.
    lower: float | None = None
    upper: float | None = None

    @property
    def interval(self) -> tuple[float, float]:
        """The 95 % confidence interval (lower, upper)."""
        if self.lower is not None:
            return self.lower, self.upper
        return self.mean - self.ci95, self.mean + self.ci95

    @property
    def relative_ci95(self) -> float:
        """ci95 / |mean| (nan for a zero mean)."""
        return self.ci95 / abs(self.mean) if self.mean != 0 else float("nan")

    def to_dict(self) -> dict:
        """``mean`` and ``ci95``; for a probability also ``ci95_lower`` and ``ci95_upper``."""
        out = {"mean": self.mean, "ci95": self.ci95}
        if self.lower is not None:
            out.update(ci95_lower=self.lower, ci95_upper=self.upper)
        return out

    def __format__(self, spec):
        """``mean ± ci95`` (a probability: ``mean [lower, upper]``); without a spec the
        mean is rounded to its interval (:mod:`randvib.formatting`), with one
        (``f"{stat:.3e}"``) every number uses it."""
        if self.lower is not None:
            if not spec:
                return formatting.proportion(self.mean, self.lower, self.upper)
            return f"{self.mean:{spec}} [{self.lower:{spec}}, {self.upper:{spec}}]"
        if not spec:
            return formatting.estimate(self.mean, self.ci95)
        return f"{self.mean:{spec}} ± {self.ci95:{spec}}"

    def __str__(self):
        return format(self, "")

    def __float__(self):
        """The estimate itself (``float(stat)``); its interval is dropped."""
        return float(self.mean)

    # Scaling or shifting by a known number maps the interval exactly (a linear map
    # of the mean), so those return a Statistic; products of two estimates need their
    # correlation (paired_ratio) and are refused, as is a number divided by one.
    def _scaled(self, factor: float) -> Statistic:
        factor = float(factor)
        ends = {}
        if self.lower is not None:
            low, high = sorted((self.lower * factor, self.upper * factor))
            ends = {"lower": low, "upper": high}
        return Statistic(self.mean * factor, self.ci95 * abs(factor),
                         self.std_error * abs(factor), self.n_paths, **ends)  # fmt: skip

    def _shifted(self, offset: float) -> Statistic:
        offset = float(offset)
        ends = {}
        if self.lower is not None:
            ends = {"lower": self.lower + offset, "upper": self.upper + offset}
        return Statistic(self.mean + offset, self.ci95, self.std_error, self.n_paths, **ends)

    def __mul__(self, other):
        return self._scaled(other) if _is_scalar(other) else NotImplemented

    __rmul__ = __mul__

    def __truediv__(self, other):
        return self._scaled(1.0 / float(other)) if _is_scalar(other) else NotImplemented

    def __add__(self, other):
        return self._shifted(other) if _is_scalar(other) else NotImplemented

    __radd__ = __add__

    def __sub__(self, other):
        return self._shifted(-float(other)) if _is_scalar(other) else NotImplemented

    def __rsub__(self, other):
        return self._scaled(-1.0)._shifted(other) if _is_scalar(other) else NotImplemented

    def __neg__(self):
        return self._scaled(-1.0)


def _is_scalar(value) -> bool:
    """A plain real number (not a Statistic, not an array), for Statistic's arithmetic."""
    return isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool)


def estimate(samples, controls=None, folds: int = 4) -> Statistic:
    """Mean of independent ``samples`` with a t-based 95 % half-width.

    Parameters
    ----------
    samples : array_like, shape (n,)
        One value per independent path.
    controls : array_like, shape (n, p), optional
        Control variates with known mean zero. The controlled estimator is the
        mean of ``Y - X beta``. ``beta`` is fitted by least squares with
        *cross-fitting*: the paths are split into ``folds`` contiguous groups
        and each group's residuals use the coefficients fitted on the other
        groups. The residuals are then independent of their own coefficients,
        so the estimate is unbiased and its half-width (from the residuals'
        spread) honest even with many controls and few paths; fitting beta on
        the same paths under-reports the error (in-sample overfitting). The
        empirical coverage of the 95 % interval, and the under-coverage of
        in-sample fitting, are checked over thousands of repeated estimations
        in ``tests/test_statistics.py::test_cross_fitted_intervals_cover_at_95_percent``.
    folds : int
        Number of cross-fitting groups (>= 2).
    """
    y = np.asarray(samples, dtype=float)
    n = y.size
    if n < 2:
        raise ValueError(f"need at least 2 paths for a confidence interval, got {n}")
    residual = y
    if controls is not None and np.size(controls) > 0:
        x = np.asarray(controls, dtype=float).reshape(n, -1)
        x = x[:, np.std(x, axis=0) > 0]  # drop constant columns (e.g. unused controls)
        p = x.shape[1]
        if p > 0:
            fold_size = n // folds
            if fold_size < 2 or n - fold_size <= p + 1:
                raise ValueError(
                    f"need more paths to use {p} control variates with {folds} folds, got {n}"
                )
            group = np.minimum(np.arange(n) // fold_size, folds - 1)
            residual = np.empty(n)
            for g in range(folds):
                test = group == g
                train = ~test
                design = np.column_stack([np.ones(train.sum()), x[train]])
                coef, *_ = np.linalg.lstsq(design, y[train], rcond=None)
                residual[test] = y[test] - x[test] @ coef[1:]
    mean = float(np.mean(residual))
    var = float(np.var(residual, ddof=1))
    se = np.sqrt(var / n)
    return Statistic(
        mean=mean, ci95=float(special.stdtrit(n - 1, 0.975) * se), std_error=float(se), n_paths=n
    )


#: The normal quantile of a two-sided 95 % interval.
Z95 = float(special.ndtri(0.975))


def wilson_interval(p, n, z: float = Z95):
    """The Wilson score interval of a proportion ``p`` observed over ``n`` trials.

    ``(p + z^2/(2n) +- z sqrt(p (1 - p)/n + z^2/(4 n^2))) / (1 + z^2/n)``
    (Wilson 1927; Agresti and Coull 1998, Brown, Cai and DasGupta 2001): it
    stays inside [0, 1] and keeps close to its nominal coverage for rare
    events, where the Wald interval p +- z sqrt(p (1 - p)/n) has none (it is
    [0, 0] when no path reached the level). Arrays broadcast.

    Returns
    -------
    (lower, upper)
    """
    p, n = np.asarray(p, dtype=float), np.asarray(n, dtype=float)
    z2n = z * z / n
    centre = (p + z2n / 2.0) / (1.0 + z2n)
    half = z * np.sqrt(p * (1.0 - p) / n + z2n / (4.0 * n)) / (1.0 + z2n)
    # at p = 0 (1) the lower (upper) end is 0 (1) exactly, not a rounding of it
    lower = np.where(p <= 0.0, 0.0, np.clip(centre - half, 0.0, 1.0))
    upper = np.where(p >= 1.0, 1.0, np.clip(centre + half, 0.0, 1.0))
    return lower, upper


def effective_trials(p, std_error, n_paths):
    """The number of independent trials behind a probability ``p`` estimated over paths.

    For 0/1 outcomes it is the number of paths. A path's fraction of time
    beyond a level (in [0, 1], mean p) varies less than one outcome,
    Var <= p (1 - p), so the estimate's variance p (1 - p) / n_eff defines
    ``n_eff = p (1 - p) / SE^2 >= n_paths`` (the design-effect adjustment of
    Korn and Graubard 1998 for correlated samples; a controlled estimate's
    smaller SE counts as more trials); n_paths where the paths do not vary.
    Arrays broadcast.
    """
    p = np.clip(np.asarray(p, dtype=float), 0.0, 1.0)
    variance = np.asarray(std_error, dtype=float) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(variance > 0, p * (1.0 - p) / variance, n_paths)
    return np.maximum(ratio, n_paths)


def proportion(per_path, controls=None) -> Statistic:
    """A probability over independent paths: the mean with the Wilson 95 % interval.

    ``per_path`` holds one outcome per path: 0 or 1 (did the path reach the
    stroke), or a fraction of the path's time (beyond the stroke), whose
    interval counts :func:`effective_trials`. ``controls`` as for
    :func:`estimate` (the controlled mean, clipped to [0, 1]). ``ci95`` is the
    interval's longer side, ``std_error`` the estimate's.
    """
    plain = estimate(per_path, controls)
    p = min(max(plain.mean, 0.0), 1.0)
    trials = effective_trials(p, plain.std_error, plain.n_paths)
    lower, upper = (float(x) for x in wilson_interval(p, trials))
    half = max(p - lower, upper - p)
    return Statistic(p, half, plain.std_error, plain.n_paths, lower=lower, upper=upper)


@dataclass(frozen=True)
class FirstPassage:
    """Time for |z| to first exceed the stroke, from each path's start state.

    Paths that never reach the stroke within the run (``t_end``) are
    *censored*: their first-passage time is only known to exceed ``t_end``.
    The mean first-passage time is reported (``mean``, a t interval over
    paths) only when every path reached the stroke; otherwise ``mean`` is
    None and what the data do determine is given instead: how many paths
    reached it, and the restricted mean E[min(tau, t_end)] (a plain mean
    over paths, with its interval), a lower bound of the mean first-passage
    time. With ``initial="stationary"`` the start is random and some paths
    may start beyond the stroke (time 0); ``initial="rest"`` asks how soon
    the magnet reaches its stops from rest.

    Attributes
    ----------
    mean : Statistic or None
        E[tau] (s), when every path reached the stroke.
    restricted_mean : Statistic
        E[min(tau, t_end)] (s), always defined.
    paths_reached : int
        Paths that reached the stroke within the run.
    n_paths : int
    horizon : float
        t_end (s), the censoring time.
    """

    mean: Statistic | None
    restricted_mean: Statistic
    paths_reached: int
    n_paths: int
    horizon: float

    @classmethod
    def from_times(cls, times, horizon: float) -> FirstPassage:
        """From per-path first times (s; negative: not reached within ``horizon``)."""
        times = np.asarray(times, dtype=float)
        reached = times >= 0
        restricted = np.where(reached, times, horizon)
        return cls(
            mean=estimate(times) if np.all(reached) else None,
            restricted_mean=estimate(restricted),
            paths_reached=int(reached.sum()),
            n_paths=int(times.size),
            horizon=float(horizon),
        )

    def to_dict(self) -> dict:
        return {
            "mean": None if self.mean is None else self.mean.mean,
            "ci95": None if self.mean is None else self.mean.ci95,
            "paths_reached": self.paths_reached,
            "n_paths": self.n_paths,
            "horizon": self.horizon,
            "restricted_mean": self.restricted_mean.to_dict(),
        }


@dataclass(frozen=True)
class TimeStatistics:
    """Monte Carlo estimates at several times, each with its 95 % half-width.

    The estimate at each time is the mean over independent paths of that
    path's value at that time (a snapshot of a transient ensemble), with the
    Student-t interval of :func:`estimate`; ``self[i]`` is time i's
    :class:`Statistic`.

    Attributes
    ----------
    mean, ci95, std_error : ndarray
        One value per time.
    n_paths : int
    """

    mean: np.ndarray
    ci95: np.ndarray
    std_error: np.ndarray
    n_paths: int
    #: A probability's Wilson interval at each time (:meth:`proportions`); else None.
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None

    @classmethod
    def from_paths(cls, per_path) -> TimeStatistics:
        """From values of shape (n_paths, n_times), one row per independent path."""
        per_path = np.asarray(per_path, dtype=float)
        n = per_path.shape[0]
        if n < 2:
            raise ValueError(f"need at least 2 paths for a confidence interval, got {n}")
        mean, half = mean_and_half_width(per_path)
        return cls(mean, half, per_path.std(axis=0, ddof=1) / np.sqrt(n), n)

    @classmethod
    def proportions(cls, per_path) -> TimeStatistics:
        """Probabilities at each time from outcomes (n_paths, n_times) in [0, 1]: the
        Wilson interval of :func:`proportion` at each time (``ci95`` its longer side)."""
        plain = cls.from_paths(per_path)
        trials = effective_trials(plain.mean, plain.std_error, plain.n_paths)
        lower, upper = wilson_interval(plain.mean, trials)
        half = np.maximum(plain.mean - lower, upper - plain.mean)
        return cls(plain.mean, half, plain.std_error, plain.n_paths, lower, upper)

    def __len__(self) -> int:
        return self.mean.size

    def __getitem__(self, i) -> Statistic:
        ends = {}
        if self.lower is not None:
            ends = {"lower": float(self.lower[i]), "upper": float(self.upper[i])}
        return Statistic(
            float(self.mean[i]), float(self.ci95[i]), float(self.std_error[i]), self.n_paths,
            **ends,
        )  # fmt: skip

    def to_list(self) -> list:
        """[[mean, 95 % half-width], ...] over the times, ready for JSON."""
        return [[float(m), float(h)] for m, h in zip(self.mean, self.ci95, strict=True)]

    def intervals(self) -> list:
        """[[lower, upper], ...]: the 95 % interval at each time (JSON-ready)."""
        if self.lower is not None:
            return [[float(a), float(b)] for a, b in zip(self.lower, self.upper, strict=True)]
        return [[float(m - h), float(m + h)] for m, h in zip(self.mean, self.ci95, strict=True)]


def mean_and_half_width(per_path: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean over paths (axis 0) and the t-based 95 % half-width of it."""
    n = per_path.shape[0]
    mean = per_path.mean(axis=0)
    se = per_path.std(axis=0, ddof=1) / np.sqrt(n)
    return mean, special.stdtrit(n - 1, 0.975) * se


def paired_ratio(per_path: np.ndarray, reference: np.ndarray) -> tuple[float, float]:
    """mean(per_path) / mean(reference) on the same paths, and its 95 % half-width (delta method)."""
    ratio = float(np.mean(per_path) / np.mean(reference))
    s = estimate(per_path - ratio * reference)
    return ratio, s.ci95 / float(np.mean(reference))


def holm_significant(p_values, level: float = 0.05) -> np.ndarray:
    """Holm-Bonferroni step-down: which of several tests reject at family level ``level``."""
    p = np.asarray(p_values, dtype=float)
    order = np.argsort(p)
    reject = np.zeros(p.size, dtype=bool)
    for rank, i in enumerate(order):
        if p[i] > level / (p.size - rank):
            break
        reject[i] = True
    return reject


def two_sided_p_value(stat) -> float:
    """p-value of mean = 0 for a :class:`Statistic` (normal approximation)."""
    from scipy import stats as _stats

    if stat.std_error == 0:
        return 0.0 if stat.mean != 0 else 1.0
    return float(2 * _stats.norm.sf(abs(stat.mean) / stat.std_error))


def median_first_passage(times, horizon: float) -> float:
    """Median first time (s) with censoring at ``horizon``; NaN unless more than half reached.

    With one censoring time for all paths the Kaplan-Meier survival curve is
    the empirical one before ``horizon``, so the median is the empirical
    median of the reached times whenever more than half the paths reached it.
    """
    times = np.asarray(times, dtype=float)
    if 2 * np.count_nonzero(times >= 0) <= times.size:
        return float("nan")
    return float(np.quantile(np.where(times >= 0, times, horizon), 0.5))
