"""Devices through events: paired event ensembles, their tables, analytic comparisons, numbers.

A study of events runs several devices under one event per intensity S
(:class:`randvib.Enveloped`), the devices of one intensity on one seed
(paired: the same base acceleration path by path), through
:func:`randvib.run_ensembles` with :class:`randvib.EventSettings`
(:func:`event_cases` builds the cases, one group per intensity). From the
run, :func:`event_tables` computes per case the energy per event
E[int_0^T P_e dt] (J), the probability that the peak |z| reaches the stroke,
the peak quantiles, the paired energy ratio to a reference device, the
stationary prediction at the envelope's peak times the event's
power-equivalent duration int e^2 dt / e_peak^2, and time-dependent
statistical linearisation (:func:`randvib.transient_response`: the exact
Lyapunov solution for a linear device, with the Poisson and Vanmarcke
first-passage approximations) through the event; :func:`event_verdicts`
gives the numbers behind a report's verdicts and
:func:`energy_and_stroke_figure` draws the energy and the stroke against S.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from randvib.analytic.prediction import predict
from randvib.analytic.transient import transient_response
from randvib.figure_style import PALETTE, new_figure, panel_letters, save_figure, styled
from randvib.montecarlo.ensembles import Case
from randvib.statistics import paired_ratio

__all__ = [
    "energy_and_stroke_figure",
    "event_cases",
    "event_tables",
    "event_verdicts",
    "half_level",
    "level_slope",
]

#: E[P_e](t) below this fraction of its peak is left out of the time-resolved error.
MEANINGFUL = 0.1


def event_cases(devices: dict, event, levels) -> list[Case]:
    """One case per intensity and device, labelled ``device`` and ``level``; a group per intensity.

    ``devices``: {name: (Harvester, start)}; ``event(level)``: the
    :class:`randvib.Enveloped` event at intensity ``level``. Intensity i is
    group i: with a run of seed s it runs on seed ``GROUP_SEEDS * s + i``.
    """
    return [
        Case({"device": name, "level": level}, device, event(level), group=i, initial=start)
        for i, level in enumerate(levels)
        for name, (device, start) in devices.items()
    ]


def _analytic(device, ev, start, times, t_end):
    """The transient Lyapunov solution (None where the closure refuses the case)."""
    try:
        return transient_response(device, ev, times, t_end=t_end, start=start)
    except ValueError:  # a start in one well: the zero-mean closure cannot follow it
        return None


def _stationary_energy(device, ev, t_end):
    """Stationary linearisation at the envelope's peak times the power-equivalent duration (J)."""
    try:
        power = predict(device, ev.peak_excitation(), "linearisation").power_electrical
    except ValueError:  # no stationary Gaussian solution
        return np.nan
    return float(power) * ev.envelope.equivalent_duration(t_end)


