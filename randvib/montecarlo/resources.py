"""How large and how long a Monte Carlo run is, told before it starts.

:func:`check_resources` refuses a run whose arrays cannot fit in memory;
:func:`announce_long_run` says how long a long run will take, at the speed
of the compiled loop timed on this machine (the shared wording and clock:
:mod:`randvib._resources`).
"""

from __future__ import annotations

import numba

from randvib._interrupts import interruptible
from randvib._resources import LONG_RUN_SECONDS, announce_duration, check_memory, timed
from randvib.montecarlo import kernel
from randvib.montecarlo.kernel_setup import KernelSetup
from randvib.montecarlo.validation import Run

#: Rough speed of the compiled loop, path-steps per second per thread (Heun,
#: Coulomb friction on a laptop core, about 3e7): it only decides whether a run
#: could be long enough to time a probe of it (:func:`announce_long_run`).
PATH_STEPS_PER_SECOND = 3e7
#: A run shorter than LONG_RUN_SECONDS / PROBE_MARGIN at the rough speed is
#: not probed: the machine would have to be this many times slower to make it long.
PROBE_MARGIN = 30.0
#: Path-steps per thread of the timed probe (about 0.1 s at the rough speed).
PROBE_PATH_STEPS = 3e6


def announce_long_run(run: Run, setup: KernelSetup) -> None:
    """Say how long a long run will take, at the speed measured on this machine.

    A run that could be long (more than LONG_RUN_SECONDS / PROBE_MARGIN at the
    rough speed) is timed on a short probe first: the first paths for a few
    thousand steps, after a call that compiles the loop, so that neither the
    compilation nor the machine's guessed speed enters the estimate. Input
    synthesised per path is not probed (its synthesis is per whole path); its
    estimate uses the rough speed and the synthesis' measured cost (about 3x
    the white-noise loop, ``benchmarks/bench_engine.py``).
    """
    threads = numba.get_num_threads()
    work = float(run.n_paths) * run.grid.n_steps * (2 if run.companion else 1)
    rough = work / (PATH_STEPS_PER_SECOND * threads)
    if rough <= LONG_RUN_SECONDS / PROBE_MARGIN:
        return
    what = f"simulating {run.n_paths} paths x {run.grid.n_steps} steps"
    if run.driver is not None:
        announce_duration(what, 3.0 * rough, stacklevel=5, basis="a rough estimate")
    else:
        announce_duration(what, work / _measured_speed(run, setup, threads), stacklevel=5)


def _measured_speed(run: Run, setup: KernelSetup, threads: int) -> float:
    """Path-steps per second of this run's compiled loop on this machine (a timed probe)."""
    paths = min(run.n_paths, kernel.LANES * threads)
    steps = int(min(run.grid.n_steps, max(100, PROBE_PATH_STEPS * threads / paths)))

    def probe(n_paths, n_steps):
        timing = kernel.pack(kernel.Timing, run.grid.dt, n_steps, min(run.grid.n_burn, n_steps - 1))
        arguments = setup.arguments(run, 0, n_paths)
        arguments["timing"] = timing
        arguments["recording"] = arguments["recording"]._replace(n_record=0)
        # in a worker thread, as every run of the loop: a Ctrl-C whose handler ran
        # in the main thread while it was inside the compiled probe came out of
        # numba's runtime as a SystemError, or not at all (tests/test_interrupts.py)
        interruptible(kernel.run_ensemble, **arguments)

    probe(1, 2)  # compiles (or loads) the loop: not part of the speed
    _, elapsed = timed(lambda: probe(paths, steps))
    return paths * steps * (2 if run.companion else 1) / elapsed


def check_resources(run: Run, batch_paths) -> None:
    """Refuse a run whose arrays cannot fit in memory."""
    n_steps, n_paths = run.grid.n_steps, run.n_paths
    batch = n_paths if batch_paths is None else min(int(batch_paths), n_paths)
    chunks = -(-batch // kernel.LANES)
    rec = run.record
    n_bytes = 8.0 * (
        2 * n_paths * kernel.N_ACC  # per-path averages, and one batch's
        # histogram counts per chunk, their sum, then densities and bin edges
        + (chunks * 2 + 6) * rec.histogram_bins
        + min(rec.record_paths, n_paths) * (n_steps // rec.record_every + 1) * 3
    )
    check_memory(
        f"simulating {n_paths} paths of {n_steps} steps",
        n_bytes,
        "reduce `n_paths`, `histogram_bins` or `record_paths`, or run in parts with `first_path`",
    )
