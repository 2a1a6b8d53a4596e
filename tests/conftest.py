import os
import signal
import sys
import threading
from pathlib import Path

import pytest  # imports no matplotlib, so the backend below is still in time

os.environ.setdefault("MPLBACKEND", "Agg")

from randvib._interrupts import KERNEL_THREAD  # noqa: E402 (imports neither numba nor matplotlib)

ROOT = Path(__file__).resolve().parents[1]


def _visible_entries(folder: Path) -> set[str]:
    return {p.name for p in folder.iterdir() if not p.name.startswith(".")}


@pytest.fixture(autouse=True, scope="session")
def _nothing_written_into_the_checkout():
    """The tests write only under pytest's tmp_path: three CSV records named
    -1, 0 and nan (a test giving `--out` bad values from the checkout) were once
    committed by accident. Fails the session if the project root gains a file."""
    before = _visible_entries(ROOT)
    yield
    new = sorted(_visible_entries(ROOT) - before - {"__pycache__"})
    assert not new, f"the tests wrote {new} into {ROOT}; write under tmp_path"


#: Signals whose handlers the package and its tests install (Ctrl-C, SIGTERM).
_HANDLED_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class _ProcessState:
    """What one test could change for the tests after it, read at one moment.

    Signal handlers and the signal mask (Ctrl-C tests, the command line's
    handlers), the environment, the working directory, numpy's error state,
    matplotlib's rcParams, the friction-law registry (a test may define a law),
    and the threads alive (a test's timer that sends Ctrl-C later).
    """

    def __init__(self):
        import numpy as np

        from randvib.models.friction import FRICTION_MODELS

        self.handlers = {s: signal.getsignal(s) for s in _HANDLED_SIGNALS}
        self.mask = signal.pthread_sigmask(signal.SIG_BLOCK, [])
        self.environ = dict(os.environ)
        self.cwd = os.getcwd()
        self.numpy_errors = np.geterr()
        self.friction_laws = dict(FRICTION_MODELS)
        self.threads = set(threading.enumerate())
        mpl = sys.modules.get("matplotlib")
        self.rc = None if mpl is None else dict(mpl.rcParams)
        numba = sys.modules.get("numba")
        self.numba_threads = None if numba is None else numba.get_num_threads()

    def changes(self, after: "_ProcessState") -> list[str]:
        """What differs in ``after``, in words (threads are handled apart)."""
        found = [
            f"the handler of {signal.Signals(s).name}"
            for s in _HANDLED_SIGNALS
            if after.handlers[s] != self.handlers[s]
        ]
        if after.mask != self.mask:
            found.append("the signal mask")
        if after.environ != self.environ:
            keys = sorted(set(after.environ.items()) ^ set(self.environ.items()))
            found.append(f"the environment ({sorted({k for k, _ in keys})})")
        if after.cwd != self.cwd:
            found.append("the working directory")
        if after.numpy_errors != self.numpy_errors:
            found.append("numpy's error state (np.seterr)")
        if after.friction_laws != self.friction_laws:
            found.append("the friction-law registry")
        return found

    def restore(self) -> None:
        import numpy as np

        from randvib.models.friction import FRICTION_MODELS

        for s, handler in self.handlers.items():
            if handler is not None:  # None: installed from C, cannot be set again
                signal.signal(s, handler)
        signal.pthread_sigmask(signal.SIG_SETMASK, self.mask)
        os.environ.clear()
        os.environ.update(self.environ)
        os.chdir(self.cwd)
        np.seterr(**self.numpy_errors)
        FRICTION_MODELS.clear()
        FRICTION_MODELS.update(self.friction_laws)
        mpl = sys.modules.get("matplotlib")
        if mpl is not None and self.rc is not None:
            mpl.rcParams.update(self.rc)
        if self.numba_threads is not None:
            sys.modules["numba"].set_num_threads(self.numba_threads)


