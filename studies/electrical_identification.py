"""The whole harvester from what users measure: ``randvib study electrical-identification``.

(or ``python studies/electrical_identification.py OUT [--quick]``). Two
devices are synthesised under the paper's band-limited shaker excitation
(4-20 Hz), every channel with white sensor noise of 1 % of its RMS:

* a **coil** harvester with Coulomb friction and inductance (the paper's
  mechanics, Table 2 Coulomb with m = 0.0226 kg; alpha = 1 Wb/m, R_C = 2 ohm,
  L = 20 mH), recorded at two loads, 3 and 30 ohm;
* a **piezo** harvester with a Duffing spring (m = 0.01 kg, c = 0.01 Ns/m,
  k = 100 N/m, k3 = 2e6 N/m^3, theta = 5e-4 N/V, C_p = 100 nF) at 100 kohm.

Each is identified (coupling included, the mass given) from the displacement
only, from the load voltage only and from both. What the records cannot fix
is refused before fitting, with what to add (docs/identification.md, "What
records can fix"); the rest are fitted. Reported: the parameters against the
truth with their 95 % intervals, the intervals' coverage over the seeds, and
the load power each identified device predicts (statistical linearisation,
S = 0.5 (m/s^2)^2/Hz) against the true device's, at the load that is best for
the linear device under white noise (the coupling's closed form).
The verdict says which channel identifies what. (Linearisation is off by some
per cent for the piezo's hardening spring, for the truth and the estimates alike:
the comparison is of devices, not of the method.)

The quick run (one seed, 1 s records, a small search started next to the
truth) only exercises the pipeline; the full run searches from scratch with
identify's defaults, over several seeds.
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

import randvib as rv
from randvib.figure_style import PALETTE, new_figure, panel_letters, save_figure
from randvib.studies import report, script_main

#: The coil harvester: paper Table 2 (Coulomb, training data 1) and a strong coil.
COIL = dict(m=0.0226, c=0.049, k=57.4, k3=70742.0, fc=0.0058, alpha=1.0, r_coil=2.0,
            inductance=0.02)  # fmt: skip
#: The piezo harvester with a Duffing spring.
PIEZO = dict(m=0.01, c=0.01, k=100.0, k3=2e6, theta=5e-4, capacitance=1e-7)
#: device -> (truth, friction model, coupling, loads (ohm), RMS base acceleration (m/s^2)).
DEVICES = {
    "coil": (COIL, "coulomb", "inductive", (3.0, 30.0), 2.0),
    "piezo": (PIEZO, "viscous", "piezo", (1e5,), 2.0),
}
#: What each channel set fits.
CHANNELS = {
    "displacement": ("relative_displacement",),
    "voltage": ("voltage",),
    "both": ("relative_displacement", "voltage"),
}
#: Sensor noise on every channel, as a share of its RMS.
NOISE = 0.01
#: The excitation of the power predictions: white, one-sided PSD (m/s^2)^2/Hz.
PSD = 0.5

__all__ = ["CHANNELS", "DEVICES", "device", "run_study", "settings_for"]


def settings_for(quick: bool) -> dict:
    """Seeds, record length and rate, the search (and whether it starts near the truth)."""
    if quick:
        # the polish from 5 % off: a pipeline check, so a bounded number of steps
        return dict(seeds=(0,), duration=0.6, fs=1000.0, popsize=8, generations=2, near=True,
                    polish_maxfev=20)  # fmt: skip
    return dict(seeds=tuple(range(4)), duration=4.0, fs=1000.0, popsize=30, generations=60,
                near=False, polish_maxfev=None)  # fmt: skip


def device(name: str, r_load: float, scale: float = 1.0) -> rv.Harvester:
    """The ``name`` harvester at load ``r_load`` (every parameter times ``scale``)."""
    truth, model, coupling, _, _ = DEVICES[name]
    p = {k: v * scale for k, v in truth.items()}
    if coupling == "piezo":
        electrical = rv.Piezo(p["theta"], p["capacitance"], r_load)
    else:
        electrical = rv.Inductive(p["alpha"], r_load, p["r_coil"], p["inductance"])
    friction = rv.Coulomb(p["fc"]) if model == "coulomb" else None
    return rv.Harvester.with_coupling(p["m"], p["c"], p["k"], electrical, k3=p["k3"],
                                      friction=friction)  # fmt: skip


def records(name: str, seed: int, settings: dict) -> list:
    """One record per load: displacement and load voltage, each with 1 % sensor noise."""
    _, _, _, loads, rms = DEVICES[name]
    out = []
    for i, r_load in enumerate(loads):
        common = dict(duration=settings["duration"], sample_rate=settings["fs"],
                      seed=[seed, i], outputs=CHANNELS["both"], name=f"{name}-{r_load:g}ohm")  # fmt: skip
        clean = rv.synthetic_record(device(name, r_load), rms, **common)
        noise = {kind: NOISE * float(np.std(clean[kind])) for kind in CHANNELS["both"]}
        out.append(rv.synthetic_record(device(name, r_load), rms, noise=noise, **common))
    return out


def fit(name: str, channels: str, seed: int, settings: dict):
    """The identification of ``name`` from ``channels`` (None and the refusal if refused)."""
    truth, model, coupling, loads, _ = DEVICES[name]
    try:
        result = rv.identify(
            records(name, seed, settings), model, m=truth["m"], coupling=coupling,
            r_load=loads, outputs=CHANNELS[channels], seed=seed, progress=False,
            popsize=settings["popsize"], maxiter=settings["generations"],
            polish_maxfev=settings["polish_maxfev"],
            init=device(name, loads[0], 1.05) if settings["near"] else None,
        )  # fmt: skip
    except rv.IdentifiabilityError as refusal:
        return None, str(refusal)
    return result, ""


def parameter_rows(name, channels, seed, result, refusal) -> list:
    """Estimate, standard error, 95 % interval and coverage of each free parameter."""
    truth = DEVICES[name][0]
    if result is None:
        return [dict(device=name, channels=channels, seed=seed, parameter="", truth=np.nan,
                     estimate=np.nan, standard_error=np.nan, lower=np.nan, upper=np.nan,
                     covered=np.nan, refused=refusal)]  # fmt: skip
    rows = []
    for p in (n for n in truth if n in result.free):
        lo, hi = result.confidence_intervals.get(p, (np.nan, np.nan))
        rows.append(dict(device=name, channels=channels, seed=seed, parameter=p, truth=truth[p],
                         estimate=result.parameters[p],
                         standard_error=result.standard_errors.get(p, np.nan), lower=lo,
                         upper=hi, covered=float(lo <= truth[p] <= hi), refused=""))  # fmt: skip
    return rows


def reference_load(name: str) -> float:
    """The load (ohm) the powers are compared at: the linear device's white-noise optimum
    (the coupling's closed form, without friction or the cubic spring)."""
    truth = DEVICES[name][0]
    electrical = device(name, 1.0).electrical
    return float(electrical.white_noise_optimal_load(truth["m"], truth["c"], truth["k"]))


def power_row(name, channels, seed, result) -> dict:
    """Load power the identified device predicts, against the true device's, at the reference load."""
    r_load = reference_load(name)
    with warnings.catch_warnings():  # the method's validity: the same for truth and estimate
        warnings.filterwarnings("ignore", message="the cubic spring takes")
        true_power = rv.expected_power(device(name, r_load), PSD, into="load")
        predicted = np.nan
        if result is not None:
            predicted = rv.expected_power(result.harvester(r_load=r_load), PSD, into="load")
    return dict(device=name, channels=channels, seed=seed, r_load=r_load,
                true_power=float(true_power), predicted_power=float(predicted),
                relative_error=float(predicted / true_power - 1.0))  # fmt: skip


def coverage_table(rows: pd.DataFrame) -> pd.DataFrame:
    """Per device, channels and parameter: intervals covering the truth, with the share's
    exact (Clopper-Pearson) 95 % interval, and the median relative error."""
    fitted = rows[rows.refused == ""]
    out = []
    for (dev, ch, p), g in fitted.groupby(["device", "channels", "parameter"], sort=False):
        hits, n = int(g.covered.sum()), len(g)
        lo = stats.beta.ppf(0.025, hits, n - hits + 1) if hits else 0.0
        hi = stats.beta.ppf(0.975, hits + 1, n - hits) if hits < n else 1.0
        error = float(np.median(np.abs(g.estimate / g.truth - 1.0)))
        out.append(dict(device=dev, channels=ch, parameter=p, covered=hits, fits=n,
                        share_low=lo, share_high=hi, median_relative_error=error))  # fmt: skip
    return pd.DataFrame(out)


#: Relative standard error beyond which a parameter counts as not determined (as identify's).
UNDETERMINED = 0.5
#: How the verdict names each channel set.
SAID = {"displacement": "the displacement", "voltage": "the load voltage", "both": "both channels"}


def verdict(rows: pd.DataFrame, powers: pd.DataFrame) -> list[str]:
    """Which channel identifies what, device by device (from the tables)."""
    out = []
    for dev in DEVICES:
        parts = []
        for ch in CHANNELS:
            g = rows[(rows.device == dev) & (rows.channels == ch)]
            refused = g[g.refused != ""]
            seeds, lost = g.seed.nunique(), refused.seed.nunique()
            lead = f"from {SAID[ch]}"
            if lost:  # the refusal's reason, without the list of what to add
                why = refused.refused.iloc[0].split(" (", 1)[0].split(": ", 1)[0]
                if lost == seeds:
                    parts.append(f"{lead} refused on every seed: {why} (with what to add)")
                    continue
                lead += f" (refused on {lost} of {seeds} seeds: {why}; on the other {seeds - lost})"
            p = powers[(powers.device == dev) & (powers.channels == ch)]
            parts.append(_channel_verdict(lead, g[g.refused == ""], p))
        out.append(f"{dev}: " + "; ".join(parts) + ".")
    return out


def _channel_verdict(lead: str, g: pd.DataFrame, p: pd.DataFrame) -> str:
    """What one channel set's fitted seeds (rows ``g``, powers ``p``) determine, in words."""
    relative = (g.standard_error / g.estimate.abs()).groupby(g.parameter).median()
    fixed = [name for name in relative.index if relative[name] <= UNDETERMINED]
    loose = [name for name in relative.index if relative[name] > UNDETERMINED]
    if not fixed:
        return f"{lead} nothing is determined"
    return (
        f"{lead} {', '.join(fixed)} are identified (median relative standard "
        f"error {100 * float(relative[fixed].median()):.2g} %)"
        + (f", {', '.join(loose)} not determined (relative standard error above "
           f"{100 * UNDETERMINED:g} %)" if loose else "")
        + f"; {100 * float(g.covered.mean()):.0f} % of the 95 % intervals cover the "
        f"truth; the load power at the reference load within "
        f"{100 * float(np.max(np.abs(p.relative_error))):.2g} %"
    )  # fmt: skip


def figure(rows: pd.DataFrame, path: Path) -> Path:
    """Estimate / truth - 1 with its 95 % interval, per parameter and channel set."""
    fig, axes = new_figure(1, len(DEVICES), figsize=(7.0, 2.8))
    for ax, dev in zip(axes[0], DEVICES, strict=True):
        params = [p for p in DEVICES[dev][0] if p in set(rows[rows.device == dev].parameter)]
        for j, ch in enumerate(CHANNELS):
            g = rows[(rows.device == dev) & (rows.channels == ch) & (rows.refused == "")]
            g = g.groupby("parameter").first()
            x = [i + 0.2 * (j - 1) for i, p in enumerate(params) if p in g.index]
            sel = [p for p in params if p in g.index]
            if not sel:
                continue
            est = g.loc[sel]
            y = 100 * (est.estimate / est.truth - 1)
            err = [
                100 * (est.estimate - est.lower) / est.truth,
                100 * (est.upper - est.estimate) / est.truth,
            ]
            ax.errorbar(x, y, yerr=err, fmt="o", color=PALETTE[j], label=ch)
        ax.axhline(0.0, color="black", lw=0.6)
        ax.set_xticks(range(len(params)), params, rotation=45)
        ax.set_ylabel("estimate / truth - 1 (%)")
        ax.set_title(f"{dev} (first seed)", loc="right")
    handles, labels = axes[0, 0].get_legend_handles_labels()  # beside the data, not over it
    fig.legend(handles, labels, loc="outside lower center", ncols=len(CHANNELS), frameon=False)
    panel_letters(axes[0])
    return save_figure(fig, path)


def run_study(
    out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True, threads=None
) -> Path:
    """Run the campaign; write the tables, the figure and ``report.md`` into ``out_dir``.

    ``seed`` offsets the seeds; ``workers`` and ``scheduler`` are not used
    (each identification runs in this process on ``threads`` numba threads).
    """
    from randvib.studies import campaign

    settings = settings_for(quick)
    identity = {"study": "electrical-identification", "quick": bool(quick), "seed": int(seed),
                **{k: list(v) if isinstance(v, tuple) else v for k, v in settings.items()}}  # fmt: skip
    out = report.prepare_output_dir(out_dir, identity, {"threads": threads})
    campaign.set_threads(threads)
    start = time.perf_counter()
    rows, powers = [], []
    for s in (seed + k for k in settings["seeds"]):
        for dev in DEVICES:
            for ch in CHANNELS:
                result, refusal = fit(dev, ch, s, settings)
                rows += parameter_rows(dev, ch, s, result, refusal)
                if result is not None:
                    powers.append(power_row(dev, ch, s, result))
    rows, powers = pd.DataFrame(rows), pd.DataFrame(powers)
    coverage = coverage_table(rows)
    for name, table in (
        ("parameters.csv", rows),
        ("coverage.csv", coverage),
        ("power.csv", powers),
    ):
        report.write_table(out, name, table)
    figure(rows[rows.seed == seed + settings["seeds"][0]], out / "parameters.png")
    sentences = verdict(rows, powers)
    report.write_verdicts(out, {"coverage": coverage.to_dict("records")}, sentences)
    elapsed = time.perf_counter() - start
    return report.write_report(
        out, "The whole harvester from what users measure",
        [("Verdict", "\n\n".join(sentences)),
         ("Parameters against the truth", "![parameters](parameters.png)\n\n"
          + report.markdown_table(rows[rows.refused == ""].drop(columns="refused"), ".4g")),
         ("Refused", report.markdown_table(rows[rows.refused != ""][["device", "channels", "seed",
                                                                      "refused"]])),
         ("Coverage of the 95 % intervals over the seeds", report.markdown_table(coverage, ".3g")),
         ("Load power predicted by each identified device", report.markdown_table(powers, ".4g"))],
        intro=_setup(settings, quick, elapsed),
    )  # fmt: skip


def _setup(settings, quick, elapsed) -> str:
    how = ("a small search started 5 % from the truth (quick run: the pipeline only)"
           if settings["near"] else "identify's default search from scratch")  # fmt: skip
    return (
        f"{len(settings['seeds'])} seed(s); records of {settings['duration']:g} s at "
        f"{settings['fs']:g} Hz under 4-20 Hz base excitation, every channel with white noise "
        f"of {100 * NOISE:g} % of its RMS; SaDE {settings['popsize']} x {settings['generations']}"
        f", {how}; the mass given. Wall time {elapsed:.0f} s."
    )


if __name__ == "__main__":
    sys.exit(script_main(run_study))
