"""Running the ``randvib`` command in-process, for the CLI tests."""

from randvib.cli import main


def run(capsys, *argv):
    """``(exit code, stdout, stderr)`` of ``randvib ARGV...``."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(capsys, argv, fragment):
    """``randvib ARGV`` exits 2 with one line on stderr containing ``fragment``, no traceback."""
    code, out, err = run(capsys, *argv)
    assert code == 2, (out, err)
    assert fragment in err, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def fit_args(path, *extra):
    """``randvib identify PATH`` with a tiny, fast search (the output-path and message tests)."""
    return ["identify", path, "--model", "coulomb", "--m", "0.0226", "--popsize", "8",
            "--generations", "2", "--no-progress", "--no-polish", *extra]  # fmt: skip
