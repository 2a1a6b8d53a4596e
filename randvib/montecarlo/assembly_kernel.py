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
(:func:`row_offsets`). Every operation loops over the :data:`LANES` paths of
a chunk innermost: the paths' arithmetic is independent and identical, so a
path's result does not depend on its lane, its chunk, the threads or the
batches, and the compiler vectorises the loops across lanes (each lane's
operations stay the same IEEE operations in the same order: the results are
bit for bit those of scalar code).

**The scheme** is the single-mass kernel's additive-noise predictor-corrector
(:class:`randvib.montecarlo.integrators.Integrator` weights (b1, b2)):
``y_p = y + R(y) dt + G dW``, ``y_{n+1} = y + (b1 R(y) + b2 R(y_p)) dt + G dW``
with the noise gain G: ``r`` on the velocities under white or given input, the
filter's input gain on its states under a rational spectrum. Tones and shock
trains (the single mass's :class:`~randvib.montecarlo.kernel.Forcing`) add
their exact step integral ``u_n`` of -a(t) to the velocities as ``r u_n / 2``
before the step and again after it (:func:`_forcing_first_half`).

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

from randvib.models.friction import (
    KERNEL_COULOMB,
    KERNEL_GENERIC,
    KERNEL_NONE,
    KERNEL_TANH,
    friction_force_and_rate,
)
from randvib.montecarlo.kernel import CHECK_EVERY
from randvib.montecarlo.rectified_kernel import _bridge_predictor, _bridge_rates, _bridge_update
from randvib.montecarlo.rng import seed_path_state, standard_normal
from randvib.montecarlo.stop_flag import stop_requested

#: Paths advanced together in a chunk (the single-mass kernel's are 8): the step's loops
#: over them are vectorised, and 32 amortise each loop's set-up (a path's result does
#: not depend on its lane or chunk).
LANES = 32
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
# The helpers of the step below are compiled apart without reference counting
# and inlined by LLVM where they are called (:data:`_step`). Inlined by numba
# instead (``inline="always"``), every array a helper takes was bound to a new
# variable, two atomic reference-count updates (calls into the runtime) each,
# and numba's pruning left most of them in the time loop: profiled (perf, the
# 2-DOF benchmark), the draws of the noise alone spent 8 such calls per
# path-step, together more than half the step. They take arrays one by one
# (taking a field of a named tuple, unpacking a tuple of arrays or slicing
# inside the time loop binds a new reference), so the chunk's arrays are made
# and unpacked once (:func:`_run_chunk`); a stage's state and rates are
# ``ys[s]`` and ``rs[s]`` (s = 0: the step's start, 1: Heun's predictor),
# indexed, never sliced. ``dims`` is (N, ov, oth, oc, ob, of, rows, E, C, B,
# n_filter): the counts and row offsets as one tuple of integers
# (:func:`dims_of`); the step's helpers get it with the chunk's live lanes
# appended (``dims[11]``).
#
# Every loop over the lanes is straight-line and runs to that run-time count:
# branches and loops over DOFs or parts stay outside it, and the compiler,
# not knowing the count, vectorises it (4 doubles an instruction, with a
# run-time check that the rows written and read do not overlap). Over a
# constant count (LANES) it unrolled the loop into scalar code instead (numba
# keeps LLVM's straight-line vectoriser off). Measured (issue 31,
# docs/benchmarks.md), each of these made the step slower, not faster: a
# loop over the DOFs inside the lanes' loop (summing M^-1 K x per lane in a
# register: 5 DOFs 1.5-2x slower), a tuple of arrays unpacked in the time
# loop (2-3x), and rows carried as 8-tuples ("bundles": no vector code). A
# row's acceleration is zeroed, then its couplings subtracted: starting from
# its first coupling saves a pass over scalar code, but the select it takes
# inside the lanes' loop may keep the loop from vectorising (not measured).

#: The step's helpers: no reference counts (``_nrt=False``: they allocate
#: nothing) and LLVM's ``alwaysinline`` (``forceinline``), so that a call
#: passing a dozen arrays costs nothing once compiled.
_step = numba.njit(cache=True, _nrt=False, forceinline=True)


@numba.njit(cache=True)
def dims_of(layout):
    """``dims``: the layout's counts and row offsets (:func:`row_offsets`) as one int tuple."""
    n, e, c, b = layout.n_dof, layout.n_elements, layout.n_circuits, layout.n_bridges
    ov, oth, oc, ob, of = row_offsets_compiled(n, e, c, b)
    return (n, ov, oth, oc, ob, of, layout.n_rows, e, c, b, layout.n_filter)


@_step
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


@_step
def _push(rs, s, ov, n, push, part, tmp, nl):
    """rs[s, v rows] -= push[part] * tmp: a force tmp on the part's coordinate, on every DOF."""
    for a in range(n):
        g = push[part, a]
        if g != 0.0:
            for j in range(nl):
                rs[s, ov + a, j] -= g * tmp[j]


@numba.njit(cache=True)
def _couplings(stiffness, damping):
    """The nonzero entries of ``stiffness`` and ``damping`` (M^-1 K_lin, M^-1 C_lin), row by row.

    Returns ``(start, columns, values)``: row a's entries are ``start[a] ..
    start[a + 1] - 1``, entry q couples DOF ``columns[q]`` with the weights
    ``values[q] = (K_ab, C_ab)``, one of them possibly 0. A host with
    harvesters couples each harvester with the host alone: 13 of 25 entries
    at 5 DOFs, each one pass over the lanes instead of two.
    """
    n = stiffness.shape[0]
    start = np.zeros(n + 1, dtype=np.int64)
    columns = np.zeros(n * n, dtype=np.int64)
    values = np.zeros((n * n, 2))
    q = 0
    for a in range(n):
        for b in range(n):
            if stiffness[a, b] != 0.0 or damping[a, b] != 0.0:
                columns[q] = b
                values[q, 0] = stiffness[a, b]
                values[q, 1] = damping[a, b]
                q += 1
        start[a + 1] = q
    return start, columns, values


@_step
def _linear_rates(ys, rs, s, dims, start, columns, values, drive, fa, fc, tmp):
    """The linear part's acceleration; the filter's rates and its output's push.

    x' = v is not copied into ``rs``: :func:`_advance` reads the velocities.
    The couplings are :func:`_couplings`'s; each is subtracted as K_ab x_b,
    then C_ab v_b, a zero weight skipped (the order of the dense loop).
    """
    n, ov, of, n_filter, nl = dims[0], dims[1], dims[5], dims[10], dims[11]
    for a in range(n):
        for j in range(nl):
            rs[s, ov + a, j] = 0.0
        for q in range(start[a], start[a + 1]):
            b = columns[q]
            kab = values[q, 0]
            cab = values[q, 1]
            if kab != 0.0 and cab != 0.0:  # one pass for both, the same operations
                for j in range(nl):
                    rs[s, ov + a, j] = (rs[s, ov + a, j] - kab * ys[s, b, j]) - cab * ys[
                        s, ov + b, j
                    ]
            elif kab != 0.0:
                for j in range(nl):
                    rs[s, ov + a, j] -= kab * ys[s, b, j]
            else:
                for j in range(nl):
                    rs[s, ov + a, j] -= cab * ys[s, ov + b, j]
    if n_filter > 0:
        for q in range(n_filter):
            for j in range(nl):
                total = 0.0
                for b in range(n_filter):
                    total += fa[q, b] * ys[s, of + b, j]
                rs[s, of + q, j] = total
        for j in range(nl):
            total = 0.0
            for b in range(n_filter):
                total += fc[b] * ys[s, of + b, j]
            tmp[j] = total
        _push(rs, s, ov, n, drive, 0, tmp, nl)


@_step
def _element_rates(
    ys, rs, fs, s, dims, coords, push, springs, kinds, slots, fp, p, cb0, cb1, cb2, cb3, tmp
):
    """Each element's force k2 u^2 + k3 u^3 + F(u', theta) and its friction state's rate.

    ``fs[s, e]`` gets the friction force F alone (for the accumulators); ``p``
    is a scratch row for the law's parameters; ``cb0`` .. ``cb3`` the callbacks.
    Coulomb's law (paper Eq. 4-5, sgn(0) = 0) is written out here, spring and
    friction in one pass without a branch (the commonest law; through the
    built-ins' dispatch, :func:`~randvib.models.friction.friction_force_and_rate`,
    each lane branched on the law and on the sign of u', which the branch
    predictor misses about half the time). Its state keeps its start
    (:func:`_advanced_rows`). The other laws' rates are written for every lane.
    """
    n, ov, oth, n_elements, nl = dims[0], dims[1], dims[2], dims[7], dims[11]
    for e in range(n_elements):
        i = coords[e, 0]
        k = coords[e, 1]
        k2 = springs[e, 0]
        k3 = springs[e, 1]
        kind = kinds[e]
        if kind == KERNEL_COULOMB:
            fc = fp[e, 0]
            for j in range(nl):
                du = ys[s, ov + i, j] - ys[s, ov + k, j]
                # sgn(du) as (du > 0) - (du < 0): no branch on a sign the predictor misses
                # half the time; F_c times +-1 or 0 is exactly +-F_c or 0
                force = fc * (np.float64(du > 0.0) - np.float64(du < 0.0))
                fs[s, e, j] = force
                u = ys[s, i, j] - ys[s, k, j]
                tmp[j] = (k2 + k3 * u) * u * u + force
            _push(rs, s, ov, n, push, e, tmp, nl)
            continue
        for q in range(p.size):
            p[q] = fp[e, q]
        if kind == KERNEL_GENERIC:
            slot = slots[e]
            for j in range(nl):
                du = ys[s, ov + i, j] - ys[s, ov + k, j]
                fs[s, e, j], rs[s, oth + e, j] = _callback(
                    slot, p, du, ys[s, oth + e, j], cb0, cb1, cb2, cb3
                )
        else:
            for j in range(nl):
                du = ys[s, ov + i, j] - ys[s, ov + k, j]
                fs[s, e, j], rs[s, oth + e, j] = friction_force_and_rate(
                    kind, p, du, ys[s, oth + e, j]
                )
        for j in range(nl):
            u = ys[s, i, j] - ys[s, k, j]
            tmp[j] = (k2 + k3 * u) * u * u + fs[s, e, j]
        _push(rs, s, ov, n, push, e, tmp, nl)


@_step
def _circuit_rates(ys, rs, s, dims, coords, push, circuits, tmp):
    """Each linear circuit's state rate ``a s + b u'`` and its force ``f s`` on its coordinate."""
    n, ov, oc, n_elements, n_circuits = dims[0], dims[1], dims[3], dims[7], dims[8]
    nl = dims[11]
    for c in range(n_circuits):
        part = n_elements + c
        i = coords[part, 0]
        k = coords[part, 1]
        a_s = circuits[c, 0]
        b_s = circuits[c, 1]
        f_s = circuits[c, 2]
        for j in range(nl):
            du = ys[s, ov + i, j] - ys[s, ov + k, j]
            state = ys[s, oc + c, j]
            rs[s, oc + c, j] = a_s * state + b_s * du
            tmp[j] = f_s * state
        _push(rs, s, ov, n, push, part, tmp, nl)


@_step
def _bridges_rates(ys, rs, stage, s, dims, coords, push, bridges, tmp):
    """Each bridge's force and states' rates (:func:`~randvib.montecarlo.rectified_kernel._bridge_rates`).

    ``stage[s, b]`` and ``stage[2 + s, b]`` get the coil's current (A) and the
    conducting diodes' drop (V) at stage s.
    """
    n, ov, ob, n_parts, n_bridges = dims[0], dims[1], dims[4], dims[7] + dims[8], dims[9]
    nl = dims[11]
    for b in range(n_bridges):
        part = n_parts + b
        i = coords[part, 0]
        k = coords[part, 1]
        rect = _rect(bridges, b)
        q = ob + 2 * b
        for j in range(nl):
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
        _push(rs, s, ov, n, push, part, tmp, nl)


# ------------------------------------------------------------------ the step
@numba.njit(cache=True)
def _advanced_rows(dims, kinds):
    """The rows :func:`_advance` steps besides x: v, the friction states that move, circuits, filter.

    A memoryless law's state (none, Coulomb, tanh: rate 0, no noise) keeps its
    start for ever, so its row is left out: four of the 5-DOF benchmark's 14.
    """
    n, ov, oth, ob, of, rows = dims[0], dims[1], dims[2], dims[4], dims[5], dims[6]
    out = np.zeros(rows, dtype=np.int64)
    count = 0
    for row in range(ov, ov + n):
        out[count] = row
        count += 1
    for row in range(oth, ob):  # friction states, then circuits
        e = row - oth
        if e < kinds.size and (KERNEL_NONE <= kinds[e] <= KERNEL_TANH):
            continue
        out[count] = row
        count += 1
    # the bridges' rows (ob .. of - 1) take their own steps: _bridges_predictor, _bridges_update
    for row in range(of, rows):
        out[count] = row
        count += 1
    return out[:count]


@_step
def _advance(ys, rs, gain, noise, dt, weights, dims, advanced, predictor):
    """x and the ``advanced`` rows: the predictor (into ys[1]) or the scheme's update (ys[0]).

    The displacements' rates are the velocities (read from ``ys``, rows
    ``ov ..``; they take no noise), and they are advanced before the
    velocities are overwritten. The base's rows stay at zero and are skipped.
    """
    b1, b2 = weights
    n, ov, nl = dims[0], dims[1], dims[11]
    if predictor:
        for a in range(n):
            for j in range(nl):
                ys[1, a, j] = ys[0, a, j] + ys[0, ov + a, j] * dt
    elif b2 == 0.0:
        for a in range(n):
            for j in range(nl):
                ys[0, a, j] = ys[0, a, j] + b1 * ys[0, ov + a, j] * dt
    else:
        for a in range(n):
            for j in range(nl):
                ys[0, a, j] = ys[0, a, j] + (b1 * ys[0, ov + a, j] + b2 * ys[1, ov + a, j]) * dt
    if predictor:
        for q in range(advanced.size):
            row = advanced[q]
            g = gain[row]
            for j in range(nl):
                ys[1, row, j] = ys[0, row, j] + rs[0, row, j] * dt + g * noise[j]
    elif b2 == 0.0:
        for q in range(advanced.size):
            row = advanced[q]
            g = gain[row]
            for j in range(nl):
                ys[0, row, j] = ys[0, row, j] + b1 * rs[0, row, j] * dt + g * noise[j]
    else:
        for q in range(advanced.size):
            row = advanced[q]
            g = gain[row]
            for j in range(nl):
                ys[0, row, j] = (
                    ys[0, row, j] + (b1 * rs[0, row, j] + b2 * rs[1, row, j]) * dt + g * noise[j]
                )


@_step
def _bridges_predictor(ys, rs, dt, dims, bridges):
    """The bridges' states at the predictor: an Euler stage, clamped or blocked."""
    ob, n_bridges, nl = dims[4], dims[9], dims[11]
    for b in range(n_bridges):
        rect = _rect(bridges, b)
        q = ob + 2 * b
        for j in range(nl):
            ys[1, q, j], ys[1, q + 1, j] = _bridge_predictor(
                ys[0, q, j], ys[0, q + 1, j], rs[0, q, j], rs[0, q + 1, j], dt, rect
            )


@_step
def _bridges_update(ys, rs, stage, dt, weights, dims, bridges, acc, first, in_window):
    """The bridges' states after the step, and (in the window) their energies into ``acc``.

    ``stage`` holds the currents at the two stages (``stage[0]``, ``stage[1]``)
    and the diodes' drops (``stage[2]``, ``stage[3]``), each (B, LANES);
    ``first`` is the first bridge accumulator column.
    """
    b1, b2 = weights
    ob, n_bridges, nl = dims[4], dims[9], dims[11]
    for b in range(n_bridges):
        rect = _rect(bridges, b)
        rkind, output, second, v_b = rect[0], rect[1], rect[3], rect[5]
        q = ob + 2 * b
        col = first + N_BRIDGE_ACC * b
        for j in range(nl):
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


@_step
def _increments(dwl, noise_l, rng, lanes, given, dw, start_path, n, sqdt, amp, ki, wi, fi):
    """Step n's increments dW (s^0.5) into ``dwl`` and ``amp dW`` into ``noise_l``; 0 in unused lanes.

    Given increments are read from ``dw``; else each lane draws from its stream.
    """
    for j in range(LANES):
        if j >= lanes:
            dwl[j] = 0.0
        elif given:
            dwl[j] = dw[start_path + j, n]
        else:
            dwl[j] = sqdt * standard_normal(rng, j, ki, wi, fi)
        noise_l[j] = amp * dwl[j]


# ---------------------------------------------------------------- forcing
# Tones and shocks (kernel.Forcing) reach an assembly as they reach the single
# mass (kernel.run_ensemble): the exact step integral u_n of -a(t), here on every
# velocity through r (M x'' = ... - M r a), half before the scheme's step and half
# after it (Strang splitting); the window's sums see the velocities before the
# first half, as the single mass's do (they are swapped in and out around them).
@_step
def _forcing_first_half(
    ys, kick, keep, n, dt, start_path, lanes, dims, drive, omega, gain, phase, kicks
):
    """Half of step n's forcing, r u_n / 2, onto each DOF's velocity; the velocities before into ``keep``.

    ``kick`` gets u_n per lane (:class:`~randvib.montecarlo.kernel.Forcing`), for the second half.

    ``omega``, ``gain``, ``phase``, ``kicks``: the fields of kernel.Forcing, one
    by one (a tuple of arrays unpacked in the time loop costs reference counts).
    """
    n_dof, ov = dims[0], dims[1]
    # kernel._forced_increment's arithmetic, in its order (a one-DOF assembly follows the
    # single mass bit for bit), one tone at a time over the lanes
    for j in range(LANES):
        kick[j] = 0.0
    if kicks.shape[0] > 0:
        for j in range(lanes):
            kick[j] = kicks[start_path + j, n]
    t = (n + 0.5) * dt
    for q in range(omega.shape[0]):
        w, g = omega[q], gain[q]
        for j in range(lanes):
            kick[j] -= g * np.cos(w * t + phase[start_path + j, q])
    for a in range(n_dof):
        r = 0.5 * drive[0, a]
        for j in range(LANES):
            keep[a, j] = ys[0, ov + a, j]
            ys[0, ov + a, j] += r * kick[j]


@_step
def _forcing_swap(ys, keep, dims):
    """Exchange the velocities with ``keep`` (before and after the window's sums)."""
    n_dof, ov = dims[0], dims[1]
    for a in range(n_dof):
        for j in range(LANES):
            v = ys[0, ov + a, j]
            ys[0, ov + a, j] = keep[a, j]
            keep[a, j] = v


@_step
def _forcing_second_half(ys, kick, dims, drive):
    """The step's other half r u_n / 2 onto each DOF's velocity, after the scheme's update."""
    n_dof, ov = dims[0], dims[1]
    for a in range(n_dof):
        r = 0.5 * drive[0, a]
        for j in range(LANES):
            ys[0, ov + a, j] += r * kick[j]


# ------------------------------------------------------------ accumulators
@_step
def _accumulate(ys, fs, dw, dims, coords, cols, stroke_coords, limits, ito_weights, acc, was, tmp):
    """Add the state at the step's start to the window's sums (:class:`Columns`).

    ``cols`` is (xx, vv, friction, abs_du, circuit, ito, stroke, bridge);
    ``was`` (S, LANES) holds 1 where |u| was beyond its stroke at the state
    before (-1 at the window's first state: no crossing counted into it);
    ``tmp`` is scratch for (M r)^T v, summed over the DOFs in their order.
    """
    n, ov, oc, n_elements, n_circuits = dims[0], dims[1], dims[3], dims[7], dims[8]
    nl = dims[11]
    xx, vv, fr, ab, ci, ito, st, _ = cols
    col = 0
    for a in range(n):
        for b in range(a, n):
            for j in range(nl):
                acc[xx + col, j] += ys[0, a, j] * ys[0, b, j]
                acc[vv + col, j] += ys[0, ov + a, j] * ys[0, ov + b, j]
            col += 1
    for e in range(n_elements):
        i = coords[e, 0]
        k = coords[e, 1]
        for j in range(nl):
            du = ys[0, ov + i, j] - ys[0, ov + k, j]
            acc[fr + e, j] += du * fs[0, e, j]
            acc[ab + e, j] += abs(du)
    for c in range(n_circuits):
        for j in range(nl):
            acc[ci + c, j] += ys[0, oc + c, j] * ys[0, oc + c, j]
    n_strokes = limits.size
    for q in range(n_strokes):
        i = stroke_coords[q, 0]
        k = stroke_coords[q, 1]
        for j in range(nl):
            _stroke_state(acc, was, q, j, abs(ys[0, i, j] - ys[0, k, j]), limits[q], st, n_strokes)
    for j in range(nl):
        tmp[j] = 0.0
    for a in range(n):
        w = ito_weights[a]
        for j in range(nl):
            tmp[j] += w * ys[0, ov + a, j]
    for j in range(nl):
        acc[ito, j] += tmp[j] * dw[j]


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
    paths, start, every, noise, stop, forcing,
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
    # the step's loops run over the live lanes: a count the compiler cannot know, so it
    # vectorises them (a constant 8 or 32 it unrolled into scalar code, measured)
    sd = dims + (lanes,)
    rng = np.empty((LANES, 4), dtype=np.uint64)
    ys = np.zeros((2, rows, LANES))  # the state and Heun's predictor
    rs = np.zeros((2, rows, LANES))  # the rates at both stages
    fs = np.zeros((2, n_elements, LANES))  # friction forces at both stages
    stage = np.zeros((4, n_bridges, LANES))  # bridges' currents and drops at both stages
    y = ys[0]
    acc = np.zeros((columns.n, LANES))
    dwl, noise_l, tmp = np.zeros(LANES), np.zeros(LANES), np.zeros(LANES)
    stiffness, damping, gain, drive, fa, fc, amp = linear
    k_start, k_columns, k_values = _couplings(stiffness, damping)
    coords, push, springs, kinds, slots, fp, circuits, bridges = parts
    advanced = _advanced_rows(dims, kinds)  # x, v and the states that move
    mass, kmat, ito_weights = columns.mass, columns.stiffness, columns.ito_weights
    stroke_coords, limits = columns.stroke_coordinates, columns.stroke_limits
    cols = (columns.xx, columns.vv, columns.friction, columns.abs_du, columns.circuit,
            columns.ito, columns.stroke, columns.bridge)  # fmt: skip
    h0, h1 = columns.h0, columns.h1
    p = np.zeros(fp.shape[1])
    sqdt, given = np.sqrt(dt), dw.shape[0] > 0
    n_stages = 1 if scheme[1] == 0.0 else 2
    f_omega, f_gain, f_phase, f_kicks = forcing
    forced = f_omega.shape[0] > 0 or f_kicks.shape[0] > 0  # False: NO_FORCING
    kick, keep = np.zeros(LANES), np.zeros((dims[0], LANES))
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
        _increments(dwl, noise_l, rng, lanes, given, dw, start_path, n, sqdt, amp, ki, wi, fi)
        if forced:
            _forcing_first_half(ys, kick, keep, n, dt, start_path, lanes, dims, drive,
                                f_omega, f_gain, f_phase, f_kicks)  # fmt: skip
        # the step; Heun's two stages through one call of each rate function, inlined once
        for s in range(n_stages):
            _linear_rates(ys, rs, s, sd, k_start, k_columns, k_values, drive, fa, fc, tmp)
            _element_rates(ys, rs, fs, s, sd, coords, push, springs, kinds, slots, fp, p,
                           cb0, cb1, cb2, cb3, tmp)  # fmt: skip
            _circuit_rates(ys, rs, s, sd, coords, push, circuits, tmp)
            _bridges_rates(ys, rs, stage, s, sd, coords, push, bridges, tmp)
            if s == 0:
                if n >= n_burn:  # the window's sums, at the step's start
                    if forced:
                        _forcing_swap(ys, keep, dims)
                    _accumulate(ys, fs, dwl, sd, coords, cols, stroke_coords, limits,
                                ito_weights, acc, was, tmp)  # fmt: skip
                    if forced:
                        _forcing_swap(ys, keep, dims)
                if n_stages == 2:
                    _advance(ys, rs, gain, noise_l, dt, scheme, sd, advanced, True)
                    _bridges_predictor(ys, rs, dt, sd, bridges)
        _bridges_update(ys, rs, stage, dt, scheme, sd, bridges, acc, cols[7], n >= n_burn)
        _advance(ys, rs, gain, noise_l, dt, scheme, sd, advanced, False)
        if forced:
            _forcing_second_half(ys, kick, dims, drive)
        if records.shape[0] > 0 and (n + 1) % every == 0:
            _record(records, y, start_path, lanes, (n + 1) // every)
        if (n + 1) % CHECK_EVERY == 0 or n == n_steps - 1:
            stopped = False
            for j in range(lanes):
                if not _finite(y, j):
                    failed[start_path + j] = n + 1
                    stopped = True
            if stopped or stop_requested(stop):
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
    noise, stop, forcing,
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
    forcing : kernel.Forcing
        Tones and shocks added to the input, the single mass's group
        (:class:`randvib.montecarlo.kernel.Forcing`, built by
        :meth:`randvib.montecarlo.forcing.ForcingInput.group`; its phases and
        kicks per path of this batch); :data:`~randvib.montecarlo.kernel.NO_FORCING`
        without (one compiled signature).

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
            timing, paths, start, recording.every, noise, stop, forcing,
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
