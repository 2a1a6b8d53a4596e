"""Energy harvested from one event, and the end stop: ``randvib study events``.

(or ``python studies/events.py OUT [--quick]``). A harvester on a bridge or a
rail sleeper is judged by what one passing vehicle gives it, not by a
stationary mean. The event here is bridge-like: Kanai-Tajimi ground-type
noise (filter at 6 Hz, zeta = 0.4, low-frequency level S) under the
Shinozuka-Sato envelope e(t) = A (exp(-t / 2 s) - exp(-2 t / s)) scaled to a
peak of 1 (rise to the peak in 0.92 s, decay over a few seconds:
int e^2 dt = 2.0 s), simulated from rest (:func:`randvib.simulate_transient`)
for 8 s, on three devices with a 5 mm stroke:

* ``linear``: the figure9 device without friction and spring (c_m = c_e =
  0.1 Ns/m, k = 57.4 N/m, m = 0.0226 kg assumed), for which the transient
  Lyapunov equation is exact (a check of the Monte Carlo) and the
  first-passage approximations (Poisson, Vanmarcke) are defined;
* ``paper``: the figure9 device (Coulomb Fc = 5.8 mN, k3 = 70742 N/m^3);
* ``bistable``: the same damping and friction with k = -57.4 N/m and its
  wells at +-2.5 mm (k3 = 9.18e6 N/m^3), starting at rest in one well.

At each intensity S the three devices run on one seed (the same base
acceleration, path by path: paired). Computed: the energy per event
E[int_0^T P_e dt] and the probability of reaching the stroke during the
event, against S; how far the stationary prediction at the envelope's peak
times the event's power-equivalent duration (int e^2 dt) is from the event's
true energy; and time-dependent statistical linearisation
(:func:`randvib.transient_response`) against Monte Carlo through the event.

The paired-ensemble runner (:func:`randvib.run_ensembles`) keeps per-path
time averages of stationary runs; an event needs snapshots at given times
from t = 0, so this study runs :func:`randvib.simulate_transient` in-process,
pairing the devices by the seed.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

import randvib as rv
from randvib.figure_style import PALETTE, new_figure, panel_letters, save_figure, styled
from randvib.formatting import percent, plus_minus
from randvib.statistics import paired_ratio
from randvib.studies import report, script_main

NAME = "events"
STROKE = 0.005  #: m, the end stops
FC = 0.0058  #: N, the paper's Coulomb level
T_END = 8.0  #: s, the simulated window: e(8 s)^2 = 0.0015
ENVELOPE = rv.ShinozukaSato.unit_peak(0.5, 2.0)
#: Report times of the time-resolved tables (s).
TIMES = tuple(np.round(np.arange(0.0, T_END + 1e-9, 0.2), 10))
QUICK = {"levels": (0.1, 0.5, 2.0), "n_paths": 400, "dt": 2.5e-4}
FULL = {"levels": (0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 4.0), "n_paths": 2000, "dt": 2.5e-4}
#: E[P_e](t) below this fraction of its peak is left out of the time-resolved error.
MEANINGFUL = 0.1

__all__ = ["devices", "event", "grid", "run_study"]


def grid(quick: bool) -> dict:
    """The intensities S ((m/s^2)^2/Hz), paths per run and the step (s)."""
    return dict(QUICK if quick else FULL)


def devices() -> dict:
    """The three devices (all with the 5 mm stroke) and where each starts."""
    paper = rv.preset("figure9").updated(stroke=STROKE)
    well = 0.0025  # m
    bistable = paper.updated(k=-paper.k, k3=paper.k / well**2)
    return {
        "linear": (paper.updated(fc=0.0, k3=0.0), "rest"),
        "paper": (paper, "rest"),
        "bistable": (bistable, "unexcited"),
    }


def event(level: float) -> rv.Enveloped:
    """The bridge-like event at low-frequency level S = ``level``."""
    return rv.Enveloped(rv.KanaiTajimi(level, 6.0, 0.4), ENVELOPE)


# ----------------------------------------------------------------- compute
def _analytic(device, ev, start):
    """The transient Lyapunov solution (None where the closure refuses the case)."""
    try:
        return rv.transient_response(device, ev, TIMES, t_end=T_END, start=start)
    except ValueError:  # a start in one well: the zero-mean closure cannot follow it
        return None


def _stationary_energy(device, ev):
    """Stationary linearisation at the envelope's peak times the power-equivalent duration (J)."""
    try:
        power = rv.predict(device, ev.peak_excitation(), "linearisation").power_electrical
    except ValueError:  # no stationary Gaussian solution
        return np.nan
    return float(power) * ev.envelope.equivalent_duration(T_END)


