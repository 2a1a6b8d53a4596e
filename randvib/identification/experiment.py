"""Several records of one device, each at its own load with its own channels, and their cost.

An experiment is what a rig gives: one or more records of one device
(:class:`RecordedTest`), each with an input channel, the output channels
fitted (:data:`~randvib.identification.circuit.OUTPUT_KINDS`: displacement,
velocity, load voltage, load current) and, with a coupling, the known load
R_L it was taken at. The cost is the paper's J (Eq. 11) per channel, each
normalised by its own variance, weighted and summed over channels and records:

    J = sum_records sum_channels w_k 100 / (N sigma_k^2) sum_i (y_k,i - yhat_k,i)^2

:class:`ExperimentCost` scores a population of parameter sets on every
record in one compiled batch per record (as SaDE needs), each channel's
sensor offset profiled out in closed form unless fixed;
:class:`ExperimentError` is the weighted residual vector the least-squares
polish minimises (its sum of squares is J), with the blocks (one per record
and channel) the covariance treats separately.

Parameters are handled by name: the device's and the coupling's are shared
by all records; a record's own (input offset, each channel's offset, the
initial state z0, v0 and, with a circuit state, x0) carry the suffix ``[i]``
when there are several records (:func:`own_name`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from randvib.identification.circuit import (
    CIRCUIT_START,
    ELECTRICAL_OUTPUTS,
    OFFSET_NAMES,
    check_output_kind,
    circuit_terms,
    is_dynamic,
    output_coefficients,
    quasi_static_state,
)
from randvib.identification.cost import initial_velocity
from randvib.identification.input_reconstruction import driving_signal, reconstruct_input
from randvib.identification.least_squares import SimulationError
from randvib.identification.models import check_model
from randvib.identification.record_bridge import dc_channel, run_bridge
from randvib.identification.record_integrator import (
    DEVICE_PARAMETERS,
    SEARCH_SUBCYCLES,
    parameter_matrix,
    run_kernel,
)
from randvib.models.record import Record

#: The initial state of each record's simulation (the circuit's x0 only with one).
START = ("z0", "v0")
#: The secants' steps of the start's profiling, as shares of each candidate's own
#: displacement or velocity scale: one Gauss-Newton step per entry.
PROFILE_STEPS = (0.1, 0.01)


@dataclass(frozen=True)
class RecordedTest:
    """One record of the device: the channels fitted and the load it was taken at.

    Attributes
    ----------
    record : Record
        Its input channel drives the device; it holds every channel of ``outputs``.
    outputs : tuple of str
        The channels fitted, by kind (:data:`~randvib.identification.circuit.OUTPUT_KINDS`).
    r_load : float or None
        The known load resistance R_L (ohm) of the record, with a coupling
        (behind a bridge with a storage capacitor: the capacitor's load).
    bridge : dict or None
        The known full-wave bridge between the coupling and its output
        (:func:`known_bridge`): ``v_diode`` (V) and ``storage_capacitance``
        (F, with ``r_load``) or ``battery`` (V); None without one.
    """

    record: Record
    outputs: tuple
    r_load: float | None = None
    bridge: dict | None = None


def own_name(name: str, index: int, count: int) -> str:
    """A record's own parameter ``name``: itself for one record, ``name[index]`` for several."""
    return name if count == 1 else f"{name}[{index}]"


def recorded_tests(records, outputs=None, r_load=None, coupling=None, rectifier=None) -> tuple:
    """The :class:`RecordedTest` of each record, checked.

    ``outputs``: kinds fitted on every record (default the relative
    displacement); ``r_load``: one load for all records or one per record
    (ohm), needed with a coupling; ``rectifier``: the known bridge of every
    record (:func:`known_bridge`).
    """
    records = (records,) if isinstance(records, Record) else tuple(records)
    if not records or not all(isinstance(r, Record) for r in records):
        raise ValueError("`record` must be a randvib Record or a sequence of them")
    kinds = ("relative_displacement",) if outputs is None else tuple(outputs)
    if isinstance(outputs, str):
        kinds = (outputs,)
    if not kinds or len(set(kinds)) != len(kinds):
        raise ValueError(f"`outputs` must name distinct output kinds, got {outputs!r}")
    for kind in kinds:
        check_output_kind(kind)
    loads = _loads(r_load, len(records), coupling)
    for record in records:
        missing = [kind for kind in kinds if kind not in record]
        if missing:
            raise ValueError(
                f"record {record.name!r} has no {', '.join(missing)} channel to fit; it has "
                f"{', '.join(record.channels)} (`outputs` names the channels fitted)"
            )
    electrical = [kind for kind in kinds if kind in ELECTRICAL_OUTPUTS]
    if electrical and coupling is None:
        raise ValueError(
            f"a `{electrical[0]}` output is the circuit's: name the coupling "
            "(`coupling=`, `--coupling resistive|inductive|piezo`) and the load (`--r-load`)"
        )
    bridge = known_bridge(rectifier, coupling, loads, kinds)
    return tuple(
        RecordedTest(r, kinds, load, bridge) for r, load in zip(records, loads, strict=True)
    )


#: The bridge's parameters an identification takes as known (``rectifier=``).
BRIDGE_KEYS = ("v_diode", "storage_capacitance", "battery")


def known_bridge(rectifier, coupling, loads, kinds) -> dict | None:
    """The checked ``rectifier`` dict: ``v_diode`` (V, default 0) and ``storage_capacitance``
    (F; each record's R_L its load) or ``battery`` (V); None for none.

    Refused: a coupling other than ``inductive`` or ``piezo``, an unknown key,
    both outputs or neither, a battery's ``voltage`` channel (constant V_b) and a
    piezo element's ``current`` into a battery (its charge passes in jumps).
    """
    if rectifier is None:
        return None
    from randvib.models.rectifier import RECTIFIED

    if not isinstance(rectifier, dict):
        raise ValueError(
            f"`rectifier` must be a dict of {', '.join(BRIDGE_KEYS)}; got {rectifier!r}"
        )
    if coupling not in RECTIFIED:
        raise ValueError(
            f"`rectifier` (--rectifier bridge) rectifies a coil or a piezo element: it needs "
            f"`coupling` {' or '.join(map(repr, RECTIFIED))}; got {coupling!r}"
        )
    unknown = sorted(set(rectifier) - set(BRIDGE_KEYS))
    if unknown:
        raise ValueError(f"`rectifier`: unknown {unknown}; allowed: {', '.join(BRIDGE_KEYS)}")
    out = {"v_diode": 0.0, **{k: float(v) for k, v in rectifier.items()}}
    if ("battery" in out) == ("storage_capacitance" in out):
        raise ValueError(
            "`rectifier` needs exactly one output: `storage_capacitance` (F; each record's "
            "`r_load` its load) or `battery` (V)"
        )
    # the model's own checks of every value, at the first record's load
    cls = RECTIFIED[coupling]
    probe = {"alpha": 1.0, "r_coil": 1.0} if coupling == "inductive" else {"theta": 1.0,
             "capacitance": 1.0}  # fmt: skip
    load = {} if "battery" in out else {"r_load": loads[0]}
    cls(**probe, **out, **load)
    if "battery" in out and "voltage" in kinds:
        raise ValueError(
            "a battery holds the bridge's output at V_b: its `voltage` channel is constant and "
            "fixes nothing; fit the `current` (or use a storage capacitor)"
        )
    if "battery" in out and coupling == "piezo" and "current" in kinds:
        raise ValueError(
            "a piezo element's bridge charges a battery in the clamp's jumps, no current at a "
            "sample: fit the `relative_velocity` or use a storage capacitor"
        )
    return out


def check_weights(weights, tests) -> dict:
    """``kind -> w`` of the fitted channels: positive and finite, each a kind the records fit.

    A weight for a channel no record fits would be ignored silently, and a
    negative or zero one would reward a misfit: both are refused.
    """
    if weights is None:
        return {}
    if not isinstance(weights, dict):
        raise ValueError(f"`weights` must be a dict of output kind -> weight, got {weights!r}")
    fitted = tuple(dict.fromkeys(kind for test in tests for kind in test.outputs))
    out = {}
    for kind, value in weights.items():
        if kind not in fitted:
            raise ValueError(
                f"`weights` (--weight) names {kind!r}, which no record fits; the fitted "
                f"channels are {', '.join(fitted)}"
            )
        try:
            w = float(value)
        except (TypeError, ValueError):
            w = float("nan")
        if not (0.0 < w < float("inf")):
            raise ValueError(f"`weights` (--weight) {kind}={value!r}: a weight must be positive")
        out[kind] = w
    return out


def _loads(r_load, n: int, coupling) -> list:
    if coupling is None:
        if r_load is not None:
            raise ValueError("`r_load` is the coupling's load: it needs `coupling` (`--coupling`)")
        return [None] * n
    if r_load is None:
        raise ValueError(
            f"the {coupling} coupling needs each record's load resistance (`r_load=`, `--r-load`)"
        )
    loads = [r_load] * n if np.ndim(r_load) == 0 else list(r_load)
    if len(loads) != n:
        raise ValueError(f"`r_load` gives {len(loads)} loads for {n} records: one, or one each")
    out = []
    for value in loads:
        value = float(value)
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"`r_load` must be > 0 (ohm), got {value!r}")
        out.append(value)
    return out


