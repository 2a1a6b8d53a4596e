"""The deterministic response of the device to a record's input (paper Eq. 1).

:func:`record_response` integrates Eq. 1 driven by a record's input channel
for one :class:`~randvib.models.harvester.Harvester` or a batch of them (array
parameters) at once (the compiled integrator of
:mod:`randvib.identification.record_integrator`, on the input reconstructed by
:mod:`randvib.identification.input_reconstruction`). A candidate whose
response leaves a sanity bound (``response_limit``) or becomes non-finite is
stopped and gets NaN samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from randvib._validation import check_int
from randvib.identification.circuit import (
    ELECTRICAL_OUTPUTS,
    OUTPUT_KINDS,
    check_output_kind,
    output_coefficients,
)
from randvib.identification.input_reconstruction import HOLDS, driving_signal
from randvib.identification.models import MeasurementModel, device_circuit, device_parameters
from randvib.identification.record_bridge import bridge_output, run_bridge
from randvib.identification.record_integrator import parameter_matrix, run_kernel
from randvib.models.harvester import Harvester
from randvib.models.record import INPUT_KINDS, Record


@dataclass(frozen=True, eq=False)
class BatchSimulation:
    """Responses of a batch of devices to one record's input (:func:`record_response`).

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times (s).
    z, v : ndarray, shape (n_pop, n)
        Relative displacement (m) and velocity (m/s) at the samples; NaN after
        a candidate diverged. One device is a batch of one: ``z[0]`` is its
        response, and :meth:`to_record` makes a record of it.
    x : ndarray, shape (n_pop, n)
        The circuit state (a coil's current, A; a piezo element's voltage,
        V); zeros without one. Behind a diode bridge: the coil's current
        (signed) or the piezo element's voltage V_p.
    harvester : Harvester or None
        The simulated device, whose coupling says what :meth:`output` reads.
    record : Record or None
        The record whose input drove the devices.
    """

    time: np.ndarray
    z: np.ndarray
    v: np.ndarray
    x: np.ndarray | None = None
    harvester: Harvester | None = None
    record: Record | None = field(default=None, repr=False)
    #: Behind a diode bridge: :data:`~randvib.identification.record_bridge.BRIDGE_COLUMNS`
    #: at the samples, shape (n_pop, n, 5); None without one.
    bridge_states: np.ndarray | None = field(default=None, repr=False)

    def output(self, kind: str) -> np.ndarray:
        """The channel ``kind`` of :data:`~randvib.identification.circuit.OUTPUT_KINDS`.

        ``relative_displacement`` z (m), ``relative_velocity`` z' (m/s),
        ``voltage`` the load voltage (V: R_L i of a coil, V of a piezo
        element) and ``current`` the load current (A), as the sensors would
        read them without offset or noise; shape (n_pop, n). Behind a diode
        bridge the DC side's: the storage capacitor's V_C and the load
        current V_C / R_L, or a coil's charging current |i| into a battery
        (:func:`~randvib.identification.record_bridge.bridge_output`).
        """
        check_output_kind(kind, "kind")
        coupling = None if self.harvester is None else self.harvester.electrical
        if self.bridge_states is not None:  # the DC side: V_C, the load's current
            return bridge_output(kind, coupling, self.bridge_states)
        if kind in ELECTRICAL_OUTPUTS and coupling is None:
            raise ValueError(
                f"a `{kind}` output needs the device's circuit: build it with a coupling "
                "(Harvester.with_coupling or Harvester.from_electrical)"
            )
        name = None if coupling is None else coupling.name
        r_load = None if coupling is None else coupling.r_load
        params = {} if coupling is None else coupling.parameters()
        cz, cv, cx = output_coefficients(kind, name, params, r_load)
        x = self.x if self.x is not None else 0.0
        return cz * self.z + np.atleast_1d(cv)[:, None] * self.v + np.atleast_1d(cx)[:, None] * x

    @property
    def n_devices(self) -> int:
        """How many devices the batch simulated (rows of :attr:`z`)."""
        return self.z.shape[0]

    def to_record(self, index: int | None = None, name: str | None = None) -> Record:
        """The driving record with device ``index``'s response as ``relative_displacement``.

        ``index`` may be left out for a batch of one device. The response is
        the true one (no sensor offset): the displacement, and each output
        channel the driving record holds (:meth:`output`) replaced by its
        simulated value (a circuit channel dropped where the device has no
        circuit); the record's other channels are kept.
        """
        if index is None:
            if self.n_devices != 1:
                raise ValueError(
                    f"this batch simulated {self.n_devices} devices: give `index` "
                    f"(0 to {self.n_devices - 1}) for the one to make a record of"
                )
            index = 0
        index = check_int("index", index, minimum=-self.n_devices, maximum=self.n_devices - 1)
        if self.record is None:
            raise ValueError("this batch does not hold the record that drove it")
        channels = dict(self.record.channels)
        coupled = self.harvester is not None and self.harvester.electrical is not None
        for kind in OUTPUT_KINDS:
            if kind != "relative_displacement" and kind not in channels:
                continue
            if kind in ELECTRICAL_OUTPUTS and not coupled:
                channels.pop(kind)  # measured, and not simulated: not this device's
            else:
                channels[kind] = self.output(kind)[index]
        label = name or f"{self.record.name} (simulated)"
        return Record(self.record.dt, time=self.record.time, name=label, **channels)

    def __repr__(self) -> str:  # the sizes, not the samples
        duration = self.time.size * (self.time[1] - self.time[0]) if self.time.size > 1 else 0.0
        devices = "1 device" if self.n_devices == 1 else f"{self.n_devices} devices"
        return (
            f"BatchSimulation({devices} x {self.time.size} samples, {duration:.6g} s; "
            f"z, v of shape {self.z.shape})"
        )


def record_response(
    harvester: Harvester,
    record: Record,
    *,
    measurement: MeasurementModel | None = None,
    input_kind: str | None = None,
    substeps: int = 4,
    hold: str = "linear",
    lowpass: float | None = None,
    z0=0.0,
    v0=0.0,
    theta0=0.0,
    x0=0.0,
    v_c0=0.0,
    response_limit: float = np.inf,
) -> BatchSimulation:
    """The response of Eq. 1 to a record's input, for one device or a batch at once.

    Deterministic: the device is driven by the record's input channel,
    reconstructed between samples, from a given initial state. (The Monte
    Carlo simulation driven by a measured base acceleration, with a
    confidence interval, is :func:`randvib.monte_carlo_on_record`.)

    Parameters
    ----------
    harvester : Harvester
        The device with any friction law: a static coupling as its damper
        c_e (in c = c_m + c_e), a coil with inductance or a piezo element
        with its circuit state (the current i, A, or the voltage V, V),
        integrated with the motion; a diode bridge's states (the storage
        capacitor's V_C, a coil's current with inductance, the piezo's
        clamped voltage) by the Monte Carlo kernel's bridge step
        (:mod:`randvib.identification.record_bridge`). Its parameters
        may be 1-D arrays of one length: a batch of devices, one response
        each, simulated in one parallel compiled call.
    record : Record
        Its input channel drives the device: base displacement (m,
        differentiated twice), base acceleration (m/s^2) or force on the
        mass (N).
    measurement : MeasurementModel, optional
        The input channel's offset (the device is driven by the input less
        it) and the quadratic stiffness k2; default none. The returned z is
        the true displacement, without the output offset.
    input_kind : {'base_displacement', 'base_acceleration', 'force'}, optional
        The channel that drives the device, for a record with several (the
        base motion of :func:`randvib.band_limited_excitation`).
    substeps : int, optional
        Integration steps per sample interval (default 4).
    hold : {'linear', 'zero', 'cubic', 'bandlimited'}
        Reconstruction of the input between samples
        (:func:`~randvib.identification.input_reconstruction.reconstruct_input`).
    lowpass : float, optional
        Zero-phase low-pass cut-off (Hz) for the driving signal.
    z0, v0, theta0, x0 : float or array_like
        Initial displacement (m), velocity (m/s), LuGre bristle state (m),
        circuit state (A or V; behind a bridge a coil's current with
        inductance or the piezo's voltage).
    v_c0 : float or array_like
        Behind a bridge with a storage capacitor: its voltage at t = 0 (V,
        default 0, empty).
    response_limit : float, optional
        |z| above which a candidate counts as diverged (m).

    Returns
    -------
    BatchSimulation
        One row of z, v and the circuit state per device of the batch; its
        :meth:`~BatchSimulation.output` gives a channel (the load voltage...).

    Examples
    --------
    >>> import numpy as np
    >>> import randvib as rv
    >>> motion = rv.band_limited_excitation(2.0, 500.0, 1.07, seed=1)
    >>> devices = rv.preset("coulomb-td1").updated(fc=np.array([0.0, 0.0058]))
    >>> response = rv.record_response(devices, motion, input_kind="base_acceleration")
    >>> response.z.shape
    (2, 1000)
    """
    parameters = device_parameters(
        harvester, measurement, "record_response", scalar=False, rectified=True
    )
    circuit = device_circuit(harvester)
    if not isinstance(record, Record):
        raise ValueError(f"`record` must be a randvib.Record, got {type(record).__name__}")
    kind = _input_kind(record, input_kind)
    substeps = check_int("substeps", substeps, minimum=1)
    if hold not in HOLDS:
        raise ValueError(f"`hold` must be one of {', '.join(HOLDS)}; got {hold!r}")
    friction = None if harvester.friction is None else type(harvester.friction)
    matrix = parameter_matrix(parameters, friction, circuit)
    drive, base_input = driving_signal(record[kind], record.dt, kind, lowpass)
    if harvester.is_rectified:
        states = _bridge_states(
            harvester, matrix, (drive, base_input, record.dt), substeps, hold,
            (z0, v0, theta0, x0, v_c0), response_limit,
        )  # fmt: skip
        return BatchSimulation(
            time=record.time, z=states[..., 0], v=states[..., 1], x=states[..., 2],
            harvester=harvester, record=record, bridge_states=states,
        )  # fmt: skip
    _, z, v, x = run_kernel(
        matrix,
        friction,
        drive,
        base_input,
        record.dt,
        substeps=substeps,
        hold=hold,
        z0=z0,
        v0=v0,
        theta0=theta0,
        x0=x0,
        response_limit=response_limit,
    )
    return BatchSimulation(time=record.time, z=z, v=v, x=x, harvester=harvester, record=record)


def _bridge_states(harvester, matrix, drive, substeps, hold, start, response_limit):
    """:func:`~randvib.identification.record_bridge.run_bridge` of a device behind a bridge.

    Refused: a sub-step above 0.2 over the storage capacitor's fastest rate
    (the Monte Carlo kernel's own limit for V_C's explicit step), and a
    quadratic stiffness k2 (the Monte Carlo drift the bridge step shares has
    none).
    """
    bridge = harvester.electrical
    rate, step = bridge.fastest_rate(), drive[2] / substeps
    if rate * step > 0.2:  # as the Monte Carlo kernel's check: V_C's explicit step
        raise ValueError(
            f"`substeps` = {substeps} leaves a step of {step:.3g} s, too large for the "
            f"{bridge.name}'s storage capacitor (its fastest rate {rate:.3g} 1/s): use "
            f"substeps >= {math.ceil(rate * drive[2] / 0.2)} (`--substeps`)"
        )
    z0, v0, theta0, x0, v_c0 = start
    if np.any(np.asarray(v_c0) != 0.0) and bridge.has_battery:
        raise ValueError(
            f"`v_c0` is a storage capacitor's voltage; the {bridge.name} has a battery"
        )
    code, output, p = bridge.kernel_parameters()
    friction = None if harvester.friction is None else type(harvester.friction)
    return run_bridge(
        matrix, p, (code, output), friction, drive[0], drive[1], drive[2],
        substeps=substeps, hold=hold, z0=z0, v0=v0, theta0=theta0, s1=x0, v_c0=v_c0,
        response_limit=response_limit,
    )  # fmt: skip


def _input_kind(record: Record, input_kind) -> str:
    """The channel that drives the device: ``input_kind``, or the record's one input."""
    if input_kind is None:
        return record.input_kind
    if input_kind not in INPUT_KINDS:
        raise ValueError(
            f"`input_kind` must be one of {', '.join(INPUT_KINDS)}; got {input_kind!r}"
        )
    record[input_kind]  # refused, naming the record's channels, when it has none
    return input_kind
