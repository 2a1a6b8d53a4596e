"""Writing a study's results: CSV tables, verdicts, Markdown tables and the report.

A study writes into one folder (made by :func:`prepare_output_dir`, which refuses
another run's folder and lets the same run resume):
CSV tables (:func:`write_table`), ``verdicts.json`` (:func:`write_verdicts`:
the numbers behind every sentence of the report, for tests and other
programs), PNG figures (:func:`randvib.figure_style.save_figure`) and ``report.md``
(:func:`write_report`), whose tables come from :func:`markdown_table`, the
one Markdown table writer of the package. Every write is atomic, so an
interrupted study leaves no half-written file, and goes through
:func:`randvib._io.write_tracked`: a rerun into the same folder refuses to
replace a report, table or figure that the user edited since (``--force``
allows it).
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from randvib._io import dumps, prepare_output_dir, write_tracked
from randvib.formatting import formatted, significant, unsigned_zeros
from randvib.quantities import report_header

__all__ = [
    "ensembles_text",
    "fc_levels",
    "markdown_table",
    "print_verdicts",
    "readable_table",
    "prepare_output_dir",
    "sign_word",
    "verdict_lines",
    "write_report",
    "write_table",
    "write_verdicts",
]


def markdown_table(df: pd.DataFrame, floatfmt: str = ".4g", numparse: bool = True) -> str:
    """``df`` as a GitHub-flavoured Markdown table, without the index.

    Numbers are written with ``floatfmt``; a NaN cell reads 'n/a', a
    negative number that rounds to zero reads 0 (no 'nan' or '-0' in a
    report), booleans read yes/no, and bare column names of stored
    quantities (``psd``, ``k3``, ``phi``...) get their units. ``numparse=False`` keeps text columns that look like numbers
    (e.g. "1e+05") as written.
    """
    from tabulate import tabulate

    df = df.rename(columns=_BARE_HEADERS)
    for column in df.columns:
        if pd.api.types.is_bool_dtype(df[column]):
            df[column] = df[column].map(lambda v: "yes" if v else "no")
        if pd.api.types.is_float_dtype(df[column]):
            df[column] = [formatted(v, floatfmt) for v in df[column]]
        elif pd.api.types.is_object_dtype(df[column]) or pd.api.types.is_string_dtype(df[column]):
            df[column] = [formatted(v, floatfmt) if isinstance(v, float)
                          else unsigned_zeros(v) if isinstance(v, str) else v
                          for v in df[column]]  # fmt: skip
    return tabulate(
        df,
        headers="keys",
        tablefmt="github",
        showindex=False,
        floatfmt=floatfmt,
        disable_numparse=not numparse,
    )


#: Bare column names a report table may still carry, and their headers with units (the
#: quantities are stored in these units; Fc is not here: stored in N, shown in mN).
_BARE_HEADERS = {
    **{name: report_header(name) for name in ("psd", "k3", "zeta", "f0")},
    "phi": "φ",
    "kappa": "κ",
    "n_paths": "paths",
    "p": "p-value",
}


#: Raw result columns and how a report shows them: (header with its unit, scale factor).
READABLE_COLUMNS = {
    "psd": (report_header("psd"), 1.0),
    "k3": (report_header("k3"), 1.0),
    "fc": ("Fc (mN)", 1e3),
    "phi": ("φ", 1.0),
    "zeta": (report_header("zeta"), 1.0),
    "linearisation_power": ("P Eq. 32 (mW)", 1e3),
    "power_electrical": ("P Monte Carlo (mW)", 1e3),
    "power_electrical_ci95": ("95 % half-width (mW)", 1e3),
    "power_electrical_half": ("P at dt/2 (mW)", 1e3),
    "power_electrical_ci95_half": ("95 % half-width at dt/2 (mW)", 1e3),
    "difference": ("difference (mW)", 1e3),
    "combined_ci95": ("combined 95 % half-width (mW)", 1e3),
    "bias_below_error": ("bias below error", None),
    "linearisation_rel_error": ("Eq. 32 error (%)", 100.0),
    "linearisation_rel_error_ci95": ("Eq. 32 error 95 % half-width (%)", 100.0),
    "linearisation_consistent": ("Eq. 32 inside the 95 % CI", None),
    "contrast": ("contrast (µW)", 1e6),
    "contrast_ci95": ("contrast 95 % half-width (µW)", 1e6),
    "reference": ("P(Fc, 0) (mW)", 1e3),
    "relative_contrast": ("contrast / P(Fc, 0) (%)", 100.0),
    "relative_ci95": ("95 % half-width (%)", 100.0),
    "p_value": ("p-value", 1.0),
    "detectable": ("detectable (95 %)", None),
    "detectable_holm": ("detectable (Holm)", None),
    "n_paths": ("paths", 1.0),
}


def readable_table(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` for a report: known raw columns (:data:`READABLE_COLUMNS`) renamed with their
    units and scaled (W to mW, fractions to %, N to mN), yes/no for booleans; others kept."""
    out = {}
    for column in df.columns:
        header, scale = READABLE_COLUMNS.get(column, (column, 1.0))
        values = df[column]
        if scale is None or pd.api.types.is_bool_dtype(values):
            values = values.map(lambda v: "yes" if bool(v) else "no")
        elif scale != 1.0:
            values = values * scale
        out[header] = values.to_numpy()
    return pd.DataFrame(out)


