"""simulate's arguments checked in one place and grouped into a :class:`Run`.

:func:`validated` checks every argument of :func:`randvib.simulate` (the
device, the input, the time grid, the paths and seed, the start, what is
recorded, given increments) with messages that name the argument, the value
and what is allowed, and returns the :class:`Run` that the set-up and the
batches read. :func:`check_options` refuses the options that the input or
the circuit cannot honour; :func:`check_scales` refuses parameters whose
linearised scales overflow float64.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from randvib._validation import MAX_SEED, check_int, check_scalar_device
from randvib.models.combined import as_input, parts_of
from randvib.models.excitation import Excitation, White, as_excitation
from randvib.models.harvester import Harvester
from randvib.models.potential import CONFINING
from randvib.models.translation import Translated
from randvib.montecarlo import driven
from randvib.montecarlo.bridge_step import storage_start
from randvib.montecarlo.forcing import ForcingInput, nyquist_refusal
from randvib.montecarlo.integrators import Integrator, integrator
from randvib.montecarlo.options import InitialState, RecordOptions, TimeGrid

#: Largest path index (streams are keyed by unsigned 64-bit integers).
MAX_PATH_INDEX = 2**62


@dataclass(frozen=True)
class Run:
    """:func:`randvib.simulate`'s arguments, validated and grouped."""

    harvester: Harvester
    psd: float
    excitation: Excitation
    scheme: Integrator
    grid: TimeGrid
    n_paths: int
    seed: int
    first_path: int
    initial: InitialState
    record: RecordOptions
    dW: np.ndarray | None
    companion: bool
    #: Velocity increments of a given base acceleration, ``driver(first, count)``
    #: -> (count, n_steps) (m/s): synthesised or recorded input (:mod:`randvib.montecarlo.driven`).
    driver: object = None
    #: Tones and shocks added to the input (:class:`~randvib.montecarlo.forcing.ForcingInput`), or None.
    forcing: object = None
    #: The whole input as given (the random part, tones and shocks); ``excitation``
    #: is its random part, or, with none (tones or shocks alone), the white
    #: noise of a nominal level that the linear checks and the start see while
    #: the kernel's noise is switched off (``psd`` 0).
    input: Excitation | None = None


def validated(
    harvester,
    psd,
    scheme,
    *,
    t_end,
    dt,
    burn_in,
    n_paths,
    seed,
    first_path,
    initial,
    dW,
    companion,
    record,
) -> Run:
    """:func:`randvib.simulate`'s arguments checked, in one place; messages name the argument.

    ``scheme`` is the integrator's name and ``record`` (histogram_bins,
    histogram_range, record_paths, record_every).
    """
    if not isinstance(harvester, Harvester):
        raise ValueError(f"`harvester` must be a randvib.Harvester, got {type(harvester).__name__}")
    check_scalar_device(harvester, "simulate")  # device, friction and coupling parameters
    # Statistics are time averages of a stationary state: a confining
    # potential, or the free mass for its velocity.
    harvester.potential.require("simulate", CONFINING + ("free",))
    if companion and harvester.potential.is_free:
        raise ValueError(
            "`companion` needs a confining potential: the friction-free companion's exact "
            "E[z^2] (Gibbs) does not exist for the free mass (k = k3 = 0)"
        )
    common = checked_input(psd, scheme, t_end=t_end, dt=dt, burn_in=burn_in, n_paths=n_paths,
                           seed=seed, dW=dW)  # fmt: skip
    return Run(
        harvester=harvester,
        **common._asdict(),  # the input, grid, paths and seed, checked alike
        first_path=check_int("first_path", first_path, 0, MAX_PATH_INDEX),
        initial=InitialState.from_argument(initial),
        record=RecordOptions.validated(*record),
        companion=bool(companion),
    )


class CheckedInput(NamedTuple):
    """The input and time grid of a run, checked (:func:`checked_input`)."""

    scheme: Integrator
    input: Excitation  # the whole input: random part, tones, shocks
    excitation: Excitation  # its random part as simulated (a nominal white level if none)
    psd: float | None  # the white level the kernel draws (0: no random part)
    grid: TimeGrid
    n_paths: int
    seed: int
    driver: object
    forcing: ForcingInput | None
    dW: np.ndarray | None  # given Brownian increments, checked


