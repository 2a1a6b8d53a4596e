"""Study ``figure9``: the paper's Figure 9, with error bars and statistical verdicts.

Paper Section 5: c_m = c_e = 0.1 Ns/m, S = 1, 0.5, 0.1 (m/s^2)^2/Hz,
k3 = 0 (panel a) and 5e5 N/m^3 (panel b), other parameters from Table 2
(Coulomb, training data 1; m = 0.0226 kg assumed). Expected electrical power
against Fc: Monte Carlo points with 95 % intervals over the Eq. 32 curves.

Verdicts: equivalent linearisation vs Monte Carlo at every point, and the
Duffing-Coulomb interaction contrast
[P(Fc, k3) - P(Fc, 0)] - [P(0, k3) - P(0, 0)] from paired
common-random-number paths; plus a half-step re-run showing the time-step
bias is below the statistical error.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from randvib._io import atomic_write_text, prepare_output_dir
from randvib.analytic.prediction import METHODS, expected_power
from randvib.models.presets import preset
from randvib.montecarlo.sweep import (
    SweepSettings,
    cartesian,
    linearisation_verdicts,
)
from randvib.studies._common import (
    fc_where_power_halves,
    highest_friction_points,
    interaction_contrasts,
    markdown_table,
    save_figure,
    step_check_verdict,
    sweep_with_step_check,
    write_report,
)

PSDS = (1.0, 0.5, 0.1)
K3S = (0.0, 5e5)


def study_points(n_fc: int) -> list[dict]:
    base = preset("figure9")
    points = []
    for psd in PSDS:
        fc_max = 2.0 * fc_where_power_halves(base, psd)  # well past half power
        points += cartesian(psd=[psd], k3=list(K3S), fc=np.linspace(0, fc_max, n_fc))
    return points


def settings_for(quick: bool, seed: int) -> SweepSettings:
    # 128 paths at least, quick mode too: the paired interaction contrasts use
    # eight control variates and need ten paths per control (sweep.paired_contrast)
    if quick:
        return SweepSettings(
            target_rel_ci=0.01, window=1.0, burn_in=0.5, seed=seed, min_paths=128, batch_paths=64
        )
    return SweepSettings(
        target_rel_ci=0.005, window=2.0, burn_in=0.5, seed=seed, min_paths=128, batch_paths=64
    )


def plot(table: pd.DataFrame, base, out: Path) -> Path:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(PSDS), 2, figsize=(10, 10), sharex="row", squeeze=False)
    for col, k3 in enumerate(K3S):
        for row, psd in enumerate(PSDS):
            ax = axes[row, col]
            sub = table[(table.psd == psd) & (table.k3 == k3)].sort_values("fc")
            fc = np.linspace(0, sub.fc.max(), 200)
            device = base.updated(k3=k3, fc=fc)
            ax.plot(fc, expected_power(device, psd) * 1e3, "k-", label="Eq. 32 (linearisation)")
            if "averaging" in METHODS:
                try:
                    ax.plot(
                        fc,
                        np.asarray(expected_power(device, psd, "averaging")) * 1e3,
                        "b--",
                        lw=1,
                        label="stochastic averaging",
                    )
                except Exception:  # noqa: BLE001 - the extra curve is optional
                    pass
            ax.errorbar(
                sub.fc,
                sub.power_electrical * 1e3,
                yerr=sub.power_electrical_ci95 * 1e3,
                fmt="rx",
                ms=6,
                capsize=3,
                label="Monte Carlo (95 % CI)",
            )
            ax.set_title(
                f"({'ab'[col]}) k3 = {k3:g} N/m$^3$, S = {psd:g} (m/s$^2$)$^2$/Hz", fontsize=9
            )
            ax.set_ylabel("E[P$_e$] (mW)")
            ax.grid(alpha=0.3)
            if row == len(PSDS) - 1:
                ax.set_xlabel("Coulomb friction Fc (N)")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle("Paper Figure 9: expected electrical power against Coulomb friction")
    return save_figure(fig, out / "figure9.png")


def plot_interaction(inter: pd.DataFrame, out: Path) -> Path:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    for psd in PSDS:
        sub = inter[inter.psd == psd].sort_values("fc")
        ax.errorbar(
            sub.fc,
            100 * sub.relative_contrast,
            yerr=100 * sub.relative_ci95,
            fmt="o-",
            capsize=3,
            label=f"S = {psd:g}",
        )
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("Coulomb friction Fc (N)")
    ax.set_ylabel("interaction contrast / P(Fc, k3=0) (%)")
    ax.set_title("Duffing-Coulomb interaction at k3 = 5e5 N/m$^3$ (95 % CI, paired paths)")
    ax.legend()
    ax.grid(alpha=0.3)
    return save_figure(fig, out / "interaction.png")


def _levels(rows: pd.DataFrame) -> str:
    """'S = 1: Fc = 2.1, 4.2 mN; S = 0.1: ...' for report sentences."""
    parts = []
    for (psd, k3), sub in rows.groupby(["psd", "k3"], sort=False):
        fcs = ", ".join(f"{1e3 * f:.3g}" for f in sorted(sub.fc))
        parts.append(f"S = {psd:g}, k3 = {k3:g}: Fc = {fcs} mN")
    return "; ".join(parts)


def linearisation_verdict(table: pd.DataFrame) -> tuple[dict, str]:
    """Eq. 32 against Monte Carlo: the numbers behind the verdict, and the sentence.

    A point is *outside* where Eq. 32 is outside the Monte Carlo 95 % interval
    (``linearisation_consistent`` False). Its sign is the sign of
    ``linearisation_rel_error`` (negative: Eq. 32 under-predicts). "Higher
    friction" means the upper half of the Fc range of the point's (S, k3)
    series (Fc / max Fc > 1/2). Friction-free points are exact (control
    variates) and are not counted among the points that could be outside by
    chance.
    """
    fc_max = table.groupby(["psd", "k3"]).fc.transform("max")
    rel_level = table.fc / fc_max
    outside = table[~table.linearisation_consistent.astype(bool)]
    n_friction = int((table.fc > 0).sum())
    under = int((outside.linearisation_rel_error < 0).sum())
    over = int((outside.linearisation_rel_error > 0).sum())
    high = int((rel_level[outside.index] > 0.5).sum())
    data = {
        "n_points": len(table),
        "n_friction_points": n_friction,
        "n_outside": len(outside),
        "expected_by_chance": 0.05 * n_friction,
        "n_under": under,
        "n_over": over,
        "n_outside_high_friction": high,
        "outside_points": outside[["psd", "k3", "fc"]].to_dict("records"),
    }
    chance = f"{data['expected_by_chance']:.1f} expected by chance at 95 %"
    if outside.empty:
        sentence = (
            "Eq. 32 lies inside the Monte Carlo 95 % interval at every point: at the resolution "
            "of these intervals it is not distinguishable from the simulated power."
        )
    else:
        if high == len(outside):
            where = "all of them in the upper half of their series' friction range"
        elif high == 0:
            where = "none of them in the upper half of their series' friction range"
        else:
            where = f"{high} of them in the upper half of their series' friction range"
        if over == 0:
            sign = "Eq. 32 under-predicts the power at every one"
        elif under == 0:
            sign = "Eq. 32 over-predicts the power at every one"
        else:
            sign = f"Eq. 32 under-predicts at {under} and over-predicts at {over}"
        levels = (
            "every point with friction"
            if len(outside) == n_friction and (outside.fc > 0).all()
            else _levels(outside)
        )
        sentence = (
            f"Eq. 32 is outside the Monte Carlo 95 % interval at {len(outside)} of {len(table)} "
            f"points ({chance} among the {n_friction} with friction), {where} "
            f"({levels}); {sign}."
        )
        if over == 0 and len(outside) > data["expected_by_chance"]:
            sentence += (
                " An under-prediction means a simulated E|z'| below the Gaussian "
                "sqrt(2/pi) sigma_v (exact energy balance): the velocity is not Gaussian "
                "once the magnet sticks."
            )
    return data, sentence


def interaction_verdict(inter: pd.DataFrame) -> tuple[dict, str]:
    """The interaction contrasts' verdict: counts, the largest contrast, and the sentence."""
    big = inter.loc[inter.relative_contrast.abs().idxmax()]
    holm = inter[inter.detectable_holm.astype(bool)]
    data = {
        "n_contrasts": len(inter),
        "n_detectable": int(inter.detectable.sum()),
        "n_holm": len(holm),
        "largest_relative_contrast": float(big.relative_contrast),
        "largest_relative_ci95": float(big.relative_ci95),
        "largest_at": {"psd": float(big.psd), "fc": float(big.fc)},
        "bound_relative": float((inter.relative_contrast.abs() + inter.relative_ci95).max()),
    }
    if holm.empty:
        sentence = (
            f"no interaction is detectable at this precision (0 of {len(inter)} contrasts after "
            f"Holm's correction); the contrast stays within ±{100 * data['bound_relative']:.2f} % "
            "of P(Fc, 0) (largest |estimate| + 95 % half-width)."
        )
    else:
        signs = np.sign(holm.relative_contrast)
        sign = (
            "all positive"
            if (signs > 0).all()
            else "all negative"
            if (signs < 0).all()
            else "of either sign"
        )
        sentence = (
            f"an interaction is detectable at {len(holm)} of {len(inter)} (S, Fc) points after "
            f"Holm's correction ({_levels(holm.assign(k3=K3S[1]))}), {sign}, up to "
            f"{100 * holm.relative_contrast.abs().max():.2f} % of P(Fc, 0): the Duffing spring "
            "changes the friction-affected power, which Eq. 32 cannot show."
        )
    return data, sentence


