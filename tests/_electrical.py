"""An independent generator of shaker records of harvesters with their circuits.

Shared by ``tests/test_electrical_identification.py``, ``tests/test_electrical_cli.py``
and the coverage campaign ``tests/calibration/electrical_coverage.py``. None of
randvib's simulators is used: the base acceleration is a band-limited Gaussian
signal synthesised by FFT (periodic, so that its band-limited interpolant,
``scipy.signal.resample``, is exact at the samples), and Eq. 1 with the coil's
or the piezo element's circuit is integrated by plain RK4 on that interpolant at
``up`` times the sample rate, from rest, as ``tests/test_hold_choice.py``'s
``rk4_displacement`` does for the mechanics alone:

* coil: ``m z'' + c z' + k z + k3 z^3 + Fc sgn z' + alpha i = -m y''``,
  ``L i' + (R_L + R_C) i = alpha z'``; load voltage ``R_L i``;
* piezo: ``m z'' + c z' + k z + k3 z^3 + theta V = -m y''``,
  ``C_p V' + V / R_L = theta z'``; load voltage ``V``.

Coulomb friction is ``Fc sign(z')`` at the fine step (it chatters about z' = 0
while the magnet sticks, by about ``h Fc / m`` in velocity: an O(h) error of
the generator, 1.6e-5 m/s at 16 kHz for the paper's device). Sensor noise is
white and Gaussian, independent per channel, from its own seeded stream.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from randvib.models.record import Record

#: A coil harvester with Coulomb friction and inductance (the paper's mechanics,
#: Table 2 Coulomb with m = 0.0226 kg, and a coil coupled strongly enough that
#: its damping is comparable with the mechanical one).
COIL = dict(m=0.0226, c=0.049, k=57.4, k3=70742.0, fc=0.0058, alpha=1.0, r_coil=2.0,
            inductance=0.02)  # fmt: skip
#: A piezo harvester with a Duffing spring (resonance 16 Hz, R_L C_p = 10 ms).
PIEZO = dict(m=0.01, c=0.01, k=100.0, k3=2e6, theta=5e-4, capacitance=1e-7)
#: The band of the shaker (Hz), as the paper's tests.
BAND = (4.0, 20.0)


def base_acceleration(duration, fs, rms, seed, band=BAND) -> np.ndarray:
    """Band-limited Gaussian base acceleration (m/s^2) with the RMS ``rms``, by FFT."""
    n = int(round(duration * fs))
    rng = np.random.default_rng([seed, 34])
    spectrum = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, 1.0 / fs)
    spectrum[(f < band[0]) | (f > band[1])] = 0.0
    a = np.fft.irfft(spectrum, n)
    return a * rms / np.std(a)


def _rk4(rate, fine, h, up) -> np.ndarray:
    """RK4 of ``(z, v, x)' = rate(z, v, x, y'')`` from rest at step h on the fine input;
    the state at every up-th step (plain floats: the loop is the generator's cost)."""
    n = (len(fine) - 1) // up + 1
    out = np.empty((n, 3))
    z = v = x = 0.0
    for i in range(n * up):
        if i % up == 0:
            out[i // up] = z, v, x
        if i + 1 == len(fine):
            break
        y0, y1 = fine[i], fine[i + 1]
        ym = 0.5 * (y0 + y1)
        a1, b1, c1 = rate(z, v, x, y0)
        a2, b2, c2 = rate(z + h / 2 * a1, v + h / 2 * b1, x + h / 2 * c1, ym)
        a3, b3, c3 = rate(z + h / 2 * a2, v + h / 2 * b2, x + h / 2 * c2, ym)
        a4, b4, c4 = rate(z + h * a3, v + h * b3, x + h * c3, y1)
        z += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        v += h / 6 * (b1 + 2 * b2 + 2 * b3 + b4)
        x += h / 6 * (c1 + 2 * c2 + 2 * c3 + c4)
    return out


def _sign(v) -> float:
    return 1.0 if v > 0 else -1.0 if v < 0 else 0.0


def fine_input(a, up, interpolation) -> list:
    """The input at ``up`` times the rate: band-limited (``resample``) or linear between samples."""
    if interpolation == "linear":
        n = len(a)
        return np.interp(np.arange((n - 1) * up + 1) / up, np.arange(n), a).tolist()
    return signal.resample(a, len(a) * up).tolist()


def coil_states(truth, a, fs, r_load, up=16, interpolation="bandlimited") -> np.ndarray:
    """(z, z', i) at the samples of a coil harvester driven by ``a`` (from rest)."""
    m, c, k, k3, fc = (float(truth[n]) for n in ("m", "c", "k", "k3", "fc"))
    alpha, ind = float(truth["alpha"]), float(truth["inductance"])
    resistance = float(r_load + truth["r_coil"])

    def rate(z, v, i, acc):
        force = c * v + k * z + k3 * z * z * z + fc * _sign(v) + alpha * i
        return v, -force / m - acc, (alpha * v - resistance * i) / ind

    return _rk4(rate, fine_input(a, up, interpolation), 1.0 / (fs * up), up)


def piezo_states(truth, a, fs, r_load, up=16, interpolation="bandlimited") -> np.ndarray:
    """(z, z', V) at the samples of a piezo harvester driven by ``a`` (from rest)."""
    m, c, k, k3 = (float(truth[n]) for n in ("m", "c", "k", "k3"))
    theta, cp, r_load = float(truth["theta"]), float(truth["capacitance"]), float(r_load)

    def rate(z, v, volt, acc):
        force = c * v + k * z + k3 * z * z * z + theta * volt
        return v, -force / m - acc, (theta * v - volt / r_load) / cp

    return _rk4(rate, fine_input(a, up, interpolation), 1.0 / (fs * up), up)


def record(kind, truth, *, r_load, duration=2.0, fs=1000.0, rms=2.0, seed=0, noise=None,
           outputs=("voltage",), up=16, interpolation="linear", name=None) -> Record:  # fmt: skip
    """A shaker record of the ``kind`` (``coil`` or ``piezo``) harvester at load ``r_load``.

    ``noise``: ``{kind: RMS}`` of each channel's sensor noise as a share of the
    channel's own RMS (e.g. ``{"voltage": 0.01}``: 1 %). ``interpolation``:
    the input between samples (``linear``, what identify's default chooses
    for a 4-20 Hz band at 1 kHz, or ``bandlimited``): how a real shaker's
    signal runs between samples is not the question these records ask.
    """
    a = base_acceleration(duration, fs, rms, seed)
    generate = coil_states if kind == "coil" else piezo_states
    states = generate(truth, a, fs, r_load, up, interpolation)
    z, v, x = states.T
    voltage = r_load * x if kind == "coil" else x
    current = x if kind == "coil" else x / r_load
    clean = {"relative_displacement": z, "relative_velocity": v, "voltage": voltage,
             "current": current}  # fmt: skip
    rng = np.random.default_rng([seed, 35])
    channels = {}
    for out in outputs:
        share = (noise or {}).get(out, 0.0)
        channels[out] = clean[out] + share * np.std(clean[out]) * rng.standard_normal(z.size)
    return Record(1.0 / fs, base_acceleration=a, name=name or f"{kind}-{r_load:g}ohm",
                  **channels)  # fmt: skip
