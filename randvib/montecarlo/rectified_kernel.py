"""The compiled steps of a full-wave diode bridge (:class:`randvib.montecarlo.kernel.Rectifier`).

:func:`rectified_white_step` (white or given input) and :func:`rectified_step`
(the device with a shaping filter's states) advance the device, its friction
state and the bridge's states by one step of the additive-noise scheme of
:func:`randvib.montecarlo.kernel.scheme_step`, and return the step's energy
into the output, the coil's resistance and the diodes. The bridge's side of
both is shared: :func:`_bridge_rates` (force and state rates at a stage),
:func:`_bridge_predictor` (the predictor's bridge states) and
:func:`_bridge_update` (the step's bridge states and energy accounting).
The loop :func:`randvib.montecarlo.kernel.full_loop` compiles them, not the
lean white-noise one (:func:`~randvib.montecarlo.kernel.lean_loop`); the record
simulation of a bridge (:mod:`randvib.identification.record_bridge`) steps
:func:`rectified_white_step` on a recorded input. Equations:
docs/conventions.md, "Full-wave bridge".
"""

from __future__ import annotations

import math

import numba
import numpy as np

from randvib.montecarlo.drift import _acceleration


@numba.njit(cache=True, inline="always")
def bridge_constants(kind, output, rp, dt):
    """The bridge's tuple ``rect`` that the steps read, from :class:`kernel.Rectifier
    <randvib.montecarlo.kernel.Rectifier>`'s ``kind``, ``output`` and ``p`` at the step dt.

    ``(kind, output, gain, R_C or C_p, V_d, V_b, C, R_L)`` and, to spare
    divisions per step: 1/R_C, theta/C_p, 1/C, 1/(R_L C), C_p/(C_p + C),
    C/(C_p + C); then the Shockley diodes' I_s (0: a constant drop) and
    2 n V_T, 1/L, and dt/R_L. Shared by the Monte Carlo loop and the record
    simulation (:mod:`randvib.identification.record_bridge`).
    """
    return (
        kind, output, rp[0], rp[1], rp[2], rp[3], rp[4], rp[5],
        1.0 / rp[1], rp[0] / rp[1], 1.0 / rp[4], 1.0 / (rp[5] * rp[4]),
        rp[1] / (rp[1] + rp[4]), rp[4] / (rp[1] + rp[4]), rp[6], 2.0 * rp[7],
        1.0 / rp[8] if rp[8] > 0.0 else 0.0, dt / rp[5] if rp[5] > 0.0 else 0.0,
    )  # fmt: skip


@numba.njit(cache=True, inline="always")
def _bridge_current(v, v_c, rect):
    """(current (A), drop of the two conducting diodes (V)) of the coil's bridge.

    ``e = alpha v``; V_out is V_b (battery) or ``v_c``. Constant drop:
    ``i = sgn(e) max(0, |e| - V_out - 2 V_d) / R_C``. Shockley diodes (I_s > 0,
    ``rect[14]``; ``rect[15]`` = 2 n V_T): ``|e| - V_out = R_C |i| + 2 n V_T
    ln(1 + |i| / I_s)``, solved by Newton's method in y = ln(1 + |i| / I_s),
    where the equation is convex and increasing: from an upper bound the
    iterates fall monotonically to the root.
    """
    output, gain, v_d, v_b, inv_r_coil = rect[1], rect[2], rect[4], rect[5], rect[8]
    v_out = v_b if output == 0 else v_c
    e = gain * v
    i_s = rect[14]
    if i_s > 0.0:
        over = abs(e) - v_out
        if over <= 0.0:
            return 0.0, 0.0
        r_is, c = rect[3] * i_s, rect[15]
        y = min(over / c, np.log1p(over / r_is))
        for _ in range(60):
            ey = np.exp(y)
            step = (r_is * (ey - 1.0) + c * y - over) / (r_is * ey + c)
            y -= step
            if step <= 1e-13 * y:
                break
        i = i_s * np.expm1(y)
        return (i if e > 0.0 else -i), c * y
    over = abs(e) - v_out - 2.0 * v_d
    if over <= 0.0:
        return 0.0, 0.0
    return (over * inv_r_coil if e > 0.0 else -over * inv_r_coil), 2.0 * v_d


