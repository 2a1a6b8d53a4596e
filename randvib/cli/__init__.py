"""Command line: ``randvib <command> ...``.

Each command lives in its own module exposing ``register(subparsers)`` which
adds its parser and sets ``handler``; :data:`COMMANDS` lists the modules.
Every user error (bad value, unknown name, unreadable or unwritable file)
ends with one line on stderr and exit status 2, never a traceback; Ctrl-C
ends with exit status 130 and SIGTERM with 143 (128 + 15), both keeping
what was finished, releasing folder locks and ending worker processes.
Anything else that
escapes a command is a bug: one line naming it, exit status 1, and the
traceback only with ``RANDVIB_TRACEBACK=1``.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
import warnings

from randvib._interrupts import interrupted_exit, sigterm_stops

#: Command modules under randvib.cli, in the order shown by --help.
COMMANDS = ["power", "simulate", "study", "record", "identify", "validate"]


class UserError(Exception):
    """An error caused by the user's input; printed as one line, exit 2."""


#: What argparse takes for a negative number (not an option): its own pattern
#: misses exponents, so `--k3 -5e5` would be read as a missing value.
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message):  # one line, no usage dump, exit 2
        raise UserError(f"{self.prog}: {message}")


def build_parser() -> argparse.ArgumentParser:
    from randvib import __version__

    parser = _Parser(prog="randvib", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"randvib {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"randvib.cli.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"randvib.cli.{name}":
                continue  # command not built yet
            raise
        module.register(sub)
    return parser


def main(argv=None) -> int:
    with warnings.catch_warnings():
        # numpy's floating-point warnings at extreme values: every result is
        # checked for finiteness instead, and refused with a message naming it
        warnings.filterwarnings("ignore", category=RuntimeWarning, module=r"(numpy|scipy|randvib)")
        warnings.filterwarnings("ignore", message=r"Matrix is exactly singular")
        warnings.showwarning = _show_warning
        with sigterm_stops():
            return _main(argv)


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """A warning as one line naming its kind (no source file, no code line)."""
    print(f"randvib: warning ({category.__name__}): {message}", file=file or sys.stderr)


def _main(argv) -> int:
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        return int(args.handler(args) or 0)
    except (UserError, ValueError, OSError, NotImplementedError) as exc:
        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if not message.startswith("randvib"):
            message = f"randvib: error: {message}"
        print(message, file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (Terminated)
        code, line = interrupted_exit(exc)
        print(line, file=sys.stderr)
        return code
    except Exception as exc:  # a bug: one line, not a traceback (unless asked for)
        if os.environ.get("RANDVIB_TRACEBACK"):
            raise
        text = str(exc).strip().splitlines()
        print(
            f"randvib: internal error: {type(exc).__name__}: {text[0] if text else ''} "
            "(please report it; RANDVIB_TRACEBACK=1 shows the traceback)",
            file=sys.stderr,
        )
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
