"""``randvib.design``: the harvester that harvests most from a vibration under a stroke budget.

The user fixes what is fixed (a :class:`~randvib.Harvester` with its mass,
mechanical damping, friction, coupling and stroke) and the excitation, and
names the parameters to choose with their ranges. The design

1. searches with the analytic predictors where they take the candidate
   (:mod:`randvib.harvester_design.search`; exact for a linear device under a rational
   spectrum);
2. confirms the optimum and the runners-up by Monte Carlo, all on one seed
   (common random numbers, :func:`randvib.run_ensembles`; a Dask cluster and
   resume as for every sweep);
3. where Monte Carlo disagrees with the analytic answer (a runner-up
   significantly better, paired; the optimum significantly beyond the budget;
   or its prediction off by more than
   :data:`~randvib.harvester_design.confirmation.PREDICTION_TOLERANCE`), refines
   by Monte Carlo on shrinking local grids around the best confirmed
   feasible candidate, and reports what the analytic answer would have cost;
4. with a bound on the mean first-passage time to the stroke
   (``min_first_passage``), predicts it where the method's response is
   Gaussian (:func:`randvib.harvester_design.search.predicted_first_passage`) and checks
   it by Monte Carlo on the confirmed candidates (each path's first time
   beyond the stroke, :class:`randvib.statistics.FirstPassage`);
5. reports the power the excitation delivers (m S / 4 under white noise),
   the efficiency, and the fractions of the limits: under a spectrum the
   stationary non-causal bound at the budget's displacement variance
   (:func:`randvib.analytic.harvesting_limit.harvesting_limit`; a bound for
   every linear device meeting the budget, not for every device), the same
   bound with E[z^2] <= d^2 (any device within |z| <= d), and the causal
   bound a device can approach
   (:func:`randvib.analytic.harvesting_limit.causal_harvesting_limit`); on
   a record the non-causal bound on the record itself with |z| <= stroke
   (:func:`randvib.analytic.harvesting_limit.record_harvesting_limit`).

An :class:`~randvib.models.assembly.Assembly` goes through the same steps
with its own parts: dotted-path parameters and a stroke budget on its
coordinates (:mod:`randvib.harvester_design.assembly_budget`), the objective
summed over its transducers or one transducer's
(:class:`~randvib.harvester_design.objectives.AssemblyObjective`), the
search by ``linearisation`` and the confirmation by its own Monte Carlo
(:mod:`randvib.harvester_design.assembly_confirmation`); no harvesting limit
or first passage yet.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from types import SimpleNamespace

import numpy as np

from randvib.analytic.harvesting_limit import (
    causal_harvesting_limit,
    gaussian_displacement_budget,
    harvesting_limit,
    predictable_spectrum,
    record_harvesting_limit,
)
from randvib.harvester_design.assembly_budget import stroke_budget
from randvib.harvester_design.assembly_confirmation import AssemblyConfirmed
from randvib.harvester_design.confirmation import (
    ConfirmedCandidates,
    within,
)
from randvib.harvester_design.constraints import FirstPassageLimit
from randvib.harvester_design.objectives import AssemblyObjective, objective_named
from randvib.harvester_design.result import DesignResult
from randvib.harvester_design.search import (
    COARSE,
    Candidate,
    InfeasibleBudget,
    NothingPredicted,
    analytic_search,
)
from randvib.harvester_design.space import DesignSpace
from randvib.models.assembly import Assembly
from randvib.models.excitation import Measured, as_excitation
from randvib.models.harvester import Harvester
from randvib.montecarlo.bridge_step import BridgeIdleWarning, bridge_input_rms, never_conducted
from randvib.montecarlo.ensembles import Case, EnsembleResult, run_ensembles
from randvib.montecarlo.on_record import monte_carlo_on_record
from randvib.montecarlo.sweep import SweepSettings
from randvib.statistics import FirstPassage, Statistic, estimate, proportion

__all__ = ["design"]

#: Monte Carlo refinement: rounds, and the half-width of the first local grid (unit box).
REFINE_ROUNDS = 2
REFINE_STEP = 0.15


def design(
    harvester: Harvester | Assembly,
    excitation,
    vary: Mapping,
    *,
    stroke: float | None = None,
    exceedance: float = 0.01,
    objective="electrical",
    monte_carlo: bool = True,
    settings: SweepSettings | None = None,
    runners_up: int = 2,
    refine: bool = True,
    out_dir=None,
    executor=None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    min_first_passage: float | None = None,
    segments: int = 10,
    stroke_on=None,
    transducer: int | None = None,
    max_first_passage: float | None = None,
    duration: float | None = None,
) -> DesignResult:
    """Choose the varied parameters that maximise the power with ``P(|z| > stroke) <= exceedance``.

    Parameters
    ----------
    harvester : Harvester or Assembly
        What is fixed: mass (kg), mechanical damping (Ns/m), friction,
        coupling; the varied parameters' values in it are ignored. An
        :class:`~randvib.models.assembly.Assembly` (a harvester on a host, a
        two-mass harvester, an array; docs/assemblies.md) is searched with
        ``linearisation`` (exact for a linear assembly) and confirmed by its
        own Monte Carlo (:mod:`randvib.harvester_design.assembly_confirmation`).
    excitation : float or Excitation
        White-noise level S ((m/s^2)^2/Hz) or any excitation (a band-pass,
        Kanai-Tajimi, tabulated or measured spectrum). A measured record
        is searched with its Welch PSD (:attr:`randvib.Measured.spectrum`)
        and confirmed (and refined) on the record itself: every candidate is
        driven by the recorded base acceleration and its ``segments``
        windows are the paths (:func:`randvib.monte_carlo_on_record`), the
        same windows for every candidate (common random numbers).
    vary : mapping of str to (low, high)
        The parameters to choose and their ranges (SI): ``k``, ``k3`` (any
        sign; k < 0 < k3 is bistable), ``c_e``, ``c_m``, a friction law's
        or the coupling's parameters (``alpha``, ``r_load``, ``theta``, ...;
        a bridge's ``battery`` V_b (V) or storage load ``r_load``). An
        assembly's by dotted path: ``transducer.0.r_load``, ``element.1.k3``,
        ``structure.stiffness.0.0`` (:meth:`~randvib.models.assembly.Assembly.updated`);
        refused: an unknown path, a mass, the influence, a stroke, a derived
        c_e (:func:`~randvib.harvester_design.assembly_budget.vary_refusal`).
    stroke : float, optional
        Stroke d (m), > 0; default the harvester's (an assembly's: set on
        each ``stroke_on`` coordinate; default the strokes it carries).
    exceedance : float
        The budget eps: the stationary fraction of time with |z| > d, in (0, 1).
    objective : str or Objective
        ``"electrical"`` (E[P_e]), ``"load"`` (E[i^2 R_L]) or ``"stored"``
        (the DC power through a diode bridge, V_b E|i| or E[V_C^2] / R_L:
        searched with ``bridge-closure`` where it is offered, by Monte Carlo
        elsewhere); see
        :data:`randvib.harvester_design.objectives.OBJECTIVES`.
    monte_carlo : bool
        Confirm (and refine) by Monte Carlo; False: the analytic answer only.
    settings : SweepSettings, optional
        Monte Carlo settings; default a 1 % precision target on the power
        (``target_rel_ci=0.01``), control variates under white noise.
    runners_up : int
        Candidates confirmed beside the optimum.
    refine : bool
        Refine by Monte Carlo where it disagrees with the analytic ranking.
    out_dir, executor, workers, scheduler, progress : optional
        As for :func:`randvib.run_ensembles` (resumable in ``out_dir``, a
        Dask cluster at ``scheduler``). A record's runs take ``settings``'
        ``burn_in`` (record time before each window), ``seed`` and a step
        of at most ``settings.dt`` (whole substeps of the record's step);
        they run in this process, without ``out_dir`` or a cluster.
    min_first_passage : float, optional
        T (s), > 0: also require a mean first-passage time to the stroke
        E[tau] >= T, from the ensembles' stationary start. The search uses
        the prediction where there is one (Gaussian response: Rice's rate
        with Vanmarcke's clumping, :func:`~randvib.harvester_design.search.predicted_first_passage`);
        Monte Carlo rejects a candidate whose E[tau] is significantly below
        T (every path reached the stroke and the 95 % interval lies below T)
        and confirms it when E[min(tau, t_end)], a lower bound, is
        significantly above T. Paths censored at the run's end t_end
        (burn-in plus window) leave it undetermined: to confirm T, run
        longer than T (``settings``).
    segments : int
        A record's windows (Monte Carlo paths), >= 2; each should be much
        longer than the device's decay time 2 m / c
        (:attr:`randvib.RecordSimulation.lag1_correlation` checks it).
    stroke_on : str or list of str, optional
        An assembly's coordinates the budget holds on, ``element.N`` or
        ``transducer.N``; default every part with a stroke, each of which
        must then meet it (:class:`~randvib.harvester_design.assembly_budget.StrokeBudget`).
    transducer : int, optional
        An assembly's one transducer whose power the objective counts (the
        others as they are); default the sum over all its transducers
        (:class:`~randvib.harvester_design.objectives.AssemblyObjective`).
    max_first_passage, duration : float, optional
        P in (0, 1) and T (s), given together: also require
        P(|z| reaches the stroke within T) <= P from the stationary state
        (:class:`~randvib.harvester_design.constraints.FirstPassageLimit`):
        predicted from the Gaussian answer in the search, then confirmed by
        the rare-event estimate (:func:`randvib.first_passage`) on the
        candidates Monte Carlo confirmed, the best not rejected chosen.

    Returns
    -------
    DesignResult

    Raises
    ------
    ValueError
        One line for an unknown parameter, an empty range, no stroke, a bad
        budget or objective, or an infeasible budget
        (:class:`~randvib.harvester_design.search.InfeasibleBudget`: the best reachable
        exceedance, or the longest first passage), or a bad ``min_first_passage``.

    Examples
    --------
    >>> import randvib as rv
    >>> fixed = rv.Harvester(m=0.0226, c_m=0.049, c_e=0.1, k=57.4, stroke=0.003)
    >>> result = rv.design(fixed, rv.BandPass(1.0, 8.0, 0.1), {"k": (20, 120), "c_e": (0.01, 1)},
    ...                    exceedance=0.01, monte_carlo=False)
    >>> print(f"k = {result.optimum['k']:.1f} N/m, c_e = {result.optimum['c_e']:.3f} Ns/m")
    k = 59.1 N/m, c_e = 0.456 Ns/m
    """
    _check_min_first_passage(min_first_passage)
    strikes = FirstPassageLimit.checked(max_first_passage, duration)
    excitation = as_excitation(excitation)
    if isinstance(harvester, Assembly):
        space, goal, stroke = _assembly_setup(
            harvester, excitation, vary, stroke, stroke_on, objective, transducer,
            dict(min_first_passage=min_first_passage, max_first_passage=max_first_passage,
                 out_dir=out_dir, executor=executor,
                 workers=workers, scheduler=scheduler), monte_carlo,
        )  # fmt: skip
        limits = dict(limit_kind=None)  # no harvesting limit of an assembly yet
        limit = None
    else:
        if stroke_on is not None or transducer is not None:
            raise ValueError(
                "`stroke_on` and `transducer` name the parts of an assembly; a single-mass "
                "harvester has one stroke, on z, and one transducer"
            )
        space, goal, stroke, limits = _single_mass_setup(
            harvester, excitation, vary, stroke, exceedance, objective, progress
        )
        limit = limits.pop("limit")  # the result builders give it beside its fraction
    try:
        search = analytic_search(
            space, excitation, exceedance, goal, runners_up, min_first_passage, strikes
        )
    except NothingPredicted as exc:
        if not monte_carlo:
            raise ValueError(
                f"{exc}: only Monte Carlo can search them (monte_carlo=True)"
            ) from None
        search = None
    confirmed_on = "record windows" if isinstance(excitation, Measured) else "simulated paths"
    common = dict(objective=goal.name, stroke=stroke, exceedance_budget=float(exceedance),
                  evaluations=0 if search is None else search.evaluations,
                  min_first_passage=min_first_passage, max_first_passage=max_first_passage,
                  duration=duration, **limits)  # fmt: skip
    if monte_carlo:
        common["monte_carlo_input"] = confirmed_on
    if space.is_assembly:
        common["objective_scope"] = goal.scope
    if not monte_carlo:
        common.update(_strike_fields(strikes, search.optimum))
        return _analytic_result(space, search, limit, common)
    settings = settings or SweepSettings(
        target_rel_ci=0.01, control_variates=excitation.is_white, max_paths=2048
    )
    common["monte_carlo_precision"] = settings.target_rel_ci
    run = dict(settings=settings, out_dir=out_dir, executor=executor, workers=workers,
               scheduler=scheduler, progress=progress)  # fmt: skip
    if space.is_assembly:
        confirmed = AssemblyConfirmed(space, excitation, goal, settings, progress)
    else:
        confirmed = _Confirmed(space, excitation, goal, run, min_first_passage, segments)
    best, candidates, chosen = _confirm(confirmed, space, search, exceedance, refine)
    reliability = verdict = None
    if strikes is not None:  # the rare-event estimate decides, best Monte Carlo power first
        chosen, reliability, verdict = strikes.decide(
            confirmed, chosen, exceedance, space, excitation, settings.seed
        )
    _require_feasible(confirmed, chosen, space, exceedance, min_first_passage)
    _require_power(confirmed, chosen)
    common.update(_strike_fields(strikes, chosen, reliability, verdict))
    return _confirmed_result(confirmed, space, best, chosen, candidates, exceedance, limit, common)


def _single_mass_setup(harvester, excitation, vary, stroke, exceedance, objective, progress):
    """A single mass's design space, objective, stroke and limits (:func:`_limit`)."""
    stroke = harvester.stroke if stroke is None else stroke
    if stroke is None:
        raise ValueError("`stroke` is needed: the design's budget is on P(|z| > stroke)")
    sigma_budget = gaussian_displacement_budget(stroke, exceedance)
    fixed = harvester.updated(stroke=stroke)
    goal = objective_named(objective)
    refusal = goal.requires(fixed)
    if refusal:
        raise ValueError(refusal)
    limits = _limit(fixed, excitation, stroke, sigma_budget, progress)
    return DesignSpace(fixed, vary), goal, float(stroke), limits


def _assembly_setup(
    assembly, excitation, vary, stroke, stroke_on, objective, transducer, options, monte_carlo
):
    """An assembly's design space (with its stroke budget), objective and strokes.

    Refuses in one line what a design does not do for assemblies yet: a
    first-passage bound, a resumable folder or a cluster (the candidates run
    in this process, on numba threads), Monte Carlo on a measured record.
    """
    for name, value in options.items():
        if value is not None:
            raise ValueError(
                f"`{name}` is not taken with an assembly: its candidates run in this process "
                "(numba threads), without a first-passage bound, resume folder or cluster"
            )
    if monte_carlo and isinstance(excitation, Measured):
        raise ValueError(
            "an assembly's design is confirmed on simulated paths: give the record's spectrum "
            "(Measured.spectrum) or monte_carlo=False"
        )
    fixed, budget = stroke_budget(assembly, stroke, stroke_on)
    goal = AssemblyObjective(objective_named(objective), transducer)
    refusal = goal.requires(fixed)
    if refusal:
        raise ValueError(refusal)
    return DesignSpace(fixed, vary, budget), goal, dict(budget.strokes)


def _strike_fields(strikes: FirstPassageLimit | None, chosen, reliability=None, verdict=None):
    """The result's fields of the strike limit (``max_first_passage``): predicted, estimated."""
    return dict(
        first_passage_probability_predicted=math.nan
        if strikes is None
        else strikes.predicted(chosen),
        first_passage_probability=None
        if reliability is None
        else reliability.probability_first_passage,
        first_passage_probability_confirmed=verdict,
    )


def _check_min_first_passage(min_first_passage) -> None:
    """Refuse a ``min_first_passage`` that is not a finite time > 0 (None: no bound)."""
    if min_first_passage is not None and not (
        isinstance(min_first_passage, (int, float))
        and math.isfinite(min_first_passage)
        and min_first_passage > 0
    ):
        raise ValueError(
            f"`min_first_passage` must be a finite time > 0 (s), got {min_first_passage!r}"
        )


def _limit(
    fixed: Harvester, excitation, stroke: float, sigma_budget: float, progress: bool = False
) -> dict:
    """The harvesting limits (W) the result compares with, each with what it bounds in words.

    ``limit``: on a record the non-causal bound on the record itself with
    |z| <= stroke; otherwise the stationary non-causal bound at the budget's
    Gaussian displacement RMS, which bounds every device with that E[z^2]
    (every linear device meeting the budget), not every device meeting it.
    ``limit_hard_stroke``: the bound for any device held within |z| <= stroke
    (E[z^2] <= d^2). ``causal_limit``: what a causal device can approach at
    the budget's RMS (:func:`causal_harvesting_limit`; not on a record).
    ``progress``: a bar over the record bound's chunks (seconds per thousand samples).
    """
    m, c_m = fixed.m, fixed.c_m
    if isinstance(excitation, Measured) and c_m > 0:
        limit = record_harvesting_limit(m, c_m, excitation, stroke, progress=progress)
        return dict(
            limit=limit, limit_hard_stroke=limit, causal_limit=None,
            limit_kind="record, non-causal (the whole record known): any device within "
            "|z| <= stroke, from rest",
            causal_limit_kind="not computed on a record",
        )  # fmt: skip
    limit = harvesting_limit(m, c_m, excitation, sigma_budget)
    causal = causal_harvesting_limit(m, c_m, excitation, sigma_budget)
    if excitation.is_white:
        causal_kind = "causal: m S / 4, the power white noise injects (any budget)"
    elif predictable_spectrum(excitation):
        lo, hi = excitation.support
        causal_kind = (
            f"causal = non-causal: the spectrum vanishes outside {lo:g}-{hi:g} Hz, so its past "
            "determines its future (Paley-Wiener)"
        )
    else:
        causal_kind = None if causal is None else (
            "causal (Wiener-Hopf) at the budget's Gaussian RMS: the best linear active "
            "transducer approaches it"
        )  # fmt: skip
    return dict(
        limit=limit,
        limit_kind=None if limit is None else (
            "stationary, non-causal: any device with E[z^2] at most the budget's Gaussian "
            "RMS squared, so every linear device meeting the budget, not every device "
            "(limit_hard_stroke: any within |z| <= stroke)"
        ),
        limit_hard_stroke=harvesting_limit(m, c_m, excitation, stroke),
        causal_limit=causal,
        causal_limit_kind=causal_kind,
    )  # fmt: skip


def _analytic_result(space: DesignSpace, search, limit, common: dict) -> DesignResult:
    """The analytic answer alone (``monte_carlo=False``): the search's optimum and runners-up."""
    best = search.optimum
    return DesignResult(
        optimum=best.values,
        analytic_optimum=best.values,
        method=best.method,
        device=space.device(best.u),
        power_predicted=best.power,
        exceedance_predicted=best.exceedance,
        power_monte_carlo=None,
        stroke_exceedance_monte_carlo=None,
        input_power=best.input_power,
        efficiency=best.power / best.input_power,
        limit=limit,
        fraction_of_limit=None if limit is None else best.power / limit,
        runners_up=[_runner(c) for c in search.runners_up],
        first_passage_predicted=best.first_passage,
        **common,
    )


def _confirm(confirmed: _Confirmed, space: DesignSpace, search, exceedance: float, refine: bool):
    """Steps 2 and 3 of the design: confirm the candidates by Monte Carlo, refine on disagreement.

    ``search`` None (no method predicts the range): Monte Carlo searches a
    coarse grid, then refines. Returns ``(best, candidates, chosen)``: the
    analytic optimum (None without a search), the candidates confirmed beside
    it, and the chosen one.
    """
    if search is None:  # Monte Carlo searches a coarse grid, then refines
        best = None
        candidates = [confirmed.point(u) for u in space.grid(COARSE if space.dimension > 1 else 5)]
        candidates = [c for c in candidates if c is not None]
        confirmed.add(candidates)
        disagrees = True
    else:
        best = search.optimum
        candidates = [best, *search.runners_up]
        # the devices no method predicts are candidates only Monte Carlo can judge
        unpredicted = [c for c in map(confirmed.point, search.unpredicted) if c is not None]
        confirmed.add(candidates + unpredicted)
        candidates += unpredicted
        disagrees = confirmed.disagrees(best, candidates, exceedance)
    chosen = confirmed.best(exceedance, confirmed.candidates)
    if refine and disagrees:
        step = REFINE_STEP
        for _ in range(REFINE_ROUNDS):
            local = _neighbours(space, chosen.u, step)
            confirmed.add([c for c in map(confirmed.point, local) if c is not None])
            chosen = confirmed.best(exceedance, confirmed.candidates)
            step /= 3.0
    if best is not None and chosen is not best and not confirmed.better(chosen, best, exceedance):
        chosen = best  # Monte Carlo's maximum is not significantly better: keep the analytic one
    return best, candidates, chosen


def _require_feasible(
    confirmed: _Confirmed, chosen, space: DesignSpace, exceedance: float, min_first_passage
) -> None:
    """Raise :class:`InfeasibleBudget` when Monte Carlo rejects the chosen device's budget."""
    x = confirmed.exceedance(chosen)
    if not within(x, exceedance):
        where = ", ".join(f"{k} = {v:.6g}" for k, v in chosen.values.items())
        raise InfeasibleBudget(
            f"the stroke budget {space.budget_words()} <= {exceedance:g} cannot be met in the "
            f"ranges given: the best reachable exceedance (Monte Carlo) is {x.mean:.3g} "
            f"± {x.ci95:.2g} (at {where})"
        )
    if confirmed.passage(chosen) is False:
        first = confirmed.first_passage(chosen).mean
        where = ", ".join(f"{k} = {v:.6g}" for k, v in chosen.values.items())
        raise InfeasibleBudget(
            f"the first-passage constraint E[tau] >= {min_first_passage:g} s (mean time to "
            f"|z| > {space.harvester.stroke:g} m) is not met by the best device within the stroke budget: "
            f"Monte Carlo gives {first.mean:.3g} ± {first.ci95:.2g} s (at {where})"
        )


def _require_power(confirmed: ConfirmedCandidates, chosen) -> None:
    """Refuse an optimum of zero power: no candidate delivered any, so none is best.

    A diode bridge that never conducted says why (its transducer's RMS voltage
    against the threshold) and what would help (a single mass's runs).
    """
    if confirmed.power(chosen).mean > 0.0:
        return
    why = "no candidate in the ranges delivered any power"
    located = getattr(confirmed, "where", {}).get(id(chosen))
    if located is None:  # an assembly's runs: no bridge diagnosis yet
        raise ValueError(f"the design has no optimum: {why}")
    result, i = located
    run = result.simulation(i)
    if run.harvester.is_rectified and never_conducted(run):
        where = ", ".join(f"{k} = {v:.6g}" for k, v in chosen.values.items())
        advice = run.harvester.electrical.idle_advice(bridge_input_rms(run))
        why += f"; at {where}, {advice}"
    raise ValueError(f"the design has no optimum: {why}")


def _confirmed_result(
    confirmed: _Confirmed,
    space: DesignSpace,
    best,
    chosen,
    candidates,
    exceedance: float,
    limit,
    common: dict,
) -> DesignResult:
    """The design confirmed by Monte Carlo: the chosen device, its runners-up, the analytic cost."""
    x = confirmed.exceedance(chosen)
    power = confirmed.power(chosen)
    input_power = confirmed.input_power(chosen)
    return DesignResult(
        optimum=chosen.values,
        analytic_optimum={} if best is None else best.values,
        method="monte-carlo" if best is None else best.method,
        device=space.device(chosen.u),
        power_predicted=chosen.power,
        exceedance_predicted=chosen.exceedance,
        power_monte_carlo=power,
        stroke_exceedance_monte_carlo=x,
        input_power=input_power,
        efficiency=power.mean / input_power.mean,
        limit=limit,
        fraction_of_limit=None if limit is None else power.mean / limit,
        runners_up=[
            {
                **_runner(c),
                "power_monte_carlo": confirmed.power(c),
                "stroke_exceedance_monte_carlo": confirmed.exceedance(c),
                "difference_to_optimum": confirmed.difference(c, chosen),
            }
            for c in candidates
            if c is not chosen
        ],
        analytic_cost=None if best is None else confirmed.difference(chosen, best),
        analytic_feasible=None if best is None else confirmed.feasible(best, exceedance),
        refined=best is not None and chosen is not best,
        monte_carlo_cases=len(confirmed.candidates),
        first_passage_predicted=chosen.first_passage,
        first_passage_monte_carlo=confirmed.first_passage(chosen),
        first_passage_confirmed=confirmed.passage(chosen),
        **common,
    )


def _runner(c: Candidate) -> dict:
    return {"values": c.values, "power_predicted": c.power, "exceedance_predicted": c.exceedance,
            "first_passage_predicted": c.first_passage}  # fmt: skip


def _neighbours(space: DesignSpace, u, step: float) -> list:
    """The 3^d points of a local grid of half-width ``step`` around ``u``, inside the box."""
    offsets = np.stack(
        [a.ravel() for a in np.meshgrid(*[[-step, 0.0, step]] * space.dimension, indexing="ij")],
        axis=-1,
    )
    return [np.clip(u + o, 0.0, 1.0) for o in offsets]


class _OnRecord:
    """Candidates' runs on a record's windows, read as an :class:`EnsembleResult` is."""

    power_samples = EnsembleResult.power_samples

    def __init__(self, runs):
        self.runs = runs
        self.cases = [SimpleNamespace(device=r.harvester) for r in runs]
        self.settings = SweepSettings(control_variates=False)

    def averages(self, index: int):
        return self.runs[index].averages

    def simulation(self, index: int):
        return self.runs[index]


class _Confirmed(ConfirmedCandidates):
    """The single mass's candidates by Monte Carlo with common random numbers.

    Under a spectrum every run is group 0 of one seed; on a record path i is
    the record's window i for every candidate.
    """

    def __init__(self, space, excitation, goal, run, min_first_passage=None, segments=10):
        super().__init__(space, excitation, goal, min_first_passage)
        self.run = run
        self.record = excitation if isinstance(excitation, Measured) else None
        self.segments = segments

    def add(self, candidates) -> None:
        new = self.new(candidates)
        if not new:
            return
        if self.record is not None:
            result = _OnRecord([self._on_record(self.space.device(c.u)) for c in new])
            for i, c in enumerate(new):
                self.where[id(c)] = (result, i)
            self.candidates += new
            return
        cases = [
            Case(labels={"candidate": len(self.candidates) + i}, device=self.space.device(c.u),
                 excitation=self.excitation, group=0)
            for i, c in enumerate(new)
        ]  # fmt: skip
        run = self.run
        out_dir = run["out_dir"]
        if out_dir is not None:  # one resumable folder per batch of candidates
            from pathlib import Path

            out_dir = Path(out_dir) / f"batch{len(self.candidates)}"
        with warnings.catch_warnings():  # a candidate whose bridge never conducts is only
            warnings.simplefilter("ignore", BridgeIdleWarning)  # a poor one; _require_power
            result = run_ensembles(cases, **{**run, "out_dir": out_dir}, name="design")
        for i, c in enumerate(new):
            self.where[id(c)] = (result, i)
        self.candidates += new

    def _on_record(self, device):
        """The device driven by the record, its windows the paths (the same for every device)."""
        settings = self.run["settings"]
        substeps = max(1, math.ceil(self.record.dt / settings.dt - 1e-9))
        return monte_carlo_on_record(
            device, self.record, segments=self.segments, burn_in=settings.burn_in,
            substeps=substeps, scheme=settings.scheme, seed=settings.seed, progress=False,
        )  # fmt: skip

    def _samples(self, c) -> np.ndarray:
        result, i = self.where[id(c)]
        return self.goal.monte_carlo(result, i)

    def _controls(self, c):
        """The case's zero-mean control variates per path (white noise), or None."""
        result, i = self.where[id(c)]
        return result.simulation(i).controls() if result.settings.control_variates else None

    def exceedance(self, c) -> Statistic:
        result, i = self.where[id(c)]
        return proportion(result.averages(i).beyond_stroke)  # Wilson: stays in [0, 1]

    def input_power(self, c) -> Statistic:
        """c_m E[z'^2] + E[z' F] + electrical power, path by path (every dissipation)."""
        result, i = self.where[id(c)]
        averages, device = result.averages(i), result.cases[i].device
        if device.is_rectified:  # what the bridge takes: stored, coil and diode losses
            electrical = averages.stored_power + averages.coil_loss + averages.diode_loss
        else:
            electrical = result.power_samples(i)
        samples = device.c_m * averages.v2 + averages.friction_power + electrical
        return estimate(samples, self._controls(c))

    def first_passage(self, c) -> FirstPassage:
        """Time to ``|z| > stroke`` from each path's (stationary) start, censored at t_end."""
        result, i = self.where[id(c)]
        return result.simulation(i).stroke_first_passage

    def passage(self, c) -> bool | None:
        """The first-passage bound by Monte Carlo: True when E[min(tau, t_end)] (a lower
        bound of E[tau]) is significantly above it, False when every path reached the
        stroke and E[tau] is significantly below it, None when undetermined (or no bound)."""
        if self.min_first_passage is None:
            return None
        first = self.first_passage(c)
        restricted = first.restricted_mean
        if restricted.mean - restricted.ci95 >= self.min_first_passage:
            return True
        if first.mean is not None and first.mean.mean + first.mean.ci95 < self.min_first_passage:
            return False
        return None
