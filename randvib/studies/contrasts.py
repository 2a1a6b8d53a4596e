"""Contrasts between sweep points: paired Monte Carlo estimates and analytic predictions.

The interaction contrast of two factors a, b (e.g. Coulomb friction and the
Duffing spring),

    [P(a, b) - P(a, 0)] - [P(0, b) - P(0, 0)],

is zero when the effect of b on the expected power does not depend on a.
:func:`interaction_contrasts` estimates it from common-random-number paths
of a sweep with a per-contrast test and Holm's step-down over the family,
:func:`paired_interactions` within the groups of a paired run
(:func:`randvib.run_ensembles`); :func:`predicted_contrasts` and
:func:`predicted_contrast_curves` give an analytic method's value of the
same contrast, :func:`predicted_power_curves` the method's power itself on a
fine Fc grid (the curves under a figure's Monte Carlo points).
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from randvib.analytic.averaging import AveragingValidityWarning
from randvib.analytic.prediction import expected_power
from randvib.models.harvester import Harvester
from randvib.montecarlo.sweep import SweepResult, paired_contrast
from randvib.statistics import holm_significant, two_sided_p_value

__all__ = [
    "interaction_contrasts",
    "paired_interactions",
    "predicted_contrast_curves",
    "predicted_contrasts",
    "predicted_power_curves",
]


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


def paired_interactions(result, a: str, b: str, *, predicted: dict | None = None) -> pd.DataFrame:
    """Interaction contrasts of two labels within each group of a paired run.

    For every case with labels ``a`` and ``b`` both non-zero, the contrast

        [P(a, b) - P(a, 0)] - [P(0, b) - P(0, 0)]

    with the three partner cases of its group (same labels but ``a``/``b``),
    estimated path by path on their common paths
    (:meth:`randvib.EnsembleResult.paired`). No test is applied here: the
    caller chooses the family for Holm's correction
    (:func:`randvib.statistics.holm_significant`).

    Parameters
    ----------
    result : EnsembleResult
    a, b : str
        Labels of the two factors (e.g. ``"fc"`` and ``"k3"``).
    predicted : dict, optional
        Name -> one value per case (W; e.g. an analytic power): the same
        contrast of these values, relative to their own P(a, 0), as
        ``{name}_relative_contrast``.

    Returns
    -------
    DataFrame
        The case's labels but ``a``; ``contrast`` and ``contrast_ci95`` (W),
        ``reference`` (P(a, 0), W), ``relative_contrast``, ``relative_ci95``,
        ``p_value`` (two-sided), ``n_paths``; the predicted columns; and
        ``{b}_alone_relative``, the paired effect of ``b`` without ``a``,
        [P(0, b) - P(0, 0)] / P(0, 0). One row per contrast, in case order.
    """
    table = result.table
    rows = []
    for i, case in enumerate(result.cases):
        if case.labels[a] == 0 or case.labels[b] == 0:
            continue
        a0 = result.partner(i, **{b: 0.0})
        b0, zero = result.partner(i, **{a: 0.0}), result.partner(i, **{a: 0.0, b: 0.0})
        four = {i: 1.0, a0: -1.0, b0: -1.0, zero: 1.0}
        s = result.paired(four)
        reference = table.power_electrical[a0]
        row = {k: v for k, v in case.labels.items() if k != a}
        row.update({
            "contrast": s.mean, "contrast_ci95": s.ci95, "reference": reference,
            "relative_contrast": s.mean / reference, "relative_ci95": s.ci95 / reference,
            "p_value": two_sided_p_value(s), "n_paths": s.n_paths,
        })  # fmt: skip
        for name, values in (predicted or {}).items():
            value = np.asarray(values, dtype=float)
            combined = value[i] - value[a0] - value[b0] + value[zero]
            row[f"{name}_relative_contrast"] = combined / value[a0]
        alone = result.paired({b0: 1.0, zero: -1.0})
        row[f"{b}_alone_relative"] = alone.mean / table.power_electrical[zero]
        rows.append(row)
    if not rows:
        raise ValueError(f"no case of the run has both `{a}` and `{b}` non-zero")
    return pd.DataFrame(rows)


def _power(device, psd, method):
    # the studies flag averaging's validity from zeta_friction in their reports
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AveragingValidityWarning)
        return np.asarray(expected_power(device, psd, method), dtype=float)


def predicted_contrasts(
    base: Harvester, rows: pd.DataFrame, method: str = "averaging"
) -> pd.Series:
    """Relative Fc-k3 interaction contrast that ``method`` predicts at each row.

    ``rows`` holds ``psd``, ``fc`` and ``k3`` (e.g. the table of
    :func:`interaction_contrasts`). Relative to the method's own P(Fc, 0).
    Stochastic averaging gives the exact Gibbs power at Fc = 0 for every k3,
    so its P(0, k3) - P(0, 0) is zero; Eq. 32's whole contrast is zero (c_eq
    has no k3).
    """
    out = []
    for row in rows.itertuples():
        p = {
            (fc, k3): float(_power(base.updated(k3=k3, fc=fc), row.psd, method))
            for fc in (row.fc, 0.0)
            for k3 in (row.k3, 0.0)
        }
        contrast = p[(row.fc, row.k3)] - p[(row.fc, 0.0)] - p[(0.0, row.k3)] + p[(0.0, 0.0)]
        out.append(contrast / p[(row.fc, 0.0)])
    return pd.Series(out, index=rows.index, name=f"{method}_relative_contrast")


def predicted_contrast_curves(
    base: Harvester, psds, k3s, fc_max: dict, method: str = "averaging", n: int = 60
) -> pd.DataFrame:
    """:func:`predicted_contrasts` on a fine Fc grid (0 excluded) per S and k3 > 0, for figures.

    ``fc_max`` maps each S to the largest Fc (N). Columns ``psd``, ``k3``,
    ``fc`` and ``{method}_relative_contrast``.
    """
    frames = []
    for psd in psds:
        fc = np.linspace(0.0, fc_max[psd], n)[1:]
        p_ref = _power(base.updated(k3=0.0, fc=fc), psd, method)
        p_ref0 = float(_power(base.updated(k3=0.0, fc=0.0), psd, method))
        for k3 in k3s:
            if k3 == 0:
                continue
            p = _power(base.updated(k3=k3, fc=fc), psd, method)
            p0 = float(_power(base.updated(k3=k3, fc=0.0), psd, method))
            frames.append(
                pd.DataFrame(
                    {
                        "psd": psd,
                        "k3": k3,
                        "fc": fc,
                        f"{method}_relative_contrast": (p - p_ref - p0 + p_ref0) / p_ref,
                    }
                )
            )
    return pd.concat(frames, ignore_index=True)


def predicted_power_curves(
    base: Harvester, psds, k3s, fc_max: dict, method: str = "linearisation", n: int = 200
) -> pd.DataFrame:
    """E[P_e] (W) by ``method`` on a fine Fc grid from 0 per S and k3, for figures and tables.

    ``fc_max`` maps each S to the largest Fc (N). Columns ``psd``, ``k3``,
    ``fc`` and ``{method}_power``, S by S, then k3.
    """
    frames = []
    for psd in psds:
        fc = np.linspace(0, fc_max[psd], n)
        for k3 in k3s:
            power = _power(base.updated(k3=k3, fc=fc), psd, method)
            frames.append(pd.DataFrame({"psd": psd, "k3": k3, "fc": fc, f"{method}_power": power}))
    return pd.concat(frames)
