"""Figures the studies share: power and contrasts against the Coulomb level.

Each function draws from a study's table, saves one PNG at ``path``
(:func:`randvib.studies.report.save_figure`) and returns the path; nothing
is computed here except the analytic curves drawn for comparison.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from randvib.analytic.prediction import METHODS, expected_power
from randvib.studies.report import save_figure


def power_against_friction(table: pd.DataFrame, base, psds, k3s, path: Path) -> Path:
    """Expected power against Fc, one panel per (S, k3): Monte Carlo with 95 % bars over Eq. 32.

    The paper's Figure 9 layout (rows S, columns k3), with the averaging
    curve where that method is available. ``table`` is a sweep table with
    ``psd``, ``k3``, ``fc``, ``power_electrical`` and its ``_ci95`` (W).
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(psds), 2, figsize=(10, 10), sharex="row", squeeze=False)
    for col, k3 in enumerate(k3s):
        for row, psd in enumerate(psds):
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
            if row == len(psds) - 1:
                ax.set_xlabel("Coulomb friction Fc (N)")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle("Paper Figure 9: expected electrical power against Coulomb friction")
    return save_figure(fig, path)


def contrast_against_friction(inter: pd.DataFrame, title: str, path: Path) -> Path:
    """Relative interaction contrasts against Fc, one line per S, with 95 % bars."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    for psd in inter.psd.unique():
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
    ax.set_title(title)
    ax.legend()
    ax.grid(alpha=0.3)
    return save_figure(fig, path)


def _colours(k3s) -> dict:
    import matplotlib.pyplot as plt

    cycle = plt.get_cmap("tab10").colors
    return {k3: cycle[i % len(cycle)] for i, k3 in enumerate(sorted(k3s))}


def _k3_label(k3: float, labels: dict) -> str:
    extra = labels.get(k3)
    return f"k3 = {k3:.3g} N/m$^3$" + (f" ({extra})" if extra else "")


def contrast_bands(
    inter: pd.DataFrame, curves: pd.DataFrame | None, path: Path, labels: dict | None = None
) -> Path:
    """Relative interaction contrasts against Fc (mN), one panel per S, one band per k3.

    ``curves`` (optional) adds an analytic prediction, dashed
    (:func:`randvib.studies.contrasts.predicted_contrast_curves`, averaging);
    ``labels`` names some k3 values in the legend.
    """
    labels = labels or {}
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
            ax.plot(fc, y, "o-", color=colours[k3], ms=4, label=_k3_label(k3, labels))
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
    return save_figure(fig, path)


def linearisation_error_bands(table: pd.DataFrame, path: Path, labels: dict | None = None) -> Path:
    """Eq. 32's relative error against Fc (mN) with 95 % bars, one panel per S, one line per k3."""
    labels = labels or {}
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
                label=_k3_label(k3, labels),
            )
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_title(f"S = {psd:g} (m/s$^2$)$^2$/Hz", fontsize=10)
        ax.set_xlabel("Coulomb friction Fc (mN)")
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("Eq. 32 error (P$_{lin}$ - P$_{MC}$) / P$_{MC}$  (%)")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle("Equivalent linearisation error at every k3 (95 % CI)")
    fig.tight_layout()
    return save_figure(fig, path)


def _error_series(ax, sub, methods, style: int, shift: float, label: str) -> None:
    """One series of :func:`error_against_friction_level`: Eq. 32 solid, averaging dashed."""
    import matplotlib.pyplot as plt

    marker = "os^Dv<>p"[style % 8]
    colour = plt.get_cmap("tab10").colors[style % 10]
    ax.errorbar(
        sub.phi * shift,
        100 * sub.linearisation_rel_error,
        yerr=100 * sub.linearisation_rel_error_ci95,
        fmt=marker + "-",
        ms=4,
        capsize=2,
        color=colour,
        label=f"Eq. 32, {label}",
    )
    if "averaging" in methods:
        ax.errorbar(
            sub.phi * shift,
            100 * sub.averaging_rel_error,
            yerr=100 * sub.averaging_rel_error_ci95,
            fmt=marker + "--",
            mfc="none",
            ms=4,
            capsize=2,
            lw=0.8,
            color=colour,
            label=f"averaging, {label}",
        )


