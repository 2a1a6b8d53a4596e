"""Study ``assemblies`` (studies/assemblies.py) and its building blocks :mod:`randvib.studies.assembly_cases`.

The single-mass answer is checked against an independent route (under white
base noise a host mode's absolute acceleration is exactly a Kanai-Tajimi
process, so the single-mass answer is the single-mass harvester's exact power
under that spectrum); the crossing of the 5 % error by its definition; the
verdicts on constructed tables whose answers are known; and a quick run end
to end, its verdicts recomputed from its CSV tables.
"""

import json
import math

import numpy as np
import pandas as pd
import pytest

import randvib as rv
from randvib.cli import main
from randvib.studies import load
from randvib.studies.assembly_cases import (
    HostMode,
    array_verdicts,
    assembly_monte_carlo,
    mass_ratio_at_error,
    single_mass_error,
    single_mass_power,
    single_mass_verdicts,
    tuned,
    two_mass_verdicts,
)

study = load("assemblies")
HOST = HostMode(1.0, 10.0, 0.02)


def test_single_mass_answer_under_white_noise_is_the_kanai_tajimi_answer():
    m = 0.03
    k, c_m, c_e = tuned(HOST, m, frequency_ratio=1.1)
    ours = single_mass_power(HOST, m, k, c_m, c_e, rv.White(0.1))
    kanai = rv.KanaiTajimi(0.1, HOST.frequency, HOST.damping_ratio)
    theirs = rv.predict(rv.Harvester(m=m, c_m=c_m, c_e=c_e, k=k), kanai).power_electrical
    assert ours == pytest.approx(float(theirs), rel=1e-9)


def test_the_error_vanishes_with_the_mass_ratio_and_crosses_where_found():
    x = rv.BandPass(0.1, 10.0, 0.1)
    tiny = single_mass_error(HOST, 1e-9, x)
    assert abs(tiny["error"]) < 1e-5  # no reaction from a vanishing mass
    ratio, where = mass_ratio_at_error(HOST, x, 0.05)
    assert where == "crossed"
    assert abs(single_mass_error(HOST, ratio, x)["error"]) == pytest.approx(0.05, rel=1e-6)
    assert mass_ratio_at_error(HOST, x, 1e-9) == (1e-8, "below")
    assert mass_ratio_at_error(HOST, x, 1e6) == (None, "never")


def _errors():
    rows = []
    for name, errors in (("white", (0.01, 0.2, 1.0)), ("band", (0.1, 0.5, 3.0))):
        for host_zeta, scale in ((0.01, 1.0), (0.05, 0.2)):
            for ratio, error in zip((1e-3, 1e-2, 0.1), errors, strict=True):
                rows.append({"input": name, "host_zeta": host_zeta, "mass_ratio": ratio,
                             "power_assembly": 1.0, "power_single_mass": 1 + error * scale,
                             "error": error * scale})  # fmt: skip
    return pd.DataFrame(rows)


def test_single_mass_verdicts_from_a_constructed_table():
    errors = _errors()
    crossings = pd.DataFrame([
        {"input": "white", "host_zeta": 0.01, "mass_ratio_crossing": 2e-3, "where": "crossed"},
        {"input": "white", "host_zeta": 0.05, "mass_ratio_crossing": 9e-3, "where": "crossed"},
        {"input": "band", "host_zeta": 0.01, "mass_ratio_crossing": 1e-8, "where": "below"},
        {"input": "band", "host_zeta": 0.05, "mass_ratio_crossing": 5e-4, "where": "crossed"},
    ])  # fmt: skip
    # Monte Carlo at z = 0.5 and z = 4 (t quantile of 100 paths)
    t = 1.9842169515086827
    checks = pd.DataFrame([
        {"power_assembly": 1.0, "power_mc": 1.0 + 0.5 * 0.01, "power_mc_ci95": t * 0.01, "n_paths": 100},
        {"power_assembly": 1.0, "power_mc": 1.0 + 4.0 * 0.01, "power_mc_ci95": t * 0.01, "n_paths": 100},
        {"power_assembly": 1.0, "power_mc": math.nan, "power_mc_ci95": math.nan, "n_paths": 0},
    ])  # fmt: skip
    v = single_mass_verdicts(errors, crossings, checks, 0.05)
    assert v["overestimates_everywhere"]
    assert v["largest_error"] == 3.0 and v["largest_error_at"]["input"] == "band"
    # within 5 % at the smallest ratio: white at both dampings (0.01, 0.002), band only at
    # the heavier (0.02; 0.1 at the lighter)
    assert v["right_at_smallest_ratio"] == [
        "white, zeta_h = 0.01",
        "white, zeta_h = 0.05",
        "band, zeta_h = 0.05",
    ]
    assert v["cases"] == 4 and v["smallest_mass_ratio"] == 1e-3
    assert v["crossings"]["white, zeta_h = 0.05"] == 9e-3
    assert v["crossing_where"]["band, zeta_h = 0.01"] == "below"
    assert v["crossing_grows_with_host_damping"]
    # crossed ones over zeta_h zeta_a: white 2e-3 / 5e-4 = 4 and 9e-3 / 2.5e-3 = 3.6; band 0.2
    assert v["crossing_over_damping"]["white"] == pytest.approx([3.6, 4.0])
    assert v["crossing_over_damping"]["band"] == pytest.approx([0.2, 0.2])
    assert v["monte_carlo_agree"] == 1 and v["monte_carlo_largest_z"] == pytest.approx(4.0)
    assert v["monte_carlo_checks"] == 2  # the row without a run is not counted
    crossings.loc[1, "mass_ratio_crossing"] = 1e-3  # white: lighter damping crosses later
    assert not single_mass_verdicts(errors, crossings, checks, 0.05)[
        "crossing_grows_with_host_damping"
    ]


