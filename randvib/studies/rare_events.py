"""The rare-event study's building blocks: strokes by probability, estimates beside the answers.

For each device and input of ``randvib study rare-events`` (studies/rare_events.py):

* :func:`strokes_at` - the strokes at which the first passage within T has
  given probabilities (1e-2 ... 1e-8), read off a pilot subset simulation's
  intermediate levels (P(peak > b_j) ~ 0.1^j);
* :func:`rows_at` - at each stroke the rare-event estimate
  (:func:`randvib.first_passage`, subset simulation) of the first-passage
  probability, the stationary exceedance and the crossing rate, beside the
  Gaussian answer the design search uses (statistical linearisation's
  sigma_z: erfc for the exceedance, Rice's rate, Poisson and Vanmarcke for
  the first passage; :mod:`randvib.analytic.crossings`) and, where one
  exists, the exact anchor (Gibbs: friction-free devices under white noise);
* :func:`unsafe_strokes` - per device and input, the stroke from which the
  Gaussian answer is unsafe by a factor of 2 or more (the estimate's 95 %
  lower bound at least twice it), for the stationary exceedance (the design's
  budget) and for the first passage (its Vanmarcke constraint);
* :func:`probability_figure` - probability against stroke, one panel per device.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd

from randvib.analytic.crossings import CROSSING_METHODS
from randvib.figure_style import colour, new_figure, save_figure
from randvib.montecarlo.path_simulator import HarvesterPaths
from randvib.montecarlo.reliability import first_passage
from randvib.montecarlo.step_check import LinearTestSystem
from randvib.montecarlo.subset_simulation import subset_simulation

__all__ = ["probability_figure", "rows_at", "strokes_at", "unsafe_strokes"]

#: The Gaussian answer is unsafe where the estimate is at least this many times it.
UNSAFE_FACTOR = 2.0


def strokes_at(device, excitation, probabilities, *, duration, dt, seed, samples) -> list:
    """Strokes (m) at which P(first passage within ``duration``) is about each of ``probabilities``.

    A pilot subset simulation towards a stroke far beyond reach (20 linearised
    standard deviations), stopped after as many levels as the smallest
    probability needs: its level b_j has P(peak > b_j) ~ 0.1^j, and the stroke
    for 10^-j is b_j (to the pilot's precision: the estimates at these
    strokes are what the study reports).
    """
    far = 20.0 * math.sqrt(_gaussian_variance(device, excitation))
    sim = HarvesterPaths(device, excitation, stroke=far, duration=duration, dt=dt)
    depth = max(int(round(-math.log10(p))) for p in probabilities)
    run = subset_simulation(sim, samples, np.random.default_rng(seed), max_levels=depth + 1)
    thresholds = [level.threshold * far for level in run.levels[:-1]]
    out = []
    for p in probabilities:
        j = int(round(-math.log10(p)))
        out.append(thresholds[j - 1] if j <= len(thresholds) else math.nan)
    return out


def _gaussian_variance(device, excitation) -> float:
    """E[z^2] of the linear test system of the step check (the Gibbs spread of a double
    well): the scale of the pilot's far stroke."""
    return LinearTestSystem.of(device, excitation).spread[0] ** 2


def rows_at(name, device, excitation, strokes, *, duration, dt, seed, target_cov, samples):
    """One row per stroke: the rare-event estimates, the Gaussian answer and the exact anchor."""
    rows = []
    for stroke in strokes:
        if not math.isfinite(stroke):
            continue
        r = first_passage(device, excitation, duration=duration, stroke=stroke, dt=dt,
                          target_cov=target_cov, seed=seed, samples_per_level=samples,
                          progress=False)  # fmt: skip
        row = {"device": name, "stroke": stroke}
        for key in ("probability_first_passage", "stationary_exceedance", "upcrossing_rate"):
            stat = getattr(r, key)
            row[key], row[f"{key}_ci95"], row[f"{key}_se"] = stat.mean, stat.ci95, stat.std_error
        row["path_steps"], row["crude_path_steps"] = r.path_steps, r.crude_path_steps
        row.update(_answers(device, excitation, stroke, duration))
        rows.append(row)
    return rows


