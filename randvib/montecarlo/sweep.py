"""Precision-driven Monte Carlo sweeps over device and excitation parameters.

A sweep evaluates a list of parameter points (any keys that
:meth:`randvib.Harvester.updated` accepts, plus ``psd``). At every point it
adds independent paths in batches until the 95 % confidence half-width of the
expected electrical power falls below a target relative precision, and it
records the analytic predictions beside the Monte Carlo estimates.

Design choices a careful user expects:

* **Common random numbers.** Every point uses the same seed, so path *i* sees
  the same Brownian increments at every point; differences between points (for
  example the Duffing-Coulomb interaction contrast) are then estimated path by
  path with most of the noise cancelled.
* **Control variates.** Each path also integrates the friction-free device
  with the same noise, whose stationary E[v^2] = S m / (4c) and E[z^2] (Gibbs)
  are exact, and carries the Ito integral and energy change of the energy
  balance; see :meth:`randvib.montecarlo.results.SimulationResult.controls`.
* **Incremental, resumable output.** Each finished point is written at once
  (one JSON row and one ``.npy`` of per-path powers, each by atomic rename);
  the CSV table is regenerated from them. An interrupted sweep resumes without
  recomputing finished points; a folder holding a different sweep is refused.
* **Any executor.** Points run on a ``concurrent.futures.Executor``: local
  processes by default, or a Dask distributed cluster.
"""

from __future__ import annotations

import dataclasses
import functools
import io
import itertools
import json
import math
import os
import time
import warnings
from collections.abc import Iterable, Mapping
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from randvib._io import (
    atomic_write_bytes,
    atomic_write_text,
    dumps,
    finite_json,
    prepare_output_dir,
    sha256,
    unlock_folder,
)
from randvib._processes import (
    WorkerPool,
    WorkerProcessWarning,
    caller_stacklevel,
    why_no_processes,
    worker_start,
)
from randvib._progress import progress_bar
from randvib._validation import MAX_SEED, check_int, check_positive
from randvib.analytic.prediction import METHODS, predict
from randvib.models.harvester import Harvester
from randvib.statistics import estimate

if TYPE_CHECKING:  # pandas is imported where a table is built: a sweep's worker
    import pandas as pd  # process imports this module and never needs it (0.7 CPU-s)

STATISTICS = ("power_electrical", "velocity_variance", "displacement_variance", "mean_abs_velocity")


def cartesian(**axes) -> list[dict]:
    """All combinations of the given parameter values, as a list of points.

    >>> cartesian(psd=[1.0, 0.5], fc=[0.0, 0.01])  # doctest: +NORMALIZE_WHITESPACE
    [{'psd': 1.0, 'fc': 0.0}, {'psd': 1.0, 'fc': 0.01},
     {'psd': 0.5, 'fc': 0.0}, {'psd': 0.5, 'fc': 0.01}]
    """
    names = list(axes)
    values = []
    for name in names:
        vals = np.atleast_1d(np.asarray(axes[name], dtype=float)).tolist()
        if not vals:
            raise ValueError(f"grid axis `{name}` is empty; give at least one value")
        values.append(vals)
    return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*values)]


#: Smallest target relative half-width: 1e-6 needs (2 CV / 1e-6)^2 = 4e12 CV^2 paths, far
#: beyond any max_paths; below it a target is a typing error (1e-300), not a precision.
MIN_TARGET_REL_CI = 1e-6


