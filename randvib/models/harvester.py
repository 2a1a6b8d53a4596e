"""The device model: paper Eq. 1-3.

    m z'' + (c_e + c_m) z' + k z + k3 z^3 + F(z', theta) = -m y''

``z`` is the displacement of the centre magnet relative to the base (m),
``y`` the base displacement (m) and ``F`` the friction force (N) of one of the
models in :mod:`randvib.models.friction`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, fields
from functools import cached_property

import numpy as np

from randvib._validation import check_finite, check_nonnegative, check_positive, scalar_or_array
from randvib.models.coupling import COUPLINGS, Coupling, Resistive
from randvib.models.friction import FrictionModel
from randvib.models.potential import Potential
from randvib.quantities import unit


def _check_real(name, value, _unit):
    """Any finite value: the potential it makes (double well, free mass) is the methods' business."""
    return check_finite(name, value)


__all__ = ["Harvester"]


class ElectricalDampingOverflow(ValueError):
    """A coupling's electrical damping c_e overflows float64 (e.g. alpha = 1e308)."""


@dataclass(frozen=True, eq=False)
class Harvester:
    """Single-degree-of-freedom electromagnetic harvester (paper Eq. 1).

    Immutable; numeric parameters may be numpy arrays that broadcast together,
    so that one analytic call evaluates a whole sweep (simulation needs
    scalars).

    Parameters
    ----------
    m : float
        Moving (centre-magnet) mass (kg), > 0. The paper never prints it; its
        presets use 0.0226 kg, from k = 57.4 N/m and f_n = 8 Hz.
    c_m : float
        Mechanical viscous damping (Ns/m), >= 0.
    c_e : float
        Electrical damping (Ns/m), >= 0; see :meth:`from_electrical` for Eq. 3.
    k : float
        Linear stiffness (N/m), any finite value: k > 0 monostable, k < 0
        bistable (with k3 > 0), k = 0 pure cubic or, with k3 = 0, the free
        mass (see :class:`~randvib.models.potential.Potential`).
    k3 : float, optional
        Cubic (Duffing) stiffness (N/m^3), any finite value. A non-confining
        potential (k3 < 0, or k < 0 with k3 = 0) can be built but every
        stationary method refuses it.
    friction : FrictionModel or None, optional
        Friction model; ``None`` for none.
    electrical : Coupling or None, optional
        The electrical coupling (:mod:`randvib.models.coupling`): resistive
        (paper Eq. 3), inductive or piezo. A static one's ``c_e`` must equal
        its electrical damping (alpha^2 / (R_L + R_C) for the resistive
        circuit; use :meth:`from_electrical`); a dynamic one (inductance or
        capacitance > 0) acts through its circuit state and needs ``c_e = 0``
        (use :meth:`with_coupling`). With a coupling, load power is defined.
    stroke : float or None, optional
        Stroke limit (m), > 0: the largest |z| before the magnet meets its end
        stops. It changes no dynamics; the methods report how often and how
        soon |z| exceeds it (``stroke_exceedance``, first-passage time).

    Examples
    --------
    >>> import randvib as rv
    >>> device = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4, k3=5e5, friction=rv.Coulomb(0.0058))
    >>> device.c
    0.2
    >>> device.updated(fc=0.01).friction
    Coulomb(fc=0.01)
    >>> wired = rv.Harvester.from_electrical(
    ...     m=0.0226, c_m=0.049, k=57.4, alpha=0.1992, r_load=2.0, r_coil=0.48
    ... )
    >>> print(f"c_e = {wired.c_e:.5f} Ns/m")  # alpha^2 / (R_L + R_C), Eq. 3
    c_e = 0.01600 Ns/m
    """

    m: float
    c_m: float
    c_e: float
    k: float
    k3: float = 0.0
    friction: FrictionModel | None = None
    electrical: Coupling | None = None
    stroke: float | None = None

    def __post_init__(self):
        for name, check in (
            ("m", check_positive),
            ("c_m", check_nonnegative),
            ("c_e", check_nonnegative),
            ("k", _check_real),
            ("k3", _check_real),
        ):
            value = check(name, getattr(self, name), unit(name))
            object.__setattr__(self, name, scalar_or_array(value))
        if self.stroke is not None:
            stroke = check_positive("stroke", self.stroke, "m")
            if np.ndim(stroke):
                raise ValueError(f"`stroke` must be one number (m), got {self.stroke!r}")
            object.__setattr__(self, "stroke", float(stroke))
        if self.friction is not None and not isinstance(self.friction, FrictionModel):
            raise ValueError(
                f"`friction` must be a randvib friction model (Coulomb, Tanh, LuGre) "
                f"or None, got {self.friction!r}"
            )
        if self.electrical is not None:
            self._check_coupling()
        undamped_allowed = self.has_circuit or self.is_rectified
        if np.any(self.c_m + self.c_e <= 0) and self.friction is None and not undamped_allowed:
            raise ValueError(
                "total damping `c_m + c_e` must be > 0 without friction, got "
                f"{self.c_m!r} + {self.c_e!r}; the undamped oscillator has no stationary state"
            )

    def _check_coupling(self):
        """The coupling is one of the family, and ``c_e`` agrees with it."""
        if not isinstance(self.electrical, Coupling):
            raise ValueError(
                f"`electrical` must be a randvib coupling ({', '.join(COUPLINGS)}) or None, "
                f"got {self.electrical!r}"
            )
        expected = self.electrical.electrical_damping
        if not np.allclose(self.c_e, expected, rtol=1e-12, atol=0):
            what = (
                "a dynamic coupling acts through its circuit state, so c_e must be 0"
                if self.electrical.is_dynamic
                else "from `electrical`"
            )
            raise ValueError(
                f"`c_e` = {self.c_e!r} Ns/m disagrees with {expected!r} Ns/m {what}; use "
                "Harvester.from_electrical or Harvester.with_coupling"
            )

    @classmethod
    def bistable(cls, well: float, barrier: float, **parameters) -> Harvester:
        """A bistable device given by its wells at z = +-``well`` (m) and ``barrier`` (J).

        The same device as ``Harvester(k=..., k3=..., ...)`` with
        k = -4 barrier / well^2 < 0 < k3 = 4 barrier / well^4
        (:meth:`Potential.from_wells`); ``parameters`` are the others
        (``m``, ``c_m``, ``c_e``, ``friction``, ``electrical``, ``stroke``).

        Examples
        --------
        >>> import randvib as rv
        >>> d = rv.Harvester.bistable(0.002, 1e-4, m=0.0226, c_m=0.049, c_e=0.0)
        >>> print(f"k = {d.k:g} N/m, k3 = {d.k3:g} N/m^3, wells at +-{d.potential.wells[1]:g} m")
        k = -100 N/m, k3 = 2.5e+07 N/m^3, wells at +-0.002 m
        """
        for name in ("k", "k3"):
            if name in parameters:
                raise ValueError(
                    f"Harvester.bistable takes the wells and the barrier, not `{name}`: give "
                    "either well/barrier or k/k3 (Harvester(...))"
                )
        potential = Potential.from_wells(well, barrier)
        return cls(k=potential.k, k3=potential.k3, **parameters)

    @classmethod
    def with_coupling(cls, m, c_m, k, coupling: Coupling, k3=0.0, friction=None, stroke=None):
        """Build a harvester with any electrical coupling (:mod:`randvib.models.coupling`).

        ``c_e`` follows from the coupling: its electrical damping when it is
        static (resistive, Eq. 3; inductive with L = 0; piezo with C_p = 0),
        0 when it carries a circuit state.
        """
        try:
            with np.errstate(all="ignore"):
                c_e = coupling.electrical_damping
        except OverflowError:  # Python floats: alpha**2 beyond float64
            c_e = np.inf
        if not np.all(np.isfinite(c_e)):
            raise ElectricalDampingOverflow(
                f"the electrical damping c_e of {coupling!r} is not a finite number "
                "(it overflows float64); give coupling parameters of a physical size"
            )
        return cls(
            m=m,
            c_m=c_m,
            c_e=c_e,
            k=k,
            k3=k3,
            friction=friction,
            electrical=coupling,
            stroke=stroke,
        )

    @classmethod
    def from_electrical(cls, m, c_m, k, alpha, r_load, r_coil, k3=0.0, friction=None, stroke=None):
        """Build a harvester whose c_e follows from the circuit (paper Eq. 3).

        The mechanical parameters are as for :class:`Harvester`.

        Parameters
        ----------
        alpha : float
            Flux gradient (Wb/m).
        r_load, r_coil : float
            Load and coil resistances (ohm).
        """
        electrical = Resistive(alpha, r_load, r_coil)
        return cls.with_coupling(m, c_m, k, electrical, k3=k3, friction=friction, stroke=stroke)

    # ----------------------------------------------------------------- derived
    @property
    def c(self):
        """Total viscous damping c = c_m + c_e (Ns/m)."""
        return self.c_m + self.c_e

    @property
    def natural_frequency(self):
        """Small-oscillation frequency about the stable rest position (rad/s).

        omega_n = sqrt(k/m) for k >= 0; for a bistable device (k < 0 < k3) the
        frequency in either well, sqrt(-2 k/m) (U'' = -2 k at z = +-sqrt(-k/k3));
        nan for a non-confining potential. See :attr:`Potential.stiffness_at_rest`.
        """
        with np.errstate(invalid="ignore"):
            return np.sqrt(self.potential.stiffness_at_rest / self.m)

    @property
    def potential(self) -> Potential:
        """The restoring potential k z^2/2 + k3 z^4/4 and what it allows."""
        if isinstance(self.k, float) and isinstance(self.k3, float):
            return self._scalar_potential
        return Potential(self.k, self.k3)

    @cached_property
    def _scalar_potential(self) -> Potential:
        # Made once: the harvester is immutable and k, k3 are numbers (arrays, which
        # could be changed in place, get a new Potential at every call). Every
        # prediction asks for it several times, a design's search thousands.
        return Potential(self.k, self.k3)

    @property
    def has_circuit(self) -> bool:
        """True when the coupling carries a circuit state (inductance or capacitance > 0)."""
        return self.electrical is not None and self.electrical.is_dynamic

    @property
    def is_rectified(self) -> bool:
        """True when the coupling goes through a diode bridge (:mod:`randvib.models.rectifier`)."""
        return self.electrical is not None and self.electrical.rectified

    def linear_surrogate(self) -> Harvester:
        """The device with a rectified coupling replaced by its linear surrogate.

        The surrogate (:meth:`randvib.models.rectifier.Rectified.linear_surrogate`)
        has the conducting bridge's damping: Monte Carlo checks its step and
        draws its random start on it. Any other device is returned as it is.
        """
        if not self.is_rectified:
            return self
        return Harvester.with_coupling(
            self.m, self.c_m, self.k, self.electrical.linear_surrogate(), k3=self.k3,
            friction=self.friction, stroke=self.stroke,
        )  # fmt: skip

    @property
    def coupling_name(self) -> str:
        """``resistive`` (also for a bare c_e), ``inductive`` or ``piezo``."""
        return "resistive" if self.electrical is None else self.electrical.name

    def require_resistive(self, method: str, alternatives: str) -> None:
        """Refuse a circuit state for a ``method`` that assumes a viscous electrical damper."""
        if self.has_circuit:
            raise ValueError(
                f"{method} assumes resistive coupling (a viscous c_e); the "
                f"{self.electrical.name} coupling's circuit state is handled by {alternatives}"
            )

    @property
    def friction_name(self) -> str:
        return "none" if self.friction is None else self.friction.name

    def electrical_power(self, velocity):
        """Instantaneous power into the electrical domain c_e z'^2 (W)."""
        self.require_resistive("electrical_power(velocity)", "randvib.simulate")
        return self.c_e * np.asarray(velocity, dtype=float) ** 2

    def _require_electrical(self, what: str):
        if self.electrical is None:
            raise ValueError(
                f"{what} needs the circuit: build the harvester with "
                "Harvester.from_electrical(alpha=..., r_load=..., r_coil=...)"
            )
        if self.electrical.is_dynamic or not isinstance(self.electrical, Resistive):
            raise ValueError(
                f"{what} as a function of the velocity needs the resistive coupling; the "
                f"{self.electrical.name} coupling's {self.electrical.state_name or 'output'} "
                "depends on its history"
            )
        return self.electrical

    def load_current(self, velocity):
        """Current i = alpha z' / (R_L + R_C) (A)."""
        e = self._require_electrical("load current")
        return e.alpha * np.asarray(velocity, dtype=float) / (e.r_load + e.r_coil)

    def load_voltage(self, velocity):
        """Load voltage V = alpha z' R_L / (R_L + R_C) (V)."""
        e = self._require_electrical("load voltage")
        return self.load_current(velocity) * e.r_load

    def load_power(self, velocity):
        """Instantaneous power into the load i^2 R_L (W)."""
        e = self._require_electrical("load power")
        return self.load_current(velocity) ** 2 * e.r_load

    # ----------------------------------------------------------------- updates
    def parameters(self) -> dict:
        """Every parameter by name (SI units), friction and circuit included."""
        out = {name: getattr(self, name) for name in ("m", "c_m", "c_e", "k", "k3")}
        out["friction"] = self.friction_name
        if self.friction is not None:
            out.update(self.friction.parameters())
        if self.electrical is not None:
            if not isinstance(self.electrical, Resistive):
                out["coupling"] = self.electrical.name
            out.update(self.electrical.parameters())
        if self.stroke is not None:
            out["stroke"] = self.stroke
        return out

    def updated(self, **changes) -> Harvester:
        """A copy with some parameters changed, friction and circuit ones included.

        Keys may be any of ``m, c_m, c_e, k, k3, stroke``, the friction model's
        parameters (``fc``, ``beta``, ...) or the circuit's (``alpha``,
        ``r_load``, ``r_coil``; c_e then follows Eq. 3). ``c`` sets the total
        damping, split in the current ratio of c_m to c_e.
        """
        own = {
            name: changes.pop(name)
            for name in ("m", "c_m", "c_e", "k", "k3", "friction", "stroke")
            if name in changes
        }
        if "c" in changes:
            c_new = np.asarray(changes.pop("c"), dtype=float)
            share = self.c_m / self.c if np.all(self.c > 0) else 0.5
            own.setdefault("c_m", c_new * share)
            own.setdefault("c_e", c_new * (1 - share))
        friction = own.pop("friction", self.friction)
        if friction is not None:
            names = {f.name for f in fields(friction)}
            mine = {key: changes.pop(key) for key in list(changes) if key in names}
            if mine:
                friction = dataclasses.replace(friction, **mine)
        electrical = self.electrical
        circuit_names = (
            electrical.parameter_names()
            if electrical is not None
            else ("alpha", "r_load", "r_coil")
        )
        circuit = {key: changes.pop(key) for key in list(changes) if key in circuit_names}
        if circuit:
            if electrical is None:
                raise ValueError(
                    f"cannot set {sorted(circuit)}: this harvester has no circuit "
                    "(build it with Harvester.from_electrical)"
                )
            electrical = dataclasses.replace(electrical, **circuit)
            own["c_e"] = electrical.electrical_damping
        elif electrical is not None and "c_e" in own:
            electrical = None  # an explicit c_e overrides the circuit
        if changes:
            allowed = sorted(
                {"m", "c", "c_m", "c_e", "k", "k3", "stroke", *circuit_names}
                | ({f.name for f in fields(friction)} if friction else set())
            )
            raise ValueError(
                f"unknown parameter name(s) {sorted(changes)}; allowed: {', '.join(allowed)}"
            )
        return dataclasses.replace(self, friction=friction, electrical=electrical, **own)