@dataclass
class _Prepared:
    """What one record's simulations and scores need, computed once."""

    test: RecordedTest
    index: int
    drive: np.ndarray
    base_input: bool
    fine: np.ndarray | None
    skip: int
    measured: dict  # kind -> samples
    norm: dict  # kind -> w 100 / (N sigma^2)
    limit: float


class ExperimentCost:
    """Batched J of one model on the records and channels of an experiment.

    Calling it with ``X`` (n, d), columns in the order of :attr:`free`,
    returns n costs; each record's population is simulated in one parallel
    compiled call. Diverged candidates cost ``inf``. Each channel's offset is
    profiled out (J minimised over it in closed form) unless ``fixed`` holds
    it. The simulation starts from the record (:meth:`start`) unless the
    parameters give z0, v0 (and x0).
    """

    def __init__(self, tests, model, coupling, *, fixed, free, weights=None, simulation):
        self.tests = tuple(tests)
        self.model = model
        self.friction = check_model(model)
        self.coupling = coupling
        self.fixed = dict(fixed)
        self.free = tuple(free)
        self.weights = check_weights(weights, self.tests)
        self.substeps = simulation.substeps
        self.hold = simulation.hold
        self.skip = simulation.skip
        self.prepared = [self._prepare(t, i, simulation) for i, t in enumerate(self.tests)]
        self.evaluations = 0
        self.seconds = 0.0
        self.record = self.tests[0].record  # what messages name

    @property
    def count(self) -> int:
        return len(self.tests)

    def own(self, name: str, index: int) -> str:
        return own_name(name, index, self.count)

    def _prepare(self, test, index, simulation) -> _Prepared:
        record = test.record
        skip = simulation.skip
        if skip > record.n - 2:
            raise ValueError(
                f"`skip` = {skip} leaves fewer than 2 of the {record.n} samples of record "
                f"{record.name!r} to score; use --skip <= {max(record.n - 2, 0)}"
            )
        drive, base = driving_signal(record.input, record.dt, record.input_kind, simulation.lowpass)
        fine = None
        if simulation.hold != "zero":
            fine = reconstruct_input(drive, record.dt, simulation.substeps, simulation.hold)
        measured, norm = {}, {}
        for kind in test.outputs:
            y = np.asarray(record[kind], dtype=float)
            variance = float(np.var(y[skip:]))
            if not (variance > 0 and np.isfinite(variance)):
                raise ValueError(
                    f"`{kind}` of record {record.name!r} is constant; J (Eq. 11) is undefined"
                )
            weight = float(self.weights.get(kind, 1.0))
            measured[kind] = y
            norm[kind] = 100.0 * weight / ((y.size - skip) * variance)
        limit = 100.0 * _displacement_scale(record, test.outputs)
        return _Prepared(test, index, drive, base, fine, skip, measured, norm, limit)

    # ------------------------------------------------------------ parameters
    def parameters(self, X) -> dict:
        """Rows of ``X`` as named columns, with the fixed values."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        out = {name: np.full(X.shape[0], float(value)) for name, value in self.fixed.items()}
        out.update({name: X[:, j] for j, name in enumerate(self.free)})
        return out

    def device_of(self, named: dict, index: int) -> dict:
        """The kernel's parameters of record ``index``: the shared ones and its input offset."""
        law_names = () if self.friction is None else self.friction.parameter_names()
        out = {name: named[name] for name in DEVICE_PARAMETERS + law_names + ("k2",)}
        out["input_offset"] = named.get(self.own("input_offset", index), 0.0)
        return out

    def offset(self, named: dict, kind: str, index: int):
        return named.get(self.own(OFFSET_NAMES[kind], index))

    # ------------------------------------------------------------ simulation
    def run(self, named: dict, index: int, start=None, **options):
        """The compiled batch of record ``index`` (z, v and the circuit state stored).

        Behind a bridge (:attr:`RecordedTest.bridge`) the bridge's record
        simulation (:func:`~randvib.identification.record_bridge.run_bridge`),
        whose ``x`` is the DC output voltage and ``x0`` the storage capacitor's
        voltage at t = 0.
        """
        prep = self.prepared[index]
        n_pop = max(np.size(v) for v in named.values())
        device = self.device_of(named, index)
        if prep.test.bridge is not None:
            return _run_bridged(self, named, prep, device, n_pop, start)
        c_e, circuit = circuit_terms(self.coupling, named, prep.test.r_load)
        device["c"] = device["c"] + c_e
        matrix = parameter_matrix(device, self.friction, circuit)
        if matrix.shape[0] != n_pop:
            matrix = np.repeat(matrix, n_pop, axis=0)
        z0, v0, x0 = self.start(named, index) if start is None else start
        return run_kernel(
            matrix, self.friction, prep.drive, prep.base_input, prep.test.record.dt,
            substeps=self.substeps, hold=self.hold, fine=prep.fine, z0=z0, v0=v0, x0=x0,
            response_limit=prep.limit, **options,
        )  # fmt: skip

    def outputs(self, named: dict, index: int, run) -> dict:
        """Each fitted channel as the model gives it, without offsets: kind -> (n_pop, n)."""
        test = self.prepared[index].test
        if test.bridge is not None:
            battery = "battery" in test.bridge
            return {k: dc_channel(k, battery, test.r_load, run.states) for k in test.outputs}
        out = {}
        for kind in test.outputs:
            cz, cv, cx = output_coefficients(kind, self.coupling, named, test.r_load)
            out[kind] = (
                np.atleast_1d(cz)[:, None] * run.z
                + np.atleast_1d(cv)[:, None] * run.v
                + np.atleast_1d(cx)[:, None] * run.x
            )
        return out

    def start(self, named: dict, index: int):
        """(z0, v0, x0) per parameter set: the named values, else from the record's first samples.

        A displacement channel gives z0 (less its offset) and v0 (its
        fourth-order one-sided difference); a velocity channel v0; an
        electrical one the circuit state x0 and, through the candidate's
        quasi-static gain, v0 and z0 (z0 from the channel's running integral,
        whose mean is the displacement's, zero).
        """
        prep = self.prepared[index]
        n_pop = max(np.size(v) for v in named.values())
        given = [named.get(self.own(name, index)) for name in (*START, CIRCUIT_START)]
        z0, v0, x0 = _record_start(self, named, prep)
        values = [g if g is not None else d for g, d in zip(given, (z0, v0, x0), strict=True)]
        return tuple(np.broadcast_to(np.asarray(v, dtype=float), (n_pop,)) for v in values)

    # ------------------------------------------------------------ the cost
    def __call__(self, X):
        named = self.parameters(X)
        started = time.perf_counter()
        total = np.zeros(np.atleast_2d(X).shape[0])
        for index in range(self.count):
            total += self.record_cost(named, index)[0]
        self.seconds += time.perf_counter() - started
        self.evaluations += total.size
        return np.where(np.isfinite(total), total, np.inf)

    def unmeasured_start(self, named: dict, index: int) -> tuple:
        """The parts of record ``index``'s initial state no channel gives (and not named).

        A displacement channel gives z0 and v0; a velocity channel v0; an
        electrical channel the circuit state; what remains (z0 of a velocity
        record, z0 and v0 of a voltage record) is profiled in the search
        (:meth:`record_cost`).
        """
        kinds = self.prepared[index].test.outputs
        if "relative_displacement" in kinds:
            return ()
        out = ("z0",) if "relative_velocity" in kinds else ("z0", "v0")
        return tuple(b for b in out if self.own(b, index) not in named)

    def record_cost(self, named: dict, index: int):
        """(weighted SSE, best start shift) of record ``index`` per parameter set.

        Each channel's offset is profiled (J's minimum over a constant, in
        closed form) unless named; the unmeasured part of the initial state
        (:meth:`unmeasured_start`) is profiled too, by Gauss-Newton steps of
        least squares on the responses' sensitivities to it (secants over a
        tenth, then a hundredth, of each candidate's own displacement or
        velocity scale): one step is exact for a linear device, the second
        corrects the first's linearisation of a nonlinear one (a Duffing
        piezo's J at the truth, from rest: 15.8 from the record's guess of z0,
        0.71 after one step, 0.033 after two, as with z0 exact and v0 the
        velocity's noisy first sample; 0.0197 from the exact start). A lightly damped
        device remembers a wrong start for seconds, which would otherwise
        dominate J.
        """
        start = self.start(named, index)
        free = self.unmeasured_start(named, index)
        total = np.zeros(0)
        for relative in PROFILE_STEPS[: 1 if not free else len(PROFILE_STEPS)]:
            total, shift = self._profiled_step(named, index, start, free, relative)
            start = list(start)
            for j, base in enumerate(free):
                start[START.index(base)] = start[START.index(base)] + shift[:, j]
            start = tuple(start)
        given = self.start(named, index)
        shift = (
            np.column_stack([start[START.index(b)] - given[START.index(b)] for b in free])
            if free
            else np.zeros((total.size, 0))
        )
        return total, shift

    def _profiled_step(self, named, index, start, free, relative):
        """One Gauss-Newton step of the start's profiling from ``start`` (see record_cost)."""
        prep = self.prepared[index]
        run = self.run(named, index, start=start, max_subcycles=SEARCH_SUBCYCLES)
        errors = {
            kind: y[:, prep.skip :] - prep.measured[kind][prep.skip :]
            for kind, y in self.outputs(named, index, run).items()
        }
        slopes, steps = [], []
        for base in free:
            j = START.index(base)
            trace = run.z if j == 0 else run.v
            step = relative * np.std(np.where(np.isfinite(trace), trace, 0.0), axis=1)
            step = np.where(np.isfinite(step) & (step > 0), step, 1.0)
            moved = list(start)
            moved[j] = start[j] + step
            bridged = prep.test.bridge is not None  # x0 is then the capacitor's V_C
            if (
                j == 1
                and not bridged
                and not any(k in ELECTRICAL_OUTPUTS for k in prep.test.outputs)
            ):
                moved[2] = quasi_static_state(self.coupling, named, prep.test.r_load, moved[1])
            other = self.run(named, index, start=tuple(moved), max_subcycles=SEARCH_SUBCYCLES)
            slopes.append({
                kind: (y[:, prep.skip :] - prep.measured[kind][prep.skip :] - errors[kind])
                for kind, y in self.outputs(named, index, other).items()
            })  # fmt: skip
            steps.append(step)
        return _profiled_sse(self, named, index, errors, slopes, steps)

    def residuals(self, named: dict) -> list:
        """(record index, kind, measured less simulated) of every channel, after ``skip``."""
        out = []
        for index, prep in enumerate(self.prepared):
            run = self.run(named, index)
            for kind, model in self.outputs(named, index, run).items():
                offset = self.offset(named, kind, index)
                y = model[0] + (0.0 if offset is None else float(np.ravel(offset)[0]))
                out.append((index, kind, (prep.measured[kind] - y)[prep.skip :]))
        return out

    def channel_costs(self, named: dict) -> tuple[list, list]:
        """J, RMS error and residual verdict of each record's channels for one parameter set.

        Returns the rows of J (Eq. 11, normalised by the channel's own
        variance) and RMS error, and the rows of the residual diagnostics
        (:func:`~randvib.identification.residuals.residual_diagnostics`,
        against the record's input), with the first channel's diagnostics.
        """
        from randvib.identification.residuals import residual_diagnostics

        rows, verdicts, first = [], [], None
        for index, kind, e in self.residuals(named):
            prep = self.prepared[index]
            variance = float(np.var(prep.measured[kind][prep.skip :]))
            where = {"record": prep.test.record.name, "output": kind}
            rows.append({
                **where, "r_load": prep.test.r_load,
                "cost": float(100.0 * np.mean(e**2) / variance),
                "rms_error": float(np.sqrt(np.mean(e**2))), "samples": int(e.size),
            })  # fmt: skip
            if not np.all(np.isfinite(e)):
                continue
            diagnostics = residual_diagnostics(e, prep.test.record.input[prep.skip :])
            first = first or diagnostics
            verdicts.append({**where, "verdict": diagnostics.verdict,
                             "ljung_box_p": float(diagnostics.ljung_box_p)})  # fmt: skip
        return rows, verdicts, first


