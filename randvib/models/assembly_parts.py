"""The parts of an assembly that act on one relative coordinate: springs, elements, transducers.

An element or a transducer of an :class:`~randvib.models.assembly.Assembly`
acts on the relative motion ``u = x_i - x_j`` of two degrees of freedom, or
``u = x_i`` of one against the base (``between = (i, None)``, written
``[i, "base"]`` in a device file), with equal and opposite forces: ``+f`` on
DOF i and ``-f`` on DOF j (docs/conventions.md, "Assemblies").

* :class:`Spring` - the restoring force ``k u + k2 u^2 + k3 u^3`` (N): every
  spring law randvib has (linear, quadratic, cubic; a
  :class:`~randvib.models.potential.Potential` is converted to one).
* :class:`Element` - a spring, a friction law of
  :mod:`randvib.models.friction` (Coulomb, tanh, LuGre with its bristle
  state, or any registered law), a viscous dashpot ``damping`` (Ns/m) and an
  optional ``stroke`` (m) on its coordinate, in any combination.
* :class:`Transducer` - an electrical coupling of
  :mod:`randvib.models.coupling` or :mod:`randvib.models.rectifier`
  (resistive, inductive, piezo, a coil or piezo into a diode bridge) on its
  coordinate; a bare electrical damping c_e (the CLI's ``--c-e``) is an
  :class:`ElectricalDamper`.

All are frozen dataclasses of scalars, validated on construction with
messages that name the argument, its value and what is allowed.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, fields

import numpy as np

from randvib._validation import check_finite, check_nonnegative, check_positive
from randvib.models.coupling import Coupling
from randvib.models.friction import FrictionModel
from randvib.models.parameters import parameter
from randvib.models.potential import Potential

#: How a device file and messages name the base in ``between``.
BASE = "base"


def _one_number(name: str, value, check, unit: str) -> float:
    """``check(name, value, unit)`` of one number, as a float; an array is refused by name."""
    if isinstance(value, bool | np.bool_) or np.ndim(value) != 0:
        raise ValueError(f"`{name}` must be one number ({unit or 'dimensionless'}), got {value!r}")
    return float(check(name, value, unit))


def _check_real(name, value, _unit=""):
    return check_finite(name, value)


def parse_between(value, who: str = "between") -> tuple[int, int | None]:
    """``(i, j)`` from two DOF indices, or ``(i, None)`` from ``[i, "base"]`` / ``(i, None)``.

    Indices are integers >= 0 and differ; DOF existence is checked by the
    assembly, which knows how many there are.
    """
    try:
        first, second = value
    except (TypeError, ValueError):
        raise ValueError(
            f'`{who}` must be two DOF indices or a DOF index and "base", e.g. [1, 0] or '
            f'[1, "base"]; got {value!r}'
        ) from None
    pair = []
    for position, item in enumerate((first, second)):
        if position == 1 and (item is None or item == BASE):
            pair.append(None)
            continue
        if isinstance(item, bool) or not isinstance(item, numbers.Integral) or item < 0:
            allowed = 'an integer >= 0 or "base"' if position == 1 else "an integer >= 0"
            raise ValueError(
                f"`{who}` = {_shown(value)}: entry {position} must be {allowed}, got {item!r}"
            )
        pair.append(int(item))
    if pair[0] == pair[1]:
        raise ValueError(f"`{who}` = {_shown(value)} joins DOF {pair[0]} to itself")
    return pair[0], pair[1]


def _shown(value) -> str:
    """``between`` as a device file writes it: ``[1, "base"]``."""
    try:
        return "[" + ", ".join('"base"' if x is None or x == BASE else repr(x) for x in value) + "]"
    except TypeError:
        return repr(value)


def between_words(between: tuple[int, int | None]) -> str:
    """``[1, 0]`` or ``[1, "base"]``: a coordinate as the device file writes it."""
    return _shown(between)


def incidence(between: tuple[int, int | None], n_dof: int) -> np.ndarray:
    """The vector d with u = d^T x: d_i = 1, d_j = -1 (no j for the base)."""
    d = np.zeros(n_dof)
    i, j = between
    d[i] = 1.0
    if j is not None:
        d[j] = -1.0
    return d


def check_between_in(between, n_dof: int, who: str) -> None:
    """Refuse a coordinate on a DOF the assembly does not have, naming ``who``."""
    for index in between:
        if index is not None and index >= n_dof:
            raise ValueError(
                f"{who}: `between` = {between_words(between)} names DOF {index}, but the "
                f'structure has DOFs 0..{n_dof - 1} (or "base")'
            )


def _check_stroke(stroke):
    if stroke is None:
        return None
    return _one_number("stroke", stroke, check_positive, "m")


# ----------------------------------------------------------------- springs
@dataclass(frozen=True, eq=False)
class Spring:
    """The restoring force ``k u + k2 u^2 + k3 u^3`` (N) on a relative coordinate u.

    Parameters
    ----------
    k : float
        Linear stiffness (N/m), any finite value (negative: a bistable
        element with k3 > 0).
    k2 : float
        Quadratic stiffness (N/m^2), any finite value (an asymmetric spring).
    k3 : float
        Cubic (Duffing) stiffness (N/m^3), any finite value.
    """

    k: float = 0.0
    k2: float = 0.0
    k3: float = 0.0

    def __post_init__(self):
        for name, unit in (("k", "N/m"), ("k2", "N/m^2"), ("k3", "N/m^3")):
            object.__setattr__(
                self, name, _one_number(name, getattr(self, name), _check_real, unit)
            )

    @classmethod
    def of(cls, value) -> Spring:
        """A Spring from a Spring, a :class:`Potential` (k, k3) or a mapping of k, k2, k3."""
        if isinstance(value, Spring):
            return value
        if isinstance(value, Potential):
            return cls(k=value.k, k3=value.k3)
        if isinstance(value, dict):
            unknown = sorted(set(value) - {"k", "k2", "k3"})
            if unknown:
                raise ValueError(
                    f"`spring` has unknown key(s) {', '.join(map(repr, unknown))}; "
                    "allowed: k (N/m), k2 (N/m^2), k3 (N/m^3)"
                )
            return cls(**value)
        raise ValueError(
            f"`spring` must be a randvib Spring, a Potential or {{k, k2, k3}}, got {value!r}"
        )

    def force(self, u):
        """Restoring force k u + k2 u^2 + k3 u^3 (N) at ``u`` (m)."""
        u = np.asarray(u, dtype=float)
        return self.k * u + self.k2 * u * u + self.k3 * u**3

    def energy(self, u):
        """Stored energy k u^2/2 + k2 u^3/3 + k3 u^4/4 (J)."""
        u = np.asarray(u, dtype=float)
        return 0.5 * self.k * u * u + self.k2 * u**3 / 3.0 + 0.25 * self.k3 * u**4

    @property
    def is_linear(self) -> bool:
        """True when the force is k u (k2 = k3 = 0)."""
        return self.k2 == 0.0 and self.k3 == 0.0

    def parameters(self) -> dict:
        return {"k": self.k, "k2": self.k2, "k3": self.k3}


# ---------------------------------------------------------------- elements
@dataclass(frozen=True, eq=False)
class Element:
    """A spring, friction law and/or dashpot on the relative coordinate ``between``.

    Parameters
    ----------
    between : (int, int or None)
        The DOFs i, j of ``u = x_i - x_j``; ``(i, None)`` (or ``(i, "base")``)
        for ``u = x_i`` against the base. The force f(u, u') acts as ``+f``
        on DOF i and ``-f`` on DOF j.
    spring : Spring, Potential, dict or None
        The restoring force k u + k2 u^2 + k3 u^3 (:class:`Spring`).
    friction : FrictionModel or None
        A friction law of the relative velocity u' (with its own state for
        LuGre).
    damping : float
        A viscous dashpot c u' on the coordinate (Ns/m), >= 0.
    stroke : float or None
        The largest |u| (m) before end stops: reported, not acted on.
    """

    between: tuple
    spring: Spring | None = None
    friction: FrictionModel | None = None
    damping: float = 0.0
    stroke: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "between", parse_between(self.between))
        if self.spring is not None:
            object.__setattr__(self, "spring", Spring.of(self.spring))
        if self.friction is not None:
            if not isinstance(self.friction, FrictionModel):
                raise ValueError(
                    "`friction` must be a randvib friction law (Coulomb, Tanh, LuGre, ...) or "
                    f"None, got {self.friction!r}"
                )
            for name, value in self.friction.parameters().items():
                if np.ndim(value):
                    raise ValueError(
                        f"`friction` parameter `{name}` must be one number, got {value!r}"
                    )
        object.__setattr__(
            self, "damping", _one_number("damping", self.damping, check_nonnegative, "Ns/m")
        )
        object.__setattr__(self, "stroke", _check_stroke(self.stroke))
        if (
            self.spring is None
            and self.friction is None
            and self.damping == 0
            and self.stroke is None
        ):
            raise ValueError(
                f"the element on {between_words(self.between)} has no `spring`, `friction`, "
                "`damping` or `stroke`: give at least one"
            )

    @property
    def linear_stiffness(self) -> float:
        """The spring's k (N/m); 0 without a spring."""
        return 0.0 if self.spring is None else self.spring.k

    @property
    def is_linear(self) -> bool:
        """True when the element is a linear spring and dashpot (no k2, k3 or friction)."""
        spring_linear = self.spring is None or self.spring.is_linear
        return spring_linear and (self.friction is None or self.friction.vanishes)

    def nonlinear_force(self, u, v, theta=None):
        """The force beyond the linear part: k2 u^2 + k3 u^3 + F(v, theta) (N)."""
        u = np.asarray(u, dtype=float)
        out = np.zeros(np.broadcast(u, np.asarray(v)).shape)
        if self.spring is not None:
            out = out + self.spring.k2 * u * u + self.spring.k3 * u**3
        if self.friction is not None:
            out = out + self.friction.force(v, theta)
        return out

    def parameters(self) -> dict:
        """Every number by its path under ``element.N.`` (friction's by its own names)."""
        out = {}
        if self.spring is not None:
            out.update(self.spring.parameters())
        if self.friction is not None:
            out.update(self.friction.parameters())
        out["damping"] = self.damping
        if self.stroke is not None:
            out["stroke"] = self.stroke
        return out


