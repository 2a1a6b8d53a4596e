"""Inputs added together: one random part, tones and a shock train (``+``).

A pump's mount sees a broadband floor with lines at the running speed; a
vehicle's, road noise with impacts. :class:`Combined` is the sum of
independent inputs, each of which the rest of randvib treats in its own way:

* ``random`` - one stationary random part: a Gaussian spectrum (white,
  band-pass, Kanai-Tajimi, band-limited, tabulated) or a non-Gaussian
  translation process (:class:`~randvib.models.translation.Translated`);
  None for tones or shocks alone;
* ``tones`` - deterministic sinusoids (:class:`~randvib.models.tone.Tone`);
* ``shocks`` - a Poisson train of pulses (:class:`~randvib.models.shock.ShockTrain`).

Build it with ``+`` (``BandPass(1, 8, 0.1) + Tone(25, 0.5) + Tone(50, 0.2)``)
or :func:`combine`; :func:`as_input` turns a bare tone into one. The
declarations of the family (:class:`~randvib.models.excitation.Excitation`)
describe the sum: ``psd`` is the continuous part (the random part's and the
shocks' Campbell spectrum), :meth:`Combined.lines` the tones, ``variance``
everything; the parts are independent, so their second moments add through
any linear device (:mod:`randvib.analytic.harmonic_linearisation`).
The objects know nothing of the device: a tone is a deterministic base
acceleration and a shock train a sampled one, for any model that takes a
base acceleration (Monte Carlo: :mod:`randvib.montecarlo.forcing`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from randvib.models import composition
from randvib.models.excitation import Excitation, as_excitation
from randvib.models.shock import ShockTrain
from randvib.models.tone import Tone


@dataclass(frozen=True, eq=False)
class Combined(Excitation, registered=False):
    """The sum of independent inputs: a random part, tones and a shock train.

    Parameters
    ----------
    random : Excitation or None
        Gaussian spectrum or translation process; None: no random part.
    tones : tuple of Tone
        Deterministic sinusoids (any number).
    shocks : ShockTrain or None
        A Poisson train of pulses.

    Examples
    --------
    >>> import randvib as rv
    >>> pump = rv.BandPass(0.5, 8.0, 0.2) + rv.Tone(25.0, 1.0)
    >>> pump.name, len(pump.lines()), round(pump.variance, 4)
    ('band-pass + 1 tone', 1, 3.0133)
    """

    random: Excitation | None = None
    tones: tuple = ()
    shocks: ShockTrain | None = None
    name = "combined"  # replaced per instance by a description (``band-pass + 1 tone``)
    is_gaussian = False

    def __post_init__(self):
        random = self.random
        if random is not None:
            random = as_excitation(random)
            if isinstance(random, Combined | ShockTrain):
                raise ValueError(
                    f"`random` must be one random spectrum, got a {random.name}: add the tones "
                    "and shocks to it with `+`"
                )
        tones = tuple(self.tones)
        for tone in tones:
            if not isinstance(tone, Tone):
                raise ValueError(f"`tones` must hold randvib.Tone objects, got {tone!r}")
        if self.shocks is not None and not isinstance(self.shocks, ShockTrain):
            raise ValueError(f"`shocks` must be a randvib.ShockTrain, got {self.shocks!r}")
        if random is None and not tones and self.shocks is None:
            raise ValueError("a combined input needs a random part, a tone or a shock train")
        object.__setattr__(self, "random", random)
        object.__setattr__(self, "tones", tones)
        words = [random.name] if random is not None else []
        if tones:
            words.append(f"{len(tones)} tone{'s' * (len(tones) > 1)}")
        if self.shocks is not None:
            words.append("shocks")
        object.__setattr__(self, "name", " + ".join(words))

    # ------------------------------------------------------------ the parts
    @property
    def continuous(self) -> tuple[Excitation, ...]:
        """The parts with a spectral density: the random part and the shocks (Campbell)."""
        return tuple(part for part in (self.random, self.shocks) if part is not None)

    def lines(self) -> tuple:
        return self.tones

    @property
    def level(self):
        """The random part's level ((m/s^2)^2/Hz): None where it has none (a table), 0 without one."""
        return 0.0 if self.random is None else getattr(self.random, "level", None)

    # ------------------------------------------------------------ declarations
    def psd(self, frequency):
        """The continuous part's one-sided PSD: the random part's plus the shocks'."""
        total = np.zeros(np.shape(frequency))
        for part in self.continuous:
            total = total + part.psd(frequency)
        return total

    @property
    def variance(self) -> float:
        """E[a^2] of the sum ((m/s^2)^2): the parts' variances and the tones' A^2 / 2."""
        return sum(p.variance for p in self.continuous) + sum(t.mean_square for t in self.tones)

    @property
    def kurtosis(self) -> float:
        """The sum's kurtosis: the parts' fourth cumulants add (independent parts).

        A tone's fourth cumulant is -3 A^4 / 8 (kurtosis 1.5); infinite variance
        (white noise) gives 3.
        """
        variance = self.variance
        if not np.isfinite(variance):
            return 3.0
        cumulant = sum((p.kurtosis - 3.0) * p.variance**2 for p in self.continuous)
        cumulant += sum(-1.5 * t.mean_square**2 for t in self.tones)
        return 3.0 + cumulant / variance**2

    @property
    def support(self):
        spans = [p.support for p in self.continuous] or [(0.0, 0.0)]
        lo = min(s[0] for s in spans)
        hi = max([s[1] for s in spans] + [t.frequency for t in self.tones])
        return lo, hi

    def features(self):
        return tuple(f for part in self.continuous for f in part.features())

    def breakpoints(self):
        return tuple(sorted({b for part in self.continuous for b in part.breakpoints()}))

    def scaled(self, factor: float) -> Combined:
        """Every part's power times ``factor``: the tones' amplitudes times sqrt(factor)."""
        root = float(np.sqrt(factor))
        random = None if self.random is None else self.random.scaled(factor)
        tones = tuple(Tone(t.frequency, t.amplitude * root, t.phase) for t in self.tones)
        shocks = self.shocks
        if shocks is not None:
            shocks = ShockTrain(shocks.rate, shocks.amplitude * root, shocks.duration,
                                shocks.shape, shocks.distribution)  # fmt: skip
        return Combined(random, tones, shocks)

    def sample(self, duration, dt, n_paths=1, seed=None):
        raise NotImplementedError(
            "a combined input is simulated part by part (randvib.simulate); sample its "
            "random part, tones and shocks apart"
        )

    def parameters(self) -> dict:
        """The random part's parameters as its own (``excitation`` its kind, ``none`` without
        one), with ``tones`` (a list) and ``shocks`` (an object) where there are any."""
        out = {"excitation": "none"} if self.random is None else self.random.parameters()
        if self.tones:
            out["tones"] = [t.parameters() for t in self.tones]
        if self.shocks is not None:
            out["shocks"] = self.shocks.parameters()
        return out

    def __repr__(self) -> str:
        parts = [repr(self.random)] if self.random is not None else []
        parts += [f"Tone({t.frequency:g} Hz, {t.amplitude:g} m/s^2)" for t in self.tones]
        parts += [repr(self.shocks)] if self.shocks is not None else []
        return " + ".join(parts)


