"""Studies ``interaction`` and ``linearisation-accuracy``: building blocks and tiny end-to-end runs;
the study scripts' packaging (randvib.studies.load, pyproject.toml).

The end-to-end runs go through ``randvib study NAME --quick`` (in-process
``main``) with the quick grid and settings monkeypatched to a few points and
short windows, so they check the command-line path, the verdict data against
the CSV tables, the interaction contrast against the FPK grids, resuming,
refusing another run's folder (another grid or seed) and the exact scaling
laws; the verdict wording itself is checked
on synthetic tables below.

Covers the studies' building blocks :mod:`randvib.studies.grids`,
:mod:`randvib.studies.contrasts`, :mod:`randvib.studies.accuracy`,
:mod:`randvib.studies.verdicts` and :mod:`randvib.studies.report`.
"""

import json
import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from study_checks import check_study_run, contrast_zscores

import randvib as rv
from randvib.analytic.prediction import expected_power
from randvib.cli import main
from randvib.formatting import plus_minus
from randvib.montecarlo import sweep
from randvib.montecarlo.sweep import SweepSettings
from randvib.studies import STUDIES, load
from randvib.studies.accuracy import trusted_limit
from randvib.studies.grids import (
    duffing_strength,
    fc_at_friction_level,
    fc_where_power_halves,
    friction_level,
    friction_level_points,
    power_ratio,
)
from randvib.studies.verdicts import (
    interaction_counts,
    interaction_summary,
    linearisation_by_spring,
    scaling_sentence,
)

interaction = load("interaction")  # the script studies/interaction.py
linearisation_accuracy = load("linearisation-accuracy")  # studies/linearisation_accuracy.py

BASE = rv.preset("figure9")
TINY = SweepSettings(dt=1e-4, window=0.3, burn_in=0.1, min_paths=48, max_paths=48, batch_paths=48)


ROOT = Path(__file__).resolve().parents[1]


# ----------------------------------------------------------------- the scripts ship with the package
def test_setuptools_packages_are_the_packages_on_disk():
    """pyproject.toml lists the packages by hand (the scripts' mapping needs it): the list must
    be every package of the source tree, plus the study scripts mapped from studies/."""
    from setuptools import find_packages

    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    on_disk = find_packages(str(ROOT), include=["randvib", "randvib.*"])
    assert sorted(config["packages"]) == sorted([*on_disk, "randvib.study_scripts"])
    assert config["package-dir"] == {"randvib.study_scripts": "studies"}
    scripts = (ROOT / "studies").glob("*.py")
    assert {p.stem.replace("_", "-") for p in scripts if p.stem != "__init__"} == set(STUDIES)


def test_load_takes_the_scripts_beside_the_package():
    module = load("figure9")
    assert module.__name__ == "randvib.study_scripts.figure9"
    assert Path(module.__file__) == ROOT / "studies" / "figure9.py"
    assert load("figure9") is module
    with pytest.raises(ValueError, match="unknown study 'nope'; available: figure9"):
        load("nope")


