"""``randvib.first_passage``: end-stop strikes at probabilities crude Monte Carlo cannot reach.

For a device in its stationary state, with stroke D and a service window T:

* ``probability_first_passage`` - P(|z| reaches D within T), the start included;
* ``upcrossing_rate`` - the mean number per second of times |z| rises
  through D (both ends of the stroke);
* ``stationary_exceedance`` - P(|z| > D) at a fixed time (the fraction of
  time beyond the stroke);

each with its 95 % half-width, from one of three estimators of the same
path simulator (:mod:`randvib.montecarlo.path_simulator`):

* ``subset`` - subset simulation (:mod:`randvib.montecarlo.subset_simulation`),
  for every device and input; a pilot run of ``samples_per_level`` samples
  per level gives a coefficient of variation (Au & Beck's, with the chains'
  correlation), from which five independent runs that together reach
  ``target_cov`` are planned; their spread gives the interval (:func:`_subset`);
* ``importance`` - importance sampling by a change of drift towards the
  design points (:mod:`randvib.montecarlo.importance_sampling`): exact design
  points for a linear device, its linearisation's scaled to the stroke
  otherwise; refused where the weights degenerate;
* ``crude`` - independent paths, the reference: (1 - p) / (p cov^2) of
  them for a coefficient of variation cov.

The two rare quantities besides the first passage vanish on paths that do
not reach D (a path beyond D, or rising through it, has reached it), so each
estimator gives them from the same paths: E[h] = E[h 1_F].

``path_steps`` counts what was spent (paths x steps, burn-in included), and
``crude_path_steps`` what crude Monte Carlo would need for the same
coefficient of variation at the estimated probability.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from randvib._progress import progress_bar, progress_wanted
from randvib._validation import check_choice, check_int, check_positive
from randvib.models.assembly import Assembly
from randvib.montecarlo.assembly_paths import AssemblyPaths, default_assembly_step
from randvib.montecarlo.importance_sampling import (
    MAX_WEIGHT_SHARE,
    MIN_EFFECTIVE_SAMPLES,
    ImportanceDesign,
    importance_batch,
    weight_diagnostics,
)
from randvib.montecarlo.path_simulator import HarvesterPaths, default_step
from randvib.montecarlo.subset_simulation import subset_simulation
from randvib.statistics import Statistic

__all__ = ["METHODS", "ReliabilityResult", "estimate_first_passage", "first_passage"]

#: The estimators by name (the CLI's ``--method``).
METHODS = ("subset", "importance", "crude")
#: Path-steps a run may spend unless told otherwise (about four minutes on two cores).
DEFAULT_MAX_PATH_STEPS = 2e9
#: Normal quantile of the two-sided 95 % interval.
Z95 = 1.959963984540054
#: Subset simulation plans (this x pilot c.o.v. / target)^2 runs after its pilot.
PLANNING_MARGIN = 1.2
#: Independent runs after the pilot, per stage: their spread is the c.o.v. (:func:`_subset`),
#: with RUNS - 1 degrees of freedom (t quantile 2.78); more would make each run smaller,
#: and a run's bias falls like 1 / its size.
RUNS = 5
#: Memory for a subset simulation run's chains (current rows, proposals and the top
#: rows, about 4 x N p0 rows of the simulator's dimension).
MAX_CHAIN_BYTES = 2**29
#: Rows per importance-sampling or crude batch.
BATCH = 2000


class BudgetWarning(RuntimeWarning):
    """The path-step budget ran out before the target coefficient of variation."""


@dataclass(frozen=True)
class ReliabilityResult:
    """What :func:`first_passage` found (SI units; each estimate with its 95 % half-width).

    Attributes
    ----------
    probability_first_passage : Statistic
        P(|z| reaches the stroke within the window, from the stationary state).
    upcrossing_rate : Statistic
        Mean up-crossings of |z| through the stroke per second, both ends (1/s).
    stationary_exceedance : Statistic
        P(|z| > stroke).
    path_steps : int
        Integration steps spent (paths x steps per path, burn-in included).
    method : str
        ``subset``, ``importance`` or ``crude``.
    stroke, duration, dt, burn_in : float
        D (m), the window T (s), the step (s), the unmonitored burn-in (s).
    start : str
        How the stationary start was drawn.
    target_cov : float
        The coefficient of variation asked for.
    details : dict
        The estimator's own diagnostics (subset: runs, levels; importance:
        effective sample size, largest weight share, amplitude; crude: paths
        and failures).
    """

    probability_first_passage: Statistic
    upcrossing_rate: Statistic
    stationary_exceedance: Statistic
    path_steps: int
    method: str
    stroke: float
    duration: float
    dt: float
    burn_in: float
    start: str
    target_cov: float
    steps_per_path: int
    details: dict = field(default_factory=dict)

    @property
    def cov(self) -> float:
        """Coefficient of variation of the first-passage probability."""
        p = self.probability_first_passage
        return p.std_error / p.mean if p.mean > 0 else math.inf

    @property
    def crude_path_steps(self) -> float:
        """Path-steps crude Monte Carlo needs for this coefficient of variation at this p:
        (1 - p) / (p cov^2) paths of the same length."""
        p, cov = self.probability_first_passage.mean, self.cov
        if not (p > 0 and math.isfinite(cov) and cov > 0):
            return math.nan
        return (1.0 - p) / (p * cov * cov) * self.steps_per_path

    def to_dict(self) -> dict:
        """The JSON keys: the three estimates as {mean, ci95}, path_steps, method, settings."""
        return {
            "probability_first_passage": self.probability_first_passage.to_dict(),
            "upcrossing_rate": self.upcrossing_rate.to_dict(),
            "stationary_exceedance": self.stationary_exceedance.to_dict(),
            "path_steps": int(self.path_steps),
            "method": self.method,
            "cov": self.cov,
            "crude_path_steps": self.crude_path_steps,
            "stroke": self.stroke,
            "duration": self.duration,
            "dt": self.dt,
            "burn_in": self.burn_in,
            "start": self.start,
            "target_cov": self.target_cov,
            "details": self.details,
        }


def first_passage(
    harvester,
    excitation,
    *,
    duration: float,
    stroke: float | None = None,
    stroke_on: str | None = None,
    method: str = "subset",
    target_cov: float = 0.1,
    dt: float | None = None,
    scheme: str = "heun",
    seed: int = 0,
    burn_in: float | None = None,
    samples_per_level: int = 1000,
    p0: float = 0.1,
    max_path_steps: float = DEFAULT_MAX_PATH_STEPS,
    progress: bool | None = None,
) -> ReliabilityResult:
    """The probability that the stroke is reached within ``duration``, from the stationary state.

    Parameters
    ----------
    harvester : Harvester or Assembly
        Any device :func:`randvib.simulate` takes, the free mass excepted; an
        assembly (several masses) under white noise or a rational spectrum,
        monitored on one coordinate (``stroke_on``;
        :class:`~randvib.montecarlo.assembly_paths.AssemblyPaths`).
    excitation : float or Excitation
        White-noise level S ((m/s^2)^2/Hz) or an excitation (a measured
        record through its Welch spectrum).
    duration : float
        The window T (s), > 0.
    stroke : float, optional
        D (m), > 0; default the harvester's (an assembly: its coordinate's).
    stroke_on : str, optional
        An assembly's monitored coordinate, ``element.N`` or ``transducer.N``
        (default: its one part with a stroke); refused for a single mass.
    method : {"subset", "importance", "crude"}
        The estimator (module docstring).
    target_cov : float
        Coefficient of variation of the first-passage probability to reach, in (0, 1).
    dt : float, optional
        Step (s); default :func:`~randvib.montecarlo.path_simulator.default_step`
        (a stationary-variance bias of at most 1e-4 on the linearised device,
        with its spring's stiffness at the stroke).
    scheme : str
        ``heun`` or ``euler-maruyama``.
    seed : int
        Seed of the standard normals (numpy's PCG64).
    burn_in : float, optional
        Unmonitored time (s) before the window; default 0 where the start is
        exact, ten energy decay times m / c_eq where it is linearised.
    samples_per_level : int
        Subset simulation's samples per level (and per run), >= 100.
    p0 : float
        Subset simulation's level probability, in [0.05, 0.5].
    max_path_steps : float
        Budget; the run stops there with a :class:`BudgetWarning` if the
        target is not reached.
    progress : bool, optional
        Progress bar (default: on a terminal or in a notebook).

    Returns
    -------
    ReliabilityResult

    Examples
    --------
    >>> import randvib as rv
    >>> device = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4)
    >>> r = rv.first_passage(device, 1.0, stroke=0.015, duration=0.5, dt=1e-3,
    ...                      method="importance", target_cov=0.2, progress=False)
    >>> print(f"{r.probability_first_passage.mean:.1e}")
    3.0e-04
    """
    if isinstance(harvester, Assembly):
        simulator = _assembly_paths(harvester, excitation, stroke, stroke_on, method, duration,
                                    dt, scheme, burn_in)  # fmt: skip
        return estimate_first_passage(
            simulator, method=method, target_cov=target_cov, seed=seed,
            samples_per_level=samples_per_level, p0=p0, max_path_steps=max_path_steps,
            progress=progress,
        )  # fmt: skip
    if stroke_on is not None:
        raise ValueError(
            f"`stroke_on` = {stroke_on!r} names a coordinate of an assembly; a single mass's "
            "stroke is on z: leave it out"
        )
    stroke = harvester.stroke if stroke is None else stroke
    if stroke is None:
        raise ValueError("`stroke` is needed: the first passage is to |z| = stroke")
    if dt is None:
        dt = default_step(harvester, excitation, scheme, stroke)
    simulator = HarvesterPaths(
        harvester, excitation, stroke=stroke, duration=duration, dt=dt, scheme=scheme,
        burn_in=burn_in,
    )  # fmt: skip
    return estimate_first_passage(
        simulator, method=method, target_cov=target_cov, seed=seed,
        samples_per_level=samples_per_level, p0=p0, max_path_steps=max_path_steps,
        progress=progress,
    )  # fmt: skip


def _assembly_paths(assembly, excitation, stroke, stroke_on, method, duration, dt, scheme,
                    burn_in) -> AssemblyPaths:  # fmt: skip
    """The path simulator of an assembly; importance sampling refused for a nonlinear one."""
    check_choice("method", method, METHODS)
    if method == "importance" and not assembly.is_linear:
        raise ValueError(
            "method='importance' on an assembly needs a linear one (its design points are exact "
            "only then; a nonlinear assembly's weights are not checked to stay reliable): use "
            "method='subset'"
        )
    if dt is None:
        dt = default_assembly_step(assembly, excitation, scheme)
    return AssemblyPaths(assembly, excitation, stroke=stroke, stroke_on=stroke_on,
                         duration=duration, dt=dt, scheme=scheme, burn_in=burn_in)  # fmt: skip


def estimate_first_passage(
    simulator,
    *,
    method: str = "subset",
    target_cov: float = 0.1,
    seed: int = 0,
    samples_per_level: int = 1000,
    p0: float = 0.1,
    max_path_steps: float = DEFAULT_MAX_PATH_STEPS,
    progress: bool | None = None,
) -> ReliabilityResult:
    """:func:`first_passage` of any path simulator (:class:`~randvib.montecarlo.path_simulator.PathSimulator`).

    The options are :func:`first_passage`'s; a device with several masses
    provides its own simulator and is estimated here.
    """
    check_choice("method", method, METHODS)
    target_cov = float(target_cov)
    if not 0.0 < target_cov < 1.0:
        raise ValueError(f"`target_cov` must be in (0, 1), got {target_cov!r}")
    samples_per_level = check_int("samples_per_level", samples_per_level, 100)
    p0 = float(p0)
    if not 0.05 <= p0 <= 0.5:
        raise ValueError(f"`p0` must be in [0.05, 0.5], got {p0!r}")
    budget = float(check_positive("max_path_steps", max_path_steps))
    if progress is None:
        progress = progress_wanted()
    rng = np.random.default_rng(seed)
    run = {"subset": _subset, "importance": _importance, "crude": _crude}[method]
    bar = progress_bar(1, desc=f"first passage ({method})", unit="path", transient=True) if (
        progress
    ) else None  # fmt: skip
    try:
        estimates, paths, details = run(simulator, rng, target_cov, budget, bar,
                                        samples_per_level=samples_per_level, p0=p0)  # fmt: skip
    finally:
        if bar is not None:
            bar.close()
    if hasattr(simulator, "coordinate"):  # an assembly's monitored coordinate
        details = {**details, "stroke_on": simulator.coordinate}
    per_second = 1.0 / simulator.duration
    return ReliabilityResult(
        probability_first_passage=estimates["failed"],
        upcrossing_rate=estimates["upcrossings"] * per_second,
        stationary_exceedance=estimates["beyond"],
        path_steps=int(paths * simulator.steps_per_path),
        method=method,
        stroke=simulator.stroke,
        duration=simulator.duration,
        dt=simulator.dt,
        burn_in=simulator.burn_in,
        start=simulator.start,
        target_cov=target_cov,
        steps_per_path=simulator.steps_per_path,
        details=details,
    )


def _statistic(mean: float, cov: float, n: int, quantile: float = Z95) -> Statistic:
    """A Statistic from a positive estimate and its coefficient of variation.

    A rare-event estimate is skewed (a product of level probabilities, a mean
    of weights): its 95 % interval is taken as the lognormal's with that
    coefficient of variation, [p / f, p f], f = exp(1.96 sqrt(log(1 + cov^2))),
    and the half-width reported is its upper one, p (f - 1), so that
    mean +- ci95 contains it (p (2 - f) <= p / f). For a small cov it is the
    normal 1.96 cov p. ``quantile`` replaces 1.96 where the c.o.v. is itself estimated
    from a few independent runs (Student t).
    """
    if not math.isfinite(cov):
        return Statistic(float(mean), math.inf, math.inf, int(n))
    factor = math.exp(quantile * math.sqrt(math.log1p(cov * cov)))
    return Statistic(float(mean), abs(mean) * (factor - 1.0), abs(mean) * cov, int(n))


def _advance(bar, paths: int, done: int, needed: float) -> None:
    if bar is not None:
        bar.total = max(int(needed), done)
        bar.update(paths)


def _out_of_budget(method: str, cov: float, target: float, spent: float) -> None:
    warnings.warn(
        f"method={method!r} spent its budget of {spent:.3g} path-steps at a coefficient of "
        f"variation of {cov:.3g}, short of the target {target:g}: raise `max_path_steps` "
        "(--max-path-steps)",
        BudgetWarning,
        stacklevel=4,
    )


def _subset(simulator, rng, target, budget, bar, *, samples_per_level, p0):
    """A pilot run plans :data:`RUNS` independent runs; the spread of their estimates is the c.o.v.

    The pilot (``samples_per_level`` N) gives Au & Beck's c.o.v. delta; the
    estimate needs about U = 1.2 (delta / target)^2 times N samples per level,
    run as :data:`RUNS` independent runs of U / RUNS times N each
    (:func:`_independent_runs`). The estimate is their mean; its c.o.v. is
    that of the mean from the runs' spread, with RUNS - 1 degrees of freedom
    (a Student t quantile in the interval), or Au & Beck's pooled one if that
    is larger. Au & Beck's alone takes the levels as uncorrelated and sees the
    chains' correlation only within their 1 / p0 states: in long windows, where
    a level's seeds descend from few paths of the level below, it was 2x too
    small for a stiff Duffing spring and 7x for a bistable device
    (tests/calibration/rare_event_long_window.py, rare_event_cov_diagnosis.py).
    Where the runs' spread still exceeds the target, a second stage of RUNS
    larger runs sized from it follows (Stein's two-stage rule), within the
    budget. The runs are few and large rather than many and small: a run's
    bias falls like 1 / N (Au & Beck 2001), and it is large where the levels
    are correlated (runs of 500 samples per level of the stiff Duffing device
    at T = 0.5 s came out 25-35 % high). The pilot is not pooled: its c.o.v.
    chose the size, and a rule that stops when the estimate's own c.o.v. is
    small stops early on high estimates. A pilot that meets the target alone
    is the answer, with Au & Beck's c.o.v.
    """
    n_chains = max(1, int(round(p0 * samples_per_level)))
    n = n_chains * (samples_per_level // n_chains)
    pilot = subset_simulation(simulator, n, rng, p0=p0)
    paths = pilot.evaluations
    runs = [pilot]
    if not math.isfinite(pilot.cov):  # no failure even at p0^MAX_LEVELS: nothing to plan
        warnings.warn(
            f"subset simulation found no path beyond the stroke after {len(pilot.levels)} "
            f"levels: P(first passage) is below about {p0 ** len(pilot.levels):.0e} here",
            BudgetWarning,
            stacklevel=4,
        )
    elif pilot.cov > target:
        runs, paths = _independent_runs(simulator, rng, pilot, target, budget, bar, p0=p0)
    names = ("failed", "beyond", "upcrossings")
    sizes = np.array([r.n_per_level for r in runs], dtype=float)
    estimates, spread = {}, {}
    for k in names:
        values = np.array([_run_mean(r, k) for r in runs])
        mean, between = pooled_runs(values, sizes)
        weights = sizes / sizes.sum()
        # a run without failures (estimate 0) has no c.o.v. of its own: the spread counts it
        covs = np.array(
            [_run_cov(r, k) if v > 0 else 0.0 for r, v in zip(runs, values, strict=True)]
        )
        variance = float(np.sum((weights * covs * values) ** 2))
        au_beck = math.sqrt(variance) / mean if mean > 0 else math.inf
        spread[k] = between
        cov, quantile = au_beck, Z95
        if len(runs) > 1 and between >= au_beck:
            cov, quantile = between, float(stats.t.ppf(0.975, len(runs) - 1))
        estimates[k] = _statistic(mean, cov, paths, quantile)
    details = {
        "runs": len(runs),
        "pilot_cov": pilot.cov,
        "between_runs_cov": spread["failed"],
        "samples_per_level": [r.n_per_level for r in runs],
        "p0": p0,
        "levels": [len(r.levels) for r in runs],
        "level_thresholds": [float(lv.threshold) * simulator.stroke for lv in runs[0].levels],
        "gamma": [float(lv.gamma) for lv in runs[0].levels],
        "acceptance": [float(lv.acceptance) for lv in runs[0].levels[1:]],
    }
    return estimates, paths, details


def pooled_runs(values, sizes) -> tuple[float, float]:
    """(mean, its c.o.v.) of independent runs' estimates ``values`` of ``sizes`` samples per level.

    A run's variance is taken as sigma^2 / size: the mean is weighted by the
    sizes, sigma^2 = sum size_r (v_r - mean)^2 / (R - 1) and the mean's
    variance sigma^2 / sum size_r (R - 1 degrees of freedom). The c.o.v. is
    nan for one run and inf for a zero mean.
    """
    values = np.asarray(values, dtype=float)
    sizes = np.asarray(sizes, dtype=float)
    mean = float(sizes @ values / sizes.sum())
    if values.size < 2:
        return mean, math.nan
    if not mean > 0:
        return mean, math.inf
    sigma2 = float(sizes @ (values - mean) ** 2) / (values.size - 1)
    return mean, math.sqrt(sigma2 / sizes.sum()) / mean


def _independent_runs(simulator, rng, pilot, target, budget, bar, *, p0):
    """(runs, paths spent, the pilot's included): :data:`RUNS` independent runs sized from the
    pilot's c.o.v., and RUNS larger ones sized from their spread where it exceeds the target."""
    n = pilot.n_per_level
    paths = pilot.evaluations
    memory = max(1, MAX_CHAIN_BYTES // (32 * max(1, round(p0 * n)) * simulator.dimension))
    units = PLANNING_MARGIN * (pilot.cov / target) ** 2  # samples per level in all, in N
    runs: list = []
    for _ in range(2):
        size = max(1, min(math.ceil(units / RUNS), memory))
        affordable = int((budget / simulator.steps_per_path - paths) // pilot.evaluations)
        if RUNS * size > affordable:
            size = affordable // RUNS
            _out_of_budget("subset", target * math.sqrt(units / max(RUNS * size, 1)), target,
                           budget)  # fmt: skip
            if size < 1:
                break
        for _ in range(RUNS):
            runs.append(subset_simulation(simulator, n * size, rng, p0=p0))
            paths += runs[-1].evaluations
            _advance(bar, runs[-1].evaluations, paths, paths + pilot.evaluations * size * RUNS)
        sizes = [r.n_per_level / n for r in runs]
        _, between = pooled_runs([r.probability for r in runs], sizes)
        if not between > target:
            break
        units = PLANNING_MARGIN * sum(sizes) * (between / target) ** 2 - sum(sizes)
    return (runs, paths) if len(runs) > 1 else ([pilot], paths)


def _run_mean(run, name):
    return run.probability if name == "failed" else run.means[name]


def _run_cov(run, name):
    return run.cov if name == "failed" else run.covs[name]


def _importance(simulator, rng, target, budget, bar, **_):
    """Batches of weighted samples until the c.o.v. reaches ``target``; refused when the
    failing samples' weights have degenerated (:data:`MIN_EFFECTIVE_SAMPLES`,
    :data:`MAX_WEIGHT_SHARE`)."""
    design = ImportanceDesign.of(simulator)
    parts: dict = {"failed": [], "beyond": [], "upcrossings": []}
    while True:
        batch = importance_batch(simulator, design, BATCH, rng)
        for k, v in batch.items():
            parts[k].append(v)
        values = {k: np.concatenate(v) for k, v in parts.items()}
        n = values["failed"].size
        mean = values["failed"].mean()
        cov = values["failed"].std(ddof=1) / math.sqrt(n) / mean if mean > 0 else math.inf
        _advance(bar, BATCH, n, n * max(min(cov, 1e3) / target, 1.0) ** 2)
        ess, share = weight_diagnostics(values["failed"])
        if cov <= target and ess >= MIN_EFFECTIVE_SAMPLES:
            break
        if (n + BATCH) * simulator.steps_per_path > budget:
            _out_of_budget("importance", cov, target, n * simulator.steps_per_path)
            break
    if ess < MIN_EFFECTIVE_SAMPLES or share > MAX_WEIGHT_SHARE:
        raise ValueError(
            f"method='importance': the weights have degenerated ({ess:.3g} effective failing "
            f"samples of {n}, the largest carrying {share:.0%} of the estimate; reliable "
            f"needs >= {MIN_EFFECTIVE_SAMPLES} and <= {MAX_WEIGHT_SHARE:.0%}): the "
            "linearisation's design points miss this device's failure paths; use "
            "method='subset'"
        )
    estimates = {}
    for k, v in values.items():
        m = v.mean()
        estimates[k] = _statistic(m, v.std(ddof=1) / math.sqrt(n) / m if m > 0 else math.inf, n)
    details = {"effective_sample_size": ess, "max_weight_share": share,
               "amplitude": design.amplitude, "samples": n}  # fmt: skip
    return estimates, n, details


def _crude(simulator, rng, target, budget, bar, **_):
    """Independent paths until the c.o.v. sqrt((1 - p) / (n p)) reaches ``target``."""
    parts: dict = {"failed": [], "beyond": [], "upcrossings": []}
    while True:
        out = simulator(rng.standard_normal((BATCH, simulator.dimension)))
        parts["failed"].append((out.peak > simulator.stroke).astype(float))
        parts["beyond"].append(out.beyond)
        parts["upcrossings"].append(out.upcrossings)
        values = {k: np.concatenate(v) for k, v in parts.items()}
        n = values["failed"].size
        failures = int(values["failed"].sum())
        p = failures / n
        cov = math.sqrt((1.0 - p) / (n * p)) if failures else math.inf
        _advance(bar, BATCH, n, n * max(min(cov, 1e3) / target, 1.0) ** 2)
        if cov <= target:
            break
        if (n + BATCH) * simulator.steps_per_path > budget:
            _out_of_budget("crude", cov, target, n * simulator.steps_per_path)
            break
    estimates = {}
    for k, v in values.items():
        m = float(v.mean())
        if m > 0:
            estimates[k] = _statistic(m, v.std(ddof=1) / math.sqrt(n) / m, n)
        else:  # no path reached the stroke: the 95 % upper bound 3 / n (rule of three)
            estimates[k] = Statistic(0.0, 3.0 / n, 3.0 / n / Z95, n)
    return estimates, n, {"paths": n, "failures": failures}
