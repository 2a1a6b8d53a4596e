"""Monte Carlo of an assembly: ``randvib.simulate(assembly, excitation, ...)``.

The assembly (:class:`randvib.models.assembly.Assembly`; docs/assemblies.md)

    M x'' + C x' + K x + sum_e d_e f_e(u_e, u_e') = -M r a(t)

is integrated by its own compiled kernel
(:mod:`randvib.montecarlo.assembly_kernel`) with the single mass's schemes,
streams and options: white noise (``a = sqrt(S/2) dW / dt``); a rational
spectrum through its shaping filter's states; a band-limited or tabulated
spectrum synthesised per path (:class:`randvib.montecarlo.driven.SynthesisedInput`)
and a measured record cut into segments
(:func:`randvib.montecarlo.on_record.monte_carlo_on_record`), both as the
step integrals of the base acceleration reaching the velocities through r.
Beyond Gaussian noise, as for the single mass: a translated (non-Gaussian)
input synthesised per path (:class:`randvib.montecarlo.driven.TranslatedInput`),
and tones and shock trains added to any of these (or alone) as the kernel's
forcing (:class:`randvib.montecarlo.forcing.ForcingInput`: the exact step
integral of -a(t) through r, half before and half after each step; the
phases and trains from the single mass's streams).

The driver is the single mass's, part for part: arguments checked into an
:class:`AssemblyRun` (:func:`validated_assembly`), the step checked on the
linearised assembly (:class:`~randvib.montecarlo.assembly_step_check.AssemblyTestSystem`),
the tables set up (:mod:`randvib.montecarlo.assembly_setup`), the paths run
in interruptible batches (:func:`run_assembly_batches`) and the per-path
averages wrapped in an :class:`~randvib.montecarlo.assembly_results.AssemblySimulationResult`.
Path i draws from stream (seed, first_path + i), so results are bit-identical
for any number of threads and any batching.
"""

from __future__ import annotations

import functools
import time
import warnings
from dataclasses import dataclass

import numpy as np

from randvib._interrupts import interruptible
from randvib._progress import progress_bar, progress_wanted
from randvib._resources import check_memory
from randvib._validation import check_int
from randvib.models.assembly import Assembly
from randvib.models.excitation import Excitation
from randvib.montecarlo import driven
from randvib.montecarlo.assembly_kernel import run_assembly_ensemble
from randvib.montecarlo.assembly_results import AssemblyHistories, AssemblySimulationResult
from randvib.montecarlo.assembly_setup import AssemblyKernelSetup
from randvib.montecarlo.assembly_step_check import AssemblyTestSystem
from randvib.montecarlo.batches import SimulationDivergedError, batch_bounds
from randvib.montecarlo.integrators import Integrator
from randvib.montecarlo.options import TimeGrid, numba_threads
from randvib.montecarlo.validation import MAX_PATH_INDEX, BridgeStartWarning, checked_input

__all__ = ["simulate_assembly"]


@dataclass(frozen=True)
class AssemblyRun:
    """An assembly's simulate arguments, validated and grouped (as :class:`~randvib.montecarlo.validation.Run`)."""

    assembly: Assembly
    psd: float | None
    excitation: Excitation
    scheme: Integrator
    grid: TimeGrid
    n_paths: int
    seed: int
    first_path: int
    #: ("stationary" | "rest" | "state", x0 (N,), v0 (N,))
    initial: tuple
    record_paths: int
    record_every: int
    dW: np.ndarray | None
    #: Velocity increments of a given base acceleration, ``driver(first, count)``:
    #: a synthesised Gaussian or translated (non-Gaussian) input, or a record.
    driver: object = None
    #: Tones and shocks added to the input (:class:`~randvib.montecarlo.forcing.ForcingInput`), or None.
    forcing: object = None
    #: The whole input as given; ``excitation`` is its random part, or with none (tones
    #: or shocks alone) the nominal white level the step check and the start see.
    input: Excitation | None = None


