"""Identification of the whole harvester from what users measure (:func:`identify_experiment`).

The mechanical model of paper Eq. 1 and, with a coupling, its circuit
(:mod:`randvib.identification.circuit`) are fitted to one or more records
of one device (:mod:`randvib.identification.experiment`), each at its own
load with its own channels (displacement, velocity, load voltage, load
current), as :func:`randvib.identify` does for a displacement record: SaDE
on the summed per-channel J (Eq. 11), the channels' offsets profiled out,
then the least-squares polish of the weighted simulation error, which gives
the standard errors (a sandwich with each channel's own noise).

Before anything is searched the records' structure is checked
(:func:`~randvib.identification.identifiability.structural_identifiability`):
what no record of this kind can fix is refused with one line naming what to
add. After the fit, the local check at the estimate
(:func:`~randvib.identification.identifiability.local_identifiability`)
refuses a split of the damping, the mass or the coupling that the data do
not make; the fit is kept on the error (``error.result``).
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from randvib._resources import announce_duration
from randvib._validation import check_finite, check_int
from randvib.identification.bounds import (
    SAMPLES_PER_PARAMETER,
    SearchSpace,
    channel_scales,
    default_bounds,
    equation_error_mass,
)
from randvib.identification.circuit import (
    ALL_COUPLING_PARAMETERS,
    BRIDGE_NOTE,
    CIRCUIT_START,
    COUPLING_PARAMETERS,
    OFFSET_NAMES,
    check_coupling_parameter,
    coupling_bounds,
    is_dynamic,
)
from randvib.identification.experiment import (
    START,
    ExperimentCost,
    ExperimentError,
    RecordedTest,
    check_weights,
    own_name,
)
from randvib.identification.identifiability import (
    Configuration,
    Identifiability,
    IdentifiabilityError,
    _remedies,
    linear_information,
    local_identifiability,
    structural_identifiability,
)
from randvib.identification.input_reconstruction import driving_signal
from randvib.identification.models import MODEL_PARAMETERS, check_parameter, parameter_specs
from randvib.identification.record_integrator import EXTRA_PARAMETERS
from randvib.identification.result import IdentificationResult
from randvib.identification.sade import named_callback, sade
from randvib.identification.settings import EXPERIMENT_POLISH_MAXFEV

#: Corners of the search box probed before the search (a circuit's stiffest
#: corners cost many sub-cycles each: a sample suffices to find a box where
#: nothing simulates).
PROBE_CORNERS = 8
#: A record's own parameters (with ``[i]`` when there are several records).
PER_RECORD = ("input_offset", *OFFSET_NAMES.values(), *START, CIRCUIT_START)


def _names(model, coupling) -> tuple:
    """The shared parameters: the device's, the friction law's, k2 and the coupling's."""
    return ("m",) + MODEL_PARAMETERS[model] + ("k2",) + COUPLING_PARAMETERS.get(coupling, ())


def _check_value(model, name, value, label):
    if name in ALL_COUPLING_PARAMETERS:
        return check_coupling_parameter(name, value, label)
    return check_parameter(model, name, value, label)


def resolve_fixed(model, coupling, tests, fixed, m) -> dict:
    """The user's fixed values by the names the fit uses (a record's own expanded to each).

    ``--fix voltage_offset=0`` holds every record's voltage offset,
    ``voltage_offset[1]=0`` only the second record's.
    """
    shared = _names(model, coupling)
    count = len(tests)
    out = {}
    for key, value in dict(fixed or {}).items():
        base, _, index = key.partition("[")
        if base in shared and not index:
            out[key] = _check_value(model, base, value, f"--fix {key}")
        elif base in PER_RECORD and base not in (*START, CIRCUIT_START):
            which = range(count) if not index else [_record_index(key, index, count)]
            for i in which:
                out[own_name(base, i, count)] = float(check_finite(f"--fix {key}", value))
        else:
            allowed = shared + ("input_offset",) + tuple(OFFSET_NAMES.values())
            raise ValueError(
                f"`--fix {key}`: unknown parameter for model {model!r}"
                + (f" with the {coupling} coupling" if coupling else "")
                + f"; allowed: {', '.join(allowed)} (a record's own with [i])"
            )
    if m is not None:
        value = check_parameter(model, "m", m, "m")
        if "m" in out and out["m"] != value:
            raise ValueError(f"`m` given twice with different values: {m} and --fix m={out['m']}")
        out["m"] = value
    return out


