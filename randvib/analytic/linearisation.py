"""Equivalent linearisation under white noise (paper Eq. 19-32): the route's fast path.

Statistical linearisation has one route,
:func:`randvib.analytic.statistical_linearisation.linearise`: under white
noise with a resistive coupling it takes the closed forms of this module
(:func:`white_noise_linearisation`, which broadcasts over arrays of
parameters and levels); under any other excitation, or with a circuit state,
the fixed point with the Lyapunov solution
(:func:`randvib.analytic.statistical_linearisation.statistical_linearisation`).

The nonlinear device is replaced by the linear oscillator
``m z'' + c_eq z' + k z = m w(t)`` (Eq. 18) whose damping satisfies the
statistical-linearisation condition (Eq. 19)

    c_eq = c + E[v F(v)] / E[v^2],   v ~ N(0, sigma_v^2),

together with the linear oscillator's velocity variance (Eq. 20)

    sigma_v^2 = S m / (4 c_eq).

Eliminating c_eq gives one scalar equation for sigma_v,

    c sigma_v^2 + E[v F(v)] = S m / 4,

which is the exact stationary energy balance of the nonlinear device with the
velocity's distribution replaced by a Gaussian. For Coulomb friction it has
the closed form of Eq. 30. The paper's Eq. 32 writes sigma_z^2 where the
velocity variance is meant; we use the velocity variance.

Potentials. c_eq and sigma_v^2 do not involve the spring, so under white
noise with a resistive circuit the velocity variance and the power are the
same for every potential (monostable, bistable, pure cubic, free mass).
Without friction that is exact: the Gibbs density makes the velocity
Gaussian with E[v^2] = S m/(4c) for any confining potential, and the free
mass's velocity is an Ornstein-Uhlenbeck process. With friction it carries
the Gaussian-velocity error of Eq. 30, whatever the potential.

The displacement is where the Gaussian closure fails for a double well.
k_eq = k + 3 k3 E[z^2] with E[z^2] = m sigma_v^2 / k_eq
(:func:`linear_displacement_variance`) puts one Gaussian at z = 0, on the
barrier, where the true density has two peaks at the wells +-z_w,
z_w^2 = -k/k3. At low noise (barrier k^2/(4 k3) >> T = m sigma_v^2) the
true E[z^2] -> z_w^2 but the closure gives k_eq -> 3 k3 T/|k| and
E[z^2] -> z_w^2 / 3: three times too small, and its stroke exceedance
erfc(s/sqrt(2 E[z^2])) is wrong accordingly (a stroke just outside the well
is reached about half the time in truth, rarely by the Gaussian). At high
noise (T >> barrier) the quartic dominates and the closure's error tends to
the pure-cubic one, E[z^2] low by 15 % (exact Gamma(3/4)/Gamma(1/4)
sqrt(4T/k3) against sqrt(T/(3 k3))). Both limits are tests
(tests/test_potentials.py). Use the FPK solvers for the displacement and the
stroke statistics of a double well.

Units: S is the one-sided PSD of the base acceleration in (m/s^2)^2/Hz with
E[w(t1) w(t2)] = (S/2) delta(t2 - t1) (Eq. 17).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from randvib._validation import check_choice, check_positive, scalar_or_array
from randvib.models.friction import coulomb_equivalent_damping
from randvib.models.harvester import Harvester

_BISECTION_STEPS = 200


@dataclass(frozen=True, eq=False)
class LinearisedDevice:
    """The numbers of a statistical linearisation (SI units).

    What :func:`~randvib.analytic.statistical_linearisation.linearise`
    returns; :class:`~randvib.analytic.statistical_linearisation.LinearisationResult`
    adds the harvester and the excitation. On the white-noise fast path the
    fields broadcast over array parameters and levels.

    Attributes
    ----------
    c_eq : float or ndarray
        Equivalent damping c + E[v F(v)] / E[v^2] (Ns/m), paper Eq. 19.
    k_eq : float or ndarray
        Equivalent stiffness k + 3 k3 E[z^2] (N/m); 0 for the free mass.
    velocity_variance : float or ndarray
        E[v^2] ((m/s)^2) of the linearised device.
    displacement_variance : float, ndarray or None
        E[z^2] (m^2); None for the free mass (not stationary).
    power_electrical : float or ndarray
        E[P_e] (W): c_e E[v^2], or from the circuit state ((R_L + R_C) E[i^2],
        E[V^2] / R_L).
    power_load : float, ndarray or None
        The share reaching R_L (W), when the harvester has a circuit.
    circuit_variance : float or None
        E[i^2] (A^2) or E[V^2] (V^2) of a circuit state; None without one.
    method : str
        How the variances were computed: ``white-noise`` (Eq. 20, the fast
        path), ``lyapunov`` or ``spectral`` (the fixed point).
    """

    c_eq: object
    k_eq: object
    velocity_variance: object
    displacement_variance: object
    power_electrical: object
    power_load: object
    circuit_variance: object
    method: str


def _solve_velocity_std(c, m, psd, mean_velocity_force):
    """Solve c s^2 + E_s[v F(v)] = S m / 4 for s = sigma_v by bisection in log s.

    The left side is increasing in s for any friction with v F(v) >= 0 whose
    Gaussian mean grows with s (all odd, non-decreasing F); bisection is then
    globally convergent, and 200 halvings of a bracket of at most 1e40 reach
    the last bit of a double.
    """
    target = psd * m / 4.0
    c_b, target = np.broadcast_arrays(c, target)
    # Upper bound: viscous only (friction can only lower the variance) or, with
    # c = 0, grow until the balance is exceeded.
    hi = np.where(c_b > 0, np.sqrt(target / np.where(c_b > 0, c_b, 1.0)), np.sqrt(target))
    for _ in range(200):
        residual = c_b * hi**2 + mean_velocity_force(hi) - target
        if np.all(residual >= 0):
            break
        hi = np.where(residual < 0, hi * 4.0, hi)
    lo = hi * 1e-20
    log_lo, log_hi = np.log(lo), np.log(hi)
    for _ in range(_BISECTION_STEPS):
        mid = 0.5 * (log_lo + log_hi)
        s = np.exp(mid)
        below = c_b * s**2 + mean_velocity_force(s) - target < 0
        log_lo = np.where(below, mid, log_lo)
        log_hi = np.where(below, log_hi, mid)
    return np.exp(0.5 * (log_lo + log_hi))


#: How :func:`equivalent_damping` computes E[v F(v)]: the values of ``expectation``.
EXPECTATIONS = ("auto", "closed-form", "fixed-point")


def equivalent_damping(harvester: Harvester, psd, expectation: str = "auto"):
    """Equivalent viscous damping c_eq (Ns/m), paper Eq. 19-20 and 30.

    Parameters
    ----------
    harvester : Harvester
        Device; its parameters may be arrays that broadcast with ``psd``.
    psd : array_like
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0.
    expectation : {"auto", "closed-form", "fixed-point"}
        How the Gaussian expectation E[v F(v)] of Eq. 19 is taken (not an
        analytic method in the sense of :func:`randvib.predict`: this is
        always equivalent linearisation). ``closed-form`` is the law's closed
        form where it declares one (Coulomb: Eq. 30; also no friction);
        ``fixed-point`` solves Eq. 19-20 with Gaussian expectations by
        quadrature, for any memoryless odd friction law; ``auto`` picks the
        closed form where it exists.

    Returns
    -------
    float or ndarray
        c_eq, broadcast over ``psd`` and the harvester's parameters.

    Examples
    --------
    >>> import randvib as rv
    >>> print(f"{rv.equivalent_damping(rv.preset('figure9'), 1.0):.5f} Ns/m")  # Eq. 30
    0.22949 Ns/m
    >>> tanh = rv.preset("figure9").updated(friction=rv.Tanh(0.0058, 4.8e8))
    >>> print(f"{rv.equivalent_damping(tanh, 1.0):.5f} Ns/m")  # Eq. 19-20, fixed point
    0.22949 Ns/m
    """
    psd = check_positive("psd", psd, "(m/s^2)^2/Hz")
    check_choice("expectation", expectation, EXPECTATIONS)
    harvester.require_resistive(
        "equivalent_damping (Eq. 19-30, a viscous c_e)", "randvib.statistical_linearisation"
    )
    friction = harvester.friction
    c = np.asarray(harvester.c, dtype=float)
    m = np.asarray(harvester.m, dtype=float)
    # The law declares its closed form (Coulomb: Eq. 30); none is Eq. 30 with Fc = 0.
    if friction is None:
        closed_form = coulomb_equivalent_damping(c, 0.0, psd, m)
    else:
        closed_form = friction.closed_form_equivalent_damping(c, psd, m)
    if expectation == "closed-form" and closed_form is None:
        raise ValueError(
            f"`expectation`='closed-form' (Eq. 30) exists only for Coulomb or no friction, "
            f"not {friction.name!r}; use 'fixed-point'"
        )
    if friction is not None and not friction.has_equivalent_damping:
        raise ValueError(
            f"equivalent linearisation needs a memoryless friction law; {friction.name!r} "
            "has internal state. Use randvib.simulate for it."
        )
    if closed_form is not None and expectation != "fixed-point":
        result = closed_form
    else:
        if friction is None:
            mean_vf = lambda s: 0.0 * s  # noqa: E731 - viscous only
        else:
            mean_vf = friction.mean_velocity_force
        sigma = _solve_velocity_std(c, m, psd, mean_vf)
        result = psd * m / (4.0 * sigma**2)
    result = np.broadcast_to(
        result, np.broadcast_shapes(np.shape(result), np.shape(psd), np.shape(m))
    )
    return scalar_or_array(np.array(result))


def linear_displacement_variance(harvester: Harvester, velocity_variance):
    """Gaussian-closure displacement variance (m^2) of the Duffing spring.

    Statistical linearisation of k z + k3 z^3 gives k_eq = k + 3 k3 sigma_z^2
    with sigma_z^2 = sigma_v^2 m / k_eq (linear oscillator), whose positive root
    is k_eq = (k + sqrt(k^2 + 12 k3 m sigma_v^2)) / 2: positive for any
    confining potential, k < 0 and k = 0 included (see the module docstring
    for how far it is off for a double well). The free mass (k_eq = 0) has
    no stationary displacement: inf.
    """
    k, k3, m = (np.asarray(x, dtype=float) for x in (harvester.k, harvester.k3, harvester.m))
    a = m * np.asarray(velocity_variance, dtype=float)
    k_eq = 0.5 * (k + np.sqrt(k**2 + 12.0 * k3 * a))
    with np.errstate(divide="ignore"):
        return a / k_eq


def white_noise_linearisation(harvester: Harvester, psd, expectation: str = "auto"):
    """The white-noise fast path of statistical linearisation, resistive coupling (Eq. 19-20).

    c_eq from :func:`equivalent_damping` (Eq. 30 in closed form for Coulomb
    friction), E[v^2] = S m / (4 c_eq) (Eq. 20), the Gaussian-closure spring
    (:func:`linear_displacement_variance`) and E[P_e] = c_e E[v^2] (Eq. 32).
    Broadcasts over ``psd`` and array-valued harvester parameters.

    Returns
    -------
    LinearisedDevice
        ``method`` is ``white-noise``; for the free mass E[z^2] is None and
        k_eq is 0.
    """
    c_eq = equivalent_damping(harvester, psd, expectation)
    vv = np.asarray(psd) * harvester.m / (4.0 * np.asarray(c_eq))  # Eq. 20
    if harvester.potential.is_free:
        zz, k_eq = None, np.zeros_like(vv)
    else:
        zz = linear_displacement_variance(harvester, vv)
        with np.errstate(invalid="ignore"):  # the free points of a grid: 0 * inf
            k_eq = np.where(np.isfinite(zz), harvester.k + 3.0 * harvester.k3 * zz, 0.0)
    power, load = linear_power(harvester, vv)
    return LinearisedDevice(
        c_eq=c_eq,
        k_eq=scalar_or_array(k_eq),
        velocity_variance=scalar_or_array(vv),
        displacement_variance=None if zz is None else scalar_or_array(zz),
        power_electrical=scalar_or_array(np.asarray(power)),
        power_load=None if load is None else scalar_or_array(np.asarray(load)),
        circuit_variance=None,
        method="white-noise",
    )


def linear_power(harvester: Harvester, velocity, state=None):
    """(electrical, load) power (W, or W/Hz for PSDs) from E[v^2] and the circuit's E[x^2].

    Resistive coupling (or a bare c_e): c_e E[v^2] (Eq. 32) and the load's
    share of it; a circuit state: the coupling's own powers of its mean
    square ``state``. The load power is None without a coupling.
    """
    coupling = harvester.electrical
    if coupling is None:
        return harvester.c_e * velocity, None
    if not coupling.is_dynamic:  # the former c_e E[v^2], to the same bits
        power = harvester.c_e * velocity
        return power, power * coupling.load_fraction
    return coupling.power_electrical(velocity, state), coupling.power_load(velocity, state)
