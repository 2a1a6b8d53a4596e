"""Base excitation: the excitation family and synthetic shaker campaigns.

**The excitation family.** An excitation is one class, a frozen dataclass
subclassing :class:`Excitation`, that declares what every consumer needs
(docs/conventions.md, "Beyond the paper"):

* ``psd(f)`` - the one-sided PSD of the base acceleration,
  (m/s^2)^2/Hz, f in Hz; ``variance`` - its integral ((m/s^2)^2, infinite
  for white noise); ``is_white``;
* ``shaping_filter()`` - for rational spectra (white, band-pass,
  Kanai-Tajimi) a :class:`ShapingFilter`: a state-space block driven by the
  white noise of the conventions, E[w(t1) w(t2)] = (S/2) delta(t2 - t1),
  whose output has exactly this PSD; None for the others;
* ``sample(duration, dt, n_paths, seed)`` - for the non-rational ones
  (band-limited, tabulated, measured) a stationary Gaussian synthesis in the
  frequency domain (:func:`synthesise`; :func:`synthesised_increments` gives
  its exact step integrals, one generator per path, for Monte Carlo), each
  bin carrying the exact power of its cell (``cumulative_power``);
* ``support``, ``features`` and ``breakpoints`` - where the spectrum lives,
  its peaks and its kinks, so that a quadrature over frequency can resolve
  them (:mod:`randvib.analytic.linear_response`).

Defining a subclass with its own ``name`` registers it in
:data:`EXCITATIONS`. :func:`as_excitation` turns a plain number into white
noise, so a ``psd`` argument can take either.

**Synthetic shaker campaigns.** The paper's experiments (Sec. 3) drove the
shaker under displacement control so that the base *acceleration* had a flat
power spectral density between 4 and 20 Hz; the model was then driven by the
recorded *displacement*. :func:`band_limited_excitation` makes both signals
from one realisation, as a :class:`~randvib.models.record.Record` of the base
motion: a Gaussian acceleration with a flat one-sided PSD on
``[f_lo, f_hi]`` and the displacement (and velocity) a shaker table would
follow to produce it.

The signal is synthesised in the frequency domain (white Gaussian noise,
band-pass by zeroing FFT bins), so it is exactly band-limited and periodic
with the record length; displacement and velocity are its exact spectral
integrals ``Y = -A / omega^2``, ``V = A / (i omega)``, which exist because
the band excludes zero frequency.

**Measured records.** :class:`Measured` is the excitation of a measured base
acceleration: a :class:`~randvib.models.record.Record` with a
``base_acceleration`` channel and its Welch PSD.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from randvib._validation import (
    check_int,
    check_nonnegative,
    check_positive,
    check_scalar,
)
from randvib.models import composition
from randvib.models.record import Record, read_csv, read_record
from randvib.models.state_space import StateSpace
from randvib.models.tone import Tone
from randvib.quantities import unit


class BaseMotionOverflow(ValueError):
    """The base motion of an RMS beyond float64 (:func:`band_limited_excitation`, rms = 1e308)."""


def band_limited_excitation(
    duration: float,
    fs: float,
    rms: float,
    f_lo: float = 4.0,
    f_hi: float = 20.0,
    *,
    seed=None,
) -> Record:
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
    Record
        The base motion on the grid ``i / fs``: the channels
        ``base_acceleration`` (m/s^2), scaled to exactly ``rms``, and the
        ``base_velocity`` (m/s) and ``base_displacement`` (m) a shaker would
        follow (exact spectral integrals; the record is periodic, so the
        motion has no drift). The nominal one-sided PSD height is
        ``rms^2 / (f_hi - f_lo)``.

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
    if not all(np.all(np.isfinite(x)) for x in (acceleration, velocity, displacement)):
        raise BaseMotionOverflow(
            f"`rms` = {rms!r} m/s^2 overflows float64 in the base motion; lower it"
        )
    return Record(
        1.0 / fs,
        base_acceleration=acceleration,
        base_velocity=velocity,
        base_displacement=displacement,
        name=f"band-limited {f_lo:g}-{f_hi:g} Hz, {rms:g} m/s^2 RMS",
    )


# ====================================================== the excitation family
#: Name -> excitation class; filled by :class:`Excitation` subclasses.
EXCITATIONS: dict[str, type] = {}

_PSD_UNIT = unit("psd")

#: The functions that take an array of white-noise levels S (named in refusals).
BROADCASTING = "randvib.predict, randvib.expected_power and randvib.equivalent_damping"


@dataclass(frozen=True, eq=False)
class ShapingFilter:
    """A rational excitation as a linear filter of white noise.

    The filter's input ``w`` is the white noise of the conventions,
    E[w(t1) w(t2)] = (S/2) delta(t2 - t1) with ``S = noise_psd``, and its
    one output, ``acceleration``, has the one-sided PSD
    ``|H(i 2 pi f)|^2 S`` of the excitation.

    Attributes
    ----------
    system : StateSpace
        The filter (states in the order the excitation documents), input w,
        output ``acceleration`` ((m/s^2)).
    noise_psd : float
        One-sided PSD S of w ((m/s^2)^2/Hz).
    """

    system: StateSpace
    noise_psd: float

    @property
    def noise_intensity(self) -> float:
        """q = S/2: E[w(t1) w(t2)] = q delta(t2 - t1) ((m/s^2)^2 s)."""
        return 0.5 * self.noise_psd

    def psd(self, frequency) -> np.ndarray:
        """The output's one-sided PSD |H|^2 S ((m/s^2)^2/Hz) at ``frequency`` (Hz)."""
        return np.abs(self.system.frequency_response(frequency)[0]) ** 2 * self.noise_psd


