"""Human-readable output helpers for the CLI: tables, and the device and excitation used.

Numbers are shown to the precision they have, by the rules of
:mod:`randvib.formatting`: an analytic value to six significant digits, a
Monte Carlo mean to the decimal of the second significant digit of its 95 %
half-width (the half-width itself to two digits), so that no digit is
printed that the ensemble does not support; units come from
:mod:`randvib.quantities`. JSON output is never rounded.
"""

from __future__ import annotations

import numpy as np
from tabulate import tabulate

from randvib.formatting import cell, compact
from randvib.quantities import QUANTITIES, unit

#: Table columns that hold words, not numbers.
TEXT_COLUMNS = ("unit", "status", "")


def print_table(rows, headers) -> None:
    """A plain table: numbers as :func:`randvib.formatting.cell`, right-aligned."""
    rows = [[v if isinstance(v, str) else cell(v) for v in row] for row in rows]
    # numbers flush right; the first column and text columns flush left
    align = ["left"] + ["left" if h in TEXT_COLUMNS else "right" for h in headers[1:]]
    print(tabulate(rows, headers=headers, disable_numparse=True, colalign=tuple(align)))


def _assignments(values: dict, units: dict) -> str:
    """``name value unit, ...`` with four significant digits."""
    return ", ".join(
        f"{name} {cell(value, 4)} {units.get(name, '')}".rstrip() for name, value in values.items()
    )


def _units(model) -> dict:
    """A friction law's or a coupling's parameter units, as its class declares them."""
    return {name: spec.unit for name, spec in type(model).parameter_specs().items()}


def _quantity_units(names) -> dict:
    """The units of ``names`` from :mod:`randvib.quantities` (a name not there has none)."""
    return {name: unit(name) for name in names if name in QUANTITIES}


def with_units(obj: dict, electrical=None, extra: dict | None = None) -> dict:
    """A JSON object with a ``units`` entry: the unit of each of its quantities.

    Every key of ``obj`` that :mod:`randvib.quantities` declares with a unit
    (a circuit state's in its coupling's unit) gets one, as identify's
    ``units`` entry gives its parameters'; ``extra`` adds others (a design's
    varied parameters). Keys that hold words (method, friction) have none.
    """
    units = {k: unit(k, electrical) for k in obj if k in QUANTITIES and unit(k, electrical)}
    return {**obj, "units": {**units, **(extra or {})}}


#: The device's own parameters, shown first.
DEVICE_PARAMETERS = ("m", "c_m", "c_e", "k", "k3")


def describe_device(harvester) -> str:
    """One line: the device actually simulated or predicted (after preset and options)."""
    own = {name: getattr(harvester, name) for name in DEVICE_PARAMETERS}
    if harvester.has_circuit:
        del own["c_e"]  # a circuit state couples through the circuit (c_e = 0), shown below
    parts = [_assignments(own, _quantity_units(own))]
    if np.ndim(harvester.k) == 0 and harvester.potential.kind == "bistable":
        parts.append(_bistable(harvester))
    friction = harvester.friction
    if friction is None:
        parts.append("no friction")
    else:
        parts.append(
            f"{harvester.friction_name} friction "
            f"({_assignments(friction.parameters(), _units(friction))})"
        )
    if harvester.electrical is not None:
        electrical = harvester.electrical
        parts.append(
            f"{harvester.coupling_name} coupling "
            f"({_assignments(electrical.parameters(), _units(electrical))})"
        )
    if harvester.stroke is not None:
        stroke = {"stroke": harvester.stroke}
        parts.append(_assignments(stroke, _quantity_units(stroke)))
    return "device: " + "; ".join(parts)


def _bistable(harvester) -> str:
    """``bistable: wells at z = +-z_w m, barrier ... J, well frequency ... Hz``."""
    potential = harvester.potential
    well_hz = harvester.natural_frequency / (2.0 * np.pi)
    return (
        f"bistable: wells at z = +-{compact(potential.wells[1])} m, barrier "
        f"{compact(potential.barrier_height)} J, well frequency {compact(well_hz)} Hz"
    )


def describe_excitation(psd) -> str:
    """One line: the base excitation used (white level, or the excitation's parameters).

    Tones and shocks follow the random part (``none`` without one).
    """
    if isinstance(psd, int | float):
        return f"excitation: white noise, S = {psd:.6g} {unit('psd')} (one-sided)"
    parameters = psd.parameters()
    kind = parameters.pop("excitation")
    tones, shocks = parameters.pop("tones", ()), parameters.pop("shocks", None)
    numbers = {k: v for k, v in parameters.items() if isinstance(v, int | float) and v is not None}
    text = f"excitation: {kind}"
    if numbers:
        text += f" ({_assignments(numbers, _quantity_units(numbers))})"
    for tone in tones:
        phase = "random phase" if tone["phase"] is None else f"phase {cell(tone['phase'], 4)} deg"
        text += (
            f" + tone {cell(tone['frequency'], 4)} Hz, {cell(tone['amplitude'], 4)} m/s^2 ({phase})"
        )
    if shocks is not None:
        text += (
            f" + shocks ({cell(shocks['rate'], 4)} 1/s, {cell(shocks['amplitude'], 4)} m/s^2, "
            f"{cell(shocks['duration'], 4)} s, {shocks['shape']}, {shocks['distribution']})"
        )
    return text
