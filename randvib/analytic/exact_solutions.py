"""Exact results used as references: linear oscillator, Gibbs densities, schemes.

* Linear oscillator under white noise: E[v^2] = S m / (4 c) (paper Eq. 20) and
  E[z^2] = S m^2 / (4 c k).
* Without friction and with linear damping, the stationary density of the
  Duffing oscillator is exactly the Gibbs density
  p(z, v) ∝ exp(-(m v^2/2 + k z^2/2 + k3 z^4/4) / (m sigma_v^2)) with
  sigma_v^2 = S m / (4 c): velocity Gaussian, independent of z, for every k3.
* (The schemes' own exact recursions on the linear oscillator, the targets of
  a simulation at finite dt, live with the schemes:
  :func:`randvib.montecarlo.integrators.scheme_stationary_covariance`.)
* Stationary energy balance (Ito's rule on the mechanical energy, any
  stiffness, any memoryless friction): c E[v^2] + E[v F(v)] = S m / 4.
"""

from __future__ import annotations

import numpy as np
from scipy import integrate

from randvib._validation import check_nonnegative, check_positive


def linear_velocity_variance(m, c, psd):
    """E[v^2] = S m / (4 c) ((m/s)^2) of the linear oscillator (paper Eq. 20)."""
    return np.asarray(psd) * np.asarray(m) / (4.0 * np.asarray(c))


def linear_displacement_variance(m, c, k, psd):
    """E[z^2] = S m^2 / (4 c k) (m^2) of the linear oscillator."""
    return linear_velocity_variance(m, c, psd) * np.asarray(m) / np.asarray(k)


def gibbs_displacement_moment(m, c, k, k3, psd, power: int = 2) -> float:
    """E[z^power] under the exact stationary density without friction.

    p(z) ∝ exp(-(k z^2/2 + k3 z^4/4) / (m sigma_v^2)), sigma_v^2 = S m/(4c).
    Computed in the scaled variable x = z / sqrt(m sigma_v^2 / k) by adaptive
    quadrature, accurate from k3 = 0 to strongly quartic wells.
    """
    m, c, k, psd = (
        float(check_positive(n, x)) for n, x in (("m", m), ("c", c), ("k", k), ("psd", psd))
    )
    k3 = float(check_nonnegative("k3", k3))
    temperature = m * linear_velocity_variance(m, c, psd)  # m sigma_v^2 (J)
    scale = np.sqrt(temperature / k)
    eps = k3 * temperature / k**2  # quartic strength in scaled units

    def weight(x):
        return np.exp(-(0.5 * x * x + 0.25 * eps * x**4))

    upper = 40.0
    num = integrate.quad(
        lambda x: x**power * weight(x), 0, upper, epsabs=0, epsrel=1e-13, limit=200
    )[0]
    den = integrate.quad(weight, 0, upper, epsabs=0, epsrel=1e-13, limit=200)[0]
    return float(num / den * scale**power)
