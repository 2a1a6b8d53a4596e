"""Paper Figure 9 with error bars and verdicts: ``randvib study figure9 --out OUT [--quick]``.

(or ``python studies/figure9.py OUT [--quick]``). Paper Section 5:
c_m = c_e = 0.1 Ns/m, S = 1, 0.5, 0.1 (m/s^2)^2/Hz, k3 = 0 (panel a) and
5e5 N/m^3 (panel b), other parameters from Table 2 (Coulomb, training data 1;
m = 0.0226 kg assumed). Expected electrical power against Fc: Monte Carlo
points with 95 % intervals over the Eq. 32 curves.

Verdicts: equivalent linearisation vs Monte Carlo at every point, and the
Duffing-Coulomb interaction contrast
[P(Fc, k3) - P(Fc, 0)] - [P(0, k3) - P(0, 0)] from paired
common-random-number paths; plus a half-step re-run showing the time-step
bias is below the statistical error.
"""

from __future__ import annotations

import sys

import randvib as rv
from randvib.studies import figures, script_main
from randvib.studies.contrasts import interaction_contrasts, predicted_power_curves
from randvib.studies.grids import coulomb_grid, highest_friction_points
from randvib.studies.half_step import (
    check_step_bias,
    half_step_section,
    half_step_verdict,
    sweep_with_half_step,
)
from randvib.studies.report import (
    markdown_table,
    prepare_output_dir,
    readable_table,
    write_report,
    write_table,
    write_verdicts,
)
from randvib.studies.verdicts import interaction_verdict, linearisation_verdict

PSDS = (1.0, 0.5, 0.1)
K3S = (0.0, 5e5)


def study_points(n_fc: int) -> list[dict]:
    """Fc from 0 to twice Eq. 32's half-power level (well past half power) at each S."""
    return coulomb_grid(rv.preset("figure9"), PSDS, K3S, n_fc)


def settings_for(quick: bool, seed: int) -> rv.SweepSettings:
    # 128 paths at least, quick mode too: the paired interaction contrasts use
    # eight control variates and need ten paths per control (sweep.paired_contrast)
    return rv.SweepSettings(
        target_rel_ci=0.01 if quick else 0.005,
        window=1.0 if quick else 2.0,
        burn_in=0.5,
        seed=seed,
        min_paths=128,
        batch_paths=64,
    )


def linearisation_section(table, settings, lin_data, lin_sentence) -> str:
    err = table["linearisation_rel_error"]
    worst = table.loc[err.abs().idxmax()]
    columns = ["psd", "k3", "fc", "linearisation_power", "power_electrical"]
    columns += ["power_electrical_ci95", "linearisation_rel_error"]
    columns += ["linearisation_consistent", "n_paths"]
    return (
        f"{len(table)} points; the Monte Carlo 95 % half-width is at most "
        f"{100 * (table.power_electrical_ci95 / table.power_electrical).max():.2f} % of the power "
        f"(target {100 * settings.target_rel_ci:g} %; {int(table.n_paths.sum())} paths in all).\n\n"
        f"Equivalent linearisation (Eq. 32) lies inside the Monte Carlo 95 % interval at "
        f"{lin_data['n_points'] - lin_data['n_outside']} of {lin_data['n_points']} points. Its "
        f"largest error is "
        f"{100 * worst.linearisation_rel_error:+.2f} % ± {100 * worst.linearisation_rel_error_ci95:.2f} % "
        f"(S = {worst.psd:g}, k3 = {worst.k3:g}, Fc = {worst.fc:.4g} N). "
        f"Errors beyond 1 %: {int((err.abs() > 0.01).sum())} points; beyond 5 %: "
        f"{int((err.abs() > 0.05).sum())}.\n\n"
        f"Verdict on the paper's first claim: {lin_sentence}\n\n"
        + markdown_table(readable_table(table[columns]))
    )


