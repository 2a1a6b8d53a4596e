"""How results show themselves: compact reprs, HTML tables for Jupyter, pandas.

The result classes (:class:`~randvib.montecarlo.results.SimulationResult`,
:class:`~randvib.analytic.power_prediction.PowerPrediction`,
:class:`~randvib.analytic.statistical_linearisation.LinearisationResult`,
:class:`~randvib.identification.result.IdentificationResult`) build a list of
rows ``(name, value, unit)`` and hand it here, so that the terminal, the
notebook and the tables agree on what is shown and to what precision.
"""

from __future__ import annotations

import html
import math

import numpy as np


def pandas():
    """The pandas module, or an ImportError that says how to get it."""
    try:
        import pandas as pd
    except ImportError as error:  # pragma: no cover - pandas is a dependency
        raise ImportError(
            "to_frame() needs pandas: pip install pandas (or pip install -e . in a checkout)"
        ) from error
    return pd


def number(value, digits: int = 5) -> str:
    """A number to ``digits`` significant figures; arrays by their shape and range."""
    if value is None:
        return "-"
    array = np.asarray(value)
    if array.ndim > 0:
        if array.size == 0:
            return f"array{array.shape}"
        return f"array{array.shape} {number(array.min(), 3)} .. {number(array.max(), 3)}"
    x = float(array)
    if x == 0 or not math.isfinite(x):
        return f"{x:g}"
    return f"{x:.{digits}g}"


def estimate(mean: float, ci95: float) -> str:
    """``mean ± ci95`` with the mean to the precision its interval supports.

    The half-width keeps two significant figures and the mean is written to
    the same decimal place (``0.00246461 ± 0.00000055``): the last digit shown is
    the interval's second. See :func:`estimate_parts`.
    """
    if not (_finite(mean) and _finite(ci95)) or ci95 <= 0:
        return number(mean, 6)
    return " ± ".join(estimate_parts(mean, ci95))


#: Below this magnitude the leading zeros hide the digits: 9.29e-06, not 0.00000929.
PLAIN_BELOW = 1e-4

#: Most significant digits shown of an estimate (a noise-free fit's interval
#: may support more; eight say all a reader can use).
MAX_FIGURES = 8


def estimate_parts(mean, half_width) -> tuple[str, str]:
    """A Monte Carlo mean and its 95 % half-width, as the half-width allows.

    The half-width is shown to two significant digits and the mean to the same
    decimal place (``0.0024619 +- 0.00027`` -> ``0.00246``, ``0.00027``), both
    in one notation, chosen by the mean's size; a mean known to more than
    :data:`MAX_FIGURES` digits is shown to that many. A zero or missing half-width
    leaves the mean at six significant digits; non-finite values are ``n/a``.
    One rule for the terminal tables, the reprs and the notebook.

    Examples
    --------
    >>> estimate_parts(0.0024619412547950926, 0.000272784)
    ('0.00246', '0.00027')
    >>> estimate_parts(12345.678, 140.0)
    ('12350', '140')
    >>> estimate_parts(9.2912e-06, 9.81e-07)
    ('9.29e-06', '9.8e-07')
    >>> estimate_parts(0.0490000000112, 2.09e-12)
    ('0.049000000', '2.1e-12')
    """
    if not (_finite(mean) and _finite(half_width) and half_width > 0):
        return _cell(mean), _cell(half_width)
    decimals = 1 - math.floor(math.log10(half_width))  # the 2nd significant digit's place
    half = round(half_width, decimals)
    if half > 0 and math.floor(math.log10(half)) > math.floor(math.log10(half_width)):
        decimals -= 1  # 0.0996 rounded up to 0.10: two digits are now one place earlier
    shown = decimals
    if mean != 0:  # no more than MAX_FIGURES digits, however small the interval
        shown = min(decimals, MAX_FIGURES - 1 - math.floor(math.log10(abs(mean))))
    # the pair in one notation, chosen by the mean: 0.000722 and 0.000042;
    # a half-width past the eighth decimal in exponent notation (2.1e-12)
    plain = round(mean, shown) == 0 or abs(mean) >= PLAIN_BELOW
    return _fixed(mean, shown, plain), _fixed(half_width, decimals, plain and decimals <= 8)


def _finite(value) -> bool:
    return isinstance(value, int | float | np.floating) and math.isfinite(value)


def _cell(value) -> str:
    """A value without an interval: six significant digits, ``n/a`` if not a number."""
    if value is None:
        return ""
    if isinstance(value, float | np.floating) and not math.isfinite(value):
        return "n/a"
    return f"{value + 0.0:.6g}" if _finite(value) else str(value)


