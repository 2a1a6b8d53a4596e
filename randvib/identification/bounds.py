"""The search space of an identification: default bounds from a record's scales.

Each parameter declares how it is searched (:data:`~randvib.identification.models.DEVICE_SPECS`
and the friction laws' ``parameter(...)`` fields): its default bounds as a
function of the record's characteristic scales (:func:`record_scales`), and
whether on a log scale. :func:`default_bounds` evaluates them;
:func:`search_space` adds the measurement model's (k2, the input offset) and
the user's, and checks that every free parameter has a finite box.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from randvib.identification.input_reconstruction import driving_signal
from randvib.identification.models import MODEL_PARAMETERS, check_parameter, parameter_specs
from randvib.models.parameters import RecordScales
from randvib.models.record import OUTPUT_CHANNEL, Record

#: Fewest samples per free parameter that a record must have.
SAMPLES_PER_PARAMETER = 10


def record_scales(record: Record, m: float | None):
    """Characteristic frequency, displacement, velocity and force of a record."""
    z = record.z - np.mean(record.z)
    v = np.gradient(z, record.dt)
    omega = float(np.sqrt(np.mean(v**2) / np.mean(z**2)))  # zero-crossing frequency of z
    drive, base = driving_signal(record.input, record.dt, record.input_kind)
    if m is None:
        # force input, free mass: equation-error least squares m z'' + c z' + k z = u
        acc = np.gradient(v, record.dt)
        a = np.column_stack([acc, v, z, np.ones_like(z)])
        coef = np.linalg.lstsq(a, drive, rcond=None)[0]
        m_ref = float(coef[0]) if coef[0] > 0 else float(np.std(drive) / np.std(acc))
    else:
        m_ref = float(m)
    force = float(np.sqrt(np.mean(drive**2))) * (m_ref if base else 1.0)
    return omega, float(np.max(np.abs(z))), float(np.sqrt(np.mean(v**2))), force, m_ref


def velocity_gain(drive, output, dt) -> float:
    """|output / z'| near resonance, from the input's and the output's spectra.

    For a channel proportional to the (unmeasured) velocity (a load voltage
    or current) driven by a base acceleration: the transfer function
    ``H = S_ay / S_aa`` (Welch) peaks at the resonance w0, where the
    velocity's own is ``1 / (2 zeta w0)`` with zeta from the peak's
    half-power width; the gain is ``|H(w0)| 2 zeta w0``. Scales only (a
    friction or hardening device is not linear): the search boxes are
    decades wide.
    """
    from scipy import signal

    n = drive.size
    nperseg = int(min(n, max(256, n // 8)))
    f, p_ay = signal.csd(drive, output, fs=1.0 / dt, nperseg=nperseg)
    _, p_aa = signal.welch(drive, fs=1.0 / dt, nperseg=nperseg)
    excited = p_aa > 1e-2 * np.max(p_aa)
    gain = np.where(excited, np.abs(p_ay) / np.where(excited, p_aa, 1.0), 0.0)
    peak = int(np.argmax(gain))
    half = gain >= gain[peak] / np.sqrt(2.0)
    lo = hi = peak
    while lo > 0 and half[lo - 1]:
        lo -= 1
    while hi < gain.size - 1 and half[hi + 1]:
        hi += 1
    width = max(f[hi] - f[lo], f[1] - f[0])
    zeta = float(np.clip(width / (2.0 * max(f[peak], f[1])), 0.005, 1.0))
    return float(gain[peak] * 2.0 * zeta * 2.0 * np.pi * max(f[peak], f[1]))


def channel_scales(record: Record, outputs, m: float | None) -> RecordScales:
    """The :class:`RecordScales` of a record from whichever channels it has.

    A displacement channel gives them as :func:`record_scales` does; a
    velocity channel through its running integral (detrended); a voltage or
    current alone through :func:`velocity_gain`, the velocity's scale being
    fixed by the input (Eq. 1: z'' + ... = -y''), which makes the
    displacement's an estimate: the cubic stiffness's box is widened for it.
    """
    from scipy import signal

    if "relative_displacement" in outputs:
        omega, z_max, v_rms, force, m_ref = record_scales(record, m)
        return RecordScales(m=m_ref, omega=omega, z_max=z_max, v_rms=v_rms, force=force)
    drive, base = driving_signal(record.input, record.dt, record.input_kind)
    if "relative_velocity" in outputs:
        v = record["relative_velocity"] - np.mean(record["relative_velocity"])
        widen = 1.0
    else:
        kind = next(k for k in outputs if k in ("voltage", "current"))
        y = record[kind] - np.mean(record[kind])
        gain = velocity_gain(drive, y, record.dt) * (1.0 if base else 1.0 / (m or 1.0))
        v = y / gain
        widen = 2.0  # an estimated displacement: half of it in the cubic box
    z = signal.detrend(np.cumsum(v) * record.dt)
    if m is None:
        raise ValueError(
            f"record {record.name!r} measures no displacement: give the mass (`--m`) or its "
            "search range (`--bounds m=LO:HI`)"
        )
    omega = float(np.sqrt(np.mean(v**2) / np.mean(z**2)))
    force = float(np.sqrt(np.mean(drive**2))) * (float(m) if base else 1.0)
    return RecordScales(
        m=float(m), omega=omega, z_max=float(np.max(np.abs(z))) / widen,
        v_rms=float(np.sqrt(np.mean(v**2))), force=force,
    )  # fmt: skip


def default_bounds(
    record: Record, model: str, m: float | None = None, scales: RecordScales | None = None
) -> dict:
    """Search bounds derived from the record's own scales, as each parameter declares.

    With the characteristic angular frequency ``w = rms(z')/rms(z)``, the
    largest displacement ``z_max``, the RMS velocity ``v_rms``, the RMS
    external force ``F`` (``m rms(y'')`` or ``rms(u)``) and the mass ``m``
    (given, or an equation-error least-squares estimate when free):

    ======  ==========================================  =====
    m       [0.1, 10] x m_ls (free mass only)           log
    c       2 m w x [1e-4, 2] (damping ratio)           log
    k       m w^2 x [0.1, 10]                           log
    k3      [0, 10 m w^2 / z_max^2]                     linear
    fc, fs  F x [1e-4, 1]                               log
    beta    [1, 1e10] / v_rms                           log
    sigma0  m w^2 x [1e-3, 10]                          log
    sigma1  2 m w x [1e-4, 10]                          log
    vs      v_rms x [1e-4, 10]                          log
    ======  ==========================================  =====

    The device's rows are :data:`~randvib.identification.models.DEVICE_SPECS`, the friction rows the
    law's own :func:`~randvib.models.parameters.parameter` declarations (the table
    above is what the built-in laws declare). These cover the paper's
    Table 2 for its records; override any of them with ``bounds=`` in
    :func:`~randvib.identification.identify.identify` (``--bounds NAME=LO:HI``). A parameter declared without
    default bounds must be fixed or bounded there.
    """
    specs = parameter_specs(model)
    if scales is None:
        omega, z_max, v_rms, force, m_ref = record_scales(record, m)
        scales = RecordScales(m=m_ref, omega=omega, z_max=z_max, v_rms=v_rms, force=force)
    names = MODEL_PARAMETERS[model] + (("m",) if m is None else ())
    return {
        name: tuple(float(x) for x in specs[name].search(scales))
        for name in names
        if specs[name].search is not None
    }


@dataclass(frozen=True)
class SearchSpace:
    """What SaDE searches: the free parameters, their bounds, which are log-scaled."""

    free: tuple
    box: dict
    log: list


def search_space(record, model, fixed, bounds, skip) -> SearchSpace:
    """Free parameters and their bounds (declared defaults, then the user's)."""
    candidates = MODEL_PARAMETERS[model] + ("m", "k2", "input_offset")
    free = tuple(n for n in candidates if n not in fixed)
    if not free:
        raise ValueError(
            f"every parameter of model {model!r} is fixed "
            f"({', '.join(n for n in candidates if n not in ('m', 'k2'))}, with m given and "
            "k2 without --quadratic): nothing is "
            "left to identify; leave one free (drop its `--fix`), or score fixed values on the "
            "record with `randvib validate`"
        )
    needed = max(20, SAMPLES_PER_PARAMETER * (len(free) + 3)) + skip
    if record.n < needed:
        raise ValueError(
            f"record {record.name!r} has {record.n} samples; the {model} model with "
            f"{len(free)} free parameters needs at least {needed}"
        )
    if np.ptp(record.z[skip:]) == 0:
        raise ValueError(
            f"`{OUTPUT_CHANNEL}` of record {record.name!r} is constant; J (Eq. 11) is undefined"
        )
    if np.ptp(record.input) == 0:
        # nothing drives the device: no parameter is identifiable from its response
        raise ValueError(
            f"`{record.input_kind}` of record {record.name!r} is constant "
            f"({float(record.input[0]):g} throughout): nothing drives the device, so no "
            "parameter can be identified; give the record's input column "
            "(`--input-column NAME`)"
        )
    box = default_bounds(record, model, fixed.get("m"))
    box.update(_extra_bounds(record, fixed.get("m")))
    box.update(_user_bounds(model, bounds))
    unbounded = [name for name in free if name not in box]
    if unbounded:
        raise ValueError(
            f"parameter(s) {unbounded} of model {model!r} declare no default search bounds; "
            "fix them (`--fix NAME=VALUE`) or bound them (`--bounds NAME=LO:HI`)"
        )
    specs = parameter_specs(model)
    for name in free:
        lo, hi = box[name]
        positive = name in specs and specs[name].positive  # k2, offsets: any sign
        if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi and (lo > 0 or not positive)):
            raise ValueError(
                f"the search bounds of `{name}` are ({lo!r}, {hi!r}), which model {model!r} "
                f"cannot search: the record {record.name!r} (its sample rate and amplitudes) "
                f"is outside the range of its default bounds; give `--bounds {name}=LO:HI`"
            )
    return SearchSpace(
        free=free,
        box={name: box[name] for name in free},
        log=[name in specs and specs[name].log and box[name][0] > 0 for name in free],
    )


