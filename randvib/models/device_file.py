"""Device files: an assembly in TOML (read with :mod:`tomllib`), and written back.

The schema (docs/assemblies.md; it may be extended, never changed)::

    [structure]                 # DOFs 0..N-1, coordinates relative to the base
    mass = [0.5, 0.05]          # kg: a list (diagonal) or a full matrix
    stiffness = [[3948.0, -197.4], [-197.4, 197.4]]   # N/m, full matrix
    damping = [[0.62, -0.02], [-0.02, 0.02]]          # Ns/m, full matrix
    influence = [1.0, 1.0]      # optional, default all ones

    [[element]]                 # any number
    between = [1, 0]            # two DOF indices, or [1, "base"]
    spring = { k3 = 5e5 }       # k (N/m), k2 (N/m^2), k3 (N/m^3)
    friction = { law = "coulomb", fc = 0.005 }   # any registered law and its parameters
    damping = 0.01              # a dashpot on the coordinate (Ns/m); extension
    stroke = 0.004              # the largest |u| (m); extension

    [[transducer]]              # any number, reported in file order
    between = [1, 0]
    coupling = "resistive"      # or "inductive", "piezo"; optional rectifier = "bridge"
    c_e = 0.05                  # the same parameter names as the command-line flags
    stroke = 0.004              # extension

Extensions of ``[structure]`` (instead of the matrices):

* ``chain = { mass = [...], stiffness = [...], damping = [...] }``: lumped
  masses, mass i joined to mass i - 1 and mass 0 to the base
  (:func:`~randvib.models.structure.chain_matrices`);
* ``modes = { frequency = [...], damping_ratio = [...], modal_mass = [...],
  participation = [...], shapes = [[...]] }`` with an optional
  ``masses = [...]`` (lumped masses appended as DOFs):
  :func:`~randvib.models.structure.modal_matrices`.

A transducer's parameters are its coupling's (``alpha``, ``r_load``,
``r_coil``, ``inductance``, ``theta``, ``capacitance``; with ``rectifier =
"bridge"`` the bridge's ``v_diode``, ``battery``, ``storage_capacitance``,
...); ``coupling = "resistive"`` also takes ``c_e`` alone, a bare
electrical damping, as ``--c-e`` does.

A bad file is refused with one line: the file, the table, the key, the value
and what is allowed (``[[element]] 1: `between` = [3, 0] names DOF 3, but
the structure has DOFs 0..1 (or "base")``).
"""

from __future__ import annotations

import tomllib
from dataclasses import MISSING, fields
from pathlib import Path

from randvib.models.assembly_parts import (
    BASE,
    ElectricalDamper,
    Element,
    Spring,
    Transducer,
    check_between_in,
    parse_between,
)
from randvib.models.coupling import COUPLINGS
from randvib.models.friction import FRICTION_MODELS
from randvib.models.rectifier import RECTIFIED
from randvib.models.structure import chain_matrices, modal_matrices, structure_matrices

#: The keys of each table (besides a coupling's parameters for a transducer).
STRUCTURE_KEYS = ("mass", "stiffness", "damping", "influence", "chain", "modes", "masses")
ELEMENT_KEYS = ("between", "spring", "friction", "damping", "stroke")
TRANSDUCER_KEYS = ("between", "coupling", "rectifier", "stroke")
CHAIN_KEYS = ("mass", "stiffness", "damping")
MODE_KEYS = ("frequency", "damping_ratio", "modal_mass", "participation", "shapes")


class DeviceFileError(ValueError):
    """A device file that cannot be read, or that describes no valid assembly: one line."""


