"""Linear, hardening or bistable, with friction and a stroke limit: ``randvib study devices``.

(or ``python studies/devices.py OUT [--quick]``). Issue 11 asks where, if
anywhere, bistability pays once friction and a stroke limit are in the
picture. Three devices share the magnet, the damping, the circuit and the
friction of the paper's figure9 device (m = 0.0226 kg, c_m = c_e = 0.1 Ns/m,
resistive coupling, Coulomb Fc = 5.8 mN) and differ in the spring only:

- **linear**: k = 57.4 N/m, k3 = 0 (f_n = 8.02 Hz);
- **hardening**: k = 57.4 N/m and the bistable device's k3;
- **bistable**: k_b = -k / 2, so that the small-amplitude frequency inside a
  well (stiffness -2 k_b = k) is the linear device's f_n: the same magnet
  tuned to the same frequency. Its k3 sets the barrier
  k_b^2 / (4 k3) equal to the energy scale of the motion at the reference
  level, m E[z'^2] = m^2 S_ref / (4 c) with S_ref = 1 (m/s^2)^2/Hz (the
  linear friction-free device's): at the reference level the magnet crosses
  the barrier neither rarely nor all the time. This gives
  k3 = k^2 / (16 m E[z'^2]) = 3.23e5 N/m^3 and wells at z_w = 9.43 mm.

**The stroke** is one fixed gap for all three, ``STROKE`` = 12 mm
(1.27 z_w; 3.6 times the linear device's rms displacement at the
reference level).

**Equal input power.** The input is scaled by a factor g (``levels``) of a
reference. "Equal input power" means: *the same mean power injected by the
base into the reference linear device without friction* (c E[z'^2] with
c = c_m + c_e), set to g S_ref m / 4 (W). Under white noise the injected
power S m / 4 is the same for every device (the Ito term of the energy
balance), so this is the level S = g S_ref. A band-pass
input's peak level is chosen so that the reference device receives the same
power (equivalently: the same E[z'^2]). Equal base-acceleration variance is
not used: white noise has none (infinite), and any cut-off frequency would
be arbitrary.

**Measured** by Monte Carlo (Heun, the band's filter states integrated with
the device, every device on the same paths: paired), from rest at a stable
equilibrium (z = 0; z = +z_w for the bistable device): the electrical power
E[P_e] = c_e E[z'^2], the fraction of time with |z| > stroke, and the first
time |z| reaches the stroke. Paths that do not reach it within the run are
*censored*: the mean first-passage time is reported only when every path
reached it; otherwise the restricted mean E[min(tau, t_end)] (a lower bound)
and, when more than half reached it, the median (Kaplan-Meier with one
censoring time: the empirical median).

**Predicted** by statistical linearisation (every device and input; it may
have no zero-mean solution for the bistable device under a band), fpk-fast
and fpk (white noise, resistive coupling: any confining potential) and
stochastic averaging (white noise, monostable devices; no stroke statistic),
each against Monte Carlo with the relative error's 95 % interval.

**The trade-off** is summarised as the power at a fixed exceedance budget
(``BUDGET`` = 1 % of the time beyond the gap): per device and input, the
level g at which the Monte Carlo exceedance crosses the budget is
interpolated (log-log, between the two levels that bracket it) and the
power there read off the same interpolation; its range is the same
interpolation through the exceedance's 95 % interval.
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

import randvib as rv
from randvib._progress import progress_bar
from randvib.analytic.linear_response import mechanical_block, output_variances
from randvib.figure_style import colour as style_colour
from randvib.figure_style import new_figure, panel_letters, save_figure, styled
from randvib.statistics import median_first_passage, paired_ratio
from randvib.studies import script_main
from randvib.studies.report import (
    markdown_table,
    plus_minus,
    prepare_output_dir,
    write_report,
    write_table,
    write_verdicts,
)

NAME = "devices"
FC = 0.0058  #: N, the paper's Coulomb level (Table 2, training data 1)
STROKE = 0.012  #: m, the gap: one number for every device
S_REF = 1.0  #: (m/s^2)^2/Hz, the reference white-noise level (g = 1)
BUDGET = 0.01  #: the exceedance budget: fraction of time with |z| > STROKE
#: Inputs: a band-pass centred at (a fraction of) the linear resonance, damping ratio 0.1.
BANDS = {"band at f_n": 1.0, "band at f_n/2": 0.5}
BAND_ZETA = 0.1
DEVICES = ("linear", "hardening", "bistable")
#: Monte Carlo: (paths, time per path incl. burn-in (s), dt (s), burn-in (s)).
FULL_MC = (512, 41.0, 2e-4, 1.0)
QUICK_MC = (128, 11.0, 2e-4, 1.0)
#: A stroke exceedance is compared with a method only where Monte Carlo resolves it this well.
RESOLVED = 0.25

__all__ = ["devices", "grid", "input_of", "power_at_budget", "run_study", "verdicts"]


def grid(quick: bool) -> dict:
    """The study's axes: inputs, level factors g, analytic methods and Monte Carlo sizes."""
    if quick:
        return {"inputs": ("white", "band at f_n"), "levels": (1 / 16, 1 / 4, 1.0, 4.0),
                "methods": ("linearisation", "fpk-fast", "averaging"), "mc": QUICK_MC}  # fmt: skip
    return {
        "inputs": ("white", *BANDS),
        "levels": tuple(2.0**e for e in range(-5, 3)),
        "methods": ("linearisation", "fpk-fast", "fpk", "averaging"),
        "mc": FULL_MC,
    }


