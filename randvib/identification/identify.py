"""Identification of the device and friction models from a record (paper Sec. 3-4).

The model (paper Eq. 1) with one of the friction laws is fitted to a record
by minimising the normalised cost J (paper Eq. 11,
:mod:`randvib.identification.cost`) with self-adaptive differential evolution
(:func:`randvib.identification.sade.sade`), then a least-squares polish of the
simulation error that also gives the parameters' standard errors
(:mod:`randvib.identification.least_squares`). Every generation's population
is simulated in one batched, compiled call
(:mod:`randvib.identification.record_integrator`).

Measurement model (measured = true + offset): constant offsets of the input
and output channels, the input between samples (linear, cubic spline or
band-limited reconstruction; by default chosen from the input's content
against the sample rate,
:func:`~randvib.identification.input_reconstruction.choose_hold`), the initial state, and an optional quadratic
stiffness k2, estimated with the parameters (:func:`identify`). By default
the initial state (z0, z'0) is estimated with the parameters; with
``initial_state='record'`` the simulation starts from the first sample (less
the output offset) and a velocity estimated from the first five samples.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, replace

import numpy as np

from randvib._resources import timed
from randvib._validation import check_int, check_positive
from randvib.identification.bounds import (
    SAMPLES_PER_PARAMETER,
    SearchSpace,
    probe_points,
    search_space,
)
from randvib.identification.circuit import OUTPUT_KINDS, check_coupling_kind
from randvib.identification.cost import CostFunction
from randvib.identification.models import (
    MODEL_PARAMETERS,
    check_model,
    check_parameter,
    check_parameters,
    device_parameters,
)
from randvib.identification.prediction import score
from randvib.identification.record_integrator import EXTRA_PARAMETERS
from randvib.identification.result import IdentificationResult
from randvib.identification.sade import named_callback, sade
from randvib.identification.settings import (
    POLISH_MAXFEV,
    SearchSettings,
    SimulationSettings,
    resolve_settings,
)
from randvib.models.record import OUTPUT_CHANNEL, Record


def _resolve_fixed(model, fixed, m, record):
    names = MODEL_PARAMETERS[model]
    allowed = names + ("m",) + EXTRA_PARAMETERS
    fixed = dict(fixed or {})
    for key, value in fixed.items():
        if key not in allowed:
            raise ValueError(
                f"`--fix {key}`: unknown parameter for model {model!r}; allowed: "
                f"{', '.join(allowed)}"
            )
        fixed[key] = check_parameter(model, key, value, f"--fix {key}")
    if m is not None:
        if "m" in fixed and fixed["m"] != float(m):
            raise ValueError(f"`m` given twice with different values: {m} and --fix m={fixed['m']}")
        fixed["m"] = float(check_positive("m", m, "kg"))
    if "m" not in fixed and record.input_kind != "force":
        raise ValueError(
            f"`m` (kg) is required with a `{record.input_kind}` input: under base excitation "
            "the mass is not identifiable (Eq. 1 divided by m leaves c/m, k/m, k3/m, F/m)"
        )
    if "m" in fixed and fixed["m"] <= 0:
        raise ValueError(f"`m` must be > 0 (kg), got {fixed['m']!r}")
    return fixed


def _measurement_model(record, fixed, quadratic) -> tuple[dict, tuple, tuple]:
    """Which of k2 and the offsets are estimated: (fixed, reported, notes).

    ``fixed`` gains k2 = 0 without ``quadratic`` and input_offset = 0 where a
    constant input offset cannot be told apart from the rest of the model;
    ``reported`` are the extra parameters the result lists (estimated or
    fixed by the user); ``notes`` say why an offset is not estimated.
    """
    fixed = dict(fixed)
    if quadratic and "k2" in fixed:
        raise ValueError("`--quadratic` estimates k2; it cannot also be fixed (--fix k2=...)")
    # reported: estimated, or held by the user at a nonzero value (validate needs it)
    reported = tuple(
        n
        for n in EXTRA_PARAMETERS
        if n == "k2" and quadratic or n != "k2" and n not in fixed or fixed.get(n, 0.0) != 0.0
    )
    notes = []
    if not quadratic:
        fixed.setdefault("k2", 0.0)
    if "input_offset" not in fixed:
        why = None
        if record.input_kind == "base_displacement":
            why = "a constant offset on a displacement vanishes in its second derivative"
        elif quadratic:
            why = (
                "with k2 free a constant input only shifts the displacement's origin, which "
                "k, k2 and the output offset absorb exactly"
            )
        elif fixed.get("k3") == 0.0 and fixed.get("k2") == 0.0:
            why = "with a linear spring a constant input only shifts z, as the output offset does"
        if why is not None:
            fixed["input_offset"] = 0.0
            reported = tuple(n for n in reported if n != "input_offset")
            notes.append(f"input_offset fixed at 0: {why}")
    return fixed, reported, tuple(notes)


def identify(
    record,
    model: str,
    *,
    m: float | None = None,
    coupling: str | None = None,
    r_load=None,
    rectifier: dict | None = None,
    outputs=None,
    weights: dict | None = None,
    fixed: dict | None = None,
    bounds: dict | None = None,
    init=None,
    quadratic: bool = False,
    search: SearchSettings | None = None,
    simulation: SimulationSettings | None = None,
    progress: bool = True,
    callback=None,
    **options,
) -> IdentificationResult:
    """Fit a model and its measurement model to a record: SaDE, then least squares.

    The global search (self-adaptive DE, :func:`randvib.identification.sade.sade`)
    minimises J (Eq. 11) with the output offset profiled out in closed form;
    the local polish (:mod:`randvib.identification.least_squares`) then
    minimises the simulation error over every estimated quantity (model
    parameters, offsets, initial state) and gives their standard errors.
    The reported cost is J.

    The measurement model (measured = true + offset on each channel): a
    constant output offset is estimated unless fixed; a constant input
    offset is estimated for force and base-acceleration inputs when the
    restoring force makes it identifiable (k3 free or nonzero and k2 not
    free; see ``notes`` of the result otherwise).

    With ``coupling`` (and each record's load ``r_load``) the circuit is
    identified with the mechanics: alpha, the coil's resistance and
    inductance, or theta and C_p, c being then the mechanical damping c_m;
    ``outputs`` fits the load voltage, the current or the velocity instead
    of (or beside) the displacement, each channel's J normalised by its own
    variance and summed (``weights``); several records of one device (each
    at its own load) are fitted at once. What the records can fix is checked
    first (:mod:`randvib.identification.identifiability`): a parameter no
    record of this kind can fix is refused with one line naming what to add,
    and after the fit a split of the damping, the mass or the coupling that
    the data do not make is refused too (:class:`IdentifiabilityError
    <randvib.identification.identifiability.IdentifiabilityError>`); the
    result's ``identifiability`` says what was fixed and why
    (docs/identification.md).

    Parameters
    ----------
    record : Record or sequence of Record
        Training record(s) of one device.
    model : {'viscous', 'coulomb', 'tanh', 'lugre'}
        Friction model (``viscous`` is the paper's no-friction model), or
        any other registered law.
    m : float, optional
        Mass (kg); required with base excitation unless the records fix it
        (a circuit channel at two loads, a piezo's voltage and velocity),
        identified when omitted with a force input.
    coupling : {'resistive', 'inductive', 'piezo'}, optional
        Identify the coupling too (:mod:`randvib.identification.circuit`).
    r_load : float or sequence of float, optional
        Each record's known load resistance R_L (ohm), with ``coupling``.
    rectifier : dict, optional
        The coupling's output goes through a known full-wave diode bridge
        (:mod:`randvib.models.rectifier`): ``v_diode`` (V) and
        ``storage_capacitance`` (F, each record's ``r_load`` across it) or
        ``battery`` (V); ``voltage`` is then the DC output voltage V_C and
        ``current`` the load current V_C / R_L (a battery's charging current),
        simulated by :mod:`randvib.identification.record_bridge`. The
        structural analysis is linear and is not made; the fit's covariance
        judges what the records fix.
    outputs : sequence of str, optional
        The channels fitted, by kind: ``relative_displacement`` (default),
        ``relative_velocity``, ``voltage`` (the load voltage), ``current``;
        each is the record's channel of that name, fitted only as that kind.
    weights : dict, optional
        ``kind -> w`` multiplying each channel's J (default 1).
    fixed : dict, optional
        Parameters held at given values, e.g. ``{"k3": 0.0}`` for a linear
        spring, ``{"input_offset": 0.0, "output_offset": 0.0}`` for sensors
        known to have none.
    bounds : dict, optional
        ``name -> (lower, upper)`` overriding
        :func:`~randvib.identification.bounds.default_bounds` (search box).
    init : Harvester, optional
        A starting guess (a device, a preset included, with c = c_m + c_e)
        placed in the initial population.
    quadratic : bool
        Estimate a quadratic stiffness k2 (N/m^2): restoring force
        ``k z + k2 z^2 + k3 z^3``; the input offset is then held at 0. With
        k3 free the two describe the same family: a cubic force about an
        origin shifted by s has the quadratic term 3 k3 s and a constant
        force, which the input offset takes; ``quadratic`` reports the
        asymmetry as k2 about the output sensor's origin instead.
    search : SearchSettings, optional
        SaDE and polish settings (popsize 30, maxiter 60, seed 0, tol 1e-6,
        patience 15, polish True).
    simulation : SimulationSettings, optional
        Record simulation settings (substeps 4, the input's reconstruction
        chosen from the record, no low-pass, skip 0, initial state estimated).
    progress : bool
        Progress bar of the search (default True, as the Monte Carlo runs; the
        CLI turns it off with --no-progress or --json).
    callback : callable, optional
        ``callback(generation, parameters_dict, cost)``; True stops.
    **options
        Fields of either settings object as keywords (``popsize=``,
        ``maxiter=``, ``seed=``, ``tol=``, ``patience=``, ``polish=``;
        ``substeps=``, ``hold=``, ``lowpass=``, ``skip=``,
        ``initial_state=``); they override ``search`` and ``simulation``.

    Returns
    -------
    IdentificationResult
    """
    check_model(model)
    search, simulation = resolve_settings("identify", options, search=search, simulation=simulation)
    single = isinstance(record, Record)
    if outputs is None and single and OUTPUT_CHANNEL not in record:
        others = [k for k in OUTPUT_KINDS if k in record]
        raise ValueError(
            f"record {record.name!r} has no {OUTPUT_CHANNEL} channel"
            + (f"; fit its {', '.join(others)} with `outputs=` (`--output-kind`)" if others else "")
        )
    plain = outputs is None or tuple(np.atleast_1d(outputs)) == (OUTPUT_CHANNEL,)
    if rectifier is not None and coupling is None:
        raise ValueError(
            "`rectifier` (--rectifier bridge) rectifies a coupling's output: name it "
            "(`coupling='inductive'` or `'piezo'`, `--coupling`)"
        )
    if not (single and plain and coupling is None and r_load is None and not weights):
        from randvib.identification.experiment import recorded_tests
        from randvib.identification.experiment_fit import identify_experiment

        coupling = check_coupling_kind(coupling)
        return identify_experiment(
            recorded_tests(record, outputs, r_load, coupling, rectifier), model, coupling, m=m,
            fixed=fixed, bounds=bounds, init=init, quadratic=quadratic, weights=weights,
            search=search, simulation=simulation, progress=progress, callback=callback,
        )  # fmt: skip
    if not isinstance(record, Record):
        raise ValueError(f"`record` must be a randvib Record, got {type(record).__name__}")
    fixed = _resolve_fixed(model, fixed, m, record)
    fixed, reported, notes = _measurement_model(record, fixed, bool(quadratic))
    simulation, why = simulation.for_record(record)
    notes += (why,) if why else ()
    space = search_space(record, model, fixed, bounds, simulation.skip)
    cost = _identification_cost(record, model, fixed, space.free, simulation)
    _check_population(search, len(space.free))
    speed = _refuse_unsimulable(cost, space)
    _announce(record, search, simulation, speed)
    searched = cost
    if search.search_samples is not None:
        check_int("search_samples", search.search_samples, minimum=SAMPLES_PER_PARAMETER * 2)
    if search.search_samples is not None and record.n > search.search_samples:
        window = record.rows(0, search.search_samples, name=record.name)
        searched = _identification_cost(window, model, fixed, space.free, simulation)
    start = time.perf_counter()
    res = sade(
        searched,
        [space.box[n] for n in space.free],
        log=space.log,
        names=space.free,
        init=_initial_guess(init, space),
        callback=named_callback(callback, space.free),
        progress=progress,
        **search.sade_options(),
    )
    cost.evaluations, cost.seconds = searched.evaluations, searched.seconds
    found = dict(zip(space.free, map(float, res.x), strict=True))
    given = frozenset(bounds or ())
    refined = _polish(cost, space, found, simulation, search, given) if search.polish else None
    elapsed = time.perf_counter() - start
    result = _identification_result(
        cost, space, res, refined, elapsed, search, simulation, reported, notes
    )
    if np.isfinite(result.cost):
        result.residuals = result.diagnose(record)
    _warn_at_bound(result)
    _warn_unidentifiable(result)
    return result


#: What to do about estimates the record cannot tell apart, by the names involved.
OFFSETS_ADVICE = (
    "an input offset shifts z by a constant (-m a0 / k for a nearly linear spring), as the "
    "output offset does: hold one at a known value (`--fix input_offset=0` for a sensor "
    "zeroed before the test; `fixed=` in Python) and fit again"
)
START_ADVICE = (
    "start from the record's first samples (`--initial-state record`) or fit a longer record"
)
#: The advice for any other group.
SEPARATE = (
    "hold one at a known value (`--fix NAME=VALUE`; `fixed=` in Python) or fit a record that "
    "separates them (another level or input)"
)


def _warn_unidentifiable(result) -> None:
    """Warn once per group of estimates the record cannot tell apart (pairs linked by
    :attr:`~IdentificationResult.unidentifiable_pairs`, also saved in the JSON)."""
    groups: list[set] = []
    for a, b, _ in result.unidentifiable_pairs:
        joined = [g for g in groups if a in g or b in g]
        merged = set().union({a, b}, *joined)
        groups = [g for g in groups if g not in joined] + [merged]
    names = list(result.uncertainty.names) if groups else []
    for group in groups:
        members = sorted(group, key=names.index)
        advice = []
        if {"input_offset", "output_offset"} <= group:
            advice.append(OFFSETS_ADVICE)
        if group & {"z0", "v0"}:
            advice.append(START_ADVICE)
        listed = ", ".join(members[:-1]) + f" and {members[-1]}"
        warnings.warn(
            f"{listed} are not identifiable apart (correlations up to "
            f"{max(abs(r) for a, b, r in result.unidentifiable_pairs if a in group):.4f} in "
            f"magnitude): the record determines only a combination of them, so their separate "
            f"values mean little; {'; or '.join(advice) or SEPARATE}",
            UserWarning,
            stacklevel=3,
        )


def _warn_at_bound(result) -> None:
    """Warn, naming ``--bounds``, when a free parameter ended on its search box:
    the cost may fall further beyond it, so the value is not an estimate."""
    if not result.at_bound:
        return
    which = ", ".join(
        f"{name} = {result.parameters[name]:.4g} {result.unit(name)} on its {side} bound"
        for name, side in result.at_bound.items()
    )
    example = next(iter(result.at_bound))
    warnings.warn(
        f"{which}: the optimum may lie beyond the search box, so this is no estimate; "
        f"widen it (`--bounds {example}=LO:HI`, `bounds=` in Python) and fit again",
        UserWarning,
        stacklevel=3,
    )


def _check_population(search: SearchSettings, d: int) -> None:
    """Refuse a SaDE population that cannot fit in memory, before anything runs."""
    from randvib.identification.sade import check_population_memory

    check_population_memory(check_int("popsize", search.popsize, 6), d)


def _announce(record: Record, search: SearchSettings, simulation: SimulationSettings, speed):
    """Say how long a long identification will take: at most popsize x (maxiter + 1)
    simulations at ``speed``, the record sub-steps per second measured on the
    probes of :func:`_refuse_unsimulable`."""
    from randvib._resources import announce_duration

    popsize, maxiter = check_int("popsize", search.popsize, 6), check_int("maxiter", search.maxiter)
    steps = float(popsize) * (maxiter + 1) * record.n * simulation.substeps
    announce_duration(
        f"identification ({popsize} x {maxiter + 1} simulations of {record.n} samples)",
        steps / speed,
        stacklevel=4,
    )


def _identification_cost(record, model, fixed, free, simulation) -> CostFunction:
    return CostFunction(
        record,
        model,
        fixed=fixed,
        free=free,
        profile_offset="output_offset" not in fixed,
        **simulation.to_dict(),
    )


@dataclass(frozen=True)
class _Polished:
    """The least-squares polish's outcome."""

    parameters: dict
    initial_state: dict
    cost: float
    uncertainty: object
    message: str
    simulations: int


def _polish(cost: CostFunction, space, found: dict, simulation, search, given) -> _Polished:
    """Least squares of the simulation error from the search's best ``found``."""
    from randvib.identification.least_squares import INITIAL_STATE, SimulationError, polish

    names = list(space.free)
    theta0 = [found[n] for n in names]
    z0 = cost.z0
    if cost.profile_offset:
        # start from the offset the search profiled for this candidate
        z = cost.simulate({**cost.fixed, **found})[0][cost.skip :]
        offset = float(np.mean(cost.record.z[cost.skip :] - z))
        names.append("output_offset")
        theta0.append(offset)
        z0 = float(cost.record.z[0]) - offset
    if simulation.initial_state == "estimate":
        names += list(INITIAL_STATE)
        theta0 += [z0, cost.v0]
    problem = SimulationError(cost, _coordinates(cost, space, names, given))
    theta, residuals, unc, message = polish(
        problem, np.array(theta0), max_nfev=search.polish_maxfev or POLISH_MAXFEV
    )
    values = dict(zip(names, map(float, theta), strict=True))
    return _Polished(
        parameters={n: v for n, v in values.items() if n not in INITIAL_STATE},
        initial_state={n: values.get(n, getattr(cost, n)) for n in INITIAL_STATE},
        cost=float(100.0 * (residuals @ residuals) / (cost.n_scored * cost.variance)),
        uncertainty=unc,
        message=str(message),
        simulations=problem.simulations,
    )


def _coordinates(cost, space, names, given=frozenset()):
    """Scales and bounds of the least-squares vector: the search box for the model's
    parameters and for the names in ``given`` (bounded by the user); none for the
    offsets and k2 otherwise."""
    from randvib.identification.least_squares import Coordinates

    z_scale = float(np.std(cost.record.z))
    scales = {
        "output_offset": z_scale,
        "z0": z_scale,
        "v0": float(np.std(np.diff(cost.record.z))) / cost.record.dt,
        "input_offset": max(float(np.std(cost.drive)), 1e-300),
    }
    log, scale, lower, upper = [], [], [], []
    for name in names:
        if name in space.free:
            lo, hi = space.box[name]
            is_log = space.log[space.free.index(name)]
            log.append(is_log)
            scale.append(max(abs(lo), abs(hi)) or 1.0)
            # the default boxes of the offsets and k2 only start the search (a
            # cubic spring about a shifted origin needs an input offset beyond
            # the input's mean +- half its SD); a box the user gave is kept
            bounded = name not in EXTRA_PARAMETERS or name in given
            lower.append(lo if bounded else -np.inf)
            upper.append(hi if bounded else np.inf)
        else:
            log.append(False)
            scale.append(scales[name] or 1.0)
            lower.append(-np.inf)
            upper.append(np.inf)
    return Coordinates(
        names=tuple(names),
        log=np.array(log, bool),
        scale=np.array(scale, float),
        lower=np.array(lower, float),
        upper=np.array(upper, float),
    )


def _refuse_unsimulable(cost: CostFunction, space: SearchSpace) -> float:
    """Refuse before searching when the model cannot simulate the record anywhere probed.

    A fixed value or bound at which the model diverges or overflows (``--fix
    k3=1e308``, ``--bounds k=1e300:1e308``) would make every candidate of the
    search diverge; one batched simulation at the box's corners and centre
    finds it first. Some probes diverging is normal (wide default bounds);
    all of them diverging is refused. Returns the record sub-steps per second
    the probes ran at (after one that compiles the simulation), for the
    duration estimate.
    """
    probes = probe_points(space)
    with np.errstate(all="ignore"):
        cost(probes[:1])  # compiles (or loads) the simulation: not part of the speed
        costs, elapsed = timed(lambda: cost(probes))
    if not np.any(np.isfinite(costs)):
        raise ValueError(
            f"the {cost.model} model cannot simulate record {cost.record.name!r} with the "
            f"fixed values {cost.fixed} anywhere in the bounds {space.box}: all {len(probes)} "
            "probes (the corners and centre of the bounds) diverged; check `--fix` and "
            "`--bounds` (nothing was searched)"
        )
    return len(probes) * cost.record.n * cost.substeps / elapsed


def _initial_guess(init, space: SearchSpace):
    """The user's device as one row of the initial population (None without one).

    Its parameters that the model has (c = c_m + c_e) are the guess, clipped
    into the box; the others (the offsets, k2, another law's) start at the
    box's centre.
    """
    if init is None:
        return None
    guess = device_parameters(init, None, "identify's `init`")
    guess = {name: value for name, value in guess.items() if name not in EXTRA_PARAMETERS}
    return [[np.clip(guess.get(n, np.mean(space.box[n])), *space.box[n]) for n in space.free]]


def _outside_search_box(parameters, space) -> tuple:
    """Notes naming an offset or k2 the unbounded polish moved outside its search box
    (the ``bounds`` reported for it are the global search's, not the polish's)."""
    out = []
    for name in EXTRA_PARAMETERS:
        if name in space.free and name in parameters:
            lo, hi = space.box[name]
            value = parameters[name]
            if not lo <= value <= hi:
                out.append(
                    f"{name} = {value:.6g}: outside its search box [{lo:.6g}, {hi:.6g}], which "
                    "only starts the search; the least-squares polish leaves it unbounded "
                    f"(`--bounds {name}=LO:HI` bounds both)"
                )
    return tuple(out)


def _identification_result(cost, space, res, refined, elapsed, search, simulation, reported, notes):
    if not np.isfinite(res.fun):
        raise ValueError(
            f"no candidate of the {cost.model} model could simulate record "
            f"{cost.record.name!r} (best J = {res.fun!r}): every simulation diverged; check the "
            f"fixed values {cost.fixed} and the bounds {space.box}"
        )
    parameters = {**cost.fixed, **dict(zip(space.free, map(float, res.x), strict=True))}
    j, message, unc, nfev = float(res.fun), res.message, None, res.nfev
    start = {"z0": cost.z0, "v0": cost.v0}
    if refined is not None:
        parameters.update(refined.parameters)
        j, unc = refined.cost, refined.uncertainty
        start = refined.initial_state
        message += f"; least-squares polish: {refined.message}"
        nfev += refined.simulations
    else:
        # without the polish: the profiled offset, and J from the record's start
        if cost.profile_offset:
            z = cost.simulate(parameters)[0][cost.skip :]
            parameters["output_offset"] = float(np.mean(cost.record.z[cost.skip :] - z))
        simulation = replace(simulation, initial_state="record")
        checked = check_parameters(parameters, cost.model)
        pred = score(checked, cost.model, cost.record, simulation)
        j, start = pred.cost, pred.initial_state
    order = ("m",) + MODEL_PARAMETERS[cost.model] + reported
    notes = notes + _outside_search_box(parameters, space)
    seconds = cost.seconds
    return IdentificationResult(
        model=cost.model,
        parameters={name: float(parameters[name]) for name in order},
        free=space.free + (("output_offset",) if cost.profile_offset else ()),
        cost=j,
        bounds={n: tuple(map(float, space.box[n])) for n in space.free},
        nfev=nfev,
        generations=res.nit,
        elapsed=elapsed,
        simulations_per_second=cost.evaluations / seconds if seconds else float("nan"),
        message=message,
        history={"best": res.history["best"], "nfev": res.history["nfev"]},
        record=cost.record.name,
        settings={
            **simulation.to_dict(),
            "popsize": search.popsize,
            "maxiter": search.maxiter,
            "seed": search.seed if isinstance(search.seed, int | None) else "generator",
        },
        uncertainty=unc,
        initial_state={k: float(v) for k, v in start.items()},
        notes=notes,
        input_kind=cost.record.input_kind,
    )
