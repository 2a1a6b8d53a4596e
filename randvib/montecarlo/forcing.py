"""Tones and shocks in Monte Carlo: the kernel's deterministic and sampled forcing.

A tone ``a(t) = A cos(omega t + phi)`` and a shock train are base
accelerations added to whatever random input a run has (white noise, a
shaping filter, synthesised or translated input, a record). The compiled
kernel (:class:`randvib.montecarlo.kernel.Forcing`) adds their exact step
integral

    u_n = -int_{n dt}^{(n + 1) dt} a(t) dt
        = -sum_q 2 A_q sin(omega_q dt / 2) / omega_q cos(omega_q (n + 1/2) dt + phi_q)
          - (the shock train's step integral)

to the velocity (paper Eq. 1: m z'' = ... - m y''), half before and half
after each step of the scheme: one cosine per tone per step, arrays of tones
of any length in one compiled loop.

Each path owns its forcing, from streams keyed by (seed, path) that are not
the kernel's: a random phase phi_q = 2 pi Phi(n_q) from the normals of the
stream (:data:`TONE_KEY` seed, path) (:func:`randvib.montecarlo.rng.path_normals`),
and a shock train from numpy's generator on the seed sequence (seed,
:data:`SHOCK_KEY`, path). So results are bit-identical for any number of
threads and any batching, and a device run with and without a tone sees the
same noise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special

from randvib.analytic.linear_response import mechanical_block, output_variances
from randvib.models.shock import ShockTrain
from randvib.montecarlo import kernel
from randvib.montecarlo.rng import path_normals

#: Spawn key of the tones' phase streams ("TONE").
TONE_KEY = 0x544F4E45
#: Spawn key of the shock trains' streams ("SHOK").
SHOCK_KEY = 0x53484F4B


def _derived_seed(seed: int, key: int) -> int:
    sequence = np.random.SeedSequence(seed, spawn_key=(key,))
    return int(sequence.generate_state(1, np.uint64)[0])


@dataclass(frozen=True)
class ForcingInput:
    """The tones and the shock train of a run, as the kernel's :class:`~randvib.montecarlo.kernel.Forcing`.

    Attributes
    ----------
    tones : tuple of Tone
    shocks : ShockTrain or None
    n_steps : int
        Steps per path (burn-in included); t = 0 at the first.
    dt : float
        Step (s).
    seed : int
        The run's seed; path i's phases and shocks come from its own streams.
    """

    tones: tuple
    shocks: ShockTrain | None
    n_steps: int
    dt: float
    seed: int

    def phases(self, first: int, count: int) -> np.ndarray:
        """Phases (rad) of paths ``first .. first + count - 1``, shape (count, n_tones)."""
        n_tones = len(self.tones)
        out = np.empty((count, n_tones))
        random = [q for q, tone in enumerate(self.tones) if tone.random_phase]
        if random:
            normals = path_normals(_derived_seed(self.seed, TONE_KEY), count, n_tones, first)
            out[:, random] = 2.0 * np.pi * special.ndtr(normals[:, random])
        for q, tone in enumerate(self.tones):
            if not tone.random_phase:
                out[:, q] = np.deg2rad(tone.phase)
        return out

    def kicks(self, first: int, count: int) -> np.ndarray:
        """-int a dt of the shock train over every step of each path, shape (count, n_steps).

        Shape (0, 0) without shocks.
        """
        if self.shocks is None:
            return np.zeros((0, 0))
        seed = _derived_seed(self.seed, SHOCK_KEY)
        out = np.empty((count, self.n_steps))
        span = self.n_steps * self.dt
        for row, path in enumerate(range(first, first + count)):
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(path,)))
            times, peaks = self.shocks.draw(span, rng)
            out[row] = -self.shocks.step_integrals(times, peaks, self.n_steps, self.dt)
        return out

    def group(self, first: int, count: int) -> kernel.Forcing:
        """The kernel's argument group for paths ``first .. first + count - 1``."""
        omega = np.array([tone.omega for tone in self.tones], dtype=float)
        amplitude = np.array([tone.amplitude for tone in self.tones], dtype=float)
        gain = 2.0 * amplitude * np.sin(0.5 * omega * self.dt) / omega if omega.size else omega
        return kernel.Forcing(
            np.ascontiguousarray(omega),
            np.ascontiguousarray(gain, dtype=float),
            np.ascontiguousarray(self.phases(first, count)),
            np.ascontiguousarray(self.kicks(first, count)),
        )

    def acceleration(self, first: int, count: int) -> np.ndarray:
        """-u_n / dt: the forcing's mean base acceleration over each step (m/s^2), (count, n_steps).

        What the kernel adds, as an acceleration: for an independent
        simulator on the same input (tests) and for plots.
        """
        group = self.group(first, count)
        t = (np.arange(self.n_steps) + 0.5) * self.dt
        u = -np.einsum(
            "q,iqn->in",
            group.gain,
            np.cos(group.omega[None, :, None] * t[None, None, :] + group.phase[:, :, None]),
        )
        if group.kicks.shape[0]:
            u = u + group.kicks
        return -u / self.dt


def nyquist_refusal(tones, dt: float) -> str | None:
    """The refusal of a tone the time step cannot resolve (above 1/(2 dt)), or None."""
    nyquist = 0.5 / dt
    above = [tone for tone in tones if tone.frequency >= nyquist]
    if not above:
        return None
    tone = max(above, key=lambda t: t.frequency)
    return (
        f"the tone at {tone.frequency:g} Hz (`tone`) is at or above the simulation's Nyquist "
        f"frequency {nyquist:g} Hz (half the sampling rate of `dt` = {dt:g} s): use tones "
        f"below it, or `dt` < {0.5 / tone.frequency:.3g} s"
    )


def forcing_spread(run, linear, spread) -> tuple[float, float]:
    """(std z, std v) of a random start with the tones and shocks added to ``spread``.

    On the run's linearised device (m, c_eff, k_eff of ``linear``, a
    :class:`~randvib.montecarlo.step_check.LinearTestSystem`): each tone's
    mean square |H|^2 A^2 / 2 and the shock train's Campbell variance add
    to the random part's (independent inputs). A start, which the burn-in
    corrects; the free mass has no stationary z (0).
    """
    h = run.harvester
    forcing = run.forcing
    block = mechanical_block(float(h.m), float(linear.c_eff), float(linear.k_eff))
    z2, v2 = spread[0] ** 2, spread[1] ** 2
    for tone in forcing.tones:
        response = np.abs(block.frequency_response(tone.frequency)) ** 2 * tone.mean_square
        z2, v2 = z2 + float(response[0]), v2 + float(response[1])
    if forcing.shocks is not None:
        out = output_variances(block, forcing.shocks)
        z2, v2 = z2 + out["z"], v2 + out["v"]
    if h.potential.is_free:
        z2 = 0.0
    return float(np.sqrt(z2)), float(np.sqrt(v2))