@pytest.mark.slow
def test_a_wheel_ships_the_study_scripts(tmp_path):
    """``randvib study NAME`` must work from any install: the wheel carries the scripts of
    studies/ as randvib.study_scripts (built from a copy: a build writes into its tree).

    Built with the test environment's setuptools (``--no-build-isolation``; the [test]
    extra pins the version pyproject.toml's build-system asks for): an isolated build
    spent most of the test's 6.4 CPU-s installing setuptools into a fresh environment."""
    project = tmp_path / "project"
    project.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, project / name)
    skip = shutil.ignore_patterns("__pycache__", "*.pyc", "*.nbi", "*.nbc")
    for name in ("randvib", "studies"):
        shutil.copytree(ROOT / name, project / name, ignore=skip)
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation",
         "-w", str(tmp_path / "dist"), str(project)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert built.returncode == 0, built.stderr[-2000:]
    (wheel,) = (tmp_path / "dist").glob("randvib-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    expected = {f"randvib/study_scripts/{s.replace('-', '_')}.py" for s in STUDIES}
    assert expected | {"randvib/study_scripts/__init__.py"} <= names
    assert not any(n.startswith("studies/") for n in names)


def _public_module(module: str) -> bool:
    """What a study script may import from randvib: the package (its exports), the studies'
    building blocks (randvib.studies.*) and the package's top-level public modules
    (randvib.statistics, randvib.figure_style, randvib.datasets); not the engine's
    subpackages (models, analytic, montecarlo, identification) nor a private module."""
    parts = module.split(".")
    if any(part.startswith("_") for part in parts):
        return False
    if parts[:2] == ["randvib", "studies"] or parts == ["randvib"]:
        return True
    return len(parts) == 2 and (ROOT / "randvib" / f"{parts[1]}.py").is_file()


@pytest.mark.parametrize("name", STUDIES)
def test_study_scripts_use_the_public_api(name):
    """A study reads as a user's script: what it needs is exported (``import randvib as rv``)
    or a randvib.studies building block; no engine module, no private module or name."""
    import ast

    tree = ast.parse((ROOT / "studies" / f"{name.replace('-', '_')}.py").read_text())
    imports = [(node.module, [a.name for a in node.names]) for node in ast.walk(tree)
               if isinstance(node, ast.ImportFrom)]  # fmt: skip
    imports += [(a.name, []) for node in ast.walk(tree) if isinstance(node, ast.Import)
                for a in node.names]  # fmt: skip
    ours = [(m, names) for m, names in imports if m and m.split(".")[0] == "randvib"]
    outside = [m for m, _ in ours if not _public_module(m)]
    private = [n for _, names in ours for n in names if n.startswith("_")]
    assert outside == [] and private == [], (outside, private)


# ----------------------------------------------------------------- friction level phi
@pytest.mark.parametrize("psd", [0.1, 1.0, 10.0])
def test_friction_level_round_trip_and_half_power(psd):
    device = BASE.updated(c_m=0.03, c_e=0.07)
    fc = np.array([0.0, 1e-3, 0.05, 0.3])
    assert np.allclose(fc_at_friction_level(device, psd, friction_level(device, psd, fc)), fc)
    # Eq. 32 halves the power at phi = sqrt(pi)/2 whatever S and c
    assert np.isclose(
        friction_level(device, psd, fc_where_power_halves(device, psd)), np.sqrt(np.pi) / 2
    )


def test_eq32_depends_on_fc_and_s_only_through_phi():
    phi = np.array([0.05, 0.5, 1.0, 3.0])
    for psd in (0.1, 1.0, 10.0):
        fc = fc_at_friction_level(BASE, psd, phi)
        ratio = expected_power(BASE.updated(fc=fc), psd) / expected_power(BASE.updated(fc=0), psd)
        assert np.allclose(ratio, power_ratio(phi), rtol=1e-10)


def test_duffing_strength_repeats_for_equal_k3_times_s():
    mu = duffing_strength(BASE, np.array([0.1, 1.0]), np.array([5e7, 5e6]))
    assert mu[0] == pytest.approx(mu[1])
    # mu = k3 sigma_z0^2 / k with sigma_z0^2 the linear oscillator's E[z^2]
    vv = 1.0 * BASE.m / (4 * BASE.c)
    assert duffing_strength(BASE, 1.0, 5e5) == pytest.approx(5e5 * vv * BASE.m / BASE.k**2)


def test_plus_minus_formats_percent():
    assert plus_minus([0.0123, -0.004], [0.001, 0.0005]) == ["+1.23 ± 0.10", "-0.40 ± 0.05"]


# ----------------------------------------------------------------- threshold interpolation
def test_trusted_limit_interpolates_first_crossing_in_log_phi():
    phi = np.array([0.1, 1.0, 10.0])
    # bound = |error| + ci: 0.5 %, 2.5 %, 12.5 %; each crossing a quarter of a decade in
    error, ci = np.array([-0.004, -0.024, -0.124]), np.full(3, 0.001)
    assert trusted_limit(phi, error, ci, 0.01) == pytest.approx(10**-0.75)
    assert trusted_limit(phi, error, ci, 0.05) == pytest.approx(10**0.25)
    assert trusted_limit(phi, error, ci, 0.2) == np.inf
    assert trusted_limit(phi, error, ci, 0.001) == 0.0
    # order of the rows does not matter
    assert trusted_limit(phi[::-1], error[::-1], ci, 0.01) == pytest.approx(10**-0.75)


def test_trusted_limit_takes_the_interval_and_first_crossing():
    phi = np.array([0.1, 0.2, 0.4, 0.8])
    # the estimate alone stays below 1 % at 0.2, the upper bound does not
    error, ci = np.array([0.002, 0.009, 0.004, 0.03]), np.array([0.001, 0.003, 0.001, 0.001])
    limit = trusted_limit(phi, error, ci, 0.01)
    assert 0.1 < limit < 0.2
    # a later dip back below the tolerance does not extend the trusted range
    assert limit == pytest.approx(
        np.exp(np.log(0.1) + (0.01 - 0.003) / (0.012 - 0.003) * np.log(2))
    )


def test_trusted_limit_rejects_bad_input():
    with pytest.raises(ValueError, match="one length"):
        trusted_limit([0.1, 1.0], [0.0], [0.0], 0.01)
    with pytest.raises(ValueError, match="> 0"):
        trusted_limit([0.0, 1.0], [0.0, 0.0], [0.0, 0.0], 0.01)


# ----------------------------------------------------------------- grids
def test_interaction_grid_holds_every_contrast_partner():
    points = interaction.study_points(BASE, (1.0, 0.1), (0.0, 5e7), 3)
    assert len(points) == 2 * 2 * 3
    for p in points:
        fc_max = 2 * fc_where_power_halves(BASE, p["psd"])
        assert 0.0 <= p["fc"] <= fc_max * (1 + 1e-12)
        for fc, k3 in ((p["fc"], 0.0), (0.0, p["k3"]), (0.0, 0.0)):
            assert {**p, "fc": fc, "k3": k3} in points
    with pytest.raises(ValueError, match="include 0"):
        interaction.study_points(BASE, (1.0,), (5e5,), 3)


def test_linearisation_accuracy_grid_sets_fc_by_phi():
    series = ((1.0, 0.0, 0.1), (10.0, 5e5, 0.025))
    points = friction_level_points(BASE, series, (0.1, 2.0))
    assert len(points) == 4
    for p in points:
        device = BASE.updated(c_m=p["c_m"], c_e=p["c_e"])
        assert np.round(friction_level(device, p["psd"], p["fc"]), 9) in (0.1, 2.0)
    with pytest.raises(ValueError, match="phis"):
        friction_level_points(BASE, series, (0.0, 1.0))


def test_half_step_points_and_levels_of_a_friction_level_grid():
    """The re-run points: per (k3, damping), the highest Fc at its largest S; phi and zeta of
    every point's own device (its damping)."""
    from randvib.studies.grids import damping_ratio, hardest_at_largest_psd, point_levels

    series = ((0.1, 0.0, 0.1), (10.0, 0.0, 0.1), (1.0, 0.0, 0.025), (10.0, 5e5, 0.1))
    points = friction_level_points(BASE, series, (0.1, 2.0, 0.5))
    hardest = hardest_at_largest_psd(points)
    assert [(p["psd"], p["k3"], p["c_m"]) for p in hardest] == [
        (10.0, 0.0, 0.1), (1.0, 0.0, 0.025), (10.0, 5e5, 0.1)
    ]  # fmt: skip
    levels = point_levels(BASE, points)
    assert np.allclose(levels.phi, np.tile([0.1, 2.0, 0.5], 4))
    light = BASE.updated(c_m=0.025, c_e=0.025)
    assert (
        levels.zeta.tolist()
        == [damping_ratio(BASE)] * 6 + [damping_ratio(light)] * 3 + [damping_ratio(BASE)] * 3
    )
    assert all(p["fc"] == max(q["fc"] for q in points if q["psd"] == p["psd"] and
                              q["c_m"] == p["c_m"]) for p in hardest)  # fmt: skip


# ----------------------------------------------------------------- end to end (tiny)
def _mtimes(folder):
    return {p.name: p.stat().st_mtime_ns for p in sorted((folder / "sweep" / "points").glob("*"))}


def _cli_study(name, out, capsys):
    """``randvib study NAME --quick`` in-process; the quick grid is monkeypatched small."""
    argv = ["study", name, "--quick", "--out", str(out), "--workers", "1", "--no-progress"]
    assert main(argv) == 0
    check_study_run(capsys.readouterr().out, out)
    return out / "report.md"


def _no_pool(*args, **kwargs):
    raise AssertionError("a worker-process pool started under --workers 1")


def test_interaction_study_end_to_end(tmp_path, monkeypatch, capsys):
    grid = {"psds": (1.0,), "k3s": (0.0, 5e7), "n_fc": 2}
    out = tmp_path / "inter"
    monkeypatch.setattr(interaction, "grid", lambda quick: grid)
    monkeypatch.setattr(interaction, "settings_for", lambda quick, seed: TINY)
    # --workers 1 runs the sweep and its half-step re-run in this process (their own
    # default is a pool on every core: two spawned interpreters loading numba, 4x the CPU)
    monkeypatch.setattr(sweep, "WorkerPool", _no_pool)
    report = _cli_study("interaction", out, capsys)
    inter = pd.read_csv(out / "interaction.csv")
    assert len(inter) == 1 and inter.k3[0] == 5e7 and inter.fc[0] > 0
    # (The Fc = 0 bracket, zero through the companion control by construction,
    # is no longer asserted: it cannot fail.) The contrast against the FPK
    # grids' contrast, which needs no sampling: within 4 standard errors
    # (tests/calibration/studies.py, seeds 0-19 of this tiny run: z mean +0.23,
    # SD 1.07, largest |z| 2.39; 48 paths, so this run detects only contrasts
    # of several percent of P(Fc, 0): a check of the pairing, not of the size).
    z = contrast_zscores(inter)
    assert abs(z.z[0]) <= 4 and z.se[0] > 0
    # verdict data recomputed from the CSV, and the sentence built from it
    verdict = json.loads((out / "verdicts.json").read_text())
    row = verdict["interaction"]["by_k3"]["5e+07"]
    assert row["n_holm"] == int(inter.detectable_holm.sum())
    assert row["n_detectable"] == int((inter.p_value < 0.05).sum())
    assert row["largest_relative_contrast"] == pytest.approx(inter.relative_contrast[0])
    text = report.read_text()
    if row["n_holm"] == 0:
        bound = 100 * (abs(inter.relative_contrast[0]) + inter.relative_ci95[0])
        assert f"stays within ±{bound:.2f} % of P(Fc, 0)" in text
    else:
        assert "The interaction is detectable (Holm" in text
    table = pd.read_csv(out / "results.csv")
    assert len(table) == 4
    lin = verdict["linearisation"]
    spread = abs(float(np.diff(table[table.fc > 0].linearisation_rel_error)[0]))
    assert lin["spread"] == pytest.approx(spread)
    check = pd.read_csv(out / "step_check.csv")
    assert verdict["step_check"]["n_below"] == int(check.bias_below_error.sum())

    # same run again: resumes from the stored points, recomputes nothing
    before = _mtimes(out)
    _cli_study("interaction", out, capsys)
    assert _mtimes(out) == before
    assert pd.read_csv(out / "interaction.csv").equals(inter)

    monkeypatch.setattr(interaction, "grid", lambda quick: {**grid, "n_fc": 3})
    with pytest.raises(FileExistsError, match="different run"):
        interaction.run_study(out, quick=True, workers=1)


def test_linearisation_accuracy_study_end_to_end(tmp_path, monkeypatch, capsys):
    grid = {"series": ((1.0, 0.0, 0.1), (10.0, 0.0, 0.1)), "phis": (0.5, 3.0)}
    out = tmp_path / "acc"
    monkeypatch.setattr(linearisation_accuracy, "grid", lambda quick: grid)
    monkeypatch.setattr(linearisation_accuracy, "settings_for", lambda quick, seed, series: TINY)
    report = _cli_study("linearisation-accuracy", out, capsys)
    table = pd.read_csv(out / "results.csv")
    assert np.allclose(table.phi, np.tile([0.5, 3.0], 2))
    # k3 = 0: the series at S = 1 and 10 are the same paths rescaled (exact scaling)
    a, b = (table[table.psd == s].sort_values("phi") for s in (1.0, 10.0))
    assert np.allclose(
        a.linearisation_rel_error.to_numpy(), b.linearisation_rel_error.to_numpy(), atol=1e-9
    )
    assert (table.linearisation_rel_error_ci95 > 0).all()
    limits = pd.read_csv(out / "thresholds.csv")
    lin_limits = limits[limits.method == "linearisation"]
    for (psd, sub), limit in zip(
        table.groupby("psd", sort=False), lin_limits.itertuples(), strict=True
    ):
        assert limit.psd == psd
        assert limit.phi_5pct == trusted_limit(
            sub.phi, sub.linearisation_rel_error, sub.linearisation_rel_error_ci95, 0.05
        )
    verdict = json.loads((out / "verdicts.json").read_text())
    spread = verdict["collapse"]["0"]["spread"]
    assert spread <= linearisation_accuracy.ROUNDING
    big = table.linearisation_rel_error[table.linearisation_rel_error.abs() > 0.01]
    assert verdict["n_error_over_1pct"] == len(big)
    assert verdict["n_negative_over_1pct"] == int((big < 0).sum())
    text = report.read_text()
    assert "which collapse on phi" in text and "equal to rounding" in text
    meta = json.loads((out / "metadata.json").read_text())["identity"]
    assert meta["study"] == "linearisation-accuracy" and meta["grid"]["phis"] == [0.5, 3.0]

    before = _mtimes(out)
    _cli_study("linearisation-accuracy", out, capsys)
    assert _mtimes(out) == before
    with pytest.raises(FileExistsError, match="different run"):
        linearisation_accuracy.run_study(out, quick=True, seed=1, workers=1)


# ----------------------------------------------------------------- verdict wording follows the data
def _inter_rows(contrasts, averaging, holm=(False, False, False, False)):
    return pd.DataFrame(
        {
            "psd": 1.0,
            "k3": [5e5, 5e5, 5e7, 5e7],
            "fc": [0.01, 0.02, 0.01, 0.02],
            "phi": [0.5, 1.0, 0.5, 1.0],
            "relative_contrast": contrasts,
            "relative_ci95": 0.002,
            "detectable": [abs(c) > 0.002 for c in contrasts],
            "detectable_holm": list(holm),
            "averaging_relative_contrast": averaging,
        }
    )


def test_interaction_summary_counts_holm_per_k3_and_describes_averaging():
    inter = _inter_rows([0.001, -0.001, 0.004, 0.009], [1e-4, 3e-4, 2e-3, 6e-3])
    verdict, _ = interaction_summary(inter, (0.0, 5e5, 5e7), interaction.K3_LABELS)
    assert verdict.startswith("No interaction is detectable")
    assert "±1.10 %" in verdict  # |0.009| + 0.002 at the largest k3
    assert "all positive contrasts growing in size with k3 and Fc" in verdict
    counts = interaction_counts(inter, (0.0, 5e5, 5e7))
    assert counts["by_k3"]["5e+07"]["n_detectable"] == 2 and counts["n_holm"] == 0
    inter = _inter_rows(
        [0.001, -0.001, 0.004, 0.009], [1e-4, 3e-5, 2e-3, 6e-3], holm=(False, False, True, True)
    )
    verdict, _ = interaction_summary(inter, (0.0, 5e5, 5e7), interaction.K3_LABELS)
    assert "detectable (Holm, family level 5 %) at 2 of 4" in verdict
    assert "2 at k3 = 5e+07" in verdict
    assert "growing in size with k3 (not monotonically with Fc)" in verdict


def test_interaction_linearisation_by_spring_and_scaling_follow_the_data():
    lin = pd.DataFrame(
        {
            "psd": 1.0,
            "k3": [0.0, 0.0, 5e7, 5e7],
            "fc": [0.01, 0.02, 0.01, 0.02],
            "phi": [0.5, 1.0, 0.5, 1.0],
            "linearisation_rel_error": [-0.01, -0.06, -0.012, -0.05],
            "linearisation_rel_error_ci95": 0.004,
        }
    )
    data = linearisation_by_spring(lin)
    assert data["series_largest_at_top_fc"] == 2 and data["spread"] == pytest.approx(0.01)
    assert "changes with k3 by up to 1.00 %" in data["sentence"]  # > sqrt(2) * 0.4 %
    data = linearisation_by_spring(lin.assign(linearisation_rel_error_ci95=0.008))
    assert "no resolved dependence on the spring" in data["sentence"]
    lin.loc[1, "linearisation_rel_error"] = -0.005
    assert "largest at the highest Fc in 1 of 2" in linearisation_by_spring(lin)["where_largest"]
    inter = pd.DataFrame({"phi": [0.5, 0.5], "mu": [0.1, 0.1], "relative_contrast": [0.01, 0.01]})
    assert "i.e. to rounding" in scaling_sentence(inter)
    inter.loc[1, "relative_contrast"] = 0.012
    assert "more than rounding" in scaling_sentence(inter)
    assert "no two rows" in scaling_sentence(inter.assign(mu=[0.1, 0.2]))


def test_linearisation_vs_averaging_reading_follows_the_data():
    reading = load("linearisation-vs-averaging").reading

    df = pd.DataFrame(
        {
            "psd": 1.0,
            "kappa": [0.0, 0.5, 2.0, 0.0, 0.5, 2.0],
            "k3": [0.0, 0.0, 0.0, 7e6, 7e6, 7e6],
            "err_linearisation": [0.0, -0.03, -0.09, 0.0, -0.03, -0.09],
            "err_averaging": [0.0, 0.01, 0.02, 0.0, 0.005, 0.01],
            "dk3_averaging": [0, 0, 0, 0.0, 0.004, 0.008],
            "dk3_fpk": [0, 0, 0, 0.0, 0.001, 0.002],
            "dk3_mc": [0, 0, 0, 0.0, 0.0012, 0.0019],
            "power_fpk_fast": [1.0, 1.0, 1.0, 1.0, 1.0, 1.0002],
            "power_fpk": 1.0,
        }
    )
    text = reading(df, {"fpk_fast_point_s": 0.002})
    assert "underestimates the power at every point with friction, increasingly with kappa" in text
    assert "at most 0.33 times linearisation's, and shrinks as k3" in text
    assert "overstates it (4.0-4.0x) relative to the FPK reference, with the right sign" in text
    assert "at most 0.19 % there" in text and "within 0.020 % at every point, at 2.0 ms" in text
    df.loc[2, "err_linearisation"] = 0.01
    df.loc[5, "dk3_averaging"] = -0.001
    text = reading(df)
    assert "underestimates the power at 3 of 4 points" in text and "not monotonically" in text
    assert "wrong sign" in text and "ms a point" not in text


def test_interaction_contrasts_holm_at_family_level(monkeypatch):
    """Holm's step-down at 5 % over the family, on contrasts with known z-scores.

    z = 2.2, 2.1, 0.5 give p = 0.028, 0.036, 0.62: two pass on their own at
    5 %, none after Holm (0.028 > 0.05 / 3); at a 10 % family level two would.
    """
    from types import SimpleNamespace

    from randvib.statistics import Statistic
    from randvib.studies import contrasts

    points = [{"fc": fc, "k3": k3} for k3 in (0.0, 1.0) for fc in (0.0, 0.1, 0.2, 0.3)]
    table = pd.DataFrame(
        {"point": range(8), "power_electrical": 1.0, "power_electrical_ci95": 0.01}
    )
    result = SimpleNamespace(points=points, table=table)
    z_of_point = {5: 2.2, 6: -2.1, 7: 0.5}

    def fake_contrast(result, base, weights):
        i = max(weights)  # the (fc, k3) point itself has the largest index
        return Statistic(z_of_point[i] * 1e-3, 1.96e-3, 1e-3, 100)

    monkeypatch.setattr(contrasts, "paired_contrast", fake_contrast)
    inter = contrasts.interaction_contrasts(result, BASE, "fc", "k3")
    assert inter.fc.tolist() == [0.1, 0.2, 0.3]
    assert inter.detectable.tolist() == [True, True, False]
    assert inter.detectable_holm.tolist() == [False, False, False]
    z_of_point[5], z_of_point[6] = 2.5, -2.3  # p = 0.012 <= 0.05 / 3, then 0.021 <= 0.05 / 2
    inter = contrasts.interaction_contrasts(result, BASE, "fc", "k3")
    assert inter.detectable_holm.tolist() == [True, True, False]