# -------------------------------------------------------------- transducers
@dataclass(frozen=True, eq=False)
class ElectricalDamper(Coupling):
    """A bare electrical damping c_e (the single-mass ``--c-e``): force c_e u', power c_e u'^2.

    The electrical side is not described (no circuit, no load): its power is
    ``power_electrical`` and there is no ``power_load``. Not registered in
    :data:`~randvib.models.coupling.COUPLINGS` (the CLI's ``--coupling``
    names circuits); a device file writes it ``coupling = "resistive"`` with
    ``c_e``, as the command line's ``--c-e``.

    Parameters
    ----------
    c_e : float
        Electrical damping (Ns/m), >= 0.
    """

    c_e: float = parameter("Ns/m", description="electrical damping c_e")

    #: A bare damper has no load resistance: no power_load.
    has_load = False

    @property
    def electrical_damping(self):
        return self.c_e

    def white_noise_optimal_load(self, m, c_m, k):
        raise ValueError("a bare electrical damping c_e has no load resistance to optimise")


# Set after the class is made, so that it is not registered as a --coupling choice:
# it is the resistive coupling given by its damping alone.
ElectricalDamper.name = "resistive"


@dataclass(frozen=True, eq=False)
class Transducer:
    """An electrical coupling on the relative coordinate ``between``.

    Parameters
    ----------
    between : (int, int or None)
        As for :class:`Element`: the magnet moves with u = x_i - x_j relative
        to its coil (or piezo element), or u = x_i against the base.
    coupling : Coupling or float
        A coupling of :mod:`randvib.models.coupling` (``Resistive``,
        ``Inductive``, ``Piezo``) or :mod:`randvib.models.rectifier`
        (``BridgeCoil``, ``BridgePiezo``); a number is a bare electrical
        damping c_e (Ns/m, :class:`ElectricalDamper`).
    stroke : float or None
        The largest |u| (m) before end stops: reported, not acted on.
    """

    between: tuple
    coupling: Coupling
    stroke: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "between", parse_between(self.between))
        coupling = self.coupling
        if not isinstance(coupling, Coupling):
            if isinstance(coupling, numbers.Real) and not isinstance(coupling, bool):
                coupling = ElectricalDamper(c_e=coupling)
            else:
                raise ValueError(
                    "`coupling` must be a randvib coupling (Resistive, Inductive, Piezo, "
                    f"BridgeCoil, BridgePiezo) or an electrical damping c_e in Ns/m, got {coupling!r}"
                )
        for name, value in coupling.parameters().items():
            if value is not None and np.ndim(value):
                raise ValueError(f"`coupling` parameter `{name}` must be one number, got {value!r}")
        object.__setattr__(self, "coupling", coupling)
        object.__setattr__(self, "stroke", _check_stroke(self.stroke))

    @property
    def is_dynamic(self) -> bool:
        """True for a linear coupling with a circuit state (inductance or capacitance > 0)."""
        return not self.coupling.rectified and self.coupling.is_dynamic

    @property
    def is_rectified(self) -> bool:
        """True for a coupling through a diode bridge."""
        return self.coupling.rectified

    @property
    def has_load(self) -> bool:
        """True when the coupling names a load resistance (power_load is defined)."""
        return getattr(self.coupling, "has_load", True)

    @property
    def electrical_damping(self) -> float:
        """c_e (Ns/m) of a static linear coupling; 0 for a circuit state or a bridge."""
        if self.coupling.rectified or self.coupling.is_dynamic:
            return 0.0
        return float(self.coupling.electrical_damping)

    def parameters(self) -> dict:
        """Every number by its path under ``transducer.N.`` (the coupling's own names)."""
        out = {k: v for k, v in self.coupling.parameters().items() if v is not None}
        if self.stroke is not None:
            out["stroke"] = self.stroke
        return out


def coupling_words(coupling: Coupling) -> str:
    """``resistive``, ``inductive``, ``piezo``, ``inductive bridge`` or ``piezo bridge``."""
    return coupling.name


def declared_fields(obj) -> tuple[str, ...]:
    """The dataclass field names of a friction law or coupling."""
    return tuple(f.name for f in fields(obj))
