"""What :func:`randvib.simulate_transient` returns: an event's ensemble and its statistics.

:class:`TransientResult` holds, per path, the snapshots of (z, v, circuit
state, peak |z| so far) at the report times and the event's integrals (peak
|z|, int v^2 dt, int x^2 dt), and computes every statistic from them with
its 95 % interval over the independent paths (:mod:`randvib.statistics`):
time-resolved mean squares and powers (:class:`~randvib.statistics.TimeStatistics`),
the energy the event delivers, the distribution of the peak |z| and the
probability of reaching the stroke. Numbers are computed here; tables are
drawn by :mod:`randvib._display`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from randvib import _display, formatting
from randvib.models.event import Enveloped, EventStart
from randvib.models.harvester import Harvester
from randvib.montecarlo import kernel
from randvib.statistics import FirstPassage, Statistic, TimeStatistics, estimate, proportion

#: Quantiles of the peak |z| reported by :meth:`TransientResult.to_dict`.
PEAK_QUANTILES = (0.5, 0.9, 0.99)


@dataclass(frozen=True)
class TransientResult:
    """Monte Carlo ensemble of an event (:func:`randvib.simulate_transient`), SI units.

    Time-resolved statistics are :class:`~randvib.statistics.TimeStatistics`
    over ``times`` (``result.velocity_variance[i]`` is time i's
    :class:`~randvib.statistics.Statistic`); the event's totals are
    :class:`~randvib.statistics.Statistic`. The mean squares are about z = 0
    (the variances for a start at rest, whose mean is 0 by symmetry).

    Attributes
    ----------
    harvester : Harvester
    event : Enveloped
    start : EventStart
    scheme : str
    dt, t_end : float
        Step and end of the window (s).
    seed, first_path : int
    times : ndarray
        Report times (s), on the step grid.
    snapshots : ndarray, shape (n_paths, n_times, 4)
        Per path: z (m), v (m/s), circuit state (A or V; 0 without one),
        peak |z| from t = 0 (m) at each time.
    integrals : ndarray, shape (n_paths, 3)
        Per path: peak |z| over [0, t_end] (m), int v^2 dt, int x^2 dt.
    first_hit : ndarray
        Per path: the first time |z| > stroke (s), -1 where never (or no stroke).
    wall_time : float
        Seconds spent in the compiled loop.
    """

    harvester: Harvester
    event: Enveloped
    start: EventStart
    scheme: str
    dt: float
    t_end: float
    seed: int
    first_path: int
    times: np.ndarray
    snapshots: np.ndarray = field(repr=False)
    integrals: np.ndarray = field(repr=False)
    first_hit: np.ndarray = field(repr=False)
    wall_time: float = 0.0

    @property
    def n_paths(self) -> int:
        return self.snapshots.shape[0]

    def _column(self, index: int) -> np.ndarray:
        return self.snapshots[:, :, index]

    # ------------------------------------------------------- time-resolved
    @property
    def displacement_variance(self) -> TimeStatistics:
        """E[z^2(t)] (m^2) at ``times``."""
        return TimeStatistics.from_paths(self._column(kernel.SNAP_Z) ** 2)

    @property
    def displacement_mean(self) -> TimeStatistics:
        """E[z(t)] (m) at ``times``: 0 from rest, the drift out of a well otherwise."""
        return TimeStatistics.from_paths(self._column(kernel.SNAP_Z))

    @property
    def velocity_variance(self) -> TimeStatistics:
        """E[z'^2(t)] ((m/s)^2) at ``times``."""
        return TimeStatistics.from_paths(self._column(kernel.SNAP_V) ** 2)

    def _powers(self, v2, x2, which: str):
        """Per-path electrical or load power (W) from v^2 and the circuit state's square."""
        h = self.harvester
        if h.has_circuit:
            return getattr(h.electrical, which)(v2, x2)
        fraction = 1.0 if which == "power_electrical" else h.electrical.load_fraction
        return h.c_e * fraction * v2

    @property
    def power_electrical(self) -> TimeStatistics:
        """E[P_e(t)] (W): c_e E[z'^2(t)], or from the circuit state, at ``times``."""
        v2, x2 = self._column(kernel.SNAP_V) ** 2, self._column(kernel.SNAP_X) ** 2
        return TimeStatistics.from_paths(self._powers(v2, x2, "power_electrical"))

    @property
    def power_load(self) -> TimeStatistics | None:
        """E[P_L(t)] (W) into R_L at ``times``; None without a coupling."""
        if self.harvester.electrical is None:
            return None
        v2, x2 = self._column(kernel.SNAP_V) ** 2, self._column(kernel.SNAP_X) ** 2
        return TimeStatistics.from_paths(self._powers(v2, x2, "power_load"))

    @property
    def circuit_mean_square(self) -> TimeStatistics | None:
        """E[i^2(t)] (A^2) or E[V^2(t)] (V^2) of a circuit state; None without one."""
        if not self.harvester.has_circuit:
            return None
        return TimeStatistics.from_paths(self._column(kernel.SNAP_X) ** 2)

    @property
    def stroke_exceedance(self) -> TimeStatistics | None:
        """P(|z(t)| > stroke) at ``times``; None without a stroke."""
        if self.harvester.stroke is None:
            return None
        beyond = np.abs(self._column(kernel.SNAP_Z)) > self.harvester.stroke
        return TimeStatistics.proportions(beyond.astype(float))

    @property
    def stroke_reached(self) -> TimeStatistics | None:
        """P(|z| has exceeded the stroke at some step in [0, t]) at ``times``; None without one."""
        if self.harvester.stroke is None:
            return None
        reached = self._column(kernel.SNAP_PEAK) > self.harvester.stroke
        return TimeStatistics.proportions(reached.astype(float))

    # ------------------------------------------------------------ the event
    def _energies(self, which: str) -> np.ndarray:
        v2 = self.integrals[:, kernel.EVENT_V2]
        x2 = self.integrals[:, kernel.EVENT_X2]
        return self._powers(v2, x2, which)

    @property
    def path_energies(self) -> np.ndarray:
        """Per path, int_0^t_end P_e dt (J) (trapezoid rule): for paired comparisons."""
        return self._energies("power_electrical")

    @property
    def energy_electrical(self) -> Statistic:
        """E[int_0^t_end P_e dt] (J): the energy the event delivers, with its interval."""
        return estimate(self.path_energies)

    @property
    def energy_load(self) -> Statistic | None:
        """The share of :attr:`energy_electrical` reaching R_L (J); None without a coupling."""
        if self.harvester.electrical is None:
            return None
        return estimate(self._energies("power_load"))

    @property
    def peak_displacement(self) -> np.ndarray:
        """Per path, the largest |z| over [0, t_end] (m): the peak's distribution."""
        return self.integrals[:, kernel.EVENT_PEAK].copy()

    def peak_quantiles(self, levels=PEAK_QUANTILES) -> dict:
        """Empirical quantiles of the peak |z| (m), ``{level: value}``."""
        peaks = self.peak_displacement
        return {float(q): float(np.quantile(peaks, q)) for q in levels}

    def peak_exceedance(self, level: float) -> Statistic:
        """P(peak |z| over the event > ``level`` (m)), with its Wilson 95 % interval."""
        return proportion((self.peak_displacement > level).astype(float))

    @property
    def stroke_first_passage(self) -> FirstPassage | None:
        """First time |z| > stroke from t = 0 (:class:`~randvib.statistics.FirstPassage`)."""
        if self.harvester.stroke is None:
            return None
        return FirstPassage.from_times(self.first_hit, self.t_end)

    # ------------------------------------------------------------ presenting
    def _series(self) -> list[tuple[str, TimeStatistics, str]]:
        """(name, TimeStatistics, unit) of every time-resolved statistic this run has."""
        names = (
            "displacement_variance",
            "velocity_variance",
            "power_electrical",
            "power_load",
            "circuit_mean_square",
            "stroke_exceedance",
            "stroke_reached",
        )
        return _display.time_series(self, names)

    def to_frame(self):
        """One row per time: ``time`` (s), each statistic's mean and ``<name>_ci95``."""
        pd = _display.pandas()
        frame = pd.DataFrame({"time": self.times})
        for name, stat, _ in self._series():
            frame[name] = stat.mean
            frame[f"{name}_ci95"] = stat.ci95
            if stat.lower is not None:  # a probability: its Wilson interval's ends
                frame[f"{name}_lower"], frame[f"{name}_upper"] = stat.lower, stat.upper
        return frame

    def to_dict(self) -> dict:
        """JSON-ready: ``times``; each statistic as [[mean, 95 % half-width], ...] over them
        (a probability also as ``<name>_interval``: [[lower, upper], ...], its Wilson
        interval, and ``stroke_reached_event_interval``); ``energy_electrical`` as [mean,
        half-width]; the peak |z|; the run's settings."""
        out = {"times": self.times.tolist()}
        for name, stat, _ in self._series():
            out[name] = stat.to_list()
            if stat.lower is not None:
                out[f"{name}_interval"] = stat.intervals()
        energy = self.energy_electrical
        out["energy_electrical"] = [energy.mean, energy.ci95]
        if self.energy_load is not None:
            out["energy_load"] = [self.energy_load.mean, self.energy_load.ci95]
        peak = estimate(self.peak_displacement)
        out["peak_displacement"] = {
            "mean": [peak.mean, peak.ci95],
            "quantiles": {f"{q:g}": v for q, v in self.peak_quantiles().items()},
        }
        if self.harvester.stroke is not None:
            reached = self.peak_exceedance(self.harvester.stroke)
            out["stroke"] = self.harvester.stroke
            out["stroke_reached_event"] = [reached.mean, reached.ci95]
            out["stroke_reached_event_interval"] = list(reached.interval)
        out.update(
            n_paths=self.n_paths,
            dt=self.dt,
            t_end=self.t_end,
            method=self.scheme,  # as SimulationResult's JSON
            seed=self.seed,
            wall_time=self.wall_time,
            **self.start.to_dict(),
            **self.event.parameters(),
        )
        return out

    def _note(self) -> str:
        energy = self.energy_electrical
        return (
            f"{self.n_paths} paths, dt {self.dt:g} s, {self.scheme}, seed {self.seed}, "
            f"{self.event.name}, start {self.start.describe()}; energy int_0^{self.t_end:g} "
            f"P_e dt = {formatting.estimate(energy.mean, energy.ci95)} J"
        )

    def _table(self):
        return _display.time_rows(
            self.times,
            self._series(),
            lambda stat, i: format(stat[i], ""),  # mean ± half-width, a probability's [lo, hi]
        )

    def __repr__(self) -> str:
        energy = self.energy_electrical
        return (
            f"TransientResult({self.n_paths} paths, {self.times.size} times to {self.t_end:g} s, "
            f"{self.event.name}; energy_electrical = "
            f"{formatting.estimate(energy.mean, energy.ci95)} J)"
        )

    def __str__(self) -> str:
        title = "Monte Carlo transient (mean ± 95 % half-width)"
        return _display.time_table(title, *self._table(), self._note())

    def _repr_html_(self) -> str:
        title = "Monte Carlo transient (mean ± 95 % half-width)"
        return _display.time_html_table(title, *self._table(), self._note())
