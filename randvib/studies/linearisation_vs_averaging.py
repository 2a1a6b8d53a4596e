"""Study ``linearisation-vs-averaging``: analytic power predictions against Monte Carlo.

Grid: the figure9 device (c_m = c_e = 0.1 Ns/m, k = 57.4 N/m, m = 0.0226 kg
assumed), S in {1, 0.5, 0.1} (m/s^2)^2/Hz, k3 in {0, 7.07e4 (paper), 5e5,
7e6 (~100x)} N/m^3 and Coulomb levels set by the dimensionless friction level

    kappa = 4 Fc^2 / (pi S m c)

(the group of paper Eq. 30: Eq. 32 predicts P(kappa)/P(0) = 1/(1 + kappa +
sqrt(kappa (2 + kappa))), half power at kappa = 1/4), from 0 to 2 (about a
fifth of the friction-free power).

At every point: E[P_e] from equivalent linearisation (Eq. 32), stochastic
averaging (:mod:`randvib.analytic.averaging`), the fast corrected FPK grids
(``method="fpk-fast"``, :func:`randvib.analytic.fokker_planck.fast_fpk_statistics`),
the FPK reference grid solution (:func:`randvib.analytic.fokker_planck.fpk_statistics`)
and Monte Carlo (:func:`randvib.simulate`, stochastic Heun, with the
energy-identity and friction-free-companion control variates). Relative
errors are taken against Monte Carlo. The two fast candidates of issue 6
(averaging and fpk-fast) are judged against its criteria: speed (one point
under 10 ms, a 100-point sweep under 1 s, timed in the run), at most a third
of linearisation's error where that exceeds 3 %, at most 5 % everywhere, and
the k3 interaction's sign and size inside the Monte Carlo interval.

The k3 interaction, P(Fc, k3) / P(Fc, 0) - 1, is estimated from paired runs:
all k3 values at one (S, kappa) share their Brownian paths (same seed and
streams), and the per-path differences, with both runs' control variates,
give its mean and 95 % interval.
"""

from __future__ import annotations

import json
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from randvib._io import atomic_write_text, prepare_output_dir
from randvib.analytic.averaging import AveragingValidityWarning, averaging_statistics
from randvib.analytic.fokker_planck import fast_fpk_statistics, fpk_statistics
from randvib.analytic.linearisation import equivalent_damping
from randvib.analytic.prediction import expected_power
from randvib.models.presets import preset
from randvib.montecarlo import kernel
from randvib.montecarlo.simulation import estimate, simulate, step_bias
from randvib.studies.report import markdown_table

NAME = "linearisation-vs-averaging"
PSDS = (1.0, 0.5, 0.1)
K3S = (0.0, 7.07e4, 5e5, 7e6)
KAPPAS = (0.0, 0.1, 0.25, 0.5, 1.0, 2.0)

#: Analytic methods: column suffix -> (method name in randvib.METHODS, label).
ANALYTIC = {
    "linearisation": ("linearisation", "linearisation (Eq. 32)"),
    "averaging": ("averaging", "averaging"),
    "fpk_fast": ("fpk-fast", "fast FPK"),
    "fpk": ("fpk", "FPK grid (reference)"),
}
#: The fast methods judged against issue 6's criteria.
CANDIDATES = ("averaging", "fpk_fast")
#: Issue 6's speed bars: one point (s) and a 100-point sweep (s).
POINT_BAR, SWEEP_BAR = 10e-3, 1.0

#: Monte Carlo sizes: (paths, simulated time per path (s), dt (s), burn-in (s)).
FULL_MC = (256, 80.0, 2.5e-4, 2.0)
QUICK_MC = (64, 40.0, 5e-4, 2.0)


def grid(quick: bool) -> tuple[tuple, tuple, tuple]:
    """(psds, kappas, k3s) of the study."""
    if quick:
        return (1.0, 0.1), (0.0, 0.5, 2.0), (0.0, 7e6)
    return PSDS, KAPPAS, K3S


def fc_of_kappa(kappa, psd, device):
    """Coulomb level Fc (N) for the friction level kappa = 4 Fc^2/(pi S m c)."""
    return float(np.sqrt(kappa * np.pi * psd * device.m * device.c / 4.0))


