"""The Gaussian answer's validity under tones and non-Gaussian input, against Monte Carlo (by hand).

python tests/calibration/non_gaussian_limits.py [tones|kurtosis|both|summary] [n_paths] [window_s]

(run from tests/calibration/: the per-case tables are written there, and
``summary`` summarises them again).

Measures the limits that statistical linearisation declares
(randvib/analytic/statistical_linearisation.py) for inputs beyond
stationary Gaussian noise:

* **tones** - the combined harmonic-and-random linearisation against Monte
  Carlo: devices (the paper's, a Duffing k3 = 1e6 N/m^3, with and without
  Coulomb friction Fc = 5.8 mN) under a tone at 0.8, 1 and 1.25 f_n of
  amplitude 0.25 to 4 m/s^2 on two floors (band-pass at f_n, zeta 0.25; the
  Kanai-Tajimi floor of the ``non-gaussian`` study), response-matched to
  white S = 1. For each case the indicators of the declared limits --
  friction's share of the dissipation, the cubic spring's share of the
  largest equivalent stiffness (random part's or a tone's) -- and the
  relative power error with its 95 % interval. The summary prints the
  largest |error| (less its interval) among the cases inside both declared
  limits and beyond each.
* **kurtosis** - statistical linearisation with the Gaussian input of the
  same spectrum against Monte Carlo on translation processes of kurtosis
  3 to 10 (band-pass and Kanai-Tajimi floors, the same monostable devices,
  each with its end stop): for each kurtosis, the largest error of the power
  and of the stroke exceedance beyond its interval; the limit is the largest
  |kurtosis - 3| below which every such error is within 5 %.

Results of the last run are in ``non_gaussian_limits.txt`` beside this file.
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np
import pandas as pd

import randvib as rv
from randvib.studies.gaussian_error import TOLERANCE, relative_errors
from randvib.studies.grids import fixed_paths, matched_band, response_matched

BASE = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4)
F_N = float(BASE.natural_frequency / (2 * np.pi))
FC = 0.0058
SPRINGS = {"paper": (57.4, 70742.0), "duffing": (57.4, 1e6), "bistable": (-28.7, 3.23e5)}


def floors() -> dict:
    return {
        "band-pass": matched_band(BASE, 1.0, 0.25, 1.0),
        "kanai-tajimi": response_matched(rv.KanaiTajimi(1.0, 2.0 * F_N, 0.5), BASE, 1.0),
    }


#: End stops (m), about 2.5 standard deviations out under the floors (as the study's).
STROKES = {"paper": 8e-3, "duffing": 6e-3, "bistable": 12e-3}


def devices(names) -> dict:
    out = {}
    for name in names:
        k, k3 = SPRINGS[name]
        for fc in (0.0, FC):
            friction = rv.Coulomb(fc) if fc else None
            out[(name, fc)] = BASE.updated(k=k, k3=k3, friction=friction, stroke=STROKES[name])
    return out


def indicators(device, excitation) -> dict:
    """The declared limits' indicators and the Gaussian power (NaN without an answer)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if excitation.lines():
                lin = rv.combined_linearisation(device, excitation)
                stiffness = [lin.k_eq] + [t.k_eq for t in lin.tones]
            else:
                lin = rv.statistical_linearisation(device, excitation)
                stiffness = [lin.k_eq]
        exceedance = rv.predict(device, excitation).stroke_exceedance
    except ValueError:
        return {"power_gaussian": np.nan, "friction_share": np.nan, "stiffness_share": np.nan,
                "exceedance_gaussian": np.nan}  # fmt: skip
    vv = lin.velocity_variance
    friction = max(lin.c_eq - device.c, 0.0) * vv
    share_f = friction / (friction + device.c_m * vv + lin.power_electrical)
    share_k = max(1.0 - device.k / k if k > 0 else np.inf for k in stiffness)
    return {"power_gaussian": lin.power_electrical, "friction_share": share_f,
            "stiffness_share": share_k, "exceedance_gaussian": exceedance}  # fmt: skip


def run(cases, settings) -> pd.DataFrame:
    result = rv.run_ensembles([c for c, _ in cases], settings, progress=False, name="limits")
    rows = []
    for (case, extra), r in zip(cases, result.table.itertuples(), strict=True):
        row = {**case.labels, **extra, "power_mc": r.power_electrical,
               "power_mc_ci95": r.power_electrical_ci95, "exceedance_mc": r.stroke_exceedance,
               "exceedance_mc_ci95": r.stroke_exceedance_ci95}  # fmt: skip
        row.update(indicators(case.device, case.excitation))
        rows.append(row)
    table = pd.DataFrame(rows)
    table["error"], table["error_ci95"] = relative_errors(
        table.power_gaussian, table.power_mc, table.power_mc_ci95
    )
    table["beyond"] = (table.error.abs() - table.error_ci95).clip(lower=0.0)
    table["exceedance_error"], table["exceedance_error_ci95"] = relative_errors(
        table.exceedance_gaussian, table.exceedance_mc, table.exceedance_mc_ci95
    )
    table["exceedance_beyond"] = (table.exceedance_error.abs() - table.exceedance_error_ci95).clip(
        lower=0.0
    )
    return table


