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
(:data:`MODELS`, :data:`MODEL_PARAMETERS`), the units (:data:`UNITS`) and
the one check of a parameter's value (:func:`check_parameter`).
"""

from __future__ import annotations

from collections.abc import Mapping

from randvib._validation import check_finite, check_nonnegative, check_positive
from randvib.identification.record_integrator import EXTRA_PARAMETERS
from randvib.models.friction import FRICTION_MODELS, Parameter, RegistryView

#: The device's own parameters (Eq. 1; friction laws declare theirs): unit,
#: default bounds from the record's scales, log scale (k3 may be zero).
DEVICE_SPECS = {
    "m": Parameter("kg", True, lambda s: (0.1 * s.m, 10 * s.m)),
    "c": Parameter("Ns/m", False, lambda s: (1e-4 * s.c_ref, 2 * s.c_ref)),
    "k": Parameter("N/m", True, lambda s: (0.1 * s.k_ref, 10 * s.k_ref)),
    "k3": Parameter("N/m^3", False, lambda s: (0.0, 2 * s.k_ref / s.z_max**2), log=False),
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


#: Units of the quadratic stiffness and the sensor offsets.
EXTRA_UNITS = {"k2": "N/m^2", "input_offset": "input unit", "output_offset": "m"}


def unit_of(model, name):
    return EXTRA_UNITS[name] if name in EXTRA_UNITS else parameter_specs(model)[name].unit


class _Units(Mapping):
    """Parameter name -> unit, from the device's and the laws' declarations."""

    def _table(self):
        out = {name: spec.unit for name, spec in DEVICE_SPECS.items()} | EXTRA_UNITS
        for law in FRICTION_MODELS.values():
            out.update({name: spec.unit for name, spec in law.parameter_specs().items()})
        return out

    def __getitem__(self, key):
        return self._table()[key]

    def __iter__(self):
        return iter(self._table())

    def __len__(self):
        return len(self._table())


#: Parameter name -> SI unit (live view; a law's own units win in its results).
UNITS = _Units()


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


def check_parameters(parameters, model):
    check_model(model)
    names = ("m",) + MODEL_PARAMETERS[model]
    missing = [n for n in names if n not in parameters]
    if missing:
        raise ValueError(
            f"parameters for model {model!r} lack {missing}; needed: {', '.join(names)}"
        )
    names += tuple(n for n in EXTRA_PARAMETERS if n in parameters)
    return {n: check_parameter(model, n, parameters[n]) for n in names}
