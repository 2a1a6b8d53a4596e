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