def devices(base: rv.Harvester | None = None) -> dict:
    """The three devices and their start states {name: (Harvester, (z0, v0))} (see module doc)."""
    base = (base or rv.preset("figure9")).updated(fc=FC, stroke=STROKE)
    motion = base.m**2 * S_REF / (4 * base.c)  # m E[z'^2] of the linear friction-free device
    k_b = -base.k / 2
    k3 = k_b**2 / (4 * motion)  # barrier k_b^2 / (4 k3) = m E[z'^2]
    well = float(np.sqrt(-k_b / k3))
    return {
        "linear": (base.updated(k3=0.0), (0.0, 0.0)),
        "hardening": (base.updated(k3=k3), (0.0, 0.0)),
        "bistable": (base.updated(k=k_b, k3=k3), (well, 0.0)),
    }


def input_of(name: str, g: float, base: rv.Harvester | None = None) -> rv.Excitation:
    """Input ``name`` at level factor g: equal power injected into the linear friction-free device.

    White: S = g S_ref (injected power g S_ref m / 4 into any device). A band:
    its peak level makes the linear device's (no friction, no cubic term)
    E[z'^2] equal to g S_ref m / (4 c), so it receives c E[z'^2] = g S_ref m / 4.
    """
    if name == "white":
        return rv.White(g * S_REF)
    if name not in BANDS:
        raise ValueError(f"unknown input {name!r}; available: white, {', '.join(BANDS)}")
    base = base or rv.preset("figure9")
    f_n = np.sqrt(base.k / base.m) / (2 * np.pi)
    shape = rv.BandPass(1.0, BANDS[name] * f_n, BAND_ZETA)
    linear = output_variances(mechanical_block(base.m, base.c, base.k), shape)["v"]
    return rv.BandPass(g * S_REF * base.m / (4 * base.c) / linear, shape.f0, BAND_ZETA)


# ----------------------------------------------------------------- compute
def first_passage_columns(first) -> dict:
    """Censoring-aware first-passage columns of a :class:`FirstPassage`."""
    return {
        "fp_paths_reached": first.paths_reached, "fp_n_paths": first.n_paths,
        "fp_horizon": first.horizon,
        "fp_mean": np.nan if first.mean is None else first.mean.mean,
        "fp_mean_ci95": np.nan if first.mean is None else first.mean.ci95,
        "fp_restricted_mean": first.restricted_mean.mean,
        "fp_restricted_ci95": first.restricted_mean.ci95,
    }  # fmt: skip


def simulate_device(device, start, excitation, mc, seed, threads):
    """One Monte Carlo run: its results row and the per-path powers (W)."""
    n_paths, t_end, dt, burn = mc
    r = rv.simulate(
        device, excitation, t_end=t_end, dt=dt, n_paths=n_paths, burn_in=burn, seed=seed,
        threads=threads, progress=False, initial=start, scheme="heun",
    )  # fmt: skip
    p, x = r.power_electrical, r.stroke_exceedance
    row = {
        "power_mc": p.mean, "power_mc_ci95": p.ci95, "n_paths": p.n_paths,
        "exceedance_mc": x.mean, "exceedance_mc_ci95": x.ci95,
        "z_rms_mc": float(np.sqrt(r.displacement_variance.mean)),
        **first_passage_columns(r.stroke_first_passage),
        "fp_median": median_first_passage(r.averages.first_hit_time, t_end),
    }  # fmt: skip
    return row, device.c_e * r.averages.v2