@dataclass(frozen=True)
class SweepSettings:
    """How each point is simulated.

    Attributes
    ----------
    dt : float
        Time step (s).
    window : float
        Averaging time per path (s), after ``burn_in``.
    burn_in : float
        Discarded initial time per path (s).
    scheme : str
        Integrator name (:data:`randvib.montecarlo.integrators.INTEGRATORS`).
    target_rel_ci : float
        Stop adding paths when the relative 95 % half-width of E[P_e] is at or
        below this (e.g. 0.005 for 0.5 %).
    min_paths, max_paths, batch_paths : int
        First batch size, cap on paths per point, and granularity of batches.
    seed : int
        Common seed of every point (common random numbers).
    control_variates : bool
        Use the control variates where they hold: the energy balance's under
        white noise or a filtered spectrum, and under white noise with a
        viscous c_e the friction-free companion integrated alongside; plain
        means under a synthesised or recorded input.
    """

    dt: float = 1e-4
    window: float = 2.0
    burn_in: float = 0.5
    scheme: str = "heun"
    target_rel_ci: float = 0.005
    min_paths: int = 32
    max_paths: int = 4096
    batch_paths: int = 32
    seed: int = 0
    control_variates: bool = True

    def __post_init__(self):
        check_positive("dt", self.dt, "s")
        check_positive("window", self.window, "s")
        if not (np.isfinite(self.burn_in) and self.burn_in >= 0):
            raise ValueError(f"`burn_in` must be >= 0 s, got {self.burn_in!r}")
        if not (np.isfinite(self.target_rel_ci) and self.target_rel_ci >= MIN_TARGET_REL_CI):
            raise ValueError(
                f"`target_rel_ci` must be >= {MIN_TARGET_REL_CI:g} (the 95 % half-width over the "
                f"power; a mean over n paths reaches about 2 CV / sqrt(n)), got "
                f"{self.target_rel_ci!r}"
            )
        check_int("min_paths", self.min_paths, 8)
        check_int("batch_paths", self.batch_paths, 1)
        check_int("max_paths", self.max_paths, self.min_paths)
        check_int("seed", self.seed, 0, MAX_SEED)

    def to_dict(self) -> dict:
        """The settings as JSON-ready values, with the integrator under its JSON key ``method``.

        Sweep folders and study metadata name the integrator ``method``; the key
        is kept so that existing result folders keep their identity (resume).
        """
        out = asdict(self)
        return {("method" if k == "scheme" else k): v for k, v in out.items()}


def validate_points(base: Harvester, points: Iterable[Mapping]) -> list[dict]:
    """Check every point's names and values up front; return plain dicts."""
    points = [dict(p) for p in points]
    if not points:
        raise ValueError("the sweep grid is empty; give at least one point")
    for p in points:
        if "psd" not in p:
            raise ValueError(f"every point needs `psd`; got {p}")
        check_positive("psd", p["psd"], "(m/s^2)^2/Hz")
        base.updated(**{k: v for k, v in p.items() if k != "psd"})  # raises on bad names/values
    return points


def point_device(base: Harvester, point: Mapping) -> Harvester:
    return base.updated(**{k: v for k, v in point.items() if k != "psd"})


def _analytic(device: Harvester, psd: float) -> dict:
    out = {}
    for name, method in METHODS.items():
        if method.reference:  # too slow to run at every sweep point
            continue
        if method.rectifier and not device.is_rectified:  # a diode bridge's method only
            continue
        try:
            out[f"{name}_power"] = float(predict(device, psd, name).power_electrical)
        except (ValueError, NotImplementedError):
            out[f"{name}_power"] = float("nan")
    return out


def simulate_to_precision(
    device: Harvester,
    excitation,
    settings: SweepSettings,
    *,
    seed: int,
    initial="stationary",
    threads: int | None = None,
):
    """One ensemble simulated to the settings' precision, in batches of paths.

    The first batch has ``settings.min_paths`` paths; batches follow (path
    streams continuing the ensemble: ``first_path`` = the paths so far) until
    the 95 % half-width of E[P_e] is at most ``settings.target_rel_ci`` of it
    or ``settings.max_paths`` is reached (min_paths = max_paths: a fixed size).

    Parameters
    ----------
    device : Harvester
    excitation : float or Excitation
        As :func:`randvib.simulate` takes it.
    settings : SweepSettings
    seed : int
        The ensemble's seed: path i is stream (seed, i).
    initial : "stationary", "rest" or (z0, v0)
        The start of every path (:func:`randvib.simulate`).
    threads : int, optional
        numba threads (default: as set).

    Returns
    -------
    SimulationResult
        Of all the batches' paths.
    """
    from randvib.montecarlo.simulation import simulate

    # the controls where they hold: the energy balance's under white noise or a shaping
    # filter (Brownian increments), the companion's exact moments under white noise and
    # a viscous c_e only (no circuit state, no bridge); elsewhere plain means
    white = getattr(excitation, "is_white", True)
    filtered = white or excitation.shaping_filter() is not None
    controls = settings.control_variates and filtered
    kw = dict(
        t_end=settings.burn_in + settings.window,
        dt=settings.dt,
        burn_in=settings.burn_in,
        scheme=settings.scheme,
        seed=seed,
        initial=initial,
        companion=controls and white and not (device.has_circuit or device.is_rectified),
        control_variates=controls,
        threads=threads,
        progress=False,
    )
    batches = [simulate(device, excitation, n_paths=settings.min_paths, first_path=0, **kw)]
    n = settings.min_paths
    while True:
        per_path = np.vstack([b.per_path for b in batches])
        result = dataclasses.replace(batches[0], per_path=per_path)
        rel = result.power_electrical.relative_ci95
        if not (rel > settings.target_rel_ci) or n >= settings.max_paths:
            return result
        # paths needed if the spread stays the same (CI ~ n^-1/2), plus 10 %
        # (a target far below reach asks for max_paths: the ratio's square would overflow)
        factor = min(rel / settings.target_rel_ci, math.sqrt(settings.max_paths / n) * 2.0)
        wanted = math.ceil(n * factor**2 * 1.1)
        extra = max(wanted - n, settings.batch_paths)
        extra = math.ceil(extra / settings.batch_paths) * settings.batch_paths
        extra = min(extra, settings.max_paths - n)
        batches.append(simulate(device, excitation, n_paths=extra, first_path=n, **kw))
        n += extra


