"""Study ``interaction``: does the Duffing spring change the effect of Coulomb friction?

Paper Section 5 concludes from Figure 9 (k3 = 0 and 5e5 N/m^3) that the cubic
stiffness hardly matters for the expected power of the friction-affected
device; equivalent linearisation (Eq. 30-32) cannot say otherwise, because
c_eq has no k3 in it. This study takes k3 several decades beyond the paper,

    k3 = 0, 7.07e4 (Table 2), 5e5 (Figure 9), 5e6, 5e7 N/m^3 (100x Figure 9),

on the Figure 9 device (preset ``figure9``: c_m = c_e = 0.1 Ns/m,
k = 57.4 N/m, m = 0.0226 kg assumed), with S = 1, 0.5, 0.1 (m/s^2)^2/Hz and
Coulomb levels Fc from 0 to twice the level where Eq. 32 halves the power
(phi = Fc / (c sigma_v0) from 0 to sqrt(pi) = 1.77 at every S).

At every (S, Fc > 0, k3 > 0) it estimates the interaction contrast

    [P(Fc, k3) - P(Fc, 0)] - [P(0, k3) - P(0, 0)]

from common-random-number paths (:func:`randvib.studies._common.interaction_contrasts`),
relative to P(Fc, 0), with a 95 % interval, a per-point verdict and Holm's
correction over the family. Beside it: the contrast predicted by stochastic
averaging (:mod:`randvib.analytic.averaging`), which, unlike Eq. 32, does depend on
k3, and the linearisation error at every point. A half-step re-run of the
hardest points shows the time-step bias is below the statistical error.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from randvib._io import atomic_write_text, prepare_output_dir
from randvib.analytic.averaging import AveragingValidityWarning, averaging_statistics
from randvib.analytic.prediction import METHODS, expected_power
from randvib.models.presets import preset
from randvib.montecarlo.sweep import SweepSettings, cartesian, linearisation_verdicts
from randvib.studies._common import (
    burn_in_for,
    check_step_bias,
    fc_where_power_halves,
    friction_level,
    highest_friction_points,
    interaction_contrasts,
    markdown_table,
    plus_minus,
    save_figure,
    step_check_verdict,
    sweep_with_step_check,
    write_report,
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


def grid(quick: bool) -> dict:
    """The study's axes: S values, k3 values and the number of Fc levels per S."""
    if quick:
        return {"psds": PSDS, "k3s": QUICK_K3S, "n_fc": QUICK_N_FC}
    return {"psds": PSDS, "k3s": K3S, "n_fc": N_FC}


def study_points(base, psds, k3s, n_fc) -> list[dict]:
    """(psd, k3, fc) points: Fc from 0 to twice Eq. 32's half-power level at each S."""
    if 0.0 not in k3s:
        raise ValueError(f"`k3s` must include 0 (the contrast's reference), got {k3s}")
    if n_fc < 2:
        raise ValueError(f"`n_fc` must be >= 2 (Fc = 0 and at least one level), got {n_fc}")
    points = []
    for psd in psds:
        fc_max = 2.0 * fc_where_power_halves(base, psd)
        points += cartesian(psd=[psd], k3=list(k3s), fc=np.linspace(0.0, fc_max, n_fc))
    return points


def duffing_strength(device, psd, k3):
    """mu = k3 sigma_z0^2 / k: cubic against linear spring force at the friction-free rms z.

    sigma_z0^2 = S m^2 / (4 c k) (linear oscillator, Eq. 20 with E[z^2] = E[z'^2] m / k).
    With z scaled by sqrt(S), the Duffing-Coulomb SDE depends on S and k3 only
    through phi and mu, so grid points with equal k3 S repeat one problem.
    """
    c, m, k = float(device.c), float(device.m), float(device.k)
    return np.asarray(k3, dtype=float) * np.asarray(psd, dtype=float) * m**2 / (4 * c * k**2)


def settings_for(quick: bool, seed: int) -> SweepSettings:
    # 128 paths at least in both modes: a paired contrast regresses on the energy-balance
    # controls of its points, which paired_contrast only uses with ten paths per control
    burn_in = burn_in_for([preset("figure9")])
    if quick:
        return SweepSettings(
            dt=DT,
            target_rel_ci=0.01,
            window=1.0,
            burn_in=burn_in,
            seed=seed,
            min_paths=128,
            batch_paths=64,
        )
    return SweepSettings(
        dt=DT,
        target_rel_ci=0.0015,
        window=2.0,
        burn_in=burn_in,
        seed=seed,
        min_paths=128,
        batch_paths=64,
    )


