"""Compiled ensemble kernel of an assembly: N DOFs, elements, transducers, one time loop.

The assembly (:class:`randvib.models.assembly.Assembly`, docs/assemblies.md)

    M x'' + C x' + K x + sum_e d_e f_e(u_e, u_e') = -M r a(t),     u_e = d_e^T x

is integrated as the first-order system ``x' = v``,
``v' = -M^-1 (C_lin v + K_lin x) - sum_p (M^-1 d_p) f_p - r a`` with, beside
(x, v), the parts' own states: a friction state per element (LuGre's
bristles; unused by memoryless laws), a circuit state per linear dynamic
transducer (a coil's current, a piezo's voltage: ``s' = a s + b u'``, force
``f s``), two states per diode bridge (the piezo's voltage or the coil's
current, and the storage capacitor's voltage: the steps of
:mod:`randvib.montecarlo.rectified_kernel`), and the excitation's shaping
filter (its output y is the base acceleration: ``v' -= r y``). The linear
springs, dashpots and static couplings (c_e) are in C_lin and K_lin
(:meth:`~randvib.models.assembly.Assembly.linear_matrices`); the kernel
evaluates only the nonlinear forces ``k2 u^2 + k3 u^3 + F(u', theta)``.

**One compiled signature for every assembly.** The structure and the parts
arrive as tables (:class:`Linear`, :class:`Parts`, :class:`Columns`), their
sizes read at run time; a generic friction law is called through one of
:data:`N_CALLBACKS` compiled callbacks of the single type
:data:`randvib.models.friction.KERNEL_SIGNATURE`. Nothing here is shared
with, or changes, the single-mass kernel (:mod:`randvib.montecarlo.kernel`).

**The state of a chunk** is one array ``y`` of shape (rows, LANES): rows
``0 .. N`` hold x and a zero row for the base, rows ``N + 1 .. 2N + 1`` v and
the base's zero velocity (so that a part on ``(i, base)`` reads row N like a
DOF, without a branch), then the friction, circuit, bridge and filter states
(:func:`row_offsets`). Every operation loops over the LANES paths of a
chunk innermost: the paths' arithmetic is independent and identical, so a
path's result does not depend on its lane, its chunk, the threads or the
batches, and the compiler can vectorise the loops across lanes.

**The scheme** is the single-mass kernel's additive-noise predictor-corrector
(:class:`randvib.montecarlo.integrators.Integrator` weights (b1, b2)):
``y_p = y + R(y) dt + G dW``, ``y_{n+1} = y + (b1 R(y) + b2 R(y_p)) dt + G dW``
with the noise gain G: ``r`` on the velocities under white or given input, the
filter's input gain on its states under a rational spectrum.

**Per-path accumulators** (:class:`Columns`): time averages over the window
of x x^T and v v^T (upper triangles), of each element's friction power
u' F and |u'|, of each circuit state's square, each bridge's stored power,
coil and diode losses and output voltage, the Ito sum (M r)^T v dW / T, the
energy H at the window's ends, and for each stroke the fraction of steps beyond
it, the peak |u| and the number of up-crossings of |u| through it.

**A given start per path** (``noise.start``, shape (paths, rows), as the
single-mass kernel's :class:`~randvib.montecarlo.kernel.Noise`) replaces the
drawn one: the rare-event estimators express the stationary start through
standard normals (:mod:`randvib.montecarlo.assembly_paths`).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from randvib.models.friction import KERNEL_GENERIC, friction_force_and_rate
from randvib.montecarlo.kernel import CHECK_EVERY, LANES
from randvib.montecarlo.rectified_kernel import _bridge_predictor, _bridge_rates, _bridge_update
from randvib.montecarlo.rng import seed_path_state, standard_normal

#: Distinct generic (non-built-in) friction laws one assembly may use at once.
N_CALLBACKS = 4
#: Columns of :attr:`Parts.bridges`: the 18 constants of the single-mass kernel's
#: bridge tuple (:func:`bridge_constants`), then the energies' halves: C_p / 2 (piezo)
#: or L / 2 (coil) of the first bridge state, C / 2 of the storage capacitor.
N_BRIDGE = 20
#: Accumulators per bridge: stored power, coil loss, diode loss (W), output voltage (V).
BRIDGE_STORED, BRIDGE_COIL, BRIDGE_DIODE, BRIDGE_V_OUT = 0, 1, 2, 3
N_BRIDGE_ACC = 4


class Layout(NamedTuple):
    """How many of each: DOFs, elements, linear circuits, bridges, filter states; rows in all."""

    n_dof: int
    n_elements: int
    n_circuits: int
    n_bridges: int
    n_filter: int
    n_rows: int


def row_offsets(n_dof, n_elements, n_circuits, n_bridges):
    """Rows of v, friction, circuit, bridge and filter states in the chunk's state array.

    x is at rows ``0 .. n_dof - 1`` and the base at row ``n_dof``; v at ``ov ..
    ov + n_dof - 1`` and the base's at ``ov + n_dof``.
    """
    ov = n_dof + 1
    oth = ov + n_dof + 1
    oc = oth + n_elements
    ob = oc + n_circuits
    of = ob + 2 * n_bridges
    return ov, oth, oc, ob, of


row_offsets_compiled = numba.njit(cache=True)(row_offsets)


class Linear(NamedTuple):
    """The linear part: ``v' = -(stiffness x + damping v) - drive y`` and the noise gains."""

    stiffness: np.ndarray  #: float64[N, N]: M^-1 K_lin (1/s^2)
    damping: np.ndarray  #: float64[N, N]: M^-1 C_lin (1/s)
    gain: np.ndarray  #: float64[rows]: G, each row's share of the step's noise increment
    drive: np.ndarray  #: float64[1, N]: r, the weight of the filter's output y on each DOF
    filter_a: np.ndarray  #: float64[2, 2]: the shaping filter's state matrix
    filter_c: np.ndarray  #: float64[2]: its output row (y = c . states)
    noise_amp: float  #: sqrt(S/2) (white, filter) or 1 (given increments, m/s)


