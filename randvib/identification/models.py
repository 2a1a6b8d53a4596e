"""The identification models and their parameters.

A model is the device of paper Eq. 1 with one friction law: ``viscous`` (c
(Ns/m), k (N/m), k3 (N/m^3): the paper's "no friction") and one per
registered friction law (:data:`randvib.models.friction.FRICTION_MODELS`:
``coulomb`` Eq. 4-5, ``tanh`` Eq. 6, ``lugre`` Eq. 8-10, and any law defined
elsewhere), which adds that law's parameters with the units, search bounds and
scales it declares; plus the mass ``m`` (kg). With base excitation the mass
cannot be identified (dividing Eq. 1 by m leaves c/m, k/m, k3/m, F/m), so it
must be given; with a force input it may be left free and is identified.

This module holds the declarations every part of the identification reads:
the device's own parameters (:data:`DEVICE_SPECS`), the models
(:data:`MODELS`, :data:`MODEL_PARAMETERS`), their units (:func:`unit_of`) and
the one check of a parameter's value (:func:`check_parameter`).

**One device.** Outside the search, a model's parameter values are a
:class:`~randvib.models.harvester.Harvester` (the record simulation uses its
total damping c = c_m + c_e: a record cannot separate them) plus a
:class:`MeasurementModel` (the sensors' offsets and the quadratic stiffness
k2, which a Harvester does not have). :func:`device_parameters` turns the
pair into the named parameters the compiled simulation takes,
:func:`device_from_parameters` turns identified parameters back into the pair.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from randvib._validation import (
    check_finite,
    check_nonnegative,
    check_positive,
    check_scalar_device,
    scalar_or_array,
)
from randvib.identification.circuit import (
    ALL_COUPLING_PARAMETERS,
    OFFSET_NAMES,
    circuit_terms,
    coupling_unit,
)
from randvib.identification.record_integrator import EXTRA_PARAMETERS
from randvib.models.friction import FRICTION_MODELS, RegistryView
from randvib.models.harvester import Harvester
from randvib.models.parameters import Parameter
from randvib.quantities import unit

#: The device's own parameters (Eq. 1; friction laws declare theirs): unit,
#: default bounds from the record's scales, log scale (k3 may be zero).
DEVICE_SPECS = {
    "m": Parameter(unit("m"), True, lambda s: (0.1 * s.m, 10 * s.m)),
    "c": Parameter(unit("c"), False, lambda s: (1e-4 * s.c_ref, 2 * s.c_ref)),
    "k": Parameter(unit("k"), True, lambda s: (0.1 * s.k_ref, 10 * s.k_ref)),
    # k3 z_max^3 up to 10 times the linear force m w^2 z_max (k's own upper factor):
    # w of a hardening record already holds part of k3, and a record reaching far
    # into the cubic range (k3 = 1.2e6 N/m^3 at 25 m/s^2) needs more than twice it
    "k3": Parameter(unit("k3"), False, lambda s: (0.0, 10 * s.k_ref / s.z_max**2), log=False),
}


#: Identification model name -> friction law name of the simulator (live view
#: of the registry: ``viscous`` is no friction, every law is a model).
MODELS = RegistryView(lambda law: "none" if law is None else law.name, none_key="viscous")


#: Parameters of each model, in reporting order (``m`` comes in addition).
MODEL_PARAMETERS = RegistryView(
    lambda law: ("c", "k", "k3") + (() if law is None else law.parameter_names()),
    none_key="viscous",
)


def parameter_specs(model) -> dict[str, Parameter]:
    """Declarations of every parameter of a model, ``m`` included."""
    law = check_model(model)
    return {**DEVICE_SPECS, **({} if law is None else law.parameter_specs())}


def unit_of(model, name):
    """The unit of parameter ``name`` of ``model``: a law's or a coupling's own
    declaration, else :func:`randvib.quantities.unit` (``m``, ``c``, ``k``,
    ``k3``, ``k2``, the offsets); a record's own ``name[i]`` as ``name``'s."""
    base = name.split("[")[0]
    specs = parameter_specs(model)
    if base in specs:
        return specs[base].unit
    if base in ALL_COUPLING_PARAMETERS:
        return coupling_unit(base)
    return unit(base)


def check_model(model):
    """The friction law class of an identification model (``viscous``: None)."""
    if model not in MODELS:
        raise ValueError(f"`model` must be one of {', '.join(MODELS)}; got {model!r}")
    return None if model == "viscous" else FRICTION_MODELS[model]


def model_of(friction_name: str) -> str:
    """Identification model of a friction law name (``none`` -> ``viscous``)."""
    return "viscous" if friction_name == "none" else friction_name


def check_parameter(model: str, name: str, value, label: str | None = None) -> float:
    """``value`` of parameter ``name`` of ``model`` as a float, if the model allows it.

    The rules are the declarations' (:data:`DEVICE_SPECS` and the friction
    law's ``parameter(...)`` fields): finite, and > 0 for a positive
    parameter (m, k, Fc, ...), >= 0 for the others (c, k3, ...). They hold
    for fixed values, search bounds and validated parameters alike.
    """
    label = label or name
    if name in EXTRA_PARAMETERS:  # k2 and the sensor offsets: any finite value
        return float(check_finite(label, value))
    spec = parameter_specs(model).get(name)
    if spec is None:
        raise ValueError(
            f"`{label}`: unknown parameter for model {model!r}; allowed: "
            f"{', '.join(('m',) + MODEL_PARAMETERS[model])}"
        )
    check = check_positive if spec.positive else check_nonnegative
    return float(check(label, value, spec.unit))


def check_parameters(parameters, model) -> dict:
    """Every parameter of ``model`` (``m`` included) from ``parameters``, each checked
    (:func:`check_parameter`), with the measurement model's that are given."""
    check_model(model)
    names = ("m",) + MODEL_PARAMETERS[model]
    missing = [n for n in names if n not in parameters]
    if missing:
        raise ValueError(
            f"parameters for model {model!r} lack {missing}; needed: {', '.join(names)}"
        )
    names += tuple(n for n in EXTRA_PARAMETERS if n in parameters)
    return {n: check_parameter(model, n, parameters[n]) for n in names}


