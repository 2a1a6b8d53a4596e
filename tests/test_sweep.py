"""Sweeps: grids, precision targets, common random numbers, resumable output, executors."""

import json

import numpy as np
import pytest

import randvib as rv
import randvib.montecarlo.sweep as sweep_module
from randvib.montecarlo.sweep import (
    SweepSettings,
    cartesian,
    holm_significant,
    linearisation_verdicts,
    paired_contrast,
    run_sweep,
)

BASE = rv.preset("figure9")
FAST = SweepSettings(
    dt=1e-4,
    window=0.5,
    burn_in=0.2,
    target_rel_ci=0.02,
    min_paths=32,
    batch_paths=32,
    max_paths=256,
    seed=4,
)


def test_cartesian_grid():
    pts = cartesian(psd=[1.0, 0.5], k3=[0, 5e5], fc=np.array([0.0, 0.01]))
    assert len(pts) == 8 and pts[0] == {"psd": 1.0, "k3": 0.0, "fc": 0.0}
    with pytest.raises(ValueError, match="grid axis `fc` is empty"):
        cartesian(psd=[1.0], fc=[])


@pytest.mark.parametrize(
    ("points", "fragment"),
    [
        ([], "grid is empty"),
        ([{"fc": 0.01}], "needs `psd`"),
        ([{"psd": 0.0}], "`psd` must be > 0"),
        ([{"psd": 1.0, "stiffness": 3.0}], "unknown parameter name"),
        ([{"psd": 1.0, "fc": -1.0}], "`fc` must be >= 0"),
    ],
)
def test_bad_grids(points, fragment):
    with pytest.raises(ValueError, match=fragment):
        run_sweep(BASE, points, FAST, workers=1, progress=False)


def test_precision_target_met_and_rows_complete():
    pts = cartesian(psd=[0.5], k3=[0.0, 5e5], fc=[0.0, 0.01, 0.03])
    res = run_sweep(BASE, pts, FAST, workers=1, progress=False)
    t = res.table
    assert len(t) == 6
    rel = t.power_electrical_ci95 / t.power_electrical
    assert np.all((rel <= FAST.target_rel_ci) | (t.n_paths >= FAST.max_paths))
    assert np.all(t.n_paths % FAST.batch_paths == 0)
    for col in (
        "linearisation_power",
        "power_electrical",
        "velocity_variance_ci95",
        "simulated_time",
    ):
        assert col in t
    # the power column matches a direct simulation with the same paths
    direct = rv.simulate(
        BASE.updated(fc=0.03, k3=0.0),
        0.5,
        t_end=0.7,
        dt=1e-4,
        burn_in=0.2,
        seed=4,
        n_paths=int(t.n_paths[2]),
        companion=True,
        control_variates=True,
    )
    assert t.power_electrical[2] == pytest.approx(direct.power_electrical.mean, rel=1e-12)


def test_common_random_numbers_make_k3_contrast_exact_without_friction():
    # Without friction E[v^2] = S m / (4c) for every k3, so the paired contrast
    # P(0, k3) - P(0, 0) must vanish within its (small) interval.
    pts = cartesian(psd=[1.0], k3=[0.0, 5e5], fc=[0.0, 0.02])
    # 96 paths: enough (>= 10 per control) for the paired controls to be used
    settings = SweepSettings(**{**FAST.__dict__, "min_paths": 96})
    res = run_sweep(BASE, pts, settings, workers=1, progress=False)
    contrast = paired_contrast(res, BASE, {2: 1.0, 0: -1.0})
    assert abs(contrast.mean) <= contrast.ci95 + 1e-15
    # the paired interaction contrast is far tighter than the unpaired one
    inter = paired_contrast(res, BASE, {3: 1.0, 1: -1.0, 2: -1.0, 0: 1.0})
    unpaired = np.hypot(res.table.power_electrical_ci95[3], res.table.power_electrical_ci95[1])
    assert inter.ci95 < unpaired


