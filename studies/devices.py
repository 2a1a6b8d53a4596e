"""Linear, hardening or bistable, with friction and a stroke limit: ``randvib study devices``.

(or ``python studies/devices.py OUT [--quick]``). Where, if anywhere, does
bistability pay once friction and a stroke limit are in the picture? Three
devices share the magnet, damping, circuit and friction of the paper's
figure9 device (m = 0.0226 kg, c_m = c_e = 0.1 Ns/m, resistive, Coulomb
Fc = 5.8 mN) and differ in the spring only:

- **linear**: k = 57.4 N/m, k3 = 0 (f_n = 8.02 Hz);
- **hardening**: k = 57.4 N/m and the bistable device's k3;
- **bistable**: k_b = -k / 2, so that the small-amplitude frequency inside a
  well (stiffness -2 k_b = k) is the linear device's f_n. Its k3 sets the
  barrier k_b^2 / (4 k3) equal to the energy scale of the motion at the
  reference level, m E[z'^2] = m^2 S_ref / (4 c) with S_ref = 1
  (m/s^2)^2/Hz: k3 = k^2 / (16 m E[z'^2]) = 3.23e5 N/m^3, wells at 9.43 mm.

**The stroke** is one gap for all three, ``STROKE`` = 12 mm (1.27 z_w; 3.6
times the linear device's rms displacement at the reference level).

**Equal input power.** The input is scaled by a factor g of a reference: the
mean power injected into the reference linear device without friction,
c E[z'^2], is g S_ref m / 4 (W). Under white noise this is S = g S_ref, the
power white noise injects into any device; a band-pass input's peak level is
chosen so that the reference device receives the same power
(:func:`randvib.studies.grids.response_matched`). Equal base-acceleration
variance is not used: white noise has none.

**Measured** by Monte Carlo (Heun, the band's filter states with the device,
the three devices of a level on the same paths: paired), from rest at a
stable equilibrium (z = 0; z = +z_w for the bistable device): E[P_e], the
fraction of time with |z| > stroke and the first time |z| reaches it,
censored at the end of the run (:func:`randvib.studies.budget.stroke_results`).
**Predicted** by statistical linearisation, fpk-fast and fpk (white noise)
and stochastic averaging (white noise, monostable), each against Monte Carlo
with the relative error's 95 % interval. **The trade-off**: the power at
``BUDGET`` = 1 % of the time beyond the gap, interpolated over the levels
(:mod:`randvib.studies.budget`).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

import randvib as rv
from randvib.formatting import plus_minus
from randvib.studies import budget, figures, report, script_main
from randvib.studies.grids import fixed_paths, matched_band
from randvib.studies.methods import (
    accuracy_sentences,
    method_accuracy,
    methods_against_monte_carlo,
    methods_shown,
)

NAME = "devices"
FC = 0.0058  #: N, the paper's Coulomb level (Table 2, training data 1)
STROKE = 0.012  #: m, the gap: one number for every device
S_REF = 1.0  #: (m/s^2)^2/Hz, the reference white-noise level (g = 1)
BUDGET = 0.01  #: the exceedance budget: fraction of time with |z| > STROKE
BANDS = {"band at f_n": 1.0, "band at f_n/2": 0.5}  #: band-pass centre / f_n
BAND_ZETA = 0.1
DEVICES = ("linear", "hardening", "bistable")
RESOLVED = 0.25  #: exceedances compared with a method where Monte Carlo's half-width is below this
#: Monte Carlo per case: paths, window and burn-in (s), step (s).
QUICK_MC = {"n_paths": 128, "window": 10.0, "burn_in": 1.0, "dt": 2e-4}
FULL_MC = {"n_paths": 512, "window": 40.0, "burn_in": 1.0, "dt": 2e-4}

__all__ = ["answer", "compute", "devices", "grid", "input_of", "run_study", "verdicts"]


def grid(quick: bool) -> dict:
    """The study's axes: inputs, level factors g, analytic methods and Monte Carlo sizes."""
    if quick:
        return {"inputs": ("white", "band at f_n"), "levels": (1 / 16, 1 / 4, 1.0, 4.0),
                "methods": ("linearisation", "fpk-fast", "averaging"), "mc": QUICK_MC}  # fmt: skip
    return {"inputs": ("white", *BANDS), "levels": tuple(2.0**e for e in range(-5, 3)),
            "methods": ("linearisation", "fpk-fast", "fpk", "averaging"), "mc": FULL_MC}  # fmt: skip


