"""Worker processes from a plain script: detected, and the points run in this process.

Covers :mod:`randvib._processes` (whether spawned workers can start: an unguarded
script's top-level call, a main program that is not a file) and its use by
:func:`randvib.montecarlo.sweep.make_executor`, the one place where sweeps, paired
ensembles, designs and studies start processes; and the control variates a sweep
point uses where they hold (:func:`randvib.montecarlo.sweep.simulate_to_precision`
under a filtered and a synthesised input, as :func:`randvib.design` runs it).

Before (issue 35, item 8): ``rv.design`` at a script's top level ended with three
multiprocessing RuntimeErrors ("bootstrapping phase") and BrokenProcessPool.
"""

import subprocess
import sys
import textwrap

import pytest

import randvib as rv
from randvib._processes import _guarded, why_no_processes
from randvib.montecarlo.sweep import SweepSettings, simulate_to_precision

#: A script asking whether workers could start (light: randvib._processes imports no numba).
PROBE = """
from randvib._processes import why_no_processes
{indent}print(why_no_processes() or "workers can start")
"""


def _run(argv, **kwargs):
    return subprocess.run(
        [sys.executable, *argv], capture_output=True, text=True, timeout=60, check=False, **kwargs
    )


def test_an_unguarded_script_is_told_from_a_guarded_one(tmp_path):
    unguarded = tmp_path / "plain.py"
    unguarded.write_text(PROBE.format(indent=""))
    done = _run([str(unguarded)])
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == (
        'plain.py calls randvib at its top level (line 3) without `if __name__ == "__main__":`, '
        "so each worker process would run the script again; put the script's work under that "
        "guard to use worker processes"
    )
    guarded = tmp_path / "guarded.py"
    guarded.write_text(
        PROBE.format(indent="    ").replace(
            "\n    print", '\nif __name__ == "__main__":\n    print'
        )
    )
    done = _run([str(guarded)])
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "workers can start"
    # a script piped to `python -`: the workers have no file to import
    done = _run(["-"], input=PROBE.format(indent=""), cwd=tmp_path)
    assert "'<stdin>' is not a file that worker processes can import" in done.stdout
    # no main file at all (`python -c`, a notebook): workers do not import it
    done = _run(
        ["-c", "from randvib._processes import why_no_processes; print(why_no_processes())"]
    )
    assert done.stdout.strip() == "None", done.stderr


def test_the_guard_is_found_whichever_way_it_is_written(tmp_path):
    script = tmp_path / "s.py"
    script.write_text(
        textwrap.dedent(
            """\
            import randvib
            top = 1
            if "__main__" == __name__:
                inside = 1
                also = 2
            if __name__ != "__main__":
                not_a_guard = 1
            """
        )
    )
    assert not _guarded(str(script), 2)
    assert _guarded(str(script), 4) and _guarded(str(script), 5)
    assert not _guarded(str(script), 7)
    assert why_no_processes() is None  # pytest's own main is guarded


def test_make_executor_runs_in_process_with_one_line_at_the_users_call(monkeypatch):
    """Where workers cannot start, every sweep, ensemble, design and study runs its points
    here (no executor) and says why in one warning pointing at the caller's line."""
    from randvib.montecarlo import sweep

    monkeypatch.setattr(sweep, "why_no_processes", lambda: "the reason")
    with pytest.warns(sweep.WorkerProcessWarning) as caught:
        executor, close = sweep.make_executor(2)
    assert executor is None
    close()
    (warning,) = caught
    assert str(warning.message) == "running in this process, not 2 worker processes: the reason"
    assert warning.filename == __file__ and "\n" not in str(warning.message)


@pytest.mark.parametrize(
    "excitation", [rv.BandPass(1.0, 8.0, 0.2), rv.BandLimited(1.0, 4.0, 20.0)], ids=str
)
def test_a_sweep_point_uses_the_controls_that_hold_under_its_input(excitation):
    """rv.design's default settings ask for control variates; under a filtered input
    the companion (white noise only) was requested anyway and refused, under a
    synthesised one every control: the point now uses those that hold."""
    settings = SweepSettings(dt=5e-4, window=0.3, burn_in=0.1, min_paths=8, max_paths=8)
    result = simulate_to_precision(rv.preset("figure9"), excitation, settings, seed=1)
    assert result.n_paths == 8
    assert result.control_variates == (excitation.shaping_filter() is not None)
