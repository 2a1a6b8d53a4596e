"""The half-step check of a diode bridge: does the time step resolve its switching?

The linear step check (:mod:`randvib.montecarlo.step_check`) sees a bridge
through its linear surrogate, the conducting bridge's damper, and so misses
what the switching itself costs: the bridge's current (coil) is only
Lipschitz in the state and the piezo's clamp is a projection, so the schemes
lose their smooth-problem order there. This check measures the step's effect
directly: a short pilot ensemble at ``dt`` and at ``dt / 2`` on the same
Brownian increments (the coarse increment the sum of two fine ones), and the
relative change of the stored power between them. The tests measure the
order of convergence of the bridge's energy accounting (about 1, see
tests/test_rectifier.py), so the change at ``dt`` is about the error of the
``dt / 2`` run, and a step ``dt * (tol / change)`` keeps it below ``tol``.
"""

from __future__ import annotations

import warnings

import numpy as np

from randvib.analytic.bridge import BRIDGE_CLOSURE, capacitor_level

#: Largest relative change of the stored power between dt and dt/2 that passes quietly.
BRIDGE_STEP_TOLERANCE = 0.01
#: Paths and at most this many steps (of dt) of the pilot ensemble.
PILOT_PATHS = 16
PILOT_STEPS = 20_000
#: The measured order of convergence the advice assumes (tests/test_rectifier.py).
BRIDGE_ORDER = 1.0


class BridgeStepWarning(RuntimeWarning):
    """Halving the time step changes a bridge's stored power noticeably."""


def bridge_step_change(
    simulate, harvester, psd, dt: float, scheme: str, t_end: float, seed: int = 0
):
    """Relative change of the stored power, and its 95 % half-width, from dt to dt/2.

    A pilot of :data:`PILOT_PATHS` paths over ``min(t_end, PILOT_STEPS dt)``
    from rest, the same Brownian increments at both steps; the change is the
    mean of the paired per-path differences over the dt / 2 mean.
    Brownian input only: white noise or a shaping filter. ``simulate`` is
    :func:`randvib.simulate`, handed in by the driver that calls this check
    (so that this module and the driver need not import each other).
    """
    n_coarse = int(min(round(t_end / dt), PILOT_STEPS))
    rng = np.random.default_rng([seed, 2])
    fine = rng.normal(0.0, np.sqrt(dt / 2.0), (PILOT_PATHS, 2 * n_coarse))
    coarse = fine.reshape(PILOT_PATHS, n_coarse, 2).sum(axis=2)
    runs = []
    for step, increments in ((dt, coarse), (dt / 2.0, fine)):
        with warnings.catch_warnings():  # the pilot's own start (from rest) is no user's concern
            warnings.simplefilter("ignore")
            result = simulate(
                harvester, psd, t_end=n_coarse * dt, dt=step, n_paths=PILOT_PATHS,
                scheme=scheme, dW=increments, initial="rest", progress=False, check_step=False,
            )  # fmt: skip
        runs.append(result.averages.stored_power)
    reference = float(np.mean(runs[1]))
    if reference <= 0.0:  # nothing stored in the pilot: nothing to compare
        return 0.0, 0.0
    diff = (runs[0] - runs[1]) / reference
    return float(np.mean(diff)), float(1.96 * np.std(diff, ddof=1) / np.sqrt(diff.size))


def check_bridge_step(run, simulate) -> None:
    """Warn when halving the step changes the bridge's stored power by more than 1 %.

    Only a change beyond the pilot's own 95 % interval counts; the warning
    gives the step that would bring it under :data:`BRIDGE_STEP_TOLERANCE`
    at the measured order :data:`BRIDGE_ORDER`. Synthesised or recorded input,
    and tones or shocks (no Brownian increments alone to halve) are not checked.
    ``simulate`` runs the pilot (:func:`bridge_step_change`).
    """
    excitation = run.excitation
    if run.driver is not None or run.forcing is not None or excitation.shaping_filter() is None:
        return  # no Brownian increments alone to halve
    psd = excitation if not excitation.is_white else run.psd
    dt = run.grid.dt
    change, half_width = bridge_step_change(
        simulate, run.harvester, psd, dt, run.scheme.name, run.grid.t_end, run.seed
    )
    if abs(change) > BRIDGE_STEP_TOLERANCE and abs(change) > half_width:
        quiet = dt * (BRIDGE_STEP_TOLERANCE / abs(change)) ** (1.0 / BRIDGE_ORDER)
        warnings.warn(
            f"dt = {dt!r} s does not resolve the {run.harvester.electrical.name}'s "
            f"switching: halving it changes the stored power by {change:+.2%} "
            f"(+- {half_width:.1%}); its error falls about like dt^{BRIDGE_ORDER:g}, so use "
            f"dt <= {quiet:.2g} s for less than {BRIDGE_STEP_TOLERANCE:.0%}",
            BridgeStepWarning,
            stacklevel=4,
        )