def _analytic(device, psd) -> dict:
    c_e = device.c_e
    lin_vv = psd * device.m / (4.0 * float(equivalent_damping(device, psd)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AveragingValidityWarning)
        avg = averaging_statistics(device, psd)
    fpk_vv = fpk_statistics(device, psd, 160)[0]
    return {
        "power_linearisation": c_e * lin_vv,
        "power_averaging": c_e * avg.velocity_variance,
        "power_fpk_fast": c_e * fast_fpk_statistics(device, psd)[0],
        "power_fpk": c_e * fpk_vv,
        "zeta_eff": avg.zeta_eff,
        "zeta_friction": avg.zeta_friction,
    }


def _simulate_column(psd, kappa, k3s, base, mc, seed, threads):
    """All k3 at one (S, kappa), sharing Brownian paths; rows and paired contrasts."""
    n_paths, t_sim, dt, burn_in = mc
    rows, per_path, controls = [], {}, {}
    for k3 in k3s:
        device = base.updated(k3=k3, fc=fc_of_kappa(kappa, psd, base))
        started = time.perf_counter()
        res = simulate(
            device,
            psd,
            t_end=burn_in + t_sim,
            dt=dt,
            n_paths=n_paths,
            burn_in=burn_in,
            seed=seed,
            companion=True,
            control_variates=True,
            threads=threads,
            progress=False,
        )
        power = res.power_electrical
        row = {
            "psd": psd,
            "kappa": kappa,
            "fc": float(device.friction.fc),
            "k3": k3,
            "power_mc": power.mean,
            "power_mc_ci95": power.ci95,
            "step_bias": abs(step_bias("heun", device, psd, dt)),
            "n_paths": n_paths,
            "mc_seconds": time.perf_counter() - started,
        }
        row.update(_analytic(device, psd))
        rows.append(row)
        per_path[k3] = device.c_e * res.column(kernel.ACC_V2)
        controls[k3] = res.controls()
    k0 = k3s[0]
    for row in rows:
        k3 = row["k3"]
        ref = next(r for r in rows if r["k3"] == k0)
        if k3 == k0:
            row["dk3_mc"], row["dk3_mc_ci95"] = 0.0, 0.0
            continue
        diff = estimate(per_path[k3] - per_path[k0], np.hstack([controls[k3], controls[k0]]))
        row["dk3_mc"] = diff.mean / ref["power_mc"]
        row["dk3_mc_ci95"] = diff.ci95 / ref["power_mc"]
    return rows


def compute_table(quick: bool, seed: int, threads, progress: bool) -> pd.DataFrame:
    base = preset("figure9")
    psds, kappas, k3s = grid(quick)
    mc = QUICK_MC if quick else FULL_MC
    columns = [(psd, kappa) for psd in psds for kappa in kappas]
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(
            total=len(columns), desc=NAME, unit="column", disable=None
        )  # None: terminals only
    rows = []
    for i, (psd, kappa) in enumerate(columns):
        # A fresh seed per (S, kappa) column; shared within it (paired k3).
        rows += _simulate_column(psd, kappa, k3s, base, mc, seed * 1000 + i, threads)
        if bar is not None:
            bar.update()
    if bar is not None:
        bar.close()
    return _derived(pd.DataFrame(rows))


def _derived(df: pd.DataFrame) -> pd.DataFrame:
    """Errors against MC and the analytic k3 changes P(k3)/P(k3_min) - 1 per (S, kappa)."""
    df = df.copy()
    ref = df.groupby(["psd", "kappa"])["k3"].transform("min")
    base = df[df["k3"] == ref].set_index(["psd", "kappa"])
    key = pd.MultiIndex.from_frame(df[["psd", "kappa"]])
    for name in ANALYTIC:
        df[f"err_{name}"] = df[f"power_{name}"] / df["power_mc"] - 1.0
        df[f"dk3_{name}"] = df[f"power_{name}"] / base[f"power_{name}"].reindex(key).values - 1.0
    df["mc_rel_ci95"] = df["power_mc_ci95"] / df["power_mc"]
    return df


def _fill_missing_analytic(df: pd.DataFrame) -> pd.DataFrame:
    """Add analytic columns a table written by an older version lacks (fpk-fast)."""
    missing = [name for name in ANALYTIC if f"power_{name}" not in df]
    if not missing:
        return df
    df = df.copy()
    base = preset("figure9")
    for name in missing:
        method = ANALYTIC[name][0]
        df[f"power_{name}"] = [
            float(expected_power(base.updated(k3=r.k3, fc=r.fc), r.psd, method))
            for r in df.itertuples()
        ]
    return _derived(df)


def time_methods(repeats: int = 3) -> dict:
    """Best wall time (s) of one point and of a 100-point broadcast sweep per candidate.

    The point is the figure9 device at S = 1, kappa = 1, k3 = 5e5; the sweep
    covers kappa in [0, 2] (25 levels) x the four k3 of the study at S = 1.
    """
    base = preset("figure9")
    point = base.updated(k3=5e5, fc=fc_of_kappa(1.0, 1.0, base))
    fc = np.array([fc_of_kappa(x, 1.0, base) for x in np.linspace(0.0, 2.0, 25)])
    sweep = base.updated(fc=fc[None, :], k3=np.array(K3S)[:, None])
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AveragingValidityWarning)
        for name in CANDIDATES:
            method = ANALYTIC[name][0]
            for label, device in (("point", point), ("sweep100", sweep)):
                best = np.inf
                for _ in range(repeats):
                    started = time.perf_counter()
                    expected_power(device, 1.0, method)
                    best = min(best, time.perf_counter() - started)
                out[f"{name}_{label}_s"] = best
    return out