def simulate_assembly(
    assembly: Assembly,
    psd,
    *,
    t_end: float,
    dt: float,
    n_paths: int,
    burn_in: float = 0.0,
    scheme: str = "heun",
    seed: int = 0,
    dW=None,
    initial="stationary",
    first_path: int = 0,
    companion: bool = False,
    control_variates: bool = False,
    histogram_bins: int = 0,
    histogram_range=None,
    record_paths: int = 0,
    record_every: int = 1,
    threads: int | None = None,
    batch_paths: int | None = None,
    progress: bool | None = None,
    check_step: bool = True,
) -> AssemblySimulationResult:
    """Simulate an ensemble of an assembly; :func:`randvib.simulate` with an Assembly comes here.

    The options are :func:`randvib.simulate`'s, with these differences:
    ``initial`` is "stationary" (every x, v, circuit and filter state drawn
    jointly from the linearised assembly's stationary law), "rest" or a pair
    (x0, v0) of N-vectors; ``record_paths`` keeps the whole state of the
    first paths (:class:`~randvib.montecarlo.assembly_results.AssemblyHistories`);
    ``companion`` and the histograms are the single mass's and are refused.

    Returns
    -------
    AssemblySimulationResult
        Per DOF ``displacement_variance`` and ``velocity_variance``; per
        transducer ``power_electrical``, ``power_load``, ``power_stored``, ...;
        the energy balance under white noise.
    """
    if companion:
        raise ValueError(
            "`companion` is the single mass's friction-free companion (exact S m/(4c), Gibbs "
            "E[z^2]); an assembly has none: use companion=False (control_variates=True "
            "keeps the energy-balance controls)"
        )
    if histogram_bins or histogram_range is not None:
        raise ValueError(
            "`histogram_bins` / `histogram_range` are the single mass's (z, v) histograms; for "
            "an assembly use record_paths to keep its states"
        )
    run = validated_assembly(
        assembly, psd, scheme, t_end=t_end, dt=dt, burn_in=burn_in, n_paths=n_paths, seed=seed,
        first_path=first_path, initial=initial, dW=dW, record=(record_paths, record_every),
    )  # fmt: skip
    return execute_assembly(
        run, control_variates=control_variates, check_step=check_step, threads=threads,
        batch_paths=batch_paths, progress=progress,
    )  # fmt: skip


def validated_assembly(
    assembly, psd, scheme, *, t_end, dt, burn_in, n_paths, seed, first_path, initial, dW, record
) -> AssemblyRun:
    """The arguments checked in one place; messages name the argument."""
    if not isinstance(assembly, Assembly):
        raise ValueError(f"`assembly` must be a randvib.Assembly, got {type(assembly).__name__}")
    common = checked_input(psd, scheme, t_end=t_end, dt=dt, burn_in=burn_in, n_paths=n_paths,
                           seed=seed, dW=dW)  # fmt: skip
    record_paths = check_int("record_paths", record[0], 0)
    record_every = check_int("record_every", record[1], 1)
    return AssemblyRun(
        assembly=assembly,
        **common._asdict(),  # the input, grid, paths and seed, checked alike
        first_path=check_int("first_path", first_path, 0, MAX_PATH_INDEX),
        initial=_initial(initial, assembly.n_dof),
        record_paths=record_paths,
        record_every=record_every,
    )


def _initial(initial, n: int) -> tuple:
    """("stationary" | "rest" | "state", x0, v0) from simulate's ``initial``."""
    zeros = np.zeros(n)
    if isinstance(initial, str):
        if initial not in ("stationary", "rest"):
            raise ValueError(
                f"`initial` must be 'stationary', 'rest' or (x0, v0) with {n} entries each, "
                f"got {initial!r}"
            )
        return initial, zeros, zeros
    try:
        x0, v0 = (np.array(part, dtype=float).reshape(-1) for part in initial)
    except (TypeError, ValueError):
        x0 = v0 = None
    if x0 is None or x0.shape != (n,) or v0.shape != (n,) or not np.all(np.isfinite([*x0, *v0])):
        raise ValueError(
            f"`initial` must be 'stationary', 'rest' or (x0, v0): two lists of {n} finite "
            f"numbers (m, m/s), one per DOF; got {initial!r}"
        )
    return "state", x0, v0