def _averaging_power(device, psd):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AveragingValidityWarning)
        return np.asarray(expected_power(device, psd, "averaging"), dtype=float)


def averaging_contrasts(base, inter: pd.DataFrame) -> pd.Series:
    """Relative interaction contrast predicted by stochastic averaging at each row.

    Relative to averaging's own P(Fc, 0). Averaging gives the exact Gibbs
    power at Fc = 0 for every k3, so its P(0, k3) - P(0, 0) is zero.
    """
    out = []
    for row in inter.itertuples():
        p = {
            (fc, k3): float(_averaging_power(base.updated(k3=k3, fc=fc), row.psd))
            for fc in (row.fc, 0.0)
            for k3 in (row.k3, 0.0)
        }
        contrast = p[(row.fc, row.k3)] - p[(row.fc, 0.0)] - p[(0.0, row.k3)] + p[(0.0, 0.0)]
        out.append(contrast / p[(row.fc, 0.0)])
    return pd.Series(out, index=inter.index, name="averaging_relative_contrast")


def averaging_curves(base, psds, k3s, fc_max: dict, n: int = 60) -> pd.DataFrame:
    """Averaging's relative contrast on a fine Fc grid, for the figure."""
    frames = []
    for psd in psds:
        fc = np.linspace(0.0, fc_max[psd], n)[1:]
        p_ref = _averaging_power(base.updated(k3=0.0, fc=fc), psd)
        p_ref0 = float(_averaging_power(base.updated(k3=0.0, fc=0.0), psd))
        for k3 in k3s:
            if k3 == 0:
                continue
            p = _averaging_power(base.updated(k3=k3, fc=fc), psd)
            p0 = float(_averaging_power(base.updated(k3=k3, fc=0.0), psd))
            frames.append(
                pd.DataFrame(
                    {
                        "psd": psd,
                        "k3": k3,
                        "fc": fc,
                        "averaging_relative_contrast": (p - p_ref - p0 + p_ref0) / p_ref,
                    }
                )
            )
    return pd.concat(frames, ignore_index=True)


def _colours(k3s) -> dict:
    import matplotlib.pyplot as plt

    cycle = plt.get_cmap("tab10").colors
    return {k3: cycle[i % len(cycle)] for i, k3 in enumerate(sorted(k3s))}


def _k3_label(k3: float) -> str:
    extra = K3_LABELS.get(k3)
    return f"k3 = {k3:.3g} N/m$^3$" + (f" ({extra})" if extra else "")


def plot_contrasts(inter: pd.DataFrame, curves: pd.DataFrame | None, out: Path) -> Path:
    import matplotlib.pyplot as plt

    psds = sorted(inter.psd.unique(), reverse=True)
    k3s = sorted(inter.k3.unique())
    colours = _colours(k3s)
    fig, axes = plt.subplots(1, len(psds), figsize=(4.6 * len(psds), 4.4), squeeze=False)
    for ax, psd in zip(axes[0], psds, strict=True):
        for k3 in k3s:
            sub = inter[(inter.psd == psd) & (inter.k3 == k3)].sort_values("fc")
            # the contrast is zero by definition at Fc = 0
            fc = np.r_[0.0, sub.fc] * 1e3
            y = 100 * np.r_[0.0, sub.relative_contrast]
            ci = 100 * np.r_[0.0, sub.relative_ci95]
            ax.fill_between(fc, y - ci, y + ci, color=colours[k3], alpha=0.2, lw=0)
            ax.plot(fc, y, "o-", color=colours[k3], ms=4, label=_k3_label(k3))
            if curves is not None:
                cur = curves[(curves.psd == psd) & (curves.k3 == k3)]
                ax.plot(
                    np.r_[0.0, cur.fc] * 1e3,
                    100 * np.r_[0.0, cur.averaging_relative_contrast],
                    "--",
                    color=colours[k3],
                    lw=1,
                )
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_title(f"S = {psd:g} (m/s$^2$)$^2$/Hz", fontsize=10)
        ax.set_xlabel("Coulomb friction Fc (mN)")
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("interaction contrast / P(Fc, k3 = 0)  (%)")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    if curves is not None:
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], color="grey", ls="--", lw=1))
        labels.append("stochastic averaging (prediction)")
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 3), fontsize=9)
    fig.suptitle(
        "Duffing-Coulomb interaction [P(Fc,k3) - P(Fc,0)] - [P(0,k3) - P(0,0)]: "
        "Monte Carlo, paired paths, 95 % bands"
    )
    fig.tight_layout(rect=(0, 0.1 if len(labels) > 3 else 0.07, 1, 1))
    return save_figure(fig, out / "interaction.png")


