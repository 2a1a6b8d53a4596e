"""Resources told up front: work that cannot fit is refused, a long run says how long.

Covers :mod:`randvib._resources` (the memory check, the clock and wording of
the duration announcement) and its users: :mod:`randvib.montecarlo.resources`
(a simulation's arrays, the speed of a timed probe of the compiled loop),
:mod:`randvib.identification.input_reconstruction` (the input at the sub-steps of
``record``, ``identify`` and ``validate``) and :mod:`randvib.identification.identify` (a population that cannot fit, a long
search announced at the speed of its probes of the bounds).
"""

import numba
import numpy as np
import pytest
from _cli import fit_args, one_line_error

import randvib as rv
from randvib import _resources
from randvib._resources import available_memory
from randvib.montecarlo.simulation import simulate

BASE = rv.preset("figure9")


def test_work_that_cannot_fit_is_refused_with_the_estimate():
    with pytest.raises(ValueError, match="needs about .* of memory"):
        simulate(BASE, 1.0, t_end=0.1, dt=1e-4, n_paths=8, histogram_bins=10**12)
    # the case, killed at 24 GB: counts, their sum and densities exceed the memory
    if available_memory() < 8 * 8 * 10**9:
        with pytest.raises(ValueError, match="needs about .* of memory"):
            simulate(BASE, 1.0, t_end=0.1, dt=1e-4, n_paths=8, histogram_bins=10**9)


def test_population_that_cannot_fit_is_refused(capsys, record_csv):
    one_line_error(capsys, fit_args(record_csv[0], "--popsize", "100000000"), "of memory")


def _probe_clock(seconds_per_probe):
    """A clock on which the timed probe lasts ``seconds_per_probe``."""
    ticks = iter(np.arange(100) * seconds_per_probe)
    return lambda: float(next(ticks))


@pytest.mark.parametrize("probe_seconds, warned", [(1000.0, True), (1e-9, False)])
def test_long_run_estimate_follows_the_measured_speed(monkeypatch, probe_seconds, warned):
    """The announcement uses the speed of a timed probe, not a fixed rate: the same
    run is announced on a (simulated) slow machine and not on a fast one."""
    import warnings

    from randvib._resources import LongRunWarning, duration_text
    from randvib.montecarlo import kernel, resources

    monkeypatch.setattr(resources, "PATH_STEPS_PER_SECOND", 1.0)  # a run that could be long
    monkeypatch.setattr(_resources, "clock", _probe_clock(probe_seconds))
    n_paths, n_steps = 4, 500
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        simulate(BASE, 1.0, t_end=n_steps * 1e-4, dt=1e-4, n_paths=n_paths, progress=False)
    said = [str(w.message) for w in caught if issubclass(w.category, LongRunWarning)]
    assert bool(said) is warned
    if warned:
        # the probe ran every path (<= LANES x threads) for every step of this short run
        probe_paths = min(n_paths, kernel.LANES * numba.get_num_threads())
        expected = n_paths * n_steps / (probe_paths * n_steps / probe_seconds)
        assert f"will take about {duration_text(expected)} (at the speed measured here)" in said[0]


@pytest.mark.parametrize("probe_seconds, warned", [(1e4, True), (1e-9, False)])
def test_identification_estimate_follows_the_measured_speed(
    monkeypatch, record_csv, probe_seconds, warned
):
    """identify times its probes of the bounds and announces a long search at that speed."""
    import warnings

    import randvib.identification.identify as driver
    from randvib._resources import LongRunWarning, duration_text

    monkeypatch.setattr(_resources, "clock", _probe_clock(probe_seconds))
    probed = []
    points = driver.probe_points
    monkeypatch.setattr(
        driver, "probe_points", lambda space: probed.append(points(space)) or probed[-1]
    )
    record = rv.read_record(record_csv[0])
    settings = rv.SearchSettings(popsize=6, maxiter=1, polish=False)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rv.identify(record, "coulomb", m=0.0226, search=settings)
    said = [str(w.message) for w in caught if issubclass(w.category, LongRunWarning)]
    assert bool(said) is warned
    if warned:
        # popsize x (maxiter + 1) runs at the speed of len(probes) runs in probe_seconds
        expected = 6 * 2 / (len(probed[0]) / probe_seconds)
        assert f"will take about {duration_text(expected)} (at the speed measured here)" in said[0]


@pytest.mark.parametrize(
    "argv",
    [
        ["record", "--preset", "figure9", "--rms", "2", "--duration", "2", "--substeps", "1e6",
         "--out", "r.csv"],
        ["identify", "{rec}", "--model", "coulomb", "--m", "0.0226", "--popsize", "8",
         "--generations", "2", "--no-progress", "--substeps", "1000000"],
        ["validate", "{params}", "{rec}", "--substeps", "1000000"],
    ],
)  # fmt: skip
def test_huge_substeps_refused_up_front(capsys, tmp_path, monkeypatch, record_csv, argv):
    # The fine input is 4e9 values for 2000 samples (2 per sub-step), about 128 GB with
    # its temporaries: refused with the estimate, not a MemoryError, on a machine of 16 GB.
    monkeypatch.setattr(_resources, "available_memory", lambda: 16 * 10**9)
    monkeypatch.chdir(tmp_path)
    argv = [a.format(rec=record_csv[0], params=record_csv[1]) for a in argv]
    one_line_error(capsys, argv, "lower `--substeps`")
    assert not (tmp_path / "r.csv").exists()