def _extra_bounds(record, m) -> dict:
    """Search boxes of k2 and the input offset from the record's scales.

    k2 within +-2 m w^2 / z_max (its force at z_max at most twice the
    linear spring's); the input offset within the measured input's mean
    +- half its standard deviation (the true input of a shaker test has no
    mean, so the measured mean is the offset up to the record's finite
    length).
    """
    omega, z_max, _, _, m_ref = record_scales(record, m)
    drive, _ = driving_signal(record.input, record.dt, record.input_kind)
    k2 = 2 * m_ref * omega**2 / z_max
    mean, half = float(np.mean(drive)), 0.5 * float(np.std(drive))
    return {"k2": (-k2, k2), "input_offset": (mean - half, mean + half)}


def _user_bounds(model, bounds) -> dict:
    allowed = MODEL_PARAMETERS[model] + ("m", "k2", "input_offset")
    out = {}
    for name, pair in (bounds or {}).items():
        if name not in allowed:
            raise ValueError(
                f"`--bounds {name}`: unknown parameter for model {model!r}; allowed: "
                f"{', '.join(allowed)}"
            )
        lo, hi = (check_parameter(model, name, x, f"--bounds {name}") for x in pair)
        if lo > hi:
            raise ValueError(f"`--bounds {name}`: lower {lo!r} > upper {hi!r}")
        if lo == hi:
            raise ValueError(
                f"`--bounds {name}={lo:g}:{hi:g}`: a search range needs lower < upper; a value "
                f"known exactly is fixed: `--fix {name}={lo:g}`"
            )
        out[name] = (lo, hi)
    return out


