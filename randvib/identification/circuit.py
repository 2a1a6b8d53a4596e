"""The electrical side of an identification: a coupling's parameters, its circuit and its outputs.

With a coupling named (``coupling="inductive"``, ``--coupling inductive``)
the identified damping ``c`` is the mechanical one, c_m, and the coupling's
own parameters are identified beside the mechanical ones, each record at its
known load R_L (docs/conventions.md, :mod:`randvib.models.coupling`):

=============  =============================  =================================  ==================================
coupling       identified                     motion (force on the mass)         circuit state x
=============  =============================  =================================  ==================================
``resistive``  alpha (Wb/m), r_coil (ohm)     c_e z', c_e = alpha^2/(R_L + R_C)  none (i algebraic)
``inductive``  alpha, r_coil, inductance (H)  alpha i                            i: L i' + (R_L + R_C) i = alpha z'
``piezo``      theta (N/V), capacitance (F)   theta V                            V: C_p V' + V / R_L = theta z'
=============  =============================  =================================  ==================================

What a record's output channels hold (:data:`OUTPUT_KINDS`), each a linear
combination ``c_z z + c_v z' + c_x x`` of the simulated state
(:func:`output_coefficients`): ``relative_displacement`` z (m),
``relative_velocity`` z' (m/s), ``voltage`` the load voltage (V: R_L i of a
coil, V of a piezo element) and ``current`` the load current (A: i of a coil,
V / R_L of a piezo element). A coupling with ``inductance`` or ``capacitance``
fixed at 0 is static: its circuit has no state and acts as the damper c_e.

The parameters are handled by name throughout (shared ones by their own
name, a record's own with a ``[i]`` suffix when there are several records),
so that a model with more parameters (an assembly's) needs no new plumbing.
"""

from __future__ import annotations

import numpy as np

from randvib.models.coupling import COUPLINGS, Coupling
from randvib.quantities import unit

#: What an identification can fit to: the channels a harvester's sensors give.
OUTPUT_KINDS = ("relative_displacement", "relative_velocity", "voltage", "current")
#: Output kinds that need the circuit (a coupling and its load).
ELECTRICAL_OUTPUTS = ("voltage", "current")
#: The name of each output channel's sensor offset (measured = true + offset);
#: the displacement's keeps the name it had before the other outputs existed.
OFFSET_NAMES = {
    "relative_displacement": "output_offset",
    "relative_velocity": "velocity_offset",
    "voltage": "voltage_offset",
    "current": "current_offset",
}

#: The couplings an identification can fit, and their identified parameters in
#: reporting order (R_L is each record's known load, never identified).
COUPLING_PARAMETERS = {
    "resistive": ("alpha", "r_coil"),
    "inductive": ("alpha", "r_coil", "inductance"),
    "piezo": ("theta", "capacitance"),
}
#: Every coupling parameter an identification may hold (fixed or free).
ALL_COUPLING_PARAMETERS = ("alpha", "r_coil", "inductance", "theta", "capacitance")
#: The circuit state's initial value, estimated per record like z0 and v0.
CIRCUIT_START = "x0"


def check_coupling_kind(coupling) -> str | None:
    """``coupling`` if an identification can fit it (None: no coupling), else a ValueError."""
    if coupling is None or coupling in COUPLING_PARAMETERS:
        return coupling
    raise ValueError(
        f"`coupling` must be one of {', '.join(COUPLING_PARAMETERS)}; got {coupling!r}"
    )


def check_output_kind(kind, where: str = "outputs") -> str:
    """``kind`` if it is one of :data:`OUTPUT_KINDS`, else a ValueError naming them."""
    if kind not in OUTPUT_KINDS:
        raise ValueError(f"`{where}`: {kind!r} is not one of {', '.join(OUTPUT_KINDS)}")
    return kind


def check_coupling_parameter(name: str, value, label: str | None = None) -> float:
    """``value`` of coupling parameter ``name`` as a float, checked as its coupling declares.

    alpha and theta > 0; r_coil, inductance and capacitance >= 0 (L or C_p
    = 0: the static coupling).
    """
    from randvib._validation import check_nonnegative, check_positive

    for cls in COUPLINGS.values():
        specs = cls.parameter_specs()
        if name in specs:
            check = check_positive if specs[name].positive else check_nonnegative
            return float(check(label or name, value, specs[name].unit))
    raise ValueError(f"`{label or name}`: {name!r} is not a coupling parameter")


def coupling_unit(name: str) -> str:
    """The SI unit of a coupling parameter (as its coupling class declares it)."""
    for cls in COUPLINGS.values():
        specs = cls.parameter_specs()
        if name in specs:
            return specs[name].unit
    return unit(name)


