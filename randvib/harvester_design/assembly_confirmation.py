"""Monte Carlo confirmation of an assembly's design candidates: :class:`AssemblyConfirmed`.

Each candidate assembly is simulated by :func:`randvib.simulate` (the
assembly kernel, :mod:`randvib.montecarlo.assembly_simulation`) on one seed:
path i draws from the stream (seed, i) for every candidate, so the base
excitation of path i is common to all of them (common random numbers) and
two candidates' powers are compared path by path
(:class:`~randvib.harvester_design.confirmation.ConfirmedCandidates`). A
candidate runs ``settings.min_paths`` paths, then more in batches (the
streams continued with ``first_path``) until the 95 % half-width of its
objective is ``settings.target_rel_ci`` of it or ``settings.max_paths`` is
reached, as :func:`randvib.montecarlo.sweep.simulate_to_precision` does for
the single mass.

Read per path from the assembly's result: the objective over its
transducers (:meth:`~randvib.harvester_design.objectives.AssemblyObjective.monte_carlo`),
the stroke budget's coordinates
(:meth:`~randvib.harvester_design.assembly_budget.StrokeBudget.simulated`),
every dissipation as the input power (``dissipated_power``), and the
energy-balance control variates under white noise or a shaping filter
(``controls``). No first passage is estimated for assemblies.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from randvib.harvester_design.confirmation import ConfirmedCandidates
from randvib.montecarlo.simulation import simulate
from randvib.statistics import Statistic, estimate

__all__ = ["AssemblyConfirmed"]


class AssemblyConfirmed(ConfirmedCandidates):
    """An assembly's candidates by Monte Carlo with common random numbers.

    Parameters
    ----------
    space : DesignSpace
        Of an assembly, with its stroke budget.
    excitation : Excitation
    goal : AssemblyObjective
    settings : SweepSettings
        Step, window, burn-in, scheme, seed, control variates and the
        precision target (min_paths, max_paths, batch_paths, target_rel_ci).
    progress : bool
        A progress bar per run.
    """

    def __init__(self, space, excitation, goal, settings, progress: bool = False):
        super().__init__(space, excitation, goal)
        self.settings = settings
        self.progress = progress

    def add(self, candidates) -> None:
        new = self.new(candidates)
        for c in new:
            self.where[id(c)] = self._to_precision(self.space.device(c.u))
        self.candidates += new

    def _run(self, assembly, n_paths: int, first_path: int):
        s = self.settings
        return simulate(
            assembly, self.excitation, t_end=s.burn_in + s.window, dt=s.dt, n_paths=n_paths,
            burn_in=s.burn_in, scheme=s.scheme, seed=s.seed, first_path=first_path,
            control_variates=s.control_variates, progress=self.progress,
        )  # fmt: skip

    def _to_precision(self, assembly):
        """The assembly's run, extended in batches until its objective is precise enough."""
        s = self.settings
        batches = [self._run(assembly, s.min_paths, 0)]
        n = s.min_paths
        while True:
            per_path = np.vstack([b.per_path for b in batches])
            result = dataclasses.replace(batches[0], per_path=per_path)
            rel = self._statistic(result, self.goal.monte_carlo(result)).relative_ci95
            if not (rel > s.target_rel_ci) or n >= s.max_paths:
                return result
            # paths needed if the spread stays the same (CI ~ n^-1/2), plus 10 %
            wanted = math.ceil(n * (rel / s.target_rel_ci) ** 2 * 1.1)
            extra = math.ceil(max(wanted - n, s.batch_paths) / s.batch_paths) * s.batch_paths
            extra = min(extra, s.max_paths - n)
            batches.append(self._run(assembly, extra, n))
            n += extra

    def _statistic(self, result, samples) -> Statistic:
        controls = result.controls() if self.settings.control_variates else None
        return estimate(samples, controls)

    def result(self, c):
        """The candidate's Monte Carlo result (an assembly's :func:`randvib.simulate` result)."""
        return self.where[id(c)]

    def _samples(self, c) -> np.ndarray:
        return self.goal.monte_carlo(self.where[id(c)])

    def _controls(self, c):
        """The run's zero-mean control variates per path, or None."""
        return self.where[id(c)].controls() if self.settings.control_variates else None

    def exceedance(self, c) -> Statistic:
        """The budget's coordinate most likely to break it (:class:`StrokeBudget`)."""
        return self.space.budget.simulated(self.where[id(c)])

    def input_power(self, c) -> Statistic:
        """Every dissipation together, path by path (r^T M r S / 4 under white noise)."""
        result = self.where[id(c)]
        return estimate(result.dissipated_power(), self._controls(c))

    def first_passage(self, c):
        """Not estimated for assemblies: None."""
        return None

    def passage(self, c):
        """No first-passage bound for assemblies: None."""
        return None