def verdicts(df: pd.DataFrame, timings: dict | None = None) -> dict:
    """Issue 6's acceptance criteria, evaluated on the table for each candidate.

    Keys per candidate ``name`` (``averaging``, ``fpk_fast``):
    ``{name}_third_where_lin_over_3pct`` and ``{name}_worst_ratio_where_lin_over_3pct``
    (its |error| over linearisation's, worst case), ``max_err_{name}``,
    ``{name}_within_5pct``, ``interaction_{name}_inside`` and
    ``interaction_{name}_sign_ok`` (counts), ``{name}_interaction_met``, and
    with ``timings`` (:func:`time_methods`) ``{name}_fast_enough``. The
    averaging keys keep their old short names too (``avg_...``).
    """
    lin = df["err_linearisation"].abs()
    big = lin > 0.03
    inter = df[df["k3"] > df["k3"].min()]
    # Interval for the predicted change: MC 95 % interval widened by the two
    # runs' time-step bias bounds (the pairing does not cancel them exactly).
    width = inter["dk3_mc_ci95"] + inter["step_bias"] + df["step_bias"].min()
    significant = inter["dk3_mc"].abs() > width
    out = {
        "points": len(df),
        "lin_over_3pct": int(big.sum()),
        "max_err_linearisation": float(lin.max()),
        "max_err_fpk": float(df["err_fpk"].abs().max()),
        "max_mc_rel_ci95": float(df["mc_rel_ci95"].max()),
        "interaction_points": len(inter),
        "interaction_significant": int(significant.sum()),
    }
    for name in ANALYTIC:
        err = df[f"err_{name}"].abs()
        out[f"max_err_{name}"] = float(err.max())
        inside = (inter[f"dk3_{name}"] - inter["dk3_mc"]).abs() <= width
        sign_ok = ~significant | (np.sign(inter[f"dk3_{name}"]) == np.sign(inter["dk3_mc"]))
        out[f"interaction_{name}_inside"] = int(inside.sum())
        out[f"interaction_{name}_sign_ok"] = int(sign_ok.sum())
        if name == "linearisation":
            continue
        ratio = (err[big] / lin[big]).max() if big.any() else 0.0
        out[f"{name}_worst_ratio_where_lin_over_3pct"] = float(ratio)
        out[f"{name}_third_where_lin_over_3pct"] = bool(np.all(err[big] <= lin[big] / 3.0))
        out[f"{name}_within_5pct"] = bool(np.all(err <= 0.05))
        out[f"{name}_interaction_met"] = bool(inside.all() and sign_ok.all())
        if timings and f"{name}_point_s" in timings:
            out[f"{name}_fast_enough"] = bool(
                timings[f"{name}_point_s"] < POINT_BAR and timings[f"{name}_sweep100_s"] < SWEEP_BAR
            )
    out["avg_third_where_lin_over_3pct"] = out["averaging_third_where_lin_over_3pct"]
    out["avg_within_5pct"] = out["averaging_within_5pct"]
    return out


