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
