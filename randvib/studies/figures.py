"""Figures the studies share: power and contrasts against the Coulomb level or the bandwidth,
power against stroke exceedance, the methods' errors against the input level, the Gaussian
answer's errors under tones and non-Gaussian input.

Each function draws from a study's table, saves one PNG at ``path``
(:func:`randvib.figure_style.save_figure`) and returns the path; nothing
is computed here except the analytic curves drawn for comparison.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from randvib.analytic.prediction import METHODS, expected_power
from randvib.figure_style import colour, new_figure, num_tex, panel_letters, save_figure, styled


def _averaging_power(device, psd):
    """Stochastic averaging's E[P_e] (W), or None where the method is unavailable."""
    if "averaging" not in METHODS:
        return None
    try:
        return np.asarray(expected_power(device, psd, "averaging"), dtype=float)
    except Exception:  # noqa: BLE001 - the extra curve is optional
        return None


@styled
def power_against_friction(table: pd.DataFrame, base, psds, k3s, path: Path) -> Path:
    """Expected power (mW) and the methods' relative error (%) against Fc (mN), a column per S.

    Top row: the paper's Figure 9 (Monte Carlo with 95 % bars, a marker per
    k3, over Eq. 32 and stochastic averaging); bottom row: the relative
    errors of both methods against Monte Carlo with 95 % bars, where the
    few-percent differences of the claim are visible. ``table`` is a sweep
    table with ``psd``, ``k3``, ``fc``, ``power_electrical`` and its
    ``_ci95`` (W).
    """
    fig, axes = new_figure(2, len(psds), figsize=(3.0 * len(psds) + 0.6, 5.6), sharex="col")
    markers = dict(zip(sorted(k3s), "o^sD", strict=False))
    for col, psd in enumerate(psds):
        top, bottom = axes[0, col], axes[1, col]
        for j, k3 in enumerate(sorted(k3s)):
            sub = table[(table.psd == psd) & (table.k3 == k3)].sort_values("fc")
            fc = np.linspace(0, sub.fc.max(), 200)
            device = base.updated(k3=k3, fc=fc)
            c = colour(j)
            if j == 0:  # Eq. 32 does not depend on k3
                top.plot(1e3 * fc, 1e3 * expected_power(device, psd), "-", color="0.2", lw=1,
                         label="Eq. 32 (linearisation)", zorder=1)  # fmt: skip
            averaging = _averaging_power(device, psd)
            if averaging is not None:
                top.plot(1e3 * fc, 1e3 * averaging, "--", color=c, lw=1, zorder=2,
                         label=f"stochastic averaging, k$_3$ = {num_tex(k3)} N/m$^3$")  # fmt: skip
            # a small offset keeps the two springs' coincident markers apart
            shift = 1e3 * (j - (len(k3s) - 1) / 2) * 0.012 * sub.fc.max()
            top.errorbar(1e3 * sub.fc + shift, 1e3 * sub.power_electrical,
                         yerr=1e3 * sub.power_electrical_ci95, fmt=markers[k3], color=c,
                         mfc="none" if j else c, zorder=3,
                         label=f"Monte Carlo, k$_3$ = {num_tex(k3)} N/m$^3$")  # fmt: skip
            mc, ci = sub.power_electrical.to_numpy(), sub.power_electrical_ci95.to_numpy()
            at = base.updated(k3=k3, fc=sub.fc.to_numpy())
            lin = expected_power(at, psd)
            bottom.errorbar(1e3 * sub.fc + shift, 100 * (lin - mc) / mc, yerr=100 * ci / mc,
                            fmt=markers[k3] + "-", color=c, mfc="none" if j else c,
                            label=f"Eq. 32, k$_3$ = {num_tex(k3)} N/m$^3$")  # fmt: skip
            avg = _averaging_power(at, psd)
            if avg is not None:
                bottom.plot(1e3 * sub.fc + shift, 100 * (avg - mc) / mc, markers[k3] + "--",
                            color=c, mfc="none", lw=1,
                            label=f"averaging, k$_3$ = {num_tex(k3)} N/m$^3$")  # fmt: skip
        top.set_title(f"S = {psd:g} (m/s$^2$)$^2$/Hz")
        bottom.axhline(0.0, color="k", lw=0.6, zorder=1)
        bottom.set_xlabel("Coulomb friction $F_c$ (mN)")
    axes[0, 0].set_ylabel("E[$P_e$] (mW)")
    axes[1, 0].set_ylabel("(P$_{method}$ − P$_{MC}$) / P$_{MC}$ (%)")
    # one legend for both rows, below the panels (a second one inside (d) covered its points)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    more = axes[1, 0].get_legend_handles_labels()
    fig.legend(handles + more[0], labels + more[1], loc="outside lower center", ncol=3,
               fontsize=6)  # fmt: skip
    panel_letters(axes)
    return save_figure(fig, path)


