"""The paper's two claims under narrow-band excitation: ``randvib study excitation``.

(or ``python studies/excitation.py OUT [--quick]``). The paper's analysis
assumes white noise, under which the spring cannot matter for a resistive
harvester (c E[v^2] + E[vF] = S m / 4 for any k3). Real base motion is often
narrow-band. The figure9 device (c_m = c_e = 0.1 Ns/m, k = 57.4 N/m, f_n =
8.02 Hz, m = 0.0226 kg assumed) is driven by band-pass noise
(:class:`randvib.BandPass`) centred at, below (f_n / 1.25) and above
(1.25 f_n) the linear resonance, with damping ratio zeta from 0.5 (broad)
down to 0.02 (a band 0.3 Hz wide, a fifth of the device's own bandwidth).
Each band's peak level gives the linear device (no friction, no spring) the
E[z'^2] of white noise S = 1 (m/s^2)^2/Hz, so the paper's Coulomb level
Fc = 5.8 mN is equally strong relative to the motion everywhere.

**(1) Equivalent linearisation against Monte Carlo.** Statistical
linearisation (c_eq from E[vF]/E[v^2], k_eq = k + 3 k3 E[z^2], variances from
the Lyapunov equation of device and filter) against Monte Carlo (Heun with
the filter's states), its relative error with a 95 % interval.

**(2) The Duffing-Coulomb interaction.** At Fc = 5.8 mN and k3 = 5e5 N/m^3
(the paper's Figure 9) up to 5e7 (100x), the contrast
[P(Fc, k3) - P(Fc, 0)] - [P(0, k3) - P(0, 0)] from the four devices run on
the same paths (one group per band), relative to P(Fc, 0), with Holm's
correction over the bands; linearisation's value of it (which, unlike
Eq. 32, depends on k3 under coloured input) beside it, and white noise
(S = 1) as the reference.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import special

import randvib as rv
from randvib.figure_style import num_tex
from randvib.formatting import plus_minus, significant
from randvib.statistics import holm_significant
from randvib.studies import figures, report, script_main
from randvib.studies.contrasts import paired_interactions
from randvib.studies.grids import fixed_paths, matched_band
from randvib.studies.methods import linearisation_against_monte_carlo
from randvib.studies.spectra_figure import spectra_against_linearisation
from randvib.studies.verdicts import contrast_range, holds_down_to

NAME = "excitation"
FC = 0.0058  #: N, the paper's Coulomb level (Table 2, training data 1)
K3_LABELS = {5e5: "Fig. 9", 5e6: "10x Fig. 9", 5e7: "100x Fig. 9"}
CENTRES = {"below": 1 / 1.25, "at": 1.0, "above": 1.25}  #: band centre / f_n
PRACTICAL = 0.01  #: a contrast below this fraction of P(Fc, 0) is practically absent
#: Monte Carlo per case: paths, window and burn-in (s), step (s).
QUICK_MC = {"n_paths": 128, "window": 10.0, "burn_in": 1.0, "dt": 2e-4}
FULL_MC = {"n_paths": 512, "window": 30.0, "burn_in": 1.0, "dt": 2e-4}

__all__ = ["grid", "run_study", "verdicts"]


def grid(quick: bool) -> dict:
    """The study's axes: band centres, zetas, k3 values and the Monte Carlo sizes."""
    if quick:
        return {"centres": tuple(CENTRES), "zetas": (0.5, 0.1, 0.02), "k3s": (0.0, 5e5, 5e7),
                "mc": QUICK_MC}  # fmt: skip
    return {"centres": tuple(CENTRES), "zetas": (0.5, 0.2, 0.1, 0.05, 0.02),
            "k3s": (0.0, 5e5, 5e6, 5e7), "mc": FULL_MC}  # fmt: skip


