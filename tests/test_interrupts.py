"""Interrupts that interrupt: Ctrl-C and SIGTERM stop a run, keep what finished, end its workers.

Covers :mod:`randvib._interrupts` as the package uses it, and the entry point
:mod:`randvib.__main__` (an interrupt while it starts: one line): the compiled Monte
Carlo loops of one mass and of an assembly (:func:`randvib.simulate`), which read
their stop flag with :mod:`randvib.montecarlo.stop_flag` and leave no thread
computing once stopped, the command line's exit statuses
(:mod:`randvib.cli`: 130 for Ctrl-C, 143 for SIGTERM, one line), a sweep's
worker processes (:func:`randvib.montecarlo.sweep.make_executor`: they ignore
Ctrl-C while starting and end with a killed parent), a study's folder lock
released, and the study scripts' entry point
(:func:`randvib.studies.script_main`).
"""

import _thread
import gc
import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest
from _cli import error_lines, run

import randvib as rv
from randvib import _io
from randvib._interrupts import KERNEL_THREAD
from randvib.montecarlo.simulation import simulate

ROOT = Path(__file__).resolve().parents[1]
BASE = rv.preset("figure9")


def _interrupt_after(seconds):
    timer = threading.Timer(seconds, _thread.interrupt_main)
    timer.start()
    return timer


def test_ctrl_c_stops_a_running_simulation():
    # compiled first, so that the interrupt lands inside the compiled loop
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)
    # 4e10 path-steps: many minutes on any machine (4e9 ran to its end in 60 s on two
    # cores, too close to the bound below); Ctrl-C after 1 s
    kwargs = dict(t_end=20000.0, dt=1e-4, n_paths=200, progress=False)
    timer = _interrupt_after(1.0)
    started = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        simulate(BASE, 1.0, **kwargs)
    timer.cancel()
    assert time.perf_counter() - started < 60  # stopped, not run to the end
    # and the loop itself stopped: in Python 3.11 an interrupted Thread.join marked its
    # thread as ended while it computed on in the background (CPython gh-90882)
    assert not [t for t in threading.enumerate() if t.name == KERNEL_THREAD]


def test_ctrl_c_stops_a_running_assembly_simulation():
    """The assembly kernel's loop reads its stop flag from memory at every check
    (randvib.montecarlo.stop_flag): with a plain read, LLVM read it once before the
    loop, and a Ctrl-C waited for the whole run to end."""
    device = rv.Assembly.from_harvester(BASE)
    rv.simulate(device, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)
    timer = _interrupt_after(1.0)
    started = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):  # 4e10 path-steps: many minutes on any machine
        rv.simulate(device, 1.0, t_end=20000.0, dt=1e-4, n_paths=200, progress=False)
    timer.cancel()
    assert time.perf_counter() - started < 60  # stopped, not run to the end
    assert not [t for t in threading.enumerate() if t.name == KERNEL_THREAD]


def test_compiled_loop_never_runs_in_the_main_thread(monkeypatch):
    """The cause of a Ctrl-C lost in the full suite: the long-run announcement timed a
    probe of the compiled loop by calling it in the main thread, where signal handlers
    run; a Ctrl-C that came during the probe was raised inside numba's runtime
    callback (``_numba_unpickle``) and came out as a SystemError, or not at all, and
    the run went on ("DID NOT RAISE"). The 1 s timer of
    test_ctrl_c_stops_a_running_simulation fell into the probe only when the
    machine was slow enough at that moment, hence the order dependence. Every
    call of the loop, probe included, now runs in a worker thread (interruptible)."""
    from randvib.montecarlo import kernel, resources

    compiled = kernel.run_ensemble
    threads = []

    def recorded(**kwargs):
        threads.append(threading.current_thread() is threading.main_thread())
        return compiled(**kwargs)

    monkeypatch.setattr(kernel, "run_ensemble", recorded)
    monkeypatch.setattr(resources, "PROBE_MARGIN", 1e12)  # probe even this short run
    simulate(BASE, 1.0, t_end=0.05, dt=1e-4, n_paths=16, progress=False)
    assert len(threads) >= 3  # the probe's two calls and the run
    assert not any(threads), threads


