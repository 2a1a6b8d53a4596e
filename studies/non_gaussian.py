"""Tones on noise and non-Gaussian vibration against the Gaussian answer: ``randvib study non-gaussian``.

(or ``python studies/non_gaussian.py OUT [--quick]``). Harvesters on pumps
see a tone on a broadband floor; on vehicles, vibration of kurtosis 4 to 10.
How wrong is the Gaussian analytic answer -- statistical linearisation under
the Gaussian input of the same spectrum, in its combined harmonic-and-random
form under a tone (:mod:`randvib.analytic.harmonic_linearisation`) -- for
the power and for how often the end stop is struck?

**Devices.** Three springs on the paper's magnet, damping and circuit
(figure9: m = 0.0226 kg, c_m = c_e = 0.1 Ns/m, resistive), each without
friction and with Coulomb Fc = 5.8 mN: the paper's device (k = 57.4 N/m,
k3 = 70742 N/m^3, f_n = 8.02 Hz), a Duffing device (k3 = 1e6 N/m^3) and the
bistable device of the ``devices`` study (k = -28.7 N/m, k3 = 3.23e5 N/m^3:
in-well frequency f_n, wells at 9.43 mm). Each has its end stop (``STROKES``)
about 2.5 standard deviations out under the floor.

**The floor.** Kanai-Tajimi noise (filter at 2 f_n, damping ratio 0.5: a
broadband ground-like spectrum) at the level that gives the linear
friction-free device the response of white noise S = 1 (m/s^2)^2/Hz
(:func:`randvib.studies.grids.response_matched`).

**(i) A tone of growing amplitude** A on the floor, at 0.8 f_n, f_n and
1.25 f_n (random phase: stationary). **(ii) Non-Gaussian input** of the
floor's spectrum and kurtosis 3 to 10: a translation process
(:class:`randvib.Translated`, generalised-normal marginal). Monte Carlo
(Heun; the filter's states with the device, the tone as forcing in the
kernel; the translation synthesised per path) with the cases of one device
on one seed, against the Gaussian answer: the relative error with the 95 %
interval of Monte Carlo, and a verdict from it (:mod:`randvib.studies.gaussian_error`):
"errs" where the whole interval lies beyond 5 %.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

import randvib as rv
from randvib.formatting import plus_minus
from randvib.studies import figures, report, script_main
from randvib.studies.gaussian_error import TOLERANCE, gaussian_answers, verdict_counts, with_errors
from randvib.studies.grids import fixed_paths, response_matched
from randvib.studies.spectra_figure import spectra_against_linearisation

NAME = "non-gaussian"
FC = 0.0058  #: N, the paper's Coulomb level (Table 2, training data 1)
BASE = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4)
F_N = float(BASE.natural_frequency / (2 * np.pi))  #: Hz, the linear device's (8.02)
#: Springs (k N/m, k3 N/m^3) and end stops (m).
SPRINGS = {"paper": (57.4, 70742.0), "duffing": (57.4, 1e6), "bistable": (-28.7, 3.23e5)}
STROKES = {"paper": 8e-3, "duffing": 6e-3, "bistable": 12e-3}
POSITIONS = {"below": 0.8, "at": 1.0, "above": 1.25}  #: tone frequency / f_n
QUICK_MC = {"n_paths": 64, "window": 8.0, "burn_in": 1.0, "dt": 2.5e-4}
FULL_MC = {"n_paths": 256, "window": 30.0, "burn_in": 2.0, "dt": 2.5e-4}

__all__ = ["grid", "run_study", "verdicts"]


def grid(quick: bool) -> dict:
    """The study's axes: devices, tone positions and amplitudes, kurtoses, Monte Carlo sizes."""
    if quick:
        return {"devices": tuple(SPRINGS), "positions": tuple(POSITIONS), "amplitudes": (1.0,),
                "kurtoses": (6.0,), "mc": QUICK_MC}  # fmt: skip
    return {"devices": tuple(SPRINGS), "positions": tuple(POSITIONS),
            "amplitudes": (0.25, 0.5, 1.0, 2.0, 4.0), "kurtoses": (3.0, 4.0, 6.0, 8.0, 10.0),
            "mc": FULL_MC}  # fmt: skip