def simulate_level(level, axes, seed, threads):
    """Every device under one intensity on one seed: their results and analytic solutions."""
    ev = event(level)
    out = {}
    for name, (device, start) in devices().items():
        mc = rv.simulate_transient(device, ev, t_end=T_END, dt=axes["dt"],
                                   n_paths=axes["n_paths"], times=TIMES, start=start,
                                   seed=seed, threads=threads, progress=False)  # fmt: skip
        out[name] = (mc, _analytic(device, ev, start), _stationary_energy(device, ev))
    return out


def _rows(level, runs) -> tuple[list, list]:
    """The rows of results.csv and transient.csv for one intensity."""
    rows, series = [], []
    paper_energy = runs["paper"][0].path_energies
    for name, (mc, lin, stationary) in runs.items():
        energy = mc.energy_electrical
        reached = mc.peak_exceedance(STROKE)
        peaks = mc.peak_quantiles((0.5, 0.9))
        power = mc.power_electrical
        row = {
            "device": name, "level": level, "n_paths": mc.n_paths,
            "energy_mc": energy.mean, "energy_mc_ci95": energy.ci95,
            "stroke_reached_mc": reached.mean, "stroke_reached_mc_ci95": reached.ci95,
            "peak_median": peaks[0.5], "peak_p90": peaks[0.9],
            "energy_stationary": stationary,
            "energy_lin": np.nan if lin is None else lin.energy_electrical,
            "stroke_poisson": np.nan, "stroke_vanmarcke": np.nan,
            "time_error_max": np.nan, "time_error_at": np.nan, "time_error_ci95": np.nan,
        }  # fmt: skip
        ratio, half = paired_ratio(mc.path_energies, paper_energy)
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
        for i, t in enumerate(mc.times):
            series.append({
                "device": name, "level": level, "time": float(t),
                "power_mc": power.mean[i], "power_mc_ci95": power.ci95[i],
                "power_lin": np.nan if lin is None else lin.power_electrical[i],
                "stroke_reached_mc": mc.stroke_reached.mean[i],
            })  # fmt: skip
    return rows, series


def compute(axes, seed, threads, progress):
    """results.csv, transient.csv, and the runs kept for the figure (the middle intensity)."""
    rows, series, kept = [], [], None
    levels = axes["levels"]
    for i, level in enumerate(levels):
        runs = simulate_level(level, axes, seed * 1000 + i, threads)
        more, more_series = _rows(level, runs)
        rows += more
        series += more_series
        if i == len(levels) // 2:
            kept = (level, runs)
        if progress:
            print(f"{NAME}: S = {level:g} done ({i + 1}/{len(levels)})", file=sys.stderr)
    return pd.DataFrame(rows), pd.DataFrame(series), kept


# ----------------------------------------------------------------- verdicts
def _slope(sub: pd.DataFrame) -> float:
    """d log E / d log S of the energy per event (1 for a linear device)."""
    return float(np.polyfit(np.log(sub.level), np.log(sub.energy_mc), 1)[0])