def compute(base, axes, settings, out, workers, scheduler, progress):
    """results.csv (every device and band) and contrasts.csv (every band and k3 > 0)."""
    bands = [(c, z, matched_band(base, CENTRES[c], z, 1.0)) for c in axes["centres"]
             for z in axes["zetas"]]  # fmt: skip
    cases = [rv.Case({"centre": c, "f0": getattr(x, "f0", np.nan), "zeta": z, "level": x.level,
                      "fc": fc, "k3": k3}, base.updated(fc=fc, k3=k3), x, group=(c, z))
             for c, z, x in [*bands, ("white", np.inf, rv.White(1.0))]
             for fc in (0.0, FC) for k3 in axes["k3s"]]  # fmt: skip
    run = rv.run_ensembles(cases, settings, out_dir=out / "ensembles", workers=workers,
                           scheduler=scheduler, progress=progress, name=NAME)  # fmt: skip
    table = run.table.rename(columns={"power_electrical": "power_mc",
                                      "power_electrical_ci95": "power_mc_ci95"})  # fmt: skip
    labels = ["centre", "f0", "zeta", "level", "fc", "k3", "power_mc", "power_mc_ci95", "n_paths"]
    results = pd.concat([table[labels], linearisation_against_monte_carlo(run)], axis=1)
    inter = paired_interactions(
        run, "fc", "k3", predicted={"linearisation": results.power_linearisation}
    )
    inter = inter.rename(columns={"k3_alone_relative": "spring_alone_relative"})
    banded = inter.centre != "white"  # Holm's family: the bands (white noise is the reference)
    inter["detectable"], inter["detectable_holm"] = inter.p_value < 0.05, False
    inter.loc[banded, "detectable_holm"] = holm_significant(inter.p_value[banded])
    practical = inter.relative_contrast.abs() >= PRACTICAL
    inter["breaks_no_interaction"] = inter.detectable_holm & practical
    return results, inter


# ----------------------------------------------------------------- verdicts
def where(centre: str) -> str:
    """'band above resonance (1.25 f_n)': a band's centre in words and as a multiple of f_n."""
    return f"band {centre} resonance ({CENTRES[centre]:g} f_n)"


def verdicts(results: pd.DataFrame, inter: pd.DataFrame) -> dict:
    """The numbers behind the report's verdicts, computed from the two tables."""
    lin = results[(results.fc > 0) & (results.centre != "white")]
    by_zeta = lin.groupby("zeta").linearisation_rel_error.agg(lambda e: float(e.abs().max()))
    worst = lin.loc[lin.linearisation_rel_error.abs().idxmax()]
    exact = results[(results.fc == 0) & (results.k3 == 0)]
    se = exact.power_mc_ci95 / special.stdtrit(exact.n_paths - 1, 0.975)
    z_exact = (exact.power_linearisation - exact.power_mc) / se
    band = inter[inter.centre != "white"]
    breaks = band[band.breaks_no_interaction]
    largest = band.loc[band.relative_contrast.abs().idxmax()]
    white = results[(results.centre == "white") & (results.fc > 0)]
    return {
        "linearisation": {
            "largest_abs_error_by_zeta": {f"{z:g}": v for z, v in by_zeta.items()},
            "largest_abs_error": float(abs(worst.linearisation_rel_error)),
            "where_largest": f"{where(worst.centre)}, zeta = {worst.zeta:g}, k3 = {significant(worst.k3, 3)}",
            "largest_ci95": float(worst.linearisation_rel_error_ci95),
            "white_noise_errors": [float(e) for e in white.linearisation_rel_error],
            "linear_device_exact_max_abs_score": float(np.abs(z_exact).max()),
        },
        "interaction": {
            "n_contrasts": int(len(band)),
            "n_detectable_holm": int(band.detectable_holm.sum()),
            "n_breaks": int(len(breaks)),
            "practical_threshold": PRACTICAL,
            "breaks": breaks[["centre", "zeta", "k3", "relative_contrast", "relative_ci95"]
                             ].to_dict("records"),
            "by_k3": {significant(k3, 3): contrast_range(sub, "band {centre} resonance, zeta = {zeta:g}")
                      for k3, sub in band.groupby("k3")},
            "largest_relative_contrast": float(largest.relative_contrast),
            "largest_relative_ci95": float(largest.relative_ci95),
            "where_largest": f"{where(largest.centre)}, zeta = {largest.zeta:g}, "
                             f"k3 = {significant(largest.k3, 3)}",
            "white_relative_contrasts": {
                significant(r.k3, 3): [float(r.relative_contrast), float(r.relative_ci95)]
                for r in inter[inter.centre == "white"].itertuples()},
            "no_interaction_holds_down_to_zeta": {
                f"{where(centre)}, k3 = {significant(k3, 3)}": holds_down_to(sub)
                for (centre, k3), sub in band.groupby(["centre", "k3"])},
        },
    }  # fmt: skip