def _record_index(key, index, count) -> int:
    try:
        i = int(index.rstrip("]"))
    except ValueError:
        i = -1
    if not 0 <= i < count:
        raise ValueError(f"`--fix {key}`: the record index must be 0 to {count - 1}")
    return i


def measurement_model(model, tests, fixed, quadratic) -> tuple[dict, tuple]:
    """k2 and each record's input offset: estimated or held at 0 where it cannot be told apart.

    As for one displacement record (:func:`randvib.identification.identify`):
    a base displacement loses a constant offset in its second derivative;
    with a linear spring a constant input only shifts z, which no velocity,
    voltage or current shows and a displacement's offset absorbs.
    """
    fixed = dict(fixed)
    notes = []
    if quadratic and "k2" in fixed:
        raise ValueError("`--quadratic` estimates k2; it cannot also be fixed (--fix k2=...)")
    if not quadratic:
        fixed.setdefault("k2", 0.0)
    linear = fixed.get("k3") == 0.0 and fixed.get("k2") == 0.0
    for i, test in enumerate(tests):
        name = own_name("input_offset", i, len(tests))
        if name in fixed:
            continue
        why = None
        if test.record.input_kind == "base_displacement":
            why = "a constant offset on a displacement vanishes in its second derivative"
        elif quadratic:
            why = "with k2 free a constant input only shifts the origin, which k and k2 absorb"
        elif linear:
            why = (
                "with a linear spring a constant input only shifts z, which no channel tells apart"
            )
        if why is not None:
            fixed[name] = 0.0
            notes.append(f"{name} fixed at 0: {why}")
    return fixed, tuple(notes)


def configuration(model, coupling, tests, fixed) -> Configuration:
    """The structural test's view of the fit (:mod:`randvib.identification.identifiability`)."""
    shared = _names(model, coupling)
    specs = parameter_specs(model)
    units = {name: spec.unit for name, spec in specs.items()}
    units["k2"] = "N/m^2"
    return Configuration(
        coupling=coupling,
        force_input=tests[0].record.input_kind == "force",
        records=tuple((t.r_load, t.outputs) for t in tests),
        free=tuple(n for n in shared if n not in fixed),
        fixed={n: v for n, v in fixed.items() if n in shared},
        units=units,
    )