def event_tables(run, *, reference: str, stroke: float):
    """The results table (a row per case) and the time-resolved table (a row per case and time).

    Parameters
    ----------
    run : EnsembleResult
        An event run of :func:`event_cases`' cases.
    reference : str
        The device the paired energy ratios are taken against.
    stroke : float
        The end stops (m): P(peak |z| over the event reaches it).

    Returns
    -------
    results : DataFrame
        ``device``, ``level``, ``n_paths``, ``energy_mc`` (J) with ``_ci95``,
        ``stroke_reached_mc`` with ``_ci95`` (the longer side of its Wilson interval,
        ``_lower`` and ``_upper``), ``peak_median`` and ``peak_p90``
        (m), ``energy_stationary``, ``energy_lin`` (J), the linear device's
        ``stroke_poisson`` and ``stroke_vanmarcke``, the largest relative
        error of the linearised E[P_e](t) (``time_error_max``, at
        ``time_error_at`` (s), ``time_error_ci95``; where E[P_e] is at least
        :data:`MEANINGFUL` of its peak) and ``energy_over_paper`` with
        ``_ci95`` (paired, over ``reference``).
    series : DataFrame
        ``device``, ``level``, ``time`` (s), ``power_mc`` (W) with ``_ci95``,
        ``power_lin`` (W) and ``stroke_reached_mc`` (by that time).
    """
    rows, series = [], []
    settings = run.settings
    times = settings.times
    for i, case in enumerate(run.cases):
        mc = run.transient(i)
        ev, device = case.excitation, case.device
        lin = _analytic(device, ev, case.initial, times, settings.t_end)
        energy = mc.energy_electrical
        reached = mc.peak_exceedance(stroke)
        peaks = mc.peak_quantiles((0.5, 0.9))
        power = mc.power_electrical
        row = {
            "device": case.labels["device"], "level": case.labels["level"], "n_paths": mc.n_paths,
            "energy_mc": energy.mean, "energy_mc_ci95": energy.ci95,
            "stroke_reached_mc": reached.mean, "stroke_reached_mc_ci95": reached.ci95,
            "stroke_reached_mc_lower": reached.lower, "stroke_reached_mc_upper": reached.upper,
            "peak_median": peaks[0.5], "peak_p90": peaks[0.9],
            "energy_stationary": _stationary_energy(device, ev, settings.t_end),
            "energy_lin": np.nan if lin is None else lin.energy_electrical,
            "stroke_poisson": np.nan, "stroke_vanmarcke": np.nan,
            "time_error_max": np.nan, "time_error_at": np.nan, "time_error_ci95": np.nan,
        }  # fmt: skip
        paper = run.transient(run.partner(i, device=reference)).path_energies
        ratio, half = paired_ratio(mc.path_energies, paper)
        row["energy_over_paper"], row["energy_over_paper_ci95"] = ratio, half
        if lin is not None:
            if lin.stroke_reached_poisson is not None:
                row["stroke_poisson"] = float(lin.stroke_reached_poisson[-1])
                row["stroke_vanmarcke"] = float(lin.stroke_reached_vanmarcke[-1])
            error = lin.power_electrical / power.mean - 1.0
            keep = power.mean > MEANINGFUL * power.mean.max()
            worst = int(np.flatnonzero(keep)[np.argmax(np.abs(error[keep]))])
            row["time_error_max"] = float(error[worst])
            row["time_error_at"] = float(mc.times[worst])
            row["time_error_ci95"] = float(lin.power_electrical[worst] * power.ci95[worst]
                                           / power.mean[worst] ** 2)  # fmt: skip
        rows.append(row)
        for k, t in enumerate(mc.times):
            series.append({
                "device": row["device"], "level": row["level"], "time": float(t),
                "power_mc": power.mean[k], "power_mc_ci95": power.ci95[k],
                "power_lin": np.nan if lin is None else lin.power_electrical[k],
                "stroke_reached_mc": mc.stroke_reached.mean[k],
            })  # fmt: skip
    return pd.DataFrame(rows), pd.DataFrame(series)


def level_slope(sub: pd.DataFrame) -> float:
    """d log E / d log S of the energy per event (1 for a linear device)."""
    return float(np.polyfit(np.log(sub.level), np.log(sub.energy_mc), 1)[0])


def half_level(sub: pd.DataFrame):
    """The intensity at which P(stroke reached) crosses 1/2 (log-interpolated), or None."""
    p, s = sub.stroke_reached_mc.to_numpy(), sub.level.to_numpy()
    above = np.flatnonzero(p >= 0.5)
    if above.size == 0 or above[0] == 0:
        return None if above.size == 0 else float(s[0])
    i = above[0]
    w = (0.5 - p[i - 1]) / (p[i] - p[i - 1])
    return float(np.exp(np.log(s[i - 1]) + w * (np.log(s[i]) - np.log(s[i - 1]))))


