"""Synthetic records of an assembly: ``randvib record --device FILE.toml`` (issue 31).

:func:`assembly_record` is :func:`~randvib.identification.synthetic.synthetic_record`
for an :class:`~randvib.models.assembly.Assembly` of N DOFs: the same
band-limited shaker test (the same excitation realisation on the same seed),
the same input channel, sensor noise and offsets, and one column per DOF and
per transducer instead of the single mass's one per kind:

* ``dof.I.relative_displacement`` (m) and ``dof.I.relative_velocity`` (m/s):
  x_I and x_I' of DOF I, relative to the base;
* ``transducer.T.voltage`` (V) and ``transducer.T.current`` (A): the load
  voltage and current of transducer T (file order), read from its relative
  coordinate u = d^T x and its circuit state exactly as the single mass's
  channels (:func:`~randvib.identification.circuit.output_coefficients`).

The names follow the device file's dotted paths (``transducer.0.r_load``).

Why it is not the single mass's integrator
------------------------------------------
The single mass's record is integrated by the compiled RK4 of
:mod:`randvib.identification.record_integrator` (exact stick-slip events), which
has no assembly. An assembly is integrated from rest by its own compiled kernel
(:mod:`randvib.montecarlo.assembly_kernel`, Heun by default), one path driven by
the base acceleration linearly interpolated between the samples and integrated
exactly over each of ``substeps`` steps per sample
(:class:`~randvib.montecarlo.driven.RecordedInput`, as
:func:`~randvib.montecarlo.on_record.monte_carlo_on_record` drives it). A one-DOF
assembly's record therefore equals the single mass's to the schemes' step
error (second order for Heun), not bit for bit; the input column is the same
realisation, bit for bit.
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass

import numpy as np

from randvib._validation import check_finite, check_int, check_nonnegative, check_positive
from randvib.identification.circuit import OUTPUT_KINDS, check_output_kind, output_coefficients
from randvib.identification.synthetic import (
    PAPER_BAND,
    SYNTHETIC_INPUTS,
    excitation_text,
    realised_input,
)
from randvib.models.assembly import Assembly
from randvib.models.excitation import BaseMotionOverflow, Measured
from randvib.models.record import TIME_COLUMN, Record
from randvib.montecarlo.assembly_kernel import row_offsets
from randvib.montecarlo.assembly_setup import PartOrder
from randvib.montecarlo.assembly_simulation import execute_assembly, validated_assembly
from randvib.montecarlo.driven import RecordedInput
from randvib.quantities import unit

__all__ = ["AssemblyRecord", "assembly_record", "record_column"]

#: Output kinds recorded once per DOF; the others (voltage, current) once per transducer.
DOF_OUTPUTS = ("relative_displacement", "relative_velocity")


def record_column(kind: str, index: int) -> str:
    """The column of output ``kind`` of DOF or transducer ``index``: ``dof.1.relative_velocity``."""
    where = "dof" if kind in DOF_OUTPUTS else "transducer"
    return f"{where}.{index}.{kind}"


@dataclass(frozen=True, eq=False)
class AssemblyRecord:
    """A synthetic record of an assembly (:func:`assembly_record`).

    Attributes
    ----------
    dt : float
        Sample interval (s).
    columns : dict
        Column name -> samples: the input channel (``base_acceleration``,
        m/s^2, or ``base_displacement``, m) first, then the response columns
        (:func:`record_column`), as measured (true + offset + noise).
    input_kind : str
        The input column's name.
    name : str
        Record label.
    """

    dt: float
    columns: dict
    input_kind: str
    name: str = "synthetic"

    @property
    def n(self) -> int:
        """Number of samples."""
        return self.columns[self.input_kind].size

    @property
    def sample_rate(self) -> float:
        """Samples per second (Hz)."""
        return 1.0 / self.dt

    @property
    def time(self) -> np.ndarray:
        """Sample times (s), from 0."""
        return np.arange(self.n) * self.dt

    def to_frame(self):
        """The record as a DataFrame: ``time``, the input, the response columns."""
        import pandas as pd

        return pd.DataFrame({TIME_COLUMN: self.time, **self.columns})


def assembly_record(
    assembly: Assembly,
    excitation,
    *,
    duration: float,
    sample_rate: float,
    seed=None,
    input: str = "base_acceleration",  # noqa: A002 - the record's column name
    noise_z: float = 0.0,
    noise_input: float = 0.0,
    offset_z: float = 0.0,
    offset_input: float = 0.0,
    substeps: int = 8,
    band: tuple[float, float] = PAPER_BAND,
    name: str = "synthetic",
    outputs=("relative_displacement",),
    noise: dict | None = None,
    offsets: dict | None = None,
    scheme: str = "heun",
) -> AssemblyRecord:
    """Simulate an assembly from rest under a band-limited base excitation, as sensors see it.

    The arguments are :func:`~randvib.identification.synthetic.synthetic_record`'s
    (the same excitation realisation for the same ``seed``); the assembly
    ``M x'' + C x' + K x + sum_e f_e = -M r a(t)`` (docs/assemblies.md) is
    driven by the true base acceleration a, whatever the input column holds.

    Parameters
    ----------
    assembly : Assembly
        The device (``rv.Assembly.from_toml(path)``).
    excitation : float, Excitation or Record
        As for ``synthetic_record``: an RMS (m/s^2) over ``band``, an
        excitation with ``sample()`` or a Record of base motion holding a
        ``base_acceleration`` channel.
    outputs : sequence of str
        Output kinds: ``relative_displacement`` and ``relative_velocity`` give
        one column per DOF, ``voltage`` and ``current`` one per transducer
        (each transducer must have a circuit: a coupling with a load, not a
        bare ``c_e`` nor a diode bridge).
    noise_z, offset_z : float
        Sensor noise RMS and offset (m) of every displacement column.
    noise, offsets : dict, optional
        ``kind -> RMS`` and ``kind -> offset`` of every column of that kind.
    scheme : {'heun', 'euler'}
        The assembly kernel's scheme.

    Returns
    -------
    AssemblyRecord
        Noise is drawn for every possible column in a fixed order (input,
        displacements, velocities, voltages, currents), so that one column's
        noise does not depend on which others are recorded.

    Raises
    ------
    ValueError
        An argument out of range, named in the message.
    """
    if not isinstance(assembly, Assembly):
        raise ValueError(f"`assembly` must be a randvib.Assembly, got {type(assembly).__name__}")
    duration = float(check_positive("duration", duration, "s"))
    sample_rate = float(check_positive("sample_rate", sample_rate, "Hz"))
    if input not in SYNTHETIC_INPUTS:
        raise ValueError(f"`input` must be one of {', '.join(SYNTHETIC_INPUTS)}; got {input!r}")
    substeps = check_int("substeps", substeps, minimum=1)
    outputs = _outputs(outputs, assembly)
    rms, shift = _channel_values(noise_z, offset_z, noise, offsets)
    noise_input = float(check_nonnegative("noise_input", noise_input))
    offset_input = float(check_finite("offset_input", offset_input))
    excitation_rng, noise_rng = np.random.default_rng(seed).spawn(2)
    acceleration, recorded = _base_motion(
        excitation, input, duration, sample_rate, band, excitation_rng
    )
    dt = 1.0 / sample_rate
    true = _simulate(assembly, acceleration, dt, substeps, scheme)
    n_dof, n_transducers = assembly.n_dof, len(assembly.transducers)
    eps = noise_rng.standard_normal((1 + 2 * n_dof + 2 * n_transducers, acceleration.size))
    columns = {input: recorded + offset_input + noise_input * eps[0]}
    # the noise rows: the input's, then each kind's block of DOFs or transducers
    first_row = {
        "relative_displacement": 1,
        "relative_velocity": 1 + n_dof,
        "voltage": 1 + 2 * n_dof,
        "current": 1 + 2 * n_dof + n_transducers,
    }
    for kind in outputs:
        for index in range(n_dof if kind in DOF_OUTPUTS else n_transducers):
            column = record_column(kind, index)
            noisy = rms[kind] * eps[first_row[kind] + index]
            columns[column] = true[column] + shift[kind] + noisy
    return AssemblyRecord(dt, columns, input, name)


def _outputs(outputs, assembly: Assembly) -> tuple:
    """The output kinds, checked against the assembly's transducers."""
    outputs = (outputs,) if isinstance(outputs, str) else tuple(outputs)
    if not outputs or len(set(outputs)) != len(outputs):
        raise ValueError(f"`outputs` must name distinct output kinds, got {outputs!r}")
    for kind in outputs:
        check_output_kind(kind, "outputs")
        if kind in DOF_OUTPUTS:
            continue
        if not assembly.transducers:
            raise ValueError(f"a `{kind}` output needs a transducer; the assembly has none")
        for index, transducer in enumerate(assembly.transducers):
            coupling = transducer.coupling
            if transducer.is_rectified or getattr(coupling, "r_load", None) is None:
                what = "a diode bridge" if transducer.is_rectified else "an electrical damping"
                raise ValueError(
                    f"a `{kind}` output needs every transducer's circuit, but transducer "
                    f"{index} is {what} without a load ({coupling.name}); record "
                    f"{' or '.join(DOF_OUTPUTS)} of this device, or give the transducer a "
                    "coupling with r_load"
                )
    return outputs