# ------------------------------------------------------------- one device
@dataclass(frozen=True)
class MeasurementModel:
    """What the record simulation adds to a Harvester: the sensors' offsets and k2.

    An offset is what a sensor adds (measured = true + offset). The
    quadratic stiffness k2 is the term of the restoring force
    ``k z + k2 z^2 + k3 z^3`` that a :class:`~randvib.models.harvester.Harvester`
    does not have (its potential is even). It is defined about the output
    sensor's zero: with k3 != 0 a cubic spring whose centre is shifted by s
    from that zero (z -> z + s) has the quadratic term 3 k3 s and a constant
    force, which the input offset takes, so k2 belongs with the offsets
    and is estimated with them (:func:`randvib.identify`,
    ``quadratic``). The initial state is not part of it: it belongs to one
    record and is estimated, or taken from the first samples, record by
    record (:class:`~randvib.identification.settings.SimulationSettings`).

    Attributes
    ----------
    input_offset : float
        Offset of the input channel, in its unit (m/s^2 for a base
        acceleration, N for a force; a base displacement's vanishes in its
        second derivative).
    output_offset : float
        Offset of the relative-displacement sensor (m).
    k2 : float
        Quadratic stiffness (N/m^2).
    channel_offsets : dict
        The other output channels' offsets by kind (``relative_velocity``
        m/s, ``voltage`` V, ``current`` A); absent ones are 0.
    """

    input_offset: float = 0.0
    output_offset: float = 0.0
    k2: float = 0.0
    channel_offsets: dict = field(default_factory=dict)

    def __post_init__(self):
        for name in EXTRA_PARAMETERS:
            object.__setattr__(self, name, scalar_or_array(check_finite(name, getattr(self, name))))
        offsets = {}
        for kind, value in dict(self.channel_offsets).items():
            if kind not in OFFSET_NAMES or kind == "relative_displacement":
                raise ValueError(
                    f"`channel_offsets`: {kind!r} is not an output channel other than the "
                    f"displacement (whose offset is `output_offset`); allowed: "
                    f"{', '.join(k for k in OFFSET_NAMES if k != 'relative_displacement')}"
                )
            offsets[kind] = float(check_finite(f"channel_offsets[{kind!r}]", value))
        object.__setattr__(self, "channel_offsets", offsets)

    def parameters(self) -> dict:
        """``k2``, ``input_offset`` and ``output_offset`` by name."""
        return {name: getattr(self, name) for name in EXTRA_PARAMETERS}

    def offset(self, kind: str) -> float:
        """The sensor offset of output channel ``kind`` (its unit; 0 when not given)."""
        if kind == "relative_displacement":
            return float(np.ravel(self.output_offset)[0])
        return self.channel_offsets.get(kind, 0.0)

    @classmethod
    def from_parameters(cls, parameters: dict) -> MeasurementModel:
        """The measurement model among identified ``parameters`` (absent ones: 0)."""
        channel = {
            kind: parameters[name]
            for kind, name in OFFSET_NAMES.items()
            if kind != "relative_displacement" and name in parameters
        }
        given = {name: parameters[name] for name in EXTRA_PARAMETERS if name in parameters}
        return cls(**given, channel_offsets=channel)


