"""Subset simulation (Au & Beck 2001) over the standard normals behind each path.

Au, S.-K. and Beck, J. L. (2001), "Estimation of small failure probabilities
in high dimensions by subset simulation", Probabilistic Engineering Mechanics
16, 263-277. The failure event F = {peak |u| over the window > D} is reached
through nested events F_j = {peak > b_j}, b_1 < b_2 < ... < D, each chosen
adaptively so that P(F_j | F_{j-1}) = p0:

* level 0: N independent rows xi ~ N(0, I) (:mod:`randvib.montecarlo.path_simulator`);
* level j: the N p0 rows of level j-1 with the largest peaks are the seeds
  of N p0 Markov chains of 1 / p0 states each (the seed the first), which
  sample N(0, I) restricted to F_j. The step is preconditioned Crank-Nicolson
  (pCN): xi' = rho xi + sqrt(1 - rho^2) eta, eta ~ N(0, I), accepted iff
  xi' is in F_j. pCN leaves N(0, I) invariant in any dimension, so the
  acceptance does not fall with the thousands of increments of a path (the
  component-wise modified Metropolis of Au & Beck does not either, the random
  walk does); sigma = sqrt(1 - rho^2) is adapted between steps towards an
  acceptance of 0.44 (Papaioannou, Betz, Zwirglmaier and Straub 2015,
  "MCMC algorithms for subset simulation", Probabilistic Engineering
  Mechanics 41, 89-103: adaptive conditional sampling, here isotropic);
* the last level has at least N p0 failures: P(F) = p0^(m-1) P_m, and any
  h that vanishes outside F (the fraction of time beyond D, the number of
  up-crossings) has E[h] = p0^(m-1) x (the last level's mean of h).

The coefficient of variation is Au & Beck's (their Eq. 19-29): at level j,
delta_j^2 = R_j(0) / (N mean_j^2) (1 + gamma_j), with

    gamma_j = 2 sum_{k=1}^{Ns-1} (1 - k / Ns) R_j(k) / R_j(0),

R_j(k) the covariance of the level's indicator (or of h) k states apart
along the same chain, estimated over all chains; level 0 is independent
(gamma 0); delta^2 = sum_j delta_j^2 for the product (the levels taken as
uncorrelated, Au & Beck's approximation, checked for coverage in
tests/calibration/rare_event_coverage.py). gamma_j < 0 is taken as 0. Where
the levels are correlated (long windows, stiff or bistable springs) this c.o.v.
is too small; :func:`randvib.first_passage` therefore takes its interval from
the spread of independent runs (:func:`randvib.montecarlo.reliability.pooled_runs`).

Memory stays at a few times (N p0) x dimension: a level keeps its chains'
current rows and the N p0 rows with the largest peaks so far (the next seeds),
plus one number per sample.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

__all__ = ["SubsetLevel", "SubsetRun", "chain_mean_variance", "subset_simulation"]

#: Target acceptance of the conditional sampling step (Papaioannou et al. 2015).
TARGET_ACCEPTANCE = 0.44
#: Initial sigma of the pCN step.
INITIAL_SIGMA = 0.6
#: Levels after which a run stops even short of the stroke (p0^20: 1e-20 at p0 = 0.1).
MAX_LEVELS = 20


class SubsetStagnationWarning(RuntimeWarning):
    """Subset simulation could not raise its intermediate level (chains stuck)."""


@dataclass(frozen=True)
class SubsetLevel:
    """One level of a run: its lower bound b_j (as peak / D), conditional probability,
    coefficient of variation, Au & Beck's gamma and its chains' acceptance rate."""

    threshold: float
    probability: float
    cov: float
    gamma: float
    acceptance: float


@dataclass(frozen=True)
class SubsetRun:
    """One subset simulation run.

    ``probability`` P(F) and ``cov`` its coefficient of variation; ``means``
    the estimates of E[h] for each h (``beyond``, ``upcrossings``) and
    ``covs`` theirs; ``evaluations`` the paths simulated; ``n_per_level`` N.
    """

    probability: float
    cov: float
    means: dict
    covs: dict
    evaluations: int
    levels: list = field(default_factory=list)
    n_per_level: int = 0


def chain_mean_variance(values) -> tuple[float, float, float]:
    """(mean, variance of the mean, gamma) of samples arranged as chains, shape (Nc, Ns).

    Au & Beck's estimator of the correlation along the chains:
    Var = R(0) / N (1 + gamma), gamma = 2 sum_k (1 - k/Ns) R(k) / R(0),
    R(k) = sum over chains and l of v_l v_(l+k) / (N - k Nc) - mean^2;
    gamma < 0 is taken as 0 (conservative).
    """
    values = np.asarray(values, dtype=float)
    n_chains, length = values.shape
    n = values.size
    mean = float(values.mean())
    r0 = float(np.mean(values * values)) - mean * mean
    if not r0 > 0:
        return mean, 0.0, 0.0
    gamma = 0.0
    for k in range(1, length):
        rk = float(np.sum(values[:, :-k] * values[:, k:])) / (n - k * n_chains) - mean * mean
        gamma += 2.0 * (1.0 - k / length) * rk / r0
    gamma = max(gamma, 0.0)
    return mean, r0 / n * (1.0 + gamma), gamma


class _Top:
    """The ``size`` samples with the largest peaks seen so far at a level, repeats included
    (a rejected step repeats its chain's state): rows, peak / D and the values of h."""

    def __init__(self, size: int):
        self.size = size
        self.rows = None
        self.y = self.beyond = self.up = np.empty(0)

    def offer(self, rows, y, beyond, up) -> None:
        if self.rows is None:
            self.rows = rows[:0].copy()
        rows = np.concatenate([self.rows, rows])
        values = [np.concatenate(pair) for pair in
                  ((self.y, y), (self.beyond, beyond), (self.up, up))]  # fmt: skip
        if values[0].size > self.size:
            best = np.argpartition(-values[0], self.size - 1)[: self.size]
            rows, values = rows[best], [v[best] for v in values]
        self.rows = rows
        self.y, self.beyond, self.up = values

    def seeds(self, threshold, count, rng):
        """``count`` samples above ``threshold``, drawn without replacement if there are more."""
        above = np.flatnonzero(self.y > threshold)
        if above.size > count:
            above = rng.choice(above, count, replace=False)
        return self.rows[above], self.y[above], self.beyond[above], self.up[above]


def next_threshold(y, count: int) -> float:
    """The level b with at least ``count`` samples above it: midway between the largest
    distinct value with ``count`` samples at or above it and the next one below."""
    values = np.sort(np.ravel(y))[::-1]
    b_hi = values[count - 1]
    below = values[values < b_hi]
    return 0.5 * (b_hi + below[0]) if below.size else -math.inf


def subset_simulation(
    simulator, n_per_level: int, rng, *, p0: float = 0.1, max_levels: int = MAX_LEVELS
) -> SubsetRun:
    """One subset simulation run of ``simulator`` (a :class:`~randvib.montecarlo.path_simulator.PathSimulator`).

    Parameters
    ----------
    simulator : PathSimulator
    n_per_level : int
        N, a multiple of N p0 (samples per level).
    rng : numpy.random.Generator
    p0 : float
        Conditional probability of each intermediate level, 0 < p0 <= 0.5.
    max_levels : int
        Levels after which the run stops short of the stroke (its intermediate
        levels b_j, P(peak > b_j) ~ p0^j, are then the answer: a pilot's
        complementary distribution of the peak).

    Returns
    -------
    SubsetRun
    """
    n_chains = int(round(p0 * n_per_level))
    length = n_per_level // n_chains
    stroke = simulator.stroke
    rows = rng.standard_normal((n_per_level, simulator.dimension))
    out = simulator(rows)
    y = out.peak / stroke
    # level 0: independent samples, one "chain" each
    records = _Records(y[:, None], out.beyond[:, None], out.upcrossings[:, None])
    top = _Top(2 * n_chains)
    top.offer(rows, y, out.beyond, out.upcrossings)
    del rows
    levels, log_p, cov2 = [], 0.0, 0.0
    sigma = INITIAL_SIGMA
    evaluations = n_per_level
    threshold = -math.inf
    for level in range(max_levels - 1):
        if int(np.sum(records.y > 1.0)) >= n_chains:
            break
        new = next_threshold(records.y, n_chains)
        if not new > threshold:
            warnings.warn(
                f"subset simulation stalled at level {level} (peak / D = {threshold:.4g}): the "
                "chains no longer move; the estimate is that of the levels reached",
                SubsetStagnationWarning,
                stacklevel=2,
            )
            break
        threshold = new
        p_level, var, gamma = chain_mean_variance(records.y > threshold)
        cov_level = math.sqrt(var) / p_level
        levels.append(SubsetLevel(threshold, p_level, cov_level, gamma, records.acceptance))
        log_p += math.log(p_level)
        cov2 += cov_level**2
        seeds = top.seeds(threshold, n_chains, rng)
        records, top, sigma = _level(simulator, seeds, length, threshold, sigma, rng)
        evaluations += seeds[0].shape[0] * (length - 1)
    mean_f, var_f, gamma_f = chain_mean_variance(records.y > 1.0)
    cov_f = math.sqrt(var_f) / mean_f if mean_f > 0 else math.inf
    levels.append(SubsetLevel(1.0, mean_f, cov_f, gamma_f, records.acceptance))
    means, covs = {}, {}
    for name, values in (("beyond", records.beyond), ("upcrossings", records.up)):
        mean, var, _ = chain_mean_variance(values)
        means[name] = math.exp(log_p) * mean
        covs[name] = math.sqrt(cov2 + var / mean**2) if mean > 0 else math.inf
    return SubsetRun(
        probability=math.exp(log_p) * mean_f,
        cov=math.sqrt(cov2 + cov_f**2),
        means=means,
        covs=covs,
        evaluations=evaluations,
        levels=levels,
        n_per_level=n_chains * length,
    )


@dataclass
class _Records:
    """Per-sample values of a level, shape (chains, states): peak / D, beyond, up-crossings."""

    y: np.ndarray
    beyond: np.ndarray
    up: np.ndarray
    acceptance: float = math.nan


def _level(simulator, seeds, length, threshold, sigma, rng):
    """The chains of one level from ``seeds`` (rows in F_j = {peak / D > threshold}, with
    their peak / D, beyond and up-crossings).

    Returns the level's records, its top samples (next seeds) and the adapted sigma.
    """
    current, y0, beyond0, up0 = seeds
    current = current.copy()
    n_chains = current.shape[0]
    stroke = simulator.stroke
    y, beyond, up = (np.empty((n_chains, length)) for _ in range(3))
    y[:, 0], beyond[:, 0], up[:, 0] = y0, beyond0, up0
    top = _Top(2 * n_chains)
    top.offer(current, y0, beyond0, up0)
    accepted = 0
    log_scale = math.log(sigma)
    for step in range(1, length):
        s = min(math.exp(log_scale), 1.0)
        proposal = math.sqrt(1.0 - s * s) * current + s * rng.standard_normal(current.shape)
        out = simulator(proposal)
        y_new = out.peak / stroke
        accept = y_new > threshold
        current[accept] = proposal[accept]
        y[:, step] = np.where(accept, y_new, y[:, step - 1])
        beyond[:, step] = np.where(accept, out.beyond, beyond[:, step - 1])
        up[:, step] = np.where(accept, out.upcrossings, up[:, step - 1])
        top.offer(current, y[:, step], beyond[:, step], up[:, step])
        rate = float(np.mean(accept))
        accepted += int(np.sum(accept))
        # Robbins-Monro towards the target acceptance (Papaioannou et al. 2015, Alg. 5)
        log_scale += (rate - TARGET_ACCEPTANCE) / math.sqrt(step)
    acceptance = accepted / (n_chains * max(length - 1, 1))
    return _Records(y, beyond, up, acceptance), top, min(math.exp(log_scale), 1.0)
