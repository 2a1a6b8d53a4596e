"""A tone: a deterministic sinusoidal base acceleration, alone or on top of noise.

Rotating machines (pumps, fans, motors) shake their mounts at the running
speed and its harmonics on a broadband floor. A tone is

    a(t) = A cos(2 pi f t + phi)    (m/s^2, f in Hz, phi in radians)

(docs/conventions.md, "Tones, shocks and non-Gaussian input"). With its phase drawn uniformly
on [0, 2 pi) for every realisation (``phase=None``, the default) the tone is a
stationary process of mean 0 and mean square A^2 / 2, independent of any
noise it is added to; with a given phase it is the same deterministic signal
in every realisation (in degrees, as the command line's ``--tone F:A:PHASE``).

A tone is not a spectrum (its power sits on one frequency): it joins one by
``+`` (:class:`~randvib.models.combined.Combined`), ``BandPass(1, 8, 0.1) +
Tone(25, 0.5)``, or stands alone (``Tone(25, 0.5)`` wherever an excitation is
taken). A linear device's response to it is exact by superposition: the tone
through the device's frequency response, amplitude ``|H(i 2 pi f)| A``
(:mod:`randvib.analytic.harmonic_linearisation`); Monte Carlo integrates it
as deterministic forcing inside the compiled kernel
(:mod:`randvib.montecarlo.forcing`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from randvib._validation import check_finite, check_positive, check_scalar
from randvib.models import composition


@dataclass(frozen=True, eq=False)
class Tone:
    """A sinusoidal base acceleration ``A cos(2 pi f t + phi)``.

    Parameters
    ----------
    frequency : float
        f (Hz), > 0.
    amplitude : float
        A, the base acceleration's amplitude (m/s^2), > 0; its mean square
        is A^2 / 2.
    phase : float or None
        phi in degrees; None (default): uniform on [0, 360) and independent
        for every realisation (path), so that the input is stationary.

    Examples
    --------
    >>> import randvib as rv
    >>> tone = rv.Tone(25.0, 0.5)
    >>> tone.mean_square
    0.125
    >>> (rv.BandPass(1.0, 8.0, 0.1) + tone).lines()
    (Tone(frequency=25.0, amplitude=0.5, phase=None),)
    """

    frequency: float
    amplitude: float
    phase: float | None = None

    def __post_init__(self):
        one = "a tone is one sinusoid; add several tones for several frequencies"
        f = check_scalar("frequency", self.frequency, one)
        a = check_scalar("amplitude", self.amplitude, one)
        object.__setattr__(self, "frequency", float(check_positive("frequency", f, "Hz")))
        object.__setattr__(self, "amplitude", float(check_positive("amplitude", a, "m/s^2")))
        if self.phase is not None:
            phase = float(check_finite("phase", check_scalar("phase", self.phase, one)))
            object.__setattr__(self, "phase", phase)

    @property
    def omega(self) -> float:
        """Angular frequency 2 pi f (rad/s)."""
        return 2.0 * math.pi * self.frequency

    @property
    def mean_square(self) -> float:
        """E[a^2] = A^2 / 2 ((m/s^2)^2), over a period or over the random phase."""
        return 0.5 * self.amplitude**2

    @property
    def random_phase(self) -> bool:
        """True when the phase is drawn per realisation (stationary input)."""
        return self.phase is None

    def parameters(self) -> dict:
        """The tone's numbers (Hz, m/s^2, degrees or None), ready for JSON."""
        return {"frequency": self.frequency, "amplitude": self.amplitude, "phase": self.phase}

    def lines(self) -> tuple:
        return (self,)

    def __add__(self, other):
        # the composite module builds on this one: reached through its registry
        return composition.combine(self, other)

    def __radd__(self, other):
        return composition.combine(other, self)


def parse_tone(text: str) -> Tone:
    """A tone from the command line's ``F:A[:PHASE]`` (Hz, m/s^2, degrees).

    Raises
    ------
    ValueError
        One line naming ``--tone``, the text and what is allowed.
    """
    parts = text.split(":")
    try:
        if len(parts) in (2, 3):
            numbers = [float(p) for p in parts]
            return Tone(numbers[0], numbers[1], numbers[2] if len(parts) == 3 else None)
    except ValueError as exc:
        reason = str(exc).replace("`frequency`", "F").replace("`amplitude`", "A")
        reason = reason.replace("`phase`", "PHASE")
        raise ValueError(
            f"`--tone` {text!r}: {reason} (F:A[:PHASE], F in Hz, A in m/s^2, PHASE in degrees)"
        ) from None
    raise ValueError(
        f"`--tone` must be F:A or F:A:PHASE (F in Hz > 0, A in m/s^2 > 0, PHASE in degrees), "
        f"got {text!r}"
    )