def search_space(model, coupling, tests, fixed, bounds) -> SearchSpace:
    """The free shared parameters and each record's input offset, with their boxes."""
    shared = _names(model, coupling)
    count = len(tests)
    offsets = [own_name("input_offset", i, count) for i in range(count)]
    free = tuple(n for n in (*shared, *offsets) if n not in fixed)
    first = tests[0]
    needed = max(20, SAMPLES_PER_PARAMETER * (len(free) + 3))
    for test in tests:
        if test.record.n < needed:
            raise ValueError(
                f"record {test.record.name!r} has {test.record.n} samples; the {model} model with "
                f"{len(free)} free parameters needs at least {needed}"
            )
    m_ref = fixed.get("m")
    if m_ref is None and first.record.input_kind != "force":
        m_ref = _mass_reference(first, coupling, bounds)
    # a force input without the mass: the displacement's equation-error estimate
    scales = channel_scales(first.record, first.outputs, m_ref)
    box = default_bounds(first.record, model, None if "m" in free else scales.m, scales=scales)
    if coupling is not None:
        box.update(coupling_bounds(coupling, scales, [t.r_load for t in tests], first.record.dt))
    k2 = 2 * scales.k_ref / scales.z_max
    box["k2"] = (-k2, k2)
    for name, test in zip(offsets, tests, strict=True):
        drive, _ = driving_signal(test.record.input, test.record.dt, test.record.input_kind)
        mean, half = float(np.mean(drive)), 0.5 * float(np.std(drive))
        box[name] = (mean - half, mean + half)
    for name, (lo, hi) in (bounds or {}).items():
        base = name.partition("[")[0]
        if name not in box and base not in shared:
            raise ValueError(
                f"`--bounds {name}`: unknown parameter; allowed: {', '.join((*shared, *offsets))}"
            )
        lo, hi = (_check_value(model, base, x, f"--bounds {name}") for x in (lo, hi))
        if not lo < hi:
            raise ValueError(f"`--bounds {name}`: a search range needs lower < upper")
        box[name] = (lo, hi)
    specs = parameter_specs(model)
    log = [
        box[n][0] > 0 and (n in ALL_COUPLING_PARAMETERS or n in specs and specs[n].log)
        for n in free
    ]
    return SearchSpace(free=free, box={n: box[n] for n in free}, log=log)


def _mass_reference(test: RecordedTest, coupling, bounds) -> float:
    """The centre of the mass's search box when the mass is free under base excitation."""
    if bounds and "m" in bounds:
        lo, hi = bounds["m"]
        return float(np.sqrt(lo * hi))
    estimate = equation_error_mass(test.record, test.outputs, coupling, test.r_load)
    if estimate is None:
        raise ValueError(
            "the mass is free and no channel gives its scale: give it (`--m`) or its search "
            "range (`--bounds m=LO:HI`)"
        )
    return estimate


#: What the structural analysis says behind a bridge (:func:`identify_experiment`).
BRIDGE_STRUCTURE = (
    "behind a diode bridge the linear symmetries of the structural analysis do not hold (the "
    "threshold V_out + 2 V_d sets the transducer's voltage scale); what the records fix is "
    "judged at the estimate, from the fit's covariance alone"
)


def identify_experiment(
    tests, model, coupling, *, m, fixed, bounds, init, quadratic, weights, search, simulation,
    progress, callback,
) -> IdentificationResult:  # fmt: skip
    """Fit ``model`` with ``coupling`` to the records ``tests`` (see :func:`randvib.identify`)."""
    weights = check_weights(weights, tests)
    fixed = resolve_fixed(model, coupling, tests, fixed, m)
    if "m" not in fixed and tests[0].record.input_kind != "force" and coupling is None:
        raise ValueError(
            f"`m` (kg) is required with a `{tests[0].record.input_kind}` input: under base "
            "excitation the mass is not identifiable (Eq. 1 divided by m leaves c/m, k/m, k3/m, F/m)"
        )
    fixed, notes = measurement_model(model, tests, fixed, bool(quadratic))
    bridged = tests[0].bridge is not None
    if bridged:  # the switching breaks the linear symmetries: the fit's covariance decides
        structure = Identifiability((), (), (BRIDGE_STRUCTURE,))
        known = ", ".join(f"{k} = {v:g}" for k, v in tests[0].bridge.items())
        notes += (f"{BRIDGE_NOTE} {known}",)
    else:
        structure = structural_identifiability(configuration(model, coupling, tests, fixed))
    if not structure.identifiable:
        raise IdentifiabilityError(structure.refusal())
    simulation, why = simulation.for_record(tests[0].record)
    notes += (why,) if why else ()
    space = search_space(model, coupling, tests, fixed, bounds)
    cost = ExperimentCost(tests, model, coupling, fixed=fixed, free=space.free,
                          weights=weights, simulation=simulation)  # fmt: skip
    searched = _search_cost(cost, tests, search, simulation, weights)
    _announce(cost, searched, space, search)
    start = time.perf_counter()
    res = sade(
        searched, [space.box[n] for n in space.free], log=space.log, names=space.free,
        init=_initial_guess(init, space), callback=named_callback(callback, space.free),
        progress=progress, **search.sade_options(),
    )  # fmt: skip
    if not np.isfinite(res.fun):
        raise ValueError(
            f"no candidate of the {model} model could simulate the records (best J = "
            f"{res.fun!r}): every simulation diverged; check the fixed values and the bounds"
        )
    cost.evaluations, cost.seconds = searched.evaluations, searched.seconds
    found = dict(zip(space.free, map(float, res.x), strict=True))
    polished = _polish(cost, space, found, simulation, search, frozenset(bounds or ()))
    result = _result(cost, space, res, polished, time.perf_counter() - start, search,
                     simulation, structure, notes)  # fmt: skip
    _check_locally(result, configuration(model, coupling, tests, fixed), cost, not bridged)
    return result


