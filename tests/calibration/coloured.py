"""Seed calibration of the Monte Carlo assertions in tests/test_simulation_coloured.py.

Run by hand (not collected by pytest), from the repository root:

    NUMBA_NUM_THREADS=1 python tests/calibration/coloured.py [n_seeds] [--first=SEED] [name ...]

For every exact comparison (``case_*`` in the test module: the coarse-step
cases against the scheme's discrete Lyapunov covariance, the fine-step cases
against the continuous one) it reruns the statistic over seeds 1000, 1001, ...
and prints, per assertion, the number of seeds, the mean and standard
deviation of the z-scores and the largest |z| (calibrated: mean near 0, SD
near 1, no |z| above 4), plus the smallest power margin (detect * |reference|
/ standard error, which must be >= 6). Names: the keys of COARSE (coarse-...)
and FINE (fine-...) in the test module. Last results of the fine-step cases (with
their control variates): tests/calibration/coloured.txt.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # this checkout's randvib

import test_simulation_coloured as t  # noqa: E402
from _stats import calibrate as _calibrate  # noqa: E402

CASES = {
    **{
        f"coarse-{name}": (lambda s, a=args: t.case_coarse_discrete(*a, s))
        for name, args in t.COARSE.items()
    },
    **{
        f"fine-{name}": (lambda s, a=args: t.case_fine_continuous(*a, s))
        for name, args in t.FINE.items()
    },
}


def calibrate(name, case, seeds):
    return _calibrate(name, case, seeds, widths=(24, 10))


def main():
    args = sys.argv[1:]
    first = 1000
    for arg in [a for a in args if a.startswith("--first=")]:
        first = int(arg.split("=", 1)[1])
        args.remove(arg)
    n = int(args[0]) if args else 40
    only = args[1:] or None
    for name, case in CASES.items():
        if only and name not in only:
            continue
        calibrate(name, case, range(first, first + n))


if __name__ == "__main__":
    main()