@numba.njit(cache=True, inline="always")
def _piezo_clamp(v_p, v_c, rect):
    """Clamp |V_p| at V_out + 2 V_d: (V_p, V_C, charge through the bridge (C)).

    The charge beyond the clamp goes through the bridge: into the battery, or
    shared between C_p and the storage capacitor C, which then move together
    (charge conserved: ``C_p (|V_p| - 2 V_d) + C V_C`` before and after).
    """
    # branch-free min/max (whether the bridge conducts is data-dependent: a branch on it
    # is mispredicted often); off the clamp, min(|V_p|, limit) = |V_p| and V_C stays
    output, c_p, v_d, v_b, cap = rect[1], rect[3], rect[4], rect[5], rect[6]
    a = abs(v_p)
    if output == 0:
        limit = v_b + 2.0 * v_d
        return math.copysign(min(a, limit), v_p), v_c, c_p * max(a - limit, 0.0)
    # the shared level, weights C_p, C over C_p + C; below V_C when the bridge is off
    v_c_new = max(rect[12] * (a - 2.0 * v_d) + rect[13] * v_c, v_c)
    return math.copysign(min(a, v_c_new + 2.0 * v_d), v_p), v_c_new, cap * (v_c_new - v_c)


@numba.njit(cache=True, inline="always")
def _bridge_rates(v, s1, s2, rect, inv_m):
    """(acceleration (m/s^2), V_p', V_C', current (A), diodes' drop (V)) at (v, V_p, V_C)."""
    rkind, output, gain = rect[0], rect[1], rect[2]
    inv_cap, inv_rc = rect[10], rect[11]
    if rkind == 1:
        i, drop = _bridge_current(v, s2, rect)
        ds2 = abs(i) * inv_cap - s2 * inv_rc if output == 1 else 0.0
        return -gain * i * inv_m, 0.0, ds2, i, drop
    if rkind == 3:  # a coil with inductance: the current s1 is a state
        i = s1
        v_th = (rect[5] if output == 0 else s2) + 2.0 * rect[4]
        e = gain * v
        if i > 0.0:
            di = (e - rect[3] * i - v_th) * rect[16]
        elif i < 0.0:
            di = (e - rect[3] * i + v_th) * rect[16]
        else:  # blocked: the bridge opens once |e| exceeds the threshold
            over = abs(e) - v_th
            di = 0.0 if over <= 0.0 else (over if e > 0.0 else -over) * rect[16]
        ds2 = abs(i) * inv_cap - s2 * inv_rc if output == 1 else 0.0
        return -gain * i * inv_m, di, ds2, i, 2.0 * rect[4]
    ds2 = -s2 * inv_rc if output == 1 else 0.0
    return -gain * s1 * inv_m, rect[9] * v, ds2, 0.0, 0.0


@numba.njit(cache=True, inline="always")
def _bridge_predictor(s1, s2, ds1, ds2, dt, rect):
    """The bridge's states (s1, s2) at the predictor: an Euler stage, clamped or blocked."""
    rkind = rect[0]
    s1p = s1 + ds1 * dt
    s2p = s2 + ds2 * dt
    if rkind == 2:
        s1p, s2p, _ = _piezo_clamp(s1p, s2p, rect)
    elif rkind == 3 and s1p * s1 < 0.0:  # the diodes block the reverse current
        s1p = 0.0
    return s1p, s2p