@pytest.mark.parametrize("after", [0.05, 0.3, 0.8])
def test_ctrl_c_at_any_moment_of_a_long_run_raises_keyboard_interrupt(after):
    """Whenever it comes (validation, step check, the timed probe, the loop), a Ctrl-C
    ends a long run with KeyboardInterrupt, never another exception."""
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)
    timer = _interrupt_after(after)
    started = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        simulate(BASE, 1.0, t_end=1000.0, dt=1e-4, n_paths=200, progress=False)
    timer.cancel()
    assert time.perf_counter() - started < 60


@pytest.fixture
def swallowed_ctrl_c():
    """``arm(during)``: one Ctrl-C whose handler runs inside a gc callback, and is lost.

    Python runs a signal handler between two bytecodes of the main thread, also
    inside a finaliser or a gc callback, where the KeyboardInterrupt it raises
    is "ignored" (sys.unraisablehook) and lost. A gc callback at every
    collection of a low threshold sends it at a chosen moment of a run:
    ``during="loop"`` while a compiled loop runs, ``"set-up"`` while the run
    prepares (no loop running yet).
    """
    from randvib import _interrupts

    state = {"during": None, "fired": False}

    def swallow(phase, info):
        if state["during"] is None or state["fired"]:
            return
        if threading.current_thread() is not threading.main_thread():
            return
        running = bool(_interrupts._RUNNING_LOOPS)
        if not _interrupts._OPEN_WATCHES or running != (state["during"] == "loop"):
            return
        state["fired"] = True
        _thread.interrupt_main()
        for _ in range(1000):  # the handler runs here, inside the callback
            pass

    def arm(during):
        state["during"] = during

    threshold = gc.get_threshold()
    gc.callbacks.append(swallow)
    gc.set_threshold(10)
    try:
        yield arm
    finally:
        gc.callbacks.remove(swallow)
        gc.set_threshold(*threshold)
    assert state["fired"], "the swallowed Ctrl-C was never sent: the test checked nothing"


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
@pytest.mark.parametrize("during", ["set-up", "loop"])
def test_ctrl_c_swallowed_by_a_finaliser_still_stops_a_simulation(swallowed_ctrl_c, during):
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)
    started = time.perf_counter()
    swallowed_ctrl_c(during)
    with pytest.raises(KeyboardInterrupt):
        simulate(BASE, 1.0, t_end=2000.0, dt=1e-4, n_paths=200, progress=False)
    assert time.perf_counter() - started < 60  # stopped, not run to the end


def test_threads_option_reaches_the_loop_and_is_not_left_behind():
    """``threads=`` ran the loop on every thread (numba's setting is per thread and the
    loop runs in a worker thread) and stayed set for every later run in the session."""
    import numba

    from randvib._interrupts import interruptible
    from randvib.montecarlo.options import numba_threads

    @numba.njit
    def loop_threads(stop):
        return numba.get_num_threads()

    before = numba.get_num_threads()
    with numba_threads(1):
        assert interruptible(loop_threads) == 1
    assert numba.get_num_threads() == before
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False, threads=1)
    assert numba.get_num_threads() == before


def test_ctrl_c_in_the_cli_exits_130(capsys):
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)
    timer = _interrupt_after(1.0)
    code, out, err = run(capsys, "simulate", "--preset", "figure9", "--psd", "1",
                         "--paths", "200", "--t-end", "2000", "--dt", "1e-4")  # fmt: skip
    timer.cancel()
    assert code == 130 and "interrupted" in err and "Traceback" not in err


def test_ctrl_c_in_a_study_exits_130_and_releases_its_folder(capsys, tmp_path, monkeypatch):
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)

    def long_study(out_dir, *, quick, seed, workers, scheduler, progress):
        out = _io.prepare_output_dir(out_dir, {"study": "long"})
        _io.write_tracked(out / "first.csv", "finished part\n")
        # Ctrl-C once the first part is on disk (a fixed time from the start raced with
        # the folder's set-up on a busy machine), while the long part runs
        timers.append(_interrupt_after(0.5))
        simulate(BASE, 1.0, t_end=2000.0, dt=1e-4, n_paths=200, progress=False)

    timers = []
    monkeypatch.setattr("randvib.cli.study.load_study", lambda name: long_study)
    code, out, err = run(capsys, "study", "interaction", "--out", tmp_path / "s")
    for timer in timers:
        timer.cancel()
    assert code == 130 and "Traceback" not in err
    assert (tmp_path / "s" / "first.csv").read_text() == "finished part\n"  # kept
    assert not (tmp_path / "s" / _io.LOCK_FILE).exists()


