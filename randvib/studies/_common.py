"""Pieces shared by the packaged studies: grids, step-size checks, reports."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from randvib._io import atomic_write_text
from randvib.harvester import Harvester
from randvib.linearisation import coulomb_equivalent_damping
from randvib.sweep import SweepSettings, run_sweep


def fc_where_power_halves(device: Harvester, psd: float) -> float:
    """Coulomb level (N) at which Eq. 32 predicts half the friction-free power.

    Half power means c_eq = 2c; Eq. 27 then gives
    Fc = c sqrt(2 pi) / 4 * sqrt(S m / (2c)).
    """
    c, m = float(device.c), float(device.m)
    fc = c * np.sqrt(2 * np.pi) / 4 * np.sqrt(psd * m / (2 * c))
    assert np.isclose(coulomb_equivalent_damping(c, fc, psd, m), 2 * c)
    return float(fc)


def step_size_check(
    base: Harvester,
    points: list,
    settings: SweepSettings,
    out_dir: Path,
    table: pd.DataFrame,
    *,
    executor=None,
    workers=None,
    scheduler=None,
    progress=True,
) -> pd.DataFrame:
    """Re-run ``points`` (a subset of ``table``) at half the step and compare.

    The time-step bias of the study is below its statistical error where the
    two estimates agree within their combined 95 % half-width,
    sqrt(ci_dt^2 + ci_dt/2^2); the table gives both and the verdict.
    """
    half = replace(settings, dt=settings.dt / 2, seed=settings.seed + 1)
    rerun = run_sweep(
        base,
        points,
        half,
        out_dir=out_dir,
        executor=executor,
        workers=workers,
        scheduler=scheduler,
        progress=progress,
        name="step-check",
    )
    keys = [k for k in points[0]]
    merged = rerun.table.merge(table, on=keys, suffixes=("_half", ""))
    merged["difference"] = merged["power_electrical_half"] - merged["power_electrical"]
    merged["combined_ci95"] = np.hypot(
        merged["power_electrical_ci95_half"], merged["power_electrical_ci95"]
    )
    merged["bias_below_error"] = merged["difference"].abs() <= merged["combined_ci95"]
    cols = keys + [
        "power_electrical",
        "power_electrical_ci95",
        "power_electrical_half",
        "power_electrical_ci95_half",
        "difference",
        "combined_ci95",
        "bias_below_error",
    ]
    return merged[cols]


def markdown_table(df: pd.DataFrame, floatfmt: str = ".4g") -> str:
    from tabulate import tabulate

    return tabulate(df, headers="keys", tablefmt="github", showindex=False, floatfmt=floatfmt)


def write_report(out_dir: Path, title: str, sections: list[tuple[str, str]]) -> Path:
    text = [f"# {title}", ""]
    for heading, body in sections:
        text += [f"## {heading}", "", body.strip(), ""]
    path = Path(out_dir) / "report.md"
    atomic_write_text(path, "\n".join(text))
    return path


def save_figure(fig, path: Path) -> Path:
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path