def event_verdicts(
    results: pd.DataFrame, *, linear: str, reference: str, other: str, setup
) -> dict:
    """The numbers behind a report's verdicts, computed from :func:`event_tables`' results.

    ``linear``: the linear device (exact analytic check, first-passage
    approximations); ``reference``: the device of the paired ratios and of
    the linearisation's accuracy; ``other``: the device whose energy is
    compared with the reference's; ``setup``: the reference Harvester (its m
    and c give the linear decay time).
    """
    by = {name: sub.sort_values("level") for name, sub in results.groupby("device", sort=False)}
    lin_dev, paper = by[linear], by[reference]
    z_exact = (lin_dev.energy_mc - lin_dev.energy_lin) / (lin_dev.energy_mc_ci95 / 1.96)
    stationary = results.energy_stationary / results.energy_mc - 1.0
    has_stationary = results.assign(stationary_error=stationary).dropna(subset=["stationary_error"])
    lin_energy = paper.energy_lin / paper.energy_mc - 1.0
    strongest = results[results.level == results.level.max()].set_index("device")
    first_passage = lin_dev.stroke_vanmarcke - lin_dev.stroke_reached_mc
    worst = paper.loc[paper.time_error_max.abs().idxmax()]
    return {
        "setup": {"m": float(setup.m), "c": float(setup.c)},
        "energy": {
            "slope_in_level": {name: level_slope(sub) for name, sub in by.items()},
            "at_strongest_level": float(results.level.max()),
            "strongest_mJ": {n: 1e3 * float(strongest.energy_mc[n]) for n in by},
            f"{other}_over_{reference}": {
                f"{r.level:g}": [float(r.energy_over_paper), float(r.energy_over_paper_ci95)]
                for r in by[other].itertuples()
            },
            f"{linear}_device_exact_max_abs_z": float(np.abs(z_exact).max()),
        },
        "stationary_times_duration": {
            name: {
                "min_error": float(sub.stationary_error.min()),
                "max_error": float(sub.stationary_error.max()),
            }
            for name, sub in has_stationary.groupby("device", sort=False)
        },  # fmt: skip
        "linearisation": {
            "energy_error_min": float(lin_energy.min()),
            "energy_error_max": float(lin_energy.max()),
            "largest_time_error": float(paper.time_error_max.abs().max()),
            "largest_time_error_where": (
                f"S = {worst.level:g}, t = {worst.time_error_at:g} s, "
                f"{100 * worst.time_error_max:+.1f} ± {100 * worst.time_error_ci95:.1f} %"
            ),
        },
        "stroke": {
            "reached_at_strongest": {n: float(strongest.stroke_reached_mc[n]) for n in by},
            "half_level": {name: half_level(sub) for name, sub in by.items()},
            "poisson_error_max": float((lin_dev.stroke_poisson - lin_dev.stroke_reached_mc).max()),
            "vanmarcke_error_min": float(first_passage.min()),
            "vanmarcke_abs_error_max": float(first_passage.abs().max()),
        },
    }


@styled
def energy_and_stroke_figure(results: pd.DataFrame, stroke: float, path: Path) -> Path:
    """Energy per event and P(stroke reached) against the intensity, a line per device.

    From :func:`event_tables`' results: Monte Carlo with 95 % bars, the
    transient linearisation and the stationary-times-duration estimate where
    defined, and the linear device's Poisson and Vanmarcke approximations.
    The stroke's label reads ``stroke`` (m).
    """
    fig, axes = new_figure(1, 2, figsize=(9.0, 3.6))
    for i, (name, sub) in enumerate(results.groupby("device", sort=False)):
        sub = sub.sort_values("level")
        colour = PALETTE[i]
        ax = axes[0, 0]
        ax.errorbar(sub.level, 1e3 * sub.energy_mc, yerr=1e3 * sub.energy_mc_ci95, fmt="o",
                    ms=4, capsize=2, color=colour, label=f"{name}, Monte Carlo")  # fmt: skip
        if sub.energy_lin.notna().any():
            ax.plot(sub.level, 1e3 * sub.energy_lin, "-", color=colour, lw=1,
                    label=f"{name}, transient linearisation")  # fmt: skip
        if sub.energy_stationary.notna().any():
            ax.plot(sub.level, 1e3 * sub.energy_stationary, ":", color=colour, lw=1,
                    label=f"{name}, stationary x duration")  # fmt: skip
        ax = axes[0, 1]
        reached = sub.stroke_reached_mc
        bars = [reached - sub.stroke_reached_mc_lower, sub.stroke_reached_mc_upper - reached]
        ax.errorbar(sub.level, reached, yerr=bars, fmt="o-", ms=4, capsize=2, color=colour,
                    lw=1, label=f"{name}, Monte Carlo (Wilson 95 %)")  # fmt: skip
        if sub.stroke_poisson.notna().any():
            # both approximations assume the Gaussian response of a linear device
            ax.plot(sub.level, sub.stroke_poisson, "--", color=colour, lw=1,
                    label=f"{name}, Poisson (linear device only)")  # fmt: skip
            ax.plot(sub.level, sub.stroke_vanmarcke, ":", color=colour, lw=1,
                    label=f"{name}, Vanmarcke (linear device only)")  # fmt: skip
    axes[0, 0].set(xscale="log", yscale="log", xlabel="intensity S ((m/s$^2$)$^2$/Hz)",
                   ylabel="energy per event (mJ)")  # fmt: skip
    axes[0, 1].set(xscale="log", xlabel="intensity S ((m/s$^2$)$^2$/Hz)",
                   ylabel=f"P(|z| reaches {1e3 * stroke:g} mm)", ylim=(-0.02, 1.02))  # fmt: skip
    for ax in axes[0]:
        ax.grid(alpha=0.3, lw=0.5)
        # beside the panel, not over its points
        ax.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncols=2)
    panel_letters(axes)
    return save_figure(fig, path)