@pytest.fixture(autouse=True)
def _process_state_restored(request):
    """Every test starts from the same process state and leaves it as it found it.

    A test starts as a fresh interpreter does: Ctrl-C raises KeyboardInterrupt
    (an xdist worker or an earlier test may have changed the handler). After
    it, timers it started are cancelled (a Ctrl-C timer firing in a later test
    stopped the wrong test), a compiled loop's thread it started is given a moment to
    end (one still running fails the test: a stopped run that computed on in the
    background cost the later tests minutes of CPU), and
    signal handlers, mask, environment, working directory, numpy's error state,
    rcParams, the friction-law registry and numba's thread count are put back. A test that changed
    the signal handlers, the signal mask or the working directory without
    restoring them itself fails here, naming what it left behind: tests must
    restore what they change (monkeypatch, tmp_path), so that none depends on
    another.
    """
    # The handler the process had (SIG_IGN in a job started in the background) is put
    # back at the end; the test is judged against the state it started in.
    inherited_int = signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    before = _ProcessState()
    yield
    running = []
    for thread in set(threading.enumerate()) - before.threads:
        if isinstance(thread, threading.Timer):
            thread.cancel()
            thread.join(5)
        elif thread.name == KERNEL_THREAD:  # a stopped run must not compute on
            thread.join(5)
            if thread.is_alive():
                running.append(thread)
    after = _ProcessState()
    before.restore()
    signal.signal(signal.SIGINT, inherited_int)
    left = [
        c
        for c in before.changes(after)
        if c.startswith(("the handler", "the signal", "the working"))
    ]
    if left:
        pytest.fail(f"{request.node.nodeid} left {', '.join(left)} changed", pytrace=False)
    if running:
        pytest.fail(f"{request.node.nodeid} left a compiled loop running", pytrace=False)


@pytest.fixture(scope="module")
def record_csv(tmp_path_factory):
    """A 2 s synthetic record of the Coulomb TD1 device, and its fitted-parameter file."""
    import json

    import randvib as rv

    folder = tmp_path_factory.mktemp("records")
    path = folder / "rec.csv"
    record = rv.synthetic_record(
        rv.preset("coulomb-td1"), 2.0, duration=2.0, sample_rate=1000.0, seed=1
    )
    record.to_csv(path, float_format=None)
    params = folder / "params.json"
    params.write_text(
        json.dumps(
            {
                "model": "coulomb",
                "parameters": {"m": 0.0226, "c": 0.049, "k": 57.4, "k3": 70742.0, "fc": 0.0058},
                "settings": {"substeps": 4},
            }
        )
    )
    return path, params


# ---------------------------------------------------------------- where the time goes
# RANDVIB_TEST_CPU=FILE appends one line per test phase to FILE: the CPU seconds the
# phase spent in this process (every thread: numba's too) and in the subprocesses it
# waited for, beside its wall time. CPU time hardly depends on what else the machine
# runs, so it says where a shared machine's suite spends its time (docs/testing.md).
_CPU_LOG = os.environ.get("RANDVIB_TEST_CPU")


def _cpu_seconds() -> float:
    import resource

    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


if _CPU_LOG:
    import time

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(item, nextitem):
        cpu, wall = _cpu_seconds(), time.perf_counter()
        yield
        with open(_CPU_LOG, "a") as log:
            log.write(
                f"{_cpu_seconds() - cpu:.3f}\t{time.perf_counter() - wall:.3f}\t{item.nodeid}\n"
            )


# ---------------------------------------------------------------- running in parallel
# The suite runs on pytest-xdist's workers with --dist loadfile (pyproject.toml): each
# test module runs on one worker, so a fixture built once per module (a built site, a
# study's quick run) is built once. (--dist loadgroup would share modules out finer,
# but pytest-xdist 3.8 marks its groups on Node._nodeid, which pytest 9 no longer
# reads: every group was split over the workers and the site was built twice.) Modules
# are handed out in collection order (--no-loadscope-reorder), and the ones that take
# longest (measured with RANDVIB_TEST_CPU, docs/testing.md) are moved to the front so
# that neither worker is left with a long module at the end. pytest-randomly shuffles
# the order first (a new seed every run, printed in the header): an order dependence
# shows up as a failure that `--randomly-seed=N` repeats (`-p no:randomly` keeps the
# file order).

#: Test modules moved to the front of the queue, longest first.
LONG_MODULES = (
    "test_docs.py",
    "test_mutations.py",
)


def pytest_configure(config):
    """Workers use one BLAS thread each: two workers on two cores with a BLAS pool each
    ran a least-squares study twice as long in CPU (measured: 27.7 against 14.3 s).
    Set before xdist starts the workers, which inherit it; serial runs keep theirs."""
    if getattr(config.option, "numprocesses", None) and not hasattr(config, "workerinput"):
        for name in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
            os.environ.setdefault(name, "1")
    if hasattr(config, "workerinput"):
        _start_compile_log(config)