def _half_level(sub: pd.DataFrame):
    """The intensity at which P(stroke reached) crosses 1/2 (log-interpolated), or None."""
    p, s = sub.stroke_reached_mc.to_numpy(), sub.level.to_numpy()
    above = np.flatnonzero(p >= 0.5)
    if above.size == 0 or above[0] == 0:
        return None if above.size == 0 else float(s[0])
    i = above[0]
    w = (0.5 - p[i - 1]) / (p[i] - p[i - 1])
    return float(np.exp(np.log(s[i - 1]) + w * (np.log(s[i]) - np.log(s[i - 1]))))


def verdicts(results: pd.DataFrame) -> dict:
    """The numbers behind the report's verdicts, computed from results.csv."""
    by = {name: sub.sort_values("level") for name, sub in results.groupby("device", sort=False)}
    linear, paper = by["linear"], by["paper"]
    z_exact = (linear.energy_mc - linear.energy_lin) / (linear.energy_mc_ci95 / 1.96)
    stationary = results.energy_stationary / results.energy_mc - 1.0
    has_stationary = results.assign(stationary_error=stationary).dropna(subset=["stationary_error"])
    lin_energy = paper.energy_lin / paper.energy_mc - 1.0
    strongest = results[results.level == results.level.max()].set_index("device")
    paper_device = devices()["paper"][0]
    return {
        "setup": {"m": float(paper_device.m), "c": float(paper_device.c)},
        "energy": {
            "slope_in_level": {name: _slope(sub) for name, sub in by.items()},
            "at_strongest_level": float(results.level.max()),
            "strongest_mJ": {n: 1e3 * float(strongest.energy_mc[n]) for n in by},
            "bistable_over_paper": {
                f"{r.level:g}": [float(r.energy_over_paper), float(r.energy_over_paper_ci95)]
                for r in by["bistable"].itertuples()
            },
            "linear_device_exact_max_abs_z": float(np.abs(z_exact).max()),
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
            "largest_time_error_where": _where(paper),
        },
        "stroke": {
            "reached_at_strongest": {n: float(strongest.stroke_reached_mc[n]) for n in by},
            "half_level": {name: _half_level(sub) for name, sub in by.items()},
            "poisson_error_max": float((linear.stroke_poisson - linear.stroke_reached_mc).max()),
            "vanmarcke_error_min": float(
                (linear.stroke_vanmarcke - linear.stroke_reached_mc).min()
            ),
            "vanmarcke_abs_error_max": float(
                (linear.stroke_vanmarcke - linear.stroke_reached_mc).abs().max()
            ),
        },
    }


def _where(paper: pd.DataFrame) -> str:
    worst = paper.loc[paper.time_error_max.abs().idxmax()]
    return (
        f"S = {worst.level:g}, t = {worst.time_error_at:g} s, "
        f"{100 * worst.time_error_max:+.1f} ± {100 * worst.time_error_ci95:.1f} %"
    )