def interaction_section(inter, inter_data, inter_sentence, figure) -> str:
    big = inter.loc[inter.relative_contrast.abs().idxmax()]
    return (
        f"![interaction]({figure.name})\n\n"
        f"Contrast [P(Fc,k3) - P(Fc,0)] - [P(0,k3) - P(0,0)] at k3 = 5e5 N/m^3 from paired paths "
        f"(same noise at every point). Detectable (|contrast| > 95 % half-width) at "
        f"{inter_data['n_detectable']} of {inter_data['n_contrasts']} (S, Fc) points; the largest "
        f"relative contrast is "
        f"{100 * big.relative_contrast:+.2f} % ± {100 * big.relative_ci95:.2f} % "
        f"(S = {big.psd:g}, Fc = {big.fc:.4g} N). The points share their paths (common random "
        f"numbers), so their verdicts are correlated; with Holm's correction for "
        f"{inter_data['n_contrasts']} tests at family level 5 %, {inter_data['n_holm']} remain.\n\n"
        f"Verdict on the paper's second claim at its own k3: {inter_sentence}\n\n"
        + markdown_table(readable_table(inter))
    )


def setup_section(settings, seed, quick, figure) -> str:
    return (
        f"Device: paper Section 5 (preset `figure9`: c_m = c_e = 0.1 Ns/m, k = 57.4 N/m, "
        f"k3 as given, m = 0.0226 kg assumed). S = {', '.join(map(str, PSDS))} (m/s^2)^2/Hz; "
        f"Fc from 0 to twice the level where Eq. 32 halves the power. Heun, dt = "
        f"{settings.dt:g} s, {settings.burn_in:g} s burn-in + {settings.window:g} s per path, "
        f"seed {seed}, control variates {'on' if settings.control_variates else 'off'}."
        f"{' Quick mode.' if quick else ''}\n\n![Figure 9]({figure.name})"
    )


def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True):
    """Run the Figure 9 study; write figures, CSVs and ``report.md`` into ``out_dir``."""
    base = rv.preset("figure9")
    points = study_points(7 if quick else 13)
    settings = settings_for(quick, seed)
    worst_bias = check_step_bias(base, points, settings)
    out = prepare_output_dir(out_dir, {"study": "figure9", "quick": quick, "seed": seed})

    # compute: the sweep, and a half-step re-run where the nonlinearity is largest
    result, check = sweep_with_half_step(
        base, points, settings, out, "figure9", highest_friction_points(points),
        workers=workers, scheduler=scheduler, progress=progress,
    )  # fmt: skip
    table = rv.linearisation_verdicts(result.table)
    inter = interaction_contrasts(result, base, "fc", "k3")
    fc_max = {psd: table[table.psd == psd].fc.max() for psd in PSDS}

    # tables and figures
    write_table(out, "results.csv", table)
    write_table(out, "interaction.csv", inter)
    write_table(out, "step_check.csv", check)
    write_table(out, "curves.csv", predicted_power_curves(base, PSDS, K3S, fc_max))
    fig_main = figures.power_against_friction(table, base, PSDS, K3S, out / "figure9.png")
    fig_inter = figures.contrast_against_friction(
        inter, "Duffing-Coulomb interaction at k$_3$ = 5 × 10$^5$ N/m$^3$", out / "interaction.png"
    )

    # verdicts and report
    lin_data, lin_sentence = linearisation_verdict(table)
    inter_data, inter_sentence = interaction_verdict(inter, K3S[1])
    write_verdicts(
        out,
        {"linearisation": lin_data, "interaction": inter_data, "step_check": half_step_verdict(check)},
        [lin_sentence, "Interaction at the paper's k3: " + inter_sentence],
    )  # fmt: skip
    top = ", ".join(f"{k3:.3g}" for k3 in K3S)
    return write_report(
        out,
        "Figure 9 study: equivalent linearisation and the Duffing-Coulomb interaction",
        [
            ("Set-up", setup_section(settings, seed, quick, fig_main)),
            ("Equivalent linearisation against Monte Carlo",
             linearisation_section(table, settings, lin_data, lin_sentence)),
            ("Duffing-Coulomb interaction",
             interaction_section(inter, inter_data, inter_sentence, fig_inter)),
            ("Time-step check", half_step_section(
                check, settings, f"the highest Fc at each S, with k3 = {top}", worst_bias)),
        ],
    )  # fmt: skip


if __name__ == "__main__":
    sys.exit(script_main(run_study))