def _search_cost(cost, tests, search, simulation, weights):
    """The search's cost: on each record's first ``search_samples`` samples, if asked."""
    n = search.search_samples
    if n is None:
        return cost
    check_int("search_samples", n, minimum=SAMPLES_PER_PARAMETER * 2)
    if all(t.record.n <= n for t in tests):
        return cost
    windows = [
        RecordedTest(t.record.rows(0, min(n, t.record.n), name=t.record.name), t.outputs, t.r_load)
        for t in tests
    ]
    return ExperimentCost(windows, cost.model, cost.coupling, fixed=cost.fixed, free=cost.free,
                          weights=weights, simulation=simulation)  # fmt: skip


def _announce(cost, searched, space, search) -> None:
    """Refuse a box where nothing simulates; say how long a long search will take."""
    from randvib.identification.bounds import probe_points
    from randvib.identification.sade import check_population_memory

    popsize = check_int("popsize", search.popsize, 6)
    check_population_memory(popsize, len(space.free))
    probes = probe_points(space, corners=PROBE_CORNERS)
    with np.errstate(all="ignore"):
        searched(probes[:1])  # compiles (or loads) the simulation
        started = time.perf_counter()
        costs = searched(probes)
        elapsed = max(time.perf_counter() - started, 1e-9)
    if not np.any(np.isfinite(costs)):
        raise ValueError(
            f"the {cost.model} model cannot simulate the records with the fixed values "
            f"{cost.fixed} anywhere in the bounds {space.box}: all {len(probes)} probes (the "
            "corners and centre of the bounds) diverged; check `--fix` and `--bounds`"
        )
    per_candidate = elapsed / len(probes)
    maxiter = check_int("maxiter", search.maxiter)
    announce_duration(
        f"identification ({popsize} x {maxiter + 1} simulations of {len(cost.tests)} record(s))",
        per_candidate * popsize * (maxiter + 1),
        stacklevel=5,
    )


def _initial_guess(init, space: SearchSpace):
    """The user's device (a Harvester with c_m, its coupling's parameters) as one row."""
    if init is None:
        return None
    guess = {"m": init.m, "c": init.c_m, "k": init.k, "k3": init.k3}
    if init.friction is not None:
        guess.update(init.friction.parameters())
    if init.electrical is not None:
        guess.update(init.electrical.parameters())
    return [[np.clip(guess.get(n, np.mean(space.box[n])), *space.box[n]) for n in space.free]]


