"""Seed calibration of the Monte Carlo assertions in tests/test_simulation.py and test_statistics.py.

Run by hand (not collected by pytest), from the repository root:

    NUMBA_NUM_THREADS=1 python tests/calibration/simulation.py [n_seeds]

For every exact comparison (``case_*`` in the test module) it reruns the
statistic over seeds 1000, 1001, ... and prints, per assertion, the number of
seeds, the mean and standard deviation of the z-scores and the largest |z|
(calibrated: mean near 0, SD near 1, no |z| above 4), plus the smallest power
margin (detect * |reference| / standard error, which must be >= 6). For
test_rng.py it prints the spread of each z-score (the KS p-value and the
largest pair correlation, in units of 1/sqrt(n), as they are). For the
coverage test it prints the hit fractions against the binomial acceptance
region, and for the control-variate gain the smallest ratio.

Usage: ``simulation.py N [name ...]`` runs N seeds (fewer for the slow
cases) for the named groups only (linear, load, scheme-em, scheme-heun,
gibbs, balance, lugre, rng, gain, coverage).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import test_simulation as t  # noqa: E402
from _stats import calibrate as _calibrate  # noqa: E402

CASES = {
    "linear": (t.case_linear_continuous, 1.0),
    "load": (t.case_load_power, 1.0),
    "scheme-em": (lambda s: t.case_scheme_discrete("euler-maruyama", s), 1.0),
    "scheme-heun": (lambda s: t.case_scheme_discrete("heun", s), 1.0),
    "gibbs": (t.case_duffing_gibbs, 1.0),
    "balance": (t.case_energy_balance, 1.0),
    "lugre": (t.case_lugre_fine_reference, 0.4),  # slower (numpy reference): fewer seeds
}


def calibrate(name, case, seeds):
    return _calibrate(name, case, seeds, widths=(12, 20))


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    only = sys.argv[2:] or None
    for name, (case, share) in CASES.items():
        if only and name not in only:
            continue
        calibrate(name, case, range(1000, 1000 + max(20, int(n * share))))
    if not only or "rng" in only:
        import test_rng

        rows = [test_rng.rng_z_scores(s) for s in range(1000, 1000 + max(20, 2 * n))]
        for key in rows[0]:
            v = np.array([r[key] for r in rows])
            print(
                f"rng          {key:25s} seeds {v.size}  mean {v.mean():+.3f}  SD {v.std(ddof=1):.3f}  "
                f"min {v.min():.3g}  max {v.max():.3g}",
                flush=True,
            )
    if not only or "gain" in only:
        gains = [t.case_control_variate_gain(s) for s in range(1000, 1000 + max(20, n // 2))]
        print(
            f"gain         seeds {len(gains)}  smallest ratio {min(gains):.2f}  median {np.median(gains):.2f}"
        )
    if not only or "coverage" in only:
        import test_statistics as ts

        k = max(20, n // 5)
        for label, reps, fn in (
            ("synthetic n=100 p=4", 3000, lambda s: ts.synthetic_coverage(s, 3000, 100, 4)),
            ("simulation groups", 600, lambda s: ts.simulation_coverage(s, 600)),
            ("in-sample n=24 p=6", 2000, lambda s: ts.synthetic_coverage(s, 2000, 24, 6, True)),
        ):
            lo, hi = ts.binomial_acceptance(reps)
            hits = np.array([fn(s) for s in range(1000, 1000 + k)])
            inside = np.sum((hits >= lo) & (hits <= hi))
            print(
                f"coverage {label:22s} seeds {k}  mean {hits.mean() / reps:.4f}  "
                f"range [{hits.min() / reps:.4f}, {hits.max() / reps:.4f}]  "
                f"region [{lo / reps:.4f}, {hi / reps:.4f}]  inside {inside}/{k}",
                flush=True,
            )


if __name__ == "__main__":
    main()
