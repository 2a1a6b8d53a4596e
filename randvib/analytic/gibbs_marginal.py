"""The exact stationary law of the displacement under white noise: tails, crossings, quantiles.

With white base acceleration of one-sided PSD S, linear damping c, no
friction and a resistive (viscous) coupling, the stationary density of any
confining potential U(z) = k z^2/2 + k3 z^4/4 is Gibbs's (docs/conventions.md):

    p(z, v) ∝ exp(-(m v^2 / 2 + U(z)) / T),    T = m sigma_v^2 = S m^2 / (4 c),

z and v independent, v Gaussian with E[v^2] = S m / (4 c) (paper Eq. 20).
:class:`GibbsDisplacement` tabulates the tail P(|z| > d) of the marginal of z
to full relative precision at every level (the tail is summed from the outer
edge inwards, interval by interval with Gauss-Legendre rules, so that 1e-30
is as accurate as 0.5), which gives

* the stationary exceedance P(|z| > d);
* Rice's rate of up-crossings of |z| through d, exact here because z and
  z' are independent: nu = 2 p_z(d) sigma_v / sqrt(2 pi) (both ends);
* the quantile transform z = F^-1(Phi(xi)) of a standard normal xi: the
  exact stationary start of the rare-event estimators
  (:mod:`randvib.montecarlo.path_simulator`), whose random vector is
  standard normal.
"""

from __future__ import annotations

import numpy as np
from scipy import interpolate, special

from randvib._validation import check_positive
from randvib.models.potential import Potential

#: Intervals of the tabulated tail on [0, z_hi], and Gauss-Legendre nodes per interval.
TAIL_INTERVALS = 4096
GAUSS_NODES = 8
#: The table ends where the density is exp(-EDGE) of its peak (the exceedance there, ~1e-35).
EDGE = 80.0


class GibbsDisplacement:
    """The stationary marginal of z of a friction-free device under white noise.

    Parameters
    ----------
    m, c : float
        Mass (kg) and total linear damping c_m + c_e (Ns/m), > 0.
    k, k3 : float
        Potential U = k z^2/2 + k3 z^4/4 (N/m, N/m^3); confining.
    psd : float
        One-sided PSD S of the white base acceleration ((m/s^2)^2/Hz), > 0.
    """

    def __init__(self, m, c, k, k3, psd):
        m, c, psd = (float(check_positive(n, x)) for n, x in (("m", m), ("c", c), ("psd", psd)))
        self.potential = Potential(float(k), float(k3))
        self.potential.require("the Gibbs density")
        self.temperature = m * psd * m / (4.0 * c)  # T = m sigma_v^2 (J)
        self.velocity_std = float(np.sqrt(psd * m / (4.0 * c)))
        low = float(self.potential.minimum)
        self.z_hi = float(self.potential.outer_turning_point(low + EDGE * self.temperature))
        self._shift = low
        edges = np.linspace(0.0, self.z_hi, TAIL_INTERVALS + 1)
        nodes, weights = np.polynomial.legendre.leggauss(GAUSS_NODES)
        half = 0.5 * np.diff(edges)
        points = 0.5 * (edges[:-1] + edges[1:])[:, None] + half[:, None] * nodes[None, :]
        pieces = np.sum(self._weight(points) * weights[None, :], axis=1) * half
        # tail[i] = int_{edges[i]}^{z_hi}: summed from the edge inwards (relative precision)
        tail = np.concatenate([np.cumsum(pieces[::-1])[::-1], [0.0]])
        self._half_mass = float(tail[0])  # int_0^inf of the unnormalised density
        self._edges = edges[:-1]
        self._log_tail = np.log(tail[:-1] / self._half_mass)  # log P(|z| > edge)
        # z as a function of log P(|z| > z): monotone, interpolated shape-preserving
        self._quantile = interpolate.PchipInterpolator(self._log_tail[::-1], self._edges[::-1])

    def _weight(self, z):
        """exp(-(U(z) - min U) / T): the unnormalised density."""
        return np.exp(-(self.potential.energy(z) - self._shift) / self.temperature)

    def density(self, d) -> np.ndarray:
        """p_z(d) (1/m), the normalised stationary density of z."""
        return self._weight(np.asarray(d, dtype=float)) / (2.0 * self._half_mass)

    def exceedance(self, d) -> np.ndarray:
        """P(|z| > d) for d >= 0 (m): the interval holding d from the table, the rest exactly."""
        d = np.abs(np.asarray(d, dtype=float))
        inside = d < self.z_hi
        i = np.clip(np.searchsorted(self._edges, d, side="right") - 1, 0, self._edges.size - 1)
        lo = self._edges[i]
        nodes, weights = np.polynomial.legendre.leggauss(GAUSS_NODES)
        # int_d^{lo + h} = (tail at lo) - int_lo^d, with int_lo^d by its own Gauss rule
        half = 0.5 * (d - lo)
        points = (0.5 * (lo + d))[..., None] + half[..., None] * nodes
        partial = np.sum(self._weight(points) * weights, axis=-1) * half / self._half_mass
        tail = np.exp(self._log_tail[i]) - partial
        return np.where(inside, np.maximum(tail, 0.0), 0.0)

    def upcrossing_rate(self, d) -> np.ndarray:
        """Mean rate (1/s) of up-crossings of |z| through d, both ends: 2 p_z(d) sigma_v / sqrt(2 pi).

        Rice's formula, exact here: z' is Gaussian and independent of z.
        """
        return 2.0 * self.density(d) * self.velocity_std / np.sqrt(2.0 * np.pi)

    def from_normal(self, xi) -> np.ndarray:
        """z = F^-1(Phi(xi)) (m): standard normals mapped to the stationary z, tails exact.

        Symmetric: z(-xi) = -z(xi); P(|z| > z(xi)) = 2 Phi(-|xi|), from the
        tail table (shape-preserving interpolation of z against the log tail).
        Normals beyond the table's edge (|xi| > 12) map to its edge.
        """
        xi = np.asarray(xi, dtype=float)
        log_tail = np.log(2.0) + special.log_ndtr(-np.abs(xi))
        log_tail = np.clip(log_tail, self._log_tail[-1], 0.0)
        return np.sign(xi) * self._quantile(log_tail)
