"""How results show themselves: compact reprs, HTML tables for Jupyter, pandas.

The result classes (:class:`~randvib.montecarlo.simulation.SimulationResult`,
:class:`~randvib.analytic.prediction.PowerPrediction`,
:class:`~randvib.analytic.statistical_linearisation.LinearisationResult`,
:class:`~randvib.identification.fitting.IdentificationResult`) build a list of
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
    the same decimal place (``0.00246461 ± 5.5e-07``): the last digit shown is
    the interval's second.
    """
    if not (math.isfinite(mean) and math.isfinite(ci95)) or ci95 <= 0:
        return number(mean, 6)
    if mean == 0:
        return f"0 ± {_figures(ci95, 2)}"
    figures = math.floor(math.log10(abs(mean))) - math.floor(math.log10(ci95)) + 2
    return f"{_figures(mean, max(figures, 1))} ± {_figures(ci95, 2)}"


def _figures(x: float, n: int) -> str:
    """``x`` to ``n`` significant figures, trailing zeros kept (0.00030, not 0.0003)."""
    text = f"{x:#.{n}g}"
    return text.replace(".e", "e").removesuffix(".")


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
