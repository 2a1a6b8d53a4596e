"""The recorded input as the integrator reads it: derivative, filter, reconstruction.

The input is sampled on a uniform grid ``t_i = i dt``. The kernel
(:mod:`randvib.identification.record_integrator`) is driven by a base
acceleration (m/s^2) or a force (N) (:func:`driving_signal`); between samples
the signal is reconstructed (:func:`reconstruct_input`: linear, cubic spline
or band-limited (sinc) interpolation; a zero-order hold). By default the
reconstruction is chosen from the record (:func:`choose_hold`): linear where
it agrees with the band-limited interpolant to :data:`HOLD_TOLERANCE`, the
band-limited one where the input has content close to the Nyquist frequency
that straight lines between samples would misrepresent.

A recorded base displacement is turned into base acceleration by the
fourth-order central difference
``y''_i = (-y_{i-2} + 16 y_{i-1} - 30 y_i + 16 y_{i+1} - y_{i+2}) / (12 dt^2)``
(relative error (omega dt)^4 / 90, 2e-7 at 20 Hz and 1 kHz), with the
second-order stencil next to the ends (:func:`second_derivative`).
Differentiation amplifies sensor noise at high frequency; ``lowpass``
applies a zero-phase Butterworth filter to the derived acceleration
(:func:`lowpass_filter`).
"""

from __future__ import annotations

import numpy as np

from randvib._resources import check_memory
from randvib._validation import check_positive
from randvib.models.record import INPUT_KINDS

#: Reconstructions of the input between samples (see :func:`reconstruct_input`).
HOLDS = ("linear", "zero", "cubic", "bandlimited")
#: The reconstruction chosen from the record's input (:func:`choose_hold`).
AUTO_HOLD = "auto"
#: Largest relative RMS difference, at the mid-points between samples, between
#: a reconstruction and the band-limited interpolant that is accepted without a
#: warning (and below which ``auto`` keeps the linear one).
HOLD_TOLERANCE = 0.01
#: Fraction of the input's power above :data:`NEAR_NYQUIST` times the Nyquist
#: frequency beyond which the input is taken as not band-limited: an
#: anti-aliased sensor leaves orders of magnitude less there.
NYQUIST_POWER_LIMIT = 1e-3
#: Where the band next to the Nyquist frequency starts, as its fraction.
NEAR_NYQUIST = 0.9


def second_derivative(y, dt):
    """Acceleration from displacement samples by central differences (m/s^2).

    Fourth-order five-point stencil inside, second-order three-point stencil
    at the second and second-to-last samples, the end values copied from
    their neighbours.
    """
    y = np.asarray(y, dtype=float)
    n = y.shape[-1]
    if n < 5:
        raise ValueError(
            f"a base-displacement record needs at least 5 samples to be differentiated, got {n}"
        )
    a = np.empty_like(y)
    a[..., 2:-2] = (
        -y[..., :-4] + 16 * y[..., 1:-3] - 30 * y[..., 2:-2] + 16 * y[..., 3:-1] - y[..., 4:]
    ) / (12 * dt**2)
    a[..., 1] = (y[..., 0] - 2 * y[..., 1] + y[..., 2]) / dt**2
    a[..., -2] = (y[..., -3] - 2 * y[..., -2] + y[..., -1]) / dt**2
    a[..., 0] = a[..., 1]
    a[..., -1] = a[..., -2]
    return a


def lowpass_filter(x, dt, cutoff):
    """Zero-phase 4th-order Butterworth low-pass (``cutoff`` in Hz)."""
    from scipy import signal

    cutoff = float(check_positive("lowpass", cutoff, "Hz"))
    nyquist = 0.5 / dt
    if cutoff >= nyquist:
        raise ValueError(
            f"`lowpass` must be below the Nyquist frequency {nyquist:.6g} Hz, got {cutoff}"
        )
    lowest = 1.0 / (max(len(x), 1) * dt)  # one cycle over the record
    if cutoff < lowest:
        raise ValueError(
            f"`lowpass` must be at least {lowest:.6g} Hz (one cycle over the record's "
            f"{len(x) * dt:.6g} s), got {cutoff!r}"
        )
    sos = signal.butter(4, cutoff / nyquist, output="sos")
    return signal.sosfiltfilt(sos, x)


