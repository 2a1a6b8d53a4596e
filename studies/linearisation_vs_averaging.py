"""Analytic power predictions against Monte Carlo: ``randvib study linearisation-vs-averaging``.

(or ``python studies/linearisation_vs_averaging.py OUT [--quick]``). Grid: the
figure9 device (c_m = c_e = 0.1 Ns/m, k = 57.4 N/m, m = 0.0226 kg assumed),
S in {1, 0.5, 0.1} (m/s^2)^2/Hz, k3 in {0, 7.07e4 (paper), 5e5, 7e6 (~100x)}
N/m^3 and Coulomb levels set by the dimensionless friction level

    kappa = 4 Fc^2 / (pi S m c)

(the group of paper Eq. 30: Eq. 32 predicts P(kappa)/P(0) = 1/(1 + kappa +
sqrt(kappa (2 + kappa))), half power at kappa = 1/4), from 0 to 2 (about a
fifth of the friction-free power).

At every point: E[P_e] from equivalent linearisation (Eq. 32), stochastic
averaging, the fast corrected FPK grids (``method="fpk-fast"``), the FPK
reference grid solution and Monte Carlo (:func:`randvib.run_ensembles`,
stochastic Heun, with the energy-identity and friction-free-companion control
variates). Relative errors are taken against Monte Carlo. The two fast
candidates (averaging and fpk-fast) are judged against the accuracy criteria
for a fast method (:mod:`randvib.studies.methods`): speed (one point under
10 ms, a 100-point sweep under 1 s, timed in the run), at most a third of
linearisation's error where that exceeds 3 %, at most 5 % everywhere, and the
k3 interaction's sign and size inside the Monte Carlo interval.

The k3 interaction, P(Fc, k3) / P(Fc, 0) - 1, is estimated from paired runs:
all k3 values at one (S, kappa) are one group of the ensembles (the same
Brownian paths), and the per-path differences, with both runs' control
variates (:meth:`randvib.EnsembleResult.paired`), give its mean and 95 %
interval.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

import randvib as rv
from randvib.studies import figures, script_main
from randvib.studies.grids import fixed_paths
from randvib.studies.methods import (
    ANALYTIC,
    CANDIDATES,
    criteria_table,
    k3_change_interval,
    kappa_cases,
    paired_k3_table,
    reading,
    time_methods,
)
from randvib.studies.methods import fast_method_verdicts as verdicts
from randvib.studies.report import (
    markdown_table,
    prepare_output_dir,
    write_report,
    write_table,
    write_verdicts,
)

NAME = "linearisation-vs-averaging"
PSDS = (1.0, 0.5, 0.1)
K3S = (0.0, 7.07e4, 5e5, 7e6)
KAPPAS = (0.0, 0.1, 0.25, 0.5, 1.0, 2.0)
#: Monte Carlo per case: paths, window and burn-in (s), step (s).
FULL_MC = {"n_paths": 256, "window": 80.0, "burn_in": 2.0, "dt": 2.5e-4}
QUICK_MC = {"n_paths": 64, "window": 40.0, "burn_in": 2.0, "dt": 5e-4}

__all__ = ["grid", "reading", "run_study", "verdicts"]


def grid(quick: bool) -> dict:
    """The study's axes: S values, friction levels kappa, k3 values and the Monte Carlo sizes."""
    if quick:
        return {"psds": (1.0, 0.1), "kappas": (0.0, 0.5, 2.0), "k3s": (0.0, 7e6), "mc": QUICK_MC}
    return {"psds": PSDS, "kappas": KAPPAS, "k3s": K3S, "mc": FULL_MC}


# ----------------------------------------------------------------- report sections
def errors_shown(df: pd.DataFrame) -> pd.DataFrame:
    """The errors of every method, for the report: units in the headers, errors in %."""

    def pct(x):
        return f"{100 * x:+.2f}"

    return pd.DataFrame(
        {
            "S ((m/s²)²/Hz)": df["psd"].map("{:g}".format),
            "κ": df["kappa"].map("{:g}".format),
            "Fc (mN)": (1e3 * df["fc"]).map("{:.3g}".format),
            "k3 (N/m³)": df["k3"].map("{:g}".format),
            "P Monte Carlo (mW)": (1e3 * df["power_mc"]).map("{:.4g}".format),
            "MC 95 % half-width (%)": (100 * df["mc_rel_ci95"]).map("{:.2f}".format),
            "linearisation error (%)": df["err_linearisation"].map(pct),
            "averaging error (%)": df["err_averaging"].map(pct),
            "fast FPK error (%)": df["err_fpk_fast"].map(pct),
            "FPK error (%)": df["err_fpk"].map(pct),
            "friction damping ratio ζ_f": df["zeta_friction"].map("{:.3f}".format),
        }
    )


def k3_changes_shown(df: pd.DataFrame) -> pd.DataFrame:
    """The k3 changes: MC ± the widened interval; '(out)' marks a prediction outside it."""
    rows, width = k3_change_interval(df)

    def mark(name):
        inside = (rows[f"dk3_{name}"] - rows["dk3_mc"]).abs() <= width
        return (100 * rows[f"dk3_{name}"]).map("{:+.3f}".format) + np.where(inside, "", " (out)")

    return pd.DataFrame(
        {
            "S ((m/s²)²/Hz)": rows["psd"].map("{:g}".format),
            "κ": rows["kappa"].map("{:g}".format),
            "k3 (N/m³)": rows["k3"].map("{:g}".format),
            "Monte Carlo (%)": (100 * rows["dk3_mc"]).map("{:+.3f}".format)
            + " ± "
            + (100 * width).map("{:.3f}".format),
            "averaging (%)": mark("averaging"),
            "fast FPK (%)": mark("fpk_fast"),
            "FPK (%)": mark("fpk"),
        }
    )


