"""The paper's two claims under narrow-band excitation: ``randvib study excitation``.

(or ``python studies/excitation.py OUT [--quick]``). The paper's analysis
assumes white noise, under which the spring cannot matter for a resistive
harvester (c E[v^2] + E[vF] = S m / 4 for any k3). Real base motion is often
narrow-band. This study drives the figure9 device (preset ``figure9``:
c_m = c_e = 0.1 Ns/m, k = 57.4 N/m, linear resonance f_n = 8.02 Hz,
m = 0.0226 kg assumed) with second-order band-pass noise
(:class:`randvib.BandPass`) centred at, below (f_n / 1.25) and above
(1.25 f_n) the linear resonance, with the filter's damping ratio zeta from
0.5 (broad) down to 0.02 (a band 2 zeta f0 = 0.3 Hz wide, a fifth of the
device's own half-power bandwidth).

**Response-matched level.** Each band's peak level S is chosen so that the
linear device (no friction, no spring) has the same E[z'^2] as under the
paper's white noise of S = 1 (m/s^2)^2/Hz; the Coulomb level Fc = 5.8 mN
(the paper's) is then equally strong relative to the motion everywhere, and
the comparison isolates the band's shape.

**(1) Equivalent linearisation against Monte Carlo.** At every point,
statistical linearisation (Gaussian closure: c_eq from E[vF]/E[v^2],
k_eq = k + 3 k3 E[z^2], variances from the Lyapunov equation of device and
filter; :func:`randvib.statistical_linearisation`) is compared with Monte
Carlo (:func:`randvib.simulate` with the filter's states, Heun), its
relative error with a 95 % interval.

**(2) The Duffing-Coulomb interaction.** At Fc = 5.8 mN and
k3 = 5e5 N/m^3 (the paper's Figure 9) up to 5e7 (100x), the contrast

    [P(Fc, k3) - P(Fc, 0)] - [P(0, k3) - P(0, 0)]

is estimated from the four devices run on the same paths (same seed: same
Brownian increments and filter states; the per-path difference, Student t
over paths), relative to P(Fc, 0), with Holm's correction over the family.
Under coloured input the second bracket is no longer zero by theory, so all
four points are simulated. Statistical linearisation's prediction of the same
contrast (which, unlike Eq. 32, depends on k3 under coloured input) is shown
beside it. The same contrast under white noise (S = 1) is the reference.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import special

import randvib as rv
from randvib._progress import progress_bar
from randvib.analytic.linear_response import mechanical_block, output_variances
from randvib.figure_style import colour as style_colour
from randvib.figure_style import new_figure, num_tex, panel_letters, save_figure, styled
from randvib.statistics import estimate, holm_significant, two_sided_p_value
from randvib.studies import script_main
from randvib.studies.report import (
    markdown_table,
    plus_minus,
    prepare_output_dir,
    write_report,
    write_table,
    write_verdicts,
)

NAME = "excitation"
FC = 0.0058  #: N, the paper's Coulomb level (Table 2, training data 1)
ZETAS = (0.5, 0.2, 0.1, 0.05, 0.02)
K3S = (0.0, 5e5, 5e6, 5e7)
K3_LABELS = {5e5: "Fig. 9", 5e6: "10x Fig. 9", 5e7: "100x Fig. 9"}
#: Band centre relative to the linear resonance f_n.
CENTRES = {"below": 1 / 1.25, "at": 1.0, "above": 1.25}
#: Monte Carlo: (paths, time per path incl. burn-in (s), dt (s), burn-in (s)).
FULL_MC = (512, 31.0, 2e-4, 1.0)
QUICK_MC = (128, 11.0, 2e-4, 1.0)
#: A contrast below this fraction of P(Fc, 0) is called practically absent even if detected.
PRACTICAL = 0.01

__all__ = ["grid", "matched_excitation", "run_study"]


def grid(quick: bool) -> dict:
    """The study's axes: band centres, zetas, k3 values and the Monte Carlo sizes."""
    if quick:
        return {"centres": tuple(CENTRES), "zetas": (0.5, 0.1, 0.02), "k3s": (0.0, 5e5, 5e7),
                "mc": QUICK_MC}  # fmt: skip
    return {"centres": tuple(CENTRES), "zetas": ZETAS, "k3s": K3S, "mc": FULL_MC}


