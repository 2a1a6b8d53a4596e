"""Monte Carlo of an event: ``simulate_transient``, the ensemble through a transient window.

An event (:class:`randvib.Enveloped`: a stationary excitation times an
envelope e(t)) is simulated from t = 0 with the compiled loop of
:func:`randvib.simulate` (:mod:`randvib.montecarlo.kernel`), its
:class:`~randvib.montecarlo.kernel.Transient` group switched on:

* the envelope enters step n through one number ``gain[n]``: for white
  noise the step's RMS envelope ``sqrt(int e^2 dt / dt)`` multiplies the
  noise increment, so each step injects exactly the variance
  int e^2 (S/2) dt of the continuous input; for a shaping filter (band-pass,
  Kanai-Tajimi) the step's mean envelope multiplies the filter's output in
  the device's acceleration (the filter itself runs stationary from its
  stationary law); for synthesised input (band-limited, tabulated) the
  step's mean envelope multiplies the input's exact step integral (a
  second-order quadrature of int e y dt). The step integrals of e and e^2
  are exact (:meth:`randvib.models.event.Envelope.step_integrals`);
* every path starts from the same state
  (:class:`~randvib.models.event.EventStart`: rest by default), a filter's
  states from their stationary law (from the path's own stream), a circuit
  at rest;
* the kernel keeps (z, v, circuit state, peak |z| so far) of every path at
  the requested times, and per path the peak |z| over the event and the
  integrals of v^2 and of the circuit state's square (trapezoid rule), from
  which :class:`~randvib.montecarlo.transient_results.TransientResult`
  computes every statistic with its interval over the independent paths.

There is no burn-in and no time averaging: each statistic at time t is a
mean over paths of the paths' values at t. The paths are those of
:func:`randvib.simulate` (path i draws from stream (seed, i)), so results do
not depend on threads or batches.
"""

from __future__ import annotations

import time

import numpy as np

from randvib._interrupts import ctrl_c_noticed, interruptible
from randvib._progress import progress_bar, progress_wanted
from randvib._resources import check_memory
from randvib._validation import check_finite
from randvib.models.event import Enveloped, EventStart
from randvib.models.harvester import Harvester
from randvib.montecarlo import driven, kernel
from randvib.montecarlo.batches import batch_bounds, raise_if_diverged
from randvib.montecarlo.kernel_setup import KernelSetup
from randvib.montecarlo.options import numba_threads
from randvib.montecarlo.resources import check_resources
from randvib.montecarlo.step_check import LinearTestSystem
from randvib.montecarlo.transient_results import TransientResult
from randvib.montecarlo.validation import Run, check_options, check_scales, validated

#: Report times of a run given none: this many intervals on [0, t_end].
DEFAULT_INTERVALS = 50


