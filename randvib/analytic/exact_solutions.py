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
* The free mass (k = k3 = 0) with Coulomb friction: the velocity decouples
  and has the Caughey-Dienes density exp(-(4/(S m))(c v^2/2 + Fc |v|)).
* Stationary energy balance (Ito's rule on the mechanical energy, any
  stiffness, any memoryless friction): c E[v^2] + E[v F(v)] = S m / 4.
* The linear oscillator from rest under white noise switched on at t = 0
  (Caughey and Stumpf 1961): its second moments at every time and the
  integral of E[v^2] over an event, in closed form.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy import integrate, special

from randvib._validation import check_nonnegative, check_positive
from randvib.models.potential import Potential


def linear_velocity_variance(m, c, psd):
    """E[v^2] = S m / (4 c) ((m/s)^2) of the linear oscillator (paper Eq. 20)."""
    return np.asarray(psd) * np.asarray(m) / (4.0 * np.asarray(c))


def linear_displacement_variance(m, c, k, psd):
    """E[z^2] = S m^2 / (4 c k) (m^2) of the linear oscillator."""
    return linear_velocity_variance(m, c, psd) * np.asarray(m) / np.asarray(k)


def _gibbs_weight(m, c, k, k3, psd):
    """(weight(x), z_hi) of the Gibbs displacement density on x = z / z_hi in [0, 1].

    weight = exp(-(U(z) - min U) / T), T = m sigma_v^2 = S m^2 / (4 c), for any
    confining U = k z^2/2 + k3 z^4/4 (monostable, bistable, pure cubic);
    z_hi is the outer turning point 80 T above the minimum, where the density
    is exp(-80) of its peak.
    """
    m, c, psd = (float(check_positive(n, x)) for n, x in (("m", m), ("c", c), ("psd", psd)))
    potential = Potential(float(k), float(k3))
    potential.require("the Gibbs density")
    temperature = m * linear_velocity_variance(m, c, psd)  # m sigma_v^2 (J)
    low = float(potential.minimum)
    z_hi = float(potential.outer_turning_point(low + 80.0 * temperature))
    # In x = z / z_hi: U / T = a x^2/2 + eps x^4/4, shifted by its minimum.
    a = float(k) * z_hi**2 / temperature
    eps = float(k3) * z_hi**4 / temperature
    shift = low / temperature

    def weight(x):
        return np.exp(-(0.5 * a * x * x + 0.25 * eps * x**4 - shift))

    return weight, z_hi, potential


def _gibbs_integral(weight, lo, potential, z_hi, f=None):
    """int_lo^1 f(x) weight(x) dx, split at the well so quad sees the peak."""
    wells = [w / z_hi for w in potential.wells if lo < w / z_hi < 1.0]
    g = weight if f is None else (lambda x: f(x) * weight(x))
    return integrate.quad(g, lo, 1.0, points=wells or None, epsabs=0, epsrel=1e-12, limit=400)[0]


def gibbs_displacement_moment(m, c, k, k3, psd, power: int = 2) -> float:
    """E[z^power] under the exact stationary density without friction.

    p(z) ∝ exp(-(k z^2/2 + k3 z^4/4) / (m sigma_v^2)), sigma_v^2 = S m/(4c),
    for any confining potential (monostable, bistable k < 0 < k3, pure cubic
    k = 0); by adaptive quadrature in z / z_hi, z_hi the outer turning point
    80 T above the potential's minimum. Odd powers are zero by symmetry.
    """
    m, c, psd = (float(check_positive(n, x)) for n, x in (("m", m), ("c", c), ("psd", psd)))
    return _gibbs_moment(m, c, float(k), float(k3), psd, power)


@functools.lru_cache(maxsize=256, typed=True)
def _gibbs_moment(m: float, c: float, k: float, k3: float, psd: float, power: int) -> float:
    """:func:`gibbs_displacement_moment` of checked floats, remembered.

    A simulation asks for the same moment three times (the step check's stiffness,
    the companion's start, its control's mean) and a sweep or a seed loop asks again
    for every batch; each is two adaptive quadratures (about 1 ms of CPU).
    """
    weight, z_hi, potential = _gibbs_weight(m, c, k, k3, psd)
    num = _gibbs_integral(weight, 0.0, potential, z_hi, lambda x: x**power)
    den = _gibbs_integral(weight, 0.0, potential, z_hi)
    return float(num / den * z_hi**power)


