"""``python -m randvib`` and the ``randvib`` console script.

Ctrl-C and SIGTERM are taken over before anything heavy is imported, so that
an interrupt while the program starts or ends prints one line, not a traceback.
"""

from randvib._interrupts import exit_at_once_on_signals

exit_at_once_on_signals()


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