class Excitation:
    """Base class of the excitations: the declaration every consumer reads.

    Subclasses are frozen dataclasses; one that sets ``name`` is registered
    in :data:`EXCITATIONS`. See the module docstring for what an excitation
    declares.
    """

    #: Short name used by the CLI and tables.
    name: str = "excitation"
    #: True for ideal white noise (the paper's model, which every analytic method
    #: accepts; each declares whether it accepts another, ``AnalyticMethod.coloured``).
    is_white: bool = False
    #: True for a stationary Gaussian process: its spectrum says everything about it.
    #: Translation processes, measured records, shock trains and tones are not
    #: (:mod:`randvib.models.translation`, :mod:`randvib.models.shock`, :mod:`randvib.models.combined`).
    is_gaussian: bool = True

    def __init_subclass__(cls, registered: bool = True, **kwargs):
        # ``registered=False``: a composite or a non-Gaussian process, built from
        # other objects rather than from numbers, is not an ``--excitation`` spectrum
        super().__init_subclass__(**kwargs)
        if registered and "name" in cls.__dict__:
            EXCITATIONS[cls.name] = cls

    @property
    def kurtosis(self) -> float:
        """E[a^4] / E[a^2]^2 of the base acceleration a: 3 for a Gaussian process."""
        return 3.0

    def lines(self) -> tuple:
        """The deterministic tones (:class:`~randvib.models.tone.Tone`) in the input; none here."""
        return ()

    def __add__(self, other):
        """The sum of independent inputs: ``BandPass(...) + Tone(25, 1) + ShockTrain(...)``.

        One random spectrum with any number of tones and at most one shock
        train (:class:`~randvib.models.combined.Combined`).
        """
        # the composite module builds on this one: reached through its registry
        return composition.combine(self, other)

    def __radd__(self, other):
        return composition.combine(other, self)

    def psd(self, frequency) -> np.ndarray:  # pragma: no cover - abstract
        """One-sided PSD of the base acceleration ((m/s^2)^2/Hz) at ``frequency`` (Hz)."""
        raise NotImplementedError

    @property
    def variance(self) -> float:  # pragma: no cover - abstract
        """E[y''^2] = int_0^inf S(f) df ((m/s^2)^2); infinite for white noise."""
        raise NotImplementedError

    @property
    def support(self) -> tuple[float, float]:
        """(lowest, highest) frequency (Hz) outside which the PSD is zero."""
        return 0.0, np.inf

    def features(self) -> tuple[tuple[float, float], ...]:
        """Spectral peaks as (centre, half-width) pairs (Hz), for quadrature."""
        return ()

    def breakpoints(self) -> tuple[float, ...]:
        """Frequencies (Hz) where the PSD has a jump or a kink, for quadrature."""
        return ()

    def shaping_filter(self) -> ShapingFilter | None:
        """The filter of white noise with this PSD (rational spectra), else None."""
        return None

    def cumulative_power(self, frequency) -> np.ndarray:
        """int_0^f S(f') df' ((m/s^2)^2) at ``frequency`` (Hz).

        The synthesis (:func:`synthesis_power`) gives each frequency bin the
        exact power of its cell, so a synthesised path's variance is the
        spectrum's integral below the Nyquist frequency for any record length.
        This default is the trapezoid rule on 2049 points up to each f;
        the non-rational spectra integrate exactly.
        """
        f = np.asarray(frequency, dtype=float)
        grid = np.linspace(0.0, 1.0, 2049)
        values = [np.trapezoid(self.psd(x * grid), x * grid) for x in f.ravel()]
        return np.reshape(values, f.shape)

    def sample(self, duration: float, dt: float, n_paths: int = 1, seed=None) -> np.ndarray:
        """Stationary Gaussian paths of the base acceleration (m/s^2), see :func:`synthesise`."""
        return synthesise(self, duration, dt, n_paths, seed)

    def scaled(self, factor: float) -> Excitation:
        """The same spectrum with its PSD multiplied by ``factor`` (> 0): the level times it."""
        factor = float(check_positive("factor", factor))
        return replace(self, level=self.level * factor)

    def parameters(self) -> dict:
        """The excitation's name and parameters (SI units), ready for JSON."""
        out = {"excitation": self.name}
        out.update({f.name: getattr(self, f.name) for f in fields(self)})
        return out


