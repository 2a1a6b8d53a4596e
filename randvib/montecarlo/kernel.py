"""Compiled ensemble kernel: one time loop for every scheme and friction model.

Paths are processed in chunks of :data:`LANES` independent paths that advance
together, step by step: the per-step dependency chain of one path is short
and latency-bound, so interleaving a few paths keeps the core busy. Chunks run
in parallel (``numba.prange``). Every path draws from its own stream
(:mod:`randvib.montecarlo.rng`) and owns its accumulators, and the cross-path reductions
happen afterwards in path order, so results are bit-identical for any number
of threads and any batching of paths.

Two step functions: :func:`scheme_step` for the white-noise device with a
resistive (viscous) circuit, the compile-time fast path, and
:func:`auxiliary_step` for the device with up to :data:`N_AUX` linear
auxiliary states (:class:`Auxiliary`: an excitation's shaping filter and/or a
circuit's current or voltage), one compiled path for every excitation x
coupling combination. A diode bridge (:class:`Rectifier`) has its own
steps in :mod:`randvib.montecarlo.rectified_kernel`; the device's drift they
share with the steps here is in :mod:`randvib.montecarlo.drift`.

The loop is compiled twice at most (:func:`run_ensemble`): a lean signature
with no optional group (white noise, resistive circuit; every optional branch
pruned when compiling) and a full one that takes every group (filter or
circuit, event, bridge, tones and shocks), a missing one as an empty
stand-in recognised at run time; every combination shares it, so a fresh
checkout compiles it once (tests/_warm_kernels.py warms both before a
parallel test run).

Memory is O(n_paths): per-path running sums only, unless histograms or
recorded histories are requested.
"""

from __future__ import annotations

import functools
from typing import NamedTuple, get_type_hints

import numba
import numpy as np

from randvib.montecarlo.drift import _acceleration
from randvib.montecarlo.rectified_kernel import (
    bridge_constants,
    rectified_step,
    rectified_white_step,
)
from randvib.montecarlo.rng import seed_path_state, standard_normal
from randvib.montecarlo.stop_flag import stop_requested

#: Paths advanced together inside one chunk.
LANES = 8

# Columns of the per-path accumulator array (time averages over the window).
ACC_V2 = 0  # mean v^2 ((m/s)^2)
ACC_Z2 = 1  # mean z^2 (m^2)
ACC_ABS_V = 2  # mean |v| (m/s)
ACC_VF = 3  # mean v F (W): friction power
ACC_VDW = 4  # sum v_n dW_n / T (m/s / sqrt(s)): Ito integral, mean exactly 0
ACC_H0 = 5  # mechanical energy at the start of the window (J)
ACC_H1 = 6  # mechanical energy at the end of the window (J)
ACC_COMP_V2 = 7  # companion (same noise, no friction) mean v^2
ACC_COMP_Z2 = 8  # companion mean z^2
ACC_CIRCUIT2 = 9  # mean x^2 of the circuit state (A^2 or V^2); 0 without one
ACC_BEYOND = 10  # fraction of the window's steps with |z| > stroke
ACC_FIRST_HIT = 11  # time (s) of the first state with |z| > stroke from t = 0; -1: none
ACC_STORED = 12  # mean power into the bridge's output, battery or storage load (W); 0 without
ACC_COIL_LOSS = 13  # mean R_C i^2 of a rectified coil (W); 0 without
ACC_DIODE_LOSS = 14  # mean 2 V_d |i| of a bridge (W); 0 without
ACC_V_OUT = 15  # mean output voltage of a bridge, V_b or V_C (V); 0 without
ACC_PEAK = 16  # largest |z| over the window's states, its end included (m); not an average
ACC_UPCROSS = 17  # number of the window's steps on which |z| rises through the stroke
N_ACC = 18


class PathAverages:
    """Named view of the kernel's per-path accumulators (columns ``ACC_*``).

    The kernel returns one row of time averages per path; consumers read them
    through these names so that the column layout stays the kernel's business.

    Parameters
    ----------
    per_path : ndarray, shape (n_paths, N_ACC)
        As returned by :func:`run_ensemble` (or stored by a sweep).
    """

    def __init__(self, per_path):
        self.per_path = per_path

    def _col(self, index):
        return self.per_path[:, index]

    @property
    def v2(self):
        """Time average of v^2 per path ((m/s)^2)."""
        return self._col(ACC_V2)

    @property
    def z2(self):
        """Time average of z^2 per path (m^2)."""
        return self._col(ACC_Z2)

    @property
    def abs_v(self):
        """Time average of |v| per path (m/s)."""
        return self._col(ACC_ABS_V)

    @property
    def friction_power(self):
        """Time average of v F per path (W)."""
        return self._col(ACC_VF)

    @property
    def ito_integral(self):
        """(1/T) sum v_n dW_n per path (m/s^1.5): mean exactly zero."""
        return self._col(ACC_VDW)

    def energy_change(self, window):
        """(H(T) - H(0)) / T per path (W) over an averaging ``window`` T (s)."""
        return (self._col(ACC_H1) - self._col(ACC_H0)) / window

    @property
    def companion_v2(self):
        """The friction-free companion's time average of v^2 ((m/s)^2); 0 without one."""
        return self._col(ACC_COMP_V2)

    @property
    def companion_z2(self):
        """The friction-free companion's time average of z^2 (m^2); 0 without one."""
        return self._col(ACC_COMP_Z2)

    @property
    def circuit_square(self):
        """Time average of the circuit state's square per path (i^2 in A^2, V^2 in V^2)."""
        return self._col(ACC_CIRCUIT2)

    @property
    def beyond_stroke(self):
        """Fraction of the window's steps with |z| > stroke per path (0 without a stroke)."""
        return self._col(ACC_BEYOND)

    @property
    def first_hit_time(self):
        """Time (s) of the first state with |z| > stroke, from t = 0; -1 where none was."""
        return self._col(ACC_FIRST_HIT)

    @property
    def stored_power(self):
        """Time average of the power into a bridge's output per path (W); 0 without one."""
        return self._col(ACC_STORED)

    @property
    def coil_loss(self):
        """Time average of R_C i^2 of a rectified coil per path (W); 0 without one."""
        return self._col(ACC_COIL_LOSS)

    @property
    def diode_loss(self):
        """Time average of 2 V_d |i| of a bridge per path (W); 0 without one."""
        return self._col(ACC_DIODE_LOSS)

    @property
    def peak(self):
        """Largest |z| per path over the window's states, its last included (m)."""
        return self._col(ACC_PEAK)

    @property
    def upcrossings(self):
        """Number of up-crossings of |z| through the stroke per path in the window (both ends)."""
        return self._col(ACC_UPCROSS)

    @property
    def output_voltage(self):
        """Time average of a bridge's output voltage per path, V_b or V_C (V); 0 without one."""
        return self._col(ACC_V_OUT)

    def energy_balance_controls(self, window):
        """The two zero-mean controls of the energy balance: Ito integral, energy change."""
        return [self.ito_integral, self.energy_change(window)]


#: How often (steps) the kernel checks for a non-finite state.
CHECK_EVERY = 256


# ------------------------------------------------------------- argument groups
# The compiled loop takes its inputs in these small groups (numba accepts
# named tuples, heterogeneous ones included, and reads their fields by name at
# compile time). Build them with the functions below, which fix each field's
# type: a field that is sometimes an int and sometimes a float would compile,
# and cache, a second copy of the kernel.


