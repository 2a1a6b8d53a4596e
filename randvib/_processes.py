"""Whether worker processes can start here, and why not.

randvib's sweeps, paired ensembles, designs and studies run their points in
worker processes started with ``spawn`` (fork is unsafe once numba's
threading layer runs). A spawned worker imports the main program first: a
script that calls randvib at its top level, without ``if __name__ ==
"__main__":``, would run again in every worker, and each would try to start
workers of its own (multiprocessing's RuntimeError about the "bootstrapping
phase", then ``BrokenProcessPool``). :func:`why_no_processes` tells that case
(and a main program that is not a file, such as a script piped to ``python
-``) from the ones that work (a guarded script, ``python -m``, a notebook, an
interactive session, the ``randvib`` command), so that the caller runs its
points in this process instead, with a one-line :class:`WorkerProcessWarning`.

:class:`WorkerPool` and :func:`worker_start` are the local workers themselves
(:func:`randvib.montecarlo.sweep.make_executor` builds them). They live here, in a
module that imports nothing heavy, because a spawned worker imports the module of its
initializer before it can do anything else: from the sweep module that was numpy,
pandas, scipy and the analytic layer, seconds of CPU per worker before its first point.
"""

from __future__ import annotations

import ast
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor

from randvib._interrupts import ctrl_c_blocked, worker_ignores_ctrl_c


class WorkerProcessWarning(RuntimeWarning):
    """Points run in this process: worker processes could not start (the message says why)."""


def why_no_processes() -> str | None:
    """Why spawned worker processes cannot start from here, in words; None if they can."""
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if path is None:  # interactive, a notebook, ``python -c``: workers do not import it
        return None
    name = os.path.basename(path)
    if not os.path.isfile(path):
        return f"the main program {name!r} is not a file that worker processes can import"
    line = _top_level_line(main)
    if line is None or _guarded(path, line):
        return None
    return (
        f"{name} calls randvib at its top level (line {line}) without "
        '`if __name__ == "__main__":`, so each worker process would run the script again; '
        "put the script's work under that guard to use worker processes"
    )


def _top_level_line(main) -> int | None:
    """The line of the main module's top-level code now running, if it is on the stack."""
    frame = sys._getframe(1)
    while frame is not None:
        if frame.f_globals is main.__dict__ and frame.f_code.co_name == "<module>":
            return frame.f_lineno
        frame = frame.f_back
    return None


def _guarded(path: str, line: int) -> bool:
    """Whether ``line`` of the script ``path`` lies inside an ``if __name__ == "__main__":``."""
    try:
        with open(path, encoding="utf-8") as source:
            tree = ast.parse(source.read(), path)
    except (OSError, SyntaxError, UnicodeDecodeError, ValueError):
        return True  # cannot tell: leave the decision to multiprocessing
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and _is_main_test(node.test):
            first, last = node.body[0].lineno, node.body[-1].end_lineno
            if first <= line <= last:
                return True
    return False


def _is_main_test(test) -> bool:
    """``__name__ == "__main__"`` (either way round)."""
    if not (isinstance(test, ast.Compare) and len(test.ops) == 1):
        return False
    if not isinstance(test.ops[0], ast.Eq):
        return False
    sides = [test.left, test.comparators[0]]
    names = [s for s in sides if isinstance(s, ast.Name) and s.id == "__name__"]
    values = [s for s in sides if isinstance(s, ast.Constant) and s.value == "__main__"]
    return len(names) == 1 and len(values) == 1


def caller_stacklevel() -> int:
    """The ``stacklevel`` of a warning issued by the caller of this function that points
    at the first frame outside randvib (the user's line, not the library's)."""
    root = os.path.dirname(os.path.abspath(__file__))
    frame, level = sys._getframe(1), 1
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(root):
        frame, level = frame.f_back, level + 1
    return level


def worker_start(parent: int, initializer=None) -> None:
    """In each local worker: end when the parent goes, then the user's initializer.

    A sweep killed with SIGTERM or SIGKILL cannot shut its pool down; its
    workers would live on (one numba-loaded interpreter each). A daemon
    thread in every worker checks once a second that the parent is still
    there and ends the worker when it is not. A worker ignores SIGINT
    (:func:`randvib._interrupts.worker_ignores_ctrl_c`): the parent alone
    stops the sweep (keeping the finished points) and ends its workers. The
    worker was born with SIGINT blocked (:class:`WorkerPool`), so a Ctrl-C
    that came while it was still importing is discarded.
    """
    import threading

    worker_ignores_ctrl_c()

    def watch():
        while True:
            time.sleep(1.0)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, name="randvib-parent-watch", daemon=True).start()
    if initializer is not None:
        initializer()


class WorkerPool(ProcessPoolExecutor):
    """A process pool whose workers are born with SIGINT blocked.

    A spawned worker spends its first second or so importing numpy, numba and
    randvib before :func:`worker_start` can ignore SIGINT; a Ctrl-C in that
    window ended it with a KeyboardInterrupt traceback on the user's terminal.
    The pool spawns its workers inside :meth:`submit` (one per submission
    until it has ``max_workers``), so every submission blocks SIGINT in the
    submitting thread (:func:`randvib._interrupts.ctrl_c_blocked`): the
    workers inherit the mask, and a Ctrl-C meanwhile is delivered to the
    parent when the mask is restored.
    """

    def submit(self, fn, /, *args, **kwargs):
        with ctrl_c_blocked():
            return super().submit(fn, *args, **kwargs)
