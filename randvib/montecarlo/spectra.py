"""Response spectra from Monte Carlo: Welch's method on the recorded paths.

Where does the power come from, and how does the spring detune the device?
:func:`response_spectra` estimates the one-sided PSDs of z and v and the
electrical power's frequency distribution c_e S_v(f) (W/Hz, its integral is
E[P_e], paper Eq. 31) from the paths a simulation recorded
(``simulate(..., record_paths=N)``), to set beside the linearisation's
(:meth:`randvib.LinearisationResult.response_spectra`). Under tones each
tone's line is measured by projection on it (:func:`line_mean_squares`):
its mean square, beside the combined linearisation's
(:meth:`randvib.CombinedLinearisation.response_spectra`).

Each recorded path's averaging window (after the burn-in) gives one Welch
estimate (Hann window, 50 % overlap, no detrending: the response has zero
mean); the spectrum is their mean over paths and its 95 % interval Student's
t over the paths, which are independent. The expected value of the estimate
is the true PSD smoothed by the Hann window's kernel (resolution about
2 / segment duration), which matters near a sharp resonance; the tests
compare it with that smoothed exact spectrum.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from randvib._validation import check_positive
from randvib.models.excitation import welch_segment_length
from randvib.statistics import mean_and_half_width


@dataclass(frozen=True, eq=False)
class SampledSpectra:
    """Monte Carlo response spectra with their 95 % half-widths (SI units, f in Hz).

    Attributes
    ----------
    frequency : ndarray
        f (Hz).
    displacement, velocity : ndarray
        PSD of z (m^2/Hz) and of v ((m/s)^2/Hz), mean over paths.
    power : ndarray
        c_e S_v(f) (W/Hz): the frequency distribution of E[P_e].
    displacement_ci95, velocity_ci95, power_ci95 : ndarray
        Half-widths of their 95 % intervals (Student t over paths).
    n_paths : int
        Recorded paths behind the estimate.
    segment_duration : float
        Welch segment length (s); the resolution is about twice its inverse.
    lines : dict or None
        Under tones, each tone's line: ``frequency`` (Hz) and the mean squares
        of the response at it, ``displacement`` (m^2), ``velocity``
        ((m/s)^2), ``power`` (c_e times the velocity's, W), with ``*_ci95``
        half-widths over paths (:func:`line_mean_squares`). None without tones.
    """

    frequency: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    power: np.ndarray
    displacement_ci95: np.ndarray
    velocity_ci95: np.ndarray
    power_ci95: np.ndarray
    n_paths: int
    segment_duration: float
    lines: dict | None = None

    def __repr__(self) -> str:  # the grid and the evidence, not the arrays
        peak = float(self.frequency[int(np.argmax(self.power))]) if self.power.size else np.nan
        return (
            f"SampledSpectra({self.frequency.size} frequencies, 0-{self.frequency[-1]:g} Hz, "
            f"{self.n_paths} paths, segments of {self.segment_duration:g} s; "
            f"power density peaks at {peak:g} Hz)"
        )

    def to_frame(self):
        """The spectra as a :class:`pandas.DataFrame`, one row per frequency."""
        import pandas as pd

        names = ("frequency", "displacement", "velocity", "power")
        names += ("displacement_ci95", "velocity_ci95", "power_ci95")
        return pd.DataFrame({name: getattr(self, name) for name in names})


def response_spectra(result, segment_duration: float | None = None) -> SampledSpectra:
    """Welch spectra of z, v and of the electrical power from a simulation's recorded paths.

    Parameters
    ----------
    result : SimulationResult
        From :func:`randvib.simulate` (or :func:`randvib.monte_carlo_on_record`)
        with ``record_paths >= 2``; ``record_every`` sets the sample step
        (keep its Nyquist frequency well above the response's band).
    segment_duration : float, optional
        Welch segment length (s); default the largest power of two of
        samples not above an eighth of the window
        (:func:`randvib.models.excitation.welch_segment_length`).

    Returns
    -------
    SampledSpectra

    Raises
    ------
    ValueError
        Without at least two recorded paths, or with a segment longer than
        the window.
    """
    histories = result.histories
    if histories is None or histories.z.shape[0] < 2:
        raise ValueError(
            "response spectra need recorded paths: simulate with record_paths >= 2 "
            "(each recorded path gives one Welch estimate; the interval is over paths)"
        )
    step = float(histories.time[1] - histories.time[0])
    start = int(np.ceil(result.burn_in / step - 1e-9))
    z = histories.z[:, start:]
    v = histories.v[:, start:]
    n = z.shape[1]
    if segment_duration is None:
        length = welch_segment_length(n)
    else:
        length = int(round(check_positive("segment_duration", segment_duration, "s") / step))
        if not 8 <= length <= n:
            raise ValueError(
                f"`segment_duration` must hold 8 to {n} samples of {step:g} s (the window), "
                f"got {segment_duration!r} s"
            )
    welch = dict(fs=1.0 / step, window="hann", nperseg=length, noverlap=length // 2)
    f, pz = signal.welch(z, detrend=False, **welch)
    _, pv = signal.welch(v, detrend=False, **welch)
    c_e = float(result.harvester.c_e)
    (sz, hz), (sv, hv) = mean_and_half_width(pz), mean_and_half_width(pv)
    tones = result.excitation.lines() if result.excitation is not None else ()
    lines = None
    if tones:
        frequencies = np.array([tone.frequency for tone in tones])
        lines = {"frequency": frequencies}
        for name, x in (("displacement", z), ("velocity", v)):
            lines[name], lines[f"{name}_ci95"] = mean_and_half_width(
                line_mean_squares(x, step, frequencies)
            )
        lines["power"], lines["power_ci95"] = c_e * lines["velocity"], c_e * lines["velocity_ci95"]
    return SampledSpectra(
        frequency=f,
        displacement=sz,
        velocity=sv,
        power=c_e * sv,
        displacement_ci95=hz,
        velocity_ci95=hv,
        power_ci95=c_e * hv,
        n_paths=z.shape[0],
        segment_duration=length * step,
        lines=lines,
    )


def line_mean_squares(x, step: float, frequencies) -> np.ndarray:
    """Each path's mean square at each frequency: |(2/T) sum x e^{-i w t} dt|^2 / 2.

    The amplitude of the sinusoid at f in a record of length T by projection
    (a lock-in estimate, at f itself rather than on a Welch bin), halved: the
    line's mean square. The random part adds about 2 S(f) / T, its power in
    the projection's bandwidth 1/T, which a long window makes small.

    Parameters
    ----------
    x : ndarray, shape (n_paths, n)
        Samples every ``step`` seconds.
    frequencies : array_like
        Line frequencies (Hz).

    Returns
    -------
    ndarray, shape (n_paths, n_lines)
    """
    x = np.asarray(x, dtype=float)
    t = np.arange(x.shape[1]) * step
    phasors = np.exp(-2j * np.pi * np.outer(t, np.asarray(frequencies, dtype=float)))
    amplitude = 2.0 * (x - x.mean(axis=1, keepdims=True)) @ phasors / x.shape[1]
    return 0.5 * np.abs(amplitude) ** 2
