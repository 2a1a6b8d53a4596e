"""Pieces shared by the packaged studies: grids, step-size checks, reports."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from randvib._io import atomic_write_text
from randvib.analytic.linearisation import coulomb_equivalent_damping
from randvib.models.harvester import Harvester
from randvib.montecarlo.sweep import (
    SweepResult,
    SweepSettings,
    holm_significant,
    make_executor,
    paired_contrast,
    point_device,
    run_sweep,
    two_sided_p_value,
)


def fc_where_power_halves(device: Harvester, psd: float) -> float:
    """Coulomb level (N) at which Eq. 32 predicts half the friction-free power.

    Half power means c_eq = 2c; Eq. 27 then gives
    Fc = c sqrt(2 pi) / 4 * sqrt(S m / (2c)).
    """
    c, m = float(device.c), float(device.m)
    fc = c * np.sqrt(2 * np.pi) / 4 * np.sqrt(psd * m / (2 * c))
    assert np.isclose(coulomb_equivalent_damping(c, fc, psd, m), 2 * c)
    return float(fc)


def friction_level(device: Harvester, psd, fc):
    """Dimensionless Coulomb level phi = Fc / (c sigma_v0).

    sigma_v0^2 = S m / (4 c) is the friction-free velocity variance (paper
    Eq. 20). Eq. 30-32 depend on Fc only through phi: with
    kappa = phi^2 / pi, P / P(0) = 1 / (1 + kappa + sqrt(kappa (2 + kappa))),
    so Eq. 32 halves the power at phi = sqrt(pi) / 2 (about 0.886). For
    k3 = 0 the SDE itself scales exactly (z, z' and Fc all with sqrt(S)), so
    any statistic of P / P(0) depends on phi and the damping ratio only.
    """
    c, m = float(device.c), float(device.m)
    return np.asarray(fc, dtype=float) / (c * np.sqrt(np.asarray(psd, dtype=float) * m / (4 * c)))


def fc_at_friction_level(device: Harvester, psd, phi):
    """Coulomb level Fc (N) of the dimensionless level phi (inverse of :func:`friction_level`)."""
    c, m = float(device.c), float(device.m)
    return np.asarray(phi, dtype=float) * c * np.sqrt(np.asarray(psd, dtype=float) * m / (4 * c))


def plus_minus(value, ci, scale: float = 100.0, fmt: str = "+.2f") -> list[str]:
    """'value ± ci' strings (default: fractions as percent) for report tables."""
    return [
        f"{scale * v:{fmt}} ± {scale * c:{fmt.lstrip('+')}}"
        for v, c in zip(np.atleast_1d(value), np.atleast_1d(ci), strict=True)
    ]


def burn_in_for(devices, relaxation_times: float = 6.0, resolution: float = 0.5) -> float:
    """Burn-in (s): ``relaxation_times`` energy relaxation times m/c of the slowest device.

    Paths start from the linearised (Gaussian, Eq. 30) state, which is not
    the stationary law of a friction-affected device; the mean energy relaxes
    as exp(-c t / m), so a burn-in of a few m/c makes the start's bias in the
    time averages (and in the energy-change control) negligible. (The
    friction-free companion starts from its own stationary spread.) Rounded
    up to ``resolution``.
    """
    tau = max(float(d.m) / float(d.c) for d in devices)
    return float(np.ceil(relaxation_times * tau / resolution) * resolution)


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


def interaction_contrasts(
    result: SweepResult,
    base: Harvester,
    a: str = "fc",
    b: str = "k3",
    *,
    level: float = 0.05,
    zero_baseline: bool = False,
) -> pd.DataFrame:
    """Interaction contrasts of two factors of a sweep, from paired paths.

    For every point with ``a != 0`` and ``b != 0`` the contrast

        [P(a, b) - P(a, 0)] - [P(0, b) - P(0, 0)]

    is estimated with :func:`randvib.montecarlo.sweep.paired_contrast` from the four
    points that share all other parameters (e.g. ``psd``). It is zero when the
    effect of ``b`` on the expected power does not depend on ``a``. The
    ``relative_*`` columns divide by the Monte Carlo P(a, 0). ``detectable``
    tests each contrast at ``level`` (two-sided); ``detectable_holm`` applies
    Holm's correction over the whole family (the contrasts share paths, so
    their verdicts are correlated).

    ``zero_baseline=True`` is for factors whose effect at ``a = 0`` is zero
    by theory, as k3's is without friction (E[z'^2] = S m / (4c) for every k3,
    exact stationary density). The paired estimate then uses only the two
    ``a != 0`` points, over all the paths they share: the ``a = 0`` points,
    whose power the friction-free companion makes exact, stop at the sweep's
    first batch and would otherwise cap the paths of every contrast. Their
    bracket P(0, b) - P(0, 0) is reported from the sweep's estimates
    (``baseline``, ``baseline_ci95``) as a check.

    Returns
    -------
    DataFrame
        The point's parameters, then ``contrast`` and ``contrast_ci95`` (W),
        ``reference`` (P(a, 0), W), ``relative_contrast``, ``relative_ci95``, ``p_value``, ``detectable``,
        ``n_paths`` (paths behind the paired estimate), ``detectable_holm``
        (and the ``baseline`` columns); one row per contrast, in sweep order.
    """
    points = result.points
    keys = list(points[0])
    for name in (a, b):
        if name not in keys:
            raise ValueError(f"factor `{name}` is not a parameter of the sweep; it has {keys}")

    def key(point, **override):
        return tuple(float(override.get(k, point[k])) for k in keys)

    index = {key(p): i for i, p in enumerate(points)}
    power = dict(zip(result.table.point, result.table.power_electrical, strict=True))
    ci95 = dict(zip(result.table.point, result.table.power_electrical_ci95, strict=True))
    rows = []
    for i, p in enumerate(points):
        if p[a] == 0 or p[b] == 0:
            continue
        partner = {}
        for va, vb in ((p[a], 0.0), (0.0, p[b]), (0.0, 0.0)):
            k = key(p, **{a: va, b: vb})
            if k not in index:
                raise ValueError(
                    f"the contrast at {p} needs the point {dict(zip(keys, k, strict=True))}, "
                    "which is not in the sweep; include 0 in both factors' grids"
                )
            partner[(va, vb)] = index[k]
        weights = {i: 1.0}
        weights[partner[(p[a], 0.0)]] = -1.0
        if not zero_baseline:
            weights[partner[(0.0, p[b])]] = -1.0
            weights[partner[(0.0, 0.0)]] = 1.0
        s = paired_contrast(result, base, weights)
        reference = power[partner[(p[a], 0.0)]]
        p_value = two_sided_p_value(s)
        row = {
            **{k: float(p[k]) for k in keys},
            "contrast": s.mean,
            "contrast_ci95": s.ci95,
            "reference": reference,
            "relative_contrast": s.mean / reference,
            "relative_ci95": s.ci95 / reference,
            "p_value": p_value,
            "detectable": p_value < level,
            "n_paths": s.n_paths,
        }
        if zero_baseline:
            j, j0 = partner[(0.0, p[b])], partner[(0.0, 0.0)]
            row["baseline"] = power[j] - power[j0]
            row["baseline_ci95"] = float(np.hypot(ci95[j], ci95[j0]))
        rows.append(row)
    if not rows:
        raise ValueError(f"no point of the sweep has both `{a}` and `{b}` non-zero")
    table = pd.DataFrame(rows)
    table["detectable_holm"] = holm_significant(table.p_value, level)
    return table


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

    Uses :func:`randvib.montecarlo.simulation.step_bias` (the scheme's exact stationary
    bias on each point's linearised device).
    """
    from randvib.montecarlo.simulation import WARN_STEP_BIAS, step_bias

    worst = max(
        step_bias(settings.scheme, point_device(base, p), p["psd"], settings.dt) for p in points
    )
    if worst > WARN_STEP_BIAS:
        raise ValueError(
            f"dt = {settings.dt:g} s gives a linearised step bias of {worst:.2%}; "
            "use a smaller step"
        )
    return worst