def _subprocess_env():
    return {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
        "NUMBA_NUM_THREADS": "1",
    }


def test_sigterm_stops_simulate_and_exits_143():
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)  # numba cache warm
    # 4e10 path-steps: its LongRunWarning is printed once the run starts
    argv = ["simulate", "--preset", "figure9", "--psd", "1", "--paths", "200",
            "--t-end", "20000", "--dt", "1e-4"]  # fmt: skip
    child = subprocess.Popen(
        [sys.executable, "-m", "randvib", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_subprocess_env(),
    )
    assert "will take about" in child.stderr.readline()
    time.sleep(0.5)
    child.send_signal(signal.SIGTERM)
    out, err = child.communicate(timeout=60)
    assert child.returncode == 143, err
    assert "terminated" in err and "Traceback" not in err and len(error_lines(err)) == 1


@pytest.mark.parametrize(
    "stop, code",
    [(KeyboardInterrupt, 130), ("sigterm", 143)],
)
def test_study_script_main_stops_with_one_line(capsys, tmp_path, stop, code):
    """``python studies/NAME.py OUT``: Ctrl-C and SIGTERM end with 130 / 143 and
    one line (they printed a KeyboardInterrupt traceback)."""
    from randvib.studies import script_main

    def run_study(out_dir, *, quick, seed, workers, scheduler, progress):
        """A study stopped while it runs."""
        if stop == "sigterm":
            os.kill(os.getpid(), signal.SIGTERM)  # handled: raises Terminated here
            time.sleep(5)
        raise stop()

    run_study.__module__ = __name__
    assert script_main(run_study, [str(tmp_path / "o")]) == code
    err = capsys.readouterr().err
    assert len(error_lines(err)) == 1 and "Traceback" not in err


def test_sweep_workers_end_when_the_sweep_is_killed(tmp_path):
    script = textwrap.dedent(
        """
        import os, sys, time
        sys.path.insert(0, sys.argv[1])
        from trust_worker import pid
        if __name__ == "__main__":
            # imported here, not by the workers (which run this file first): they
            # import only randvib._processes, the home of their entry point
            from randvib.montecarlo.sweep import make_executor
            pool, close = make_executor(workers=2)
            print(" ".join(map(str, set(pool.map(pid, range(16))))), flush=True)
            time.sleep(120)
        """
    )
    (tmp_path / "trust_worker.py").write_text(
        "import os, time\ndef pid(_):\n    time.sleep(0.2)\n    return os.getpid()\n"
    )
    (tmp_path / "main.py").write_text(script)
    parent = subprocess.Popen(
        [sys.executable, str(tmp_path / "main.py"), str(tmp_path)],
        stdout=subprocess.PIPE,
        text=True,
        env={
            **os.environ,
            "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
        },
    )
    workers = [int(p) for p in parent.stdout.readline().split()]
    assert workers
    parent.send_signal(signal.SIGKILL)
    parent.wait()
    deadline = time.monotonic() + 30
    alive = workers
    while alive and time.monotonic() < deadline:
        time.sleep(0.2)
        alive = [p for p in workers if _alive(p)]
    assert alive == []


def test_sweep_workers_ignore_ctrl_c_while_they_are_still_starting(tmp_path):
    """Found by CI: a Ctrl-C that reached a worker while it was still importing
    (before its initializer could ignore SIGINT) printed a KeyboardInterrupt
    traceback from multiprocessing's spawn_main. SIGINT sent to every worker
    the moment they are spawned, long before any has imported randvib: the pool
    still works and nothing is written to stderr."""
    script = textwrap.dedent(
        """
        import os, signal
        if __name__ == "__main__":
            from randvib.montecarlo.sweep import make_executor  # not in the workers
            pool, close = make_executor(workers=2)
            futures = [pool.submit(abs, i) for i in range(-8, 0)]  # spawns both workers
            pids = [p.pid for p in pool._processes.values()]
            for pid in pids:
                os.kill(pid, signal.SIGINT)
            print(len(pids), sum(f.result() for f in futures), flush=True)
            close()
        """
    )
    (tmp_path / "main.py").write_text(script)
    done = subprocess.run(
        [sys.executable, str(tmp_path / "main.py")],
        capture_output=True,
        text=True,
        timeout=600,  # spawning two numba-loaded workers on a busy machine
        env=_subprocess_env(),
    )
    assert (done.returncode, done.stdout.split(), done.stderr) == (0, ["2", "36"], "")


def _alive(pid):
    try:
        os.waitpid(pid, os.WNOHANG)  # reap if it happens to be our child
    except ChildProcessError:
        pass
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    status = Path(f"/proc/{pid}/status")
    return not (status.exists() and "zombie" in status.read_text())


def test_documented_sweep_example_has_the_main_guard():
    readme = (ROOT / "docs" / "studies.md").read_text()
    block = readme[readme.index("from randvib.montecarlo.sweep import SweepSettings") :]
    block = block[: block.index("```")]
    assert 'if __name__ == "__main__":' in block
    assert block.index("__main__") < block.index("run_sweep(")
    assert "trust" in readme[readme.index("scheduler=` (and `--scheduler`)") :][:300]


SWEEP_STUDY = """
import sys
import randvib as rv
import randvib.cli.study
from randvib.cli import main
from randvib.montecarlo.sweep import SweepSettings, cartesian, run_sweep


def sweep_study(out_dir, *, quick, seed, workers, scheduler, progress):
    # 2000 small points on 2 worker processes: minutes, far longer than the test waits
    settings = SweepSettings(dt=2e-4, window=1.0, burn_in=0.05, target_rel_ci=0.5,
                             min_paths=8, batch_paths=8, max_paths=8)
    points = cartesian(psd=[1.0 + i / 1000 for i in range(2000)])
    run_sweep(rv.preset("figure9"), points, settings, out_dir=out_dir, workers=workers,
              progress=False)


if __name__ == "__main__":
    randvib.cli.study.load_study = lambda name: sweep_study
    sys.exit(main(["study", "interaction", "--out", sys.argv[1], "--workers", "2"]))
"""


def _children(pid):
    """Process ids whose parent is ``pid`` (Linux /proc)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


@pytest.mark.parametrize(
    "how, code",
    [("ctrl-c", 130), ("sigterm", 143)],
)
def test_interrupted_process_pool_sweep_keeps_points_and_ends_workers(tmp_path, how, code):
    """Ctrl-C (SIGINT to the whole process group, as a terminal sends it) or
    SIGTERM (to the parent only) on a sweep over 2 worker processes: exit
    130 / 143, no worker left, the finished points kept and valid, the lock gone."""
    simulate(BASE, 1.0, t_end=0.01, dt=2e-4, n_paths=2, progress=False)  # numba cache warm
    script, out = tmp_path / "sweep_study.py", tmp_path / "out"
    script.write_text(SWEEP_STUDY)
    child = subprocess.Popen(
        [sys.executable, str(script), str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_subprocess_env(),
        start_new_session=True,  # its own process group, as a shell job
    )
    deadline = time.monotonic() + 120
    while not list(out.glob("points/*.json")) and time.monotonic() < deadline:
        assert child.poll() is None, child.communicate()
        time.sleep(0.1)
    workers = _children(child.pid)
    assert len(workers) >= 2  # the two workers (and spawn's resource tracker)
    if how == "ctrl-c":
        os.killpg(child.pid, signal.SIGINT)
    else:
        child.send_signal(signal.SIGTERM)
    _, err = child.communicate(timeout=60)
    assert child.returncode == code, err
    assert "Traceback" not in err and len(error_lines(err)) == 1, err
    deadline = time.monotonic() + 30
    while any(_alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not [p for p in workers if _alive(p)]
    assert not (out / _io.LOCK_FILE).exists()
    points = sorted(out.glob("points/*.json"))
    assert 1 <= len(points) < 2000
    for p in points:
        stored = json.loads(p.read_text())
        assert math.isfinite(stored["row"]["power_electrical"])


def _wait_until_it_catches(pid: int, signum: int, timeout: float = 60.0) -> None:
    """Wait until process ``pid`` has a handler for ``signum`` (Linux: SigCgt in /proc)."""
    status = Path(f"/proc/{pid}/status")
    if not status.exists():
        return  # no /proc: the delays count from "ready", as before
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            caught = next(
                int(line.split()[1], 16)
                for line in status.read_text().splitlines()
                if line.startswith("SigCgt:")
            )
        except (OSError, StopIteration):  # the process has ended
            return
        if caught & (1 << (signum - 1)):
            return
        time.sleep(0.001)


@pytest.mark.parametrize("how, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupt_while_the_command_line_starts_prints_no_traceback(how, code):
    # The signal lands at several moments of the start (imports, parser, warnings set-up,
    # the command); every one ends with one line and the signal's status (randvib.__main__).
    # The delays count from the end of the interpreter's own start (site), which no
    # program can guard: "ready" is printed once it is over, then `python -m randvib` runs.
    start = (
        "import os, runpy, sys; os.write(2, b'ready\\n'); "
        "sys.argv = ['randvib', 'power', '--preset', 'figure9', '--psd', '1']; "
        "runpy.run_module('randvib', run_name='__main__', alter_sys=True)"
    )
    for delay in (0.0, 0.05, 0.15, 0.3, 0.5):
        child = subprocess.Popen(
            [sys.executable, "-c", start],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=_subprocess_env(),
        )
        assert child.stderr.readline() == "ready\n"
        # from the moment __main__'s first statements caught SIGTERM (they install both
        # handlers at once): on a loaded machine the child may wait 50 ms for a core
        # after "ready", and a signal then tested the scheduler, not randvib (the
        # window before the handler is test_..._entry_points_first_import_...'s)
        _wait_until_it_catches(child.pid, signal.SIGTERM)
        time.sleep(delay)
        child.send_signal(how)
        out, err = child.communicate(timeout=60)
        if child.returncode == 0:
            continue  # finished before the signal came
        assert child.returncode == code, (delay, err)
        assert "Traceback" not in err and len(error_lines(err)) == 1, (delay, err)


@pytest.mark.parametrize("how, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupt_during_the_entry_points_first_import_prints_one_line(how, code):
    # The signal is sent from inside the import of randvib._interrupts (a meta-path
    # hook), the first import of randvib.__main__: the handler must already be in
    # place, installed by __main__'s first statements through the C module _signal.
    start = textwrap.dedent(f"""
        import os, runpy, sys
        class Kick:
            def find_spec(self, name, path=None, target=None):
                if name == "randvib._interrupts":
                    os.kill(os.getpid(), {int(how)})
                return None
        sys.meta_path.insert(0, Kick())
        sys.argv = ["randvib", "power", "--preset", "figure9", "--psd", "1"]
        runpy.run_module("randvib", run_name="__main__", alter_sys=True)
    """)
    child = subprocess.run(
        [sys.executable, "-c", start],
        capture_output=True,
        text=True,
        env=_subprocess_env(),
        timeout=60,
    )
    assert child.returncode == code, child.stderr
    assert "Traceback" not in child.stderr and len(error_lines(child.stderr)) == 1, child.stderr


def test_interrupt_swallowed_by_a_finaliser_still_ends_non_zero(capsys, monkeypatch):
    # Ctrl-C raised inside a finaliser is "ignored" by Python and the command goes on to
    # finish: the user asked it to stop, so the status must still say it was stopped.
    from randvib.cli import power

    class Finalised:
        def __del__(self):
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.2)  # the handler runs here, inside __del__

    real = power.run

    def run_with_a_finaliser(args):
        Finalised()  # collected at once: its __del__ swallows the KeyboardInterrupt
        return real(args)

    monkeypatch.setattr(power, "run", run_with_a_finaliser)  # looked up by register()
    # Python reports the swallowed interrupt to sys.unraisablehook, whose default prints
    # "Exception ignored in ..." and a traceback (a SIGTERM in an import lock's weakref
    # callback did, in CI); the command line drops the interrupts it noted
    reported = []
    monkeypatch.setattr(sys, "unraisablehook", reported.append)
    code, out, err = run(capsys, "power", "--preset", "figure9", "--psd", "1")
    assert "power_electrical" in out  # the command did finish
    assert code == 130 and "randvib: interrupted" in err
    assert reported == [] and "Traceback" not in err and len(error_lines(err)) == 1, err
