"""An assembly as a path simulator: rare events of one coordinate of a device of several masses.

:class:`AssemblyPaths` is the :class:`~randvib.montecarlo.path_simulator.PathSimulator`
of an :class:`~randvib.models.assembly.Assembly` (docs/assemblies.md), so that
:func:`randvib.first_passage` (subset simulation, crude Monte Carlo, and
importance sampling for a linear assembly) estimates the first passage of the
relative coordinate u = d^T x of one element or transducer (``stroke_on``)
through its stroke D. It runs the assembly's own compiled kernel
(:func:`randvib.montecarlo.assembly_kernel.run_assembly_ensemble`, its one
signature: no new compilation) on given increments, and reads each path's
peak |u|, up-crossings and fraction of steps beyond D from the kernel's
stroke columns. A path's row is

    xi = (start normals | one normal per step),

* the **start**: for a linear assembly the scheme's own exact stationary
  Gaussian law of (filter, x, v, circuit states), x0 = L xi, L the Cholesky
  factor of the discrete Lyapunov solution P = A P A^T + dt B B^T of the
  kernel's recursion (built here from the kernel's own tables, so that the
  window starts stationary to rounding at any dt); otherwise the linearised
  assembly's stationary Gaussian law
  (:class:`~randvib.montecarlo.assembly_step_check.AssemblyTestSystem`, as
  ``simulate`` draws it) followed by a burn-in of
  :data:`~randvib.montecarlo.path_simulator.BURN_IN_DECAYS` energy decay
  times 1 / (2 min |Re lambda|) of the linearised system, which the window
  does not monitor;
* the **input**: the Brownian increments dW_n = sqrt(dt) xi_n of white noise
  or of a rational spectrum's shaping filter. Band-limited and tabulated
  spectra (synthesised per path from the seed) and records are refused: their
  input is not a function of the row here.

A linear assembly also offers its :class:`~randvib.montecarlo.path_simulator.LinearSurrogate`
(u_n = a_n . xi exactly), so importance sampling's change of drift towards the
design points is exact for it; a nonlinear assembly has none
(:func:`randvib.first_passage` refuses importance sampling for it).
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numba
import numpy as np
from scipy import linalg

from randvib._interrupts import interruptible
from randvib._validation import check_positive
from randvib.analytic.assembly_crossings import stroke_coordinate
from randvib.models.assembly import Assembly
from randvib.models.excitation import Measured, as_excitation
from randvib.montecarlo import assembly_kernel as ak
from randvib.montecarlo import kernel
from randvib.montecarlo.assembly_setup import AssemblyKernelSetup, start_state
from randvib.montecarlo.assembly_simulation import validated_assembly
from randvib.montecarlo.assembly_step_check import AssemblyTestSystem
from randvib.montecarlo.batches import SimulationDivergedError
from randvib.montecarlo.path_simulator import (
    BURN_IN_DECAYS,
    MAX_BATCH_SAMPLES,
    RARE_STEP_BIAS,
    SMALL_CALL_STEPS,
    LinearSurrogate,
    PathOutcome,
    PathSimulator,
)
from randvib.montecarlo.rng import ZIG_FI, ZIG_KI, ZIG_WI

__all__ = ["AssemblyPaths", "default_assembly_step", "kernel_linear_system"]


def kernel_linear_system(setup: AssemblyKernelSetup) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rows, F, G): the linear system the kernel integrates, over its active rows.

    ``rows`` are the kernel's rows of x, v, the linear circuits' and the
    filter's states (the base's, friction and bridge rows left out); F and G
    give ``dy = F y dt + G dW`` on them, read from the kernel's own tables
    (:class:`~randvib.montecarlo.assembly_kernel.Linear`, :class:`~randvib.montecarlo.assembly_kernel.Parts`).
    Valid for a linear assembly (its elements' forces are all in C_lin, K_lin).
    """
    lay, lin, parts = setup.layout, setup.linear, setup.parts
    n, e, c = lay.n_dof, lay.n_elements, lay.n_circuits
    ov, _, oc, _, of = ak.row_offsets(n, e, c, lay.n_bridges)
    f = np.zeros((lay.n_rows, lay.n_rows))
    f[np.arange(n), ov + np.arange(n)] = 1.0
    f[ov : ov + n, :n] = -lin.stiffness
    f[ov : ov + n, ov : ov + n] = -lin.damping
    for slot in range(c):
        part = e + slot
        i, k = parts.coordinates[part]
        a_s, b_s, f_s, _ = parts.circuits[slot]
        f[oc + slot, ov + i] += b_s
        f[oc + slot, ov + k] -= b_s  # k = n is the base's zero velocity row: dropped below
        f[oc + slot, oc + slot] = a_s
        f[ov : ov + n, oc + slot] -= parts.push[part] * f_s
    nf = lay.n_filter
    f[of : of + nf, of : of + nf] = lin.filter_a[:nf, :nf]
    f[ov : ov + n, of : of + nf] -= np.outer(lin.drive[0], lin.filter_c[:nf])
    rows = np.array([*range(n), *range(ov, ov + n), *range(oc, oc + c), *range(of, of + nf)])
    g = lin.gain * lin.noise_amp
    return rows, f[np.ix_(rows, rows)], g[rows][:, None]