def devices(base: rv.Harvester | None = None) -> dict:
    """The three devices and their start states {name: (Harvester, (z0, v0))} (see module doc)."""
    base = (base or rv.preset("figure9")).updated(fc=FC, stroke=STROKE)
    motion = base.m**2 * S_REF / (4 * base.c)  # m E[z'^2] of the linear friction-free device
    k_b = -base.k / 2
    k3 = k_b**2 / (4 * motion)  # barrier k_b^2 / (4 k3) = m E[z'^2]
    well = float(np.sqrt(-k_b / k3))
    return {"linear": (base.updated(k3=0.0), (0.0, 0.0)),
            "hardening": (base.updated(k3=k3), (0.0, 0.0)),
            "bistable": (base.updated(k=k_b, k3=k3), (well, 0.0))}  # fmt: skip


def input_of(name: str, g: float, base: rv.Harvester | None = None) -> rv.Excitation:
    """Input ``name`` at level factor g: equal power injected into the linear friction-free device."""
    if name == "white":
        return rv.White(g * S_REF)
    if name not in BANDS:
        raise ValueError(f"unknown input {name!r}; available: white, {', '.join(BANDS)}")
    return matched_band(base or rv.preset("figure9"), BANDS[name], BAND_ZETA, g * S_REF)


# ----------------------------------------------------------------- verdicts
def verdicts(results: pd.DataFrame, methods: pd.DataFrame) -> dict:
    """The numbers behind the report's verdicts, computed from the two tables."""
    at_budget = budget.budget_table(results, BUDGET)
    return {
        "stroke": STROKE, "budget": BUDGET, "n_levels": int(results.g.nunique()),
        "fixed_input": {name: budget.gains_over_linear(sub, BUDGET)
                        for name, sub in results.groupby("input", sort=False)},
        "at_budget": {name: budget.budget_verdicts(sub)
                      for name, sub in at_budget.groupby("input", sort=False)},
        "methods": method_accuracy(methods, where="{device}, {input}, g = {g:g}", by="device"),
    }  # fmt: skip