def _one(name: str, value):
    """An excitation's parameter is one number; an array is refused by name."""
    return check_scalar(name, value, "an excitation describes one spectrum; make one per value")


def as_excitation(value) -> Excitation:
    """An :class:`Excitation` as is; a number S as white noise ``White(S)``; a tone as an input.

    A :class:`~randvib.models.tone.Tone` alone becomes the
    :class:`~randvib.models.combined.Combined` input of that tone.
    """
    if isinstance(value, Excitation):
        return value
    if isinstance(value, Tone):
        # the composite module builds on this one: reached through its registry
        return composition.as_input(value)
    if getattr(value, "is_event", False):
        raise ValueError(
            f"the {value.name} event is not stationary: its transient response is computed by "
            "randvib.simulate_transient (Monte Carlo) and randvib.transient_response (analytic)"
        )
    # an array of levels is refused by name here (float() would fail with numpy's
    # own words); predict, expected_power and equivalent_damping take arrays
    value = check_scalar("psd", value, f"a white-noise level S in {_PSD_UNIT}", BROADCASTING)
    return White(float(check_positive("psd", value, _PSD_UNIT)))


# ------------------------------------------------------------ rational
class _Rational(Excitation):
    """Spectra with a shaping filter; simulated through the filter's states."""

    def sample(self, duration, dt, n_paths=1, seed=None):
        raise NotImplementedError(
            f"the {self.name} spectrum is rational: simulate it through its shaping "
            "filter (shaping_filter()), integrated with the device"
        )


@dataclass(frozen=True, eq=False)
class White(_Rational):
    """Ideal white noise: S(f) = S, E[w(t1) w(t2)] = (S/2) delta (paper Eq. 17).

    Parameters
    ----------
    level : float
        One-sided PSD S ((m/s^2)^2/Hz), > 0.
    """

    level: float
    name = "white"
    is_white = True

    def __post_init__(self):
        object.__setattr__(
            self, "level", float(check_positive("level", _one("level", self.level), _PSD_UNIT))
        )

    def psd(self, frequency):
        return np.full(np.shape(frequency), self.level)

    @property
    def variance(self) -> float:
        return np.inf

    def shaping_filter(self) -> ShapingFilter:
        """No states: the acceleration is the white noise itself (D = 1)."""
        return ShapingFilter(
            StateSpace(np.zeros((0, 0)), [], np.zeros((1, 0)), [1.0], ("acceleration",)), self.level
        )


@dataclass(frozen=True, eq=False)
class _SecondOrder(_Rational):
    """White noise through ``x1'' + 2 zeta omega0 x1' + omega0^2 x1 = w``.

    The filter states are (x1, x1'); the excitation is a combination of them
    (``_output_row``), omega0 = 2 pi f0.
    """

    level: float
    f0: float
    zeta: float

    def __post_init__(self):
        object.__setattr__(
            self, "level", float(check_positive("level", _one("level", self.level), _PSD_UNIT))
        )
        object.__setattr__(self, "f0", float(check_positive("f0", _one("f0", self.f0), "Hz")))
        object.__setattr__(self, "zeta", float(check_positive("zeta", _one("zeta", self.zeta))))

    def features(self):
        return ((self.f0, self.zeta * self.f0),)

    def _denominator(self, f):
        f = np.asarray(f, dtype=float)
        return (self.f0**2 - f**2) ** 2 + (2.0 * self.zeta * f * self.f0) ** 2

    def _output_row(self, omega0):  # pragma: no cover - abstract
        raise NotImplementedError

    def shaping_filter(self) -> ShapingFilter:
        w0 = 2.0 * np.pi * self.f0
        a = [[0.0, 1.0], [-(w0**2), -2.0 * self.zeta * w0]]
        system = StateSpace(a, [0.0, 1.0], [self._output_row(w0)], [0.0], ("acceleration",))
        return ShapingFilter(system, self.level)