_STYLE = {
    "linearisation": ("C3", "-"),
    "averaging": ("C0", "-"),
    "fpk_fast": ("C1", "--"),
    "fpk": ("C2", ":"),
}


def _plots(df: pd.DataFrame, out: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    psds = sorted(df["psd"].unique(), reverse=True)
    k3s = sorted(df["k3"].unique())
    markers = dict(zip(k3s, "os^D", strict=False))
    paths = []

    fig, axes = plt.subplots(1, len(psds), figsize=(4.2 * len(psds), 3.8), sharey=True)
    axes = np.atleast_1d(axes)
    for ax, psd in zip(axes, psds, strict=True):
        sub = df[df["psd"] == psd]
        for k3 in k3s:
            s = sub[sub["k3"] == k3].sort_values("kappa")
            for name, (color, ls) in _STYLE.items():
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
        Line2D([], [], color=c, ls=ls, label=ANALYTIC[n][1]) for n, (c, ls) in _STYLE.items()
    ]
    handles += [Line2D([], [], color="0.3", ls="", marker=markers[k3], label=f"k3 = {k3:g} N/m$^3$")
                for k3 in k3s]  # fmt: skip
    handles.append(plt.Rectangle((0, 0), 1, 1, color="0.8", label="MC 95 % CI"))
    fig.subplots_adjust(bottom=0.3)
    fig.legend(handles=handles, loc="lower center", ncol=5, fontsize=7, frameon=False,
               bbox_to_anchor=(0.5, 0.0))  # fmt: skip
    fig.suptitle("Error of E[P_e]: linearisation (Eq. 32), averaging and the FPK grids", y=1.03)
    paths.append(out / "error_vs_friction.png")
    fig.savefig(paths[-1], dpi=120, bbox_inches="tight")
    plt.close(fig)

    inter = df[df["k3"] == max(k3s)]
    fig, axes = plt.subplots(1, len(psds), figsize=(4.2 * len(psds), 3.6), sharey=True)
    axes = np.atleast_1d(axes)
    for ax, psd in zip(axes, psds, strict=True):
        s = inter[inter["psd"] == psd].sort_values("kappa")
        ax.errorbar(s["kappa"], 100 * s["dk3_mc"], 100 * s["dk3_mc_ci95"], fmt="ko", ms=4,
                    capsize=3, label="Monte Carlo (paired), 95 % CI")  # fmt: skip
        for name, (color, ls) in _STYLE.items():
            ax.plot(s["kappa"], 100 * s[f"dk3_{name}"], ls, color=color, label=ANALYTIC[name][1])
        ax.axhline(0, color="k", lw=0.6)
        ax.set_title(f"S = {psd:g}")
        ax.set_xlabel(r"friction level $\kappa$")
    axes[0].set_ylabel(f"P(k3={max(k3s):g}) / P(k3={min(k3s):g}) - 1 (%)")
    axes[0].legend(fontsize=7)
    fig.suptitle("Duffing-Coulomb interaction: change of power with k3 at fixed Fc", y=1.03)
    paths.append(out / "interaction.png")
    fig.savefig(paths[-1], dpi=120, bbox_inches="tight")
    plt.close(fig)
    return paths


def _yes(flag) -> str:
    return "**met**" if flag else "**not met**"


