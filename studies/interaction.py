"""Does the Duffing spring change the effect of Coulomb friction? ``randvib study interaction``.

(or ``python studies/interaction.py OUT [--quick]``). Paper Section 5
concludes from Figure 9 (k3 = 0 and 5e5 N/m^3) that the cubic stiffness
hardly matters for the expected power of the friction-affected device;
equivalent linearisation (Eq. 30-32) cannot say otherwise, because c_eq has
no k3 in it. This study takes k3 several decades beyond the paper,

    k3 = 0, 7.07e4 (Table 2), 5e5 (Figure 9), 5e6, 5e7 N/m^3 (100x Figure 9),

on the Figure 9 device (preset ``figure9``: c_m = c_e = 0.1 Ns/m,
k = 57.4 N/m, m = 0.0226 kg assumed), with S = 1, 0.5, 0.1 (m/s^2)^2/Hz and
Coulomb levels Fc from 0 to twice the level where Eq. 32 halves the power
(phi = Fc / (c sigma_v0) from 0 to sqrt(pi) = 1.77 at every S).

At every (S, Fc > 0, k3 > 0) it estimates the interaction contrast

    [P(Fc, k3) - P(Fc, 0)] - [P(0, k3) - P(0, 0)]

from common-random-number paths (:func:`randvib.studies.contrasts.interaction_contrasts`),
relative to P(Fc, 0), with a 95 % interval, a per-point verdict and Holm's
correction over the family. Beside it: the contrast predicted by stochastic
averaging, which, unlike Eq. 32, does depend on k3, and the linearisation
error at every point. A half-step re-run of the hardest points shows the
time-step bias is below the statistical error.
"""

from __future__ import annotations

import sys

import numpy as np

import randvib as rv
from randvib.formatting import plus_minus
from randvib.studies import figures, script_main
from randvib.studies.contrasts import (
    interaction_contrasts,
    predicted_contrast_curves,
    predicted_contrasts,
)
from randvib.studies.grids import (
    burn_in_for,
    coulomb_grid,
    duffing_strength,
    friction_level,
    highest_friction_points,
)
from randvib.studies.half_step import (
    check_step_bias,
    half_step_section,
    half_step_verdict,
    sweep_text,
    sweep_with_half_step,
)
from randvib.studies.methods import method_errors
from randvib.studies.report import (
    markdown_table,
    prepare_output_dir,
    write_report,
    write_table,
    write_verdicts,
)
from randvib.studies.verdicts import (
    interaction_counts,
    interaction_summary,
    linearisation_by_spring,
    scaling_sentence,
)

NAME = "interaction"
PSDS = (1.0, 0.5, 0.1)
#: 0, Table 2 (Coulomb, training data 1), Figure 9, 10x and 100x Figure 9 (N/m^3).
K3S = (0.0, 7.07e4, 5e5, 5e6, 5e7)
K3_LABELS = {7.07e4: "Table 2", 5e5: "Fig. 9", 5e6: "10x Fig. 9", 5e7: "100x Fig. 9"}
QUICK_K3S = (0.0, 5e5, 5e7)
N_FC, QUICK_N_FC = 7, 4
#: Heun step (s): bias on the linearised device below 1e-4 even at k3 = 5e7, S = 1.
DT = 1e-4

__all__ = ["grid", "run_study", "settings_for", "study_points"]


def grid(quick: bool) -> dict:
    """The study's axes: S values, k3 values and the number of Fc levels per S."""
    if quick:
        return {"psds": PSDS, "k3s": QUICK_K3S, "n_fc": QUICK_N_FC}
    return {"psds": PSDS, "k3s": K3S, "n_fc": N_FC}


def study_points(base, psds, k3s, n_fc) -> list[dict]:
    """(psd, k3, fc) points: Fc from 0 to twice Eq. 32's half-power level at each S."""
    if 0.0 not in k3s:
        raise ValueError(f"`k3s` must include 0 (the contrast's reference), got {k3s}")
    return coulomb_grid(base, psds, k3s, n_fc)


def settings_for(quick: bool, seed: int) -> rv.SweepSettings:
    # 128 paths at least in both modes: a paired contrast regresses on the energy-balance
    # controls of its points, which paired_contrast only uses with ten paths per control
    return rv.SweepSettings(
        dt=DT,
        target_rel_ci=0.01 if quick else 0.0015,
        window=1.0 if quick else 2.0,
        burn_in=burn_in_for([rv.preset("figure9")]),
        seed=seed,
        min_paths=128,
        batch_paths=64,
    )