class EnergyBalanceWarning(RuntimeWarning):
    """A bridge's powers do not sum to the white-noise input m S / 4."""


def check_bridge_balance(result) -> None:
    """Warn when a white-noise bridge run's powers miss m S / 4 beyond their interval.

    Every dissipation path (mechanical, stored, coil, diodes) sums to the
    input m S / 4 (docs/conventions.md); the check allows the residual's 95 %
    half-width (narrowed by the energy-balance control variates, which hold
    for any white-noise run) plus :data:`BRIDGE_STEP_TOLERANCE` of m S / 4 for
    the step's accounting error, which the half-step check keeps below that.
    """
    if not (result.harvester.is_rectified and result.is_white) or result.n_paths < 2:
        return
    # the cross-fitted controls need a few paths per fold; few paths: plain means
    residual = result.energy_balance_residual(control_variates=result.n_paths >= 16)
    supplied = result.psd * result.harvester.m / 4.0
    if abs(residual.mean) > residual.ci95 + BRIDGE_STEP_TOLERANCE * supplied:
        warnings.warn(
            f"the bridge's powers miss the white-noise input m S / 4 = {supplied:.4g} W by "
            f"{residual.mean:+.3g} W (+- {residual.ci95:.2g}): lengthen the burn-in (the "
            "storage capacitor's charging) or reduce dt (the switching)",
            EnergyBalanceWarning,
            stacklevel=3,
        )


class BridgeIdleWarning(RuntimeWarning):
    """A bridge never conducted: its transducer's voltage never reached the threshold."""


def bridge_input_rms(result) -> float:
    """RMS of the transducer's open-circuit voltage (V) in a run whose bridge never conducted.

    The coil's EMF ``alpha z'`` or the piezo's ``theta z / C_p``, from the
    run's own E[z'^2] or E[z^2] (the motion of a bridge that never conducts
    is the open-circuit motion).
    """
    bridge = result.harvester.electrical
    averages = result.averages
    if bridge.transducer == "piezo":
        return bridge.theta / bridge.capacitance * float(np.sqrt(np.mean(averages.z2)))
    return bridge.alpha * float(np.sqrt(np.mean(averages.v2)))


def never_conducted(result) -> bool:
    """No path of a bridge run carried current, though its threshold V_out + 2 V_d is above 0.

    The current shows in the coil's and the diodes' losses and in a battery's
    stored power (a storage capacitor's is also its discharge); a threshold
    of 0 (a battery of 0 V or a capacitor with ideal diodes) conducts without
    storing, which is no idle bridge.
    """
    averages = result.averages
    bridge = result.harvester.electrical
    carried = averages.coil_loss + averages.diode_loss
    if bridge.has_battery:
        carried = carried + averages.stored_power
        blocked = bridge.threshold() > 0.0
    else:
        blocked = bridge.v_diode > 0.0
    return blocked and bool(np.all(carried == 0.0))


def check_bridge_conducted(result) -> None:
    """Warn (:class:`BridgeIdleWarning`) when a bridge run stored nothing because it never
    conducted: the transducer's voltage, its RMS and the threshold, and what would help."""
    if not result.harvester.is_rectified or not never_conducted(result):
        return
    advice = result.harvester.electrical.idle_advice(bridge_input_rms(result))
    warnings.warn(
        f"{advice} ({result.n_paths} paths x {result.averaging_time:g} s)",
        BridgeIdleWarning,
        stacklevel=3,
    )


def storage_start(run) -> float:
    """The storage capacitor's voltage at t = 0 (V): its charge-balance level, or 0.

    With a random ("stationary") start, white noise and a coil's constant-drop
    bridge without inductance, the closure's level V_C = R_L E|i|(V_C)
    (:func:`randvib.analytic.bridge.capacitor_level`; a friction law with
    memory left out, it only adds damping), so that the burn-in need not
    cover the capacitor's charging. Otherwise (a battery, a start from rest
    or a given state, another bridge or input) 0: the capacitor starts empty.
    """
    h = run.harvester
    bridge = h.electrical
    if bridge.has_battery or run.initial.kind != "stationary" or run.driver is not None:
        return 0.0
    if run.forcing is not None:  # tones or shocks: the closure's level is white noise's
        return 0.0
    if not (run.excitation.is_white and BRIDGE_CLOSURE._coil(h)):
        return 0.0
    if h.friction is not None and not h.friction.has_equivalent_damping:
        h = h.updated(friction=None)
    return float(capacitor_level(h, float(run.psd)))