# ----------------------------------------------------------------- report
def setup_section(axes, results, settings, quick, wall) -> str:
    levels = results.drop_duplicates(["centre", "zeta"])[["centre", "f0", "zeta", "level"]]
    mc = report.ensembles_text(settings, quick, wall, how=" with the filter's two states",
                               paired="one seed per band, shared by its eight devices")  # fmt: skip
    return (
        "Device: preset `figure9` (c_m = c_e = 0.1 Ns/m, k = 57.4 N/m, m = 0.0226 kg assumed; "
        f"linear resonance 8.02 Hz), Coulomb Fc = 0 and {1e3 * FC:g} mN, k3 = "
        + ", ".join(significant(k, 3) for k in axes["k3s"])
        + " N/m^3. Band-pass input (peak S at f0, half-power bandwidth 2 zeta f0), peak level "
        "matched so that the linear device's E[z'^2] equals that under white noise S = 1 "
        "(levels below). " + mc + "\n\n" + report.markdown_table(levels, floatfmt=".4g")
    )


def linearisation_section(results, v, figure) -> str:
    lin = v["linearisation"]
    shown = results[["centre", "zeta"]].assign(**{"Fc (mN)": 1e3 * results.fc, "k3": results.k3})
    shown["P_MC (mW)"] = plus_minus(results.power_mc, results.power_mc_ci95, 1e3, ".4f")
    shown["P_lin (mW)"] = [f"{1e3 * p:.4f}" for p in results.power_linearisation]
    shown["lin. error (%)"] = plus_minus(results.linearisation_rel_error,
                                         results.linearisation_rel_error_ci95)  # fmt: skip
    shown["k_eq / k"] = results.k_eq / 57.4
    by_zeta = ", ".join(f"{100 * e:.1f} % at zeta = {z}"
                        for z, e in lin["largest_abs_error_by_zeta"].items())  # fmt: skip
    white = ", ".join(f"{100 * e:+.2f} %" for e in lin["white_noise_errors"])
    return (
        f"![linearisation error]({figure.name})\n\n**Verdict.** With friction, statistical "
        f"linearisation's largest error against Monte Carlo is {100 * lin['largest_abs_error']:.1f}"
        f" % (± {100 * lin['largest_ci95']:.1f} %, {lin['where_largest']}); largest magnitude per "
        f"band: {by_zeta}. Under white noise (S = 1) the same devices give {white}. The linear "
        "device (no friction, no spring) is exact for both methods, a check of the Monte Carlo: "
        "the largest |difference| / standard error is "
        f"{lin['linear_device_exact_max_abs_score']:.2f}.\n\n"
        + report.markdown_table(shown, floatfmt=".3g")
    )