def state_unit(coupling: str | None) -> str:
    """Unit of the circuit state x: A (coil current), V (piezo voltage); '' for none."""
    if coupling in (None, "resistive"):
        return ""
    return COUPLINGS[coupling].state_unit


def is_dynamic(coupling: str | None, parameters: dict) -> bool:
    """True when the coupling carries a circuit state (its L or C_p is not held at 0)."""
    if coupling == "inductive":
        return bool(np.any(np.asarray(parameters["inductance"]) > 0))
    if coupling == "piezo":
        return bool(np.any(np.asarray(parameters["capacitance"]) > 0))
    return False


def circuit_terms(coupling: str | None, parameters: dict, r_load):
    """``(c_e, (a, b, f))`` per parameter set: the static damping and the circuit state.

    ``c_e`` (Ns/m) is added to the mechanical c where the circuit has no
    state (resistive; L or C_p = 0); ``x' = a x + b z'`` with the force
    ``f x`` on the mass where it has one (zeros elsewhere). Arrays broadcast
    over the candidates of a batch.
    """
    if coupling is None:
        return 0.0, None
    r_load = np.asarray(r_load, dtype=float)
    if coupling == "piezo":
        theta = np.asarray(parameters["theta"], dtype=float)
        cp = np.asarray(parameters["capacitance"], dtype=float)
        dynamic = cp > 0
        safe = np.where(dynamic, cp, 1.0)
        c_e = np.where(dynamic, 0.0, theta**2 * r_load)
        a = np.where(dynamic, -1.0 / (r_load * safe), 0.0)
        b = np.where(dynamic, theta / safe, 0.0)
        return c_e, (a, b, np.where(dynamic, theta, 0.0))
    alpha = np.asarray(parameters["alpha"], dtype=float)
    resistance = r_load + np.asarray(parameters["r_coil"], dtype=float)
    ind = np.asarray(parameters.get("inductance", 0.0), dtype=float)
    dynamic = ind > 0
    safe = np.where(dynamic, ind, 1.0)
    c_e = np.where(dynamic, 0.0, alpha**2 / resistance)
    a = np.where(dynamic, -resistance / safe, 0.0)
    b = np.where(dynamic, alpha / safe, 0.0)
    return c_e, (a, b, np.where(dynamic, alpha, 0.0))


def output_coefficients(kind: str, coupling: str | None, parameters: dict, r_load):
    """``(c_z, c_v, c_x)``: the channel ``kind`` as ``c_z z + c_v z' + c_x x``.

    Per parameter set (arrays broadcast over a batch). A coil's load voltage
    is ``R_L i`` and its current ``i`` (``alpha z' / (R_L + R_C)`` without
    inductance); a piezo element's voltage is ``V`` and its current
    ``V / R_L`` (``theta R_L z'`` without capacitance).
    """
    if kind == "relative_displacement":
        return 1.0, 0.0, 0.0
    if kind == "relative_velocity":
        return 0.0, 1.0, 0.0
    if coupling is None:
        raise ValueError(
            f"a `{kind}` output needs the circuit: name the coupling (`coupling=`, "
            "`--coupling resistive|inductive|piezo`) and its load (`r_load=`, `--r-load`)"
        )
    r_load = np.asarray(r_load, dtype=float)
    scale = r_load if kind == "voltage" else 1.0  # the coil's voltage is R_L i
    if coupling == "piezo":
        scale = 1.0 if kind == "voltage" else 1.0 / r_load  # the piezo's current is V / R_L
        cp = np.asarray(parameters["capacitance"], dtype=float)
        static = parameters["theta"] * r_load * scale  # V = theta R_L z' when C_p = 0
        return 0.0, np.where(cp > 0, 0.0, static), np.where(cp > 0, scale, 0.0)
    ind = np.asarray(parameters.get("inductance", 0.0), dtype=float)
    static = parameters["alpha"] / (r_load + np.asarray(parameters["r_coil"])) * scale
    return 0.0, np.where(ind > 0, 0.0, static), np.where(ind > 0, scale, 0.0)


def quasi_static_state(coupling: str | None, parameters: dict, r_load, velocity):
    """The circuit state that follows the velocity with no lag: ``-b z' / a``.

    Where the circuit is fast (or when nothing better is known) it starts
    there: i = alpha z' / (R_L + R_C), V = theta R_L z'.
    """
    if not is_dynamic(coupling, parameters):
        return 0.0
    _, (a, b, _) = circuit_terms(coupling, parameters, r_load)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(a != 0, -b * velocity / np.where(a != 0, a, 1.0), 0.0)


