"""Band-limited base motion: band_limited_excitation (randvib.models.excitation), a Record."""

import numpy as np
import pytest

from randvib.models.excitation import band_limited_excitation


def test_rms_and_band():
    ex = band_limited_excitation(20.0, 1000.0, 1.07, seed=0)
    assert np.sqrt(np.mean(ex["base_acceleration"] ** 2)) == pytest.approx(1.07, rel=1e-12)
    spec = np.abs(np.fft.rfft(ex["base_acceleration"])) ** 2
    f = np.fft.rfftfreq(ex["base_acceleration"].size, 1e-3)
    outside = (f < 4.0) | (f > 20.0)
    assert spec[outside].sum() < 1e-20 * spec.sum()


def test_flat_psd_in_band():
    # Averaged periodogram over the band: each bin's power is chi^2(2)/2-distributed,
    # so the mean of the lower and upper half of the band agree within ~4/sqrt(bins).
    ex = band_limited_excitation(200.0, 200.0, 1.0, seed=1)
    spec = np.abs(np.fft.rfft(ex["base_acceleration"])) ** 2
    f = np.fft.rfftfreq(ex["base_acceleration"].size, 1 / 200.0)
    low = spec[(f >= 4) & (f < 12)].mean()
    high = spec[(f >= 12) & (f <= 20)].mean()
    assert abs(low / high - 1) < 4 / np.sqrt(1600)


def test_displacement_and_velocity_are_integrals():
    ex = band_limited_excitation(10.0, 2000.0, 1.0, seed=2)
    dt = ex.dt
    acc_from_v = np.gradient(ex["base_velocity"], dt)
    vel_from_y = np.gradient(ex["base_displacement"], dt)
    # central differences: relative error (omega dt)^2 / 6 at 20 Hz
    tol = (2 * np.pi * 20 * dt) ** 2 / 6 * 3
    inner = slice(1, -1)
    assert np.max(np.abs(acc_from_v - ex["base_acceleration"])[inner]) < tol * np.max(
        np.abs(ex["base_acceleration"])
    )
    assert np.max(np.abs(vel_from_y - ex["base_velocity"])[inner]) < tol * np.max(
        np.abs(ex["base_velocity"])
    )
    assert abs(ex["base_displacement"].mean()) < 1e-12


def test_gaussian_and_seeded():
    a = band_limited_excitation(100.0, 200.0, 1.0, seed=7)["base_acceleration"]
    b = band_limited_excitation(100.0, 200.0, 1.0, seed=7)["base_acceleration"]
    np.testing.assert_array_equal(a, b)
    kurtosis = np.mean(a**4) / np.mean(a**2) ** 2
    # about 1600 independent frequency bins: kurtosis 3 within a few 1/sqrt(n)
    assert abs(kurtosis - 3) < 0.4
    frame = band_limited_excitation(1.0, 100.0, 1.0, seed=7).to_frame()
    assert list(frame.columns) == [
        "time",
        "base_acceleration",
        "base_velocity",
        "base_displacement",
    ]


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(rms=0.0), "`rms` must be > 0"),
        (dict(f_lo=20.0, f_hi=4.0), "`f_hi` must be > `f_lo`"),
        (dict(fs=30.0), "Nyquist"),
        (dict(duration=0.001), "number of samples"),
        (dict(duration=0.05, fs=1000.0, f_lo=4.0, f_hi=5.0), "no frequency bin"),
    ],
)
def test_bad_arguments(kwargs, match):
    args = dict(duration=10.0, fs=1000.0, rms=1.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        band_limited_excitation(**args)
