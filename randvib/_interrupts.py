"""How a run stops on Ctrl-C or SIGTERM: compiled loops, worker processes, entry points.

* :func:`interruptible` calls a compiled (nogil) loop so that Ctrl-C stops it
  within a fraction of a second (a compiled loop does not see signals).
* :func:`ctrl_c_blocked` and :func:`worker_ignores_ctrl_c`: a process pool's
  workers leave Ctrl-C to their parent from the moment they are spawned.
* :func:`sigterm_stops` and :func:`interrupted_exit`: SIGTERM handled as
  Ctrl-C is, for the command line and the study scripts; :func:`interrupts_seen`
  notices a Ctrl-C that a finaliser or a callback swallowed, so that such a run
  still ends with a non-zero status.
* :func:`exit_at_once_on_signals`: while the command line starts (imports)
  and once it has finished (interpreter shutdown), Ctrl-C and SIGTERM end
  the process at once with one line and 130 / 143, never a traceback nor an
  "Exception ignored" note and exit 0.

A run stopped by SIGTERM (``kill``, a batch scheduler's time limit) should
end as one stopped by Ctrl-C: finished points and fits kept, folder locks
released, worker processes ended, one line on stderr. :class:`Terminated`
is a :class:`KeyboardInterrupt`, so every path that stops on Ctrl-C stops on
SIGTERM the same way; the entry points tell the two apart for the exit
status (130 = 128 + SIGINT, 143 = 128 + SIGTERM).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading

#: The signals received in this process while a command ran (see interrupts_seen).
_SEEN: list[int] = []


class Terminated(KeyboardInterrupt):
    """SIGTERM received: raised in the main thread so that a run stops as on Ctrl-C."""


def _raise_terminated(signum, frame):
    _SEEN.append(signum)
    raise Terminated()


def _raise_interrupt(signum, frame):
    _SEEN.append(signum)
    raise KeyboardInterrupt


@contextlib.contextmanager
def sigterm_stops():
    """Within the block, SIGTERM raises :class:`Terminated` and Ctrl-C KeyboardInterrupt.

    Both are noted (:func:`interrupts_seen`), so that one swallowed on its way
    (raised inside a finaliser or a callback, which Python reports as
    "Exception ignored" and goes on) is still known when the run ends. Main
    thread only.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    del _SEEN[:]
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    previous_int = signal.signal(signal.SIGINT, _raise_interrupt)
    previous_hook = sys.unraisablehook
    sys.unraisablehook = _quiet_noted_interrupts(previous_hook)
    try:
        yield
    finally:
        sys.unraisablehook = previous_hook
        signal.signal(signal.SIGTERM, previous)
        signal.signal(signal.SIGINT, previous_int)


def _quiet_noted_interrupts(previous):
    """An unraisable hook that drops the interrupts this module raised and noted.

    Python prints "Exception ignored in ..." and a traceback for an exception
    raised where it cannot propagate: a ``__del__``, a weakref callback (the
    import system's module locks have one: a SIGTERM 0.15 s into the command
    line's start landed there, found by CI). The signal is noted in ``_SEEN``,
    and the run ends with its status and one line (:func:`interrupts_seen`),
    so the traceback is noise. Every other unraisable exception goes to the
    previous hook.
    """

    def hook(unraisable):
        if isinstance(unraisable.exc_value, KeyboardInterrupt) and _SEEN:
            return
        previous(unraisable)

    return hook


def interrupts_seen() -> KeyboardInterrupt | None:
    """The interrupt received within the last :func:`sigterm_stops` block, if any.

    A run whose interrupt was swallowed by a finaliser finishes normally; its
    entry point asks here and ends with the interrupt's status all the same.
    """
    if not _SEEN:
        return None
    return Terminated() if _SEEN[-1] == signal.SIGTERM else KeyboardInterrupt()


def _exit_at_once(signum, frame):
    if signum == signal.SIGTERM:
        line = b"randvib: terminated (SIGTERM)\n"
    else:
        line = b"randvib: interrupted\n"
    with contextlib.suppress(OSError):
        os.write(2, line)
    os._exit(128 + signum)


def exit_at_once_on_signals() -> None:
    """From now on Ctrl-C and SIGTERM end the process at once: one line, 130 or 143.

    For the entry points, before their imports (nothing computed yet, nothing
    to keep) and after the command returned (its results written, its locks
    released): the interpreter then runs imports, finalisers and atexit
    handlers, where a KeyboardInterrupt would print a traceback or be
    "ignored" with exit 0.
    """
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, _exit_at_once)
        signal.signal(signal.SIGTERM, _exit_at_once)


def interrupted_exit(exc: KeyboardInterrupt) -> tuple[int, str]:
    """The exit status and the one line to print for a stopped run.

    A command that knows what it kept (a sweep's finished points, where)
    says so in the interrupt's ``kept`` attribute, which replaces the
    generic "finished results were kept".
    """
    kept = getattr(exc, "kept", None) or "finished results were kept"
    if isinstance(exc, Terminated):
        return 128 + signal.SIGTERM, f"randvib: terminated (SIGTERM); {kept}"
    return 128 + signal.SIGINT, f"randvib: interrupted; {kept}"


