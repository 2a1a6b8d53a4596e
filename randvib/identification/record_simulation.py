"""Deterministic simulation of the device driven by a recorded input (paper Eq. 1).

    m z'' + c z' + k z + k3 z^3 + F(z', theta) = e(t)

with ``e(t) = -m y''(t)`` for base excitation and ``e(t) = u(t)`` for a force
applied to the mass. The input is sampled on a uniform grid ``t_i = i dt``;
between samples it is **linearly interpolated** (first-order hold; a
zero-order hold is available), and each sample interval is split into
``substeps`` equal steps.

A recorded base displacement is turned into base acceleration by the
fourth-order central difference
``y''_i = (-y_{i-2} + 16 y_{i-1} - 30 y_i + 16 y_{i+1} - y_{i+2}) / (12 dt^2)``
(relative error (omega dt)^4 / 90, 2e-7 at 20 Hz and 1 kHz), with the
second-order stencil next to the ends. Differentiation amplifies sensor noise
at high frequency; ``lowpass`` applies a zero-phase Butterworth filter to the
derived acceleration.

Integration (one compiled kernel, ``parallel=True`` over a population of
parameter sets):

* **Smooth models** (no friction, LuGre, tanh with a moderate beta): classical
  fourth-order Runge-Kutta on ``(z, z', theta)``. LuGre's bristle equation
  (Eq. 8) relaxes at the rate ``|z'| sigma0 / (sigma0 g)``, which can be far
  faster than the dynamics; steps are sub-cycled so that this rate times the
  step stays below one. During a search (``max_subcycles`` =
  :data:`SEARCH_SUBCYCLES`), a parameter set needing more than 32 sub-cycles
  per step (relaxation rate above 32 / h, 1.3e5 1/s at 1 kHz with 4
  sub-steps; the paper's Table 2 values need about 2e3 1/s) is rejected like a
  diverged one.
* **Coulomb** (Eq. 4-5): an event-driven stick-slip integrator. In slip the
  friction force has a fixed sign and RK4 is used; a velocity zero within a
  step is located on the step's cubic Hermite interpolant of the velocity and
  the step is redone up to it. At the zero the non-friction force
  ``g = e - c z' - k z - k3 z^3`` decides: ``|g| <= Fc`` sticks (``z' = 0``
  exactly, ``z`` frozen), otherwise slip restarts in the direction of ``g``.
  Breakaway, when ``|g|`` reaches ``Fc``, is found exactly because ``g`` is
  linear in time during a stick (linearly interpolated input, frozen ``z``).
  Sticking is therefore exact and free of chattering, and the scheme keeps
  fourth order between events.
* **tanh with a large beta** (Eq. 6, paper values up to 1e9 s/m): the friction
  relaxes the velocity on the time scale ``tau = m / (Fc beta)`` (4 ns for the
  paper's device), far below any affordable step, so an explicit step would
  chatter across zero and an implicit one would be first order. When the
  sub-step exceeds ``2 tau`` the model is integrated like Coulomb friction with
  a boundary layer: outside ``|z'| < x_b / beta`` (``tanh(x_b)`` within 2e-7 of
  1 and stable for RK4) the exact tanh force is used; inside it the velocity
  follows its quasi-static value ``z' = artanh(g / Fc) / beta`` (the slow
  manifold of the singularly perturbed equation, error O(tau)), so the model
  "creeps" while ``|g| < Fc tanh(x_b)`` and crosses the layer instantly
  otherwise. Results therefore do not depend on the step size; below the
  switch (``h <= 2 tau``) plain RK4 is stable and accurate.

Which path a friction law takes is its own declaration
(:mod:`randvib.models.friction`): ``stick_slip`` selects the event-located
integrator (``Fc sgn v``) or its boundary-layer form (``Fc tanh(beta v)``),
``kernel_relaxation_rate`` the sub-cycling of a law with memory, and
everything else is RK4 on the law's compiled ``kernel``.

A candidate whose response leaves a sanity bound (``response_limit``) or
becomes non-finite is stopped and gets an infinite cost / NaN samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from randvib._validation import check_finite, check_int, check_positive
from randvib.models.friction import (
    FRICTION_MODELS,
    KERNEL_NONE,
    N_KERNEL_PARAMETERS,
    STICK_SLIP_SIGN,
    STICK_SLIP_TANH,
    FrictionModel,
    RegistryView,
    evaluate_friction,
    kernel_callback,
)
from randvib.models.harvester import Harvester

#: Input kinds a record may carry, and what the kernel is driven by.
INPUT_KINDS = ("base_displacement", "base_acceleration", "force")
#: Friction law name -> kernel code (``none`` = viscous only); a live view of
#: the registry :data:`randvib.models.friction.FRICTION_MODELS`.
FRICTION_KINDS = RegistryView(lambda law: KERNEL_NONE if law is None else law.kernel_code)
#: Friction law name -> parameter names in kernel order (live view, as above).
FRICTION_PARAMETERS = RegistryView(lambda law: () if law is None else law.parameter_names())
#: Device parameters shared by every model.
DEVICE_PARAMETERS = ("m", "c", "k", "k3")
HOLDS = ("linear", "zero")

_SLIP = 0
_STICK = 1
_MAX_EVENTS = 24  # events handled inside one sub-step before the step is forced
#: LuGre sub-cycles per sub-step allowed while searching: stiffer candidates
#: (bristle relaxation much faster than the record's dynamics) are rejected as
#: diverged instead of costing thousands of steps each. Single simulations
#: (prediction, validation) allow 4096.
SEARCH_SUBCYCLES = 32


# --------------------------------------------------------------------- kernel
@numba.njit(cache=True, inline="always")
def _slip_force(tanh_mode, fc, beta, vb, sgn, v):
    # Friction while slipping in direction sgn, continued smoothly past the
    # boundary so that RK4 trial steps and the event interpolant are defined.
    if tanh_mode:
        w = sgn * v
        if w < vb:
            w = vb
        return sgn * fc * math.tanh(beta * w)
    return sgn * fc


@numba.njit(cache=True, inline="always")
def _slip_acc(m, c, k, k3, e, z, v, tanh_mode, fc, beta, vb, sgn):
    return (e - c * v - k * z - k3 * z * z * z - _slip_force(tanh_mode, fc, beta, vb, sgn, v)) / m


@numba.njit(cache=True)
def _slip_rk4(m, c, k, k3, gain, u0, du, s, hh, z, v, tanh_mode, fc, beta, vb, sgn):
    e0 = gain * (u0 + du * s)
    e1 = gain * (u0 + du * (s + 0.5 * hh))
    e2 = gain * (u0 + du * (s + hh))
    a1 = _slip_acc(m, c, k, k3, e0, z, v, tanh_mode, fc, beta, vb, sgn)
    z2 = z + 0.5 * hh * v
    v2 = v + 0.5 * hh * a1
    a2 = _slip_acc(m, c, k, k3, e1, z2, v2, tanh_mode, fc, beta, vb, sgn)
    z3 = z + 0.5 * hh * v2
    v3 = v + 0.5 * hh * a2
    a3 = _slip_acc(m, c, k, k3, e1, z3, v3, tanh_mode, fc, beta, vb, sgn)
    z4 = z + hh * v3
    v4 = v + hh * a3
    a4 = _slip_acc(m, c, k, k3, e2, z4, v4, tanh_mode, fc, beta, vb, sgn)
    zn = z + hh / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4)
    vn = v + hh / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return zn, vn, a1


@numba.njit(cache=True, inline="always")
def _creep_velocity(tanh_mode, fc, beta, g):
    # Quasi-static velocity inside the tanh boundary layer: Fc tanh(beta v) = g.
    if not tanh_mode:
        return 0.0
    return math.atanh(g / fc) / beta


@numba.njit(cache=True)
def _smooth_rk4(kind, fn, p, m, c, k, k3, gain, u0, du, s, hh, z, v, th):
    e0 = gain * (u0 + du * s)
    e1 = gain * (u0 + du * (s + 0.5 * hh))
    e2 = gain * (u0 + du * (s + hh))
    f1, r1 = evaluate_friction(kind, fn, p, v, th)
    a1 = (e0 - c * v - k * z - k3 * z * z * z - f1) / m
    z2 = z + 0.5 * hh * v
    v2 = v + 0.5 * hh * a1
    t2 = th + 0.5 * hh * r1
    f2, r2 = evaluate_friction(kind, fn, p, v2, t2)
    a2 = (e1 - c * v2 - k * z2 - k3 * z2 * z2 * z2 - f2) / m
    z3 = z + 0.5 * hh * v2
    v3 = v + 0.5 * hh * a2
    t3 = th + 0.5 * hh * r2
    f3, r3 = evaluate_friction(kind, fn, p, v3, t3)
    a3 = (e1 - c * v3 - k * z3 - k3 * z3 * z3 * z3 - f3) / m
    z4 = z + hh * v3
    v4 = v + hh * a3
    t4 = th + hh * r3
    f4, r4 = evaluate_friction(kind, fn, p, v4, t4)
    a4 = (e2 - c * v4 - k * z4 - k3 * z4 * z4 * z4 - f4) / m
    zn = z + hh / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4)
    vn = v + hh / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    tn = th + hh / 6.0 * (r1 + 2.0 * r2 + 2.0 * r3 + r4)
    return zn, vn, tn


@numba.njit(cache=True)
def _hermite_root(hh, q0, d0, q1, d1):
    # Fraction tau in (0, 1] where the cubic Hermite interpolant through
    # (q0, d0) at 0 and (q1, d1) at hh first reaches zero; q0 > 0 >= q1.
    lo = 0.0
    hi = 1.0
    for _ in range(48):
        mid = 0.5 * (lo + hi)
        t2 = mid * mid
        t3 = t2 * mid
        q = (
            (2 * t3 - 3 * t2 + 1) * q0
            + (t3 - 2 * t2 + mid) * hh * d0
            + (-2 * t3 + 3 * t2) * q1
            + (t3 - t2) * hh * d1
        )
        if q > 0.0:
            lo = mid
        else:
            hi = mid
    return hi


@numba.njit(cache=True)
def _run_one(
    par,
    kind,
    fn,
    slip,
    relax_rate,
    base_input,
    u,
    dt,
    nsub,
    linear,
    z0,
    v0,
    th0,
    zref,
    skip,
    zlim,
    max_sub,
    out_z,
    out_v,
    store,
):
    """Simulate one parameter set; return the sum of squared errors against zref
    over the samples from index ``skip`` on."""
    m = par[0]
    c = par[1]
    k = par[2]
    k3 = par[3]
    p = par[4:]
    gain = -m if base_input else 1.0
    h = dt / nsub
    n = u.shape[0]
    have_ref = zref.shape[0] == n

    sticky = False
    tanh_mode = False
    fc = 0.0
    beta = 0.0
    vb = 0.0
    fstick = 0.0
    # The law declares how the stick-slip integrator reads p (``stick_slip``).
    if slip == STICK_SLIP_SIGN and p[0] > 0.0:
        sticky = True
        fc = p[0]
        fstick = fc
    elif slip == STICK_SLIP_TANH and p[0] > 0.0:
        tau = m / (p[0] * p[1])
        if h > 2.0 * tau:
            sticky = True
            tanh_mode = True
            fc = p[0]
            beta = p[1]
            xb = max(8.0, 0.5 * math.log(4.0 * h / tau))
            vb = xb / beta
            fstick = fc * math.tanh(xb)
    if slip == STICK_SLIP_SIGN and not sticky:
        kind = KERNEL_NONE  # Fc = 0
    if slip == STICK_SLIP_TANH and p[0] == 0.0:
        kind = KERNEL_NONE

    z = z0
    v = v0
    th = th0
    mode = _SLIP
    sgn = 1.0
    if sticky:
        e = gain * u[0]
        if abs(v) <= vb or v == 0.0:
            g = e - c * v - k * z - k3 * z * z * z
            if abs(g) <= fstick:
                mode = _STICK
                v = _creep_velocity(tanh_mode, fc, beta, g)
            else:
                sgn = 1.0 if g > 0 else -1.0
                v = sgn * vb
        else:
            sgn = 1.0 if v > 0 else -1.0

    sse = 0.0
    if have_ref and skip == 0:
        sse = (z - zref[0]) ** 2
    if store:
        out_z[0] = z
        out_v[0] = v
    for i in range(n - 1):
        u0 = u[i]
        du = (u[i + 1] - u[i]) / dt if linear else 0.0
        for j in range(nsub):
            a = j * h
            b = dt if j == nsub - 1 else a + h
            if not sticky:
                nc = 1
                if relax_rate > 0.0:
                    nc = int(abs(v) * relax_rate * (b - a)) + 1
                    if nc > max_sub:
                        # bristles stiffer than the step resolves: rejected as diverged
                        if store:
                            for r in range(i + 1, n):
                                out_z[r] = math.nan
                                out_v[r] = math.nan
                        return math.inf
                hh = (b - a) / nc
                for q in range(nc):
                    z, v, th = _smooth_rk4(
                        kind, fn, p, m, c, k, k3, gain, u0, du, a + q * hh, hh, z, v, th
                    )
                continue
            s = a
            for it in range(_MAX_EVENTS):
                if s >= b:
                    break
                if mode == _STICK:
                    ga = gain * (u0 + du * s) - k * z - k3 * z * z * z
                    gb = gain * (u0 + du * b) - k * z - k3 * z * z * z
                    if abs(ga) <= fstick and abs(gb) <= fstick:
                        if tanh_mode:
                            gm = 0.5 * (ga + gb)
                            z += (b - s) * _creep_velocity(tanh_mode, fc, beta, gm)
                            v = _creep_velocity(tanh_mode, fc, beta, gb)
                        s = b
                    else:
                        if abs(ga) > fstick:
                            s_new = s
                            sgn = 1.0 if ga > 0 else -1.0
                        else:
                            target = fstick if gb > 0 else -fstick
                            frac = (target - ga) / (gb - ga)
                            frac = min(max(frac, 0.0), 1.0)
                            s_new = s + frac * (b - s)
                            sgn = 1.0 if gb > 0 else -1.0
                        if tanh_mode:
                            # creep up to breakaway at the mean quasi-static velocity
                            gm = 0.5 * (ga + sgn * fstick)
                            z += (s_new - s) * _creep_velocity(tanh_mode, fc, beta, gm)
                        s = s_new
                        mode = _SLIP
                        v = sgn * vb
                else:
                    hh = b - s
                    if hh <= 1e-14 * dt:
                        s = b
                        break
                    z1, v1, a0 = _slip_rk4(
                        m, c, k, k3, gain, u0, du, s, hh, z, v, tanh_mode, fc, beta, vb, sgn
                    )
                    if sgn * v1 > vb or it == _MAX_EVENTS - 1:
                        z = z1
                        v = v1
                        s = b
                        continue
                    # velocity reaches the boundary inside the step: locate, redo
                    e1 = gain * (u0 + du * b)
                    a1 = _slip_acc(m, c, k, k3, e1, z1, v1, tanh_mode, fc, beta, vb, sgn)
                    frac = _hermite_root(hh, sgn * v - vb, sgn * a0, sgn * v1 - vb, sgn * a1)
                    hs = frac * hh
                    z, v, a0 = _slip_rk4(
                        m, c, k, k3, gain, u0, du, s, hs, z, v, tanh_mode, fc, beta, vb, sgn
                    )
                    s = s + hs
                    if s > b:
                        s = b
                    v = sgn * vb
                    g = gain * (u0 + du * s) - c * v - k * z - k3 * z * z * z
                    if abs(g) <= fstick:
                        mode = _STICK
                        v = _creep_velocity(tanh_mode, fc, beta, g)
                    else:
                        new = 1.0 if g > 0 else -1.0
                        if new != sgn:
                            sgn = new
                            v = sgn * vb  # cross the (zero-width or 1/beta) layer
        if not (abs(z) < zlim) or not (abs(v) < math.inf):
            if store:
                for r in range(i + 1, n):
                    out_z[r] = math.nan
                    out_v[r] = math.nan
            return math.inf
        if have_ref and i + 1 >= skip:
            sse += (z - zref[i + 1]) ** 2
        if store:
            out_z[i + 1] = z
            out_v[i + 1] = v
    return sse


@numba.njit(cache=True, parallel=True)
def _run_batch(
    params,
    kind,
    fn,
    slip,
    relax,
    base_input,
    u,
    dt,
    nsub,
    linear,
    z0,
    v0,
    th0,
    zref,
    skip,
    zlim,
    max_sub,
    out_z,
    out_v,
    store,
):
    n_pop = params.shape[0]
    sse = np.empty(n_pop)
    for i in numba.prange(n_pop):
        if store:
            sse[i] = _run_one(
                params[i], kind, fn, slip, relax[i], base_input, u, dt, nsub, linear,
                z0[i], v0[i], th0[i], zref, skip, zlim, max_sub, out_z[i], out_v[i], True,
            )  # fmt: skip
        else:
            sse[i] = _run_one(
                params[i], kind, fn, slip, relax[i], base_input, u, dt, nsub, linear,
                z0[i], v0[i], th0[i], zref, skip, zlim, max_sub, out_z[0], out_v[0], False,
            )  # fmt: skip
    return sse


# ----------------------------------------------------------------- python API
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


@dataclass(frozen=True, eq=False)
class BatchSimulation:
    """Responses of a population of parameter sets to one recorded input.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times (s).
    z, v : ndarray, shape (n_pop, n)
        Relative displacement (m) and velocity (m/s) at the samples; NaN after
        a candidate diverged.
    """

    time: np.ndarray
    z: np.ndarray
    v: np.ndarray


def _law(friction):
    """The law class named ``friction`` (``none``: None); a law class or None passes through."""
    if friction is None or isinstance(friction, type) and issubclass(friction, FrictionModel):
        return friction
    if friction not in FRICTION_KINDS:
        raise ValueError(f"`friction` must be one of {', '.join(FRICTION_KINDS)}; got {friction!r}")
    return None if friction == "none" else FRICTION_MODELS[friction]


def device_parameters(device, friction=None) -> tuple[dict, str]:
    """Named record-simulation parameters and friction name of a device.

    The record simulator and identification work with the total viscous
    damping ``c = c_m + c_e`` (Eq. 1): a record cannot separate the two.

    Parameters
    ----------
    device : Harvester or dict
        A :class:`~randvib.models.harvester.Harvester` (a preset included); the dict
        of its :meth:`~randvib.models.harvester.Harvester.parameters` (``c_m``,
        ``c_e``, ``friction`` and the friction and circuit parameters); or
        ``m, c, k, k3`` and the friction parameters, with ``friction``
        naming the law.
    friction : str, optional
        Friction law name; required for the last form, checked against the
        device's own law for the others.

    Returns
    -------
    parameters : dict
        ``m`` (kg), ``c`` (Ns/m), ``k`` (N/m), ``k3`` (N/m^3) and the law's
        parameters.
    friction : str
    """
    if isinstance(device, Harvester):
        params = {"m": device.m, "c": device.c, "k": device.k, "k3": device.k3}
        if device.friction is not None:
            params.update(device.friction.parameters())
        own = device.friction_name
    elif isinstance(device, dict) and ("c_m" in device or "friction" in device):
        # Harvester.parameters(): total damping; the circuit's alpha, r_load,
        # r_coil only explain c_e, which is already in it.
        params = {k: v for k, v in device.items() if k not in _HARVESTER_ONLY}
        params["c"] = np.asarray(device.get("c_m", 0.0)) + np.asarray(device.get("c_e", 0.0))
        own = device.get("friction", "none")
    else:
        if friction is None:
            raise ValueError(
                "`friction` is required with a parameter dict (m, c, k, k3, ...); "
                "or pass a randvib.Harvester"
            )
        return dict(device), friction
    if friction is not None and friction != own:
        raise ValueError(f"`friction` = {friction!r} disagrees with the device's {own!r}")
    return params, own


#: Harvester.parameters() keys that the record simulator does not take.
_HARVESTER_ONLY = ("c_m", "c_e", "friction", "alpha", "r_load", "r_coil")


def parameter_matrix(parameters: dict, friction) -> np.ndarray:
    """Kernel parameter rows ``[m, c, k, k3, friction...]`` from named arrays.

    Parameters
    ----------
    parameters : dict
        ``m, c, k, k3`` and the friction parameters (see
        :data:`FRICTION_PARAMETERS`); scalars or 1-D arrays of one length.
    friction : str or FrictionModel subclass
        One of :data:`FRICTION_KINDS`, or a law class.
    """
    law = _law(friction)
    friction = "none" if law is None else law.name
    names = DEVICE_PARAMETERS + (() if law is None else law.parameter_names())
    missing = [name for name in names if name not in parameters]
    if missing:
        raise ValueError(
            f"missing parameter(s) {missing} for friction {friction!r}; needed: {', '.join(names)}"
        )
    extra = sorted(set(parameters) - set(names))
    if extra:
        raise ValueError(
            f"unknown parameter(s) {extra} for friction {friction!r}; allowed: {', '.join(names)}"
        )
    columns = [np.atleast_1d(check_finite(name, parameters[name])) for name in names]
    n_pop = max(col.shape[0] for col in columns)
    out = np.zeros((n_pop, 4 + N_KERNEL_PARAMETERS))
    for j, col in enumerate(columns):
        if col.ndim != 1 or col.shape[0] not in (1, n_pop):
            raise ValueError(f"parameter `{names[j]}` must be a scalar or a 1-D array of {n_pop}")
        out[:, j] = col
    if np.any(out[:, 0] <= 0):
        raise ValueError(f"`m` must be > 0 (kg), got {out[out[:, 0] <= 0, 0][0]!r}")
    return out


def run_kernel(
    matrix,
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
    reference=None,
    skip=0,
    response_limit=np.inf,
    store=True,
    max_subcycles=4096,
):
    """Low-level batched call; validated arguments. Returns (sse, z, v)."""
    law = _law(friction)
    n_pop = matrix.shape[0]
    n = drive.shape[0]
    z0 = np.broadcast_to(np.asarray(z0, dtype=float), (n_pop,)).copy()
    v0 = np.broadcast_to(np.asarray(v0, dtype=float), (n_pop,)).copy()
    th0 = np.broadcast_to(np.asarray(theta0, dtype=float), (n_pop,)).copy()
    zref = np.empty(0) if reference is None else np.ascontiguousarray(reference, dtype=float)
    shape = (n_pop, n) if store else (1, 1)
    out_z = np.empty(shape)
    out_v = np.empty(shape)
    sse = _run_batch(
        np.ascontiguousarray(matrix),
        KERNEL_NONE if law is None else law.kernel_code,
        kernel_callback(law),
        0 if law is None else law.stick_slip,
        np.zeros(n_pop) if law is None else law.kernel_relaxation_rate(matrix[:, 4:]),
        bool(base_input),
        drive,
        float(dt),
        int(substeps),
        hold == "linear",
        z0,
        v0,
        th0,
        zref,
        int(skip),
        float(response_limit),
        int(max_subcycles),
        out_z,
        out_v,
        bool(store),
    )
    return sse, (out_z if store else None), (out_v if store else None)


def simulate_record(
    parameters,
    friction=None,
    input_values=None,
    dt: float | None = None,
    *,
    input_kind: str = "base_acceleration",
    substeps: int = 4,
    hold: str = "linear",
    lowpass: float | None = None,
    z0=0.0,
    v0=0.0,
    theta0=0.0,
    response_limit: float = np.inf,
) -> BatchSimulation:
    """Simulate Eq. 1 driven by a recorded input, for many parameter sets at once.

    Called as ``simulate_record(harvester, input_values, dt, ...)`` with a
    :class:`~randvib.models.harvester.Harvester` (a preset included) or its
    ``parameters()`` dict, or as ``simulate_record(parameters, friction,
    input_values, dt, ...)`` with a dict of named parameters.

    Parameters
    ----------
    parameters : Harvester or dict
        A device (simulated with c = c_m + c_e), or ``m`` (kg), ``c`` (Ns/m),
        ``k`` (N/m), ``k3`` (N/m^3) and the friction parameters (``fc`` N;
        ``beta`` s/m; ``sigma0`` N/m, ``sigma1`` Ns/m, ``fs`` N, ``vs`` m/s;
        see :data:`FRICTION_PARAMETERS`); scalars or 1-D arrays (one row per
        candidate).
    friction : str, optional
        Friction law name: ``none`` or a registered law (paper Eq. 4-10:
        ``coulomb``, ``tanh``, ``lugre``); only with a parameter dict.
    input_values : array_like, shape (n,)
        Input samples on the uniform grid ``i dt``: base displacement (m),
        base acceleration (m/s^2) or force on the mass (N).
    dt : float
        Sample interval (s).
    input_kind : {'base_displacement', 'base_acceleration', 'force'}
    substeps : int, optional
        Integration steps per sample interval (default 4).
    hold : {'linear', 'zero'}
        Interpolation of the input between samples.
    lowpass : float, optional
        Zero-phase low-pass cut-off (Hz) for the driving signal.
    z0, v0, theta0 : float or array_like
        Initial displacement (m), velocity (m/s), LuGre bristle state (m).
    response_limit : float, optional
        |z| above which a candidate counts as diverged (m).

    Returns
    -------
    BatchSimulation
    """
    if not (friction is None or isinstance(friction, str | type)):
        # simulate_record(device, input_values, dt): the device names its law.
        friction, input_values, dt = None, friction, input_values
    parameters, friction = device_parameters(parameters, friction)
    if input_values is None or dt is None:
        raise ValueError("`input_values` and `dt` are required")
    dt = float(check_positive("dt", dt, "s"))
    substeps = check_int("substeps", substeps, minimum=1)
    if hold not in HOLDS:
        raise ValueError(f"`hold` must be one of {', '.join(HOLDS)}; got {hold!r}")
    values = check_finite("input_values", input_values)
    if values.ndim != 1 or values.shape[0] < 2:
        raise ValueError(
            f"`input_values` must be 1-D with at least 2 samples, got shape {values.shape}"
        )
    matrix = parameter_matrix(parameters, friction)
    drive, base_input = driving_signal(values, dt, input_kind, lowpass)
    _, z, v = run_kernel(
        matrix,
        friction,
        drive,
        base_input,
        dt,
        substeps=substeps,
        hold=hold,
        z0=z0,
        v0=v0,
        theta0=theta0,
        response_limit=response_limit,
    )
    return BatchSimulation(time=np.arange(values.shape[0]) * dt, z=z, v=v)