def _answers(device, excitation, stroke, duration) -> dict:
    """The Gaussian answer (NaN where linearisation refuses) and the exact anchor's values."""
    out = {}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the tail warning is what the study measures
            g = CROSSING_METHODS["gaussian"].solve(device, excitation, stroke, duration)
        out.update(gaussian_exceedance=g.stationary_exceedance, gaussian_rate=g.upcrossing_rate,
                   gaussian_poisson=g.first_passage_poisson,
                   gaussian_vanmarcke=math.nan if g.first_passage_vanmarcke is None
                   else g.first_passage_vanmarcke)  # fmt: skip
    except (ValueError, ArithmeticError):
        out.update(gaussian_exceedance=math.nan, gaussian_rate=math.nan,
                   gaussian_poisson=math.nan, gaussian_vanmarcke=math.nan)  # fmt: skip
    gibbs = CROSSING_METHODS["gibbs"]
    if gibbs.accepts(device, excitation):
        e = gibbs.solve(device, excitation, stroke, duration)
        out.update(exact_exceedance=e.stationary_exceedance, exact_rate=e.upcrossing_rate,
                   exact_poisson=e.first_passage_poisson)  # fmt: skip
    else:
        out.update(exact_exceedance=math.nan, exact_rate=math.nan, exact_poisson=math.nan)
    return out


def unsafe_strokes(results: pd.DataFrame) -> dict:
    """Per device: the smallest stroke at which the Gaussian answer is unsafe by >= 2.

    For the stationary exceedance (against erfc of the linearised sigma_z) and the
    first passage (against Vanmarcke's, Poisson's where Vanmarcke is not given):
    the first stroke whose estimate's 95 % lower bound is at least
    :data:`UNSAFE_FACTOR` times the Gaussian answer, and every stroke beyond it
    unsafe too; None where no stroke of the grid is (the Gaussian answer is
    safe there, or not given). With the ratio estimate / Gaussian at each stroke.
    """
    out = {}
    for device, sub in results.sort_values("stroke").groupby("device", sort=False):
        entry = {}
        fp_gauss = sub.gaussian_vanmarcke.fillna(sub.gaussian_poisson)
        for what, est, ci, gauss in (
            ("exceedance", sub.stationary_exceedance, sub.stationary_exceedance_ci95,
             sub.gaussian_exceedance),
            ("first_passage", sub.probability_first_passage,
             sub.probability_first_passage_ci95, fp_gauss),
        ):  # fmt: skip
            unsafe = ((est - ci) >= UNSAFE_FACTOR * gauss).to_numpy()
            from_here = [i for i in range(len(unsafe)) if unsafe[i:].all()]
            ratios = (est / gauss).to_numpy()
            entry[what] = {
                "unsafe_from_stroke": float(sub.stroke.iloc[from_here[0]]) if from_here else None,
                "ratio_by_stroke": {
                    f"{s:.4g}": _finite(r) for s, r in zip(sub.stroke, ratios, strict=True)
                },
            }
        out[device] = entry
    return out


def _finite(x) -> float | None:
    return float(x) if np.isfinite(x) else None


def probability_figure(results: pd.DataFrame, path):
    """P(first passage within T) and P(|z| > D) against D, one panel per device family."""
    families = sorted({d.split(",")[0] for d in results.device})
    fig, axes = new_figure(1, len(families), figsize=(4.2 * len(families), 3.8), squeeze=False)
    for ax, family in zip(axes[0], families, strict=True):
        members = [d for d in dict.fromkeys(results.device) if d.split(",")[0] == family]
        for i, device in enumerate(members):
            sub = results[results.device == device].sort_values("stroke")
            mm = 1e3 * sub.stroke
            ax.errorbar(mm, sub.probability_first_passage, sub.probability_first_passage_ci95,
                        marker="o", color=colour(i), label=f"{device}: subset simulation")  # fmt: skip
            gauss = sub.gaussian_vanmarcke.fillna(sub.gaussian_poisson)
            if gauss.notna().any():
                ax.plot(mm, gauss, "--", color=colour(i), label=f"{device}: Gaussian (Vanmarcke)")
            if sub.exact_poisson.notna().any():
                ax.plot(mm, sub.exact_poisson, ":", color=colour(i),
                        label=f"{device}: exact rate, Poisson")  # fmt: skip
        ax.set(yscale="log", xlabel="stroke D (mm)", ylabel="P(|z| reaches D within T)",
               title=family)  # fmt: skip
        ax.legend(fontsize=6)
    return save_figure(fig, path)
