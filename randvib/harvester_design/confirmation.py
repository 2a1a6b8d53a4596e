"""Monte Carlo judgement of a design's candidates: which meets the budget, which harvests more.

A design confirms its analytic candidates by Monte Carlo with common random
numbers: path i of every candidate sees the same base excitation, so the
difference of two candidates' powers is estimated path by path (paired),
far more precisely than either power. :class:`ConfirmedCandidates` holds the
candidates simulated so far and answers the design's questions from their
per-path samples: is the budget met (:meth:`~ConfirmedCandidates.feasible`),
is one significantly better than another (:meth:`~ConfirmedCandidates.better`),
which is best (:meth:`~ConfirmedCandidates.best`), does Monte Carlo
contradict the analytic choice (:meth:`~ConfirmedCandidates.disagrees`).

How the candidates are simulated is the subclass's: the single mass's
ensembles or record windows (:mod:`randvib.harvester_design.design`), an
assembly's runs (:mod:`randvib.harvester_design.assembly_confirmation`). A
subclass gives ``add``, ``_samples`` (each path's objective power),
``_controls`` (zero-mean control variates per path, or None),
``exceedance``, ``input_power``, ``first_passage`` and ``passage``.
"""

from __future__ import annotations

import math

import numpy as np

from randvib.harvester_design.search import Candidate, Evaluator
from randvib.statistics import Statistic, estimate

__all__ = ["PREDICTION_TOLERANCE", "ConfirmedCandidates", "within"]

#: A prediction further than this fraction (beyond the 95 % interval) from Monte Carlo
#: is off, and Monte Carlo refines: linearisation's error under white noise is within
#: a few per cent (README), so a larger gap means the analytic ranking is not reliable.
PREDICTION_TOLERANCE = 0.02


def within(x: Statistic, budget: float) -> bool:
    """The budget is not significantly exceeded: the 95 % interval reaches down to it (its
    lower end: a proportion's Wilson interval is not symmetric about the mean)."""
    return x.interval[0] <= budget


class ConfirmedCandidates:
    """Candidates simulated with common random numbers: path i is common to all.

    Parameters
    ----------
    space : DesignSpace
    excitation : Excitation
    goal : Objective or AssemblyObjective
    min_first_passage : float, optional
        The design's bound on the mean first-passage time (s), if any.
    """

    def __init__(self, space, excitation, goal, min_first_passage=None):
        self.space, self.excitation, self.goal = space, excitation, goal
        self.min_first_passage = min_first_passage
        self.candidates: list = []
        self.where: dict = {}  # candidate id -> where its run is

    def point(self, u) -> Candidate | None:
        """A candidate at ``u``: predicted where a method takes it, else unpredicted (nan)."""
        known = Evaluator(self.space, self.excitation, self.goal)(u)
        if known is not None:
            return known
        try:
            self.space.device(u)
        except ValueError:
            return None
        return Candidate(u, self.space.values(u), math.nan, math.nan, "none", math.nan)

    def new(self, candidates) -> list:
        """The candidates not simulated yet (a point already simulated is not run twice)."""
        return [
            c for c in candidates if all(np.max(np.abs(c.u - o.u)) > 1e-9 for o in self.candidates)
        ]

    def power(self, c) -> Statistic:
        return estimate(self._samples(c), self._controls(c))

    def feasible(self, c, budget: float) -> bool:
        """Monte Carlo rejects neither the stroke budget nor the first-passage bound."""
        return within(self.exceedance(c), budget) and self.passage(c) is not False

    def difference(self, a, b) -> Statistic:
        """Power of ``a`` minus that of ``b`` on their common paths (paired, W)."""
        x, y = self._samples(a), self._samples(b)
        n = min(len(x), len(y))
        controls = None
        if self._controls(a) is not None:
            controls = np.hstack([self._controls(a)[:n], self._controls(b)[:n]])
        return estimate(x[:n] - y[:n], controls)

    def best(self, budget: float, among) -> Candidate:
        """The highest Monte Carlo power among those the budget does not reject.

        A candidate is rejected when its Monte Carlo exceedance is significantly
        above the budget (the 95 % interval lies above it): an optimum on the
        budget's boundary has an estimate on either side of it by chance. If
        every candidate is rejected, the one with the least exceedance.
        """
        feasible = [c for c in among if self.feasible(c, budget)]
        if not feasible:
            return min(among, key=lambda c: self.exceedance(c).mean)
        return max(feasible, key=lambda c: self.power(c).mean)

    def disagrees(self, best, candidates, budget: float) -> bool:
        """Monte Carlo contradicts the analytic choice: the optimum is significantly beyond
        the budget, its prediction lies outside its Monte Carlo interval by more than
        :data:`PREDICTION_TOLERANCE`, or another candidate is significantly better (paired
        95 % interval above 0)."""
        if not self.feasible(best, budget):
            return True
        power = self.power(best)
        if abs(power.mean - best.power) > power.ci95 + PREDICTION_TOLERANCE * best.power:
            return True  # the predictor is off here: its ranking is not to be trusted
        return any(self.better(c, best, budget) for c in candidates if c is not best)

    def better(self, a, b, budget: float) -> bool:
        """``a`` meets the budget and harvests significantly more than ``b`` on the common
        paths (paired 95 % interval above 0, and above rounding: 1e-9 of the power)."""
        if not self.feasible(a, budget):
            return False
        d = self.difference(a, b)
        return d.mean - d.ci95 > 1e-9 * abs(self.power(b).mean)