@styled
def contrast_against_friction(inter: pd.DataFrame, title: str, path: Path) -> Path:
    """Relative interaction contrasts (%) against Fc (mN), one line per S, with 95 % bars.

    ``title`` names the spring in the axis title (e.g. "k3 = 5e5 N/m^3").
    """
    fig, axes = new_figure(figsize=(5.6, 3.6))
    ax = axes[0, 0]
    for j, psd in enumerate(sorted(inter.psd.unique(), reverse=True)):
        sub = inter[inter.psd == psd].sort_values("fc")
        ax.errorbar(1e3 * sub.fc, 100 * sub.relative_contrast, yerr=100 * sub.relative_ci95,
                    fmt="os^D"[j % 4] + "-", color=colour(j),
                    label=f"S = {psd:g} (m/s$^2$)$^2$/Hz")  # fmt: skip
    ax.axhline(0, color="k", lw=0.6, zorder=1)
    ax.set_xlabel("Coulomb friction $F_c$ (mN)")
    ax.set_ylabel("interaction contrast / P($F_c$, 0) (%)")
    ax.set_title(title)
    # below the axes: inside, it would hide error bars
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=3,
               title="Monte Carlo, paired paths, 95 % CI")  # fmt: skip
    return save_figure(fig, path)


def _colours(k3s) -> dict:
    return {k3: colour(i) for i, k3 in enumerate(sorted(k3s))}


def _k3_label(k3: float, labels: dict) -> str:
    extra = labels.get(k3)
    return f"k$_3$ = {num_tex(k3)} N/m$^3$" + (f" ({extra})" if extra else "")


