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

The Monte Carlo runs through the paired-ensemble runner
(:func:`randvib.run_ensembles` with :class:`randvib.EventSettings`: resumable),
one group (seed) per intensity; the tables come from
:mod:`randvib.studies.events`.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

import randvib as rv
from randvib.formatting import percent, plus_minus
from randvib.studies import report, script_main
from randvib.studies.events import (
    energy_and_stroke_figure,
    event_cases,
    event_tables,
    event_verdicts,
)

NAME = "events"
STROKE = 0.005  #: m, the end stops
FC = 0.0058  #: N, the paper's Coulomb level
T_END = 8.0  #: s, the simulated window: e(8 s)^2 = 0.0015
ENVELOPE = rv.ShinozukaSato.unit_peak(0.5, 2.0)
#: Report times of the time-resolved tables (s).
TIMES = tuple(np.round(np.arange(0.0, T_END + 1e-9, 0.2), 10))
QUICK = {"levels": (0.1, 0.5, 2.0), "n_paths": 400, "dt": 2.5e-4}
FULL = {"levels": (0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 4.0), "n_paths": 2000, "dt": 2.5e-4}

__all__ = ["devices", "event", "grid", "run_study", "sentences", "verdicts"]


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


# ----------------------------------------------------------------- verdicts
def verdicts(results: pd.DataFrame) -> dict:
    """The numbers behind the report's verdicts, computed from results.csv."""
    return event_verdicts(results, linear="linear", reference="paper", other="bistable",
                          setup=devices()["paper"][0])  # fmt: skip


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


def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True) -> Path:
    """Run the events study and write ``report.md``, CSVs, figures and ``verdicts.json``.

    ``quick``: three intensities, 400 paths (about a minute); the cases run on
    ``workers`` local processes or the Dask cluster at ``scheduler``, and a
    rerun into ``out_dir`` resumes from the finished cases.
    """
    axes = grid(quick)
    out = report.prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed, **axes})
    started = time.perf_counter()
    settings = rv.EventSettings(T_END, axes["dt"], axes["n_paths"], times=TIMES, seed=seed)
    run = rv.run_ensembles(event_cases(devices(), event, axes["levels"]), settings,
                           out_dir=out / "ensembles", workers=workers, scheduler=scheduler,
                           progress=progress, name=NAME)  # fmt: skip
    results, series = event_tables(run, reference="paper", stroke=STROKE)
    middle = len(axes["levels"]) // 2  # the group (intensity) of the transient figure
    level = axes["levels"][middle]
    report.write_table(out, "results.csv", results)
    report.write_table(out, "transient.csv", series)
    v = verdicts(results)
    lines = sentences(v)
    figure = energy_and_stroke_figure(results, STROKE, out / "energy_and_stroke.png")
    curves = np.linspace(0.0, T_END, 401)  # the analytic curves on a fine grid
    shown = {
        f"{name} device": (
            run.transient(run.find(middle, device=name)),
            rv.transient_response(devices()[name][0], event(level), curves, t_end=T_END),
        )
        for name in ("linear", "paper")
    }
    rv.plot_transient(shown, path=out / "transient.png")
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
                f"![transient](transient.png)\n\nMean-square displacement, electrical power, "
                f"the energy harvested since the event began and P(stroke reached) against "
                f"time at S = {level:g}: Monte Carlo (95 % band; the whole event's energy as "
                "one marker at its end; probabilities with Wilson intervals) beside "
                "time-dependent statistical linearisation (the paper's device) and the exact "
                "Lyapunov solution with the Poisson and Vanmarcke approximations (the linear "
                "device); dotted, the envelope's intensity.",
            ),
        ],
    )


if __name__ == "__main__":
    sys.exit(script_main(run_study))
