"""Up-front estimates of the memory and time a run needs.

Work that cannot fit in memory is refused before it starts, with the
estimate and what is available (:func:`check_memory`); a run expected to
take long says so first (:func:`announce_duration`), so that a user can
stop it (Ctrl-C) instead of waiting blind.
"""

from __future__ import annotations

import os
import time
import warnings


class LongRunWarning(UserWarning):
    """A run is expected to take long; the message says about how long."""


#: Warn when a run is expected to take longer than this (s).
LONG_RUN_SECONDS = 600.0


def available_memory() -> int:
    """Bytes of memory available to a new allocation (MemAvailable, else physical)."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - exotic systems
        return 2**62


def size_text(n_bytes: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if n_bytes < 1000 or unit == "PB":
            return f"{n_bytes:.3g} {unit}"
        n_bytes /= 1000
    return f"{n_bytes:.3g} PB"  # pragma: no cover


def duration_text(seconds: float) -> str:
    for unit, size in (("years", 3.15e7), ("days", 86400), ("hours", 3600), ("minutes", 60)):
        if seconds >= size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.3g} s"


def check_memory(what: str, n_bytes: float, hint: str) -> None:
    """Refuse ``what`` if it needs more than the memory available now.

    Raises
    ------
    ValueError
        With the estimate, the memory available and ``hint`` (what to change).
    """
    available = available_memory()
    if n_bytes > available:
        raise ValueError(
            f"{what} needs about {size_text(n_bytes)} of memory, more than the "
            f"{size_text(available)} available; {hint}"
        )


#: The clock that times probes of a run's speed (a test replaces it).
clock = time.perf_counter


def timed(call):
    """``(call(), seconds it took)`` on :data:`clock`, never 0 s (a speed divides by it)."""
    started = clock()
    value = call()
    return value, max(clock() - started, 1e-9)


def announce_duration(
    what: str, seconds: float, stacklevel: int = 3, basis: str = "at the speed measured here"
) -> None:
    """Warn (:class:`LongRunWarning`) when ``what`` is expected to take long.

    ``basis`` says where the estimate comes from (a timed probe of the run,
    or a rough speed).
    """
    if seconds > LONG_RUN_SECONDS:
        warnings.warn(
            f"{what} will take about {duration_text(seconds)} ({basis}); Ctrl-C stops it",
            LongRunWarning,
            stacklevel=stacklevel,
        )
