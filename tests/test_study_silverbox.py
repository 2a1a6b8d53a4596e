"""The Silverbox study at its quick size: measured data, the physical model's target.

The quick study fits the Duffing model on the first 20,000 samples of the
benchmark's multisine training part only (SaDE 12 x 10, then the
least-squares polish) and is scored as the benchmark scores it on its
multisine test and full arrow-head (and the part without extrapolation),
which nothing was tuned on: the first 50 samples of each not scored, the
simulation started from them.

Covers the shipped record (:mod:`randvib.datasets`), its identification
(:mod:`randvib.identification.identify`) and the benchmark's building block
(:mod:`randvib.studies.benchmark`: fits kept in the study's folder, a rerun
loads them) as the study runs them.
"""

import json

import pandas as pd

from randvib.studies import load

study = load("silverbox")  # the script studies/silverbox.py


def test_quick_study_meets_the_arrow_head_target(tmp_path):
    """The study's target (TARGET_MV): RMS <= 0.5 mV on both benchmark tests with the physical
    model (measured, quick: 0.389 mV full arrow-head, 0.308 mV multisine test)."""
    study.run_study(tmp_path / "sb", quick=True, progress=False)
    table = pd.read_csv(tmp_path / "sb" / "results.csv")
    rms = dict(zip(table["record"], table["RMS error (mV)"], strict=True))
    tests = ("multisine test", "arrow-head full", "arrow-head no extrapolation")
    assert set(rms) == {"multisine train (first 20,000)", *tests}
    assert rms["arrow-head full"] <= 0.5
    assert rms["multisine test"] <= 0.5
    report = (tmp_path / "sb" / "report.md").read_text()
    assert "Beintema" in report and "GRU" in report
    verdicts = json.loads((tmp_path / "sb" / "verdicts.json").read_text())
    assert verdicts["arrow_head_rms_mV"] == rms["arrow-head full"]
    assert verdicts["multisine_test_rms_mV"] == rms["multisine test"]
    assert f"{rms['arrow-head full']:.3g} mV RMS" in verdicts["verdicts"][0]
    assert f"multisine test to {rms['multisine test']:.3g} mV" in verdicts["verdicts"][0]
    assert verdicts["best_model"] == "Duffing" and len(verdicts["verdicts"]) == 2
    assert verdicts["meets_target"] is (max(rms[t] for t in tests[:2]) <= 0.5)
    # a rerun loads the fit kept in the folder: the same table, the fit not rewritten
    fit = tmp_path / "sb" / "duffing.json"
    stamp = fit.stat().st_mtime_ns
    study.run_study(tmp_path / "sb", quick=True, progress=False)
    assert fit.stat().st_mtime_ns == stamp
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "sb" / "results.csv"), table)


def test_verdicts_follow_from_the_tables():
    rows = [
        ("linear (k3 = 0)", "arrow-head", 8.0), ("linear (k3 = 0)", "multisine test", 4.0),
        ("Duffing", "arrow-head", 0.4), ("Duffing", "multisine test", 0.3),
    ]  # fmt: skip
    table = pd.DataFrame(rows, columns=["model", "record", "RMS error (mV)"])
    ablation = pd.DataFrame({"arrow-head RMS (mV)": [2.0, 1.0, 0.4]})
    data, sentences = study.silverbox_verdicts(table, ablation, "multisine test", "arrow-head")
    assert data["best_model"] == "Duffing" and data["duffing_over_linear_arrow_head"] == 20.0
    assert "3.27 times smaller than the 1.31 mV" in sentences[0]  # 1.31 / 0.4
    assert "1.03 times smaller than its 0.31 mV" in sentences[0]  # 0.31 / 0.3
    assert "It meets the physical model's target of 0.5 mV" in sentences[0]
    assert "not below 0.3 mV" in sentences[1] and data["below_aim"] is False
    assert "20 times the Duffing model's" in sentences[2]
    assert "divides the Duffing model's arrow-head error by 5 (2 -> 0.4 mV)" in sentences[3]
    k2 = [("Duffing + k2", "arrow-head", 0.38), ("Duffing + k2", "multisine test", 0.3)]
    with_k2 = pd.concat([table, pd.DataFrame(k2, columns=table.columns)])
    data, sentences = study.silverbox_verdicts(
        with_k2, pd.DataFrame(), "multisine test", "arrow-head"
    )
    assert data["best_model"] == "Duffing + k2" and data["k2_change_arrow_head"] == 0.38 / 0.4 - 1
    assert "changes the arrow-head error by -5.000 %" in sentences[3]
    worse = table.assign(**{"RMS error (mV)": [8.0, 4.0, 2.8, 0.72]})
    _, sentences = study.silverbox_verdicts(worse, pd.DataFrame(), "multisine test", "arrow-head")
    assert "2.14 times larger than the 1.31 mV" in sentences[0] and len(sentences) == 3
    assert "It misses the physical model's target of 0.5 mV" in sentences[0]


def test_rms_beyond_a_first_part_is_the_rms_of_the_rest():
    import numpy as np
    import pytest

    from randvib.studies.benchmark import rms_beyond

    e = np.random.default_rng(0).normal(size=1000) * np.linspace(1.0, 3.0, 1000)
    full, part = np.sqrt(np.mean(e**2)), np.sqrt(np.mean(e[:700] ** 2))
    assert rms_beyond(full, 1000, part, 700) == pytest.approx(np.sqrt(np.mean(e[700:] ** 2)))
    with pytest.raises(ValueError, match="`n_part` must lie in"):
        rms_beyond(full, 1000, part, 1000)
