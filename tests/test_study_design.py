"""Study ``design`` (studies/design.py, over :func:`randvib.design`): a tiny end-to-end run.

``randvib study design --quick`` with the inputs, strokes, bandwidths and Monte
Carlo sizes monkeypatched to a few short runs: the files are written, the
verdict's counts are recomputed from results.csv, and the linear optima agree
with an independent analytic design of the same input.

The analytic search runs on a coarser grid with one local start
(:data:`randvib.harvester_design.search.GRID`, ``STARTS``), the independent
design too: this test is about the study's pipeline, which takes whatever
optimum the search returns; the search itself, at its own grid, is checked in
tests/test_design.py. (At the search's default grid and four starts the test
spent 116 CPU-s, nearly all of it in the analytic search.)
"""

import json

import numpy as np
import pandas as pd
import pytest

import randvib as rv
from randvib.cli import main
from randvib.harvester_design import search
from randvib.studies import load

study = load("design")


def test_design_study_quick_end_to_end(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(search, "GRID", {1: 41, 2: 9, 3: 5})
    monkeypatch.setattr(search, "STARTS", 1)
    band = rv.BandPass(1.0, 8.0, 0.3)
    monkeypatch.setattr(
        study, "inputs", lambda quick: {"band": band.scaled(study.LEVEL / band.variance)}
    )
    # no stroke beyond the study's own: the budget table is then the results' rows at
    # STROKE (checked below); its extra strokes were three more designs nothing here read
    monkeypatch.setattr(study, "STROKES", {True: ()})
    monkeypatch.setattr(study, "ZETAS", {True: (0.3,)})  # the input's own bandwidth
    monkeypatch.setattr(study, "QUICK_MC", {"dt": 2e-4, "window": 1.0, "burn_in": 0.3,
                                            "min_paths": 24, "max_paths": 24})  # fmt: skip
    out = tmp_path / "design"
    assert (
        main(["study", "design", "--quick", "--out", str(out), "--no-progress", "--workers", "1"])
        == 0
    )
    for name in ("report.md", "results.csv", "budget.csv", "bandwidth.csv", "design.png"):
        assert (out / name).is_file(), name
    results = pd.read_csv(out / "results.csv")
    v = json.loads((out / "verdicts.json").read_text())
    assert set(results.family) == set(study.FAMILIES)
    nonlinear = results[(results.family != "linear") & results.feasible]
    assert v["comparisons"] == len(nonlinear)
    lin = results[results.family == "linear"].iloc[0]
    half = np.hypot(nonlinear.power_mc_ci95, lin.power_mc_ci95)
    assert v["nonlinear_pays"] == int(((nonlinear.power_mc - lin.power_mc) > half).sum())
    exact = rv.design(study.FIXED, band.scaled(study.LEVEL / band.variance), study.FAMILIES["linear"][1],
                      exceedance=study.EPS, monte_carlo=False)  # fmt: skip
    assert lin.power_predicted == pytest.approx(exact.power_predicted, rel=1e-9)
    assert lin.opt_k == pytest.approx(exact.optimum["k"], rel=1e-9)
    budget = pd.read_csv(out / "budget.csv")
    assert sorted(budget.family) == sorted(study.FAMILIES) and (budget.stroke == study.STROKE).all()
    assert budget.set_index("family").power_mc.to_dict() == pytest.approx(
        results.set_index("family").power_mc.to_dict(), rel=1e-12
    )
    bandwidth = pd.read_csv(out / "bandwidth.csv")
    at_input = bandwidth[(bandwidth.zeta == 0.3) & (bandwidth.family == "linear")].iloc[0]
    assert at_input.k == pytest.approx(exact.optimum["k"], rel=1e-9)
    assert "A nonlinear spring" in (out / "report.md").read_text()