def test_linearisation_verdicts_columns():
    pts = cartesian(psd=[0.1], fc=[0.0, 0.015])
    t = linearisation_verdicts(run_sweep(BASE, pts, FAST, workers=1, progress=False).table)
    assert t.linearisation_consistent[0]  # no friction: Eq. 32 exact
    err = t.linearisation_rel_error[1]
    assert err == pytest.approx(t.linearisation_power[1] / t.power_electrical[1] - 1)


def test_holm():
    assert list(holm_significant([0.001, 0.04, 0.2])) == [True, False, False]
    assert list(holm_significant([0.01, 0.02])) == [True, True]


def test_resume_interrupted_sweep_without_recomputing(tmp_path, monkeypatch):
    pts = cartesian(psd=[1.0], fc=[0.0, 0.01, 0.02, 0.03])
    calls = []
    real = sweep_module.run_point

    def flaky(base, point, settings, threads=1):
        if len(calls) == 2:
            raise KeyboardInterrupt  # the user stops the sweep
        calls.append(point["fc"])
        return real(base, point, settings, threads)

    monkeypatch.setattr(sweep_module, "run_point", flaky)
    with pytest.raises(KeyboardInterrupt):
        run_sweep(BASE, pts, FAST, out_dir=tmp_path / "s", workers=1, progress=False)
    saved = sorted((tmp_path / "s" / "points").glob("*.json"))
    assert len(saved) == 2
    first = [json.loads(p.read_text()) for p in saved]

    calls.clear()

    def counting(base, point, settings, threads=1):
        calls.append(point["fc"])
        return real(base, point, settings, threads)

    monkeypatch.setattr(sweep_module, "run_point", counting)
    res = run_sweep(BASE, pts, FAST, out_dir=tmp_path / "s", workers=1, progress=False)
    assert calls == [0.02, 0.03]  # finished points were loaded, not recomputed
    assert [r for r in res.table.to_dict("records")[:2]] == [
        {"point": i, **first[i]} for i in range(2)
    ]
    assert (tmp_path / "s" / "results.csv").read_text().count("\n") == 5


def test_folder_with_a_different_sweep_is_refused(tmp_path):
    pts = cartesian(psd=[1.0], fc=[0.0, 0.01])
    run_sweep(BASE, pts, FAST, out_dir=tmp_path, workers=1, progress=False)
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    with pytest.raises(FileExistsError, match="different run"):
        run_sweep(
            BASE,
            cartesian(psd=[1.0], fc=[0.0, 0.02]),
            FAST,
            out_dir=tmp_path,
            workers=1,
            progress=False,
        )
    assert before == {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    other = tmp_path / "not-empty"
    other.mkdir()
    (other / "mine.txt").write_text("precious")
    with pytest.raises(FileExistsError, match="not empty"):
        run_sweep(BASE, pts, FAST, out_dir=other, workers=1, progress=False)
    assert (other / "mine.txt").read_text() == "precious"


def test_process_pool_gives_the_same_numbers():
    pts = cartesian(psd=[0.5], fc=[0.0, 0.02])
    local = run_sweep(BASE, pts, FAST, workers=1, progress=False).table
    pooled = run_sweep(BASE, pts, FAST, workers=2, progress=False).table
    assert np.array_equal(local.power_electrical, pooled.power_electrical)


def test_dask_local_cluster_on_loopback():
    distributed = pytest.importorskip("distributed")
    pts = cartesian(psd=[0.5], fc=[0.0, 0.02, 0.04])
    local = run_sweep(BASE, pts, FAST, workers=1, progress=False).table
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None, processes=True
    ) as cluster:
        res = run_sweep(BASE, pts, FAST, scheduler=cluster.scheduler_address, progress=False)
    assert np.array_equal(res.table.power_electrical, local.power_electrical)
    assert np.array_equal(res.table.n_paths, local.n_paths)


def test_settings_validation():
    with pytest.raises(ValueError, match="`target_rel_ci`"):
        SweepSettings(target_rel_ci=0)
    with pytest.raises(ValueError, match="`max_paths`"):
        SweepSettings(min_paths=64, max_paths=32)
