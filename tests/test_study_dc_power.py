"""Study ``dc-power`` (studies/dc_power.py): a quick run end to end, its verdicts from its tables.

Covers the study's building blocks :mod:`randvib.studies.bridge` (paired cases of the
resistive coil and the bridges, the stored-power and optimum tables, the
overstatement verdict) through ``randvib study dc-power --quick``.
"""

import json

import numpy as np
import pandas as pd

from randvib.cli import main


def test_dc_power_quick_run_and_its_verdicts(tmp_path, capsys):
    out = tmp_path / "dc"
    assert main(["study", "dc-power", "--quick", "--out", str(out), "--workers", "1"]) == 0
    capsys.readouterr()
    stored = pd.read_csv(out / "stored.csv")
    optimum = pd.read_csv(out / "optimum.csv")
    verdicts = json.loads((out / "verdicts.json").read_text())
    data = verdicts.get("data", verdicts)
    # the verdict counts follow from the table: overstated = ratio's interval below 1
    assert data["n_cases"] == len(stored)
    assert data["n_overstated"] == int((stored.ratio + stored.ratio_ci95 < 1).sum())
    assert data["never_conducts"] == int((stored.power_stored == 0).sum())
    # a diode drop stores less than ideal diodes at the same level and battery (paired paths)
    for (psd, battery), sub in stored.groupby(["psd", "battery"]):
        ideal, drop = sub[sub.v_diode == 0].iloc[0], sub[sub.v_diode > 0].iloc[0]
        assert drop.power_stored <= ideal.power_stored + ideal.power_stored_ci95, (psd, battery)
    # the closure, where offered, within its declared 6.5 % (+ MC's interval)
    offered = stored.dropna(subset=["closure"])
    assert len(offered) > 0
    err = np.abs(offered.closure - offered.power_stored)
    assert np.all(err <= 0.065 * offered.power_stored + offered.power_stored_ci95)
    assert set(optimum.optimum.str.split(" ").str[0]) <= {"interior", "upper", "lower", "refused"}
    assert (out / "report.md").read_text().count("## ") == 3
    assert (out / "dc_power.png").stat().st_size > 0


def test_dc_power_figure_draws_monte_carlo_levels_as_points_not_lines(tmp_path, monkeypatch):
    """On log axes a line through two Monte Carlo levels (each at its own best battery)
    drew a trend nothing computed (issue 35): every series is markers only."""
    from randvib.study_scripts import dc_power

    drawn = {}
    monkeypatch.setattr(dc_power, "save_figure", lambda fig, path: drawn.setdefault("fig", fig))
    rows = [
        {"psd": s, "v_diode": d, "battery": b, "power_stored": p, "power_stored_ci95": 0.1 * p,
         "power_resistive": 2e-3 * s}
        for s in (0.25, 1.0) for d in (0.0, 0.02) for b, p in ((0.01, 1e-4 * s), (0.03, 3e-4 * s))
    ]  # fmt: skip
    dc_power.figure(pd.DataFrame(rows), tmp_path)
    lines = [
        line for ax in drawn["fig"].axes for line in ax.get_lines() if len(line.get_xdata()) > 1
    ]
    assert lines, "nothing drawn"
    assert all(line.get_linestyle() == "None" for line in lines), [
        (line.get_label(), line.get_linestyle()) for line in lines
    ]