@dataclass(frozen=True, eq=False)
class BandPass(_SecondOrder):
    """Second-order band-pass noise: peak S at f0, half-power bandwidth 2 zeta f0.

    ``S(f) = S (2 zeta f f0)^2 / ((f0^2 - f^2)^2 + (2 zeta f f0)^2)``; the
    shaping filter's output is ``2 zeta omega0 x1'``.

    Parameters
    ----------
    level : float
        Peak PSD S ((m/s^2)^2/Hz), > 0.
    f0 : float
        Centre frequency (Hz), > 0.
    zeta : float
        Damping ratio of the filter, > 0 (narrow band: small zeta).

    Examples
    --------
    >>> import numpy as np
    >>> import randvib as rv
    >>> excitation = rv.BandPass(1.0, 8.0, 0.1)  # peak S (m/s^2)^2/Hz at f0 = 8 Hz
    >>> excitation.psd(np.array([4.0, 8.0, 16.0])).round(4)
    array([0.0175, 1.    , 0.0175])
    >>> excitation.is_white
    False
    """

    name = "band-pass"

    def psd(self, frequency):
        f = np.asarray(frequency, dtype=float)
        return self.level * (2.0 * self.zeta * f * self.f0) ** 2 / self._denominator(f)

    @property
    def variance(self) -> float:
        """pi zeta f0 S: the peak times the noise bandwidth pi zeta f0."""
        return np.pi * self.zeta * self.f0 * self.level

    def _output_row(self, omega0):
        return [0.0, 2.0 * self.zeta * omega0]


@dataclass(frozen=True, eq=False)
class KanaiTajimi(_SecondOrder):
    """Kanai-Tajimi noise: low-frequency level S, ground filter at f0.

    ``S(f) = S (f0^4 + (2 zeta f f0)^2) / ((f0^2 - f^2)^2 + (2 zeta f f0)^2)``;
    the shaping filter's output is ``omega0^2 x1 + 2 zeta omega0 x1'``. As
    f0 grows it tends to white noise of level S.

    Parameters
    ----------
    level : float
        PSD at f = 0, S ((m/s^2)^2/Hz), > 0.
    f0 : float
        Filter frequency (Hz), > 0.
    zeta : float
        Filter damping ratio, > 0.
    """

    name = "kanai-tajimi"

    def psd(self, frequency):
        f = np.asarray(frequency, dtype=float)
        numerator = self.f0**4 + (2.0 * self.zeta * f * self.f0) ** 2
        return self.level * numerator / self._denominator(f)

    @property
    def variance(self) -> float:
        """pi f0 S (1 + 4 zeta^2) / (4 zeta)."""
        return np.pi * self.f0 * self.level * (1.0 + 4.0 * self.zeta**2) / (4.0 * self.zeta)

    def _output_row(self, omega0):
        return [omega0**2, 2.0 * self.zeta * omega0]


# --------------------------------------------------------- non-rational
@dataclass(frozen=True, eq=False)
class BandLimited(Excitation):
    """Flat PSD S between f_lo and f_hi (inclusive), zero outside.

    Parameters
    ----------
    level : float
        PSD in the band, S ((m/s^2)^2/Hz), > 0.
    f_lo, f_hi : float
        Band edges (Hz), 0 <= f_lo < f_hi (the paper's tests: 4 and 20 Hz).
    """

    level: float
    f_lo: float
    f_hi: float
    name = "band-limited"

    def __post_init__(self):
        object.__setattr__(
            self, "level", float(check_positive("level", _one("level", self.level), _PSD_UNIT))
        )
        object.__setattr__(
            self, "f_lo", float(check_nonnegative("f_lo", _one("f_lo", self.f_lo), "Hz"))
        )
        object.__setattr__(
            self, "f_hi", float(check_positive("f_hi", _one("f_hi", self.f_hi), "Hz"))
        )
        if self.f_hi <= self.f_lo:
            raise ValueError(f"`f_hi` must be > `f_lo` = {self.f_lo} Hz, got {self.f_hi} Hz")

    def psd(self, frequency):
        f = np.asarray(frequency, dtype=float)
        return np.where((f >= self.f_lo) & (f <= self.f_hi), self.level, 0.0)

    @property
    def variance(self) -> float:
        return self.level * (self.f_hi - self.f_lo)

    def cumulative_power(self, frequency):
        f = np.asarray(frequency, dtype=float)
        return self.level * np.clip(f - self.f_lo, 0.0, self.f_hi - self.f_lo)

    @property
    def support(self):
        return self.f_lo, self.f_hi

    def breakpoints(self):
        return self.f_lo, self.f_hi