def coupling_from_parameters(coupling: str, parameters: dict, r_load: float) -> Coupling:
    """The :mod:`randvib.models.coupling` object of identified ``parameters`` at load ``r_load``."""
    cls = COUPLINGS[check_coupling_kind(coupling)]
    values = {name: float(parameters[name]) for name in COUPLING_PARAMETERS[coupling]}
    return cls(r_load=float(r_load), **values)


#: The rectifiers a saved identification names (``"rectifier": {"kind": "bridge", ...}``).
RECTIFIER_KINDS = ("bridge",)
#: The known values of a saved bridge: each diode's drop and exactly one output.
RECTIFIER_KEYS = ("v_diode", "storage_capacitance", "battery")
#: How an identification behind a bridge begins its note (files saved before the
#: ``rectifier`` field held the bridge only there).
BRIDGE_NOTE = "behind a full-wave diode bridge, known:"


def bridge_from_parameters(coupling: str, parameters: dict, bridge: dict, r_load):
    """The rectified coupling (:mod:`randvib.models.rectifier`) of identified ``parameters``.

    ``coupling``: the transducer (``inductive`` or ``piezo``); ``bridge``: its
    known ``v_diode`` (V) and ``storage_capacitance`` (F, with the load
    ``r_load``, ohm) or ``battery`` (V; ``r_load`` unused), as
    :func:`~randvib.identification.experiment.known_bridge` checks them.
    """
    from randvib.models.rectifier import rectified

    values = {name: float(parameters[name]) for name in COUPLING_PARAMETERS[coupling]}
    values.update({k: float(v) for k, v in bridge.items()})
    if "battery" not in bridge:
        values["r_load"] = float(r_load)
    return rectified(coupling, **values)


def saved_rectifier(saved, where: str = "`rectifier`") -> dict:
    """The known bridge of a saved identification's ``rectifier`` object ({} for none).

    ``{"kind": "bridge", "v_diode": V_d, "storage_capacitance": C}`` or
    ``{..., "battery": V_b}``; refused, naming ``where``, when it is anything else.
    """
    if saved is None:
        return {}
    if not isinstance(saved, dict) or saved.get("kind") not in RECTIFIER_KINDS:
        raise ValueError(
            f'{where} must be an object with "kind": {" or ".join(map(repr, RECTIFIER_KINDS))}'
            f", got {saved!r}"
        )
    values = {k: v for k, v in saved.items() if k != "kind"}
    unknown = sorted(set(values) - set(RECTIFIER_KEYS))
    if unknown or ("battery" in values) == ("storage_capacitance" in values):
        raise ValueError(
            f"{where}: a bridge holds `v_diode` and exactly one of `storage_capacitance`, "
            f"`battery`; got {sorted(values)}"
        )
    try:
        return {k: float(v) for k, v in values.items()}
    except (TypeError, ValueError):
        raise ValueError(f"{where}: its values must be numbers, got {values!r}") from None


def coupling_bounds(coupling: str, scales, r_loads, dt: float) -> dict:
    """Default search boxes of the coupling's parameters from a record's scales.

    With ``c_ref = 2 m w`` (critical damping at the record's frequency w) and
    the records' loads R_L:

    ===========  ================================================  ===
    alpha        sqrt(c_ref R_L) x [1e-3, 3]  (c_e up to 9 c_ref)  log
    r_coil       R_L x [1e-3, 10]                                  log
    inductance   R_L x [dt / 8, 10 / w]  (time constant L / R)     log
    theta        sqrt(c_ref / R_L) x [1e-3, 10]                    log
    capacitance  [dt / 8, 10 / w] / R_L  (time constant R_L C_p)   log
    ===========  ================================================  ===

    A time constant below dt / 8 has no effect the samples resolve (it is
    the static coupling's limit); below it the circuit would also cost the
    search many sub-cycles per step.
    """
    lo, hi = float(min(r_loads)), float(max(r_loads))
    c_ref, omega = scales.c_ref, scales.omega
    boxes = {
        "alpha": (1e-3 * np.sqrt(c_ref * lo), 3.0 * np.sqrt(c_ref * hi)),
        "r_coil": (1e-3 * lo, 10.0 * hi),
        "inductance": (lo * dt / 8.0, hi * 10.0 / omega),
        "theta": (1e-3 * np.sqrt(c_ref / hi), 10.0 * np.sqrt(c_ref / lo)),
        "capacitance": (dt / (8.0 * hi), 10.0 / (omega * lo)),
    }
    return {name: tuple(map(float, boxes[name])) for name in COUPLING_PARAMETERS[coupling]}
