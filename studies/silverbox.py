"""Silverbox benchmark (measured data): ``python studies/silverbox.py OUT_DIR [--quick]``.

Fits the linear (k3 fixed at 0) and the Duffing model, force input u = V1,
output y = V2, mass free, on the multisine part (samples 40,700 to the end)
and validates on the arrow-head part (the first 40,700 samples); writes
``silverbox.md`` and the fitted parameters as JSON. The record ships with the
package (``randvib.datasets.silverbox_path()``); the same fits from the
command line::

    randvib identify SNLS80mV.csv --input-column V1 --input-kind force \\
        --output-column V2 --sample-rate 610.3515625 --rows 40700: \\
        --model viscous --fix k3=0 --save linear.json
    randvib validate linear.json SNLS80mV.csv --input-column V1 --input-kind force \\
        --output-column V2 --sample-rate 610.3515625 --rows 0:40700
"""

import json
import sys
from pathlib import Path

from randvib.datasets import silverbox
from randvib.identification.fitting import identify, predict_record


def main(out_dir, quick=False):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=False)
    estimation = silverbox("multisine")
    validation = silverbox("arrow-head")
    opt = dict(popsize=20, maxiter=40) if quick else dict(popsize=50, maxiter=200)
    rows = []
    for label, fixed in (("linear (k3 = 0)", {"k3": 0.0}), ("Duffing", {})):
        res = identify(estimation, "viscous", fixed=fixed, seed=0, substeps=4, progress=True, **opt)
        (out / f"{label.split()[0].lower()}.json").write_text(json.dumps(res.to_dict(), indent=2))
        for rec in (estimation, validation):
            pred = predict_record(res.parameters, "viscous", rec, substeps=4)
            rows.append((label, rec.name, pred.cost, 1e3 * pred.rms_error, res.parameters))
    lines = ["| model | record | J (Eq. 11) | RMS error (mV) |", "|---|---|---|---|"]
    lines += [f"| {m} | {r} | {j:.4g} | {e:.3g} |" for m, r, j, e, _ in rows]
    lines += ["", "Parameters (per unit force gain; mass free):", ""]
    for m, _, _, _, p in rows[::2]:
        lines.append(f"- {m}: " + ", ".join(f"{k} = {v:.6g}" for k, v in p.items()))
    text = "\n".join(lines) + "\n"
    (out / "silverbox.md").write_text(text)
    print(text)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: python studies/silverbox.py OUT_DIR [--quick]")
    main(sys.argv[1], quick="--quick" in sys.argv[2:])
