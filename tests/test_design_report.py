"""What a design reports beside its optimum (:mod:`randvib.harvester_design.result`, ``randvib design``).

Issue 35: the limits say what they bound (the Gaussian budget's bound is
not a bound for every device meeting the budget; a hard-stroke bound and a
causal one beside it, each labelled), and the report says what its numbers
do not: the device chosen (not the ranges' midpoints), Monte Carlo values to
the digits their intervals support, an inactive stroke budget, a missed
precision target, every fraction in ``print(result)``.
"""

from __future__ import annotations

import json
import re

import pytest
from _cli import run

import randvib as rv
from randvib import formatting
from randvib.analytic.harvesting_limit import (
    causal_harvesting_limit,
    gaussian_displacement_budget,
    harvesting_limit,
)
from randvib.montecarlo.sweep import SweepSettings

M, C_M = 0.0226, 0.05


def _analytic(excitation, stroke=0.002, eps=0.01, k=57.4):
    fixed = rv.Harvester(m=M, c_m=C_M, c_e=0.1, k=k, stroke=stroke)
    return rv.design(fixed, excitation, {"c_e": (0.01, 2.0)}, exceedance=eps, monte_carlo=False)


@pytest.fixture(scope="module")
def band_pass():
    """The analytic design under band-pass input at a 3 mm stroke (the budget binds)."""
    return _analytic(rv.BandPass(1.0, 8.0, 0.1), 0.003)


def test_each_limit_says_what_it_bounds(band_pass):
    """The issue's band-limited case, a band-pass and white noise, without Monte Carlo."""
    d, eps = 0.002, 0.01
    sigma = gaussian_displacement_budget(d, eps)
    band = rv.BandLimited(1.0, 4.0, 20.0)
    r = _analytic(band, d, eps)
    assert r.limit == pytest.approx(5.39e-3, abs=5e-6)  # the number the issue quoted
    assert "not every device" in r.limit_kind
    assert r.limit_hard_stroke == harvesting_limit(M, C_M, band, d)  # any device inside walls
    assert r.causal_limit == r.limit and "Paley-Wiener" in r.causal_limit_kind

    bp = rv.BandPass(1.0, 8.0, 0.1)
    r = band_pass
    sigma = gaussian_displacement_budget(0.003, eps)
    assert r.causal_limit == causal_harvesting_limit(M, C_M, bp, sigma) < r.limit
    # the optimum is a causal (passive, linear) device with E[z^2] = sigma^2 at most
    assert r.power_predicted <= r.causal_limit
    assert r.fraction_of_causal_limit == pytest.approx(r.power_predicted / r.causal_limit)

    r = _analytic(rv.White(1.0), d, eps, k=2000.0)
    assert r.limit is None and r.limit_hard_stroke is None  # non-causal: unbounded
    assert r.causal_limit == M / 4  # m S / 4
    data = r.to_dict()
    for key in ("limit_hard_stroke", "causal_limit", "causal_limit_kind",
                "fraction_of_causal_limit", "notes"):  # fmt: skip
        assert key in data
    json.dumps(data)
    text = str(r)
    assert "none (unbounded for white noise)" in text and "fraction_of_causal_limit" in text


@pytest.fixture(scope="module")
def confirmed():
    """A band-pass design with a few Monte Carlo paths, a wide stroke and a tight target."""
    fixed = rv.Harvester(m=M, c_m=C_M, c_e=0.1, k=57.4, stroke=0.02)
    settings = SweepSettings(dt=2e-4, window=1.0, burn_in=0.3, min_paths=32, max_paths=32,
                             target_rel_ci=1e-4, control_variates=False, seed=1)  # fmt: skip
    return rv.design(fixed, rv.BandPass(1.0, 8.0, 0.1), {"c_e": (0.01, 1.0)}, exceedance=0.01,
                     settings=settings, runners_up=1, refine=False, workers=1)  # fmt: skip


def test_notes_say_an_inactive_budget_and_a_missed_target(confirmed, band_pass):
    notes = confirmed.notes
    assert len(notes) == 2
    x = confirmed.stroke_exceedance_monte_carlo
    # 32 paths that saw nothing: the Wilson interval [0, 0.107] does not contradict the
    # prediction, which is what the note needs beside one
    assert confirmed.exceedance_predicted < 1e-3 and x.interval[0] < 1e-3
    assert "stroke budget is inactive" in notes[0]
    missed = confirmed.power_monte_carlo.ci95 / confirmed.power_monte_carlo.mean
    assert missed > 1e-4 and f"{missed:.2%}" in notes[1] and "0.01%" in notes[1]
    text = str(confirmed)
    assert "stroke budget is inactive" in text and "precision target was missed" in text
    for label in ("fraction_of_limit (non-causal)", "fraction_of_causal_limit",
                  "limit_hard_stroke (non-causal)"):  # fmt: skip
        assert label in text
    assert confirmed.to_dict()["notes"] == notes
    # a budget that binds says nothing
    assert band_pass.notes == []


def test_cli_shows_the_optimum_rounded_estimates_labelled_limits_and_notes(
    capsys, monkeypatch, confirmed
):
    import randvib.cli.design as cli_design

    monkeypatch.setattr(cli_design, "design", lambda *args, **kwargs: confirmed)
    code, out, _ = run(capsys, "design", "--m", M, "--c-m", C_M, "--excitation", "band-pass",
                       "--psd", 1, "--f0", 8, "--zeta", 0.1, "--k", 57.4, "--stroke", 0.02,
                       "--vary", "c_e=0.01:1", "--no-progress")  # fmt: skip
    assert code == 0
    header = out.splitlines()[0]
    assert header.startswith("device at the optimum:")
    c_e = confirmed.optimum["c_e"]
    assert f"c_e {c_e:.4g} Ns/m" in header and "c_e 0.505" not in header  # not the midpoint
    assert "varied: c_e 0.01 to 1 Ns/m" in out
    power = confirmed.power_monte_carlo
    shown = formatting.estimate(power.mean, power.ci95)
    assert re.search(rf"power_monte_carlo\s+{re.escape(shown)}\s+W", out)
    half_width = shown.split(" ± ")[1]
    assert len(re.sub(r"e.*|[.0]", "", half_width.lstrip("0."))) <= 2  # two significant digits
    assert "limit (non-causal)" in out and "causal_limit " in out
    assert "limit: stationary, non-causal" in out
    assert out.count("note: ") == 2
