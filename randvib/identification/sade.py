"""Self-adaptive differential evolution (SaDE) for batched cost functions.

The paper identifies its models with "SADE" (Sec. 3.1, refs [24, 25]: Worden
& Manson), which is the strategy-adaptation scheme of Qin & Suganthan. This
module implements that scheme (Qin, Huang & Suganthan, "Differential
evolution algorithm with strategy adaptation for global numerical
optimization", IEEE TEC 13(2), 2009), rather than jDE (Brest et al. 2006),
for two reasons: it is what the paper's authors used, and its strategy pool
adapts between exploitative moves (rand-to-best) and explorative ones, which
suits identification landscapes that are narrow valleys along correlated
parameters (k with k3, c with Fc).

Per generation, each target vector i

* draws a strategy k with learned probabilities p_k from the pool
  DE/rand/1/bin, DE/rand-to-best/2/bin, DE/rand/2/bin, DE/current-to-rand/1;
* draws F_i ~ N(0.5, 0.3) (clipped to [0.05, 2]) and CR_i ~ N(CRm_k, 0.1)
  (clipped to [0, 1]);
* replaces its parent when the trial is no worse.

Every ``learning_period`` generations the success rates of the strategies
over the last period set p_k (plus 0.01 so no strategy dies out) and the
median of the successful CR values sets CRm_k.

The search runs in the unit cube: each parameter is mapped linearly, or
logarithmically for those flagged ``log`` (parameters spanning decades such as
tanh's beta, LuGre's sigma0 or the Stribeck velocity). Components leaving the
cube are bounced back between the parent and the bound. The whole trial
population is evaluated in one call of the (batched) cost function.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from randvib._progress import progress_bar
from randvib._resources import check_memory
from randvib._validation import check_int

STRATEGIES = ("rand/1/bin", "rand-to-best/2/bin", "rand/2/bin", "current-to-rand/1")


@dataclass
class SADEResult:
    """Outcome of :func:`sade`.

    Attributes
    ----------
    x : ndarray
        Best parameter vector found (original units).
    fun : float
        Its cost.
    nfev : int
        Number of cost evaluations (candidate simulations) spent.
    nit : int
        Generations run.
    message : str
        Why the search stopped.
    history : dict
        Per generation: ``best`` cost, cumulative ``nfev``, population cost
        ``spread`` and strategy ``probabilities``.
    population, costs : ndarray
        Final population (original units) and its costs.
    elapsed : float
        Wall time (s).
    """

    x: np.ndarray
    fun: float
    nfev: int
    nit: int
    message: str
    history: dict = field(default_factory=dict)
    population: np.ndarray | None = None
    costs: np.ndarray | None = None
    elapsed: float = 0.0
    polished: bool = False


class _Space:
    """Map between the unit cube and the parameter box (linear or log)."""

    def __init__(self, bounds, log, names):
        bounds = np.asarray(bounds, dtype=float)
        if bounds.ndim != 2 or bounds.shape[1] != 2 or bounds.shape[0] == 0:
            raise ValueError(
                f"`bounds` must be a sequence of (lower, upper) pairs, got {bounds.tolist()!r}"
            )
        d = bounds.shape[0]
        self.names = list(names) if names is not None else [f"x[{i}]" for i in range(d)]
        if len(self.names) != d:
            raise ValueError(f"`names` has {len(self.names)} entries for {d} bounds")
        log = np.zeros(d, bool) if log is None else np.asarray(log, bool)
        if log.shape != (d,):
            raise ValueError(f"`log` must have one flag per parameter ({d}), got {log.shape}")
        for name, (lo, hi), lg in zip(self.names, bounds, log, strict=True):
            if not (np.isfinite(lo) and np.isfinite(hi)):
                raise ValueError(f"bounds for `{name}` must be finite, got ({lo}, {hi})")
            if lo > hi:
                raise ValueError(f"bounds for `{name}`: lower {float(lo)!r} > upper {float(hi)!r}")
            if lg and lo <= 0:
                raise ValueError(
                    f"bounds for `{name}` are log-scaled and must be > 0, got lower {float(lo)!r}"
                )
        self.lo = np.where(log, np.log(np.where(log, bounds[:, 0], 1.0)), bounds[:, 0])
        self.hi = np.where(log, np.log(np.where(log, bounds[:, 1], 1.0)), bounds[:, 1])
        self.log = log
        self.bounds = bounds

    def to_x(self, unit):
        y = self.lo + np.asarray(unit) * (self.hi - self.lo)
        x = np.array(y, dtype=float)
        x[..., self.log] = np.exp(y[..., self.log])
        # exact bounds despite exp/log round-off
        return np.clip(x, self.bounds[:, 0], self.bounds[:, 1])

    def to_unit(self, x):
        x = np.asarray(x, dtype=float)
        y = np.where(self.log, np.log(np.where(self.log, np.maximum(x, 1e-300), 1.0)), x)
        width = np.where(self.hi > self.lo, self.hi - self.lo, 1.0)
        return np.clip((y - self.lo) / width, 0.0, 1.0)


def _distinct_indices(rng, n, count):
    # For each row i, `count` distinct indices different from i.
    keys = rng.random((n, n))
    keys[np.arange(n), np.arange(n)] = np.inf
    return np.argsort(keys, axis=1)[:, :count]


def _latin_hypercube(rng, popsize, d):
    """A start in the unit cube that covers every parameter's range evenly."""
    pop = rng.permuted(np.tile(np.arange(popsize), (d, 1)), axis=1).T + rng.random((popsize, d))
    return pop / popsize


