"""Is the time-step bias below the statistical error? Half-step re-runs and their verdict.

:func:`sweep_with_half_step` runs a study's sweep and re-runs a few points
(usually the hardest, :func:`randvib.studies.grids.highest_friction_points`)
at half the step with independent noise; :func:`half_step_verdict` counts
the points whose two estimates agree within their combined 95 % half-width.
:func:`check_step_bias` refuses a step whose linearised bias is already too
large before anything runs; :func:`sweep_text` says in words how the sweep
ran, :func:`half_step_section` is the report's section on the re-run.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from randvib.models.harvester import Harvester
from randvib.montecarlo.sweep import (
    SweepSettings,
    make_executor,
    point_device,
    run_sweep,
)
from randvib.studies.report import markdown_table, readable_table


def half_step_rerun(
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


def _quiet_worker() -> None:
    import warnings

    from randvib.analytic.averaging import AveragingValidityWarning

    warnings.simplefilter("ignore", AveragingValidityWarning)


def study_executor(workers=None, scheduler=None):
    """:func:`randvib.montecarlo.sweep.make_executor`, with quiet local workers.

    Local worker processes ignore :class:`~randvib.analytic.averaging.AveragingValidityWarning`
    (the sweep evaluates the averaging prediction at every point, and at high
    friction it would repeat once per point); the studies flag those points in
    their reports instead, from ``zeta_friction``.
    """
    return make_executor(workers, scheduler, initializer=_quiet_worker)


def check_step_bias(base: Harvester, points: list, settings: SweepSettings) -> float:
    """The largest linearised step bias over ``points``; refuse it above the warning level.

    Uses :func:`randvib.montecarlo.step_check.step_bias` (the scheme's exact stationary
    bias on each point's linearised device).
    """
    from randvib.montecarlo.step_check import WARN_STEP_BIAS, step_bias

    worst = max(
        step_bias(settings.scheme, point_device(base, p), p["psd"], settings.dt) for p in points
    )
    if worst > WARN_STEP_BIAS:
        raise ValueError(
            f"dt = {settings.dt:g} s gives a linearised step bias of {worst:.2%}; "
            "use a smaller step"
        )
    return worst


def sweep_with_half_step(
    base: Harvester,
    points: list,
    settings: SweepSettings,
    out: Path,
    name: str,
    check_points: list,
    *,
    workers=None,
    scheduler=None,
    progress=True,
):
    """Run a study's sweep into ``out/sweep`` and its half-step re-run of ``check_points``.

    Returns the :class:`~randvib.montecarlo.sweep.SweepResult` and the table of
    :func:`half_step_rerun`.
    """
    import warnings

    from randvib.analytic.averaging import AveragingValidityWarning

    executor, close = study_executor(workers, scheduler)
    # no executor means in this process (one worker, or no processes allowed): say so to
    # the runs, whose own default (workers=None) is a pool of every core's processes
    where = {"executor": executor} if executor is not None else {"workers": 1}
    try:
        with warnings.catch_warnings():  # in-process runs; the reports flag these points
            warnings.simplefilter("ignore", AveragingValidityWarning)
            result = run_sweep(
                base,
                points,
                settings,
                out_dir=out / "sweep",
                progress=progress,
                name=name,
                **where,
            )
            check = half_step_rerun(
                base,
                check_points,
                settings,
                out / "step-check",
                result.table,
                progress=progress,
                **where,
            )
    finally:
        close()
    return result, check


def half_step_verdict(check: pd.DataFrame) -> dict:
    """Half-step re-run: how many points agree within the combined 95 % half-width."""
    from randvib.studies.evidence import independence_note, independent_count

    n_below = int(check.bias_below_error.sum())
    worst = (check.difference.abs() / check.combined_ci95).max()
    n_independent = independent_count(check)
    data = {
        "n_points": len(check),
        "n_independent_points": n_independent,
        "n_below": n_below,
        "largest_difference_over_ci95": float(worst),
    }
    note = independence_note(len(check), n_independent)
    if n_below == len(check):
        data["sentence"] = (
            f" (largest difference {worst:.2f} times the combined 95 % half-width{note})"
        )
    else:
        data["sentence"] = (
            f"; at {len(check) - n_below} the half-step estimate differs by more than the "
            f"combined 95 % half-width (largest {worst:.2f} times it; "
            f"{0.05 * n_independent:.1f} expected by chance{note})"
        )
    return data


def half_step_section(check: pd.DataFrame, settings: SweepSettings, which: str,
                      worst_bias: float | None = None) -> str:  # fmt: skip
    """A report's time-step section: the half-step re-run of ``which`` points and its verdict.

    ``check`` is the table of :func:`half_step_rerun`, ``settings`` the
    sweep's; ``worst_bias`` (:func:`check_step_bias`), when given, is quoted
    as the largest linearised step bias at the sweep's step.
    """
    verdict = half_step_verdict(check)
    bias = "" if worst_bias is None else (
        " Linearised step bias at dt (randvib.montecarlo.step_check.step_bias) at most "
        f"{worst_bias:.1e}."
    )  # fmt: skip
    return (
        f"Re-run of {len(check)} points ({which}) at dt/2 = {settings.dt / 2:g} s, independent "
        f"noise. Time-step bias below the statistical error at {verdict['n_below']} of "
        f"{len(check)} points{verdict['sentence']}.{bias}\n\n"
        + markdown_table(readable_table(check))
    )


def sweep_text(settings: SweepSettings, n_paths: int, quick: bool) -> str:
    """How a study's sweep ran, in words: step, burn-in, window, precision, paths, seed.

    For a sweep whose burn-in comes from :func:`randvib.studies.grids.burn_in_for`
    (six energy relaxation times); ``n_paths`` is the paths over all points.
    """
    return (
        f"Heun, dt = {settings.dt:g} s, {settings.burn_in:g} s burn-in (at least six energy "
        "relaxation times m/c, so that each path, started from the Gaussian linearised state, "
        f"has forgotten its start) + {settings.window:g} s per path, paths added until the 95 % "
        f"half-width of each power is {100 * settings.target_rel_ci:g} % ({n_paths} paths in "
        f"all), seed {settings.seed}, common random numbers across points, control variates "
        f"{'on' if settings.control_variates else 'off'}.{' Quick mode.' if quick else ''}"
    )