@dataclass(frozen=True, eq=False)
class Tabulated(Excitation):
    """A PSD given as a table, linearly interpolated, zero outside the table.

    Parameters
    ----------
    frequency : array_like
        Frequencies (Hz), >= 0, strictly increasing, at least two.
    density : array_like
        One-sided PSD at those frequencies ((m/s^2)^2/Hz), >= 0, not all zero.
    """

    frequency: np.ndarray
    density: np.ndarray
    name = "tabulated"

    def __post_init__(self):
        f = check_nonnegative("frequency", self.frequency, "Hz")
        p = check_nonnegative("psd", self.density, _PSD_UNIT)
        if f.ndim != 1 or f.size < 2 or p.shape != f.shape:
            raise ValueError(
                "`frequency` and `psd` must be 1-D of the same length >= 2, got shapes "
                f"{f.shape} and {p.shape}"
            )
        steps = np.diff(f)
        if np.any(steps <= 0):
            i = int(np.argmax(steps <= 0))
            raise ValueError(
                f"`frequency` must be strictly increasing, got {float(f[i + 1])!r} Hz after "
                f"{float(f[i])!r} Hz (rows {i} and {i + 1})"
            )
        if not np.any(p > 0):
            raise ValueError("`psd` must be > 0 somewhere; the table has no power")
        with np.errstate(all="ignore"):
            power = float(np.trapezoid(p, f))
        if not np.isfinite(power):
            raise ValueError(
                f"the table's total power (the variance, integral of `psd` over `frequency`) "
                f"overflows float64, with `psd` up to {float(p.max()):.3g} {_PSD_UNIT} over "
                f"{float(f[0]):g}-{float(f[-1]):g} Hz; give the PSD in {_PSD_UNIT}"
            )
        object.__setattr__(self, "frequency", f)
        object.__setattr__(self, "density", p)

    def scaled(self, factor: float) -> Tabulated:
        factor = float(check_positive("factor", factor))
        return Tabulated(self.frequency, self.density * factor)

    @classmethod
    def from_csv(cls, path) -> Tabulated:
        """Read a table with the columns ``frequency`` (Hz) and ``psd`` ((m/s^2)^2/Hz)."""
        frame = read_columns(path, ("frequency", "psd"))
        return cls(frame["frequency"], frame["psd"])

    def psd(self, frequency):
        return np.interp(frequency, self.frequency, self.density, left=0.0, right=0.0)

    @property
    def variance(self) -> float:
        """The exact integral of the interpolated table (trapezoid rule)."""
        return float(np.trapezoid(self.density, self.frequency))

    def cumulative_power(self, frequency):
        """Exact integral of the interpolated table from 0 to ``frequency`` (Hz)."""
        f = np.clip(np.asarray(frequency, dtype=float), self.frequency[0], self.frequency[-1])
        nodes = np.concatenate(
            [
                [0.0],
                np.cumsum(np.diff(self.frequency) * 0.5 * (self.density[1:] + self.density[:-1])),
            ]
        )
        i = np.clip(
            np.searchsorted(self.frequency, f, side="right") - 1, 0, self.frequency.size - 2
        )
        partial = (f - self.frequency[i]) * 0.5 * (self.density[i] + self.psd(f))
        return nodes[i] + partial

    @property
    def support(self):
        nonzero = np.flatnonzero(self.density > 0)
        lo = self.frequency[max(nonzero[0] - 1, 0)]
        hi = self.frequency[min(nonzero[-1] + 1, self.frequency.size - 1)]
        return float(lo), float(hi)

    def breakpoints(self):
        return tuple(self.frequency)

    def parameters(self) -> dict:
        lo, hi = self.support
        return {"excitation": self.name, "f_lo": lo, "f_hi": hi, "variance": self.variance}

    def __repr__(self) -> str:  # the size and range, not the arrays
        lo, hi = self.support
        return (
            f"Tabulated({self.frequency.size} points, {lo:g}-{hi:g} Hz, "
            f"variance {self.variance:.4g} (m/s^2)^2)"
        )


def welch_segment_length(n_samples: int) -> int:
    """Welch segment length (samples) for a record of ``n_samples``.

    The largest power of two not above n/8, so that with 50 % overlap
    between 15 and 31 Hann-windowed segments are averaged (relative standard
    error of each PSD value about 1/sqrt(0.95 K) for K segments), and at least
    64 samples (or the whole record if shorter).
    """
    if n_samples < 8 * 64:
        return min(n_samples, 64)
    return 2 ** int(np.floor(np.log2(n_samples / 8)))