def run_point(base: Harvester, point: Mapping, settings: SweepSettings, threads: int | None = 1):
    """Simulate one point to the target precision (:func:`simulate_to_precision`).

    Returns
    -------
    row : dict
        Parameters, analytic predictions, estimates with ci95, paths, times.
    per_path : ndarray, shape (n_paths, n_columns)
        Per-path accumulators (:mod:`randvib.montecarlo.kernel` columns) for paired
        comparisons between points.
    """
    device = point_device(base, point)
    psd = float(point["psd"])
    started = time.perf_counter()
    result = simulate_to_precision(device, psd, settings, seed=settings.seed, threads=threads)
    row = {**{k: float(v) for k, v in point.items()}, **_analytic(device, psd)}
    for name in STATISTICS:
        s = getattr(result, name)
        row[name] = s.mean
        row[f"{name}_ci95"] = s.ci95
    row.update(
        n_paths=result.n_paths,
        averaging_time=settings.window,
        simulated_time=result.n_paths * (settings.window + settings.burn_in),
        wall_time=time.perf_counter() - started,
    )
    return row, result.per_path


# ------------------------------------------------------------------ executors
#: Seconds to wait for a Dask scheduler to answer.
SCHEDULER_TIMEOUT = 10


def make_executor(workers: int | None = None, scheduler: str | None = None, initializer=None):
    """An executor and a closer: local processes, or a Dask cluster at ``scheduler``.

    ``initializer`` runs once in each local worker process (not on Dask).
    """
    if scheduler is not None:
        try:
            from distributed import Client
        except ImportError:  # pragma: no cover - depends on the environment
            raise ValueError(
                "`scheduler` needs Dask distributed: pip install 'randvib[distributed]'"
            ) from None
        try:
            # a short connect timeout: a wrong address fails in seconds, not after 30 s
            client = Client(scheduler, timeout=SCHEDULER_TIMEOUT)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:
            raise ValueError(
                f"`scheduler` {scheduler!r}: cannot connect to a Dask scheduler there within "
                f"{SCHEDULER_TIMEOUT} s ({type(exc).__name__}: {str(exc).splitlines()[0]})"
            ) from None
        return client.get_executor(pure=False), client.close
    workers = os.cpu_count() or 1 if workers is None else check_int("workers", workers, 1)
    if workers == 1:
        return None, lambda: None
    reason = why_no_processes()
    if reason is not None:  # an unguarded script: its workers would run it again
        warnings.warn(
            f"running in this process, not {workers} worker processes: {reason}",
            WorkerProcessWarning,
            stacklevel=caller_stacklevel(),
        )
        return None, lambda: None
    # spawn, not fork: numba's OpenMP threading layer may already be running
    # in this process, and forking it is unsafe (the child aborts)
    import multiprocessing

    pool = WorkerPool(
        max_workers=workers,
        mp_context=multiprocessing.get_context("spawn"),
        initializer=functools.partial(worker_start, os.getpid(), initializer),
    )
    return pool, functools.partial(_close_pool, pool)


def _close_pool(pool: ProcessPoolExecutor) -> None:
    """Shut the pool down; after Ctrl-C (or any error) do not wait for running points."""
    import sys

    if sys.exc_info()[0] is not None:
        # the points in flight are lost anyway: end their workers now
        # (ProcessPoolExecutor has no public way to)
        for process in list(getattr(pool, "_processes", {}).values()):
            process.terminate()
    pool.shutdown(cancel_futures=True)