def matched_excitation(base: rv.Harvester, centre: str, zeta: float) -> rv.BandPass:
    """Band-pass noise whose linear response E[z'^2] equals white noise S = 1's, S m / (4 c)."""
    f_n = np.sqrt(base.k / base.m) / (2 * np.pi)
    shape = rv.BandPass(1.0, CENTRES[centre] * f_n, zeta)
    linear = output_variances(mechanical_block(base.m, base.c, base.k), shape)["v"]
    return rv.BandPass(base.m / (4 * base.c) / linear, shape.f0, zeta)


# ----------------------------------------------------------------- compute
def _cases(base, axes):
    """(centre label, zeta, excitation) per band, the white-noise reference last."""
    cases = [(c, z, matched_excitation(base, c, z)) for c in axes["centres"] for z in axes["zetas"]]
    return cases + [("white", np.inf, rv.White(1.0))]


def simulate_case(base, excitation, k3s, mc, seed, threads):
    """Every (Fc, k3) device under one excitation on the same paths: rows and per-path powers."""
    n_paths, t_end, dt, burn = mc
    rows, per_path = [], {}
    for fc in (0.0, FC):
        for k3 in k3s:
            device = base.updated(fc=fc, k3=k3)
            r = rv.simulate(
                device, excitation, t_end=t_end, dt=dt, n_paths=n_paths, burn_in=burn,
                seed=seed, threads=threads, progress=False,
            )  # fmt: skip
            sl = rv.statistical_linearisation(device, excitation)
            per_path[(fc, k3)] = device.c_e * r.averages.v2
            p = r.power_electrical
            rows.append({
                "fc": fc, "k3": k3, "power_mc": p.mean, "power_mc_ci95": p.ci95,
                "n_paths": p.n_paths, "power_linearisation": sl.power_electrical,
                "k_eq": sl.k_eq, "c_eq": sl.c_eq,
                "linearisation_rel_error": sl.power_electrical / p.mean - 1.0,
                "linearisation_rel_error_ci95": sl.power_electrical * p.ci95 / p.mean**2,
            })  # fmt: skip
    return rows, per_path


def contrast_rows(per_path, rows, k3s) -> list[dict]:
    """Paired interaction contrasts at Fc = FC for every k3 > 0, Monte Carlo and linearisation."""
    lin = {(r["fc"], r["k3"]): r["power_linearisation"] for r in rows}
    out = []
    for k3 in k3s[1:]:
        s = estimate(
            per_path[(FC, k3)] - per_path[(FC, 0.0)] - per_path[(0.0, k3)] + per_path[(0.0, 0.0)]
        )
        reference = float(np.mean(per_path[(FC, 0.0)]))
        predicted = lin[(FC, k3)] - lin[(FC, 0.0)] - lin[(0.0, k3)] + lin[(0.0, 0.0)]
        spring_alone = estimate(per_path[(0.0, k3)] - per_path[(0.0, 0.0)])
        out.append({
            "k3": k3, "contrast": s.mean, "contrast_ci95": s.ci95, "reference": reference,
            "relative_contrast": s.mean / reference, "relative_ci95": s.ci95 / reference,
            "p_value": two_sided_p_value(s), "n_paths": s.n_paths,
            "linearisation_relative_contrast": predicted / lin[(FC, 0.0)],
            "spring_alone_relative": spring_alone.mean / float(np.mean(per_path[(0.0, 0.0)])),
        })  # fmt: skip
    return out


def compute(base, axes, seed, threads, progress) -> tuple[pd.DataFrame, pd.DataFrame]:
    """results.csv (every device and band) and contrasts.csv (every band and k3 > 0)."""
    cases = _cases(base, axes)
    bar = None
    if progress:
        bar = progress_bar(len(cases), desc=NAME, unit="band")
    results, contrasts = [], []
    for i, (centre, zeta, excitation) in enumerate(cases):
        head = {"centre": centre, "f0": getattr(excitation, "f0", np.nan), "zeta": zeta,
                "level": excitation.level}  # fmt: skip
        rows, per_path = simulate_case(base, excitation, axes["k3s"], axes["mc"], seed * 1000 + i,
                                       threads)  # fmt: skip
        results += [{**head, **r} for r in rows]
        contrasts += [{**head, **r} for r in contrast_rows(per_path, rows, axes["k3s"])]
        if bar is not None:
            bar.update()
    if bar is not None:
        bar.close()
    inter = pd.DataFrame(contrasts)
    banded = inter.centre != "white"
    inter["detectable"] = inter.p_value < 0.05
    inter["detectable_holm"] = False
    inter.loc[banded, "detectable_holm"] = holm_significant(inter.p_value[banded])
    inter["breaks_no_interaction"] = inter.detectable_holm & (
        inter.relative_contrast.abs() >= PRACTICAL
    )
    return pd.DataFrame(results), inter