class Device(NamedTuple):
    """The oscillator's coefficients (paper Eq. 15-17)."""

    m: float  #: mass (kg)
    c: float  #: total viscous damping c_m + c_e (Ns/m)
    k: float  #: linear stiffness (N/m)
    k3: float  #: cubic stiffness (N/m^3)
    noise_amp: float  #: sqrt(S/2) (m/s^1.5): the velocity's diffusion


class Friction(NamedTuple):
    """A friction law's compiled form (:func:`randvib.models.friction.kernel_arguments`)."""

    kind: int  #: kernel code of the law
    p: np.ndarray  #: float64[N_KERNEL_PARAMETERS] parameters
    fn: object  #: compiled callback, used for KERNEL_GENERIC laws only


class Timing(NamedTuple):
    """``n_steps`` steps of ``dt`` (s), the first ``n_burn`` outside the averaging window."""

    dt: float
    n_steps: int
    n_burn: int


class Paths(NamedTuple):
    """Paths ``first`` to ``first + count - 1``; path i draws from stream (seed, i)."""

    seed: np.uint64
    first: int
    count: int


class Start(NamedTuple):
    """Initial state: (z, v) (m, m/s), or with ``random`` N(0, z^2) x N(0, v^2)."""

    random: bool
    z: float
    v: float


class Companion(NamedTuple):
    """The friction-free companion: integrated alongside when ``enabled``.

    It starts at (z, v) or, when the device's :class:`Start` is random, from
    the device's two normal draws scaled by (z, v) (its own stationary spread).
    """

    enabled: bool
    z: float
    v: float


class Recording(NamedTuple):
    """What is recorded besides the time averages.

    Histograms of (z, v) over the window in ``hist_bins`` bins on
    [hist_lo, hist_hi) (``hist_bins`` 0: none); (z, v, theta) of the first
    ``n_record`` paths every ``every`` steps, initial state included; the
    stroke statistics (columns ``ACC_BEYOND``, ``ACC_FIRST_HIT``) against
    ``stroke`` (m; inf: none).
    """

    hist_lo: np.ndarray  #: float64[2]
    hist_hi: np.ndarray  #: float64[2]
    hist_bins: int
    n_record: int
    every: int
    stroke: float


class Auxiliary(NamedTuple):
    """Linear auxiliary states integrated with the device: shaping filter and circuit.

    Up to :data:`N_AUX` states ``x`` with

        dx = (A x + B v) dt + G sqrt(S/2) dW,    dv = (... - C x) dt + g_v sqrt(S/2) dW,

    one block for every excitation x coupling combination
    (:func:`auxiliary_step`). A rational spectrum's shaping filter
    (band-pass, Kanai-Tajimi; :meth:`randvib.models.excitation.Excitation.shaping_filter`)
    is driven by the noise (G) and puts its output, the base acceleration,
    into the device's acceleration through C (paper Eq. 18, m z'' = ... - m y);
    then g_v = 0. A dynamic circuit (:mod:`randvib.models.coupling`) is driven
    by the velocity (B) and pushes back with f x / m through C; under white
    noise g_v = 1. Unused states have zero rows and columns. White noise with
    a resistive circuit has no block at all (``None``: :func:`scheme_step`).
    """

    n: int  #: number of states in use, 1 .. N_AUX (the random start draws n normals)
    coefficients: np.ndarray  #: float64[N_AUX_COEFFICIENTS]: A (row-major), B, G, C, g_v
    square: np.ndarray  #: float64[N_AUX]: row P; the kernel averages (P x)^2 (ACC_CIRCUIT2)
    start: np.ndarray  #: float64[N_AUX, N_AUX]: Cholesky factor of the states' start covariance


#: Largest number of auxiliary states (a 2-state filter and a 1-state circuit).
N_AUX = 3
#: Length of :attr:`Auxiliary.coefficients`: A (9), B (3), G (3), C (3), g_v (1).
N_AUX_COEFFICIENTS = 19


#: No given starting states (:attr:`Noise.start`): the :class:`Start` decides.
NO_START = np.zeros((0, 0))
#: Columns of :attr:`Noise.start`: z (m), v (m/s) and the auxiliary states x1 .. x3.
N_START = 2 + 3


class Noise(NamedTuple):
    """Where the randomness comes from: the Brownian increments and, optionally, the start.

    ``dw`` (n_paths, n_steps) given increments (s^0.5), or shape (0, 0) to draw
    them from the paths' streams with the ziggurat tables ``ki, wi, fi``
    (:mod:`randvib.montecarlo.rng`). ``start`` (n_paths, :data:`N_START`)
    gives each path its own starting state (z, v, x1, x2, x3), in place of
    :class:`Start`'s (the rare-event estimators express the stationary start
    through standard normals, :mod:`randvib.montecarlo.path_simulator`), or
    shape (0, 0) (:data:`NO_START`) for none.
    """

    dw: np.ndarray
    ki: np.ndarray
    wi: np.ndarray
    fi: np.ndarray
    start: np.ndarray = NO_START


class Transient(NamedTuple):
    """An event's envelope per step, its start, and what is kept of each path at given times.

    For :func:`randvib.simulate_transient`: step n's input is multiplied by
    ``gain[n]`` (the envelope over the step, :mod:`randvib.montecarlo.transient`),
    either the noise increment itself (``scale_noise``: white noise, whose
    gain is the step's RMS envelope, and synthesised input) or the shaping
    filter's output where it enters the device's acceleration (the C entries
    marked by ``filter_mask``; the filter itself runs stationary). The device
    starts from the fixed :class:`Start`, the first ``n_start`` auxiliary
    (filter) states from N(0, L L^T), L = ``start``. The kernel writes, per
    path of the batch, (z, v, P x, max |z| so far) at the state indices
    ``snap_steps`` (state j is at t = j dt) into ``snapshots``, and the peak
    |z| over the run, int v^2 dt and int (P x)^2 dt (trapezoid rule) into
    ``event``. Build it with :func:`transient_group`, which fixes the types.
    """

    gain: np.ndarray  #: float64[n_steps]
    scale_noise: bool
    filter_mask: np.ndarray  #: float64[N_AUX]: 1.0 where the state's C entry carries e(t)
    n_start: int
    start: np.ndarray  #: float64[N_AUX, N_AUX]
    snap_steps: np.ndarray  #: int64[n_times], increasing
    snapshots: np.ndarray  #: float64[count, n_times, N_SNAP] (written)
    event: np.ndarray  #: float64[count, N_EVENT] (written)


#: Columns of :attr:`Transient.snapshots`: z (m), v (m/s), P x (A or V; 0 without a
#: circuit), max |z| from t = 0 (m).
class Rectifier(NamedTuple):
    """A full-wave bridge and its output (:mod:`randvib.models.rectifier`).

    ``kind`` 1: a coil (algebraic current, L = 0), 2: a piezo element (state
    V_p), 3: a coil with inductance (state i); ``output`` 0: a battery, 1: a storage capacitor with its load (state
    V_C). ``p = (gain, r_or_cp, V_d, V_b, C, R_L, I_s, n V_T, L)`` (I_s = 0: a
    constant drop V_d; I_s > 0: Shockley diodes; L the coil's inductance):
    :meth:`randvib.models.rectifier.Rectified.kernel_parameters`.
    ``v_c0`` (V): the storage capacitor's voltage at t = 0.
    """

    kind: int
    output: int
    p: np.ndarray
    v_c0: float