def setup_text(df, mc, wall) -> str:
    n_paths, t_sim, dt = mc["n_paths"], mc["window"], mc["dt"]
    return (
        "Figure9 device (c_m = c_e = 0.1 Ns/m, k = 57.4 N/m, m = 0.0226 kg assumed), "
        "Coulomb friction at levels kappa = 4 Fc^2/(pi S m c) (Eq. 30's group; half power "
        "by Eq. 32 at kappa = 0.25). Errors of E[P_e] relative to Monte Carlo "
        f"({n_paths} paths x {t_sim:g} s, dt = {dt:g} s, stochastic Heun, control variates; "
        f"largest time-step bias bound {100 * df['step_bias'].max():.3f} %). "
        f"Monte Carlo time {df['mc_seconds'].sum():.0f} s; this report {wall:.0f} s."
    )


def verdicts_section(df, v, timings) -> str:
    criteria = ("fast_enough", "third_where_lin_over_3pct", "within_5pct", "interaction_met")
    met = [ANALYTIC[n][1] for n in CANDIDATES if all(v.get(f"{n}_{c}", True) for c in criteria)]
    summary = (
        f"All criteria met by: {', '.join(met)}." if met else "No candidate meets every criterion."
    )
    return (
        "The accuracy criteria for a fast method, per candidate (times measured in this run; "
        "the interaction interval is the paired MC 95 % interval widened by the two runs' "
        f"time-step bias bounds):\n\n{criteria_table(v, timings)}\n\n{summary}\n\n"
        f"- Largest |error| vs MC: linearisation {100 * v['max_err_linearisation']:.2f} %, "
        f"averaging {100 * v['max_err_averaging']:.2f} %, fast FPK "
        f"{100 * v['max_err_fpk_fast']:.2f} %, FPK reference {100 * v['max_err_fpk']:.2f} % "
        f"(largest MC 95 % half-width {100 * v['max_mc_rel_ci95']:.2f} %).\n"
        f"- k3 interaction, P(Fc, k3)/P(Fc, k3 = {df['k3'].min():g}) - 1 at "
        f"{v['interaction_points']} points ({v['interaction_significant']} significantly "
        "non-zero in MC): inside the interval for averaging "
        f"{v['interaction_averaging_inside']}, fast FPK {v['interaction_fpk_fast_inside']}, "
        f"FPK reference {v['interaction_fpk_inside']}, linearisation "
        f"{v['interaction_linearisation_inside']} (it predicts no change at all).\n\n"
        f"Reading: {reading(df, timings)}\n\n"
        "![errors](error_vs_friction.png)\n\n![interaction](interaction.png)"
    )


def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True) -> Path:
    """Run the study and write ``report.md``, ``results.csv`` and two PNG figures.

    ``quick``: smaller grid and Monte Carlo (about half a minute). The k3
    values of each (S, kappa) run on shared paths (one group of
    :func:`randvib.run_ensembles`) on ``workers`` local processes or the Dask
    cluster at ``scheduler``, and resume from ``OUT/ensembles``.
    """
    axes = grid(quick)
    settings = fixed_paths(**axes["mc"], seed=seed, control_variates=True)
    out = prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed, **axes})
    started = time.perf_counter()

    # compute (or resume), then time the fast candidates
    cases = kappa_cases(rv.preset("figure9"), axes["psds"], axes["kappas"], axes["k3s"])
    run = rv.run_ensembles(cases, settings, out_dir=out / "ensembles", workers=workers,
                           scheduler=scheduler, progress=progress, name=NAME)  # fmt: skip
    df = paired_k3_table(run)
    write_table(out, "results.csv", df)
    timings = time_methods(K3S)
    v = verdicts(df, timings)

    # figures, verdicts and report
    labels = {name: label for name, (_, label) in ANALYTIC.items()}
    figures.method_errors_against_kappa(df, labels, out / "error_vs_friction.png")
    figures.k3_change_against_kappa(df, labels, out / "interaction.png")
    write_verdicts(out, {**v, "reading": "Reading: " + reading(df, timings)})
    return write_report(
        out,
        f"Study {NAME}{' (quick)' if quick else ''}",
        [
            ("Verdicts", verdicts_section(df, v, timings)),
            (
                "Errors of E[P_e] against Monte Carlo",
                markdown_table(errors_shown(df), numparse=False),
            ),
            (
                "Change of power with k3 at fixed Fc (paired Monte Carlo)",
                "MC: mean ± the widened interval used by the verdict; '(out)' marks a prediction "
                "outside it.\n\n"
                + markdown_table(k3_changes_shown(df), floatfmt="g", numparse=False)
                + "\n\nFiles: `results.csv` (every column), the two PNG figures, `metadata.json`.",
            ),
        ],
        intro=setup_text(df, axes["mc"], time.perf_counter() - started),
    )


if __name__ == "__main__":
    sys.exit(script_main(run_study))