class Parts(NamedTuple):
    """Elements, linear circuits and bridges as tables (row p of ``coordinates`` and ``push``).

    Parts are numbered elements first, then circuits, then bridges;
    ``coordinates[p] = (i, j)`` with j = N for the base, ``push[p] = M^-1 d_p``
    (the acceleration of a unit force on the part's coordinate).
    """

    coordinates: np.ndarray  #: int64[P, 2]
    push: np.ndarray  #: float64[P, N]
    springs: np.ndarray  #: float64[E, 2]: (k2, k3) (N/m^2, N/m^3)
    friction_kind: np.ndarray  #: int64[E]: kernel code of the law (0: none)
    friction_slot: np.ndarray  #: int64[E]: which callback a generic law uses
    friction_p: np.ndarray  #: float64[E, N_KERNEL_PARAMETERS]
    circuits: (
        np.ndarray
    )  #: float64[C, 4]: (a, b, f, f/b): s' = a s + b u', force f s, energy f s^2/(2b)
    bridges: np.ndarray  #: float64[B, N_BRIDGE]


class Columns(NamedTuple):
    """Where each accumulator is in a path's row, and what the energy and strokes need."""

    xx: int  #: first of the N(N+1)/2 upper-triangle averages of x x^T
    vv: int  #: first of those of v v^T
    friction: int  #: first of E averages of u' F (W)
    abs_du: int  #: first of E averages of |u'| (m/s)
    circuit: int  #: first of C averages of s^2
    bridge: int  #: first of N_BRIDGE_ACC per bridge
    ito: int  #: (M r)^T v dW summed over the window / T
    h0: int  #: energy at the window's start (J)
    h1: int  #: energy at the end (J)
    #: first of S fractions of the window's steps beyond a stroke, then S peaks of |u| over
    #: the window's states, its end included (m), then S counts of the window's steps on
    #: which |u| rises through its stroke (the rare-event estimators',
    #: :mod:`randvib.montecarlo.assembly_paths`)
    stroke: int
    n: int  #: columns in all
    mass: np.ndarray  #: float64[N, N]: M, for the kinetic energy
    stiffness: np.ndarray  #: float64[N, N]: K_lin, for the potential energy
    ito_weights: np.ndarray  #: float64[N]: M r
    stroke_coordinates: np.ndarray  #: int64[S, 2]
    stroke_limits: np.ndarray  #: float64[S] (m)


class Start(NamedTuple):
    """Each path's first state: ``state`` plus, at ``rows``, L n with n standard normals."""

    state: np.ndarray  #: float64[rows]
    rows: np.ndarray  #: int64[K]: the rows drawn at random (K = 0: a fixed start)
    chol: np.ndarray  #: float64[K, K]: lower Cholesky factor of their covariance


class Recording(NamedTuple):
    """The whole state of the first ``n_record`` paths every ``every`` steps (t = 0 included)."""

    n_record: int
    every: int