def checked_input(psd, scheme, *, t_end, dt, burn_in, n_paths, seed, dW) -> CheckedInput:
    """What a single-mass and an assembly run check alike: the integrator, the input
    split into its random part and its tones and shocks, the time grid, the number of
    paths, the seed, the driver of coloured input, the deterministic forcing and the
    given Brownian increments.

    With tones or shocks alone, the linear checks and the start see a nominal white
    level while the kernel's noise is off (``psd`` 0).
    """
    scheme = integrator(scheme)
    whole = as_input(psd)
    random, tones, shocks = parts_of(whole)
    excitation = _simulated_excitation(random if random is not None else _nominal_white(whole))
    grid = TimeGrid.from_times(t_end, dt, burn_in)
    n_paths = check_int("n_paths", n_paths, 1)
    seed = check_int("seed", seed, 0, MAX_SEED)
    driver = _driver(excitation, grid, seed, dW)
    forcing = None
    if tones or shocks is not None:
        refusal = nyquist_refusal(tones, grid.dt)
        if refusal:
            raise ValueError(refusal)
        forcing = ForcingInput(tones, shocks, grid.n_steps, grid.dt, seed)
    level = 0.0 if random is None else getattr(excitation, "level", None)
    increments = checked_increments(dW, n_paths, grid.n_steps)
    return CheckedInput(
        scheme, whole, excitation, level, grid, n_paths, seed, driver, forcing, increments
    )


def _driver(excitation: Excitation, grid: TimeGrid, seed: int, dW):
    """The given increments of a synthesised or translated input, or None (noise, filter)."""
    if excitation.shaping_filter() is not None and excitation.is_gaussian:
        return None
    if dW is not None:
        raise ValueError(
            f"`dW` drives white noise or a shaping filter; the {excitation.name} input is "
            "synthesised from the seed (leave dW=None)"
        )
    if isinstance(excitation, Translated):
        return driven.TranslatedInput(excitation, grid.n_steps, grid.dt, seed)
    return driven.SynthesisedInput(excitation, grid.n_steps, grid.dt, seed)


def _nominal_white(whole: Excitation) -> Excitation:
    """White noise of a nominal level for an input of tones or shocks alone.

    The kernel's noise is off (``psd`` 0); the step check, the random start
    and the histogram ranges see the device linearised under this level:
    the input's mean square spread over its highest frequency (a tone's, or
    a pulse's 1/D), so that the start has about the right energy.
    """
    tops = [tone.frequency for tone in whole.lines()]
    shocks = parts_of(whole)[2]
    if shocks is not None:
        tops.append(1.0 / shocks.duration)
    return White(whole.variance / max(tops))


def _simulated_excitation(psd) -> Excitation:
    """``psd`` as an excitation that :func:`randvib.simulate` can drive, or a clear refusal.

    White noise and the rational spectra with a 2-state shaping filter
    (band-pass, Kanai-Tajimi) are integrated with the device; band-limited
    and tabulated spectra are synthesised (:class:`~randvib.montecarlo.driven.SynthesisedInput`);
    a measured record is simulated on the record itself by
    :func:`randvib.monte_carlo_on_record`.
    """
    if not isinstance(psd, Excitation):
        return as_excitation(psd)  # one positive number (an array refused by name)
    if psd.is_white:
        return psd
    if isinstance(psd, Translated):
        return psd
    if psd.name == "measured":
        raise ValueError(
            "simulate draws its own paths; to simulate the device on the measured record "
            "itself use randvib.monte_carlo_on_record(harvester, record, ...), for Gaussian "
            "paths with the record's Welch PSD pass record.spectrum"
        )
    shaping = psd.shaping_filter()
    if shaping is not None and (shaping.system.n_states != 2 or np.any(shaping.system.d != 0)):
        raise ValueError(
            f"simulate integrates shaping filters of 2 states without feed-through; the "
            f"{psd.name} filter has {shaping.system.n_states}"
        )
    return psd


def checked_increments(dW, n_paths, n_steps):
    """Given Brownian increments as a contiguous (n_paths, n_steps) array, or None."""
    if dW is None:
        return None
    dW = np.ascontiguousarray(dW, dtype=float)
    if dW.shape != (n_paths, n_steps):
        raise ValueError(
            f"`dW` must have shape (n_paths, n_steps) = {(n_paths, n_steps)}, got {dW.shape}"
        )
    if not np.all(np.isfinite(dW)):
        raise ValueError("`dW` must be finite")
    return dW


def check_options(run: Run, control_variates: bool) -> None:
    """Refuse the options that this run's input or circuit cannot honour, saying why."""
    if run.forcing is not None or not run.excitation.is_gaussian:
        _check_forced_options(run, control_variates)
    _check_coloured_options(run.excitation, run.companion, control_variates)
    _check_circuit_options(run.harvester, run.companion)
    if run.harvester.is_rectified:
        _check_bridge(run)


