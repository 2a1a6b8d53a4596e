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
"""

from __future__ import annotations

import ast
import os
import sys


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