def predictions(device, excitation, methods) -> list[dict]:
    """Every method's power and exceedance, or why it refused (one row per method)."""
    rows = []
    for method in methods:
        row = {"method": method, "power": np.nan, "exceedance": np.nan, "refused": ""}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", rv.AveragingValidityWarning)
            try:
                p = rv.predict(device, excitation, method)
            except ValueError as err:
                row["refused"] = str(err).split(";")[0][:160]
                rows.append(row)
                continue
        row["power"] = float(p.power_electrical)
        if p.stroke_exceedance is not None:
            row["exceedance"] = float(p.stroke_exceedance)
        rows.append(row)
    return rows


def compute_point(name, g, axes, seed, threads):
    """Every device under one input at one level, on the same paths: results and method rows."""
    excitation = input_of(name, g)
    head = {"input": name, "g": g, "level": excitation.level}
    results, methods, per_path = [], [], {}
    for device_name, (device, start) in devices().items():
        row, per_path[device_name] = simulate_device(device, start, excitation, axes["mc"], seed,
                                                     threads)  # fmt: skip
        results.append({**head, "device": device_name, **row})
        for m in predictions(device, excitation, axes["methods"]):
            methods.append({**head, "device": device_name, **m, **_errors(m, row)})
    for row in results:
        ratio, ci = paired_ratio(per_path[row["device"]], per_path["linear"])
        row["power_ratio_to_linear"], row["power_ratio_ci95"] = ratio, ci
    return results, methods


def _errors(m: dict, mc: dict) -> dict:
    """Relative errors of a prediction against Monte Carlo, with their 95 % half-widths."""
    out = {}
    for q, ref, ci in (("power", "power_mc", "power_mc_ci95"),
                       ("exceedance", "exceedance_mc", "exceedance_mc_ci95")):  # fmt: skip
        resolved = mc[ref] > 0 and (q == "power" or mc[ci] <= RESOLVED * mc[ref])
        ok = resolved and np.isfinite(m[q])
        out[f"{q}_rel_error"] = m[q] / mc[ref] - 1.0 if ok else np.nan
        out[f"{q}_rel_error_ci95"] = m[q] * mc[ci] / mc[ref] ** 2 if ok else np.nan
    return out


def compute(axes, seed, threads, progress) -> tuple[pd.DataFrame, pd.DataFrame]:
    """results.csv (device x input x level) and methods.csv (the same x method)."""
    points = [(name, g) for name in axes["inputs"] for g in axes["levels"]]
    bar = None
    if progress:
        bar = progress_bar(len(points), desc=NAME, unit="point")
    results, methods = [], []
    for i, (name, g) in enumerate(points):
        r, m = compute_point(name, g, axes, seed * 1000 + i, threads)
        results += r
        methods += m
        if bar is not None:
            bar.update()
    if bar is not None:
        bar.close()
    return pd.DataFrame(results), pd.DataFrame(methods)


# ----------------------------------------------------------------- the budget
def power_at_budget(sub: pd.DataFrame, budget: float = BUDGET) -> dict:
    """Power (W) where the Monte Carlo exceedance of one device and input crosses ``budget``.

    Log-log interpolation of (g, exceedance) and (g, power) between the two
    levels that bracket the budget; ``low``/``high`` repeat it with the
    exceedance at the ends of its 95 % interval (upper end: less power).
    ``bracket`` says "bracketed", "below" (every level exceeds the budget: the
    power is below the lowest level's) or "above" (none does: above the
    highest level's).
    """
    sub = sub.sort_values("g")
    g, p = sub.g.to_numpy(), sub.power_mc.to_numpy()
    x, ci = sub.exceedance_mc.to_numpy(), sub.exceedance_mc_ci95.to_numpy()

    def crossing(exceed):
        above = np.flatnonzero(exceed > budget)
        if above.size == 0:
            return np.inf, "above"
        i = above[0]
        if i == 0:
            return -np.inf, "below"
        lo, hi = max(exceed[i - 1], budget * 1e-3), exceed[i]
        t = np.log(budget / lo) / np.log(hi / lo)
        return float(np.exp(np.log(g[i - 1]) + t * np.log(g[i] / g[i - 1]))), "bracketed"

    def power_at(level):
        if not np.isfinite(level):
            return float(p[0] if level < 0 else p[-1])
        return float(np.exp(np.interp(np.log(level), np.log(g), np.log(p))))

    level, where = crossing(x)
    return {
        "bracket": where, "g": level if np.isfinite(level) else np.nan, "power": power_at(level),
        "power_low": power_at(crossing(x + ci)[0]), "power_high": power_at(crossing(x - ci)[0]),
    }  # fmt: skip


