"""The best linear, hardening and bistable harvesters under one stroke budget: ``randvib study design``.

(or ``python studies/design.py OUT [--quick]``). For the paper's magnet mass
(m = 0.0226 kg assumed, c_m = 0.049 Ns/m, no friction) and a stroke of a few
millimetres, :func:`randvib.design` chooses each family's parameters for the
most electrical power with P(|z| > stroke) <= 1 %: linear (k, c_e), hardening
(k, k3, c_e) and bistable (k < 0 with k3 = 1e7 N/m^3, c_e), under band-pass
inputs of several widths and centres, a Kanai-Tajimi input and a recorded
input (the Silverbox multisine input with its time axis stretched 10x, so
that its band covers the device's, as a stand-in for an accelerometer
record). Every input is scaled to E[a^2] = 9 (m/s^2)^2 (0.3 g RMS), a level at
which the budget binds. Each optimum is
confirmed by Monte Carlo; the report gives the powers with 95 % intervals,
their fractions of the non-causal limit at the budget's Gaussian RMS
(:func:`randvib.harvesting_limit`: a bound for the linear devices that meet
the budget, not for the nonlinear ones) and of the causal limit a device can
approach (:func:`randvib.causal_harvesting_limit`), and the verdict,
computed from the table, on when a nonlinear spring pays.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

import randvib as rv
from randvib import datasets
from randvib.figure_style import new_figure, save_figure
from randvib.studies import report, script_main

NAME = "design"
EPS = 0.01  #: the budget on P(|z| > stroke)
STROKE = 0.003  #: m
LEVEL = 9.0  #: E[a^2] of every input, (m/s^2)^2
FIXED = rv.Harvester(m=rv.MAGNET_MASS, c_m=0.049, c_e=0.1, k=57.4, stroke=STROKE)
#: Each family: the harvester's fixed k3 and the ranges it chooses.
FAMILIES = {
    "linear": (0.0, {"k": (5.0, 500.0), "c_e": (0.005, 2.0)}),
    "hardening": (0.0, {"k": (5.0, 500.0), "k3": (1e4, 1e8), "c_e": (0.005, 2.0)}),
    "bistable": (1e7, {"k": (-60.0, -1.0), "c_e": (0.005, 2.0)}),
}
QUICK_MC = {"dt": 2e-4, "window": 4.0, "burn_in": 1.0, "min_paths": 64, "max_paths": 64}
FULL_MC = {"dt": 1e-4, "window": 8.0, "burn_in": 1.0, "target_rel_ci": 0.01,
           "min_paths": 32, "max_paths": 2048}  # fmt: skip

#: Strokes of the power-against-budget figure (m) and the bandwidths of the optimum figure.
STROKES = {True: (0.002, 0.005), False: (0.001, 0.002, 0.004, 0.006)}
ZETAS = {True: (0.5, 0.2, 0.05, 0.02), False: (0.5, 0.3, 0.2, 0.1, 0.05, 0.03, 0.02, 0.01)}

__all__ = ["inputs", "run_study", "verdicts"]


def recorded_input() -> rv.Measured:
    """The Silverbox input, time stretched 10x (band ~0-20 Hz), as a base acceleration.

    Welch segments of 512 samples (0.12 Hz bins): fine enough for the
    device's resonance, coarse enough for fast spectral integrals.
    """
    record = datasets.silverbox("multisine")
    u = np.asarray(record["force"])
    stretched = rv.Record(time=10 * record.dt * np.arange(u.size), base_acceleration=u)
    return rv.Measured(stretched, segment_length=512)


def inputs(quick: bool) -> dict:
    """Input name -> excitation with E[a^2] = LEVEL (m/s^2)^2."""
    bands = [(8.0, 0.3), (8.0, 0.03)] if quick else [
        (8.0, 0.5), (8.0, 0.3), (8.0, 0.1), (8.0, 0.03), (5.0, 0.1), (12.0, 0.1)]  # fmt: skip
    out = {f"band-pass {f0:g} Hz, zeta {z:g}": rv.BandPass(1.0, f0, z) for f0, z in bands}
    out["Kanai-Tajimi 8 Hz, zeta 0.3"] = rv.KanaiTajimi(1.0, 8.0, 0.3)
    out["recorded (Silverbox input, 10x slower)"] = recorded_input()
    return {name: x.scaled(LEVEL / x.variance) for name, x in out.items()}


def one_design(family: str, excitation, stroke: float, settings, where: dict) -> dict:
    """The row of one family's design under one input and stroke (``where``: workers, scheduler)."""
    k3, vary = FAMILIES[family]
    try:
        r = rv.design(FIXED.updated(k3=k3), excitation, vary, stroke=stroke, exceedance=EPS,
                      settings=settings, progress=False, **where)  # fmt: skip
    except ValueError as refusal:  # an infeasible budget: the row says so
        return {"family": family, "stroke": stroke, "feasible": False, "note": str(refusal)}
    return {"family": family, "stroke": stroke, "feasible": True, "method": r.method,
            **{f"opt_{k}": v for k, v in r.optimum.items()},
            "power_predicted": r.power_predicted, "power_mc": r.power_monte_carlo.mean,
            "power_mc_ci95": r.power_monte_carlo.ci95,
            "exceedance_mc": r.stroke_exceedance_monte_carlo.mean,
            "exceedance_mc_ci95": r.stroke_exceedance_monte_carlo.ci95,
            "limit": r.limit, "fraction_of_limit": r.fraction_of_limit,
            "causal_limit": r.causal_limit, "fraction_of_causal_limit": r.fraction_of_causal_limit,
            "refined": r.refined, "note": ""}  # fmt: skip