def answer(v: dict) -> str:
    """The study's question answered from the verdict numbers: where bistability pays, if anywhere."""
    parts, mark = [], budget.bound_mark
    for name, devs in v["fixed_input"].items():
        b, at = devs["bistable"], v["at_budget"][name]["bistable"]
        levels = ", ".join(f"{g:g}" for g in b["levels_more_power"])
        more = f"at g = {levels}" if levels else "at none of the levels"
        within = ", ".join(
            f"g = {w['g']:g} ({w['ratio']:.3f} ± {w['ratio_ci95']:.3f} times, "
            f"{100 * w['exceedance']:.2g} ± {100 * w['exceedance_ci95']:.2g} % beyond)"
            for w in b["more_power_within_budget"]
        )
        parts.append(
            f"{name}: more power than the linear device (paired, 95 %) {more}; "
            f"of these, within the budget (exceedance and its half-width at most "
            f"{100 * v['budget']:g} %): {within or 'none'}; largest "
            f"ratio {b['largest_ratio']:.3f} ± {b['largest_ratio_ci95']:.3f} at g = "
            f"{b['largest_ratio_at_g']:g}, where it spends {100 * b['exceedance_there']:.2g} % of "
            f"the time beyond the gap (linear: {100 * b['linear_exceedance_there']:.2g} %); at the "
            f"{100 * v['budget']:g} % budget it delivers {mark(at)}{at['ratio_to_linear']:.3g} "
            f"times the linear device's power ({'pays' if at['beats_linear'] else 'does not pay'})"
        )
    paying = [(name, w["g"]) for name, d in v["fixed_input"].items()
              for w in d["bistable"]["more_power_within_budget"]]  # fmt: skip
    total = sum(len(d["bistable"]["levels_more_power"]) + len(d["bistable"]["levels_less_power"])
                for d in v["fixed_input"].values())  # fmt: skip
    hardening = ", ".join(
        f"{name} {mark(d['hardening'])}{d['hardening']['ratio_to_linear']:.3g}"
        f"{' (pays)' * d['hardening']['beats_linear']}" for name, d in v["at_budget"].items()
    )  # fmt: skip
    return (
        f"At equal input, the bistable device delivers significantly more power than the linear "
        f"one while within the {100 * v['budget']:g} % budget at {len(paying)} of "
        f"{len(v['fixed_input']) * v['n_levels']} (input, level) points"
        + (": " + ", ".join(f"{n} at g = {g:g}" for n, g in paying) if paying else "")
        + f" (significantly different power at {total}). " + "; ".join(parts)
        + f". For comparison, the hardening device at the budget: {hardening}."
    )  # fmt: skip


# ----------------------------------------------------------------- report
def setup_section(axes, results, settings, quick, wall) -> str:
    rows = [{"device": name, "k (N/m)": d.k, "k3 (N/m^3)": d.k3, "start z0 (mm)": 1e3 * z0,
             "kind": d.potential.kind} for name, (d, (z0, _)) in devices().items()]  # fmt: skip
    levels = results.drop_duplicates(["input", "g"])[["input", "g", "level"]]
    mc = report.ensembles_text(
        settings, quick, wall, start=", from rest at a stable equilibrium",
        paired="one seed per input and level, shared by the three devices")  # fmt: skip
    return (
        "Same magnet, damping, circuit and friction (figure9: m = 0.0226 kg, c_m = c_e = 0.1 Ns/m, "
        f"resistive, Coulomb Fc = {1e3 * FC:g} mN); the spring differs (module docstring: the "
        "bistable device has the linear one's in-well frequency and a barrier equal to the "
        f"motion's energy scale at the reference level). Gap {1e3 * STROKE:g} mm for all. "
        "Levels g scale the input so that the power injected into the linear friction-free "
        "device is g S_ref m / 4 with S_ref = 1 (m/s^2)^2/Hz: white S = g; band-pass inputs "
        f"(damping ratio {BAND_ZETA:g}) have the peak level below. {mc}\n\n"
        + report.markdown_table(pd.DataFrame(rows), floatfmt=".4g") + "\n\n"
        + report.markdown_table(levels, floatfmt=".4g")
    )  # fmt: skip


def power_section(results, v, figure) -> str:
    shown = results[["input", "g", "device"]].copy()
    pm = plus_minus
    shown["E[P_e] (mW)"] = pm(results.power_mc, results.power_mc_ci95, 1e3, ".4f")
    shown["/ linear (paired)"] = pm(results.power_ratio_to_linear, results.power_ratio_ci95, 1.0,
                                    ".3f")  # fmt: skip
    shown["beyond gap (%)"] = pm(results.exceedance_mc, results.exceedance_mc_ci95, 100.0, ".3g")
    shown["z_rms (mm)"] = 1e3 * results.z_rms_mc
    shown = shown.join(budget.first_passage_cells(results))
    return (
        f"![power against exceedance]({figure.name})\n\n**Verdict.** {answer(v)}\n\n"
        "First passage from rest: the mean is shown only when every path reached the gap; "
        "otherwise '>= x' is the restricted mean E[min(tau, t_end)] (a lower bound, with its "
        "interval). The median is the Kaplan-Meier median (one censoring time: the empirical one) "
        "when more than half the paths reached the gap.\n\n"
        + report.markdown_table(shown, floatfmt=".4g")
    )


