"""The assembly kernel's tables for a run: structure, parts, accumulators, start.

:class:`AssemblyKernelSetup` turns a validated
:class:`~randvib.montecarlo.assembly_simulation.AssemblyRun` into the argument
groups of :func:`randvib.montecarlo.assembly_kernel.run_assembly_ensemble`
once per run, and adds the paths and the noise for each batch:

* :func:`parts_tables` - the elements (springs' k2, k3, friction laws), the
  linear circuits (a, b, f) and the bridges (the rectified steps' constants)
  with their coordinates and pushes ``M^-1 d``;
* :func:`linear_tables` - ``M^-1 K_lin``, ``M^-1 C_lin``, the noise gain of
  each row (the influence r on the velocities under white or given input; the
  filter's input gain under a rational spectrum) and the shaping filter;
* :func:`column_layout` - where each per-path average lives;
* :func:`start_state` - the fixed start and the rows drawn at random from the
  linearised stationary law (:class:`~randvib.montecarlo.assembly_step_check.AssemblyTestSystem`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg

from randvib.models.assembly import Assembly
from randvib.models.friction import KERNEL_GENERIC, N_KERNEL_PARAMETERS, kernel_arguments
from randvib.models.friction import _no_generic_kernel as NO_CALLBACK
from randvib.models.rectifier import CAPACITOR, PIEZO
from randvib.montecarlo import assembly_kernel as ak
from randvib.montecarlo import kernel
from randvib.montecarlo.kernel_setup import batch_noise


@dataclass(frozen=True)
class PartOrder:
    """Which transducers are linear circuits and which are bridges, in transducer order."""

    circuits: tuple[int, ...]
    bridges: tuple[int, ...]

    @classmethod
    def of(cls, assembly: Assembly) -> PartOrder:
        return cls(
            tuple(i for i, t in enumerate(assembly.transducers) if t.is_dynamic),
            tuple(i for i, t in enumerate(assembly.transducers) if t.is_rectified),
        )


def layout_of(assembly: Assembly, n_filter: int) -> ak.Layout:
    """The counts of every kind of row (:class:`~randvib.montecarlo.assembly_kernel.Layout`)."""
    order = PartOrder.of(assembly)
    n, e, c, b = assembly.n_dof, len(assembly.elements), len(order.circuits), len(order.bridges)
    rows = ak.row_offsets(n, e, c, b)[4] + n_filter
    return kernel.pack(ak.Layout, n, e, c, b, n_filter, rows)


def parts_tables(assembly: Assembly, dt: float) -> tuple[ak.Parts, tuple]:
    """Elements, then linear circuits, then bridges as the kernel's tables (:class:`Parts`),
    and the friction callbacks."""
    n = assembly.n_dof
    order = PartOrder.of(assembly)
    parts = [*assembly.elements, *(assembly.transducers[i] for i in order.circuits)]
    parts += [assembly.transducers[i] for i in order.bridges]
    m_inv = linalg.inv(assembly.mass)
    coordinates = np.array(
        [(p.between[0], n if p.between[1] is None else p.between[1]) for p in parts],
        dtype=np.int64,
    ).reshape(len(parts), 2)
    push = np.array([m_inv @ assembly.incidence(p) for p in parts]).reshape(len(parts), n)
    springs = np.zeros((len(assembly.elements), 2))
    for index, element in enumerate(assembly.elements):
        if element.spring is not None:
            springs[index] = element.spring.k2, element.spring.k3
    kinds, slots, p, callbacks = _friction_tables(assembly)
    circuits = np.zeros((len(order.circuits), 4))
    for row, index in enumerate(order.circuits):
        a_s, b_s, f_s = assembly.transducers[index].coupling.circuit_equation()
        circuits[row] = a_s, b_s, f_s, f_s / b_s
    bridges = np.zeros((len(order.bridges), ak.N_BRIDGE))
    for row, index in enumerate(order.bridges):
        code, output, rp = assembly.transducers[index].coupling.kernel_parameters()
        bridges[row, :18] = ak.bridge_constants(code, output, rp, dt)
        # energy of the first state (C_p V_p^2 / 2 or L i^2 / 2) and of the storage capacitor
        bridges[row, 18] = 0.5 * (rp[1] if code == PIEZO else rp[8])
        bridges[row, 19] = 0.5 * rp[4] if output == CAPACITOR else 0.0
    parts = ak.Parts(
        coordinates, np.ascontiguousarray(push, dtype=float), springs, kinds, slots, p, circuits,
        bridges,
    )  # fmt: skip
    return parts, callbacks


def _friction_tables(assembly: Assembly):
    """(kinds, callback slots, parameters, callbacks) of the elements' friction laws."""
    count = len(assembly.elements)
    kinds = np.zeros(count, dtype=np.int64)
    slots = np.zeros(count, dtype=np.int64)
    p = np.zeros((count, N_KERNEL_PARAMETERS))
    callbacks = []
    for index, element in enumerate(assembly.elements):
        kinds[index], p[index], fn = kernel_arguments(element.friction)
        if kinds[index] == KERNEL_GENERIC:
            if fn not in callbacks:
                callbacks.append(fn)
            slots[index] = callbacks.index(fn)
    if len(callbacks) > ak.N_CALLBACKS:
        raise ValueError(
            f"the assembly's elements use {len(callbacks)} different registered friction laws "
            f"outside randvib's built-ins; the compiled kernel takes at most {ak.N_CALLBACKS}"
        )
    callbacks += [NO_CALLBACK] * (ak.N_CALLBACKS - len(callbacks))
    return kinds, slots, p, tuple(callbacks)


