"""The outcome of an identification: :class:`IdentificationResult`, the device it found."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from randvib import _display, formatting
from randvib.identification.circuit import (
    BRIDGE_NOTE,
    bridge_from_parameters,
    coupling_from_parameters,
    saved_rectifier,
)
from randvib.identification.identifiability import Identifiability
from randvib.identification.models import MeasurementModel, device_from_parameters, unit_of
from randvib.identification.prediction import Prediction, predict_record
from randvib.identification.residuals import MAX_LAG, ResidualDiagnostics, residual_diagnostics
from randvib.identification.settings import SimulationSettings
from randvib.models.harvester import Harvester
from randvib.models.record import Record
from randvib.quantities import unit

#: Distance from a search bound, as a share of the interval's width, within
#: which a free parameter counts as on it (the polish's bounded least squares
#: stops exactly on a bound; 1e-6 is far below any meaningful resolution of
#: the fit and far above float64 rounding).
BOUND_TOLERANCE = 1e-6

#: |correlation| of two estimates from which they count as not identifiable apart:
#: the variance of either, the other held, is 1 - r^2 = 0.2 % of its own (a factor
#: 22 on the standard error): the record determines one combination of the two.
UNIDENTIFIABLE_CORRELATION = 0.999


@dataclass
class IdentificationResult:
    """Identified parameters of one model on one record.

    The parameters are given back as the identified device,
    :meth:`harvester` (a :class:`~randvib.models.harvester.Harvester`, its
    damping c as c_m), and its :attr:`measurement` model (the offsets and
    k2), which :func:`~randvib.identification.prediction.predict_record` and
    :func:`~randvib.identification.prediction.validate` take; :meth:`predict`
    does so with the fit's :attr:`simulation` settings.

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
        Why a measurement-model parameter was not estimated, how the input
        is reconstructed between samples.
    input_kind : str
        What the training record's input channel holds
        (``base_acceleration``, ``base_displacement`` or ``force``): the unit
        of ``input_offset`` (:meth:`unit`); empty when not known.
    residuals : ResidualDiagnostics or None
        Whiteness of the training residual and its independence of the input
        (:func:`~randvib.identification.residuals.residual_diagnostics`), with
        the verdict ``white`` or ``structured``; None when not computed (of
        the first record's first channel when there are several).
    coupling : str
        The coupling identified with the mechanics (``resistive``,
        ``inductive``, ``piezo``); empty when c is the total damping.
    outputs : tuple of str
        The channels fitted (``relative_displacement`` unless told).
    r_loads : tuple of float
        Each record's known load R_L (ohm), with a coupling.
    rectifier : dict
        The known full-wave diode bridge the coupling's output went through
        (``v_diode``, V, and ``storage_capacitance``, F, or ``battery``, V;
        :func:`randvib.identify`'s ``rectifier``); empty for none. Saved as
        ``"rectifier": {"kind": "bridge", ...}``; :meth:`harvester` wires the
        coupling through it.
    records : tuple of str
        The records' names, in the order of their ``[i]`` parameters.
    weights : dict
        The channels' weights in J (absent: 1).
    channel_costs : list of dict
        J (Eq. 11, each channel normalised by its own variance) and the RMS
        error of each record's channels: ``record``, ``output``, ``r_load``,
        ``cost``, ``rms_error``, ``samples``.
    channel_residuals : list of dict
        Each record's channels' residual verdicts (``record``, ``output``,
        ``verdict``, ``ljung_box_p``).
    identifiability : Identifiability or None
        What the records fix and why, and the check at the estimate
        (:mod:`randvib.identification.identifiability`).
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
    input_kind: str = ""
    residuals: ResidualDiagnostics | None = None
    coupling: str = ""
    outputs: tuple = ("relative_displacement",)
    r_loads: tuple = ()
    rectifier: dict = field(default_factory=dict)
    records: tuple = ()
    weights: dict = field(default_factory=dict)
    channel_costs: list = field(default_factory=list)
    channel_residuals: list = field(default_factory=list)
    identifiability: Identifiability | None = None

    def unit(self, name: str) -> str:
        """The SI unit of parameter ``name``; ``input_offset`` is in the input channel's unit."""
        if name.partition("[")[0] == "input_offset" and self.input_kind:
            return unit(self.input_kind)
        return unit_of(self.model, name)

    @property
    def standard_errors(self) -> dict:
        """Standard error of each estimated parameter (its unit); empty without the polish."""
        if self.uncertainty is None:
            return {}
        se = self.uncertainty.standard_error
        return {n: se[n] for n in self.parameters if n in se}

    @property
    def unidentifiable_pairs(self) -> list[tuple[str, str, float]]:
        """Pairs of estimates whose |correlation| is at least
        :data:`UNIDENTIFIABLE_CORRELATION`: ``(name, name, correlation)``; the record
        determines only a combination of each pair (empty without the polish)."""
        if self.uncertainty is None:
            return []
        names, r = list(self.uncertainty.names), np.asarray(self.uncertainty.correlation)
        return [
            (names[i], names[j], float(r[i, j]))
            for i in range(len(names))
            for j in range(i + 1, len(names))
            if abs(r[i, j]) >= UNIDENTIFIABLE_CORRELATION
        ]

    @property
    def at_bound(self) -> dict:
        """Free parameters the search left on a bound: name -> ``"lower"`` or ``"upper"``.

        Within :data:`BOUND_TOLERANCE` of the box's width. Such a value is
        where the search stopped, not an estimate: the cost may fall further
        beyond the bound, and the local (Gauss-Newton) interval, which assumes
        an interior minimum, does not apply.
        """
        return {
            name: side for name, (side, _) in self._boxed().items() if side in ("lower", "upper")
        }

    def _boxed(self) -> dict:
        """Free parameters inside their search box: name -> (where, (lo, hi)).

        ``where`` is "lower", "upper" or "inside". A value outside its box
        (an offset, whose box is the search's start only) is not listed.
        """
        out = {}
        for name, (lo, hi) in self.bounds.items():
            if name not in self.free or name not in self.parameters:
                continue
            lo, hi, value = float(lo), float(hi), float(self.parameters[name])
            tol = BOUND_TOLERANCE * (hi - lo)
            if not lo - tol <= value <= hi + tol:
                continue
            where = "lower" if value <= lo + tol else "upper" if value >= hi - tol else "inside"
            out[name] = (where, (lo, hi))
        return out

    @property
    def confidence_intervals(self) -> dict:
        """95 % confidence interval of each estimated parameter, inside its search box.

        A parameter on a bound (:attr:`at_bound`) has none: its local interval
        assumes an interior minimum. A parameter inside its box has the local
        interval cut at the box (the search cannot return a value beyond it).
        """
        if self.uncertainty is None:
            return {}
        boxed = self._boxed()
        out = {}
        for name in self.standard_errors:
            a, b = self.uncertainty.interval[name]
            if name in boxed:
                where, (lo, hi) = boxed[name]
                if where != "inside":
                    continue
                a, b = max(a, lo), min(b, hi)
            out[name] = (a, b)
        return out

    def to_dict(self) -> dict:
        """JSON-ready summary."""
        return {
            "model": self.model,
            "parameters": {k: float(v) for k, v in self.parameters.items()},
            "units": {k: self.unit(k) for k in self.parameters},
            "input_kind": self.input_kind,
            **self._electrical_dict(),
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
            **({} if self.residuals is None else {"residuals": self.residuals.to_dict()}),
            # free parameters left on a search bound: not estimates, no interval
            "at_bound": self.at_bound,
            # pairs the record cannot tell apart: [name, name, correlation]
            "unidentifiable_pairs": [list(pair) for pair in self.unidentifiable_pairs],
            **(
                {}
                if self.uncertainty is None
                else {
                    "uncertainty_of": "all estimated quantities",
                    **self.uncertainty.to_dict(),
                    "confidence_intervals_95": {
                        k: [float(a), float(b)] for k, (a, b) in self.confidence_intervals.items()
                    },
                }
            ),
        }

    def _electrical_dict(self) -> dict:
        """The coupling, channels, loads and identifiability (only what a fit has)."""
        out = {}
        if self.coupling:
            out["coupling"] = self.coupling
            out["r_loads"] = [float(r) for r in self.r_loads]
        if self.rectifier:  # the bridge as data, not only in the notes
            out["rectifier"] = {
                "kind": "bridge",
                **{k: float(v) for k, v in self.rectifier.items()},
            }
        if tuple(self.outputs) != ("relative_displacement",) or self.channel_costs:
            out["outputs"] = list(self.outputs)
            out["records"] = list(self.records)
            out["weights"] = dict(self.weights)
            out["channel_costs"] = list(self.channel_costs)
            out["channel_residuals"] = list(self.channel_residuals)
        if self.identifiability is not None:
            out["identifiability"] = self.identifiability.to_dict()
        return out

    @classmethod
    def from_dict(cls, d: dict) -> IdentificationResult:
        """The result that :meth:`to_dict` wrote (a fit saved as JSON), uncertainty included.

        The standard errors, correlations, covariance method and residual
        diagnostics come back as saved; the intervals are recomputed from
        them (:meth:`Uncertainty.from_dict
        <randvib.identification.least_squares.Uncertainty.from_dict>`). The
        per-generation history is not saved and comes back empty.
        """
        from randvib.identification.least_squares import Uncertainty

        initial_state = dict(d.get("initial_state", {}))
        uncertainty = None
        if "standard_errors" in d:
            uncertainty = Uncertainty.from_dict(d, {**initial_state, **d["parameters"]})
        residuals = d.get("residuals")
        return cls(
            model=d["model"],
            parameters=d["parameters"],
            free=tuple(d["free"]),
            cost=d["cost"],
            bounds={k: tuple(v) for k, v in d["bounds"].items()},
            nfev=d["simulations"],
            generations=d["generations"],
            elapsed=d["elapsed_s"],
            simulations_per_second=d["simulations_per_second"],
            message=d["message"],
            record=d["record"],
            settings=d["settings"],
            uncertainty=uncertainty,
            initial_state=initial_state,
            notes=tuple(d.get("notes", ())),
            input_kind=d.get("input_kind", ""),
            residuals=None if residuals is None else ResidualDiagnostics.from_dict(residuals),
            coupling=d.get("coupling", ""),
            outputs=tuple(d.get("outputs", ("relative_displacement",))),
            r_loads=tuple(float(r) for r in d.get("r_loads", ())),
            rectifier=saved_rectifier(d.get("rectifier")),
            records=tuple(d.get("records", ())),
            weights=dict(d.get("weights", {})),
            channel_costs=list(d.get("channel_costs", [])),
            channel_residuals=list(d.get("channel_residuals", [])),
            identifiability=None
            if "identifiability" not in d
            else Identifiability.from_dict(d["identifiability"]),
        )

    def to_frame(self):
        """The parameters as a :class:`pandas.DataFrame`, one row per parameter.

        Columns ``value``, ``unit``, ``free`` (identified, not fixed),
        ``std_error`` and the 95 % confidence interval ``ci95_lower``,
        ``ci95_upper`` (:attr:`standard_errors`, :attr:`confidence_intervals`:
        NaN for a fixed parameter, one left on a search bound, or without the
        polish), ``status`` (``identified``, ``fixed``, ``at lower bound``,
        ``at upper bound``), and the search box ``search_lower``,
        ``search_upper`` (where the search looked, not an interval: NaN for
        a fixed parameter). The cost and the search's summary are in
        :meth:`to_dict`.
        """
        pd = _display.pandas()
        se, ci = self.standard_errors, self.confidence_intervals
        nan = (np.nan, np.nan)
        rows = {
            name: {
                "value": float(value),
                "unit": self.unit(name),
                "free": name in self.free,
                "std_error": float(se.get(name, np.nan)),
                "ci95_lower": float(ci.get(name, nan)[0]),
                "ci95_upper": float(ci.get(name, nan)[1]),
                "status": self._status(name),
                "search_lower": float(self.bounds[name][0]) if name in self.bounds else np.nan,
                "search_upper": float(self.bounds[name][1]) if name in self.bounds else np.nan,
            }
            for name, value in self.parameters.items()
        }
        return pd.DataFrame.from_dict(rows, orient="index").rename_axis("parameter")

    def _status(self, name: str) -> str:
        """``identified``, ``fixed`` or ``at lower/upper bound`` (where the search stopped)."""
        at_bound = self.at_bound
        if name in at_bound:
            return f"at {at_bound[name]} bound"
        return "identified" if name in self.free else "fixed"

    def _rows(self):
        rows = [("cost J (Eq. 11)", formatting.compact(self.cost, 4), "")]
        se, ci = self.standard_errors, self.confidence_intervals
        for name, value in self.parameters.items():
            status = self._status(name)
            text = formatting.compact(value)
            if name in se:  # value ± standard error [95 % interval], the digits the error allows
                shown, error, interval = formatting.with_standard_error(
                    value, se[name], ci.get(name)
                )
                text = f"{shown} ± {error} {interval}".rstrip()
            shown = name if status == "identified" else f"{name} ({status})"
            rows.append((shown, text, self.unit(name)))
        if self.residuals is not None:
            rows.append(("residual", self.residuals.verdict, ""))
        return rows

    def _search_line(self) -> str:
        record = f" on {self.record!r}" if self.record else ""
        return (
            f"{self.model}{record}: {self.nfev} simulations, {self.generations} generations, "
            f"{self.elapsed:.3g} s; {self.message}"
        )

    def __repr__(self) -> str:
        # compact: the per-generation history stays in .history, not on the screen
        se = self.standard_errors
        values = ", ".join(
            f"{name}={formatting.compact(v)}"
            if name not in se
            else f"{name}={' ± '.join(formatting.estimate_parts(v, se[name]))}"
            for name, v in self.parameters.items()
        )
        verdict = "" if self.residuals is None else f"; residual {self.residuals.verdict}"
        return (
            f"IdentificationResult(model={self.model!r}, cost={formatting.compact(self.cost, 4)}, "
            f"{values}{verdict}; {self.nfev} simulations, {self.generations} generations)"
        )

    def _title(self) -> str:
        if self.uncertainty is None:
            return "Identification (no standard errors: the polish was skipped)"
        return "Identification (value ± standard error [95 % interval])"

    def __str__(self) -> str:
        """The table of :meth:`_repr_html_` as plain text (``print(result)``)."""
        return _display.text_table(self._title(), self._rows(), self._search_line())

    def _repr_html_(self) -> str:
        return _display.html_table(self._title(), self._rows(), self._search_line())

    def harvester(self, electrical=None, *, r_load: float | None = None) -> Harvester:
        """The identified device, its damping c as c_m.

        A fit made behind a diode bridge (:attr:`rectifier`) gives the
        coupling through that bridge (:mod:`randvib.models.rectifier`).

        Parameters
        ----------
        electrical : Coupling, optional
            A coupling to wire the device with (its c_e is added to the
            identified c, which a record taken in open circuit does not hold),
            e.g. ``randvib.Resistive(alpha, r_load, r_coil)``. A fit that
            identified its coupling has it already (c is then c_m).
        r_load : float, optional
            With an identified coupling: the load (ohm) to wire it to;
            default the first record's (a storage capacitor's load behind a
            bridge; unused with a battery).
        """
        if self.coupling:
            if electrical is not None:
                raise ValueError(
                    f"this fit identified its {self.coupling} coupling: give `r_load` to wire it "
                    "to another load, not another coupling"
                )
            load = self.r_loads[0] if r_load is None else r_load
            if self.rectifier:
                electrical = bridge_from_parameters(
                    self.coupling, self.parameters, self.rectifier, load
                )
            else:
                self._refuse_unsaved_bridge()
                electrical = coupling_from_parameters(self.coupling, self.parameters, load)
        elif r_load is not None:
            raise ValueError("`r_load` needs a fit that identified its coupling (`coupling=`)")
        return device_from_parameters(self.model, self.parameters, electrical)[0]

    def _refuse_unsaved_bridge(self) -> None:
        """A fit made behind a bridge whose file predates the ``rectifier`` field (its notes
        name the bridge) is refused rather than wired without it."""
        note = next((n for n in self.notes if n.startswith(BRIDGE_NOTE)), None)
        if note is not None:
            raise ValueError(
                f'this fit was made {note.rstrip(".")}, but saves no "rectifier" field: add '
                '`"rectifier": {"kind": "bridge", "v_diode": ..., "storage_capacitance" or '
                '"battery": ...}` to its JSON, or identify again'
            )

    @property
    def measurement(self) -> MeasurementModel:
        """The identified (or fixed) offsets and k2 (the first record's); absent ones are 0."""
        return self.measurement_of(0)

    def measurement_of(self, index: int) -> MeasurementModel:
        """The offsets of record ``index`` (its ``[index]`` parameters) and k2."""
        count = max(len(self.records), 1)
        own = {}
        for name, value in self.parameters.items():
            base, _, which = name.partition("[")
            if not which and count == 1 or which and int(which.rstrip("]")) == index:
                own[base] = value
        return MeasurementModel.from_parameters(own)

    @property
    def simulation(self) -> SimulationSettings:
        """The simulation settings of the fit, as :func:`predict_record` takes them."""
        return SimulationSettings(**{k: v for k, v in self.settings.items() if k in _SIMULATION})

    def diagnose(self, record: Record, max_lag: int = MAX_LAG) -> ResidualDiagnostics:
        """Residual diagnostics of the fit on ``record`` (the training record or another).

        The residual is the measured less the simulated output (:meth:`predict`)
        after the ``skip`` samples, tested against the record's input
        (:func:`~randvib.identification.residuals.residual_diagnostics`).
        """
        pred = self.predict(record)
        skip = int(self.settings.get("skip", 0))
        kind = pred.outputs[0]
        residual = record[kind][skip:] - pred.simulated(kind)[skip:]
        return residual_diagnostics(residual, record.input[skip:], max_lag)

    def predict(
        self, record: Record, electrical=None, *, r_load: float | None = None, index: int = 0
    ) -> Prediction:
        """``record`` simulated with the identified device and measurement model.

        :func:`~randvib.identification.prediction.predict_record` with
        :meth:`harvester` (wired with ``electrical``, or with the identified
        coupling at ``r_load``, default the ``index``-th record's load),
        the ``index``-th record's offsets (:meth:`measurement_of`), the fit's
        channels and its :attr:`simulation` settings; the initial state is
        obtained for ``record`` as the fit obtained it.
        """
        channels = bool(self.coupling) or tuple(self.outputs) != ("relative_displacement",)
        if self.coupling and r_load is None:
            r_load = self.r_loads[index]
        return predict_record(
            self.harvester(electrical, r_load=r_load),
            record,
            measurement=self.measurement_of(index),
            simulation=self.simulation,
            **({"outputs": tuple(self.outputs)} if channels else {}),
        )


#: The fields of SimulationSettings, among a result's ``settings``.
_SIMULATION = tuple(SimulationSettings().to_dict())
