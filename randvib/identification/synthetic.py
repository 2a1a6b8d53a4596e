"""Synthetic records: a device simulated under a band-limited shaker test, as a sensor sees it.

One call, :func:`synthetic_record`, takes the four steps of a synthetic test
(realise the excitation, pick the input channel, simulate the device with
:func:`~randvib.identification.record_response.record_response`, wrap a
:class:`~randvib.models.record.Record`) and adds what a real measurement
adds: Gaussian sensor noise and constant offsets on each channel.
An offset is what the sensor adds: measured value = true value + offset.

The excitation follows the paper's shaker tests (Sec. 3): a Gaussian base
acceleration with a flat one-sided PSD, by default between 4 and 20 Hz,
given either by its RMS (scaled exactly, :func:`band_limited_excitation`)
or as a :class:`~randvib.models.excitation.BandLimited` spectrum (or any
excitation with ``sample()``), whose realisation has the spectrum's
variance only on average.
"""

from __future__ import annotations

from numbers import Real

import numpy as np

from randvib._validation import (
    check_finite,
    check_int,
    check_nonnegative,
    check_positive,
    check_scalar_device,
)
from randvib.identification.circuit import ELECTRICAL_OUTPUTS, OUTPUT_KINDS, check_output_kind
from randvib.identification.record_response import record_response
from randvib.models.excitation import BaseMotionOverflow, Excitation, band_limited_excitation
from randvib.models.harvester import Harvester
from randvib.models.potential import CONFINING
from randvib.models.presets import PRESETS, preset
from randvib.models.record import Record
from randvib.quantities import unit

#: The input channels a synthetic record can carry (the shaker's sensors).
SYNTHETIC_INPUTS = ("base_acceleration", "base_displacement")
#: Band of the paper's shaker tests (Hz), used when the excitation is an RMS.
PAPER_BAND = (4.0, 20.0)