@styled
def contrast_bands(
    inter: pd.DataFrame, curves: pd.DataFrame | None, path: Path, labels: dict | None = None
) -> Path:
    """Relative interaction contrasts against Fc (mN), one panel per S, one band per k3.

    The contrast is [P(Fc,k3) - P(Fc,0)] - [P(0,k3) - P(0,0)] over
    P(Fc, 0), Monte Carlo on paired paths with its 95 % band (in the
    legend). ``curves`` (optional) adds an analytic prediction, dashed
    (:func:`randvib.studies.contrasts.predicted_contrast_curves`, averaging);
    ``labels`` names some k3 values in the legend.
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    labels = labels or {}
    psds = sorted(inter.psd.unique(), reverse=True)
    k3s = sorted(inter.k3.unique())
    colours = _colours(k3s)
    fig, axes = new_figure(1, len(psds), figsize=(3.2 * len(psds) + 0.6, 3.6))
    for ax, psd in zip(axes[0], psds, strict=True):
        for j, k3 in enumerate(k3s):
            sub = inter[(inter.psd == psd) & (inter.k3 == k3)].sort_values("fc")
            # the contrast is zero by definition at Fc = 0
            fc = np.r_[0.0, sub.fc] * 1e3
            y = 100 * np.r_[0.0, sub.relative_contrast]
            ci = 100 * np.r_[0.0, sub.relative_ci95]
            ax.fill_between(fc, y - ci, y + ci, color=colours[k3], alpha=0.18, lw=0)
            ax.plot(fc, y, "os^Dv"[j % 5] + "-", color=colours[k3], ms=3.5, zorder=3)
            if curves is not None:
                cur = curves[(curves.psd == psd) & (curves.k3 == k3)]
                ax.plot(np.r_[0.0, cur.fc] * 1e3,
                        100 * np.r_[0.0, cur.averaging_relative_contrast], "--",
                        color=colours[k3], lw=1)  # fmt: skip
        ax.axhline(0.0, color="k", lw=0.6, zorder=1)
        ax.set_title(f"S = {psd:g} (m/s$^2$)$^2$/Hz")
        ax.set_xlabel("Coulomb friction $F_c$ (mN)")
    axes[0, 0].set_ylabel("interaction contrast / P($F_c$, 0) (%)")
    handles = [Line2D([], [], color=colours[k3], marker="os^Dv"[j % 5], ms=3.5,
                      label=_k3_label(k3, labels)) for j, k3 in enumerate(k3s)]  # fmt: skip
    handles.append(
        Patch(color="0.5", alpha=0.35, label="Monte Carlo 95 % band, series colour (paired paths)")
    )
    if curves is not None:
        handles.append(Line2D([], [], color="0.3", ls="--", lw=1,
                              label="stochastic averaging (prediction)"))  # fmt: skip
    fig.legend(handles=handles, loc="outside lower center", ncol=3)
    panel_letters(axes)
    return save_figure(fig, path)


@styled
def linearisation_error_bands(table: pd.DataFrame, path: Path, labels: dict | None = None) -> Path:
    """Eq. 32's relative error against Fc (mN) with 95 % bars, one panel per S, one line per k3."""
    labels = labels or {}
    psds = sorted(table.psd.unique(), reverse=True)
    k3s = sorted(table.k3.unique())
    colours = _colours(k3s)
    fig, axes = new_figure(1, len(psds), figsize=(3.2 * len(psds) + 0.6, 3.6), sharey=True)
    for ax, psd in zip(axes[0], psds, strict=True):
        for j, k3 in enumerate(k3s):
            sub = table[(table.psd == psd) & (table.k3 == k3) & (table.fc > 0)].sort_values("fc")
            # small horizontal offsets keep overlapping error bars apart
            shift = (j - (len(k3s) - 1) / 2) * 0.012 * sub.fc.max()
            ax.errorbar((sub.fc + shift) * 1e3, 100 * sub.linearisation_rel_error,
                        yerr=100 * sub.linearisation_rel_error_ci95, fmt="os^Dv"[j % 5] + "-",
                        ms=3.5, color=colours[k3], mfc="none" if j % 2 else colours[k3],
                        label=_k3_label(k3, labels))  # fmt: skip
        ax.axhline(0.0, color="k", lw=0.6, zorder=1)
        ax.set_title(f"S = {psd:g} (m/s$^2$)$^2$/Hz")
        ax.set_xlabel("Coulomb friction $F_c$ (mN)")
    axes[0, 0].set_ylabel("Eq. 32 error (P$_{lin}$ − P$_{MC}$) / P$_{MC}$ (%)")
    fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="outside lower center",
               ncol=min(len(k3s), 4), title="Monte Carlo 95 % CI as bars")  # fmt: skip
    panel_letters(axes)
    return save_figure(fig, path)


def _error_series(ax, sub, methods, style: int, shift: float, label: str) -> None:
    """One series of :func:`error_against_friction_level`: Eq. 32 solid, averaging dashed."""
    marker, c = "os^Dv<>p"[style % 8], colour(style)
    ax.errorbar(sub.phi * shift, 100 * sub.linearisation_rel_error,
                yerr=100 * sub.linearisation_rel_error_ci95, fmt=marker + "-", ms=3.5, color=c,
                label=f"Eq. 32, {label}", zorder=3)  # fmt: skip
    if "averaging" in methods:
        ax.errorbar(sub.phi * shift, 100 * sub.averaging_rel_error,
                    yerr=100 * sub.averaging_rel_error_ci95, fmt=marker + "--", mfc="none",
                    ms=3.5, lw=0.9, color=c, label=f"averaging, {label}", zorder=3)  # fmt: skip