def error_against_friction_level(
    table: pd.DataFrame, methods, tolerances, path: Path, phi_ticks=(0.05, 0.2, 0.5, 0.89, 2.0, 5.0)
) -> Path:
    """Relative errors of the analytic ``methods`` against phi, one panel per k3.

    One series per (damping ratio zeta, S) with 95 % bars, green bands at
    the ``tolerances``, and a top axis giving Eq. 32's P / P(0) at
    ``phi_ticks``. ``table`` has ``phi``, ``zeta``, ``psd``, ``k3`` and the
    methods' ``_rel_error`` and ``_rel_error_ci95`` columns.
    """
    import matplotlib.pyplot as plt

    from randvib.studies.grids import power_ratio

    k3s = sorted(table.k3.unique())
    fig, axes = plt.subplots(1, len(k3s), figsize=(6.4 * len(k3s), 5.0), squeeze=False, sharey=True)
    keys = sorted({(z, s) for z, s in zip(table.zeta, table.psd, strict=True)}, reverse=True)
    style = {key: j for j, key in enumerate(keys)}
    ymin = min(-0.12, 1.1 * float(table[[f"{m}_rel_error" for m in methods]].min().min()))
    for ax, k3 in zip(axes[0], k3s, strict=True):
        for lo, alpha in zip(sorted(tolerances, reverse=True), (0.06, 0.08, 0.12), strict=False):
            ax.axhspan(-100 * lo, 100 * lo, color="tab:green", alpha=alpha, lw=0)
        for tol in tolerances:
            ax.axhline(-100 * tol, color="tab:green", lw=0.6, ls=":")
            ax.axhline(100 * tol, color="tab:green", lw=0.6, ls=":")
        groups = list(table[table.k3 == k3].groupby(["zeta", "psd"], sort=False))
        for j, ((zeta, psd), sub) in enumerate(groups):
            # small multiplicative offsets keep coincident series visible
            shift = 1.0 + 0.025 * (j - (len(groups) - 1) / 2)
            label = f"S = {psd:g}, zeta = {zeta:.3f}"
            _error_series(ax, sub.sort_values("phi"), methods, style[(zeta, psd)], shift, label)
        ax.set_xscale("log")
        ax.set_ylim(100 * ymin, 3.0)
        ax.set_xlabel("friction level phi = Fc / (c sigma$_{v0}$)")
        ax.set_title(f"k3 = {k3:.3g} N/m$^3$", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, loc="lower left")
        top = ax.secondary_xaxis("top", functions=(lambda p: p, lambda p: p))
        ticks = [p for p in phi_ticks if p <= table.phi.max() * 1.01]
        top.set_xticks(ticks, [f"{power_ratio(p):.2f}" for p in ticks], fontsize=7)
        top.set_xlabel("Eq. 32 P / P(0) at that phi", fontsize=8)
    axes[0, 0].set_ylabel("(P$_{method}$ - P$_{MC}$) / P$_{MC}$  (%), 95 % CI")
    fig.suptitle(
        "Error of equivalent linearisation (Eq. 32) and stochastic averaging against "
        "Monte Carlo; bands at ±"
        + ", ".join(f"{round(100 * t)}" for t in sorted(tolerances))
        + " %"
    )
    fig.tight_layout()
    return save_figure(fig, path)


#: Colour and line style of each analytic method (:data:`randvib.studies.methods.ANALYTIC`).
METHOD_STYLE = {
    "linearisation": ("C3", "-"),
    "averaging": ("C0", "-"),
    "fpk_fast": ("C1", "--"),
    "fpk": ("C2", ":"),
}


