"""Identification of the device and friction models from time histories (paper Sec. 3-4).

The model (paper Eq. 1) with one of four friction laws is fitted to a record
by minimising the normalised cost (paper Eq. 11)

    J(theta) = 100 / (N sigma_z^2) * sum_i (z_i - zhat_i(theta))^2

with self-adaptive differential evolution (:func:`randvib.identification.sade.sade`),
then a least-squares polish of the simulation error that also gives the
parameters' standard errors (:mod:`randvib.identification.least_squares`); a
model that predicts the mean scores 100 (Eq. 12), J < 5 is a good fit and
J < 1 excellent. Every generation's population is simulated in one batched,
compiled call (:mod:`randvib.identification.record_simulation`).

Measurement model (measured = true + offset): constant offsets of the input
and output channels, the input between samples (linear, cubic spline or
band-limited reconstruction), the initial state, and an optional quadratic
stiffness k2, estimated with the parameters (:func:`identify`).

Models: ``viscous`` (c (Ns/m), k (N/m), k3 (N/m^3): the paper's "no
friction") and one per registered friction law
(:data:`randvib.models.friction.FRICTION_MODELS`: ``coulomb`` Eq. 4-5, ``tanh``
Eq. 6, ``lugre`` Eq. 8-10, and any law defined elsewhere), which adds that
law's parameters with the units, search bounds and scales it declares; plus
the mass ``m`` (kg). With base excitation the mass cannot be identified
(dividing Eq. 1 by m leaves c/m, k/m, k3/m, F/m), so it must be given; with a
force input it may be left free and is identified.

By default the initial state (z0, z'0) is estimated with the parameters;
with ``initial_state='record'`` the simulation starts from the first sample
(less the output offset) and a velocity estimated from the first five
samples (fourth-order one-sided difference). LuGre's bristle state starts at
zero.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace

import numpy as np

from randvib import _display
from randvib._resources import timed
from randvib._validation import MAX_SEED, check_finite, check_int, check_nonnegative, check_positive
from randvib.identification.record_simulation import (
    EXTRA_PARAMETERS,
    HOLDS,
    SEARCH_SUBCYCLES,
    device_parameters,
    driving_signal,
    parameter_matrix,
    reconstruct_input,
    run_kernel,
)
from randvib.identification.sade import sade
from randvib.models.friction import FRICTION_MODELS, Parameter, RecordScales, RegistryView
from randvib.models.record import OUTPUT_CHANNEL, Record

#: The device's own parameters (Eq. 1; friction laws declare theirs): unit,
#: default bounds from the record's scales, log scale (k3 may be zero).
DEVICE_SPECS = {
    "m": Parameter("kg", True, lambda s: (0.1 * s.m, 10 * s.m)),
    "c": Parameter("Ns/m", False, lambda s: (1e-4 * s.c_ref, 2 * s.c_ref)),
    "k": Parameter("N/m", True, lambda s: (0.1 * s.k_ref, 10 * s.k_ref)),
    "k3": Parameter("N/m^3", False, lambda s: (0.0, 2 * s.k_ref / s.z_max**2), log=False),
}
#: Identification model name -> friction law name of the simulator (live view
#: of the registry: ``viscous`` is no friction, every law is a model).
MODELS = RegistryView(lambda law: "none" if law is None else law.name, none_key="viscous")
#: Parameters of each model, in reporting order (``m`` comes in addition).
MODEL_PARAMETERS = RegistryView(
    lambda law: ("c", "k", "k3") + (() if law is None else law.parameter_names()),
    none_key="viscous",
)


def _specs(model) -> dict[str, Parameter]:
    """Declarations of every parameter of a model, ``m`` included."""
    law = _check_model(model)
    return {**DEVICE_SPECS, **({} if law is None else law.parameter_specs())}


#: Units of the quadratic stiffness and the sensor offsets.
EXTRA_UNITS = {"k2": "N/m^2", "input_offset": "input unit", "output_offset": "m"}


def _unit(model, name):
    return EXTRA_UNITS[name] if name in EXTRA_UNITS else _specs(model)[name].unit


class _Units(Mapping):
    """Parameter name -> unit, from the device's and the laws' declarations."""

    def _table(self):
        out = {name: spec.unit for name, spec in DEVICE_SPECS.items()} | EXTRA_UNITS
        for law in FRICTION_MODELS.values():
            out.update({name: spec.unit for name, spec in law.parameter_specs().items()})
        return out

    def __getitem__(self, key):
        return self._table()[key]

    def __iter__(self):
        return iter(self._table())

    def __len__(self):
        return len(self._table())


#: Parameter name -> SI unit (live view; a law's own units win in its results).
UNITS = _Units()
#: Fewest samples per free parameter that a record must have.
SAMPLES_PER_PARAMETER = 10
#: How the simulation's initial state is obtained (SimulationSettings.initial_state).
INITIAL_STATES = ("estimate", "record")


# ---------------------------------------------------------------------- settings
@dataclass(frozen=True)
class SimulationSettings:
    """How a record is simulated and scored (:func:`identify`, :func:`predict_record`).

    Attributes
    ----------
    substeps : int
        Integration steps per sample interval (default 4).
    hold : {'linear', 'zero'}
        Interpolation of the input between samples.
    lowpass : float or None
        Zero-phase low-pass cut-off (Hz) for the driving signal (useful for a
        base displacement differentiated twice).
    skip : int
        Samples at the start left out of J.
    initial_state : {'estimate', 'record'}
        ``estimate`` (default): the initial displacement and velocity are
        estimated with the parameters (by the least-squares polish in
        :func:`identify`; by a two-parameter fit in :func:`predict_record`
        and :func:`validate`), so a correct model is never penalised for its
        start. ``record``: start from the first sample (less the output
        offset) and the velocity of :func:`initial_velocity`.
    """

    substeps: int = 4
    hold: str = "linear"
    lowpass: float | None = None
    skip: int = 0
    initial_state: str = "estimate"

    def __post_init__(self):
        object.__setattr__(self, "substeps", check_int("substeps", self.substeps, minimum=1))
        object.__setattr__(self, "skip", check_int("skip", self.skip, minimum=0))
        if self.hold not in HOLDS:
            raise ValueError(f"`hold` must be one of {', '.join(HOLDS)}; got {self.hold!r}")
        if self.initial_state not in INITIAL_STATES:
            raise ValueError(
                f"`initial_state` must be one of {', '.join(INITIAL_STATES)}; "
                f"got {self.initial_state!r}"
            )

    def to_dict(self) -> dict:
        return _fields_of(self)


@dataclass(frozen=True)
class SearchSettings:
    """SaDE settings of an identification (see :func:`randvib.identification.sade.sade`).

    Attributes
    ----------
    popsize : int
        Population size.
    maxiter : int
        Most generations.
    seed : int, numpy.random.Generator or None
        Random seed or generator of the search.
    tol : float
        Stop when the population's spread of J falls below this.
    patience : int or None
        Stop after this many generations without improvement (None: never).
    polish : bool
        Finish with the least-squares polish of the simulation error
        (:mod:`randvib.identification.least_squares`), which also estimates
        the initial state and gives the parameters' uncertainty.
    polish_maxfev : int
        Most residual evaluations of the polish (each Jacobian costs 2 d
        more simulations, run in one batch).
    search_samples : int or None
        Search on the record's first ``search_samples`` samples only (None:
        all); the polish always fits the whole record. The search only has
        to find the optimum's basin, so a window of a few periods of the
        slowest dynamics is enough and makes it proportionally cheaper.
    """

    popsize: int = 30
    maxiter: int = 60
    seed: int | np.random.Generator | None = 0
    tol: float = 1e-6
    patience: int | None = 15
    polish: bool = True
    polish_maxfev: int = 40
    search_samples: int | None = None

    def __post_init__(self):
        if isinstance(self.seed, int | np.integer) and not isinstance(self.seed, bool):
            check_int("seed", self.seed, 0, MAX_SEED)

    def to_dict(self) -> dict:
        return _fields_of(self)


#: SearchSettings fields that are not SaDE's.
_NOT_SADE = ("polish", "polish_maxfev", "search_samples")


def _fields_of(settings) -> dict:
    # not dataclasses.asdict: that deep-copies, and a seed Generator must be
    # the caller's own (it advances)
    return {f.name: getattr(settings, f.name) for f in fields(settings)}


def _settings(caller, options: dict, **given):
    """The settings objects ``given`` (name -> object or None), with fields named
    as keywords in ``options`` replacing theirs: ``identify(..., popsize=20)``
    is ``identify(..., search=SearchSettings(popsize=20))``."""
    options = dict(options)
    out = []
    for name, value in given.items():
        cls = _SETTINGS[name]
        if value is not None and not isinstance(value, cls):
            raise ValueError(f"`{name}` must be a {cls.__name__}, got {type(value).__name__}")
        mine = {f.name: options.pop(f.name) for f in fields(cls) if f.name in options}
        out.append(replace(value if value is not None else cls(), **mine))
    if options:
        raise TypeError(f"{caller}() got unexpected keyword argument(s) {', '.join(options)}")
    return out


_SETTINGS = {"search": SearchSettings, "simulation": SimulationSettings}


# ------------------------------------------------------------------- cost (Eq. 11)
def initial_velocity(z, dt):
    """Velocity at the first sample from the first five (fourth-order one-sided, m/s)."""
    return (-25 * z[0] + 48 * z[1] - 36 * z[2] + 16 * z[3] - 3 * z[4]) / (12 * dt)


def normalised_cost(z_measured, z_model):
    """J of paper Eq. 11 for one or many simulated responses (last axis: time)."""
    z_measured = np.asarray(z_measured, dtype=float)
    err = np.mean((np.asarray(z_model) - z_measured) ** 2, axis=-1)
    return 100.0 * err / np.var(z_measured)


class CostFunction:
    """Batched J(theta) (Eq. 11) of one model on one record.

    Calling it with an array ``X`` of shape (n, d), columns in the order of
    :attr:`free`, returns the n costs; every row is simulated in one
    parallel compiled call. Diverged candidates cost ``inf``.

    With ``profile_offset`` the output offset is not a column of ``X``:
    each candidate is scored with its best constant output offset (J
    minimised over it in closed form), as the search does when the offset
    is estimated. The simulation starts from ``z0`` (default: the first
    sample less the output offset, fixed or guessed as the record's mean)
    and ``v0`` (default: :func:`initial_velocity`).
    """

    def __init__(
        self,
        record: Record,
        model: str,
        *,
        fixed: dict,
        free,
        substeps: int = 4,
        hold: str = "linear",
        lowpass: float | None = None,
        skip: int = 0,
        initial_state: str = "record",
        profile_offset: bool = False,
        z0: float | None = None,
        v0: float | None = None,
    ):
        self.record = record
        self.model = model
        self.friction = _check_model(model)
        self.fixed = dict(fixed)
        self.free = tuple(free)
        self.substeps = substeps
        self.hold = hold
        self.skip = skip
        self.profile_offset = bool(profile_offset)
        self.drive, self.base_input = driving_signal(
            record.input, record.dt, record.input_kind, lowpass
        )
        if skip > record.n - 2:
            raise ValueError(
                f"`skip` = {skip} leaves fewer than 2 of the {record.n} samples of record "
                f"{record.name!r} to score; use --skip <= {max(record.n - 2, 0)}"
            )
        self.fine = (
            None if hold == "zero" else reconstruct_input(self.drive, record.dt, substeps, hold)
        )
        scored = record.z[skip:]
        self.variance = float(np.var(scored))
        if self.variance == 0 or np.ptp(scored) == 0 or not np.isfinite(self.variance):
            raise ValueError(
                f"`{OUTPUT_CHANNEL}` of record {record.name!r} is constant; J (Eq. 11) is undefined"
            )
        self.n_scored = scored.size
        offset = self.fixed.get(
            "output_offset", float(np.mean(record.z)) if profile_offset else 0.0
        )
        self.z0 = float(record.z[0] - offset) if z0 is None else float(z0)
        self.v0 = float(initial_velocity(record.z, record.dt)) if v0 is None else float(v0)
        self.limit = 100.0 * float(np.max(np.abs(record.z - offset)))
        self.evaluations = 0
        self.seconds = 0.0

    def parameters(self, X) -> dict:
        X = np.atleast_2d(np.asarray(X, dtype=float))
        out = {name: X[:, j] for j, name in enumerate(self.free)}
        for name, value in self.fixed.items():
            out[name] = np.full(X.shape[0], float(value))
        return out

    def run(self, matrix, **options):
        """The compiled batch on this record's input, start and sub-steps."""
        options.setdefault("z0", self.z0)
        options.setdefault("v0", self.v0)
        return run_kernel(
            matrix,
            self.friction,
            self.drive,
            self.base_input,
            self.record.dt,
            substeps=self.substeps,
            hold=self.hold,
            response_limit=self.limit,
            fine=self.fine,
            **options,
        )

    _run = run

    def __call__(self, X):
        params = self.parameters(X)
        matrix = parameter_matrix(params, self.friction)
        start = time.perf_counter()
        sse, _, _ = self.run(
            matrix,
            reference=self.record.z,
            skip=self.skip,
            store=False,
            max_subcycles=SEARCH_SUBCYCLES,
            profile_offset=self.profile_offset,
        )
        self.seconds += time.perf_counter() - start
        self.evaluations += matrix.shape[0]
        return 100.0 * sse / (self.n_scored * self.variance)

    def simulate(self, parameters: dict, electrical=None, z0=None, v0=None):
        """Responses (z, v) of one parameter set, c raised by c_e when a circuit is given."""
        params = {k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in parameters.items()}
        if electrical is not None:
            params["c"] = params["c"] + electrical.electrical_damping
        matrix = parameter_matrix(params, self.friction)
        start = {k: v for k, v in (("z0", z0), ("v0", v0)) if v is not None}
        _, z, v = self.run(matrix, **start)
        return z[0], v[0]


# ------------------------------------------------------------------------ bounds
def _scales(record: Record, m: float | None):
    """Characteristic frequency, displacement, velocity and force of a record."""
    z = record.z - np.mean(record.z)
    v = np.gradient(z, record.dt)
    omega = float(np.sqrt(np.mean(v**2) / np.mean(z**2)))  # zero-crossing frequency of z
    drive, base = driving_signal(record.input, record.dt, record.input_kind)
    if m is None:
        # force input, free mass: equation-error least squares m z'' + c z' + k z = u
        acc = np.gradient(v, record.dt)
        a = np.column_stack([acc, v, z, np.ones_like(z)])
        coef = np.linalg.lstsq(a, drive, rcond=None)[0]
        m_ref = float(coef[0]) if coef[0] > 0 else float(np.std(drive) / np.std(acc))
    else:
        m_ref = float(m)
    force = float(np.sqrt(np.mean(drive**2))) * (m_ref if base else 1.0)
    return omega, float(np.max(np.abs(z))), float(np.sqrt(np.mean(v**2))), force, m_ref


def default_bounds(record: Record, model: str, m: float | None = None) -> dict:
    """Search bounds derived from the record's own scales, as each parameter declares.

    With the characteristic angular frequency ``w = rms(z')/rms(z)``, the
    largest displacement ``z_max``, the RMS velocity ``v_rms``, the RMS
    external force ``F`` (``m rms(y'')`` or ``rms(u)``) and the mass ``m``
    (given, or an equation-error least-squares estimate when free):

    ======  ==========================================  =====
    m       [0.1, 10] x m_ls (free mass only)           log
    c       2 m w x [1e-4, 2] (damping ratio)           log
    k       m w^2 x [0.1, 10]                           log
    k3      [0, 2 m w^2 / z_max^2]                      linear
    fc, fs  F x [1e-4, 1]                               log
    beta    [1, 1e10] / v_rms                           log
    sigma0  m w^2 x [1e-3, 10]                          log
    sigma1  2 m w x [1e-4, 10]                          log
    vs      v_rms x [1e-4, 10]                          log
    ======  ==========================================  =====

    The device's rows are :data:`DEVICE_SPECS`, the friction rows the
    law's own :func:`~randvib.models.friction.parameter` declarations (the table
    above is what the built-in laws declare). These cover the paper's
    Table 2 for its records; override any of them with ``bounds=`` in
    :func:`identify` (``--bounds NAME=LO:HI``). A parameter declared without
    default bounds must be fixed or bounded there.
    """
    specs = _specs(model)
    omega, z_max, v_rms, force, m_ref = _scales(record, m)
    scales = RecordScales(m=m_ref, omega=omega, z_max=z_max, v_rms=v_rms, force=force)
    names = MODEL_PARAMETERS[model] + (("m",) if m is None else ())
    return {
        name: tuple(float(x) for x in specs[name].search(scales))
        for name in names
        if specs[name].search is not None
    }


def _check_model(model):
    """The friction law class of an identification model (``viscous``: None)."""
    if model not in MODELS:
        raise ValueError(f"`model` must be one of {', '.join(MODELS)}; got {model!r}")
    return None if model == "viscous" else FRICTION_MODELS[model]


def model_of(friction_name: str) -> str:
    """Identification model of a friction law name (``none`` -> ``viscous``)."""
    return "viscous" if friction_name == "none" else friction_name


# ---------------------------------------------------------------------- identify
@dataclass
class IdentificationResult:
    """Identified parameters of one model on one record.

    Attributes
    ----------
    model : str
        ``viscous``, ``coulomb``, ``tanh`` or ``lugre``.
    parameters : dict
        Every parameter (SI units), ``m`` included, fixed ones too.
    free : tuple of str
        The identified ones.
    cost : float
        J (Eq. 11) on the training record.
    bounds : dict
        Search bounds of the free parameters.
    nfev, generations : int
        Simulations spent and SaDE generations run.
    elapsed : float
        Wall time (s).
    simulations_per_second : float
        Simulation throughput of the batched kernel.
    message : str
        Why the search stopped.
    history : dict
        Best cost and simulations spent per generation.
    record : str
        Name of the training record.
    settings : dict
        Simulation settings (substeps, hold, lowpass, skip, seed, ...).
    uncertainty : Uncertainty or None
        Standard errors, 95 % intervals and correlations of the estimated
        quantities (:class:`randvib.identification.least_squares.Uncertainty`);
        None without the polish.
    initial_state : dict
        ``z0`` (m) and ``v0`` (m/s) the simulation starts from.
    notes : tuple of str
        Why a measurement-model parameter was not estimated.
    """

    model: str
    parameters: dict
    free: tuple
    cost: float
    bounds: dict
    nfev: int
    generations: int
    elapsed: float
    simulations_per_second: float
    message: str
    history: dict = field(default_factory=dict)
    record: str = ""
    settings: dict = field(default_factory=dict)
    uncertainty: object = None
    initial_state: dict = field(default_factory=dict)
    notes: tuple = ()

    @property
    def standard_errors(self) -> dict:
        """Standard error of each estimated parameter (its unit); empty without the polish."""
        if self.uncertainty is None:
            return {}
        se = self.uncertainty.standard_error
        return {n: se[n] for n in self.parameters if n in se}

    @property
    def confidence_intervals(self) -> dict:
        """95 % confidence interval of each estimated parameter."""
        if self.uncertainty is None:
            return {}
        return {n: self.uncertainty.interval[n] for n in self.standard_errors}

    def to_dict(self) -> dict:
        """JSON-ready summary."""
        return {
            "model": self.model,
            "parameters": {k: float(v) for k, v in self.parameters.items()},
            "units": {k: _unit(self.model, k) for k in self.parameters},
            "cost": float(self.cost),
            "free": list(self.free),
            "bounds": {k: [float(a), float(b)] for k, (a, b) in self.bounds.items()},
            "record": self.record,
            "simulations": int(self.nfev),
            "generations": int(self.generations),
            "elapsed_s": float(self.elapsed),
            "simulations_per_second": float(self.simulations_per_second),
            "message": self.message,
            "settings": self.settings,
            "initial_state": dict(self.initial_state),
            "notes": list(self.notes),
            **(
                {}
                if self.uncertainty is None
                else {"uncertainty_of": "all estimated quantities", **self.uncertainty.to_dict()}
            ),
        }

    def to_frame(self):
        """The parameters as a :class:`pandas.DataFrame`, one row per parameter.

        Columns ``value``, ``unit``, ``free`` (identified, not fixed) and the
        search bounds ``lower``, ``upper`` (NaN for a fixed parameter); the
        cost and the search's summary are in :meth:`to_dict`.
        """
        pd = _display.pandas()
        specs = _specs(self.model)
        rows = {
            name: {
                "value": float(value),
                "unit": specs[name].unit,
                "free": name in self.free,
                "lower": float(self.bounds[name][0]) if name in self.bounds else np.nan,
                "upper": float(self.bounds[name][1]) if name in self.bounds else np.nan,
            }
            for name, value in self.parameters.items()
        }
        return pd.DataFrame.from_dict(rows, orient="index").rename_axis("parameter")

    def _rows(self):
        specs = _specs(self.model)
        rows = [("cost J (Eq. 11)", _display.number(self.cost, 4), "")]
        for name, value in self.parameters.items():
            fixed = "" if name in self.free else " (fixed)"
            rows.append((name + fixed, _display.number(value), specs[name].unit))
        return rows

    def _search_line(self) -> str:
        record = f" on {self.record!r}" if self.record else ""
        return (
            f"{self.model}{record}: {self.nfev} simulations, {self.generations} generations, "
            f"{self.elapsed:.3g} s; {self.message}"
        )

    def __repr__(self) -> str:
        # compact: the per-generation history stays in .history, not on the screen
        values = ", ".join(f"{name}={_display.number(v)}" for name, v in self.parameters.items())
        return (
            f"IdentificationResult(model={self.model!r}, cost={_display.number(self.cost, 4)}, "
            f"{values}; {self.nfev} simulations, {self.generations} generations)"
        )

    def _repr_html_(self) -> str:
        return _display.html_table("Identification", self._rows(), self._search_line())

    def predict(self, record: Record, electrical=None) -> Prediction:
        """Simulate ``record`` with these parameters (see :func:`predict_record`)."""
        return predict_record(
            self.parameters,
            self.model,
            record,
            electrical=electrical,
            **_sim_settings(self.settings),
        )

    def harvester(self, electrical=None):
        """The identified device as a :class:`randvib.Harvester` (c as c_m)."""
        from randvib.models.harvester import Harvester

        p = self.parameters
        if p.get("k2", 0.0) != 0.0:
            raise ValueError(
                f"the identified k2 = {p['k2']:.6g} N/m^2 has no place in a Harvester "
                "(restoring force k z + k3 z^3); identify without --quadratic"
            )
        law = _check_model(self.model)
        friction = None if law is None else law(**{n: p[n] for n in law.parameter_names()})
        if electrical is None:
            return Harvester(m=p["m"], c_m=p["c"], c_e=0.0, k=p["k"], k3=p["k3"], friction=friction)
        return Harvester.from_electrical(
            m=p["m"], c_m=p["c"], k=p["k"], k3=p["k3"], alpha=electrical.alpha,
            r_load=electrical.r_load, r_coil=electrical.r_coil, friction=friction,
        )  # fmt: skip


def _sim_settings(settings):
    names = ("substeps", "hold", "lowpass", "skip", "initial_state")
    return {k: settings[k] for k in names if k in settings}


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
    record: Record,
    model: str,
    *,
    m: float | None = None,
    fixed: dict | None = None,
    bounds: dict | None = None,
    init=None,
    quadratic: bool = False,
    search: SearchSettings | None = None,
    simulation: SimulationSettings | None = None,
    progress: bool = False,
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

    Parameters
    ----------
    record : Record
        Training record.
    model : {'viscous', 'coulomb', 'tanh', 'lugre'}
        Friction model (``viscous`` is the paper's no-friction model), or
        any other registered law.
    m : float, optional
        Mass (kg); required with base excitation, identified when omitted
        with a force input.
    fixed : dict, optional
        Parameters held at given values, e.g. ``{"k3": 0.0}`` for a linear
        spring, ``{"input_offset": 0.0, "output_offset": 0.0}`` for sensors
        known to have none.
    bounds : dict, optional
        ``name -> (lower, upper)`` overriding :func:`default_bounds` (search box).
    init : dict or Harvester, optional
        A starting guess ``name -> value`` (or a device, a preset included,
        with c = c_m + c_e) placed in the initial population.
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
        Record simulation settings (substeps 4, linear hold, no low-pass,
        skip 0, initial state estimated).
    progress : bool
        Progress bar.
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
    _check_model(model)
    if not isinstance(record, Record):
        raise ValueError(f"`record` must be a randvib Record, got {type(record).__name__}")
    search, simulation = _settings("identify", options, search=search, simulation=simulation)
    fixed = _resolve_fixed(model, fixed, m, record)
    fixed, reported, notes = _measurement_model(record, fixed, bool(quadratic))
    space = _search_space(record, model, fixed, bounds, simulation.skip)
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
        callback=_named_callback(callback, space.free),
        progress=progress,
        **{k: v for k, v in search.to_dict().items() if k not in _NOT_SADE},
    )
    cost.evaluations, cost.seconds = searched.evaluations, searched.seconds
    found = dict(zip(space.free, map(float, res.x), strict=True))
    refined = _polish(cost, space, found, simulation, search) if search.polish else None
    elapsed = time.perf_counter() - start
    return _identification_result(
        cost, space, res, refined, elapsed, search, simulation, reported, notes
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


@dataclass(frozen=True)
class _SearchSpace:
    """What SaDE searches: the free parameters, their bounds, which are log-scaled."""

    free: tuple
    box: dict
    log: list


def _search_space(record, model, fixed, bounds, skip) -> _SearchSpace:
    """Free parameters and their bounds (declared defaults, then the user's)."""
    candidates = MODEL_PARAMETERS[model] + ("m", "k2", "input_offset")
    free = tuple(n for n in candidates if n not in fixed)
    needed = max(20, SAMPLES_PER_PARAMETER * (len(free) + 3)) + skip
    if record.n < needed:
        raise ValueError(
            f"record {record.name!r} has {record.n} samples; the {model} model with "
            f"{len(free)} free parameters needs at least {needed}"
        )
    if np.ptp(record.z[skip:]) == 0:
        raise ValueError(
            f"`{OUTPUT_CHANNEL}` of record {record.name!r} is constant; J (Eq. 11) is undefined"
        )
    box = default_bounds(record, model, fixed.get("m"))
    box.update(_extra_bounds(record, fixed.get("m")))
    box.update(_user_bounds(model, bounds))
    unbounded = [name for name in free if name not in box]
    if unbounded:
        raise ValueError(
            f"parameter(s) {unbounded} of model {model!r} declare no default search bounds; "
            "fix them (`--fix NAME=VALUE`) or bound them (`--bounds NAME=LO:HI`)"
        )
    specs = _specs(model)
    for name in free:
        lo, hi = box[name]
        positive = name in specs and specs[name].positive  # k2, offsets: any sign
        if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi and (lo > 0 or not positive)):
            raise ValueError(
                f"the search bounds of `{name}` are ({lo!r}, {hi!r}), which model {model!r} "
                f"cannot search: the record {record.name!r} (its sample rate and amplitudes) "
                f"is outside the range of its default bounds; give `--bounds {name}=LO:HI`"
            )
    return _SearchSpace(
        free=free,
        box={name: box[name] for name in free},
        log=[name in specs and specs[name].log and box[name][0] > 0 for name in free],
    )


def _extra_bounds(record, m) -> dict:
    """Search boxes of k2 and the input offset from the record's scales.

    k2 within +-2 m w^2 / z_max (its force at z_max at most twice the
    linear spring's); the input offset within the measured input's mean
    +- half its standard deviation (the true input of a shaker test has no
    mean, so the measured mean is the offset up to the record's finite
    length).
    """
    omega, z_max, _, _, m_ref = _scales(record, m)
    drive, _ = driving_signal(record.input, record.dt, record.input_kind)
    k2 = 2 * m_ref * omega**2 / z_max
    mean, half = float(np.mean(drive)), 0.5 * float(np.std(drive))
    return {"k2": (-k2, k2), "input_offset": (mean - half, mean + half)}


def _user_bounds(model, bounds) -> dict:
    allowed = MODEL_PARAMETERS[model] + ("m",)
    out = {}
    for name, pair in (bounds or {}).items():
        if name not in allowed:
            raise ValueError(
                f"`--bounds {name}`: unknown parameter for model {model!r}; allowed: "
                f"{', '.join(allowed)}"
            )
        lo, hi = (check_parameter(model, name, x, f"--bounds {name}") for x in pair)
        if lo > hi:
            raise ValueError(f"`--bounds {name}`: lower {lo!r} > upper {hi!r}")
        out[name] = (lo, hi)
    return out


def check_parameter(model: str, name: str, value, label: str | None = None) -> float:
    """``value`` of parameter ``name`` of ``model`` as a float, if the model allows it.

    The rules are the declarations' (:data:`DEVICE_SPECS` and the friction
    law's ``parameter(...)`` fields): finite, and > 0 for a positive
    parameter (m, k, Fc, ...), >= 0 for the others (c, k3, ...). They hold
    for fixed values, search bounds and validated parameters alike.
    """
    label = label or name
    if name in EXTRA_PARAMETERS:  # k2 and the sensor offsets: any finite value
        return float(check_finite(label, value))
    spec = _specs(model).get(name)
    if spec is None:
        raise ValueError(
            f"`{label}`: unknown parameter for model {model!r}; allowed: "
            f"{', '.join(('m',) + MODEL_PARAMETERS[model])}"
        )
    check = check_positive if spec.positive else check_nonnegative
    return float(check(label, value, spec.unit))


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


def _polish(cost: CostFunction, space, found: dict, simulation, search) -> _Polished:
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
    problem = SimulationError(cost, _coordinates(cost, space, names))
    theta, residuals, unc, message = polish(
        problem, np.array(theta0), max_nfev=search.polish_maxfev
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


def _coordinates(cost, space, names):
    """Scales and bounds of the least-squares vector (the search box for model parameters)."""
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
            # offsets and k2 are only searched in a box; the polish is free
            bounded = name not in EXTRA_PARAMETERS
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


#: At most this many corners of the search box are probed before a search.
PROBE_CORNERS = 64


def _probe_points(space: _SearchSpace) -> np.ndarray:
    """The box's corners (a seeded sample of 64 of them in more than 6 dimensions)
    and its centre (arithmetic, and geometric on log-scaled axes), one per row."""
    lo = np.array([space.box[n][0] for n in space.free], dtype=float)
    hi = np.array([space.box[n][1] for n in space.free], dtype=float)
    d = lo.size
    if 2**d <= PROBE_CORNERS:
        bits = (np.arange(2**d)[:, None] >> np.arange(d)) & 1
    else:
        bits = np.random.default_rng(0).integers(0, 2, size=(PROBE_CORNERS, d))
    centre = lo / 2 + hi / 2  # (lo + hi) / 2 overflows at 1e308
    geometric = np.where(space.log, np.sqrt(np.abs(lo)) * np.sqrt(np.abs(hi)), centre)
    return np.vstack([np.where(bits == 1, hi, lo), centre, geometric])


def _refuse_unsimulable(cost: CostFunction, space: _SearchSpace) -> float:
    """Refuse before searching when the model cannot simulate the record anywhere probed.

    A fixed value or bound at which the model diverges or overflows (``--fix
    k3=1e308``, ``--bounds k=1e300:1e308``) would make every candidate of the
    search diverge; one batched simulation at the box's corners and centre
    finds it first. Some probes diverging is normal (wide default bounds);
    all of them diverging is refused. Returns the record sub-steps per second
    the probes ran at (after one that compiles the simulation), for the
    duration estimate.
    """
    probes = _probe_points(space)
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


def _initial_guess(init, space: _SearchSpace):
    """The user's guess as one row of the initial population (None without one)."""
    if init is not None and not isinstance(init, dict) or isinstance(init, dict) and "c_m" in init:
        init = device_parameters(init)[0]  # a Harvester (or its parameters()) as the guess
    if not init:
        return None
    return [[np.clip(init.get(n, np.mean(space.box[n])), *space.box[n]) for n in space.free]]


def _named_callback(callback, free):
    """SaDE's ``callback(gen, x, f)`` as the user's ``callback(gen, {name: value}, f)``."""
    if callback is None:
        return None

    def named(gen, x, f):
        return callback(gen, dict(zip(free, map(float, x), strict=True)), f)

    return named


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
        pred = predict_record(parameters, cost.model, cost.record, simulation=simulation)
        j, start = pred.cost, pred.initial_state
    order = ("m",) + MODEL_PARAMETERS[cost.model] + reported
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
    )


# ---------------------------------------------------------- predict_record/validate
@dataclass(frozen=True, eq=False)
class Prediction:
    """Simulated response of a parameter set to a record.

    Attributes
    ----------
    record : Record
    z, v : ndarray
        Simulated relative displacement as the output sensor reads it
        (true + ``output_offset``, m) and velocity (m/s).
    cost : float
        J (Eq. 11) against the record.
    rms_error : float
        RMS of z - zhat (units of z).
    voltage : ndarray or None
        Simulated load voltage (V) when a circuit was given:
        ``V = alpha z' R_L / (R_L + R_C)``.
    initial_state : dict
        ``z0`` (m), ``v0`` (m/s) the simulation started from (estimated by
        default, see :class:`SimulationSettings`).
    """

    record: Record
    z: np.ndarray
    v: np.ndarray
    cost: float
    rms_error: float
    voltage: np.ndarray | None = None
    initial_state: dict = field(default_factory=dict)


def _device_and_model(parameters, model, record):
    """Accept ``(device, record)`` as well as ``(parameters, model, record)``.

    A device is a :class:`~randvib.models.harvester.Harvester` (a preset included)
    or its ``parameters()`` dict; its friction law names the model and its
    circuit, if any, gives the voltage. Returns (parameters, model, record,
    circuit).
    """
    from randvib.models.harvester import Harvester

    if record is None and not isinstance(model, str):
        model, record = None, model
    circuit = parameters.electrical if isinstance(parameters, Harvester) else None
    if isinstance(parameters, Harvester) or isinstance(parameters, dict) and "c_m" in parameters:
        friction = None if model is None else MODELS.get(model, model)
        parameters, friction = device_parameters(parameters, friction)
        model = model_of(friction)
    elif model is None:
        raise ValueError("`model` is required with a parameter dict; or pass a randvib.Harvester")
    return parameters, model, record, circuit


def _check_parameters(parameters, model):
    _check_model(model)
    names = ("m",) + MODEL_PARAMETERS[model]
    missing = [n for n in names if n not in parameters]
    if missing:
        raise ValueError(
            f"parameters for model {model!r} lack {missing}; needed: {', '.join(names)}"
        )
    names += tuple(n for n in EXTRA_PARAMETERS if n in parameters)
    return {n: check_parameter(model, n, parameters[n]) for n in names}


def _start_estimate(cost: CostFunction):
    """(z0, v0): the initial state that best explains the record, all else given.

    A two-parameter least-squares fit of the simulation error (for a correct
    model the error is then the noise alone, whatever the record's start).
    """
    from randvib.identification.least_squares import (
        INITIAL_STATE,
        Coordinates,
        SimulationError,
        polish,
    )

    z_scale = float(np.std(cost.record.z)) or 1.0
    v_scale = float(np.std(np.diff(cost.record.z))) / cost.record.dt or 1.0
    coords = Coordinates(
        names=INITIAL_STATE,
        log=np.zeros(2, bool),
        scale=np.array([z_scale, v_scale]),
        lower=np.full(2, -np.inf),
        upper=np.full(2, np.inf),
    )
    theta, _, _, _ = polish(SimulationError(cost, coords), np.array([cost.z0, cost.v0]))
    return float(theta[0]), float(theta[1])


def predict_record(
    parameters,
    model: str | None = None,
    record: Record | None = None,
    *,
    electrical=None,
    simulation: SimulationSettings | None = None,
    **options,
) -> Prediction:
    """Simulate a record with given parameters and score it with J (Eq. 11).

    Called as ``predict_record(parameters, model, record)`` with identified
    parameters (total damping ``c``), or as ``predict_record(device, record)``
    with a :class:`~randvib.models.harvester.Harvester` (a preset included)
    or its ``parameters()`` dict: the device's law names the model,
    c = c_m + c_e, and its circuit, if any, gives the load voltage. (The
    analytic power prediction is :func:`randvib.predict`.)

    Parameters
    ----------
    parameters : dict or Harvester
        ``m`` (kg), ``c`` (Ns/m), ``k`` (N/m), ``k3`` (N/m^3) and the model's
        friction parameters; or a device.
    model : str, optional
        Identification model (see :data:`MODELS`); only with a parameter dict.
    record : Record
    electrical : ElectricalCoupling, optional
        Adds the coil's damping c_e = alpha^2/(R_L + R_C) (Eq. 3) to the
        identified c and gives the load voltage.
    simulation : SimulationSettings, optional
        Its fields may also be given as keywords (``substeps=``, ``hold=``,
        ``lowpass=``, ``skip=``), which override it.

    Returns
    -------
    Prediction
    """
    (simulation,) = _settings("predict_record", options, simulation=simulation)
    parameters, model, record, circuit = _device_and_model(parameters, model, record)
    params = _check_parameters(parameters, model)
    if electrical is not None:
        params["c"] += electrical.electrical_damping
    cost = CostFunction(record, model, fixed=params, free=(), **simulation.to_dict())
    start = {"z0": cost.z0, "v0": cost.v0}
    if simulation.initial_state == "estimate":
        start["z0"], start["v0"] = _start_estimate(cost)
    z, v = cost.simulate(params, **start)
    z = z + params.get("output_offset", 0.0)  # what the output sensor reads
    skip = simulation.skip
    if np.all(np.isfinite(z)):
        j = float(normalised_cost(record.z[skip:], z[skip:]))
        rms = float(np.sqrt(np.mean((record.z[skip:] - z[skip:]) ** 2)))
    else:
        j = rms = float("inf")
    voltage = None
    circuit = electrical if electrical is not None else circuit
    if circuit is not None:
        voltage = circuit.alpha * v * circuit.load_fraction
    return Prediction(
        record=record, z=z, v=v, cost=j, rms_error=rms, voltage=voltage, initial_state=start
    )


def predict(*args, **kwargs) -> Prediction:
    """Deprecated name of :func:`predict_record` (``randvib.predict`` is the analytic power)."""
    warnings.warn(
        "randvib.identification.fitting.predict is deprecated; use predict_record "
        "(randvib.predict is the analytic power prediction)",
        DeprecationWarning,
        stacklevel=2,
    )
    return predict_record(*args, **kwargs)


@dataclass(frozen=True)
class ValidationRow:
    record: str
    model: str
    cost: float
    rms_error: float
    samples: int


def validate(parameters, model, records=None, **settings) -> list[ValidationRow]:
    """J (Eq. 11) and RMS error of given parameters on each of several records.

    Called as ``validate(parameters, model, records)`` or
    ``validate(device, records)`` with a Harvester; ``settings`` are those of
    :func:`predict_record` (``simulation=`` or its fields as keywords).
    """
    if records is None:
        model, records = None, model
    parameters, model, _, _ = _device_and_model(parameters, model, records)
    rows = []
    for record in records:
        pred = predict_record(parameters, model, record, **settings)
        rows.append(ValidationRow(record.name, model, pred.cost, pred.rms_error, record.n))
    return rows