def _fixed(value: float, decimals: int, plain: bool) -> str:
    """``value`` rounded to ``decimals`` places (negative: tens, hundreds...), in plain
    notation if ``plain``, else in exponent notation with the same digits."""
    rounded = round(value, decimals) + 0.0  # + 0.0: never "-0"
    if decimals >= 0 and plain:
        return f"{rounded:.{decimals}f}"
    if decimals < 0 and abs(rounded) < 1e9:
        return f"{rounded:.0f}"
    digits = max(1, math.floor(math.log10(abs(rounded))) + decimals + 1) if rounded else 1
    return f"{rounded:.{digits - 1}e}"


def text_table(title: str, rows, note: str = "") -> str:
    """Rows ``(name, value, unit)`` as aligned plain text under ``title``."""
    width = max((len(name) for name, _, _ in rows), default=0)
    lines = [title]
    lines += [f"  {name:<{width}}  {value} {unit}".rstrip() for name, value, unit in rows]
    if note:
        lines.append(f"  ({note})")
    return "\n".join(lines)


def html_table(title: str, rows, note: str = "") -> str:
    """Rows ``(name, value, unit)`` as a small HTML table (Jupyter's ``_repr_html_``)."""
    body = "".join(
        f"<tr><td style='text-align:left'>{html.escape(name)}</td>"
        f"<td style='text-align:right'>{html.escape(value)}</td>"
        f"<td style='text-align:left'>{html.escape(unit)}</td></tr>"
        for name, value, unit in rows
    )
    caption = f"<b>{html.escape(title)}</b>"
    if note:
        caption += f"<br><small>{html.escape(note)}</small>"
    return (
        f"<table><caption style='text-align:left'>{caption}</caption>"
        "<thead><tr><th>quantity</th><th>value</th><th>unit</th></tr></thead>"
        f"<tbody>{body}</tbody></table>"
    )


#: Column headers of the time-resolved tables (the quantity's name -> a short label).
TIME_LABELS = {
    "displacement_variance": "E[z^2]",
    "velocity_variance": "E[v^2]",
    "power_electrical": "E[P_e]",
    "power_load": "E[P_L]",
    "circuit_mean_square": "E[x^2]",
    "cumulative_energy": "energy to t",
    "stroke_exceedance": "P(|z| > stroke)",
    "stroke_reached": "P(reached)",
    "stroke_reached_poisson": "reached, Poisson*",
    "stroke_reached_vanmarcke": "reached, Vanmarcke*",
    "c_eq": "c_eq",
    "k_eq": "k_eq",
}


#: Units of the time-resolved quantities (a circuit's mean square: A^2 or V^2, by coupling).
TIME_UNITS = {
    "displacement_variance": "m^2",
    "velocity_variance": "(m/s)^2",
    "power_electrical": "W",
    "power_load": "W",
    "cumulative_energy": "J",
    "c_eq": "Ns/m",
    "k_eq": "N/m",
}


def time_series(result, names) -> list[tuple]:
    """(name, values, unit) of the quantities ``names`` that ``result`` has (not None)."""
    circuit = "V^2" if result.harvester.coupling_name == "piezo" else "A^2"
    out = []
    for name in names:
        values = getattr(result, name)
        if values is not None:
            unit = circuit if name == "circuit_mean_square" else TIME_UNITS.get(name, "")
            out.append((name, values, unit))
    return out


def time_header(name: str, unit: str) -> str:
    """A time table's header: the short label of ``name`` and its unit."""
    return f"{TIME_LABELS.get(name, name)} ({unit})" if unit else TIME_LABELS.get(name, name)


def time_rows(times, series, cell) -> tuple[list, list]:
    """(headers, rows) of a time table: ``series`` (name, values, unit), ``cell(values, i)``."""
    headers = ["time (s)"] + [time_header(name, unit) for name, _, unit in series]
    rows = [[number(t)] + [cell(values, i) for _, values, _ in series] for i, t in enumerate(times)]
    return headers, rows


def time_table(title: str, headers, rows, note: str = "") -> str:
    """A time-resolved table (one row per time, cells already text) under ``title``."""
    from tabulate import tabulate

    body = tabulate(rows, headers=headers, disable_numparse=True, stralign="right")
    lines = [title, body]
    if note:
        lines.append(f"({note})")
    return "\n".join(lines)


def time_html_table(title: str, headers, rows, note: str = "") -> str:
    """:func:`time_table` as a small HTML table (Jupyter's ``_repr_html_``)."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in headers)
    body = "".join(
        "<tr>"
        + "".join(f"<td style='text-align:right'>{html.escape(c)}</td>" for c in row)
        + "</tr>"
        for row in rows
    )
    caption = f"<b>{html.escape(title)}</b>"
    if note:
        caption += f"<br><small>{html.escape(note)}</small>"
    return (
        f"<table><caption style='text-align:left'>{caption}</caption>"
        f"<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
    )
