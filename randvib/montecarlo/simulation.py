"""Monte Carlo simulation of the harvester under white or coloured base excitation: ``simulate``.

The SDE (docs/conventions.md, paper Eq. 1 and 15-17) for the state (z, v = z') and,
for LuGre friction, the bristle state theta:

    dz = v dt
    dv = -(c v + k z + k3 z^3 + F(v, theta)) / m dt + sqrt(S/2) dW
    dtheta = theta'(v, theta) dt

with sqrt(S/2) dW the paper's white base acceleration (Eq. 17). Under a
rational spectrum (band-pass, Kanai-Tajimi) the base acceleration is instead
the output y of the spectrum's 2-state shaping filter driven by that white
noise, and dv gets -y dt in place of the noise (paper Eq. 18 with a
coloured base); the filter states are integrated with the device by the same
scheme (:func:`randvib.montecarlo.kernel.auxiliary_step`). Under a
band-limited or tabulated spectrum y is synthesised per path and dv gets the
exact step integral -int y dt through the kernel's given-increments path
(:mod:`randvib.montecarlo.driven`).

A coupling with a circuit state (coil inductance, piezo capacitance;
:mod:`randvib.models.coupling`) adds that state, ``x' = a x + b v``, with the
force ``f x`` on the magnet, to the same linear auxiliary block; the kernel
averages x^2 per path, so the circuit's power comes with its interval.

A diode bridge (:mod:`randvib.models.rectifier`) is integrated by the
kernel's rectified steps, with its stored power, coil and diode losses per
path; a run checks its step by halving it on a pilot ensemble
(:mod:`randvib.montecarlo.bridge_step`) and, under white noise, that every
dissipation path sums to m S / 4.

Each path is an independent realisation; statistics are time averages over
the window [burn_in, t_end) on each path, and their confidence intervals come
from the spread between paths (independent by construction), so they do not
depend on any assumption about correlation times.

:func:`simulate` is the driver (:func:`execute` for an already validated
run); the parts it orchestrates each have their module:

* :mod:`~randvib.montecarlo.validation` - the arguments checked and grouped
  into a :class:`~randvib.montecarlo.validation.Run`; the run options
  (time grid, initial state, recording) in :mod:`~randvib.montecarlo.options`;
* :mod:`~randvib.montecarlo.resources` - the memory check and the long-run
  announcement;
* :mod:`~randvib.montecarlo.kernel_setup` - the compiled loop's arguments:
  device, friction, start, auxiliary block (filter, circuit), recording;
* :mod:`~randvib.montecarlo.batches` - the compiled calls, interruptible,
  batch by batch;
* :mod:`~randvib.montecarlo.results` - :class:`SimulationResult` and its
  statistics, histograms and recorded paths.
"""

from __future__ import annotations

import functools
import time

from randvib._interrupts import ctrl_c_noticed
from randvib._progress import progress_wanted
from randvib.models.assembly import Assembly
from randvib.models.excitation import Excitation
from randvib.models.harvester import Harvester
from randvib.montecarlo import driven
from randvib.montecarlo.assembly_simulation import simulate_assembly
from randvib.montecarlo.batches import batch_bounds, run_batches
from randvib.montecarlo.bridge_step import (
    check_bridge_balance,
    check_bridge_conducted,
    check_bridge_step,
)
from randvib.montecarlo.kernel_setup import KernelSetup
from randvib.montecarlo.options import numba_threads
from randvib.montecarlo.resources import announce_long_run, check_resources
from randvib.montecarlo.results import SimulationResult
from randvib.montecarlo.step_check import LinearTestSystem
from randvib.montecarlo.validation import Run, check_options, check_scales, validated

#: The public API; ``execute`` is the driver's entry for already validated runs.
__all__ = ["simulate"]