def interaction_section(inter, v, figure) -> str:
    it = v["interaction"]
    per_k3 = "; ".join(
        f"k3 = {k3}: {r['n_breaks']} of {r['n_points']}, contrast "
        f"{100 * r['min_relative_contrast']:+.1f} to {100 * r['max_relative_contrast']:+.1f} %, "
        f"smallest {100 * r['smallest_abs']:+.2f} ± {100 * r['smallest_abs_ci95']:.2f} % "
        f"({r['smallest_abs_where']})" for k3, r in it["by_k3"].items()
    )  # fmt: skip
    white = ", ".join(f"k3 = {k}: {100 * c:+.2f} ± {100 * h:.2f} %"
                      for k, (c, h) in it["white_relative_contrasts"].items())  # fmt: skip
    holds = "; ".join(f"{key}: {'none' if z is None else f'zeta >= {z:g}'}"
                      for key, z in it["no_interaction_holds_down_to_zeta"].items())  # fmt: skip
    shown = inter[["centre", "zeta", "k3"]].copy()
    shown["contrast / P(Fc,0) (%)"] = plus_minus(inter.relative_contrast,
                                                        inter.relative_ci95)  # fmt: skip
    shown["linearisation (%)"] = [f"{100 * x:+.2f}" for x in inter.linearisation_relative_contrast]
    shown["spring alone, Fc = 0 (%)"] = [f"{100 * x:+.2f}" for x in inter.spring_alone_relative]
    shown["p"], shown["Holm"] = inter.p_value, inter.detectable_holm
    return (
        f'![interaction]({figure.name})\n\n**Verdict.** "No interaction" fails at '
        f"{it['n_breaks']} of {it['n_contrasts']} band points (Holm-detectable and at least "
        f"{100 * PRACTICAL:g} % of P(Fc, 0); {it['n_detectable_holm']} Holm-detectable). By k3: "
        f"{per_k3}. The largest contrast is {100 * it['largest_relative_contrast']:+.1f} ± "
        f"{100 * it['largest_relative_ci95']:.1f} % of P(Fc, 0) ({it['where_largest']}). Under "
        f"white noise (S = 1): {white}. Bands down to which no interaction holds (broadest "
        f"first): {holds}.\n\nUnder a narrow band the spring moves the resonance (k_eq) against "
        "the band, so P(0, k3) - P(0, 0) is no longer zero (column 'spring alone'); the contrast "
        "asks whether friction changes that effect.\n\n"
        + report.markdown_table(shown, floatfmt=".3g")
    )


# ----------------------------------------------------------------- the study
def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True) -> Path:
    """Run the excitation study and write ``report.md``, CSVs, figures and ``verdicts.json``.

    ``quick``: three bands per centre and three springs, 128 paths (about a
    minute on one core). The cases run on ``workers`` local processes or the
    Dask cluster at ``scheduler``, and resume from ``OUT/ensembles``.
    """
    base, axes = rv.preset("figure9"), grid(quick)
    settings = fixed_paths(**axes["mc"], seed=seed)
    out = report.prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed, **axes})
    started = time.perf_counter()
    results, inter = compute(base, axes, settings, out, workers, scheduler, progress)
    report.write_table(out, "results.csv", results)
    report.write_table(out, "contrasts.csv", inter)
    v = verdicts(results, inter)
    fig_lin = figures.error_against_bandwidth(results, CENTRES, out / "linearisation_error.png")
    fig_inter = figures.contrast_against_bandwidth(inter, CENTRES, K3_LABELS,
                                                   out / "interaction.png")  # fmt: skip
    narrowest = matched_band(base, CENTRES["at"], min(axes["zetas"]), 1.0)
    spectra_against_linearisation(
        {f"k$_3$ = {num_tex(k3)} N/m$^3$": base.updated(fc=FC, k3=k3)
         for k3 in (0.0, max(axes["k3s"]))}, narrowest, settings, out / "spectra.png",
    )  # fmt: skip
    report.write_verdicts(out, v)
    wall = time.perf_counter() - started
    return report.write_report(
        out,
        f"Study {NAME}: the paper's claims under narrow-band excitation{' (quick)' * quick}",
        [
            ("Set-up", setup_section(axes, results, settings, quick, wall)),
            ("Equivalent linearisation against Monte Carlo",
             linearisation_section(results, v, fig_lin)),
            ("Duffing-Coulomb interaction", interaction_section(inter, v, fig_inter)),
            ("Where the power comes from",
             "![spectra](spectra.png)\n\nResponse spectra at the linear resonance, narrowest band, "
             f"Fc = {1e3 * FC:g} mN, without and with the stiffest spring: Monte Carlo (Welch on "
             "32 recorded paths, 95 % band) and statistical linearisation."),
        ],
    )  # fmt: skip


if __name__ == "__main__":
    sys.exit(script_main(run_study))