def _profiled_sse(cost, named, index, errors, slopes, steps):
    """Weighted SSE minimised over the profiled offsets and start shifts (see record_cost)."""
    prep = cost.prepared[index]
    n_pop = next(iter(errors.values())).shape[0]
    k = len(slopes)
    gram, cross = np.zeros((n_pop, k, k)), np.zeros((n_pop, k))
    total = np.zeros(n_pop)
    for kind, e in errors.items():
        offset = cost.offset(named, kind, index)
        w = prep.norm[kind]
        if offset is None:  # profiled: centre the error and the slopes
            e = e - np.mean(e, axis=1, keepdims=True)
            centred = [s[kind] - np.mean(s[kind], axis=1, keepdims=True) for s in slopes]
        else:
            e = e + np.asarray(offset)[:, None]
            centred = [s[kind] for s in slopes]
        total += w * np.sum(e**2, axis=1)
        for a in range(k):
            cross[:, a] += w * np.sum(centred[a] * e, axis=1)
            for b in range(a, k):
                gram[:, a, b] += w * np.sum(centred[a] * centred[b], axis=1)
                gram[:, b, a] = gram[:, a, b]
    if not k:
        return total, np.zeros((n_pop, 0))
    ok = np.all(np.isfinite(gram), axis=(1, 2)) & np.all(np.isfinite(cross), axis=1)
    shift = np.zeros((n_pop, k))
    for i in np.flatnonzero(ok):
        shift[i] = -np.linalg.lstsq(gram[i], cross[i], rcond=None)[0]
    total = total + np.einsum("ij,ij->i", shift, cross)
    return np.maximum(total, 0.0), shift * np.column_stack(steps)