def sentences(v: dict) -> list[str]:
    """The report's verdicts in words, from :func:`verdicts`' numbers."""
    e, st, lin, sk = v["energy"], v["stationary_times_duration"], v["linearisation"], v["stroke"]
    slopes = ", ".join(f"{n} {s:.2f}" for n, s in e["slope_in_level"].items())
    ratios = e["bistable_over_paper"]
    lo, hi = min(r[0] for r in ratios.values()), max(r[0] for r in ratios.values())
    stationary = "; ".join(
        f"{name} {percent(x['min_error'], 1, True)} to {percent(x['max_error'], 1, True)}"
        for name, x in st.items()
    )
    worst_linear = max(abs(st["linear"]["min_error"]), abs(st["linear"]["max_error"]))
    worst_other = max(max(abs(x["min_error"]), abs(x["max_error"]))
                      for name, x in st.items() if name != "linear")  # fmt: skip
    decay = 2 * v["setup"]["m"] / v["setup"]["c"]
    holds = "holds" if worst_linear <= 0.05 else "does not hold"
    reading = (f"it {holds} for the linear device (within "
               f"{percent(worst_linear, 1)}; its decay time 2 m / c = {decay:.2f} s "
               f"against the envelope's {ENVELOPE.equivalent_duration(T_END):.1f} s), and errs by "
               f"up to {percent(worst_other, 0)} for the nonlinear devices, whose "
               "power is not proportional to the intensity")  # fmt: skip
    half = ", ".join(
        f"{n} {'beyond the largest S' if s is None else f'S = {s:.3g}'}"
        for n, s in sk["half_level"].items()
    )
    return [
        f"Energy per event grows with the intensity S as S^p with p = {slopes} (1 for a "
        f"linear device); the bistable device gives {lo:.2f} to {hi:.2f} times the paper's "
        "device's energy per event (paired on the same base motion).",
        f"Stationary power at the envelope's peak times the event's power-equivalent duration "
        f"misses the event's energy by {stationary}: {reading}.",
        f"Time-dependent statistical linearisation of the paper's device gives the event energy "
        f"within {percent(lin['energy_error_min'], 1, True)} to "
        f"{percent(lin['energy_error_max'], 1, True)} of Monte Carlo; its largest "
        f"error in E[P_e](t) is at {lin['largest_time_error_where']}.",
        f"The 5 mm stroke is reached in half of the events at {half}. For the linear device "
        f"Poisson's out-crossing approximation over-estimates P(stroke reached) by up to "
        f"{sk['poisson_error_max']:.3f} and Vanmarcke's is within "
        f"{sk['vanmarcke_abs_error_max']:.3f} (both approximate).",
    ]


# ----------------------------------------------------------------- figures
@styled
def energy_figure(results: pd.DataFrame, path: Path) -> Path:
    """Energy per event and P(stroke reached) against the intensity, a line per device."""
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
        ax.errorbar(sub.level, sub.stroke_reached_mc, yerr=sub.stroke_reached_mc_ci95, fmt="o-",
                    ms=4, capsize=2, color=colour, lw=1, label=f"{name}, Monte Carlo")  # fmt: skip
        if sub.stroke_poisson.notna().any():
            ax.plot(sub.level, sub.stroke_poisson, "--", color=colour, lw=1, label="Poisson")
            ax.plot(sub.level, sub.stroke_vanmarcke, ":", color=colour, lw=1, label="Vanmarcke")
    axes[0, 0].set(xscale="log", yscale="log", xlabel="intensity S ((m/s$^2$)$^2$/Hz)",
                   ylabel="energy per event (mJ)")  # fmt: skip
    axes[0, 1].set(xscale="log", xlabel="intensity S ((m/s$^2$)$^2$/Hz)",
                   ylabel="P(|z| reaches 5 mm)", ylim=(-0.02, 1.02))  # fmt: skip
    for ax in axes[0]:
        ax.grid(alpha=0.3, lw=0.5)
        ax.legend(fontsize=6)
    panel_letters(axes)
    return save_figure(fig, path)


# ----------------------------------------------------------------- report
def setup_section(axes, seed, quick, wall) -> str:
    return (
        "Event: Kanai-Tajimi noise (f0 = 6 Hz, zeta = 0.4, level S) times the Shinozuka-Sato "
        f"envelope (b = 0.5 1/s, c = 2 1/s, A = {ENVELOPE.a:.4f}: peak 1 at "
        f"{ENVELOPE.peak_time:.2f} s, int e^2 dt = {ENVELOPE.square_integral(T_END):.3f} s), "
        f"{T_END:g} s from rest. Devices (m = 0.0226 kg assumed, c_m = c_e = 0.1 Ns/m, stroke "
        "5 mm): linear (k = 57.4 N/m), paper (figure9: Coulomb 5.8 mN, k3 = 70742 N/m^3), "
        "bistable (k = -57.4 N/m, wells at +-2.5 mm, Coulomb 5.8 mN, from rest in one well). "
        f"Intensities S = {', '.join(f'{s:g}' for s in axes['levels'])} (m/s^2)^2/Hz. Monte "
        f"Carlo: Heun with the filter's states, dt = {axes['dt']:g} s, {axes['n_paths']} paths "
        f"per device and intensity, one seed per intensity shared by the three devices "
        f"(paired; seed {seed}). {'Quick mode. ' if quick else ''}Wall time {wall:.0f} s."
    )


