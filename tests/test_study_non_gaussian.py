"""Study ``non-gaussian`` (studies/non_gaussian.py) at a tiny size, end to end through the CLI.

The study's numbers are Monte Carlo; what is checked here holds at any
size: the Gaussian answers in the table are :func:`randvib.predict`'s under
the same inputs, the relative errors and their intervals are the estimates'
ratio carried through, each verdict follows from its interval and the 5 %
tolerance, the verdicts are recomputed from the CSV, the figures are drawn,
and computing again resumes from the stored cases without recomputing them.

Covers the study script with the building block it uses:
:mod:`randvib.studies.gaussian_error` (the Gaussian answer against Monte
Carlo, its verdicts).
"""

import json
import warnings

import numpy as np
import pandas as pd
import pytest
from study_checks import check_study_run

import randvib as rv
from randvib.cli import main
from randvib.studies import load
from randvib.studies.gaussian_error import error_verdict, relative_errors
from randvib.studies.grids import fixed_paths

study = load("non-gaussian")
TINY = {"devices": ("paper", "bistable"), "positions": ("at",), "amplitudes": (2.0,),
        "kurtoses": (6.0,), "mc": {"n_paths": 16, "window": 1.5, "burn_in": 0.5, "dt": 2.5e-4}}  # fmt: skip


def _run(out, capsys):
    argv = [
        "study",
        "non-gaussian",
        "--quick",
        "--out",
        str(out),
        "--no-progress",
        "--workers",
        "1",
    ]
    assert main(argv) == 0
    return check_study_run(capsys.readouterr().out, out)


def test_non_gaussian_study_end_to_end(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(study, "grid", lambda quick: TINY)
    out = tmp_path / "ng"
    text = _run(out, capsys)
    results = pd.read_csv(out / "results.csv")
    assert len(results) == 2 * 2 * 3  # devices x friction x (floor, tone, kurtosis)
    inputs = {(labels["input"], labels["amplitude"], labels["kurtosis"]): x
              for labels, x in study.inputs(TINY)}  # fmt: skip
    for r in results.itertuples():
        device = study.device(r.device, r.fc)
        x = inputs[(r.input, r.amplitude, r.kurtosis)]
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                expected = rv.predict(device, x).power_electrical
        except ValueError:  # no Gaussian answer: the table says none
            assert np.isnan(r.power_gaussian) and r.power_verdict == "no answer"
            continue
        assert r.power_gaussian == pytest.approx(expected, rel=1e-12)
        error, half = relative_errors(r.power_gaussian, r.power_mc, r.power_mc_ci95)
        assert (r.power_error, r.power_error_ci95) == pytest.approx((float(error), float(half)))
        assert r.power_verdict == error_verdict(error, half)
    verdict = json.loads((out / "verdicts.json").read_text())
    assert verdict == json.loads(json.dumps(study.verdicts(results)))
    counts = verdict["tones"]["counts"]["power"]
    assert sum(counts.values()) == 4
    assert f"errs by more than 5 % at {counts['errs']} of 4 cases" in text
    for figure in ("tone_errors.png", "kurtosis_errors.png", "spectra.png"):
        assert (out / figure).stat().st_size > 10_000
    # computing again resumes from the stored cases (the figures are not redrawn here)
    stored = {p: p.stat().st_mtime_ns for p in (out / "ensembles" / "points").iterdir()}
    settings = fixed_paths(**TINY["mc"], seed=0)
    again = study.compute(TINY, settings, out, workers=1, scheduler=None, progress=False)
    assert {p: p.stat().st_mtime_ns for p in (out / "ensembles" / "points").iterdir()} == stored
    pd.testing.assert_frame_equal(again.reset_index(drop=True), results, check_dtype=False)


def test_verdicts_follow_the_interval_and_the_tolerance():
    error = np.array([0.10, 0.03, 0.06, -0.09, np.nan])
    half = np.array([0.02, 0.01, 0.02, 0.05, 0.01])
    assert list(error_verdict(error, half)) == ["errs", "within", "undecided", "undecided",
                                                "no answer"]  # fmt: skip
    e, h = relative_errors([1.1], [1.0], [0.1])
    assert (float(e[0]), float(h[0])) == pytest.approx((0.1, 0.11))