class Forcing(NamedTuple):
    """Deterministic and sampled base acceleration added to any input: tones and shocks.

    Step n's velocity increment gets ``u_n = kicks[i, n] - sum_q gain_q cos(omega_q
    (n + 1/2) dt + phase[i, q])`` for path i of the batch: the exact integral of
    -a(t) over the step for the tones a = A_q cos(omega_q t + phase), with
    ``gain_q = 2 A_q sin(omega_q dt / 2) / omega_q`` (one cosine per tone per
    step), and for a shock train its exact step integrals ``kicks``
    (:mod:`randvib.montecarlo.forcing`). The kernel gives it to the velocity in two
    halves, before and after the scheme's step (Strang splitting: second order
    in dt, like the scheme), whatever the step (white noise, filter, circuit,
    bridge). Build it with :func:`randvib.montecarlo.forcing.ForcingInput.group`.
    """

    omega: np.ndarray  #: float64[n_tones] (rad/s)
    gain: np.ndarray  #: float64[n_tones] (m/s)
    phase: np.ndarray  #: float64[count, n_tones] (rad)
    kicks: np.ndarray  #: float64[count, n_steps] (m/s), or shape (0, 0) without shocks


SNAP_Z, SNAP_V, SNAP_X, SNAP_PEAK = 0, 1, 2, 3
N_SNAP = 4
#: Columns of :attr:`Transient.event`: peak |z| over the run (m), int v^2 dt
#: ((m/s)^2 s), int (P x)^2 dt (A^2 s or V^2 s).
EVENT_PEAK, EVENT_V2, EVENT_X2 = 0, 1, 2
N_EVENT = 3


def transient_group(gain, scale_noise, filter_mask, n_start, start, snap_steps, count):
    """A :class:`Transient` with its output arrays for ``count`` paths, each field typed."""
    snap_steps = np.ascontiguousarray(snap_steps, dtype=np.int64)
    return Transient(
        np.ascontiguousarray(gain, dtype=float),
        bool(scale_noise),
        np.ascontiguousarray(filter_mask, dtype=float),
        int(n_start),
        np.ascontiguousarray(start, dtype=float),
        snap_steps,
        np.zeros((count, snap_steps.size, N_SNAP)),
        np.zeros((count, N_EVENT)),
    )


def _empty_groups():
    """The full loop's stand-ins for missing optional groups (:func:`run_ensemble`)."""
    square = np.zeros((N_AUX, N_AUX))
    auxiliary = Auxiliary(0, np.zeros(N_AUX_COEFFICIENTS), np.zeros(N_AUX), square)
    transient = transient_group(np.zeros(0), False, np.zeros(N_AUX), 0, square, (), 0)
    # kind 0: no bridge; ones, so that the loop's set-up divides by no zero
    rectifier = Rectifier(0, 0, np.ones(9), 0.0)
    forcing = Forcing(np.zeros(0), np.zeros(0), np.zeros((0, 0)), np.zeros((0, 0)))
    return auxiliary, transient, rectifier, forcing


#: No auxiliary states (``n`` 0), no event (no steps' gains), no bridge (``kind`` 0), no
#: tones and no shocks: what the full loop gets in place of a missing group, each typed
#: as the real ones (one compiled signature for every combination of groups).
NO_AUXILIARY, NO_TRANSIENT, NO_RECTIFIER, NO_FORCING = _empty_groups()


@functools.cache
def _field_types(group) -> dict:
    """The declared field types of an argument group (read once per group, not per run:
    ``get_type_hints`` evaluates the annotations anew at every call, about 1 ms a run)."""
    return get_type_hints(group)


def pack(group, *values):
    """``group(*values)`` with each value cast to its field's declared type.

    Parameters
    ----------
    group : type
        One of the argument groups above (:class:`Device`, :class:`Timing`, ...).
    *values
        Field values in order; floats, ints, bools and the uint64 seed are cast,
        arrays made contiguous float64 (the RNG tables are passed as they are).
    """
    cast = {float: float, int: int, bool: bool, np.uint64: np.uint64}
    hints = _field_types(group)
    out = []
    for name, value in zip(group._fields, values, strict=True):
        kind = hints[name]
        if kind in cast:
            value = cast[kind](value)
        elif kind is np.ndarray and group is not Noise:
            value = np.ascontiguousarray(value, dtype=float)
        out.append(value)
    return group(*out)


@numba.njit(cache=True, inline="always")
def scheme_step(z, v, theta, dt, noise, weights, drift, kind, p, fn):
    """One step of the additive-noise scheme with drift weights ``(b1, b2)``.

    The single definition of every integrator's step
    (:class:`randvib.montecarlo.integrators.Integrator`): Euler predictor
    ``x_p = x + f(x) dt + g dW`` and update
    ``x + (b1 f(x) + b2 f(x_p)) dt + g dW``; ``b2 = 0`` skips the predictor
    (Euler-Maruyama), ``b1 = b2 = 1/2`` is stochastic Heun. The friction-free
    companion takes the same step with friction kind 0.

    Parameters
    ----------
    z, v, theta : float
        State: displacement (m), velocity (m/s), friction state (law's unit).
    dt : float
        Step (s).
    noise : float
        Velocity increment of the step, sqrt(S/2) dW (m/s).
    weights : (float, float)
        ``(b1, b2)`` (:attr:`Integrator.kernel_weights`).
    drift : (float, float, float, float)
        ``(1/m, c, k, k3)`` (1/kg, Ns/m, N/m, N/m^3).
    kind, p, fn : int, float64[:], callback
        The friction law (:class:`Friction`); the companion passes kind 0.
        Passed apart, not as a tuple: a tuple holding an array costs a
        reference-count update per step (a third slower, measured).

    Returns
    -------
    z, v, theta : float
        State after the step.
    force : float
        Friction force at the start of the step (N), for the accumulators.
    """
    b1, b2 = weights
    acc1, rate1, force = _acceleration(z, v, theta, drift, kind, p, fn)
    if b2 == 0.0:
        return z + b1 * v * dt, v + b1 * acc1 * dt + noise, theta + b1 * rate1 * dt, force
    zp = z + v * dt
    vp = v + acc1 * dt + noise
    tp = theta + rate1 * dt
    acc2, rate2, _ = _acceleration(zp, vp, tp, drift, kind, p, fn)
    return (
        z + (b1 * v + b2 * vp) * dt,
        v + (b1 * acc1 + b2 * acc2) * dt + noise,
        theta + (b1 * rate1 + b2 * rate2) * dt,
        force,
    )