def bridge_constants(kind, output, p, dt) -> np.ndarray:
    """The bridge's 18 kernel constants, as :func:`randvib.montecarlo.kernel.run_ensemble` builds them.

    ``(kind, output, gain, R_C or C_p, V_d, V_b, C, R_L, 1/R_C, gain/R_C or
    theta/C_p, 1/C, 1/(R_L C), C_p/(C_p + C), C/(C_p + C), I_s, 2 n V_T, 1/L,
    dt/R_L)`` from :meth:`randvib.models.rectifier.Rectified.kernel_parameters`;
    the rectified steps (:mod:`randvib.montecarlo.rectified_kernel`) read them.
    """
    rp = np.asarray(p, dtype=float)
    return np.array(
        [
            kind, output, rp[0], rp[1], rp[2], rp[3], rp[4], rp[5],
            1.0 / rp[1], rp[0] / rp[1], 1.0 / rp[4], 1.0 / (rp[5] * rp[4]),
            rp[1] / (rp[1] + rp[4]), rp[4] / (rp[1] + rp[4]), rp[6], 2.0 * rp[7],
            1.0 / rp[8] if rp[8] > 0.0 else 0.0, dt / rp[5] if rp[5] > 0.0 else 0.0,
        ],
        dtype=float,
    )  # fmt: skip


# ------------------------------------------------------------------ rates
# The helpers below are inlined where they are called (``inline="always"``:
# a compiled call passing a dozen arrays costs more than the arithmetic),
# and they take arrays one by one: taking a field of a named tuple, unpacking
# a tuple of arrays or slicing inside the time loop binds a new reference, two
# atomic reference-count updates each (measured: together 3x the step). So
# the chunk's arrays are made and unpacked once (:func:`_run_chunk`); a
# stage's state and rates are ``ys[s]`` and ``rs[s]`` (s = 0: the step's
# start, 1: Heun's predictor), indexed, never sliced. ``dims`` is (N, ov, oth,
# oc, ob, of, rows, E, C, B, n_filter): the counts and row offsets as one
# tuple of integers (:func:`dims_of`).
#
# Every loop over the lanes is straight-line: branches and loops over DOFs or
# parts stay outside it, so that the compiler unrolls it (and partly
# vectorises it). Measured against this layout (issue 31, docs/benchmarks.md),
# each of these made the step slower, not faster: a loop over the DOFs inside
# the lanes' loop (summing M^-1 K x per lane in a register: 5 DOFs 1.5-2x
# slower), an inlined helper taking arrays called inside the lanes' loop
# (reference counts in every lane: 2-3x), a tuple of arrays unpacked in the
# time loop (2-3x), and rows carried as 8-tuples ("bundles", to free the
# compiler from aliasing: no vector code resulted, and the helpers' calls
# cost reference counts).


@numba.njit(cache=True)
def dims_of(layout):
    """``dims``: the layout's counts and row offsets (:func:`row_offsets`) as one int tuple."""
    n, e, c, b = layout.n_dof, layout.n_elements, layout.n_circuits, layout.n_bridges
    ov, oth, oc, ob, of = row_offsets_compiled(n, e, c, b)
    return (n, ov, oth, oc, ob, of, layout.n_rows, e, c, b, layout.n_filter)


@numba.njit(cache=True, inline="always")
def _rect(t, b):
    """Bridge b's constants (row b of the table) as the tuple the rectified steps take."""
    return (
        t[b, 0], t[b, 1], t[b, 2], t[b, 3], t[b, 4], t[b, 5], t[b, 6], t[b, 7], t[b, 8], t[b, 9],
        t[b, 10], t[b, 11], t[b, 12], t[b, 13], t[b, 14], t[b, 15], t[b, 16], t[b, 17],
    )  # fmt: skip


@numba.njit(cache=True)
def _callback(slot, p, du, theta, cb0, cb1, cb2, cb3):
    """(F (N), theta') of a generic (registered, not built-in) law through its callback.

    The callbacks travel one by one (a tuple of function-typed values is an
    experimental numba type, and the parallel loop does not take one); this
    is called apart from the built-in laws' loop, where the mere presence of
    the callbacks costs twice the force (measured).
    """
    if slot == 0:
        return cb0(p, du, theta)
    if slot == 1:
        return cb1(p, du, theta)
    if slot == 2:
        return cb2(p, du, theta)
    return cb3(p, du, theta)


@numba.njit(cache=True, inline="always")
def _push(rs, s, ov, n, push, part, tmp):
    """rs[s, v rows] -= push[part] * tmp: a force tmp on the part's coordinate, on every DOF."""
    for a in range(n):
        g = push[part, a]
        if g != 0.0:
            for j in range(LANES):
                rs[s, ov + a, j] -= g * tmp[j]


