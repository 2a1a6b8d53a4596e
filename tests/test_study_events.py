"""Study ``events`` (studies/events.py) at a tiny size, end to end through the CLI.

What must hold at any size: the linear device's event energy agrees with the
exact Lyapunov solution within its interval (a check of the Monte Carlo),
the transient linearisation of the linear device is that exact solution, the
stationary-times-duration estimate is the stationary power at the peak times
int e^2 dt, the paired ratio of the paper's device to itself is 1, the
verdicts are recomputed from the CSV, and the report and figures exist.

Computing again into the same folder resumes every case from its checksummed
store (the same tables, byte for byte), and an event run of the paired-ensemble
runner is :func:`randvib.simulate_transient` on the group's seed.

Covers the study script with its figures (:mod:`randvib.studies.transient_figure`),
its building block :mod:`randvib.studies.events` and the runner's event cases
(:mod:`randvib.montecarlo.event_cases`).
"""

import json
import warnings

import numpy as np
import pandas as pd
import pytest
from _stats import assert_matches
from study_checks import check_study_run, statistic

import randvib as rv
from randvib.cli import main
from randvib.studies import load
from randvib.studies.events import event_cases, event_tables, half_level

events = load("events")
TINY = {"levels": (0.2, 1.0), "n_paths": 160, "dt": 2.5e-4}
#: The simulated window of the tiny run (s): the event's first 4 s (its peak at 0.92 s,
#: 96 % of int e^2 dt over 8 s). Most of the run's time is the transient Lyapunov
#: solutions (the run's and its resume's tables), in proportion to the window.
T_TINY = 4.0


def test_events_study_end_to_end(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(events, "grid", lambda quick: dict(TINY))
    monkeypatch.setattr(events, "T_END", T_TINY)
    monkeypatch.setattr(events, "TIMES", tuple(np.round(np.arange(0.0, T_TINY + 1e-9, 0.2), 10)))
    out = tmp_path / "events"
    argv = ["study", "events", "--quick", "--out", str(out), "--no-progress", "--workers", "1"]
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
    # computing again loads every case from the store: the same tables, byte for byte as
    # written (the figures and their two transient solutions are not redrawn here: a
    # rerun through the command line is tests/test_study_figure9.py's and test_cli_paths.py's)
    stored = sorted((out / "ensembles" / "points").glob("*.npy"))
    assert len(stored) == len(results)
    stamps = [p.stat().st_mtime_ns for p in stored]
    settings = rv.EventSettings(events.T_END, TINY["dt"], TINY["n_paths"], times=events.TIMES,
                                seed=0)  # fmt: skip
    run = rv.run_ensembles(event_cases(events.devices(), events.event, TINY["levels"]), settings,
                           out_dir=out / "ensembles", workers=1, progress=False,
                           name=events.NAME)  # fmt: skip
    assert [p.stat().st_mtime_ns for p in stored] == stamps
    with warnings.catch_warnings():  # as in the run, where the command line showed them
        warnings.simplefilter("ignore", rv.LinearisationValidityWarning)  # the bistable device
        warnings.simplefilter("ignore", RuntimeWarning)  # E[P_e] = 0 at t = 0: 0 / 0, masked
        again = event_tables(run, reference="paper", stroke=events.STROKE)
    for table, name in zip(again, ("results.csv", "transient.csv"), strict=True):
        assert table.to_csv(index=False).encode() == (out / name).read_bytes(), name


def test_an_event_run_is_simulate_transient_on_the_group_seed():
    """Group j of a run with seed s is simulate_transient at seed 1000 s + j, path by path."""
    settings = rv.EventSettings(1.0, 5e-4, 8, times=(0.0, 0.5, 1.0), seed=3)
    devices = {name: events.devices()[name] for name in ("linear", "paper")}
    cases = event_cases(devices, events.event, (0.5, 2.0))
    run = rv.run_ensembles(cases, settings, workers=1, progress=False)
    assert run.groups == [0, 0, 1, 1]
    i = run.find(1, device="paper")
    direct = rv.simulate_transient(
        devices["paper"][0], events.event(2.0), t_end=1.0, dt=5e-4, n_paths=8,
        times=(0.0, 0.5, 1.0), seed=3001, progress=False,
    )  # fmt: skip
    got = run.transient(i)
    np.testing.assert_array_equal(got.snapshots, direct.snapshots)
    np.testing.assert_array_equal(got.path_energies, direct.path_energies)
    np.testing.assert_array_equal(got.first_hit, direct.first_hit)
    np.testing.assert_array_equal(got.times, direct.times)
    assert run.table.energy_electrical[i] == direct.energy_electrical.mean
    with pytest.raises(ValueError, match="event run have no time averages"):
        run.paired_ratios(device="linear")
    with pytest.raises(ValueError, match="events run with randvib.EventSettings"):
        rv.run_ensembles([rv.Case({"x": 1}, devices["paper"][0], 1.0)], settings, progress=False)
    with pytest.raises(ValueError, match="events run with randvib.EventSettings"):
        rv.run_ensembles(cases, rv.SweepSettings(), progress=False)
    stationary_start = rv.Case({"x": 1}, devices["paper"][0], events.event(1.0))
    with pytest.raises(ValueError, match="an event starts from `initial` 'rest'"):
        rv.run_ensembles([stationary_start], settings, progress=False)
    with pytest.raises(ValueError, match="times"):
        rv.EventSettings(1.0, 5e-4, 8, times=(0.0, 2.0))


def test_half_level_interpolates_in_log_intensity():
    sub = pd.DataFrame({"level": [0.1, 1.0, 10.0], "stroke_reached_mc": [0.0, 0.25, 0.75]})
    assert half_level(sub) == pytest.approx(np.sqrt(10.0))
    assert half_level(sub.assign(stroke_reached_mc=[0.0, 0.1, 0.2])) is None
