"""Writing a study's results: CSV tables, verdicts, Markdown tables and the report.

A study writes into one folder (made by :func:`prepare_output_dir`, which refuses
another run's folder and lets the same run resume):
CSV tables (:func:`write_table`), ``verdicts.json`` (:func:`write_verdicts`:
the numbers behind every sentence of the report, for tests and other
programs), PNG figures (:func:`save_figure`) and ``report.md``
(:func:`write_report`), whose tables come from :func:`markdown_table`, the
one Markdown table writer of the package. Every write is atomic, so an
interrupted study leaves no half-written file, and goes through
:func:`randvib._io.write_tracked`: a rerun into the same folder refuses to
replace a report, table or figure that the user edited since (``--force``
allows it).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from randvib._io import dumps, prepare_output_dir, write_tracked

__all__ = [
    "fc_levels",
    "markdown_table",
    "plus_minus",
    "prepare_output_dir",
    "save_figure",
    "sign_word",
    "write_report",
    "write_table",
    "write_verdicts",
]


def plus_minus(value, ci, scale: float = 100.0, fmt: str = "+.2f") -> list[str]:
    """'value ± ci' strings (default: fractions as percent) for report tables."""
    return [
        f"{scale * v:{fmt}} ± {scale * c:{fmt.lstrip('+')}}"
        for v, c in zip(np.atleast_1d(value), np.atleast_1d(ci), strict=True)
    ]


def markdown_table(df: pd.DataFrame, floatfmt: str = ".4g", numparse: bool = True) -> str:
    """``df`` as a GitHub-flavoured Markdown table, without the index.

    ``numparse=False`` keeps text columns that look like numbers (e.g.
    "1e+05") as written.
    """
    from tabulate import tabulate

    return tabulate(
        df,
        headers="keys",
        tablefmt="github",
        showindex=False,
        floatfmt=floatfmt,
        disable_numparse=not numparse,
    )


def write_table(out_dir: Path, name: str, df: pd.DataFrame) -> Path:
    """Write ``df`` as ``out_dir/name`` (CSV, no index)."""
    return write_tracked(Path(out_dir) / name, df.to_csv(index=False))


def write_verdicts(out_dir: Path, verdicts: dict) -> Path:
    """Write the numbers behind the report's verdicts as ``out_dir/verdicts.json``."""
    return write_tracked(Path(out_dir) / "verdicts.json", dumps(verdicts, indent=2))


def write_report(
    out_dir: Path, title: str, sections: list[tuple[str, str]], intro: str | None = None
) -> Path:
    """Write ``out_dir/report.md``: the title, ``intro`` (if given), then one ``##`` section
    per (heading, body)."""
    text = [f"# {title}", ""]
    if intro is not None:
        text += [intro.strip(), ""]
    for heading, body in sections:
        text += [f"## {heading}", "", body.strip(), ""]
    return write_tracked(Path(out_dir) / "report.md", "\n".join(text))


def save_figure(fig, path: Path) -> Path:
    """Save ``fig`` as a PNG (120 dpi) and close it (refusing to replace an edited one)."""
    import io

    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=120, bbox_inches="tight")
    plt.close(fig)
    return write_tracked(path, buffer.getvalue())


def sign_word(rows: pd.DataFrame, column: str = "relative_contrast") -> str:
    """'all positive', 'all negative' or 'of either sign': the signs of ``rows[column]``."""
    if (rows[column] > 0).all():
        return "all positive"
    if (rows[column] < 0).all():
        return "all negative"
    return "of either sign"


def fc_levels(rows: pd.DataFrame) -> str:
    """'S = 1, k3 = 0: Fc = 21, 42 mN; S = 0.1, ...': the Coulomb levels of ``rows`` by series."""
    parts = []
    for (psd, k3), sub in rows.groupby(["psd", "k3"], sort=False):
        fcs = ", ".join(f"{1e3 * f:.3g}" for f in sorted(sub.fc))
        parts.append(f"S = {psd:g}, k3 = {k3:g}: Fc = {fcs} mN")
    return "; ".join(parts)
