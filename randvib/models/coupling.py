"""Electrical couplings: the transducer and circuit that take power from the magnet.

One model family, declared once (like the friction laws of
:mod:`randvib.models.friction` and the excitations of
:mod:`randvib.models.excitation`): each coupling is a frozen dataclass whose
fields are made with :func:`~randvib.models.parameters.parameter`, and a
subclass that sets ``name`` is registered in :data:`COUPLINGS`, which the CLI
and the methods read.

=============  ===========================================  ======================
coupling       equations (docs/conventions.md)              power
=============  ===========================================  ======================
``resistive``  force c_e z', c_e = alpha^2/(R_L + R_C)      P_e = c_e z'^2,
               (paper Eq. 3)                                P_L = R_L i^2
``inductive``  force alpha i on the magnet,                 P_e = (R_L + R_C) i^2,
               L di/dt + (R_L + R_C) i = alpha z'           P_L = R_L i^2
``piezo``      force theta V on the mass,                   P_e = P_L = V^2 / R_L
               C_p dV/dt + V / R_L = theta z'
=============  ===========================================  ======================

Sign conventions. The circuit's force *opposes* the motion: the device reads
``m z'' + c_m z' + k z + k3 z^3 + F + f x = -m y''`` with ``f x = alpha i``
(inductive) or ``theta V`` (piezo), and the circuit state ``x`` is driven by
``+z'``. Then the power the magnet gives the circuit is ``f x z'`` and, by the
circuit equation, ``f x z' = R x^2 + d/dt(E_x)`` with the stored energy
``E_x = L i^2 / 2`` or ``C_p V^2 / 2``: the coupling only dissipates (its
stationary mean power ``R E[i^2]`` or ``E[V^2]/R_L`` is >= 0), and with white
noise the energy balance reads ``c_m E[z'^2] + E[z' F] + P_e = S m / 4``.

A *static* coupling (resistive; inductive with L = 0; piezo with C_p = 0) is
a viscous damper ``c_e``; a *dynamic* one (L > 0, C_p > 0) carries one state,
``x' = a x + b z'`` with the force ``f x`` on the magnet
(:meth:`Coupling.circuit_equation`), which Monte Carlo integrates as an
auxiliary state of the kernel and equivalent linearisation keeps as a state of
the linear system.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from randvib.models.parameters import DeclaredParameters, parameter

#: Registered couplings by name (``resistive``, ``inductive``, ``piezo``).
COUPLINGS: dict[str, type] = {}


class Coupling(DeclaredParameters):
    """Base class of the electrical couplings: the declaration every consumer reads.

    Subclasses are frozen dataclasses whose fields are made with
    :func:`~randvib.models.parameters.parameter`; one that sets ``name`` is
    registered in :data:`COUPLINGS`.
    """

    #: Short name used by the CLI and in messages.
    name: str = "coupling"
    #: True for a coupling through a diode bridge (:mod:`randvib.models.rectifier`).
    rectified: bool = False
    #: Name and unit of the circuit state of a dynamic coupling.
    state_name: str = ""
    state_unit: str = ""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "name" in cls.__dict__:
            COUPLINGS[cls.name] = cls

    def parameters(self) -> dict:
        """The coupling's parameters by name (SI units)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    # ----------------------------------------------------------- dynamics
    @property
    def is_dynamic(self) -> bool:
        """True when the circuit carries a state (an inductance or a capacitance > 0)."""
        return False

    @property
    def electrical_damping(self):
        """c_e (Ns/m) of a static coupling; 0 for a dynamic one (its force is f x)."""
        raise NotImplementedError  # pragma: no cover - abstract

    def circuit_equation(self):
        """``(a, b, f)`` of a dynamic coupling: ``x' = a x + b z'``, force ``f x`` (N).

        ``a`` (1/s) < 0, ``b`` (state unit per metre) and ``f`` (N per state
        unit) > 0, so that ``f x z'`` is the power into the circuit.
        """
        raise ValueError(f"the {self.name} coupling here is static: it has no circuit state")

    def _representable(self, a, b, f):
        """``(a, b, f)`` as floats, refused when a time constant leaves float64's range."""
        a, b, f = (float(x) for x in (a, b, f))
        if not (np.isfinite(a) and np.isfinite(b) and np.isfinite(f)) or a == 0:
            raise ValueError(
                f"the {self.name} circuit of {self!r} has a time constant beyond float64's "
                f"range (x' = a x + b z' with a = {a:.3g} 1/s, b = {b:.3g}); give its "
                "parameters a physical size"
            )
        return a, b, f

    # -------------------------------------------------------------- power
    @property
    def load_fraction(self):
        """Share of the electrical power that reaches the load."""
        return 1.0

    def power_electrical(self, velocity_square, state_square=None):
        """Mean power into the electrical domain (W) from E[z'^2] and E[x^2].

        Linear in the two mean squares, so it applies equally to variances,
        to per-path time averages and to spectral densities.
        """
        if self.is_dynamic:
            return self._state_power(state_square)
        return self.electrical_damping * velocity_square

    def power_load(self, velocity_square, state_square=None):
        """Mean power into the load resistance (W), as :meth:`power_electrical`."""
        return self.power_electrical(velocity_square, state_square) * self.load_fraction

    def _state_power(self, state_square):  # pragma: no cover - abstract
        raise NotImplementedError

    def white_noise_optimal_load(self, m, c_m, k):
        """Classical optimum R_L (ohm) of the linear device under white noise, no friction."""
        raise NotImplementedError  # pragma: no cover - abstract