@numba.njit(cache=True, inline="always")
def auxiliary_step(z, v, theta, x1, x2, x3, dt, noise, weights, drift, kind, p, fn, block):
    """:func:`scheme_step` for the device with linear auxiliary states (filter, circuit).

    The augmented state (z, v, theta, x1, x2, x3) takes the same additive-noise
    step: the noise increment enters the velocity with the gain g_v and the
    auxiliary states with G, the auxiliary states are driven by A x + B v,
    and the device's acceleration gets -C x (:class:`Auxiliary`). The block is
    linear, so the scheme's orders hold for the augmented system and
    :meth:`Integrator.linear_recursion` gives its exact recursion on a linear
    device. With a 2-state filter alone (third state, B and g_v zero) every
    operation of the former filter-only step is done in the same order plus
    exact zeros, so its results are bit for bit those of that step.

    Parameters
    ----------
    z, v, theta, dt, noise, weights, drift, kind, p, fn
        As for :func:`scheme_step`; ``noise`` is sqrt(S/2) dW.
    x1, x2, x3 : float
        Auxiliary states (filter states, circuit current (A) or voltage (V)).
    block : tuple of 19 floats
        ``(a11, ..., a33, b1, b2, b3, g1, g2, g3, c1, c2, c3, g_v)`` of
        :class:`Auxiliary`.

    Returns
    -------
    z, v, theta, x1, x2, x3 : float
        State after the step.
    force : float
        Friction force at the start of the step (N).
    """
    b1, b2 = weights
    a11, a12, a13, a21, a22, a23, a31, a32, a33 = block[0:9]
    bv1, bv2, bv3, g1, g2, g3, c1, c2, c3, gv = block[9:19]
    acc1, rate1, force = _acceleration(z, v, theta, drift, kind, p, fn)
    acc1 -= c1 * x1 + c2 * x2 + c3 * x3
    d1 = a11 * x1 + a12 * x2 + a13 * x3 + bv1 * v
    d2 = a21 * x1 + a22 * x2 + a23 * x3 + bv2 * v
    d3 = a31 * x1 + a32 * x2 + a33 * x3 + bv3 * v
    nv = gv * noise
    if b2 == 0.0:
        return (
            z + b1 * v * dt,
            v + b1 * acc1 * dt + nv,
            theta + b1 * rate1 * dt,
            x1 + b1 * d1 * dt + g1 * noise,
            x2 + b1 * d2 * dt + g2 * noise,
            x3 + b1 * d3 * dt + g3 * noise,
            force,
        )
    zp = z + v * dt
    vp = v + acc1 * dt + nv
    tp = theta + rate1 * dt
    x1p = x1 + d1 * dt + g1 * noise
    x2p = x2 + d2 * dt + g2 * noise
    x3p = x3 + d3 * dt + g3 * noise
    acc2, rate2, _ = _acceleration(zp, vp, tp, drift, kind, p, fn)
    acc2 -= c1 * x1p + c2 * x2p + c3 * x3p
    e1 = a11 * x1p + a12 * x2p + a13 * x3p + bv1 * vp
    e2 = a21 * x1p + a22 * x2p + a23 * x3p + bv2 * vp
    e3 = a31 * x1p + a32 * x2p + a33 * x3p + bv3 * vp
    return (
        z + (b1 * v + b2 * vp) * dt,
        v + (b1 * acc1 + b2 * acc2) * dt + nv,
        theta + (b1 * rate1 + b2 * rate2) * dt,
        x1 + (b1 * d1 + b2 * e1) * dt + g1 * noise,
        x2 + (b1 * d2 + b2 * e2) * dt + g2 * noise,
        x3 + (b1 * d3 + b2 * e3) * dt + g3 * noise,
        force,
    )


@numba.njit(cache=True, inline="always")
def filter_step(z, v, theta, x1, x2, dt, noise, weights, drift, kind, p, fn, block):
    """:func:`auxiliary_step` for a 2-state shaping filter alone (no circuit, g_v = 0).

    The same operations in the same order without the third state's and the
    velocity drive's exact zeros, so the results are those of
    :func:`auxiliary_step` bit for bit, at the cost of a 2-state filter.
    """
    b1, b2 = weights
    a11, a12, a21, a22 = block[0], block[1], block[3], block[4]
    g1, g2, c1, c2 = block[12], block[13], block[15], block[16]
    acc1, rate1, force = _acceleration(z, v, theta, drift, kind, p, fn)
    acc1 -= c1 * x1 + c2 * x2
    r1 = a11 * x1 + a12 * x2
    r2 = a21 * x1 + a22 * x2
    if b2 == 0.0:
        return (
            z + b1 * v * dt,
            v + b1 * acc1 * dt,
            theta + b1 * rate1 * dt,
            x1 + b1 * r1 * dt + g1 * noise,
            x2 + b1 * r2 * dt + g2 * noise,
            force,
        )
    zp = z + v * dt
    vp = v + acc1 * dt
    tp = theta + rate1 * dt
    x1p = x1 + r1 * dt + g1 * noise
    x2p = x2 + r2 * dt + g2 * noise
    acc2, rate2, _ = _acceleration(zp, vp, tp, drift, kind, p, fn)
    acc2 -= c1 * x1p + c2 * x2p
    return (
        z + (b1 * v + b2 * vp) * dt,
        v + (b1 * acc1 + b2 * acc2) * dt,
        theta + (b1 * rate1 + b2 * rate2) * dt,
        x1 + (b1 * r1 + b2 * (a11 * x1p + a12 * x2p)) * dt + g1 * noise,
        x2 + (b1 * r2 + b2 * (a21 * x1p + a22 * x2p)) * dt + g2 * noise,
        force,
    )


@numba.njit(cache=True, inline="always")
def _scaled_block(block, mask, gain):
    """The auxiliary block with the masked (filter) C entries times ``gain``: e(t) C x_f."""
    return (
        block[0], block[1], block[2], block[3], block[4], block[5], block[6], block[7],
        block[8], block[9], block[10], block[11], block[12], block[13], block[14],
        block[15] * (1.0 + mask[0] * (gain - 1.0)),
        block[16] * (1.0 + mask[1] * (gain - 1.0)),
        block[17] * (1.0 + mask[2] * (gain - 1.0)),
        block[18],
    )  # fmt: skip


@numba.njit(cache=True, inline="always")
def _drawn_states(rng, j, ki, wi, fi, chol, n):
    """(x1, x2, x3) = L (n1, n2, n3) for the first ``n`` states, from lane j's stream."""
    x1 = x2 = x3 = 0.0
    if n > 0:
        n1 = standard_normal(rng, j, ki, wi, fi)
        x1 = chol[0, 0] * n1
        if n > 1:
            n2 = standard_normal(rng, j, ki, wi, fi)
            x2 = chol[1, 0] * n1 + chol[1, 1] * n2
            if n > 2:
                n3 = standard_normal(rng, j, ki, wi, fi)
                x3 = chol[2, 0] * n1 + chol[2, 1] * n2 + chol[2, 2] * n3
    return x1, x2, x3


@numba.njit(cache=True, inline="always")
def _snapshots(snapshots, snap, k, state, start, lanes, z, v, square, peak):
    """Write the lanes' (z, v, P x, peak) for every snapshot k, k + 1, ... at ``state``.

    Returns the index of the next snapshot to take.
    """
    while k < snap.shape[0] and snap[k] == state:
        for j in range(lanes):
            snapshots[start + j, k, SNAP_Z] = z[j]
            snapshots[start + j, k, SNAP_V] = v[j]
            snapshots[start + j, k, SNAP_X] = square[j]
            snapshots[start + j, k, SNAP_PEAK] = peak[j]
        k += 1
    return k