class AssemblyPaths(PathSimulator):
    """An assembly's monitored coordinate as a path simulator (module docstring).

    Parameters
    ----------
    assembly : Assembly
    excitation : float or Excitation
        White-noise level S or a rational spectrum (band-pass, Kanai-Tajimi).
    stroke : float, optional
        D (m); default the monitored part's own stroke.
    stroke_on : str, optional
        ``element.N`` or ``transducer.N``; default the one part with a stroke.
    duration : float
        Monitored window T (s), > 0, rounded to whole steps.
    dt : float
        Step (s); checked on the linearised assembly as ``simulate`` checks it.
    scheme : str
        ``heun`` or ``euler-maruyama``.
    burn_in : float, optional
        Unmonitored time before the window (s); default 0 for a linear
        assembly (exact start), 10 energy decay times otherwise.
    """

    def __init__(self, assembly, excitation, *, stroke=None, stroke_on=None, duration, dt,
                 scheme="heun", burn_in=None):  # fmt: skip
        if not isinstance(assembly, Assembly):
            raise ValueError(
                f"`assembly` must be a randvib.Assembly, got {type(assembly).__name__}"
            )
        excitation = as_excitation(excitation)
        if isinstance(excitation, Measured) or excitation.shaping_filter() is None:
            raise ValueError(
                "the rare events of an assembly are estimated over its Brownian increments: "
                "white noise or a rational spectrum (band-pass, Kanai-Tajimi); a band-limited "
                f"or tabulated spectrum or a record is not taken yet, got {excitation.name}"
            )
        self.coordinate, self.stroke = stroke_coordinate(assembly, stroke_on, stroke)
        device = assembly.updated({f"{self.coordinate}.stroke": self.stroke})
        self.assembly, self.excitation = device, excitation
        self.column = [path for path, _, _ in device.strokes()].index(self.coordinate)
        duration = float(check_positive("duration", duration, "s"))
        system = functools.cache(lambda: AssemblyTestSystem.of(device, excitation))
        self.exactly_linear = device.is_linear
        if burn_in is None:
            decay = float(np.min(-linalg.eigvals(system().drift).real))
            burn_in = 0.0 if self.exactly_linear else BURN_IN_DECAYS / (2.0 * decay)
        probe = self._run(duration, dt, scheme, 0.0)
        system().check_step(probe.scheme.name, probe.grid.dt)
        window = probe.grid.n_steps * probe.grid.dt
        self.run = self._run(float(burn_in) + window, dt, scheme, float(burn_in))
        grid = self.run.grid
        self.duration, self.burn_in, self.dt = grid.window_steps * grid.dt, grid.burn_in, grid.dt
        self.steps_per_path = grid.n_steps
        self.setup = AssemblyKernelSetup.prepare(self.run, system)
        if self.exactly_linear:
            self._start = self._exact_start()
            self.start = "exact: the scheme's stationary Gaussian law of the linear assembly"
        else:
            stationary = dataclasses.replace(
                self.run, initial=("stationary", *self.run.initial[1:])
            )
            self._start = start_state(stationary, self.setup.layout, system())
            self.start = f"linearised Gaussian law, then {self.burn_in:g} s of burn-in"
        self._n_start = self._start.chol.shape[0]
        self.dimension = self._n_start + grid.n_steps

    def _run(self, t_end, dt, scheme, burn_in):
        return validated_assembly(
            self.assembly, self.excitation, scheme, t_end=t_end, dt=dt, burn_in=burn_in,
            n_paths=1, seed=0, first_path=0, initial="rest", dW=None, record=(0, 1),
        )  # fmt: skip

    @functools.cached_property
    def _recursion(self):
        """(rows, A, B) of the kernel's scheme on the linear assembly's active rows."""
        rows, f, g = kernel_linear_system(self.setup)
        a, b = self.run.scheme.linear_recursion(f, g, self.dt)
        if not np.max(np.abs(linalg.eigvals(a))) < 1.0:
            raise ValueError(
                f"the linear assembly has no stationary state under the {self.run.scheme.name} "
                f"step dt = {self.dt!r} s (a mode does not decay): its first passage from a "
                "stationary state is not defined"
            )
        return rows, a, b

    def _exact_start(self) -> ak.Start:
        rows, a, b = self._recursion
        covariance = linalg.solve_discrete_lyapunov(a, self.dt * (b @ b.T))
        chol = np.linalg.cholesky(0.5 * (covariance + covariance.T))
        return ak.Start(np.zeros(self.setup.layout.n_rows), rows.astype(np.int64), chol)

    @functools.cached_property
    def linear_surrogate(self) -> LinearSurrogate | None:
        """u_n = c . y_n of the linear assembly on the same rows (None for a nonlinear one)."""
        if not self.exactly_linear:
            return None
        rows, a, b = self._recursion
        pick = np.zeros(self.setup.layout.n_rows)
        i, k = self.setup.columns.stroke_coordinates[self.column]
        pick[i] += 1.0
        pick[k] -= 1.0  # k = N (the base's row) is not among the rows
        grid = self.run.grid
        return LinearSurrogate(a, b[:, 0], pick[rows], self._start.chol, self.dt,
                               grid.n_burn, grid.n_steps)  # fmt: skip

    def starts(self, normals) -> np.ndarray:
        """Each row's first state of the kernel (rows of its state array), shape (paths, rows)."""
        normals = np.asarray(normals, dtype=float)
        out = np.tile(self._start.state, (normals.shape[0], 1))
        out[:, self._start.rows] += normals @ self._start.chol.T
        return out

    def __call__(self, normals) -> PathOutcome:
        normals = np.ascontiguousarray(normals, dtype=float)
        if normals.ndim != 2 or normals.shape[1] != self.dimension:
            raise ValueError(
                f"`normals` must have shape (n_paths, {self.dimension}), got {normals.shape}"
            )
        batch = max(1, MAX_BATCH_SAMPLES // self.dimension)
        acc = np.empty((normals.shape[0], self.setup.columns.n))
        for lo in range(0, normals.shape[0], batch):
            acc[lo : lo + batch] = self._batch(normals[lo : lo + batch], lo)
        first = self.setup.columns.stroke + self.column
        count = self.setup.columns.stroke_limits.size
        return PathOutcome(acc[:, first + count], acc[:, first + 2 * count], acc[:, first])

    def _batch(self, rows, lo) -> np.ndarray:
        noise = kernel.Noise(
            np.ascontiguousarray(math.sqrt(self.dt) * rows[:, self._n_start :]),
            ZIG_KI, ZIG_WI, ZIG_FI, np.ascontiguousarray(self.starts(rows[:, : self._n_start])),
        )  # fmt: skip
        arguments = self.setup.arguments(self.run, 0, 1)
        arguments.update(noise=noise, paths=kernel.pack(kernel.Paths, 0, lo, rows.shape[0]))
        if rows.shape[0] * self.steps_per_path > SMALL_CALL_STEPS:
            acc, failed, _ = interruptible(ak.run_assembly_ensemble, **arguments)
        else:  # a Markov chain step of a few dozen paths: one thread (path_simulator's reason)
            threads = numba.get_num_threads()
            numba.set_num_threads(1)
            try:
                acc, failed, _ = ak.run_assembly_ensemble(stop=np.zeros(1, np.int64), **arguments)
            finally:
                numba.set_num_threads(threads)
        bad = np.flatnonzero(failed >= 0)
        if bad.size:
            raise SimulationDivergedError(
                f"simulation diverged: a path became non-finite by step {failed[bad[0]]} with dt "
                f"= {self.dt!r} s, scheme {self.run.scheme.name}; assembly "
                f"{self.assembly.describe()}"
            )
        return acc


def default_assembly_step(assembly: Assembly, excitation, scheme: str) -> float:
    """The step of :func:`randvib.first_passage` on an assembly when none is given (s).

    The largest step whose stationary-variance bias on the linearised assembly
    stays below :data:`~randvib.montecarlo.path_simulator.RARE_STEP_BIAS`, rounded
    down to one significant digit (the single mass also checks its spring's
    tangent at the stroke; here the linearised assembly alone is checked).
    """
    step = AssemblyTestSystem.of(assembly, as_excitation(excitation)).largest_step(
        scheme, RARE_STEP_BIAS
    )
    if not step > 0:
        raise ValueError("no step keeps the scheme's bias below 1e-4 for this assembly: give `dt`")
    scale = 10.0 ** math.floor(math.log10(step))
    return math.floor(step / scale) * scale