def plot_linearisation_error(table: pd.DataFrame, out: Path) -> Path:
    import matplotlib.pyplot as plt

    psds = sorted(table.psd.unique(), reverse=True)
    k3s = sorted(table.k3.unique())
    colours = _colours(k3s)
    fig, axes = plt.subplots(
        1, len(psds), figsize=(4.6 * len(psds), 4.0), squeeze=False, sharey=True
    )
    for ax, psd in zip(axes[0], psds, strict=True):
        for j, k3 in enumerate(k3s):
            sub = table[(table.psd == psd) & (table.k3 == k3) & (table.fc > 0)].sort_values("fc")
            # small horizontal offsets keep overlapping error bars apart
            shift = (j - (len(k3s) - 1) / 2) * 0.006 * sub.fc.max()
            ax.errorbar(
                (sub.fc + shift) * 1e3,
                100 * sub.linearisation_rel_error,
                yerr=100 * sub.linearisation_rel_error_ci95,
                fmt="o-",
                ms=3,
                capsize=2,
                color=colours[k3],
                label=_k3_label(k3),
            )
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_title(f"S = {psd:g} (m/s$^2$)$^2$/Hz", fontsize=10)
        ax.set_xlabel("Coulomb friction Fc (mN)")
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("Eq. 32 error (P$_{lin}$ - P$_{MC}$) / P$_{MC}$  (%)")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle("Equivalent linearisation error at every k3 (95 % CI)")
    fig.tight_layout()
    return save_figure(fig, out / "linearisation_error.png")


def _sign(rows: pd.DataFrame, column: str = "relative_contrast") -> str:
    if (rows[column] > 0).all():
        return "all positive"
    if (rows[column] < 0).all():
        return "all negative"
    return "of either sign"


def _growth(inter: pd.DataFrame, column: str = "averaging_relative_contrast") -> str:
    """' growing in size with k3 and Fc' where |column| rises along both axes, else what holds."""

    def rising(by: str, along: str) -> bool:
        return all(
            bool(np.all(np.diff(sub.sort_values(along)[column].abs().to_numpy()) > 0))
            for _, sub in inter.groupby(["psd", by])
            if len(sub) > 1
        )

    with_fc, with_k3 = rising("k3", "fc"), rising("fc", "k3")
    if with_fc and with_k3:
        return " growing in size with k3 and Fc"
    if with_fc:
        return " growing in size with Fc (not monotonically with k3)"
    if with_k3:
        return " growing in size with k3 (not monotonically with Fc)"
    return " (not monotonic in k3 or Fc)"


def interaction_counts(inter: pd.DataFrame, k3s) -> dict:
    """The numbers behind the interaction verdict, per k3 (keys are k3 as text)."""
    out = {"n_contrasts": len(inter), "n_holm": int(inter.detectable_holm.sum()), "by_k3": {}}
    for k3 in k3s:
        if k3 == 0:
            continue
        sub = inter[inter.k3 == k3]
        worst = sub.loc[sub.relative_contrast.abs().idxmax()]
        out["by_k3"][f"{k3:g}"] = {
            "n": len(sub),
            "n_detectable": int(sub.detectable.sum()),
            "n_holm": int(sub.detectable_holm.sum()),
            "largest_relative_contrast": float(worst.relative_contrast),
            "largest_relative_ci95": float(worst.relative_ci95),
            "bound_relative": float((sub.relative_contrast.abs() + sub.relative_ci95).max()),
        }
    return out