def budget_table(results: pd.DataFrame) -> pd.DataFrame:
    """:func:`power_at_budget` for every input and device, with the ratio to the linear device."""
    rows = [{"input": name, "device": dev, **power_at_budget(sub)}
            for (name, dev), sub in results.groupby(["input", "device"], sort=False)]  # fmt: skip
    table = pd.DataFrame(rows)
    linear = table[table.device == "linear"].set_index("input").power
    table["ratio_to_linear"] = table.power / table.input.map(linear)
    return table


# ----------------------------------------------------------------- verdicts
def verdicts(results: pd.DataFrame, methods: pd.DataFrame) -> dict:
    """The numbers behind the report's verdicts, computed from the two tables."""
    budget = budget_table(results)
    return {
        "stroke": STROKE,
        "budget": BUDGET,
        "n_levels": int(results.g.nunique()),
        "fixed_input": {
            name: _fixed_input(sub) for name, sub in results.groupby("input", sort=False)
        },
        "at_budget": {name: _at_budget(sub) for name, sub in budget.groupby("input", sort=False)},
        "methods": _method_accuracy(methods),
    }


def _fixed_input(sub: pd.DataFrame) -> dict:
    """Per device at one input: the levels where it beats the linear device (paired), and by how much."""
    out = {}
    for dev, rows in sub[sub.device != "linear"].groupby("device", sort=False):
        more = rows[rows.power_ratio_to_linear - rows.power_ratio_ci95 > 1]
        less = rows[rows.power_ratio_to_linear + rows.power_ratio_ci95 < 1]
        best = rows.loc[rows.power_ratio_to_linear.idxmax()]
        out[dev] = {
            "levels_more_power": [float(g) for g in more.g],
            "levels_less_power": [float(g) for g in less.g],
            "largest_ratio": float(best.power_ratio_to_linear),
            "largest_ratio_ci95": float(best.power_ratio_ci95),
            "largest_ratio_at_g": float(best.g),
            "exceedance_there": float(best.exceedance_mc),
            "linear_exceedance_there": float(
                sub[(sub.device == "linear") & (sub.g == best.g)].exceedance_mc.iloc[0]
            ),
            "more_power_within_budget": [
                {
                    "g": float(r.g),
                    "ratio": float(r.power_ratio_to_linear),
                    "ratio_ci95": float(r.power_ratio_ci95),
                    "exceedance": float(r.exceedance_mc),
                    "exceedance_ci95": float(r.exceedance_mc_ci95),
                }
                for r in more.itertuples()
                if r.exceedance_mc + r.exceedance_mc_ci95 <= BUDGET
            ],  # fmt: skip
        }
    return out


def _at_budget(sub: pd.DataFrame) -> dict:
    """Per device at one input: power at the exceedance budget and whether it beats the linear one."""
    linear = sub[sub.device == "linear"].iloc[0]
    out = {}
    for row in sub.itertuples():
        out[row.device] = {
            "bracket": row.bracket, "g": None if np.isnan(row.g) else float(row.g),
            "power": float(row.power), "power_low": float(row.power_low),
            "power_high": float(row.power_high), "ratio_to_linear": float(row.ratio_to_linear),
            "ratio_bound": _ratio_bound(row.bracket, linear.bracket),
            "beats_linear": bool(row.device != "linear" and row.bracket == "bracketed"
                                 and linear.bracket == "bracketed"
                                 and row.power_low > linear.power_high),
        }  # fmt: skip
    return out


