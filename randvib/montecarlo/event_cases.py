"""Event cases of the paired-ensemble runner: one transient ensemble per case, stored and resumed.

:func:`randvib.run_ensembles` given :class:`EventSettings` runs each case
(a device under an :class:`randvib.Enveloped` event, from the case's start)
with :func:`randvib.simulate_transient` instead of the stationary
simulation, on the case's group seed: the devices of a group see the same
base acceleration path by path (paired). What the runner stores per case is
every path's data of the :class:`~randvib.montecarlo.transient_results.TransientResult`
in one array (:func:`pack`): the snapshots at the report times, the event's
integrals and the first time the stroke was exceeded, so that a resumed run
rebuilds the same result to the last bit (:func:`unpack`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from randvib._validation import MAX_SEED, check_int, check_positive
from randvib.models.event import Enveloped, EventStart
from randvib.montecarlo import kernel
from randvib.montecarlo.options import TimeGrid
from randvib.montecarlo.transient import simulate_transient, snapshot_steps
from randvib.montecarlo.transient_results import TransientResult

__all__ = ["EventSettings", "pack", "run_event_case", "unpack"]


@dataclass(frozen=True)
class EventSettings:
    """How each case of an event run is simulated (:func:`randvib.simulate_transient`).

    Attributes
    ----------
    t_end : float
        End of the simulated window from t = 0 (s); the event's energy is
        integrated over [0, t_end].
    dt : float
        Time step (s).
    n_paths : int
        Paths per case (a fixed size), >= 2.
    times : tuple of float, optional
        Report times (s) of the time-resolved statistics; None: 51 on [0, t_end].
    scheme : str
        Integrator name.
    seed : int
        The run's seed: group j runs on ``GROUP_SEEDS * seed + j``.
    """

    t_end: float
    dt: float
    n_paths: int
    times: tuple | None = None
    scheme: str = "heun"
    seed: int = 0

    def __post_init__(self):
        check_positive("t_end", self.t_end, "s")
        check_positive("dt", self.dt, "s")
        check_int("n_paths", self.n_paths, 2)
        check_int("seed", self.seed, 0, MAX_SEED)
        if self.times is not None:
            times = tuple(float(t) for t in np.atleast_1d(np.asarray(self.times, dtype=float)))
            object.__setattr__(self, "times", times)
        self.snapshot_steps()  # times outside [0, t_end] or on one step are refused here

    def snapshot_steps(self) -> np.ndarray:
        """The step indices of the report times (:func:`randvib.montecarlo.transient.snapshot_steps`)."""
        grid = TimeGrid.from_times(self.t_end, self.dt, 0.0)
        return snapshot_steps(self.times, grid.dt, grid.n_steps)

    def columns(self) -> int:
        """Columns of a case's per-path array (:func:`pack`)."""
        return self.snapshot_steps().size * kernel.N_SNAP + kernel.N_EVENT + 1

    def to_dict(self) -> dict:
        """JSON-ready values (a stored run's identity)."""
        return {
            "kind": "event",
            "t_end": self.t_end,
            "dt": self.dt,
            "n_paths": self.n_paths,
            "times": None if self.times is None else list(self.times),
            "method": self.scheme,
            "seed": self.seed,
        }


def run_event_case(case, settings: EventSettings, seed: int, threads: int | None = 1):
    """Simulate one event case: its row and every path's data (:func:`pack`).

    Returns
    -------
    row : dict
        ``energy_electrical`` and ``_ci95`` (J, E[int_0^t_end P_e dt]); with a
        stroke, ``stroke_reached_event`` and ``_ci95`` (P(peak |z| > stroke));
        then ``n_paths``, ``simulated_time`` and ``wall_time`` (s).
    per_path : ndarray, shape (n_paths, settings.columns())
    """
    started = time.perf_counter()
    result = simulate_transient(
        case.device, case.excitation, t_end=settings.t_end, dt=settings.dt,
        n_paths=settings.n_paths, times=settings.times, start=case.initial,
        scheme=settings.scheme, seed=seed, threads=threads, progress=False,
    )  # fmt: skip
    energy = result.energy_electrical
    row = {"energy_electrical": energy.mean, "energy_electrical_ci95": energy.ci95}
    if case.device.stroke is not None:
        reached = result.peak_exceedance(case.device.stroke)
        row.update(stroke_reached_event=reached.mean, stroke_reached_event_ci95=reached.ci95)
    row.update(
        n_paths=result.n_paths,
        simulated_time=result.n_paths * result.t_end,
        wall_time=time.perf_counter() - started,
    )
    return row, pack(result)


def pack(result: TransientResult) -> np.ndarray:
    """Every path's snapshots, event integrals and first-hit time, one row per path."""
    n = result.n_paths
    return np.hstack(
        [result.snapshots.reshape(n, -1), result.integrals, result.first_hit.reshape(n, 1)]
    )


def unpack(per_path: np.ndarray, case, settings: EventSettings, seed: int) -> TransientResult:
    """The :class:`~randvib.montecarlo.transient_results.TransientResult` of a packed case."""
    steps = settings.snapshot_steps()
    grid = TimeGrid.from_times(settings.t_end, settings.dt, 0.0)
    n_snap = steps.size * kernel.N_SNAP
    n = per_path.shape[0]
    return TransientResult(
        harvester=case.device, event=case.excitation,
        start=EventStart.of(case.initial, case.device), scheme=settings.scheme,
        dt=grid.dt, t_end=grid.n_steps * grid.dt, seed=seed, first_path=0,
        times=steps * grid.dt,
        snapshots=per_path[:, :n_snap].reshape(n, steps.size, kernel.N_SNAP),
        integrals=per_path[:, n_snap : n_snap + kernel.N_EVENT],
        first_hit=per_path[:, -1],
    )  # fmt: skip


def check_event_case(case, settings) -> None:
    """Refuse a stationary case in an event run, an event case in a stationary one, and an
    event case whose ``initial`` is not an event's start."""
    is_event = isinstance(case.excitation, Enveloped)
    if is_event != isinstance(settings, EventSettings):
        raise ValueError(
            f"case {dict(case.labels)} has "
            + ("an event (Enveloped)" if is_event else "a stationary excitation")
            + f" but the settings are {type(settings).__name__}: events run with "
            "randvib.EventSettings, stationary excitations with randvib.SweepSettings"
        )
    if is_event:
        try:
            EventStart.of(case.initial, case.device)
        except ValueError:
            raise ValueError(
                f"case {dict(case.labels)}: an event starts from `initial` 'rest', "
                f"'unexcited' or a state (z0, v0); got {case.initial!r}"
            ) from None