def device_parameters(
    harvester: Harvester,
    measurement=None,
    function: str = "the record simulation",
    *,
    scalar=True,
    rectified=False,
) -> dict:
    """The record simulation's named parameters of a device and its measurement model.

    ``m``, ``c`` (= c_m + c_e, the static coupling's damping included),
    ``k``, ``k3``, the friction law's parameters, ``k2`` and the offsets; a
    coupling with a circuit state is :func:`device_circuit`'s. ``function``
    is named in refusals: anything but a Harvester, a diode bridge (unless
    ``rectified``: :mod:`randvib.identification.record_bridge` simulates it)
    and, with ``scalar``, array parameters.
    """
    if not isinstance(harvester, Harvester):
        raise ValueError(
            f"{function} needs a randvib.Harvester (a preset included), got "
            f"{type(harvester).__name__}"
        )
    if measurement is None:
        measurement = MeasurementModel()
    elif not isinstance(measurement, MeasurementModel):
        raise ValueError(
            f"`measurement` must be a randvib.MeasurementModel, got {type(measurement).__name__}"
        )
    if scalar:
        check_scalar_device(harvester, function)
    if harvester.is_rectified and not rectified:
        raise ValueError(
            f"{function} integrates a coil or a piezo element on its load, not the "
            f"{harvester.electrical.name}'s switching; the bridge is simulated by randvib.simulate"
        )
    out = {"m": harvester.m, "c": harvester.c, "k": harvester.k, "k3": harvester.k3}
    if harvester.friction is not None:
        out.update(harvester.friction.parameters())
    out.update(measurement.parameters())
    return out


def device_circuit(harvester: Harvester):
    """``(a, b, f)`` of the device's circuit state (``x' = a x + b z'``, force ``f x``), or None.

    None for a device without a coupling or with a static one (whose c_e
    is in :attr:`Harvester.c <randvib.models.harvester.Harvester.c>`).
    """
    if not harvester.has_circuit:
        return None
    coupling = harvester.electrical
    return circuit_terms(coupling.name, coupling.parameters(), coupling.r_load)[1]


def device_from_parameters(
    model: str, parameters: dict, electrical=None
) -> tuple[Harvester, MeasurementModel]:
    """Identified ``parameters`` of ``model`` as the device and its measurement model.

    The identified damping ``c`` becomes the Harvester's c_m: a record taken
    in open circuit holds no electrical damping. ``electrical`` (a coupling,
    e.g. ``Resistive(alpha, r_load, r_coil)``) wires the device, its
    c_e added to c (:meth:`~randvib.models.harvester.Harvester.with_coupling`).
    """
    law = check_model(model)
    p = check_parameters(parameters, model)
    if law is None and p["c"] == 0:
        raise ValueError(
            "`c` must be > 0 (Ns/m) for the viscous model: without friction an undamped "
            "device is no randvib.Harvester"
        )
    friction = None if law is None else law(**{name: p[name] for name in law.parameter_names()})
    if electrical is None:
        device = Harvester(m=p["m"], c_m=p["c"], c_e=0.0, k=p["k"], k3=p["k3"], friction=friction)
    else:
        device = Harvester.with_coupling(
            p["m"], p["c"], p["k"], electrical, k3=p["k3"], friction=friction
        )
    return device, MeasurementModel.from_parameters(p)