@dataclass(frozen=True, eq=False)
class Resistive(Coupling):
    """Electromagnetic transducer with a resistive circuit (paper Eq. 3, Fig. 2b).

    Parameters
    ----------
    alpha : float
        Flux gradient (Wb/m = V s/m), > 0. The paper's device: 0.1992 Wb/m.
    r_load : float
        Load resistance R_L (ohm), > 0.
    r_coil : float
        Coil resistance R_C (ohm), >= 0. The paper's device: 0.48 ohm.
    """

    alpha: float = parameter("Wb/m", positive=True, description="flux gradient alpha")
    r_load: float = parameter("ohm", positive=True, description="load resistance R_L")
    r_coil: float = parameter("ohm", description="coil resistance R_C")

    name = "resistive"

    @property
    def electrical_damping(self):
        """c_e = alpha^2 / (R_L + R_C) (Ns/m), paper Eq. 3."""
        return self.alpha**2 / (self.r_load + self.r_coil)

    @property
    def load_fraction(self):
        """R_L / (R_L + R_C): the share of the electrical power reaching the load."""
        return self.r_load / (self.r_load + self.r_coil)

    def white_noise_optimal_load(self, m, c_m, k):
        """R_L* = sqrt(R_C^2 + R_C alpha^2 / c_m), independent of S, m, k (and k3)."""
        return np.sqrt(self.r_coil**2 + self.r_coil * self.alpha**2 / c_m)


@dataclass(frozen=True, eq=False)
class Inductive(Coupling):
    """Electromagnetic transducer with a coil inductance.

    ``L di/dt + (R_L + R_C) i = alpha z'``, force ``alpha i`` on the magnet
    (opposing its motion); with ``L = 0`` it is :class:`Resistive`.

    Parameters
    ----------
    alpha : float
        Flux gradient (Wb/m), > 0.
    r_load : float
        Load resistance R_L (ohm), > 0.
    r_coil : float
        Coil resistance R_C (ohm), >= 0.
    inductance : float
        Coil inductance L (H), >= 0.
    """

    alpha: float = parameter("Wb/m", positive=True, description="flux gradient alpha")
    r_load: float = parameter("ohm", positive=True, description="load resistance R_L")
    r_coil: float = parameter("ohm", description="coil resistance R_C")
    inductance: float = parameter("H", description="coil inductance L")

    name = "inductive"
    state_name = "current"
    state_unit = "A"

    @property
    def is_dynamic(self) -> bool:
        return _all_positive(self.inductance)

    @property
    def resistance(self):
        """R_L + R_C (ohm)."""
        return self.r_load + self.r_coil

    @property
    def electrical_damping(self):
        return 0.0 if self.is_dynamic else self.alpha**2 / self.resistance

    @property
    def load_fraction(self):
        return self.r_load / self.resistance

    def circuit_equation(self):
        if not self.is_dynamic:
            return super().circuit_equation()
        with np.errstate(all="ignore"):  # float64 division: an overflow is inf, refused below
            inductance = np.float64(self.inductance)
            return self._representable(
                -self.resistance / inductance, self.alpha / inductance, self.alpha
            )

    def _state_power(self, state_square):
        return self.resistance * state_square  # (R_L + R_C) E[i^2]

    def white_noise_optimal_load(self, m, c_m, k):
        """R_L*^2 = R_C^2 + R_C (L c_m^2 + alpha^2 m)/(c_m m) + L (L k + alpha^2)/m.

        From the Lyapunov solution of (z, z', i) under white noise:
        ``E[i^2] = S alpha^2 m^2 / (4 D)``,
        ``D = c_m m R^2 + (L c_m^2 + alpha^2 m) R + L c_m (L k + alpha^2)``,
        R = R_L + R_C; d(R_L/D)/dR_L = 0 gives the root. L = 0 is the
        resistive optimum.
        """
        r_c, alpha, ind = self.r_coil, self.alpha, self.inductance
        return np.sqrt(
            r_c**2
            + r_c * (ind * c_m**2 + alpha**2 * m) / (c_m * m)
            + ind * (ind * k + alpha**2) / m
        )


