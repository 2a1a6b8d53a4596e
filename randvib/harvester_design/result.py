"""What a design returns: :class:`DesignResult`."""

from __future__ import annotations

from dataclasses import dataclass, field

from randvib import _display, formatting
from randvib.quantities import parameter_unit, unit
from randvib.statistics import FirstPassage, Statistic

__all__ = ["DesignResult"]


def _stat(s: Statistic | None):
    return None if s is None else s.to_dict()


@dataclass(frozen=True)
class DesignResult:
    """The chosen device, its predicted and confirmed power, and the limit (SI units).

    Attributes
    ----------
    optimum : dict
        Varied parameter name -> chosen value.
    device : Harvester
        The fixed harvester with the chosen values.
    objective : str
        The maximised power (:data:`randvib.harvester_design.objectives.OBJECTIVES`).
    stroke : float or dict
        The stroke d (m); an assembly's: coordinate path -> its stroke (m),
        each held to the budget.
    exceedance_budget : float
        The budget eps on P(|z| > d) (an assembly's: on each coordinate).
    method : str
        The analytic method of the search.
    power_predicted : float
        The analytic prediction of the objective at ``optimum`` (W).
    exceedance_predicted : float
        The predicted P(|z| > d) at ``optimum``.
    power_monte_carlo, stroke_exceedance_monte_carlo : Statistic or None
        Monte Carlo mean and 95 % half-width at ``optimum`` (None without Monte Carlo);
        the power is the objective's (the stored power for ``"stored"``).
    input_power : Statistic or float
        Power the excitation delivers to the device (W): c_m E[z'^2] + E[z' F]
        + electrical power, from Monte Carlo (else the prediction). m S / 4
        under white noise.
    efficiency : float
        Objective power over input power (mean values).
    limit : float or None
        The most any transducer on this mass can take (W): under a spectrum
        :func:`randvib.analytic.harvesting_limit.harvesting_limit` at the
        Gaussian displacement RMS of the budget; on a measured record
        :func:`randvib.analytic.harvesting_limit.record_harvesting_limit`,
        the non-causal bound on the record with |z| <= stroke. None where
        no finite bound exists.
    limit_kind : str or None
        Which bound ``limit`` is: ``"stationary: ..."`` or ``"record: ..."``.
    fraction_of_limit : float or None
        The optimum's power (Monte Carlo mean, else predicted) over ``limit``.
    runners_up : list of dict
        Other candidates: ``values``, ``power_predicted``, ``exceedance_predicted``
        and, with Monte Carlo, ``power_monte_carlo``, ``stroke_exceedance_monte_carlo``
        and ``difference_to_optimum`` (paired, W).
    analytic_optimum : dict
        The analytic search's optimum (equal to ``optimum`` unless Monte Carlo refined it).
    analytic_cost : Statistic or None
        Monte Carlo power of ``optimum`` minus that of ``analytic_optimum``,
        paired (W): what the analytic answer would have cost (0 when equal).
    analytic_feasible : bool or None
        Whether the analytic optimum met the budget in Monte Carlo (its 95 %
        interval on the exceedance reaches down to the budget) and Monte Carlo
        did not reject its first passage (``min_first_passage``).
    refined : bool
        Monte Carlo moved the optimum.
    evaluations : int
        Analytic predictions made.
    monte_carlo_cases : int
        Ensembles simulated.
    min_first_passage : float or None
        The bound T (s) on the mean first-passage time to the stroke, if any.
    first_passage_predicted : float
        Predicted mean first-passage time to the stroke (s) from a stationary
        start; NaN where the method does not give it.
    first_passage_monte_carlo : FirstPassage or None
        Monte Carlo time to |z| > stroke from the ensembles' start (censored at
        the run's end).
    first_passage_confirmed : bool or None
        Monte Carlo's verdict on ``min_first_passage``: True (E[min(tau, t_end)]
        significantly above T), False (E[tau] significantly below T), None
        (undetermined: paths censored at t_end, or no bound).
    objective_scope : str or None
        An assembly's: ``"all transducers"`` (their powers summed) or
        ``"transducer I"``; None for a single mass.
    max_first_passage, duration : float or None
        The bound P on P(|z| reaches the stroke within T) and T (s), if any.
    first_passage_probability_predicted : float
        That probability by the Gaussian answer (NaN where not predicted).
    first_passage_probability : Statistic or None
        That probability by the rare-event estimate (:func:`randvib.first_passage`).
    first_passage_probability_confirmed : bool or None
        Its verdict on ``max_first_passage``: True (95 % interval below P),
        None (undetermined); a rejected candidate is never the design.
    monte_carlo_input : str or None
        What drove the Monte Carlo: ``"record windows"`` (a measured record
        itself, its windows the paths, :func:`randvib.monte_carlo_on_record`)
        or ``"simulated paths"`` (Gaussian paths of the spectrum); None
        without Monte Carlo.
    """

    optimum: dict
    device: object = field(repr=False)
    objective: str
    stroke: float | dict
    exceedance_budget: float
    method: str
    power_predicted: float
    exceedance_predicted: float
    power_monte_carlo: Statistic | None
    stroke_exceedance_monte_carlo: Statistic | None
    input_power: object
    efficiency: float
    limit: float | None
    fraction_of_limit: float | None
    runners_up: list = field(repr=False)
    analytic_optimum: dict = field(repr=False)
    analytic_cost: Statistic | None = None
    analytic_feasible: bool | None = None
    refined: bool = False
    evaluations: int = 0
    monte_carlo_cases: int = 0
    min_first_passage: float | None = None
    first_passage_predicted: float = float("nan")
    first_passage_monte_carlo: FirstPassage | None = None
    first_passage_confirmed: bool | None = None
    monte_carlo_input: str | None = None
    limit_kind: str | None = None
    objective_scope: str | None = None
    max_first_passage: float | None = None
    duration: float | None = None
    first_passage_probability_predicted: float = float("nan")
    first_passage_probability: Statistic | None = None
    first_passage_probability_confirmed: bool | None = None

    def to_dict(self) -> dict:
        """JSON-ready: the keys of ``randvib design --json``."""
        input_power = self.input_power
        return {
            "optimum": dict(self.optimum),
            "objective": self.objective,
            "stroke": self.stroke,
            "exceedance": self.exceedance_budget,
            "method": self.method,
            "power_predicted": self.power_predicted,
            "stroke_exceedance_predicted": self.exceedance_predicted,
            "power_monte_carlo": _stat(self.power_monte_carlo),
            "stroke_exceedance_monte_carlo": _stat(self.stroke_exceedance_monte_carlo),
            "input_power": input_power.to_dict()
            if isinstance(input_power, Statistic)
            else input_power,
            "efficiency": self.efficiency,
            "limit": self.limit,
            "limit_kind": self.limit_kind,
            "fraction_of_limit": self.fraction_of_limit,
            "runners_up": [
                {k: (_stat(v) if isinstance(v, Statistic) else v) for k, v in r.items()}
                for r in self.runners_up
            ],
            "analytic_optimum": dict(self.analytic_optimum),
            "analytic_cost": _stat(self.analytic_cost),
            "analytic_feasible": self.analytic_feasible,
            "refined": self.refined,
            "evaluations": self.evaluations,
            "monte_carlo_cases": self.monte_carlo_cases,
            "min_first_passage": self.min_first_passage,
            "first_passage_predicted": self.first_passage_predicted,
            "first_passage_monte_carlo": None
            if self.first_passage_monte_carlo is None
            else self.first_passage_monte_carlo.to_dict(),
            "first_passage_confirmed": self.first_passage_confirmed,
            "monte_carlo_input": self.monte_carlo_input,
            **({} if self.objective_scope is None else {"objective_scope": self.objective_scope}),
            "max_first_passage": self.max_first_passage,
            "duration": self.duration,
            "first_passage_probability_predicted": self.first_passage_probability_predicted,
            "first_passage_probability": _stat(self.first_passage_probability),
            "first_passage_probability_confirmed": self.first_passage_probability_confirmed,
        }

    def to_frame(self):
        """One row per candidate (the optimum first): parameters, powers and exceedances."""
        pd = _display.pandas()
        rows = [
            {
                "candidate": "optimum",
                **self.optimum,
                "power_predicted": self.power_predicted,
                "stroke_exceedance_predicted": self.exceedance_predicted,
                **_columns("power_monte_carlo", self.power_monte_carlo),
                **_columns("stroke_exceedance_monte_carlo", self.stroke_exceedance_monte_carlo),
            }
        ]
        for i, r in enumerate(self.runners_up, 1):
            rows.append({
                "candidate": f"runner-up {i}",
                **r["values"],
                "power_predicted": r["power_predicted"],
                "stroke_exceedance_predicted": r["exceedance_predicted"],
                **_columns("power_monte_carlo", r.get("power_monte_carlo")),
                **_columns(
                    "stroke_exceedance_monte_carlo", r.get("stroke_exceedance_monte_carlo")
                ),
            })  # fmt: skip
        return pd.DataFrame(rows)

    def _rows(self):
        rows = [
            (name, formatting.compact(v), parameter_unit(name, self.device))
            for name, v in self.optimum.items()
        ]
        rows.append(
            ("power_predicted", formatting.compact(self.power_predicted), unit("power_predicted"))
        )
        rows.append((
            "stroke_exceedance_predicted",
            formatting.compact(self.exceedance_predicted),
            unit("stroke_exceedance_predicted"),
        ))  # fmt: skip
        if self.power_monte_carlo is not None:
            rows.append(
                ("power_monte_carlo", f"{self.power_monte_carlo}", unit("power_monte_carlo"))
            )
            rows.append((
                "stroke_exceedance_monte_carlo",
                f"{self.stroke_exceedance_monte_carlo}",
                unit("stroke_exceedance_monte_carlo"),
            ))  # fmt: skip
        if self.limit is not None:
            rows.append(("limit", formatting.compact(self.limit), unit("limit")))
        return rows

    def __repr__(self) -> str:
        chosen = ", ".join(f"{k}={formatting.compact(v)}" for k, v in self.optimum.items())
        mc = "" if self.power_monte_carlo is None else f", monte_carlo={self.power_monte_carlo}"
        return (
            f"DesignResult({chosen}, power_predicted={formatting.compact(self.power_predicted)}"
            f"{mc})"
        )

    def __str__(self) -> str:
        """The table of :meth:`_repr_html_` as plain text (``print(result)``)."""
        return _display.text_table("Design", self._rows())

    def _repr_html_(self) -> str:
        return _display.html_table("Design", self._rows())


def _columns(name: str, s: Statistic | None) -> dict:
    if s is None:
        return {name: float("nan"), f"{name}_ci95": float("nan")}
    return {name: s.mean, f"{name}_ci95": s.ci95}
