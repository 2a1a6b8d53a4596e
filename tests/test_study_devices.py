"""Study ``devices`` (studies/devices.py) at a tiny size, end to end through the CLI.

The study's numbers are Monte Carlo; checked here is what must hold at any
size: the input levels inject the same power into the linear friction-free
device (exactly, by its Lyapunov solution), the bistable device has the
linear one's in-well stiffness and a barrier equal to the reference energy
scale, Monte Carlo's white-noise power agrees with fpk-fast (an independent
method, accurate to 0.05 %) within its interval for every device, the paired
ratios and the censored first-passage columns are consistent, the budget
interpolation (randvib/studies/budget.py) is exact on a power law, the
verdicts are recomputed from the CSVs, and computing again resumes from the
stored cases (randvib.run_ensembles) without recomputing them, to the same tables.

Covers the study script with the building blocks it uses:
:mod:`randvib.studies.budget`, :mod:`randvib.studies.methods` (the analytic
methods against Monte Carlo) and :mod:`randvib.montecarlo.ensembles`.
"""

import json

import numpy as np
import pandas as pd
import pytest
from _stats import assert_matches
from study_checks import check_study_run, statistic

import randvib as rv
from randvib.cli import main
from randvib.studies import load
from randvib.studies.budget import power_at_budget
from randvib.studies.grids import fixed_paths

devices = load("devices")
TINY = {"inputs": ("white", "band at f_n"), "levels": (0.25, 1.0),
        "methods": ("linearisation", "fpk-fast"),
        "mc": {"n_paths": 64, "window": 2.5, "burn_in": 0.5, "dt": 2e-4}}  # fmt: skip


def _run(out, capsys):
    argv = ["study", "devices", "--quick", "--out", str(out), "--no-progress", "--workers", "1"]
    assert main(argv) == 0
    check_study_run(capsys.readouterr().out, out)


def test_equal_input_power_and_the_bistable_choice():
    base = rv.preset("figure9")
    reference = base.updated(fc=0.0, k3=0.0)
    for name in ("white", *devices.BANDS):
        for g in (0.25, 2.0):
            lin = rv.statistical_linearisation(reference, devices.input_of(name, g))
            injected = base.c * lin.velocity_variance  # exact: linear, no friction
            assert injected == pytest.approx(g * devices.S_REF * base.m / 4, rel=1e-9)
    devs = devices.devices()
    bistable, (z0, _) = devs["bistable"]
    assert -2 * bistable.k == pytest.approx(base.k, rel=1e-12)
    assert bistable.potential.barrier_height == pytest.approx(base.m**2 / (4 * base.c), rel=1e-12)
    assert z0 == pytest.approx(bistable.potential.wells[-1], rel=1e-12)
    assert {d.stroke for d, _ in devs.values()} == {devices.STROKE}


def test_power_at_budget_is_exact_on_a_power_law():
    g = np.array([0.5, 2.0, 8.0])
    table = pd.DataFrame({"g": g, "power_mc": 2 * g, "exceedance_mc": 1e-3 * g**2,
                          "exceedance_mc_ci95": 1e-4 * g**2})  # fmt: skip
    at = power_at_budget(table, 1e-2)
    assert at["bracket"] == "bracketed"
    assert at["g"] == pytest.approx(np.sqrt(10), rel=1e-12)
    assert at["power"] == pytest.approx(2 * np.sqrt(10), rel=1e-12)
    assert at["power_low"] == pytest.approx(2 * np.sqrt(10 / 1.1), rel=1e-12)
    assert at["power_high"] == pytest.approx(2 * np.sqrt(10 / 0.9), rel=1e-12)
    assert power_at_budget(table, 1e-6)["bracket"] == "below"
    assert power_at_budget(table, 0.5)["bracket"] == "above"


def test_devices_study_end_to_end(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(devices, "grid", lambda quick: TINY)
    out = tmp_path / "dev"
    _run(out, capsys)
    read = {"keep_default_na": False, "na_values": [""]}
    results = pd.read_csv(out / "results.csv", **read)
    methods = pd.read_csv(out / "methods.csv", **read)
    assert len(results) == 2 * 2 * 3 and len(methods) == 2 * 2 * 3 * 2
    fpk = methods[(methods.method == "fpk-fast") & (methods.input == "white")]
    # fpk-fast refuses a double well with friction deeper than its measured limit
    # (fokker_planck.FAST_MAX_BARRIER, the cross-check campaign): a refusal, never a number
    why = fpk.refused.fillna("")  # an empty cell reads as NaN
    refused = fpk[why != ""]
    assert (refused.device == "bistable").all() and refused.power.isna().all()
    assert refused.refused.str.contains("treats double wells with friction").all()
    fpk = fpk[why == ""]
    assert len(fpk) >= 4  # the other devices at both levels
    for r in fpk.itertuples():
        mc = results[(results.input == r.input) & (results.g == r.g) & (results.device == r.device)]
        mc = mc.iloc[0]
        stat = statistic(mc.power_mc, mc.power_mc_ci95, mc.n_paths)
        assert_matches(stat, r.power, detect=0.3, what=f"{r.device} at g = {r.g}")
    assert (methods[methods.input != "white"].method == "fpk-fast").sum() == 6
    assert (
        methods[(methods.method == "fpk-fast") & (methods.input != "white")].refused != ""
    ).all()
    # paired ratios: the ratio of the powers; the linear device's is exactly 1
    for _, sub in results.groupby(["input", "g"]):
        linear = sub[sub.device == "linear"].iloc[0]
        np.testing.assert_allclose(sub.power_ratio_to_linear, sub.power_mc / linear.power_mc,
                                   rtol=1e-12)  # fmt: skip
        assert linear.power_ratio_ci95 == pytest.approx(0.0, abs=1e-12)
    # censoring: a mean only when every path reached the gap, else a lower bound below the horizon
    complete = results.fp_paths_reached == results.fp_n_paths
    assert (
        np.isfinite(results.fp_mean[complete]).all() and np.isnan(results.fp_mean[~complete]).all()
    )
    assert (results.fp_restricted_mean <= results.fp_horizon + 1e-12).all()
    assert (
        np.isnan(results.fp_median) == (2 * results.fp_paths_reached <= results.fp_n_paths)
    ).all()
    # verdicts.json is what the tables say, and the report states it
    verdict = json.loads((out / "verdicts.json").read_text())
    assert verdict == json.loads(json.dumps(devices.verdicts(results, methods)))
    text = (out / "report.md").read_text()
    assert devices.answer(verdict) in text
    for figure in ("power_vs_exceedance.png", "method_errors.png"):
        assert (out / figure).stat().st_size > 10_000
    # computing again resumes from the stored cases, and gives the same tables, byte for
    # byte as written (the figures are not redrawn here: a rerun through the command line
    # is tests/test_study_figure9.py's and tests/test_cli_paths.py's)
    stored = {p: p.stat().st_mtime_ns for p in (out / "ensembles" / "points").iterdir()}
    assert len(stored) == 2 * len(results)  # a row and the per-path averages per case
    settings = fixed_paths(**TINY["mc"], seed=0)
    again = devices.compute(TINY, settings, out, workers=1, scheduler=None, progress=False)
    assert {p: p.stat().st_mtime_ns for p in (out / "ensembles" / "points").iterdir()} == stored
    for table, name in zip(again, ("results.csv", "methods.csv"), strict=True):
        assert table.to_csv(index=False).encode() == (out / name).read_bytes(), name
