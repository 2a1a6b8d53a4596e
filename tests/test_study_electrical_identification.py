"""The electrical-identification study (studies/electrical_identification.py) end to end
in its quick form, through ``randvib study`` (:mod:`randvib.cli.study`), and its verdict
from given tables.

The quick run only exercises the pipeline (one seed, 0.6 s records, a small search
started next to the truth). The full run (4 seeds, 4 s records, identify's default
search from scratch) is run by hand and its results are not yet recorded; the coverage
of the intervals over seeds is tests/calibration/electrical_coverage.py's (results in
electrical_coverage.txt beside it).
"""

import json

import numpy as np
import pandas as pd
from _cli import run

from randvib.cli.study import load_study
from randvib.studies import load

study = load("electrical-identification")


def test_quick_run_writes_the_tables_the_figure_and_a_verdict_per_device(capsys, tmp_path):
    assert load_study("electrical-identification") is study.run_study
    out = tmp_path / "study"
    code, _, err = run(capsys, "study", "electrical-identification", "--quick", "--out", out,
                       "--no-progress")  # fmt: skip
    assert code == 0, err
    rows = pd.read_csv(out / "parameters.csv", keep_default_na=False)
    assert set(rows.device) == set(study.DEVICES) and set(rows.channels) == set(study.CHANNELS)
    verdicts = json.loads((out / "verdicts.json").read_text())["verdicts"]
    assert [v.split(":")[0] for v in verdicts] == list(study.DEVICES)
    assert (out / "parameters.png").is_file() and "## Coverage" in (out / "report.md").read_text()
    powers = pd.read_csv(out / "power.csv")
    assert np.all(powers.true_power > 0)


def test_verdict_says_which_channel_identifies_what():
    """From given rows: a refusal is quoted with its reason, a fit by what it fixes and
    what it leaves undetermined (relative standard error above 50 %)."""

    def row(dev, ch, p, se, refused="", seed=0):
        return dict(device=dev, channels=ch, seed=seed, parameter=p, truth=1.0, estimate=1.0,
                    standard_error=se, lower=0.9, upper=1.1, covered=1.0, refused=refused)  # fmt: skip

    why = "the records cannot determine c, alpha (why): add"
    rows = [row(d, "displacement", "c", 0.01) for d in study.DEVICES]
    rows += [row(d, "voltage", "alpha", 0.9) for d in study.DEVICES]
    rows += [row(d, "both", "", np.nan, why) for d in study.DEVICES]
    # one seed refused, the other fitted (the full run's piezo from its voltage)
    rows += [row(d, "voltage", "", np.nan, why, seed=1) for d in study.DEVICES]
    rows += [row(d, "voltage", "alpha", 0.9, seed=2) for d in study.DEVICES]
    powers = pd.DataFrame(
        [dict(device=d, channels=c, relative_error=0.01) for d in study.DEVICES
         for c in ("displacement", "voltage")]
    )  # fmt: skip
    coil = study.verdict(pd.DataFrame(rows), powers)[0]
    assert coil.startswith("coil: from the displacement c are identified (median relative")
    assert (
        "from the load voltage (refused on 1 of 3 seeds: the records cannot determine c, "
        "alpha; on the other 2) nothing is determined" in coil
    )
    assert (
        "from both channels refused on every seed: the records cannot determine c, alpha (" in coil
    )
