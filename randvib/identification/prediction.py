"""A record simulated with given parameters and scored: prediction and validation.

:func:`predict_record` simulates a record with given parameters (paper Eq. 1)
and scores it with J (Eq. 11); :func:`validate` does so on several records.
By default the initial state is estimated (a two-parameter fit of the
simulation error, so that a correct model is never penalised for its start).
(The analytic power prediction is :func:`randvib.predict`.)
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from randvib.identification.cost import CostFunction, normalised_cost
from randvib.identification.models import MODELS, check_parameters, model_of
from randvib.identification.record_response import device_parameters
from randvib.identification.settings import SimulationSettings, resolve_settings
from randvib.models.record import Record


@dataclass(frozen=True, eq=False)
class Prediction:
    """Simulated response of a parameter set to a record.

    Attributes
    ----------
    record : Record
    z, v : ndarray
        Simulated relative displacement as the output sensor reads it
        (true + ``output_offset``, m) and velocity (m/s).
    cost : float
        J (Eq. 11) against the record.
    rms_error : float
        RMS of z - zhat (units of z).
    voltage : ndarray or None
        Simulated load voltage (V) when a circuit was given:
        ``V = alpha z' R_L / (R_L + R_C)``.
    initial_state : dict
        ``z0`` (m), ``v0`` (m/s) the simulation started from (estimated by
        default, see :class:`~randvib.identification.settings.SimulationSettings`).
    """

    record: Record
    z: np.ndarray
    v: np.ndarray
    cost: float
    rms_error: float
    voltage: np.ndarray | None = None
    initial_state: dict = field(default_factory=dict)


def _device_and_model(parameters, model, record):
    """Accept ``(device, record)`` as well as ``(parameters, model, record)``.

    A device is a :class:`~randvib.models.harvester.Harvester` (a preset included)
    or its ``parameters()`` dict; its friction law names the model and its
    circuit, if any, gives the voltage. Returns (parameters, model, record,
    circuit).
    """
    from randvib.models.harvester import Harvester

    if record is None and not isinstance(model, str):
        model, record = None, model
    circuit = parameters.electrical if isinstance(parameters, Harvester) else None
    if isinstance(parameters, Harvester) or isinstance(parameters, dict) and "c_m" in parameters:
        friction = None if model is None else MODELS.get(model, model)
        parameters, friction = device_parameters(parameters, friction)
        model = model_of(friction)
    elif model is None:
        raise ValueError("`model` is required with a parameter dict; or pass a randvib.Harvester")
    return parameters, model, record, circuit


def _start_estimate(cost: CostFunction):
    """(z0, v0): the initial state that best explains the record, all else given.

    A two-parameter least-squares fit of the simulation error (for a correct
    model the error is then the noise alone, whatever the record's start).
    """
    from randvib.identification.least_squares import (
        INITIAL_STATE,
        Coordinates,
        SimulationError,
        polish,
    )

    z_scale = float(np.std(cost.record.z)) or 1.0
    v_scale = float(np.std(np.diff(cost.record.z))) / cost.record.dt or 1.0
    coords = Coordinates(
        names=INITIAL_STATE,
        log=np.zeros(2, bool),
        scale=np.array([z_scale, v_scale]),
        lower=np.full(2, -np.inf),
        upper=np.full(2, np.inf),
    )
    theta, _, _, _ = polish(SimulationError(cost, coords), np.array([cost.z0, cost.v0]))
    return float(theta[0]), float(theta[1])


def predict_record(
    parameters,
    model: str | None = None,
    record: Record | None = None,
    *,
    electrical=None,
    simulation: SimulationSettings | None = None,
    **options,
) -> Prediction:
    """Simulate a record with given parameters and score it with J (Eq. 11).

    Called as ``predict_record(parameters, model, record)`` with identified
    parameters (total damping ``c``), or as ``predict_record(device, record)``
    with a :class:`~randvib.models.harvester.Harvester` (a preset included)
    or its ``parameters()`` dict: the device's law names the model,
    c = c_m + c_e, and its circuit, if any, gives the load voltage. (The
    analytic power prediction is :func:`randvib.predict`.)

    Parameters
    ----------
    parameters : dict or Harvester
        ``m`` (kg), ``c`` (Ns/m), ``k`` (N/m), ``k3`` (N/m^3) and the model's
        friction parameters; or a device.
    model : str, optional
        Identification model (see :data:`~randvib.identification.models.MODELS`); only with a parameter dict.
    record : Record
    electrical : ElectricalCoupling, optional
        Adds the coil's damping c_e = alpha^2/(R_L + R_C) (Eq. 3) to the
        identified c and gives the load voltage.
    simulation : SimulationSettings, optional
        Its fields may also be given as keywords (``substeps=``, ``hold=``,
        ``lowpass=``, ``skip=``), which override it.

    Returns
    -------
    Prediction
    """
    (simulation,) = resolve_settings("predict_record", options, simulation=simulation)
    parameters, model, record, circuit = _device_and_model(parameters, model, record)
    params = check_parameters(parameters, model)
    if electrical is not None:
        params["c"] += electrical.electrical_damping
    cost = CostFunction(record, model, fixed=params, free=(), **simulation.to_dict())
    start = {"z0": cost.z0, "v0": cost.v0}
    if simulation.initial_state == "estimate":
        start["z0"], start["v0"] = _start_estimate(cost)
    z, v = cost.simulate(params, **start)
    z = z + params.get("output_offset", 0.0)  # what the output sensor reads
    skip = simulation.skip
    if np.all(np.isfinite(z)):
        j = float(normalised_cost(record.z[skip:], z[skip:]))
        rms = float(np.sqrt(np.mean((record.z[skip:] - z[skip:]) ** 2)))
    else:
        j = rms = float("inf")
    voltage = None
    circuit = electrical if electrical is not None else circuit
    if circuit is not None:
        voltage = circuit.alpha * v * circuit.load_fraction
    return Prediction(
        record=record, z=z, v=v, cost=j, rms_error=rms, voltage=voltage, initial_state=start
    )


def predict(*args, **kwargs) -> Prediction:
    """Deprecated name of :func:`predict_record` (``randvib.predict`` is the analytic power)."""
    warnings.warn(
        "randvib.identification.fitting.predict is deprecated; use predict_record "
        "(randvib.predict is the analytic power prediction)",
        DeprecationWarning,
        stacklevel=2,
    )
    return predict_record(*args, **kwargs)


@dataclass(frozen=True)
class ValidationRow:
    record: str
    model: str
    cost: float
    rms_error: float
    samples: int


def validate(parameters, model, records=None, **settings) -> list[ValidationRow]:
    """J (Eq. 11) and RMS error of given parameters on each of several records.

    Called as ``validate(parameters, model, records)`` or
    ``validate(device, records)`` with a Harvester; ``settings`` are those of
    :func:`predict_record` (``simulation=`` or its fields as keywords).
    """
    if records is None:
        model, records = None, model
    parameters, model, _, _ = _device_and_model(parameters, model, records)
    rows = []
    for record in records:
        pred = predict_record(parameters, model, record, **settings)
        rows.append(ValidationRow(record.name, model, pred.cost, pred.rms_error, record.n))
    return rows