def compute(quick: bool, settings, where: dict) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """results (every input and family), budget (power vs stroke), bandwidth (optimum vs zeta)."""
    xs = inputs(quick)
    results = pd.DataFrame([{"input": name, **one_design(f, x, STROKE, settings, where)}
                            for name, x in xs.items() for f in FAMILIES])  # fmt: skip
    reference = next(iter(xs.values()))
    budget = pd.DataFrame([one_design(f, reference, s, settings, where) for s in STROKES[quick]
                           for f in FAMILIES])  # fmt: skip
    budget = pd.concat([budget, results[results.input == next(iter(xs))].drop(columns="input")])
    bandwidth = pd.DataFrame([
        {"zeta": z, "family": f, **rv.design(FIXED.updated(k3=FAMILIES[f][0]),
                                             rv.BandPass(1.0, 8.0, z).scaled(LEVEL / rv.BandPass(
                                                 1.0, 8.0, z).variance), FAMILIES[f][1],
                                             exceedance=EPS, monte_carlo=False).optimum}
        for z in ZETAS[quick] for f in ("linear", "hardening")])  # fmt: skip
    return results, budget.sort_values(["family", "stroke"]), bandwidth


def verdicts(results: pd.DataFrame) -> dict:
    """Per input: does a nonlinear family beat the linear optimum beyond the intervals?"""
    rows = []
    for name, sub in results.groupby("input", sort=False):
        lin = sub[sub.family == "linear"].iloc[0]
        for _, r in sub[(sub.family != "linear") & sub.feasible].iterrows():
            # the designs' estimates are independent: half-widths add in quadrature
            diff = r.power_mc - lin.power_mc
            half = float(np.hypot(r.power_mc_ci95, lin.power_mc_ci95))
            rows.append({"input": name, "family": r.family, "gain": diff / lin.power_mc,
                         "gain_ci95": half / lin.power_mc, "pays": bool(diff - half > 0),
                         "loses": bool(diff + half < 0)})  # fmt: skip
    gains = pd.DataFrame(rows)
    pays = gains[gains.pays]
    return {
        "comparisons": int(len(gains)),
        "nonlinear_pays": int(len(pays)),
        "nonlinear_loses": int(gains.loses.sum()) if len(gains) else 0,
        "where_it_pays": pays[["input", "family", "gain"]].to_dict("records"),
        "largest_gain": float(gains.gain.max()) if len(gains) else None,
        "fraction_of_limit_linear": {
            r.input: r.fraction_of_limit for r in results[results.family == "linear"].itertuples()
        },
        "gains": gains.to_dict("records"),
    }


