"""A measured benchmark: physical models fitted on a training record, scored on held-out records.

A benchmark study (Silverbox) identifies several models on one training
record and simulates each held-out record with every fit, scoring J (paper
Eq. 11) and the RMS simulation error. :func:`fit_and_score` runs the fits
(:func:`randvib.identify`, each kept in the study's folder as JSON by
:func:`randvib.studies.campaign.identify_cached`, so an interrupted study
resumes) and tabulates the scores; :func:`ablation_table` does so for the
steps of an ablation (one fit per step, its RMS error per record);
:func:`parameter_listing` lists the fitted parameters with their standard
errors; :func:`rms_beyond` gives the error over the samples of a record
beyond its first part (the arrow-head's extrapolated amplitudes).

A record is scored as the benchmark scores it: ``score`` (the options of
:func:`randvib.predict_record`, e.g. ``skip`` for the samples left out of
the score and ``initial_state="record"`` for a start taken from the first
samples only) overrides the fit's own simulation settings on the held-out
records; the training record is scored as it was fitted.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from randvib.identification.prediction import predict_record
from randvib.studies.campaign import identify_cached

__all__ = ["ablation_table", "fit_and_score", "parameter_listing", "rms_beyond", "score_fit"]

#: The column of the RMS simulation error (mV) in :func:`fit_and_score`'s table.
RMS = "RMS error (mV)"


def score_fit(fit, record, **score) -> dict:
    """J (Eq. 11) and RMS error (mV) of ``fit`` simulating ``record`` (``score``: overrides)."""
    prediction = predict_record(
        fit.harvester(), record, measurement=fit.measurement, simulation=fit.simulation, **score
    )
    return {"J (Eq. 11)": prediction.cost, RMS: 1e3 * prediction.rms_error}


def fit_and_score(records, fits: dict, folder, *, model="viscous", score=None, **kwargs):
    """Every fit of ``fits`` on ``records[0]``, scored on every record.

    Parameters
    ----------
    records : list of Record
        The training record first, then the held-out records.
    fits : dict
        label -> (file name stem, :func:`randvib.identify` options).
    folder : path-like
        Where each fit is kept (``STEM.json``); a fit found there is loaded.
    model : str
        The model identified.
    score : dict, optional
        :func:`randvib.predict_record` options for the held-out records.
    kwargs
        :func:`randvib.identify` options common to every fit.

    Returns
    -------
    table : DataFrame
        ``model`` (the label), ``record`` (its name), ``J (Eq. 11)``, ``RMS error (mV)``.
    results : dict
        label -> :class:`~randvib.IdentificationResult`.
    """
    rows, results = [], {}
    for label, (stem, options) in fits.items():
        fit = identify_cached(Path(folder) / f"{stem}.json", records[0], model,
                              **{**kwargs, **options})  # fmt: skip
        results[label] = fit
        for i, rec in enumerate(records):
            scored = score_fit(fit, rec, **((score or {}) if i else {}))
            rows.append({"model": label, "record": rec.name, **scored})
    return pd.DataFrame(rows), results


def rms_beyond(full_rms: float, n_full: int, part_rms: float, n_part: int) -> float:
    """The RMS error over the samples of a record beyond its first part (same units).

    ``full_rms`` over the ``n_full`` scored samples of the record, ``part_rms``
    over the ``n_part`` scored samples of its first part (both scored from the
    same start): the mean squares add, weighted by the sample counts.
    """
    if not 0 < n_part < n_full:
        raise ValueError(f"`n_part` must lie in (0, n_full = {n_full}), got {n_part!r}")
    return float(((full_rms**2 * n_full - part_rms**2 * n_part) / (n_full - n_part)) ** 0.5)


def ablation_table(records, steps: dict, folder, last: tuple, **kwargs) -> pd.DataFrame:
    """One fit per step of an ablation: its RMS error (mV) on each record, a row per step.

    ``steps`` and ``kwargs`` as :func:`fit_and_score`'s ``fits`` and options;
    ``last``: (label, table of :func:`fit_and_score`'s rows of the complete
    model) for the last row. Columns ``measurement model`` and ``RECORD RMS (mV)``.
    """
    table, _ = fit_and_score(records, steps, folder, **kwargs)
    label, complete = last
    table = pd.concat([table, complete.assign(model=label)])
    wide = table.pivot(index="model", columns="record", values=RMS)
    wide = wide.loc[list(dict.fromkeys(table["model"])), [r.name for r in records]]
    wide.columns = [f"{name} RMS (mV)" for name in wide.columns]
    return wide.rename_axis("measurement model").reset_index()


def parameter_listing(fits: dict) -> str:
    """A Markdown list of each fit's parameters, with standard errors where the polish gave them."""
    lines = []
    for label, res in fits.items():
        se = res.standard_errors
        items = [
            f"{k} = {v:.6g}" + (f" +- {se[k]:.2g}" if k in se else "")
            for k, v in res.parameters.items()
        ]
        lines.append(f"- {label}: " + ", ".join(items))
    return "\n".join(lines)
