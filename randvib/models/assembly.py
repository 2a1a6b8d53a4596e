"""Assemblies: harvesters on a host structure, two-mass harvesters, arrays (issue 31).

An assembly has N degrees of freedom x, displacements relative to the base
(docs/conventions.md, "Assemblies"; docs/assemblies.md):

    M x'' + C x' + K x + sum_e d_e f_e(u_e, u_e') = -M r a(t),     u_e = d_e^T x

with a linear structure (mass, damping and stiffness matrices M, C, K and the
influence vector r; :mod:`randvib.models.structure` builds them from
matrices, a chain or modes) and parts that act on one relative coordinate
u = x_i - x_j, or u = x_i against the base (d_e has +1 at i and -1 at j):
:class:`~randvib.models.assembly_parts.Element` (spring k u + k2 u^2 + k3 u^3,
friction of any law, a dashpot) and
:class:`~randvib.models.assembly_parts.Transducer` (any coupling of
:mod:`randvib.models.coupling` or :mod:`randvib.models.rectifier`, with its
circuit state). The single-mass :class:`~randvib.models.harvester.Harvester`
is the one-DOF assembly (:meth:`Assembly.from_harvester`,
:meth:`Assembly.as_harvester`); its own code paths are kept for it.

Design notes
------------
* **Frozen, scalar, validated once.** :class:`Assembly` holds float64
  arrays and tuples of frozen parts; every constructor goes through
  ``__post_init__``, whose refusals name the argument (``mass``,
  ``elements[2]``) and the allowed values. No broadcasting over parameter
  arrays: a sweep builds one assembly per point (:meth:`Assembly.updated`).
* **The linear part** is what a Lyapunov equation sees: M; the structure's C
  and K plus every element's dashpot and linear spring k and every static
  coupling's c_e, each as ``c d d^T`` (:meth:`Assembly.linear_matrices`); the
  linear circuits' states. Nonlinear parts (k2, k3, friction, diode bridges)
  are not in it: the analytic methods linearise them, Monte Carlo integrates
  them.
* **State layout** of :meth:`Assembly.linear_state_space`:
  ``X = [x_0 .. x_{N-1}, x'_0 .. x'_{N-1}, s_0 .. s_{K-1}]`` where s_t is the
  circuit state (a coil's current in A, a piezo's voltage in V) of the t-th
  transducer in :attr:`Assembly.circuit_transducers` (the transducers with a
  linear dynamic coupling, in transducer order); input the base acceleration
  a (m/s^2): ``X' = A X + B a``. A circuit obeys ``s' = a_s s + b_s u'`` and
  pushes ``f_s s`` on its coordinate
  (:meth:`~randvib.models.coupling.Coupling.circuit_equation`).
* **Parameters by dotted path** (design's ``--vary`` and identification):
  ``structure.mass.I.J`` (``structure.mass.I`` is the diagonal entry),
  ``structure.stiffness.I.J``, ``structure.damping.I.J`` (an off-diagonal
  path sets both symmetric entries), ``structure.influence.I``;
  ``element.N.k|k2|k3|damping|stroke`` and the friction law's own names
  (``element.N.fc``); ``transducer.N.<the coupling's names>`` (``c_e`` of a
  bare damper, ``alpha``, ``r_load``, ``inductance``, ``theta``, ...) and
  ``transducer.N.stroke``. :meth:`Assembly.get`, :meth:`Assembly.updated`,
  :meth:`Assembly.parameters`.
* **Strokes** sit on element or transducer coordinates
  (:meth:`Assembly.strokes`): "the stroke of the magnet relative to its host".
* **Device files** (TOML) are read and written by
  :mod:`randvib.models.device_file` (:meth:`Assembly.from_toml`,
  :meth:`Assembly.to_toml`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy import linalg

from randvib.models.assembly_parts import (
    ElectricalDamper,
    Element,
    Spring,
    Transducer,
    between_words,
    check_between_in,
    incidence,
)
from randvib.models.device_file import device_text, read_device
from randvib.models.harvester import Harvester
from randvib.models.structure import (
    chain_matrices,
    modal_matrices,
    structure_matrices,
)

__all__ = ["Assembly"]

#: The structure's matrices by the name a dotted path uses.
MATRICES = ("mass", "stiffness", "damping")
#: The units of the structure's entries, by the name a dotted path uses.
STRUCTURE_UNITS = {"mass": "kg", "stiffness": "N/m", "damping": "Ns/m", "influence": ""}
#: The units of an element's own numbers and of any part's stroke.
PART_UNITS = {"k": "N/m", "k2": "N/m^2", "k3": "N/m^3", "damping": "Ns/m", "stroke": "m"}


@dataclass(frozen=True, eq=False)
class Assembly:
    """A linear structure of N DOFs with elements and transducers on relative coordinates.

    Build one with :meth:`from_matrices`, :meth:`chain`, :meth:`from_modes`,
    :meth:`from_toml` or :meth:`from_harvester` (the constructor takes the
    same arguments as :meth:`from_matrices`).

    Parameters
    ----------
    mass : array_like
        Mass matrix M (kg): a list (its diagonal) or a symmetric
        positive-definite matrix.
    stiffness : array_like
        Symmetric stiffness matrix K (N/m).
    damping : array_like
        Symmetric positive semi-definite damping matrix C (Ns/m).
    influence : array_like or None
        Influence vector r (default all ones: every DOF feels the base
        acceleration with its own mass).
    elements : sequence of Element
        Springs, friction and dashpots on relative coordinates.
    transducers : sequence of Transducer
        Electrical couplings on relative coordinates, reported in this order.

    Examples
    --------
    >>> import randvib as rv
    >>> host = rv.Assembly.chain(
    ...     mass=[0.5, 0.05], stiffness=[3750.6, 197.4], damping=[0.6, 0.02],
    ...     transducers=[rv.Transducer((1, 0), 0.05)],
    ... )
    >>> host.n_dof, [round(f, 3) for f in host.natural_frequencies()]
    (2, [9.531, 14.463])
    >>> host.get("transducer.0.c_e")
    0.05
    """

    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    influence: np.ndarray | None = None
    elements: tuple = ()
    transducers: tuple = ()

    def __post_init__(self):
        m, c, k, r = structure_matrices(self.mass, self.stiffness, self.damping, self.influence)
        for name, value in (("mass", m), ("damping", c), ("stiffness", k), ("influence", r)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        for name, kind in (("elements", Element), ("transducers", Transducer)):
            parts = getattr(self, name)
            if isinstance(parts, Element | Transducer) or not isinstance(parts, list | tuple):
                raise ValueError(f"`{name}` must be a list of {kind.__name__}, got {parts!r}")
            for index, part in enumerate(parts):
                if not isinstance(part, kind):
                    raise ValueError(
                        f"`{name}[{index}]` must be a randvib {kind.__name__}, got {part!r}"
                    )
                check_between_in(part.between, self.n_dof, f"`{name}[{index}]`")
            object.__setattr__(self, name, tuple(parts))

    # ------------------------------------------------------------ constructors
    @classmethod
    def from_matrices(
        cls, mass, stiffness, damping, influence=None, elements=(), transducers=()
    ) -> Assembly:
        """The assembly of the given matrices (see the class parameters)."""
        return cls(mass, stiffness, damping, influence, tuple(elements), tuple(transducers))

    @classmethod
    def chain(cls, mass, stiffness, damping, elements=(), transducers=()) -> Assembly:
        """A chain of lumped masses: mass i joined to mass i - 1, mass 0 to the base.

        ``stiffness[i]`` (N/m) and ``damping[i]`` (Ns/m) join mass i to its
        neighbour below (:func:`~randvib.models.structure.chain_matrices`).
        """
        m, c, k, r = chain_matrices(mass, stiffness, damping)
        return cls(m, k, c, r, tuple(elements), tuple(transducers))

    @classmethod
    def from_modes(
        cls,
        frequency,
        damping_ratio,
        modal_mass,
        participation,
        shapes,
        masses=(),
        elements=(),
        transducers=(),
    ) -> Assembly:
        """A host given by its modes at its attachment points, plus lumped ``masses``.

        DOFs 0..n-1 are the attachment points' displacements (as many as
        modes), then one per lumped mass
        (:func:`~randvib.models.structure.modal_matrices`).
        """
        m, c, k, r = modal_matrices(
            frequency, damping_ratio, modal_mass, participation, shapes, masses
        )
        return cls(m, k, c, r, tuple(elements), tuple(transducers))

    @classmethod
    def from_toml(cls, path) -> Assembly:
        """Read a device file (:mod:`randvib.models.device_file`, docs/assemblies.md)."""
        return cls.from_matrices(**read_device(path))

    def to_toml(self) -> str:
        """The device file text of this assembly (matrix form), which :meth:`from_toml` reads back."""
        return device_text(self)

    @classmethod
    def from_harvester(cls, harvester: Harvester) -> Assembly:
        """The one-DOF assembly of a single-mass harvester.

        ``M = [[m]]``, ``C = [[c_m]]``, ``K = [[k]]``; one element on
        ``(0, base)`` with the cubic spring k3, the friction law and the
        stroke (where any is given); one transducer on ``(0, base)`` with the
        coupling (a bare c_e, possibly 0, as an ElectricalDamper).
        """
        if not isinstance(harvester, Harvester):
            raise ValueError(f"`harvester` must be a randvib Harvester, got {harvester!r}")
        values = {name: getattr(harvester, name) for name in ("m", "c_m", "c_e", "k", "k3")}
        arrays = [name for name, value in values.items() if np.ndim(value)]
        if arrays:
            raise ValueError(
                f"an assembly has scalar parameters: the harvester's `{arrays[0]}` is an array; "
                "make one assembly per value"
            )
        spring = Spring(k3=harvester.k3) if harvester.k3 != 0 else None
        elements = ()
        if spring is not None or harvester.friction is not None or harvester.stroke is not None:
            elements = (Element((0, None), spring, harvester.friction, stroke=harvester.stroke),)
        coupling = harvester.electrical
        if coupling is None:
            coupling = ElectricalDamper(c_e=harvester.c_e)
        transducers = (Transducer((0, None), coupling),)
        return cls(
            [[harvester.m]], [[harvester.k]], [[harvester.c_m]], [1.0], elements, transducers
        )

    def as_harvester(self) -> Harvester:
        """The single-mass Harvester this assembly is, or a ValueError saying why it is not one.

        A one-DOF assembly with influence 1, parts on ``(0, base)`` only, no
        quadratic spring, at most one friction law, one transducer and one
        stroke: its linear springs and dashpots add to k and c_m, its cubic
        springs to k3.
        """
        why = self._not_single_mass()
        if why:
            raise ValueError(f"this assembly is not a single-mass harvester: {why}")
        springs = [e.spring for e in self.elements if e.spring is not None]
        frictions = [e.friction for e in self.elements if e.friction is not None]
        strokes = [p.stroke for p in self.elements + self.transducers if p.stroke is not None]
        k = float(self.stiffness[0, 0]) + sum(s.k for s in springs)
        k3 = sum(s.k3 for s in springs)
        c_m = float(self.damping[0, 0]) + sum(e.damping for e in self.elements)
        friction = frictions[0] if frictions else None
        stroke = strokes[0] if strokes else None
        m = float(self.mass[0, 0])
        coupling = self.transducers[0].coupling if self.transducers else ElectricalDamper(c_e=0.0)
        if isinstance(coupling, ElectricalDamper):
            return Harvester(m, c_m, coupling.c_e, k, k3, friction, None, stroke)
        return Harvester.with_coupling(m, c_m, k, coupling, k3, friction, stroke)

    def _not_single_mass(self) -> str:
        """Why the assembly is not a Harvester, in words; empty when it is one."""
        parts = self.elements + self.transducers
        if self.n_dof != 1:
            return f"it has {self.n_dof} DOFs"
        if self.influence[0] != 1.0:
            return f"its influence is {self.influence[0]!r}, not 1"
        if any(p.between != (0, None) for p in parts):
            return "a part is not on (0, base)"
        checks = (
            (any(e.spring is not None and e.spring.k2 != 0 for e in self.elements), "k2 != 0"),
            (sum(e.friction is not None for e in self.elements) > 1, "two friction laws"),
            (len(self.transducers) > 1, "two transducers"),
            (sum(p.stroke is not None for p in parts) > 1, "two strokes"),
        )
        return next((why for bad, why in checks if bad), "")

    # ------------------------------------------------------------ what it is
    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom N."""
        return self.mass.shape[0]

    def incidence(self, part) -> np.ndarray:
        """d with u = d^T x for an Element, a Transducer or a ``between`` pair."""
        between = getattr(part, "between", part)
        return incidence(between, self.n_dof)

    @property
    def circuit_transducers(self) -> tuple[int, ...]:
        """Indices of the transducers whose circuit state is in :meth:`linear_state_space`."""
        return tuple(i for i, t in enumerate(self.transducers) if t.is_dynamic)

    @property
    def is_linear(self) -> bool:
        """True when every part is linear: no k2, k3, acting friction or diode bridge."""
        return all(e.is_linear for e in self.elements) and not any(
            t.is_rectified for t in self.transducers
        )

    @property
    def has_friction_memory(self) -> bool:
        """True when some element's friction law carries a state (LuGre)."""
        return any(e.friction is not None and e.friction.has_memory for e in self.elements)

    def linear_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(M, C_lin, K_lin): the structure plus every linear part, each as ``c d d^T``.

        C_lin adds the elements' dashpots and the static couplings' c_e; K_lin
        the elements' linear springs k. Nonlinear parts and circuit states are
        not included (see the module docstring).
        """
        c = self.damping.copy()
        k = self.stiffness.copy()
        for element in self.elements:
            d = self.incidence(element)
            c += element.damping * np.outer(d, d)
            k += element.linear_stiffness * np.outer(d, d)
        for transducer in self.transducers:
            d = self.incidence(transducer)
            c += transducer.electrical_damping * np.outer(d, d)
        return self.mass.copy(), c, k

    def linear_state_space(self, extra_damping=None, extra_stiffness=None):
        """(A, B) of the linear part: ``X' = A X + B a`` with the base acceleration a (m/s^2).

        States ``[x (N), x' (N), circuit states (len(circuit_transducers))]``
        (module docstring). ``extra_damping`` and ``extra_stiffness`` (N x N)
        are added to C_lin and K_lin: the equivalent linear parts of the
        linearised elements (:mod:`randvib.analytic.assembly_linearisation`).
        """
        m, c, k = self.linear_matrices()
        if extra_damping is not None:
            c = c + extra_damping
        if extra_stiffness is not None:
            k = k + extra_stiffness
        n, circuits = self.n_dof, self.circuit_transducers
        size = 2 * n + len(circuits)
        m_inv = linalg.inv(m)
        a = np.zeros((size, size))
        a[:n, n : 2 * n] = np.eye(n)
        a[n : 2 * n, :n] = -m_inv @ k
        a[n : 2 * n, n : 2 * n] = -m_inv @ c
        for slot, index in enumerate(circuits, start=2 * n):
            transducer = self.transducers[index]
            a_s, b_s, f_s = transducer.coupling.circuit_equation()
            d = self.incidence(transducer)
            a[n : 2 * n, slot] = -f_s * (m_inv @ d)
            a[slot, n : 2 * n] = b_s * d
            a[slot, slot] = a_s
        b = np.zeros(size)
        b[n : 2 * n] = -self.influence
        return a, b

    def state_names(self) -> tuple[str, ...]:
        """Names of the states of :meth:`linear_state_space`: ``x0``, ``v0``, ``current2``..."""
        names = [f"x{i}" for i in range(self.n_dof)] + [f"v{i}" for i in range(self.n_dof)]
        for index in self.circuit_transducers:
            names.append(f"{self.transducers[index].coupling.state_name}{index}")
        return tuple(names)

    def natural_frequencies(self) -> list[float]:
        """Undamped natural frequencies (Hz) of the linear part, ascending (0 for a free mode)."""
        m, _, k = self.linear_matrices()
        eig = linalg.eigh(k, m, eigvals_only=True)
        return [float(np.sqrt(max(e, 0.0)) / (2.0 * np.pi)) for e in eig]

    def strokes(self) -> list[tuple[str, tuple, float]]:
        """(path, between, stroke) of every part with a stroke: ``("element.0", (1, 0), 0.004)``."""
        out = []
        for kind, parts in (("element", self.elements), ("transducer", self.transducers)):
            for index, part in enumerate(parts):
                if part.stroke is not None:
                    out.append((f"{kind}.{index}", part.between, part.stroke))
        return out

    def describe(self) -> str:
        """One line: the DOFs, elements and transducers."""
        parts = [
            f"{self.n_dof} DOF(s), masses {', '.join(f'{x:g}' for x in np.diag(self.mass))} kg"
        ]
        for kind, items in (("element", self.elements), ("transducer", self.transducers)):
            for index, part in enumerate(items):
                what = part.coupling.name if kind == "transducer" else _element_words(part)
                parts.append(f"{kind} {index} on {between_words(part.between)}: {what}")
        return "; ".join(parts)

    # ------------------------------------------------------------ parameters
    def parameters(self) -> dict[str, float]:
        """Every number by its dotted path (module docstring), the structure's included."""
        out = {}
        for name in MATRICES:
            matrix = getattr(self, name)
            for (i, j), value in np.ndenumerate(matrix):
                out[f"structure.{name}.{i}.{j}"] = float(value)
        for i, value in enumerate(self.influence):
            out[f"structure.influence.{i}"] = float(value)
        for kind, parts in (("element", self.elements), ("transducer", self.transducers)):
            for index, part in enumerate(parts):
                for name, value in part.parameters().items():
                    out[f"{kind}.{index}.{name}"] = value
        return out

    def get(self, path: str):
        """The number at a dotted path (``transducer.0.c_e``, ``element.1.k3``, ...)."""
        kind, index, name = _split(path, self)
        if kind == "structure":
            return float(getattr(self, index)[name])
        part = _part(self, kind, index, path)
        if kind == "transducer" and name == "c_e":
            return part.electrical_damping
        values = part.parameters()
        if kind == "element" and name in ("k", "k2", "k3") and part.spring is None:
            return 0.0
        if name == "stroke" and part.stroke is None:
            return None
        if name not in values:
            raise ValueError(_unknown_path(path, kind, index, part))
        return values[name]

    def parameter_unit(self, path: str) -> str:
        """The SI unit of the number at a dotted path (``""`` for the influence or unknown)."""
        kind, index, name = _split(path, self)
        if kind == "structure":
            return STRUCTURE_UNITS[index]
        part = _part(self, kind, index, path)
        if name in PART_UNITS:
            return PART_UNITS[name]
        models = (part.friction,) if kind == "element" else (part.coupling,)
        for model in models:
            specs = type(model).parameter_specs() if model is not None else {}
            if name in specs:
                return specs[name].unit
        return ""

    def updated(self, changes: dict) -> Assembly:
        """A copy with the numbers at the given dotted paths changed (validated again).

        ``{"element.1.k3": 1e6, "transducer.0.r_load": 4.0}``; an off-diagonal
        structure entry sets both symmetric entries.
        """
        if not isinstance(changes, dict):
            raise ValueError(f"`changes` must be a dict of dotted path -> value, got {changes!r}")
        matrices = {name: np.array(getattr(self, name)) for name in (*MATRICES, "influence")}
        parts = {"element": list(self.elements), "transducer": list(self.transducers)}
        for path, value in changes.items():
            kind, index, name = _split(path, self)
            if kind == "structure":
                matrix = matrices[index]
                matrix[name] = value
                if len(name) == 2:
                    matrix[name[::-1]] = value
            else:
                part = _part(self, kind, index, path)
                parts[kind][index] = _updated_part(parts[kind][index], name, value, path, part)
        return Assembly(
            matrices["mass"], matrices["stiffness"], matrices["damping"], matrices["influence"],
            tuple(parts["element"]), tuple(parts["transducer"]),
        )  # fmt: skip


def _element_words(element: Element) -> str:
    words = []
    if element.spring is not None:
        s = element.spring
        words.append(f"spring k {s.k:g} N/m, k2 {s.k2:g} N/m^2, k3 {s.k3:g} N/m^3")
    if element.friction is not None:
        words.append(f"{element.friction.name} friction")
    if element.damping:
        words.append(f"dashpot {element.damping:g} Ns/m")
    if element.stroke is not None:
        words.append(f"stroke {element.stroke:g} m")
    return ", ".join(words)


def _split(path, assembly: Assembly):
    """(kind, index, name) of a dotted path; for the structure (``structure``, matrix, entry)."""
    if not isinstance(path, str):
        raise ValueError(f"a parameter path must be a string such as 'element.0.k3', got {path!r}")
    pieces = path.split(".")
    if pieces[0] == "structure":
        return ("structure", *_structure_entry(path, pieces[1:], assembly.n_dof))
    if pieces[0] in ("element", "transducer") and len(pieces) == 3 and pieces[1].isdigit():
        return pieces[0], int(pieces[1]), pieces[2]
    raise ValueError(
        f"unknown parameter path {path!r}: paths are structure.mass|stiffness|damping.I.J, "
        "structure.influence.I, element.N.NAME or transducer.N.NAME"
    )


def _structure_entry(path: str, rest: list[str], n: int):
    """(matrix name, index tuple) of ``structure.NAME.I[.J]``."""
    if rest and rest[0] in (*MATRICES, "influence") and all(p.isdigit() for p in rest[1:]):
        name, indices = rest[0], tuple(int(p) for p in rest[1:])
        if name == "mass" and len(indices) == 1:
            indices = (indices[0], indices[0])  # the diagonal entry
        wanted = 1 if name == "influence" else 2
        if len(indices) == wanted and all(i < n for i in indices):
            return name, indices
    raise ValueError(
        f"unknown parameter path {path!r}: the structure's are structure.mass.I[.J], "
        f"structure.stiffness.I.J, structure.damping.I.J and structure.influence.I, with "
        f"I, J in 0..{n - 1}"
    )


def _part(assembly: Assembly, kind: str, index: int, path: str):
    parts = assembly.elements if kind == "element" else assembly.transducers
    if index >= len(parts):
        raise ValueError(
            f"unknown parameter path {path!r}: the assembly has {len(parts)} {kind}(s) "
            f"(0..{len(parts) - 1})"
            if parts
            else f"unknown parameter path {path!r}: the assembly has no {kind}"
        )
    return parts[index]


def _unknown_path(path: str, kind: str, index: int, part) -> str:
    names = sorted(part.parameters())
    if kind == "element":
        names = sorted({*names, "k", "k2", "k3", "damping", "stroke"})
    else:
        names = sorted({*names, "stroke"} | ({"c_e"} if part.electrical_damping else set()))
    return f"unknown parameter path {path!r}; {kind} {index} has {', '.join(names)}"


def _updated_part(part, name: str, value, path: str, original):
    """``part`` with its parameter ``name`` set to ``value`` (Element or Transducer)."""
    if name == "stroke":
        return dataclasses.replace(part, stroke=value)
    if isinstance(part, Element):
        if name in ("k", "k2", "k3"):
            spring = part.spring or Spring()
            return dataclasses.replace(part, spring=dataclasses.replace(spring, **{name: value}))
        if name == "damping":
            return dataclasses.replace(part, damping=value)
        law = part.friction
        if law is not None and name in law.parameter_names():
            return dataclasses.replace(part, friction=dataclasses.replace(law, **{name: value}))
        raise ValueError(_unknown_path(path, "element", int(path.split(".")[1]), original))
    coupling = part.coupling
    if name in coupling.parameter_names():
        return dataclasses.replace(part, coupling=dataclasses.replace(coupling, **{name: value}))
    if name == "c_e":
        raise ValueError(
            f"{path!r}: the {coupling.name} coupling's c_e follows from its circuit "
            f"({', '.join(coupling.parameter_names())}); change those"
        )
    raise ValueError(_unknown_path(path, "transducer", int(path.split(".")[1]), original))
