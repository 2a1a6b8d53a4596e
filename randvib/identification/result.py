"""The outcome of an identification: :class:`IdentificationResult`, the device it found."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from randvib import _display, formatting
from randvib.identification.models import MeasurementModel, device_from_parameters, unit_of
from randvib.identification.prediction import Prediction, predict_record
from randvib.identification.settings import SimulationSettings
from randvib.models.harvester import Harvester
from randvib.models.record import Record


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
        rows = {
            name: {
                "value": float(value),
                "unit": unit_of(self.model, name),
                "free": name in self.free,
                "lower": float(self.bounds[name][0]) if name in self.bounds else np.nan,
                "upper": float(self.bounds[name][1]) if name in self.bounds else np.nan,
            }
            for name, value in self.parameters.items()
        }
        return pd.DataFrame.from_dict(rows, orient="index").rename_axis("parameter")

    def _rows(self):
        rows = [("cost J (Eq. 11)", formatting.compact(self.cost, 4), "")]
        for name, value in self.parameters.items():
            fixed = "" if name in self.free else " (fixed)"
            rows.append((name + fixed, formatting.compact(value), unit_of(self.model, name)))
        return rows

    def _search_line(self) -> str:
        record = f" on {self.record!r}" if self.record else ""
        return (
            f"{self.model}{record}: {self.nfev} simulations, {self.generations} generations, "
            f"{self.elapsed:.3g} s; {self.message}"
        )

    def __repr__(self) -> str:
        # compact: the per-generation history stays in .history, not on the screen
        values = ", ".join(f"{name}={formatting.compact(v)}" for name, v in self.parameters.items())
        return (
            f"IdentificationResult(model={self.model!r}, cost={formatting.compact(self.cost, 4)}, "
            f"{values}; {self.nfev} simulations, {self.generations} generations)"
        )

    def __str__(self) -> str:
        """The table of :meth:`_repr_html_` as plain text (``print(result)``)."""
        return _display.text_table("Identification", self._rows(), self._search_line())

    def _repr_html_(self) -> str:
        return _display.html_table("Identification", self._rows(), self._search_line())

    def harvester(self, electrical=None) -> Harvester:
        """The identified device, its damping c as c_m (c_e = 0).

        Parameters
        ----------
        electrical : Coupling, optional
            A coupling to wire the device with (its c_e is added to the
            identified c, which a record taken in open circuit does not hold),
            e.g. ``randvib.Resistive(alpha, r_load, r_coil)``.
        """
        return device_from_parameters(self.model, self.parameters, electrical)[0]

    @property
    def measurement(self) -> MeasurementModel:
        """The identified (or fixed) offsets and k2; those not estimated are 0."""
        return MeasurementModel.from_parameters(self.parameters)

    @property
    def simulation(self) -> SimulationSettings:
        """The simulation settings of the fit, as :func:`predict_record` takes them."""
        return SimulationSettings(**{k: v for k, v in self.settings.items() if k in _SIMULATION})

    def predict(self, record: Record, electrical=None) -> Prediction:
        """``record`` simulated with the identified device and measurement model.

        :func:`~randvib.identification.prediction.predict_record` with
        :meth:`harvester` (wired with ``electrical``, if given),
        :attr:`measurement` and the fit's :attr:`simulation` settings; the
        initial state is obtained for ``record`` as the fit obtained it.
        """
        return predict_record(
            self.harvester(electrical),
            record,
            measurement=self.measurement,
            simulation=self.simulation,
        )


#: The fields of SimulationSettings, among a result's ``settings``.
_SIMULATION = tuple(SimulationSettings().to_dict())
