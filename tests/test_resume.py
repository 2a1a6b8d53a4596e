"""Resumed runs: a corrupted sweep point or stored fit is named and computed again.

Covers the checksummed point store of :mod:`randvib.montecarlo.sweep`
(:class:`~randvib.montecarlo.sweep.PointStore`: every way a point's JSON row
or per-path array can be damaged, the results table rebuilt from the points)
and the fits an identification campaign keeps on disk
(:func:`randvib.studies.campaign.identify_cached`).
"""

import json

import numpy as np
import pytest

import randvib as rv
import randvib.montecarlo.sweep as sweep_module
from randvib.montecarlo.sweep import SweepSettings, cartesian, run_sweep

BASE = rv.preset("figure9")


TINY = SweepSettings(
    dt=2e-4, window=0.2, burn_in=0.05, target_rel_ci=0.5, min_paths=8, batch_paths=8, max_paths=8
)


def _corrupt(points, how):
    json0, npy0 = points / "00000.json", points / "00000.npy"
    if how == "doubled power":
        stored = json.loads(json0.read_text())
        stored["row"]["power_electrical"] *= 2
        json0.write_text(json.dumps(stored))
    elif how == "empty object":
        json0.write_text("{}")
    elif how == "zero-byte json":
        json0.write_bytes(b"")
    elif how == "nan in npy":
        arr = np.load(npy0)
        arr[0, 0] = np.nan
        np.save(npy0, arr)
    elif how == "another point's arrays":
        npy0.write_bytes((points / "00001.npy").read_bytes())
    elif how == "truncated npy":
        npy0.write_bytes(npy0.read_bytes()[:-40])
    elif how == "npy missing":
        npy0.unlink()


@pytest.mark.parametrize(
    "how",
    [
        "doubled power",
        "empty object",
        "zero-byte json",
        "nan in npy",
        "another point's arrays",
        "truncated npy",
        "npy missing",
    ],
)
def test_corrupted_point_is_named_and_recomputed(tmp_path, monkeypatch, how):
    pts = cartesian(psd=[1.0], fc=[0.0, 0.01])
    first = run_sweep(BASE, pts, TINY, out_dir=tmp_path, workers=1, progress=False)
    _corrupt(tmp_path / "points", how)
    calls = []
    real = sweep_module.run_point

    def counting(base, point, settings, threads=1):
        calls.append(point["fc"])
        return real(base, point, settings, threads)

    monkeypatch.setattr(sweep_module, "run_point", counting)
    with pytest.warns(UserWarning, match="sweep point 0 .* unusable"):
        again = run_sweep(BASE, pts, TINY, out_dir=tmp_path, workers=1, progress=False)
    assert calls == [0.0]  # only the bad point was recomputed
    cols = ["power_electrical", "velocity_variance", "n_paths"]
    assert again.table[cols].equals(first.table[cols])  # same seed: the same numbers
    assert np.array_equal(again.per_path[0], first.per_path[0])


def test_results_csv_is_rebuilt_from_the_points(tmp_path):
    pts = cartesian(psd=[1.0], fc=[0.0, 0.01])
    run_sweep(BASE, pts, TINY, out_dir=tmp_path, workers=1, progress=False)
    good = (tmp_path / "results.csv").read_text()
    (tmp_path / "results.csv").write_text("point,power_electrical\n0,123\n")
    run_sweep(BASE, pts, TINY, out_dir=tmp_path, workers=1, progress=False)
    assert (tmp_path / "results.csv").read_text() == good


def test_unreadable_stored_fit_is_named_and_fitted_again(tmp_path, record_csv):
    from randvib.models.record import read_record
    from randvib.studies.campaign import identify_cached

    path = tmp_path / "fit.json"
    path.write_text("")  # a zero-byte file left by a crash
    record = read_record(record_csv[0])
    kwargs = dict(m=0.0226, popsize=8, maxiter=2, polish=False)
    with pytest.warns(UserWarning, match="fit.json.* unusable"):
        fit = identify_cached(path, record, "coulomb", **kwargs)
    again = identify_cached(path, record, "coulomb", **kwargs)  # now loaded, not refitted
    assert again.parameters == fit.parameters and json.loads(path.read_text())["model"] == "coulomb"


def test_stored_fit_is_loaded_with_its_uncertainty_and_input_kind(tmp_path, record_csv):
    """A fit loaded from the campaign's cache keeps what the fit reported: standard
    errors, the 95 % intervals (recomputed exactly from the saved estimates, standard
    errors and degrees of freedom), the covariance method, the residual verdict and
    the input's kind (the unit of input_offset)."""
    from randvib.models.record import read_record
    from randvib.studies.campaign import identify_cached, load_fit

    path = tmp_path / "fit.json"
    record = read_record(record_csv[0])
    fit = identify_cached(path, record, "coulomb", m=0.0226, popsize=8, maxiter=2)
    loaded = load_fit(path)
    assert fit.uncertainty is not None and fit.residuals is not None
    assert loaded.input_kind == fit.input_kind == "base_acceleration"
    assert loaded.unit("input_offset") == fit.unit("input_offset")
    assert loaded.standard_errors == fit.standard_errors
    assert loaded.confidence_intervals.keys() == fit.confidence_intervals.keys()
    for name, interval in fit.confidence_intervals.items():
        assert loaded.confidence_intervals[name] == pytest.approx(interval, rel=1e-12)
    assert loaded.uncertainty.method == fit.uncertainty.method
    assert loaded.uncertainty.bandwidth == fit.uncertainty.bandwidth
    np.testing.assert_array_equal(loaded.uncertainty.correlation, fit.uncertainty.correlation)
    assert loaded.residuals.verdict == fit.residuals.verdict
    assert loaded.to_dict() == json.loads(path.read_text())