def gibbs_exceedance(m, c, k, k3, psd, stroke) -> float:
    """P(|z| > stroke) under the exact stationary density without friction.

    The density of :func:`gibbs_displacement_moment`; ``stroke`` (m) > 0.
    """
    stroke = float(check_positive("stroke", stroke, "m"))
    weight, z_hi, potential = _gibbs_weight(m, c, k, k3, psd)
    if stroke >= z_hi:
        return 0.0  # beyond the density's exp(-80) edge
    tail = _gibbs_integral(weight, stroke / z_hi, potential, z_hi)
    return float(tail / _gibbs_integral(weight, 0.0, potential, z_hi))


def caughey_dienes_velocity_density(m, c, fc, psd, v):
    """Stationary velocity density (s/m) of the free mass with Coulomb friction.

    With k = k3 = 0 the velocity obeys its own SDE,
    dv = -(c v + Fc sgn v)/m dt + sqrt(S/2) dW, whose zero-flux stationary
    density (Caughey and Dienes, 1961) is

        p(v) ∝ exp(-(4/(S m)) (c v^2/2 + Fc |v|)),

    i.e. exp(-2 m Phi(v) / D_F) with the force potential Phi = c v^2/2 + Fc|v|
    and the force-noise intensity D_F = m^2 S/2 (for c > 0, Fc = 0 the
    Gaussian of variance S m/(4c), Eq. 20). c >= 0, Fc >= 0, not both zero.
    """
    m, psd = (float(check_positive(n, x)) for n, x in (("m", m), ("psd", psd)))
    c, fc = (float(check_nonnegative(n, x)) for n, x in (("c", c), ("fc", fc)))
    if c == 0 and fc == 0:
        raise ValueError("`c` and `fc` are both 0: the free mass has no stationary velocity")
    beta = 4.0 / (psd * m)

    def unnormalised(u):
        return np.exp(-beta * (0.5 * c * u * u + fc * np.abs(u)))

    # The exponent reaches 80 at v_hi; beyond it the density is negligible.
    v_hi = (np.sqrt(fc**2 + 160.0 * c / beta) - fc) / c if c > 0 else 80.0 / (beta * fc)
    half = integrate.quad(unnormalised, 0.0, v_hi, epsabs=0, epsrel=1e-13, limit=200)[0]
    return unnormalised(np.asarray(v, dtype=float)) / (2.0 * half)


def caughey_dienes_moments(m, c, fc, psd) -> tuple[float, float]:
    """(E[v^2], E|v|) ((m/s)^2, m/s) of :func:`caughey_dienes_velocity_density`.

    Closed form: on v > 0 the density is a Gaussian exp(-a (v + b/(2a))^2)
    cut at 0 (a = 2c/(S m), b = 4 Fc/(S m)); with c = 0 it is Laplace,
    E[v^2] = 2/b^2, E|v| = 1/b.
    """
    m, psd = (float(check_positive(n, x)) for n, x in (("m", m), ("psd", psd)))
    c, fc = (float(check_nonnegative(n, x)) for n, x in (("c", c), ("fc", fc)))
    if c == 0 and fc == 0:
        raise ValueError("`c` and `fc` are both 0: the free mass has no stationary velocity")
    a, b = 2.0 * c / (psd * m), 4.0 * fc / (psd * m)
    if a == 0:
        return 2.0 / b**2, 1.0 / b
    # v = u - mu with u > mu ~ N(0, 1/(2a)) truncated: moments via erfcx (no overflow).
    mu, s2 = b / (2.0 * a), 1.0 / (2.0 * a)
    ratio = np.sqrt(s2) * np.sqrt(2.0 / np.pi) / special.erfcx(mu / np.sqrt(2.0 * s2))
    mean = ratio - mu  # E[u | u > mu] - mu = E|v|
    second = s2 + mu * ratio - 2.0 * mu * ratio + mu * mu  # E[(u - mu)^2 | u > mu]
    return float(second), float(mean)


def _underdamped(m, c, k):
    """(omega_n (rad/s), zeta, omega_d (rad/s)) of an underdamped linear oscillator."""
    m, c, k = (float(check_positive(n, x)) for n, x in (("m", m), ("c", c), ("k", k)))
    omega = np.sqrt(k / m)
    zeta = c / (2.0 * np.sqrt(k * m))
    if not zeta < 1.0:
        raise ValueError(
            f"the closed form is for an underdamped oscillator: zeta = c / (2 sqrt(k m)) = "
            f"{zeta:.6g} must be < 1"
        )
    return omega, zeta, omega * np.sqrt(1.0 - zeta * zeta)