def _displacement_scale(record: Record, outputs) -> float:
    """A bound on |z| (m) for the divergence check: the displacement's own, else a wide one."""
    if "relative_displacement" in outputs:
        return float(np.ptp(record["relative_displacement"])) or 1.0
    if "relative_velocity" in outputs:
        v = record["relative_velocity"]
        return float(np.sum(np.abs(v - np.mean(v))) * record.dt) or 1.0
    return 1e3  # nothing measures z: a bound far beyond any device (1 km)


def _record_start(cost: ExperimentCost, named: dict, prep: _Prepared):
    """(z0, v0, x0) from the record's first samples (see :meth:`ExperimentCost.start`)."""
    test, index = prep.test, prep.index
    measured = prep.measured
    dt = test.record.dt

    def less_offset(kind):
        offset = cost.offset(named, kind, index)
        y = measured[kind]
        return y - (np.mean(y) if offset is None else np.asarray(offset)[:, None])

    z0 = v0 = None
    if "relative_displacement" in measured:
        z = np.atleast_2d(less_offset("relative_displacement"))
        z0, v0 = z[:, 0], initial_velocity(z[:, :5].T, dt)
    if "relative_velocity" in measured:
        v = np.atleast_2d(less_offset("relative_velocity"))
        v0 = v[:, 0]
        if z0 is None:
            z0 = -np.mean(np.cumsum(v, axis=1) * dt, axis=1) + 0.5 * v[:, 0] * dt
    electrical = [kind for kind in test.outputs if kind in ELECTRICAL_OUTPUTS]
    x0 = None
    if test.bridge is not None:  # the DC side's first sample gives V_C; z0, v0 are profiled
        z0 = 0.0 if z0 is None else z0
        v0 = 0.0 if v0 is None else v0
        x0 = 0.0
        if electrical and "battery" not in test.bridge:
            y = np.atleast_2d(less_offset(electrical[0]))[:, 0]
            x0 = np.maximum(y if electrical[0] == "voltage" else y * test.r_load, 0.0)
        return z0, v0, x0
    if electrical:
        kind = electrical[0]
        y = np.atleast_2d(less_offset(kind))
        cz, cv, cx = output_coefficients(kind, cost.coupling, named, test.r_load)
        dynamic = is_dynamic(cost.coupling, named)
        if dynamic:
            x0 = y[:, 0] / cx
            per_velocity = cx * quasi_static_state(cost.coupling, named, test.r_load, 1.0)
        else:
            per_velocity = cv
        if v0 is None:
            v0 = y[:, 0] / per_velocity
        if z0 is None:
            z0 = -np.mean(np.cumsum(y, axis=1) * dt, axis=1) / per_velocity
    z0 = 0.0 if z0 is None else z0
    v0 = 0.0 if v0 is None else v0
    if x0 is None:
        x0 = quasi_static_state(cost.coupling, named, test.r_load, v0)
    return z0, v0, x0