@numba.njit(cache=True, inline="always")
def _bridge_update(s1, s1n, s2n, current, diodes, load, dt, rect):
    """The step's end: (s1, s2) clamped or blocked, and the energies (J) stored and in the diodes.

    ``s1n, s2n`` the scheme's update of the bridge's states from ``s1``;
    ``current``, ``diodes``, ``load`` the stage-weighted |i| (A), drop times
    |i| (W) and V_C^2 (V^2).
    """
    rkind, output, v_d, v_b = rect[0], rect[1], rect[4], rect[5]
    if rkind == 2:
        s1n, s2n, charge = _piezo_clamp(s1n, s2n, rect)  # the piezo's bridge charge (C)
    else:
        charge = current * dt
        if rkind == 3 and s1n * s1 < 0.0:  # the diodes block the reverse current
            s1n = 0.0
    stored = v_b * charge if output == 0 else load * rect[17]  # rect[17] = dt / R_L
    # the coil's diodes: their drop times the current at each stage; the piezo's: the charge
    diode = diodes * dt if rkind != 2 else 2.0 * v_d * charge
    return s1n, s2n, stored, diode


@numba.njit(cache=True, inline="always")
def rectified_step(
    z, v, theta, x1, x2, x3, s1, s2, dt, noise, weights, drift, kind, p, fn, block, rect
):
    """:func:`auxiliary_step` for the device with a full-wave bridge (:class:`Rectifier`).

    The filter's states (x1, x2, x3; ``block`` without a circuit) take the
    auxiliary step; the bridge adds its force and its states: ``s2`` = V_C
    of a storage capacitor (C V_C' = |i| - V_C / R_L), ``s1`` = V_p of a
    piezo element (C_p V_p' = theta v, clamped by :func:`_piezo_clamp` after
    each stage, the excess charge through the bridge) or the current i of a
    coil with inductance (L i' = e - R_C i - sgn(i) V_th; held at 0 when the
    diodes would let it reverse, until |e| exceeds V_th). The bridge's current
    is continuous in the state for the coil (a dead zone) and the clamp a
    projection for the piezo, so the scheme keeps its form but not its
    smooth-problem order (docs/conventions.md; the tests measure it).

    Returns
    -------
    z, v, theta, x1, x2, x3, s1, s2 : float
        State after the step.
    force : float
        Friction force at the start of the step (N).
    stored, coil, diode : float
        Energy (J) of the step into the output, the coil's resistance and the diodes.
    """
    b1, b2 = weights
    a11, a12, a13, a21, a22, a23, a31, a32, a33 = block[0:9]
    bv1, bv2, bv3, g1, g2, g3, c1, c2, c3, gv = block[9:19]
    rkind, second = rect[0], rect[3]
    inv_m = drift[0]
    acc1, rate1, force = _acceleration(z, v, theta, drift, kind, p, fn)
    acc1 -= c1 * x1 + c2 * x2 + c3 * x3
    d1 = a11 * x1 + a12 * x2 + a13 * x3 + bv1 * v
    d2 = a21 * x1 + a22 * x2 + a23 * x3 + bv2 * v
    d3 = a31 * x1 + a32 * x2 + a33 * x3 + bv3 * v
    nv = gv * noise
    f1, ds1, ds2, i1, drop1 = _bridge_rates(v, s1, s2, rect, inv_m)
    acc1 += f1
    if b2 == 0.0:
        zn = z + b1 * v * dt
        vn = v + b1 * acc1 * dt + nv
        tn = theta + b1 * rate1 * dt
        x1n = x1 + b1 * d1 * dt + g1 * noise
        x2n = x2 + b1 * d2 * dt + g2 * noise
        x3n = x3 + b1 * d3 * dt + g3 * noise
        s1n = s1 + b1 * ds1 * dt
        s2n = s2 + b1 * ds2 * dt
        current = b1 * abs(i1)
        coil = b1 * i1 * i1 * second if rkind != 2 else 0.0
        diodes = b1 * drop1 * abs(i1)
        load = b1 * s2 * s2
    else:
        zp = z + v * dt
        vp = v + acc1 * dt + nv
        tp = theta + rate1 * dt
        x1p = x1 + d1 * dt + g1 * noise
        x2p = x2 + d2 * dt + g2 * noise
        x3p = x3 + d3 * dt + g3 * noise
        s1p, s2p = _bridge_predictor(s1, s2, ds1, ds2, dt, rect)
        acc2, rate2, _ = _acceleration(zp, vp, tp, drift, kind, p, fn)
        acc2 -= c1 * x1p + c2 * x2p + c3 * x3p
        e1 = a11 * x1p + a12 * x2p + a13 * x3p + bv1 * vp
        e2 = a21 * x1p + a22 * x2p + a23 * x3p + bv2 * vp
        e3 = a31 * x1p + a32 * x2p + a33 * x3p + bv3 * vp
        f2, es1, es2, i2, drop2 = _bridge_rates(vp, s1p, s2p, rect, inv_m)
        acc2 += f2
        zn = z + (b1 * v + b2 * vp) * dt
        vn = v + (b1 * acc1 + b2 * acc2) * dt + nv
        tn = theta + (b1 * rate1 + b2 * rate2) * dt
        x1n = x1 + (b1 * d1 + b2 * e1) * dt + g1 * noise
        x2n = x2 + (b1 * d2 + b2 * e2) * dt + g2 * noise
        x3n = x3 + (b1 * d3 + b2 * e3) * dt + g3 * noise
        s1n = s1 + (b1 * ds1 + b2 * es1) * dt
        s2n = s2 + (b1 * ds2 + b2 * es2) * dt
        current = b1 * abs(i1) + b2 * abs(i2)
        coil = (b1 * i1 * i1 + b2 * i2 * i2) * second if rkind != 2 else 0.0
        diodes = b1 * drop1 * abs(i1) + b2 * drop2 * abs(i2)
        load = b1 * s2 * s2 + b2 * s2p * s2p
    s1n, s2n, stored, diode = _bridge_update(s1, s1n, s2n, current, diodes, load, dt, rect)
    return zn, vn, tn, x1n, x2n, x3n, s1n, s2n, force, stored, coil * dt, diode