def _channel_values(noise_z, offset_z, noise, offsets) -> tuple[dict, dict]:
    """Each output kind's noise RMS and offset, checked (as the single mass's sensors)."""
    rms = {kind: 0.0 for kind in OUTPUT_KINDS}
    shift = dict(rms)
    rms["relative_displacement"] = float(check_nonnegative("noise_z", noise_z, "m"))
    shift["relative_displacement"] = float(check_finite("offset_z", offset_z))
    for kind, value in (noise or {}).items():
        check_output_kind(kind, "noise")
        rms[kind] = float(check_nonnegative(f"noise of {kind}", value, unit(kind)))
    for kind, value in (offsets or {}).items():
        check_output_kind(kind, "offsets")
        shift[kind] = float(check_finite(f"offset of {kind}", value))
    return rms, shift


def _base_motion(excitation, kind, duration, sample_rate, band, rng):
    """(true base acceleration, true input column): one realisation, as the single mass's."""
    with np.errstate(all="ignore"):
        try:
            # the same generator state twice: both channels of one realisation
            recorded = realised_input(
                excitation, kind, duration, sample_rate, band, copy.deepcopy(rng)
            )
            acceleration = recorded
            if kind != "base_acceleration":
                acceleration = realised_input(
                    excitation, "base_acceleration", duration, sample_rate, band, rng
                )
        except BaseMotionOverflow:
            recorded = acceleration = None
    if recorded is None or not (
        np.all(np.isfinite(recorded)) and np.all(np.isfinite(acceleration))
    ):
        raise ValueError(
            f"`excitation` {excitation_text(excitation)} overflows float64 in the {kind} "
            "signal; lower it (`--rms` / `--psd`)"
        )
    return acceleration, recorded