@styled
def error_against_friction_level(
    table: pd.DataFrame, methods, tolerances, path: Path, phi_ticks=(0.05, 0.2, 0.5, 0.89, 2.0, 5.0)
) -> Path:
    """Relative errors of the analytic ``methods`` against phi, one panel per k3.

    One series per (damping ratio zeta, S) with 95 % bars, green bands at
    the ``tolerances`` (in the legend), and a top axis giving Eq. 32's
    P / P(0) at ``phi_ticks``. ``table`` has ``phi``, ``zeta``, ``psd``,
    ``k3`` and the methods' ``_rel_error`` and ``_rel_error_ci95`` columns.
    """
    from matplotlib.patches import Patch

    from randvib.studies.grids import power_ratio

    k3s = sorted(table.k3.unique())
    fig, axes = new_figure(1, len(k3s), figsize=(4.6 * len(k3s) + 0.6, 4.6), sharey=True)
    keys = sorted({(z, s) for z, s in zip(table.zeta, table.psd, strict=True)}, reverse=True)
    style = {key: j for j, key in enumerate(keys)}
    ymin = min(-0.12, 1.1 * float(table[[f"{m}_rel_error" for m in methods]].min().min()))
    bands = list(zip(sorted(tolerances, reverse=True), (0.08, 0.12, 0.18), strict=False))
    for ax, k3 in zip(axes[0], k3s, strict=True):
        for tol, alpha in bands:
            ax.axhspan(-100 * tol, 100 * tol, color=PALETTE_GREEN, alpha=alpha, lw=0, zorder=0)
        groups = list(table[table.k3 == k3].groupby(["zeta", "psd"], sort=False))
        for j, ((zeta, psd), sub) in enumerate(groups):
            # small multiplicative offsets keep coincident series visible
            shift = 1.0 + 0.025 * (j - (len(groups) - 1) / 2)
            label = f"S = {psd:g} (m/s$^2$)$^2$/Hz, ζ = {zeta:.3f}"
            _error_series(ax, sub.sort_values("phi"), methods, style[(zeta, psd)], shift, label)
        ax.set_xscale("log")
        ax.set_ylim(100 * ymin, 3.0)
        ax.set_xlabel(r"friction level $\varphi = F_c / (c\,\sigma_{v0})$")
        ax.grid(alpha=0.3, which="both")
        top = ax.secondary_xaxis("top", functions=(lambda p: p, lambda p: p))
        ticks = [p for p in phi_ticks if p <= table.phi.max() * 1.01]
        top.set_xticks(ticks, [f"{power_ratio(p):.2f}" for p in ticks])
        top.set_xlabel(f"Eq. 32 P / P(0) at that φ;  k$_3$ = {num_tex(k3)} N/m$^3$")
    axes[0, 0].set_ylabel("(P$_{method}$ − P$_{MC}$) / P$_{MC}$ (%), 95 % CI")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    for tol, _ in sorted(bands):
        # the bands are nested: inside ±tol, every wider band's shade lies underneath too
        alpha = 1.0 - float(np.prod([1.0 - a for t, a in bands if t >= tol]))
        handles.append(Patch(color=PALETTE_GREEN, alpha=alpha, lw=0))
        labels.append(f"|error| ≤ {100 * tol:g} %")
    fig.legend(handles, labels, loc="outside lower center", ncol=3)
    panel_letters(axes)
    return save_figure(fig, path)


#: Colour and line style of each analytic method (:data:`randvib.studies.methods.ANALYTIC`).
METHOD_STYLE = {
    "linearisation": (colour(1), "-"),
    "averaging": (colour(0), "-"),
    "fpk_fast": (colour(4), "--"),
    "fpk": (colour(2), ":"),
}

#: The colour of tolerance bands (the palette's bluish green).
PALETTE_GREEN = colour(2)