# The strategy pool, one function each, in the order of STRATEGIES. Each gets
# the rows' parents ``xi``, the best vector ``xb``, five distinct partners
# ``xs`` (x1..x5), the scale factors ``fr`` (column) and the generator.
def _rand_1(xi, xb, xs, fr, rng):
    return xs[0] + fr * (xs[1] - xs[2])


def _rand_to_best_2(xi, xb, xs, fr, rng):
    return xi + fr * (xb - xi) + fr * (xs[0] - xs[1]) + fr * (xs[2] - xs[3])


def _rand_2(xi, xb, xs, fr, rng):
    return xs[0] + fr * (xs[1] - xs[2]) + fr * (xs[3] - xs[4])


def _current_to_rand_1(xi, xb, xs, fr, rng):
    kk = rng.random((xi.shape[0], 1))
    return xi + kk * (xs[0] - xi) + fr * (xs[1] - xs[2])


_MUTATIONS = (_rand_1, _rand_to_best_2, _rand_2, _current_to_rand_1)
_NO_CROSSOVER = 3  # current-to-rand/1 is rotation-invariant: no binomial crossover


class _StrategyAdaptation:
    """Qin-Suganthan learning of the strategy probabilities p_k and CR medians CRm_k."""

    def __init__(self, learning_period: int):
        n = len(STRATEGIES)
        self.period = learning_period
        self.probs = np.full(n, 1.0 / n)
        self.crm = np.full(n, 0.5)
        self.success = np.zeros((learning_period, n))
        self.failure = np.zeros((learning_period, n))
        self.cr_memory = [[] for _ in range(n)]

    def draw(self, rng, popsize):
        """Strategy, F_i ~ N(0.5, 0.3) and CR_i ~ N(CRm_k, 0.1) for each target vector."""
        strategy = rng.choice(len(STRATEGIES), size=popsize, p=self.probs)
        f = np.clip(rng.normal(0.5, 0.3, popsize), 0.05, 2.0)[:, None]
        cr = np.clip(rng.normal(self.crm[strategy], 0.1), 0.0, 1.0)
        return strategy, f, cr

    def learn(self, generation, strategy, cr, better):
        """Record this generation's successes; after a full period, update p_k and CRm_k."""
        n = len(STRATEGIES)
        slot = generation % self.period
        self.success[slot] = np.bincount(strategy[better], minlength=n)
        self.failure[slot] = np.bincount(strategy[~better], minlength=n)
        for k in range(n):
            self.cr_memory[k].append(cr[better & (strategy == k)])
            if len(self.cr_memory[k]) > self.period:
                self.cr_memory[k].pop(0)
        if generation + 1 < self.period:
            return
        ns = self.success.sum(axis=0)
        nf = self.failure.sum(axis=0)
        rate = ns / np.maximum(ns + nf, 1) + 0.01  # + 0.01: no strategy dies out
        self.probs = rate / rate.sum()
        for k in range(n):
            values = np.concatenate(self.cr_memory[k]) if self.cr_memory[k] else np.empty(0)
            if values.size:
                self.crm[k] = float(np.median(values))


