"""Seed calibration of the Monte Carlo assertions in tests/test_coupling_synthesised.py.

Run by hand (not collected by pytest), from the repository root:

    NUMBA_NUM_THREADS=1 python tests/calibration/coupling_synthesised.py [n_seeds] [name ...]

Reruns ``case_band_limited_circuit`` over seeds 1000, 1001, ... and prints, per
assertion, the mean and SD of the z-scores, the largest |z| and the smallest
power margin (>= 6 needed). Names: the keys of ``COUPLINGS``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # this checkout's randvib

import test_coupling_synthesised as t  # noqa: E402
from _stats import calibrate  # noqa: E402

if __name__ == "__main__":
    n_seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    for name in sys.argv[2:] or list(t.COUPLINGS):
        calibrate(
            name, lambda s, n=name: t.case_band_limited_circuit(n, s), range(1000, 1000 + n_seeds)
        )