@numba.njit(cache=True, inline="always")
def _linear_rates(ys, rs, s, dims, stiffness, damping, drive, fa, fc, tmp):
    """The linear part's acceleration; the filter's rates and its output's push.

    x' = v is not copied into ``rs``: :func:`_advance` reads the velocities.
    """
    n, ov, of, n_filter = dims[0], dims[1], dims[5], dims[10]
    for a in range(n):
        for j in range(LANES):
            rs[s, ov + a, j] = 0.0
        for b in range(n):
            kab = stiffness[a, b]
            cab = damping[a, b]
            if kab != 0.0:
                for j in range(LANES):
                    rs[s, ov + a, j] -= kab * ys[s, b, j]
            if cab != 0.0:
                for j in range(LANES):
                    rs[s, ov + a, j] -= cab * ys[s, ov + b, j]
    if n_filter > 0:
        for q in range(n_filter):
            for j in range(LANES):
                total = 0.0
                for b in range(n_filter):
                    total += fa[q, b] * ys[s, of + b, j]
                rs[s, of + q, j] = total
        for j in range(LANES):
            total = 0.0
            for b in range(n_filter):
                total += fc[b] * ys[s, of + b, j]
            tmp[j] = total
        _push(rs, s, ov, n, drive, 0, tmp)


@numba.njit(cache=True, inline="always")
def _element_rates(
    ys, rs, fs, s, dims, coords, push, springs, kinds, slots, fp, p, cb0, cb1, cb2, cb3, tmp
):
    """Each element's force k2 u^2 + k3 u^3 + F(u', theta) and its friction state's rate.

    ``fs[s, e]`` gets the friction force F alone (for the accumulators); ``p``
    is a scratch row for the law's parameters; ``cb0`` .. ``cb3`` the callbacks.
    """
    n, ov, oth, n_elements = dims[0], dims[1], dims[2], dims[7]
    for e in range(n_elements):
        i = coords[e, 0]
        k = coords[e, 1]
        k2 = springs[e, 0]
        k3 = springs[e, 1]
        kind = kinds[e]
        slot = slots[e]
        for q in range(p.size):
            p[q] = fp[e, q]
        if kind == KERNEL_GENERIC:
            for j in range(LANES):
                du = ys[s, ov + i, j] - ys[s, ov + k, j]
                fs[s, e, j], rs[s, oth + e, j] = _callback(
                    slot, p, du, ys[s, oth + e, j], cb0, cb1, cb2, cb3
                )
        else:
            for j in range(LANES):
                du = ys[s, ov + i, j] - ys[s, ov + k, j]
                fs[s, e, j], rs[s, oth + e, j] = friction_force_and_rate(
                    kind, p, du, ys[s, oth + e, j]
                )
        for j in range(LANES):
            u = ys[s, i, j] - ys[s, k, j]
            tmp[j] = (k2 + k3 * u) * u * u + fs[s, e, j]
        _push(rs, s, ov, n, push, e, tmp)


@numba.njit(cache=True, inline="always")
def _circuit_rates(ys, rs, s, dims, coords, push, circuits, tmp):
    """Each linear circuit's state rate ``a s + b u'`` and its force ``f s`` on its coordinate."""
    n, ov, oc, n_elements, n_circuits = dims[0], dims[1], dims[3], dims[7], dims[8]
    for c in range(n_circuits):
        part = n_elements + c
        i = coords[part, 0]
        k = coords[part, 1]
        a_s = circuits[c, 0]
        b_s = circuits[c, 1]
        f_s = circuits[c, 2]
        for j in range(LANES):
            du = ys[s, ov + i, j] - ys[s, ov + k, j]
            state = ys[s, oc + c, j]
            rs[s, oc + c, j] = a_s * state + b_s * du
            tmp[j] = f_s * state
        _push(rs, s, ov, n, push, part, tmp)


@numba.njit(cache=True, inline="always")
def _bridges_rates(ys, rs, stage, s, dims, coords, push, bridges, tmp):
    """Each bridge's force and states' rates (:func:`~randvib.montecarlo.rectified_kernel._bridge_rates`).

    ``stage[s, b]`` and ``stage[2 + s, b]`` get the coil's current (A) and the
    conducting diodes' drop (V) at stage s.
    """
    n, ov, ob, n_parts, n_bridges = dims[0], dims[1], dims[4], dims[7] + dims[8], dims[9]
    for b in range(n_bridges):
        part = n_parts + b
        i = coords[part, 0]
        k = coords[part, 1]
        rect = _rect(bridges, b)
        q = ob + 2 * b
        for j in range(LANES):
            du = ys[s, ov + i, j] - ys[s, ov + k, j]
            # with 1/m = 1 the bridge's "acceleration" is minus its force on the coordinate
            minus_force, ds1, ds2, i_b, v_drop = _bridge_rates(
                du, ys[s, q, j], ys[s, q + 1, j], rect, 1.0
            )
            rs[s, q, j] = ds1
            rs[s, q + 1, j] = ds2
            stage[s, b, j] = i_b
            stage[2 + s, b, j] = v_drop
            tmp[j] = -minus_force
        _push(rs, s, ov, n, push, part, tmp)