def read_device(path) -> dict:
    """The arguments of :meth:`Assembly.from_matrices <randvib.models.assembly.Assembly.from_matrices>`
    from a device file.

    Raises
    ------
    DeviceFileError
        One line naming the file, the table, the key, the value and what is allowed.
    """
    path = Path(path)
    if path.is_dir():
        raise DeviceFileError(f"device file {path}: is a folder, not a TOML file")
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DeviceFileError(f"device file {path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DeviceFileError(f"device file {path}: cannot be read ({exc})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise DeviceFileError(f"device file {path}: is not valid TOML ({exc})") from None
    return parse_device(data, str(path))


def parse_device(data: dict, source: str = "device") -> dict:
    """The assembly's arguments from a parsed device file (``tomllib`` output)."""
    where = f"device file {source}"
    unknown = sorted(set(data) - {"structure", "element", "transducer", "description"})
    if unknown:
        raise DeviceFileError(
            f"{where}: unknown table or key {unknown[0]!r}; allowed: [structure], [[element]], "
            "[[transducer]] and description"
        )
    if not isinstance(data.get("structure"), dict):
        raise DeviceFileError(f"{where}: needs a [structure] table (mass, stiffness, damping)")
    try:
        mass, damping, stiffness, influence = _structure(data["structure"])
    except ValueError as exc:
        raise DeviceFileError(f"{where}: [structure] {exc}") from None
    n = mass.shape[0]
    out = {"mass": mass, "stiffness": stiffness, "damping": damping, "influence": influence}
    for kind, build in (("element", _element), ("transducer", _transducer)):
        tables = data.get(kind, [])
        if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
            raise DeviceFileError(f"{where}: `{kind}` must be an array of tables, [[{kind}]]")
        parts = []
        for index, table in enumerate(tables):
            label = f"[[{kind}]] {index}"
            try:
                part = build(table)
                check_between_in(part.between, n, label)
            except ValueError as exc:
                text = str(exc)
                raise DeviceFileError(
                    f"{where}: {text}" if text.startswith(label) else f"{where}: {label}: {text}"
                ) from None
            parts.append(part)
        out[f"{kind}s"] = tuple(parts)
    return out


def _refuse_unknown(table: dict, allowed, what: str) -> None:
    unknown = [key for key in table if key not in allowed]
    if unknown:
        raise ValueError(
            f"unknown key {unknown[0]!r} = {table[unknown[0]]!r}{what}; allowed: "
            f"{', '.join(allowed)}"
        )


def _numbers(name: str, value):
    """Refuse booleans and words inside a list of numbers (numpy would take True as 1)."""
    items = value if isinstance(value, list) else [value]
    for item in items:
        if isinstance(item, list):
            _numbers(name, item)
        elif isinstance(item, bool) or not isinstance(item, int | float):
            raise ValueError(f"`{name}` must be numbers, got {item!r} in {value!r}")
    return value


def _structure(table: dict):
    _refuse_unknown(table, STRUCTURE_KEYS, "")
    forms = [key for key in ("chain", "modes") if key in table]
    matrices = [key for key in ("mass", "stiffness", "damping") if key in table]
    if len(forms) + bool(matrices) != 1:
        raise ValueError(
            "must give the structure one way: `mass`, `stiffness` and `damping` (matrices), or "
            f"`chain`, or `modes`; got {', '.join(sorted(table)) or 'nothing'}"
        )
    if "masses" in table and forms != ["modes"]:
        raise ValueError("`masses` (lumped masses added to a host) goes with `modes`")
    if "influence" in table and forms:
        raise ValueError(f"`influence` goes with the matrices; `{forms[0]}` sets its own")
    if forms == ["chain"]:
        chain = _subtable(table["chain"], "chain", CHAIN_KEYS)
        return chain_matrices(**{k: _numbers(f"chain.{k}", v) for k, v in chain.items()})
    if forms == ["modes"]:
        modes = _subtable(table["modes"], "modes", MODE_KEYS)
        masses = _numbers("masses", table.get("masses", []))
        return modal_matrices(
            **{k: _numbers(f"modes.{k}", v) for k, v in modes.items()}, masses=masses
        )
    missing = [key for key in ("mass", "stiffness", "damping") if key not in table]
    if missing:
        raise ValueError(f"needs `{missing[0]}` beside {', '.join(f'`{k}`' for k in matrices)}")
    values = {key: _numbers(key, table[key]) for key in ("mass", "stiffness", "damping")}
    influence = table.get("influence")
    return structure_matrices(
        values["mass"], values["stiffness"], values["damping"],
        None if influence is None else _numbers("influence", influence),
    )  # fmt: skip


def _subtable(value, name: str, keys) -> dict:
    if not isinstance(value, dict):
        raise ValueError(f"`{name}` must be a table {{{', '.join(keys)}}}, got {value!r}")
    _refuse_unknown(value, keys, f" in `{name}`")
    missing = [key for key in keys if key not in value]
    if missing:
        raise ValueError(f"`{name}` needs `{missing[0]}` (all of {', '.join(keys)})")
    return value


def _between(table: dict):
    if "between" not in table:
        raise ValueError('needs `between` (two DOF indices, or a DOF index and "base")')
    return parse_between(table["between"])


def _element(table: dict) -> Element:
    _refuse_unknown(table, ELEMENT_KEYS, "")
    between = _between(table)
    spring = table.get("spring")
    if spring is not None:
        if not isinstance(spring, dict):
            raise ValueError(f"`spring` must be a table {{k, k2, k3}}, got {spring!r}")
        spring = Spring.of({k: _numbers(f"spring.{k}", v) for k, v in spring.items()})
    friction = table.get("friction")
    if friction is not None:
        friction = _friction(friction)
    return Element(
        between, spring, friction, _numbers("damping", table.get("damping", 0.0)),
        table.get("stroke"),
    )  # fmt: skip


def _friction(value):
    if not isinstance(value, dict) or "law" not in value:
        raise ValueError(
            f"`friction` must be a table with `law` ({', '.join(FRICTION_MODELS)}) and the law's "
            f"parameters, got {value!r}"
        )
    law = FRICTION_MODELS.get(value["law"])
    if law is None:
        raise ValueError(
            f"`friction.law` = {value['law']!r} is not a friction law; allowed: "
            f"{', '.join(FRICTION_MODELS)}"
        )
    params = {k: v for k, v in value.items() if k != "law"}
    names = law.parameter_names()
    _refuse_unknown(params, names, f" in the {law.name} `friction`")
    missing = [n for n in names if n not in params]
    if missing:
        raise ValueError(
            f"the {law.name} `friction` needs `{missing[0]}` (all of {', '.join(names)})"
        )
    return law(**{k: _numbers(f"friction.{k}", v) for k, v in params.items()})


def _transducer(table: dict) -> Transducer:
    between = _between(table)
    name = table.get("coupling", "resistive")
    rectifier = table.get("rectifier")
    if rectifier is not None and rectifier != "bridge":
        raise ValueError(f'`rectifier` = {rectifier!r}; allowed: "bridge"')
    if rectifier is not None:
        if name not in RECTIFIED:
            raise ValueError(
                f'`coupling` = {name!r} with `rectifier` = "bridge"; allowed: '
                f"{', '.join(map(repr, RECTIFIED))}"
            )
        cls = RECTIFIED[name]
    elif name not in COUPLINGS:
        raise ValueError(f"`coupling` = {name!r}; allowed: {', '.join(map(repr, COUPLINGS))}")
    else:
        cls = COUPLINGS[name]
        if name == "resistive" and "c_e" in table:
            cls = ElectricalDamper  # a bare electrical damping, as --c-e
    params = {k: v for k, v in table.items() if k not in TRANSDUCER_KEYS}
    names = cls.parameter_names()
    what = f" for coupling = {name!r}" + (' with rectifier = "bridge"' if rectifier else "")
    _refuse_unknown(params, (*TRANSDUCER_KEYS, *names), what)
    required = [n for n in _required(cls) if n not in params]
    if required:
        raise ValueError(f"needs `{required[0]}`{what} (its parameters: {', '.join(names)})")
    coupling = cls(**{k: _numbers(k, v) for k, v in params.items()})
    return Transducer(between, coupling, table.get("stroke"))


def _required(cls) -> list[str]:
    """A coupling's parameters without a default."""
    return [f.name for f in fields(cls) if f.default is MISSING and f.default_factory is MISSING]


# ------------------------------------------------------------------ writing
def _number(value: float) -> str:
    return repr(float(value))


def _list(values) -> str:
    return "[" + ", ".join(_list(v) if hasattr(v, "__len__") else _number(v) for v in values) + "]"


def _inline(values: dict) -> str:
    return (
        "{ "
        + ", ".join(
            f"{k} = {v!r}" if isinstance(v, str) else f"{k} = {_number(v)}"
            for k, v in values.items()
        )
        + " }"
    )


def _between_text(between) -> str:
    i, j = between
    return f"[{i}, {j}]" if j is not None else f'[{i}, "{BASE}"]'


def device_text(assembly) -> str:
    """The device file of an assembly, in the matrix form of ``[structure]``."""
    lines = [
        f"# randvib device file: {assembly.n_dof} DOF(s), coordinates relative to the base "
        "(docs/assemblies.md)",
        "[structure]",
        f"mass = {_list(assembly.mass)}",
        f"stiffness = {_list(assembly.stiffness)}",
        f"damping = {_list(assembly.damping)}",
        f"influence = {_list(assembly.influence)}",
    ]
    for element in assembly.elements:
        lines += ["", "[[element]]", f"between = {_between_text(element.between)}"]
        if element.spring is not None:
            lines.append(f"spring = {_inline(element.spring.parameters())}")
        if element.friction is not None:
            lines.append(
                f"friction = {_inline({'law': element.friction.name, **element.friction.parameters()})}"
            )
        if element.damping:
            lines.append(f"damping = {_number(element.damping)}")
        if element.stroke is not None:
            lines.append(f"stroke = {_number(element.stroke)}")
    for transducer in assembly.transducers:
        coupling = transducer.coupling
        lines += ["", "[[transducer]]", f"between = {_between_text(transducer.between)}"]
        if coupling.rectified:
            lines += [f'coupling = "{coupling.transducer}"', 'rectifier = "bridge"']
        else:
            lines.append(f'coupling = "{coupling.name}"')
        lines += [f"{k} = {_number(v)}" for k, v in coupling.parameters().items() if v is not None]
        if transducer.stroke is not None:
            lines.append(f"stroke = {_number(transducer.stroke)}")
    return "\n".join(lines) + "\n"
