"""Seed calibration of the Monte Carlo assertions in tests/test_coupling.py.

Run by hand (not collected by pytest), from the repository root:

    NUMBA_NUM_THREADS=1 python tests/calibration/coupling.py [n_seeds] [name ...]

Reruns each ``case_*`` of the test module over seeds 1000, 1001, ... and
prints, per assertion, the mean and SD of the z-scores, the largest |z| and the
smallest power margin (>= 6 needed). Names: coarse-<COARSE key>,
paper-<PAPER_SCALE key>, balance.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # this checkout's randvib

import test_coupling as t  # noqa: E402
from _stats import calibrate  # noqa: E402

CASES = {
    **{f"coarse-{n}": (lambda s, n=n: t.case_coarse(n, s)) for n in t.COARSE},
    **{f"paper-{n}": (lambda s, n=n: t.case_paper_scale(n, s)) for n in t.PAPER_SCALE},
    "balance": t.case_energy_balance,
}

if __name__ == "__main__":
    n_seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    names = sys.argv[2:] or list(CASES)
    for name in names:
        calibrate(name, CASES[name], range(1000, 1000 + n_seeds))
