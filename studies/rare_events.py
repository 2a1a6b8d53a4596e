"""End-stop strikes at rare levels against the Gaussian answers: ``randvib study rare-events``.

(or ``python studies/rare_events.py OUT [--quick]``). A harvester built for
years of service must strike its end stop rarely, and its designer reads the
stroke off a Gaussian answer: the stationary exceedance erfc(D / (sigma_z
sqrt 2)) of the design's stroke budget, and Rice's crossing rate with
Poisson's or Vanmarcke's first-passage approximation. How wrong is that at
1e-2 to 1e-8, for devices that are not linear?

Devices (m = 0.0226 kg assumed, c_m = c_e = 0.1 Ns/m, k = 57.4 N/m), each
with and without the paper's Coulomb friction (Fc = 5.8 mN):

* ``paper`` - the paper's device (preset ``figure9``, k3 = 70742 N/m^3);
* ``duffing`` - a stiffer spring, k3 = 5e5 N/m^3;
* ``bistable`` - k = -57.4 N/m, wells at +-2.5 mm (k3 = 9.18e6 N/m^3);

under white noise (S = 1 (m/s^2)^2/Hz) and band-pass input (peak S = 1 at
8 Hz, zeta = 0.25), in a window T = 0.5 s, Heun at dt = 1e-3 s (a stationary-
variance bias near 1e-3 on these devices: about 2 % on a probability at 1e-8,
far below the factors the study is about). For each, a pilot subset
simulation finds the strokes at which the first passage within T has
probability 1e-2, 1e-4, 1e-6 and 1e-8;
at each stroke :func:`randvib.first_passage` (subset simulation) estimates the
first-passage probability, the stationary exceedance and the crossing rate
with 95 % intervals, beside the Gaussian answer (statistical linearisation,
:mod:`randvib.analytic.crossings`) and, without friction under white noise,
the exact Gibbs values. Reported: the stroke from which the Gaussian answer
is unsafe by a factor of 2 or more (:func:`randvib.studies.rare_events.unsafe_strokes`).
"""

from __future__ import annotations

import sys
import time

import pandas as pd

import randvib as rv
from randvib.studies import report, script_main
from randvib.studies.rare_events import probability_figure, rows_at, strokes_at, unsafe_strokes

NAME = "rare-events"
FC = 0.0058  #: N, the paper's Coulomb level
WELL = 0.0025  #: m, the bistable device's wells
QUICK = {"devices": ("paper", "duffing, no friction"), "inputs": ("white",),
         "probabilities": (1e-2, 1e-3), "duration": 0.2, "dt": 1e-3, "samples": 200,
         "target_cov": 0.5}  # fmt: skip
FULL = {"devices": None, "inputs": ("white", "band-pass"),
        "probabilities": (1e-2, 1e-4, 1e-6, 1e-8), "duration": 0.5, "dt": 1e-3,
        "samples": 500, "target_cov": 0.2}  # fmt: skip

__all__ = ["devices", "grid", "inputs", "run_study", "sentences"]


def grid(quick: bool) -> dict:
    """Devices, inputs, target probabilities, window T (s), step (s), subset sizes."""
    return dict(QUICK if quick else FULL)


def devices() -> dict:
    """The six devices by name (``paper``, ``paper, no friction``, ...)."""
    paper = rv.preset("figure9")
    bases = {
        "paper": paper,
        "duffing": paper.updated(k3=5e5),
        "bistable": paper.updated(k=-paper.k, k3=paper.k / WELL**2),
    }
    out = {}
    for name, device in bases.items():
        out[name] = device
        out[f"{name}, no friction"] = device.updated(friction=None)
    return out


def inputs() -> dict:
    return {"white": 1.0, "band-pass": rv.BandPass(1.0, 8.0, 0.25)}


def sentences(v: dict, g: dict) -> list[str]:
    """The report's verdicts in words, from the unsafe strokes."""
    lines = []
    for key, entry in v.items():
        for what, words in (("exceedance", "stationary exceedance (the stroke budget)"),
                            ("first_passage", "first passage (Vanmarcke)")):  # fmt: skip
            stroke = entry[what]["unsafe_from_stroke"]
            ratios = [r for r in entry[what]["ratio_by_stroke"].values() if r is not None]
            span = (f"estimate / Gaussian {min(ratios):.3g} to {max(ratios):.3g}"
                    if ratios else "no Gaussian answer")  # fmt: skip
            verdict = ("never unsafe by 2 on this grid" if stroke is None
                       else f"unsafe by 2 or more from D = {1e3 * stroke:.3g} mm")  # fmt: skip
            lines.append(f"{key}, {words}: {verdict} ({span}).")
    return lines


def run_study(out_dir, *, quick=False, seed=0, workers=None, scheduler=None, progress=True):
    """Run the study; write ``results.csv``, the figure, ``verdicts.json`` and ``report.md``.

    ``quick``: two devices under white noise at 1e-2 and 1e-3 (seconds); the
    estimates run in this process (``workers`` and ``scheduler`` are not used).
    """
    g = grid(quick)
    out = report.prepare_output_dir(out_dir, {"study": NAME, "quick": quick, "seed": seed})
    started = time.perf_counter()
    rows = []
    for input_name in g["inputs"]:
        excitation = inputs()[input_name]
        for name, device in devices().items():
            if g["devices"] is not None and name not in g["devices"]:
                continue
            strokes = strokes_at(device, excitation, g["probabilities"],
                                 duration=g["duration"], dt=g["dt"], seed=seed,
                                 samples=g["samples"])  # fmt: skip
            rows += rows_at(f"{name} ({input_name})", device, excitation, strokes,
                            duration=g["duration"], dt=g["dt"], seed=seed,
                            target_cov=g["target_cov"], samples=g["samples"])  # fmt: skip
    results = pd.DataFrame(rows)
    report.write_table(out, "results.csv", results)
    figure = probability_figure(results, out / "probability.png")
    v = unsafe_strokes(results)
    lines = sentences(v, g)
    report.write_verdicts(out, v, lines)
    wall = time.perf_counter() - started
    setup = (
        f"Devices: {', '.join(dict.fromkeys(results.device))}; window T = {g['duration']:g} s, "
        f"Heun at dt = {g['dt']:g} s; strokes at first-passage probabilities "
        f"{', '.join(f'{p:g}' for p in g['probabilities'])} (pilot subset simulation); "
        f"each estimate by subset simulation ({g['samples']} samples per level, target "
        f"c.o.v. {g['target_cov']:g}), seed {seed}.{' Quick mode.' if quick else ''} "
        f"Wall time {wall:.0f} s.\n\n![probability against stroke]({figure.name})"
    )
    shown = results[["device", "stroke", "probability_first_passage",
                     "probability_first_passage_ci95", "gaussian_vanmarcke", "gaussian_poisson",
                     "stationary_exceedance", "stationary_exceedance_ci95",
                     "gaussian_exceedance", "exact_exceedance"]]  # fmt: skip
    return report.write_report(
        out,
        f"Study {NAME}: end-stop strikes at rare levels{' (quick)' * quick}",
        [
            ("Set-up", setup),
            ("Verdicts", "\n".join(f"- {line}" for line in lines)),
            ("Estimates and answers", report.markdown_table(report.readable_table(shown))),
        ],
    )


if __name__ == "__main__":
    sys.exit(script_main(run_study))