def _summary(inter: pd.DataFrame, k3s) -> tuple[str, pd.DataFrame]:
    """Per-k3 summary table and the verdict sentence."""
    rows = []
    for k3 in k3s:
        if k3 == 0:
            continue
        sub = inter[inter.k3 == k3]
        worst = sub.loc[sub.relative_contrast.abs().idxmax()]
        bound = (sub.relative_contrast.abs() + sub.relative_ci95).max()
        rows.append(
            {
                "k3 (N/m^3)": f"{k3:.3g}" + (f" ({K3_LABELS[k3]})" if k3 in K3_LABELS else ""),
                "detectable (95 %, per point)": f"{int(sub.detectable.sum())} of {len(sub)}",
                "detectable (Holm)": f"{int(sub.detectable_holm.sum())} of {len(sub)}",
                "largest contrast (%)": plus_minus(
                    worst.relative_contrast, worst.relative_ci95, fmt="+.3f"
                )[0],
                "at S, phi": f"{worst.psd:g}, {worst.phi:.2f}",
                "bound on |contrast| (%)": f"{100 * bound:.3f}",
                "averaging, largest (%)": f"{100 * sub.averaging_relative_contrast.abs().max():.3f}"
                if "averaging_relative_contrast" in sub
                else "n/a",
            }
        )
    summary = pd.DataFrame(rows)
    holm = inter[inter.detectable_holm]
    top = max(k for k in k3s)
    at_top = inter[inter.k3 == top]
    label = f" ({K3_LABELS[top]})" if top in K3_LABELS else ""
    if holm.empty:
        bound = 100 * (at_top.relative_contrast.abs() + at_top.relative_ci95).max()
        verdict = (
            f"No interaction is detectable at the family level (Holm, 5 %, {len(inter)} "
            f"contrasts). Even at k3 = {top:.3g} N/m^3{label} the contrast stays within "
            f"±{bound:.2f} % of P(Fc, 0) (largest |estimate| + 95 % half-width)."
        )
        single = at_top[at_top.detectable]
        if len(single):
            verdict += (
                f" There, {len(single)} of {len(at_top)} contrasts pass on their own "
                f"(95 %, uncorrected; {0.05 * len(at_top):.1f} expected by chance), "
                + _sign(single)
                + f", up to {100 * single.relative_contrast.abs().max():.2f} %: a hint of an "
                f"interaction below {bound:.2f} %, not established at this precision."
            )
    else:
        where = holm.groupby("k3").size()
        big = holm.loc[holm.relative_contrast.abs().idxmax()]
        verdict = (
            f"The interaction is detectable (Holm, family level 5 %) at {len(holm)} of "
            f"{len(inter)} (S, Fc, k3) points: "
            + ", ".join(f"{n} at k3 = {k:.3g}" for k, n in where.items())
            + f". The largest is {100 * big.relative_contrast:+.2f} % ± "
            f"{100 * big.relative_ci95:.2f} % of P(Fc, 0) (k3 = {big.k3:.3g} N/m^3, "
            f"S = {big.psd:g}, Fc = {1e3 * big.fc:.3g} mN, phi = {big.phi:.2f})."
        )
        if top in where.index:
            share = at_top[at_top.detectable_holm]
            size = (
                f"{100 * share.relative_contrast.iloc[0]:+.2f} %"
                if len(share) == 1
                else _sign(share) + f", {100 * share.relative_contrast.abs().min():.2f} % to "
                f"{100 * share.relative_contrast.abs().max():.2f} % in magnitude"
            )
            verdict += (
                f" At k3 = {top:.3g} N/m^3{label}: {len(share)} of {len(at_top)} points, "
                f"{size} (of P(Fc, 0))."
            )
    if "averaging_relative_contrast" in inter:
        miss = (inter.averaging_relative_contrast - inter.relative_contrast).abs() > (
            inter.relative_ci95
        )
        verdict += (
            f" Stochastic averaging predicts {_sign(inter[inter.averaging_relative_contrast.abs() > 1e-4], 'averaging_relative_contrast')} "
            f"contrasts{_growth(inter)}, up to "
            f"{100 * inter.averaging_relative_contrast.abs().max():.2f} %; the Monte Carlo 95 % "
            f"interval excludes its prediction at {int(miss.sum())} of {len(inter)} points"
            + (
                f" (k3 = {', '.join(f'{k:.3g}' for k in sorted(inter[miss].k3.unique()))})."
                if miss.any()
                else "."
            )
        )
    return verdict, summary