def synthetic_record(
    device,
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
) -> Record:
    """Simulate a device under a band-limited base excitation and record it as sensors would.

    The true relative displacement is
    ``record_response(device, Record(1 / sample_rate, **{input: true_input}),
    substeps=substeps).z`` (Eq. 1 from rest), so a noise-free record without
    offsets is exactly that simulation; the record then holds
    ``true + offset + noise`` on each channel.

    Parameters
    ----------
    device : Harvester or str
        The device (any friction law) or a preset name (:data:`PRESETS`).
    excitation : float, Excitation or Record
        A number is the RMS base acceleration (m/s^2), > 0, of a flat band
        over :data:`PAPER_BAND` scaled exactly to it (paper Table 1: 1.07,
        1.21, ... m/s^2); an :class:`~randvib.models.excitation.Excitation`
        with ``sample()`` (e.g. ``BandLimited(S, f_lo, f_hi)``) is realised
        by frequency-domain synthesis; a :class:`~randvib.models.record.Record`
        of base motion (:func:`~randvib.models.excitation.band_limited_excitation`)
        is used as is (its sample interval and length must match, and it
        must hold the ``input`` channel).
    duration : float
        Record length (s), > 0.
    sample_rate : float
        Samples per second (Hz), above twice the top of the band.
    seed : int, numpy.random.Generator or None
        Random source of the excitation and of the noise (independent
        streams: adding noise does not change the excitation).
    input : {'base_acceleration', 'base_displacement'}
        The input channel recorded (and driving the simulation).
    noise_z, noise_input : float
        RMS of the white Gaussian sensor noise on z (m) and on the input
        (m/s^2 or m), >= 0.
    offset_z, offset_input : float
        Constant sensor offsets on z (m) and on the input (same unit).
    substeps : int
        Integration steps per sample interval, >= 1.
    band : (f_lo, f_hi)
        Band (Hz) of an excitation given as an RMS; default the paper's.
    name : str
        Record label.
    outputs : sequence of str
        The response channels recorded
        (:data:`~randvib.identification.circuit.OUTPUT_KINDS`): the
        relative displacement (default), velocity, and with a coupling the
        load voltage (a coil's ``R_L i``, its inductance's current a state;
        a piezo element's ``V``) and current, simulated as measured.
    noise, offsets : dict, optional
        ``kind -> RMS`` of each output channel's white sensor noise and
        ``kind -> offset`` (its unit); ``noise_z`` and ``offset_z`` are the
        displacement's.

    Returns
    -------
    Record
        Write it with ``record.to_csv(path)`` for ``identify``/``read_record``.

    Raises
    ------
    ValueError
        An argument out of range, named in the message.

    Examples
    --------
    >>> import numpy as np
    >>> import randvib as rv
    >>> record = rv.synthetic_record(
    ...     rv.preset("coulomb-td1"), 1.07, duration=1.0, sample_rate=500.0, seed=1
    ... )
    >>> record.n, record.dt, record.input_kind
    (500, 0.002, 'base_acceleration')
    >>> print(f"input RMS {np.sqrt(np.mean(record.input**2)):.2f} m/s^2")
    input RMS 1.07 m/s^2
    """
    device = _device(device)
    duration = float(check_positive("duration", duration, "s"))
    sample_rate = float(check_positive("sample_rate", sample_rate, "Hz"))
    if input not in SYNTHETIC_INPUTS:
        raise ValueError(f"`input` must be one of {', '.join(SYNTHETIC_INPUTS)}; got {input!r}")
    sensor = {
        "noise_z": float(check_nonnegative("noise_z", noise_z, "m")),
        "noise_input": float(check_nonnegative("noise_input", noise_input)),
        "offset_z": float(check_finite("offset_z", offset_z)),
        "offset_input": float(check_finite("offset_input", offset_input)),
    }
    substeps = check_int("substeps", substeps, minimum=1)
    outputs, noise, offsets = _sensors(outputs, noise, offsets, sensor, device)
    excitation_rng, noise_rng = np.random.default_rng(seed).spawn(2)
    with np.errstate(all="ignore"):
        try:
            true_input = _true_input(excitation, input, duration, sample_rate, band, excitation_rng)
        except BaseMotionOverflow:  # the RMS's velocity or displacement overflows
            true_input = None
    if true_input is None or not np.all(np.isfinite(true_input)):
        raise ValueError(
            f"`excitation` {_excitation_text(excitation)} overflows float64 in the {input} "
            "signal; lower it (`--rms` / `--psd`)"
        )
    dt = 1.0 / sample_rate
    sim = record_response(device, Record(dt, **{input: true_input}), substeps=substeps)
    if not (np.all(np.isfinite(sim.z)) and np.all(np.isfinite(sim.x))):
        raise ValueError(
            f"the simulated response to `excitation` {_excitation_text(excitation)} diverged; "
            "lower the excitation (`--rms` / `--psd`) or raise `substeps`"
        )
    # Independent draws per channel, always drawn so that one channel's noise
    # does not depend on whether another has any (the input's and the
    # displacement's first, as before the other channels existed).
    eps = noise_rng.standard_normal((2 + len(OUTPUT_KINDS), sim.z.shape[1]))
    measured = {input: true_input + sensor["offset_input"] + sensor["noise_input"] * eps[0]}
    for kind in outputs:
        row = 1 if kind == "relative_displacement" else 2 + OUTPUT_KINDS.index(kind)
        measured[kind] = sim.output(kind)[0] + offsets[kind] + noise[kind] * eps[row]
    return Record(dt, name=name, **measured)


