"""The analytic search of a design: the best predicted device within a stroke budget.

Every candidate is predicted by the most accurate analytic method of
:data:`randvib.analytic.prediction.METHODS` that takes it (the methods'
declarations: coloured input, potential kind, friction law; a method that
refuses a point beyond its declared validity leaves it unpredicted) and gives
a stroke exceedance. The search evaluates a regular grid of the design box,
then maximises the objective from the best feasible grid points by SLSQP with
the budget as a smooth constraint, log(eps) - log P(|z| > d) >= 0. For a
linear device with a rational spectrum the prediction is the exact Lyapunov
solution (:mod:`randvib.analytic.linear_response`) and the constraint is
sigma_z <= d / Phi^-1(1 - eps/2), so the optimum found is the exact one
(to the optimiser's tolerance, 1e-10 relative in the objective).

A coil into a diode bridge (:mod:`randvib.models.rectifier`) is predicted by
``bridge-closure`` (within its declared validity; beyond it the point is left
to Monte Carlo). The closure takes the response as Gaussian, so
its exceedance is that of a Gaussian displacement of the closure's variance,
P(|z| > d) = erfc(d / (sigma_z sqrt 2)); Monte Carlo confirms it.

An optional second constraint asks for a mean first-passage time to the
stroke of at least T. Where the method's response is Gaussian
(:data:`GAUSSIAN_RESPONSE`) it is predicted from Rice's stationary rate of
crossings out of |z| < d (:func:`randvib.analytic.first_passage.outcrossing_rate`,
with E[z z'] = 0), its crossings clumped as Vanmarcke's hazard has them
(:func:`randvib.analytic.first_passage.vanmarcke_hazard`, with the spectral
bandwidth of the linear(ised) oscillator m, c_eq, k_eq = k + 3 k3 E[z^2]
under the excitation; Poisson where k_eq <= 0), from a stationary start:
E[tau] = (1 - P(|z| > d)) / h. Independent (Poisson) crossings are too short
by the clump size under a narrow-band response; Vanmarcke's hazard tends to
Rice's rate as the bandwidth q -> 1 at a high barrier. Vanmarcke errs the
other way (too long, not conservative): against Monte Carlo for a linear
device at d = 2.58 sigma_z under band-pass input it is 1.7-2x too long where
Poisson is 5-9x too short (tests/test_design.py), so Monte Carlo's check of
the bound on the confirmed candidates is what decides. Elsewhere (``fpk-fast``'s
non-Gaussian density) no first passage is predicted and only Monte Carlo
checks the constraint.

An :class:`~randvib.models.assembly.Assembly` is predicted by the method that
takes assemblies (``linearisation``: the exact Lyapunov solution of a linear
assembly, each nonlinear element's Gaussian closure otherwise); its
exceedance is the worst of the budget's coordinates
(:class:`~randvib.harvester_design.assembly_budget.StrokeBudget`), its input
power the dissipated power of the linear(ised) assembly, and no first
passage is predicted.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property, partial

import numpy as np
from scipy import optimize

from randvib.analytic.first_passage import outcrossing_rate, spectral_bandwidth, vanmarcke_hazard
from randvib.analytic.linear_response import mechanical_block
from randvib.analytic.power_prediction import gaussian_exceedance
from randvib.analytic.prediction import METHODS, predict
from randvib.harvester_design.space import DesignSpace
from randvib.models.assembly import Assembly

__all__ = ["Candidate", "SearchOutcome", "analytic_search", "predictor_for"]

#: The analytic methods a design may use, most accurate first (never the
#: slow reference solver, which the methods declare).
PREFERENCE = ("fpk-fast", "linearisation")
#: The method of a device behind a diode bridge (the others refuse a rectifier).
RECTIFIED = "bridge-closure"
#: Methods whose stroke exceedance is that of their Gaussian displacement: their
#: closure assumes a Gaussian response, so the exceedance is its consequence.
GAUSSIAN_DISPLACEMENT = (RECTIFIED,)
#: Methods whose stationary (z, z') is Gaussian: the first passage is predicted for them.
GAUSSIAN_RESPONSE = ("linearisation", RECTIFIED)
#: Grid points per dimension of the first look, by the number of varied parameters.
GRID = {1: 41, 2: 15, 3: 7}
#: Grid points per dimension beyond three parameters.
GRID_MANY = 4
#: Local optimisations started from the best feasible grid points.
STARTS = 4
#: Two local optima closer than this in the unit box are one.
SAME_POINT = 0.05
#: Exceedances below this are taken as this (log of the constraint).
TINY = 1e-300


class InfeasibleBudget(ValueError):
    """No device in the ranges meets the stroke budget (the message says the best reachable)."""


class NothingPredicted(ValueError):
    """No analytic method predicts any device of the ranges (Monte Carlo must search them)."""


#: Grid points per dimension of the coarse look at the devices no method predicts.
COARSE = 3


@dataclass(frozen=True)
class Candidate:
    """One predicted device of the design space.

    Attributes
    ----------
    u : ndarray
        Its point of the unit box.
    values : dict
        Parameter name -> value (SI).
    power : float
        The objective's predicted power (W).
    exceedance : float
        Predicted P(|z| > stroke).
    method : str
        The analytic method that predicted it.
    input_power : float
        Predicted power the excitation delivers, c_eq E[z'^2] (W): the
        stationary sum of every dissipation.
    warned : bool
        The method warned (beyond a declared validity limit it warns at).
    passage_prediction : callable or None
        Returns the predicted mean first passage (:attr:`first_passage`) when
        first asked for it.
    """

    u: np.ndarray = field(repr=False)
    values: dict
    power: float
    exceedance: float
    method: str
    input_power: float
    warned: bool = False
    passage_prediction: Callable[[], float] | None = field(default=None, repr=False, compare=False)

    @cached_property
    def first_passage(self) -> float:
        """Predicted mean first-passage time to the stroke (s) from a stationary start.

        NaN where the method's response is not Gaussian (module docstring) or
        without a ``passage_prediction``. Computed when first asked for: a
        search without a first-passage bound asks it of the few devices it
        reports, not of every point it evaluates (a Vanmarcke bandwidth each, a
        spectral integral: a third of a linear design's search).
        """
        return math.nan if self.passage_prediction is None else self.passage_prediction()


@dataclass(frozen=True)
class SearchOutcome:
    """What the analytic search found.

    ``unpredicted`` holds the points of a coarse grid (:data:`COARSE` per
    dimension) that no method predicts (refused: a bistable device beyond
    linearisation's reach, say): candidates only Monte Carlo can judge.
    """

    optimum: Candidate
    runners_up: list
    evaluations: int
    grid: list = field(repr=False)
    unpredicted: list = field(default_factory=list, repr=False)


def predictor_for(harvester, excitation):
    """The first method of :data:`PREFERENCE` that takes the case and gives the exceedance, or None.

    A linear device without friction is linearisation's: exact there (Lyapunov).
    A device behind a diode bridge is :data:`RECTIFIED`'s where it accepts it.
    An assembly is the method's that takes assemblies.
    """
    if isinstance(harvester, Assembly):
        methods = (m for m in METHODS.values() if m.assemblies and m.accepts(harvester, excitation))
        return next(methods, None)
    if harvester.is_rectified:
        method = METHODS[RECTIFIED]
        return method if method.accepts(harvester, excitation) else None
    linear = harvester.friction is None and np.all(harvester.k3 == 0) and np.all(harvester.k > 0)
    for name in ("linearisation",) if linear else PREFERENCE:
        method = METHODS[name]
        if method.stroke_exceedance and method.accepts(harvester, excitation):
            return method
    return None


class Evaluator:
    """Predictions at box points, cached, counted."""

    def __init__(self, space: DesignSpace, excitation, objective):
        self.space, self.excitation, self.objective = space, excitation, objective
        self.cache: dict = {}

    def __call__(self, u) -> Candidate | None:
        u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
        key = tuple(np.round(u, 14))
        if key not in self.cache:
            self.cache[key] = self._predict(u)
        return self.cache[key]

    def _predict(self, u) -> Candidate | None:
        try:
            device = self.space.device(u)
        except ValueError:
            return None  # e.g. no damping at a corner of the box
        method = predictor_for(device, self.excitation)
        if method is None:
            return None
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                prediction = predict(device, self.excitation, method=method)
            except (ValueError, ArithmeticError):
                return None  # refused beyond its validity, or no Gaussian solution
        if isinstance(device, Assembly):
            return self._assembly_candidate(u, device, method, prediction, bool(caught))
        power = self.objective.analytic(prediction, device)
        exceedance = prediction.stroke_exceedance
        if exceedance is None and method.name in GAUSSIAN_DISPLACEMENT:
            exceedance = float(gaussian_exceedance(device.stroke, prediction.displacement_variance))
        if exceedance is None or not math.isfinite(power):
            return None
        return Candidate(
            u=u,
            values=self.space.values(u),
            power=power,
            exceedance=float(exceedance),
            method=method.name,
            input_power=float(prediction.c_eq * prediction.velocity_variance),
            warned=bool(caught),
            passage_prediction=partial(
                predicted_first_passage,
                prediction,
                method,
                device.stroke,
                exceedance,
                device,
                self.excitation,
            ),
        )

    def _assembly_candidate(self, u, device, method, prediction, warned) -> Candidate | None:
        """An assembly's candidate: the objective over its transducers, the budget's worst
        coordinate, the dissipated power as the input (they balance); no first passage."""
        power = self.objective.analytic(prediction, device)
        exceedance = self.space.budget.predicted(prediction)
        if not (math.isfinite(power) and math.isfinite(exceedance)):
            return None
        return Candidate(
            u=u,
            values=self.space.values(u),
            power=power,
            exceedance=exceedance,
            method=method.name,
            input_power=float(prediction.power_dissipated),
            warned=warned,
        )


def predicted_first_passage(
    prediction, method, stroke: float, exceedance: float, device=None, excitation=None
) -> float:
    """E[tau] (s) to |z| > ``stroke`` from a stationary start; NaN if not Gaussian.

    Vanmarcke's hazard with the bandwidth of the linear(ised) oscillator
    (m, c_eq, k_eq = k + 3 k3 E[z^2], statistical linearisation) under
    ``excitation`` when both ``device`` and ``excitation`` are given and
    k_eq > 0, else Poisson crossings at Rice's rate.
    """
    if method.name not in GAUSSIAN_RESPONSE or prediction.displacement_variance is None:
        return math.nan
    if prediction.tones is not None or not getattr(excitation, "is_gaussian", True):
        return math.nan  # a sinusoid's or a non-Gaussian input's crossings are not Rice's
    z2, v2 = float(prediction.displacement_variance), float(prediction.velocity_variance)
    rate = float(outcrossing_rate(z2, 0.0, v2, stroke))
    k_eq = None if device is None else device.k + 3.0 * device.k3 * z2
    if rate > 0 and excitation is not None and k_eq is not None and k_eq > 0 and z2 > 0:
        q = spectral_bandwidth(mechanical_block(device.m, float(prediction.c_eq), k_eq), excitation)
        rate = float(vanmarcke_hazard(rate, z2, stroke, q))
    return (1.0 - exceedance) / rate if rate > 0 else math.inf


def meets(c: Candidate, budget: float, min_first_passage: float | None, limit=None) -> bool:
    """The prediction meets the budget and, where it predicts them, the first-passage bounds
    (``limit``: a :class:`~randvib.harvester_design.constraints.FirstPassageLimit`)."""
    if c.exceedance > budget:
        return False
    if limit is not None and not limit.admits(c):
        return False
    return min_first_passage is None or not c.first_passage < min_first_passage


def analytic_search(
    space: DesignSpace,
    excitation,
    budget: float,
    objective,
    runners_up: int = 2,
    min_first_passage: float | None = None,
    limit=None,
):
    """Maximise the predicted objective over the box with ``P(|z| > stroke) <= budget``.

    Parameters
    ----------
    space : DesignSpace
        The varied parameters; its harvester carries the stroke.
    excitation : Excitation
    budget : float
        The largest allowed exceedance eps.
    objective : Objective
    runners_up : int
        How many other distinct good candidates to return.
    min_first_passage : float, optional
        T (s): also require a predicted mean first passage to the stroke of
        at least T where the method predicts one (:func:`predicted_first_passage`).
    limit : FirstPassageLimit, optional
        Also require a predicted P(|z| reaches the stroke within T) <= P
        (:mod:`randvib.harvester_design.constraints`).

    Returns
    -------
    SearchOutcome

    Raises
    ------
    InfeasibleBudget
        No predicted device meets the budget (says the best reachable exceedance and
        where) or the first-passage bound (says the longest predicted first passage).
    """
    evaluate = Evaluator(space, excitation, objective)
    per = GRID.get(space.dimension, GRID_MANY)
    grid = [c for c in map(evaluate, space.grid(per)) if c is not None]
    unpredicted = [u for u in space.grid(COARSE) if evaluate(u) is None and space.builds(u)]
    if not grid:
        raise NothingPredicted(
            "no analytic method predicts any device in the ranges given (every point was refused)"
        )
    feasible = sorted((c for c in grid if meets(c, budget, min_first_passage, limit)),
                      key=lambda c: -c.power)  # fmt: skip
    if not feasible:
        within = [c for c in grid if c.exceedance <= budget]
        if not within:
            best = _least_exceedance(evaluate, min(grid, key=lambda c: c.exceedance), space)
            if best.exceedance > budget:
                where = ", ".join(f"{k} = {v:.6g}" for k, v in best.values.items())
                raise InfeasibleBudget(
                    f"the stroke budget {_budget_event(space)} <= `exceedance` = {budget:g} "
                    f"cannot be met in the ranges given (`vary`): the best reachable exceedance "
                    f"is {best.exceedance:.3g} (at {where})"
                )
            within = [best]
        feasible = [c for c in within if meets(c, budget, min_first_passage, limit)]
        if not feasible and limit is not None and not any(map(limit.admits, within)):
            raise InfeasibleBudget(limit.refusal(within, space.harvester.stroke))
        if not feasible:
            feasible = [_longest_first_passage(evaluate, within, budget, min_first_passage, space)]
    scale = feasible[0].power
    if not scale > 0.0:  # the local search divides by it: nothing to maximise
        raise ValueError(
            "the objective's power is 0 at every feasible point of the ranges given (a device "
            "without electrical damping, c_e = 0, whose `vary` chooses neither c_e nor a "
            "coupling's parameters harvests nothing): give c_e or a coupling, or vary c_e"
        )
    optima = []
    for start in feasible[:STARTS]:
        found = _local(evaluate, start, budget, scale, min_first_passage, limit)
        if all(np.max(np.abs(found.u - o.u)) > SAME_POINT for o in optima):
            optima.append(found)
    optima.sort(key=lambda c: -c.power)
    others = optima[1:]
    for c in feasible:
        if len(others) >= runners_up:
            break
        if all(np.max(np.abs(c.u - o.u)) > 3 * SAME_POINT for o in [optima[0], *others]):
            others.append(c)
    return SearchOutcome(optima[0], others[:runners_up], len(evaluate.cache), grid, unpredicted)


def _local(
    evaluate, start: Candidate, budget: float, scale: float, min_first_passage=None, limit=None
) -> Candidate:
    """SLSQP from ``start``; the better of the start and the end (both feasible)."""
    log_budget = math.log(budget)
    constraints = [{"type": "ineq", "fun": lambda u: margin(u)}]
    if limit is not None:
        constraints.append({"type": "ineq", "fun": lambda u: limit.margin(evaluate(u))})
    if min_first_passage is not None:
        log_time = math.log(min_first_passage)

        def passage_margin(u):
            c = evaluate(u)
            if c is None:
                return -50.0
            if math.isnan(c.first_passage):
                return 0.0  # not predicted here: left to Monte Carlo
            return min(math.log(max(c.first_passage, TINY)) - log_time, 50.0)

        constraints.append({"type": "ineq", "fun": passage_margin})

    def power(u):
        c = evaluate(u)
        return 0.0 if c is None else -c.power / scale

    def margin(u):
        c = evaluate(u)
        return -50.0 if c is None else log_budget - math.log(max(c.exceedance, TINY))

    result = optimize.minimize(
        power,
        start.u,
        method="SLSQP",
        bounds=[(0.0, 1.0)] * len(start.u),
        constraints=constraints,
        options={"ftol": 1e-12, "maxiter": 200, "eps": 1e-7},
    )
    end = evaluate(result.x)
    if end is None or not meets(end, budget * (1 + 1e-8), _relaxed(min_first_passage), limit):
        # SLSQP may stop a hair outside the budget (or on an unpredicted point): the
        # feasible point nearest to it on the segment from the start, by bisection
        lo, hi = 0.0, 1.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            c = evaluate(start.u + mid * (result.x - start.u))
            if c is not None and meets(c, budget, min_first_passage, limit):
                lo = mid
            else:
                hi = mid
        end = evaluate(start.u + lo * (result.x - start.u))
    return end if end is not None and end.power > start.power else start


def _relaxed(min_first_passage):
    """The first-passage bound less SLSQP's tolerance on the constraint (1e-8 relative)."""
    return None if min_first_passage is None else min_first_passage * (1 - 1e-8)


def _longest_first_passage(evaluate, within, budget, min_first_passage, space) -> Candidate:
    """The longest predicted first passage among ``within`` and a local ascent from it under
    the exceedance budget, if it meets ``min_first_passage``; else InfeasibleBudget."""
    start = max(within, key=lambda c: c.first_passage)
    log_budget = math.log(budget)

    def objective(u):
        c = evaluate(u)
        return 50.0 if c is None else -math.log(max(c.first_passage, TINY))

    def margin(u):
        c = evaluate(u)
        return -50.0 if c is None else log_budget - math.log(max(c.exceedance, TINY))

    result = optimize.minimize(
        objective, start.u, method="SLSQP", bounds=[(0.0, 1.0)] * space.dimension,
        constraints=[{"type": "ineq", "fun": margin}],
    )  # fmt: skip
    end = evaluate(result.x)
    best = start
    if end is not None and end.exceedance <= budget and end.first_passage > start.first_passage:
        best = end
    if best.first_passage >= min_first_passage:
        return best  # the grid missed it: the search goes on from there
    where = ", ".join(f"{k} = {v:.6g}" for k, v in best.values.items())
    raise InfeasibleBudget(
        f"the first-passage constraint E[tau] >= {min_first_passage:g} s "
        f"(`min_first_passage`, the mean time to |z| > `stroke` = {space.harvester.stroke:g} m) "
        "cannot be met in the ranges given (`vary`) within the stroke budget: the longest "
        f"predicted is {best.first_passage:.3g} s (at {where})"
    )


def _least_exceedance(evaluate, start: Candidate, space: DesignSpace) -> Candidate:
    """The least predicted exceedance near ``start`` (for the refusal of an infeasible budget)."""

    def objective(u):
        c = evaluate(u)
        return 0.0 if c is None else math.log(max(c.exceedance, TINY))

    result = optimize.minimize(
        objective, start.u, method="L-BFGS-B", bounds=[(0.0, 1.0)] * space.dimension
    )
    end = evaluate(result.x)
    return end if end is not None and end.exceedance < start.exceedance else start


def _budget_event(space) -> str:
    """The budget's event, naming the argument that sets the stroke (``stroke``) for a single
    mass; an assembly's strokes are its coordinates' (:meth:`DesignSpace.budget_words`)."""
    if space.is_assembly:
        return space.budget_words()
    return f"P(|z| > `stroke` = {space.harvester.stroke:g} m)"