def method_errors_against_kappa(df: pd.DataFrame, labels: dict, path: Path) -> Path:
    """Relative error of every analytic method against kappa, one panel per S, a marker per k3.

    ``df`` has ``psd``, ``k3``, ``kappa``, ``mc_rel_ci95`` (drawn as a grey
    band) and ``err_{name}`` for each ``name`` of :data:`METHOD_STYLE`;
    ``labels`` names the methods in the legend.
    """
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    psds = sorted(df["psd"].unique(), reverse=True)
    k3s = sorted(df["k3"].unique())
    markers = dict(zip(k3s, "os^D", strict=False))
    fig, axes = plt.subplots(1, len(psds), figsize=(4.2 * len(psds), 3.8), sharey=True)
    axes = np.atleast_1d(axes)
    for ax, psd in zip(axes, psds, strict=True):
        sub = df[df["psd"] == psd]
        for k3 in k3s:
            s = sub[sub["k3"] == k3].sort_values("kappa")
            for name, (color, ls) in METHOD_STYLE.items():
                ax.plot(s["kappa"], 100 * s[f"err_{name}"], ls + markers[k3], color=color,
                        ms=3.5, lw=1)  # fmt: skip
        band = sub.groupby("kappa")["mc_rel_ci95"].max()
        ax.fill_between(band.index, -100 * band, 100 * band, color="0.8", zorder=-1)
        ax.axhline(0, color="k", lw=0.6)
        ax.axhspan(-3, 3, color="0.95", zorder=-2)
        ax.set_title(f"S = {psd:g} (m/s$^2$)$^2$/Hz")
        ax.set_xlabel(r"friction level $\kappa = 4F_c^2/(\pi S m c)$")
    axes[0].set_ylabel("error in E[P_e] vs Monte Carlo (%)")
    handles = [
        Line2D([], [], color=c, ls=ls, label=labels[n]) for n, (c, ls) in METHOD_STYLE.items()
    ]
    handles += [Line2D([], [], color="0.3", ls="", marker=markers[k3], label=f"k3 = {k3:g} N/m$^3$")
                for k3 in k3s]  # fmt: skip
    handles.append(plt.Rectangle((0, 0), 1, 1, color="0.8", label="MC 95 % CI"))
    fig.subplots_adjust(bottom=0.3)
    fig.legend(handles=handles, loc="lower center", ncol=5, fontsize=7, frameon=False,
               bbox_to_anchor=(0.5, 0.0))  # fmt: skip
    fig.suptitle("Error of E[P_e]: linearisation (Eq. 32), averaging and the FPK grids", y=1.03)
    return save_figure(fig, path)


def k3_change_against_kappa(df: pd.DataFrame, labels: dict, path: Path) -> Path:
    """The change of power with k3 at the largest k3 against kappa, one panel per S.

    Paired Monte Carlo (``dk3_mc`` with ``dk3_mc_ci95``) with 95 % bars, and
    every method's ``dk3_{name}`` as a line.
    """
    import matplotlib.pyplot as plt

    psds = sorted(df["psd"].unique(), reverse=True)
    k3s = sorted(df["k3"].unique())
    inter = df[df["k3"] == max(k3s)]
    fig, axes = plt.subplots(1, len(psds), figsize=(4.2 * len(psds), 3.6), sharey=True)
    axes = np.atleast_1d(axes)
    for ax, psd in zip(axes, psds, strict=True):
        s = inter[inter["psd"] == psd].sort_values("kappa")
        ax.errorbar(s["kappa"], 100 * s["dk3_mc"], 100 * s["dk3_mc_ci95"], fmt="ko", ms=4,
                    capsize=3, label="Monte Carlo (paired), 95 % CI")  # fmt: skip
        for name, (color, ls) in METHOD_STYLE.items():
            ax.plot(s["kappa"], 100 * s[f"dk3_{name}"], ls, color=color, label=labels[name])
        ax.axhline(0, color="k", lw=0.6)
        ax.set_title(f"S = {psd:g}")
        ax.set_xlabel(r"friction level $\kappa$")
    axes[0].set_ylabel(f"P(k3={max(k3s):g}) / P(k3={min(k3s):g}) - 1 (%)")
    axes[0].legend(fontsize=7)
    fig.suptitle("Duffing-Coulomb interaction: change of power with k3 at fixed Fc", y=1.03)
    return save_figure(fig, path)