# ----------------------------------------------------------------- verdicts
def verdicts(results: pd.DataFrame, inter: pd.DataFrame) -> dict:
    """The numbers behind the report's verdicts, computed from the two tables."""
    lin = results[(results.fc > 0) & (results.centre != "white")]
    by_zeta = lin.groupby("zeta").linearisation_rel_error.agg(lambda e: float(e.abs().max()))
    worst = lin.loc[lin.linearisation_rel_error.abs().idxmax()]
    exact = results[(results.fc == 0) & (results.k3 == 0)]
    z_exact = (exact.power_linearisation - exact.power_mc) / (
        exact.power_mc_ci95 / special.stdtrit(exact.n_paths - 1, 0.975)
    )
    band = inter[inter.centre != "white"]
    breaks = band[band.breaks_no_interaction]
    largest = band.loc[band.relative_contrast.abs().idxmax()]
    white = inter[inter.centre == "white"]
    holds_down_to = {
        f"{centre}, k3={k3:g}": _holds_down_to(sub)
        for (centre, k3), sub in band.groupby(["centre", "k3"])
    }
    return {
        "linearisation": {
            "largest_abs_error_by_zeta": {f"{z:g}": v for z, v in by_zeta.items()},
            "largest_abs_error": float(abs(worst.linearisation_rel_error)),
            "where_largest": f"{worst.centre} resonance, zeta = {worst.zeta:g}, k3 = {worst.k3:g}",
            "largest_ci95": float(worst.linearisation_rel_error_ci95),
            "white_noise_errors": [
                float(e)
                for e in results[
                    (results.centre == "white") & (results.fc > 0)
                ].linearisation_rel_error
            ],
            "linear_device_exact_max_abs_z": float(np.abs(z_exact).max()),
        },  # fmt: skip
        "interaction": {
            "n_contrasts": int(len(band)),
            "n_detectable_holm": int(band.detectable_holm.sum()),
            "n_breaks": int(len(breaks)),
            "practical_threshold": PRACTICAL,
            "breaks": [
                {
                    "centre": r.centre,
                    "zeta": float(r.zeta),
                    "k3": float(r.k3),
                    "relative_contrast": float(r.relative_contrast),
                    "relative_ci95": float(r.relative_ci95),
                }
                for r in breaks.itertuples()
            ],  # fmt: skip
            "by_k3": {f"{k3:g}": _range_of(sub) for k3, sub in band.groupby("k3")},
            "largest_relative_contrast": float(largest.relative_contrast),
            "largest_relative_ci95": float(largest.relative_ci95),
            "where_largest": f"{largest.centre}, zeta = {largest.zeta:g}, k3 = {largest.k3:g}",
            "white_relative_contrasts": {
                f"{r.k3:g}": [float(r.relative_contrast), float(r.relative_ci95)]
                for r in white.itertuples()
            },  # fmt: skip
            "no_interaction_holds_down_to_zeta": holds_down_to,
        },
    }


def _range_of(sub: pd.DataFrame) -> dict:
    """Breaks, the contrast's range and where it is smallest in magnitude, for one k3."""
    small = sub.loc[sub.relative_contrast.abs().idxmin()]
    return {
        "n_breaks": int(sub.breaks_no_interaction.sum()),
        "n_points": int(len(sub)),
        "min_relative_contrast": float(sub.relative_contrast.min()),
        "max_relative_contrast": float(sub.relative_contrast.max()),
        "smallest_abs": float(small.relative_contrast),
        "smallest_abs_ci95": float(small.relative_ci95),
        "smallest_abs_where": f"{small.centre}, zeta = {small.zeta:g}",
    }


def _holds_down_to(sub: pd.DataFrame) -> float | None:
    """Narrowest zeta down to which (from the broadest band) no contrast breaks no-interaction."""
    held = None
    for row in sub.sort_values("zeta", ascending=False).itertuples():
        if row.breaks_no_interaction:
            break
        held = float(row.zeta)
    return held