def execute_assembly(
    run: AssemblyRun, *, control_variates, check_step, threads, batch_paths, progress
):
    """Run a validated :class:`AssemblyRun`: check, set up, run in batches, wrap."""
    beyond = run.forcing is not None or not run.excitation.is_gaussian
    if control_variates and beyond:
        raise ValueError(
            "`control_variates` needs Gaussian noise alone; under the "
            f"{(run.input or run.excitation).name} input no control has a known mean: use "
            "control_variates=False"
        )
    if control_variates and run.excitation.shaping_filter() is None:
        raise ValueError(
            "`control_variates` needs Brownian increments (white noise, or band-pass and "
            f"Kanai-Tajimi through their filter); under the {run.excitation.name} input the Ito "
            "sum is the input power, not a zero-mean control: use control_variates=False"
        )
    _check_bridges(run)
    system = functools.cache(lambda: AssemblyTestSystem.of(run.assembly, run.excitation))
    if check_step:
        system().check_step(run.scheme.name, run.grid.dt)
    setup = AssemblyKernelSetup.prepare(run, system)
    _check_memory(run, setup, batch_paths)
    if progress is None:
        progress = progress_wanted()
    # a synthesised input's samples and a shock train's step integrals are arrays of
    # (paths in the batch) x (steps): batches bound them
    sampled = run.driver is not None or (run.forcing is not None and run.forcing.shocks is not None)
    if batch_paths is None and sampled:
        batch_paths = driven.batch_paths(run.grid.n_steps)
    batches = batch_bounds(run.n_paths, batch_paths, run.grid.n_steps, progress, run.record_paths)
    started = time.perf_counter()
    with numba_threads(threads):  # the caller's thread count is put back after the run
        per_path, records = run_assembly_batches(run, setup, batches, progress)
    histories = None
    if records is not None:
        n = run.assembly.n_dof
        times = np.arange(records.shape[1]) * run.record_every * run.grid.dt
        histories = AssemblyHistories(
            times, records[:, :, :n].copy(), records[:, :, n + 1 : 2 * n + 1].copy(), records
        )
    return AssemblySimulationResult(
        assembly=run.assembly, psd=run.psd,
        excitation=run.excitation if run.forcing is None else run.input, scheme=run.scheme.name,
        dt=run.grid.dt, t_end=run.grid.t_end, burn_in=run.grid.burn_in, seed=run.seed,
        first_path=run.first_path, per_path=per_path, columns=setup.columns,
        control_variates=control_variates, histories=histories,
        wall_time=time.perf_counter() - started,
    )  # fmt: skip


def run_assembly_batches(run: AssemblyRun, setup: AssemblyKernelSetup, batches, progress: bool):
    """The compiled loop batch by batch, interruptible; (per-path averages, records or None)."""
    per_path = np.empty((run.n_paths, setup.columns.n))
    records = None
    bar = (
        progress_bar(run.n_paths, desc="simulate", unit="path", transient=True)
        if progress
        else None
    )
    try:
        for lo, hi in batches:
            acc, failed, rec = interruptible(run_assembly_ensemble, **setup.arguments(run, lo, hi))
            bad = np.flatnonzero(failed >= 0)
            if bad.size:
                p = bad[0]
                raise SimulationDivergedError(
                    f"simulation diverged: path {run.first_path + lo + p} became non-finite by "
                    f"step {failed[p]} (t = {failed[p] * run.grid.dt:.6g} s) with dt = "
                    f"{run.grid.dt!r} s, scheme {run.scheme.name}, psd = {run.psd!r}, assembly "
                    f"{run.assembly.describe()}"
                )
            per_path[lo:hi] = acc
            if lo == 0 and run.record_paths > 0:
                records = rec
            if bar is not None:
                bar.update(hi - lo)
    finally:
        if bar is not None:
            bar.close()
    return per_path, records


def _check_memory(run: AssemblyRun, setup: AssemblyKernelSetup, batch_paths) -> None:
    """Refuse a run whose per-path averages and records cannot fit in memory."""
    records = min(run.record_paths, run.n_paths) * (run.grid.n_steps // run.record_every + 1)
    n_bytes = 8.0 * (2 * run.n_paths * setup.columns.n + records * setup.layout.n_rows)
    check_memory(
        f"simulating {run.n_paths} paths of {run.grid.n_steps} steps",
        n_bytes,
        "reduce `n_paths` or `record_paths`, or run in parts with `first_path`",
    )


def _check_bridges(run: AssemblyRun) -> None:
    """Each bridge's storage capacitor: a step that resolves its RC rate; a burn-in that charges it."""
    for index, transducer in enumerate(run.assembly.transducers):
        if not transducer.is_rectified:
            continue
        bridge = transducer.coupling
        rate = bridge.fastest_rate()
        if rate * run.grid.dt > 0.2:
            raise ValueError(
                f"`dt` = {run.grid.dt!r} s is too large for transducer {index}'s {bridge.name} "
                f"storage capacitor (its fastest rate {rate:.3g} 1/s): use dt <= {0.2 / rate:.3g} s"
            )
        if not bridge.has_battery:
            settle = 3.0 * bridge.r_load * bridge.storage_capacitance
            if run.grid.burn_in < settle:
                warnings.warn(
                    f"burn_in = {run.grid.burn_in:g} s is shorter than 3 R_L C = {settle:.3g} s "
                    f"of transducer {index}'s storage capacitor, which starts empty: its charging "
                    f"biases the stored power low; use burn_in >= {settle:.3g} s",
                    BridgeStartWarning,
                    stacklevel=4,
                )