def caughey_stumpf_moments(m, c, k, psd, t):
    """Second moments of the linear oscillator from rest under white noise switched on at t = 0.

    ``m z'' + c z' + k z = -m a`` with E[a(t1) a(t2)] = (S/2) delta(t2 - t1)
    for t >= 0 and z(0) = z'(0) = 0 (Caughey and Stumpf 1961, "Transient
    response of a dynamic system under random excitation", J. Appl. Mech.
    28, 563-566). With omega_n^2 = k/m, 2 zeta omega_n = c/m,
    omega_d = omega_n sqrt(1 - zeta^2) and r = zeta omega_n / omega_d::

        E[z^2] = S/(8 zeta omega_n^3) {1 - e^(-2 zeta omega_n t) [1 + r sin(2 omega_d t) + 2 r^2 sin^2(omega_d t)]}
        E[v^2] = S/(8 zeta omega_n) {1 - e^(-2 zeta omega_n t) [1 - r sin(2 omega_d t) + 2 r^2 sin^2(omega_d t)]}
        E[z v] = (S/4) e^(-2 zeta omega_n t) sin^2(omega_d t) / omega_d^2

    (E[z v] = d E[z^2]/dt / 2), tending to the stationary S m^2/(4 c k) and
    S m/(4 c). Underdamped oscillators (zeta < 1) only.

    Parameters
    ----------
    m, c, k : float
        Mass (kg), damping (Ns/m), stiffness (N/m), all > 0, zeta < 1.
    psd : float
        One-sided PSD S of the base acceleration ((m/s^2)^2/Hz).
    t : array_like
        Times since the noise was switched on (s), >= 0.

    Returns
    -------
    z2, zv, v2 : ndarray
        E[z^2] (m^2), E[z z'] (m^2/s) and E[z'^2] ((m/s)^2) at ``t``.
    """
    omega, zeta, omega_d = _underdamped(m, c, k)
    psd = float(check_positive("psd", psd, "(m/s^2)^2/Hz"))
    t = check_nonnegative("t", t, "s")
    r = zeta * omega / omega_d
    decay = np.exp(-2.0 * zeta * omega * t)
    sin2 = np.sin(2.0 * omega_d * t)
    square = np.sin(omega_d * t) ** 2
    z2 = psd / (8.0 * zeta * omega**3) * (1.0 - decay * (1.0 + r * sin2 + 2 * r * r * square))
    v2 = psd / (8.0 * zeta * omega) * (1.0 - decay * (1.0 - r * sin2 + 2 * r * r * square))
    zv = 0.25 * psd * decay * square / omega_d**2
    return z2, zv, v2


def caughey_stumpf_velocity_integral(m, c, k, psd, t_end):
    """int_0^T E[z'^2(t)] dt ((m/s)^2 s) of :func:`caughey_stumpf_moments`, in closed form.

    With a = 2 zeta omega_n, Omega = 2 omega_d and r = zeta omega_n / omega_d,
    E[v^2] = sigma_v^2 {1 - e^(-a t) [(1 + r^2) - r sin(Omega t) - r^2 cos(Omega t)]}
    integrates term by term; times c_e it is the expected electrical energy
    harvested from t = 0 to T (J).
    """
    omega, zeta, omega_d = _underdamped(m, c, k)
    psd = float(check_positive("psd", psd, "(m/s^2)^2/Hz"))
    big_t = check_nonnegative("t_end", t_end, "s")
    r = zeta * omega / omega_d
    a, big_omega = 2.0 * zeta * omega, 2.0 * omega_d
    decay = np.exp(-a * big_t)
    norm = a * a + big_omega * big_omega
    plain = -np.expm1(-a * big_t) / a
    sine = big_omega - decay * (
        a * np.sin(big_omega * big_t) + big_omega * np.cos(big_omega * big_t)
    )
    sine /= norm
    cosine = a + decay * (big_omega * np.sin(big_omega * big_t) - a * np.cos(big_omega * big_t))
    cosine /= norm
    sigma_v2 = psd / (8.0 * zeta * omega)
    return sigma_v2 * (big_t - ((1.0 + r * r) * plain - r * sine - r * r * cosine))
