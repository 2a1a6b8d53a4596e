"""Study ``excitation`` (studies/excitation.py) at a tiny size, end to end through the CLI.

The study's numbers are Monte Carlo; what is checked here is what must hold
at any size: the response-matched levels make the linear device's power
exactly the white-noise value (S = 1) in every band, Monte Carlo agrees with
it within its interval, the paired contrast is the combination of the four
devices' powers (same paths) and narrower than unpaired, the verdicts are
recomputed from the CSVs, and computing again resumes from the stored cases
(randvib.run_ensembles) without recomputing them, to the same tables.

Covers the study script with the building blocks it uses: :mod:`randvib.studies.grids`
(response-matched levels), :mod:`randvib.studies.contrasts` (paired interactions),
:mod:`randvib.studies.spectra_figure`.
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
from randvib.studies.grids import fixed_paths

excitation = load("excitation")
TINY = {"centres": ("at", "above"), "zetas": (0.5, 0.05), "k3s": (0.0, 5e7),
        "mc": {"n_paths": 160, "window": 2.5, "burn_in": 0.5, "dt": 2e-4}}  # fmt: skip


def _run(out, capsys):
    argv = ["study", "excitation", "--quick", "--out", str(out), "--no-progress", "--workers", "1"]
    assert main(argv) == 0
    check_study_run(capsys.readouterr().out, out)


def test_excitation_study_end_to_end(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(excitation, "grid", lambda quick: TINY)
    out = tmp_path / "exc"
    _run(out, capsys)
    results = pd.read_csv(out / "results.csv")
    inter = pd.read_csv(out / "contrasts.csv")
    assert len(results) == (2 * 2 + 1) * 4 and len(inter) == 5
    base = rv.preset("figure9")
    white = base.c_e * base.m / (4 * base.c)  # c_e S m / (4 c) at S = 1
    linear = results[(results.fc == 0) & (results.k3 == 0)]
    np.testing.assert_allclose(linear.power_linearisation, white, rtol=1e-9)
    for r in linear.itertuples():
        stat = statistic(r.power_mc, r.power_mc_ci95, r.n_paths)
        assert_matches(stat, white, detect=0.3, what=f"linear device, {r.centre} {r.zeta}")
    # the paired contrast is the four powers' combination, and pairing narrows it
    for r in inter.itertuples():
        p = results[(results.centre == r.centre) & (results.zeta == r.zeta)]
        power = {(q.fc, q.k3): q for q in p.itertuples()}
        four = [power[(excitation.FC, r.k3)], power[(excitation.FC, 0.0)],
                power[(0.0, r.k3)], power[(0.0, 0.0)]]  # fmt: skip
        combined = four[0].power_mc - four[1].power_mc - four[2].power_mc + four[3].power_mc
        assert r.contrast == pytest.approx(combined, rel=1e-9, abs=1e-15)
        assert r.contrast_ci95 < np.sqrt(sum(q.power_mc_ci95**2 for q in four))
    assert not inter[inter.centre == "white"].detectable_holm.any()
    # verdicts.json is what the tables say
    verdict = json.loads((out / "verdicts.json").read_text())
    assert verdict == json.loads(json.dumps(excitation.verdicts(results, inter)))
    text = (out / "report.md").read_text()
    largest = verdict["interaction"]["largest_relative_contrast"]
    assert f"The largest contrast is {100 * largest:+.1f}" in text
    for figure in ("interaction.png", "linearisation_error.png", "spectra.png"):
        assert (out / figure).stat().st_size > 10_000
    # computing again resumes from the stored cases, and gives the same tables, byte for
    # byte as written (the figures are not redrawn here: they were most of a rerun's time;
    # a rerun through the command line is tests/test_study_figure9.py's and
    # tests/test_cli_paths.py's)
    stored = {p: p.stat().st_mtime_ns for p in (out / "ensembles" / "points").iterdir()}
    assert len(stored) == 2 * len(results)  # a row and the per-path averages per case
    settings = fixed_paths(**TINY["mc"], seed=0)
    again = excitation.compute(rv.preset("figure9"), TINY, settings, out, workers=1,
                               scheduler=None, progress=False)  # fmt: skip
    assert {p: p.stat().st_mtime_ns for p in (out / "ensembles" / "points").iterdir()} == stored
    for table, name in zip(again, ("results.csv", "contrasts.csv"), strict=True):
        assert table.to_csv(index=False).encode() == (out / name).read_bytes(), name


def test_no_interaction_holds_down_to_the_first_break_from_the_broadest_band():
    from randvib.studies.verdicts import contrast_range, holds_down_to

    sub = pd.DataFrame({"centre": "at", "zeta": [0.02, 0.5, 0.1, 0.05],
                        "relative_contrast": [0.03, -0.001, 0.004, 0.02],
                        "relative_ci95": 0.002,
                        "breaks_no_interaction": [False, False, False, True]})  # fmt: skip
    # 0.5 and 0.1 hold, 0.05 breaks: the narrower 0.02 after it does not extend the range
    assert holds_down_to(sub) == 0.1
    assert holds_down_to(sub.assign(breaks_no_interaction=False)) == 0.02
    assert holds_down_to(sub.assign(breaks_no_interaction=[False, True, False, False])) is None
    summary = contrast_range(sub)
    assert (summary["n_breaks"], summary["n_points"]) == (1, 4)
    assert (summary["min_relative_contrast"], summary["max_relative_contrast"]) == (-0.001, 0.03)
    assert summary["smallest_abs"] == -0.001 and summary["smallest_abs_where"] == "at, zeta = 0.5"
