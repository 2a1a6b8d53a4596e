"""A record simulated with a device and scored: prediction and validation.

:func:`predict_record` simulates a record with a
:class:`~randvib.models.harvester.Harvester` and its
:class:`~randvib.identification.models.MeasurementModel` (paper Eq. 1) and
scores it with J (Eq. 11); :func:`validate` does so on several records.
By default the initial state is estimated (a two-parameter fit of the
simulation error, so that a correct model is never penalised for its start).
(The analytic power prediction is :func:`randvib.predict`.)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from randvib.identification.circuit import COUPLING_PARAMETERS, OFFSET_NAMES, output_coefficients
from randvib.identification.cost import CostFunction, normalised_cost
from randvib.identification.models import (
    MeasurementModel,
    check_parameters,
    device_parameters,
    model_of,
)
from randvib.identification.settings import SimulationSettings, resolve_settings
from randvib.models.coupling import Inductive, Resistive
from randvib.models.harvester import Harvester
from randvib.models.record import Record


@dataclass(frozen=True, eq=False)
class Prediction:
    """Simulated response of a device to a record.

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
        Simulated load voltage (V) when the device has a coupling (a coil's
        ``R_L i``, a piezo element's ``V``), without the sensor's offset.
    initial_state : dict
        ``z0`` (m), ``v0`` (m/s) (and the circuit's ``x0``) the simulation
        started from (estimated by default, see
        :class:`~randvib.identification.settings.SimulationSettings`).
    channels, costs, rms_errors : dict
        With ``outputs``: each scored channel as simulated (offset included),
        its J (Eq. 11, normalised by its own variance) and RMS error (its
        unit); ``cost`` is then their sum and ``rms_error`` the first's.
    """

    record: Record
    z: np.ndarray
    v: np.ndarray
    cost: float
    rms_error: float
    voltage: np.ndarray | None = None
    initial_state: dict = field(default_factory=dict)
    channels: dict = field(default_factory=dict)
    costs: dict = field(default_factory=dict)
    rms_errors: dict = field(default_factory=dict)

    @property
    def outputs(self) -> tuple:
        """The channels scored (``relative_displacement`` for a displacement record)."""
        return tuple(self.channels) or ("relative_displacement",)

    def simulated(self, kind: str) -> np.ndarray:
        """The simulated channel ``kind`` as its sensor reads it (offset included)."""
        if kind in self.channels:
            return self.channels[kind]
        if kind == "relative_displacement":
            return self.z
        if kind == "voltage" and self.voltage is not None:
            return self.voltage
        raise ValueError(
            f"channel {kind!r} was not simulated; simulated: {', '.join(self.outputs)}"
        )

    def __repr__(self) -> str:  # the scores and the start, not the simulated samples
        start = ", ".join(f"{k} = {float(v):.4g}" for k, v in self.initial_state.items())
        voltage = ", voltage" if self.voltage is not None else ""
        scored = f" of {', '.join(self.outputs)}" if self.channels else ""
        return (
            f"Prediction({self.record.name!r}: {self.z.shape[-1]} samples, J = {self.cost:.4g} "
            f"(Eq. 11{scored}), RMS error {self.rms_error:.4g}"
            f"{f'; start {start}' if start else ''}; z, v{voltage})"
        )


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
    problem = SimulationError(cost, coords)
    theta, _, _, _ = polish(problem, np.array([cost.z0, cost.v0]), with_uncertainty=False)
    return float(theta[0]), float(theta[1])


def predict_record(
    harvester: Harvester,
    record: Record,
    *,
    measurement: MeasurementModel | None = None,
    simulation: SimulationSettings | None = None,
    outputs=None,
    **options,
) -> Prediction:
    """Simulate a record with a device and score it with J (Eq. 11).

    The device is simulated with its coupling: a static one as its damper
    c_e, a coil with inductance or a piezo element with its circuit state;
    its circuit, if any, gives the load voltage. (The analytic power
    prediction is :func:`randvib.predict`.)

    Parameters
    ----------
    harvester : Harvester
        The device (a preset, or :meth:`IdentificationResult.harvester
        <randvib.identification.result.IdentificationResult.harvester>`), with
        scalar parameters and any coupling; behind a diode bridge its DC side
        is scored (:mod:`randvib.identification.record_bridge`: ``voltage`` the
        storage capacitor's V_C, ``current`` the load's).
    record : Record
        Its input channel drives the device; its relative displacement is
        scored, or the channels ``outputs`` names.
    outputs : sequence of str, optional
        The channels scored (:data:`~randvib.identification.circuit.OUTPUT_KINDS`:
        ``relative_displacement``, ``relative_velocity``, ``voltage``,
        ``current``), each with its own J; default the displacement.
    measurement : MeasurementModel, optional
        The sensors' offsets and k2 (an identification's ``measurement``);
        default none.
    simulation : SimulationSettings, optional
        Its fields may also be given as keywords (``substeps=``, ``hold=``,
        ``lowpass=``, ``skip=``, ``initial_state=``), which override it.

    Returns
    -------
    Prediction

    Examples
    --------
    >>> import randvib as rv
    >>> device = rv.preset("coulomb-td1")
    >>> record = rv.synthetic_record(device, 1.07, duration=1.0, sample_rate=500.0, seed=1)
    >>> rv.predict_record(device, record).cost < 1e-9  # the truth: J ~ 0
    True
    >>> print(f"J = {rv.predict_record(device.updated(fc=0.004), record).cost:.2f}")  # Fc 30 % low
    J = 1.04
    """
    (simulation,) = resolve_settings("predict_record", options, simulation=simulation)
    if isinstance(record, Record):  # else refused by score
        simulation, _ = simulation.for_record(record)
    circuit = isinstance(harvester, Harvester) and (harvester.has_circuit or harvester.is_rectified)
    if outputs is not None or circuit:
        return score_channels(harvester, record, measurement, simulation, outputs)
    parameters = device_parameters(harvester, measurement, "predict_record")
    model = model_of(harvester.friction_name)
    return score(
        check_parameters(parameters, model), model, record, simulation, harvester.electrical
    )


def score(parameters: dict, model: str, record: Record, simulation, circuit=None) -> Prediction:
    """:func:`predict_record` on checked named ``parameters`` of ``model`` (as identify has them)."""
    if not isinstance(record, Record):
        raise ValueError(f"`record` must be a randvib.Record, got {type(record).__name__}")
    cost = CostFunction(record, model, fixed=parameters, free=(), **simulation.to_dict())
    start = {"z0": cost.z0, "v0": cost.v0}
    if simulation.initial_state == "estimate":
        start["z0"], start["v0"] = _start_estimate(cost)
    z, v = cost.simulate(parameters, **start)
    z = z + parameters.get("output_offset", 0.0)  # what the output sensor reads
    skip = simulation.skip
    if np.all(np.isfinite(z)):
        j = float(normalised_cost(record.z[skip:], z[skip:]))
        rms = float(np.sqrt(np.mean((record.z[skip:] - z[skip:]) ** 2)))
    else:
        j = rms = float("inf")
    voltage = None
    if isinstance(circuit, Resistive | Inductive):  # a coil: V = alpha z' R_L / (R_L + R_C)
        voltage = circuit.alpha * v * circuit.load_fraction
    return Prediction(
        record=record, z=z, v=v, cost=j, rms_error=rms, voltage=voltage, initial_state=start
    )


def _named_device(harvester: Harvester, measurement):
    """(model, coupling, named parameters, r_load, known bridge) of a device for the channel
    simulation; the bridge (:func:`~randvib.identification.experiment.known_bridge`'s dict)
    None without one."""
    if not isinstance(harvester, Harvester):
        raise ValueError(
            f"predict_record needs a randvib.Harvester, got {type(harvester).__name__}"
        )
    parameters = device_parameters(harvester, measurement, "predict_record", rectified=True)
    model = model_of(harvester.friction_name)
    coupling = harvester.electrical
    if coupling is None:
        return model, None, parameters, None, None
    if coupling.rectified:  # the transducer's parameters named, the bridge's known
        own = coupling.parameters()
        named = {**parameters, "c": harvester.c_m}
        named.update({n: own[n] for n in COUPLING_PARAMETERS[coupling.transducer] if n in own})
        known = {n: own[n] for n in ("v_diode", "storage_capacitance", "battery") if n in own}
        # a battery has no load: its R_L stands in for the records' (unused)
        load = 1.0 if coupling.has_battery else coupling.r_load
        return model, coupling.transducer, named, load, known
    named = {**parameters, "c": harvester.c_m, **coupling.parameters()}
    named.pop("r_load")
    return model, coupling.name, named, coupling.r_load, None


def score_channels(harvester, record, measurement, simulation, outputs=None) -> Prediction:
    """:func:`predict_record` of the channels ``outputs``, a circuit state simulated.

    The record's initial state (and the circuit's) is estimated by a least-
    squares fit of the channels' error (``initial_state="estimate"``), or
    taken from its first samples.
    """
    from randvib.identification.experiment import (
        START,
        ExperimentCost,
        ExperimentError,
        recorded_tests,
    )
    from randvib.identification.least_squares import Coordinates, polish

    measurement = measurement or MeasurementModel()
    model, coupling, named, r_load, bridge = _named_device(harvester, measurement)
    if outputs is None:
        outputs = ("relative_displacement",) if "relative_displacement" in record else ()
        outputs += tuple(k for k in ("voltage",) if k in record and coupling)
    (test,) = recorded_tests(record, outputs, r_load, coupling, bridge)
    fixed = {**named, **{OFFSET_NAMES[k]: measurement.offset(k) for k in test.outputs}}
    fixed = {k: float(np.ravel(v)[0]) for k, v in fixed.items()}
    cost = ExperimentCost([test], model, coupling, fixed=fixed, free=(), simulation=simulation)
    values = {k: np.array([v]) for k, v in fixed.items()}
    start = dict(zip((*START, "x0"), (float(x[0]) for x in cost.start(values, 0)), strict=True))
    if simulation.initial_state == "estimate":
        names = START + (("x0",) if harvester.has_circuit else ())
        coords = Coordinates(
            names=names, log=np.zeros(len(names), bool),
            scale=np.array([max(abs(start[n]), 1e-9) for n in names]),
            lower=np.full(len(names), -np.inf), upper=np.full(len(names), np.inf),
        )  # fmt: skip
        problem, guess = ExperimentError(cost, coords), np.array([start[n] for n in names])
        theta, _, _, _ = polish(problem, guess, with_uncertainty=False)
        start.update(zip(names, map(float, theta), strict=True))
    values.update({k: np.array([v]) for k, v in start.items()})
    run = cost.run(values, 0, start=tuple(np.array([start[n]]) for n in (*START, "x0")))
    channels = {
        kind: y[0] + fixed[OFFSET_NAMES[kind]] for kind, y in cost.outputs(values, 0, run).items()
    }
    costs, rms = {}, {}
    skip = simulation.skip
    for kind, y in channels.items():
        measured = record[kind][skip:]
        finite = np.all(np.isfinite(y))
        costs[kind] = float(normalised_cost(measured, y[skip:])) if finite else float("inf")
        rms[kind] = float(np.sqrt(np.mean((measured - y[skip:]) ** 2))) if finite else float("inf")
    voltage = None
    if bridge is not None:
        voltage = run.x[0]  # the DC output voltage
    elif coupling is not None:
        cz, cv, cx = output_coefficients("voltage", coupling, values, r_load)
        voltage = (
            cz * run.z + np.atleast_1d(cv)[:, None] * run.v + np.atleast_1d(cx)[:, None] * run.x
        )[0]
    first = test.outputs[0]
    return Prediction(
        record=record, z=run.z[0] + fixed.get("output_offset", 0.0), v=run.v[0],
        cost=float(sum(costs.values())), rms_error=rms[first], voltage=voltage,
        initial_state=start, channels=channels, costs=costs, rms_errors=rms,
    )  # fmt: skip


@dataclass(frozen=True)
class ValidationRow:
    """J (Eq. 11), RMS error, length and residual verdict of one record in :func:`validate`."""

    record: str
    model: str
    cost: float
    rms_error: float
    samples: int
    #: The sensor offsets used on this record (re-estimated on it, or given).
    offsets: dict = field(default_factory=dict)
    #: Where they come from: one of :data:`OFFSET_SOURCES`.
    offsets_source: str = "given"
    #: Whiteness of the residual and its independence of the input on this record
    #: (:func:`~randvib.identification.residuals.residual_diagnostics`).
    residuals: object = None
    #: With several channels: each one's J and RMS error (kind -> {"cost", "rms_error"});
    #: ``cost`` is then their sum and ``rms_error`` the first's.
    channels: dict = field(default_factory=dict)
    #: The load (ohm) the record was simulated at, with a coupling.
    r_load: float | None = None

    @property
    def verdict(self) -> str | None:
        """``white`` or ``structured``: the residual diagnostics' verdict (None if none)."""
        return None if self.residuals is None else self.residuals.verdict

    def to_dict(self) -> dict:
        """JSON-ready: the scores, the offsets and their source, the residual diagnostics."""
        return {
            "record": self.record,
            "cost": self.cost,
            "rms_error": self.rms_error,
            "samples": self.samples,
            "offsets": self.offsets,
            "offsets_source": self.offsets_source,
            "residuals": None if self.residuals is None else self.residuals.to_dict(),
            **({"channels": self.channels} if self.channels else {}),
            **({"r_load": self.r_load} if self.r_load is not None else {}),
        }


#: Where a validation row's offsets come from (:func:`validate`, ``offsets="per-record"``):
#: the given ones, the output offset re-estimated on the record (the input's given),
#: or both re-estimated; the one of lowest J is kept.
OFFSET_SOURCES = ("given", "output re-estimated", "both re-estimated")


#: How :func:`validate` treats the sensors' offsets.
OFFSET_POLICIES = ("per-record", "given")


def validate(
    harvester: Harvester,
    records,
    *,
    measurement: MeasurementModel | None = None,
    offsets: str = "per-record",
    outputs=None,
    r_load=None,
    **settings,
) -> list[ValidationRow]:
    """J (Eq. 11) and RMS error of a device on each of several records.

    ``settings`` are those of :func:`predict_record` (``simulation=`` or its
    fields as keywords); ``measurement`` is the sensors' model (k2 and the
    offsets).

    Parameters
    ----------
    offsets : {"per-record", "given"}
        ``"per-record"`` (default): the sensor offsets belong to a record, not
        to the device, so they are re-estimated on each record -- the output
        offset in closed form (the mean residual, as identify profiles it),
        and the input offset too, where ``measurement`` has one, by a bounded
        scalar search of J over the record's input mean +- half its standard
        deviation (identify's box) -- and the given offsets, the output one
        re-estimated alone and both re-estimated are scored by the J reported
        (the initial state estimated), the lowest kept: a re-estimate that
        does not lower J (the pair trading off, nearly unidentifiable apart)
        never spoils a good model. ``"given"``: those of ``measurement`` on
        every record. Each row's ``offsets`` and ``offsets_source`` say which
        were used, its ``residuals`` the residual's verdict on that record.
    outputs : sequence of str, optional
        The channels scored on each record (``relative_displacement``,
        ``relative_velocity``, ``voltage``, ``current``), each with its own J
        and RMS error (``ValidationRow.channels``); then, with ``"per-record"``,
        each channel's offset is re-estimated on the record (its mean
        residual) and kept where it lowers J, the input offset given; the
        residual verdict is the first channel's.
    r_load : float or sequence of float, optional
        Each record's load (ohm) for a device with a coupling (default the
        device's own).
    """
    from randvib.identification.residuals import residual_diagnostics

    if offsets not in OFFSET_POLICIES:
        raise ValueError(f"`offsets` must be one of {', '.join(OFFSET_POLICIES)}; got {offsets!r}")
    model = model_of(harvester.friction_name) if isinstance(harvester, Harvester) else None
    measurement = measurement or MeasurementModel()
    circuit = isinstance(harvester, Harvester) and harvester.electrical is not None
    dynamic = circuit and (harvester.has_circuit or harvester.is_rectified)
    if outputs is not None or r_load is not None or dynamic:
        return _validate_channels(
            harvester, records, measurement, offsets, outputs, r_load, settings
        )
    rows = []
    for record in records:
        source, used, pred = _best_offsets(harvester, record, measurement, offsets, settings)
        skip = _skip(settings)
        residual = record.z[skip:] - pred.z[skip:]
        rows.append(
            ValidationRow(
                record.name,
                model,
                pred.cost,
                pred.rms_error,
                record.n,
                {"input_offset": used.input_offset, "output_offset": used.output_offset},
                source,
                residual_diagnostics(residual, record.input[skip:]),
            )
        )
    return rows


def _skip(settings: dict) -> int:
    """The samples left out of J at the start, from :func:`validate`'s settings."""
    options = dict(settings)
    (simulation,) = resolve_settings(
        "validate", options, simulation=options.pop("simulation", None)
    )
    return int(simulation.skip)


def _best_offsets(harvester, record, measurement, policy, settings):
    """(source, measurement, prediction) of the offsets of lowest J on ``record``."""
    candidates = {"given": measurement}
    if policy == "per-record":
        candidates["output re-estimated"] = _record_offsets(
            harvester, record, measurement, settings, estimate_input=False
        )
        if measurement.input_offset != 0.0:
            candidates["both re-estimated"] = _record_offsets(
                harvester, record, measurement, settings, estimate_input=True
            )
    scored = {
        source: (used, predict_record(harvester, record, measurement=used, **settings))
        for source, used in candidates.items()
    }
    # a re-estimate is kept only where it lowers J (ties: the given offsets)
    source = min(scored, key=lambda s: (scored[s][1].cost, s != "given"))
    return (source, *scored[source])


def _validate_channels(harvester, records, measurement, offsets, outputs, r_load, settings):
    """:func:`validate` on channels (a circuit simulated), each with its J and RMS error."""
    from randvib.identification.residuals import residual_diagnostics

    records = list(records)
    loads = [r_load] * len(records) if np.ndim(r_load) == 0 else list(r_load)
    if len(loads) != len(records):
        raise ValueError(f"`r_load` gives {len(loads)} loads for {len(records)} records")
    model = model_of(harvester.friction_name)
    skip = _skip(settings)
    rows = []
    for record, load in zip(records, loads, strict=True):
        device = harvester if load is None else harvester.updated(r_load=float(load))
        source, used, pred = _best_channel_offsets(
            device, record, measurement, offsets, outputs, settings, skip
        )
        first = pred.outputs[0]
        residual = (record[first] - pred.simulated(first))[skip:]
        rows.append(
            ValidationRow(
                record.name, model, pred.cost, pred.rms_error, record.n,
                offsets={"input_offset": float(used.input_offset),
                         **{OFFSET_NAMES[k]: used.offset(k) for k in pred.channels}},
                offsets_source=source,
                residuals=residual_diagnostics(residual, record.input[skip:]),
                channels={k: {"cost": pred.costs[k], "rms_error": pred.rms_errors[k]}
                          for k in pred.channels},
                r_load=_row_load(device),
            )
        )  # fmt: skip
    return rows


def _row_load(device) -> float | None:
    """The load R_L a validation row was scored at; None without one (no coupling, or a
    bridge into a battery)."""
    load = getattr(device.electrical, "r_load", None)
    return None if load is None else float(load)


def _best_channel_offsets(device, record, measurement, policy, outputs, settings, skip):
    """(source, measurement, prediction) on channels: the given offsets, or with
    ``"per-record"`` each channel's re-estimated (its mean residual) where that lowers J."""
    from dataclasses import replace

    given = predict_record(device, record, measurement=measurement, outputs=outputs, **settings)
    if policy != "per-record":
        return "given", measurement, given
    shift = {k: float(np.mean((record[k] - given.channels[k])[skip:])) for k in given.channels}
    channel = {k: measurement.offset(k) + d for k, d in shift.items()}
    used = replace(
        measurement,
        output_offset=channel.pop("relative_displacement", measurement.output_offset),
        channel_offsets={**measurement.channel_offsets, **channel},
    )
    pred = predict_record(device, record, measurement=used, outputs=outputs, **settings)
    # a re-estimate is kept only where it lowers J (ties: the given offsets)
    if pred.cost < given.cost:
        return "output re-estimated", used, pred
    return "given", measurement, given


def _record_offsets(
    harvester, record, measurement, settings, estimate_input: bool
) -> MeasurementModel:
    """``measurement`` with the offsets that minimise J on ``record`` (see :func:`validate`).

    J is identify's: the output offset profiled in closed form, the start
    z0 taken from the first sample less the record's mean (:class:`CostFunction`);
    the input offset searched too with ``estimate_input``, else kept.
    """
    from dataclasses import replace

    from scipy import optimize

    from randvib.identification.input_reconstruction import driving_signal

    options = dict(settings)
    (simulation,) = resolve_settings(
        "validate", options, simulation=options.pop("simulation", None)
    )
    simulation, _ = simulation.for_record(record)  # hold="auto" chosen from this record
    parameters = check_parameters(
        device_parameters(harvester, measurement, "validate"), model_of(harvester.friction_name)
    )
    model = model_of(harvester.friction_name)
    fixed = {k: v for k, v in parameters.items() if k != "output_offset"}
    if estimate_input:
        fixed.pop("input_offset", None)
    free = ("input_offset",) if estimate_input else ()
    options = simulation.to_dict()
    options.pop("initial_state", None)
    cost = CostFunction(record, model, fixed=fixed, free=free, profile_offset=True, **options)
    input_offset = measurement.input_offset
    if estimate_input:
        drive, _ = driving_signal(record.input, record.dt, record.input_kind)
        mean, half = float(np.mean(drive)), 0.5 * float(np.std(drive))
        res = optimize.minimize_scalar(
            lambda x: float(cost(np.array([[x]]))[0]),
            bounds=(mean - half, mean + half),
            method="bounded",
            options={"xatol": 1e-9 * half},
        )
        input_offset = float(res.x)
    values = {**fixed, "input_offset": input_offset} if estimate_input else dict(fixed)
    skip = simulation.skip
    output_offset = 0.0
    # the start z0 = first sample less the offset: a second pass starts from
    # the offset just estimated instead of the record's mean (its guess)
    for start in (cost.z0, None):
        z0 = start if start is not None else float(record.z[0] - output_offset)
        z, _ = cost.simulate(values, z0=z0)
        if not np.all(np.isfinite(z)):
            break
        output_offset = float(np.mean(record.z[skip:] - z[skip:]))
    return replace(measurement, input_offset=input_offset, output_offset=output_offset)
