"""Where an analytic method can be trusted: trusted ranges of the friction level phi.

An analytic method's relative error against Monte Carlo, mapped over the
dimensionless friction level phi = Fc / (c sigma_v0)
(:func:`randvib.studies.grids.friction_level`), is *trusted* to a tolerance up
to the first phi where the upper 95 % bound of the error, |error| + ci95,
exceeds it (:func:`trusted_limit`). :func:`thresholds` tabulates those limits
per series of points (one (S, k3, damping ratio) each) and method;
:func:`collapse` measures how far series that an exact scaling law makes
identical actually agree. The sentences here turn those numbers into the
verdicts of a report.

The tables are sweep tables with ``phi``, ``zeta`` (damping ratio,
:func:`randvib.studies.grids.damping_ratio`), and for every method ``m`` the
columns ``{m}_rel_error`` and ``{m}_rel_error_ci95``
(:func:`randvib.montecarlo.sweep.linearisation_verdicts`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from randvib.studies.grids import power_ratio

#: The tolerances of a trusted range (relative error): 1 %, 5 %, 10 %.
TOLERANCES = (0.01, 0.05, 0.10)


def tolerance_column(tolerance: float) -> str:
    """Column of :func:`thresholds` holding the limit for ``tolerance``: ``phi_5pct``."""
    return f"phi_{round(100 * tolerance)}pct"


def trusted_limit(phi, error, ci95, tolerance: float) -> float:
    """Largest phi up to which the error is trusted to ``tolerance``.

    Trusted means the upper 95 % bound ``|error| + ci95`` is at most
    ``tolerance``. The bound is followed from the smallest phi up to its first
    crossing, interpolated linearly in log phi between the grid points either
    side, so the answer is conservative where the error is not monotonic.

    Returns
    -------
    float
        The crossing; ``0.0`` when the bound already exceeds ``tolerance`` at
        the smallest phi (trusted nowhere on the grid), ``inf`` when it never
        does (trusted over the whole grid).
    """
    phi = np.asarray(phi, dtype=float)
    bound = np.abs(np.asarray(error, dtype=float)) + np.asarray(ci95, dtype=float)
    if phi.shape != bound.shape or phi.ndim != 1 or phi.size == 0:
        raise ValueError(
            f"`phi`, `error` and `ci95` must be 1-d of one length, got {phi.shape}, {bound.shape}"
        )
    if np.any(phi <= 0) or not np.all(np.isfinite(bound)):
        raise ValueError("`phi` must be > 0 and the error bounds finite")
    order = np.argsort(phi)
    phi, bound = phi[order], bound[order]
    above = np.flatnonzero(bound > tolerance)
    if above.size == 0:
        return float("inf")
    i = above[0]
    if i == 0:
        return 0.0
    t = (tolerance - bound[i - 1]) / (bound[i] - bound[i - 1])
    return float(np.exp(np.log(phi[i - 1]) + t * (np.log(phi[i]) - np.log(phi[i - 1]))))


def series_label(psd, k3, zeta) -> str:
    """'S = 1, k3 = 0, zeta = 0.044': the name of one series of points."""
    return f"S = {psd:g}, k3 = {k3:.3g}, zeta = {zeta:.3f}"


def thresholds(table: pd.DataFrame, methods, tolerances=TOLERANCES) -> pd.DataFrame:
    """Trusted phi (:func:`trusted_limit`) for each (S, k3, zeta) series, method and tolerance.

    One row per series and method, in the order the series first appear, with
    a column :func:`tolerance_column` per tolerance.
    """
    rows = []
    for (psd, k3, zeta), sub in table.groupby(["psd", "k3", "zeta"], sort=False):
        for method in methods:
            row = {"series": series_label(psd, k3, zeta), "psd": psd, "k3": k3, "zeta": zeta}
            row["method"] = method
            for tol in tolerances:
                row[tolerance_column(tol)] = trusted_limit(
                    sub.phi, sub[f"{method}_rel_error"], sub[f"{method}_rel_error_ci95"], tol
                )
            rows.append(row)
    return pd.DataFrame(rows)


def format_limit(value: float, phis) -> str:
    """A limit for a table: '< 0.02' (trusted nowhere), '> 5' (everywhere) or the value."""
    if value == 0.0:
        return f"< {min(phis):.3g}"
    if np.isinf(value):
        return f"> {max(phis):.3g}"
    return f"{value:.3g}"


def limit_text(value: float, phis) -> str:
    """A trusted range in words: 'phi <= x', 'every phi on the grid' or 'no phi on the grid'."""
    if value == 0.0:
        return f"no phi on the grid (fails already at {min(phis):.3g})"
    if np.isinf(value):
        return f"every phi on the grid (up to {max(phis):.3g})"
    return f"phi <= {value:.3g}"


def describe_limits(row, phis, tolerances=TOLERANCES) -> str:
    """'1 % for phi <= 0.1 (Eq. 32 P/P(0) >= 0.94), 5 % for ...': one row of :func:`thresholds`."""
    parts = []
    for tol in tolerances:
        value = row[tolerance_column(tol)]
        ratio = f" (Eq. 32 P/P(0) >= {power_ratio(value):.2f})" if 0 < value < np.inf else ""
        parts.append(f"{round(100 * tol)} % for {limit_text(value, phis)}" + ratio)
    return ", ".join(parts)


def limits_shown(limits: pd.DataFrame, phis, tolerances=TOLERANCES) -> pd.DataFrame:
    """:func:`thresholds` for a report: limits as text, one column 'phi trusted to 5 %' each."""
    shown = limits.copy()
    for tol in tolerances:
        shown[tolerance_column(tol)] = [format_limit(v, phis) for v in shown[tolerance_column(tol)]]
    shown = shown.rename(
        columns={tolerance_column(t): f"phi trusted to {round(100 * t)} %" for t in tolerances}
    )
    return shown.drop(columns=["psd", "k3", "zeta"])


def collapse(table: pd.DataFrame) -> dict:
    """Largest spread of the error between S series of one (k3, zeta), per k3.

    Returns {k3: (largest spread, largest ci95 at those points)} over the
    (k3, zeta) groups with more than one S.
    """
    out = {}
    for (k3, _zeta), sub in table.groupby(["k3", "zeta"]):
        if sub.psd.nunique() < 2:
            continue
        key = sub.phi.round(6)
        spread = sub.groupby(key).linearisation_rel_error.agg(lambda e: e.max() - e.min()).max()
        ci = sub.linearisation_rel_error_ci95.max()
        prev = out.get(k3, (0.0, 0.0))
        out[k3] = (max(prev[0], float(spread)), max(prev[1], float(ci)))
    return out


def collapse_sentence(spreads: dict, rounding: float) -> str:
    """The collapse of the S series (:func:`collapse`) per k3, in words.

    At k3 = 0 the SDE scales exactly with S, so a spread above ``rounding``
    is a simulator or grid problem; with the Duffing term it measures how far
    the spring breaks the scaling, against the intervals.
    """
    return " ".join(
        f"k3 = {k3:.3g}: largest spread of the error between S at equal phi "
        f"{100 * spread:.2g} % (95 % half-widths up to {100 * ci:.2g} %)"
        + (
            " - the same paths rescaled, equal to rounding, as the exact scaling requires."
            if k3 == 0 and spread <= rounding
            else " - more than rounding, although the exact scaling makes them the same paths "
            "rescaled: a simulator or grid problem."
            if k3 == 0
            else "; the Duffing term breaks the scaling by more than the intervals resolve."
            if spread > ci
            else "; the Duffing term breaks the exact scaling, but its effect on the error "
            "is within the intervals at this k3."
        )
        for k3, (spread, ci) in spreads.items()
    )


def reference_verdict(ref: pd.DataFrame, spread0, zeta: float, phis, rounding: float) -> str:
    """The trusted ranges of the reference device's k3 = 0 series (rows of :func:`thresholds`).

    The least limit over the series is quoted, with whether the series
    collapse on phi (``spread0``: the k3 = 0 entry of :func:`collapse`, or
    None).
    """
    worst = ref[[tolerance_column(t) for t in TOLERANCES]].min()
    if len(ref) < 2 or spread0 is None:
        tail = f"from the single S = {ref.psd.iloc[0]:g} series."
    elif spread0[0] <= rounding:
        tail = (
            f"the least over the {len(ref)} S series, which collapse on phi (largest "
            f"spread {spread0[0]:.1e})."
        )
    else:
        tail = (
            f"the least over the {len(ref)} S series, which do not collapse on phi "
            f"(spread up to {100 * spread0[0]:.2g} %)."
        )
    return (
        f"For the figure9 device without the Duffing term (zeta = {zeta:.3f}), Eq. 32 "
        f"is trusted (upper 95 % bound of its error) to {describe_limits(worst, phis)}; " + tail
    )


def error_sign_sentences(signs) -> list[str]:
    """The sign of Eq. 32's error where it exceeds 1 % (``signs``: its signs there)."""
    sentences = []
    if len(signs) and (signs > 0).all():
        sentences.append(
            "Wherever the error exceeds 1 % it is positive: Eq. 32 over-predicts the power."
        )
    elif len(signs) and not (signs < 0).all():
        sentences.append(
            f"Where the error exceeds 1 % it is negative at {int((signs < 0).sum())} and "
            f"positive at {int((signs > 0).sum())} points."
        )
    if len(signs) and (signs < 0).all():
        sentences.append(
            "Wherever the error exceeds 1 % it is negative: Eq. 32 under-predicts the power. "
            "By the exact energy balance c E[z'^2] + Fc E|z'| = S m / 4 this means the "
            "simulated E|z'| / sqrt(E[z'^2]) is below the Gaussian sqrt(2/pi): sticking puts "
            "probability near z' = 0, which the Gaussian closure cannot represent."
        )
    return sentences


def averaging_sentence(table: pd.DataFrame, limits: pd.DataFrame, phis) -> str:
    """Stochastic averaging beside Eq. 32: closer at how many points, its trusted ranges,
    and where its own validity condition (friction damping ratio zeta_f <= 0.5) fails."""
    avg = limits[limits.method == "averaging"]
    n_invalid = int((table.averaging_zeta_friction > 0.5).sum())
    better = int((table.averaging_rel_error.abs() <= table.linearisation_rel_error.abs()).sum())
    return (
        f"\n\nStochastic averaging (open markers) is at least as close to Monte Carlo as "
        f"Eq. 32 at {better} of {len(table)} points; its trusted ranges are in the same "
        "table (over all series: "
        + ", ".join(
            f"{round(100 * t)} % for {limit_text(float(avg[tolerance_column(t)].min()), phis)}"
            for t in TOLERANCES
        )
        + "). It warns of its own validity where the friction damping ratio zeta_f "
        f"exceeds 0.5 ({n_invalid} of {len(table)} points here"
        + (
            f", at phi >= {table.phi[table.averaging_zeta_friction > 0.5].min():.3g})."
            if n_invalid
            else ")."
        )
    )
