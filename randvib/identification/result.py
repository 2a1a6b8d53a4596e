"""The outcome of an identification: :class:`IdentificationResult`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from randvib import _display
from randvib.identification.models import check_model, parameter_specs, unit_of
from randvib.identification.prediction import Prediction, predict_record
from randvib.models.record import Record


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
            "units": {k: unit_of(self.model, k) for k in self.parameters},
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
        specs = parameter_specs(self.model)
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
        specs = parameter_specs(self.model)
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
        """Simulate ``record`` with these parameters (see :func:`~randvib.identification.prediction.predict_record`)."""
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
        law = check_model(self.model)
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
