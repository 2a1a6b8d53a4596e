"""Per-path random streams: distribution, independence, reproducibility.

Thresholds are 4 standard errors of each sample statistic (exact for the
moments of 1.28 million normals), or a Bonferroni bound for the maximum over
many path pairs; ``rng_z_scores`` computes them as a function of the seed so
that tests/calibration/simulation.py can check their spread over seeds.

Covers :mod:`randvib.montecarlo.rng`.
"""

import numpy as np
import pytest
from scipy import stats

from randvib.montecarlo.rng import path_normals

ZIG_R = 3.6541528853610088  # start of the ziggurat's tail
N_PAIRS_PATHS = 200
#: |correlation| * sqrt(n) threshold for the largest of the 19 900 path pairs:
#: Bonferroni at a family-wise false-failure rate of 1e-4 (about 5.8).
PAIR_THRESHOLD = float(stats.norm.isf(1e-4 / 2 / (N_PAIRS_PATHS * (N_PAIRS_PATHS - 1) / 2)))


def rng_z_scores(seed):
    """z-scores of the stream's moments, ziggurat tail mass and correlations."""
    x = path_normals(seed=seed, n_paths=64, n_per_path=20_000).ravel()
    n = x.size
    expected_tail = 2 * stats.norm.sf(ZIG_R)
    out = {
        "mean": x.mean() * np.sqrt(n),
        "variance": (x.var() - 1) / np.sqrt(2 / n),
        "skewness": stats.skew(x) / np.sqrt(6 / n),
        "excess kurtosis": stats.kurtosis(x) / np.sqrt(24 / n),
        "tail mass": (np.mean(np.abs(x) > ZIG_R) - expected_tail) / np.sqrt(expected_tail / n),
        "ks p-value": stats.kstest(x, "norm").pvalue,
    }
    y = path_normals(seed=seed + 1, n_paths=N_PAIRS_PATHS, n_per_path=5_000)
    corr = np.corrcoef(y)
    out["largest pair correlation"] = np.max(np.abs(corr[~np.eye(N_PAIRS_PATHS, dtype=bool)]))
    out["largest pair correlation"] *= np.sqrt(y.shape[1])
    out["lag-1"] = np.mean(y[:, 1:] * y[:, :-1]) * np.sqrt(y[:, 1:].size)
    return out


def test_normals_are_standard_normal_and_uncorrelated():
    """Moments, tail mass (ziggurat beyond r = 3.654), KS, cross-path and lag-1 correlation.

    Detects e.g. a 1 % error in the variance (8 standard errors at 1.28e6
    draws) or a 30 % error in the ziggurat's tail mass (330 expected draws).
    Calibration (tests/calibration/simulation.py, 200 seeds): z-scores mean /
    SD / largest |z|: mean -0.03 / 0.91 / 2.9, variance +0.04 / 1.09 / 2.7,
    skewness +0.14 / 1.01 / 2.5, excess kurtosis -0.00 / 1.00 / 3.6, tail mass
    +0.08 / 1.01 / 3.1, lag-1 +0.11 / 0.98 / 3.5; largest pair correlation x
    sqrt(n) 4.20 +- 0.30, at most 5.33 (threshold 5.8); KS p-values mean 0.505,
    SD 0.280 (uniform: 0.5, 0.289), smallest 6.3e-5 (one seed of 200 would
    fail the 1e-4 threshold: a 2 % chance for a correct generator).
    """
    z = rng_z_scores(seed=12)
    for name in ("mean", "variance", "skewness", "excess kurtosis", "tail mass", "lag-1"):
        assert abs(z[name]) < 4, (name, z[name])
    assert z["ks p-value"] > 1e-4  # false-failure rate 1e-4
    assert z["largest pair correlation"] < PAIR_THRESHOLD


def test_reproducible_and_indexed_by_path():
    a = path_normals(seed=9, n_paths=6, n_per_path=50)
    assert np.array_equal(a, path_normals(seed=9, n_paths=6, n_per_path=50))
    assert np.array_equal(a[4:], path_normals(seed=9, n_paths=2, n_per_path=50, first_path=4))
    assert not np.array_equal(a, path_normals(seed=10, n_paths=6, n_per_path=50))


@pytest.mark.parametrize("seed", [0, 1, 2**63])
def test_extreme_seeds(seed):
    assert np.all(np.isfinite(path_normals(seed=seed, n_paths=2, n_per_path=10)))
