"""Study ``rare-events`` (studies/rare_events.py), quick, end to end through the CLI.

Covers the study's building blocks :mod:`randvib.studies.rare_events` (strokes read
off a pilot subset simulation, the estimates beside the Gaussian and exact answers,
the unsafe strokes, the figure). What must hold at any size: the friction-free
device's stationary exceedance agrees with the exact Gibbs value within its
interval, the pilot's strokes give first-passage probabilities of the order asked
for, the verdicts are recomputed from results.csv, the report and figure exist.
"""

import json
import math

import pandas as pd
from _stats import assert_matches
from study_checks import check_study_run

from randvib.cli import main
from randvib.statistics import Statistic
from randvib.studies import load
from randvib.studies.rare_events import unsafe_strokes

study = load("rare-events")


def test_rare_events_quick_end_to_end(tmp_path, capsys):
    out = tmp_path / "rare"
    argv = ["study", "rare-events", "--quick", "--out", str(out), "--no-progress"]
    assert main(argv) == 0
    check_study_run(capsys.readouterr().out, out)
    results = pd.read_csv(out / "results.csv")
    g = study.grid(True)
    assert len(results) == len(g["devices"]) * len(g["probabilities"])
    for p, sub in results.groupby(results.groupby("device").cumcount()):
        asked = g["probabilities"][p]
        # the pilot's level at 0.1^j: within a factor 5 of the probability asked for
        assert all(
            abs(math.log10(x / asked)) < math.log10(5) for x in sub.probability_first_passage
        )
    free = results[results.device == "duffing, no friction (white)"]
    for r in free.itertuples():
        stat = Statistic(r.stationary_exceedance, r.stationary_exceedance_ci95,
                         r.stationary_exceedance_se, 200)  # fmt: skip
        assert_matches(stat, r.exact_exceedance, detect=8.0, what="Gibbs")
    verdicts = json.loads((out / "verdicts.json").read_text())
    data = {k: v for k, v in verdicts.items() if k != "verdicts"}
    assert data == json.loads(json.dumps(unsafe_strokes(results)))
    assert len(verdicts["verdicts"]) == 2 * len(g["devices"])
    assert (out / "probability.png").stat().st_size > 0
    assert (out / "report.md").read_text().count("## ") == 3
