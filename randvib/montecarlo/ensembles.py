"""Paired Monte Carlo ensembles: many cases, common random numbers within a group, resumable.

A *case* (:class:`Case`) is one ensemble to simulate: a device under an
excitation from a start, named by its labels (the columns that identify it in
the table). Cases of one *group* run on one seed, so path i of each of them
sees the same Brownian increments (and the same filter states or synthesised
input): ratios and contrasts between them (:meth:`EnsembleResult.paired`,
:meth:`EnsembleResult.paired_ratios`) are estimated path by path, with most
of the noise cancelled. Different groups run on different seeds: their
estimates are independent.

:func:`run_ensembles` simulates every case to the precision of a
:class:`~randvib.montecarlo.sweep.SweepSettings` (min_paths = max_paths for a
fixed size), with the sweep's machinery: local worker processes or a Dask
cluster, and in ``out_dir`` a checksummed record of every finished case (one
JSON row and one ``.npy`` of per-path averages), so that an interrupted run
resumes where it stopped and a corrupted case is named and recomputed
(:class:`~randvib.montecarlo.sweep.PointStore`). A sweep
(:func:`~randvib.montecarlo.sweep.run_sweep`) is the special case of one
device's parameter points, all on one seed.

An *event run* (settings :class:`~randvib.montecarlo.event_cases.EventSettings`,
every case's excitation an :class:`randvib.Enveloped` event) simulates each
case from t = 0 through the event (:func:`randvib.simulate_transient`) and
stores every path's snapshots (:mod:`randvib.montecarlo.event_cases`);
:meth:`EnsembleResult.transient` gives a case's
:class:`~randvib.TransientResult`.

Seeds: the groups are numbered in the order in which their first case comes
(j = 0, 1, ...), and group j runs on the seed ``GROUP_SEEDS * settings.seed + j``:
for fewer than :data:`GROUP_SEEDS` groups, runs with different settings seeds
share no stream.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Hashable, Mapping
from concurrent.futures import Executor
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from randvib._validation import MAX_SEED
from randvib.models.event import Enveloped
from randvib.models.excitation import Excitation, as_excitation
from randvib.models.harvester import Harvester
from randvib.montecarlo import event_cases
from randvib.montecarlo.sweep import PointStore, SweepSettings, run_stored, simulate_to_precision
from randvib.statistics import Statistic, estimate, median_first_passage, paired_ratio

if TYPE_CHECKING:  # pandas is imported where a table is built: a worker process
    import pandas as pd  # imports this module for run_case and never needs it

__all__ = ["GROUP_SEEDS", "Case", "EnsembleResult", "run_ensembles"]

#: Seeds per settings seed: group j of a run with seed s runs on GROUP_SEEDS * s + j.
GROUP_SEEDS = 1000

#: The statistics of every case's row (``NAME`` and ``NAME_ci95``), as
#: :class:`randvib.SimulationResult` gives them; ``displacement_variance`` is
#: NaN for the free mass.
STATISTICS = ("power_electrical", "velocity_variance", "displacement_variance", "mean_abs_velocity")


@dataclass(frozen=True)
class Case:
    """One ensemble of a paired run: a device under an excitation from a start.

    Attributes
    ----------
    labels : mapping of str to str or number
        What the case is, as columns of the result table (for example
        ``{"input": "white", "g": 0.25, "device": "linear"}``). Every case of
        a run has the same label names and its own values.
    device : Harvester
        Scalar parameters; any friction, coupling and potential that
        :func:`randvib.simulate` takes.
    excitation : float, Excitation or Enveloped
        The base acceleration: a white-noise level S ((m/s^2)^2/Hz) or an
        excitation, as :func:`randvib.simulate` takes it; or an event, as
        :func:`randvib.simulate_transient` takes it (an event run).
    group : hashable, optional
        Cases with equal groups run on one seed (common random numbers:
        paired). None: a group of its own.
    initial : "stationary", "rest", "unexcited" or (z0, v0)
        The start of every path (:func:`randvib.simulate`; an event starts
        from "rest", "unexcited" or (z0, v0), :class:`randvib.EventStart`).
    """

    labels: Mapping
    device: Harvester
    excitation: float | Excitation
    group: Hashable = None
    initial: str | tuple = "stationary"

    def __post_init__(self):
        if not isinstance(self.labels, Mapping) or not self.labels:
            raise ValueError(f"`labels` must be a non-empty mapping of names, got {self.labels!r}")
        for name, value in self.labels.items():
            if not isinstance(name, str) or not isinstance(value, str | int | float):
                raise ValueError(
                    f"`labels` must map names (str) to strings or numbers, got {name!r}: {value!r}"
                )
        if not isinstance(self.device, Harvester):
            raise ValueError(f"`device` must be a Harvester, got {type(self.device).__name__}")
        if not isinstance(self.excitation, Enveloped):
            as_excitation(self.excitation)  # a bad level or excitation is refused here, by name

    def key(self, seed: int) -> dict:
        """What this case is, JSON-ready: stored with its result and checked on resume."""
        return _plain({
            "labels": dict(self.labels),
            "seed": seed,
            "device": self.device.parameters(),
            "excitation": self._excitation().parameters(),
            "initial": self.initial,
        })  # fmt: skip

    def _excitation(self):
        if isinstance(self.excitation, Enveloped):
            return self.excitation
        return as_excitation(self.excitation)


def run_case(case: Case, settings: SweepSettings, seed: int, threads: int | None = 1):
    """Simulate one case to the settings' precision: its row of statistics and per-path averages.

    Returns
    -------
    row : dict
        ``NAME`` and ``NAME_ci95`` of :data:`STATISTICS`; with a stroke,
        ``stroke_exceedance`` (and ``_ci95``) and the first passage from the
        start (``first_passage_reached``, ``first_passage_horizon`` (s),
        ``first_passage_mean`` and ``_ci95`` (NaN unless every path reached
        the stroke), ``first_passage_restricted_mean`` and ``_ci95``
        (E[min(tau, t_end)]), ``first_passage_median`` (NaN unless more than
        half did)); then ``n_paths``, ``averaging_time``, ``simulated_time``
        and ``wall_time`` (s).
    per_path : ndarray, shape (n_paths, N_ACC)
        The kernel's per-path averages (:class:`randvib.montecarlo.kernel.PathAverages`).
    """
    started = time.perf_counter()
    result = simulate_to_precision(
        case.device, case.excitation, settings, seed=seed, initial=case.initial, threads=threads
    )
    row = {}
    for name in STATISTICS:
        s = getattr(result, name)
        row[name], row[f"{name}_ci95"] = (math.nan, math.nan) if s is None else (s.mean, s.ci95)
    if case.device.stroke is not None:
        x, first = result.stroke_exceedance, result.stroke_first_passage
        t_end = settings.burn_in + settings.window
        row.update({
            "stroke_exceedance": x.mean, "stroke_exceedance_ci95": x.ci95,
            "first_passage_reached": first.paths_reached,
            "first_passage_horizon": first.horizon,
            "first_passage_mean": math.nan if first.mean is None else first.mean.mean,
            "first_passage_mean_ci95": math.nan if first.mean is None else first.mean.ci95,
            "first_passage_restricted_mean": first.restricted_mean.mean,
            "first_passage_restricted_mean_ci95": first.restricted_mean.ci95,
            "first_passage_median": median_first_passage(result.averages.first_hit_time, t_end),
        })  # fmt: skip
    row.update(
        n_paths=result.n_paths,
        averaging_time=settings.window,
        simulated_time=result.n_paths * (settings.window + settings.burn_in),
        wall_time=time.perf_counter() - started,
    )
    return row, result.per_path


@dataclass
class EnsembleResult:
    """The cases of a paired run, their table and the per-path data behind it.

    Attributes
    ----------
    table : DataFrame
        One row per case, in the order given: its labels, then the
        statistics of :func:`run_case`.
    cases : list of Case
    settings : SweepSettings
    groups : list of int
        The group number j of each case (its seed: ``GROUP_SEEDS * settings.seed + j``).
    per_path : dict
        Case index -> per-path averages, shape (n_paths, N_ACC).
    """

    table: pd.DataFrame
    cases: list = field(repr=False)
    settings: SweepSettings
    groups: list = field(repr=False)
    per_path: dict = field(repr=False)

    def averages(self, index: int):
        """The per-path averages of case ``index`` by name (:class:`~randvib.montecarlo.kernel.PathAverages`)."""
        from randvib.montecarlo.kernel import PathAverages

        self._stationary()
        return PathAverages(self.per_path[index])

    def simulation(self, index: int):
        """Case ``index`` as :func:`randvib.simulate` returned it: its paths' averages and statistics.

        A :class:`~randvib.SimulationResult` of the stored per-path averages
        (no histogram, no recorded paths), with the run's time grid, seed and
        control variates: its statistics, and the zero-mean controls of its
        paths (:meth:`~randvib.SimulationResult.controls`), are those of the case.
        """
        from randvib.montecarlo.options import TimeGrid
        from randvib.montecarlo.results import SimulationResult

        self._stationary()
        case, settings = self.cases[index], self.settings
        excitation = as_excitation(case.excitation)
        grid = TimeGrid.from_times(
            settings.burn_in + settings.window, settings.dt, settings.burn_in
        )
        return SimulationResult(
            harvester=case.device, psd=getattr(excitation, "level", None),
            scheme=settings.scheme, dt=grid.dt, t_end=grid.t_end, burn_in=grid.burn_in,
            seed=GROUP_SEEDS * settings.seed + self.groups[index], first_path=0,
            per_path=self.per_path[index], control_variates=settings.control_variates,
            excitation=excitation,
        )  # fmt: skip

    def transient(self, index: int):
        """Case ``index`` of an event run as :func:`randvib.simulate_transient` returned it.

        A :class:`~randvib.TransientResult` of the stored paths (every
        statistic through the event, the paths' energies for paired ratios).
        """
        if not isinstance(self.settings, event_cases.EventSettings):
            raise ValueError("only the cases of an event run (EventSettings) have a transient")
        seed = GROUP_SEEDS * self.settings.seed + self.groups[index]
        return event_cases.unpack(self.per_path[index], self.cases[index], self.settings, seed)

    def power_samples(self, index: int) -> np.ndarray:
        """Each path's time-averaged electrical power (W) in case ``index``.

        c_e times the path's mean z'^2 (paper Eq. 31), or from a circuit state
        ((R_L + R_C) i^2, V^2 / R_L).
        """
        device, averages = self.cases[index].device, self.averages(index)
        if device.has_circuit:
            return device.electrical.power_electrical(averages.v2, averages.circuit_square)
        return device.c_e * averages.v2

    def find(self, group: int, **labels) -> int:
        """The index of the case of group number ``group`` whose labels include ``labels``.

        Raises
        ------
        ValueError
            None or several cases match.
        """
        want = _plain(labels)
        found = [
            i
            for i, case in enumerate(self.cases)
            if self.groups[i] == group and _plain({k: case.labels.get(k) for k in want}) == want
        ]
        if len(found) != 1:
            raise ValueError(
                f"{len(found)} cases of group {group} have the labels {labels}; need exactly one"
            )
        return found[0]

    def partner(self, index: int, **changes) -> int:
        """The case of the same group as case ``index``, with its labels but for ``changes``."""
        return self.find(self.groups[index], **{**self.cases[index].labels, **changes})

    def paired(self, weights: Mapping[int, float]) -> Statistic:
        """sum_i w_i E[P_e](case i) from the paths the cases share (common random numbers).

        The weighted sum of the cases' per-path powers is formed path by path
        (over the paths all of them have), and its mean and 95 % half-width
        are a :class:`~randvib.statistics.Statistic` (Student t over paths).
        With the run's control variates (``settings.control_variates``) every
        case's zero-mean controls (:meth:`simulation`) join the estimate, in
        the order of ``weights``. The cases must share a group.
        """
        self._one_group(weights)
        n = min(self.per_path[i].shape[0] for i in weights)
        samples = np.zeros(n)
        for i, w in weights.items():
            samples += w * self.power_samples(i)[:n]
        controls = None
        if self.settings.control_variates:
            controls = np.hstack([self.simulation(i).controls()[:n] for i in weights])
        return estimate(samples, controls)

    def paired_ratios(self, **reference) -> pd.DataFrame:
        """Every case's E[P_e] over that of its group's reference case, with a paired 95 % interval.

        The reference of case i is the case of its group whose labels are
        i's with ``reference`` applied (for example ``device="linear"``). The
        ratio of the means and its half-width by the delta method on the
        common paths (:func:`randvib.statistics.paired_ratio`); the reference
        itself has ratio 1 and half-width 0.

        Returns
        -------
        DataFrame
            Columns ``ratio`` and ``ratio_ci95``, indexed like :attr:`table`.
        """
        rows = []
        for i in range(len(self.cases)):
            j = self.partner(i, **reference)
            self._one_group({i: 1.0, j: 1.0})
            n = min(self.per_path[i].shape[0], self.per_path[j].shape[0])
            rows.append(paired_ratio(self.power_samples(i)[:n], self.power_samples(j)[:n]))
        import pandas as pd

        return pd.DataFrame(rows, columns=["ratio", "ratio_ci95"], index=self.table.index)

    def _stationary(self) -> None:
        if isinstance(self.settings, event_cases.EventSettings):
            raise ValueError(
                "the cases of an event run have no time averages: use transient(index), a "
                "randvib.TransientResult (path_energies for paired ratios)"
            )

    def _one_group(self, indices) -> None:
        groups = {self.groups[i] for i in indices}
        if len(groups) != 1:
            raise ValueError(
                f"cases {sorted(indices)} are in groups {sorted(groups)}: only cases of one "
                "group share their paths"
            )


def run_ensembles(
    cases,
    settings: SweepSettings | event_cases.EventSettings | None = None,
    *,
    out_dir=None,
    executor: Executor | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    name: str = "ensembles",
) -> EnsembleResult:
    """Simulate every case, paired within its group; optionally written to and resumed from ``out_dir``.

    Parameters
    ----------
    cases : iterable of Case
        The ensembles, each with its labels and group (see the module
        docstring for the seeds).
    settings : SweepSettings or EventSettings
        Time step, window, burn-in, scheme, paths (a precision target, or
        min_paths = max_paths for a fixed size), the seed of the run and the
        control variates (white noise only); or, for cases under events,
        :class:`~randvib.montecarlo.event_cases.EventSettings` (the window
        from t = 0, step, paths, report times and seed).
    out_dir : path-like, optional
        Folder for ``metadata.json`` and ``points/`` (one JSON row and one
        ``.npy`` per case, with checksums). Finished cases found there are
        loaded, not recomputed; a folder of another run is refused.
    executor : concurrent.futures.Executor, optional
        Where cases run; default: ``workers`` local processes (one: in this
        process, on numba's threads), or the Dask cluster at ``scheduler``.
    progress : bool
        A progress bar over the cases.
    name : str
        The run's name (progress bar, identity of ``out_dir``).

    Returns
    -------
    EnsembleResult
    """
    settings = settings or SweepSettings()
    cases = list(cases)
    if not cases or not all(isinstance(c, Case) for c in cases):
        raise ValueError("`cases` must be a non-empty list of randvib Case objects")
    names = list(cases[0].labels)
    keys = set()
    for case in cases:
        if list(case.labels) != names:
            raise ValueError(
                f"every case needs the labels {names} in this order; one has {list(case.labels)}"
            )
        key = json.dumps(_plain(dict(case.labels)), sort_keys=True)
        if key in keys:
            raise ValueError(f"two cases have the labels {dict(case.labels)}; each needs its own")
        keys.add(key)
        event_cases.check_event_case(case, settings)
    groups = _group_numbers(cases)
    if max(groups) >= GROUP_SEEDS or GROUP_SEEDS * settings.seed + max(groups) > MAX_SEED:
        raise ValueError(
            f"{max(groups) + 1} groups at seed {settings.seed}: at most {GROUP_SEEDS} groups, "
            f"and GROUP_SEEDS * seed + groups at most {MAX_SEED}"
        )
    seeds = [GROUP_SEEDS * settings.seed + j for j in groups]
    events = isinstance(settings, event_cases.EventSettings)
    runner = event_cases.run_event_case if events else run_case
    store = None
    if out_dir is not None:
        identity = {
            "name": name,
            "cases": [case.key(seed) for case, seed in zip(cases, seeds, strict=True)],
            "settings": settings.to_dict(),
        }
        required = ("energy_electrical" if events else "power_electrical", "n_paths")
        store = PointStore(out_dir, identity, required=required, table=None, what="case",
                           columns=settings.columns() if events else None)  # fmt: skip
    rows, per_path = run_stored(
        [(runner, (case, settings, seed)) for case, seed in zip(cases, seeds, strict=True)],
        [case.key(seed) for case, seed in zip(cases, seeds, strict=True)],
        store,
        executor=executor,
        workers=workers,
        scheduler=scheduler,
        progress=progress,
        name=name,
        unit="case",
    )
    import pandas as pd

    table = pd.DataFrame([{**case.labels, **rows[i]} for i, case in enumerate(cases)])
    return EnsembleResult(table, cases, settings, groups, per_path)


def _group_numbers(cases) -> list[int]:
    """Group number of each case: groups numbered in the order of their first case."""
    numbers: dict = {}
    out = []
    for i, case in enumerate(cases):
        key = ("own", i) if case.group is None else ("given", case.group)
        out.append(numbers.setdefault(key, len(numbers)))
    return out


def _plain(value):
    """``value`` JSON-ready and comparable: tuples as lists, numpy numbers as Python ones,
    non-finite floats as their names (NaN is not equal to itself)."""
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)
    return value