def _criteria_table(df: pd.DataFrame, v: dict, timings: dict) -> str:
    n_int = v["interaction_points"]
    rows = []
    if timings:
        rows.append(
            ["one point < 10 ms, 100-point sweep < 1 s"]
            + [
                f"{_yes(v[f'{n}_fast_enough'])}: {1e3 * timings[f'{n}_point_s']:.2f} ms, "
                f"{timings[f'{n}_sweep100_s']:.3f} s"
                for n in CANDIDATES
            ]
        )
    rows.append(
        [f"|error| <= 1/3 of linearisation's where that is > 3 % ({v['lin_over_3pct']} points)"]
        + [
            f"{_yes(v[f'{n}_third_where_lin_over_3pct'])}: worst ratio "
            f"{v[f'{n}_worst_ratio_where_lin_over_3pct']:.3f}"
            for n in CANDIDATES
        ]
    )
    rows.append(
        [f"|error| <= 5 % at all {v['points']} points"]
        + [
            f"{_yes(v[f'{n}_within_5pct'])}: max {100 * v[f'max_err_{n}']:.2f} %"
            for n in CANDIDATES
        ]
    )
    rows.append(
        ["k3 interaction: sign and size inside the MC interval"]
        + [
            f"{_yes(v[f'{n}_interaction_met'])}: inside at {v[f'interaction_{n}_inside']} of "
            f"{n_int}, sign right at {v[f'interaction_{n}_sign_ok']} of {n_int}"
            for n in CANDIDATES
        ]
    )
    headers = ["criterion (issue 6)"] + [ANALYTIC[n][1] for n in CANDIDATES]
    return markdown_table(pd.DataFrame(rows, columns=headers), floatfmt="g")


def _monotone(df: pd.DataFrame, column: str, by, along: str, sign: int) -> bool:
    """|column| strictly rising (sign = 1) or falling (-1) along ``along`` in every group."""
    groups = [g.sort_values(along)[column].abs().to_numpy() for _, g in df.groupby(by)]
    return all(np.all(sign * np.diff(g) > 0) for g in groups if len(g) > 1)


def reading(df: pd.DataFrame, timings: dict | None = None) -> str:
    """The report's reading of the table, each statement computed from it.

    Statements: the sign of linearisation's error and whether it grows with
    kappa; averaging's error as a share of linearisation's and whether it
    shrinks with k3; averaging's k3 change against the FPK reference's (sign,
    over- or understated); the largest Monte Carlo k3 change; how closely the
    fast FPK grids follow the reference, and their time per point.
    """
    fr = df[df["kappa"] > 0]
    if fr.empty:
        return "no point with friction on this grid."
    lin = fr["err_linearisation"]
    parts = ["the exact energy balance c E[z'^2] + Fc E|z'| = S m/4 means all methods differ "
             "only in E|z'|."]  # fmt: skip
    if (lin < 0).all():
        sign = "underestimates the power at every point with friction"
    elif (lin > 0).all():
        sign = "overestimates the power at every point with friction"
    else:
        sign = (
            f"underestimates the power at {int((lin < 0).sum())} of {len(lin)} points with friction"
        )
    grows = _monotone(fr, "err_linearisation", ["psd", "k3"], "kappa", 1)
    parts.append(
        f"Linearisation's Gaussian E|z'| = sqrt(2/pi) sigma_v {sign}"
        + (", increasingly with kappa" if grows else ", not monotonically in kappa")
        + " (Eq. 30 has no k3, so it predicts no k3 dependence)."
    )
    share = (fr["err_averaging"].abs() / lin.abs().where(lin.abs() > 0)).max()
    shrinks = df["k3"].nunique() > 1 and _monotone(fr, "err_averaging", ["psd", "kappa"], "k3", -1)
    parts.append(
        f"Averaging takes E|z'| from the non-Gaussian energy density: its |error| is at most "
        f"{share:.2f} times linearisation's"
        + (
            ", and shrinks as k3 raises the orbit frequency."
            if shrinks
            else ", and does not shrink steadily with k3."
        )  # fmt: skip
    )
    top = fr[fr["k3"] == df["k3"].max()]
    if df["k3"].nunique() > 1 and not top.empty:
        same_sign = bool((np.sign(top["dk3_averaging"]) == np.sign(top["dk3_fpk"])).all())
        ratio = (top["dk3_averaging"] / top["dk3_fpk"]).to_numpy()
        size = (
            f"overstates it ({ratio.min():.1f}-{ratio.max():.1f}x)"
            if (ratio > 1).all()
            else f"understates it ({ratio.min():.2f}-{ratio.max():.2f}x)"
            if (ratio < 1).all()
            else f"over- and understates it ({ratio.min():.2f}-{ratio.max():.2f}x)"
        )
        mc = top["dk3_mc"].abs().max()
        parts.append(
            f"At k3 = {df['k3'].max():g} averaging {size} relative to the FPK reference, "
            + ("with the right sign" if same_sign else "with the wrong sign at some points")
            + f"; the Monte Carlo change of power with k3 is at most {100 * mc:.2f} % there."
        )
    fast = (df["power_fpk_fast"] / df["power_fpk"] - 1).abs().max()
    speed = (
        f", at {1e3 * timings['fpk_fast_point_s']:.1f} ms a point"
        if timings and "fpk_fast_point_s" in timings
        else ""
    )
    parts.append(
        "The fast FPK method solves the same Fokker-Planck equation as the reference on small "
        "corrected grids; it follows the reference to within "
        f"{100 * fast:.3f} % at every point{speed}."
    )
    return " ".join(parts)