def pytest_collection_modifyitems(config, items):

    def rank(item):
        name = item.path.name
        return LONG_MODULES.index(name) if name in LONG_MODULES else len(LONG_MODULES)

    items.sort(key=rank)  # stable: the shuffled order is kept within each rank


# ---------------------------------------------------------------- compiled once per run
# The compiled kernels (numba, cache=True) cost 30-100 CPU-s each on a cold cache, and
# two workers that need the same one compiled it twice at once. Before xdist starts its
# workers (its own pytest_sessionstart runs last), the controller runs the two halves of
# tests/_warm_kernels.py in parallel subprocesses, which compile or load every signature
# the suite uses; the workers then only load them. Each worker lists what it still
# compiled (numba's "numba:compile" event, cache misses only), and the controller prints
# the list in the summary: a kernel to add to tests/_warm_kernels.py.
_WARM_SCRIPT = Path(__file__).with_name("_warm_kernels.py")
_COMPILED_KEY = "randvib_compiled"


def _parallel_controller(config) -> bool:
    """True in the controller of a pytest-xdist run with workers (not in a worker, not -n 0)."""
    workers = getattr(config.option, "numprocesses", None)
    return bool(workers) and not hasattr(config, "workerinput")


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session):
    """Warm the numba cache before the workers start; one line says how long it took."""
    config = session.config
    if not _parallel_controller(config) or config.option.collectonly:
        return
    import subprocess
    import time

    import randvib  # the package the tests import; the script imports the same one

    started = time.perf_counter()
    package_root = str(Path(randvib.__file__).resolve().parents[1])
    path = os.pathsep.join(filter(None, [package_root, os.environ.get("PYTHONPATH")]))
    env = dict(os.environ, NUMBA_NUM_THREADS="1", PYTHONPATH=path)
    halves = {
        name: subprocess.Popen(
            [sys.executable, str(_WARM_SCRIPT), name],
            cwd=ROOT,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        for name in ("single", "assembly")
    }
    failed = []
    for name, process in halves.items():
        output, _ = process.communicate()
        if process.returncode != 0:
            last = (output.strip().splitlines() or ["no output"])[-1]
            failed.append(f"{name}: {last}")
    took = time.perf_counter() - started
    reporter = config.pluginmanager.get_plugin("terminalreporter")
    if failed:
        line = (
            f"numba warm-up (tests/_warm_kernels.py) failed after {took:.0f} s "
            f"({'; '.join(failed)}); the workers compile what they need"
        )
    else:
        line = f"numba kernels warmed in {took:.1f} s (tests/_warm_kernels.py)"
    if reporter is not None:
        reporter.write_line(line)


class _CompileLog:
    """The randvib functions numba compiled in this process (outermost compilations)."""

    def __init__(self):
        self.compiled = []
        self.depth = 0

    def listener(self):
        from numba.core import event

        log = self

        class Listener(event.Listener):
            def on_start(self, ev):
                if log.depth == 0:
                    function = ev.data["dispatcher"].py_func
                    if function.__module__.startswith("randvib"):
                        name = f"{function.__module__}.{function.__qualname__}"
                        log.compiled.append(name.removeprefix("randvib."))
                log.depth += 1

            def on_end(self, ev):
                log.depth -= 1

        return Listener()


_compile_log_key = pytest.StashKey[_CompileLog]()
_compiled_key = pytest.StashKey[list]()


def _start_compile_log(config):
    """In a worker: record numba's compilations of randvib functions from now on."""
    from numba.core import event

    log = _CompileLog()
    event.register("numba:compile", log.listener())
    config.stash[_compile_log_key] = log


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session):
    """In a worker: hand the list of compilations to the controller."""
    config = session.config
    log = config.stash.get(_compile_log_key, None)
    if log is not None and hasattr(config, "workeroutput"):
        config.workeroutput[_COMPILED_KEY] = log.compiled


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """In the controller: collect a worker's compilations."""
    compiled = getattr(node, "workeroutput", {}).get(_COMPILED_KEY, [])
    node.config.stash.setdefault(_compiled_key, []).extend(compiled)


def pytest_terminal_summary(terminalreporter, config):
    """One line naming what the workers still compiled (cache misses after the warm-up)."""
    compiled = config.stash.get(_compiled_key, [])
    if compiled:
        counts = {name: compiled.count(name) for name in dict.fromkeys(compiled)}
        names = ", ".join(f"{name} x{n}" if n > 1 else name for name, n in counts.items())
        terminalreporter.write_line(
            f"numba compiled during the tests (add to tests/_warm_kernels.py): {names}"
        )
