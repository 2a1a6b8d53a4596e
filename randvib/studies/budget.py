"""Power against stroke: the power at an exceedance budget, and paired gains over a linear device.

Devices compared at several levels g of one input trace a trade-off between
the power they deliver and the time they spend beyond a stroke (a gap, an
end stop). :func:`power_at_budget` reads the power where the Monte Carlo
exceedance crosses a budget (log-log interpolation between the two levels
that bracket it; its range through the exceedance's 95 % interval), and
:func:`budget_table` does so per input and device against the linear
device; :func:`budget_verdicts` says whether a device pays there.
:func:`gains_over_linear` lists, at fixed input, the levels where a device
delivers significantly more (or less) power than the linear device on the
same paths (:meth:`randvib.EnsembleResult.paired_ratios`).

The tables hold per ``input``, level ``g`` and ``device`` (one named
"linear"): ``power_mc`` (W), ``exceedance_mc`` (the fraction of time beyond
the stroke) with ``exceedance_mc_ci95``, and the paired
``power_ratio_to_linear`` with ``power_ratio_ci95``: :func:`stroke_results`
makes them from a paired run, with the first passage to the stroke, which
:func:`first_passage_cells` writes for a report (:func:`budget_cells` the
power at the budget).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = [
    "bound_mark",
    "budget_cells",
    "budget_table",
    "budget_verdicts",
    "first_passage_cells",
    "gains_over_linear",
    "power_at_budget",
    "ratio_bound",
    "stroke_results",
]


def stroke_results(run, labels, **reference) -> pd.DataFrame:
    """The Monte Carlo table of a stroke study from a paired run (:func:`randvib.run_ensembles`).

    Per case: its ``labels`` (column names), ``power_mc`` (W) with
    ``power_mc_ci95``, ``n_paths``, ``exceedance_mc`` (fraction of time with
    |z| > stroke) with ``exceedance_mc_ci95``, ``z_rms_mc`` (m), the first
    passage to the stroke (``fp_paths_reached``, ``fp_n_paths``,
    ``fp_horizon`` (s), ``fp_mean`` with ``fp_mean_ci95`` (NaN unless every
    path reached it), ``fp_restricted_mean`` with ``fp_restricted_ci95``
    (E[min(tau, t_end)]), ``fp_median``), and the power over the reference
    case's of its group (``reference``: labels, e.g. ``device="linear"``),
    ``power_ratio_to_linear`` with ``power_ratio_ci95``
    (:meth:`randvib.EnsembleResult.paired_ratios`).
    """
    t, ratio = run.table, run.paired_ratios(**reference)
    return t[list(labels)].assign(
        power_mc=t.power_electrical, power_mc_ci95=t.power_electrical_ci95, n_paths=t.n_paths,
        exceedance_mc=t.stroke_exceedance, exceedance_mc_ci95=t.stroke_exceedance_ci95,
        z_rms_mc=np.sqrt(t.displacement_variance), fp_paths_reached=t.first_passage_reached,
        fp_n_paths=t.n_paths, fp_horizon=t.first_passage_horizon, fp_mean=t.first_passage_mean,
        fp_mean_ci95=t.first_passage_mean_ci95, fp_restricted_mean=t.first_passage_restricted_mean,
        fp_restricted_ci95=t.first_passage_restricted_mean_ci95, fp_median=t.first_passage_median,
        power_ratio_to_linear=ratio.ratio, power_ratio_ci95=ratio.ratio_ci95,
    )  # fmt: skip


def first_passage_cells(results: pd.DataFrame) -> pd.DataFrame:
    """The first passage of :func:`stroke_results` as report cells: paths that reached the
    stroke, the mean time ('>= x': the restricted mean, a lower bound, where some paths did
    not) and the median ('> horizon' where half or more did not)."""
    return pd.DataFrame({
        "reached": [f"{a}/{b}" for a, b in zip(results.fp_paths_reached, results.fp_n_paths,
                                               strict=True)],
        "mean first time (s)": [
            f"{r.fp_mean:.3g} ± {r.fp_mean_ci95:.2g}" if np.isfinite(r.fp_mean)
            else f">= {r.fp_restricted_mean:.3g} ± {r.fp_restricted_ci95:.2g}"
            for r in results.itertuples()],
        "median (s)": [f"{m:.3g}" if np.isfinite(m) else f"> {h:g}"
                       for m, h in zip(results.fp_median, results.fp_horizon, strict=True)],
    }, index=results.index)  # fmt: skip


def power_at_budget(sub: pd.DataFrame, budget: float) -> dict:
    """Power (W) where the Monte Carlo exceedance of one device and input crosses ``budget``.

    Log-log interpolation of (g, exceedance) and (g, power) between the two
    levels that bracket the budget; ``power_low``/``power_high`` repeat it
    with the exceedance at the ends of its 95 % interval (upper end: less
    power). ``bracket`` says "bracketed", "below" (every level exceeds the
    budget: the power is below the lowest level's) or "above" (none does:
    above the highest level's).
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


def budget_table(results: pd.DataFrame, budget: float) -> pd.DataFrame:
    """:func:`power_at_budget` for every input and device, with the ratio to the linear device."""
    rows = [{"input": name, "device": dev, **power_at_budget(sub, budget)}
            for (name, dev), sub in results.groupby(["input", "device"], sort=False)]  # fmt: skip
    table = pd.DataFrame(rows)
    linear = table[table.device == "linear"].set_index("input").power
    table["ratio_to_linear"] = table.power / table.input.map(linear)
    return table


def ratio_bound(device_where: str, linear_where: str) -> str:
    """How the ratio at the budget relates to the true one: "=", "<" (an upper bound), ">" or "?".

    Outside the levels run the power is the end level's: an upper bound
    ("below": the device exceeds the budget even at the lowest level) or a
    lower bound ("above").
    """
    signs = {("below", 0): "<", ("above", 0): ">", ("below", 1): ">", ("above", 1): "<"}
    found = {signs[(w, i)] for i, w in enumerate((device_where, linear_where)) if w != "bracketed"}
    return "=" if not found else found.pop() if len(found) == 1 else "?"


def bound_mark(entry: dict) -> str:
    """'< ', '> ' or '~ ' before a ratio that is a bound or unknown, else ''."""
    return {"=": "", "<": "< ", ">": "> ", "?": "~ "}[entry["ratio_bound"]]


def budget_verdicts(sub: pd.DataFrame) -> dict:
    """Per device at one input (rows of :func:`budget_table`): its power at the budget, and
    whether it beats the linear device (both bracketed, its interval above the linear one's)."""
    linear = sub[sub.device == "linear"].iloc[0]
    out = {}
    for row in sub.itertuples():
        out[row.device] = {
            "bracket": row.bracket, "g": None if np.isnan(row.g) else float(row.g),
            "power": float(row.power), "power_low": float(row.power_low),
            "power_high": float(row.power_high), "ratio_to_linear": float(row.ratio_to_linear),
            "ratio_bound": ratio_bound(row.bracket, linear.bracket),
            "beats_linear": bool(row.device != "linear" and row.bracket == "bracketed"
                                 and linear.bracket == "bracketed"
                                 and row.power_low > linear.power_high),
        }  # fmt: skip
    return out


def gains_over_linear(sub: pd.DataFrame, budget: float) -> dict:
    """Per device at one input: the levels where it beats the linear device (paired), and by how much.

    ``levels_more_power``/``levels_less_power``: the paired ratio's 95 %
    interval above/below 1; the largest ratio with where it is and the two
    devices' exceedances there; ``more_power_within_budget``: the levels with
    more power whose exceedance, half-width included, is within ``budget``.
    """
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
                {"g": float(r.g), "ratio": float(r.power_ratio_to_linear),
                 "ratio_ci95": float(r.power_ratio_ci95), "exceedance": float(r.exceedance_mc),
                 "exceedance_ci95": float(r.exceedance_mc_ci95)}
                for r in more.itertuples() if r.exceedance_mc + r.exceedance_mc_ci95 <= budget
            ],
        }  # fmt: skip
    return out


def budget_cells(table: pd.DataFrame, verdicts: dict) -> pd.DataFrame:
    """:func:`budget_table` as report cells: the power at the budget (mW) with its bracket,
    and the ratio to the linear device, marked as a bound where it is one (:func:`bound_mark`;
    ``verdicts``: :func:`budget_verdicts` by input, then device)."""
    return pd.DataFrame({
        "E[P_e] at budget (mW)": [f"{1e3 * p:.4g} [{1e3 * lo:.4g}, {1e3 * hi:.4g}]" for p, lo, hi
                                  in zip(table.power, table.power_low, table.power_high, strict=True)],
        "/ linear": [f"{bound_mark(verdicts[r.input][r.device])}{r.ratio_to_linear:.3g}"
                     for r in table.itertuples()],
    }, index=table.index)  # fmt: skip