def floor():
    """The Kanai-Tajimi floor, response-matched to white noise S = 1 (module docstring)."""
    return response_matched(rv.KanaiTajimi(1.0, 2.0 * F_N, 0.5), BASE, 1.0)


def device(name: str, fc: float):
    """The named spring with friction ``fc`` (N) and its end stop."""
    k, k3 = SPRINGS[name]
    friction = rv.Coulomb(fc) if fc > 0 else None
    return BASE.updated(k=k, k3=k3, friction=friction, stroke=STROKES[name])


def inputs(axes) -> list[tuple[dict, object]]:
    """(labels, excitation) of every input: the floor, the tones on it, the translations of it."""
    base = floor()
    out = [({"input": "floor", "position": "none", "tone_hz": 0.0, "amplitude": 0.0,
             "kurtosis": 3.0}, base)]  # fmt: skip
    for p in axes["positions"]:
        for a in axes["amplitudes"]:
            labels = {"input": "tone", "position": p, "tone_hz": POSITIONS[p] * F_N, "amplitude": a,
                      "kurtosis": 3.0}  # fmt: skip
            out.append((labels, base + rv.Tone(POSITIONS[p] * F_N, a)))
    for kurtosis in axes["kurtoses"]:
        labels = {"input": "kurtosis", "position": "none", "tone_hz": 0.0, "amplitude": 0.0,
                  "kurtosis": kurtosis}  # fmt: skip
        out.append((labels, rv.Translated(base, kurtosis)))
    return out


def compute(axes, settings, out, workers, scheduler, progress) -> pd.DataFrame:
    """results.csv: every device under every input, Monte Carlo and the Gaussian answer."""
    cases = [rv.Case({"device": name, "fc": fc, **labels}, device(name, fc), x, group=(name, fc))
             for name in axes["devices"] for fc in (0.0, FC) for labels, x in inputs(axes)]  # fmt: skip
    run = rv.run_ensembles(cases, settings, out_dir=out / "ensembles", workers=workers,
                           scheduler=scheduler, progress=progress, name=NAME)  # fmt: skip
    table = run.table.rename(columns={
        "power_electrical": "power_mc", "power_electrical_ci95": "power_mc_ci95",
        "stroke_exceedance": "exceedance_mc", "stroke_exceedance_ci95": "exceedance_mc_ci95"})  # fmt: skip
    labels = ["device", "fc", "input", "position", "tone_hz", "amplitude", "kurtosis", "power_mc",
              "power_mc_ci95", "exceedance_mc", "exceedance_mc_ci95", "n_paths"]  # fmt: skip
    results = pd.concat([table[labels], gaussian_answers(run)], axis=1)
    results = with_errors(results, "power", "power_mc")
    return with_errors(results, "exceedance", "exceedance_mc")


# ----------------------------------------------------------------- verdicts
def _smallest(rows: pd.DataFrame, column: str, along: str):
    """The smallest ``along`` value whose ``column`` verdict is "errs"; None if none does."""
    errs = rows[rows[column] == "errs"]
    return None if errs.empty else float(errs[along].min())


def verdicts(results: pd.DataFrame) -> dict:
    """The numbers behind the report's verdicts, computed from the results table."""
    tones = results[results.input == "tone"]
    kurt = results[results.input == "kurtosis"]
    out = {"tolerance": TOLERANCE, "tones": {}, "kurtosis": {}}
    for part, rows in (("tones", tones), ("kurtosis", kurt)):
        out[part]["counts"] = {q: verdict_counts(rows, q) for q in ("power", "exceedance")}
        largest = (
            rows.loc[rows.power_error.abs().idxmax()] if rows.power_error.notna().any() else None
        )
        out[part]["largest_power_error"] = None if largest is None else {
            "error": float(largest.power_error), "ci95": float(largest.power_error_ci95),
            "where": _where(largest)}  # fmt: skip
    for (name, fc), rows in tones.groupby(["device", "fc"], sort=False):
        key = _device_key(name, fc)
        out["tones"][key] = {
            p: {q: _smallest(sub, f"{q}_verdict", "amplitude") for q in ("power", "exceedance")}
            for p, sub in rows.groupby("position", sort=False)}  # fmt: skip
    for (name, fc), rows in kurt.groupby(["device", "fc"], sort=False):
        out["kurtosis"][_device_key(name, fc)] = {
            q: _smallest(rows, f"{q}_verdict", "kurtosis") for q in ("power", "exceedance")
        }
    exact = results[(results.input == "floor")]
    out["floor_power_errors"] = {_device_key(r.device, r.fc): float(r.power_error)
                                 for r in exact.itertuples()}  # fmt: skip
    return out


