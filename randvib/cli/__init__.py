"""Command line: ``randvib <command> ...``.

Each command lives in its own module exposing ``register(subparsers)`` which
adds its parser and sets ``handler``; :data:`COMMANDS` lists the modules.
Every user error (bad value, unknown name, unreadable file) ends with one
line on stderr and exit status 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import re
import sys

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
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        return int(args.handler(args) or 0)
    except (
        UserError,
        ValueError,
        FileNotFoundError,
        FileExistsError,
        PermissionError,
        NotImplementedError,
    ) as exc:
        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if not message.startswith("randvib"):
            message = f"randvib: error: {message}"
        print(message, file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("randvib: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
