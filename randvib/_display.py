"""How results show themselves: plain-text and HTML (Jupyter) tables, and pandas.

The result classes (:class:`~randvib.montecarlo.results.SimulationResult`,
:class:`~randvib.analytic.power_prediction.PowerPrediction`,
:class:`~randvib.analytic.statistical_linearisation.LinearisationResult`,
:class:`~randvib.identification.result.IdentificationResult`) build a list of
rows ``(name, value, unit)``, the values written by :mod:`randvib.formatting`
and the units from :mod:`randvib.quantities`, and hand it here, so that the
terminal and the notebook show the same table.
"""

from __future__ import annotations

import html

from randvib.formatting import compact
from randvib.quantities import QUANTITIES, unit


def pandas():
    """The pandas module, or an ImportError that says how to get it."""
    try:
        import pandas as pd
    except ImportError as error:  # pragma: no cover - pandas is a dependency
        raise ImportError(
            "to_frame() needs pandas: pip install pandas (or pip install -e . in a checkout)"
        ) from error
    return pd


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


def time_series(result, names) -> list[tuple]:
    """(name, values, unit) of the quantities ``names`` that ``result`` has (not None);
    units from :mod:`randvib.quantities` (a circuit's mean square: its coupling's)."""
    electrical = result.harvester.electrical
    out = []
    for name in names:
        values = getattr(result, name)
        if values is not None:
            out.append((name, values, unit(name, electrical) if name in QUANTITIES else ""))
    return out


def time_header(name: str, units: str) -> str:
    """A time table's header: the quantity's symbol (:mod:`randvib.quantities`) and unit."""
    quantity = QUANTITIES.get(name)
    label = quantity.symbol if quantity is not None and quantity.symbol else name
    return f"{label} ({units})" if units else label


def time_rows(times, series, cell) -> tuple[list, list]:
    """(headers, rows) of a time table: ``series`` (name, values, unit), ``cell(values, i)``."""
    headers = ["time (s)"] + [time_header(name, unit) for name, _, unit in series]
    rows = [
        [compact(t)] + [cell(values, i) for _, values, _ in series] for i, t in enumerate(times)
    ]
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