@dataclass(frozen=True, eq=False)
class Measured(Excitation):
    """A measured base-acceleration record and its PSD (Welch's method).

    The PSD is Welch's estimate (scipy.signal.welch): Hann window, 50 %
    overlap, each segment's mean removed, ``segment_length`` samples per
    segment (default :func:`welch_segment_length`: the largest power of
    two <= n/8, 15 to 31 segments), linearly interpolated between its
    frequency bins (:class:`Tabulated`). The record itself is kept for
    simulations driven by it (:func:`randvib.monte_carlo_on_record`);
    ``sample`` synthesises Gaussian surrogates with the estimated PSD.

    Parameters
    ----------
    record : Record
        A record with a ``base_acceleration`` channel (m/s^2) and at least
        64 samples (its time grid is checked by :class:`~randvib.models.record.Record`).
    segment_length : int, optional
        Welch segment length (samples), 16 <= L <= n.

    Examples
    --------
    >>> import numpy as np
    >>> import randvib as rv
    >>> t = np.arange(4096) * 1e-3
    >>> acceleration = np.random.default_rng(0).standard_normal(t.size)
    >>> rv.Measured(rv.Record(time=t, base_acceleration=acceleration)).segment_length
    512
    """

    record: Record
    segment_length: int | None = None
    name = "measured"

    def __post_init__(self):
        record = self.record
        if not isinstance(record, Record):
            raise ValueError(
                "`record` must be a randvib.Record with a base_acceleration channel, got "
                f"{type(record).__name__}"
            )
        if "base_acceleration" not in record:
            raise ValueError(
                f"`record` {record.name!r} has no base_acceleration channel (it has "
                f"{', '.join(record.channels)}); a measured excitation is a base acceleration"
            )
        if record.n < 64:
            raise ValueError(f"`record` must have at least 64 samples, got {record.n}")
        length = (
            welch_segment_length(record.n) if self.segment_length is None else self.segment_length
        )
        length = check_int("segment_length", length, minimum=16)
        if length > record.n:
            raise ValueError(
                f"`segment_length` must be <= the record's {record.n} samples, got {length}"
            )
        # imported here: scipy.signal (and the scipy.stats it loads) is a second of
        # CPU that every process importing the models layer (a sweep's worker) paid
        from scipy import signal

        f, p = signal.welch(
            self.acceleration, fs=1.0 / record.dt, window="hann", nperseg=length,
            noverlap=length // 2,
        )  # fmt: skip
        object.__setattr__(self, "segment_length", length)
        object.__setattr__(self, "spectrum", Tabulated(f, p))

    def scaled(self, factor: float) -> Measured:
        """The record's acceleration times sqrt(factor): its PSD times ``factor``."""
        factor = float(check_positive("factor", factor))
        scaled = Record(time=self.time, base_acceleration=self.acceleration * np.sqrt(factor))
        return Measured(scaled, self.segment_length)

    @classmethod
    def from_csv(
        cls,
        path,
        segment_length: int | None = None,
        *,
        input_column: str | None = None,
        sample_rate: float | None = None,
    ) -> Measured:
        """Read a record with the columns ``time`` (s) and ``base_acceleration`` (m/s^2).

        ``input_column`` names another acceleration column; ``sample_rate`` (Hz)
        serves a file without a time column (as :func:`randvib.read_record`).
        """
        record = read_record(
            path,
            input_column=input_column,
            input_kind="base_acceleration",
            output_column=None,
            sample_rate=sample_rate,
        )
        return cls(record, segment_length)

    @property
    def time(self) -> np.ndarray:
        """Sample times (s)."""
        return self.record.time

    @property
    def acceleration(self) -> np.ndarray:
        """The measured base acceleration (m/s^2)."""
        return self.record["base_acceleration"]

    @property
    def dt(self) -> float:
        """Sample step (s)."""
        return self.record.dt

    @property
    def n_segments(self) -> int:
        """Number of Welch segments averaged (50 % overlap)."""
        step = self.segment_length - self.segment_length // 2
        return (self.record.n - self.segment_length) // step + 1

    def psd(self, frequency):
        return self.spectrum.psd(frequency)

    @property
    def variance(self) -> float:
        """Integral of the Welch PSD (close to the record's variance about its mean)."""
        return self.spectrum.variance

    def cumulative_power(self, frequency):
        return self.spectrum.cumulative_power(frequency)

    @property
    def support(self):
        return self.spectrum.support

    def breakpoints(self):
        return self.spectrum.breakpoints()

    @property
    def duration(self) -> float:
        """Length of the record (s): n steps."""
        return float(self.time[-1] - self.time[0] + self.dt)

    def parameters(self) -> dict:
        return {
            "excitation": self.name,
            "duration": self.duration,
            "dt": self.dt,
            "segment_length": self.segment_length,
            # two numbers, named for what they are: the Welch integral the methods
            # use and the samples' own variance (they differ by the estimate's error)
            "psd_integral": self.variance,
            "record_variance": self.record_variance,
        }

    @property
    def kurtosis(self) -> float:
        """The recorded acceleration's sample kurtosis E[(a - mean)^4] / var^2 (3: Gaussian).

        A record carries its own marginal: Monte Carlo on it
        (:func:`randvib.monte_carlo_on_record`) drives the device with it as
        it is; the Gaussian analytic methods name this number where it is
        beyond their measured limit (:mod:`randvib.analytic.method`).
        """
        a = self.acceleration - np.mean(self.acceleration)
        return float(np.mean(a**4) / np.mean(a**2) ** 2)

    @property
    def record_variance(self) -> float:
        """Variance of the recorded acceleration about its mean ((m/s^2)^2)."""
        return float(np.var(self.acceleration))

    def __repr__(self) -> str:  # the record's size, not its samples
        return (
            f"Measured({self.record.n} samples at {1.0 / self.dt:.6g} Hz, {self.duration:.6g} s, "
            f"Welch PSD integral {self.variance:.4g} (m/s^2)^2)"
        )


