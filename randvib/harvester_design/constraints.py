"""A design constraint on end-stop strikes: P(|z| reaches the stroke within T) <= P.

The stroke budget of :func:`randvib.design` bounds the stationary fraction of
time beyond the stroke; a device in service for T seconds needs the
probability of *any* strike in that time, the first passage from the
stationary state. :class:`FirstPassageLimit` is that constraint:

* in the analytic search it is predicted from the candidate's Gaussian answer
  (:func:`randvib.harvester_design.search.predicted_first_passage`: Rice's rate
  with Vanmarcke's clumping, E[tau] = (1 - eps) / h), as
  P_T = 1 - (1 - eps) exp(-h T), and enters SLSQP as the smooth margin
  log P - log P_T; a candidate without a Gaussian prediction is left to
  the confirmation;
* the candidates Monte Carlo confirmed are then checked by the rare-event
  estimate (:func:`randvib.first_passage`, subset simulation): the best
  feasible one, by Monte Carlo power, whose 95 % interval does not lie above
  P is the design. The Gaussian prediction is not trusted alone: at
  1e-4 to 1e-8 a non-Gaussian tail (friction, a stiffening spring) moves it
  by factors (the ``rare-events`` study).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from randvib.harvester_design.search import InfeasibleBudget
from randvib.montecarlo.reliability import ReliabilityResult, first_passage

__all__ = ["FirstPassageLimit"]

#: Probabilities below this are taken as this (log of the margin).
TINY = 1e-300
#: Coefficient of variation of the confirming rare-event estimate.
CONFIRM_COV = 0.2


@dataclass(frozen=True)
class FirstPassageLimit:
    """P(|z| reaches the stroke within ``duration``) <= ``probability``, from the stationary state.

    Attributes
    ----------
    probability : float
        P, in (0, 1).
    duration : float
        T (s), > 0.
    """

    probability: float
    duration: float

    @classmethod
    def checked(cls, probability, duration) -> FirstPassageLimit | None:
        """The limit from :func:`randvib.design`'s arguments (None when neither is given)."""
        if probability is None and duration is None:
            return None
        if probability is None or duration is None:
            raise ValueError(
                "`max_first_passage` and `duration` go together: the probability of reaching "
                "the stroke within the window T"
            )
        ok = isinstance(probability, int | float) and 0.0 < probability < 1.0
        if not ok:
            raise ValueError(f"`max_first_passage` must be in (0, 1), got {probability!r}")
        if not (isinstance(duration, int | float) and math.isfinite(duration) and duration > 0):
            raise ValueError(f"`duration` must be a finite time > 0 (s), got {duration!r}")
        return cls(float(probability), float(duration))

    def predicted(self, c) -> float:
        """P_T of a candidate from its predicted exceedance and mean first passage; NaN if none."""
        eps, tau = c.exceedance, c.first_passage
        if math.isnan(tau) or math.isnan(eps):
            return math.nan
        if math.isinf(tau):
            return eps
        hazard = (1.0 - eps) / tau
        return 1.0 - (1.0 - eps) * math.exp(-hazard * self.duration)

    def admits(self, c) -> bool:
        """Not predicted above the limit (unpredicted candidates are left to the confirmation)."""
        return not self.predicted(c) > self.probability

    def margin(self, c) -> float:
        """log P - log P_T for SLSQP (-50 where nothing is predicted at all, 0 where only P_T is not)."""
        if c is None:
            return -50.0
        p = self.predicted(c)
        if math.isnan(p):
            return 0.0
        return min(math.log(self.probability) - math.log(max(p, TINY)), 50.0)

    def refusal(self, within, stroke) -> str:
        """The InfeasibleBudget message: the least predicted P_T among ``within``."""
        best = min(within, key=lambda c: self.predicted(c))
        where = ", ".join(f"{k} = {v:.6g}" for k, v in best.values.items())
        return (
            f"the first-passage constraint P(|z| reaches {stroke:g} m within {self.duration:g} s) "
            f"<= {self.probability:g} cannot be met in the ranges given within the stroke "
            f"budget: the least predicted is {self.predicted(best):.3g} (at {where})"
        )

    def rejected(self, count: int, last: ReliabilityResult, stroke) -> str:
        """The InfeasibleBudget message when the rare-event estimate rejects every candidate."""
        return (
            f"the first-passage constraint P(|z| reaches {stroke:g} m within {self.duration:g} s) "
            f"<= {self.probability:g} is not met: the rare-event estimate rejects all {count} "
            f"confirmed candidates within the stroke budget (the last: "
            f"{last.probability_first_passage})"
        )

    def estimate(self, device, excitation, seed: int = 0) -> ReliabilityResult:
        """The rare-event estimate of the candidate ``device`` (subset simulation)."""
        return first_passage(
            device, excitation, duration=self.duration, stroke=device.stroke,
            target_cov=CONFIRM_COV, seed=seed, progress=False,
        )  # fmt: skip

    def verdict(self, result: ReliabilityResult) -> bool | None:
        """True: the 95 % interval lies below P; False: above it; None: undetermined."""
        p = result.probability_first_passage
        if p.mean + p.ci95 <= self.probability:
            return True
        if p.mean - p.ci95 > self.probability:
            return False
        return None

    def decide(self, confirmed, chosen, budget, space, excitation, seed: int = 0):
        """The design among Monte Carlo's confirmed candidates: ``chosen`` first, then the
        others that meet the stroke budget by Monte Carlo power; the first the rare-event
        estimate does not reject. Returns (candidate, ReliabilityResult, verdict); raises
        InfeasibleBudget when it rejects them all."""
        others = [c for c in confirmed.candidates
                  if c is not chosen and confirmed.feasible(c, budget)]  # fmt: skip
        ranked = [chosen, *sorted(others, key=lambda c: -confirmed.power(c).mean)]
        found, result, verdict = self.confirm(ranked, lambda c: space.device(c.u), excitation, seed)
        if found is None:
            raise InfeasibleBudget(self.rejected(len(ranked), result, space.harvester.stroke))
        return found, result, verdict

    def confirm(self, ranked, device_of, excitation, seed: int = 0):
        """The first of ``ranked`` candidates the rare-event estimate does not reject.

        Returns
        -------
        (candidate, ReliabilityResult, verdict) or (None, result of the last, False)
        when every candidate is rejected.
        """
        result = None
        for c in ranked:
            result = self.estimate(device_of(c), excitation, seed)
            verdict = self.verdict(result)
            if verdict is not False:
                return c, result, verdict
        return None, result, False