def _simulate(assembly, acceleration, dt, substeps, scheme) -> dict:
    """The true response columns of the assembly from rest, one path on the record's grid."""
    n = acceleration.size
    measured = Measured(Record(dt, base_acceleration=acceleration))
    # One segment of the whole record, no burn-in, the mean kept: the record as simulated.
    source = RecordedInput(acceleration, substeps, 0, n - 1, dt / substeps)
    run = validated_assembly(
        assembly, measured.spectrum, scheme, t_end=source.n_steps * source.dt, dt=source.dt,
        burn_in=0.0, n_paths=1, seed=0, first_path=0, initial="rest", dW=None,
        record=(1, substeps),
    )  # fmt: skip
    run = dataclasses.replace(run, excitation=measured, psd=None, driver=source)
    result = execute_assembly(
        run, control_variates=False, check_step=True, threads=None, batch_paths=None,
        progress=False,
    )  # fmt: skip
    x, v, state = (result.histories.x[0], result.histories.v[0], result.histories.state[0])
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise ValueError(
            "the simulated response of the assembly diverged; lower the excitation "
            "(`--rms` / `--psd`) or raise `substeps`"
        )
    true = {}
    for i in range(assembly.n_dof):
        true[record_column("relative_displacement", i)] = x[:, i]
        true[record_column("relative_velocity", i)] = v[:, i]
    true.update(_transducer_columns(assembly, x, v, state))
    return true


def _transducer_columns(assembly, x, v, state) -> dict:
    """Each transducer's load voltage and current from its coordinate and circuit state."""
    order = PartOrder.of(assembly)
    oc = row_offsets(assembly.n_dof, len(assembly.elements), len(order.circuits), 0)[2]
    out = {}
    for index, transducer in enumerate(assembly.transducers):
        coupling = transducer.coupling
        if transducer.is_rectified or getattr(coupling, "r_load", None) is None:
            continue  # no load to read (refused by _outputs when asked for)
        d = assembly.incidence(transducer)
        u, du = x @ d, v @ d
        circuit = state[:, oc + order.circuits.index(index)] if transducer.is_dynamic else 0.0
        for kind in ("voltage", "current"):
            cz, cv, cx = output_coefficients(
                kind, coupling.name, coupling.parameters(), coupling.r_load
            )
            out[record_column(kind, index)] = cz * u + cv * du + cx * circuit
    return out