@numba.njit(cache=True, inline="always")
def _forced_increment(n, dt, row, forcing):
    """u_n of :class:`Forcing` for the batch's path ``row`` at step ``n`` (m/s)."""
    omega, gain, phase, kicks = forcing
    u = kicks[row, n] if kicks.shape[0] > 0 else 0.0
    t = (n + 0.5) * dt
    for q in range(omega.shape[0]):
        u -= gain[q] * np.cos(omega[q] * t + phase[row, q])
    return u


def run_ensemble(
    scheme,
    device,
    friction,
    timing,
    paths,
    initial,
    companion,
    recording,
    noise,
    auxiliary,
    stop,
    transient=None,
    rectifier=None,
    forcing=None,
):
    """Integrate ``paths.count`` paths and return per-path time averages.

    Two compiled loops, so that a run compiles at most twice on a cold cache:
    :func:`lean_loop` without any optional group (white noise, resistive
    circuit: the common and benchmarked case, with none of the optional
    branches), and :func:`full_loop` with every group given, the missing ones
    as their empty stand-ins (:data:`NO_AUXILIARY`, :data:`NO_TRANSIENT`,
    :data:`NO_RECTIFIER`, :data:`NO_FORCING`) that it recognises at run time.
    Both take the same operations in the same order for a given case, so the
    results are the same bit for bit whichever runs it.

    Parameters
    ----------
    scheme : (float, float)
        The integrator's drift weights ``(b1, b2)``
        (:attr:`Integrator.kernel_weights`), used by :func:`scheme_step`.
    device : Device
        (m, c, k, k3, noise_amp).
    friction : Friction
        (kind, p, fn) from :func:`randvib.models.friction.kernel_arguments`.
    timing : Timing
        (dt, n_steps, n_burn).
    paths : Paths
        (seed, first, count): which streams.
    initial : Start
        Initial state of the device.
    companion : Companion
        Whether and from where to integrate the friction-free companion.
    recording : Recording
        Histograms and recorded histories.
    noise : Noise
        Given increments or the ziggurat tables.
    auxiliary : Auxiliary or None
        The linear auxiliary states (shaping filter and/or circuit); None for
        white noise with a resistive circuit. With a random start they start
        from N(0, L L^T), L = ``auxiliary.start`` (``auxiliary.n`` more draws
        per path, after the device's).
    stop : int64[1]
        Set non-zero from another thread (Ctrl-C) to stop every path at its
        next check (every CHECK_EVERY steps); the results are then partial
        and the caller discards them. The loop releases the GIL (nogil) so
        that the caller's thread can watch for the interrupt.
    transient : Transient or None
        An event (:class:`Transient`): the per-step envelope, the filter's
        random start and the snapshots, written into its arrays. None for the
        stationary runs.
    rectifier : Rectifier or None
        A full-wave bridge (:class:`Rectifier`), stepped by
        :func:`rectified_step` with the filter's states of ``auxiliary``
        (None: white or given input); its stored power and losses go to
        ``ACC_STORED``, ``ACC_COIL_LOSS``, ``ACC_DIODE_LOSS``, its capacitors'
        energy into ``ACC_H0``/``ACC_H1``. None without one.
    forcing : Forcing or None
        Tones and shocks added to the input (:class:`Forcing`), given to the
        velocity in two half kicks around every step. None without them.

    Returns
    -------
    acc : float64[n_paths, N_ACC]
    failed_step : int64[n_paths]
        First checked step with a non-finite state, or -1.
    hist : int64[n_chunks, 2, hist_bins]
    records : float64[n_record, n_records, 3]
    """
    groups = (auxiliary, transient, rectifier, forcing)
    if all(group is None for group in groups):
        return lean_loop(
            scheme, device, friction, timing, paths, initial, companion, recording, noise, stop
        )
    return full_loop(
        scheme, device, friction, timing, paths, initial, companion, recording, noise, stop,
        NO_AUXILIARY if auxiliary is None else auxiliary,
        NO_TRANSIENT if transient is None else transient,
        NO_RECTIFIER if rectifier is None else rectifier,
        NO_FORCING if forcing is None else forcing,
    )  # fmt: skip


#: A step's pieces shared by the two loops: compiled once each, without reference
#: counts (``_nrt=False``: they allocate nothing) and inlined by LLVM
#: (``forceinline``). Inlined by numba instead (``inline="always"``), every array
#: they take cost a reference count's increment and decrement per lane and step
#: (about a quarter of the lean loop's time, measured).
_lane_step = numba.njit(cache=True, _nrt=False, forceinline=True)


# The two loops share the pieces below. Those of a step are inlined into the
# loop's parallel body (inline="always": numba inlines them before compiling,
# so the body compiles to what it would be written out). Those of the set-up,
# called once per run, are not: inlined there, numba's array analysis of the
# parallel loop mistook their returned tuples' entries for arrays' shapes (an
# AssertionError when compiling). The arrays a chunk integrates are allocated in
# the loops themselves, not in a helper, as a precaution: numba's parfor pass
# hoists an allocation out of the parallel loop where it sees no write to it.
@numba.njit(cache=True)
def _outputs(n_paths, n_chunks, n_steps, recording):
    """(acc, failed, hist, records): the arrays a loop returns, zeroed."""
    hist_bins, n_record, record_every = recording[2], recording[3], recording[4]
    acc = np.zeros((n_paths, N_ACC))
    failed = np.full(n_paths, -1, dtype=np.int64)
    hist = np.zeros((n_chunks if hist_bins > 0 else 0, 2, max(hist_bins, 1)), dtype=np.int64)
    n_rec_points = n_steps // record_every + 1 if n_record > 0 else 0
    records = np.zeros((n_record, n_rec_points, 3))
    return acc, failed, hist, records


@numba.njit(cache=True)
def _window_constants(timing, recording):
    """(window (s), 1 / window's steps, sqrt(dt), (bins per m, bins per m/s)): the scales.

    The last pair is that of :class:`Recording`'s (z, v) histogram.
    """
    dt, n_steps, n_burn = timing
    hist_lo, hist_hi, hist_bins = recording[0], recording[1], recording[2]
    window = (n_steps - n_burn) * dt
    inv_window_steps = 1.0 / (n_steps - n_burn)
    hist_scale_z = hist_bins / (hist_hi[0] - hist_lo[0]) if hist_bins > 0 else 0.0
    hist_scale_v = hist_bins / (hist_hi[1] - hist_lo[1]) if hist_bins > 0 else 0.0
    return window, inv_window_steps, np.sqrt(dt), (hist_scale_z, hist_scale_v)


@numba.njit(cache=True, inline="always")
def _start_lane(z, v, zc, vc, x1, x2, x3, j, row, rng, tables, given_start, initial, companion,
                chol, n_drawn):  # fmt: skip
    """Lane j's start (path ``row`` of the batch): given, random or fixed.

    A random start draws the device's two normals, then ``n_drawn`` for the
    auxiliary states (L = ``chol``), from the lane's stream. The lanes' arrays
    are passed one by one, never in a tuple: numba's parallel loop does not
    follow a write through a tuple's entry and dropped it as dead.
    """
    ki, wi, fi = tables
    init_random, init_z, init_v = initial
    comp_init_z, comp_init_v = companion[1], companion[2]
    if given_start.shape[0] > 0:
        z[j] = given_start[row, 0]
        v[j] = given_start[row, 1]
        x1[j] = given_start[row, 2]
        x2[j] = given_start[row, 3]
        x3[j] = given_start[row, 4]
    elif init_random:
        nz = standard_normal(rng, j, ki, wi, fi)
        nv = standard_normal(rng, j, ki, wi, fi)
        z[j] = init_z * nz
        v[j] = init_v * nv
        zc[j] = comp_init_z * nz
        vc[j] = comp_init_v * nv
        if n_drawn > 0:
            x1[j], x2[j], x3[j] = _drawn_states(rng, j, ki, wi, fi, chol, n_drawn)
    else:
        z[j] = init_z
        v[j] = init_v
        zc[j] = comp_init_z
        vc[j] = comp_init_v