def _method_accuracy(methods: pd.DataFrame) -> dict:
    """Per method and quantity: points compared, largest |error| and where, points within the MC interval."""
    out = {}
    for method, rows in methods.groupby("method", sort=False):
        entry = {
            "refused": int((rows.refused.fillna("") != "").sum()),
            "points": int(len(rows)),
            "negative_exceedance": int((rows.exceedance < 0).sum()),
            "most_negative_exceedance": float(min(rows.exceedance.min(), 0.0))
            if rows.exceedance.notna().any() else None,
        }  # fmt: skip
        for q in ("power", "exceedance"):
            err = rows.dropna(subset=[f"{q}_rel_error"])
            if err.empty:
                entry[q] = None
                continue
            worst = err.loc[err[f"{q}_rel_error"].abs().idxmax()]
            entry[q] = {
                "compared": int(len(err)),
                "largest_abs_error": float(abs(worst[f"{q}_rel_error"])),
                "largest_ci95": float(worst[f"{q}_rel_error_ci95"]),
                "where_largest": f"{worst.device}, {worst.input}, g = {worst.g:g}",
                "within_mc_interval": int(
                    (err[f"{q}_rel_error"].abs() <= err[f"{q}_rel_error_ci95"]).sum()
                ),
                "largest_abs_error_by_device": {
                    d: float(e[f"{q}_rel_error"].abs().max()) for d, e in err.groupby("device")
                },
            }
        out[method] = entry
    return out


def answer(v: dict) -> str:
    """The issue's question answered from the verdict numbers: where bistability pays, if anywhere."""
    parts = []
    for name, devs in v["fixed_input"].items():
        b = devs["bistable"]
        at = v["at_budget"][name]["bistable"]
        more = ", ".join(f"{g:g}" for g in b["levels_more_power"]) or "none"
        within = ", ".join(
            f"g = {w['g']:g} ({w['ratio']:.3f} ± {w['ratio_ci95']:.3f} times, "
            f"{100 * w['exceedance']:.2g} ± {100 * w['exceedance_ci95']:.2g} % beyond)"
            for w in b["more_power_within_budget"]
        )
        parts.append(
            f"{name}: more power than the linear device (paired, 95 %) at g = {more}; "
            f"of these, within the budget (exceedance and its half-width at most "
            f"{100 * v['budget']:g} %): {within or 'none'}; largest "
            f"ratio {b['largest_ratio']:.3f} ± {b['largest_ratio_ci95']:.3f} at g = "
            f"{b['largest_ratio_at_g']:g}, where it spends {100 * b['exceedance_there']:.2g} % of "
            f"the time beyond the gap (linear: {100 * b['linear_exceedance_there']:.2g} %); at the "
            f"{100 * v['budget']:g} % budget it delivers {_bound(at)}{at['ratio_to_linear']:.3g} "
            f"times the linear device's power ({'pays' if at['beats_linear'] else 'does not pay'})"
        )
    paying = [
        (name, w["g"]) for name, d in v["fixed_input"].items()
        for w in d["bistable"]["more_power_within_budget"]
    ]  # fmt: skip
    total = sum(len(d["bistable"]["levels_more_power"]) + len(d["bistable"]["levels_less_power"])
                for d in v["fixed_input"].values())  # fmt: skip
    n_points = len(v["fixed_input"]) * v["n_levels"]
    lead = (
        f"At equal input, the bistable device delivers significantly more power than the linear "
        f"one while within the {100 * v['budget']:g} % budget at {len(paying)} of {n_points} "
        f"(input, level) points"
        + (": " + ", ".join(f"{n} at g = {g:g}" for n, g in paying) if paying else "")
        + f" (significantly different power at {total}). "
    )
    hardening = ", ".join(
        f"{name} {_bound(d['hardening'])}{d['hardening']['ratio_to_linear']:.3g}"
        f"{' (pays)' * d['hardening']['beats_linear']}"
        for name, d in v["at_budget"].items()
    )
    return (
        lead + "; ".join(parts) + ". For comparison, the hardening device at the budget: "
        f"{hardening}."
    )


def _ratio_bound(device_where: str, linear_where: str) -> str:
    """How the ratio at the budget relates to the true one: "=", "<" (an upper bound), ">" or "?".

    Outside the levels run the power is the end level's: an upper bound
    ("below": the device exceeds the budget even at the lowest level) or a
    lower bound ("above").
    """
    signs = {("below", 0): "<", ("above", 0): ">", ("below", 1): ">", ("above", 1): "<"}
    found = {signs[(w, i)] for i, w in enumerate((device_where, linear_where)) if w != "bracketed"}
    return "=" if not found else found.pop() if len(found) == 1 else "?"