def read_columns(path, columns) -> dict:
    """The named ``columns`` of a CSV file (:func:`~randvib.models.record.read_csv`) as floats;
    a missing one is named."""
    frame = read_csv(path, "file")
    missing = [c for c in columns if c not in frame.columns]
    if missing:
        raise ValueError(
            f"`{path}` must have the columns {', '.join(columns)}; missing {', '.join(missing)} "
            f"(found {', '.join(map(str, frame.columns))})"
        )
    return {c: frame[c].to_numpy(dtype=float) for c in columns}


def synthesis_power(excitation: Excitation, n: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The bins of an n-sample synthesis and the power each one carries.

    Bin k sits at f_k = k / (n dt), k = 0 .. n // 2, and carries the exact
    power of its cell [f_k - 1/(2 n dt), f_k + 1/(2 n dt)] (clipped to
    [0, 1/(2 dt)]), ``excitation.cumulative_power`` differenced; the powers
    sum to the spectrum's integral up to the Nyquist frequency, so the
    synthesised variance is exact for any record length.

    Raises
    ------
    ValueError
        If the spectrum has power above the Nyquist frequency 1/(2 dt).
    """
    top = excitation.support[1]
    if top > 0.5 / dt * (1 + 1e-12):
        raise ValueError(
            f"`dt` = {dt} s resolves frequencies up to 1/(2 dt) = {0.5 / dt:.6g} Hz, but the "
            f"{excitation.name} spectrum has power up to {top:.6g} Hz; choose `dt` <= "
            f"{0.5 / top:.3g} s"
        )
    f = np.fft.rfftfreq(n, dt)
    edges = np.clip(np.concatenate([f - 0.5 / (n * dt), [f[-1] + 0.5 / (n * dt)]]), 0, 0.5 / dt)
    return f, np.maximum(np.diff(excitation.cumulative_power(edges)), 0.0)


def _irfft_scale(n: int, size: int) -> np.ndarray:
    """Factors turning amplitudes (A - iB) into irfft coefficients (see :func:`synthesise`)."""
    # irfft(X)_j = (1/n) [X_0 + 2 Re sum_k X_k e^{2 pi i k j/n} + X_{n/2} (-1)^j]: the
    # coefficient (n/2)(A - iB) gives A cos + B sin; DC and Nyquist are real, with n A.
    scale = np.full(size, 0.5 * n)
    scale[0] = n
    if n % 2 == 0:
        scale[-1] = n
    return scale


def synthesise(excitation: Excitation, duration: float, dt: float, n_paths: int = 1, seed=None):
    """Stationary Gaussian paths with the excitation's PSD, by frequency-domain synthesis.

    With n = duration/dt samples and the bins f_k = k / (n dt), each path is
    ``sum_k A_k cos(2 pi f_k t) + B_k sin(2 pi f_k t)`` with independent
    A_k, B_k ~ N(0, P_k), P_k the exact power of the bin's cell
    (:func:`synthesis_power`; no sine at f = 0 and at the Nyquist bin). The
    paths are exactly Gaussian and stationary (periodic with period n dt);
    their variance is exactly ``excitation.variance`` (the integral of S
    below the Nyquist frequency, where the spectrum must vanish).

    Parameters
    ----------
    excitation : Excitation
        Its spectrum must vanish above the Nyquist frequency 1/(2 dt).
    duration : float
        Length of each path (s), > 0.
    dt : float
        Sample step (s), > 0.
    n_paths : int
        Number of independent paths, >= 1.
    seed : int, numpy.random.Generator or None
        Random source (never the global numpy state).

    Returns
    -------
    ndarray, shape (n_paths, n)
        Base acceleration (m/s^2) at the times j dt.
    """
    duration = float(check_positive("duration", duration, "s"))
    dt = float(check_positive("dt", dt, "s"))
    n_paths = check_int("n_paths", n_paths, minimum=1)
    n = check_int("number of samples (duration / dt)", round(duration / dt), minimum=8)
    f, power = synthesis_power(excitation, n, dt)
    scale = _irfft_scale(n, f.size)
    rng = np.random.default_rng(seed)
    g = rng.standard_normal((2, n_paths, f.size))
    g[1][:, scale == n] = 0.0
    return np.fft.irfft(scale * np.sqrt(power) * (g[0] - 1j * g[1]), n, axis=-1)


def synthesised_increments(excitation: Excitation, n: int, dt: float, normals) -> np.ndarray:
    """Step integrals of synthesised base-acceleration paths, from each path's own normals.

    For each path, the process of :func:`synthesise` (n samples of step dt,
    period n dt), y(t) = sum_k A_k cos(w_k t) + B_k sin(w_k t), integrated
    exactly over every step: ``int_{j dt}^{(j+1) dt} y dt`` (m/s), the
    coefficient of bin k multiplied by (e^{i w_k dt} - 1) / (i w_k) (dt at
    w = 0; the Nyquist cosine integrates to zero over each step). These are
    the velocity increments a simulation with additive input needs, with the
    input's spectrum treated exactly rather than sampled.

    Parameters
    ----------
    excitation : Excitation
        Non-rational spectrum vanishing above 1/(2 dt).
    n : int
        Steps per path (the period is n dt).
    dt : float
        Step (s).
    normals : ndarray, shape (n_paths, 2 (n // 2 + 1))
        Standard normals, one row per path (A_k then B_k per bin, scaled by
        sqrt(P_k)): a path's input depends on its own row only.

    Returns
    -------
    ndarray, shape (n_paths, n)
        int y dt over each step (m/s).
    """
    from scipy import fft

    f, power = synthesis_power(excitation, n, dt)
    scale = _irfft_scale(n, f.size)
    omega = 2.0 * np.pi * f
    with np.errstate(invalid="ignore", divide="ignore"):
        step = np.where(omega > 0, np.expm1(1j * omega * dt) / (1j * omega), dt)
    if n % 2 == 0:
        step[-1] = 0.0  # the Nyquist cosine's step integral is exactly zero
    factor = scale * np.sqrt(power) * step
    g = np.asarray(normals, dtype=float).reshape(-1, 2, f.size)
    sine = np.where(scale == n, 0.0, g[:, 1])  # no sine at f = 0 and at the Nyquist bin
    return fft.irfft(factor * (g[:, 0] - 1j * sine), n, axis=-1, workers=-1)


def synthesised_values(excitation: Excitation, n: int, dt: float, normals, offset: float = 0.0):
    """Synthesised paths sampled at the times ``j dt + offset``, from each path's own normals.

    The process of :func:`synthesised_increments` (same bins, same normals,
    so the same path) evaluated at ``j dt + offset`` instead of integrated
    over the steps: each bin's coefficient turned by e^{i w_k offset}.
    ``offset = dt / 2`` gives the steps' midpoints, where a pointwise
    function of the path (a translation, :mod:`randvib.models.translation`)
    is integrated over each step by the midpoint rule.

    Returns
    -------
    ndarray, shape (n_paths, n)
        The process's values (its unit).
    """
    from scipy import fft

    f, power = synthesis_power(excitation, n, dt)
    scale = _irfft_scale(n, f.size)
    turn = np.exp(1j * 2.0 * np.pi * f * offset)
    if n % 2 == 0:
        turn[-1] = np.cos(2.0 * np.pi * f[-1] * offset)  # the Nyquist bin stays real
    g = np.asarray(normals, dtype=float).reshape(-1, 2, f.size)
    sine = np.where(scale == n, 0.0, g[:, 1])
    coefficients = scale * np.sqrt(power) * turn * (g[:, 0] - 1j * sine)
    return fft.irfft(coefficients, n, axis=-1, workers=-1)
