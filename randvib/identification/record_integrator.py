"""Eq. 1 integrated on a recorded input: the compiled batch integrator.

    m z'' + c z' + k z + k2 z^2 + k3 z^3 + F(z', theta) = e(t)

with ``e(t) = -m y''(t)`` for base excitation and ``e(t) = u(t)`` for a force
applied to the mass, the input less its channel's offset (measured = true +
offset; :mod:`randvib.identification.input_reconstruction` gives the input
between samples). Each sample interval is split into ``substeps`` equal
steps; each sub-step reads the reconstruction at its start, middle and end
(RK4's stages) and uses the quadratic through them in between. A constant
output offset is added to z where it is scored.

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
from typing import NamedTuple

import numba
import numpy as np

from randvib._validation import check_finite
from randvib.identification.input_reconstruction import HOLDS, reconstruct_input
from randvib.models.friction import (
    FRICTION_MODELS,
    KERNEL_NONE,
    N_KERNEL_PARAMETERS,
    STICK_SLIP_NONE,
    STICK_SLIP_SIGN,
    STICK_SLIP_TANH,
    FrictionModel,
    RegistryView,
    evaluate_friction,
    kernel_callback,
)

#: Friction law name -> kernel code (``none`` = viscous only); a live view of
#: the registry :data:`randvib.models.friction.FRICTION_MODELS`.
FRICTION_KINDS = RegistryView(lambda law: KERNEL_NONE if law is None else law.kernel_code)


#: Friction law name -> parameter names in kernel order (live view, as above).
FRICTION_PARAMETERS = RegistryView(lambda law: () if law is None else law.parameter_names())


#: Device parameters shared by every model.
DEVICE_PARAMETERS = ("m", "c", "k", "k3")


#: Measurement-model and extra stiffness parameters every model may take
#: (default 0): quadratic stiffness k2 (N/m^2), the input channel's offset
#: (units of the driving signal: m/s^2 or N) and the output's (m).
EXTRA_PARAMETERS = ("k2", "input_offset", "output_offset")


#: Columns of a kernel parameter row: m, c, k, k3, the friction law's
#: parameters (padded to N_KERNEL_PARAMETERS), then EXTRA_PARAMETERS, then the
#: circuit's (a, b, f) (:data:`CIRCUIT_COLUMNS`).
MATRIX_COLUMNS = 4 + N_KERNEL_PARAMETERS + len(EXTRA_PARAMETERS) + 3


_K2 = 4 + N_KERNEL_PARAMETERS


_INPUT_OFFSET = _K2 + 1


_OUTPUT_OFFSET = _K2 + 2

#: The column of a kernel parameter row holding the output sensor's offset.
OUTPUT_OFFSET_COLUMN = _OUTPUT_OFFSET


#: The circuit state's equation ``x' = a x + b z'`` and force ``f x`` on the mass
#: (:meth:`randvib.models.coupling.Coupling.circuit_equation`); all 0 without one.
CIRCUIT_COLUMNS = (_K2 + 3, _K2 + 4, _K2 + 5)


_SLIP = 0


_STICK = 1


_MAX_EVENTS = 24  # events handled inside one sub-step before the step is forced


#: LuGre sub-cycles per sub-step allowed while searching: stiffer candidates
#: (bristle relaxation much faster than the record's dynamics) are rejected as
#: diverged instead of costing thousands of steps each. Single simulations
#: (prediction, validation) allow 4096. A circuit state relaxing at |a| counts
#: the same way (|a| h sub-cycles per sub-step h).
SEARCH_SUBCYCLES = 32


# --------------------------------------------------------------------- kernel
# The compiled pieces hand each other small tuples instead of long argument
# lists (numba passes them by value, so they cost nothing):
#   dev   = (m, c, k, k3, gain, k2, u_off, ca, cb, cf)  one candidate's device;
#           the input drives it with e(t) = gain * (input(t) - u_off), gain = -m
#           for a base input, else 1; the circuit state x obeys
#           x' = ca x + cb z' and pushes the mass back with cf x (all 0: none)
#   law   = (kind, fn, p)        the friction law's kernel code, compiled
#           callback and parameters, for :func:`evaluate_friction`
#   layer = (tanh_mode, fc, beta, vb, fstick)  the friction as the stick-slip
#           integrator sees it: ``Fc sgn v`` (vb = 0) or ``Fc tanh(beta v)``
#           with the boundary layer |v| < vb; fstick is the largest friction
#           force a stick holds
#   slipping = (layer, sgn)      the friction while slipping in direction sgn = +-1
#   seg   = (a, u0, c1, c2)      input over one sub-step [a, b] of the sample
#           interval, u0 + c1 (s - a) + c2 (s - a)^2 (c2 = 0: linear)
#   st    = (z, v, mode, sgn, x) the stick-slip integrator's state
@numba.njit(cache=True, inline="always")
def _input(dev, seg, s):
    # e at time s into the sample interval: the sub-step's quadratic through
    # the reconstructed input at its start, middle and end, less the input
    # channel's offset (measured = true + offset)
    r = s - seg[0]
    return dev[4] * (seg[1] + r * (seg[2] + r * seg[3]) - dev[6])


@numba.njit(cache=True, inline="always")
def _free_force(dev, e, z, v, x):
    # g = e - c z' - k z - k2 z^2 - k3 z^3 - f x: everything but friction (N)
    return e - dev[1] * v - z * (dev[2] + z * (dev[5] + z * dev[3])) - dev[9] * x


@numba.njit(cache=True, inline="always")
def _acceleration(dev, e, z, v, x, f):
    return (_free_force(dev, e, z, v, x) - f) / dev[0]


@numba.njit(cache=True, inline="always")
def _slip_force(layer, sgn, v):
    # Friction while slipping in direction sgn, continued smoothly past the
    # boundary so that RK4 trial steps and the event interpolant are defined.
    tanh_mode, fc, beta, vb, _ = layer
    if tanh_mode:
        w = sgn * v
        if w < vb:
            w = vb
        return sgn * fc * math.tanh(beta * w)
    return sgn * fc


@numba.njit(cache=True, inline="always")
def _law_friction(law, v, th):
    # (F, theta') of the law's own kernel: the smooth path
    return evaluate_friction(law[0], law[1], law[2], v, th)


@numba.njit(cache=True, inline="always")
def _slip_friction(slipping, v, th):
    # (F, 0) while the stick-slip integrator slips
    return _slip_force(slipping[0], slipping[1], v), 0.0


@numba.njit(cache=True, inline="always")
def _rk4(friction, fr, dev, seg, s, hh, z, v, th, x):
    """Classical RK4 step of length hh from s on (z, z', theta, x).

    ``friction(fr, v, theta) -> (F, theta')`` is :func:`_law_friction` (``fr`` =
    ``law``) or :func:`_slip_friction` (``fr`` = ``slipping``), a compiled
    function named where the step is used: inlined there, each use compiles
    without the other's code (a run-time choice in every stage cost 12 % of
    the Coulomb search, and a function passed at run time defeats caching).
    The circuit state x (``x' = ca x + cb z'``) is a fourth RK4 variable.
    Returns the state after the step and the acceleration at its start (the
    slope that the event interpolant needs).
    """
    ca, cb = dev[7], dev[8]
    e0 = _input(dev, seg, s)
    e1 = _input(dev, seg, s + 0.5 * hh)
    e2 = _input(dev, seg, s + hh)
    f1, r1 = friction(fr, v, th)
    a1 = _acceleration(dev, e0, z, v, x, f1)
    q1 = ca * x + cb * v
    z2 = z + 0.5 * hh * v
    v2 = v + 0.5 * hh * a1
    t2 = th + 0.5 * hh * r1
    x2 = x + 0.5 * hh * q1
    f2, r2 = friction(fr, v2, t2)
    a2 = _acceleration(dev, e1, z2, v2, x2, f2)
    q2 = ca * x2 + cb * v2
    z3 = z + 0.5 * hh * v2
    v3 = v + 0.5 * hh * a2
    t3 = th + 0.5 * hh * r2
    x3 = x + 0.5 * hh * q2
    f3, r3 = friction(fr, v3, t3)
    a3 = _acceleration(dev, e1, z3, v3, x3, f3)
    q3 = ca * x3 + cb * v3
    z4 = z + hh * v3
    v4 = v + hh * a3
    t4 = th + hh * r3
    x4 = x + hh * q3
    f4, r4 = friction(fr, v4, t4)
    a4 = _acceleration(dev, e2, z4, v4, x4, f4)
    q4 = ca * x4 + cb * v4
    zn = z + hh / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4)
    vn = v + hh / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    tn = th + hh / 6.0 * (r1 + 2.0 * r2 + 2.0 * r3 + r4)
    xn = x + hh / 6.0 * (q1 + 2.0 * q2 + 2.0 * q3 + q4)
    return zn, vn, tn, xn, a1


@numba.njit(cache=True, inline="always")
def _creep_velocity(layer, g):
    # Quasi-static velocity inside the tanh boundary layer: Fc tanh(beta v) = g.
    tanh_mode, fc, beta, _, _ = layer
    if not tanh_mode:
        return 0.0
    return math.atanh(g / fc) / beta


@numba.njit(cache=True, inline="always")
def _circuit_at(dev, x, w, tau):
    # The circuit state tau after a moment where it was x, the mass moving at
    # the constant (creep or zero) velocity w meanwhile: exact solution of
    # x' = ca x + cb w
    ca, cb = dev[7], dev[8]
    if ca == 0.0:
        return x + cb * w * tau
    forced = -cb * w / ca
    return forced + (x - forced) * math.exp(ca * tau)


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


@numba.njit(cache=True, inline="always")
def _stick_slip_layer(slip, p, m, h):
    """(sticky, layer): whether the event-located integrator runs, and its friction.

    The law declares how ``p`` reads (``stick_slip``). tanh friction takes
    this path only when the step h exceeds twice its relaxation time
    ``tau = m / (Fc beta)``; below that plain RK4 resolves it.
    """
    if slip == STICK_SLIP_SIGN and p[0] > 0.0:
        return True, (False, p[0], 0.0, 0.0, p[0])
    if slip == STICK_SLIP_TANH and p[0] > 0.0:
        tau = m / (p[0] * p[1])
        if h > 2.0 * tau:
            xb = max(8.0, 0.5 * math.log(4.0 * h / tau))
            return True, (True, p[0], p[1], xb / p[1], p[0] * math.tanh(xb))
    return False, (False, 0.0, 0.0, 0.0, 0.0)


@numba.njit(cache=True, inline="always")
def _starting_state(dev, layer, e, z, v, x):
    """(z, v, mode, sgn, x) at t = 0: stuck when at rest (or inside the layer) and
    the non-friction force is held, else slipping in its direction."""
    vb = layer[3]
    if abs(v) <= vb or v == 0.0:
        g = _free_force(dev, e, z, v, x)
        if abs(g) <= layer[4]:
            return z, _creep_velocity(layer, g), _STICK, 1.0, x
        sgn = 1.0 if g > 0 else -1.0
        return z, sgn * vb, _SLIP, sgn, x
    return z, v, _SLIP, 1.0 if v > 0 else -1.0, x


@numba.njit(cache=True, inline="always")
def _breakaway_newton(dev, seg, z, stuck, target, s, b, guess):
    # With a curved (quadratic) input sub-step, or a circuit state decaying
    # meanwhile, g is not linear in time: refine the chord's breakaway time by
    # Newton steps on g(t) = target, kept in [s, b]. ``stuck`` = (x_s, w):
    # the circuit state at s and the (creep) velocity while stuck.
    x_s, w = stuck
    t = guess
    for _ in range(4):
        r = t - seg[0]
        x = _circuit_at(dev, x_s, w, t - s)
        slope = dev[4] * (seg[2] + 2.0 * r * seg[3]) - dev[9] * (dev[7] * x + dev[8] * w)
        if slope == 0.0:
            break
        t -= (_free_force(dev, _input(dev, seg, t), z, 0.0, x) - target) / slope
        t = min(max(t, s), b)
    return t


@numba.njit(cache=True, inline="always")
def _stick(dev, layer, seg, s, b, st):
    """Advance a stick from s: to b, or to breakaway. Returns (s, st).

    With ``z`` frozen and no circuit, g is linear in time (linear hold), so
    breakaway ``|g| = fstick`` is found exactly (a curved sub-step, or a
    circuit state decaying meanwhile, refines the chord's time by Newton
    steps). In tanh mode the mass creeps at the quasi-static velocity
    instead of standing still.
    """
    z, v, mode, sgn, x = st
    tanh_mode, _, _, vb, fstick = layer
    ga = _free_force(dev, _input(dev, seg, s), z, 0.0, x)
    w = _creep_velocity(layer, ga) if tanh_mode else 0.0
    xb = _circuit_at(dev, x, w, b - s)
    gb = _free_force(dev, _input(dev, seg, b), z, 0.0, xb)
    if abs(ga) <= fstick and abs(gb) <= fstick:
        if tanh_mode:
            z += (b - s) * _creep_velocity(layer, 0.5 * (ga + gb))
            v = _creep_velocity(layer, gb)
        return b, (z, v, mode, sgn, xb)
    if abs(ga) > fstick:
        s_new = s
        sgn = 1.0 if ga > 0 else -1.0
    else:
        target = fstick if gb > 0 else -fstick
        frac = (target - ga) / (gb - ga)
        frac = min(max(frac, 0.0), 1.0)
        s_new = s + frac * (b - s)
        if seg[3] != 0.0 or dev[9] * x != 0.0:
            s_new = _breakaway_newton(dev, seg, z, (x, w), target, s, b, s_new)
        sgn = 1.0 if gb > 0 else -1.0
    x_new = _circuit_at(dev, x, w, s_new - s)
    if tanh_mode:
        # creep up to breakaway at the mean quasi-static velocity
        z += (s_new - s) * _creep_velocity(layer, 0.5 * (ga + sgn * fstick))
    return s_new, (z, sgn * vb, _SLIP, sgn, x_new)


@numba.njit(cache=True, inline="always")
def _slip(dev, layer, seg, s, b, st, accept):
    """Slip from s: one RK4 step to b, or up to the velocity's return to the
    layer (located on the step's cubic Hermite interpolant), where the
    non-friction force decides between stick and slip. ``accept`` takes the
    step to b whatever happens in it (the event budget is spent). Returns (s, st).
    """
    z, v, mode, sgn, x = st
    vb = layer[3]
    fr = (layer, sgn)
    hh = b - s
    z1, v1, _, x1, a0 = _rk4(_slip_friction, fr, dev, seg, s, hh, z, v, 0.0, x)
    if sgn * v1 > vb or accept:
        return b, (z1, v1, mode, sgn, x1)
    # velocity reaches the boundary inside the step: locate, redo
    a1 = _acceleration(dev, _input(dev, seg, b), z1, v1, x1, _slip_force(layer, sgn, v1))
    frac = _hermite_root(hh, sgn * v - vb, sgn * a0, sgn * v1 - vb, sgn * a1)
    hs = frac * hh
    z, v, _, x, a0 = _rk4(_slip_friction, fr, dev, seg, s, hs, z, v, 0.0, x)
    s = min(s + hs, b)
    v = sgn * vb
    g = _free_force(dev, _input(dev, seg, s), z, v, x)
    if abs(g) <= layer[4]:
        return s, (z, _creep_velocity(layer, g), _STICK, sgn, x)
    new = 1.0 if g > 0 else -1.0
    if new != sgn:
        sgn = new
        v = sgn * vb  # cross the (zero-width or 1/beta) layer
    return s, (z, v, _SLIP, sgn, x)


@numba.njit(cache=True, inline="always")
def _stick_slip_substep(dev, layer, seg, a, b, tiny, st, hmax):
    """The event-located stick-slip integrator over one sub-step [a, b].

    A slip advances at most ``hmax`` at a time (1 / |ca|: a circuit state
    relaxing faster than the sub-step is resolved, as RK4's stability needs).
    """
    s = a
    budget = _MAX_EVENTS + int((b - a) / hmax)
    for it in range(budget):
        if s >= b:
            break
        if st[2] == _STICK:
            s, st = _stick(dev, layer, seg, s, b, st)
        elif b - s <= tiny:
            break
        else:
            end = b if b - s <= hmax else s + hmax
            s, st = _slip(dev, layer, seg, s, end, st, it == budget - 1)
    return st


@numba.njit(cache=True, inline="always")
def _smooth_substep(dev, fr, seg, a, b, subcycling, z, v, th, x):
    """RK4 over the sub-step [a, b], sub-cycled so that a law with memory and a
    circuit state relax by less than one e-fold per step. Returns (ok, z, v,
    th, x); ok is False when that needs more than the allowed sub-cycles."""
    relax_rate, max_sub = subcycling
    rate = abs(v) * relax_rate + abs(dev[7])
    nc = 1
    if rate > 0.0:
        nc = int(rate * (b - a)) + 1
        if nc > max_sub:
            return False, z, v, th, x
    hh = (b - a) / nc
    for q in range(nc):
        z, v, th, x, _ = _rk4(_law_friction, fr, dev, seg, a + q * hh, hh, z, v, th, x)
    return True, z, v, th, x


@numba.njit(cache=True, inline="always")
def _diverged(outputs, store, first):
    # A rejected candidate: NaN samples from ``first`` on, infinite cost.
    if store:
        for out in outputs:
            for r in range(first, out.shape[0]):
                out[r] = math.nan
    return math.inf, 0.0


@numba.njit(cache=True, inline="always")
def _segment(u, i, j, nsub, curved, a, b):
    """(a, u0, c1, c2): the input over sub-step j = [a, b] of sample interval i.

    ``u`` holds the reconstructed input at every half sub-step (2 nsub + 1
    values per interval, shared ends) when ``curved``; the sub-step is then
    the quadratic through its start, middle and end (exactly linear for a
    linear reconstruction). Otherwise ``u`` holds the samples and the input
    is held constant over the interval (zero-order hold).
    """
    if not curved:
        return (a, u[i], 0.0, 0.0)
    q = 2 * (i * nsub + j)
    ua = u[q]
    um = u[q + 1]
    ub = u[q + 2]
    hm = 0.5 * (b - a)
    return (a, ua, (4.0 * um - 3.0 * ua - ub) / (2.0 * hm), (ua - 2.0 * um + ub) / (2.0 * hm * hm))


@numba.njit(cache=True, inline="always")
def _store(outputs, store, i, z, v, x):
    if store:
        outputs[0][i] = z
        outputs[1][i] = v
        outputs[2][i] = x


@numba.njit(cache=True)
def _run_one(par, relax_rate, state0, friction, drive, scoring, outputs, store):
    """Simulate one parameter set; return the sum of squared errors against zref
    over the samples from index ``skip`` on.

    ``par`` is ``[m, c, k, k3, p..., k2, input offset, output offset, a, b, f]``
    (:data:`MATRIX_COLUMNS`), ``state0`` ``[z0, v0, theta0, x0]``; the error is
    that of ``z + output offset``; ``friction = (kind, fn, stick_slip)``,
    ``drive = (u, dt, nsub, curved, base_input)``, ``scoring = (zref, skip,
    zlim, max_subcycles)`` as built by :func:`run_kernel`; ``outputs`` =
    (z, v, x) rows written when ``store``.
    """
    kind, fn, slip = friction
    u, dt, nsub, curved, base_input = drive
    zref, skip, zlim, max_sub = scoring
    m = par[0]
    p = par[4 : 4 + N_KERNEL_PARAMETERS]
    ca, cb, cf = par[_OUTPUT_OFFSET + 1], par[_OUTPUT_OFFSET + 2], par[_OUTPUT_OFFSET + 3]
    dev = (m, par[1], par[2], par[3], -m if base_input else 1.0, par[_K2], par[_INPUT_OFFSET],
           ca, cb, cf)  # fmt: skip
    z_off = par[_OUTPUT_OFFSET]
    h = dt / nsub
    hmax = 1.0 / abs(ca) if ca != 0.0 else math.inf
    n = (u.shape[0] - 1) // (2 * nsub) + 1 if curved else u.shape[0]
    have_ref = zref.shape[0] == n

    sticky, layer = _stick_slip_layer(slip, p, m, h)
    if sticky and abs(ca) * h > max_sub:
        # a circuit far faster than the step: as many slip chunks per sub-step
        # as a law's sub-cycles, rejected alike
        return _diverged(outputs, store, 0)
    if slip == STICK_SLIP_SIGN and not sticky or slip == STICK_SLIP_TANH and p[0] == 0.0:
        kind = KERNEL_NONE  # Fc = 0: viscous only
    law = (kind, fn, p)
    z, v, th, x = state0[0], state0[1], state0[2], state0[3]
    st = (z, v, _SLIP, 1.0, x)
    if sticky:
        st = _starting_state(dev, layer, dev[4] * (u[0] - dev[6]), z, v, x)
        v = st[1]

    sse = 0.0
    sres = 0.0  # sum of the errors, for a profiled output offset
    if have_ref and skip == 0:
        sse = (z + z_off - zref[0]) ** 2
        sres = z + z_off - zref[0]
    _store(outputs, store, 0, z, v, x)
    for i in range(n - 1):
        for j in range(nsub):
            a = j * h
            b = dt if j == nsub - 1 else a + h
            seg = _segment(u, i, j, nsub, curved, a, b)
            if sticky:
                st = _stick_slip_substep(dev, layer, seg, a, b, 1e-14 * dt, st, hmax)
                z, v, x = st[0], st[1], st[4]
            else:
                ok, z, v, th, x = _smooth_substep(
                    dev, law, seg, a, b, (relax_rate, max_sub), z, v, th, x
                )
                if not ok:
                    # bristles or a circuit stiffer than the step resolves: rejected as diverged
                    return _diverged(outputs, store, i + 1)
        if not (abs(z) < zlim) or not (abs(v) < math.inf) or not (abs(x) < math.inf):
            return _diverged(outputs, store, i + 1)
        if have_ref and i + 1 >= skip:
            err = z + z_off - zref[i + 1]
            sse += err * err
            sres += err
        _store(outputs, store, i + 1, z, v, x)
    return sse, sres


@numba.njit(cache=True, parallel=True)
def _run_batch(params, relax, state0, friction, drive, scoring, out_z, out_v, out_x, store):
    # Without stored responses (store False) the outputs are (1, 1), never written.
    n_pop = params.shape[0]
    sums = np.empty((n_pop, 2))
    for i in numba.prange(n_pop):
        if store:
            outputs = (out_z[i], out_v[i], out_x[i])
        else:
            outputs = (out_z[0], out_v[0], out_x[0])
        sse, sres = _run_one(
            params[i], relax[i], state0[i], friction, drive, scoring, outputs, store
        )
        sums[i, 0] = sse
        sums[i, 1] = sres
    return sums


def _law(friction):
    """The law class named ``friction`` (``none``: None); a law class or None passes through."""
    if friction is None or isinstance(friction, type) and issubclass(friction, FrictionModel):
        return friction
    if friction not in FRICTION_KINDS:
        raise ValueError(f"`friction` must be one of {', '.join(FRICTION_KINDS)}; got {friction!r}")
    return None if friction == "none" else FRICTION_MODELS[friction]


def parameter_matrix(parameters: dict, friction, circuit=None) -> np.ndarray:
    """Kernel parameter rows ``[m, c, k, k3, friction..., k2, offsets, a, b, f]``.

    Parameters
    ----------
    parameters : dict
        ``m, c, k, k3`` and the friction parameters (see
        :data:`FRICTION_PARAMETERS`), optionally :data:`EXTRA_PARAMETERS`
        (default 0); scalars or 1-D arrays of one length.
    friction : str or FrictionModel subclass
        One of :data:`FRICTION_KINDS`, or a law class.
    circuit : (a, b, f), optional
        A circuit state ``x' = a x + b z'`` with the force ``f x`` on the mass
        (:meth:`~randvib.models.coupling.Coupling.circuit_equation`), scalars
        or 1-D arrays; default none.
    """
    law = _law(friction)
    friction = "none" if law is None else law.name
    names = DEVICE_PARAMETERS + (() if law is None else law.parameter_names())
    missing = [name for name in names if name not in parameters]
    if missing:
        raise ValueError(
            f"missing parameter(s) {missing} for friction {friction!r}; needed: {', '.join(names)}"
        )
    extra = sorted(set(parameters) - set(names) - set(EXTRA_PARAMETERS))
    if extra:
        raise ValueError(
            f"unknown parameter(s) {extra} for friction {friction!r}; allowed: "
            f"{', '.join(names + EXTRA_PARAMETERS)}"
        )
    extras = [name for name in EXTRA_PARAMETERS if name in parameters]
    labels = names + tuple(extras)
    columns = [np.atleast_1d(check_finite(name, parameters[name])) for name in labels]
    where = list(range(len(names))) + [_K2 + EXTRA_PARAMETERS.index(name) for name in extras]
    if circuit is not None:
        labels += ("circuit a", "circuit b", "circuit f")
        pairs = zip(labels[-3:], circuit, strict=True)
        columns += [np.atleast_1d(check_finite(name, x)) for name, x in pairs]
        where += list(CIRCUIT_COLUMNS)
    n_pop = max(col.shape[0] for col in columns)
    out = np.zeros((n_pop, MATRIX_COLUMNS))
    for j, col in zip(where, columns, strict=True):
        if col.ndim != 1 or col.shape[0] not in (1, n_pop):
            name = labels[where.index(j)]
            raise ValueError(f"parameter `{name}` must be a scalar or a 1-D array of {n_pop}")
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
    x0=0.0,
    reference=None,
    skip=0,
    response_limit=np.inf,
    store=True,
    max_subcycles=4096,
    fine=None,
    profile_offset=False,
):
    """Low-level batched call on validated arguments.

    Parameters
    ----------
    matrix : ndarray, shape (n_pop, MATRIX_COLUMNS)
        Parameter rows from :func:`parameter_matrix`.
    friction : str or FrictionModel subclass or None
    drive, base_input
        From :func:`~randvib.identification.input_reconstruction.driving_signal`.
    dt : float
        Sample interval (s).
    z0, v0, theta0, x0 : float or ndarray
        Initial displacement (m), velocity (m/s), bristle state (m) and
        circuit state (its unit), one per row or shared.
    reference : ndarray, optional
        Measured z (m) to score the sum of squared errors against, from
        sample ``skip`` on.
    store : bool
        Keep the responses (False during a search: only the errors are needed).
    max_subcycles : int
        Sub-cycles per sub-step a law with memory may take before the
        candidate is rejected.
    fine : ndarray, optional
        ``reconstruct_input(drive, dt, substeps, hold)`` computed once by a
        caller that runs the kernel many times.
    profile_offset : bool
        Return the error sums minimised over a constant output offset
        (added to the rows' own): ``sum e^2 - (sum e)^2 / N``.

    Returns
    -------
    KernelRun
        ``sse`` (n_pop,): sums of squared errors (0 without a reference; inf
        when diverged); ``z``, ``v``, ``x`` (n_pop, n): displacement,
        velocity and circuit state at the samples, or None when not stored.
    """
    law = _law(friction)
    n_pop = matrix.shape[0]
    n = drive.shape[0]
    state0 = np.empty((n_pop, 4))
    for j, value in enumerate((z0, v0, theta0, x0)):
        state0[:, j] = np.broadcast_to(np.asarray(value, dtype=float), (n_pop,))
    # writeable copies of read-only input: a read-only array is another compiled signature
    zref = np.empty(0) if reference is None else np.require(reference, float, ["C", "W"])
    shape = (n_pop, n) if store else (1, 1)
    out_z = np.empty(shape)
    out_v = np.empty(shape)
    out_x = np.empty(shape)
    kernel_friction = (
        KERNEL_NONE if law is None else law.kernel_code,
        kernel_callback(law),
        STICK_SLIP_NONE if law is None else law.stick_slip,
    )
    relax = np.zeros(n_pop) if law is None else law.kernel_relaxation_rate(matrix[:, 4:_K2])
    if hold not in HOLDS:
        raise ValueError(f"`hold` must be one of {', '.join(HOLDS)}; got {hold!r}")
    if fine is not None and hold != "zero":
        samples = fine  # the caller's reconstruct_input(drive, dt, substeps, hold), reused
    else:
        samples = drive if hold == "zero" else reconstruct_input(drive, dt, substeps, hold)
    samples = np.require(samples, float, ["C", "W"])
    drive_args = (samples, float(dt), int(substeps), hold != "zero", bool(base_input))
    scoring = (zref, int(skip), float(response_limit), int(max_subcycles))
    sums = _run_batch(
        np.ascontiguousarray(matrix),
        np.ascontiguousarray(relax, dtype=float),
        state0,
        kernel_friction,
        drive_args,
        scoring,
        out_z,
        out_v,
        out_x,
        bool(store),
    )
    sse = sums[:, 0]
    if profile_offset and zref.size:
        # the best constant added to z: J's minimum over the output offset
        sse = sse - sums[:, 1] ** 2 / (zref.size - int(skip))
    if not store:
        return KernelRun(sse, None, None, None)
    return KernelRun(sse, out_z, out_v, out_x)


class KernelRun(NamedTuple):
    """What :func:`run_kernel` returns: error sums and the stored responses."""

    sse: np.ndarray
    z: np.ndarray | None
    v: np.ndarray | None
    x: np.ndarray | None
