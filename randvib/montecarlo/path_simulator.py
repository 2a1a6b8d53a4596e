"""Paths as functions of standard normals: what the rare-event estimators simulate.

The rare-event estimators (:mod:`randvib.montecarlo.subset_simulation`,
:mod:`randvib.montecarlo.importance_sampling`, :mod:`randvib.montecarlo.reliability`)
never see a device. They see a *path simulator*: given a batch of standard
normal vectors xi (one row per path, :attr:`PathSimulator.dimension` entries),
it returns each path's largest |u| over the monitored window, the number of
times |u| rises through the stroke D (both ends) and the fraction of the
window's steps with |u| > D, for one monitored coordinate u. Every random
thing about a path is a function of its row, so that a Markov chain or an
importance-sampling density on the rows is one on the paths. A device with
several masses (:mod:`randvib.models` assemblies) plugs in by providing the
same interface.

:class:`HarvesterPaths` is the single-mass device of :func:`randvib.simulate`
(u = z) under every input simulate takes. Its row is

    xi = (start normals | input normals),

* the **start**, so that "from the stationary state" is part of the
  randomness: for a linear device (no friction, k3 = 0, no bridge; white or
  filtered input, any circuit) the scheme's own exact stationary Gaussian law
  of (z, v, filter, circuit), x0 = L xi, L the Cholesky factor of the
  discrete Lyapunov solution P = A P A^T + dt B B^T; for a friction-free
  device under white noise with a resistive coupling the exact Gibbs law,
  z0 = F^-1(Phi(xi_0)) (:class:`randvib.analytic.gibbs_marginal.GibbsDisplacement`),
  v0 = sigma_v xi_1; otherwise the linearised device's stationary Gaussian
  law followed by a burn-in of :data:`BURN_IN_DECAYS` energy decay times
  m / c_eq (its increments part of xi), which the window does not monitor;
* the **input**: white noise and filtered spectra as the Brownian
  increments dW_n = sqrt(dt) xi_n, one per step; band-limited and tabulated
  spectra (and a record's Welch spectrum) as the normals of their stationary
  frequency-domain synthesis (:func:`randvib.models.excitation.synthesised_increments`),
  linear in xi.

Where the device is linear in xi, or has a linearisation, the simulator also
offers a :class:`LinearSurrogate`: the linear(ised) response z_n = a_n . xi at
every monitored state, which importance sampling uses for its design points.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numba
import numpy as np
from scipy import linalg

from randvib._interrupts import interruptible
from randvib._validation import check_positive
from randvib.analytic.gibbs_marginal import GibbsDisplacement
from randvib.models.excitation import Measured, as_excitation, synthesised_increments
from randvib.models.harvester import Harvester
from randvib.montecarlo import kernel
from randvib.montecarlo.batches import raise_if_diverged
from randvib.montecarlo.kernel_setup import KernelSetup
from randvib.montecarlo.rng import ZIG_FI, ZIG_KI, ZIG_WI
from randvib.montecarlo.step_check import LinearTestSystem
from randvib.montecarlo.validation import check_scales, validated

__all__ = ["HarvesterPaths", "LinearSurrogate", "PathOutcome", "PathSimulator", "default_step"]

#: The default step keeps the scheme's stationary-variance bias below this on the
#: linearised device and on its spring's tangent at the stroke (a 1e-4 variance
#: bias moves a tail probability at u standard deviations by about u^2 / 2 times
#: that: 0.2 % at 1e-9), and resolves the crossings (omega dt about 0.02 for Heun).
RARE_STEP_BIAS = 1e-4
#: Burn-in of an approximate (linearised) start, in energy decay times m / c_eq.
BURN_IN_DECAYS = 10.0
#: Calls of at most this many path-steps run on the calling thread, single-threaded.
SMALL_CALL_STEPS = 200_000
#: Input samples per compiled call (bounds the memory of the increments: 32 MiB).
MAX_BATCH_SAMPLES = 2**22


@dataclass(frozen=True)
class PathOutcome:
    """What a path simulator returns for a batch of rows.

    Attributes
    ----------
    peak : ndarray
        Largest |u| over the window's states, its first and last included (m).
    upcrossings : ndarray
        Number of steps on which |u| rises through the stroke (both ends).
    beyond : ndarray
        Fraction of the window's steps with |u| > stroke.
    """

    peak: np.ndarray
    upcrossings: np.ndarray
    beyond: np.ndarray


class PathSimulator:
    """The interface the rare-event estimators need (a base class to document it).

    Attributes
    ----------
    dimension : int
        Standard normals per path.
    steps_per_path : int
        Integration steps per path (burn-in included): the cost unit "path-steps".
    duration : float
        Monitored window T (s).
    stroke : float
        D (m).
    dt : float
        Step (s).
    burn_in : float
        Unmonitored time before the window (s).
    start : str
        How the stationary start is drawn, in words.
    linear_surrogate : LinearSurrogate or None
        The linear(ised) response for importance sampling; None where there is none.
    exactly_linear : bool
        The surrogate is the device itself (its response is linear in xi).
    """

    dimension: int
    steps_per_path: int
    duration: float
    stroke: float
    dt: float = math.nan
    burn_in: float = 0.0
    start: str = ""
    linear_surrogate = None
    exactly_linear: bool = False

    def __call__(self, normals) -> PathOutcome:  # pragma: no cover - abstract
        """The outcome of each row of ``normals`` (shape (n_paths, dimension))."""
        raise NotImplementedError


@dataclass(frozen=True)
class LinearSurrogate:
    """A linear response to the rows: z_n = c . x_n, x_{n+1} = A x_n + b sqrt(dt) xi_{s+n}.

    ``x_0 = L xi[:s]`` (s = ``n_start``); the monitored states are n_burn ..
    n_steps. :meth:`responses` gives them for a batch; :meth:`gradient` the
    vector a_n with z_n = a_n . xi (the direction of the design point of
    z_n = +-D, at distance D / |a_n|).
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    start: np.ndarray
    dt: float
    n_burn: int
    n_steps: int

    @property
    def n_start(self) -> int:
        return self.start.shape[1]

    @functools.cached_property
    def _impulse(self) -> np.ndarray:
        """h[m] = c A^(m-1) b sqrt(dt), m = 0 .. n_steps (h[0] = 0): xi_k's effect on z_(k+m)."""
        h = np.zeros(self.n_steps + 1)
        x = self.b * math.sqrt(self.dt)
        for m in range(1, self.n_steps + 1):
            h[m] = self.c @ x
            x = self.a @ x
        return h

    @functools.cached_property
    def _start_rows(self) -> np.ndarray:
        """c A^n L for the monitored states n (rows): the start's effect on z_n."""
        rows = np.empty((self.n_steps - self.n_burn + 1, self.n_start))
        x = self.start.copy()
        for n in range(self.n_steps + 1):
            if n >= self.n_burn:
                rows[n - self.n_burn] = self.c @ x
            x = self.a @ x
        return rows

    @functools.cached_property
    def sigma(self) -> np.ndarray:
        """Standard deviation of z_n at the monitored states (m): |a_n|."""
        h2 = np.cumsum(self._impulse**2)
        n = np.arange(self.n_burn, self.n_steps + 1)
        return np.sqrt(np.sum(self._start_rows**2, axis=1) + h2[n])

    def gradient(self, index: int) -> np.ndarray:
        """a_n for the monitored state ``index`` (0 .. window steps): z_n = a_n . xi."""
        n = self.n_burn + index
        out = np.zeros(self.n_start + self.n_steps)
        out[: self.n_start] = self._start_rows[index]
        # xi_k (k < n) reaches z_n through h[n - k]
        out[self.n_start : self.n_start + n] = self._impulse[n:0:-1]
        return out

    def responses(self, normals) -> np.ndarray:
        """z_n at the monitored states for each row, shape (n_paths, window steps + 1)."""
        normals = np.asarray(normals, dtype=float)
        x0 = normals[:, : self.n_start] @ self.start.T
        z = _linear_responses(self.a, self.b * math.sqrt(self.dt), self.c, x0,
                              normals[:, self.n_start :], self.n_burn)  # fmt: skip
        return z


