"""Seed calibration of the record-length interval in tests/test_assembly_record.py.

Run by hand (not collected by pytest), from the repository root:

    NUMBA_NUM_THREADS=1 python tests/calibration/assembly_record.py [n_seeds]

Reruns ``case_two_dof`` (a linear two-DOF record's mean squares against the exact
variances, with the standard error of one synthesis period) over seeds 1000, 1001, ...
and prints, per column, the mean and SD of the z-scores (near 0 and 1 when the
interval is honest), the largest |z| and the smallest power margin (>= 6 needed).
Last results: tests/calibration/assembly_record.txt.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # this checkout's randvib

import test_assembly_record as t  # noqa: E402
from _stats import calibrate  # noqa: E402

if __name__ == "__main__":
    n_seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 40
    calibrate("two-dof", t.case_two_dof, range(1000, 1000 + n_seeds), widths=(8, 30))