# ------------------------------------------------------------------ the step
@numba.njit(cache=True, inline="always")
def _advance(ys, rs, gain, noise, dt, weights, dims, predictor):
    """Every row but the bridges': the predictor (into ys[1]) or the scheme's update (ys[0]).

    The displacements' rates are the velocities (read from ``ys``, rows
    ``ov ..``; they take no noise), and they are advanced before the
    velocities are overwritten. The base's rows stay at zero and are skipped.
    """
    b1, b2 = weights
    n, ov, oth, ob, of, rows = dims[0], dims[1], dims[2], dims[4], dims[5], dims[6]
    if predictor:
        for a in range(n):
            for j in range(LANES):
                ys[1, a, j] = ys[0, a, j] + ys[0, ov + a, j] * dt
    elif b2 == 0.0:
        for a in range(n):
            for j in range(LANES):
                ys[0, a, j] = ys[0, a, j] + b1 * ys[0, ov + a, j] * dt
    else:
        for a in range(n):
            for j in range(LANES):
                ys[0, a, j] = ys[0, a, j] + (b1 * ys[0, ov + a, j] + b2 * ys[1, ov + a, j]) * dt
    # the bridges' rows (ob .. of - 1) take their own steps: _bridges_predictor, _bridges_update
    for part in range(3):
        if part == 0:
            lo, hi = ov, ov + n
        elif part == 1:
            lo, hi = oth, ob
        else:
            lo, hi = of, rows
        if predictor:
            for row in range(lo, hi):
                g = gain[row]
                for j in range(LANES):
                    ys[1, row, j] = ys[0, row, j] + rs[0, row, j] * dt + g * noise[j]
        elif b2 == 0.0:
            for row in range(lo, hi):
                g = gain[row]
                for j in range(LANES):
                    ys[0, row, j] = ys[0, row, j] + b1 * rs[0, row, j] * dt + g * noise[j]
        else:
            for row in range(lo, hi):
                g = gain[row]
                for j in range(LANES):
                    ys[0, row, j] = (
                        ys[0, row, j]
                        + (b1 * rs[0, row, j] + b2 * rs[1, row, j]) * dt
                        + g * noise[j]
                    )


@numba.njit(cache=True, inline="always")
def _bridges_predictor(ys, rs, dt, dims, bridges):
    """The bridges' states at the predictor: an Euler stage, clamped or blocked."""
    ob, n_bridges = dims[4], dims[9]
    for b in range(n_bridges):
        rect = _rect(bridges, b)
        q = ob + 2 * b
        for j in range(LANES):
            ys[1, q, j], ys[1, q + 1, j] = _bridge_predictor(
                ys[0, q, j], ys[0, q + 1, j], rs[0, q, j], rs[0, q + 1, j], dt, rect
            )


@numba.njit(cache=True, inline="always")
def _bridges_update(ys, rs, stage, dt, weights, dims, bridges, acc, first, in_window):
    """The bridges' states after the step, and (in the window) their energies into ``acc``.

    ``stage`` holds the currents at the two stages (``stage[0]``, ``stage[1]``)
    and the diodes' drops (``stage[2]``, ``stage[3]``), each (B, LANES);
    ``first`` is the first bridge accumulator column.
    """
    b1, b2 = weights
    ob, n_bridges = dims[4], dims[9]
    for b in range(n_bridges):
        rect = _rect(bridges, b)
        rkind, output, second, v_b = rect[0], rect[1], rect[3], rect[5]
        q = ob + 2 * b
        col = first + N_BRIDGE_ACC * b
        for j in range(LANES):
            s1, s2 = ys[0, q, j], ys[0, q + 1, j]
            i1, d1 = stage[0, b, j], stage[2, b, j]
            current = b1 * abs(i1)
            coil = b1 * i1 * i1
            diodes = b1 * d1 * abs(i1)
            load = b1 * s2 * s2
            s1n = s1 + b1 * rs[0, q, j] * dt
            s2n = s2 + b1 * rs[0, q + 1, j] * dt
            if b2 != 0.0:
                i2, d2, s2p = stage[1, b, j], stage[3, b, j], ys[1, q + 1, j]
                current += b2 * abs(i2)
                coil += b2 * i2 * i2
                diodes += b2 * d2 * abs(i2)
                load += b2 * s2p * s2p
                s1n = s1 + (b1 * rs[0, q, j] + b2 * rs[1, q, j]) * dt
                s2n = s2 + (b1 * rs[0, q + 1, j] + b2 * rs[1, q + 1, j]) * dt
            if in_window:
                acc[col + BRIDGE_V_OUT, j] += v_b if output == 0 else s2  # at the step's start
            ys[0, q, j], ys[0, q + 1, j], stored, diode = _bridge_update(
                s1, s1n, s2n, current, diodes, load, dt, rect
            )
            if in_window:
                acc[col + BRIDGE_STORED, j] += stored
                acc[col + BRIDGE_COIL, j] += coil * second * dt if rkind != 2 else 0.0
                acc[col + BRIDGE_DIODE, j] += diode