def harvester_from_parameters(parameters: dict) -> Harvester:
    """The device that :meth:`Harvester.parameters` describes (a saved result's ``device``).

    ``friction`` names the law (``none``: without), ``coupling`` the coupling
    (a bridge by its name, ``inductive bridge``; absent with ``alpha``: the
    resistive one of Eq. 3); every other key is a parameter of the device,
    the law or the coupling. ``c_e`` is taken as given without a coupling and
    follows from the coupling with one.
    """
    from randvib.models.friction import friction_law
    from randvib.models.rectifier import RECTIFIED

    rest = dict(parameters)
    law = friction_law(rest.pop("friction", "none"))
    friction = None if law is None else law(**_own(rest, law))
    coupling_name = rest.pop("coupling", "resistive" if "alpha" in rest else None)
    own = {
        name: rest.pop(name) for name in ("m", "c_m", "c_e", "k", "k3", "stroke") if name in rest
    }
    if coupling_name is None:
        _no_leftovers(rest)
        return Harvester(friction=friction, **own)
    classes = {cls.name: cls for cls in (*COUPLINGS.values(), *RECTIFIED.values())}
    if coupling_name not in classes:
        raise ValueError(f"unknown coupling {coupling_name!r}; known: {', '.join(classes)}")
    coupling = classes[coupling_name](**_own(rest, classes[coupling_name]))
    _no_leftovers(rest)
    own.pop("c_e", None)  # the coupling's own
    return Harvester.with_coupling(coupling=coupling, friction=friction, **own)


def _own(values: dict, cls) -> dict:
    """The entries of ``values`` that are fields of the dataclass ``cls`` (taken out)."""
    return {f.name: values.pop(f.name) for f in fields(cls) if f.name in values}


def _no_leftovers(values: dict) -> None:
    if values:
        raise ValueError(f"unknown device parameter(s) {sorted(values)}")
