"""Study ``events`` (studies/events.py) at a tiny size, end to end through the CLI.

What must hold at any size: the linear device's event energy agrees with the
exact Lyapunov solution within its interval (a check of the Monte Carlo),
the transient linearisation of the linear device is that exact solution, the
stationary-times-duration estimate is the stationary power at the peak times
int e^2 dt, the paired ratio of the paper's device to itself is 1, the
verdicts are recomputed from the CSV, and the report and figures exist.

Covers the study script with its figures (:mod:`randvib.studies.transient_figure`).
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

events = load("events")
TINY = {"levels": (0.2, 1.0), "n_paths": 160, "dt": 2.5e-4}


def test_events_study_end_to_end(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(events, "grid", lambda quick: dict(TINY))
    out = tmp_path / "events"
    argv = ["study", "events", "--quick", "--out", str(out), "--no-progress", "--threads", "1"]
    assert main(argv) == 0
    text = check_study_run(capsys.readouterr().out, out)
    results = pd.read_csv(out / "results.csv")
    series = pd.read_csv(out / "transient.csv")
    assert len(results) == 3 * len(TINY["levels"])
    assert len(series) == len(results) * len(events.TIMES)
    linear = results[results.device == "linear"]
    for r in linear.itertuples():
        device, _ = events.devices()["linear"]
        exact = rv.transient_response(device, events.event(r.level), [events.T_END])
        assert r.energy_lin == pytest.approx(exact.energy_electrical, rel=1e-9)
        stat = statistic(r.energy_mc, r.energy_mc_ci95, r.n_paths)
        assert_matches(stat, exact.energy_electrical, detect=0.3, what=f"linear energy {r.level}")
        peak = rv.predict(device, events.event(r.level).peak_excitation(), "linearisation")
        duration = events.ENVELOPE.square_integral(events.T_END) / events.ENVELOPE.peak**2
        assert r.energy_stationary == pytest.approx(peak.power_electrical * duration, rel=1e-9)
        assert 0 <= r.stroke_vanmarcke <= 1 and 0 <= r.stroke_poisson <= 1
    paper = results[results.device == "paper"]
    np.testing.assert_allclose(paper.energy_over_paper, 1.0)
    assert results[results.device == "bistable"].energy_lin.isna().all()  # from a well
    # verdicts.json is what the table says
    verdict = json.loads((out / "verdicts.json").read_text())
    sentences = verdict.pop("verdicts")
    assert verdict == json.loads(json.dumps(events.verdicts(results)))
    assert sentences == events.sentences(events.verdicts(results))
    assert sentences[0] in text and "Poisson" in text and "| bistable |" in text
    for figure in ("energy_and_stroke.png", "transient.png"):
        assert (out / figure).stat().st_size > 10_000


def test_half_level_interpolates_in_log_intensity():
    sub = pd.DataFrame({"level": [0.1, 1.0, 10.0], "stroke_reached_mc": [0.0, 0.25, 0.75]})
    assert events._half_level(sub) == pytest.approx(np.sqrt(10.0))
    assert events._half_level(sub.assign(stroke_reached_mc=[0.0, 0.1, 0.2])) is None