def contrast_table(result, base):
    """The paired contrasts with phi, mu and averaging's prediction of them."""
    # k3's effect without friction is zero by theory (exact stationary density)
    inter = interaction_contrasts(result, base, "fc", "k3", zero_baseline=True)
    inter.insert(3, "phi", friction_level(base, inter.psd, inter.fc))
    inter.insert(4, "mu", duffing_strength(base, inter.psd, inter.k3))
    inter["averaging_relative_contrast"] = predicted_contrasts(base, inter, "averaging")
    return inter


# ----------------------------------------------------------------- report sections
def setup_section(settings, axes, table, quick) -> str:
    return (
        "Device: preset `figure9` (paper Section 5: Coulomb, training data 1, "
        "c_m = c_e = 0.1 Ns/m, k = 57.4 N/m; m = 0.0226 kg assumed). "
        f"S = {', '.join(f'{s:g}' for s in axes['psds'])} (m/s^2)^2/Hz; "
        f"k3 = {', '.join(f'{k:.3g}' for k in axes['k3s'])} N/m^3; "
        f"{axes['n_fc']} Fc levels per S from 0 to twice the level where Eq. 32 halves the "
        f"power (phi = Fc / (c sigma_v0) from 0 to {2 * np.sqrt(np.pi) / 2:.2f}, sigma_v0^2 = "
        f"S m / (4c)). " + sweep_text(settings, int(table.n_paths.sum()), quick)
    )


def contrasts_shown(inter):
    shown = inter[["psd", "k3"]].assign(**{"Fc (mN)": 1e3 * inter.fc, "phi": inter.phi})
    shown["contrast / P(Fc,0) (%)"] = plus_minus(inter.relative_contrast, inter.relative_ci95)
    shown["averaging (%)"] = [f"{100 * x:+.2f}" for x in inter.averaging_relative_contrast]
    shown["p"], shown["n_paths"] = inter.p_value, inter.n_paths
    shown["detectable"], shown["Holm"] = inter.detectable, inter.detectable_holm
    return shown


def interaction_section(inter, k3s, figure) -> str:
    verdict, summary = interaction_summary(inter, k3s, K3_LABELS)
    mu_fig9 = float(duffing_strength(rv.preset("figure9"), 1.0, 5e5))
    baseline = float(((inter.baseline.abs() + inter.baseline_ci95) / inter.reference).max())
    return (
        f"![interaction]({figure.name})\n\n**Verdict.** {verdict}\n\n"
        "Equivalent linearisation predicts no interaction at all: Eq. 30 for c_eq contains no "
        "k3, so Eq. 32 gives the same power for every spring. Stochastic averaging (dashed in "
        "the figure, `averaging` column) does depend on k3: the spring changes the orbit shapes "
        "over which the friction work is averaged. \n\nHow it is estimated: without friction "
        "E[z'^2] = S m / (4c) for every k3 (exact stationary density), so the second bracket "
        "P(0, k3) - P(0, 0) is zero by theory; the sweep's estimates of it, exact through the "
        f"friction-free companion control, are at most {100 * baseline:.1e} % of P(Fc, 0). The "
        "contrast is therefore the paired difference P(Fc, k3) - P(Fc, 0) over the paths the "
        "two points share (same Brownian increments; Ito-integral and energy-change controls "
        "of both), `n_paths` below. The contrasts share their paths (common random numbers), "
        "so neighbouring verdicts are correlated; Holm's step-down keeps the family-wise error "
        "at 5 %.\n\nScaling: the friction level phi and the Duffing strength mu = k3 "
        f"sigma_z0^2 / k (here {inter.mu.min():.2g} to {inter.mu.max():.2g}; {mu_fig9:.2g} in "
        "the paper's Figure 9 at S = 1) are the only parameters that S and k3 enter through "
        "(z scales with sqrt(S)), so rows with equal k3 S repeat one problem on the same paths"
        + scaling_sentence(inter) + "\n\n" + markdown_table(summary)
        + "\n\nEvery contrast (relative to the Monte Carlo P(Fc, k3 = 0); phi = Fc / (c "
        "sigma_v0)):\n\n" + markdown_table(contrasts_shown(inter), floatfmt=".3g")
    )  # fmt: skip