def linearisation_by_spring(lin: pd.DataFrame) -> dict:
    """Where Eq. 32's error is largest, and how much it changes with k3 at equal (S, Fc).

    ``spread`` is the largest range over k3 of the error at one (S, Fc);
    ``spread_ci95`` the largest 95 % half-width among the points; the
    sentence says whether the spring changes the error by more than the
    combined interval sqrt(2) * spread_ci95.
    """
    top_fc = lin.groupby(["psd", "k3"]).fc.transform("max")
    idx = lin.groupby(["psd", "k3"]).linearisation_rel_error.apply(lambda e: e.abs().idxmax())
    at_top = int((lin.loc[idx, "fc"] == top_fc.loc[idx]).sum())
    if at_top == len(idx):
        where = (
            "the largest |error| of every (S, k3) series is at its highest Fc, "
            f"phi = {lin.phi.max():.2f}"
        )
    else:
        where = f"largest at the highest Fc in {at_top} of {len(idx)} (S, k3) series"
    by_point = lin.groupby(["psd", "fc"])
    spread = float(by_point.linearisation_rel_error.agg(lambda e: e.max() - e.min()).max())
    half = float(lin.linearisation_rel_error_ci95.max())
    if by_point.k3.nunique().max() < 2:
        sentence = "No (S, Fc) has more than one k3 here, so the spring's effect is not resolved."
    elif spread <= np.sqrt(2) * half:
        sentence = (
            f"At equal S and Fc it changes with k3 by at most {100 * spread:.2f} %, within the "
            f"combined intervals (sqrt(2) x the 95 % half-widths, up to {100 * half:.2f} %): it "
            "is set by the friction level, with no resolved dependence on the spring - the "
            "interaction verdict above seen from the other side."
        )
    else:
        sentence = (
            f"At equal S and Fc it changes with k3 by up to {100 * spread:.2f} %, more than the "
            f"combined intervals (sqrt(2) x the 95 % half-widths, up to {100 * half:.2f} %): "
            "the spring changes Eq. 32's error."
        )
    return {
        "series_largest_at_top_fc": at_top,
        "n_series": len(idx),
        "where_largest": where,
        "spread": spread,
        "spread_ci95": half,
        "sentence": sentence,
    }


def scaling_sentence(inter: pd.DataFrame) -> str:
    """How closely rows with equal (phi, mu) agree (exact scaling: to rounding)."""
    key = [inter.phi.round(9), inter.mu.round(9)]
    groups = [g for _, g in inter.groupby(key) if len(g) > 1]
    if not groups:
        return "; no two rows of this grid share (phi, mu)."
    diff = max(float(g.relative_contrast.max() - g.relative_contrast.min()) for g in groups)
    if diff <= 1e-9:
        return (
            f"; the {len(groups)} such groups here agree to {diff:.1e} of P(Fc, 0), i.e. to "
            "rounding - a check of the simulator, not extra evidence."
        )
    return (
        f"; the {len(groups)} such groups here differ by up to {100 * diff:.3g} % of P(Fc, 0), "
        "more than rounding: the exact scaling does not hold in these results."
    )


