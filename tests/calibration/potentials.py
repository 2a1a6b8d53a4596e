"""Seed calibration of the Monte Carlo assertions in tests/test_potentials.py.

Run by hand (not collected by pytest), from the repository root:

    NUMBA_NUM_THREADS=1 python tests/calibration/potentials.py [n_seeds] [name ...]

Reruns each ``case_*`` of the test module over seeds 1000, 1001, ... and
prints, per assertion, the mean, standard deviation and largest |z| of the
z-scores (calibrated: mean near 0, SD near 1, no |z| above 4) and the
smallest power margin (>= 6). Names: gibbs, cubic, friction, free.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # this checkout's randvib

import test_potentials as t  # noqa: E402
from _stats import calibrate  # noqa: E402

CASES = {
    "gibbs": t.case_double_well_gibbs,
    "cubic": t.case_pure_cubic,
    "friction": t.case_double_well_friction,
    "free": t.case_free_mass,
}


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 40
    only = sys.argv[2:] or None
    for name, case in CASES.items():
        if not only or name in only:
            calibrate(name, case, range(1000, 1000 + n), widths=(10, 10))


if __name__ == "__main__":
    main()