def _device_key(name: str, fc: float) -> str:
    return f"{name}, {'Fc = ' + f'{1e3 * fc:g} mN' if fc > 0 else 'no friction'}"


def _where(row) -> str:
    """The case of a results row in words (its fields by name: ``kurtosis`` is also a method)."""
    kind = row["input"]
    what = (f"tone of {row['amplitude']:g} m/s^2 {row['position']} resonance" if kind == "tone"
            else f"kurtosis {row['kurtosis']:g}" if kind == "kurtosis" else "the floor alone")  # fmt: skip
    return f"{_device_key(row['device'], row['fc'])}, {what}"


# ----------------------------------------------------------------- report
def setup_section(axes, settings, quick, wall) -> str:
    x = floor()
    rows = [{"device": name, "k (N/m)": SPRINGS[name][0], "k3 (N/m^3)": SPRINGS[name][1],
             "stroke (mm)": 1e3 * STROKES[name]} for name in axes["devices"]]  # fmt: skip
    mc = report.ensembles_text(settings, quick, wall, how=" with the filter's two states",
                               paired="one seed per device, shared by its inputs")  # fmt: skip
    return (
        f"Floor: Kanai-Tajimi, S = {x.level:.4g} (m/s^2)^2/Hz at f = 0, filter {x.f0:.4g} Hz, "
        f"zeta {x.zeta:g} (variance {x.variance:.4g} (m/s^2)^2). Tones "
        + ", ".join(f"{p} resonance ({POSITIONS[p] * F_N:.3g} Hz)" for p in axes["positions"])
        + f", amplitudes {', '.join(f'{a:g}' for a in axes['amplitudes'])} m/s^2; kurtosis "
        + ", ".join(f"{k:g}" for k in axes["kurtoses"]) + " (translation process of the floor). "
        + f"Coulomb Fc = 0 and {1e3 * FC:g} mN. {mc}\n\n"
        + report.markdown_table(pd.DataFrame(rows), floatfmt=".4g")
    )  # fmt: skip


def _table(rows: pd.DataFrame) -> pd.DataFrame:
    shown = rows[["device", "fc", "position", "amplitude", "kurtosis"]].copy()
    shown["P_MC (mW)"] = plus_minus(rows.power_mc, rows.power_mc_ci95, 1e3, ".4f")
    shown["P_Gauss (mW)"] = 1e3 * rows.power_gaussian
    shown["P error (%)"] = _errors(rows.power_error, rows.power_error_ci95)
    shown["P verdict"] = rows.power_verdict
    shown["beyond stop, MC (%)"] = plus_minus(
        rows.exceedance_mc, rows.exceedance_mc_ci95, 100.0, ".3g"
    )
    shown["beyond, Gauss (%)"] = 100 * rows.exceedance_gaussian
    shown["stop error (%)"] = _errors(rows.exceedance_error, rows.exceedance_error_ci95)
    shown["stop verdict"] = rows.exceedance_verdict
    return shown


def _errors(error, half) -> list[str]:
    """Relative errors with their 95 % half-widths in %, 'n/a' without a Gaussian answer."""
    cells = plus_minus(error, half)
    return [c if np.isfinite(e) else "n/a" for c, e in zip(cells, error, strict=True)]


