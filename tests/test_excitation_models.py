"""The excitation family (randvib.models.excitation): spectra, filters, synthesis, Welch.

Statistical checks use ``_stats.assert_matches`` on estimates whose standard
error comes from independent paths (fixed seeds): 4 sigma thresholds, each
test powered for the bias it names.
"""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from _stats import assert_matches
from scipy import integrate, signal

from randvib.models.excitation import (
    EXCITATIONS,
    BandLimited,
    BandPass,
    KanaiTajimi,
    Measured,
    Tabulated,
    White,
    as_excitation,
    welch_segment_length,
)
from randvib.models.record import Record

RATIONAL = [
    White(0.7),
    BandPass(1.0, 8.0, 0.1),
    BandPass(2.0, 3.0, 0.5),
    BandPass(0.5, 20.0, 0.02),
    KanaiTajimi(1.0, 8.0, 0.3),
    KanaiTajimi(0.3, 2.0, 0.05),
]
FREQUENCIES = np.concatenate([[0.0], np.geomspace(1e-3, 1e3, 2001)])


def over_paths(values):
    """Mean over independent paths with its standard error."""
    values = np.asarray(values, dtype=float)
    return SimpleNamespace(mean=values.mean(), std_error=values.std(ddof=1) / np.sqrt(values.size))


@pytest.mark.parametrize("excitation", RATIONAL, ids=lambda e: repr(e))
def test_psd_is_the_shaping_filters_gain(excitation):
    shaping = excitation.shaping_filter()
    expected = excitation.psd(FREQUENCIES)
    np.testing.assert_allclose(shaping.psd(FREQUENCIES), expected, rtol=1e-12, atol=1e-300)
    assert shaping.noise_psd == excitation.level


@pytest.mark.parametrize("excitation", RATIONAL[1:], ids=lambda e: repr(e))
def test_variance_is_the_integral_of_the_psd(excitation):
    f0 = excitation.f0
    pieces = [(0, f0), (f0, 10 * f0), (10 * f0, np.inf)]
    total = sum(
        integrate.quad(excitation.psd, a, b, epsabs=0, epsrel=1e-12, limit=500)[0]
        for a, b in pieces
    )
    assert excitation.variance == pytest.approx(total, rel=1e-9)


def test_formulas_as_written_in_the_issue():
    f = np.array([0.0, 1.0, 8.0, 20.0])
    s, f0, z = 1.3, 8.0, 0.2
    d = (f0**2 - f**2) ** 2 + (2 * z * f * f0) ** 2
    np.testing.assert_allclose(BandPass(s, f0, z).psd(f), s * (2 * z * f * f0) ** 2 / d, rtol=1e-15)
    np.testing.assert_allclose(
        KanaiTajimi(s, f0, z).psd(f), s * (f0**4 + (2 * z * f * f0) ** 2) / d, rtol=1e-15
    )
    assert BandPass(s, f0, z).psd(f0) == pytest.approx(s)  # peak S at f0
    half = BandPass(s, f0, z).psd(f0 * (np.sqrt(1 + z**2) + np.array([-z, z])))
    np.testing.assert_allclose(half, s / 2, rtol=1e-12)  # half power 2 zeta f0 apart
    assert KanaiTajimi(s, f0, z).psd(0.0) == s
    np.testing.assert_array_equal(
        BandLimited(s, 4.0, 20.0).psd([3.9, 4.0, 12.0, 20.0, 20.1]), [0, s, s, s, 0]
    )


def test_white_and_limits():
    white = White(0.5)
    assert white.is_white and white.variance == np.inf
    assert not BandPass(0.5, 8.0, 10.0).is_white  # a wide band-pass still vanishes at f = 0
    assert BandPass(0.5, 8.0, 10.0).psd(0.0) == 0.0
    # Kanai-Tajimi tends to white noise of level S as f0 grows
    f = np.linspace(0, 50, 11)
    np.testing.assert_allclose(KanaiTajimi(0.5, 1e6, 0.3).psd(f), 0.5, rtol=1e-8)
    assert as_excitation(0.5).psd(3.0) == 0.5 and as_excitation(white) is white
    assert set(EXCITATIONS) >= {"white", "band-pass", "kanai-tajimi", "band-limited"}


