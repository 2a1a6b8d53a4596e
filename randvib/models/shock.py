"""Shocks: a Poisson train of pulses of base acceleration (filtered Poisson process).

Vehicles, rail and footsteps shake a harvester with impulses. The train is

    a(t) = sum_k A_k p(t - t_k)

with arrival times t_k of a Poisson process of rate lambda (1/s), pulse
shape p of duration D (a half sine ``sin(pi t / D)`` by default, or a
rectangle, both of peak 1 on [0, D]) and peak accelerations A_k, independent,
of random sign (so the train has mean 0) and magnitude fixed or drawn from a
distribution. ``amplitude`` is the RMS of the peaks, sqrt(E[A^2]) (m/s^2):
for ``"fixed"`` every peak has that size; ``"rayleigh"`` and
``"exponential"`` spread the magnitudes with the same E[A^2] (so the same
power) and heavier tails (E[A^4]/E[A^2]^2 = 1, 2 and 6).

**Campbell's theorem** (docs/conventions.md, "Campbell"): through a linear
filter g the train's response has variance ``lambda E[A^2] int g^2 dt``;
by Parseval that is the response to a stationary spectrum

    S(f) = 2 lambda E[A^2] |P(f)|^2     (one-sided, (m/s^2)^2/Hz)

with P the Fourier transform of p: ``|P| = (2 D / pi) |cos(pi f D)| / |1 -
(2 f D)^2|`` for the half sine, ``D |sinc(f D)|`` for the rectangle. So
:meth:`ShockTrain.psd` makes every linear device's second moments (its mean
power) exact through the spectral machinery (:mod:`randvib.analytic.linear_response`).
Its marginal is far from Gaussian: kurtosis ``3 + (E[A^4]/E[A^2]^2)
int p^4 / (lambda (int p^2)^2)``.

**Monte Carlo** draws each path's train from its own stream and gives the
kernel the exact integral of the train over every step
(:meth:`ShockTrain.step_integrals`), added to the velocity as the base
acceleration is (:mod:`randvib.montecarlo.forcing`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from randvib._validation import check_choice, check_positive, check_scalar
from randvib.models.excitation import Excitation

#: Pulse shapes: name -> (int p^2 dt / D, int p^4 dt / D).
SHAPES = {"half-sine": (0.5, 0.375), "rectangular": (1.0, 1.0)}
#: Peak distributions: name -> E[A^4] / E[A^2]^2 (the RMS peak fixed by ``amplitude``).
DISTRIBUTIONS = {"fixed": 1.0, "rayleigh": 2.0, "exponential": 6.0}


@dataclass(frozen=True, eq=False)
class ShockTrain(Excitation, registered=False):
    """A Poisson train of pulses of random sign (Campbell: exact linear second moments).

    Parameters
    ----------
    rate : float
        lambda, pulses per second (1/s), > 0.
    amplitude : float
        RMS peak base acceleration sqrt(E[A^2]) (m/s^2), > 0: every peak's
        size with ``distribution="fixed"``.
    duration : float
        Pulse duration D (s), > 0.
    shape : {"half-sine", "rectangular"}
        Pulse shape, peak 1 on [0, D].
    distribution : {"fixed", "rayleigh", "exponential"}
        Distribution of the peaks' magnitudes (their sign is random).

    Examples
    --------
    >>> import randvib as rv
    >>> shocks = rv.ShockTrain(rate=2.0, amplitude=20.0, duration=0.01)
    >>> round(shocks.variance, 6)  # lambda E[A^2] D / 2
    4.0
    >>> round(shocks.kurtosis, 2)  # 3 + 3 / (2 lambda D)
    78.0
    """

    rate: float
    amplitude: float
    duration: float
    shape: str = "half-sine"
    distribution: str = "fixed"
    name = "shocks"
    is_gaussian = False

    def __post_init__(self):
        one = "a shock train has one rate, amplitude and duration"
        for name, unit in (("rate", "1/s"), ("amplitude", "m/s^2"), ("duration", "s")):
            value = check_positive(name, check_scalar(name, getattr(self, name), one), unit)
            object.__setattr__(self, name, float(value))
        check_choice("shape", self.shape, tuple(SHAPES))
        check_choice("distribution", self.distribution, tuple(DISTRIBUTIONS))

    # --------------------------------------------------------------- the spectrum
    def pulse_spectrum(self, frequency) -> np.ndarray:
        """|P(f)|^2 (s^2) of the unit pulse, f in Hz."""
        f = np.abs(np.asarray(frequency, dtype=float))
        d = self.duration
        if self.shape == "rectangular":
            return (d * np.sinc(f * d)) ** 2
        x = 2.0 * f * d
        with np.errstate(divide="ignore", invalid="ignore"):
            p = (2.0 * d / np.pi) * np.cos(0.5 * np.pi * x) / (1.0 - x * x)
        # the removable singularity at f = 1 / (2 D): |P| = D / 2 there
        return np.where(np.abs(1.0 - x) < 1e-6, 0.5 * d, p) ** 2

    def psd(self, frequency) -> np.ndarray:
        """Campbell's one-sided PSD 2 lambda E[A^2] |P(f)|^2 ((m/s^2)^2/Hz)."""
        return 2.0 * self.rate * self.amplitude**2 * self.pulse_spectrum(frequency)

    @property
    def variance(self) -> float:
        """lambda E[A^2] int p^2 dt ((m/s^2)^2)."""
        return self.rate * self.amplitude**2 * SHAPES[self.shape][0] * self.duration

    @property
    def kurtosis(self) -> float:
        """3 + (E[A^4]/E[A^2]^2) int p^4 / (lambda (int p^2)^2): the train's marginal."""
        p2, p4 = SHAPES[self.shape]
        ratio = DISTRIBUTIONS[self.distribution]
        return 3.0 + ratio * p4 / (self.rate * self.duration * p2**2)

    def features(self):
        # the main lobe of |P|^2, about 1/D wide, centred on f = 0
        return ((0.0, 1.0 / self.duration),)

    # --------------------------------------------------------------- sampling
    def draw(self, span: float, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """Arrival times (s) on [-D, span) and signed peaks (m/s^2) of one realisation.

        Pulses that start up to D before t = 0 are included, so that the
        train is stationary from t = 0.
        """
        d = self.duration
        count = rng.poisson(self.rate * (span + d))
        times = -d + (span + d) * rng.random(count)
        sign = np.where(rng.random(count) < 0.5, -1.0, 1.0)
        if self.distribution == "fixed":
            size = np.full(count, self.amplitude)
        elif self.distribution == "rayleigh":  # E[R^2] = 2 s^2
            size = rng.rayleigh(self.amplitude / math.sqrt(2.0), count)
        else:  # exponential: E[X^2] = 2 mean^2
            size = rng.exponential(self.amplitude / math.sqrt(2.0), count)
        return times, sign * size

    def _pulse_integral(self, s) -> np.ndarray:
        """int_0^s p(t) dt (s) of the unit pulse, for any s (0 before, all of it after)."""
        d = self.duration
        s = np.clip(s, 0.0, d)
        if self.shape == "rectangular":
            return s
        return (d / np.pi) * (1.0 - np.cos(np.pi * s / d))

    def step_integrals(self, times, peaks, n_steps: int, dt: float) -> np.ndarray:
        """int a dt over each step [j dt, (j + 1) dt) of the train (m/s), exactly.

        ``times`` and ``peaks`` from :meth:`draw`; each pulse adds
        A (I(t_{j+1} - t_k) - I(t_j - t_k)) to the steps it overlaps, I the
        pulse's running integral.
        """
        out = np.zeros(n_steps)
        if times.size == 0:
            return out
        first = np.maximum(np.floor(times / dt).astype(np.int64), 0)
        last = np.minimum(np.floor((times + self.duration) / dt).astype(np.int64), n_steps - 1)
        width = int(np.max(last - first)) + 1 if np.any(last >= first) else 0
        if width == 0:
            return out
        steps = first[:, None] + np.arange(width)[None, :]
        valid = steps <= last[:, None]
        edge = steps * dt - times[:, None]
        values = peaks[:, None] * (self._pulse_integral(edge + dt) - self._pulse_integral(edge))
        np.add.at(out, steps[valid], values[valid])
        return out

    def sample(self, duration: float, dt: float, n_paths: int = 1, seed=None) -> np.ndarray:
        """Paths of the train's base acceleration (m/s^2) at the times j dt, shape (n_paths, n).

        Each sample is the step integral over [j dt, (j + 1) dt) divided by
        dt (the step's mean acceleration).
        """
        rng = np.random.default_rng(seed)
        n = int(round(float(check_positive("duration", duration, "s")) / dt))
        rows = [self.step_integrals(*self.draw(n * dt, rng), n, dt) / dt for _ in range(n_paths)]
        return np.array(rows)

    def parameters(self) -> dict:
        return {
            "excitation": self.name,
            "rate": self.rate,
            "amplitude": self.amplitude,
            "duration": self.duration,
            "shape": self.shape,
            "distribution": self.distribution,
        }