def part_section(results, v, part: str, figure: Path) -> str:
    inp = "tone" if part == "tones" else "kurtosis"
    rows = results[results.input.isin([inp, "floor"])]
    counts = v[part]["counts"]
    largest = v[part]["largest_power_error"]
    sentence = "; ".join(
        f"{q}: errs by more than {100 * TOLERANCE:g} % at {c['errs']} of {sum(c.values())} cases "
        f"({c['within']} within, {c['undecided']} undecided, {c['no answer']} without an answer)"
        for q, c in counts.items())  # fmt: skip
    onset = "; ".join(f"{key}: {_onset_words(entry, part)}" for key, entry in v[part].items()
                      if key not in ("counts", "largest_power_error"))  # fmt: skip
    worst = ("" if largest is None else f" The largest power error is {100 * largest['error']:+.1f} "
             f"± {100 * largest['ci95']:.1f} % ({largest['where']}).")  # fmt: skip
    along = "tone amplitude at which it first errs" if part == "tones" else (
        "kurtosis at which it first errs")  # fmt: skip
    return (
        f"![Gaussian errors]({figure.name})\n\n**Verdict.** The Gaussian answer {sentence}.{worst} "
        f"Smallest {along}, by device: {onset}.\n\n"
        + report.markdown_table(_table(rows), floatfmt=".4g")
    )


def _onset_words(entry: dict, part: str) -> str:
    """ "never", or where the verdict first reads "errs": "power from 2 m/s^2 at resonance"."""
    if part == "kurtosis":
        words = [f"{q} from kurtosis {k:g}" for q, k in entry.items() if k is not None]
    else:
        words = [f"{q} from {a:g} m/s^2 {p} resonance" for p, by in entry.items()
                 for q, a in by.items() if a is not None]  # fmt: skip
    return ", ".join(words) or "never"


# ----------------------------------------------------------------- the study
def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True) -> Path:
    """Run the non-Gaussian study and write ``report.md``, ``results.csv``, figures and ``verdicts.json``.

    ``quick``: one tone amplitude at three positions and kurtosis 6, 64
    paths of 8 s (a few minutes on one core). The cases run on ``workers``
    local processes or the Dask cluster at ``scheduler``, and resume from
    ``OUT/ensembles``.
    """
    axes = grid(quick)
    settings = fixed_paths(**axes["mc"], seed=seed)
    out = report.prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed, **axes})
    started = time.perf_counter()
    results = compute(axes, settings, out, workers, scheduler, progress)
    report.write_table(out, "results.csv", results)
    v = verdicts(results)
    tones = results[results.input == "tone"]
    fig_tones = figures.gaussian_errors(tones, "amplitude", "tone amplitude A (m/s$^2$)",
                                        "position", out / "tone_errors.png")  # fmt: skip
    kurt = results[results.input == "kurtosis"]
    fig_kurt = figures.gaussian_errors(kurt, "kurtosis", "kurtosis of the input", None,
                                       out / "kurtosis_errors.png")  # fmt: skip
    amplitude = max(axes["amplitudes"])
    spectra_against_linearisation(
        {f"{name}, Fc = {1e3 * FC:g} mN": device(name, FC) for name in ("paper", "duffing")},
        floor() + rv.Tone(F_N, amplitude), settings, out / "spectra.png", n_paths=16,
    )  # fmt: skip
    report.write_verdicts(out, v)
    wall = time.perf_counter() - started
    return report.write_report(
        out,
        f"Study {NAME}: tones on noise and non-Gaussian vibration against the Gaussian answer"
        f"{' (quick)' * quick}",
        [("Set-up", setup_section(axes, settings, quick, wall)),
         ("A tone of growing amplitude on the floor", part_section(results, v, "tones", fig_tones)),
         ("Non-Gaussian input of the floor's spectrum", part_section(results, v, "kurtosis",
                                                                      fig_kurt)),
         ("Where the power comes from",
          f"![spectra](spectra.png)\n\nResponse spectra under the floor and a tone of {amplitude:g} "
          "m/s^2 at resonance, with friction: Monte Carlo (Welch on 16 recorded paths, 95 % band; "
          "the tone's line by projection, with its 95 % bar) and the combined linearisation "
          "(the random part's spectrum, the line as a diamond).")],
    )  # fmt: skip


if __name__ == "__main__":
    sys.exit(script_main(run_study))