def _parts(value) -> tuple:
    """(random, tones, shocks) of one summand."""
    if isinstance(value, Combined):
        return value.random, value.tones, value.shocks
    if isinstance(value, Tone):
        return None, (value,), None
    if isinstance(value, ShockTrain):
        return None, (), value
    return as_excitation(value), (), None


def combine(a, b) -> Combined:
    """``a + b`` for inputs: tones accumulate; one random part and one shock train at most.

    ``0 + x`` is ``x`` (so that :func:`sum` works).
    """
    if isinstance(a, int) and not isinstance(a, bool) and a == 0:
        return as_input(b)
    (ra, ta, sa), (rb, tb, sb) = _parts(a), _parts(b)
    if ra is not None and rb is not None:
        raise ValueError(
            f"an input has one random part; {ra.name} + {rb.name} are two: describe their sum "
            "as one spectrum (a randvib.Tabulated of the summed PSD)"
        )
    if sa is not None and sb is not None:
        raise ValueError("an input has one shock train; give one ShockTrain with the summed rate")
    return Combined(ra if ra is not None else rb, ta + tb, sa if sa is not None else sb)


def as_input(value) -> Excitation:
    """An excitation (as :func:`~randvib.models.excitation.as_excitation`), a tone made one."""
    if isinstance(value, Tone):
        return Combined(None, (value,))
    return as_excitation(value)


def parts_of(excitation) -> tuple:
    """(random, tones, shocks) of any input: a plain excitation is its own random part."""
    excitation = as_input(excitation)
    if isinstance(excitation, ShockTrain):
        return None, (), excitation
    return _parts(excitation)


composition.register(combine=combine, as_input=as_input)