def _report(
    df: pd.DataFrame, v: dict, timings: dict, quick: bool, mc, wall: float, out: Path
) -> Path:
    def pct(x):
        return f"{100 * x:+.2f}"

    table = df.assign(
        **{
            "P_mc (W)": df["power_mc"].map("{:.4g}".format),
            "MC ci95 %": (100 * df["mc_rel_ci95"]).map("{:.2f}".format),
            "lin err %": df["err_linearisation"].map(pct),
            "avg err %": df["err_averaging"].map(pct),
            "fast FPK err %": df["err_fpk_fast"].map(pct),
            "FPK err %": df["err_fpk"].map(pct),
            "zeta_f": df["zeta_friction"].map("{:.3f}".format),
        }
    )[["psd", "kappa", "fc", "k3", "P_mc (W)", "MC ci95 %", "lin err %", "avg err %",
       "fast FPK err %", "FPK err %", "zeta_f"]]  # fmt: skip
    inter_rows = df[df["k3"] > df["k3"].min()]
    width = inter_rows["dk3_mc_ci95"] + inter_rows["step_bias"] + df["step_bias"].min()

    def mark(name):
        inside = (inter_rows[f"dk3_{name}"] - inter_rows["dk3_mc"]).abs() <= width
        return (100 * inter_rows[f"dk3_{name}"]).map("{:+.3f}".format) + np.where(
            inside, "", " (out)"
        )

    inter = inter_rows.assign(
        **{
            "psd": inter_rows["psd"].map("{:g}".format),
            "kappa": inter_rows["kappa"].map("{:g}".format),
            "k3": inter_rows["k3"].map("{:g}".format),
            "MC %": (100 * inter_rows["dk3_mc"]).map("{:+.3f}".format)
            + " ± "
            + (100 * width).map("{:.3f}".format),
            "averaging %": mark("averaging"),
            "fast FPK %": mark("fpk_fast"),
            "FPK %": mark("fpk"),
        }
    )[["psd", "kappa", "k3", "MC %", "averaging %", "fast FPK %", "FPK %"]]
    n_paths, t_sim, dt, burn = mc
    met = [ANALYTIC[n][1] for n in CANDIDATES if all(
        v.get(f"{n}_{key}", True)
        for key in ("fast_enough", "third_where_lin_over_3pct", "within_5pct", "interaction_met")
    )]  # fmt: skip
    summary = (
        f"All criteria met by: {', '.join(met)}." if met else "No candidate meets every criterion."
    )
    lines = [
        f"# Study {NAME}{' (quick)' if quick else ''}",
        "",
        "Figure9 device (c_m = c_e = 0.1 Ns/m, k = 57.4 N/m, m = 0.0226 kg assumed), "
        "Coulomb friction at levels kappa = 4 Fc^2/(pi S m c) (Eq. 30's group; half power "
        "by Eq. 32 at kappa = 0.25). Errors of E[P_e] relative to Monte Carlo "
        f"({n_paths} paths x {t_sim:g} s, dt = {dt:g} s, stochastic Heun, control variates; "
        f"largest time-step bias bound {100 * df['step_bias'].max():.3f} %). "
        f"Monte Carlo time {df['mc_seconds'].sum():.0f} s; this report {wall:.0f} s.",
        "",
        "## Verdicts",
        "",
        "Issue 6's criteria for a fast method, per candidate (times measured in this run; "
        "the interaction interval is the paired MC 95 % interval widened by the two runs' "
        "time-step bias bounds):",
        "",
        _criteria_table(df, v, timings),
        "",
        summary,
        "",
        f"- Largest |error| vs MC: linearisation {100 * v['max_err_linearisation']:.2f} %, "
        f"averaging {100 * v['max_err_averaging']:.2f} %, fast FPK "
        f"{100 * v['max_err_fpk_fast']:.2f} %, FPK reference {100 * v['max_err_fpk']:.2f} % "
        f"(largest MC 95 % half-width {100 * v['max_mc_rel_ci95']:.2f} %).",
        f"- k3 interaction, P(Fc, k3)/P(Fc, k3 = {df['k3'].min():g}) - 1 at "
        f"{v['interaction_points']} points ({v['interaction_significant']} significantly "
        "non-zero in MC): inside the interval for averaging "
        f"{v['interaction_averaging_inside']}, fast FPK {v['interaction_fpk_fast_inside']}, "
        f"FPK reference {v['interaction_fpk_inside']}, linearisation "
        f"{v['interaction_linearisation_inside']} (it predicts no change at all).",
        "",
        "Reading: " + reading(df, timings),
        "",
        "![errors](error_vs_friction.png)",
        "",
        "![interaction](interaction.png)",
        "",
        "## Errors of E[P_e] against Monte Carlo",
        "",
        markdown_table(table),
        "",
        "## Change of power with k3 at fixed Fc (paired Monte Carlo)",
        "",
        "MC: mean ± the widened interval used by the verdict; '(out)' marks a prediction "
        "outside it.",
        "",
        markdown_table(inter, floatfmt="g", numparse=False),
        "",
        "Files: `results.csv` (every column), the two PNG figures, `metadata.json`.",
        "",
    ]
    path = out / "report.md"
    atomic_write_text(path, "\n".join(lines))
    return path


