"""SIGTERM handled as Ctrl-C is, for the command line and the study scripts.

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
