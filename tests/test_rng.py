"""Per-path random streams: distribution, independence, reproducibility."""

import numpy as np
import pytest
from scipy import stats

from randvib.rng import path_normals


def test_normals_are_standard_normal():
    x = path_normals(seed=12, n_paths=64, n_per_path=20_000).ravel()
    n = x.size
    # moments within 4 standard errors (fixed seed; exact SEs of the sample moments)
    assert abs(x.mean()) < 4 / np.sqrt(n)
    assert abs(x.var() - 1) < 4 * np.sqrt(2 / n)
    assert abs(stats.skew(x)) < 4 * np.sqrt(6 / n)
    assert abs(stats.kurtosis(x)) < 4 * np.sqrt(24 / n)
    assert stats.kstest(x, "norm").pvalue > 1e-3
    # the ziggurat's tail (beyond r = 3.654) has the right mass
    tail = np.mean(np.abs(x) > 3.6541528853610088)
    expected = 2 * stats.norm.sf(3.6541528853610088)
    assert abs(tail - expected) < 4 * np.sqrt(expected / n)


def test_streams_are_uncorrelated_across_paths_and_lags():
    x = path_normals(seed=3, n_paths=200, n_per_path=5_000)
    corr = np.corrcoef(x)
    off = corr[~np.eye(200, dtype=bool)]
    assert np.max(np.abs(off)) < 5 / np.sqrt(5_000)
    lag1 = np.mean(x[:, 1:] * x[:, :-1])
    assert abs(lag1) < 4 / np.sqrt(x[:, 1:].size)


def test_reproducible_and_indexed_by_path():
    a = path_normals(seed=9, n_paths=6, n_per_path=50)
    assert np.array_equal(a, path_normals(seed=9, n_paths=6, n_per_path=50))
    assert np.array_equal(a[4:], path_normals(seed=9, n_paths=2, n_per_path=50, first_path=4))
    assert not np.array_equal(a, path_normals(seed=10, n_paths=6, n_per_path=50))


@pytest.mark.parametrize("seed", [0, 1, 2**63])
def test_extreme_seeds(seed):
    assert np.all(np.isfinite(path_normals(seed=seed, n_paths=2, n_per_path=10)))