def run_study(
    out_dir, *, quick: bool = False, seed: int = 0, workers=None, scheduler=None, progress=True
) -> Path:
    """Run the study and write ``report.md``, ``results.csv`` and two PNG figures.

    Parameters
    ----------
    out_dir : path-like
        Output folder (created; a folder holding another run is refused).
    quick : bool
        Smaller grid and Monte Carlo (about half a minute).
    seed : int
        Base seed of the Monte Carlo streams.
    workers : int, optional
        Threads for the Monte Carlo kernel (default: all cores).
    scheduler : str, optional
        Not supported: this study runs on local threads.
    progress : bool
        Progress bar over the (S, kappa) columns.

    Returns
    -------
    Path
        The Markdown report.
    """
    if scheduler is not None:
        raise ValueError(
            f"study {NAME!r} runs its Monte Carlo on local threads; `scheduler` is not "
            f"supported (got {scheduler!r}); use `workers` instead"
        )
    psds, kappas, k3s = grid(quick)
    mc = QUICK_MC if quick else FULL_MC
    identity = {
        "study": NAME,
        "quick": quick,
        "seed": seed,
        "psds": psds,
        "kappas": kappas,
        "k3s": k3s,
        "monte_carlo": mc,
    }
    out = prepare_output_dir(out_dir, identity)
    started = time.perf_counter()
    csv = out / "results.csv"
    if csv.exists():  # same identity: resume from the finished table
        df = pd.read_csv(csv)
        filled = _fill_missing_analytic(df)
        if filled is not df:
            df = filled
            atomic_write_text(csv, df.to_csv(index=False))
    else:
        df = compute_table(quick, seed, workers, progress)
        atomic_write_text(csv, df.to_csv(index=False))
    timings = time_methods()
    v = verdicts(df, timings)
    atomic_write_text(
        out / "verdicts.json",
        json.dumps({**v, "reading": "Reading: " + reading(df, timings)}, indent=2),
    )
    _plots(df, out)
    return _report(df, v, timings, quick, mc, time.perf_counter() - started, out)