class BridgeRun(NamedTuple):
    """:meth:`ExperimentCost.run` behind a bridge: ``x`` the DC output voltage, and
    ``states`` every column of :data:`~randvib.identification.record_bridge.BRIDGE_COLUMNS`."""

    sse: np.ndarray
    z: np.ndarray
    v: np.ndarray
    x: np.ndarray
    states: np.ndarray


def bridge_rows(coupling: str, named: dict, test: RecordedTest, n_pop: int):
    """((transducer, output) codes, the bridge's ``p`` per parameter set (n_pop, 9)).

    The coupling's parameters from ``named`` (alpha, r_coil, inductance or
    theta, capacitance), the bridge's known ones from ``test.bridge``
    (:meth:`randvib.models.rectifier.Rectified.kernel_parameters`'s order).
    """
    from randvib.models.rectifier import BATTERY, CAPACITOR, COIL, INDUCTIVE_COIL, PIEZO

    known = test.bridge
    battery = "battery" in known

    def column(value):
        return np.broadcast_to(np.asarray(value, dtype=float), (n_pop,))

    if coupling == "piezo":
        gain, second, inductance = named["theta"], named["capacitance"], 0.0
        code = PIEZO
    else:
        gain, second = named["alpha"], named["r_coil"]
        inductance = column(named.get("inductance", 0.0))
        code = COIL
        if np.any(inductance > 0):
            if not np.all(inductance > 0):
                raise ValueError(
                    "behind a bridge the coil's `inductance` must be > 0 for every candidate, "
                    "or fixed at 0 (`--fix inductance=0`): the two are different circuits"
                )
            code = INDUCTIVE_COIL
    rows = np.column_stack([
        column(gain), column(second), column(known["v_diode"]),
        column(known["battery"] if battery else 0.0),
        column(1.0 if battery else known["storage_capacitance"]),
        column(1.0 if battery else test.r_load), np.zeros(n_pop), np.zeros(n_pop),
        column(inductance),
    ])  # fmt: skip
    return (code, BATTERY if battery else CAPACITOR), rows


