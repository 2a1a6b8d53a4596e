"""Human-readable output helpers for the CLI."""

from __future__ import annotations

from tabulate import tabulate


def print_table(rows, headers) -> None:
    print(tabulate(rows, headers=headers, floatfmt=".6g"))