@numba.njit(cache=True, inline="always")
def rectified_white_step(z, v, theta, s1, s2, dt, noise, weights, drift, kind, p, fn, rect):
    """:func:`rectified_step` without a shaping filter (white or given input): the same
    operations less the filter's exact zeros."""
    b1, b2 = weights
    second = rect[3]
    inv_m = drift[0]
    acc1, rate1, force = _acceleration(z, v, theta, drift, kind, p, fn)
    f1, ds1, ds2, i1, drop1 = _bridge_rates(v, s1, s2, rect, inv_m)
    acc1 += f1
    if b2 == 0.0:
        zn = z + b1 * v * dt
        vn = v + b1 * acc1 * dt + noise
        tn = theta + b1 * rate1 * dt
        s1n = s1 + b1 * ds1 * dt
        s2n = s2 + b1 * ds2 * dt
        current = b1 * abs(i1)
        coil = b1 * i1 * i1
        diodes = b1 * drop1 * abs(i1)
        load = b1 * s2 * s2
    else:
        zp = z + v * dt
        vp = v + acc1 * dt + noise
        tp = theta + rate1 * dt
        s1p, s2p = _bridge_predictor(s1, s2, ds1, ds2, dt, rect)
        acc2, rate2, _ = _acceleration(zp, vp, tp, drift, kind, p, fn)
        f2, es1, es2, i2, drop2 = _bridge_rates(vp, s1p, s2p, rect, inv_m)
        acc2 += f2
        zn = z + (b1 * v + b2 * vp) * dt
        vn = v + (b1 * acc1 + b2 * acc2) * dt + noise
        tn = theta + (b1 * rate1 + b2 * rate2) * dt
        s1n = s1 + (b1 * ds1 + b2 * es1) * dt
        s2n = s2 + (b1 * ds2 + b2 * es2) * dt
        current = b1 * abs(i1) + b2 * abs(i2)
        coil = b1 * i1 * i1 + b2 * i2 * i2
        diodes = b1 * drop1 * abs(i1) + b2 * drop2 * abs(i2)
        load = b1 * s2 * s2 + b2 * s2p * s2p
    s1n, s2n, stored, diode = _bridge_update(s1, s1n, s2n, current, diodes, load, dt, rect)
    return zn, vn, tn, s1n, s2n, force, stored, coil * second * dt, diode
