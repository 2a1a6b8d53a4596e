"""Human-readable output helpers for the CLI."""

from __future__ import annotations

import math

from tabulate import tabulate


def _shown(value):
    """A cell: non-finite numbers are shown as ``n/a``, never as nan or inf."""
    if isinstance(value, float) and not math.isfinite(value):
        return "n/a"
    return value


def print_table(rows, headers) -> None:
    rows = [[_shown(v) for v in row] for row in rows]
    print(tabulate(rows, headers=headers, floatfmt=".6g"))
