"""Importance sampling of the first passage by a change of drift towards the design points.

The rows xi of a path simulator (:mod:`randvib.montecarlo.path_simulator`)
are standard normal; shifting their mean by s changes the drift of the
Brownian motion by s_k / sqrt(dt) over step k (Girsanov), with likelihood
ratio phi(xi) / phi(xi - s) = exp(-s . xi + |s|^2 / 2).

For a linear device z_n = a_n . xi at every monitored state n, so the event
{z_n > D} is the half-space beyond the *design point* s_n = D a_n / |a_n|^2
(the most likely input, at distance beta_n = D / sigma_n from the origin,
sigma_n = |a_n|: in continuous time the impulse response run backwards from
t_n, the classical design-point excitation of a linear oscillator under white
noise), and {|z| reaches D in the window} is the union of these 2 (N + 1)
half-spaces (both signs, every state). The sampling density is the mixture of
the Gaussians centred on them, weighted as their probabilities Phi(-beta_n)
(Au and Beck 2001, "First excursion probabilities for linear systems by very
efficient importance sampling", Probabilistic Engineering Mechanics 16,
193-207, with shifted rather than truncated Gaussians), and each sample's
weight is

    w(xi) = 1 / sum_j pi_j exp(+-beta_j u_j(xi) - beta_j^2 / 2),    u_j = z_j(xi) / sigma_j,

evaluated from the linear response of the same row at every state
(:class:`~randvib.montecarlo.path_simulator.LinearSurrogate`), so that no
sum over thousands of dot products is needed.

For a nonlinear device (stiffening spring, friction, circuit, bridge) the
design points of its linearisation are scaled by the factor r that brings the
device itself to D along the middle state's design direction (bisection on
the simulator). The estimate stays unbiased for any r (the density covers
every row), but its weights may degenerate: the run reports the effective
sample size of the failing terms, (sum w)^2 / sum w^2, and the largest
weight's share, and :func:`randvib.first_passage` refuses the estimate when
they show that a few paths carry it (:data:`MIN_EFFECTIVE_SAMPLES`,
:data:`MAX_WEIGHT_SHARE`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special

__all__ = ["ImportanceDesign", "importance_batch"]

#: Fewer effective failing samples than this: the weights have degenerated (refused).
MIN_EFFECTIVE_SAMPLES = 30
#: One failing sample carrying more than this share of the estimate: refused.
MAX_WEIGHT_SHARE = 0.2
#: Largest amplitude factor r searched for a nonlinear device.
MAX_AMPLITUDE = 30.0


@dataclass(frozen=True)
class ImportanceDesign:
    """The sampling density: design directions of the monitored states and their distances.

    ``beta`` (per state) are the shifts' lengths (r D / sigma_n), ``weights`` the
    mixture's probabilities over the states (each split evenly between the signs),
    ``amplitude`` r (1 for a device whose response is linear in the rows).
    """

    surrogate: object
    beta: np.ndarray
    weights: np.ndarray
    amplitude: float

    @classmethod
    def of(cls, simulator) -> ImportanceDesign:
        """The design of ``simulator``; ValueError where it has no linear surrogate or its
        device cannot be brought to the stroke along the design direction."""
        surrogate = simulator.linear_surrogate
        if surrogate is None:
            raise ValueError(
                "method='importance' needs the input's Brownian increments (white noise or a "
                "filtered spectrum); a synthesised or recorded spectrum's input is not a "
                "change of drift: use method='subset'"
            )
        sigma = surrogate.sigma
        beta_linear = simulator.stroke / sigma
        log_p = special.log_ndtr(-beta_linear)
        weights = np.exp(log_p - np.max(log_p))
        weights /= weights.sum()
        amplitude = 1.0 if simulator.exactly_linear else _amplitude(simulator, surrogate)
        return cls(surrogate, amplitude * beta_linear, weights, amplitude)

    def direction(self, index: int) -> np.ndarray:
        """The unit design direction a_n / |a_n| of the monitored state ``index``."""
        a = self.surrogate.gradient(index)
        return a / np.linalg.norm(a)

    def sample(self, n: int, rng) -> np.ndarray:
        """``n`` rows from the mixture: a state and a sign drawn, then xi = eta + s."""
        states = rng.choice(self.weights.size, size=n, p=self.weights)
        signs = rng.choice((-1.0, 1.0), size=n)
        rows = rng.standard_normal((n, self.surrogate.n_start + self.surrogate.n_steps))
        for i, (state, sign) in enumerate(zip(states, signs, strict=True)):
            rows[i] += sign * self.beta[state] * self.direction(state)
        return rows

    def log_weight(self, rows) -> np.ndarray:
        """log phi(xi) / q(xi) of each row (log-sum-exp over the states and both signs)."""
        u = self.surrogate.responses(rows) / self.surrogate.sigma
        exponent = np.abs(self.beta * u)  # the sign pointing towards the row dominates
        # cosh(beta u) = exp(|beta u|) (1 + exp(-2 |beta u|)) / 2, each sign with weight 1/2
        terms = exponent + np.log1p(np.exp(-2.0 * exponent)) - np.log(2.0)
        terms += np.log(self.weights) - 0.5 * self.beta**2
        top = np.max(terms, axis=1)
        return -(top + np.log(np.sum(np.exp(terms - top[:, None]), axis=1)))


def _amplitude(simulator, surrogate) -> float:
    """r: the device's peak on the row r beta a_mid / |a_mid| equals D (bisection in r)."""
    middle = (surrogate.sigma.size - 1) // 2
    a = surrogate.gradient(middle)
    row = (simulator.stroke / np.linalg.norm(a) ** 2) * a  # the linear design point

    def peak(r):
        return float(simulator((r * row)[None, :]).peak[0])

    lo, hi = 0.0, 1.0
    while peak(hi) <= simulator.stroke:
        lo, hi = hi, 2.0 * hi
        if hi > MAX_AMPLITUDE:
            raise ValueError(
                f"method='importance': the device does not reach the stroke along its "
                f"linearisation's design point even {MAX_AMPLITUDE:g} times amplified: use "
                "method='subset'"
            )
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if peak(mid) <= simulator.stroke else (lo, mid)
    return hi


def importance_batch(simulator, design: ImportanceDesign, n: int, rng) -> dict:
    """``n`` weighted samples: each path's weighted indicator, fraction beyond and up-crossings.

    Returns a dict of arrays ``failed``, ``beyond``, ``upcrossings`` (weights applied).
    """
    rows = design.sample(n, rng)
    weight = np.exp(design.log_weight(rows))
    out = simulator(rows)
    return {
        "failed": weight * (out.peak > simulator.stroke),
        "beyond": weight * out.beyond,
        "upcrossings": weight * out.upcrossings,
    }


def weight_diagnostics(failed) -> tuple[float, float]:
    """(effective sample size, largest share) of the weighted failing terms."""
    failed = np.asarray(failed, dtype=float)
    total = float(np.sum(failed))
    if not total > 0:
        return 0.0, 1.0
    return total**2 / float(np.sum(failed**2)), float(np.max(failed)) / total