def _run_bridged(cost, named, prep, device, n_pop, start) -> BridgeRun:
    """:meth:`ExperimentCost.run` of a record behind a bridge (no c_e: the bridge's force
    is the kernel's)."""
    matrix = parameter_matrix(device, cost.friction)
    if matrix.shape[0] != n_pop:
        matrix = np.repeat(matrix, n_pop, axis=0)
    codes, rows = bridge_rows(cost.coupling, named, prep.test, n_pop)
    z0, v0, x0 = cost.start(named, prep.index) if start is None else start
    states = run_bridge(
        matrix, rows, codes, cost.friction, prep.drive, prep.base_input, prep.test.record.dt,
        substeps=cost.substeps, hold=cost.hold, fine=prep.fine, z0=z0, v0=v0, v_c0=x0,
        response_limit=prep.limit,
    )  # fmt: skip
    return BridgeRun(np.zeros(n_pop), states[..., 0], states[..., 1], states[..., 3], states)


class ExperimentError(SimulationError):
    """The weighted simulation error of an experiment, whose sum of squares is J.

    ``e = sqrt(w_k 100 / (N sigma_k^2)) (yhat_k + offset_k - y_k)`` stacked
    over records and channels (the scored samples); :attr:`blocks` are the
    slices of each (record, channel), whose noise the covariance estimates
    separately (:func:`randvib.identification.least_squares.covariance`).
    """

    def __init__(self, cost: ExperimentCost, coordinates):
        self.cost = cost
        self.coordinates = coordinates
        self.names = coordinates.names
        self.simulations = 0
        parts, self.blocks, self.channels = [], [], []
        start = 0
        for prep in cost.prepared:
            for kind in prep.test.outputs:
                y = prep.measured[kind][prep.skip :] * np.sqrt(prep.norm[kind])
                parts.append(y)
                self.blocks.append(slice(start, start + y.size))
                self.channels.append((prep.index, kind))
                start += y.size
        self.measured = np.concatenate(parts)

    def named(self, thetas) -> dict:
        thetas = np.atleast_2d(thetas)
        out = {name: np.full(thetas.shape[0], float(v)) for name, v in self.cost.fixed.items()}
        out.update({name: thetas[:, j] for j, name in enumerate(self.names)})
        return out

    def responses(self, thetas) -> np.ndarray:
        named = self.named(thetas)
        rows = np.atleast_2d(thetas).shape[0]
        parts = []
        for index, prep in enumerate(self.cost.prepared):
            run = self.cost.run(named, index, max_subcycles=SEARCH_SUBCYCLES)
            for kind, model in self.cost.outputs(named, index, run).items():
                offset = self.cost.offset(named, kind, index)
                offset = np.zeros(rows) if offset is None else offset
                y = (model + np.asarray(offset)[:, None])[:, prep.skip :]
                parts.append(y * np.sqrt(prep.norm[kind]))
        self.simulations += rows * len(self.cost.prepared)
        return np.concatenate(parts, axis=1)

    def difference_steps(self, u, step: float) -> np.ndarray:
        """Steps of ``step`` in u: a relative change ``step`` of a log-scaled parameter.

        (Not ``step |u|`` as for one displacement record: |log theta| depends
        on the unit, 16 for a capacitance in F, which made the steps 1.6 %.)
        """
        return np.where(self.coordinates.log, step, step * np.maximum(1.0, np.abs(u)))

    def covariance_jacobian(self, u) -> np.ndarray:
        """de/du for the covariance: Richardson's extrapolation of central differences
        at 2 and 1 times :data:`~randvib.identification.least_squares.COVARIANCE_STEP`.

        A coupling's parameters and the mass meet in valleys where the
        Jacobian's columns are nearly parallel (corr(m, k) = 0.9999 for a piezo
        seen through its voltage and velocity): there a difference's error
        larger than the smallest singular value sets the standard errors too
        small (measured on such a record: se(m) 2.2e-6 kg with steps of
        1e-3 |u|, 9.0e-6 kg with steps of 1e-4 to 1e-6, the profile
        likelihood agreeing with the latter); relative steps and the
        extrapolation cancel that error while keeping steps large enough for
        stick-slip (the reason for COVARIANCE_STEP).
        """
        from randvib.identification.least_squares import COVARIANCE_STEP

        fine = self.jacobian_u(u, COVARIANCE_STEP)
        coarse = self.jacobian_u(u, 2 * COVARIANCE_STEP)
        return (4.0 * fine - coarse) / 3.0