def _polish(cost: ExperimentCost, space, found, simulation, search, given):
    """Least squares of the weighted simulation error from the search's best ``found``.

    The vector holds the free parameters, each record's channel offsets and,
    estimated, each record's initial state, started where the search's
    profiling put them (:meth:`ExperimentCost.record_cost`).
    """
    from randvib.identification.least_squares import polish

    named = cost.parameters(np.array([[found[n] for n in cost.free]]))
    names, theta0, scales = list(space.free), [found[n] for n in space.free], {}
    dynamic = is_dynamic(cost.coupling, {**cost.fixed, **found})
    starts = []
    for index, prep in enumerate(cost.prepared):
        start = [np.array(v, dtype=float) for v in cost.start(named, index)]
        shift = cost.record_cost(named, index)[1]
        for j, base in enumerate(cost.unmeasured_start(named, index)):
            start[START.index(base)] = start[START.index(base)] + shift[:, j]
        run = cost.run(named, index, start=tuple(start))
        for base, values in zip((*START, CIRCUIT_START), (run.z, run.v, run.x), strict=True):
            spread = float(np.std(values[0]))
            scales[cost.own(base, index)] = spread if np.isfinite(spread) and spread > 0 else 1.0
        for kind, model in cost.outputs(named, index, run).items():
            name = cost.own(OFFSET_NAMES[kind], index)
            scales[name] = float(np.std(prep.measured[kind])) or 1.0
            if name not in cost.fixed:
                names.append(name)
                theta0.append(float(np.mean((prep.measured[kind] - model[0])[prep.skip :])))
        starts.append(start)
    if simulation.initial_state == "estimate":
        for index, start in enumerate(starts):
            bases = (*START, CIRCUIT_START)[: 3 if dynamic else 2]
            for base, value in zip(bases, start, strict=False):
                names.append(cost.own(base, index))
                theta0.append(float(value[0]))
    problem = ExperimentError(cost, _coordinates(space, names, given, scales))
    theta, residuals, unc, message = polish(
        problem, np.array(theta0), max_nfev=search.polish_maxfev or EXPERIMENT_POLISH_MAXFEV
    )
    values = dict(zip(names, map(float, theta), strict=True))
    return values, float(residuals @ residuals), unc, str(message), problem.simulations


def _coordinates(space, names, given, scales):
    """Scales and bounds of the polish's vector: the search box for the model's
    parameters (and what the user bounded), none for offsets, k2 and the start."""
    from randvib.identification.least_squares import Coordinates

    log, scale, lower, upper = [], [], [], []
    for name in names:
        base = name.partition("[")[0]
        if name in space.free:
            lo, hi = space.box[name]
            log.append(space.log[space.free.index(name)])
            scale.append(max(abs(lo), abs(hi)) or 1.0)
            bounded = base not in (*EXTRA_PARAMETERS, "input_offset") or name in given
            lower.append(lo if bounded else -np.inf)
            upper.append(hi if bounded else np.inf)
        else:
            log.append(False)
            scale.append(scales[name])
            lower.append(-np.inf)
            upper.append(np.inf)
    return Coordinates(
        names=tuple(names), log=np.array(log, bool), scale=np.array(scale, float),
        lower=np.array(lower, float), upper=np.array(upper, float),
    )  # fmt: skip