def linear_tables(assembly: Assembly, excitation, layout: ak.Layout, driven: bool) -> ak.Linear:
    """``M^-1 K_lin``, ``M^-1 C_lin``, the rows' noise gains and the shaping filter (:class:`Linear`)."""
    n = assembly.n_dof
    m, c, k = assembly.linear_matrices()
    m_inv = linalg.inv(m)
    ov, _, _, _, of = ak.row_offsets(n, layout.n_elements, layout.n_circuits, layout.n_bridges)
    gain = np.zeros(layout.n_rows)
    filter_a, filter_c = np.zeros((2, 2)), np.zeros(2)
    if layout.n_filter:
        system = excitation.shaping_filter().system
        nf = layout.n_filter
        filter_a[:nf, :nf] = system.a
        filter_c[:nf] = system.c[system.output("acceleration")]
        gain[of : of + nf] = system.b
    else:  # white noise, or the given increments, drives the velocities through r
        gain[ov : ov + n] = assembly.influence
    amplitude = 1.0 if driven else np.sqrt(excitation.level / 2.0)
    return kernel.pack(
        ak.Linear,
        m_inv @ k,
        m_inv @ c,
        gain,
        assembly.influence[None, :],
        filter_a,
        filter_c,
        amplitude,
    )


def column_layout(assembly: Assembly, layout: ak.Layout) -> ak.Columns:
    """Where each per-path average is (:class:`~randvib.montecarlo.assembly_kernel.Columns`)."""
    n = assembly.n_dof
    tri = n * (n + 1) // 2
    friction = 2 * tri
    abs_du = friction + layout.n_elements
    circuit = abs_du + layout.n_elements
    bridge = circuit + layout.n_circuits
    ito = bridge + ak.N_BRIDGE_ACC * layout.n_bridges
    strokes = assembly.strokes()
    coordinates = np.array(
        [(b[0], n if b[1] is None else b[1]) for _, b, _ in strokes], dtype=np.int64
    ).reshape(len(strokes), 2)
    limits = np.array([s for _, _, s in strokes], dtype=float)
    m, _, k = assembly.linear_matrices()
    return ak.Columns(
        0, tri, friction, abs_du, circuit, bridge, ito, ito + 1, ito + 2, ito + 3,
        ito + 3 + 3 * len(strokes), m, k, np.ascontiguousarray(m @ assembly.influence),
        coordinates, limits,
    )  # fmt: skip


def upper_index(n: int, a: int, b: int) -> int:
    """Position of entry (a, b) of a symmetric N x N matrix in the kernel's upper triangle."""
    a, b = min(a, b), max(a, b)
    return a * n - a * (a - 1) // 2 + (b - a)