# ------------------------------------------------------------------ sweep
@dataclass
class SweepResult:
    """Rows of a finished sweep and the per-path data behind them."""

    table: pd.DataFrame
    settings: SweepSettings
    points: list = field(repr=False)
    per_path: dict = field(repr=False)  # point index -> per-path accumulators

    def power_samples(self, index: int, c_e: float) -> np.ndarray:
        """c_e times each path's mean v^2 at point ``index``: per-path E[P_e] (W)."""
        from randvib.montecarlo.kernel import PathAverages

        return c_e * PathAverages(self.per_path[index]).v2


class PointStore:
    """A result folder of many ensembles: one JSON row and one ``.npy`` of per-path data each.

    The store of :func:`run_sweep` (a sweep's points) and of
    :func:`randvib.montecarlo.ensembles.run_ensembles` (paired cases). Every
    finished point is written atomically (unique temporary name, then
    rename), so an interrupted run resumes from the points already on disk;
    the JSON holds the point's key (what it is: a grid point, a case), its
    row, and the shape and SHA-256 of the ``.npy``, and every stored point is
    checked when resumed (its key, finite ``required`` statistics, the row's
    and the array's checksums, shape and finite values); a bad one is named
    in a warning and recomputed. With a ``table`` name the rows are written
    as that CSV on every run and after each point. A folder holding another
    run (different identity) is refused untouched, and the folder is locked
    while the run writes (:func:`randvib._io.prepare_output_dir`).

    Parameters
    ----------
    out_dir : path-like
    identity : dict
        What makes two runs the same (JSON-ready).
    required : tuple of str
        Row entries that must be finite numbers in a stored point.
    table : str or None
        File name of the CSV of the rows, or None for none.
    what : str
        What a point is called in a warning ("sweep point", "case").
    columns : int, optional
        Columns of a point's per-path array; default the stationary
        kernel's per-path averages (``N_ACC``).
    """

    FORMAT = 2

    def __init__(
        self,
        out_dir,
        identity: dict,
        *,
        required: tuple = (*STATISTICS, "n_paths"),
        table: str | None = "results.csv",
        what: str = "sweep point",
        columns: int | None = None,
    ):
        self.out = prepare_output_dir(out_dir, identity)
        (self.out / "points").mkdir(exist_ok=True)
        self.required, self.table, self.what = tuple(required), table, what
        self.columns = columns

    def _paths(self, index: int) -> Path:
        return self.out / "points" / f"{index:05d}.npy"

    def _row(self, index: int) -> Path:
        return self.out / "points" / f"{index:05d}.json"

    def load_finished(self, keys: list):
        """Rows and per-path arrays of the good points already on disk (``keys``: JSON-ready)."""
        rows, per_path = {}, {}
        for i, key in enumerate(keys):
            if not (self._row(i).exists() or self._paths(i).exists()):
                continue
            try:
                rows[i], per_path[i] = self._load(i, key)
            except _BadPoint as exc:
                warnings.warn(
                    f"{self.what} {i} in {str(self.out / 'points')!r} is unusable ({exc}); "
                    "recomputing it",
                    stacklevel=4,
                )
        self.write_table(rows)
        return rows, per_path

    def _load(self, index: int, key: dict):
        """One stored point, checked; :class:`_BadPoint` says what is wrong."""
        from randvib.montecarlo.kernel import N_ACC

        row_file, npy_file = self._row(index), self._paths(index)
        try:
            stored = json.loads(row_file.read_text())
            data = npy_file.read_bytes()
        except (OSError, ValueError, UnicodeDecodeError) as exc:
            raise _BadPoint(f"cannot read {exc.__class__.__name__}: {exc}") from None
        if not isinstance(stored, dict) or stored.get("format") != self.FORMAT:
            raise _BadPoint(f"{row_file.name} is not a point record of this randvib version")
        row, shape = stored.get("row"), stored.get("shape")
        if stored.get("point") != key or not isinstance(row, dict):
            raise _BadPoint(f"{row_file.name} holds another grid point: {stored.get('point')}")
        values = [row.get(k) for k in self.required]
        if not all(isinstance(v, int | float) and math.isfinite(v) for v in values):
            raise _BadPoint(f"{row_file.name} lacks finite statistics")
        if _row_checksum(row) != stored.get("row_sha256"):
            raise _BadPoint(
                f"{row_file.name}: the row does not match the checksum recorded with it"
            )
        if sha256(data) != stored.get("sha256"):
            raise _BadPoint(f"{npy_file.name} does not match the checksum recorded with it")
        try:
            paths = np.load(io.BytesIO(data), allow_pickle=False)
        except (OSError, ValueError) as exc:
            raise _BadPoint(f"{npy_file.name}: {exc}") from None
        if list(paths.shape) != shape or shape != [row["n_paths"], self.columns or N_ACC]:
            raise _BadPoint(f"{npy_file.name} has shape {paths.shape}, expected {shape}")
        if not np.all(np.isfinite(paths)):
            raise _BadPoint(f"{npy_file.name} holds non-finite values")
        # stored as null (JSON has no NaN): a statistic not computable at this point
        return {k: math.nan if v is None else v for k, v in row.items()}, paths

    def save(self, index: int, key: dict, row: dict, paths: np.ndarray, rows: dict) -> None:
        buffer = io.BytesIO()
        np.save(buffer, paths, allow_pickle=False)
        data = buffer.getvalue()
        atomic_write_bytes(self._paths(index), data)
        row = finite_json(row, "not computable at this point")[0]
        stored = {
            "format": self.FORMAT,
            "point": key,
            "row": row,
            "row_sha256": _row_checksum(row),
            "shape": list(paths.shape),
            "sha256": sha256(data),
        }
        atomic_write_text(self._row(index), dumps(stored))
        self.write_table(rows)

    def write_table(self, rows: dict) -> None:
        if self.table is not None:
            atomic_write_text(self.out / self.table, _table(rows).to_csv(index=False))

    def close(self) -> None:
        unlock_folder(self.out)