@contextlib.contextmanager
def ctrl_c_blocked():
    """Within the block, SIGINT is blocked in this thread; one that comes stays pending.

    A blocked signal mask is inherited across fork and exec, so a process
    spawned within the block is born with SIGINT blocked (as CPython starts
    its own resource tracker); a Ctrl-C meanwhile is delivered here when the
    mask is restored: none is lost.
    """
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def worker_ignores_ctrl_c() -> None:
    """In a worker born within :func:`ctrl_c_blocked`: ignore SIGINT, then unblock it.

    A terminal's Ctrl-C reaches the whole process group; the parent alone
    stops the run (keeping what was finished) and ends its workers, so the
    user sees one line, not a traceback per worker. A Ctrl-C that came while
    the worker was still importing is pending, and is discarded by ignoring
    SIGINT before unblocking it.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


#: The name of the thread :func:`interruptible` runs a compiled loop in (none is
#: left alive once it has returned or raised).
KERNEL_THREAD = "randvib-kernel"

#: The stop flags of the compiled loops running now (:func:`interruptible`): a
#: Ctrl-C noticed by :func:`ctrl_c_noticed` sets them, so a loop stops even when
#: the KeyboardInterrupt itself is swallowed on its way to the caller.
_RUNNING_LOOPS: dict[int, object] = {}
#: The signals noticed so far by each :func:`ctrl_c_noticed` block now open: a
#: loop asked to start after one was swallowed does not start.
_OPEN_WATCHES: dict[int, list[int]] = {}


def _raise_if_noticed(noticed: list[int]) -> None:
    if noticed:
        raise Terminated() if noticed[-1] == signal.SIGTERM else KeyboardInterrupt()


@contextlib.contextmanager
def ctrl_c_noticed():
    """Within the block, a Ctrl-C (or a handled SIGTERM) stops the run even if swallowed.

    Python runs a signal handler between any two bytecodes of the main
    thread, also inside a ``__del__`` method, a weakref or gc callback or a
    ctypes callback that happens to run then; a KeyboardInterrupt raised
    there is reported as "Exception ignored" and lost, and a long run went
    on to its end (tests/test_interrupts.py reproduces it with a gc callback).
    Within the block the handler also notes the signal and sets the stop
    flag of every running compiled loop (:func:`interruptible`), then calls
    the previous handler (Python's default raises KeyboardInterrupt, the
    command line's :class:`Terminated` for SIGTERM); a block that ends
    normally after a noted signal raises it. Main thread only; a handler
    that is not a Python function (SIG_IGN: the user chose to ignore it;
    SIG_DFL for SIGTERM: the process ends) is left alone.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    noticed = []

    def notice(signum, frame):
        noticed.append(signum)
        for stop in list(_RUNNING_LOOPS.values()):
            stop[0] = 1
        previous[signum](signum, frame)

    watched = [s for s, handler in previous.items() if callable(handler)]
    for s in watched:
        signal.signal(s, notice)
    _OPEN_WATCHES[id(noticed)] = noticed  # by identity: two empty lists are equal
    try:
        yield
    finally:
        del _OPEN_WATCHES[id(noticed)]
        for s in watched:
            signal.signal(s, previous[s])
    _raise_if_noticed(noticed)  # the block ended normally: its interrupt was swallowed


def interruptible(compiled, **kwargs):
    """Call a compiled (nogil) loop so that Ctrl-C stops it within a fraction of a second.

    A compiled loop does not see signals, so it runs in a worker thread while
    this (main) thread waits; on KeyboardInterrupt the shared ``stop`` flag is
    set, the loop ends at its next check, and KeyboardInterrupt is raised
    (finished batches, points and fits are kept by the callers). The wait is
    within :func:`ctrl_c_noticed`: a Ctrl-C swallowed by a finaliser still
    stops the loop and raises here. The worker thread runs the loop on as
    many numba threads as the calling thread is set to (numba's setting is
    per thread, and a new thread starts with all of them).
    """
    import numba  # here: the command line imports this module before it needs numba
    import numpy as np

    stop = np.zeros(1, dtype=np.int64)
    if threading.current_thread() is not threading.main_thread():
        return compiled(stop=stop, **kwargs)  # signals only reach the main thread
    outcome = {}
    threads = numba.get_num_threads()
    # The loop's end is told by an Event, not by Thread.join: in Python 3.11 a
    # join(timeout) that a Ctrl-C interrupts marks the thread as stopped while it
    # still runs (CPython gh-90882), so the join after it returned at once and the
    # stopped run went on computing to its end in the background.
    finished = threading.Event()

    def target():
        try:
            numba.set_num_threads(threads)
            outcome["value"] = compiled(stop=stop, **kwargs)
        except BaseException as exc:  # handed to the caller's thread
            outcome["error"] = exc
        finally:
            finished.set()

    worker = threading.Thread(target=target, name=KERNEL_THREAD, daemon=True)
    for noticed in list(_OPEN_WATCHES.values()):  # one swallowed before this loop began
        _raise_if_noticed(noticed)
    _RUNNING_LOOPS[id(stop)] = stop
    try:
        with ctrl_c_noticed():
            worker.start()
            try:
                while not finished.wait(0.05):
                    pass
            except KeyboardInterrupt:
                stop[0] = 1
                _wait_through_interrupts(finished)
                raise
    finally:
        del _RUNNING_LOOPS[id(stop)]
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]


def _wait_through_interrupts(finished: threading.Event) -> None:
    """Wait until a stopped loop has ended, through further Ctrl-Cs.

    The loop sees its stop flag within CHECK_EVERY steps of each chunk of
    paths it is on, and each chunk it starts afterwards stops at its first
    check: a fraction of a second. Leaving before it ends would leave its thread
    computing (and holding its arrays) after the caller has moved on.
    """
    while True:
        try:
            finished.wait()
            return
        except KeyboardInterrupt:
            continue