def _bound(entry: dict) -> str:
    """'< ', '> ' or '~ ' before a ratio that is a bound or unknown, else ''."""
    return {"=": "", "<": "< ", ">": "> ", "?": "~ "}[entry["ratio_bound"]]


# ----------------------------------------------------------------- figures
@styled
def tradeoff_figure(results: pd.DataFrame, path: Path) -> Path:
    """Power against stroke exceedance over the levels, a panel per input, a line per device."""
    from matplotlib.ticker import LogLocator

    inputs = list(dict.fromkeys(results.input))
    fig, axes = new_figure(1, len(inputs), figsize=(3.6 * len(inputs), 3.4), sharey=True)
    for ax, name in zip(axes[0], inputs, strict=True):
        for dev in DEVICES:
            sub = results[(results.input == name) & (results.device == dev)].sort_values("g")
            shown = sub.exceedance_mc > 0
            ax.errorbar(sub.exceedance_mc[shown], 1e3 * sub.power_mc[shown],
                        xerr=sub.exceedance_mc_ci95[shown], yerr=1e3 * sub.power_mc_ci95[shown],
                        marker="o", ms=3, capsize=2, label=dev)  # fmt: skip
        ax.axvline(BUDGET, color="k", ls=":", lw=1, label=f"budget: {100 * BUDGET:g} % of the time")
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):
            # minor ticks at 2 and 5 only: on a narrow range all eight minor labels collide
            axis.set_minor_locator(LogLocator(subs=(2.0, 5.0)))
        ax.set_xlabel(f"fraction of time with |z| > {1e3 * STROKE:g} mm")
        ax.set_title(name, fontsize=9)
        ax.grid(alpha=0.3, lw=0.5)
    axes[0, 0].set_ylabel("E[P$_e$] (mW), Monte Carlo")
    axes[0, 0].legend(fontsize=7, title="markers: levels g; bars: 95 % CI", title_fontsize=7)
    panel_letters(axes)
    return save_figure(fig, path)


@styled
def methods_figure(methods: pd.DataFrame, path: Path) -> Path:
    """Relative errors of the methods against level, power and exceedance, a marker per device.

    A colour per method, a marker per device, 95 % bars; the error axis is
    linear while every error is within ±10 %, symmetric-log beyond.
    """
    from matplotlib.ticker import FuncFormatter, NullFormatter

    fig, axes = new_figure(1, 2, figsize=(9, 3.8))
    markers = dict(zip(DEVICES, "osD", strict=True))
    levels = sorted(methods.g.unique())
    for ax, q in zip(axes[0], ("power", "exceedance"), strict=True):
        for i, (method, rows) in enumerate(methods.groupby("method", sort=False)):
            for dev, sub in rows.dropna(subset=[f"{q}_rel_error"]).groupby("device"):
                ax.errorbar(sub.g * (1.04**i), 100 * sub[f"{q}_rel_error"],
                            yerr=100 * sub[f"{q}_rel_error_ci95"], ls="none", marker=markers[dev],
                            ms=3.5, capsize=1.5, color=style_colour(i),
                            label=f"{method}, {dev}")  # fmt: skip
        ax.axhline(0.0, color="0.5", lw=0.5, zorder=1)
        ax.set_xscale("log")
        ax.set_xticks(levels, [f"{g:g}" for g in levels])
        ax.xaxis.set_minor_formatter(NullFormatter())
        reach = (methods[f"{q}_rel_error"].abs() + methods[f"{q}_rel_error_ci95"]).max()
        if 100 * reach > 10:
            ax.set_yscale("symlog", linthresh=10)
            ax.yaxis.set_major_formatter(FuncFormatter(lambda y, _: f"{y:g}"))
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