def _trial_vectors(rng, pop, best, strategy, f, cr):
    """Mutation by each row's strategy, binomial crossover, bounce-back into the cube."""
    popsize, d = pop.shape
    r = _distinct_indices(rng, popsize, 5)
    partners = [pop[r[:, j]] for j in range(5)]
    mutant = np.empty_like(pop)
    for k, mutate in enumerate(_MUTATIONS):
        rows = strategy == k
        if rows.any():
            xs = [x[rows] for x in partners]
            mutant[rows] = mutate(pop[rows], pop[best], xs, f[rows], rng)
    cross = rng.random((popsize, d)) < cr[:, None]
    cross[np.arange(popsize), rng.integers(0, d, popsize)] = True
    cross[strategy == _NO_CROSSOVER] = True
    trial = np.where(cross, mutant, pop)
    # bounce back between parent and the violated bound
    u = rng.random(trial.shape)
    trial = np.where(trial < 0.0, pop * u, trial)
    return np.where(trial > 1.0, pop + (1.0 - pop) * u, trial)


def sade(
    func,
    bounds,
    *,
    log=None,
    names=None,
    popsize: int = 50,
    maxiter: int = 200,
    seed=None,
    tol: float = 1e-6,
    atol: float = 0.0,
    patience: int | None = None,
    learning_period: int = 20,
    init=None,
    polish: bool = False,
    polish_maxfev: int | None = None,
    callback=None,
    progress: bool = False,
) -> SADEResult:
    """Minimise a batched cost function with self-adaptive DE (Qin-Suganthan SaDE).

    Parameters
    ----------
    func : callable
        ``func(X) -> costs`` with ``X`` of shape (n, d) in original units and
        ``costs`` of shape (n,). Non-finite costs count as worst.
    bounds : sequence of (float, float)
        Lower and upper bound per parameter (lower <= upper; equal bounds fix it).
    log : sequence of bool, optional
        Search these parameters on a log scale (bounds must then be > 0).
    names : sequence of str, optional
        Parameter names for messages and progress output.
    popsize : int
        Population size NP (>= 6, the strategies draw five partners).
    maxiter : int
        Maximum number of generations.
    seed : int, numpy.random.Generator or None
        Random source.
    tol, atol : float
        Convergence: stop when the standard deviation of the population's
        costs is <= ``atol + tol * |mean cost|``.
    patience : int, optional
        Also stop after this many generations without improvement of the best.
    learning_period : int
        Generations over which strategy success rates and CR medians are learnt
        (Qin et al. use 50 for long runs; 20 adapts faster in short ones).
    init : array_like, optional
        Up to ``popsize`` starting vectors (original units) placed in the
        initial population; the rest are uniform in the (log-)box.
    polish : bool
        Refine the best vector with bounded Nelder-Mead (scipy) at the end.
    polish_maxfev : int, optional
        Evaluation budget of the polish (default 100 per parameter).
    callback : callable, optional
        ``callback(generation, best_x, best_cost)``; returning True stops.
    progress : bool
        Show a progress bar (terminal or notebook) with the best cost.

    Returns
    -------
    SADEResult
    """
    space = _Space(bounds, log, names)
    popsize = check_int("popsize", popsize, minimum=6)
    maxiter = check_int("maxiter", maxiter, minimum=0)
    learning_period = check_int("learning_period", learning_period, minimum=1)
    if patience is not None:
        patience = check_int("patience", patience, minimum=1)
    rng = np.random.default_rng(seed)
    d = space.lo.size
    check_population_memory(popsize, d)
    start = time.perf_counter()
    evaluate = _batched_cost(func, space)

    pop = _initial_population(rng, popsize, space, init)
    costs = evaluate(pop)
    nfev = popsize

    adaptation = _StrategyAdaptation(learning_period)
    history = {"best": [], "nfev": [], "spread": [], "probabilities": []}
    best = int(np.argmin(costs))
    stall = 0
    message = f"maximum number of generations ({maxiter}) reached"
    bar = progress_bar(maxiter, desc="SaDE", unit="gen", transient=True) if progress else None
    nit = 0
    try:
        for gen in range(maxiter):
            nit = gen + 1
            strategy, f, cr = adaptation.draw(rng, popsize)
            trial = _trial_vectors(rng, pop, best, strategy, f, cr)
            trial_costs = evaluate(trial)
            nfev += popsize
            better = trial_costs <= costs  # no worse: replace the parent
            adaptation.learn(gen, strategy, cr, better)
            pop = np.where(better[:, None], trial, pop)
            costs = np.where(better, trial_costs, costs)
            best = int(np.argmin(costs))
            prev = history["best"][-1] if history["best"] else np.inf
            stall = 0 if costs[best] < prev * (1 - 1e-12) else stall + 1
            spread = _record(history, costs, best, nfev, adaptation.probs)
            if bar is not None:
                bar.update(1)
                bar.set_postfix(best=f"{costs[best]:.4g}")
            if callback is not None and callback(nit, space.to_x(pop[best]), float(costs[best])):
                message = "stopped by callback"
                break
            reason = _converged(costs, spread, tol, atol, stall, patience)
            if reason:
                message = reason
                break
    finally:
        if bar is not None:
            bar.close()

    x_best, f_best, polished = space.to_x(pop[best]), float(costs[best]), False
    if polish and d > 0:
        unit, value, spent = _polish(evaluate, pop, costs, best, polish_maxfev or 100 * d)
        nfev += spent
        if value < f_best:
            x_best, f_best, polished = space.to_x(unit), value, True
    return SADEResult(
        x=x_best,
        fun=f_best,
        nfev=nfev,
        nit=nit,
        message=message,
        history=history,
        population=space.to_x(pop),
        costs=costs,
        elapsed=time.perf_counter() - start,
        polished=polished,
    )


