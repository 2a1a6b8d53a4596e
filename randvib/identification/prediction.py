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
        Simulated load voltage (V) when the device has a coil:
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

    def __repr__(self) -> str:  # the scores and the start, not the simulated samples
        start = ", ".join(f"{k} = {float(v):.4g}" for k, v in self.initial_state.items())
        voltage = ", voltage" if self.voltage is not None else ""
        return (
            f"Prediction({self.record.name!r}: {self.z.shape[-1]} samples, J = {self.cost:.4g} "
            f"(Eq. 11), RMS error {self.rms_error:.4g}{f'; start {start}' if start else ''}; "
            f"z, v{voltage})"
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
    theta, _, _, _ = polish(SimulationError(cost, coords), np.array([cost.z0, cost.v0]))
    return float(theta[0]), float(theta[1])


def predict_record(
    harvester: Harvester,
    record: Record,
    *,
    measurement: MeasurementModel | None = None,
    simulation: SimulationSettings | None = None,
    **options,
) -> Prediction:
    """Simulate a record with a device and score it with J (Eq. 11).

    The device is simulated with its total damping c = c_m + c_e (a record
    cannot separate them); its circuit, if any, gives the load voltage. (The
    analytic power prediction is :func:`randvib.predict`.)

    Parameters
    ----------
    harvester : Harvester
        The device (a preset, or :meth:`IdentificationResult.harvester
        <randvib.identification.result.IdentificationResult.harvester>`), with
        scalar parameters; a coupling with a circuit state is refused.
    record : Record
        Its input channel drives the device; its relative displacement is
        scored.
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
    """
    from randvib.identification.residuals import residual_diagnostics

    if offsets not in OFFSET_POLICIES:
        raise ValueError(f"`offsets` must be one of {', '.join(OFFSET_POLICIES)}; got {offsets!r}")
    model = model_of(harvester.friction_name) if isinstance(harvester, Harvester) else None
    measurement = measurement or MeasurementModel()
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