def test_array_verdicts_from_a_constructed_table():
    rows = [
        # bandwidth 0.1: N = 2 significantly better, N = 3 undecided
        (0.1, 1, 1.00, 0.0, math.nan, math.nan), (0.1, 2, 1.05, 0.05, 0.04, 0.01),
        (0.1, 3, 1.04, 0.04, 0.01, 0.02),
        # bandwidth 1: the single harvester significantly better than N = 2
        (1.0, 1, 2.00, 0.0, math.nan, math.nan), (1.0, 2, 1.90, -0.05, -0.1, 0.02),
        # and N = 3 the same as one harvester, to the searches' rounding
        (1.0, 3, 2.0 * (1 - 2e-9), -2e-9, 0.0, 0.02),
    ]  # fmt: skip
    table = pd.DataFrame(rows, columns=["bandwidth", "n", "power", "gain", "difference_mc",
                                        "difference_mc_ci95"])  # fmt: skip
    table["power_mc"], table["power_mc_ci95"], table["n_paths"] = table.power, 0.01, 64
    v = array_verdicts(table)
    assert v["comparisons"] == v["monte_carlo_comparisons"] == 4 and v["array_better_exact"] == 2
    assert v["array_equal_exact"] == 1
    assert v["array_significantly_better"] == 1 and v["single_significantly_better"] == 1
    assert v["by_bandwidth"]["0.1"] == {"best_n": 2, "best_gain": 0.05, "largest_gain": 0.05,
                                        "exact": {2: "above", 3: "above"},
                                        "monte_carlo": {2: "above", 3: "neither"}}  # fmt: skip
    assert v["by_bandwidth"]["1"]["best_n"] == 1 and v["by_bandwidth"]["1"]["monte_carlo"] == {
        2: "below",
        3: "neither",
    }
    assert v["by_bandwidth"]["1"]["exact"] == {2: "below", 3: "equal"}
    assert v["largest_gain"] == 0.05 and v["monte_carlo_agree"] == 6
    # without Monte Carlo: the exact verdicts stand, nothing is counted as significant
    table[["difference_mc", "difference_mc_ci95", "power_mc", "power_mc_ci95"]] = math.nan
    v = array_verdicts(table)
    assert v["array_better_exact"] == 2 and v["by_bandwidth"]["0.1"]["exact"] == {
        2: "above",
        3: "above",
    }
    assert v["by_bandwidth"]["0.1"]["monte_carlo"] == {2: None, 3: None}
    assert v["monte_carlo_comparisons"] == v["monte_carlo_checks"] == 0
    assert v["array_significantly_better"] == v["single_significantly_better"] == 0