def simulate_transient(
    harvester: Harvester,
    event: Enveloped,
    *,
    t_end: float,
    dt: float,
    n_paths: int,
    times=None,
    start="rest",
    scheme: str = "heun",
    seed: int = 0,
    dW=None,
    first_path: int = 0,
    threads: int | None = None,
    batch_paths: int | None = None,
    progress: bool | None = None,
    check_step: bool = True,
) -> TransientResult:
    """Simulate an ensemble of the harvester through an event, from t = 0 to ``t_end``.

    Parameters
    ----------
    harvester : Harvester
        As for :func:`randvib.simulate`: any friction law, coupling and
        confining potential (or the free mass); with a ``stroke`` the result
        reports how often and how soon |z| exceeds it.
    event : Enveloped
        A stationary excitation times an envelope (:mod:`randvib.models.event`):
        white, band-pass, Kanai-Tajimi, band-limited or tabulated. A measured
        record is one realisation, not an ensemble: pass its spectrum
        (``record.spectrum``) for Gaussian paths with its Welch PSD.
    t_end : float
        End of the simulated window (s); the event energy is integrated from
        0 to ``t_end``.
    dt : float
        Time step (s); checked, as for :func:`randvib.simulate`, on the device
        linearised under the envelope's peak intensity.
    n_paths : int
        Number of independent paths, >= 2.
    times : array_like, optional
        Increasing times (s) in [0, t_end] at which the ensemble's statistics
        are reported, each rounded to the nearest step (the result's
        ``times`` are those steps' times); default 51 times on [0, t_end].
    start : "rest", "unexcited" or (z0, v0)
        Where every path starts (:class:`~randvib.models.event.EventStart`).
    scheme, seed, dW, first_path, threads, batch_paths, progress, check_step
        As for :func:`randvib.simulate` (``dW`` (n_paths, n_steps) drives
        white noise or a filter; the envelope is applied to it).

    Returns
    -------
    TransientResult

    Examples
    --------
    White noise switched on at t = 0 on the linear oscillator, beside
    Caughey and Stumpf's closed form (:func:`randvib.transient_response`):

    >>> import randvib as rv
    >>> linear = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4)
    >>> event = rv.Enveloped(rv.White(1.0), rv.Step())
    >>> mc = rv.simulate_transient(linear, event, t_end=0.5, dt=2e-4, n_paths=400,
    ...                            times=[0.1, 0.5], progress=False)
    >>> exact = rv.transient_response(linear, event, [0.1, 0.5])
    >>> for s, e in zip(mc.velocity_variance.to_list(), exact.velocity_variance):
    ...     print(f"{s[0]:.4f} +- {s[1]:.4f}  exact {e:.4f}")
    0.0163 +- 0.0024  exact 0.0158
    0.0293 +- 0.0041  exact 0.0279
    """
    _check_case(harvester, event)
    start = EventStart.of(start, harvester)
    run = validated(
        harvester,
        event.excitation,
        scheme,
        t_end=t_end,
        dt=dt,
        burn_in=0.0,
        n_paths=n_paths,
        seed=seed,
        first_path=first_path,
        initial=(start.z, start.v),
        dW=dW,
        companion=False,
        record=(0, None, 0, 1),
    )
    if run.n_paths < 2:
        raise ValueError(f"`n_paths` must be >= 2 for the intervals, got {run.n_paths}")
    snap_steps = snapshot_steps(times, run.grid.dt, run.grid.n_steps)
    _check_resources(run, snap_steps, batch_paths)
    # The step check and the scales read the device linearised at the envelope's peak.
    system = LinearTestSystem.of(run.harvester, event.peak_excitation())

    def linear():
        return system

    check_scales(run, linear)
    if check_step:
        system.check_step(run.scheme.name, run.grid.dt)
    setup = KernelSetup.prepare(run, linear)
    if progress is None:
        progress = progress_wanted()
    if batch_paths is None and run.driver is not None:  # the input's memory stays bounded
        batch_paths = driven.batch_paths(run.grid.n_steps)
    batches = batch_bounds(run.n_paths, batch_paths, run.grid.n_steps, progress, 0)
    events = EventInput.of(run, event)
    started = time.perf_counter()
    with ctrl_c_noticed(), numba_threads(threads):
        snapshots, integrals, first_hit = _run_batches(
            run, setup, events, snap_steps, batches, progress
        )
    return TransientResult(
        harvester=run.harvester,
        event=event,
        start=start,
        scheme=run.scheme.name,
        dt=run.grid.dt,
        t_end=run.grid.t_end,
        seed=run.seed,
        first_path=run.first_path,
        times=snap_steps * run.grid.dt,
        snapshots=snapshots,
        integrals=integrals,
        first_hit=first_hit,
        wall_time=time.perf_counter() - started,
    )


def _check_case(harvester, event) -> None:
    """Refuse, in one line, a case :func:`simulate_transient` does not take."""
    if not isinstance(event, Enveloped):
        raise ValueError(
            "`event` must be a randvib.Enveloped (an excitation times an envelope, e.g. "
            f"rv.Enveloped(rv.White(1.0), rv.Step())); got {event!r}; for stationary "
            "statistics use randvib.simulate"
        )
    if event.excitation.name == "measured":
        raise ValueError(
            "an event ensemble needs independent paths, and a measured record is one "
            "realisation: pass its spectrum, rv.Enveloped(record.spectrum, envelope), for "
            "Gaussian paths with the record's Welch PSD"
        )
    if not isinstance(harvester, Harvester):
        raise ValueError(f"`harvester` must be a randvib.Harvester, got {type(harvester).__name__}")
    if harvester.is_rectified:
        raise ValueError(
            f"simulate_transient does not take the {harvester.electrical.name} coupling: "
            "a bridge's events are not implemented; simulate its stationary response "
            "with randvib.simulate"
        )


def _check_resources(run, snap_steps: np.ndarray, batch_paths) -> None:
    """The run's options, its memory and time, the snapshots it keeps and the envelope's gains."""
    check_options(run, False)
    check_resources(run, batch_paths)
    check_memory(
        f"keeping {run.n_paths} paths at {snap_steps.size} times",
        8.0 * run.n_paths * (snap_steps.size * kernel.N_SNAP + kernel.N_EVENT + kernel.N_ACC),
        "give fewer `times` or fewer `n_paths`, or run in parts with `first_path`",
    )
    check_memory(  # the envelope's gain on every step (Gauss-Legendre nodes, a few arrays)
        f"the envelope's gain on each of the {run.grid.n_steps:.4g} steps of t_end / dt",
        8.0 * run.grid.n_steps * (4 * ENVELOPE_NODES + 8),
        "shorten `t_end` (the last of `times`) or lengthen `dt`",
    )


#: Quadrature nodes per step of the envelope's step integrals (:meth:`Envelope.step_integrals`).
ENVELOPE_NODES = 6


