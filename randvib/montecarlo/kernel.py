"""Compiled ensemble kernel: one time loop for every scheme and friction model.

Paths are processed in chunks of :data:`LANES` independent paths that advance
together, step by step: the per-step dependency chain of one path is short
and latency-bound, so interleaving a few paths keeps the core busy. Chunks run
in parallel (``numba.prange``). Every path draws from its own stream
(:mod:`randvib.montecarlo.rng`) and owns its accumulators, and the cross-path reductions
happen afterwards in path order, so results are bit-identical for any number
of threads and any batching of paths.

Memory is O(n_paths): per-path running sums only, unless histograms or
recorded histories are requested.
"""

from __future__ import annotations

from typing import NamedTuple, get_type_hints

import numba
import numpy as np

from randvib.models.friction import evaluate_friction
from randvib.montecarlo.rng import seed_path_state, standard_normal

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
N_ACC = 9


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
    """Paths ``first .. first + count - 1``; path i draws from stream (seed, i)."""

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
    ``n_record`` paths every ``every`` steps, initial state included.
    """

    hist_lo: np.ndarray  #: float64[2]
    hist_hi: np.ndarray  #: float64[2]
    hist_bins: int
    n_record: int
    every: int


class Shaping(NamedTuple):
    """The excitation's 2-state shaping filter, integrated with the device.

    White noise has no filter state: the velocity takes the noise increment
    (:func:`scheme_step`). A rational spectrum (band-pass, Kanai-Tajimi) is
    the output y = C x of a 2-state filter x' = A x + G w of the same white
    noise (:meth:`randvib.models.excitation.Excitation.shaping_filter`), and
    the device's acceleration takes -y, its base acceleration (paper Eq. 18,
    m z'' = ... - m y; :func:`filtered_step`).
    """

    coefficients: np.ndarray  #: float64[8]: A (row-major), G, C
    start: np.ndarray  #: float64[3]: (l11, l21, l22), Cholesky factor of the filter's covariance


class Noise(NamedTuple):
    """Where the Brownian increments come from.

    ``dw`` (n_paths, n_steps) given increments (s^0.5), or shape (0, 0) to draw
    them from the paths' streams with the ziggurat tables ``ki, wi, fi``
    (:mod:`randvib.montecarlo.rng`).
    """

    dw: np.ndarray
    ki: np.ndarray
    wi: np.ndarray
    fi: np.ndarray


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
    hints = get_type_hints(group)
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
def _acceleration(z, v, theta, drift, kind, p, fn):
    inv_m, c, k, k3 = drift
    force, rate = evaluate_friction(kind, fn, p, v, theta)
    return -(c * v + k * z + k3 * z * z * z + force) * inv_m, rate, force


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
def filtered_step(z, v, theta, x1, x2, dt, noise, weights, drift, kind, p, fn, shaping):
    """:func:`scheme_step` for the device driven through a 2-state shaping filter.

    The augmented state (z, v, theta, x1, x2) takes the same additive-noise
    step: the noise increment enters the filter states (``G noise``), the
    device's acceleration gets the base acceleration -C x of the filter. The
    filter is linear, so the scheme's orders hold for the augmented system
    and :meth:`Integrator.linear_recursion` gives its exact recursion on a
    linear device.

    Parameters
    ----------
    z, v, theta, dt, noise, weights, drift, kind, p, fn
        As for :func:`scheme_step`; ``noise`` is sqrt(S/2) dW, S the filter's
        input level.
    x1, x2 : float
        Filter states.
    shaping : tuple of 8 floats
        ``(a11, a12, a21, a22, g1, g2, c1, c2)`` of :class:`Shaping`.

    Returns
    -------
    z, v, theta, x1, x2 : float
        State after the step.
    force : float
        Friction force at the start of the step (N).
    """
    b1, b2 = weights
    a11, a12, a21, a22, g1, g2, c1, c2 = shaping
    acc1, rate1, force = _acceleration(z, v, theta, drift, kind, p, fn)
    acc1 -= c1 * x1 + c2 * x2
    d1 = a11 * x1 + a12 * x2
    d2 = a21 * x1 + a22 * x2
    if b2 == 0.0:
        return (
            z + b1 * v * dt,
            v + b1 * acc1 * dt,
            theta + b1 * rate1 * dt,
            x1 + b1 * d1 * dt + g1 * noise,
            x2 + b1 * d2 * dt + g2 * noise,
            force,
        )
    zp = z + v * dt
    vp = v + acc1 * dt
    tp = theta + rate1 * dt
    x1p = x1 + d1 * dt + g1 * noise
    x2p = x2 + d2 * dt + g2 * noise
    acc2, rate2, _ = _acceleration(zp, vp, tp, drift, kind, p, fn)
    acc2 -= c1 * x1p + c2 * x2p
    return (
        z + (b1 * v + b2 * vp) * dt,
        v + (b1 * acc1 + b2 * acc2) * dt,
        theta + (b1 * rate1 + b2 * rate2) * dt,
        x1 + (b1 * d1 + b2 * (a11 * x1p + a12 * x2p)) * dt + g1 * noise,
        x2 + (b1 * d2 + b2 * (a21 * x1p + a22 * x2p)) * dt + g2 * noise,
        force,
    )


@numba.njit(cache=True, parallel=True, nogil=True)
def run_ensemble(
    scheme, device, friction, timing, paths, initial, companion, recording, noise, shaping, stop
):
    """Integrate ``paths.count`` paths and return per-path time averages.

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
    shaping : Shaping or None
        The excitation's filter; None for white noise. With a random
        start the filter starts from its own stationary law (two more draws
        per path, after the device's).
    stop : int64[1]
        Set non-zero from another thread (Ctrl-C) to stop every path at its
        next check (every CHECK_EVERY steps); the results are then partial
        and the caller discards them. The loop releases the GIL (nogil) so
        that the caller's thread can watch for the interrupt.

    Returns
    -------
    acc : float64[n_paths, N_ACC]
    failed_step : int64[n_paths]
        First checked step with a non-finite state, or -1.
    hist : int64[n_chunks, 2, hist_bins]
    records : float64[n_record, n_records, 3]
    """
    # Unpacked once into locals; the step takes the (float) scheme and drift groups.
    m, c, k, k3, noise_amp = device
    fr_kind, fr_p, fr_fn = friction
    dt, n_steps, n_burn = timing
    seed, first_path, n_paths = paths
    init_random, init_z, init_v = initial
    with_companion, comp_init_z, comp_init_v = companion
    hist_lo, hist_hi, hist_bins, n_record, record_every = recording
    dw, ki, wi, fi = noise
    # `shaping is None` is decided when compiling (numba prunes the dead branch
    # for a None argument): white noise runs the plain loop, bit for bit and at
    # its own speed; a filter compiles a second specialisation.
    if shaping is not None:
        sc = shaping.coefficients
        filt = (sc[0], sc[1], sc[2], sc[3], sc[4], sc[5], sc[6], sc[7])
        l11, l21, l22 = shaping.start[0], shaping.start[1], shaping.start[2]
    n_chunks = (n_paths + LANES - 1) // LANES
    acc = np.zeros((n_paths, N_ACC))
    failed = np.full(n_paths, -1, dtype=np.int64)
    hist = np.zeros((n_chunks if hist_bins > 0 else 0, 2, max(hist_bins, 1)), dtype=np.int64)
    n_rec_points = n_steps // record_every + 1 if n_record > 0 else 0
    records = np.zeros((n_record, n_rec_points, 3))
    given_noise = dw.shape[0] > 0
    inv_m = 1.0 / m
    drift = (inv_m, c, k, k3)
    window = (n_steps - n_burn) * dt
    inv_window_steps = 1.0 / (n_steps - n_burn)
    sqdt = np.sqrt(dt)
    hist_scale_z = hist_bins / (hist_hi[0] - hist_lo[0]) if hist_bins > 0 else 0.0
    hist_scale_v = hist_bins / (hist_hi[1] - hist_lo[1]) if hist_bins > 0 else 0.0

    for chunk in numba.prange(n_chunks):
        start = chunk * LANES
        lanes = min(LANES, n_paths - start)
        rng = np.empty((LANES, 4), dtype=np.uint64)
        z = np.zeros(LANES)
        v = np.zeros(LANES)
        th = np.zeros(LANES)
        zc = np.zeros(LANES)
        vc = np.zeros(LANES)
        x1 = np.zeros(LANES)
        x2 = np.zeros(LANES)
        a = np.zeros((LANES, N_ACC))
        for j in range(lanes):
            seed_path_state(seed, first_path + start + j, rng, j)
            if init_random:
                nz = standard_normal(rng, j, ki, wi, fi)
                nv = standard_normal(rng, j, ki, wi, fi)
                z[j] = init_z * nz
                v[j] = init_v * nv
                zc[j] = comp_init_z * nz
                vc[j] = comp_init_v * nv
                if shaping is not None:
                    n1 = standard_normal(rng, j, ki, wi, fi)
                    n2 = standard_normal(rng, j, ki, wi, fi)
                    x1[j] = l11 * n1
                    x2[j] = l21 * n1 + l22 * n2
            else:
                z[j] = init_z
                v[j] = init_v
                zc[j] = comp_init_z
                vc[j] = comp_init_v
            if start + j < n_record:
                records[start + j, 0, 0] = z[j]
                records[start + j, 0, 1] = v[j]
        stopped = False
        for n in range(n_steps):
            in_window = n >= n_burn
            for j in range(lanes):
                if given_noise:
                    dwj = dw[start + j, n]
                else:
                    dwj = sqdt * standard_normal(rng, j, ki, wi, fi)
                noise = noise_amp * dwj
                zj = z[j]
                vj = v[j]
                tj = th[j]
                if shaping is not None:
                    zn, vn, tn, x1[j], x2[j], f1 = filtered_step(
                        zj,
                        vj,
                        tj,
                        x1[j],
                        x2[j],
                        dt,
                        noise,
                        scheme,
                        drift,
                        fr_kind,
                        fr_p,
                        fr_fn,
                        filt,
                    )
                else:
                    zn, vn, tn, f1 = scheme_step(
                        zj, vj, tj, dt, noise, scheme, drift, fr_kind, fr_p, fr_fn
                    )
                if in_window:
                    if n == n_burn:
                        a[j, ACC_H0] = 0.5 * m * vj * vj + 0.5 * k * zj * zj + 0.25 * k3 * zj**4
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
                z[j] = zn
                v[j] = vn
                th[j] = tn
                if with_companion:
                    zcj = zc[j]
                    vcj = vc[j]
                    if in_window:
                        a[j, ACC_COMP_V2] += vcj * vcj
                        a[j, ACC_COMP_Z2] += zcj * zcj
                    zc[j], vc[j], _, _ = scheme_step(
                        zcj, vcj, 0.0, dt, noise, scheme, drift, 0, fr_p, fr_fn
                    )
                if start + j < n_record and (n + 1) % record_every == 0:
                    r = (n + 1) // record_every
                    records[start + j, r, 0] = z[j]
                    records[start + j, r, 1] = v[j]
                    records[start + j, r, 2] = th[j]
            if (n + 1) % CHECK_EVERY == 0 or n == n_steps - 1:
                for j in range(lanes):
                    if not (np.isfinite(z[j]) and np.isfinite(v[j]) and np.isfinite(th[j])):
                        failed[start + j] = n + 1
                        stopped = True
                if stopped or stop[0] != 0:
                    break
        for j in range(lanes):
            p = start + j
            zj = z[j]
            vj = v[j]
            a[j, ACC_H1] = 0.5 * m * vj * vj + 0.5 * k * zj * zj + 0.25 * k3 * zj**4
            for q in range(N_ACC):
                if q == ACC_H0 or q == ACC_H1:
                    acc[p, q] = a[j, q]
                elif q == ACC_VDW:
                    acc[p, q] = a[j, q] / window
                else:
                    acc[p, q] = a[j, q] * inv_window_steps
    return acc, failed, hist, records