@styled
def method_errors_against_kappa(df: pd.DataFrame, labels: dict, path: Path) -> Path:
    """Relative error of every analytic method against kappa, one panel per S, a marker per k3.

    ``df`` has ``psd``, ``k3``, ``kappa``, ``mc_rel_ci95`` (drawn as a grey
    band) and ``err_{name}`` for each ``name`` of :data:`METHOD_STYLE`;
    ``labels`` names the methods in the legend. The FPK grids are drawn
    last, thinner, so that a curve they coincide with stays visible.
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    psds = sorted(df["psd"].unique(), reverse=True)
    k3s = sorted(df["k3"].unique())
    markers = dict(zip(k3s, "os^D", strict=False))
    fig, axes = new_figure(1, len(psds), figsize=(3.2 * len(psds) + 0.6, 3.8), sharey=True)
    for ax, psd in zip(axes[0], psds, strict=True):
        sub = df[df["psd"] == psd]
        for k3 in k3s:
            s = sub[sub["k3"] == k3].sort_values("kappa")
            for z, (name, (c, ls)) in enumerate(METHOD_STYLE.items()):
                ax.plot(s["kappa"], 100 * s[f"err_{name}"], ls + markers[k3], color=c, ms=3.5,
                        lw=1.4 - 0.2 * z, mfc="none" if z % 2 else c, zorder=2 + z)  # fmt: skip
        band = sub.groupby("kappa")["mc_rel_ci95"].max()
        ax.fill_between(band.index, -100 * band, 100 * band, color="0.8", zorder=0)
        ax.axhline(0, color="k", lw=0.6, zorder=1)
        ax.axhspan(-3, 3, color="0.94", zorder=-1)
        ax.set_title(f"S = {psd:g} (m/s$^2$)$^2$/Hz")
        ax.set_xlabel(r"friction level $\kappa = 4F_c^2/(\pi S m c)$")
    axes[0, 0].set_ylabel("error in E[$P_e$] against Monte Carlo (%)")
    handles = [
        Line2D([], [], color=c, ls=ls, label=labels[n]) for n, (c, ls) in METHOD_STYLE.items()
    ]
    handles += [Line2D([], [], color="0.3", ls="", marker=markers[k3],
                       label=f"k$_3$ = {num_tex(k3)} N/m$^3$") for k3 in k3s]  # fmt: skip
    handles.append(Patch(color="0.8", label="Monte Carlo 95 % CI"))
    handles.append(Patch(color="0.94", label="±3 %"))
    fig.legend(handles=handles, loc="outside lower center", ncol=4)
    panel_letters(axes)
    return save_figure(fig, path)


@styled
def k3_change_against_kappa(df: pd.DataFrame, labels: dict, path: Path) -> Path:
    """The change of power with k3 at the largest k3 against kappa, one panel per S.

    Paired Monte Carlo (``dk3_mc`` with ``dk3_mc_ci95``) with 95 % bars, and
    every method's ``dk3_{name}`` as a line.
    """
    psds = sorted(df["psd"].unique(), reverse=True)
    k3s = sorted(df["k3"].unique())
    inter = df[df["k3"] == max(k3s)]
    fig, axes = new_figure(1, len(psds), figsize=(3.2 * len(psds) + 0.6, 3.6), sharey=True)
    for ax, psd in zip(axes[0], psds, strict=True):
        s = inter[inter["psd"] == psd].sort_values("kappa")
        for z, (name, (c, ls)) in enumerate(METHOD_STYLE.items()):
            ax.plot(s["kappa"], 100 * s[f"dk3_{name}"], ls, color=c, lw=1.4 - 0.2 * z,
                    label=labels[name], zorder=2 + z)  # fmt: skip
        ax.errorbar(s["kappa"], 100 * s["dk3_mc"], 100 * s["dk3_mc_ci95"], fmt="ko", ms=3.5,
                    label="Monte Carlo (paired), 95 % CI", zorder=10)  # fmt: skip
        ax.axhline(0, color="k", lw=0.6, zorder=1)
        ax.set_title(f"S = {psd:g} (m/s$^2$)$^2$/Hz")
        ax.set_xlabel(r"friction level $\kappa = 4F_c^2/(\pi S m c)$")
    axes[0, 0].set_ylabel(
        f"P(k$_3$ = {num_tex(max(k3s))}) / P(k$_3$ = {num_tex(min(k3s))}) − 1 (%)"
    )
    fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="outside lower center", ncol=3)
    panel_letters(axes)
    return save_figure(fig, path)


def _bandwidth_axis(ax, zetas) -> None:
    """Log zeta axis, narrowing to the right, ticks at the given zetas only; a zero line."""
    from matplotlib.ticker import NullFormatter

    ticks = sorted(z for z in set(zetas) if np.isfinite(z))
    ax.set_xscale("log")
    ax.set_xlim(ticks[-1] * 1.3, ticks[0] / 1.3)  # reversed: the band narrows to the right
    ax.set_xticks(ticks, [f"{z:g}" for z in ticks])
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("band-pass damping ratio $\\zeta$ (narrower →)")
    ax.grid(alpha=0.3, which="major", lw=0.5)
    ax.axhline(0.0, color="0.5", lw=0.5)


@styled
def error_against_bandwidth(results: pd.DataFrame, centres, path: Path) -> Path:
    """Linearisation's relative error (%) against the band's zeta, a panel per k3, a line per centre.

    ``results`` has, per band (``centre``, ``zeta``; white noise as centre
    "white", drawn dotted) and device (``fc`` (N), ``k3``),
    ``linearisation_rel_error`` and its ``_ci95``; the rows with friction
    are drawn.
    """
    lin = results[results.fc > 0]
    k3s = sorted(lin.k3.unique())
    fig, axes = new_figure(1, len(k3s), figsize=(3.2 * len(k3s) + 0.4, 3.4), sharey=True)
    for ax, k3 in zip(axes[0], k3s, strict=True):
        for centre in centres:
            sub = lin[(lin.centre == centre) & (lin.k3 == k3)].sort_values("zeta")
            ax.errorbar(sub.zeta, 100 * sub.linearisation_rel_error,
                        yerr=100 * sub.linearisation_rel_error_ci95, marker="o", ms=4, capsize=2,
                        label=f"centre {centre} f$_n$")  # fmt: skip
        for error in lin[(lin.centre == "white") & (lin.k3 == k3)].linearisation_rel_error[:1]:
            ax.axhline(100 * error, color="k", ls=":", lw=1, label="white noise")
        _bandwidth_axis(ax, lin.zeta)
        fc = 1e3 * lin[lin.k3 == k3].fc.iloc[0]
        ax.set_title(f"F$_c$ = {fc:g} mN, k$_3$ = {num_tex(k3)} N/m$^3$", fontsize=9)
    axes[0, 0].set_ylabel("linearisation error in E[P$_e$] (%)")
    fig.legend(
        *axes[0, 0].get_legend_handles_labels(), loc="outside lower center", ncol=4, fontsize=7
    )  # fmt: skip  (below the panels, off the data)
    panel_letters(axes)
    return save_figure(fig, path)


@styled
def contrast_against_bandwidth(inter: pd.DataFrame, centres, labels: dict, path: Path) -> Path:
    """Relative interaction contrast (%) against the band's zeta, a panel per centre, a line per k3.

    ``inter`` holds the contrasts of :func:`randvib.studies.contrasts.paired_interactions`
    per band (``centre``, ``zeta``) with ``linearisation_relative_contrast``
    (dashed); ``labels`` names some k3 values in the legend.
    """
    fig, axes = new_figure(1, len(centres), figsize=(10, 3.6), sharey=True)
    for ax, centre in zip(axes[0], centres, strict=True):
        for i, k3 in enumerate(sorted(inter.k3.unique())):
            sub = inter[(inter.centre == centre) & (inter.k3 == k3)].sort_values("zeta")
            ax.errorbar(sub.zeta, 100 * sub.relative_contrast, yerr=100 * sub.relative_ci95,
                        marker="o", ms=4, capsize=2, color=colour(i),
                        label=_k3_label(k3, labels))  # fmt: skip
            ax.plot(sub.zeta, 100 * sub.linearisation_relative_contrast, "--", color=colour(i),
                    lw=1)  # fmt: skip
        _bandwidth_axis(ax, inter.zeta)
        ax.set_title(f"band centred {centre} the linear resonance", fontsize=9)
    axes[0, 0].set_ylabel("interaction contrast / P(F$_c$, 0) (%)")
    fig.legend(
        *axes[0, 0].get_legend_handles_labels(),
        loc="outside lower center",
        ncol=4,
        fontsize=7,
        title="markers: Monte Carlo (95 %); dashed: linearisation",
        title_fontsize=7,
    )  # fmt: skip  (below the panels, off the data)
    panel_letters(axes)
    return save_figure(fig, path)


def _math(label: str) -> str:
    """A table's label in a figure: the natural frequency f_n typeset as $f_n$."""
    return label.replace("f_n", "$f_n$")


