"""The Gaussian answer against Monte Carlo: relative errors, their intervals and a 5 % verdict.

A study of input beyond stationary Gaussian noise (tones, non-Gaussian
vibration) asks where the Gaussian analytic answer -- statistical
linearisation under the Gaussian input of the same spectrum, or its
combined harmonic-and-random form under tones
(:mod:`randvib.analytic.harmonic_linearisation`) -- errs by more than a
tolerance. :func:`gaussian_answers` computes that answer for each case of a
paired run, :func:`relative_errors` its error against Monte Carlo with the
95 % interval of the Monte Carlo estimate carried through, and
:func:`error_verdict` classifies each error by the data:

* ``"errs"`` - the whole 95 % interval of the relative error lies beyond
  the tolerance (the Gaussian answer errs by more than it);
* ``"within"`` - the whole interval lies inside;
* ``"undecided"`` - the interval straddles the tolerance (more paths decide);
* ``"no answer"`` - no Gaussian answer exists (the Gaussian closure of a
  double well has no solution) or Monte Carlo saw nothing (no exceedance).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd

from randvib.analytic.prediction import predict

#: The tolerance of the verdicts (relative).
TOLERANCE = 0.05


def gaussian_answer(device, excitation) -> dict:
    """The Gaussian analytic answer for one case: power (W) and stroke exceedance; NaN without one.

    Statistical linearisation (``method="linearisation"``) under the input
    as given: under tones its combined harmonic-and-random form; a
    non-Gaussian translation process is answered by its spectrum. Its
    validity warnings are the study's subject, not the user's: silenced.
    """
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            p = predict(device, excitation, "linearisation")
    except ValueError:  # no Gaussian solution (a double well's closure)
        return {"power_gaussian": math.nan, "exceedance_gaussian": math.nan}
    exceedance = p.stroke_exceedance if p.stroke_exceedance is not None else math.nan
    return {"power_gaussian": float(p.power_electrical), "exceedance_gaussian": float(exceedance)}


def gaussian_answers(run) -> pd.DataFrame:
    """:func:`gaussian_answer` of every case of a run of :func:`randvib.run_ensembles`."""
    return pd.DataFrame([gaussian_answer(c.device, c.excitation) for c in run.cases])


def relative_errors(predicted, estimate, ci95) -> tuple[np.ndarray, np.ndarray]:
    """(predicted / estimate - 1, its 95 % half-width) from a Monte Carlo estimate and half-width.

    The half-width is carried through the ratio to first order
    (predicted / estimate^2 times the estimate's); NaN where the estimate is
    not positive.
    """
    predicted, estimate, ci95 = (np.asarray(x, dtype=float) for x in (predicted, estimate, ci95))
    with np.errstate(divide="ignore", invalid="ignore"):
        positive = estimate > 0
        error = np.where(positive, predicted / estimate - 1.0, np.nan)
        half = np.where(positive, np.abs(predicted) * ci95 / estimate**2, np.nan)
    return error, half


def error_verdict(error, half, tolerance: float = TOLERANCE) -> np.ndarray:
    """``errs``, ``within``, ``undecided`` or ``no answer`` for each relative error (module doc)."""
    error, half = np.asarray(error, dtype=float), np.asarray(half, dtype=float)
    size = np.abs(error)
    out = np.where(
        size - half > tolerance, "errs", np.where(size + half < tolerance, "within", "undecided")
    )
    return np.where(np.isfinite(error) & np.isfinite(half), out, "no answer")


def with_errors(table: pd.DataFrame, quantity: str, mc: str) -> pd.DataFrame:
    """``table`` with ``{quantity}_error``, ``_error_ci95`` and ``_verdict`` of the Gaussian answer.

    ``{quantity}_gaussian`` against the Monte Carlo columns ``mc`` and
    ``{mc}_ci95``.
    """
    error, half = relative_errors(table[f"{quantity}_gaussian"], table[mc], table[f"{mc}_ci95"])
    out = table.copy()
    out[f"{quantity}_error"], out[f"{quantity}_error_ci95"] = error, half
    out[f"{quantity}_verdict"] = error_verdict(error, half)
    return out


def verdict_counts(table: pd.DataFrame, quantity: str) -> dict:
    """How many cases got each verdict for ``quantity``."""
    counts = table[f"{quantity}_verdict"].value_counts()
    return {name: int(counts.get(name, 0)) for name in ("errs", "within", "undecided", "no answer")}