def figures(budget: pd.DataFrame, bandwidth: pd.DataFrame, out: Path) -> None:
    fig, axes = new_figure(1, 3, figsize=(12, 3.6))
    ax = axes[0, 0]
    colours = {}
    for family, sub in budget[budget.feasible].groupby("family"):
        drawn = ax.errorbar(1e3 * sub.stroke, 1e3 * sub.power_mc, 1e3 * sub.power_mc_ci95,
                            marker="o", label=family, capsize=2)  # fmt: skip
        colours[family] = drawn[0].get_color()
    # a family that cannot meet the budget at a stroke has no power to draw: a cross on
    # the stroke axis says so instead of a silently missing point
    for family, sub in budget[~budget.feasible].groupby("family"):
        ax.plot(1e3 * sub.stroke, [0.0] * len(sub), "x", ms=7, mew=1.5,
                color=colours.get(family, "0.3"),
                label=f"{family}: budget cannot be met")  # fmt: skip
    limits = budget.dropna(subset=["limit"]).drop_duplicates("stroke").sort_values("stroke")
    ax.plot(1e3 * limits.stroke, 1e3 * limits.limit, "k--",
            label="limit (non-causal; linear devices)")  # fmt: skip
    ax.plot(1e3 * limits.stroke, 1e3 * limits.causal_limit, "k:", label="causal limit")
    ax.set(xlabel="stroke (mm)", ylabel="power (mW)", title=r"band-pass 8 Hz, $\zeta$ = 0.3")
    # below the panel: inside, some stroke's points fell under it
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), fontsize=7, ncols=2)
    # the optimum's stiffness and electrical damping, each on its own labelled axis;
    # the families coincide where k3 -> its lower bound, so their markers differ
    # (filled circles and a solid line: linear; open squares and a dashed line: hardening;
    # colours as in the left panel; hardening drawn over linear)
    style = {
        "linear": dict(marker="o", ls="-", ms=6, zorder=2),
        "hardening": dict(marker="s", ls="--", ms=9, mfc="none", mew=1.5, zorder=3),
    }
    for family in style:
        if family in colours:
            style[family]["color"] = colours[family]
    for ax, column, symbol, label in ((axes[0, 1], "k", "$k$", "optimum $k$ (N/m)"),
                                      (axes[0, 2], "c_e", "$c_e$",
                                       "optimum $c_e$ (Ns/m)")):  # fmt: skip
        for family in ("linear", "hardening"):
            sub = bandwidth[bandwidth.family == family]
            ax.plot(sub.zeta, sub[column], label=family, **style[family])
        ax.set(xscale="log", xlabel=r"$\zeta$ (bandwidth 2$\zeta f_0$)", ylabel=label,
               title=f"optimum {symbol} against bandwidth")  # fmt: skip
        zetas = sorted(bandwidth.zeta.unique())
        ax.set_xticks(zetas, [f"{z:g}" for z in zetas])
        ax.tick_params(which="minor", labelbottom=False)
        ax.legend(fontsize="small", title="analytic optimum (family)", loc="upper center",
                  bbox_to_anchor=(0.5, -0.2), ncols=2)  # fmt: skip
    save_figure(fig, out / "design.png")


def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True) -> Path:
    """Run the design study and write ``report.md``, CSVs, ``design.png`` and ``verdicts.json``."""
    settings = rv.SweepSettings(**(QUICK_MC if quick else FULL_MC), seed=seed,
                                control_variates=False)  # fmt: skip
    out = report.prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed})
    started = time.perf_counter()
    results, budget, bandwidth = compute(
        quick, settings, {"workers": workers, "scheduler": scheduler}
    )
    for name, table in (("results.csv", results), ("budget.csv", budget),
                        ("bandwidth.csv", bandwidth)):  # fmt: skip
        report.write_table(out, name, table)
    v = verdicts(results)
    figures(budget, bandwidth, out)
    sentence = (
        f"A nonlinear spring beats the best linear device beyond the 95 % intervals in "
        f"{v['nonlinear_pays']} of {v['comparisons']} input-family comparisons and loses in "
        f"{v['nonlinear_loses']}"
        + (": " + "; ".join(f"{w['family']} under {w['input']} (+{100 * w['gain']:.1f} %)"
                            for w in v["where_it_pays"]) if v["where_it_pays"] else ".")
    )  # fmt: skip
    report.write_verdicts(out, v, [sentence])
    shown = results.drop(columns=["note"]).copy()
    wall = time.perf_counter() - started
    return report.write_report(
        out,
        f"Study {NAME}: the best harvester under a stroke budget{' (quick)' * quick}",
        [
            ("Set-up", f"m = {rv.MAGNET_MASS} kg (assumed), c_m = 0.049 Ns/m, no friction; "
             f"stroke {1e3 * STROKE:g} mm, budget P(|z| > stroke) <= {EPS:g}; every input "
             f"scaled to E[a^2] = {LEVEL:g} (m/s^2)^2. Monte Carlo: {settings}. Wall time {wall:.0f} s."),
            ("Verdict", sentence),
            ("Optima", report.markdown_table(shown, floatfmt=".4g")),
            ("Power against stroke budget; optimum against bandwidth",
             "![design](design.png)\n\n" + report.markdown_table(bandwidth, floatfmt=".4g")),
        ],
    )  # fmt: skip


if __name__ == "__main__":
    sys.exit(script_main(run_study))