def start_state(run, layout: ak.Layout, system) -> ak.Start:
    """The fixed start and, for ``initial="stationary"``, the rows drawn from the linearised law.

    Drawn jointly: the filter's states, every x and v, the linear circuits'
    states (:attr:`AssemblyTestSystem.start_covariance`). Friction states and
    the bridges' states start at 0 (a storage capacitor empty: the burn-in
    charges it).
    """
    assembly = run.assembly
    n = assembly.n_dof
    ov, _, oc, _, of = ak.row_offsets(n, layout.n_elements, layout.n_circuits, layout.n_bridges)
    state = np.zeros(layout.n_rows)
    if run.initial[0] == "state":
        state[:n], state[ov : ov + n] = run.initial[1], run.initial[2]
    if run.initial[0] != "stationary":
        return ak.Start(state, np.zeros(0, dtype=np.int64), np.zeros((0, 0)))
    nf = system.n_filter
    surrogate_circuits = system.surrogate.circuit_transducers
    rows = [of + q for q in range(nf)] + list(range(n)) + list(range(ov, ov + n))
    keep = list(range(nf + 2 * n))
    for slot, index in enumerate(PartOrder.of(assembly).circuits):
        rows.append(oc + slot)
        keep.append(nf + 2 * n + surrogate_circuits.index(index))
    chol = _cholesky(system.start_covariance[np.ix_(keep, keep)])
    return ak.Start(state, np.array(rows, dtype=np.int64), chol)


def _cholesky(cov: np.ndarray) -> np.ndarray:
    """Lower Cholesky factor; a state the linearised law pins (zero variance) stays at 0."""
    cov = 0.5 * (cov + cov.T)
    scale = np.max(np.abs(np.diag(cov))) if cov.size else 0.0
    try:
        out = np.linalg.cholesky(cov)
    except np.linalg.LinAlgError:
        out = np.linalg.cholesky(cov + 1e-12 * scale * np.eye(cov.shape[0]))
    return np.ascontiguousarray(out)


@dataclass(frozen=True)
class AssemblyKernelSetup:
    """The assembly kernel's argument groups for a run; :meth:`arguments` adds a batch's."""

    scheme: tuple
    layout: ak.Layout
    linear: ak.Linear
    parts: ak.Parts
    callbacks: tuple
    columns: ak.Columns
    timing: kernel.Timing
    start: ak.Start

    @classmethod
    def prepare(cls, run, system) -> AssemblyKernelSetup:
        """The tables of ``run``; ``system()`` gives its linear test system (for the start)."""
        assembly, excitation = run.assembly, run.excitation
        driven = run.driver is not None
        n_filter = (
            0 if driven or excitation.is_white else excitation.shaping_filter().system.n_states
        )
        layout = layout_of(assembly, n_filter)
        needs_system = run.initial[0] == "stationary"
        parts, callbacks = parts_tables(assembly, run.grid.dt)
        return cls(
            scheme=run.scheme.kernel_weights,
            layout=layout,
            linear=linear_tables(assembly, excitation, layout, driven),
            parts=parts,
            callbacks=callbacks,
            columns=column_layout(assembly, layout),
            timing=kernel.pack(kernel.Timing, run.grid.dt, run.grid.n_steps, run.grid.n_burn),
            start=start_state(run, layout, system() if needs_system else None),
        )

    def arguments(self, run, lo: int, hi: int) -> dict:
        """The keyword arguments of :func:`run_assembly_ensemble` for paths ``lo .. hi - 1``."""
        n_record = max(0, min(run.record_paths - lo, hi - lo))
        return dict(
            scheme=self.scheme,
            layout=self.layout,
            linear=self.linear,
            parts=self.parts,
            **dict(zip(("cb0", "cb1", "cb2", "cb3"), self.callbacks, strict=True)),
            columns=self.columns,
            timing=self.timing,
            paths=kernel.pack(kernel.Paths, run.seed, run.first_path + lo, hi - lo),
            start=self.start,
            recording=kernel.pack(ak.Recording, n_record, run.record_every),
            noise=batch_noise(run, lo, hi),
        )
