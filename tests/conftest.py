import os
import signal
import sys
import threading
from pathlib import Path

import pytest  # imports no matplotlib, so the backend below is still in time

os.environ.setdefault("MPLBACKEND", "Agg")

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
    stopped the wrong test), threads it started are given a moment to end, and
    signal handlers, mask, environment, working directory, numpy's error state,
    rcParams, the friction-law registry and numba's thread count are put back. A test that changed
    the signal handlers, the signal mask or the working directory without
    restoring them itself fails here, naming what it left behind: tests must
    restore what they change (monkeypatch, tmp_path), so that none depends on
    another.
    """
    before = _ProcessState()
    signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    for thread in set(threading.enumerate()) - before.threads:
        if isinstance(thread, threading.Timer):
            thread.cancel()
            thread.join(5)
    after = _ProcessState()
    before.restore()
    left = [
        c
        for c in before.changes(after)
        if c.startswith(("the handler", "the signal", "the working"))
    ]
    if left:
        pytest.fail(f"{request.node.nodeid} left {', '.join(left)} changed", pytrace=False)


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
# The suite runs on pytest-xdist's workers with --dist loadgroup (pyproject.toml): a
# test joins its module's group when it uses a module- or class-scoped fixture (a
# built site, a study's quick run, the mutants), so that the fixture is built on one
# worker only; other tests are shared out one by one. Groups are handed out in
# collection order, and the modules that take longest (measured with
# RANDVIB_TEST_CPU, docs/testing.md) are moved to the front so that neither worker is
# left with a long module at the end. pytest-randomly shuffles the order first (a
# new seed every run, printed in the header): an order dependence shows up as a
# failure that `--randomly-seed=N` repeats (`-p no:randomly` keeps the file order).

#: Test modules moved to the front of the queue, longest first.
LONG_MODULES = (
    "test_mutations.py",
    "test_docs.py",
)


def _shared_scope(item) -> bool:
    """Whether the test uses a fixture built once per module or class."""
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return False
    for definitions in info.name2fixturedefs.values():
        if definitions and definitions[-1].scope in ("module", "class", "package"):
            return True
    return False


def pytest_configure(config):
    """Workers use one BLAS thread each: two workers on two cores with a BLAS pool each
    ran a least-squares study twice as long in CPU (measured: 27.7 against 14.3 s).
    Set before xdist starts the workers, which inherit it; serial runs keep theirs."""
    if getattr(config.option, "numprocesses", None) and not hasattr(config, "workerinput"):
        for name in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
            os.environ.setdefault(name, "1")


@pytest.hookimpl(tryfirst=True)  # before xdist's worker reads the groups from the markers
def pytest_collection_modifyitems(config, items):
    for item in items:
        if _shared_scope(item):
            item.add_marker(pytest.mark.xdist_group(item.module.__name__))

    def rank(item):
        name = item.path.name
        return LONG_MODULES.index(name) if name in LONG_MODULES else len(LONG_MODULES)

    items.sort(key=rank)  # stable: the shuffled order is kept within each rank
