"""Base acceleration given as a signal: synthesised Gaussian paths and measured records.

The compiled kernel (:mod:`randvib.montecarlo.kernel`) integrates the device
with an additive velocity increment per step. Under white noise that
increment is sqrt(S/2) dW; when the base acceleration y(t) is a known signal
it is exactly ``-int_{t_n}^{t_n + dt} y(t) dt`` (paper Eq. 1, m z'' = ... -
m y''), which the kernel takes through its given-increments path with unit
amplitude. Three sources provide those increments, path by path:

* :class:`SynthesisedInput` - a stationary Gaussian process with a
  non-rational spectrum (band-limited, tabulated), synthesised in the
  frequency domain (:func:`randvib.models.excitation.synthesised_increments`)
  with each path's amplitudes from its own compiled stream
  (:func:`randvib.montecarlo.rng.path_normals`, keyed by (synthesis seed,
  path), the synthesis seed derived from ``seed`` so that these streams are
  not the kernel's): results do not depend on batching or threads, and
  batches bound the memory;
* :class:`TranslatedInput` - a non-Gaussian translation process
  (:class:`randvib.models.translation.Translated`): its Gaussian
  synthesised from the same streams, translated, integrated by the
  midpoint rule;
* :class:`RecordedInput` - a measured record, linearly interpolated between
  its samples, cut into segments that become the paths of
  :func:`randvib.montecarlo.on_record.monte_carlo_on_record`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from randvib.models.excitation import Excitation, Measured, synthesised_increments
from randvib.montecarlo.kernel import LANES
from randvib.montecarlo.rng import path_normals

#: Spawn key that separates the synthesis streams from everything else seeded by ``seed``.
SYNTHESIS_KEY = 0x53594E54  # "SYNT"
#: Input samples held at once (per batch of paths): 2^23 floats, 64 MiB, plus the FFT's copy.
MAX_INPUT_SAMPLES = 2**23


def batch_paths(n_steps: int) -> int:
    """Paths per batch so that one batch's input stays within :data:`MAX_INPUT_SAMPLES`."""
    return max(LANES, MAX_INPUT_SAMPLES // max(n_steps, 1) // LANES * LANES)


def synthesis_seed(seed: int) -> int:
    """The seed of the synthesis streams: (seed, SYNTHESIS_KEY) hashed to 64 bits.

    Path i's amplitudes are the normals of stream (synthesis_seed(seed), i),
    distinct from the kernel's stream (seed, i) that draws its random start.
    """
    sequence = np.random.SeedSequence(seed, spawn_key=(SYNTHESIS_KEY,))
    return int(sequence.generate_state(1, np.uint64)[0])


def path_amplitudes(seed: int, first: int, count: int, n: int) -> np.ndarray:
    """The standard normals behind the synthesised input of paths ``first`` to ``first + count - 1``."""
    return path_normals(synthesis_seed(seed), count, 2 * (n // 2 + 1), first)


@dataclass(frozen=True)
class SynthesisedInput:
    """Velocity increments (m/s) of synthesised Gaussian base acceleration.

    Attributes
    ----------
    excitation : Excitation
        Non-rational spectrum (band-limited, tabulated), zero above 1/(2 dt).
    n_steps : int
        Steps per path; the synthesis period is n_steps dt (the whole path,
        burn-in included), so its frequency bins are 1/(n_steps dt) apart.
    dt : float
        Step (s).
    seed : int
        Seed of the run; path i's input comes from :func:`path_amplitudes` (seed, i).
    """

    excitation: Excitation
    n_steps: int
    dt: float
    seed: int

    def __call__(self, first: int, count: int) -> np.ndarray:
        """Increments of paths ``first`` to ``first + count - 1``, shape (count, n_steps)."""
        normals = path_amplitudes(self.seed, first, count, self.n_steps)
        return -synthesised_increments(self.excitation, self.n_steps, self.dt, normals)


@dataclass(frozen=True)
class TranslatedInput:
    """Velocity increments (m/s) of a non-Gaussian translation process, path by path.

    The Gaussian y with ITAM's corrected spectrum is synthesised per path from
    the same streams as :class:`SynthesisedInput` (:func:`path_amplitudes`),
    at the steps' midpoints, translated, x = sigma g(y)
    (:class:`randvib.models.translation.Translated`), and integrated over each
    step by the midpoint rule: -dt x((j + 1/2) dt) (second order in dt, the
    scheme's order; x is a pointwise function of y, whose exact step
    integral has no closed form).

    Attributes
    ----------
    excitation : Translated
    n_steps : int
        Steps per path; the synthesis period is n_steps dt.
    dt : float
        Step (s); 1/(2 dt) must reach the translation's top frequency.
    seed : int
    """

    excitation: Excitation
    n_steps: int
    dt: float
    seed: int

    def __call__(self, first: int, count: int) -> np.ndarray:
        """Increments of paths ``first`` to ``first + count - 1``, shape (count, n_steps)."""
        normals = path_amplitudes(self.seed, first, count, self.n_steps)
        x = self.excitation.values(self.n_steps, self.dt, normals, offset=0.5 * self.dt)
        return -self.dt * x


@dataclass(frozen=True)
class RecordedInput:
    """Velocity increments (m/s) of a measured record, one segment per path.

    The record (mean removed) is linearly interpolated between its samples
    and integrated exactly over each of the ``substeps`` device steps per
    sample interval. Path i covers the record's sample intervals
    ``[i L, i L + n_burn + L)``: its first ``n_burn`` intervals are the
    record just before its window, so each window ``[n_burn + i L,
    n_burn + (i + 1) L)`` starts from the state the record itself drove the
    device into, and the windows tile the record after the first burn-in.

    Attributes
    ----------
    acceleration : ndarray
        The record's base acceleration (m/s^2), mean removed.
    substeps : int
        Device steps per sample interval.
    n_burn : int
        Sample intervals of burn-in before each window.
    window : int
        Sample intervals L of each window.
    dt : float
        Device step (s): the record's step / substeps.
    """

    acceleration: np.ndarray
    substeps: int
    n_burn: int
    window: int
    dt: float

    @classmethod
    def cut(cls, record: Measured, segments: int, burn_in: float, substeps: int) -> RecordedInput:
        """Split ``record`` into ``segments`` windows after ``burn_in`` seconds (whole samples)."""
        n_burn = int(round(burn_in / record.dt))
        window = (record.time.size - 1 - n_burn) // segments
        if window < 1:
            raise ValueError(
                f"the record's {record.time.size} samples hold no window of {segments} segments "
                f"after a burn-in of {burn_in!r} s; use fewer segments or a shorter burn-in"
            )
        acceleration = record.acceleration - np.mean(record.acceleration)
        return cls(acceleration, substeps, n_burn, window, record.dt / substeps)

    @property
    def n_steps(self) -> int:
        """Device steps per path, burn-in included."""
        return (self.n_burn + self.window) * self.substeps

    def __call__(self, first: int, count: int) -> np.ndarray:
        """Increments of segments ``first`` to ``first + count - 1``, shape (count, n_steps)."""
        m = self.substeps
        fraction = (np.arange(m) + 0.5) / m  # midpoint of each sub-step: exact for a line
        out = np.empty((count, self.n_steps))
        for row, i in enumerate(range(first, first + count)):
            a = self.acceleration[i * self.window : i * self.window + self.n_burn + self.window + 1]
            lines = a[:-1, None] + np.diff(a)[:, None] * fraction[None, :]
            out[row] = -self.dt * lines.ravel()
        return out
