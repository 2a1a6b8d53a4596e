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
reference grid solution and Monte Carlo (:func:`randvib.simulate`, stochastic
Heun, with the energy-identity and friction-free-companion control
variates). Relative errors are taken against Monte Carlo. The two fast
candidates (averaging and fpk-fast) are judged against the accuracy criteria
for a fast method (:mod:`randvib.studies.methods`): speed (one point under
10 ms, a 100-point sweep under 1 s, timed in the run), at most a third of
linearisation's error where that exceeds 3 %, at most 5 % everywhere, and the
k3 interaction's sign and size inside the Monte Carlo interval.

The k3 interaction, P(Fc, k3) / P(Fc, 0) - 1, is estimated from paired runs:
all k3 values at one (S, kappa) share their Brownian paths (same seed and
streams), and the per-path differences, with both runs' control variates,
give its mean and 95 % interval.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

import randvib as rv
from randvib._progress import progress_bar
from randvib.studies import figures, script_main
from randvib.studies.methods import (
    ANALYTIC,
    CANDIDATES,
    criteria_table,
    errors_against_mc,
    fill_missing_powers,
    k3_change_interval,
    paired_column,
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
#: Monte Carlo sizes: (paths, simulated time per path (s), dt (s), burn-in (s)).
FULL_MC = (256, 80.0, 2.5e-4, 2.0)
QUICK_MC = (64, 40.0, 5e-4, 2.0)

__all__ = ["grid", "reading", "run_study", "verdicts"]


def grid(quick: bool) -> tuple[tuple, tuple, tuple]:
    """(psds, kappas, k3s) of the study."""
    if quick:
        return (1.0, 0.1), (0.0, 0.5, 2.0), (0.0, 7e6)
    return PSDS, KAPPAS, K3S


# ----------------------------------------------------------------- compute
def compute_table(quick: bool, seed: int, threads, progress: bool) -> pd.DataFrame:
    """Every (S, kappa) column of the grid, its k3 values on shared paths, with the errors."""
    base = rv.preset("figure9")
    psds, kappas, k3s = grid(quick)
    mc = QUICK_MC if quick else FULL_MC
    columns = [(psd, kappa) for psd in psds for kappa in kappas]
    bar = None
    if progress:
        bar = progress_bar(len(columns), desc=NAME, unit="column")
    rows = []
    for i, (psd, kappa) in enumerate(columns):
        # A fresh seed per (S, kappa) column; shared within it (paired k3).
        rows += paired_column(psd, kappa, k3s, base, mc, seed * 1000 + i, threads)
        if bar is not None:
            bar.update()
    if bar is not None:
        bar.close()
    return errors_against_mc(pd.DataFrame(rows))


def table_of(out: Path, quick, seed, threads, progress) -> pd.DataFrame:
    """``results.csv``: computed, or resumed from a run of the same identity."""
    csv = out / "results.csv"
    if not csv.exists():
        df = compute_table(quick, seed, threads, progress)
        write_table(out, "results.csv", df)
        return df
    df = pd.read_csv(csv)
    filled = fill_missing_powers(df)
    if filled is not df:
        write_table(out, "results.csv", filled)
    return filled


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
    n_paths, t_sim, dt, _burn = mc
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


def run_study(
    out_dir,
    *,
    quick: bool = False,
    seed: int = 0,
    workers=None,
    threads=None,
    scheduler=None,
    progress=True,
) -> Path:
    """Run the study and write ``report.md``, ``results.csv`` and two PNG figures.

    ``quick``: smaller grid and Monte Carlo (about half a minute); ``seed``:
    base seed of the Monte Carlo streams; ``threads``: numba threads for the
    Monte Carlo kernel (default: all cores); ``workers`` (worker processes in
    the sweeping studies) is accepted and unused: this study simulates
    in-process; ``scheduler`` is not supported for the same reason;
    ``progress``: a bar over the (S, kappa) columns. Returns the Markdown report.
    """
    if scheduler is not None:
        raise ValueError(
            f"study {NAME!r} runs its Monte Carlo in-process on local threads; `scheduler` "
            f"is not supported (got {scheduler!r}); use `threads` instead"
        )
    psds, kappas, k3s = grid(quick)
    mc = QUICK_MC if quick else FULL_MC
    identity = {"study": NAME, "quick": quick, "seed": seed, "psds": psds, "kappas": kappas}
    out = prepare_output_dir(out_dir, identity | {"k3s": k3s, "monte_carlo": mc})
    started = time.perf_counter()

    # compute (or resume), then time the fast candidates
    df = table_of(out, quick, seed, threads, progress)
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
        intro=setup_text(df, mc, time.perf_counter() - started),
    )


if __name__ == "__main__":
    sys.exit(script_main(run_study))
