"""The ensemble run through the compiled loop, batch by batch.

:func:`batch_bounds` splits the paths into compiled calls (all in one, or
calls of about a second for a progress bar); :func:`run_batches` runs them,
each interruptible by Ctrl-C (:func:`randvib._interrupts.interruptible`),
refuses a diverged path by name (:class:`SimulationDivergedError`) and
gathers the per-path averages, the histogram counts and the recorded paths.
Results do not depend on the batches: path i draws from its own stream.
"""

from __future__ import annotations

import numba
import numpy as np

from randvib._interrupts import interruptible
from randvib._progress import progress_bar
from randvib._validation import check_int
from randvib.montecarlo import kernel
from randvib.montecarlo.kernel_setup import KernelSetup
from randvib.montecarlo.results import Histogram, Histories
from randvib.montecarlo.validation import Run


class SimulationDivergedError(ValueError):
    """The state became non-finite during a simulation."""


def batch_bounds(n_paths, batch_paths, n_steps, progress, record_paths) -> list[tuple[int, int]]:
    """(lo, hi): the paths lo .. hi - 1 of each compiled call.

    ``batch_paths`` None: all paths in one call, or calls of about a second
    for a live progress bar. The recorded paths all come from the first call.
    """
    if batch_paths is None:
        if progress:
            # about 1e8 path-steps per call: a second or so, for a live bar
            batch_paths = max(kernel.LANES * numba.get_num_threads(), int(1e8 // max(n_steps, 1)))
        else:
            batch_paths = n_paths
    batch_paths = check_int("batch_paths", batch_paths, 1)
    batch_paths = max(batch_paths, min(record_paths, n_paths))  # records come from batch 0
    edges = list(range(0, n_paths, batch_paths)) + [n_paths]
    return list(zip(edges[:-1], edges[1:], strict=True))


def run_batches(run: Run, setup: KernelSetup, batches, progress: bool):
    """Run the compiled loop batch by batch (``batches`` from :func:`batch_bounds`).

    Returns
    -------
    per_path : ndarray, shape (n_paths, N_ACC)
        Per-path time averages.
    histogram : Histogram or None
        Stationary histograms of z and v, from the counts per chunk of paths.
    histories : Histories or None
        Recorded histories of the first paths (from the first batch).
    """
    per_path = np.empty((run.n_paths, kernel.N_ACC))
    hist_groups = []
    records = None
    bar = None
    if progress:
        bar = progress_bar(run.n_paths, desc="simulate", unit="path", transient=True)
    try:
        for lo, hi in batches:
            acc, failed, hist, rec = interruptible(
                kernel.run_ensemble, **setup.arguments(run, lo, hi)
            )
            raise_if_diverged(run, lo, failed)
            per_path[lo:hi] = acc
            if run.record.histogram_bins > 0:
                hist_groups.append(hist)
            if lo == 0 and run.record.record_paths > 0:
                records = rec
            if bar is not None:
                bar.update(hi - lo)
    finally:
        if bar is not None:
            bar.close()
    hist_groups = np.concatenate(hist_groups) if hist_groups else None
    histogram = _histogram(setup.recording, hist_groups, batches, run.grid.window_steps)
    histories = None
    if records is not None:
        histories = Histories.from_records(records, run.record.record_every, run.grid.dt)
    return per_path, histogram, histories


def raise_if_diverged(run: Run, lo: int, failed: np.ndarray) -> None:
    """Refuse a batch (its first path ``lo``) in which a path became non-finite, naming it."""
    bad = np.flatnonzero(failed >= 0)
    if bad.size:
        p = bad[0]
        dt = run.grid.dt
        raise SimulationDivergedError(
            f"simulation diverged: path {run.first_path + lo + p} became non-finite by step "
            f"{failed[p]} (t = {failed[p] * dt:.6g} s) with dt = {dt!r} s, "
            f"scheme {run.scheme.name}, psd = {run.psd!r}, "
            f"parameters {run.harvester.parameters()}"
        )


def _histogram(recording: kernel.Recording, groups, batches, window_steps: int):
    """The run's :class:`Histogram` (None without bins)."""
    if recording.hist_bins == 0:
        return None
    # The kernel's chunks: LANES paths each, the last of each batch possibly fewer.
    sizes = [
        min(kernel.LANES, hi - start) for lo, hi in batches for start in range(lo, hi, kernel.LANES)
    ]
    return Histogram.from_counts(recording, groups, sizes, window_steps)