def check_population_memory(popsize: int, d: int) -> None:
    """Refuse a population that cannot fit in memory, with the estimate."""
    # a dozen (popsize, d) float arrays and a few per-member vectors live at once
    check_memory(
        f"a SaDE population of {popsize} x {d}",
        8.0 * popsize * (12 * d + 30),
        "use a smaller `popsize` (`--popsize`)",
    )


def _initial_population(rng, popsize, space, init):
    """Latin-hypercube start in the unit cube, with the user's ``init`` vectors first."""
    d = space.lo.size
    pop = _latin_hypercube(rng, popsize, d)
    if init is not None:
        init = np.atleast_2d(np.asarray(init, dtype=float))
        if init.shape[1] != d or init.shape[0] > popsize:
            raise ValueError(f"`init` must have shape (<= {popsize}, {d}), got {init.shape}")
        pop[: init.shape[0]] = space.to_unit(init)
    return pop


def _record(history, costs, best, nfev, probs):
    """Append one generation to ``history``; returns the population's cost spread."""
    spread = float(np.std(costs)) if np.isfinite(costs).all() else np.inf
    for key, value in zip(history, (float(costs[best]), nfev, spread, probs.tolist()), strict=True):
        history[key].append(value)
    return spread


def _converged(costs, spread, tol, atol, stall, patience):
    """Why the search should stop now, or an empty string."""
    if np.isfinite(spread) and spread <= atol + tol * abs(float(np.mean(costs))):
        return f"converged: cost spread {spread:.3g} <= atol + tol * |mean cost|"
    if patience is not None and stall >= patience:
        return f"no improvement of the best cost for {patience} generations"
    return ""


def _batched_cost(func, space):
    """The user's cost on unit-cube candidates; non-finite costs become +inf (worst)."""

    def evaluate(unit):
        costs = np.asarray(func(space.to_x(unit)), dtype=float).reshape(-1)
        if costs.shape[0] != unit.shape[0]:
            raise ValueError(
                f"the cost function returned {costs.shape[0]} values for {unit.shape[0]} candidates"
            )
        return np.where(np.isfinite(costs), costs, np.inf)

    return evaluate


def _polish(evaluate, pop, costs, best, maxfev):
    """Bounded Nelder-Mead from the best vector; returns (unit vector, cost, evaluations)."""
    from scipy.optimize import minimize

    d = pop.shape[1]
    spent = 0

    def single(unit):
        nonlocal spent
        spent += 1
        return float(evaluate(np.clip(unit, 0.0, 1.0)[None, :])[0])

    res = minimize(
        single,
        pop[best],
        method="Nelder-Mead",
        bounds=[(0.0, 1.0)] * d,
        options={
            "maxfev": maxfev,
            "xatol": 1e-10,
            "fatol": 1e-12 * max(float(costs[best]), 1e-300),
            "initial_simplex": _small_simplex(pop[best], pop, costs),
        },
    )
    return np.clip(res.x, 0.0, 1.0), float(res.fun), spent


def _small_simplex(center, pop, costs):
    # A simplex scaled to the final population's spread, so the polish starts
    # at the resolution DE reached instead of re-exploring the whole cube.
    d = center.size
    good = pop[np.argsort(costs)[: max(d + 1, 5)]]
    scale = np.maximum(np.std(good, axis=0), 1e-6)
    simplex = np.tile(center, (d + 1, 1))
    for i in range(d):
        step = scale[i] if center[i] + scale[i] <= 1.0 else -scale[i]
        simplex[i + 1, i] += step
    return np.clip(simplex, 0.0, 1.0)


def named_callback(callback, free):
    """SaDE's ``callback(gen, x, f)`` as the user's ``callback(gen, {name: value}, f)``."""
    if callback is None:
        return None

    def named(gen, x, f):
        return callback(gen, dict(zip(free, map(float, x), strict=True)), f)

    return named