def simulate(
    harvester: Harvester | Assembly,
    psd: float | Excitation,
    *,
    t_end: float,
    dt: float,
    n_paths: int,
    burn_in: float = 0.0,
    scheme: str = "heun",
    seed: int = 0,
    dW=None,
    initial="stationary",
    first_path: int = 0,
    companion: bool = False,
    control_variates: bool = False,
    histogram_bins: int = 0,
    histogram_range=None,
    record_paths: int = 0,
    record_every: int = 1,
    threads: int | None = None,
    batch_paths: int | None = None,
    progress: bool | None = None,
    check_step: bool = True,
) -> SimulationResult:
    """Simulate an ensemble of the harvester under white or coloured base excitation.

    Parameters
    ----------
    harvester : Harvester or Assembly
        An :class:`~randvib.models.assembly.Assembly` (several DOFs, elements
        and transducers on relative coordinates) is simulated by its own
        kernel with the same options
        (:func:`~randvib.montecarlo.assembly_simulation.simulate_assembly`)
        and returns an
        :class:`~randvib.montecarlo.assembly_results.AssemblySimulationResult`.
        A Harvester: device with scalar parameters; any friction model; any coupling
        (:mod:`randvib.models.coupling`): a coil's current or a piezo's
        voltage is integrated as an auxiliary state with the device, under
        white or rational input, and its mean square is averaged per path
        (``circuit_mean_square``, the power from it); the companion then is
        refused (it assumes a viscous c_e), the control variates are not.
        Any confining potential (monostable, bistable, pure cubic) or the
        free mass (k = k3 = 0: velocity statistics only,
        ``displacement_variance`` is None); a non-confining one is refused.
        With a ``stroke`` the result reports
        :attr:`SimulationResult.stroke_exceedance` and
        :attr:`SimulationResult.stroke_first_passage`.
    psd : float or Excitation
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0: the velocity
        noise is sqrt(S/2) dW (paper Eq. 17). Or an excitation
        (:mod:`randvib.models.excitation`): ``White`` as a number;
        ``BandPass`` and ``KanaiTajimi`` through their shaping filter's two
        states, driven by sqrt(S/2) dW (S their ``level``) and integrated with
        the device by the same scheme. ``BandLimited`` and ``Tabulated`` by a
        stationary Gaussian synthesis per path (:mod:`randvib.montecarlo.driven`:
        path i's input from the stream (seed, i), the kernel taking its exact
        step integrals; batches bound the memory). ``Measured`` is refused:
        simulate on the record with :func:`randvib.monte_carlo_on_record`.
        Under coloured input the companion and the control variates
        (white-noise energy balance) are refused, and the step check covers
        the filter too.
    t_end : float
        Simulated time per path (s), burn-in included.
    dt : float
        Time step (s). Steps whose scheme bias on the linearised device exceeds
        :data:`~randvib.montecarlo.step_check.MAX_STEP_BIAS` are refused (see
        :func:`~randvib.montecarlo.step_check.step_bias`).
    n_paths : int
        Number of independent paths (>= 2 for confidence intervals).
    burn_in : float
        Initial time discarded from the statistics (s), 0 <= burn_in < t_end.
    scheme : {"heun", "euler-maruyama"}
        Integrator (:data:`randvib.montecarlo.integrators.INTEGRATORS`);
        default "heun".
    seed : int
        Seed; path i uses stream (seed, first_path + i) (:mod:`randvib.montecarlo.rng`).
    dW : array_like, optional
        Brownian increments of shape (n_paths, n_steps) (s^0.5, variance dt)
        to drive the simulation instead of the internal streams.
    initial : "stationary", "rest" or (z0, v0)
        Start from independent Gaussians with the linearised stationary
        variances (drawn from each path's stream), from rest, or from a state.
    first_path : int
        Index of the first path's stream; a later batch with
        first_path = n_paths continues the same ensemble.
    companion : bool
        Integrate the friction-free device with the same noise alongside
        (control variates, :meth:`SimulationResult.controls`); white noise only.
    control_variates : bool
        Report control-variate estimates (plain path means otherwise): white
        noise, and band-pass / Kanai-Tajimi input (the Ito-sum and
        energy-change controls, :meth:`SimulationResult.controls`).
    histogram_bins, histogram_range
        Stationary histograms of z and v: number of bins and
        ((z_lo, z_hi), (v_lo, v_hi)) (default +-5 linearised std).
    record_paths, record_every : int
        Keep (z, v, theta) of the first ``record_paths`` paths every
        ``record_every`` steps.
    threads : int, optional
        Number of threads (default: all cores). Results do not depend on it.
    batch_paths : int, optional
        Paths per compiled call (default: all, or chunks of about a second when
        a progress bar is shown). Results do not depend on it.
    progress : bool, optional
        Progress bar (default: on in a notebook or when stderr is a terminal,
        off in CI and in logs).
    check_step : bool
        Refuse steps that are too large (default True).

    Returns
    -------
    SimulationResult
        Or an :class:`~randvib.montecarlo.assembly_results.AssemblySimulationResult`
        for an Assembly.

    Examples
    --------
    A small ensemble (64 paths, 2 s) of the Section 5 device; the 95 %
    half-width comes from the spread between paths:

    >>> import randvib as rv
    >>> result = rv.simulate(
    ...     rv.preset("figure9"), 1.0, t_end=2.0, burn_in=0.5, dt=5e-4, n_paths=64,
    ...     scheme="heun", seed=0, progress=False,
    ... )
    >>> power = result.power_electrical
    >>> print(f"{power.mean:.3e} +- {power.ci95:.1e} W")
    2.426e-03 +- 2.5e-04 W
    """
    with ctrl_c_noticed():  # a Ctrl-C swallowed by a finaliser still stops the run
        if isinstance(harvester, Assembly):
            return simulate_assembly(
                harvester, psd, t_end=t_end, dt=dt, n_paths=n_paths, burn_in=burn_in, scheme=scheme,
                seed=seed, dW=dW, initial=initial, first_path=first_path, companion=companion,
                control_variates=control_variates, histogram_bins=histogram_bins,
                histogram_range=histogram_range, record_paths=record_paths,
                record_every=record_every, threads=threads, batch_paths=batch_paths,
                progress=progress, check_step=check_step,
            )  # fmt: skip
        run = validated(
            harvester,
            psd,
            scheme,
            t_end=t_end,
            dt=dt,
            burn_in=burn_in,
            n_paths=n_paths,
            seed=seed,
            first_path=first_path,
            initial=initial,
            dW=dW,
            companion=companion,
            record=(histogram_bins, histogram_range, record_paths, record_every),
        )
        return execute(
            run,
            control_variates=control_variates,
            check_step=check_step,
            threads=threads,
            batch_paths=batch_paths,
            progress=progress,
        )