# ----------------------------------------------------------------- report
def setup_section(axes, results, seed, quick, wall, resumed=False) -> str:
    n_paths, t_end, dt, burn = axes["mc"]
    rows = [{"device": name, "k (N/m)": d.k, "k3 (N/m^3)": d.k3, "start z0 (mm)": 1e3 * z0,
             "kind": d.potential.kind} for name, (d, (z0, _)) in devices().items()]  # fmt: skip
    levels = results.drop_duplicates(["input", "g"])[["input", "g", "level"]]
    return (
        "Same magnet, damping, circuit and friction (figure9: m = 0.0226 kg, c_m = c_e = 0.1 Ns/m, "
        f"resistive, Coulomb Fc = {1e3 * FC:g} mN); the spring differs (module docstring: the "
        "bistable device has the linear one's in-well frequency and a barrier equal to the "
        f"motion's energy scale at the reference level). Gap {1e3 * STROKE:g} mm for all. "
        "Levels g scale the input so that the power injected into the linear friction-free "
        "device is g S_ref m / 4 with S_ref = 1 (m/s^2)^2/Hz: white S = g; band-pass inputs "
        f"(damping ratio {BAND_ZETA:g}) have the peak level below. Monte Carlo: Heun, dt = {dt:g} s, "
        f"{n_paths} paths x {t_end - burn:g} s after {burn:g} s burn-in, from rest at a stable "
        f"equilibrium, one seed per input and level shared by the three devices (paired; seed "
        f"{seed}). {'Quick mode. ' if quick else ''}Wall time {wall:.0f} s"
        f"{' (tables resumed from an earlier run)' * resumed}.\n\n"
        + markdown_table(pd.DataFrame(rows), floatfmt=".4g") + "\n\n"
        + markdown_table(levels, floatfmt=".4g")
    )  # fmt: skip


def power_section(results, v, figure) -> str:
    shown = results[["input", "g", "device"]].copy()
    shown["E[P_e] (mW)"] = plus_minus(results.power_mc, results.power_mc_ci95, 1e3, ".4f")
    shown["/ linear (paired)"] = plus_minus(results.power_ratio_to_linear,
                                            results.power_ratio_ci95, 1.0, ".3f")  # fmt: skip
    shown["beyond gap (%)"] = plus_minus(results.exceedance_mc, results.exceedance_mc_ci95,
                                         100.0, ".3g")  # fmt: skip
    shown["z_rms (mm)"] = 1e3 * results.z_rms_mc
    shown["reached"] = [f"{a}/{b}" for a, b in zip(results.fp_paths_reached, results.fp_n_paths,
                                                   strict=True)]  # fmt: skip
    shown["mean first time (s)"] = [_first_time(r) for r in results.itertuples()]
    shown["median (s)"] = [f"{m:.3g}" if np.isfinite(m) else f"> {h:g}"
                           for m, h in zip(results.fp_median, results.fp_horizon, strict=True)]  # fmt: skip
    return (
        f"![power against exceedance]({figure.name})\n\n**Verdict.** {answer(v)}\n\n"
        "First passage from rest: the mean is shown only when every path reached the gap; "
        "otherwise '>= x' is the restricted mean E[min(tau, t_end)] (a lower bound, with its "
        "interval). The median is the Kaplan-Meier median (one censoring time: the empirical one) "
        "when more than half the paths reached the gap.\n\n" + markdown_table(shown, floatfmt=".4g")
    )


def _blank_nan(texts: list[str]) -> list[str]:
    """'' for a 'nan ± nan' cell (not compared, or refused)."""
    return ["" if "nan" in t else t for t in texts]


def _first_time(r) -> str:
    if np.isfinite(r.fp_mean):
        return f"{r.fp_mean:.3g} ± {r.fp_mean_ci95:.2g}"
    return f">= {r.fp_restricted_mean:.3g} ± {r.fp_restricted_ci95:.2g}"


def budget_section(results, v) -> str:
    table = budget_table(results)
    shown = table[["input", "device", "bracket"]].copy()
    shown["g at budget"] = table.g
    shown["E[P_e] at budget (mW)"] = [
        f"{1e3 * p:.4g} [{1e3 * lo:.4g}, {1e3 * hi:.4g}]"
        for p, lo, hi in zip(table.power, table.power_low, table.power_high, strict=True)
    ]
    shown["/ linear"] = [f"{_bound(v['at_budget'][r.input][r.device])}{r.ratio_to_linear:.3g}"
                         for r in table.itertuples()]  # fmt: skip
    return (
        f"Power at the budget of {100 * BUDGET:g} % of the time beyond the {1e3 * STROKE:g} mm gap "
        "(log-log interpolation over the levels; brackets: the same through the exceedance's "
        "95 % interval; 'below': the device exceeds the budget at every level run, so its "
        "power there is an upper bound).\n\n" + markdown_table(shown, floatfmt=".4g")
    )


