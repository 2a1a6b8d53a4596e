"""Human-readable output helpers for the CLI.

Numbers are shown to the precision they have: an analytic value to
:data:`ANALYTIC_DIGITS` significant digits, a Monte Carlo mean to the decimal
of the second significant digit of its 95 % half-width (the half-width itself
to two digits), so that no digit is printed that the ensemble does not
support. JSON output is never rounded.
"""

from __future__ import annotations

import math

from tabulate import tabulate

from randvib.models.excitation import PARAMETER_UNITS

#: Significant digits of an analytic (deterministic) value in a table.
ANALYTIC_DIGITS = 6


def _finite(value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def format_value(value, digits: int = ANALYTIC_DIGITS) -> str:
    """A cell: a number to ``digits`` significant digits, non-finite as ``n/a``."""
    if value is None:
        return ""
    if isinstance(value, float) and not math.isfinite(value):
        return "n/a"
    if _finite(value) and not isinstance(value, int):
        return f"{value + 0.0:.{digits}g}"  # + 0.0: never "-0"
    return str(value)


#: Table columns that hold words, not numbers.
TEXT_COLUMNS = ("unit", "status", "")


def print_table(rows, headers) -> None:
    """A plain table: numbers as :func:`format_value` (unless already text), right-aligned."""
    rows = [[v if isinstance(v, str) else format_value(v) for v in row] for row in rows]
    # numbers flush right; the first column and text columns flush left
    align = ["left"] + ["left" if h in TEXT_COLUMNS else "right" for h in headers[1:]]
    print(tabulate(rows, headers=headers, disable_numparse=True, colalign=tuple(align)))


def _assignments(values: dict, units: dict) -> str:
    """``name value unit, ...`` with four significant digits."""
    return ", ".join(
        f"{name} {format_value(value, 4)} {units.get(name, '')}".rstrip()
        for name, value in values.items()
    )


def _units(model) -> dict:
    return {name: spec.unit for name, spec in type(model).parameter_specs().items()}


def describe_device(harvester) -> str:
    """One line: the device actually simulated or predicted (after preset and options)."""
    parts = [
        f"m {harvester.m:.4g} kg, c_m {harvester.c_m:.4g} Ns/m, c_e {harvester.c_e:.4g} Ns/m, "
        f"k {harvester.k:.4g} N/m, k3 {harvester.k3:.4g} N/m^3"
    ]
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
        parts.append(f"stroke {harvester.stroke:.4g} m")
    return "device: " + "; ".join(parts)


def describe_excitation(psd) -> str:
    """One line: the base excitation used (white level, or the excitation's parameters)."""
    if isinstance(psd, int | float):
        return f"excitation: white noise, S = {psd:.6g} (m/s^2)^2/Hz (one-sided)"
    numbers = {k: v for k, v in psd.parameters().items() if not isinstance(v, str)}
    return f"excitation: {psd.name} ({_assignments(numbers, PARAMETER_UNITS)})"