@dataclass(frozen=True, eq=False)
class Piezo(Coupling):
    """Piezoelectric element on a resistive load.

    ``C_p dV/dt + V / R_L = theta z'``, force ``theta V`` on the mass
    (opposing its motion); power ``V^2 / R_L``, all of it in the load.

    Parameters
    ----------
    theta : float
        Electromechanical coupling theta (N/V = C/m), > 0.
    capacitance : float
        Clamped capacitance C_p (F), >= 0.
    r_load : float
        Load resistance R_L (ohm), > 0.

    Examples
    --------
    >>> import randvib as rv
    >>> piezo = rv.Piezo(theta=1e-3, capacitance=1e-7, r_load=1e5)
    >>> device = rv.Harvester.with_coupling(0.0226, 0.05, 57.4, piezo)
    >>> print(f"P_L = {rv.expected_power(device, 0.5, into='load'):.4e} W")
    P_L = 1.7016e-03 W
    >>> print(f"R_L* = {piezo.white_noise_optimal_load(0.0226, 0.05, 57.4):.4g} ohm")
    R_L* = 1.831e+05 ohm
    """

    theta: float = parameter("N/V", positive=True, description="piezo coupling theta")
    capacitance: float = parameter("F", description="piezo capacitance C_p")
    r_load: float = parameter("ohm", positive=True, description="load resistance R_L")

    name = "piezo"
    state_name = "voltage"
    state_unit = "V"

    @property
    def is_dynamic(self) -> bool:
        return _all_positive(self.capacitance)

    @property
    def electrical_damping(self):
        # C_p = 0: V = theta R_L z', a damper theta^2 R_L.
        return 0.0 if self.is_dynamic else self.theta**2 * self.r_load

    def circuit_equation(self):
        if not self.is_dynamic:
            return super().circuit_equation()
        with np.errstate(all="ignore"):  # float64 division: an overflow is inf, refused below
            c_p = np.float64(self.capacitance)
            return self._representable(-1.0 / (self.r_load * c_p), self.theta / c_p, self.theta)

    def _state_power(self, state_square):
        return state_square / self.r_load  # E[V^2] / R_L

    def white_noise_optimal_load(self, m, c_m, k):
        """R_L* = sqrt(m / (C_p (C_p k + theta^2))), independent of c_m and S.

        From the Lyapunov solution of (z, z', V) under white noise:
        ``E[V^2] = S m^2 theta^2 R_L^2 / (4 D)``,
        ``D = C_p c_m (C_p k + theta^2) R_L^2 + (C_p c_m^2 + m theta^2) R_L + c_m m``;
        d(R_L/D)/dR_L = 0 gives the root.
        """
        c_p = self.capacitance
        return np.sqrt(m / (c_p * (c_p * k + self.theta**2)))


def coupling_class(name: str) -> type:
    """The registered coupling called ``name``, or a ValueError naming the choices."""
    try:
        return COUPLINGS[name]
    except KeyError:
        raise ValueError(
            f"`coupling` must be one of {', '.join(COUPLINGS)}; got {name!r}"
        ) from None


def _all_positive(value) -> bool:
    """``value`` > 0 at every point (a number, or an array over a grid of devices).

    A number is compared as is: ``np.all(np.asarray(x) > 0)`` gives the same answer
    at many times the cost, and ``is_dynamic`` is asked at every step of a
    linearisation's fixed point.
    """
    if isinstance(value, float):
        return bool(value > 0)
    return bool(np.all(np.asarray(value) > 0))