def results_section(results: pd.DataFrame, lines: list[str], figure: Path) -> str:
    shown = results[["device", "level"]].rename(columns={"level": "S"})
    shown["energy MC (mJ)"] = plus_minus(results.energy_mc, results.energy_mc_ci95,
                                                1e3, ".4g")  # fmt: skip
    shown["transient lin. (mJ)"] = 1e3 * results.energy_lin
    shown["stationary x duration (mJ)"] = 1e3 * results.energy_stationary
    shown["/ paper (paired)"] = [
        "1 (reference)" if r.device == "paper"
        else f"{r.energy_over_paper:.3f} ± {r.energy_over_paper_ci95:.3f}"
        for r in results.itertuples()
    ]  # fmt: skip
    shown["P(stroke)"] = plus_minus(results.stroke_reached_mc,
                                           results.stroke_reached_mc_ci95, 1, ".3f")  # fmt: skip
    shown["Poisson*"] = results.stroke_poisson
    shown["Vanmarcke*"] = results.stroke_vanmarcke
    shown["median peak (mm)"] = 1e3 * results.peak_median
    return (
        f"![energy and stroke]({figure.name})\n\n**Verdicts.**\n\n"
        + "\n".join(f"- {line}" for line in lines)
        + "\n\n"
        + report.markdown_table(shown, floatfmt=".4g")
        + "\n\n* approximate (out-crossing rates of the Gaussian response), linear device only."
    )


def run_study(
    out_dir, *, quick=False, seed=0, workers=None, threads=None, scheduler=None, progress=True
) -> Path:
    """Run the events study and write ``report.md``, CSVs, figures and ``verdicts.json``.

    ``quick``: three intensities, 400 paths (well under a minute); ``threads``:
    numba threads; ``workers`` is accepted and unused (in-process);
    ``scheduler`` is not supported.
    """
    if scheduler is not None:
        raise ValueError(
            f"study {NAME!r} runs its Monte Carlo in-process on local threads; `scheduler` "
            f"is not supported (got {scheduler!r}); use `threads` instead"
        )
    axes = grid(quick)
    out = report.prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed, **axes})
    started = time.perf_counter()
    results, series, (level, runs) = compute(axes, seed, threads, progress)
    report.write_table(out, "results.csv", results)
    report.write_table(out, "transient.csv", series)
    v = verdicts(results)
    lines = sentences(v)
    figure = energy_figure(results, out / "energy_and_stroke.png")
    curves = np.linspace(0.0, T_END, 401)  # the analytic curves on a fine grid
    rv.plot_transient(
        {f"{name} device": (runs[name][0], rv.transient_response(
            devices()[name][0], event(level), curves, t_end=T_END)) for name in ("linear", "paper")},
        path=out / "transient.png",
    )  # fmt: skip
    report.write_verdicts(out, v, lines)
    wall = time.perf_counter() - started
    return report.write_report(
        out,
        f"Study {NAME}: energy and end-stop hits of one event{' (quick)' * quick}",
        [
            ("Set-up", setup_section(axes, seed, quick, wall)),
            ("Energy per event and the stroke", results_section(results, lines, figure)),
            (
                "Through the event",
                f"![transient](transient.png)\n\nMean-square displacement, velocity and "
                f"electrical power against time at S = {level:g}: Monte Carlo (95 % band) "
                "beside time-dependent statistical linearisation (the paper's device) and the "
                "exact Lyapunov solution (the linear device); dotted, the envelope's intensity.",
            ),
        ],
    )


if __name__ == "__main__":
    sys.exit(script_main(run_study))