def write_table(out_dir: Path, name: str, df: pd.DataFrame) -> Path:
    """Write ``df`` as ``out_dir/name`` (CSV, no index)."""
    return write_tracked(Path(out_dir) / name, df.to_csv(index=False))


def write_verdicts(out_dir: Path, verdicts: dict, sentences=()) -> Path:
    """Write the numbers behind the report's verdicts as ``out_dir/verdicts.json``.

    ``sentences`` (the report's verdicts in words) are kept under the key
    ``"verdicts"``; :func:`print_verdicts` shows them at the end of a run.
    """
    data = {**verdicts, "verdicts": [s for s in sentences if s]} if sentences else verdicts
    return write_tracked(Path(out_dir) / "verdicts.json", dumps(data, indent=2))


def verdict_lines(out_dir: Path, max_items: int = 40) -> list[str]:
    """The verdicts of the study in ``out_dir`` as lines for the terminal.

    The sentences: ``verdicts.json``'s ``"verdicts"`` list; without it, any text
    in the file longer than a line's worth, or else the report's
    ``**Verdict.**`` paragraphs.
    With sentences, the numbers behind them are only counted (they are in the
    file); without any, every number and word of the file is shown as
    ``key.sub: value`` (lists of records counted, not listed), at most
    ``max_items`` of them.
    """
    import json

    path = Path(out_dir) / "verdicts.json"
    if not path.is_file():
        return []
    data = json.loads(path.read_text())
    lines = [f"- {s}" for s in data.pop("verdicts", [])]
    # a study that stores its sentences says everything in them; a long text among its
    # numbers is a value (an optimum's "where"), not a sentence to print
    has_sentences = bool(lines)
    flat = []

    def walk(prefix, value):
        if isinstance(value, dict):
            for key, sub in value.items():
                walk(f"{prefix}.{key}" if prefix else str(key), sub)
        elif isinstance(value, list) and any(isinstance(v, dict | list) for v in value):
            flat.append(f"{prefix}: {len(value)} entries")
        elif isinstance(value, str) and len(value) > 60 and not has_sentences:
            # a verdict sentence stored beside its numbers: shown with the sentences
            lines.append(f"- {prefix}: {value.strip().lstrip(';').strip()}")
        elif isinstance(value, float):
            flat.append(f"{prefix}: {significant(value, 4)}")
        else:
            flat.append(f"{prefix}: {value}")

    walk("", data)
    if not lines:  # no sentence stored with the numbers: the report's own
        lines = [f"- {s}" for s in _report_verdicts(Path(out_dir) / "report.md")]
    if lines:
        count = f"{len(flat)} number{'s' * (len(flat) != 1)}"
        return lines + [f"  ({count} behind them in {path})"] if flat else lines
    if len(flat) > max_items:
        flat = flat[:max_items] + [f"... ({len(flat) - max_items} more in {path})"]
    return [f"  {line}" for line in flat]


def _report_verdicts(report: Path) -> list[str]:
    """The ``**Verdict.**`` paragraphs of a study's report, without the mark."""
    try:
        text = report.read_text()
    except OSError:
        return []
    paragraphs = text.split("\n\n")
    mark, out = "**Verdict.**", []
    for i, paragraph in enumerate(paragraphs):
        if mark not in paragraph:
            continue
        rest = paragraph[paragraph.index(mark) + len(mark) :].strip()
        if rest:
            out.append(" ".join(rest.split()))
        elif i + 1 < len(paragraphs):  # "**Verdict.**" above a list: its items
            items = paragraphs[i + 1].strip().split("\n- ")
            out += [" ".join(item.lstrip("- ").replace("**", "").split()) for item in items]
    return [sentence for sentence in out if sentence]


def print_verdicts(report: Path) -> None:
    """Print the report's path and the verdicts of its folder (the end of a study run)."""
    report = Path(report)
    print(f"report: {report}")
    lines = verdict_lines(report.parent)
    if lines:
        print(f"verdicts ({report.parent / 'verdicts.json'}):")
        print("\n".join(lines))


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


def ensembles_text(settings, quick: bool, wall: float, *, paired: str, how: str = "",
                   start: str = "") -> str:  # fmt: skip
    """How a study's paired ensembles ran (:func:`randvib.run_ensembles`), in words.

    ``settings`` (:class:`randvib.SweepSettings` of a fixed size), the run's
    wall time ``wall`` (s); ``paired`` says which cases share a seed, ``how``
    and ``start`` what is integrated beside the device and from where.
    """
    return (
        f"Monte Carlo: Heun{how}, dt = {settings.dt:g} s, {settings.min_paths} paths x "
        f"{settings.window:g} s after {settings.burn_in:g} s burn-in{start}, seed "
        f"{settings.seed} ({paired}: paired). {'Quick mode. ' if quick else ''}"
        f"Wall time {wall:.0f} s."
    )