def driving_signal(values, dt, input_kind, lowpass=None):
    """The samples the kernel is driven by: base acceleration (m/s^2) or force (N).

    Parameters
    ----------
    values : array_like
        Recorded input samples (units of ``input_kind``).
    dt : float
        Sample interval (s).
    input_kind : {'base_displacement', 'base_acceleration', 'force'}
        What ``values`` are.
    lowpass : float, optional
        Cut-off (Hz) of a zero-phase low-pass applied to the driving signal.

    Returns
    -------
    samples : ndarray
    base_input : bool
        True for base excitation (``e = -m y''``), False for a force.
    """
    if input_kind not in INPUT_KINDS:
        raise ValueError(
            f"`input_kind` must be one of {', '.join(INPUT_KINDS)}; got {input_kind!r}"
        )
    x = np.asarray(values, dtype=float)
    if input_kind == "base_displacement":
        x = second_derivative(x, dt)
    if lowpass is not None:
        x = lowpass_filter(x, dt, lowpass)
    return np.ascontiguousarray(x), input_kind != "force"


def reconstruct_input(samples, dt, substeps, hold="linear"):
    """The input between samples, at every half sub-step (what the integrator reads).

    Parameters
    ----------
    samples : ndarray, shape (n,)
        The driving signal at ``t_i = i dt``.
    dt : float
        Sample interval (s).
    substeps : int
        Integration steps per sample interval.
    hold : {'linear', 'cubic', 'bandlimited'}
        ``linear``: straight lines between samples (first-order hold).
        ``cubic``: the not-a-knot cubic spline through the samples (error
        about (omega dt)^4 / 384 of the amplitude at angular frequency
        omega). ``bandlimited``: the band-limited (sinc) interpolant,
        computed by FFT zero-padding of the record's even (mirrored)
        extension, which is continuous, so the ends do not ring as a
        periodic extension would; exact for a signal with no power above
        the Nyquist frequency that the mirror keeps smooth, the right
        choice when the record is sampled not far above its bandwidth.

    Returns
    -------
    ndarray, shape ((n - 1) * 2 substeps + 1,)
        Values at ``t = q dt / (2 substeps)``.
    """
    x = np.asarray(samples, dtype=float)
    n = x.shape[0]
    up = 2 * int(substeps)
    n_fine = (n - 1) * up + 1
    # the fine times, the values and the interpolation's temporaries (a spline's or an
    # FFT's: about four arrays of the fine length), refused before any is allocated
    check_memory(
        f"the input at {int(substeps)} sub-steps per sample ({n_fine:.3g} values)",
        8.0 * 4 * n_fine,
        "lower `substeps`",
    )
    fine_t = np.arange((n - 1) * up + 1) / up  # in samples
    if hold == "linear":
        return np.ascontiguousarray(np.interp(fine_t, np.arange(n), x))
    if hold == "cubic":
        from scipy.interpolate import CubicSpline

        return np.ascontiguousarray(CubicSpline(np.arange(n), x)(fine_t))
    if hold == "bandlimited":
        return np.ascontiguousarray(_sinc_interpolation(x, up)[: fine_t.size])
    raise ValueError(
        f"`hold` must be one of {', '.join(h for h in HOLDS if h != 'zero')}; got {hold!r}"
    )


