"""How a run stops on Ctrl-C or SIGTERM: compiled loops and entry points.

* :func:`interruptible` calls a compiled (nogil) loop so that Ctrl-C stops it
  within a fraction of a second (a compiled loop does not see signals).
* :func:`sigterm_stops` and :func:`interrupted_exit`: SIGTERM handled as
  Ctrl-C is, for the command line and the study scripts.

A run stopped by SIGTERM (``kill``, a batch scheduler's time limit) should
end as one stopped by Ctrl-C: finished points and fits kept, folder locks
released, worker processes ended, one line on stderr. :class:`Terminated`
is a :class:`KeyboardInterrupt`, so every path that stops on Ctrl-C stops on
SIGTERM the same way; the entry points tell the two apart for the exit
status (130 = 128 + SIGINT, 143 = 128 + SIGTERM).
"""

from __future__ import annotations

import contextlib
import signal
import threading


class Terminated(KeyboardInterrupt):
    """SIGTERM received: raised in the main thread so that a run stops as on Ctrl-C."""


def _raise_terminated(signum, frame):
    raise Terminated()


@contextlib.contextmanager
def sigterm_stops():
    """Within the block, SIGTERM raises :class:`Terminated` (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def interrupted_exit(exc: KeyboardInterrupt) -> tuple[int, str]:
    """The exit status and the one line to print for a stopped run."""
    if isinstance(exc, Terminated):
        return 128 + signal.SIGTERM, "randvib: terminated (SIGTERM); finished results were kept"
    return 128 + signal.SIGINT, "randvib: interrupted; finished results were kept"


def interruptible(compiled, **kwargs):
    """Call a compiled (nogil) loop so that Ctrl-C stops it within a fraction of a second.

    A compiled loop does not see signals, so it runs in a worker thread while
    this (main) thread waits; on KeyboardInterrupt the shared ``stop`` flag is
    set, the loop ends at its next check, and KeyboardInterrupt is raised
    (finished batches, points and fits are kept by the callers).
    """
    import numpy as np  # here: the command line imports this module before it needs numpy

    stop = np.zeros(1, dtype=np.int64)
    if threading.current_thread() is not threading.main_thread():
        return compiled(stop=stop, **kwargs)  # signals only reach the main thread
    outcome = {}

    def target():
        try:
            outcome["value"] = compiled(stop=stop, **kwargs)
        except BaseException as exc:  # handed to the caller's thread
            outcome["error"] = exc

    worker = threading.Thread(target=target, name="randvib-kernel", daemon=True)
    worker.start()
    try:
        while worker.is_alive():
            worker.join(0.05)
    except KeyboardInterrupt:
        stop[0] = 1
        worker.join()
        raise
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]
