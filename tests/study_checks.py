"""Independent numbers for the studies' Monte Carlo results, shared by tests and calibration.

The studies estimate E[P_e] and paired contrasts by Monte Carlo. The numbers
they are checked against here come from the corrected Fokker-Planck grids
(``method="fpk-fast"``, :func:`randvib.analytic.fokker_planck.fast_fpk_statistics`),
which solve the stationary FPK equation of the same SDE by a different route
(no sampling) and agree with the fine reference grid to 0.05 % of E[z'^2]
on these devices (tests/test_fokker_planck.py). That is 1/10 or less of the
quick studies' standard errors, so it is neglected in the thresholds.

A study's CSV gives each estimate with its 95 % half-width; the standard
error is that half-width over the Student t quantile of its paths.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
from scipy import stats

from randvib.analytic.averaging import AveragingValidityWarning
from randvib.analytic.prediction import expected_power
from randvib.models.presets import preset
from randvib.statistics import Statistic


def statistic(mean, ci95, n_paths) -> Statistic:
    """A :class:`Statistic` from a study's CSV columns (t-based 95 % half-width)."""
    se = float(ci95) / stats.t.ppf(0.975, int(n_paths) - 1)
    return Statistic(float(mean), float(ci95), se, int(n_paths))


def fpk_power(psd, k3, fc) -> float:
    """E[P_e] of the figure9 device from the corrected FPK grids (independent of Monte Carlo)."""
    device = preset("figure9").updated(k3=float(k3), fc=float(fc))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AveragingValidityWarning)
        return float(expected_power(device, float(psd), "fpk-fast"))


def power_zscores(table: pd.DataFrame) -> pd.DataFrame:
    """Monte Carlo E[P_e] against the FPK power at every point with friction.

    Columns: psd, k3, fc, the FPK power, the z-score, the relative standard
    error and Eq. 32's relative error against the FPK power.
    """
    rows = []
    for r in table[table.fc > 0].itertuples():
        ref = fpk_power(r.psd, r.k3, r.fc)
        s = statistic(r.power_electrical, r.power_electrical_ci95, r.n_paths)
        rows.append(
            {
                "psd": r.psd,
                "k3": r.k3,
                "fc": r.fc,
                "fpk_power": ref,
                "z": (s.mean - ref) / s.std_error,
                "rel_se": s.std_error / ref,
                "lin_error_vs_fpk": r.linearisation_power / ref - 1.0,
                "stat": s,
            }
        )
    return pd.DataFrame(rows)


def contrast_zscores(inter: pd.DataFrame, zero_baseline: bool = False) -> pd.DataFrame:
    """Paired interaction contrasts against the FPK contrast at every row.

    The FPK contrast is [P(Fc, k3) - P(Fc, 0)] - [P(0, k3) - P(0, 0)] from
    the grids (the second bracket is zero up to the grids' truncation, a few
    1e-5 relative).
    """
    rows = []
    for r in inter.itertuples():
        p = {(fc, k3): fpk_power(r.psd, k3, fc) for fc in (r.fc, 0.0) for k3 in (r.k3, 0.0)}
        ref = p[(r.fc, r.k3)] - p[(r.fc, 0.0)] - p[(0.0, r.k3)] + p[(0.0, 0.0)]
        s = statistic(r.contrast, r.contrast_ci95, r.n_paths)
        rows.append(
            {
                "psd": r.psd,
                "k3": r.k3,
                "fc": r.fc,
                "fpk_contrast": ref,
                "fpk_relative": ref / p[(r.fc, 0.0)],
                "z": (s.mean - ref) / s.std_error,
                "se": s.std_error,
                "stat": s,
            }
        )
    return pd.DataFrame(rows)


def step_zscores(check: pd.DataFrame) -> np.ndarray:
    """Half-step minus step estimate in combined standard errors (zero without a step bias)."""
    t = stats.t.ppf(0.975, 127)
    return (check.difference / (check.combined_ci95 / t)).to_numpy()


# ----------------------------------------------------------------- what a study leaves
#: Tokens a report for an outside reader must not contain: NaN, a negative zero, and
#: references to the project's issue tracker.
_UNCLEAN = {
    "nan": r"(?i)\bnan\b",
    "-0": r"(?<![\w.])-0(\.0+)?(?![\d.])",
    "issue ": r"(?i)\bissue\s",
}


def unclean_tokens(text: str) -> dict:
    """The forbidden tokens found in a report's ``text``, with a little context each."""
    import re

    found = {}
    for name, pattern in _UNCLEAN.items():
        hits = [text[max(m.start() - 30, 0) : m.end() + 30] for m in re.finditer(pattern, text)]
        if hits:
            found[name] = hits[:3]
    return found


def check_study_run(stdout: str, out) -> str:
    """A study run's terminal output and report: the report's path, then its verdicts
    (``verdicts.json`` shown), and a report without 'nan', '-0' or 'issue '. Returns
    the report's text."""
    lines = stdout.strip().splitlines()
    assert lines[0] == f"report: {out / 'report.md'}"
    assert lines[1] == f"verdicts ({out / 'verdicts.json'}):" and len(lines) > 2
    text = (out / "report.md").read_text()
    assert unclean_tokens(text) == {}
    return text
