"""The shipped Silverbox record (randvib.datasets): present, complete and split as documented."""

import numpy as np
import pytest

from randvib import datasets


def test_silverbox_is_shipped_inside_the_package():
    path = datasets.silverbox_path()
    assert path.is_file()
    assert "randvib" in path.parts  # not read from outside the project


def test_silverbox_parts_have_the_documented_lengths_and_sampling():
    arrow, multisine = datasets.silverbox("arrow-head"), datasets.silverbox("multisine")
    assert arrow.z.size == 40_700
    assert arrow.z.size + multisine.z.size == 131_072
    assert arrow.dt == pytest.approx(2**14 / 1e7, rel=1e-12)
    # the arrow-head reaches larger output amplitudes than the multisines
    assert np.max(np.abs(arrow.z)) > np.max(np.abs(multisine.z))


def test_unknown_part_is_refused_by_name():
    with pytest.raises(ValueError, match="part must be one of"):
        datasets.silverbox("training")


def test_silverbox_split_is_the_benchmark_loaders():
    """The indices of nonlinear_benchmarks.Silverbox(): arrow-head data[100:40575] and its first
    32,000 samples; multisines data[40650:127400], their first int(0.75 n) samples training."""
    assert datasets.SILVERBOX_SPLIT == {
        "multisine train": (40_650, 40_650 + 65_062),
        "multisine test": (105_712, 127_400),
        "arrow-head full": (100, 40_575),
        "arrow-head no extrapolation": (100, 32_100),
    }
    assert 65_062 == int(0.75 * (127_400 - 40_650))
    assert datasets.SILVERBOX_INITIALISATION == 50
    split = datasets.silverbox_split()
    arrow, multisine = datasets.silverbox("arrow-head"), datasets.silverbox("multisine")
    whole_u = np.concatenate([arrow.input, multisine.input])
    whole_z = np.concatenate([arrow.z, multisine.z])
    for name, (start, stop) in datasets.SILVERBOX_SPLIT.items():
        assert split[name].name == name
        np.testing.assert_array_equal(split[name].input, whole_u[start:stop])
        np.testing.assert_array_equal(split[name].z, whole_z[start:stop])
    # training and tests do not overlap
    assert (
        datasets.SILVERBOX_SPLIT["multisine train"][1]
        <= datasets.SILVERBOX_SPLIT["multisine test"][0]
    )
    assert (
        datasets.SILVERBOX_SPLIT["arrow-head full"][1]
        <= datasets.SILVERBOX_SPLIT["multisine train"][0]
    )
