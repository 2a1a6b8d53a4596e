"""Building blocks of the ``dc-power`` study: a coil's bridge against its resistive figure.

The cases of one white-noise level share their paths (one group of
:func:`randvib.run_ensembles`): the resistive reference (the coil into a
matched load R_L = R_C, its load power) and the coil into a bridge with each
diode drop and battery voltage, so that the ratio of stored to resistive power
is paired, path by path (:func:`randvib.statistics.paired_ratio`). The
analytic side is the bridge's Gaussian closure and its optimum
(:func:`randvib.optimal_dc_output`), reported where offered.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

import randvib as rv
from randvib.statistics import paired_ratio


def coil_device(base: rv.Harvester, coupling) -> rv.Harvester:
    """``base``'s magnet, damping, spring and friction with the coupling ``coupling``."""
    return rv.Harvester.with_coupling(
        base.m, base.c_m, base.k, coupling, k3=base.k3, friction=base.friction
    )


def bridge_cases(base, alpha, r_coil, levels, drops, batteries) -> list:
    """The cases: per level (a group), the matched resistive coil and every (V_d, V_b)."""
    cases = []
    for group, level in enumerate(levels):
        reference = coil_device(base, rv.Resistive(alpha, r_coil, r_coil))
        labels = {"psd": level, "circuit": "resistive", "v_diode": 0.0, "battery": 0.0}
        cases.append(rv.Case(labels, reference, level, group=group))
        cases += [
            rv.Case({"psd": level, "circuit": "bridge", "v_diode": v_d, "battery": v_b},
                    coil_device(base, rv.BridgeCoil(alpha, r_coil, v_d, v_b)), level,
                    group=group)
            for v_d in drops for v_b in batteries
        ]  # fmt: skip
    return cases


def stored_table(result) -> pd.DataFrame:
    """Per bridge case: stored power and losses (95 %), the paired ratio to the resistive figure.

    ``resistive`` is the matched coil's load power at the same level;
    ``ratio`` = stored / resistive with its 95 % half-width; ``closure`` the
    bridge closure's stored power where it is offered (NaN where refused).
    """
    table = result.table
    rows = []
    for i, case in enumerate(result.cases):
        if not case.device.is_rectified:
            continue
        sim = result.simulation(i)
        ref = result.find(result.groups[i], circuit="resistive")
        ref_sim = result.simulation(ref)
        h = ref_sim.harvester
        resistive = h.c_e * h.electrical.load_fraction * ref_sim.averages.v2
        ratio, ratio_ci = paired_ratio(sim.averages.stored_power, resistive)
        try:
            closure = rv.predict(case.device, case.labels["psd"], "bridge-closure").power_stored
        except ValueError:  # beyond the closure's validity: Monte Carlo only
            closure = np.nan
        stored = sim.power_stored
        labels = {k: v for k, v in case.labels.items() if k != "circuit"}
        rows.append({**labels, "power_stored": stored.mean, "power_stored_ci95": stored.ci95,
                     "power_coil_loss": sim.power_coil_loss.mean,
                     "power_diode_loss": sim.power_diode_loss.mean,
                     "power_mechanical": sim.power_mechanical.mean,
                     "power_resistive": float(np.mean(resistive)), "ratio": ratio,
                     "ratio_ci95": ratio_ci, "closure": closure,
                     "n_paths": int(table.n_paths.iloc[i])})  # fmt: skip
    return pd.DataFrame(rows)


def optimum_table(base, alpha, r_coil, levels, drops, stored: pd.DataFrame) -> pd.DataFrame:
    """Per (level, V_d): the closure's optimal battery voltage and Monte Carlo's best grid V_b."""
    rows = []
    for level in levels:
        for v_d in drops:
            sub = stored[(stored.psd == level) & (stored.v_diode == v_d)]
            best = sub.loc[sub.power_stored.idxmax()]
            device = coil_device(base, rv.BridgeCoil(alpha, r_coil, v_d, battery=0.0))
            try:
                opt = rv.optimal_dc_output(device, level)
                closure = (opt.value, opt.power_stored, opt.where)
            except ValueError:
                closure = (np.nan, np.nan, "refused (beyond the closure's validity)")
            rows.append({"psd": level, "v_diode": v_d, "battery_optimal": closure[0],
                         "power_stored_optimal": closure[1], "optimum": closure[2],
                         "mc_best_battery": best.battery, "mc_best_power": best.power_stored,
                         "mc_best_power_ci95": best.power_stored_ci95})  # fmt: skip
    return pd.DataFrame(rows)


def overstatement(stored: pd.DataFrame) -> dict:
    """Where the resistive figure overstates the stored power (paired 95 %), and by how much.

    A case overstates when ratio + half-width < 1. Per level, the best case
    (largest ratio) is what a designer could reach on the grid: the
    resistive figure overstates it by the factor 1 / ratio.
    """
    over = stored[stored.ratio + stored.ratio_ci95 < 1.0]
    resolved = stored[stored.power_stored > 2.0 * stored.power_stored_ci95]
    best = stored.loc[stored.groupby("psd").ratio.idxmax()]
    return {
        "n_cases": int(len(stored)),
        "n_overstated": int(len(over)),
        "best_by_level": {
            float(r.psd): {
                "ratio": float(r.ratio),
                "ratio_ci95": float(r.ratio_ci95),
                "v_diode": float(r.v_diode),
                "battery": float(r.battery),
                "overstated": bool(r.ratio + r.ratio_ci95 < 1.0),
            }
            for r in best.itertuples()
        },  # fmt: skip
        # over the cases whose stored power is resolved (mean beyond two half-widths)
        "largest_factor": float(1.0 / resolved.ratio.min()) if len(resolved) else None,
        "never_conducts": int((stored.power_stored == 0).sum()),
        "best_by_drop": {float(r.v_diode): {"ratio": float(r.ratio), "psd": float(r.psd),
                                            "battery": float(r.battery)}
                         for r in stored.loc[stored.groupby("v_diode").ratio.idxmax()].itertuples()},
    }  # fmt: skip
