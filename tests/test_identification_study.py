"""The identification study's cheap guarantees (the full run belongs to the study itself).

Covers the identification campaign's pieces (:mod:`randvib.studies.campaign`) as the
study script uses them, through :mod:`randvib.cli.study`.
"""

import numpy as np
import pytest

from randvib.cli.study import load_study
from randvib.studies import load

study = load("identification")  # the script studies/identification.py
TEST_RMS, TRUTH, make_test, run_study = (
    study.TEST_RMS,
    study.TRUTH,
    study.make_test,
    study.run_study,
)


def test_registered_and_refuses_a_folder_from_another_run(tmp_path):
    assert load_study("identification") is run_study
    (tmp_path / "metadata.json").write_text('{"identity": {"study": "figure9"}, "info": {}}')
    with pytest.raises(FileExistsError, match="holds results of a different run"):
        run_study(tmp_path, quick=True)
    other = tmp_path / "nonempty"
    other.mkdir()
    (other / "keep.txt").write_text("user data")
    with pytest.raises(FileExistsError, match="not empty"):
        run_study(other, quick=True)
    assert (other / "keep.txt").read_text() == "user data"


def test_synthetic_tests_are_increasing_and_noisy():
    assert TEST_RMS[:2] == (1.07, 1.21) and all(np.diff(TEST_RMS) > 0)
    noisy, _ = make_test(3, duration=1.0, fs=500.0, seed=0)
    clean, v = make_test(3, duration=1.0, fs=500.0, seed=0, noise=False)
    noise = noisy.z - clean.z
    assert 1e-6 < np.std(noise) < 4e-6 and noisy.input_kind == "base_displacement"
    assert np.mean(v == 0) < 0.5 and TRUTH["fc"] == 0.0058


def test_figure8_verdict_follows_the_shares():
    import pandas as pd

    from randvib.studies.campaign import MEASURED, SIMULATED

    figure8_verdict = study.figure8_verdict

    def table(m6, mlow, coulomb, viscous):
        rows = [("test 6", "coulomb", 0.0, m6), ("test 6", "viscous", 0.0, m6)]
        rows += [("low", "coulomb", coulomb, mlow), ("low", "viscous", viscous, mlow)]
        return pd.DataFrame(rows, columns=["excitation", "model", SIMULATED, MEASURED])

    text = figure8_verdict(table(0.02, 0.2, 0.18, 0.03))
    assert "2.0 % of the measured samples" in text and "20.0 % at the low level" in text
    assert "clearer at the low level" in text and "further from the measured share" in text
    text = figure8_verdict(table(0.1, 0.12, 0.05, 0.11))
    assert "no clearer spike" in text and "no further from the measured share" in text
