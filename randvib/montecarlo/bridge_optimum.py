"""The bridge's best output by Monte Carlo: ``simulated_dc_optimum``, for any bridge and input.

:func:`randvib.optimal_dc_output` searches the bridge closure, which takes a
coil's constant-drop bridge without inductance only, within its validity. This searches Monte
Carlo instead, so it takes every bridge (coil, piezo, inductance, Shockley
diodes), every friction law and every excitation :func:`randvib.simulate`
takes, and a measured record (:class:`randvib.Measured`, simulated on the
record's own windows by :func:`randvib.monte_carlo_on_record`): the stored power on a grid of the battery voltage (or of the storage
capacitor's load, on a log grid), every grid point on the same paths (common
random numbers: the differences between points are estimated with little
noise), then a parabola through the best point and its neighbours. The answer
says whether the maximum is interior or at an end of the grid.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np

from randvib._progress import progress_bar, progress_wanted
from randvib.analytic.bridge import DcOptimum
from randvib.models.excitation import Measured
from randvib.models.harvester import Harvester
from randvib.montecarlo.bridge_step import bridge_input_rms, never_conducted
from randvib.montecarlo.on_record import monte_carlo_on_record
from randvib.montecarlo.simulation import simulate


def simulated_dc_optimum(
    harvester: Harvester,
    psd,
    bounds: tuple[float, float],
    *,
    n_grid: int = 9,
    t_end: float = 12.0,
    burn_in: float = 2.0,
    dt: float = 2e-4,
    n_paths: int = 64,
    seed: int = 0,
    progress: bool | None = None,
) -> DcOptimum:
    """The battery voltage (V) or storage load (ohm) maximising Monte Carlo's stored power.

    Parameters
    ----------
    harvester : Harvester
        With a bridge (:mod:`randvib.models.rectifier`); its battery's V_b or
        its storage load R_L is what varies.
    psd : float, Excitation or Measured
        As for :func:`randvib.simulate`; a :class:`randvib.Measured` record
        drives every grid point with the same ``n_paths`` windows of the
        record (:func:`randvib.monte_carlo_on_record`, ``burn_in`` of record
        time before each; ``t_end``, ``dt`` and ``seed`` do not apply).
    bounds : (float, float)
        The range searched: V_b (V, lower >= 0) or R_L (ohm, lower > 0, a log grid).
    n_grid : int
        Grid points (>= 3), all on the paths of ``seed``.
    t_end, burn_in, dt, n_paths, seed
        As for :func:`randvib.simulate`.
    progress : bool or None
        A bar over the grid points; None: on a terminal or in a notebook only.

    Returns
    -------
    DcOptimum
        ``value`` from a parabola through the best grid point and its
        neighbours (in log R_L for a load), ``power_stored`` Monte Carlo's at
        the best grid point, ``where`` ``"interior"`` or the end of the grid
        the best point sits on.

    Raises
    ------
    ValueError
        Where no grid point stores power (an optimum of zero power is no
        optimum): the bridge never conducted, with the transducer's RMS
        voltage against the threshold and what would help.
    """
    bridge = harvester.electrical
    if not harvester.is_rectified:
        raise ValueError("simulated_dc_optimum needs a bridge (randvib.BridgeCoil, BridgePiezo)")
    lo, hi = (float(b) for b in bounds)
    parameter = "battery" if bridge.has_battery else "r_load"
    log = parameter == "r_load"
    if not (0.0 <= lo < hi and (lo > 0.0 or not log)) or n_grid < 3:
        raise ValueError(
            f"`bounds` must be 0 <= lower < upper ({'lower > 0 for a load' if log else 'V'}) and "
            f"`n_grid` >= 3; got {bounds!r} and {n_grid!r}"
        )
    grid = np.geomspace(lo, hi, n_grid) if log else np.linspace(lo, hi, n_grid)
    power, runs = [], []
    bar = None
    if progress_wanted() if progress is None else progress:
        bar = progress_bar(n_grid, desc="optimum", unit="point")
    try:
        for value in grid:
            device = dataclasses.replace(
                harvester, electrical=dataclasses.replace(bridge, **{parameter: value})
            )
            with warnings.catch_warnings():  # one step check is enough: the grid's devices
                warnings.simplefilter("ignore")  # differ in their output only
                if isinstance(psd, Measured):
                    result = monte_carlo_on_record(
                        device, psd, segments=n_paths, burn_in=burn_in, progress=False
                    )
                else:
                    result = simulate(
                        device, psd, t_end=t_end, burn_in=burn_in, dt=dt, n_paths=n_paths,
                        seed=seed, progress=False,
                    )  # fmt: skip
            power.append(result.power_stored.mean)
            runs.append(result)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    power = np.array(power)
    if not np.max(power) > 0.0:
        raise ValueError(_nothing_stored(parameter, lo, hi, runs, n_paths))
    k = int(np.argmax(power))
    if k == 0:
        return DcOptimum(parameter, float(grid[0]), float(power[0]), "lower bound (of the grid)",
                         lo, hi)  # fmt: skip
    if k == n_grid - 1:
        return DcOptimum(parameter, float(grid[-1]), float(power[-1]),
                         "upper bound (of the grid)", lo, hi)  # fmt: skip
    x = np.log(grid[k - 1 : k + 2]) if log else grid[k - 1 : k + 2]
    a, b, _ = np.polyfit(x, power[k - 1 : k + 2], 2)
    best = -b / (2.0 * a) if a < 0 else x[1]
    best = float(np.exp(best) if log else best)
    return DcOptimum(parameter, best, float(power[k]), "interior", lo, hi)


def _nothing_stored(parameter: str, lo: float, hi: float, runs, n_paths: int) -> str:
    """Why no grid point stored power: an optimum of zero power is no optimum."""
    what = "battery voltage" if parameter == "battery" else "storage load"
    unit = "V" if parameter == "battery" else "ohm"
    head = f"no {what} in [{lo:g}, {hi:g}] {unit} stores power (Monte Carlo, {n_paths} paths)"
    # the lowest battery (the lowest threshold) or the largest load (the slowest discharge)
    run = runs[0] if parameter == "battery" else runs[-1]
    if never_conducted(run):
        return f"{head}: {run.harvester.electrical.idle_advice(bridge_input_rms(run))}"
    return (
        f"{head}: the bridge conducts only where it stores nothing (V_b = 0): search a finer "
        "range above the lower bound"
    )