class _BadPoint(Exception):
    """A stored sweep point that cannot be trusted (why in the message)."""


def _row_checksum(row: dict) -> str:
    """SHA-256 of a row's canonical JSON (what is stored is what is hashed)."""
    return sha256(json.dumps(row, sort_keys=True, allow_nan=False).encode())


def _jsonable_point(point: Mapping) -> dict:
    return json.loads(json.dumps({k: float(v) for k, v in point.items()}))


def _table(rows: dict) -> pd.DataFrame:
    import pandas as pd

    return pd.DataFrame([{"point": i, **rows[i]} for i in sorted(rows)])


def run_stored(
    calls: list,
    keys: list,
    store: PointStore | None,
    *,
    executor: Executor | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    name: str = "sweep",
    unit: str = "point",
) -> tuple[dict, dict]:
    """Run every call not finished in ``store``; return the rows and per-path arrays by index.

    The loop of :func:`run_sweep` and :func:`randvib.montecarlo.ensembles.run_ensembles`.

    Parameters
    ----------
    calls : list of (function, args)
        ``function(*args, threads=...)`` returns ``(row, per_path)``; it must be
        picklable for worker processes or a cluster. In-process it gets
        ``threads=None`` (numba's threads as set), on a worker ``threads=1``.
    keys : list of dict
        What each call computes, JSON-ready: stored with its result and
        checked when resumed.
    store : PointStore or None
        Finished points are loaded from it, and each new one saved at once;
        it is closed (unlocked) at the end.
    executor, workers, scheduler : Executor, int, str, optional
        Where the calls run: a given executor, else ``workers`` local
        processes or the Dask cluster at ``scheduler`` (:func:`make_executor`;
        one worker: in-process).
    progress : bool
        A progress bar over the calls, ``name`` and ``unit`` on it.
    """
    rows: dict[int, dict] = {}
    per_path: dict[int, np.ndarray] = {}
    if store is not None:
        try:
            rows, per_path = store.load_finished(keys)
        except BaseException:
            store.close()
            raise
    todo = [i for i in range(len(calls)) if i not in rows]
    bar = None
    if progress and todo:
        bar = progress_bar(len(calls), initial=len(calls) - len(todo), desc=name, unit=unit)
    own_close = None
    try:
        if executor is None and todo:
            executor, own_close = make_executor(workers, scheduler)
        for i, row, paths in _computed(calls, todo, executor):
            rows[i], per_path[i] = row, paths
            if store is not None:
                store.save(i, keys[i], row, paths, rows)
            if bar is not None:
                bar.update()
    finally:
        if bar is not None:
            bar.close()
        if own_close is not None:
            own_close()
        if store is not None:
            store.close()
    return rows, per_path


def _computed(calls, todo, executor):
    """Yield ``(index, row, per_path)`` for each call in ``todo`` as it finishes."""
    if executor is None:
        for i in todo:
            function, args = calls[i]
            yield (i, *function(*args, threads=None))
        return
    futures = {executor.submit(calls[i][0], *calls[i][1], threads=1): i for i in todo}
    for fut in as_completed(futures):
        yield (futures[fut], *fut.result())