def tone_cases() -> list:
    out = []
    for floor_name, floor in floors().items():
        for (name, fc), device in devices(("paper", "duffing")).items():
            for position, ratio in (("below", 0.8), ("at", 1.0), ("above", 1.25)):
                for amplitude in (0.25, 1.0, 4.0):
                    x = floor + rv.Tone(ratio * F_N, amplitude)
                    labels = {"floor": floor_name, "device": name, "fc": fc, "position": position,
                              "amplitude": amplitude}  # fmt: skip
                    out.append((rv.Case(labels, device, x, group=(floor_name, name, fc)), {}))
    return out


def kurtosis_cases() -> list:
    out = []
    for floor_name, floor in floors().items():
        translations = {k: rv.Translated(floor, k) for k in (3.0, 4.0, 6.0, 10.0)}
        # the monostable devices: a double well's Gaussian closure errs (and warns) at any kurtosis
        for (name, fc), device in devices(("paper", "duffing")).items():
            for kurtosis, x in translations.items():
                labels = {"floor": floor_name, "device": name, "fc": fc, "kurtosis": kurtosis}
                out.append((rv.Case(labels, device, x, group=(floor_name, name, fc)), {}))
    return out


def summarise_tones(table: pd.DataFrame) -> str:
    from randvib.analytic.statistical_linearisation import (
        LINEARISATION_FRICTION_SHARE_LIMIT as F_LIMIT,
    )
    from randvib.analytic.statistical_linearisation import (
        LINEARISATION_STIFFNESS_SHARE_LIMIT as K_LIMIT,
    )

    answered = table.dropna(subset=["error"])
    inside = answered[(answered.friction_share <= F_LIMIT) & (answered.stiffness_share <= K_LIMIT)]
    lines = [f"tones: {len(table)} cases, {len(answered)} with a Gaussian answer"]
    for what, rows in (("inside both limits", inside),
                       ("beyond the stiffness limit", answered[answered.stiffness_share > K_LIMIT]),
                       ("beyond the friction limit", answered[answered.friction_share > F_LIMIT])):  # fmt: skip
        if rows.empty:
            lines.append(f"  {what}: none")
            continue
        worst = rows.loc[rows.beyond.idxmax()]
        lines.append(
            f"  {what}: {len(rows)} cases, largest |error| {100 * rows.error.abs().max():.1f} %, "
            f"beyond its 95 % interval {100 * worst.beyond:.1f} % ({worst.device}, fc "
            f"{worst.fc:g}, {worst.floor}, tone {worst.amplitude:g} m/s^2 {worst.position}); "
            f"{int((rows.beyond > TOLERANCE).sum())} beyond 5 %"
        )
    return "\n".join(lines)


def summarise_kurtosis(table: pd.DataFrame) -> str:
    answered = table.dropna(subset=["error"])
    lines = [f"kurtosis: {len(table)} cases, {len(answered)} with a Gaussian answer"]
    for kurtosis, rows in answered.groupby("kurtosis"):
        for q, column in (("power", "beyond"), ("exceedance", "exceedance_beyond")):
            error = "error" if q == "power" else "exceedance_error"
            worst = rows.loc[rows[column].idxmax()]
            lines.append(
                f"  kurtosis {kurtosis:g}, {q}: largest |error| {100 * rows[error].abs().max():.1f}"
                f" %, beyond its interval {100 * worst[column]:.1f} % ({worst.device}, fc "
                f"{worst.fc:g}, {worst.floor})"
            )
    bad = answered[(answered.beyond > TOLERANCE) | (answered.exceedance_beyond > TOLERANCE)]
    lines.append(
        f"  first kurtosis with an error beyond 5 % + its interval: {bad['kurtosis'].min()}"
    )
    return "\n".join(lines)


def main(argv) -> None:
    part = argv[1] if len(argv) > 1 else "both"
    if part == "summary":  # the tables of the last run, summarised again
        print(summarise_tones(pd.read_csv("non_gaussian_limits_tones.csv")))
        print(summarise_kurtosis(pd.read_csv("non_gaussian_limits_kurtosis.csv")))
        return
    n_paths = int(argv[2]) if len(argv) > 2 else 128
    window = float(argv[3]) if len(argv) > 3 else 20.0
    settings = fixed_paths(n_paths, window, dt=2.5e-4, burn_in=2.0, seed=11)
    started = time.perf_counter()
    if part in ("tones", "both"):
        table = run(tone_cases(), settings)
        table.to_csv("non_gaussian_limits_tones.csv", index=False)
        print(summarise_tones(table), flush=True)
    if part in ("kurtosis", "both"):
        table = run(kurtosis_cases(), settings)
        table.to_csv("non_gaussian_limits_kurtosis.csv", index=False)
        print(summarise_kurtosis(table), flush=True)
    print(f"{n_paths} paths x {window:g} s per case, {time.perf_counter() - started:.0f} s wall")


if __name__ == "__main__":
    main(sys.argv)