def _sinc_interpolation(x, up):
    """Band-limited interpolation of x by a factor ``up`` via its even periodic extension."""
    n = x.shape[0]
    ext = np.concatenate([x, x[-2:0:-1]])  # period 2n - 2, continuous
    m = ext.shape[0]
    spectrum = np.fft.rfft(ext)
    if m % 2 == 0:
        spectrum[-1] *= 0.5  # split the Nyquist bin between +-fs/2
    padded = np.zeros(m * up // 2 + 1, dtype=complex)
    padded[: spectrum.shape[0]] = spectrum
    return np.fft.irfft(padded, m * up)[: (n - 1) * up + 1] * up


def midpoint_error(samples, hold: str) -> float:
    """Relative RMS difference between ``hold`` and the band-limited interpolant.

    Both reconstructions are evaluated half-way between samples, where they
    differ most; the difference is divided by the standard deviation of the
    samples. A measure of how far ``hold`` misrepresents a band-limited input.
    """
    x = np.asarray(samples, dtype=float)
    scale = float(np.std(x))
    if x.shape[0] < 3 or scale == 0.0:
        return 0.0
    exact = _sinc_interpolation(x, 2)[1::2]
    if hold == "bandlimited":
        return 0.0
    if hold == "zero":
        mid = x[:-1]
    else:
        mid = reconstruct_input(x, 1.0, 1, hold)[1::2]
    return float(np.sqrt(np.mean((mid - exact) ** 2)) / scale)


def near_nyquist_fraction(samples) -> float:
    """Fraction of the (mean-removed) input's power above :data:`NEAR_NYQUIST` x Nyquist.

    Welch's estimate (Hann window, segments of up to 1024 samples), whose
    leakage from the band's content is far below :data:`NYQUIST_POWER_LIMIT`.
    """
    from scipy import signal

    x = np.asarray(samples, dtype=float)
    if x.shape[0] < 16 or np.std(x) == 0.0:
        return 0.0
    f, p = signal.welch(x - np.mean(x), fs=1.0, nperseg=min(x.shape[0], 1024))
    total = float(np.sum(p))
    return float(np.sum(p[f >= 0.5 * NEAR_NYQUIST]) / total) if total > 0 else 0.0


def choose_hold(samples, dt: float, hold: str = AUTO_HOLD) -> tuple[str, str]:
    """The reconstruction of a record's input: ``hold``, or chosen for ``auto``.

    ``auto`` keeps the linear reconstruction where it differs from the
    band-limited interpolant by at most :data:`HOLD_TOLERANCE` (relative RMS
    at the mid-points, :func:`midpoint_error`), and chooses the band-limited
    one where it differs more (content up to a good part of the Nyquist
    frequency, which straight lines attenuate and alias). An input with more
    than :data:`NYQUIST_POWER_LIMIT` of its power next to the Nyquist frequency
    (:func:`near_nyquist_fraction`) is not band-limited: no interpolation
    represents it exactly, ``auto`` chooses as above (an input filtered too
    gently is closer to its band-limited interpolant than to straight lines)
    and a warning naming ``--hold`` says so. A
    reconstruction given explicitly is kept, with a warning when it differs
    from the band-limited interpolant of a band-limited input by more than
    the tolerance.

    Parameters
    ----------
    samples : array_like
        The driving signal (m/s^2 or N) at ``t_i = i dt``.
    dt : float
        Sample interval (s).
    hold : {'auto', 'linear', 'zero', 'cubic', 'bandlimited'}

    Returns
    -------
    hold : str
        One of :data:`HOLDS`.
    why : str
        One sentence on the choice (for a result's notes; empty for an
        explicit ``hold`` that needs no warning).
    """
    import warnings

    if hold != AUTO_HOLD and hold not in HOLDS:
        raise ValueError(f"`hold` must be one of {', '.join((AUTO_HOLD,) + HOLDS)}; got {hold!r}")
    x = np.asarray(samples, dtype=float)
    nyquist = 0.5 / dt
    near = near_nyquist_fraction(x)
    if near > NYQUIST_POWER_LIMIT:
        if hold in (AUTO_HOLD, "bandlimited", "cubic"):
            # auto: still the band-limited one if lines would differ from it (an
            # input filtered too gently is closer to band-limited than to lines)
            chosen = hold
            if hold == AUTO_HOLD:
                lines = midpoint_error(x, "linear") <= HOLD_TOLERANCE
                chosen = "linear" if lines else "bandlimited"
            why = (
                f"the input has {100 * near:.2g} % of its power above "
                f"{NEAR_NYQUIST * nyquist:.4g} Hz (Nyquist {nyquist:.4g} Hz): it is not "
                "band-limited, so no reconstruction between samples is exact; "
                f"using {chosen!r}; if the input was held constant between samples choose "
                "--hold zero (hold='zero'), else sample it faster or anti-aliased"
            )
            warnings.warn(why, UserWarning, stacklevel=3)
            return chosen, why
        return hold, ""
    # only the one reconstruction's error that decides (each costs a band-limited
    # interpolation of the whole input)
    if hold == AUTO_HOLD:
        linear = midpoint_error(x, "linear")
        if linear <= HOLD_TOLERANCE:
            return "linear", ""
        return "bandlimited", (
            f"input reconstructed band-limited (hold='bandlimited'): straight lines between "
            f"samples would misrepresent its content by {100 * linear:.2g} % RMS "
            "(chosen from the record; --hold sets it)"
        )
    error = 0.0 if hold == "bandlimited" else midpoint_error(x, hold)
    if error > HOLD_TOLERANCE:
        why = (
            f"--hold {hold} (hold={hold!r}) misrepresents this input by "
            f"{100 * error:.2g} % RMS between samples (it has content close to the "
            f"Nyquist frequency {nyquist:.4g} Hz), which biases the fit; use --hold "
            "bandlimited or leave --hold out (auto)"
        )
        warnings.warn(why, UserWarning, stacklevel=3)
        return hold, why
    return hold, ""