def _level_text(g: float) -> str:
    """A level factor as written in the tables: 1/16 for 0.0625, 4 for 4."""
    return f"1/{1 / g:g}" if g < 1 else f"{g:g}"


@styled
def power_against_exceedance(
    results: pd.DataFrame, devices, budget: float, stroke: float, path: Path
) -> Path:
    """Power against stroke exceedance over the levels, a panel per input, a line per device.

    ``results`` holds per ``input``, level ``g`` and ``device`` the Monte
    Carlo ``power_mc`` (W) and ``exceedance_mc`` (fraction of time with
    |z| > ``stroke`` (m)) with their ``_ci95``; the ``budget`` is a
    vertical line. A colour per device joins its levels; a marker shape per
    level g. A point whose paths never passed the stroke (exceedance 0, off a
    logarithmic axis) is drawn hollow at the axis' left edge, not dropped.
    """
    from matplotlib.lines import Line2D
    from matplotlib.ticker import LogLocator

    inputs = list(dict.fromkeys(results.input))
    levels = sorted(results.g.unique())
    shapes = dict(zip(levels, "osD^vph*", strict=False))
    positive = results.exceedance_mc[results.exceedance_mc > 0]
    # the left edge: a decade below the smallest exceedance seen (or the budget's)
    edge = 0.1 * min(float(positive.min()) if len(positive) else budget, budget)
    fig, axes = new_figure(1, len(inputs), figsize=(3.6 * len(inputs), 3.9), sharey=True)
    for ax, name in zip(axes[0], inputs, strict=True):
        for i, dev in enumerate(devices):
            sub = results[(results.input == name) & (results.device == dev)].sort_values("g")
            zero = (sub.exceedance_mc <= 0).to_numpy()
            # devices staggered about the edge (factors 1.4 apart, within 0.6-1.7 x edge
            # for three devices): two devices with the same power at the edge would
            # otherwise draw one hollow marker over the other
            stagger = 1.4 ** (i - (len(devices) - 1) / 2)
            x = np.where(zero, edge * stagger, sub.exceedance_mc)
            # the line joins measured exceedances only: a hollow edge point is no value
            ax.plot(x[~zero], 1e3 * sub.power_mc[~zero], "-", color=colour(i), lw=1.2)
            for (_, row), at, hollow in zip(sub.iterrows(), x, zero, strict=True):
                ax.errorbar(at, 1e3 * row.power_mc,
                            xerr=None if hollow else row.exceedance_mc_ci95,
                            yerr=1e3 * row.power_mc_ci95, marker=shapes[row.g], ms=4, capsize=2,
                            color=colour(i), mfc="white" if hollow else colour(i))  # fmt: skip
        ax.axvline(budget, color="k", ls=":", lw=1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(left=0.6 * edge / 1.4 ** max(0.0, (len(devices) - 3) / 2))
        for axis in (ax.xaxis, ax.yaxis):
            # minor ticks at 2 and 5 only: on a narrow range all eight minor labels collide
            axis.set_minor_locator(LogLocator(subs=(2.0, 5.0)))
        ax.set_xlabel(f"fraction of time with |z| > {1e3 * stroke:g} mm")
        ax.set_title(_math(name), fontsize=9)
        ax.grid(alpha=0.3, lw=0.5)
    axes[0, 0].set_ylabel("E[P$_e$] (mW), Monte Carlo")
    handles = [Line2D([], [], color=colour(i), lw=1.2, label=dev) for i, dev in enumerate(devices)]
    handles += [Line2D([], [], ls="none", marker=shapes[g], ms=4, color="0.3",
                       label=f"g = {_level_text(g)}") for g in levels]  # fmt: skip
    handles += [
        Line2D([], [], ls="none", marker="o", ms=4, color="0.3", mfc="white",
               label="hollow: never beyond (0), drawn at the left edge"),
        Line2D([], [], color="k", ls=":", lw=1, label=f"budget: {100 * budget:g} % of the time"),
    ]  # fmt: skip
    fig.legend(handles=handles, loc="outside lower center", ncol=4, fontsize=7,
               title="lines: devices; markers: input level g (95 % CI bars)",
               title_fontsize=7)  # fmt: skip
    panel_letters(axes)
    return save_figure(fig, path)


@styled
def method_errors_against_level(methods: pd.DataFrame, devices, path: Path) -> Path:
    """Relative errors of the methods against the level g, power and exceedance, a marker per device.

    ``methods`` is a table of :func:`randvib.studies.methods.methods_against_monte_carlo`
    with the level ``g`` and ``device`` among its labels. A colour per
    method, a marker per device, 95 % bars; the error axis is linear while
    every error is within ±10 %, symmetric-log beyond.
    """
    from matplotlib.ticker import FuncFormatter, NullFormatter

    fig, axes = new_figure(1, 2, figsize=(9, 3.8))
    markers = dict(zip(devices, "osD^v", strict=False))
    levels = sorted(methods.g.unique())
    for ax, q in zip(axes[0], ("power", "exceedance"), strict=True):
        for i, (method, rows) in enumerate(methods.groupby("method", sort=False)):
            for dev, sub in rows.dropna(subset=[f"{q}_rel_error"]).groupby("device"):
                ax.errorbar(sub.g * (1.04**i), 100 * sub[f"{q}_rel_error"],
                            yerr=100 * sub[f"{q}_rel_error_ci95"], ls="none", marker=markers[dev],
                            ms=3.5, capsize=1.5, color=colour(i),
                            label=f"{method}, {dev}")  # fmt: skip
        ax.axhline(0.0, color="0.5", lw=0.5, zorder=1)
        ax.set_xscale("log")
        ax.set_xticks(levels, [f"{g:g}" for g in levels])
        ax.xaxis.set_minor_formatter(NullFormatter())
        reach = (methods[f"{q}_rel_error"].abs() + methods[f"{q}_rel_error_ci95"]).max()
        if 100 * reach > 10:
            ax.set_yscale("symlog", linthresh=10)
            # 1-2-4 steps on both sides: a reader can place -40 % or +200 %
            ticks = [0.0, 5.0] + [m * 10.0**d for d in range(1, 6) for m in (1, 2, 4)]
            ticks = sorted({t * sign for t in ticks for sign in (1, -1)})
            bottom, top = ax.get_ylim()
            ax.set_yticks([t for t in ticks if bottom <= t <= top])
            ax.yaxis.set_major_formatter(FuncFormatter(lambda y, _: f"{y:g}"))
            ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("level factor g (all inputs)")
        ax.set_ylabel(f"error in {q} against Monte Carlo (%)")
    handles, labels = {}, []
    for ax in axes[0]:
        for h, label in zip(*ax.get_legend_handles_labels(), strict=True):
            if label not in handles:
                handles[label] = h
                labels.append(label)
    fig.legend([handles[k] for k in labels], labels, loc="outside lower center", ncol=4,
               title="colour: method; marker: device; bars: 95 % CI")  # fmt: skip
    panel_letters(axes)
    return save_figure(fig, path)


@styled
def gaussian_errors(table: pd.DataFrame, x: str, xlabel: str, panels: str | None, path: Path,
                    tolerance: float = 0.05) -> Path:  # fmt: skip
    """The Gaussian answer's relative error against Monte Carlo, power (top) and exceedance (bottom).

    ``table`` has ``device``, ``fc``, ``x`` and, for each quantity,
    ``{power,exceedance}_error`` and ``_error_ci95``
    (:func:`randvib.studies.gaussian_error.with_errors`); one column of
    panels per value of ``panels`` (None: one), a colour per device, solid
    with friction and dashed without, 95 % bars; the band of +-``tolerance``
    shaded. The error axis is symmetric-log beyond +-10 %.
    """
    groups = [(None, table)] if panels is None else list(table.groupby(panels, sort=False))
    fig, axes = new_figure(2, len(groups), figsize=(3.4 * len(groups) + 1.5, 6.0), sharex=True)
    devices = list(dict.fromkeys(table.device))
    for col, (key, sub) in enumerate(groups):
        for row, q in enumerate(("power", "exceedance")):
            ax = axes[row, col]
            ax.axhspan(-100 * tolerance, 100 * tolerance, color="0.9", zorder=0)
            ax.axhline(0.0, color="0.5", lw=0.5, zorder=1)
            for (dev, fc), s in sub.dropna(subset=[f"{q}_error"]).groupby(
                ["device", "fc"], sort=False
            ):
                s = s.sort_values(x)
                ax.errorbar(s[x], 100 * s[f"{q}_error"], yerr=100 * s[f"{q}_error_ci95"],
                            color=colour(devices.index(dev)), ls="-" if fc > 0 else "--",
                            marker="o" if fc > 0 else "s", ms=3, capsize=1.5, lw=1,
                            label=f"{dev}, {'Fc = ' + f'{1e3 * fc:g} mN' if fc > 0 else 'no friction'}")  # fmt: skip
            if (sub[f"{q}_error"].abs() > 0.1).any():
                ax.set_yscale("symlog", linthresh=10)
            ax.set_ylabel(f"Gaussian {q} error (%)" if col == 0 else "")
            if row == 0 and key is not None:
                ax.set_title(f"{panels} {key}", loc="right", fontsize=8)
        axes[1, col].set_xlabel(xlabel)
    handles, labels = {}, []
    for ax in axes.ravel():
        for h, label in zip(*ax.get_legend_handles_labels(), strict=True):
            if label not in handles:
                handles[label] = h
                labels.append(label)
    fig.legend([handles[k] for k in labels], labels, loc="outside lower center", ncol=3,
               title=f"bars: 95 % CI of Monte Carlo; grey: +-{100 * tolerance:g} %")  # fmt: skip
    panel_letters(axes)
    return save_figure(fig, path)