def methods_section(methods, v, figure) -> str:
    lines = []
    for method, e in v["methods"].items():
        text = [f"**{method}**: refused at {e['refused']} of {e['points']} points"]
        if e["negative_exceedance"]:
            text.append(
                f"a negative stroke exceedance (a probability below zero) at "
                f"{e['negative_exceedance']} points, down to {e['most_negative_exceedance']:.2g}"
            )
        for q in ("power", "exceedance"):
            a = e[q]
            if a is None:
                text.append(f"no {q} compared")
                continue
            by_dev = ", ".join(
                f"{d} {100 * x:.2g} %" for d, x in a["largest_abs_error_by_device"].items()
            )
            text.append(
                f"{q}: largest |error| {100 * a['largest_abs_error']:.3g} % (± "
                f"{100 * a['largest_ci95']:.2g} %, {a['where_largest']}) over {a['compared']} "
                f"points, {a['within_mc_interval']} within the Monte Carlo interval; by device: {by_dev}"
            )  # fmt: skip
        lines.append("- " + "; ".join(text) + ".")
    shown = methods[["input", "g", "device", "method"]].copy()
    for q in ("power", "exceedance"):
        shown[f"{q} error (%)"] = _blank_nan(
            plus_minus(methods[f"{q}_rel_error"], methods[f"{q}_rel_error_ci95"])
        )
    shown["refused"] = methods.refused.fillna("").str.slice(0, 60)
    return (
        f"![method errors]({figure.name})\n\n**Verdict.**\n\n" + "\n".join(lines) + "\n\n"
        f"Exceedance is compared only where Monte Carlo resolves it (95 % half-width at most "
        f"{100 * RESOLVED:g} % of the value). No analytic method here gives the first-passage "
        "time.\n\n" + markdown_table(shown, floatfmt=".4g")
    )  # fmt: skip


# ----------------------------------------------------------------- the study
def tables_of(out, axes, seed, threads, progress):
    """results.csv and methods.csv: computed, or resumed from a run of the same identity."""
    files = out / "results.csv", out / "methods.csv"
    if all(f.exists() for f in files):
        return tuple(pd.read_csv(f, keep_default_na=False, na_values=[""]) for f in files)
    results, methods = compute(axes, seed, threads, progress)
    write_table(out, "results.csv", results)
    write_table(out, "methods.csv", methods)
    return results, methods


def run_study(
    out_dir, *, quick=False, seed=0, workers=None, threads=None, scheduler=None, progress=True
) -> Path:
    """Run the devices study and write ``report.md``, CSVs, figures and ``verdicts.json``.

    ``quick``: white noise and the band at f_n, four levels, 128 paths
    (under a minute on one core); ``threads``: numba threads; ``workers`` is
    accepted and unused (in-process); ``scheduler`` is not supported.
    """
    if scheduler is not None:
        raise ValueError(
            f"study {NAME!r} runs its Monte Carlo in-process on local threads; `scheduler` "
            f"is not supported (got {scheduler!r}); use `threads` instead"
        )
    axes = grid(quick)
    out = prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed, **axes})
    started = time.perf_counter()
    resumed = (out / "results.csv").exists() and (out / "methods.csv").exists()
    results, methods = tables_of(out, axes, seed, threads, progress)
    v = verdicts(results, methods)
    fig_trade = tradeoff_figure(results, out / "power_vs_exceedance.png")
    fig_methods = methods_figure(methods, out / "method_errors.png")
    write_verdicts(out, v)
    wall = time.perf_counter() - started
    return write_report(
        out,
        f"Study {NAME}: linear, hardening and bistable with friction and a stroke limit"
        f"{' (quick)' * quick}",
        [
            ("Set-up", setup_section(axes, results, seed, quick, wall, resumed)),
            ("Power and stroke (Monte Carlo)", power_section(results, v, fig_trade)),
            ("Power at an exceedance budget", budget_section(results, v)),
            ("Which method predicts them", methods_section(methods, v, fig_methods)),
        ],
    )


if __name__ == "__main__":
    sys.exit(script_main(run_study))