def run_study(
    out_dir,
    *,
    quick: bool = False,
    seed: int = 0,
    workers=None,
    scheduler=None,
    progress: bool = True,
) -> Path:
    """Run the Figure 9 study; write figures, CSVs and ``report.md`` into ``out_dir``."""
    base = preset("figure9")
    n_fc = 7 if quick else 13
    points = study_points(n_fc)
    settings = settings_for(quick, seed)
    out = prepare_output_dir(out_dir, {"study": "figure9", "quick": quick, "seed": seed})
    # half-step check on the highest-friction points (largest nonlinearity)
    result, check = sweep_with_step_check(
        base,
        points,
        settings,
        out,
        "figure9",
        highest_friction_points(points),
        workers=workers,
        scheduler=scheduler,
        progress=progress,
    )
    table = linearisation_verdicts(result.table)
    inter = interaction_contrasts(result, base, "fc", "k3")
    atomic_write_text(out / "results.csv", table.to_csv(index=False))
    atomic_write_text(out / "interaction.csv", inter.to_csv(index=False))
    atomic_write_text(out / "step_check.csv", check.to_csv(index=False))
    curves = []
    for psd in PSDS:
        for k3 in K3S:
            fc = np.linspace(0, table[table.psd == psd].fc.max(), 200)
            curves.append(
                pd.DataFrame(
                    {
                        "psd": psd,
                        "k3": k3,
                        "fc": fc,
                        "linearisation_power": expected_power(base.updated(k3=k3, fc=fc), psd),
                    }
                )
            )
    atomic_write_text(out / "curves.csv", pd.concat(curves).to_csv(index=False))
    fig_main = plot(table, base, out)
    fig_inter = plot_interaction(inter, out)

    lin_data, lin_sentence = linearisation_verdict(table)
    inter_data, inter_sentence = interaction_verdict(inter)
    check_data = step_check_verdict(check)
    atomic_write_text(
        out / "verdicts.json",
        json.dumps(
            {"linearisation": lin_data, "interaction": inter_data, "step_check": check_data},
            indent=2,
        ),
    )
    err = table["linearisation_rel_error"]
    worst = table.loc[err.abs().idxmax()]
    lin_body = (
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
        + markdown_table(
            table[
                [
                    "psd",
                    "k3",
                    "fc",
                    "linearisation_power",
                    "power_electrical",
                    "power_electrical_ci95",
                    "linearisation_rel_error",
                    "linearisation_consistent",
                    "n_paths",
                ]
            ]
        )
    )
    big = inter.loc[inter.relative_contrast.abs().idxmax()]
    inter_body = (
        f"Contrast [P(Fc,k3) - P(Fc,0)] - [P(0,k3) - P(0,0)] at k3 = 5e5 N/m^3 from paired paths "
        f"(same noise at every point). Detectable (|contrast| > 95 % half-width) at "
        f"{inter_data['n_detectable']} of {inter_data['n_contrasts']} (S, Fc) points; the largest "
        f"relative contrast is "
        f"{100 * big.relative_contrast:+.2f} % ± {100 * big.relative_ci95:.2f} % "
        f"(S = {big.psd:g}, Fc = {big.fc:.4g} N). The points share their paths (common random "
        f"numbers), so their verdicts are correlated; with Holm's correction for "
        f"{inter_data['n_contrasts']} tests at family level 5 %, {inter_data['n_holm']} remain.\n\n"
        f"Verdict on the paper's second claim at its own k3: {inter_sentence}\n\n"
        + markdown_table(inter)
    )
    step_body = (
        f"Re-run of {len(check)} highest-friction points at dt/2 = {settings.dt / 2:g} s (independent "
        f"noise). Time-step bias below statistical error at {check_data['n_below']} of "
        f"{check_data['n_points']} points"
        f"{check_data['sentence']}.\n\n" + markdown_table(check)
    )
    return write_report(
        out,
        "Figure 9 study: equivalent linearisation and the Duffing-Coulomb interaction",
        [
            (
                "Set-up",
                f"Device: paper Section 5 (preset `figure9`: c_m = c_e = 0.1 Ns/m, k = 57.4 N/m, "
                f"k3 as given, m = 0.0226 kg assumed). S = {', '.join(map(str, PSDS))} (m/s^2)^2/Hz; "
                f"Fc from 0 to twice the level where Eq. 32 halves the power. Heun, dt = "
                f"{settings.dt:g} s, {settings.burn_in:g} s burn-in + {settings.window:g} s per path, "
                f"seed {seed}, control variates {'on' if settings.control_variates else 'off'}."
                f"{' Quick mode.' if quick else ''}\n\n![Figure 9]({fig_main.name})",
            ),
            ("Equivalent linearisation against Monte Carlo", lin_body),
            ("Duffing-Coulomb interaction", f"![interaction]({fig_inter.name})\n\n" + inter_body),
            ("Time-step check", step_body),
        ],
    )