# ------------------------------------------------------------ accumulators
@numba.njit(cache=True, inline="always")
def _accumulate(ys, fs, dw, dims, coords, cols, stroke_coords, limits, ito_weights, acc, was):
    """Add the state at the step's start to the window's sums (:class:`Columns`).

    ``cols`` is (xx, vv, friction, abs_du, circuit, ito, stroke, bridge);
    ``was`` (S, LANES) holds 1 where |u| was beyond its stroke at the state
    before (-1 at the window's first state: no crossing counted into it).
    """
    n, ov, oc, n_elements, n_circuits = dims[0], dims[1], dims[3], dims[7], dims[8]
    xx, vv, fr, ab, ci, ito, st, _ = cols
    col = 0
    for a in range(n):
        for b in range(a, n):
            for j in range(LANES):
                acc[xx + col, j] += ys[0, a, j] * ys[0, b, j]
                acc[vv + col, j] += ys[0, ov + a, j] * ys[0, ov + b, j]
            col += 1
    for e in range(n_elements):
        i = coords[e, 0]
        k = coords[e, 1]
        for j in range(LANES):
            du = ys[0, ov + i, j] - ys[0, ov + k, j]
            acc[fr + e, j] += du * fs[0, e, j]
            acc[ab + e, j] += abs(du)
    for c in range(n_circuits):
        for j in range(LANES):
            acc[ci + c, j] += ys[0, oc + c, j] * ys[0, oc + c, j]
    n_strokes = limits.size
    for q in range(n_strokes):
        i = stroke_coords[q, 0]
        k = stroke_coords[q, 1]
        for j in range(LANES):
            _stroke_state(acc, was, q, j, abs(ys[0, i, j] - ys[0, k, j]), limits[q], st, n_strokes)
    for j in range(LANES):
        total = 0.0
        for a in range(n):
            total += ito_weights[a] * ys[0, ov + a, j]
        acc[ito, j] += total * dw[j]


@numba.njit(cache=True)
def _energy(y, j, dims, mass, stiffness, coords, springs, circuits, bridges):
    """H (J) of lane j of state ``y`` (rows, LANES): kinetic, springs, circuits' and bridges' stores.

    Any function of the state serves the energy-change control (its change
    has zero mean in the stationary state); this one makes it the energy
    whose balance the Ito sum completes.
    """
    n, ov, oc, ob = dims[0], dims[1], dims[3], dims[4]
    h = 0.0
    for a in range(n):
        for b in range(n):
            h += 0.5 * (
                mass[a, b] * y[ov + a, j] * y[ov + b, j] + stiffness[a, b] * y[a, j] * y[b, j]
            )
    for e in range(dims[7]):
        u = y[coords[e, 0], j] - y[coords[e, 1], j]
        h += (springs[e, 0] / 3.0 + 0.25 * springs[e, 1] * u) * u * u * u
    for c in range(dims[8]):
        h += 0.5 * circuits[c, 3] * y[oc + c, j] * y[oc + c, j]
    for b in range(dims[9]):
        s1, s2 = y[ob + 2 * b, j], y[ob + 2 * b + 1, j]
        h += bridges[b, 18] * s1 * s1 + bridges[b, 19] * s2 * s2
    return h


@numba.njit(cache=True, inline="always")
def _stroke_state(acc, was, q, j, u, limit, st, n_strokes):
    """Stroke q's sums in lane j at a state with |u| = ``u``: beyond, peak, up-crossing."""
    beyond = 1.0 if u > limit else 0.0
    acc[st + q, j] += beyond
    if u > acc[st + n_strokes + q, j]:
        acc[st + n_strokes + q, j] = u
    if beyond > 0.0 and was[q, j] == 0.0:
        acc[st + 2 * n_strokes + q, j] += 1.0
    was[q, j] = beyond


# ---------------------------------------------------------------- the loop
@numba.njit(cache=True)
def _start_lanes(y, rng, first, lanes, seed, start, ki, wi, fi):
    """Seed each lane's stream and draw its first state ``y`` (rows, LANES) (:class:`Start`)."""
    rows, chol = start.rows, start.chol
    drawn = np.zeros(rows.size)
    for row in range(y.shape[0]):
        for j in range(LANES):
            y[row, j] = start.state[row] if j < lanes else 0.0
    for j in range(lanes):
        seed_path_state(seed, first + j, rng, j)
        for q in range(rows.size):
            drawn[q] = standard_normal(rng, j, ki, wi, fi)
            total = 0.0
            for p in range(q + 1):
                total += chol[q, p] * drawn[p]
            y[rows[q], j] += total


