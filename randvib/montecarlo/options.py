"""The run options of :func:`randvib.simulate`: time grid, initial state, what is recorded.

Each option group is a small frozen dataclass built from simulate's
arguments by one validating constructor whose messages name the argument:
:class:`TimeGrid` (``t_end``, ``dt``, ``burn_in`` in whole steps),
:class:`InitialState` (``initial``) and :class:`RecordOptions` (histograms
and recorded paths).
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass

import numba
import numpy as np

from randvib._validation import check_choice, check_int, check_positive


@contextlib.contextmanager
def numba_threads(threads):
    """Within the block, compiled loops run on ``threads`` numba threads (None: as set).

    numba's thread count is a setting of the calling thread that outlives the
    call; a run's ``threads`` option applies to that run alone, so the
    caller's setting is put back after it (a ``threads=1`` run once left
    every later run in the session on one thread).
    """
    if threads is None:
        yield
        return
    threads = check_int("threads", threads, 1)
    previous = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        yield
    finally:
        numba.set_num_threads(previous)


#: Most steps per path (int64 step counters, with room to spare).
MAX_STEPS = 2**62


@dataclass(frozen=True)
class TimeGrid:
    """The time steps of every path: ``n_steps`` of ``dt``, the first ``n_burn`` discarded.

    Attributes
    ----------
    dt : float
        Time step (s).
    n_steps : int
        Steps per path, burn-in included.
    n_burn : int
        Steps before the averaging window.
    """

    dt: float
    n_steps: int
    n_burn: int

    @classmethod
    def from_times(cls, t_end, dt, burn_in) -> TimeGrid:
        """Validated grid for ``t_end`` and ``burn_in`` (s), rounded to whole steps."""
        t_end = float(check_positive("t_end", t_end, "s"))
        dt = float(check_positive("dt", dt, "s"))
        burn_in = float(np.asarray(burn_in, dtype=float))
        if not (np.isfinite(burn_in) and 0.0 <= burn_in < t_end):
            raise ValueError(
                f"`burn_in` must satisfy 0 <= burn_in < t_end = {t_end!r} s, got {burn_in!r}"
            )
        if not t_end / dt <= MAX_STEPS:
            raise ValueError(
                f"`t_end` / `dt` = {t_end:g} s / {dt:g} s = {t_end / dt:.3g} steps per path; "
                f"at most {MAX_STEPS:.3g} can be counted: shorten `t_end` or enlarge `dt`"
            )
        grid = cls(dt, int(round(t_end / dt)), int(round(burn_in / dt)))
        if grid.window_steps < 1:
            raise ValueError(
                f"`t_end` - `burn_in` = {t_end - burn_in!r} s holds no step of dt = {dt!r} s"
            )
        return grid

    @property
    def window_steps(self) -> int:
        """Steps inside the averaging window."""
        return self.n_steps - self.n_burn

    @property
    def t_end(self) -> float:
        """Simulated time per path (s)."""
        return self.n_steps * self.dt

    @property
    def burn_in(self) -> float:
        """Discarded time per path (s)."""
        return self.n_burn * self.dt


@dataclass(frozen=True)
class InitialState:
    """Where each path starts: ``simulate(initial=...)``, validated.

    Attributes
    ----------
    kind : {"stationary", "rest", "state"}
        Independent Gaussians with the linearised stationary variances (drawn
        from each path's stream), rest, or the given state (z, v).
    z, v : float
        The given state (m, m/s) for ``kind == "state"``.
    """

    kind: str
    z: float = 0.0
    v: float = 0.0

    @classmethod
    def from_argument(cls, initial) -> InitialState:
        """From ``"stationary"``, ``"rest"`` or a finite pair (z0, v0)."""
        if isinstance(initial, str):
            return cls(check_choice("initial", initial, ("stationary", "rest")))
        z0, v0 = (float(x) for x in initial)
        if not (np.isfinite(z0) and np.isfinite(v0)):
            raise ValueError(f"`initial` state must be finite, got {initial!r}")
        return cls("state", z0, v0)


@dataclass(frozen=True)
class RecordOptions:
    """What :func:`simulate` records besides the per-path time averages.

    Attributes
    ----------
    histogram_bins : int
        Bins of the stationary histograms of z and v (0: none).
    histogram_range : ((float, float), (float, float)) or None
        ((z_lo, z_hi), (v_lo, v_hi)) (m, m/s); None: +-5 linearised std.
    record_paths : int
        Number of first paths whose (z, v, theta) are kept.
    record_every : int
        Keep every ``record_every``-th step of them (the initial state included).
    """

    histogram_bins: int = 0
    histogram_range: tuple | None = None
    record_paths: int = 0
    record_every: int = 1

    @classmethod
    def validated(cls, histogram_bins, histogram_range, record_paths, record_every):
        """Checked options; a given ``histogram_range`` as nested float tuples."""
        record_paths = check_int("record_paths", record_paths, 0)
        record_every = check_int("record_every", record_every, 1)
        histogram_bins = check_int("histogram_bins", histogram_bins, 0)
        if histogram_bins > 0 and histogram_range is not None:
            histogram_range = _checked_range(histogram_range)
        return cls(histogram_bins, histogram_range, record_paths, record_every)


def _checked_range(histogram_range) -> tuple:
    arr = np.asarray(histogram_range, dtype=float)
    if arr.shape != (2, 2) or np.any(arr[:, 1] <= arr[:, 0]):
        raise ValueError(
            "`histogram_range` must be ((z_lo, z_hi), (v_lo, v_hi)) with lo < hi, "
            f"got {histogram_range!r}"
        )
    return tuple(tuple(float(x) for x in row) for row in arr)