def _result(cost, space, res, polished, elapsed, search, simulation, structure, notes):
    """The :class:`IdentificationResult` of the polished fit, with its channels and structure."""
    values, j, unc, message, simulations = polished
    parameters = {**cost.fixed, **values}
    named = {k: np.atleast_1d(v) for k, v in parameters.items()}
    channel_costs, verdicts, diagnostics = cost.channel_costs(named)
    order = _names(cost.model, cost.coupling)
    reported = [n for n in order if n != "k2" or n in values or parameters.get("k2")]
    per_record = [
        n for n in parameters
        if n.partition("[")[0] in ("input_offset", *OFFSET_NAMES.values())
        and (n in values or parameters[n] != 0.0)
    ]  # fmt: skip
    start = {n: v for n, v in values.items() if n.partition("[")[0] in (*START, CIRCUIT_START)}
    for index in range(cost.count):
        for base, value in zip((*START, CIRCUIT_START), cost.start(named, index), strict=True):
            start.setdefault(cost.own(base, index), float(np.ravel(value)[0]))
    tests = cost.tests
    return IdentificationResult(
        model=cost.model,
        parameters={n: float(parameters[n]) for n in (*reported, *per_record)},
        free=tuple(n for n in values if n not in start),
        cost=j,
        bounds={n: tuple(map(float, space.box[n])) for n in space.free},
        nfev=res.nfev + simulations,
        generations=res.nit,
        elapsed=elapsed,
        simulations_per_second=cost.evaluations / cost.seconds if cost.seconds else float("nan"),
        message=f"{res.message}; least-squares polish: {message}",
        history={"best": res.history["best"], "nfev": res.history["nfev"]},
        record=", ".join(t.record.name for t in tests),
        settings={**simulation.to_dict(), "popsize": search.popsize, "maxiter": search.maxiter,
                  "seed": search.seed if isinstance(search.seed, int | None) else "generator"},
        uncertainty=unc,
        initial_state=start,
        notes=notes,
        input_kind=tests[0].record.input_kind,
        coupling=cost.coupling or "",
        outputs=tests[0].outputs,
        r_loads=tuple(t.r_load for t in tests) if cost.coupling else (),
        rectifier=dict(tests[0].bridge or {}),
        records=tuple(t.record.name for t in tests),
        weights=dict(cost.weights),
        channel_costs=channel_costs,
        channel_residuals=verdicts,
        residuals=diagnostics,
        identifiability=structure,
    )  # fmt: skip


def _spectra(cost: ExperimentCost, result: IdentificationResult) -> list:
    """Each record's (frequencies, input weights |A|^2 2/N, channels' noise variances)."""
    out = []
    for prep in cost.prepared:
        a = prep.drive[prep.skip :] - np.mean(prep.drive[prep.skip :])
        spectrum = np.fft.rfft(a)[1:]
        omega = 2 * np.pi * np.fft.rfftfreq(a.size, prep.test.record.dt)[1:]
        noise = {
            row["output"]: row["rms_error"] ** 2
            for row in result.channel_costs
            if row["record"] == prep.test.record.name and row["rms_error"] > 0
        }
        out.append((omega, np.abs(spectrum) ** 2 / a.size, noise))
    return out


def _check_locally(
    result: IdentificationResult, config: Configuration, cost, linearised: bool = True
) -> None:
    """Refuse a split the data do not make (after the fit); warn of one poorly determined value.

    Two opinions: the fit's own covariance (:func:`local_identifiability`) and
    the linearised device's Fisher information under the records' input
    spectra and noise (:func:`linear_information`; not behind a bridge,
    ``linearised`` False, whose switching no linear device has); a split
    either finds is refused, with each parameter's larger relative standard error.
    """
    from dataclasses import replace

    local = local_identifiability(result.uncertainty, result.parameters)
    linear = {}
    if linearised:
        linear = linear_information(config, result.parameters, _spectra(cost, result))
    if linear:
        local["linear_response"] = linear
        local["split"] = local.get("split", []) + [
            g for g in linear["split"] if g not in local.get("split", [])
        ]
        errors = local.setdefault("relative_errors", {})
        for name, value in linear["relative_errors"].items():
            errors[name] = max(errors.get(name, 0.0), value)
    result.identifiability = replace(result.identifiability, local=local)
    for group in local.get("split", []):
        errors = local["relative_errors"]
        which = ", ".join(f"{n} ({100 * errors[n]:.0f} %)" for n in group)
        remedies = _remedies(config, tuple(group)) or (f"fix one of {', '.join(group)}",)
        raise IdentifiabilityError(
            f"the records do not determine the split of {', '.join(group)} (relative standard "
            f"errors {which}): {' or '.join(remedies)}",
            result,
        )
    for name in local.get("poorly_determined", []):
        warnings.warn(
            f"{name} = {result.parameters[name]:.4g} {result.unit(name)} is poorly determined "
            f"by the records (relative standard error "
            f"{100 * local['relative_errors'][name]:.0f} %); its interval says how poorly",
            UserWarning,
            stacklevel=3,
        )
