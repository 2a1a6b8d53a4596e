"""Coverage of the identification's 95 % intervals (run by hand, not by pytest).

    NUMBA_NUM_THREADS=1 python tests/calibration/interval_coverage.py [n_noise_seeds] [excitation_seed ...]

For tests/test_measurement_model.py::test_intervals_have_the_spread_of_the_estimates:
the share of noise seeds whose interval holds the true value, per parameter,
with its exact binomial 99 % acceptance region, on one or more excitations
(default 400 seeds on the test's excitation 11), the z-scores' mean and SD
((theta_hat - theta) / se: 0 and 1 when the intervals are right), and the
suite's statistic: the squared distance of the estimate from the truth in its
own covariance (chi-square(4) per seed), its mean, and how many blocks of the
test's ``SPREAD_SEEDS`` consecutive seeds put the block's sum outside the
test's chi-square 99 % region. Last results: interval_coverage.txt beside this.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import test_measurement_model as T  # noqa: E402


def study(n, excitation_seed):
    z = {name: [] for name in T.FREE}
    distances = []
    for s in range(n):
        res = T.polish_from_truth(T._noisy(excitation_seed, s))
        for name in T.FREE:
            z[name].append((res.parameters[name] - T.TRUTH[name]) / res.standard_errors[name])
        distances.append(T.squared_distance(res))
    lo, hi = T.binomial_region(n)
    print(f"excitation {excitation_seed}, {n} noise seeds; 99 % region of the count: [{lo}, {hi}]")
    for name, values in z.items():
        values = np.array(values)
        inside = int(np.sum(np.abs(values) <= 1.96))  # the t quantile at ~1000 dof
        print(
            f"  {name:>3}: covered {inside}/{n} ({100 * inside / n:.1f} %), "
            f"z mean {values.mean():+.3f}, SD {values.std(ddof=1):.3f}"
        )
    distances = np.array(distances)
    block = T.SPREAD_SEEDS
    sums = distances[: n // block * block].reshape(-1, block).sum(axis=1)
    lo, hi = T.chi_square_region(len(T.FREE) * block)
    outside = int(np.sum((sums < lo) | (sums > hi)))
    print(
        f"  squared distance (chi-square({len(T.FREE)})): mean {distances.mean():.3f}, "
        f"SD {distances.std(ddof=1):.3f} (exact: {len(T.FREE)}, {np.sqrt(2 * len(T.FREE)):.3f})"
    )
    print(
        f"  sums over {len(sums)} blocks of {block} seeds: {outside} outside [{lo:.1f}, {hi:.1f}], "
        f"range {sums.min():.1f} .. {sums.max():.1f}; the test's block (seeds 0-{block - 1}): "
        f"{sums[0]:.1f}"
    )


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 400
    for seed in [int(a) for a in sys.argv[2:]] or [11]:
        study(n, seed)
