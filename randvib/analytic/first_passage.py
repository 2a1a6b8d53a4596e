"""First passage of a Gaussian response out of |z| < b: Poisson and Vanmarcke approximations.

For a zero-mean Gaussian displacement whose covariance with the velocity is
known at every time (the transient Lyapunov solution,
:mod:`randvib.analytic.transient`), the mean rate of out-crossings of the
two-sided barrier |z| = b follows from Rice's formula, and two standard
approximations turn it into the probability of reaching the barrier by time
t. Both are **approximate** (they assume independent crossings or clumps of
them) and are measured against Monte Carlo in the tests and the ``events``
study.

* **Rice's rate, non-stationary.** With E[z^2] = s_z^2, E[z'^2] = s_v^2 and
  E[z z'] = s_zv at time t, the velocity given z = b is Gaussian with mean
  ``mu = s_zv b / s_z^2`` and variance ``s^2 = s_v^2 - s_zv^2 / s_z^2``; the
  rate of up-crossings of b is
  ``nu+(t) = phi(b / s_z) / s_z * [s phi(mu / s) + mu Phi(mu / s)]``
  (phi, Phi the standard normal density and distribution), and by symmetry
  the rate out of |z| < b is ``nu_b = 2 nu+``.
* **Poisson**: crossings are independent events,
  ``P(t) = 1 - exp(-int_0^t nu_b dt)``; conservative (too high) for a
  narrow-band response, whose crossings come in clumps.
* **Vanmarcke** (1975, "On the distribution of the first-passage time for
  normal stationary random processes", J. Appl. Mech. 42, 215-220): the
  hazard ``h = nu_b (1 - exp(-sqrt(pi/2) q_e r)) / (1 - exp(-r^2/2))``
  with r = b / s_z and the effective bandwidth ``q_e = q^1.2``, q the
  spectral bandwidth ``sqrt(1 - l1^2 / (l0 l2))`` of the displacement (its
  spectral moments l_j = int (2 pi f)^j S_z(f) df); used here with the
  stationary bandwidth of the linear system under the stationary excitation
  (the envelope scales the spectrum, not its shape), the usual choice for a
  slowly modulated input (Corotis, Vanmarcke and Cornell 1972).
"""

from __future__ import annotations

import numpy as np
from scipy import special

from randvib.analytic.linear_response import frequency_rule
from randvib.models.excitation import Excitation
from randvib.models.state_space import StateSpace


def outcrossing_rate(z2, zv, v2, barrier) -> np.ndarray:
    """Rice's mean rate (1/s) of crossings out of |z| < ``barrier`` (both sides).

    Parameters
    ----------
    z2, zv, v2 : array_like
        E[z^2] (m^2), E[z z'] (m^2/s), E[z'^2] ((m/s)^2) of a zero-mean Gaussian (z, z').
    barrier : float
        b (m), > 0.

    Returns
    -------
    ndarray
        nu_b = 2 nu+ (1/s); 0 where z has no spread yet.
    """
    z2, zv, v2 = (np.asarray(x, dtype=float) for x in (z2, zv, v2))
    spread = z2 > 0
    safe = np.where(spread, z2, 1.0)
    sz = np.sqrt(safe)
    mu = zv * barrier / safe
    s = np.sqrt(np.maximum(v2 - zv * zv / safe, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(s > 0, mu / np.where(s > 0, s, 1.0), np.sign(mu) * np.inf)
    # E[z'+ | z = b] = s phi(mu/s) + mu Phi(mu/s); for s = 0 it is max(mu, 0)
    conditional = np.where(
        s > 0,
        s * np.exp(-0.5 * np.where(np.isfinite(ratio), ratio, 0.0) ** 2) / np.sqrt(2 * np.pi)
        + mu * special.ndtr(ratio),
        np.maximum(mu, 0.0),
    )
    with np.errstate(over="ignore"):  # a barrier beyond float64's square is never crossed
        exponent = -0.5 * np.square(np.asarray(barrier, dtype=float)) / safe
    density = np.exp(exponent) / (sz * np.sqrt(2 * np.pi))
    return np.where(spread, 2.0 * density * conditional, 0.0)


def vanmarcke_hazard(rate, z2, barrier, bandwidth) -> np.ndarray:
    """Vanmarcke's hazard (1/s) from the out-crossing ``rate`` (:func:`outcrossing_rate`).

    ``h = rate (1 - exp(-sqrt(pi/2) q^1.2 r)) / (1 - exp(-r^2/2))``,
    r = b / sqrt(E[z^2]), q the spectral ``bandwidth`` (0 < q <= 1).
    """
    z2 = np.asarray(z2, dtype=float)
    spread = z2 > 0
    r = barrier / np.sqrt(np.where(spread, z2, 1.0))
    clumping = -np.expm1(-np.sqrt(np.pi / 2) * bandwidth**1.2 * r) / -np.expm1(-0.5 * r * r)
    return np.where(spread, np.asarray(rate, dtype=float) * clumping, 0.0)


def _cumulative(times, rate) -> np.ndarray:
    """int_0^t rate dt at ``times`` (from t = 0), trapezoid rule."""
    times = np.asarray(times, dtype=float)
    rate = np.asarray(rate, dtype=float)
    return np.concatenate([[0.0], np.cumsum(0.5 * np.diff(times) * (rate[1:] + rate[:-1]))])


def probability_from_hazard(times, hazard) -> np.ndarray:
    """P(reached by t) = 1 - exp(-int_0^t h), trapezoid rule on ``times`` (from t = 0)."""
    return -np.expm1(-_cumulative(times, hazard))


def crossing_bound(times, rate, start_beyond: float = 0.0) -> np.ndarray:
    """Rice's upper bound on P(reached by t): ``start_beyond + int_0^t rate dt``, at most 1.

    The probability of at least one out-crossing is at most their expected
    number (Markov's inequality), whatever their clumping; ``start_beyond``
    is P(|z(0)| > b) (0 from rest). ``rate`` is :func:`outcrossing_rate` on
    ``times`` (from t = 0), integrated by the trapezoid rule.
    """
    return np.minimum(1.0, start_beyond + _cumulative(times, rate))


def spectral_bandwidth(block: StateSpace, excitation: Excitation, output: str = "z") -> float:
    """Vanmarcke's bandwidth q = sqrt(1 - l1^2 / (l0 l2)) of a block's stationary output.

    The spectral moments l_j = int_0^inf (2 pi f)^j |H(f)|^2 S(f) df by the
    quadrature of :func:`randvib.analytic.linear_response.frequency_rule`.
    q is near 0 for a narrow-band response, 1 for white noise.
    """
    nodes, weights = frequency_rule(block, excitation)
    response = np.abs(block.frequency_response(nodes)[block.output(output)]) ** 2
    density = response * excitation.psd(nodes) * weights
    omega = 2.0 * np.pi * nodes
    l0, l1, l2 = (float(np.sum(density * omega**j)) for j in range(3))
    return float(np.sqrt(max(1.0 - l1 * l1 / (l0 * l2), 0.0)))