@numba.njit(cache=True)
def _linear_responses(a, b, c, x0, noise, n_burn):
    """z_n = c . x_n at n = n_burn .. n_steps of x_{n+1} = A x_n + b noise_n, per row."""
    n_paths, n_steps = noise.shape
    d = a.shape[0]
    out = np.empty((n_paths, n_steps - n_burn + 1))
    x = np.empty(d)
    y = np.empty(d)
    for p in range(n_paths):
        for i in range(d):
            x[i] = x0[p, i]
        for n in range(n_steps + 1):
            if n >= n_burn:
                acc = 0.0
                for i in range(d):
                    acc += c[i] * x[i]
                out[p, n - n_burn] = acc
            if n == n_steps:
                break
            for i in range(d):
                acc = b[i] * noise[p, n]
                for j in range(d):
                    acc += a[i, j] * x[j]
                y[i] = acc
            for i in range(d):
                x[i] = y[i]
    return out


class HarvesterPaths(PathSimulator):
    """The single-mass harvester of :func:`randvib.simulate` as a path simulator (u = z).

    Parameters
    ----------
    harvester : Harvester
        Any device :func:`randvib.simulate` takes (friction, circuits, bridges,
        any confining potential); the free mass is refused (no stationary z).
    excitation : float or Excitation
        White-noise level S or an excitation; a measured record is simulated
        through its Welch spectrum (Gaussian input with the record's PSD).
    stroke : float
        D (m), > 0.
    duration : float
        Monitored window T (s), > 0, rounded to whole steps.
    dt : float
        Step (s); refused where :func:`randvib.simulate` refuses it.
    scheme : str
        ``heun`` or ``euler-maruyama``.
    burn_in : float, optional
        Unmonitored time before the window (s); default 0 for an exact start,
        :data:`BURN_IN_DECAYS` m / c_eq otherwise.
    """

    def __init__(self, harvester, excitation, *, stroke, duration, dt, scheme="heun", burn_in=None):
        if not isinstance(harvester, Harvester):
            raise ValueError(
                f"`harvester` must be a randvib.Harvester, got {type(harvester).__name__}"
            )
        stroke = float(check_positive("stroke", stroke, "m"))
        duration = float(check_positive("duration", duration, "s"))
        excitation = as_excitation(excitation)
        if isinstance(excitation, Measured):  # Gaussian input with the record's spectrum
            excitation = excitation.spectrum
        if harvester.potential.is_free:
            raise ValueError(
                "the free mass (k = k3 = 0) has no stationary displacement: its first passage "
                "from a stationary state is not defined"
            )
        device = harvester.updated(stroke=stroke)
        self.excitation = excitation
        self.stroke = stroke
        self._exact = _exact_start(device, excitation)
        probe = validated(
            device, excitation, scheme, t_end=duration, dt=dt, burn_in=0.0, n_paths=1, seed=0,
            first_path=0, initial="rest", dW=None, companion=False, record=(0, None, 0, 1),
        )  # fmt: skip
        linear = functools.cache(lambda: LinearTestSystem.of(device.linear_surrogate(), excitation))
        check_scales(probe, linear)
        linear().check_step(probe.scheme.name, probe.grid.dt)
        if burn_in is None:
            burn_in = 0.0 if self._exact else BURN_IN_DECAYS * device.m / linear().c_eff
        burn_in = float(np.asarray(burn_in, dtype=float))
        window = probe.grid.n_steps * probe.grid.dt
        self.run = validated(
            device, excitation, scheme, t_end=burn_in + window, dt=dt, burn_in=burn_in,
            n_paths=1, seed=0, first_path=0, initial="rest", dW=None, companion=False,
            record=(0, None, 0, 1),
        )  # fmt: skip
        grid = self.run.grid
        self.duration = grid.window_steps * grid.dt
        self.burn_in = grid.burn_in
        self.dt = grid.dt
        self.steps_per_path = grid.n_steps
        self.setup = KernelSetup.prepare(self.run, linear)
        self._linear = linear
        self._gaussian = None
        if self._exact != "gibbs":
            self._gaussian = _GaussianStart.of(self.run, linear, self.setup.auxiliary)
        self.exactly_linear = self._exact == "linear"
        n_start = 2 if self._exact == "gibbs" else self._gaussian.n_normals
        self._n_start = n_start
        driven = self.run.driver is not None
        self._n_input = 2 * (grid.n_steps // 2 + 1) if driven else grid.n_steps
        self.dimension = n_start + self._n_input
        self.start = {
            "linear": "exact: the scheme's stationary Gaussian law of the linear device",
            "gibbs": "exact: the Gibbs law of z, Gaussian v (white noise, no friction)",
            None: f"linearised Gaussian law, then {self.burn_in:g} s of burn-in",
        }[self._exact]
        if self._exact == "gibbs":
            h = device
            self._gibbs = GibbsDisplacement(h.m, h.c, h.k, h.k3, self.run.psd)

    @functools.cached_property
    def linear_surrogate(self) -> LinearSurrogate | None:
        """The linear(ised) device with its filter and circuit on the same rows (not under
        synthesised input, whose rows are frequency-domain normals)."""
        if self.run.driver is not None:
            return None
        g = self._gaussian or _GaussianStart.of(self.run, self._linear, None)
        a, b = self.run.scheme.linear_recursion(g.drift, g.noise, self.run.grid.dt)
        start = g.factor if self._exact != "gibbs" else np.diag(g.factor.diagonal())
        return LinearSurrogate(a, b[:, 0], g.pick_z, start, self.run.grid.dt,
                               self.run.grid.n_burn, self.run.grid.n_steps)  # fmt: skip

    def _starts(self, normals) -> np.ndarray:
        """The kernel's starting states (z, v, x1, x2, x3), shape (n_paths, N_START)."""
        out = np.zeros((normals.shape[0], kernel.N_START))
        if self._exact == "gibbs":
            out[:, 0] = self._gibbs.from_normal(normals[:, 0])
            out[:, 1] = self._gibbs.velocity_std * normals[:, 1]
            return out
        return self._gaussian.states(normals)

    def _increments(self, normals) -> np.ndarray:
        if self.run.driver is not None:  # velocity increments of the synthesised input
            grid = self.run.grid
            return -synthesised_increments(self.excitation, grid.n_steps, grid.dt, normals)
        return math.sqrt(self.run.grid.dt) * normals

    def __call__(self, normals) -> PathOutcome:
        normals = np.ascontiguousarray(normals, dtype=float)
        if normals.ndim != 2 or normals.shape[1] != self.dimension:
            raise ValueError(
                f"`normals` must have shape (n_paths, {self.dimension}), got {normals.shape}"
            )
        batch = max(1, MAX_BATCH_SAMPLES // self.dimension)
        acc = np.empty((normals.shape[0], kernel.N_ACC))
        for lo in range(0, normals.shape[0], batch):
            rows = normals[lo : lo + batch]
            acc[lo : lo + batch] = self._run(rows, lo)
        averages = kernel.PathAverages(acc)
        return PathOutcome(averages.peak, averages.upcrossings, averages.beyond_stroke)

    def _run(self, rows, lo) -> np.ndarray:
        s = self.setup
        noise = kernel.Noise(
            np.ascontiguousarray(self._increments(rows[:, self._n_start :])),
            ZIG_KI, ZIG_WI, ZIG_FI,
            np.ascontiguousarray(self._starts(rows[:, : self._n_start])),
        )  # fmt: skip
        arguments = dict(
            scheme=s.scheme, device=s.device, friction=s.friction, timing=s.timing,
            paths=kernel.pack(kernel.Paths, 0, lo, rows.shape[0]), initial=s.initial,
            companion=s.companion, recording=s.recording, noise=noise,
            auxiliary=s.auxiliary, rectifier=s.rectifier,
            forcing=None,  # no tones or shocks: run_ensemble then picks its lean or full loop
        )  # fmt: skip
        if rows.shape[0] * self.steps_per_path > SMALL_CALL_STEPS:
            acc, failed, _, _ = interruptible(kernel.run_ensemble, **arguments)
        else:
            # a Markov chain step of a few dozen paths: milliseconds, so neither a
            # watcher thread for Ctrl-C nor the threads' start-up is worth its cost
            threads = numba.get_num_threads()
            numba.set_num_threads(1)
            try:
                acc, failed, _, _ = kernel.run_ensemble(stop=np.zeros(1, np.int64), **arguments)
            finally:
                numba.set_num_threads(threads)
        raise_if_diverged(self.run, lo, failed)
        return acc


def default_step(harvester: Harvester, excitation, scheme: str, stroke: float) -> float:
    """The step of :func:`randvib.first_passage` when none is given (s).

    The largest step whose stationary-variance bias (:func:`randvib.montecarlo.step_check.step_bias`)
    stays below :data:`RARE_STEP_BIAS` both on the linearised device and on the
    device whose spring is stiffened to its tangent k + 3 k3 D^2 at the stroke
    (where the crossings happen), rounded down to one significant digit.
    """
    excitation = as_excitation(excitation)
    if isinstance(excitation, Measured):
        excitation = excitation.spectrum
    stroke = float(check_positive("stroke", stroke, "m"))
    device = harvester.linear_surrogate()
    tangent = device.updated(k=float(device.k) + 3.0 * float(device.k3) * stroke**2, k3=0.0)
    step = math.inf
    for h in (device, tangent) if float(device.k3) > 0 else (device,):
        step = min(step, LinearTestSystem.of(h, excitation).largest_step(scheme, RARE_STEP_BIAS))
    if not step > 0:
        raise ValueError("no step keeps the scheme's bias below 1e-4 for this device: give `dt`")
    scale = 10.0 ** math.floor(math.log10(step))
    return math.floor(step / scale) * scale


def _exact_start(h: Harvester, excitation) -> str | None:
    """``"linear"``, ``"gibbs"`` or None: which exact stationary law the start can use."""
    frictionless = h.friction is None or h.friction.vanishes
    if not frictionless or h.is_rectified:
        return None
    rational = excitation.shaping_filter() is not None
    if np.all(h.k3 == 0) and np.all(h.k > 0) and rational:
        return "linear"
    if excitation.is_white and not h.has_circuit and h.c > 0:
        return "gibbs"
    return None


@dataclass(frozen=True)
class _GaussianStart:
    """The stationary Gaussian law of the linear(ised) device under the scheme, as x0 = L xi.

    ``drift``, ``noise`` (F, G of dx = F x dt + G dW over (filter, z, v,
    circuit)); ``factor`` L; ``columns`` the kernel's columns of those
    states; ``pick_z`` the row picking z. Under synthesised input (no such
    system) z and v are independent with the linearised spreads and the
    circuit from the kernel's own start factor.
    """

    drift: np.ndarray
    noise: np.ndarray
    factor: np.ndarray
    columns: list
    pick_z: np.ndarray

    @property
    def n_normals(self) -> int:
        return self.factor.shape[1]

    @classmethod
    def of(cls, run, linear, auxiliary) -> _GaussianStart:
        """The start of ``run``; ``linear()`` its linear test system, ``auxiliary`` the
        kernel's block (:class:`~randvib.montecarlo.kernel.Auxiliary` or None)."""
        lin = linear()
        m = lin.m
        if run.driver is not None:
            sz, sv = lin.spread
            n_aux = 0 if auxiliary is None else auxiliary.n
            factor = np.zeros((2 + n_aux, 2 + n_aux))
            factor[0, 0], factor[1, 1] = sz, sv
            if n_aux:
                factor[2:, 2:] = auxiliary.start[:n_aux, :n_aux]
            return cls(None, None, factor, list(range(2 + n_aux)), None)
        if lin.augmented is None:
            f = np.array([[0.0, 1.0], [-lin.k_eff / m, -lin.c_eff / m]])
            g = np.array([[0.0], [math.sqrt(lin.level / 2.0)]])
            n_filter, n_states = 0, 2
        else:
            f, g, _ = lin.augmented
            n_filter, n_states = lin.n_filter, f.shape[0]
            if n_filter == 0:
                # the block's input is the base acceleration (m z'' = ... - m a): the
                # kernel adds +sqrt(S/2) dW to v, so the rows drive the same path
                g = -g
        a, b = run.scheme.linear_recursion(f, g, run.grid.dt)
        covariance = linalg.solve_discrete_lyapunov(a, run.grid.dt * (b @ b.T))
        factor = np.linalg.cholesky(0.5 * (covariance + covariance.T))
        columns = [2 + i for i in range(n_filter)] + [0, 1]
        columns += [2 + n_filter] if n_states > n_filter + 2 else []
        pick_z = np.zeros(n_states)
        pick_z[n_filter] = 1.0
        return cls(f, g, factor, columns, pick_z)

    def states(self, normals) -> np.ndarray:
        out = np.zeros((normals.shape[0], kernel.N_START))
        out[:, self.columns] = normals @ self.factor.T
        return out