def test_tabulated_interpolates_and_integrates_exactly():
    table = Tabulated([1.0, 2.0, 10.0, 15.0, 30.0], [0.0, 1.0, 3.0, 0.5, 0.0])
    np.testing.assert_allclose(table.psd([0.5, 1.5, 6.0, 12.5, 31.0]), [0, 0.5, 2.0, 1.75, 0])
    assert table.variance == pytest.approx(0.5 + 16.0 + 8.75 + 3.75, rel=1e-15)
    assert table.support == (1.0, 30.0)


def test_synthesised_band_limited_variance_and_psd():
    # 100 paths of 100 s: 1601 bins in the band per path, so a path's mean
    # square has relative sd 1/sqrt(1601) and the mean over paths 0.25 %:
    # powered for 2 %. The bins' grid adds S/T = 0.06 % (trapezoid rule).
    ex = BandLimited(0.5, 4.0, 20.0)
    x = ex.sample(100.0, 0.01, 100, seed=3)
    assert x.shape == (100, 10000)
    assert_matches(over_paths(np.mean(x**2, axis=1)), ex.variance, detect=0.02, what="variance")
    f, p = signal.welch(x, fs=100.0, nperseg=1000)
    inside = (f > 5) & (f < 19)
    assert_matches(over_paths(p[:, inside].mean(axis=1)), 0.5, detect=0.02, what="in-band PSD")
    outside = (f < 3) | (f > 21)  # one Hz from the edges: Hann leakage only
    assert p[:, outside].mean(axis=0).max() < 1e-3 * 0.5


def test_synthesised_tabulated_variance_and_psd():
    table = Tabulated([0.0, 2.0, 10.0, 15.0, 30.0], [0.0, 1.0, 3.0, 0.5, 0.0])
    x = table.sample(100.0, 0.01, 100, seed=4)
    assert_matches(over_paths(np.mean(x**2, axis=1)), table.variance, detect=0.02, what="variance")
    f, p = signal.welch(x, fs=100.0, nperseg=1000)
    for lo, hi in ((3.0, 9.0), (11.0, 14.0), (16.0, 29.0)):  # away from the kinks
        band = (f >= lo) & (f <= hi)
        truth = table.psd(f[band]).mean()  # the window's smoothing is unbiased on a line
        assert_matches(
            over_paths(p[:, band].mean(axis=1)), truth, detect=0.05, what=f"{lo}-{hi} Hz"
        )


def test_synthesis_is_seeded_and_gaussian():
    ex = BandLimited(1.0, 4.0, 20.0)
    a = ex.sample(100.0, 0.01, 4, seed=7)
    np.testing.assert_array_equal(a, ex.sample(100.0, 0.01, 4, seed=7))
    kurtosis = np.mean(a**4) / np.mean(a**2) ** 2
    assert abs(kurtosis - 3) < 4 * np.sqrt(24 / (4 * 1601))  # about 6400 independent bins


def test_measured_record_recovers_its_psd(tmp_path):
    table = Tabulated([0.0, 2.0, 10.0, 15.0, 30.0], [0.0, 1.0, 3.0, 0.5, 0.0])
    dt, n = 0.01, 200_000
    x = table.sample(n * dt, dt, 1, seed=5)[0]
    path = tmp_path / "record.csv"
    pd.DataFrame({"time": np.arange(n) * dt, "base_acceleration": x}).to_csv(path, index=False)
    measured = Measured.from_csv(path)
    np.testing.assert_allclose(measured.acceleration, x, rtol=1e-15)  # the record is kept
    assert measured.dt == pytest.approx(dt)
    assert measured.segment_length == welch_segment_length(n) == 16384
    k = measured.n_segments
    assert k == 23
    for lo, hi in ((3.0, 9.0), (11.0, 14.0), (16.0, 29.0)):
        f = measured.spectrum.frequency
        band = (f >= lo) & (f <= hi)
        # Each Welch value has relative variance (1 + 2 rho^2)/K, rho = 1/6 for Hann at 50 %
        # overlap; a band of B bins holds about B/1.5 independent ones (Hann's noise bandwidth).
        rel_se = np.sqrt((1 + 2 / 36) / k / (band.sum() / 1.5))
        truth = table.psd(f[band]).mean()
        assert abs(measured.spectrum.density[band].mean() / truth - 1) < 4 * rel_se
    assert measured.variance == pytest.approx(table.variance, rel=0.05)