@numba.njit(cache=True)
def _finite(y, j):
    """True when every state of lane j is finite."""
    for row in range(y.shape[0]):
        if not np.isfinite(y[row, j]):
            return False
    return True


@numba.njit(cache=True)
def _run_chunk(
    chunk, out, failed, records, scheme, dims, linear, parts, cb0, cb1, cb2, cb3, columns, timing,
    paths, start, every, noise, stop,
):  # fmt: skip
    """Paths ``chunk * LANES ..`` of :func:`run_assembly_ensemble`, from start to finish.

    Every array the step reads is bound here, once (module comment above).
    The step is the scheme's (module docstring): the rates at the step's
    start, the window's sums, Heun's predictor and its rates, the update.
    """
    dt, n_steps, n_burn = timing
    seed, first_path, n_paths = paths
    dw, ki, wi, fi, starts = noise.dw, noise.ki, noise.wi, noise.fi, noise.start
    rows, n_elements, n_bridges = dims[6], dims[7], dims[9]
    start_path = chunk * LANES
    lanes = min(LANES, n_paths - start_path)
    rng = np.empty((LANES, 4), dtype=np.uint64)
    ys = np.zeros((2, rows, LANES))  # the state and Heun's predictor
    rs = np.zeros((2, rows, LANES))  # the rates at both stages
    fs = np.zeros((2, n_elements, LANES))  # friction forces at both stages
    stage = np.zeros((4, n_bridges, LANES))  # bridges' currents and drops at both stages
    y = ys[0]
    acc = np.zeros((columns.n, LANES))
    dwl, noise_l, tmp = np.zeros(LANES), np.zeros(LANES), np.zeros(LANES)
    stiffness, damping, gain, drive, fa, fc, amp = linear
    coords, push, springs, kinds, slots, fp, circuits, bridges = parts
    mass, kmat, ito_weights = columns.mass, columns.stiffness, columns.ito_weights
    stroke_coords, limits = columns.stroke_coordinates, columns.stroke_limits
    cols = (columns.xx, columns.vv, columns.friction, columns.abs_du, columns.circuit,
            columns.ito, columns.stroke, columns.bridge)  # fmt: skip
    h0, h1 = columns.h0, columns.h1
    p = np.zeros(fp.shape[1])
    sqdt, given = np.sqrt(dt), dw.shape[0] > 0
    n_stages = 1 if scheme[1] == 0.0 else 2
    _start_lanes(y, rng, first_path + start_path, lanes, seed, start, ki, wi, fi)
    if starts.shape[0] > 0:  # each path's own start (rare events': assembly_paths)
        for j in range(lanes):
            for row in range(rows):
                y[row, j] = starts[start_path + j, row]
    was = np.full((limits.size, LANES), -1.0)  # no up-crossing into the window's first state
    _record(records, y, start_path, lanes, np.int64(0))  # not a literal: one signature
    for n in range(n_steps):
        if n == n_burn:
            for j in range(lanes):
                acc[h0, j] = _energy(y, j, dims, mass, kmat, coords, springs, circuits, bridges)
        for j in range(LANES):  # the step's increment dW (s^0.5); none in unused lanes
            if j >= lanes:
                dwl[j] = 0.0
            elif given:
                dwl[j] = dw[start_path + j, n]
            else:
                dwl[j] = sqdt * standard_normal(rng, j, ki, wi, fi)
            noise_l[j] = amp * dwl[j]
        # the step; Heun's two stages through one call of each rate function, inlined once
        for s in range(n_stages):
            _linear_rates(ys, rs, s, dims, stiffness, damping, drive, fa, fc, tmp)
            _element_rates(ys, rs, fs, s, dims, coords, push, springs, kinds, slots, fp, p,
                           cb0, cb1, cb2, cb3, tmp)  # fmt: skip
            _circuit_rates(ys, rs, s, dims, coords, push, circuits, tmp)
            _bridges_rates(ys, rs, stage, s, dims, coords, push, bridges, tmp)
            if s == 0:
                if n >= n_burn:  # the window's sums, at the step's start
                    _accumulate(ys, fs, dwl, dims, coords, cols, stroke_coords, limits,
                                ito_weights, acc, was)  # fmt: skip
                if n_stages == 2:
                    _advance(ys, rs, gain, noise_l, dt, scheme, dims, True)
                    _bridges_predictor(ys, rs, dt, dims, bridges)
        _bridges_update(ys, rs, stage, dt, scheme, dims, bridges, acc, cols[7], n >= n_burn)
        _advance(ys, rs, gain, noise_l, dt, scheme, dims, False)
        if records.shape[0] > 0 and (n + 1) % every == 0:
            _record(records, y, start_path, lanes, (n + 1) // every)
        if (n + 1) % CHECK_EVERY == 0 or n == n_steps - 1:
            stopped = False
            for j in range(lanes):
                if not _finite(y, j):
                    failed[start_path + j] = n + 1
                    stopped = True
            if stopped or stop[0] != 0:
                break
    for j in range(lanes):
        acc[h1, j] = _energy(y, j, dims, mass, kmat, coords, springs, circuits, bridges)
        for q in range(limits.size):  # the final state: its peak and a last up-crossing
            if n_steps > n_burn:
                u = abs(y[stroke_coords[q, 0], j] - y[stroke_coords[q, 1], j])
                beyond_sum = acc[columns.stroke + q, j]  # the final state is not a step's start
                _stroke_state(acc, was, q, j, u, limits[q], columns.stroke, limits.size)
                acc[columns.stroke + q, j] = beyond_sum
        _write(out, acc, start_path + j, j, columns, n_steps - n_burn, (n_steps - n_burn) * dt)


@numba.njit(cache=True, parallel=True, nogil=True)
def run_assembly_ensemble(
    scheme, layout, linear, parts, cb0, cb1, cb2, cb3, columns, timing, paths, start, recording,
    noise, stop,
):  # fmt: skip
    """Integrate ``paths.count`` paths of the assembly; per-path time averages (:class:`Columns`).

    Parameters
    ----------
    scheme : (float, float)
        The integrator's weights (b1, b2) (:attr:`Integrator.kernel_weights`).
    layout, linear, parts, columns : Layout, Linear, Parts, Columns
        The assembly as tables (module docstring).
    cb0, cb1, cb2, cb3 : compiled callbacks
        :data:`N_CALLBACKS` friction callbacks (of the one type
        :data:`~randvib.models.friction.KERNEL_SIGNATURE`), one by one (a tuple of
        function-typed values is an experimental numba type that the parallel
        loop does not take); ``Parts.friction_slot`` says which a generic law uses.
    timing, paths, noise : kernel.Timing, kernel.Paths, kernel.Noise
        As for :func:`randvib.montecarlo.kernel.run_ensemble`: the steps, the
        streams (seed, first, count), given increments or the ziggurat tables.
    start : Start
    recording : Recording
    stop : int64[1]
        Set non-zero from another thread (Ctrl-C) to stop at the next check.

    Returns
    -------
    acc : float64[count, columns.n]
    failed_step : int64[count]
        First checked step with a non-finite state, or -1.
    records : float64[n_record, n_points, rows]
    """
    n_steps, n_paths = timing.n_steps, paths.count
    dims = dims_of(layout)
    out = np.zeros((n_paths, columns.n))
    failed = np.full(n_paths, -1, dtype=np.int64)
    points = n_steps // recording.every + 1 if recording.n_record else 0
    records = np.zeros((recording.n_record, points, layout.n_rows))
    for chunk in numba.prange((n_paths + LANES - 1) // LANES):
        # int64 always: the parallel loop's index is typed int64, then uint64 in the
        # compiled gufunc, and each compiled (and cached) _run_chunk once more
        _run_chunk(
            np.int64(chunk), out, failed, records, scheme, dims, linear, parts, cb0, cb1, cb2, cb3, columns,
            timing, paths, start, recording.every, noise, stop,
        )  # fmt: skip
    return out, failed, records


@numba.njit(cache=True)
def _record(records, y, start_path, lanes, point):
    """Keep the whole state of the recorded paths among these lanes at ``point``."""
    for j in range(lanes):
        p = start_path + j
        if p < records.shape[0]:
            for row in range(y.shape[0]):
                records[p, point, row] = y[row, j]


@numba.njit(cache=True)
def _write(out, acc, p, j, columns, window_steps, window):
    """Path p's averages: sums over the window's steps or, for energies (J), over its time."""
    b = columns.bridge
    extremes = columns.stroke + columns.stroke_limits.size  # peaks and counts, not averages
    for q in range(columns.n):
        if q == columns.h0 or q == columns.h1 or q >= extremes:
            out[p, q] = acc[q, j]
        elif q == columns.ito or (b <= q < columns.ito and (q - b) % N_BRIDGE_ACC != BRIDGE_V_OUT):
            out[p, q] = acc[q, j] / window
        else:
            out[p, q] = acc[q, j] / window_steps