def test_two_mass_verdicts_from_a_constructed_table():
    pairs = pd.DataFrame([
        {"input": "band-pass zeta 0.3", "fc": 0.003, "power_single": 1.0, "power_two_mass": 1.2,
         "single_mc": 1.1, "single_mc_ci95": 0.01, "two_mass_mc": 1.3, "two_mass_mc_ci95": 0.01,
         "difference_mc": 0.2, "difference_mc_ci95": 0.01},
        {"input": "band-pass zeta 0.05", "fc": 0.0, "power_single": 1.0, "power_two_mass": 0.9,
         "single_mc": 1.0, "single_mc_ci95": 0.01, "two_mass_mc": 0.99, "two_mass_mc_ci95": 0.01,
         "difference_mc": -0.01, "difference_mc_ci95": 0.02},
    ])  # fmt: skip
    v = two_mass_verdicts(pairs)
    assert v["two_mass_better"] == 1 and v["undecided"] == 1 and v["single_better"] == 0
    case = v["cases"]["band-pass zeta 0.3, Fc = 3 mN"]
    assert case["monte_carlo"] == "two-mass"
    assert case["ratio_predicted"] == pytest.approx(1.2) and case["ratio_monte_carlo"] == 1.3 / 1.1
    assert case["linearisation"] == "two-mass"
    assert v["cases"]["band-pass zeta 0.05, Fc = 0 mN"]["linearisation"] == "single mass"
    assert v["two_mass_better_linearisation"] == 1 and v["monte_carlo_cases"] == 2
    # linearisation's largest error: 0.9 / 0.99 - 1 = -9.1 %
    assert v["linearisation_largest_error"] == pytest.approx(abs(0.9 / 0.99 - 1))
    # without Monte Carlo: linearisation's verdicts only
    pairs.loc[1, ["single_mc", "two_mass_mc", "difference_mc", "difference_mc_ci95"]] = math.nan
    v = two_mass_verdicts(pairs)
    assert v["cases"]["band-pass zeta 0.05, Fc = 0 mN"]["monte_carlo"] is None
    assert v["cases"]["band-pass zeta 0.05, Fc = 0 mN"]["ratio_monte_carlo"] is None
    assert v["monte_carlo_cases"] == 1 and v["undecided"] == 0 and v["two_mass_better"] == 1
    assert v["linearisation_largest_error"] == pytest.approx(abs(1.0 / 1.1 - 1))


def _quick_run(tmp_path, monkeypatch, capsys, mc):
    """A tiny run through the command line: (its CSV tables, verdicts.json, output folder)."""
    small = study.grid(True)
    # (c) without friction here: its exact design takes a second, linearisation's ten
    small.update(ratios=(1e-3, 0.05), host_zetas=(0.05,), inputs={"white": None},
                 checks=[("white", 0.05, 0.05)], bandwidths=(0.3,), fcs=(0.0,), mc=mc)  # fmt: skip
    monkeypatch.setattr(study, "grid", lambda quick: small)
    out = tmp_path / "assemblies"
    assert main(["study", "assemblies", "--quick", "--out", str(out), "--no-progress"]) == 0
    capsys.readouterr()
    tables = {name: pd.read_csv(out / f"{name}.csv")
              for name in ("single_mass", "crossings", "checks", "arrays", "two_mass")}  # fmt: skip
    data = json.loads((out / "verdicts.json").read_text())
    # every verdict is recomputed from the tables as written
    assert data["single_mass"] == json.loads(json.dumps(
        study.single_mass_verdicts(tables["single_mass"], tables["crossings"], tables["checks"],
                                   0.05),
        default=float))  # fmt: skip
    assert data["arrays"] == json.loads(json.dumps(array_verdicts(tables["arrays"])))
    assert data["two_mass"] == json.loads(json.dumps(two_mass_verdicts(tables["two_mass"])))
    # the exact answers in the tables are those of the building blocks
    row = tables["single_mass"].iloc[-1]
    again = single_mass_error(HostMode(1.0, 10.0, row.host_zeta), row.mass_ratio, rv.White(0.1),
                              **study.HARVESTER)  # fmt: skip
    assert row.power_assembly == pytest.approx(again["power_assembly"], rel=1e-12)
    assert (out / "assemblies.png").stat().st_size > 0
    assert "(c) Two masses" in (out / "report.md").read_text()
    return tables, data, out


def test_assemblies_quick_run_and_its_verdicts(tmp_path, monkeypatch, capsys):
    """With the assembly kernel, paired Monte Carlo of every device; without, none.

    The kernel is :mod:`randvib.montecarlo.assembly_simulation` (branch asmmc):
    with it, 16 paths of 1 s from rest per device; without it the study runs
    on the exact and linearised answers alone and says so.
    """
    simulated = assembly_monte_carlo()
    mc = {"n_paths": 16, "window": 1.0, "burn_in": 2.0, "dt": 5e-4} if simulated else None
    tables, data, out = _quick_run(tmp_path, monkeypatch, capsys, mc)
    assert data["arrays"]["comparisons"] == 1
    assert data["arrays"]["array_better_exact"] == int(tables["arrays"].gain.iloc[-1] > 0)
    report = (out / "report.md").read_text()
    if simulated:
        assert data["arrays"]["monte_carlo_comparisons"] == 1
        assert np.isfinite(tables["arrays"].difference_mc.iloc[-1])
        assert data["two_mass"]["monte_carlo_cases"] == len(tables["two_mass"])
        assert data["single_mass"]["monte_carlo_checks"] == 1
        assert study.NO_MONTE_CARLO not in report
    else:
        assert data["arrays"]["monte_carlo_comparisons"] == 0
        assert tables["two_mass"].single_mc.isna().all() and (tables["checks"].n_paths == 0).all()
        assert data["two_mass"]["monte_carlo_cases"] == 0
        assert study.NO_MONTE_CARLO in report and "No Monte Carlo (no assembly kernel" in report