def run_sweep(
    base: Harvester,
    points: Iterable[Mapping],
    settings: SweepSettings | None = None,
    *,
    out_dir=None,
    executor: Executor | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    name: str = "sweep",
) -> SweepResult:
    """Run a sweep, optionally writing and resuming in ``out_dir``.

    Every point runs on the seed ``settings.seed`` (common random numbers);
    :func:`randvib.montecarlo.ensembles.run_ensembles` runs cases of any
    devices, inputs and starts in groups of their own seeds.

    Parameters
    ----------
    base : Harvester
        Device; each point's values replace its parameters.
    points : iterable of mappings
        Parameter points (:func:`cartesian` builds grids); each needs ``psd``.
    settings : SweepSettings
    out_dir : path-like, optional
        Folder for ``results.csv``, ``metadata.json`` and ``points/``
        (:class:`PointStore`). Finished points found there are loaded, not
        recomputed.
    executor : concurrent.futures.Executor, optional
        Where points run; default: ``workers`` local processes, or the Dask
        cluster at ``scheduler``.
    progress : bool
        Show a progress bar over points.
    """
    settings = settings or SweepSettings()
    # the sweep's power columns are c_e E[v^2]; a circuit state has its own
    base.require_resistive("run_sweep", "randvib.simulate, point by point")
    points = validate_points(base, points)
    store = None
    if out_dir is not None:
        identity = {
            "name": name,
            "base": base.parameters(),
            "points": points,
            "settings": settings.to_dict(),
        }
        store = PointStore(out_dir, identity)
    rows, per_path = run_stored(
        [(run_point, (base, p, settings)) for p in points],
        [_jsonable_point(p) for p in points],
        store,
        executor=executor,
        workers=workers,
        scheduler=scheduler,
        progress=progress,
        name=name,
    )
    return SweepResult(table=_table(rows), settings=settings, points=points, per_path=per_path)


# ------------------------------------------------------------------ tests on results
def linearisation_verdicts(table: pd.DataFrame, method: str = "linearisation") -> pd.DataFrame:
    """Relative error of an analytic method against Monte Carlo, per point.

    ``rel_error = (P_analytic - P_mc) / P_mc`` with the 95 % half-width of
    ``P_mc`` propagated (first order); ``consistent`` is True where the
    analytic value lies inside the Monte Carlo 95 % interval.
    """
    analytic = table[f"{method}_power"]
    mc, ci = table["power_electrical"], table["power_electrical_ci95"]
    out = table.copy()
    out[f"{method}_rel_error"] = analytic / mc - 1.0
    out[f"{method}_rel_error_ci95"] = analytic * ci / mc**2
    # rounding floor: where control variates make the estimate exact (no
    # friction) its interval collapses to ~1e-19 W
    out[f"{method}_consistent"] = (analytic - mc).abs() <= ci + 1e-12 * mc.abs()
    return out


def paired_contrast(result: SweepResult, base: Harvester, weights: Mapping[int, float]):
    """Estimate sum_i w_i E[P_e](point i) from common-random-number paths.

    Uses the paths common to all points (the same path indices saw the same
    noise), forms the weighted combination path by path and returns a
    :class:`randvib.statistics.Statistic`. With the sweep's control variates
    on, each point's Ito integral and energy change (the energy-balance
    controls) serve as controls. The friction-free companions are left out
    here: the companions of points that differ only in Fc are nearly collinear
    (they differ only in their initial state), which makes the fitted
    coefficients unstable and, over repeated seeds, the reported interval
    too narrow.

    Coverage, measured over repeated seeds against the FPK interaction
    (``tests/test_sweep.py``): with 20 paths per control the 95 % interval
    covers 95.0 %; with 10 per control, the fewest for which the controls are
    used, it covers about 94 % (the energy controls absorb nearly all the
    variance, and the residuals of few paths are not quite Gaussian), so
    give a contrast at least 20 paths per control where its interval matters.
    """
    from randvib.montecarlo import kernel

    n = min(result.per_path[i].shape[0] for i in weights)
    samples = np.zeros(n)
    controls = []
    window = result.settings.window
    for i, w in weights.items():
        device = point_device(base, result.points[i])
        averages = kernel.PathAverages(result.per_path[i][:n])
        samples += w * device.c_e * averages.v2
        controls.extend(averages.energy_balance_controls(window))
    ctrl = np.column_stack(controls) if result.settings.control_variates else None
    if ctrl is not None and ctrl.shape[1] * 10 > n:
        ctrl = None  # too few paths to fit the coefficients reliably
    return estimate(samples, ctrl)