def snapshot_steps(times, dt: float, n_steps: int) -> np.ndarray:
    """The state indices (t = j dt) nearest to the report ``times`` (s), checked.

    ``times`` None: :data:`DEFAULT_INTERVALS` + 1 evenly spaced times on
    [0, t_end]. Refused, naming the value: times outside [0, t_end], not
    increasing, or two on the same step.
    """
    t_end = n_steps * dt
    if times is None:
        return np.unique(np.round(np.linspace(0, n_steps, DEFAULT_INTERVALS + 1)).astype(np.int64))
    times = check_finite("times", np.atleast_1d(np.asarray(times, dtype=float)))
    if times.ndim != 1 or times.size == 0:
        raise ValueError(f"`times` must be a 1-D list of times (s), got shape {times.shape}")
    outside = (times < 0) | (times > t_end * (1 + 1e-12))
    if np.any(outside):
        bad = float(times[np.argmax(outside)])
        raise ValueError(f"`times` must lie in [0, t_end] = [0, {t_end:g}] s, got {bad!r} s")
    if np.any(np.diff(times) <= 0):
        i = int(np.argmax(np.diff(times) <= 0))
        raise ValueError(
            f"`times` must be increasing, got {float(times[i + 1])!r} s after {float(times[i])!r} s"
        )
    steps = np.minimum(np.round(times / dt).astype(np.int64), n_steps)
    if np.any(np.diff(steps) == 0):
        i = int(np.argmax(np.diff(steps) == 0))
        raise ValueError(
            f"`times` {float(times[i])!r} s and {float(times[i + 1])!r} s fall on the same step "
            f"of dt = {dt:g} s; give times at least one step apart"
        )
    return steps


class EventInput:
    """How the envelope reaches the compiled loop: per-step gains, what they scale, the filter start.

    Built once per run by :meth:`of`; :meth:`group` gives the kernel's
    :class:`~randvib.montecarlo.kernel.Transient` for one batch of paths.
    """

    def __init__(self, gain, scale_noise, filter_mask, n_start, start):
        self.gain = gain
        self.scale_noise = scale_noise
        self.filter_mask = filter_mask
        self.n_start = n_start
        self.start = start

    @classmethod
    def of(cls, run: Run, event: Enveloped) -> EventInput:
        """The gains of ``event`` on ``run``'s time grid (see the module docstring)."""
        dt, n_steps = run.grid.dt, run.grid.n_steps
        first, second = event.envelope.step_integrals(dt, n_steps)
        excitation = event.excitation
        shaping = None if run.driver is not None else excitation.shaping_filter()
        n = kernel.N_AUX
        mask, chol = np.zeros(n), np.zeros((n, n))
        n_filter = 0
        if excitation.is_white:
            gain, scale_noise = np.sqrt(second / dt), True
        elif shaping is None:  # synthesised: the input's step integral times the mean envelope
            gain, scale_noise = first / dt, True
        else:
            gain, scale_noise = first / dt, False
            from scipy import linalg

            system = shaping.system
            n_filter = system.n_states
            stationary = linalg.solve_continuous_lyapunov(
                system.a, -shaping.noise_intensity * np.outer(system.b, system.b)
            )
            chol[:n_filter, :n_filter] = np.linalg.cholesky(stationary)
            mask[:n_filter] = 1.0
        return cls(gain, scale_noise, mask, n_filter, chol)

    def group(self, snap_steps, count: int) -> kernel.Transient:
        """The kernel's :class:`~randvib.montecarlo.kernel.Transient` for ``count`` paths."""
        return kernel.transient_group(
            self.gain,
            self.scale_noise,
            self.filter_mask,
            self.n_start,
            self.start,
            snap_steps,
            count,
        )


def _run_batches(run: Run, setup: KernelSetup, events: EventInput, snap_steps, batches, progress):
    """The compiled loop batch by batch: snapshots, event integrals and first-hit times per path."""
    snapshots = np.empty((run.n_paths, snap_steps.size, kernel.N_SNAP))
    integrals = np.empty((run.n_paths, kernel.N_EVENT))
    first_hit = np.empty(run.n_paths)
    bar = None
    if progress:
        bar = progress_bar(run.n_paths, desc="simulate", unit="path", transient=True)
    try:
        for lo, hi in batches:
            group = events.group(snap_steps, hi - lo)
            acc, failed, _, _ = interruptible(
                kernel.run_ensemble, **setup.arguments(run, lo, hi), transient=group
            )
            raise_if_diverged(run, lo, failed)
            snapshots[lo:hi] = group.snapshots
            integrals[lo:hi] = group.event
            first_hit[lo:hi] = kernel.PathAverages(acc).first_hit_time
            if bar is not None:
                bar.update(hi - lo)
    finally:
        if bar is not None:
            bar.close()
    return snapshots, integrals, first_hit
