"""``python -m randvib`` and the ``randvib`` console script.

Ctrl-C and SIGTERM are taken over by the first statements of this module,
before any other import, so that an interrupt while the program starts or
ends prints one line, not a traceback. What comes before them (the
interpreter's own start-up: ``site`` and the ``.pth`` files of the
environment, then ``randvib/__init__.py``) is outside the package's reach;
docs/development.md gives the measured window.
"""

import _signal  # the C module: the handler is in place before `signal`'s enum set-up runs


def _exit_at_start(signum, frame):
    """One line and 130 / 143, at once (the entry point has computed nothing yet)."""
    import os  # already loaded by the interpreter's start-up: no import work

    line = (
        b"randvib: terminated (SIGTERM)\n"
        if signum == _signal.SIGTERM
        else b"randvib: interrupted\n"
    )
    try:
        os.write(2, line)
    except OSError:
        pass
    os._exit(128 + signum)


_signal.signal(_signal.SIGINT, _exit_at_start)
_signal.signal(_signal.SIGTERM, _exit_at_start)

from randvib._interrupts import exit_at_once_on_signals  # noqa: E402  (after the handler)


def console() -> int:
    """Run the command line; an interrupt after it returned still ends non-zero, at once."""
    import os
    import sys

    from randvib.cli import main

    code = main()
    exit_at_once_on_signals()
    if code >= 128:
        # Interrupted: results kept, locks released, workers ended. Leave now, with
        # this status: CPython kills itself with SIGINT at exit (status -2, not 130)
        # when a KeyboardInterrupt once passed through C code run by an import.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code


if __name__ == "__main__":
    import sys

    sys.exit(console())