@_lane_step
def _window_sums(a, hist, chunk, j, n, zj, zn, vj, f1, dwj, in_window, n_burn, dt, stroke,
                 energy, hist_bins, hist_lo, hist_scale):  # fmt: skip
    """Lane j's step n into its sums: the stroke's statistics, then the window's averages.

    ``energy`` is (m, k, k3) for the device's energy at the window's start;
    ``hist_scale`` as :func:`_window_constants` returns it.
    """
    m, k, k3 = energy
    hist_scale_z, hist_scale_v = hist_scale
    if in_window:  # the path's peak and its up-crossings of the stroke
        if abs(zj) > a[j, ACC_PEAK]:
            a[j, ACC_PEAK] = abs(zj)
        if abs(zj) <= stroke and abs(zn) > stroke:
            a[j, ACC_UPCROSS] += 1.0
    if abs(zj) > stroke:
        if a[j, ACC_FIRST_HIT] < 0.0:
            a[j, ACC_FIRST_HIT] = n * dt
        if in_window:
            a[j, ACC_BEYOND] += 1.0
    if in_window:
        if n == n_burn:
            a[j, ACC_H0] += 0.5 * m * vj * vj + 0.5 * k * zj * zj + 0.25 * k3 * zj**4
        a[j, ACC_V2] += vj * vj
        a[j, ACC_Z2] += zj * zj
        a[j, ACC_ABS_V] += abs(vj)
        a[j, ACC_VF] += vj * f1
        a[j, ACC_VDW] += vj * dwj
        if hist_bins > 0:
            bz = int(np.floor((zj - hist_lo[0]) * hist_scale_z))
            bv = int(np.floor((vj - hist_lo[1]) * hist_scale_v))
            if 0 <= bz < hist_bins:
                hist[chunk, 0, bz] += 1
            if 0 <= bv < hist_bins:
                hist[chunk, 1, bv] += 1


@_lane_step
def _increment(dw, row, n, rng, j, ki, wi, fi, sqdt):
    """Lane j's Brownian increment dW (s^0.5) of step n: given (``dw`` not empty) or drawn.

    The ziggurat's tables come one by one: a tuple of arrays built at every
    step costs reference counts (numba increments each array's).
    """
    if dw.shape[0] > 0:
        return dw[row, n]
    return sqdt * standard_normal(rng, j, ki, wi, fi)


@_lane_step
def _companion_step(zc, vc, a, j, in_window, dt, noise, scheme, drift, fr_p, fr_fn):
    """Lane j's friction-free companion: its window sums, then its step on the same noise."""
    zcj = zc[j]
    vcj = vc[j]
    if in_window:
        a[j, ACC_COMP_V2] += vcj * vcj
        a[j, ACC_COMP_Z2] += zcj * zcj
    zc[j], vc[j], _, _ = scheme_step(zcj, vcj, 0.0, dt, noise, scheme, drift, 0, fr_p, fr_fn)


@_lane_step
def _record_step(records, row, n, every, z, v, th, j):
    """Lane j's (z, v, theta) after step n into the recorded history, if recorded."""
    if row < records.shape[0] and (n + 1) % every == 0:
        r = (n + 1) // every
        records[row, r, 0] = z[j]
        records[row, r, 1] = v[j]
        records[row, r, 2] = th[j]


@_lane_step
def _failed_lanes(failed, start, lanes, n, z, v, th):
    """Mark the lanes whose state is no longer finite after step n; True if any."""
    stopped = False
    for j in range(lanes):
        if not (np.isfinite(z[j]) and np.isfinite(v[j]) and np.isfinite(th[j])):
            failed[start + j] = n + 1
            stopped = True
    return stopped


@numba.njit(cache=True, inline="always")
def _finish_lane(a, j, zj, vj, energy, stroke, t_end):
    """Lane j's end: its energy, a first hit by the final state, its peak."""
    m, k, k3 = energy
    a[j, ACC_H1] = 0.5 * m * vj * vj + 0.5 * k * zj * zj + 0.25 * k3 * zj**4
    if abs(zj) > stroke and a[j, ACC_FIRST_HIT] < 0.0:
        a[j, ACC_FIRST_HIT] = t_end  # the final state
    a[j, ACC_PEAK] = max(a[j, ACC_PEAK], abs(zj))


@numba.njit(cache=True, inline="always")
def _write_lane(acc, a, j, p, window, inv_window_steps):
    """Lane j's sums into path p's row of ``acc``: averages over the window's steps or time."""
    for q in range(N_ACC):
        if q == ACC_H0 or q == ACC_H1 or q == ACC_FIRST_HIT:
            acc[p, q] = a[j, q]
        elif q == ACC_PEAK or q == ACC_UPCROSS:  # a largest value and a count
            acc[p, q] = a[j, q]
        elif q == ACC_VDW or q == ACC_STORED or q == ACC_COIL_LOSS or q == ACC_DIODE_LOSS:
            acc[p, q] = a[j, q] / window
        else:
            acc[p, q] = a[j, q] * inv_window_steps


@numba.njit(cache=True, parallel=True, nogil=True)
def lean_loop(scheme, device, friction, timing, paths, initial, companion, recording, noise, stop):
    """:func:`run_ensemble`'s loop without optional groups: white noise, resistive circuit.

    The common and benchmarked case: none of :func:`full_loop`'s run-time
    branches for a filter, a circuit, an event, a bridge or forcing is here.
    """
    m, c, k, k3, noise_amp = device
    fr_kind, fr_p, fr_fn = friction
    dt, n_steps, n_burn = timing
    seed, first_path, n_paths = paths
    with_companion = companion[0]
    hist_lo, _, hist_bins, n_record, record_every, stroke = recording
    dw, ki, wi, fi, given_start = noise
    n_chunks = (n_paths + LANES - 1) // LANES
    acc, failed, hist, records = _outputs(n_paths, n_chunks, n_steps, recording)
    window, inv_window_steps, sqdt, hist_scale = _window_constants(timing, recording)
    drift = (1.0 / m, c, k, k3)
    no_chol = np.zeros((0, 0))
    for chunk in numba.prange(n_chunks):
        start = chunk * LANES
        lanes = min(LANES, n_paths - start)
        rng = np.empty((LANES, 4), dtype=np.uint64)
        z, v, th = np.zeros(LANES), np.zeros(LANES), np.zeros(LANES)
        zc, vc = np.zeros(LANES), np.zeros(LANES)
        x1, x2, x3 = np.zeros(LANES), np.zeros(LANES), np.zeros(LANES)
        a = np.zeros((LANES, N_ACC))
        a[:, ACC_FIRST_HIT] = -1.0
        for j in range(lanes):
            seed_path_state(seed, first_path + start + j, rng, j)
            _start_lane(z, v, zc, vc, x1, x2, x3, j, start + j, rng, (ki, wi, fi), given_start,
                        initial, companion, no_chol, 0)  # fmt: skip
            if start + j < n_record:
                records[start + j, 0, 0] = z[j]
                records[start + j, 0, 1] = v[j]
        for n in range(n_steps):
            in_window = n >= n_burn
            for j in range(lanes):
                dwj = _increment(dw, start + j, n, rng, j, ki, wi, fi, sqdt)
                noise = noise_amp * dwj
                zj = z[j]
                vj = v[j]
                zn, vn, tn, f1 = scheme_step(
                    zj, vj, th[j], dt, noise, scheme, drift, fr_kind, fr_p, fr_fn
                )
                _window_sums(a, hist, chunk, j, n, zj, zn, vj, f1, dwj, in_window, n_burn, dt,
                             stroke, (m, k, k3), hist_bins, hist_lo, hist_scale)  # fmt: skip
                z[j] = zn
                v[j] = vn
                th[j] = tn
                if with_companion:
                    _companion_step(zc, vc, a, j, in_window, dt, noise, scheme, drift, fr_p, fr_fn)
                _record_step(records, start + j, n, record_every, z, v, th, j)
            if (n + 1) % CHECK_EVERY == 0 or n == n_steps - 1:
                if _failed_lanes(failed, start, lanes, n, z, v, th) or stop_requested(stop):
                    break
        for j in range(lanes):
            _finish_lane(a, j, z[j], v[j], (m, k, k3), stroke, n_steps * dt)
            _write_lane(acc, a, j, start + j, window, inv_window_steps)
    return acc, failed, hist, records