def linearisation_section(lin, lin_data, figure) -> str:
    by_k3 = lin.groupby("k3").linearisation_rel_error.agg(lambda e: e.abs().max())
    shown = lin[["psd", "k3"]].assign(**{"Fc (mN)": 1e3 * lin.fc, "phi": lin.phi})
    shown["P_MC (mW)"] = plus_minus(lin.power_electrical, lin.power_electrical_ci95, 1e3, ".4f")
    shown["Eq. 32 error (%)"] = plus_minus(lin.linearisation_rel_error,
                                           lin.linearisation_rel_error_ci95)  # fmt: skip
    shown["averaging error (%)"] = plus_minus(lin.averaging_rel_error, lin.averaging_rel_error_ci95)
    shown["zeta_f"], shown["n_paths"] = lin.averaging_zeta_friction, lin.n_paths
    invalid = (lin.averaging_zeta_friction > 0.5).any()
    return (
        f"![linearisation error]({figure.name})\n\nEq. 32 against Monte Carlo at the "
        f"{len(lin)} points with friction: the error reaches "
        f"{100 * lin.linearisation_rel_error.abs().max():.2f} % ({lin_data['where_largest']}); "
        "its largest magnitude per k3: "
        + ", ".join(f"{100 * v:.2f} % at k3 = {k:.3g}" for k, v in by_k3.items())
        + f". {lin_data['sentence']}"
        + (" The averaging predictions at points with zeta_f > 0.5 are outside that method's "
           "stated validity (it warns there)." if invalid else "")
        + "\n\n" + markdown_table(shown, floatfmt=".3g")
    )  # fmt: skip


# ----------------------------------------------------------------- the study
def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True):
    """Run the interaction study; write figures, CSVs and ``report.md`` into ``out_dir``."""
    base, axes = rv.preset("figure9"), grid(quick)
    settings = settings_for(quick, seed)
    points = study_points(base, axes["psds"], axes["k3s"], axes["n_fc"])
    worst_bias = check_step_bias(base, points, settings)
    identity = {"study": NAME, "quick": quick, "seed": seed, "grid": axes}
    out = prepare_output_dir(out_dir, {**identity, "settings": settings.to_dict()})

    # compute: half-step check where the dynamics is hardest (most friction,
    # with and without the stiffest spring)
    result, check = sweep_with_half_step(
        base, points, settings, out, NAME, highest_friction_points(points),
        workers=workers, scheduler=scheduler, progress=progress,
    )  # fmt: skip
    table = method_errors(result, base)
    table["phi"] = friction_level(base, table.psd, table.fc)
    inter = contrast_table(result, base)
    fc_max = {psd: inter[inter.psd == psd].fc.max() for psd in axes["psds"]}
    curves = predicted_contrast_curves(base, axes["psds"], axes["k3s"], fc_max, "averaging")

    # tables and figures
    write_table(out, "averaging_curves.csv", curves)
    write_table(out, "results.csv", table)
    write_table(out, "interaction.csv", inter)
    write_table(out, "step_check.csv", check)
    fig_inter = figures.contrast_bands(inter, curves, out / "interaction.png", K3_LABELS)
    fig_lin = figures.linearisation_error_bands(table, out / "linearisation_error.png", K3_LABELS)

    # verdicts and report
    lin = table[table.fc > 0]
    lin_data, k3s = linearisation_by_spring(lin), axes["k3s"]
    write_verdicts(
        out,
        {"interaction": interaction_counts(inter, k3s), "linearisation": lin_data,
         "step_check": half_step_verdict(check)},
        [interaction_summary(inter, k3s, K3_LABELS)[0]],
    )  # fmt: skip
    top = ", ".join(f"{k:.3g}" for k in sorted(check.k3.unique()))
    return write_report(
        out,
        "Duffing-Coulomb interaction beyond the paper's k3",
        [("Set-up", setup_section(settings, axes, table, quick)),
         ("Interaction contrast", interaction_section(inter, k3s, fig_inter)),
         ("Equivalent linearisation at every point", linearisation_section(lin, lin_data, fig_lin)),
         ("Time-step check", half_step_section(
             check, settings, f"the highest Fc at each S, with k3 = {top}", worst_bias))],
    )  # fmt: skip


if __name__ == "__main__":
    sys.exit(script_main(run_study))