ERRORS = [
    (lambda: BandPass(1.0, 0.0, 0.1), r"`f0` must be > 0.*got 0\.0"),
    (lambda: KanaiTajimi(1.0, -2.0, 0.1), r"`f0` must be > 0.*got -2\.0"),
    (lambda: BandPass(1.0, 8.0, 0.0), r"`zeta` must be > 0, got 0\.0"),
    (lambda: KanaiTajimi(1.0, 8.0, -0.1), r"`zeta` must be > 0"),
    (lambda: White(-1.0), r"`level` must be > 0"),
    (lambda: as_excitation(0.0), r"`psd` must be > 0"),
    (lambda: BandLimited(1.0, 20.0, 4.0), r"`f_hi` must be > `f_lo` = 20\.0 Hz, got 4\.0 Hz"),
    (lambda: BandLimited(1.0, 5.0, 5.0), r"`f_hi` must be > `f_lo`"),
    (lambda: BandLimited(1.0, -1.0, 5.0), r"`f_lo` must be >= 0"),
    (lambda: Tabulated([0, 1, 2], [1, -1, 1]), r"`psd` must be >= 0.*got .*-1\.0"),
    (lambda: Tabulated([0, 2, 1], [1, 1, 1]), r"`frequency` must be strictly increasing"),
    (lambda: Tabulated([0, 1, 1], [1, 1, 1]), r"`frequency` must be strictly increasing"),
    (lambda: Tabulated([0, 1], [0, 0]), r"`psd` must be > 0 somewhere"),
    (lambda: Tabulated([0, 1, 2], [1, np.nan, 1]), r"`psd` must be finite"),
    (
        lambda: Record(time=np.arange(100) * 0.01, base_acceleration=np.r_[np.zeros(99), np.nan]),
        r"`base_acceleration` must be finite: 1 NaN",
    ),
    (
        lambda: Record(
            time=np.r_[np.arange(50), np.arange(50) + 50.5] * 0.01, base_acceleration=np.zeros(100)
        ),
        r"`time` must be evenly spaced",
    ),
    (
        lambda: Measured(Record(time=np.arange(10) * 0.01, base_acceleration=np.zeros(10))),
        r"at least 64 samples",
    ),
    (lambda: Measured(Record(0.01, force=np.zeros(100))), r"no base_acceleration channel"),
    (lambda: BandLimited(1.0, 4.0, 20.0).sample(10.0, 0.05), r"`dt` = 0\.05 s resolves"),
    (lambda: BandLimited(1.0, 4.0, 20.0).sample(-1.0, 0.01), r"`duration` must be > 0"),
]


@pytest.mark.parametrize("make, message", ERRORS, ids=[m for _, m in ERRORS])
def test_validation_names_the_argument(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_csv_columns_are_checked(tmp_path):
    path = tmp_path / "table.csv"
    pd.DataFrame({"frequency": [0.0, 1.0], "S": [1.0, 1.0]}).to_csv(path, index=False)
    with pytest.raises(ValueError, match=r"must have the columns frequency, psd; missing psd"):
        Tabulated.from_csv(path)
    pd.DataFrame({"frequency": [0.0, 1.0, 3.0], "psd": [1.0, 2.0, 0.0]}).to_csv(path, index=False)
    assert Tabulated.from_csv(path).variance == pytest.approx(1.5 + 2.0)


@pytest.mark.parametrize("excitation", [White(1.0), BandPass(1.0, 8.0, 0.1)], ids=repr)
def test_rational_spectra_are_not_synthesised(excitation):
    with pytest.raises(NotImplementedError, match="shaping filter"):
        excitation.sample(10.0, 0.01)