@numba.njit(cache=True)
def _auxiliary_constants(auxiliary):
    """(n, in use, block, P row, filter alone, L) of an :class:`Auxiliary` group.

    The block's coefficients go to the step as a tuple of floats (an array
    would cost a reference count per step). "Filter alone": a 2-state filter
    without a circuit (no square, no velocity drive, g_v = 0), stepped by
    :func:`filter_step`.
    """
    n_aux = auxiliary.n
    ac = auxiliary.coefficients
    block = (
        ac[0], ac[1], ac[2], ac[3], ac[4], ac[5], ac[6], ac[7], ac[8], ac[9],
        ac[10], ac[11], ac[12], ac[13], ac[14], ac[15], ac[16], ac[17], ac[18],
    )  # fmt: skip
    p1, p2, p3 = auxiliary.square[0], auxiliary.square[1], auxiliary.square[2]
    filter_only = (n_aux == 2 and p1 == 0.0 and p2 == 0.0 and p3 == 0.0 and ac[9] == 0.0
                   and ac[10] == 0.0 and ac[18] == 0.0)  # fmt: skip
    # n_aux 0: the full loop's empty block (NO_AUXILIARY)
    return n_aux, n_aux > 0, block, (p1, p2, p3), filter_only, auxiliary.start


@numba.njit(cache=True)
def _rectifier_constants(rectifier, dt, has_aux, block):
    """(bridged, constants, stored energy's factors, V_C(0), the block it steps with).

    ``constants``: :func:`~randvib.montecarlo.rectified_kernel.bridge_constants`
    (shared with the record simulation of a bridge). The factors are those of
    the energy held by the piezo's C_p V_p^2 / 2 or the coil's L i^2 / 2 (the
    state s1 is V_p or i) and by the storage capacitor's C V_C^2 / 2, and the
    battery's V_b. White or given input has no filter: the noise drives the
    velocity (g_v = 1).
    """
    rp = rectifier.p
    rect = bridge_constants(rectifier.kind, rectifier.output, rp, dt)
    half_cp = 0.5 * rp[1] if rectifier.kind == 2 else 0.5 * rp[8]
    half_c = 0.5 * rp[4] if rectifier.output == 1 else 0.0
    rblock = (
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    )  # fmt: skip
    if has_aux:
        rblock = block
    # kind 0: the full loop's stand-in (NO_RECTIFIER)
    return rectifier.kind != 0, rect, (half_cp, half_c, rp[3]), rectifier.v_c0, rblock


@_lane_step
def _bridged_lane(a, j, at_burn, in_window, lane, x1, x2, x3, s1, s2, dt, noise, scheme, drift,
                  friction, rect, stored, has_aux, rblock):  # fmt: skip
    """Lane j's step through the bridge; its stored energy and losses into the window's sums.

    ``lane`` is (z, v after the forcing's half kick, theta); x1, x2, x3 and
    s1, s2 the lanes' auxiliary and circuit states, updated here; ``stored``
    as :func:`_rectifier_constants` returns it. Returns (z, v, theta, force).
    """
    zj, vs, tj = lane
    fr_kind, fr_p, fr_fn = friction
    half_cp, half_c, v_out_b = stored
    if in_window and at_burn:
        a[j, ACC_H0] = half_cp * s1[j] * s1[j] + half_c * s2[j] * s2[j]
    v_out = v_out_b if rect[1] == 0 else s2[j]  # at the step's start
    if has_aux:
        zn, vn, tn, x1[j], x2[j], x3[j], s1[j], s2[j], f1, e_s, e_c, e_d = rectified_step(
            zj, vs, tj, x1[j], x2[j], x3[j], s1[j], s2[j], dt, noise, scheme, drift, fr_kind,
            fr_p, fr_fn, rblock, rect,
        )  # fmt: skip
    else:
        zn, vn, tn, s1[j], s2[j], f1, e_s, e_c, e_d = rectified_white_step(
            zj, vs, tj, s1[j], s2[j], dt, noise, scheme, drift, fr_kind, fr_p, fr_fn, rect,
        )  # fmt: skip
    if in_window:
        # energies (J); divided by the window (s) at the end
        a[j, ACC_STORED] += e_s
        a[j, ACC_COIL_LOSS] += e_c
        a[j, ACC_DIODE_LOSS] += e_d
        a[j, ACC_V_OUT] += v_out
    return zn, vn, tn, f1


@_lane_step
def _auxiliary_lane(a, j, in_window, lane, x1, x2, x3, row, filter_only, dt, noise, scheme,
                    drift, friction, step_block):  # fmt: skip
    """Lane j's step with the auxiliary states (:func:`filter_step` or :func:`auxiliary_step`).

    ``row`` is P, whose (P x)^2 the window averages (``ACC_CIRCUIT2``).
    Returns (z, v, theta, force).
    """
    zj, vs, tj = lane
    fr_kind, fr_p, fr_fn = friction
    if filter_only:
        zn, vn, tn, x1[j], x2[j], f1 = filter_step(
            zj, vs, tj, x1[j], x2[j], dt, noise, scheme, drift, fr_kind, fr_p, fr_fn, step_block
        )  # fmt: skip
        return zn, vn, tn, f1
    x1j = x1[j]
    x2j = x2[j]
    x3j = x3[j]
    if in_window:
        sq = row[0] * x1j + row[1] * x2j + row[2] * x3j
        a[j, ACC_CIRCUIT2] += sq * sq
    zn, vn, tn, x1[j], x2[j], x3[j], f1 = auxiliary_step(
        zj, vs, tj, x1j, x2j, x3j, dt, noise, scheme, drift, fr_kind, fr_p, fr_fn, step_block
    )  # fmt: skip
    return zn, vn, tn, f1


