"""The compiled loop's arguments for a run: device, friction, start, recording, auxiliary block.

:class:`KernelSetup` turns a validated :class:`~randvib.montecarlo.validation.Run`
into the argument groups of :func:`randvib.montecarlo.kernel.run_ensemble`
once per run, and adds the paths and the noise for each batch. What the
kernel integrates besides (z, v, theta) is set up here: the linear auxiliary
block (the excitation's shaping filter and a circuit state,
:func:`_auxiliary`), the starting states of the device and its friction-free
companion, and the histogram ranges and recorded paths.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg

from randvib.analytic import exact_solutions as exact
from randvib.models.excitation import Excitation
from randvib.models.friction import kernel_arguments
from randvib.models.harvester import Harvester
from randvib.montecarlo import kernel
from randvib.montecarlo.bridge_step import storage_start
from randvib.montecarlo.forcing import forcing_spread
from randvib.montecarlo.rng import ZIG_FI, ZIG_KI, ZIG_WI
from randvib.montecarlo.step_check import driven_circuit_variance
from randvib.montecarlo.validation import Run


@dataclass(frozen=True)
class KernelSetup:
    """The compiled loop's argument groups (:mod:`randvib.montecarlo.kernel`) for a run.

    Everything but the paths, the noise and the number of recorded paths is
    the same for every batch; :meth:`arguments` adds those for one batch.
    """

    scheme: tuple
    device: kernel.Device
    friction: kernel.Friction
    timing: kernel.Timing
    initial: kernel.Start
    companion: kernel.Companion
    recording: kernel.Recording
    auxiliary: kernel.Auxiliary | None
    rectifier: kernel.Rectifier | None = None

    @classmethod
    def prepare(cls, run: Run, linear) -> KernelSetup:
        """The argument groups; ``linear()`` gives the run's linear test system
        (:class:`~randvib.montecarlo.step_check.LinearTestSystem`)."""
        h = run.harvester
        # Given base-acceleration input arrives as velocity increments (m/s): amplitude 1.
        amplitude = 1.0 if run.driver is not None else np.sqrt(run.psd / 2.0)
        device = (h.m, h.c, h.k, h.k3, amplitude)
        initial, companion = _start_states(run, linear)
        return cls(
            scheme=run.scheme.kernel_weights,
            device=kernel.pack(kernel.Device, *device),
            friction=kernel.pack(kernel.Friction, *kernel_arguments(h.friction)),
            timing=kernel.pack(kernel.Timing, run.grid.dt, run.grid.n_steps, run.grid.n_burn),
            initial=initial,
            companion=companion,
            recording=_recording(run, linear),
            auxiliary=_auxiliary(run, linear),
            rectifier=_rectifier(run),
        )

    def arguments(self, run: Run, lo: int, hi: int) -> dict:
        """The keyword arguments of :func:`~randvib.montecarlo.kernel.run_ensemble`
        for paths ``lo .. hi - 1``."""
        n_record = max(0, min(run.record.record_paths - lo, hi - lo))
        return dict(
            scheme=self.scheme,
            device=self.device,
            friction=self.friction,
            timing=self.timing,
            paths=kernel.pack(kernel.Paths, run.seed, run.first_path + lo, hi - lo),
            initial=self.initial,
            companion=self.companion,
            recording=self.recording._replace(n_record=n_record),
            noise=batch_noise(run, lo, hi),
            auxiliary=self.auxiliary,
            rectifier=self.rectifier,
            forcing=None
            if run.forcing is None
            else run.forcing.group(run.first_path + lo, hi - lo),
        )


def batch_noise(run, lo: int, hi: int) -> kernel.Noise:
    """The noise of paths ``lo`` to ``hi - 1`` of a run (a single mass's or an assembly's).

    Increments from the run's driver (a given base acceleration, synthesised or
    recorded), else its given ``dW`` rows, else none: the kernel draws them from
    the paths' own streams with the ziggurat tables.
    """
    if run.driver is not None:
        dw = run.driver(run.first_path + lo, hi - lo)
    else:
        dw = run.dW[lo:hi] if run.dW is not None else np.zeros((0, 0))
    return kernel.Noise(np.ascontiguousarray(dw, dtype=float), ZIG_KI, ZIG_WI, ZIG_FI)


def _auxiliary(run: Run, linear) -> kernel.Auxiliary | None:
    """The kernel's linear auxiliary block: the excitation's filter and the circuit state.

    None for white noise with a resistive (or no) circuit. The filter's states
    (A, G, C: :class:`randvib.models.excitation.ShapingFilter`) come first, the
    circuit's (``x' = a x + b v``, acceleration ``-(f/m) x``) last. With a
    random start the filter alone starts from its exact stationary law N(0, P),
    A P + P A^T + q G G^T = 0; with a circuit the block starts from its
    marginal law under the linearised device
    (:meth:`~randvib.montecarlo.step_check.LinearTestSystem.covariance`).
    Synthesised or recorded input (``run.driver``) reaches the velocity as
    given increments, like white noise: only a circuit needs the block, and it
    starts from its statistical-linearisation variance under that input.
    """
    h, excitation = run.harvester, run.excitation
    driven_input = run.driver is not None
    if (excitation.is_white or driven_input) and not h.has_circuit:
        return None
    n = kernel.N_AUX
    a, b, g, c, square = np.zeros((n, n)), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    n_filter = 0
    if not (excitation.is_white or driven_input):
        shaping = excitation.shaping_filter()
        system = shaping.system
        n_filter = system.n_states
        a[:n_filter, :n_filter] = system.a
        g[:n_filter] = system.b
        c[:n_filter] = system.c[0]
        q = shaping.noise_intensity
        start = linalg.solve_continuous_lyapunov(system.a, -q * np.outer(system.b, system.b))
    n_states = n_filter
    if h.has_circuit:
        a_x, b_x, f = h.electrical.circuit_equation()
        a[n_filter, n_filter], b[n_filter], c[n_filter] = a_x, b_x, f / h.m
        square[n_filter] = 1.0
        n_states += 1
        if driven_input:
            start = np.array([[_driven_circuit_variance(h, excitation)]])
        else:
            cov = linear().covariance  # (filter, z, v, circuit)
            keep = [*range(n_filter), cov.shape[0] - 1]
            start = cov[np.ix_(keep, keep)]
    chol = np.zeros((n, n))
    chol[:n_states, :n_states] = np.linalg.cholesky(start)
    # white noise (or the given increments) drives the velocity itself
    gain = 1.0 if excitation.is_white or driven_input else 0.0
    coefficients = np.concatenate([a.ravel(), b, g, c, [gain]])
    return kernel.pack(kernel.Auxiliary, n_states, coefficients, square, chol)


def _rectifier(run: Run) -> kernel.Rectifier | None:
    """The kernel's bridge (:class:`randvib.montecarlo.kernel.Rectifier`); None without one.

    The storage capacitor starts at :func:`~randvib.montecarlo.bridge_step.storage_start`
    (its charge-balance level where the closure gives one, else empty: then
    :func:`randvib.montecarlo.validation.check_options` warns when the
    burn-in is shorter than a few R_L C).
    """
    if not run.harvester.is_rectified:
        return None
    code, output, p = run.harvester.electrical.kernel_parameters()
    return kernel.pack(kernel.Rectifier, code, output, p, storage_start(run))


def _driven_circuit_variance(harvester: Harvester, excitation: Excitation) -> float:
    """E[x^2] of the circuit state under synthesised or recorded input, for the random start.

    The linear device of the step check under the (coarsened) spectrum
    (:func:`randvib.montecarlo.step_check.driven_circuit_variance`); the
    burn-in corrects the start.
    """
    return driven_circuit_variance(harvester, excitation)


def _start_states(run: Run, linear) -> tuple[kernel.Start, kernel.Companion]:
    """Initial states of the device and of its friction-free companion."""
    h, psd = run.harvester, run.psd
    random = run.initial.kind == "stationary"
    z, v = linear().spread if random else (run.initial.z, run.initial.v)
    if random and run.forcing is not None:
        # the tones' and shocks' own spread on the linearised device (the random part's
        # only where there is one: tones alone see a nominal level, kept out of the start)
        z, v = forcing_spread(run, linear(), (z, v) if psd else (0.0, 0.0))
    # The friction-free companion starts from its own stationary spread (exact
    # Gaussian velocity, Gibbs displacement variance), so its known moments
    # hold from t = 0 and its control mean is right without a long burn-in.
    comp_z, comp_v = z, v
    if run.companion and random and h.c > 0:
        comp_v = float(np.sqrt(exact.linear_velocity_variance(h.m, h.c, psd)))
        comp_z = float(np.sqrt(exact.gibbs_displacement_moment(h.m, h.c, h.k, h.k3, psd)))
        if h.friction is None or h.friction.vanishes:  # the device is its own companion
            z, v = comp_z, comp_v
    return (
        kernel.pack(kernel.Start, random, z, v),
        kernel.pack(kernel.Companion, run.companion, comp_z, comp_v),
    )


def _recording(run: Run, linear) -> kernel.Recording:
    """Histogram ranges and bins (default ranges +-5 linearised std); records per batch.

    The free mass's z spreads like a random walk: its default range is
    +-5 sqrt(2 sigma_v^2 (m/c_eff) t_end), five times the walk's spread at the end.
    """
    bins = run.record.histogram_bins
    if bins == 0:
        lo, hi = np.zeros(2), np.ones(2)  # unused
    else:
        ranges = run.record.histogram_range
        if ranges is None:
            sz, sv = linear().spread
            if run.harvester.potential.is_free:
                c_eff = linear().c_eff
                sz = sv * np.sqrt(2.0 * run.harvester.m / c_eff * run.grid.t_end)
            ranges = ((-5 * sz, 5 * sz), (-5 * sv, 5 * sv))
        arr = np.asarray(ranges, dtype=float)
        lo, hi = arr[:, 0], arr[:, 1]
    stroke = np.inf if run.harvester.stroke is None else run.harvester.stroke
    return kernel.pack(kernel.Recording, lo, hi, bins, 0, run.record.record_every, stroke)
