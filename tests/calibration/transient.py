"""Seed calibration of the Monte Carlo assertions in tests/test_transient_simulation.py.

Run by hand (not collected by pytest), from the repository root:

    NUMBA_NUM_THREADS=1 python tests/calibration/transient.py [n_seeds] [--first=SEED] [name ...]

For every event of ``CASES`` in the test module (``case_transient``: the
ensemble's E[z^2], E[v^2] at the report times and the event's energy against
the Lyapunov solution, the scheme's exact bias removed) it reruns the
statistics over seeds 1000, 1001, ... and prints, per assertion, the mean and
standard deviation of the z-scores and the largest |z| (calibrated: mean near
0, SD near 1, no |z| above 4), and the smallest power margin (>= 6).
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # this checkout's randvib

import test_transient_simulation as t  # noqa: E402
from _stats import calibrate, seeds_and_names  # noqa: E402


def main():
    seeds, only = seeds_and_names(sys.argv[1:])
    for name in t.CASES:
        if only is None or name in only:
            calibrate(name, lambda s, name=name: t.case_transient(name, s), seeds, widths=(26, 16))


if __name__ == "__main__":
    main()
