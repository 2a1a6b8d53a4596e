"""Eq. 1 behind a full-wave diode bridge, integrated on a recorded input.

The record simulation of :mod:`randvib.identification.record_integrator`
carries a linear circuit state (a coil's current with its inductance, a piezo
element's voltage); a diode bridge switches, so its states are stepped here
by the Monte Carlo kernel's own bridge step
(:func:`randvib.montecarlo.rectified_kernel.rectified_white_step`, the
equations of :mod:`randvib.models.rectifier` and docs/conventions.md, "Full-wave
bridge"), not by a second implementation:

* the transducer: a coil's current ``i = sgn(e) max(0, |e| - V_out - 2 V_d) / R_C``
  (``e = alpha z'``; with an inductance L the current is a state,
  ``L i' = e - R_C i - sgn(i) (V_out + 2 V_d)``, held at 0 by the diodes), or
  a piezo element's voltage ``C_p V_p' = theta z' - i_b``, clamped at
  ``|V_p| <= V_out + 2 V_d``;
* the output: a battery ``V_out = V_b``, or a storage capacitor with its load,
  ``C V_C' = |i| - V_C / R_L`` and ``V_out = V_C``.

The recorded input enters as the exact integral of its reconstruction
(:mod:`randvib.identification.input_reconstruction`) over each sub-step, the
velocity increment that the Monte Carlo kernel's noise is (``-int y'' dt`` for a
base input, ``int u dt / m`` for a force), and Heun's weights (1/2, 1/2) step
the rest: second order where the bridge does not switch, about first order
across a switch (the dead zone's current is only Lipschitz; the piezo's clamp
a projection), as tests/test_record_bridge.py measures. Friction is the Monte
Carlo kernel's law as it steps it (``Fc sgn z'`` chatters about z' = 0 by about
``h Fc / m``; no event location as in the record integrator's Coulomb path).

What a sensor behind the bridge reads (:func:`bridge_output`): ``voltage`` the
DC output voltage V_C (a battery's is its constant V_b: refused), ``current``
the load current V_C / R_L, or a battery's charging current |i| (a coil's; a
piezo element's bridge passes its charge in the clamp's jumps, no current at a
sample: refused).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from randvib.identification.input_reconstruction import HOLDS, reconstruct_input
from randvib.identification.record_integrator import _INPUT_OFFSET, _K2, _segment
from randvib.models.friction import KERNEL_NONE, N_KERNEL_PARAMETERS, kernel_callback
from randvib.models.rectifier import CAPACITOR, PIEZO
from randvib.montecarlo.rectified_kernel import (
    _bridge_current,
    bridge_constants,
    rectified_white_step,
)

#: Heun's stage weights, the Monte Carlo kernel's ``heun`` scheme.
HEUN_WEIGHTS = (0.5, 0.5)
#: Columns of the stored states: z (m), z' (m/s), the transducer's state (a coil's
#: current i, A, signed; a piezo element's voltage V_p, V), the DC output voltage
#: V_out (V) and the bridge's output current |i| (A; NaN for a piezo element).
BRIDGE_COLUMNS = ("z", "v", "x", "v_out", "i_out")
N_BRIDGE_COLUMNS = len(BRIDGE_COLUMNS)


@numba.njit(cache=True, inline="always")
def _bridge_store(out, i, z, v, s1, s2, rect):
    # the coil's algebraic current from the state; the state itself otherwise
    rkind, output = rect[0], rect[1]
    x = s1
    i_out = abs(s1)
    if rkind == 1:
        x = _bridge_current(v, s2, rect)[0]
        i_out = abs(x)
    elif rkind == 2:
        i_out = math.nan
    out[i, 0] = z
    out[i, 1] = v
    out[i, 2] = x
    out[i, 3] = rect[5] if output == 0 else s2
    out[i, 4] = i_out


# Compiled on its own and called from the parallel loop, not inlined into it: numba's
# parallel-loop passes over the whole record loop written out took two thirds of
# this kernel's compile time (37 against 12.5 CPU-s on a cold cache, measured);
# a call per device costs nothing beside its record.
@numba.njit(cache=True)
def _bridge_one(par, rp, codes, state0, friction, drive, out, zlim):
    """One device's record: True when it stayed finite and within |z| < zlim.

    ``par``: a row of :func:`~randvib.identification.record_integrator.parameter_matrix`
    (m, c, k, k3, the friction law's p, k2 = 0, the input offset); ``rp``
    the bridge's ``p`` (:meth:`randvib.models.rectifier.Rectified.kernel_parameters`);
    ``codes`` (transducer, output); ``state0`` (z0, v0, theta0, s1, s2);
    ``friction`` (kernel code, callback); ``drive`` (u, dt, nsub, curved, base_input).
    """
    kind, fn = friction
    u, dt, nsub, curved, base_input = drive
    m = par[0]
    drift = (1.0 / m, par[1], par[2], par[3])
    p = par[4 : 4 + N_KERNEL_PARAMETERS]
    # the velocity increment per unit of input and time: -y'' of a base input, u / m of a force
    gain = -1.0 if base_input else 1.0 / m
    u_off = par[_INPUT_OFFSET]
    h = dt / nsub
    rect = bridge_constants(codes[0], codes[1], rp, h)
    z, v, th, s1, s2 = state0[0], state0[1], state0[2], state0[3], state0[4]
    _bridge_store(out, 0, z, v, s1, s2, rect)
    for i in range(out.shape[0] - 1):
        for j in range(nsub):
            a = j * h
            b = dt if j == nsub - 1 else a + h
            seg = _segment(u, i, j, nsub, curved, a, b)
            hh = b - a
            # the exact integral of the sub-step's quadratic, less the input's offset
            integral = hh * (seg[1] - u_off + hh * (0.5 * seg[2] + hh * seg[3] / 3.0))
            z, v, th, s1, s2, _, _, _, _ = rectified_white_step(
                z, v, th, s1, s2, hh, gain * integral, HEUN_WEIGHTS, drift, kind, p, fn, rect
            )
        if not (abs(z) < zlim and abs(v) < math.inf and abs(s1) < math.inf):
            for r in range(i + 1, out.shape[0]):
                for q in range(out.shape[1]):
                    out[r, q] = math.nan
            return False
        _bridge_store(out, i + 1, z, v, s1, s2, rect)
    return True


@numba.njit(cache=True, parallel=True)
def _bridge_batch(params, rparams, codes, state0, friction, drive, out, zlim):
    # one compiled signature for every bridge, law and input: the codes are data
    n_pop = params.shape[0]
    ok = np.empty(n_pop, dtype=np.bool_)
    for i in numba.prange(n_pop):
        ok[i] = _bridge_one(params[i], rparams[i], codes, state0[i], friction, drive, out[i], zlim)
    return ok


def run_bridge(
    matrix,
    bridge_parameters,
    codes,
    friction,
    drive,
    base_input,
    dt,
    *,
    substeps=4,
    hold="linear",
    z0=0.0,
    v0=0.0,
    theta0=0.0,
    s1=0.0,
    v_c0=0.0,
    response_limit=np.inf,
    fine=None,
) -> np.ndarray:
    """The batched record simulation behind a bridge, on validated arguments.

    Parameters
    ----------
    matrix : ndarray, shape (n_pop, MATRIX_COLUMNS)
        Rows of :func:`~randvib.identification.record_integrator.parameter_matrix`
        (the circuit's columns unused; k2 must be 0).
    bridge_parameters : ndarray, shape (9,) or (n_pop, 9)
        The bridge's ``p`` (:meth:`randvib.models.rectifier.Rectified.kernel_parameters`),
        shared or one row per device (a free alpha, say).
    codes : (int, int)
        The transducer's and the output's kernel codes (same method).
    friction : FrictionModel subclass or None
    drive, base_input, dt, substeps, hold, fine
        As :func:`~randvib.identification.record_integrator.run_kernel`.
    z0, v0, theta0, s1, v_c0 : float or ndarray
        Initial displacement (m), velocity (m/s), friction state, the
        transducer's state (a coil's current with inductance, A; a piezo
        element's voltage, V) and the storage capacitor's voltage (V).
    response_limit : float
        |z| (m) beyond which a device counts as diverged (NaN from there on).

    Returns
    -------
    ndarray, shape (n_pop, n, 5)
        :data:`BRIDGE_COLUMNS` at the samples; NaN after a device diverged.
    """
    if hold not in HOLDS:
        raise ValueError(f"`hold` must be one of {', '.join(HOLDS)}; got {hold!r}")
    n_pop = matrix.shape[0]
    if np.any(matrix[:, _K2] != 0.0):
        raise ValueError(
            f"`k2` = {matrix[matrix[:, _K2] != 0.0, _K2][0]!r} N/m^2: the record simulation "
            "behind a diode bridge has no quadratic stiffness (the Monte Carlo drift it "
            "shares has none); give k2 = 0"
        )
    state0 = np.empty((n_pop, 5))
    for j, value in enumerate((z0, v0, theta0, s1, v_c0)):
        state0[:, j] = np.broadcast_to(np.asarray(value, dtype=float), (n_pop,))
    rparams = np.ascontiguousarray(
        np.broadcast_to(np.asarray(bridge_parameters, dtype=float), (n_pop, 9))
    )
    if fine is not None and hold != "zero":
        samples = fine
    else:
        samples = drive if hold == "zero" else reconstruct_input(drive, dt, substeps, hold)
    samples = np.require(samples, float, ["C", "W"])
    curved = hold != "zero"
    n = (samples.shape[0] - 1) // (2 * substeps) + 1 if curved else samples.shape[0]
    out = np.empty((n_pop, n, N_BRIDGE_COLUMNS))
    kernel_friction = (KERNEL_NONE if friction is None else friction.kernel_code,
                       kernel_callback(friction))  # fmt: skip
    _bridge_batch(
        np.ascontiguousarray(matrix, dtype=float),
        rparams,
        (int(codes[0]), int(codes[1])),
        state0,
        kernel_friction,
        (samples, float(dt), int(substeps), curved, bool(base_input)),
        out,
        float(response_limit),
    )
    return out


def bridge_output(kind: str, bridge, states: np.ndarray) -> np.ndarray:
    """The channel ``kind`` behind ``bridge`` from :func:`run_bridge`'s states, (n_pop, n).

    ``voltage``: the storage capacitor's V_C (V); ``current``: the load
    current V_C / R_L, or a coil's charging current |i| into a battery (A);
    ``relative_displacement`` z and ``relative_velocity`` z'. A battery's
    voltage (the constant V_b) and a piezo element's current into a battery
    are refused.
    """
    code, output, _ = bridge.kernel_parameters()
    if kind == "voltage" and output != CAPACITOR:
        raise ValueError(
            f"the {bridge.name}'s battery holds its output at V_b = {bridge.battery:g} V: a "
            "`voltage` channel is constant and fixes nothing; record its `current`"
        )
    if kind == "current" and output != CAPACITOR and code == PIEZO:
        raise ValueError(
            f"the {bridge.name} charges its battery in the clamp's jumps, no current at a "
            "sample: record the `relative_velocity` or use a storage capacitor"
        )
    return dc_channel(kind, output != CAPACITOR, bridge.r_load, states)


def dc_channel(kind: str, battery: bool, r_load, states: np.ndarray) -> np.ndarray:
    """The channel ``kind`` from the states (no refusals: :func:`bridge_output` makes them).

    z, z', the DC output voltage, and the load current V_C / R_L (storage
    capacitor) or the bridge's output current |i| (battery).
    """
    if kind == "relative_displacement":
        return states[..., 0]
    if kind == "relative_velocity":
        return states[..., 1]
    if kind == "voltage":
        return states[..., 3]
    if kind == "current":
        return states[..., 4] if battery else states[..., 3] / r_load
    raise ValueError(f"a diode bridge's record has no {kind!r} output")