# ----------------------------------------------------------------- figures
def _band_label(zeta) -> str:
    return "white" if not np.isfinite(zeta) else f"{zeta:g}"


def _zeta_axis(ax, zetas) -> None:
    """Log zeta axis, narrowing to the right, ticks at the study's zetas only."""
    from matplotlib.ticker import NullFormatter

    ticks = sorted(z for z in set(zetas) if np.isfinite(z))
    ax.set_xscale("log")
    ax.set_xlim(ticks[-1] * 1.3, ticks[0] / 1.3)  # reversed: the band narrows to the right
    ax.set_xticks(ticks, [f"{z:g}" for z in ticks])
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("band-pass damping ratio $\\zeta$ (narrower →)")
    ax.grid(alpha=0.3, which="major", lw=0.5)


@styled
def linearisation_figure(results: pd.DataFrame, path: Path) -> Path:
    """Linearisation's relative error against zeta, one panel per k3 (Fc = FC), a line per centre."""
    lin = results[results.fc > 0]
    k3s = sorted(lin.k3.unique())
    fig, axes = new_figure(1, len(k3s), figsize=(3.2 * len(k3s) + 0.4, 3.4), sharey=True)
    for ax, k3 in zip(axes[0], k3s, strict=True):
        for centre in CENTRES:
            sub = lin[(lin.centre == centre) & (lin.k3 == k3)].sort_values("zeta")
            ax.errorbar(sub.zeta, 100 * sub.linearisation_rel_error,
                        yerr=100 * sub.linearisation_rel_error_ci95, marker="o", ms=4, capsize=2,
                        label=f"centre {centre} f$_n$")  # fmt: skip
        white = lin[(lin.centre == "white") & (lin.k3 == k3)]
        if len(white):
            ax.axhline(100 * white.linearisation_rel_error.iloc[0], color="k", ls=":", lw=1,
                       label="white noise")  # fmt: skip
        ax.axhline(0.0, color="0.5", lw=0.5)
        _zeta_axis(ax, lin.zeta)
        ax.set_title(f"F$_c$ = {1e3 * FC:g} mN, k$_3$ = {num_tex(k3)} N/m$^3$", fontsize=9)
    axes[0, 0].set_ylabel("linearisation error in E[P$_e$] (%)")
    axes[0, 0].legend(fontsize=7)
    panel_letters(axes)
    return save_figure(fig, path)


@styled
def interaction_figure(inter: pd.DataFrame, path: Path) -> Path:
    """Relative interaction contrast against zeta, one panel per centre, a line per k3."""
    fig, axes = new_figure(1, len(CENTRES), figsize=(10, 3.6), sharey=True)
    for ax, centre in zip(axes[0], CENTRES, strict=True):
        for i, k3 in enumerate(sorted(inter.k3.unique())):
            colour = style_colour(i)
            sub = inter[(inter.centre == centre) & (inter.k3 == k3)].sort_values("zeta")
            label = f"k$_3$ = {num_tex(k3)} N/m$^3$ ({K3_LABELS.get(k3, '')})"
            ax.errorbar(sub.zeta, 100 * sub.relative_contrast, yerr=100 * sub.relative_ci95,
                        marker="o", ms=4, capsize=2, color=colour, label=label)  # fmt: skip
            ax.plot(sub.zeta, 100 * sub.linearisation_relative_contrast, "--", color=colour,
                    lw=1)  # fmt: skip
        ax.axhline(0.0, color="0.5", lw=0.5)
        _zeta_axis(ax, inter.zeta)
        ax.set_title(f"band centred {centre} the linear resonance", fontsize=9)
    axes[0, 0].set_ylabel("interaction contrast / P(F$_c$, 0) (%)")
    axes[0, 0].legend(fontsize=7, title="markers: Monte Carlo (95 %); dashed: linearisation",
                   title_fontsize=7)  # fmt: skip
    panel_letters(axes)
    return save_figure(fig, path)