@_lane_step
def _event_sums(peak, integrals, square, j, zn, vj, vn, dt, has_aux, row, x1, x2, x3):
    """Lane j's event sums after its step: the peak |z|, int v^2 dt and int (P x)^2 dt."""
    peak[j] = max(peak[j], abs(zn))
    integrals[j, 0] += 0.5 * dt * (vj * vj + vn * vn)
    if has_aux:
        sq = row[0] * x1[j] + row[1] * x2[j] + row[2] * x3[j]
        integrals[j, 1] += 0.5 * dt * (square[j] * square[j] + sq * sq)
        square[j] = sq


@numba.njit(cache=True, inline="always")
def _write_event(event_out, p, peak, integrals, j):
    """Lane j's peak |z|, int v^2 dt and int (P x)^2 dt into path p's row of the event's output."""
    event_out[p, EVENT_PEAK] = peak[j]
    event_out[p, EVENT_V2] = integrals[j, 0]
    event_out[p, EVENT_X2] = integrals[j, 1]


@numba.njit(cache=True, parallel=True, nogil=True)
def full_loop(scheme, device, friction, timing, paths, initial, companion, recording, noise, stop,
              auxiliary, transient, rectifier, forcing):  # fmt: skip
    """:func:`run_ensemble`'s loop with every optional group given (perhaps a stand-in).

    The flags ``has_aux``, ``timed``, ``bridged`` and ``forced`` recognise the
    stand-ins at run time: loop-invariant branches, taken the same way at
    every step. A case takes the same operations in the same order as in
    :func:`lean_loop`, so either gives the same results bit for bit.
    """
    m, c, k, k3, noise_amp = device
    fr_kind, fr_p, fr_fn = friction
    dt, n_steps, n_burn = timing
    seed, first_path, n_paths = paths
    with_companion = companion[0]
    hist_lo, _, hist_bins, n_record, record_every, stroke = recording
    dw, ki, wi, fi, given_start = noise
    n_aux, has_aux, block, row, filter_only, chol = _auxiliary_constants(auxiliary)
    gains, scale_noise, filter_mask, n_start, filter_start, snap, snapshots, event_out = transient
    timed = gains.shape[0] > 0  # False: NO_TRANSIENT
    bridged, rect, stored, v_c0, rblock = _rectifier_constants(rectifier, dt, has_aux, block)
    forced = forcing.omega.shape[0] > 0 or forcing.kicks.shape[0] > 0  # False: NO_FORCING
    n_chunks = (n_paths + LANES - 1) // LANES
    acc, failed, hist, records = _outputs(n_paths, n_chunks, n_steps, recording)
    window, inv_window_steps, sqdt, hist_scale = _window_constants(timing, recording)
    drift = (1.0 / m, c, k, k3)
    for chunk in numba.prange(n_chunks):
        start = chunk * LANES
        lanes = min(LANES, n_paths - start)
        rng = np.empty((LANES, 4), dtype=np.uint64)
        z, v, th = np.zeros(LANES), np.zeros(LANES), np.zeros(LANES)
        zc, vc = np.zeros(LANES), np.zeros(LANES)
        x1, x2, x3 = np.zeros(LANES), np.zeros(LANES), np.zeros(LANES)
        a = np.zeros((LANES, N_ACC))
        a[:, ACC_FIRST_HIT] = -1.0
        # the piezo's voltage V_p (V) or the inductive coil's current (A); the storage V_C (V)
        s1, s2 = np.zeros(LANES), np.full(LANES, v_c0)
        step_block = block
        # the event's peak |z|, P x (for int (P x)^2 dt) and the integrals
        peak, square, integrals = np.zeros(LANES), np.zeros(LANES), np.zeros((LANES, 2))
        for j in range(lanes):
            seed_path_state(seed, first_path + start + j, rng, j)
            _start_lane(z, v, zc, vc, x1, x2, x3, j, start + j, rng, (ki, wi, fi), given_start,
                        initial, companion, chol, n_aux if has_aux else 0)  # fmt: skip
            if timed:
                x1[j], x2[j], x3[j] = _drawn_states(rng, j, ki, wi, fi, filter_start, n_start)
                peak[j] = abs(z[j])
                if has_aux:
                    square[j] = row[0] * x1[j] + row[1] * x2[j] + row[2] * x3[j]
            if start + j < n_record:
                records[start + j, 0, 0] = z[j]
                records[start + j, 0, 1] = v[j]
        next_snap = _snapshots(snapshots, snap, 0, 0, start, lanes, z, v, square, peak)
        for n in range(n_steps):
            in_window = n >= n_burn
            if timed:
                gain = gains[n]
                if has_aux and not scale_noise:
                    step_block = _scaled_block(block, filter_mask, gain)
            for j in range(lanes):
                dwj = _increment(dw, start + j, n, rng, j, ki, wi, fi, sqdt)
                noise = noise_amp * dwj
                if timed and scale_noise:
                    noise = noise * gain
                zj = z[j]
                vj = v[j]
                vs = vj  # the velocity the step starts from: with forcing, after its half kick
                if forced:
                    kick = 0.5 * _forced_increment(n, dt, start + j, forcing)
                    vs = vj + kick
                lane = (zj, vs, th[j])
                if bridged:
                    zn, vn, tn, f1 = _bridged_lane(a, j, n == n_burn, in_window, lane, x1, x2, x3,
                        s1, s2, dt, noise, scheme, drift, friction, rect, stored, has_aux,
                        rblock)  # fmt: skip
                elif has_aux:
                    zn, vn, tn, f1 = _auxiliary_lane(a, j, in_window, lane, x1, x2, x3, row,
                        filter_only, dt, noise, scheme, drift, friction, step_block)  # fmt: skip
                else:
                    zn, vn, tn, f1 = scheme_step(zj, vs, th[j], dt, noise, scheme, drift,
                                                 fr_kind, fr_p, fr_fn)  # fmt: skip
                if forced:
                    vn += kick
                _window_sums(a, hist, chunk, j, n, zj, zn, vj, f1, dwj, in_window, n_burn, dt,
                             stroke, (m, k, k3), hist_bins, hist_lo, hist_scale)  # fmt: skip
                z[j] = zn
                v[j] = vn
                th[j] = tn
                if timed:
                    _event_sums(peak, integrals, square, j, zn, vj, vn, dt, has_aux, row,
                                x1, x2, x3)  # fmt: skip
                if with_companion:
                    _companion_step(zc, vc, a, j, in_window, dt, noise, scheme, drift, fr_p, fr_fn)
                _record_step(records, start + j, n, record_every, z, v, th, j)
            if timed:
                next_snap = _snapshots(snapshots, snap, next_snap, n + 1, start, lanes, z, v,
                                       square, peak)  # fmt: skip
            if (n + 1) % CHECK_EVERY == 0 or n == n_steps - 1:
                if _failed_lanes(failed, start, lanes, n, z, v, th) or stop_requested(stop):
                    break
        for j in range(lanes):
            _finish_lane(a, j, z[j], v[j], (m, k, k3), stroke, n_steps * dt)
            if bridged:
                a[j, ACC_H1] += stored[0] * s1[j] * s1[j] + stored[1] * s2[j] * s2[j]
            if timed:
                _write_event(event_out, start + j, peak, integrals, j)
            _write_lane(acc, a, j, start + j, window, inv_window_steps)
    return acc, failed, hist, records