def highest_friction_points(points: list, group=("psd",)) -> list:
    """The points with the largest Fc within each group: the hardest dynamics."""
    top: dict = {}
    for p in points:
        key = tuple(p[g] for g in group)
        top[key] = max(top.get(key, -np.inf), p["fc"])
    return [p for p in points if p["fc"] == top[tuple(p[g] for g in group)]]


def sweep_with_step_check(
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
    :func:`step_size_check`.
    """
    import warnings

    from randvib.analytic.averaging import AveragingValidityWarning

    executor, close = study_executor(workers, scheduler)
    try:
        with warnings.catch_warnings():  # in-process runs; the reports flag these points
            warnings.simplefilter("ignore", AveragingValidityWarning)
            result = run_sweep(
                base,
                points,
                settings,
                out_dir=out / "sweep",
                executor=executor,
                progress=progress,
                name=name,
            )
            check = step_size_check(
                base,
                check_points,
                settings,
                out / "step-check",
                result.table,
                executor=executor,
                progress=progress,
            )
    finally:
        close()
    return result, check


def step_check_verdict(check: pd.DataFrame) -> dict:
    """Half-step re-run: how many points agree within the combined 95 % half-width."""
    n_below = int(check.bias_below_error.sum())
    worst = (check.difference.abs() / check.combined_ci95).max()
    data = {
        "n_points": len(check),
        "n_below": n_below,
        "largest_difference_over_ci95": float(worst),
    }
    if n_below == len(check):
        data["sentence"] = f" (largest difference {worst:.2f} times the combined 95 % half-width)"
    else:
        data["sentence"] = (
            f"; at {len(check) - n_below} the half-step estimate differs by more than the "
            f"combined 95 % half-width (largest {worst:.2f} times it; "
            f"{0.05 * len(check):.1f} expected by chance)"
        )
    return data
