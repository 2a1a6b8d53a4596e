"""Running the ``randvib`` command in-process, for the CLI tests."""

from randvib.cli import COMPILING, main


def run(capsys, *argv):
    """``(exit code, stdout, stderr)`` of ``randvib ARGV...``."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(capsys, argv, fragment):
    """``randvib ARGV`` exits 2 with one line on stderr containing ``fragment``, no traceback.

    The one-time notice that the kernels are being compiled (printed on a fresh
    machine before the work starts, whatever the outcome) is not part of the error.
    """
    code, out, err = run(capsys, *argv)
    assert code == 2, (out, err)
    assert fragment in err, err
    assert len(error_lines(err)) == 1 and "Traceback" not in err, err


def error_lines(err):
    """The lines of ``err`` less the one-time notice that the kernels are being compiled."""
    return [line for line in err.strip().splitlines() if line != COMPILING]


def fit_args(path, *extra):
    """``randvib identify PATH`` with a tiny, fast search (the output-path and message tests)."""
    return ["identify", path, "--model", "coulomb", "--m", "0.0226", "--popsize", "8",
            "--generations", "2", "--no-progress", "--no-polish", *extra]  # fmt: skip