def execute(run: Run, *, control_variates, check_step, threads, batch_paths, progress):
    """Run a validated :class:`~randvib.montecarlo.validation.Run`: check, set up, run, wrap.

    The options are :func:`simulate`'s; :func:`randvib.monte_carlo_on_record`
    calls this with its own run (the record as the input).
    """
    check_options(run, control_variates)
    # refusals before advice: a run that cannot fit is refused before any step warning
    check_resources(run, batch_paths)
    # One linear test system per run, built when first needed (a fixed start
    # without a step check may need none): the step check, the random start,
    # the default histogram ranges and the circuit's start all use it.
    # A bridge is checked on its linear surrogate (the conducting bridge's damping).
    linear = functools.cache(
        lambda: LinearTestSystem.of(run.harvester.linear_surrogate(), run.excitation)
    )
    if check_step or run.initial.kind == "stationary":
        check_scales(run, linear)
    if check_step:
        linear().check_step(run.scheme.name, run.grid.dt)
        if run.harvester.is_rectified:  # the switching, which the linear check cannot see
            check_bridge_step(run, simulate)  # the pilot runs through the driver
    setup = KernelSetup.prepare(run, linear)
    if progress is None:
        progress = progress_wanted()
    # the input's memory stays bounded: a synthesised input's samples and a shock
    # train's step integrals are arrays of (paths in the batch) x (steps)
    sampled = run.driver is not None or (run.forcing is not None and run.forcing.shocks is not None)
    if batch_paths is None and sampled:
        batch_paths = driven.batch_paths(run.grid.n_steps)
    batches = batch_bounds(
        run.n_paths, batch_paths, run.grid.n_steps, progress, run.record.record_paths
    )
    with numba_threads(threads):
        announce_long_run(run, setup)
        started = time.perf_counter()
        per_path, histogram, histories = run_batches(run, setup, batches, progress)
        wall = time.perf_counter() - started
    result = SimulationResult(
        harvester=run.harvester,
        psd=run.psd,
        scheme=run.scheme.name,
        dt=run.grid.dt,
        t_end=run.grid.t_end,
        burn_in=run.grid.burn_in,
        seed=run.seed,
        first_path=run.first_path,
        per_path=per_path,
        control_variates=control_variates,
        histogram=histogram,
        histories=histories,
        wall_time=wall,
        excitation=run.input,
    )
    if check_step:  # the per-run identity: every path sums to m S / 4
        check_bridge_balance(result)
    check_bridge_conducted(result)  # a bridge that stored nothing says why
    return result