def budget_section(results, v) -> str:
    table = budget.budget_table(results, BUDGET)
    shown = table[["input", "device", "bracket"]].assign(**{"g at budget": table.g})
    shown = shown.join(budget.budget_cells(table, v["at_budget"]))
    return (
        f"Power at the budget of {100 * BUDGET:g} % of the time beyond the {1e3 * STROKE:g} mm gap "
        "(log-log interpolation over the levels; brackets: the same through the exceedance's "
        "95 % interval; 'below': the device exceeds the budget at every level run, so its "
        "power there is an upper bound).\n\n" + report.markdown_table(shown, floatfmt=".4g")
    )


def methods_section(methods, v, figure) -> str:
    shown = methods_shown(methods, ["input", "g", "device"])
    return (
        f"![method errors]({figure.name})\n\n**Verdict.**\n\n"
        + "\n".join(accuracy_sentences(v["methods"], by="device")) + "\n\nExceedance is compared "
        f"only where Monte Carlo resolves it (95 % half-width at most {100 * RESOLVED:g} % of the "
        "value). No analytic method here gives the first-passage time.\n\n"
        + report.markdown_table(shown, floatfmt=".4g")
    )  # fmt: skip


# ----------------------------------------------------------------- the study
def compute(axes, settings, out, workers, scheduler, progress) -> tuple[pd.DataFrame, pd.DataFrame]:
    """results.csv (every input, level and device) and methods.csv (the analytic methods)."""
    cases = [rv.Case({"input": name, "g": g, "level": input_of(name, g).level, "device": dev},
                     device, input_of(name, g), group=(name, g), initial=start)
             for name in axes["inputs"] for g in axes["levels"]
             for dev, (device, start) in devices().items()]  # fmt: skip
    run = rv.run_ensembles(cases, settings, out_dir=out / "ensembles", workers=workers,
                           scheduler=scheduler, progress=progress, name=NAME)  # fmt: skip
    results = budget.stroke_results(run, ["input", "g", "level", "device"], device="linear")
    return results, methods_against_monte_carlo(run, axes["methods"], resolved=RESOLVED)


def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True) -> Path:
    """Run the devices study and write ``report.md``, CSVs, figures and ``verdicts.json``.

    ``quick``: white noise and the band at f_n, four levels, 128 paths (under
    a minute on one core). The cases run on ``workers`` local processes or the
    Dask cluster at ``scheduler``, and resume from ``OUT/ensembles``.
    """
    axes = grid(quick)
    settings = fixed_paths(**axes["mc"], seed=seed)
    out = report.prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed, **axes})
    started = time.perf_counter()
    results, methods = compute(axes, settings, out, workers, scheduler, progress)
    report.write_table(out, "results.csv", results)
    report.write_table(out, "methods.csv", methods)
    v = verdicts(results, methods)
    fig_trade = figures.power_against_exceedance(results, DEVICES, BUDGET, STROKE,
                                                 out / "power_vs_exceedance.png")  # fmt: skip
    fig_methods = figures.method_errors_against_level(methods, DEVICES, out / "method_errors.png")
    report.write_verdicts(out, v)
    return report.write_report(
        out,
        f"Study {NAME}: linear, hardening and bistable with friction and a stroke limit"
        f"{' (quick)' * quick}",
        [("Set-up", setup_section(axes, results, settings, quick, time.perf_counter() - started)),
         ("Power and stroke (Monte Carlo)", power_section(results, v, fig_trade)),
         ("Power at an exceedance budget", budget_section(results, v)),
         ("Which method predicts them", methods_section(methods, v, fig_methods))],
    )  # fmt: skip


if __name__ == "__main__":
    sys.exit(script_main(run_study))