#: At most this many corners of the search box are probed before a search.
PROBE_CORNERS = 64


def probe_points(space: SearchSpace, corners: int = PROBE_CORNERS) -> np.ndarray:
    """The box's corners (a seeded sample of ``corners`` of them when there are more)
    and its centre (arithmetic, and geometric on log-scaled axes), one per row."""
    lo = np.array([space.box[n][0] for n in space.free], dtype=float)
    hi = np.array([space.box[n][1] for n in space.free], dtype=float)
    d = lo.size
    if 2**d <= corners:
        bits = (np.arange(2**d)[:, None] >> np.arange(d)) & 1
    else:
        bits = np.random.default_rng(0).integers(0, 2, size=(corners, d))
    centre = lo / 2 + hi / 2  # (lo + hi) / 2 overflows at 1e308
    geometric = np.where(space.log, np.sqrt(np.abs(lo)) * np.sqrt(np.abs(hi)), centre)
    return np.vstack([np.where(bits == 1, hi, lo), centre, geometric])


def equation_error_mass(record: Record, outputs, coupling: str | None, r_load) -> float | None:
    """A rough mass (kg) from a base-excited record with a motion and a circuit channel.

    Equation error, as the force-input scale does: the circuit's own equation
    (a coil's ``R_L i = alpha z' - L i' - R_C i``, a piezo's ``V / R_L =
    theta z' - C_p V'``) regressed on the measured channels gives the
    coupling's gain g (alpha or theta, force ``g x``); then Eq. 1 divided by
    m, ``-(y'' + z'') = (c/m) z' + (k/m) z + (k3/m) z^3 + (g/m) x + const``,
    regressed gives g/m and so m. The circuit's force is small beside the
    inertia and nearly collinear with z' and z in a narrow band, so this is
    a scale (within a factor of a few), which only centres the mass's search
    box; None when the channels do not allow it.
    """
    from scipy import signal

    if coupling is None or record.input_kind == "force":
        return None
    dt = record.dt
    if "relative_velocity" in outputs:
        v = record["relative_velocity"] - np.mean(record["relative_velocity"])
        z = signal.detrend(np.cumsum(v) * dt)
    elif "relative_displacement" in outputs:
        z = record.z - np.mean(record.z)
        v = np.gradient(z, dt)
    else:
        return None
    if "voltage" in outputs:
        y = record["voltage"] - np.mean(record["voltage"])
        state = y if coupling == "piezo" else y / r_load
    elif "current" in outputs:
        y = record["current"] - np.mean(record["current"])
        state = y * r_load if coupling == "piezo" else y
    else:
        return None
    if coupling == "piezo":  # V / R_L = theta z' - C_p V'
        columns = [v, -np.gradient(state, dt)]
        target = state / r_load
    else:  # R_L i = alpha z' - L i' - R_C i (no L column for a resistive coil)
        columns = [v, -state] + ([-np.gradient(state, dt)] if coupling == "inductive" else [])
        target = r_load * state
    gain = np.linalg.lstsq(np.column_stack(columns), target, rcond=None)[0][0]
    drive, _ = driving_signal(record.input, dt, record.input_kind)
    a = np.column_stack([v, z, z**3, state, np.ones_like(v)])
    per_mass = np.linalg.lstsq(a, -drive - np.gradient(v, dt), rcond=None)[0][3]
    m = float(gain / per_mass) if per_mass != 0 else float("nan")
    return m if np.isfinite(m) and m > 0 else None
