"""Seed calibration of test_friction_family's Monte Carlo energy identity (run by hand).

python tests/calibration/friction_family.py [n_seeds]
"""

import sys
from pathlib import Path

import numpy as np

sys.path[:0] = [str(Path(__file__).resolve().parents[i]) for i in (2, 1)]  # this checkout
from _stats import z_score  # noqa: E402
from test_friction_family import energy_identity  # noqa: E402

n = int(sys.argv[1]) if len(sys.argv) > 1 else 40
zs, rel_se = [], []
for seed in range(100, 100 + n):
    _, balance, reference = energy_identity(seed)
    zs.append(z_score(balance, reference))
    rel_se.append(balance.std_error / reference)
zs = np.array(zs)
print(
    f"seeds {n}: z mean {zs.mean():+.2f}, sd {zs.std(ddof=1):.2f}, max |z| {np.abs(zs).max():.2f}"
)
print(f"relative standard error {np.mean(rel_se):.2e}")