def _check_forced_options(run: Run, control_variates: bool):
    """Refuse the companion and the controls under tones, shocks or a non-Gaussian input.

    The friction-free companion's exact moments are white noise's; the
    energy-balance controls need the stationary Brownian input alone (a
    tone's energy change over a window has no zero mean at a fixed phase).
    """
    option = "companion" if run.companion else "control_variates" if control_variates else None
    if option is not None:
        raise ValueError(
            f"`{option}` needs Gaussian noise alone; under the {run.input.name} input no "
            f"control has a known mean: use {option}=False"
        )


def _check_coloured_options(excitation: Excitation, companion: bool, control_variates: bool):
    """Refuse the white-noise-only options under coloured input, saying why."""
    if excitation.is_white:
        return
    if companion:
        raise ValueError(
            "`companion` needs white noise: the friction-free companion's exact moments "
            f"(S m/(4c), Gibbs E[z^2]) do not hold under {excitation.name} excitation"
        )
    if control_variates and excitation.shaping_filter() is None:
        raise ValueError(
            "`control_variates` needs Brownian increments (white noise, or band-pass and "
            "Kanai-Tajimi through their filter): under the synthesised or recorded "
            f"{excitation.name} input the Ito sum is the input power, not a zero-mean control; "
            "use control_variates=False"
        )


def _check_circuit_options(harvester: Harvester, companion: bool):
    """Refuse the friction-free companion with a circuit state, saying why.

    The energy-balance controls (the Ito integral, mean exactly zero; the
    change of mechanical energy, zero in the stationary state) hold for any
    coupling, so ``control_variates`` stays available.
    """
    if harvester.has_circuit and companion:
        raise ValueError(
            "`companion` needs the resistive coupling: its exact moments (S m/(4c), Gibbs "
            f"E[z^2]) assume a viscous c_e, not the {harvester.electrical.name} coupling's "
            "circuit state; use companion=False"
        )


class BridgeStartWarning(RuntimeWarning):
    """The burn-in is short against the storage capacitor's charging time."""


def _check_bridge(run: Run) -> None:
    """A bridge's options: no companion; a step that resolves its output's RC rate.

    A storage capacitor that starts empty
    (:func:`~randvib.montecarlo.bridge_step.storage_start`) makes a burn-in
    shorter than 3 R_L C (about 95 % of its charging) warned about; a step above
    0.2 / rate (the charging and load rate 1/(R_C C) + 1/(R_L C) of a coil,
    1/(R_L C) of a piezo) would make the explicit scheme's V_C step
    inaccurate or unstable and is refused.
    """
    bridge = run.harvester.electrical
    if run.companion:
        raise ValueError(
            "`companion` needs the resistive coupling: its exact moments assume a viscous "
            f"c_e, not the {bridge.name}; use companion=False"
        )
    rate = bridge.fastest_rate()
    if rate * run.grid.dt > 0.2:
        raise ValueError(
            f"`dt` = {run.grid.dt!r} s is too large for the {bridge.name}'s storage "
            f"capacitor (its fastest rate {rate:.3g} 1/s): use dt <= {0.2 / rate:.3g} s"
        )
    if not bridge.has_battery and storage_start(run) == 0.0:  # it starts empty
        settle = 3.0 * bridge.r_load * bridge.storage_capacitance
        if run.grid.burn_in < settle:
            warnings.warn(
                f"burn_in = {run.grid.burn_in:g} s is shorter than 3 R_L C = {settle:.3g} s: "
                "the storage capacitor starts empty and its charging biases the stored "
                f"power low; use burn_in >= {settle:.3g} s",
                BridgeStartWarning,
                stacklevel=4,
            )


def check_scales(run: Run, linear) -> None:
    """Refuse parameters whose linearised scales are not finite float64 numbers.

    Extreme values (m = 1e308, k3 = 1e308, S = 1e308) overflow the
    step-size check and the stationary start; they are named here instead.
    ``linear`` gives the run's
    :class:`~randvib.montecarlo.step_check.LinearTestSystem` (built on first use).
    """
    h = run.harvester
    try:
        # quadrature warnings at such values would only precede the refusal
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            system = linear()
            k_eff, c_eff = system.k_eff, system.c_eff
            spread = system.spread
    except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
        problem = f"{type(exc).__name__}: {exc}"
    else:
        values = (k_eff, c_eff, *spread)
        # the free mass has no stiffness and no stationary spread in z
        positive = values[1:2] + values[3:] if h.potential.is_free else values
        if all(np.isfinite(values)) and all(v > 0 for v in positive):
            return
        problem = f"k_eff = {k_eff:.3g}, c_eff = {c_eff:.3g}, std z, v = {spread}"
    raise ValueError(
        f"the device's linearised scales are not finite positive float64 numbers ({problem}) "
        f"at psd = {run.psd!r} and {run.harvester.parameters()}: the parameters are out of "
        "range, or the device has neither damping nor friction"
    )