def _sensors(outputs, noise, offsets, sensor, device) -> tuple[tuple, dict, dict]:
    """The output channels and each one's noise RMS and offset, checked."""
    outputs = (outputs,) if isinstance(outputs, str) else tuple(outputs)
    if not outputs or len(set(outputs)) != len(outputs):
        raise ValueError(f"`outputs` must name distinct output kinds, got {outputs!r}")
    for kind in outputs:
        check_output_kind(kind)
        if kind in ELECTRICAL_OUTPUTS and device.electrical is None:
            raise ValueError(
                f"a `{kind}` output needs the device's circuit: give it a coupling "
                "(`--coupling` with its options, Harvester.with_coupling)"
            )
    rms = {kind: 0.0 for kind in OUTPUT_KINDS}
    shift = dict(rms)
    rms["relative_displacement"], shift["relative_displacement"] = (
        sensor["noise_z"],
        sensor["offset_z"],
    )
    for kind, value in (noise or {}).items():
        check_output_kind(kind, "noise")
        rms[kind] = float(check_nonnegative(f"noise of {kind}", value, unit(kind)))
    for kind, value in (offsets or {}).items():
        check_output_kind(kind, "offsets")
        shift[kind] = float(check_finite(f"offset of {kind}", value))
    return outputs, rms, shift


def _excitation_text(excitation) -> str:
    if isinstance(excitation, Real):
        return f"{excitation!r} m/s^2 RMS"
    return repr(excitation) if not isinstance(excitation, Record) else "(given signal)"


def _device(device) -> Harvester:
    if isinstance(device, str):
        if device not in PRESETS:
            raise ValueError(
                f"`device` must be a Harvester or one of {', '.join(PRESETS)}; got {device!r}"
            )
        return preset(device)
    if not isinstance(device, Harvester):
        raise ValueError(
            f"`device` must be a Harvester or a preset name, got {type(device).__name__}"
        )
    device = check_scalar_device(device, "synthetic_record")
    # a non-confining potential sends the mass to infinity within the record
    # (|z| ~ 1e269 m): refused as simulate refuses it; the free mass drifts but stays finite
    device.potential.require("a synthetic record", CONFINING + ("free",))
    return device


def _true_input(excitation, kind, duration, sample_rate, band, rng) -> np.ndarray:
    """The true input channel ``kind`` of one realisation on the record's grid."""
    if isinstance(excitation, Record):
        n = round(duration * sample_rate)
        if excitation.dt != 1.0 / sample_rate or excitation.n != n:
            raise ValueError(
                f"`excitation` is sampled at {excitation.sample_rate} Hz with {excitation.n} "
                f"samples; the record needs {sample_rate} Hz and {n}"
            )
        if kind not in excitation:
            raise ValueError(
                f"`excitation` {excitation.name!r} has no {kind} channel for `input` {kind!r}; "
                f"it has {', '.join(excitation.channels)}"
            )
        base = excitation
    elif isinstance(excitation, Real) and not isinstance(excitation, bool):
        rms = float(check_positive("excitation (RMS base acceleration)", excitation, "m/s^2"))
        base = band_limited_excitation(duration, sample_rate, rms, *band, seed=rng)
    elif isinstance(excitation, Excitation):
        acceleration = excitation.sample(duration, 1.0 / sample_rate, 1, rng)[0]
        if kind == "base_acceleration":
            return acceleration
        return _displacement(acceleration, sample_rate, excitation)
    else:
        raise ValueError(
            "`excitation` must be an RMS (m/s^2), an Excitation such as BandLimited(S, f_lo, "
            f"f_hi) or a Record of base motion; got {type(excitation).__name__}"
        )
    return base[kind]


def _displacement(acceleration, sample_rate, excitation) -> np.ndarray:
    """The shaker's displacement: the exact double spectral integral of the periodic path.

    It exists only without power at 0 Hz (a constant acceleration makes the
    table run away), so such an excitation is refused for this input.
    """
    if excitation.support[0] <= 0:
        raise ValueError(
            f"`input` base_displacement needs an excitation without power at 0 Hz, but the "
            f"{excitation.name} spectrum starts at {excitation.support[0]} Hz; give f_lo > 0"
        )
    n = acceleration.size
    spectrum = np.fft.rfft(acceleration)
    omega = 2 * np.pi * np.fft.rfftfreq(n, 1.0 / sample_rate)
    safe = np.where(omega > 0, omega, 1.0)
    return np.fft.irfft(np.where(omega > 0, -spectrum / safe**2, 0.0), n)