def spectra_figure(base, axes, seed, threads, path: Path) -> Path:
    """Where the power comes from: spectra at resonance, narrowest band, k3 = 0 and the largest."""
    n_paths, t_end, dt, burn = axes["mc"]
    excitation = matched_excitation(base, "at", min(axes["zetas"]))
    series = {}
    for k3 in (0.0, max(axes["k3s"])):
        device = base.updated(fc=FC, k3=k3)
        r = rv.simulate(device, excitation, t_end=t_end, dt=dt, n_paths=32, burn_in=burn,
                        seed=seed, threads=threads, record_paths=32, record_every=10,
                        progress=False)  # fmt: skip
        mc = r.response_spectra(segment_duration=min(4.0, (t_end - burn) / 2))
        series[f"k$_3$ = {num_tex(k3)} N/m$^3$, Monte Carlo"] = mc
        lin = rv.statistical_linearisation(device, excitation).response_spectra(mc.frequency)
        series[f"k$_3$ = {num_tex(k3)} N/m$^3$, linearisation"] = lin
    return rv.plot_response_spectra(series, excitation=excitation, path=path)


# ----------------------------------------------------------------- report
def setup_section(axes, results, seed, quick, wall) -> str:
    n_paths, t_end, dt, burn = axes["mc"]
    levels = results.drop_duplicates(["centre", "zeta"])[["centre", "f0", "zeta", "level"]]
    return (
        "Device: preset `figure9` (c_m = c_e = 0.1 Ns/m, k = 57.4 N/m, m = 0.0226 kg assumed; "
        f"linear resonance 8.02 Hz), Coulomb Fc = 0 and {1e3 * FC:g} mN, k3 = "
        + ", ".join(f"{k:g}" for k in axes["k3s"])
        + " N/m^3. Band-pass input (peak S at f0, half-power bandwidth 2 zeta f0), peak level "
        "matched so that the linear device's E[z'^2] equals that under white noise S = 1 "
        "(levels below). Monte Carlo: Heun with the filter's two states, "
        f"dt = {dt:g} s, {n_paths} paths x {t_end - burn:g} s after {burn:g} s burn-in, "
        f"seed {seed} (one seed per band, shared by its eight devices: paired). "
        f"{'Quick mode. ' if quick else ''}Wall time {wall:.0f} s.\n\n"
        + markdown_table(levels, floatfmt=".4g")
    )


def linearisation_section(results, v, figure) -> str:
    lin = v["linearisation"]
    shown = results[["centre", "zeta", "fc", "k3"]].copy()
    shown["fc"] = 1e3 * shown.fc
    shown = shown.rename(columns={"fc": "Fc (mN)"})
    shown["P_MC (mW)"] = plus_minus(results.power_mc, results.power_mc_ci95, 1e3, ".4f")
    shown["P_lin (mW)"] = [f"{1e3 * p:.4f}" for p in results.power_linearisation]
    shown["lin. error (%)"] = plus_minus(
        results.linearisation_rel_error, results.linearisation_rel_error_ci95
    )
    shown["k_eq / k"] = results.k_eq / 57.4
    by_zeta = ", ".join(
        f"{100 * e:.1f} % at zeta = {z}" for z, e in lin["largest_abs_error_by_zeta"].items()
    )
    white = ", ".join(f"{100 * e:+.2f} %" for e in lin["white_noise_errors"])
    return (
        f"![linearisation error]({figure.name})\n\n"
        f"**Verdict.** With friction, statistical linearisation's largest error against Monte "
        f"Carlo is {100 * lin['largest_abs_error']:.1f} % (± {100 * lin['largest_ci95']:.1f} %, "
        f"{lin['where_largest']}); largest magnitude per band: {by_zeta}. Under white noise "
        f"(S = 1) the same devices give {white}. The linear device (no friction, no spring) "
        "is exact for both methods, a check of the Monte Carlo: the largest |z| of the "
        f"difference is {lin['linear_device_exact_max_abs_z']:.2f}.\n\n"
        + markdown_table(shown, floatfmt=".3g")
    )