def run_study(
    out_dir,
    *,
    quick: bool = False,
    seed: int = 0,
    workers=None,
    scheduler=None,
    progress: bool = True,
    _grid: dict | None = None,
    _settings: SweepSettings | None = None,
) -> Path:
    """Run the interaction study; write figures, CSVs and ``report.md`` into ``out_dir``.

    ``_grid`` ({"psds", "k3s", "n_fc"}) and ``_settings`` replace the study's
    grid and sweep settings (for tests); they are part of the folder's identity.
    """
    base = preset("figure9")
    axes = dict(_grid) if _grid is not None else grid(quick)
    psds, k3s, n_fc = tuple(axes["psds"]), tuple(axes["k3s"]), int(axes["n_fc"])
    settings = _settings or settings_for(quick, seed)
    points = study_points(base, psds, k3s, n_fc)
    worst_bias = check_step_bias(base, points, settings)
    out = prepare_output_dir(
        out_dir,
        {
            "study": NAME,
            "quick": quick,
            "seed": seed,
            "grid": {"psds": psds, "k3s": k3s, "n_fc": n_fc},
            "settings": settings.to_dict(),
        },
    )
    # half-step check where the dynamics is hardest: most friction, with and
    # without the stiffest spring
    result, check = sweep_with_step_check(
        base,
        points,
        settings,
        out,
        NAME,
        highest_friction_points(points),
        workers=workers,
        scheduler=scheduler,
        progress=progress,
    )

    table = linearisation_verdicts(result.table)
    has_avg = "averaging" in METHODS and "averaging_power" in table
    if has_avg:
        table = linearisation_verdicts(table, "averaging")
        zeta_f = [
            float(
                averaging_statistics(
                    base.updated(k3=r.k3, fc=r.fc), r.psd, warn=False
                ).zeta_friction
            )
            for r in table.itertuples()
        ]
        table["averaging_zeta_friction"] = zeta_f
    table["phi"] = friction_level(base, table.psd, table.fc)
    inter = interaction_contrasts(result, base, "fc", "k3", zero_baseline=True)
    inter.insert(3, "phi", friction_level(base, inter.psd, inter.fc))
    inter.insert(4, "mu", duffing_strength(base, inter.psd, inter.k3))
    curves = None
    if has_avg:
        inter["averaging_relative_contrast"] = averaging_contrasts(base, inter)
        fc_max = {psd: inter[inter.psd == psd].fc.max() for psd in psds}
        curves = averaging_curves(base, psds, k3s, fc_max)
        atomic_write_text(out / "averaging_curves.csv", curves.to_csv(index=False))
    atomic_write_text(out / "results.csv", table.to_csv(index=False))
    atomic_write_text(out / "interaction.csv", inter.to_csv(index=False))
    atomic_write_text(out / "step_check.csv", check.to_csv(index=False))
    fig_inter = plot_contrasts(inter, curves, out)
    fig_lin = plot_linearisation_error(table, out)

    verdict, summary = _summary(inter, k3s)
    check_data = step_check_verdict(check)
    mu_fig9 = float(duffing_strength(base, 1.0, 5e5))
    baseline = float(((inter.baseline.abs() + inter.baseline_ci95) / inter.reference).max())
    shown = inter[["psd", "k3", "fc", "phi"]].copy()
    shown["fc"] = 1e3 * shown.fc
    shown = shown.rename(columns={"fc": "fc (mN)"})
    shown["contrast / P(Fc,0) (%)"] = plus_minus(inter.relative_contrast, inter.relative_ci95)
    if has_avg:
        shown["averaging (%)"] = [f"{100 * x:+.2f}" for x in inter.averaging_relative_contrast]
    shown["p"] = inter.p_value
    shown["n_paths"] = inter.n_paths
    shown["detectable"] = inter.detectable
    shown["Holm"] = inter.detectable_holm
    avg_note = (
        "Stochastic averaging (dashed in the figure, `averaging` column) does depend on k3: "
        "the spring changes the orbit shapes over which the friction work is averaged. "
        if has_avg
        else ""
    )
    inter_body = (
        f"![interaction]({fig_inter.name})\n\n"
        f"**Verdict.** {verdict}\n\n"
        "Equivalent linearisation predicts no interaction at all: Eq. 30 for c_eq contains no "
        "k3, so Eq. 32 gives the same power for every spring. "
        + avg_note
        + "\n\nHow it is estimated: without friction E[z'^2] = S m / (4c) for every k3 (exact "
        "stationary density), so the second bracket P(0, k3) - P(0, 0) is zero by theory; the "
        "sweep's estimates of it, exact through the friction-free companion control, are at most "
        f"{100 * baseline:.1e} % of P(Fc, 0). The contrast is therefore the paired difference "
        "P(Fc, k3) - P(Fc, 0) over the paths the two points share (same Brownian increments; "
        "Ito-integral and energy-change controls of both), `n_paths` below. The contrasts "
        "share their paths (common random numbers), so neighbouring verdicts are correlated; "
        "Holm's step-down keeps the family-wise error at 5 %.\n\n"
        f"Scaling: the friction level phi and the Duffing strength mu = k3 sigma_z0^2 / k "
        f"(here {inter.mu.min():.2g} to {inter.mu.max():.2g}; {mu_fig9:.2g} in the paper's "
        "Figure 9 at S = 1) are the only parameters that S and k3 enter through (z scales "
        "with sqrt(S)), so rows with equal k3 S repeat one problem on the same paths"
        + scaling_sentence(inter)
        + "\n\n"
        + markdown_table(summary)
        + "\n\nEvery contrast (relative to the Monte Carlo P(Fc, k3 = 0); phi = Fc / (c sigma_v0)):\n\n"
        + markdown_table(shown, floatfmt=".3g")
    )

    lin = table[table.fc > 0]
    err = lin.linearisation_rel_error
    lin_data = linearisation_by_spring(lin)
    by_k3 = lin.groupby("k3").linearisation_rel_error.agg(lambda e: e.abs().max())
    lin_shown = lin[["psd", "k3", "fc", "phi"]].copy()
    lin_shown["fc"] = 1e3 * lin_shown.fc
    lin_shown = lin_shown.rename(columns={"fc": "fc (mN)"})
    lin_shown["P_MC (mW)"] = plus_minus(lin.power_electrical, lin.power_electrical_ci95, 1e3, ".4f")
    lin_shown["Eq. 32 error (%)"] = plus_minus(
        lin.linearisation_rel_error, lin.linearisation_rel_error_ci95
    )
    if has_avg:
        lin_shown["averaging error (%)"] = plus_minus(
            lin.averaging_rel_error, lin.averaging_rel_error_ci95
        )
        lin_shown["zeta_f"] = lin.averaging_zeta_friction
    lin_shown["n_paths"] = lin.n_paths
    lin_body = (
        f"![linearisation error]({fig_lin.name})\n\n"
        f"Eq. 32 against Monte Carlo at the {len(lin)} points with friction: the error reaches "
        f"{100 * err.abs().max():.2f} % ({lin_data['where_largest']}); "
        "its largest magnitude per k3: "
        + ", ".join(f"{100 * v:.2f} % at k3 = {k:.3g}" for k, v in by_k3.items())
        + f". {lin_data['sentence']}"
        + (
            " The averaging predictions at points with zeta_f > 0.5 are outside that method's "
            "stated validity (it warns there)."
            if has_avg and (lin.averaging_zeta_friction > 0.5).any()
            else ""
        )
        + "\n\n"
        + markdown_table(lin_shown, floatfmt=".3g")
    )
    step_body = (
        f"Re-run of {len(check)} points (the highest Fc at each S, with k3 = "
        + ", ".join(f"{k:.3g}" for k in sorted(check.k3.unique()))
        + f") at dt/2 = {settings.dt / 2:g} s, independent noise. Time-step bias below the "
        f"statistical error at {check_data['n_below']} of {len(check)} points"
        f"{check_data['sentence']}. "
        f"Linearised step bias at dt (randvib.montecarlo.simulation.step_bias) at most {worst_bias:.1e}.\n\n"
        + markdown_table(check)
    )
    atomic_write_text(
        out / "verdicts.json",
        json.dumps(
            {
                "interaction": interaction_counts(inter, k3s),
                "linearisation": lin_data,
                "step_check": check_data,
            },
            indent=2,
        ),
    )
    setup = (
        "Device: preset `figure9` (paper Section 5: Coulomb, training data 1, "
        "c_m = c_e = 0.1 Ns/m, k = 57.4 N/m; m = 0.0226 kg assumed). "
        f"S = {', '.join(f'{s:g}' for s in psds)} (m/s^2)^2/Hz; "
        f"k3 = {', '.join(f'{k:.3g}' for k in k3s)} N/m^3; "
        f"{n_fc} Fc levels per S from 0 to twice the level where Eq. 32 halves the power "
        f"(phi = Fc / (c sigma_v0) from 0 to {2 * np.sqrt(np.pi) / 2:.2f}, sigma_v0^2 = S m / (4c)). "
        f"Heun, dt = {settings.dt:g} s, {settings.burn_in:g} s burn-in "
        "(at least six energy relaxation times m/c, so that each path, started from the "
        "Gaussian linearised state, has forgotten "
        f"its start) + {settings.window:g} s "
        f"per path, paths added until the 95 % half-width of each power is "
        f"{100 * settings.target_rel_ci:g} % ({int(table.n_paths.sum())} paths in all), seed "
        f"{seed}, common random numbers across points, control variates "
        f"{'on' if settings.control_variates else 'off'}.{' Quick mode.' if quick else ''}"
    )
    return write_report(
        out,
        "Duffing-Coulomb interaction beyond the paper's k3",
        [
            ("Set-up", setup),
            ("Interaction contrast", inter_body),
            ("Equivalent linearisation at every point", lin_body),
            ("Time-step check", step_body),
        ],
    )
