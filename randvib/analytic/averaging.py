"""Energy-envelope stochastic averaging: power beyond equivalent linearisation.

Equivalent linearisation (paper Eq. 19-32) closes the exact stationary energy
balance (see docs/conventions.md; Ito's rule on the energy)

    c E[z'^2] + E[z' F(z')] = S m / 4                               (*)

with a Gaussian velocity. For Coulomb friction (*) reads
``c E[z'^2] + Fc E|z'| = S m / 4``, so E[P_e] = (c_e / c)(S m/4 - Fc E|z'|):
the power depends only on how well E|z'| is predicted, and linearisation
predicts it as sqrt(2/pi) sigma_v. That is wrong as soon as friction makes the
velocity non-Gaussian, and it cannot depend on k3. The paper (Sec. 6) leaves
"approximate solutions to the stationary FPK equation of a SDOF system with
Coulomb damping" for future work; this module builds the classical one.

Method (Stratonovich/Khasminskii energy-envelope averaging; Roberts & Spanos,
*Random Vibration and Statistical Linearization*, ch. 7; Zhu, *Nonlinear
Stochastic Dynamics and Control*, 2003). With per-unit-mass energy
``H = v^2/2 + G(z)``, ``G = (k z^2/2 + k3 z^4/4)/m``, gamma = c/m, f = F/m
and the SDE of docs/conventions.md (noise intensity D = S/2 on the velocity),

    dH = (-gamma v^2 - v f(v) + D/2) dt + sqrt(D) v dW     (Ito, exact).

When damping and friction are light, H varies slowly over one period T(H) of
the undamped orbit, and H is approximately the diffusion with orbit-averaged
drift and diffusion,

    m(H)       = -gamma <v^2>(H) - <v f>(H) + D/2,
    sigma^2(H) = D <v^2>(H),

``<g>(H) = (1/T) \\oint g dt``. Its stationary (zero-flux) density is

    p(H) = T(H) exp(-Psi(H)) / Z,
    Psi(H) = \\int_0^H [2 gamma/D + 8 J(H')/(D Phi(H'))] dH',

where ``Phi(H) = \\oint v dz`` is the orbit's area (dPhi/dH = T, so
<v^2> = Phi/T) and ``J(H) = \\int_0^A f(v(z)) dz`` the friction work over a
quarter orbit (Coulomb: f_c A, so <|v|> = 4A/T and <v f> = 4J/T). The joint
density is taken uniform in time along each orbit, p(z, v) = p(H)/T(H), so
E[g] = \\int p(H) <g>(H) dH.

Properties, each a test:

* Without friction p(H) is the exact Gibbs density T(H) exp(-2 gamma H/D):
  E[z'^2] = S m/(4c) for every k3, and E[z^2] is the exact Boltzmann value.
* The averaged density satisfies the energy balance (*) exactly (E[m(H)] = 0
  for the zero-flux density), so the identity holds to quadrature accuracy.
  (*) is therefore no check of accuracy; it does show that averaging and
  linearisation differ *only* in E[z' F(z')] (Coulomb: E|z'|), which
  averaging takes from a non-Gaussian velocity density that depends on k3.

Limit. The error of averaging is first order in the energy friction removes
per cycle, and k3 lowers that by raising the orbit frequency: the error
shrinks with k3 by about as much as the true change of power with k3 (0.04-
0.17 % on the study ``linearisation-vs-averaging``), so averaging gets the
sign of that interaction but overstates its size 1.5-5x. For the k3 change
use ``method="fpk-fast"`` (:func:`randvib.analytic.fokker_planck.fast_fpk_statistics`),
which explains why a next-order averaging was not pursued.

Potentials. Averaging is implemented for the monostable potential
(k > 0, k3 >= 0) only and refuses the others with a message naming the
methods that treat them (its declaration, :class:`Averaging`). A double well would need
orbits of two kinds, inside one well (energy below the barrier, two
disjoint orbits) and around both (above it), with a period that diverges
logarithmically at the barrier energy, and a matching condition for the
energy density there; the free mass has no orbits at all. The FPK solvers
treat every confining potential and the free mass; equivalent linearisation
gets the power of any potential exactly without friction.

Quadrature. On an orbit of amplitude A the substitution z = A sin(phi)
removes the turning-point singularities: dz/v = dphi / (omega q(phi)) with
``q = sqrt(1 + mu (1 + sin^2 phi)/2)``, mu = (k3/k) A^2, omega^2 = k/m, so

    T = (4/omega) \\int_0^{pi/2} dphi / q,
    Phi = 4 omega A^2 \\int_0^{pi/2} cos^2(phi) q dphi,
    T <z^2> = (4 A^2/omega) \\int_0^{pi/2} sin^2(phi) / q dphi,
    \\oint |v| dt = 4 A.

The integrands are analytic, pi-periodic functions of sin^2(phi) whose
singularities stay a fixed distance from the real axis for every mu in
[0, inf), so the midpoint rule converges geometrically, uniformly from tiny to
huge energies (16 nodes reach rounding). A follows in closed form from the
quartic G(A) = H. The energy integral runs over x = sqrt(H), in which all
integrands, Psi included, are smooth at the origin (Coulomb: Psi ~ x), with
composite Gauss-Legendre panels and a spectral integration matrix for the
cumulative integral Psi.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from randvib._validation import check_nonnegative, check_positive, scalar_or_array
from randvib.analytic.method import AnalyticMethod, Validity, white_level
from randvib.analytic.power_prediction import PowerPrediction
from randvib.models.friction import one_minus_tanh
from randvib.models.harvester import Harvester

__all__ = [
    "AVERAGING_ZETA_LIMIT",
    "Averaging",
    "AveragingResult",
    "AveragingValidityWarning",
    "OrbitAverages",
    "averaging_statistics",
    "energy_density",
    "orbit_averages",
]

#: Friction damping ratio above which averaging is flagged as unreliable.
#: Averaging is exact without friction, whatever the viscous damping (the
#: Gibbs density); its error comes from friction, which it treats as a slow
#: perturbation of the undamped orbits. The friction's equivalent damping
#: ratio zeta_f = (E[z' F] / E[z'^2]) / (2 sqrt(k_eq m)) measures the energy
#: friction removes per cycle relative to the energy stored. Against the FPK
#: reference (tests/test_fokker_planck.py; viscous damping ratios 0.02-0.44,
#: friction levels 4 Fc^2/(pi S m c) = 0.1-10) the error in E[z'^2] stayed
#: below 2.5 % for zeta_f <= 0.5, then grew slowly to 6 % at zeta_f = 8.
AVERAGING_ZETA_LIMIT = 0.5

# Midpoint nodes in phi on [0, pi/2]: sin^2 of them. Geometric convergence
# (see module docstring); 16 nodes are at rounding level for every mu.
_N_PHI = 16
_SIN2 = np.sin((np.arange(_N_PHI) + 0.5) * (0.5 * np.pi / _N_PHI)) ** 2

# Energy grid in x = sqrt(H): composite Gauss-Legendre on panels of [0, 1]
# scaled by x_max per point: uniform (width 0.1) above 0.1 and geometric below,
# down to 1e-6. The orbit quantities change character near x_t = omega /
# sqrt(k3/k) (quadratic to quartic potential), which can sit anywhere in
# [0, x_max]; a panel never exceeds its distance from the origin, so such a
# near-singularity at distance x_t is resolved wherever it falls.
_EDGES = np.concatenate(([0.0], np.geomspace(1e-6, 0.1, 11)[:-1], np.linspace(0.1, 1.0, 10)))
_N_PANELS = len(_EDGES) - 1
_N_GL = 12
_GL_T, _GL_W = np.polynomial.legendre.leggauss(_N_GL)
#: Psi at the end of the energy grid: the density there is exp(-70).
_PSI_END = 70.0
#: If Psi at x_max falls short of this (slowly decaying tanh friction), extend.
_PSI_ENOUGH = 45.0


def _integration_matrix(t: np.ndarray) -> np.ndarray:
    """Q[i, j] = int_{-1}^{t_i} l_j(s) ds for the Lagrange basis l_j on nodes t."""
    n = len(t)
    vander = np.polynomial.legendre.legvander(t, n - 1)
    coeffs = np.linalg.inv(vander)  # column j: Legendre coefficients of l_j
    antideriv = np.polynomial.legendre.legint(coeffs, lbnd=-1.0, axis=0)
    return np.polynomial.legendre.legval(t, antideriv).T


_GL_Q = _integration_matrix(_GL_T)
_HALF_UNIT = 0.5 * np.diff(_EDGES)  # panel half-widths
_X_UNIT = (_EDGES[:-1, None] + _HALF_UNIT[:, None] * (1.0 + _GL_T[None, :])).ravel()
_W_UNIT = (_HALF_UNIT[:, None] * _GL_W[None, :]).ravel()

# Tanh friction: the boundary layer where tanh(beta v) departs from sgn(v)
# sits at the turning point (t = pi/2 - phi -> 0) with a width 1/(beta omega A)
# that can be 1e-8 rad (beta ~ 1e9 s/m); geometric panels down to 1e-13 rad
# resolve any width (what lies below contributes < 1e-26).
_TANH_EDGES = np.concatenate(([0.0], np.geomspace(1e-13, 0.5 * np.pi, 41)))
_TANH_T = (
    0.5 * (_TANH_EDGES[:-1] + _TANH_EDGES[1:])[:, None]
    + 0.5 * np.diff(_TANH_EDGES)[:, None] * np.polynomial.legendre.leggauss(8)[0][None, :]
).ravel()
_TANH_W = (
    0.5 * np.diff(_TANH_EDGES)[:, None] * np.polynomial.legendre.leggauss(8)[1][None, :]
).ravel()

#: Points evaluated together (memory ~ points x 120 x 320 doubles for tanh).
_CHUNK = 256


class AveragingValidityWarning(RuntimeWarning):
    """Stochastic averaging is used outside its range of validity (heavy damping)."""


@dataclass(frozen=True)
class OrbitAverages:
    """Undamped-orbit quantities at given energies (SI units).

    Attributes
    ----------
    energy : ndarray
        Mechanical energy E = m z'^2/2 + k z^2/2 + k3 z^4/4 (J).
    amplitude : ndarray
        Turning point A (m), the positive root of U(A) = E.
    period : ndarray
        Orbit period T (s).
    mean_square_velocity : ndarray
        <z'^2> over one period ((m/s)^2).
    mean_abs_velocity : ndarray
        <|z'|> = 4 A / T (m/s).
    mean_square_displacement : ndarray
        <z^2> over one period (m^2).
    """

    energy: np.ndarray
    amplitude: np.ndarray
    period: np.ndarray
    mean_square_velocity: np.ndarray
    mean_abs_velocity: np.ndarray
    mean_square_displacement: np.ndarray


@dataclass(frozen=True)
class AveragingResult:
    """Stationary statistics from the averaged energy density (SI units).

    Attributes
    ----------
    velocity_variance : float or ndarray
        E[z'^2] ((m/s)^2).
    mean_abs_velocity : float or ndarray
        E|z'| (m/s).
    displacement_variance : float or ndarray
        E[z^2] (m^2).
    friction_power : float or ndarray
        E[z' F(z')] (W), the mean power dissipated by friction.
    zeta_eff : float or ndarray
        Effective damping ratio c_eq / (2 sqrt(k_eq m)) with
        c_eq = S m / (4 E[z'^2]) and k_eq = m E[z'^2] / E[z^2] (equipartition).
    zeta_friction : float or ndarray
        Friction's share of it, (E[z' F] / E[z'^2]) / (2 sqrt(k_eq m)): the
        small parameter of averaging (see :data:`AVERAGING_ZETA_LIMIT`).
    """

    velocity_variance: object
    mean_abs_velocity: object
    displacement_variance: object
    friction_power: object
    zeta_eff: object
    zeta_friction: object


def turning_point_squared(h, omega2, lam):
    """A^2 (m^2) of the undamped orbit at energy ``h`` per unit mass (J/kg).

    The positive root of G(A) = omega2 (A^2/2 + lam A^4/4) = h, with
    omega2 = k/m and lam = k3/k, written without cancellation. Also the
    z half-width of the FPK solvers' boxes.
    """
    return 4.0 * h / omega2 / (1.0 + np.sqrt(1.0 + 4.0 * lam * h / omega2))


def _orbit(x, omega, lam):
    """Orbit integrals at energies H = x^2 (J/kg) for omega^2 = k/m, lam = k3/k.

    Returns amplitude A, period T, area Phi = T <v^2>, and T <z^2>.
    """
    a2 = turning_point_squared(x * x, omega**2, lam)
    amp = np.sqrt(a2)
    q = np.sqrt(1.0 + (lam * a2)[..., None] * (0.5 * (1.0 + _SIN2)))
    inv_q = np.mean(1.0 / q, axis=-1)
    period = (2.0 * np.pi / omega) * inv_q
    area = (2.0 * np.pi) * omega * a2 * np.mean((1.0 - _SIN2) * q, axis=-1)
    t_z2 = (2.0 * np.pi / omega) * a2 * np.mean(_SIN2 / q, axis=-1)
    return amp, period, area, t_z2


def _tanh_fraction(amp, omega, lam, beta):
    """J / (f_c A) for tanh friction: 1 - int_0^{pi/2} (1 - tanh(beta v)) sin t dt."""
    a2 = amp * amp
    cos2 = np.cos(_TANH_T) ** 2  # sin^2(phi) at phi = pi/2 - t
    q = np.sqrt(1.0 + (lam * a2)[..., None] * (0.5 * (1.0 + cos2)))
    arg = (beta * omega * amp)[..., None] * np.sin(_TANH_T) * q
    return 1.0 - np.sum(one_minus_tanh(arg) * np.sin(_TANH_T) * _TANH_W, axis=-1)


def _quarter_friction_work(amp, omega, lam, fcm, beta):
    """J(H) = int_0^A f(v(z)) dz (per unit mass); beta = inf means Coulomb."""
    if np.all(np.isinf(beta)):
        return fcm * amp
    frac = _tanh_fraction(amp, omega, np.broadcast_to(lam, amp.shape), beta)
    return fcm * amp * np.where(np.isinf(beta), 1.0, frac)


def _psi_slope(x, gamma, dd, area, work):
    """dPsi/dx at x = sqrt(H): 2x (2 gamma/D + 8 J/(D Phi)) (module docstring).

    ``area`` is Phi(H) and ``work`` J(H); finite at x -> 0 because J/Phi ~ 1/x.
    """
    return 2.0 * x * (2.0 * gamma / dd + 8.0 * work / (dd * area))


def linear_psi_root(gamma, fcm, dd, psi):
    """x = sqrt(H) at which the linear-spring averaged exponent reaches ``psi``.

    For the linear spring with viscous damping gamma (1/s), Coulomb level
    fcm (N/kg) and noise intensity dd = D (m^2/s^3), Psi = a x^2 + b x with
    a = 2 gamma/D and b = 8 sqrt(2) fcm/(pi D); this solves a x^2 + b x = psi
    without cancellation. It bounds the true Psi from above and from below
    within 10 % for Coulomb friction (the orbit shape factor Phi / (A v_max)
    only moves from pi to 3.50 as k3 A^2 / k grows), so it sizes the energy
    grid here and the box of the fast FPK solver.
    """
    a = 2.0 * gamma / dd
    b = 8.0 * np.sqrt(2.0) * fcm / (np.pi * dd)
    return 2.0 * psi / (b + np.sqrt(b * b + 4.0 * a * psi))


def _moments(m, c, k, k3, fc, beta, psd):
    """Averaged stationary moments for 1-d parameter arrays of equal length.

    Returns E[v^2], E|v|, E[z^2], E[v f(v)] (per unit mass) and the
    normaliser Z = int T exp(-Psi) dH.
    """
    gamma, omega, lam, fcm, dd = c / m, np.sqrt(k / m), k3 / k, fc / m, 0.5 * psd
    # The density at the grid's end is below exp(-60) (see linear_psi_root).
    x_max = linear_psi_root(gamma, fcm, dd, _PSI_END)
    col = (slice(None), None)
    for _ in range(30):
        out = _moments_on_grid(x_max, gamma[col], omega[col], lam[col], fcm[col], beta[col], dd)
        short = out[-1] < _PSI_ENOUGH
        if not np.any(short):
            break
        # Tanh friction is weaker than Coulomb at low velocity, so Psi can
        # grow more slowly than the estimate: stretch the grid there.
        x_max = np.where(short, 2.0 * x_max, x_max)
    return out[:-1]


def _moments_on_grid(x_max, gamma, omega, lam, fcm, beta, dd):
    x = x_max[:, None] * _X_UNIT
    w = x_max[:, None] * _W_UNIT
    amp, period, area, t_z2 = _orbit(x, omega, lam)
    work = _quarter_friction_work(amp, omega, lam, fcm, beta)
    dpsi = _psi_slope(x, gamma, dd[:, None], area, work)
    panels = dpsi.reshape(len(x_max), _N_PANELS, _N_GL)
    half = x_max[:, None, None] * _HALF_UNIT[None, :, None]
    within = half * np.einsum("ij,bpj->bpi", _GL_Q, panels)  # from each panel's start
    totals = half[..., 0] * np.einsum("j,bpj->bp", _GL_W, panels)
    ends = np.cumsum(totals, axis=1)
    psi = ((ends - totals)[..., None] + within).reshape(x.shape)
    rho = w * 2.0 * x * np.exp(-psi)  # dH = 2x dx
    z = np.sum(rho * period, axis=1)
    vv = np.sum(rho * area, axis=1) / z
    abs_v = np.sum(rho * 4.0 * amp, axis=1) / z
    zz = np.sum(rho * t_z2, axis=1) / z
    fpow = np.sum(rho * 4.0 * work, axis=1) / z  # E[v f(v)] per unit mass
    return vv, abs_v, zz, fpow, z, ends[:, -1]


def memoryless_parameters(harvester: Harvester, psd, method: AnalyticMethod):
    """Broadcast (m, c, k, k3, fc, beta, psd) for the semi-analytic methods.

    ``beta = inf`` marks Coulomb friction (or none, with ``fc = 0``). Methods
    that need the friction form Fc tanh(beta v) (averaging, the FPK solvers)
    share this; the law declares (Fc, beta) through ``coulomb_tanh_form()``.
    The case is first checked against ``method``'s declaration
    (:meth:`~randvib.analytic.method.AnalyticMethod.require`, the refusal
    naming it by its ``title``): these methods reduce the device to (z, v)
    under white noise with a viscous electrical damping c_e (resistive coupling).
    """
    method.require(harvester, psd, method.title)
    friction = harvester.friction
    fc, beta = (0.0, np.inf) if friction is None else friction.coulomb_tanh_form()
    psd = check_positive("psd", white_level(psd), "(m/s^2)^2/Hz")
    arrays = np.broadcast_arrays(
        *(
            np.asarray(v, dtype=float)
            for v in (harvester.m, harvester.c, harvester.k, harvester.k3, fc, beta, psd)
        )
    )
    m, c, k, k3, fc, beta, psd = arrays
    if np.any((c <= 0) & (fc <= 0)):
        raise ValueError(
            "total damping `c_m + c_e` and friction `fc` are both 0 at some parameter point; "
            "the undamped oscillator has no stationary state"
        )
    return arrays


def averaging_statistics(harvester: Harvester, psd, *, warn: bool = True) -> AveragingResult:
    """Stationary moments by energy-envelope stochastic averaging.

    Parameters
    ----------
    harvester : Harvester
        Device with Coulomb, tanh or no friction; parameters may be arrays
        that broadcast with ``psd``.
    psd : array_like
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0, or a
        :class:`~randvib.models.excitation.White` excitation; white noise is
        assumed, any other excitation is refused with a ValueError (paper Eq. 17).
    warn : bool
        Emit :class:`AveragingValidityWarning` where ``zeta_friction`` exceeds
        :data:`AVERAGING_ZETA_LIMIT`.

    Returns
    -------
    AveragingResult
        Broadcast over ``psd`` and the harvester's parameters.

    Raises
    ------
    ValueError
        For bad ``psd``, for LuGre friction (it has memory, so the energy
        drift is not a function of the energy alone), for points with
        neither damping nor friction, and for what :class:`Averaging` does
        not accept (a potential other than monostable, a circuit state, a
        non-white excitation: the message names the methods that do).
    """
    m, c, k, k3, fc, beta, psd = memoryless_parameters(harvester, psd, AVERAGING)
    shape = m.shape
    flat = [np.ravel(a) for a in (m, c, k, k3, fc, beta, psd)]
    n = flat[0].size
    vv, abs_v, zz, fpow = (np.empty(n) for _ in range(4))
    # Absurd inputs (no damping to speak of) overflow; they are refused below.
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for start in range(0, n, _CHUNK):
            sl = slice(start, start + _CHUNK)
            vv[sl], abs_v[sl], zz[sl], fpow[sl], _ = _moments(*(a[sl] for a in flat))
    if not np.all(np.isfinite(vv) & np.isfinite(zz) & (zz > 0)):
        bad = int(np.argmin(np.isfinite(vv) & np.isfinite(zz) & (zz > 0)))
        raise ValueError(
            "stochastic averaging found no finite stationary moments for c = "
            f"{flat[1][bad]!r} Ns/m, fc = {flat[4][bad]!r} N, psd = {flat[6][bad]!r}: "
            "damping and friction are too small for this excitation"
        )
    m_f, psd_f = flat[0], flat[-1]
    c_eq = psd_f * m_f / (4.0 * vv)
    k_eq = m_f * vv / zz
    zeta = c_eq / (2.0 * np.sqrt(k_eq * m_f))
    zeta_f = m_f * fpow / vv / (2.0 * np.sqrt(k_eq * m_f))
    if warn and np.any(zeta_f > AVERAGING_ZETA_LIMIT):
        _warn_beyond_validity(zeta_f, zeta)

    def shaped(a):
        return scalar_or_array(a.reshape(shape))

    return AveragingResult(
        velocity_variance=shaped(vv),
        mean_abs_velocity=shaped(abs_v),
        displacement_variance=shaped(zz),
        friction_power=shaped(m_f * fpow),
        zeta_eff=shaped(zeta),
        zeta_friction=shaped(zeta_f),
    )


def _warn_beyond_validity(zeta_f, zeta):
    """AveragingValidityWarning at the worst point, for the caller of averaging_statistics."""
    worst = int(np.argmax(zeta_f))
    warnings.warn(
        "stochastic averaging assumes friction removes little energy per cycle, but the "
        "friction damping ratio zeta_f = (E[z'F]/E[z'^2]) / (2 sqrt(k_eq m)) = "
        f"{zeta_f[worst]:.3g} exceeds {AVERAGING_ZETA_LIMIT} (total zeta_eff = "
        f"{zeta[worst]:.3g}); its power may be low by 3-6 %. Use method='fpk-fast' "
        "(or 'fpk', or Monte Carlo) there.",
        AveragingValidityWarning,
        stacklevel=3,
    )


def orbit_averages(harvester: Harvester, energy) -> OrbitAverages:
    """Period and orbit averages of the undamped Duffing oscillator.

    Parameters
    ----------
    harvester : Harvester
        Supplies m, k and k3 (scalars or arrays broadcasting with ``energy``).
    energy : array_like
        Mechanical energy E = m z'^2/2 + k z^2/2 + k3 z^4/4 (J), >= 0. At
        E = 0 the limits (T = 2 pi/omega, averages 0) are returned.

    Returns
    -------
    OrbitAverages
    """
    harvester.potential.require("orbit_averages", ("monostable",))
    energy = check_nonnegative("energy", energy, "J")
    m, k, k3, energy = np.broadcast_arrays(
        *(np.asarray(v, dtype=float) for v in (harvester.m, harvester.k, harvester.k3, energy))
    )
    x = np.sqrt(energy / m)
    omega = np.sqrt(k / m)
    amp, period, area, t_z2 = _orbit(x, omega, k3 / k)
    return OrbitAverages(
        energy=energy,
        amplitude=amp,
        period=period,
        mean_square_velocity=area / period,
        mean_abs_velocity=4.0 * amp / period,
        mean_square_displacement=t_z2 / period,
    )


def energy_density(harvester: Harvester, psd, energy):
    """Stationary density p(E) (1/J) of the mechanical energy, by averaging.

    ``p(E) = T(H) exp(-Psi(H)) / (m Z)`` with H = E/m (module docstring);
    integrates to one over E >= 0. Without friction it is the exact Gibbs
    density T exp(-4 c E/(S m^2)) / (m Z).

    Parameters
    ----------
    harvester : Harvester
        Device with scalar parameters and Coulomb, tanh or no friction.
    psd : float
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0, or a
        :class:`~randvib.models.excitation.White` excitation; white noise is
        assumed, any other excitation is refused with a ValueError.
    energy : array_like
        Energies E (J), >= 0.
    """
    m, c, k, k3, fc, beta, psd = (
        float(np.ravel(a)[0]) for a in memoryless_parameters(harvester, psd, AVERAGING)
    )
    if any(np.ndim(v) for v in (harvester.m, harvester.c, harvester.k, harvester.k3)):
        raise ValueError("energy_density needs scalar harvester parameters")
    energy = check_nonnegative("energy", energy, "J")
    x_true = np.sqrt(np.ravel(energy) / m)
    x_e = np.where(x_true > 0, x_true, 1.0)  # Psi(0) = 0 is set below
    gamma, omega, lam, fcm, dd = c / m, np.sqrt(k / m), k3 / k, fc / m, 0.5 * psd
    # Psi(x_e) by Gauss-Legendre on [0, x_e] with the same panel rule.
    nodes = x_e[:, None] * _X_UNIT
    amp, _, area, _ = _orbit(nodes, omega, lam)
    dpsi = _psi_slope(nodes, gamma, dd, area, _quarter_friction_work(amp, omega, lam, fcm, beta))
    psi = np.where(x_true > 0, np.sum(dpsi * (x_e[:, None] * _W_UNIT), axis=1), 0.0)
    _, period, _, _ = _orbit(x_true, omega, lam)
    # Normalisation Z = int T exp(-Psi) dH, from the moment grid.
    z = _moments(*(np.array([v]) for v in (m, c, k, k3, fc, beta, psd)))[4][0]
    return (period * np.exp(-psi) / (m * z)).reshape(np.shape(energy))


class Averaging(AnalyticMethod):
    """Energy-envelope stochastic averaging (this module): a non-Gaussian velocity.

    Within 2 % of the FPK reference on the study grid where friction removes
    little energy per cycle (zeta_friction <= :data:`AVERAGING_ZETA_LIMIT`;
    beyond it warns), but it overstates the change of power with k3 1.5-5x
    (module docstring). White noise, resistive coupling, the monostable
    potential and friction of the form Fc tanh(beta v) only.
    """

    name = "averaging"
    title = "stochastic averaging"
    summary = "stochastic averaging, non-Gaussian velocity, within 2 %, 0.3 ms"
    potentials = ("monostable",)
    friction_form = "fc-tanh"
    validity = (
        Validity(
            "zeta_friction",
            AVERAGING_ZETA_LIMIT,
            "warns",
            "friction's damping ratio (E[z' F] / E[z'^2]) / (2 sqrt(k_eq m)), the energy "
            "friction removes per cycle against the energy stored; beyond it the power may be "
            "low by 3-6 %",
        ),
    )

    def solve(self, harvester: Harvester, psd) -> PowerPrediction:
        r = averaging_statistics(harvester, psd)
        return PowerPrediction.from_white_noise(
            harvester,
            self.name,
            r.velocity_variance,
            r.displacement_variance,
            r.mean_abs_velocity,
            psd,
        )


#: The method's declaration, which the functions of this module check their input against
#: (:data:`randvib.analytic.prediction.METHODS` holds it).
AVERAGING = Averaging()
