"""Silverbox benchmark (measured data): ``randvib study silverbox --out OUT [--quick]``.

(or ``python studies/silverbox.py OUT [--quick]``). Fits the linear (k3
fixed at 0) and the Duffing model, force input u = V1, output y = V2, mass
free, on the multisine part (samples 40,700 to the end) and validates on the
arrow-head part (the first 40,700 samples); writes ``report.md``, the fit
table ``results.csv`` and the fitted parameters as ``linear.json`` and
``duffing.json``. The record ships with the package
(``randvib.datasets.silverbox_path()``); the same fits from the command line::

    randvib identify SNLS80mV.csv --input-column V1 --input-kind force \\
        --output-column V2 --sample-rate 610.3515625 --rows 40700: \\
        --model viscous --fix k3=0 --save linear.json
    randvib validate linear.json SNLS80mV.csv --input-column V1 --input-kind force \\
        --output-column V2 --sample-rate 610.3515625 --rows 0:40700
"""

from __future__ import annotations

import sys

import pandas as pd

from randvib._io import dumps, write_tracked
from randvib.datasets import silverbox
from randvib.identification.fitting import identify, predict_record
from randvib.studies import script_main
from randvib.studies.report import markdown_table, prepare_output_dir, write_report, write_table

MODELS = {"linear (k3 = 0)": {"k3": 0.0}, "Duffing": {}}
SUBSTEPS = 4


def fit_and_validate(estimation, validation, label, fixed, opt, seed, progress):
    """One model fitted on ``estimation``; its cost and RMS error on both records."""
    res = identify(
        estimation, "viscous", fixed=fixed, seed=seed, substeps=SUBSTEPS, progress=progress, **opt
    )
    rows = []
    for rec in (estimation, validation):
        pred = predict_record(res.parameters, "viscous", rec, substeps=SUBSTEPS)
        rows.append(
            {
                "model": label,
                "record": rec.name,
                "J (Eq. 11)": pred.cost,
                "RMS error (mV)": 1e3 * pred.rms_error,
            }
        )
    return res, rows


def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True):
    """Fit and validate the Silverbox models; write ``report.md`` and the fits into ``out_dir``.

    ``workers`` and ``scheduler`` are not used: each fit runs in this process.
    """
    opt = dict(popsize=20, maxiter=40) if quick else dict(popsize=50, maxiter=200)
    out = prepare_output_dir(out_dir, {"study": "silverbox", "quick": quick, "seed": seed})
    estimation, validation = silverbox("multisine"), silverbox("arrow-head")
    rows, params = [], {}
    for label, fixed in MODELS.items():
        res, fit_rows = fit_and_validate(estimation, validation, label, fixed, opt, seed, progress)
        write_tracked(out / f"{label.split()[0].lower()}.json", dumps(res.to_dict(), indent=2))
        rows += fit_rows
        params[label] = res.parameters
    table = pd.DataFrame(rows)
    write_table(out, "results.csv", table)
    listing = "\n".join(
        f"- {m}: " + ", ".join(f"{k} = {v:.6g}" for k, v in p.items()) for m, p in params.items()
    )
    return write_report(
        out,
        "Silverbox: linear and Duffing models identified from measured data",
        [
            (
                "Fits",
                "Estimation on the multisine part, validation on the arrow-head part "
                f"(force u = V1, output y = V2, mass free, {SUBSTEPS} sub-steps, seed {seed}"
                f"{', quick mode' if quick else ''}).\n\n" + markdown_table(table),
            ),
            ("Parameters (per unit force gain; mass free)", listing),
        ],
    )


if __name__ == "__main__":
    sys.exit(script_main(run_study))
