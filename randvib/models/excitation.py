"""Band-limited Gaussian base excitation for synthetic shaker campaigns.

The paper's experiments (Sec. 3) drove the shaker under displacement control
so that the base *acceleration* had a flat power spectral density between
4 and 20 Hz; the model was then driven by the recorded *displacement*. This
module makes both signals from one realisation: a Gaussian acceleration with
a flat one-sided PSD on ``[f_lo, f_hi]`` and the displacement (and velocity)
a shaker table would follow to produce it.

The signal is synthesised in the frequency domain (white Gaussian noise,
band-pass by zeroing FFT bins), so it is exactly band-limited and periodic
with the record length; displacement and velocity are its exact spectral
integrals ``Y = -A / omega^2``, ``V = A / (i omega)``, which exist because
the band excludes zero frequency.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from randvib._validation import check_int, check_positive


@dataclass(frozen=True, eq=False)
class BaseExcitation:
    """One realisation of band-limited base motion on a uniform grid.

    Attributes
    ----------
    time : ndarray
        Sample times (s), starting at 0.
    acceleration, velocity, displacement : ndarray
        Base acceleration y'' (m/s^2), velocity y' (m/s) and displacement y (m).
    fs : float
        Sample rate (Hz).
    f_lo, f_hi : float
        Band edges (Hz).
    rms : float
        RMS of the acceleration (m/s^2), exact for this realisation.
    """

    time: np.ndarray
    acceleration: np.ndarray
    velocity: np.ndarray
    displacement: np.ndarray
    fs: float
    f_lo: float
    f_hi: float
    rms: float

    @property
    def psd(self) -> float:
        """Nominal one-sided PSD height S = rms^2 / (f_hi - f_lo) ((m/s^2)^2/Hz)."""
        return self.rms**2 / (self.f_hi - self.f_lo)

    def to_frame(self):
        """The signals as a :class:`pandas.DataFrame` with CSV-ready column names."""
        import pandas as pd

        return pd.DataFrame(
            {
                "time": self.time,
                "base_acceleration": self.acceleration,
                "base_velocity": self.velocity,
                "base_displacement": self.displacement,
            }
        )


def band_limited_excitation(
    duration: float,
    fs: float,
    rms: float,
    f_lo: float = 4.0,
    f_hi: float = 20.0,
    *,
    seed=None,
) -> BaseExcitation:
    """Gaussian base acceleration with a flat one-sided PSD between two frequencies.

    Parameters
    ----------
    duration : float
        Record length (s), > 0; at least a few periods of ``f_lo``.
    fs : float
        Sample rate (Hz), > 2 ``f_hi``.
    rms : float
        RMS base acceleration (m/s^2), > 0 (paper Table 1: 1.07, 1.21, ...).
    f_lo, f_hi : float, optional
        Band edges (Hz); the paper uses 4 and 20 Hz.
    seed : int, numpy.random.Generator or None
        Random source (never the global numpy state).

    Returns
    -------
    BaseExcitation
        Acceleration scaled to exactly ``rms``, with the velocity and
        displacement a shaker would follow (exact spectral integrals; the
        record is periodic, so the motion has no drift).

    Raises
    ------
    ValueError
        If an argument is out of range or the band holds no frequency bin.
    """
    duration = float(check_positive("duration", duration, "s"))
    fs = float(check_positive("fs", fs, "Hz"))
    rms = float(check_positive("rms", rms, "m/s^2"))
    f_lo = float(check_positive("f_lo", f_lo, "Hz"))
    f_hi = float(check_positive("f_hi", f_hi, "Hz"))
    if f_hi <= f_lo:
        raise ValueError(f"`f_hi` must be > `f_lo` = {f_lo} Hz, got {f_hi} Hz")
    if f_hi >= fs / 2:
        raise ValueError(
            f"`f_hi` must be below the Nyquist frequency fs/2 = {fs / 2} Hz, got {f_hi}"
        )
    n = check_int("number of samples (duration * fs)", round(duration * fs), minimum=8)
    rng = np.random.default_rng(seed)
    freqs = np.fft.rfftfreq(n, 1.0 / fs)
    band = (freqs >= f_lo) & (freqs <= f_hi)
    if not band.any():
        raise ValueError(
            f"no frequency bin of a {duration} s record lies in [{f_lo}, {f_hi}] Hz; "
            f"make `duration` longer than {1.0 / (f_hi - f_lo):.3g} s"
        )
    spectrum = np.fft.rfft(rng.standard_normal(n))
    spectrum[~band] = 0.0
    acc = np.fft.irfft(spectrum, n)
    scale = rms / np.sqrt(np.mean(acc**2))
    spectrum *= scale
    omega = 2 * np.pi * freqs
    safe = np.where(band, omega, 1.0)
    acceleration = np.fft.irfft(spectrum, n)
    velocity = np.fft.irfft(np.where(band, spectrum / (1j * safe), 0.0), n)
    displacement = np.fft.irfft(np.where(band, -spectrum / safe**2, 0.0), n)
    return BaseExcitation(
        time=np.arange(n) / fs,
        acceleration=acceleration,
        velocity=velocity,
        displacement=displacement,
        fs=fs,
        f_lo=f_lo,
        f_hi=f_hi,
        rms=rms,
    )