def interaction_section(inter, v, figure) -> str:
    it = v["interaction"]
    per_k3 = "; ".join(
        f"k3 = {k3}: {r['n_breaks']} of {r['n_points']}, contrast {100 * r['min_relative_contrast']:+.1f} "
        f"to {100 * r['max_relative_contrast']:+.1f} %, smallest "
        f"{100 * r['smallest_abs']:+.2f} ± {100 * r['smallest_abs_ci95']:.2f} % ({r['smallest_abs_where']})"
        for k3, r in it["by_k3"].items()
    )
    verdict = (
        f'"No interaction" fails at {it["n_breaks"]} of {it["n_contrasts"]} band points '
        f"(Holm-detectable and at least {100 * PRACTICAL:g} % of P(Fc, 0); "
        f"{it['n_detectable_holm']} Holm-detectable). By k3: {per_k3}."
    )
    white = ", ".join(
        f"k3 = {k}: {100 * c:+.2f} ± {100 * h:.2f} %"
        for k, (c, h) in it["white_relative_contrasts"].items()
    )
    holds = "; ".join(
        f"{key}: {'none' if z is None else f'zeta >= {z:g}'}"
        for key, z in it["no_interaction_holds_down_to_zeta"].items()
    )
    shown = inter[["centre", "zeta", "k3"]].copy()
    shown["contrast / P(Fc,0) (%)"] = plus_minus(inter.relative_contrast, inter.relative_ci95)
    shown["linearisation (%)"] = [f"{100 * x:+.2f}" for x in inter.linearisation_relative_contrast]
    shown["spring alone, Fc = 0 (%)"] = [f"{100 * x:+.2f}" for x in inter.spring_alone_relative]
    shown["p"] = inter.p_value
    shown["Holm"] = inter.detectable_holm
    return (
        f"![interaction]({figure.name})\n\n**Verdict.** {verdict} The largest contrast is "
        f"{100 * it['largest_relative_contrast']:+.1f} ± {100 * it['largest_relative_ci95']:.1f} % "
        f"of P(Fc, 0) ({it['where_largest']}). Under white noise (S = 1): {white}. "
        f"Bands down to which no interaction holds (broadest first): {holds}.\n\n"
        "Under a narrow band the spring moves the resonance (k_eq) against the band, so "
        "P(0, k3) - P(0, 0) is no longer zero (column 'spring alone'); the contrast asks "
        "whether friction changes that effect.\n\n" + markdown_table(shown, floatfmt=".3g")
    )


# ----------------------------------------------------------------- the study
def tables_of(out, base, axes, seed, threads, progress):
    """results.csv and contrasts.csv: computed, or resumed from a run of the same identity."""
    files = out / "results.csv", out / "contrasts.csv"
    if all(f.exists() for f in files):
        return tuple(pd.read_csv(f) for f in files)
    results, inter = compute(base, axes, seed, threads, progress)
    write_table(out, "results.csv", results)
    write_table(out, "contrasts.csv", inter)
    return results, inter


def run_study(
    out_dir, *, quick=False, seed=0, workers=None, threads=None, scheduler=None, progress=True
) -> Path:
    """Run the excitation study and write ``report.md``, CSVs, figures and ``verdicts.json``.

    ``quick``: three bands per centre and three springs, 128 paths (about a
    minute on one core); ``threads``: numba threads; ``workers`` is accepted
    and unused (in-process); ``scheduler`` is not supported.
    """
    if scheduler is not None:
        raise ValueError(
            f"study {NAME!r} runs its Monte Carlo in-process on local threads; `scheduler` "
            f"is not supported (got {scheduler!r}); use `threads` instead"
        )
    base = rv.preset("figure9")
    axes = grid(quick)
    out = prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed, **axes})
    started = time.perf_counter()
    results, inter = tables_of(out, base, axes, seed, threads, progress)
    v = verdicts(results, inter)
    fig_lin = linearisation_figure(results, out / "linearisation_error.png")
    fig_inter = interaction_figure(inter, out / "interaction.png")
    spectra_figure(base, axes, seed, threads, out / "spectra.png")
    write_verdicts(out, v)
    wall = time.perf_counter() - started
    return write_report(
        out,
        f"Study {NAME}: the paper's claims under narrow-band excitation{' (quick)' * quick}",
        [
            ("Set-up", setup_section(axes, results, seed, quick, wall)),
            (
                "Equivalent linearisation against Monte Carlo",
                linearisation_section(results, v, fig_lin),
            ),
            ("Duffing-Coulomb interaction", interaction_section(inter, v, fig_inter)),
            (
                "Where the power comes from",
                "![spectra](spectra.png)\n\nResponse spectra at the linear resonance, narrowest "
                f"band, Fc = {1e3 * FC:g} mN, without and with the stiffest spring: Monte Carlo "
                "(Welch on 32 recorded paths, 95 % band) and statistical linearisation.",
            ),
        ],
    )


if __name__ == "__main__":
    sys.exit(script_main(run_study))
