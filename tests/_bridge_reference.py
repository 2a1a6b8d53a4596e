"""An independent plain-numpy integrator of a coil harvester behind a full-wave bridge.

Shared by ``tests/test_record_bridge.py`` and its calibration note. None of
randvib's simulators is used: Eq. 1 with the coil's bridge (docs/conventions.md,
"Full-wave bridge") is integrated by classical RK4 at ``up`` steps per sample on
the linearly interpolated input, from rest (the storage capacitor empty):

* ``m z'' + c z' + k z + k3 z^3 + alpha i = -m y''``, ``e = alpha z'``;
* L = 0: ``i = sgn(e) max(0, |e| - V_out - 2 V_d) / R_C`` (a dead zone:
  continuous, so RK4 converges, at second order across a switch);
* L > 0: ``L i' = e - R_C i - sgn(i) (V_out + 2 V_d)`` while ``i != 0``; at
  ``i = 0`` the diodes hold it until ``|e| > V_out + 2 V_d``, and a step that
  would reverse it ends at 0. The conducting pair is the one at the step's
  start for all four stages (a stage that changed it would jump the rate by
  2 V_th / L: RK4 then converged at first order with a large constant, 4e-3 of
  V_C's RMS at 32 steps per sample; this way 1.9e-6 against 64);
* ``V_out = V_b`` (battery) or ``V_C`` with ``C V_C' = |i| - V_C / R_L``.
"""

from __future__ import annotations

import math

import numpy as np


def coil_bridge_states(device, a, fs, up=32):
    """(z, z', i, V_out) at the samples of the coil-and-bridge ``device`` driven by ``a``.

    ``device``: a dict of m, c, k, k3, alpha, r_coil, inductance, v_diode and either
    battery or storage_capacitance with r_load.
    """
    m, c, k, k3 = (float(device[n]) for n in ("m", "c", "k", "k3"))
    alpha, r_coil = float(device["alpha"]), float(device["r_coil"])
    ind, v_d = float(device.get("inductance", 0.0)), float(device["v_diode"])
    battery = device.get("battery")
    cap, r_load = device.get("storage_capacitance"), device.get("r_load")

    def threshold(v_c):
        return (battery if battery is not None else v_c) + 2.0 * v_d

    def pair(v, i, v_c):
        # the conducting pair (+1, -1) or none (0) of the coil with inductance
        if i != 0.0:
            return math.copysign(1.0, i)
        return math.copysign(1.0, v) if abs(alpha * v) > threshold(v_c) else 0.0

    def current(v, i, v_c, direction):
        if ind == 0.0:
            e = alpha * v
            over = abs(e) - threshold(v_c)
            return (math.copysign(over / r_coil, e) if over > 0 else 0.0), 0.0
        if direction == 0.0:
            return 0.0, 0.0
        return i, (alpha * v - r_coil * i - direction * threshold(v_c)) / ind

    def rate(z, v, i, v_c, acc, direction):
        cur, di = current(v, i, v_c, direction)
        force = c * v + k * z + k3 * z * z * z + alpha * cur
        dv_c = 0.0 if battery is not None else abs(cur) / cap - v_c / (r_load * cap)
        return v, -force / m - acc, di, dv_c

    n = len(a)
    fine = np.interp(np.arange((n - 1) * up + 1) / up, np.arange(n), a).tolist()
    h = 1.0 / (fs * up)
    out = np.empty((n, 4))
    s = [0.0, 0.0, 0.0, 0.0]
    for step in range(len(fine)):
        direction = pair(s[1], s[2], s[3])
        if step % up == 0:
            cur = current(s[1], s[2], s[3], direction)[0]
            out[step // up] = s[0], s[1], cur, battery if battery is not None else s[3]
        if step + 1 == len(fine):
            break
        y0, y1 = fine[step], fine[step + 1]
        ym = 0.5 * (y0 + y1)
        k1 = rate(*s, y0, direction)
        k2 = rate(*(x + h / 2 * d for x, d in zip(s, k1, strict=True)), ym, direction)
        k3_ = rate(*(x + h / 2 * d for x, d in zip(s, k2, strict=True)), ym, direction)
        k4 = rate(*(x + h * d for x, d in zip(s, k3_, strict=True)), y1, direction)
        new = [x + h / 6 * (p + 2 * q + 2 * r + w)
               for x, p, q, r, w in zip(s, k1, k2, k3_, k4, strict=True)]  # fmt: skip
        if ind > 0.0 and new[2] * direction < 0.0:  # the diodes block the reverse current
            new[2] = 0.0
        s = new
    return out
