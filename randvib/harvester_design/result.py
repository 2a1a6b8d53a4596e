"""What a design returns: :class:`DesignResult`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from randvib import _display, formatting
from randvib.quantities import parameter_unit, unit
from randvib.statistics import FirstPassage, Statistic

__all__ = ["DesignResult"]

#: A stroke budget is inactive when the optimum's exceedance is below this fraction of it.
INACTIVE_BUDGET = 0.1


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
        A non-causal bound (W; a transducer that sees the future): under a
        spectrum :func:`randvib.analytic.harvesting_limit.harvesting_limit`
        at the Gaussian displacement RMS of the budget, which bounds every
        device with that E[z^2], so every linear device that meets the
        budget, but not a nonlinear one (a tail budget does not bound
        E[z^2]); on a measured record
        :func:`randvib.analytic.harvesting_limit.record_harvesting_limit`,
        the bound on the record with |z| <= stroke, from rest. None where no
        finite bound exists (white noise).
    limit_kind : str or None
        What ``limit`` bounds, in words (``"stationary, non-causal, ..."`` or
        ``"record, non-causal ..."``).
    limit_hard_stroke : float or None
        The non-causal bound for any device held within |z| <= stroke (W):
        the stationary bound with E[z^2] <= d^2 (the record bound on a record).
    causal_limit : float or None
        What a causal device can approach at the budget's RMS (W,
        :func:`randvib.analytic.harvesting_limit.causal_harvesting_limit`):
        m S / 4 under white noise; the Wiener-Hopf bound under a rational
        spectrum; the non-causal ``limit`` where the spectrum vanishes on a
        band; None on a record.
    causal_limit_kind : str or None
        What ``causal_limit`` is, in words.
    fraction_of_limit : float or None
        The optimum's power (Monte Carlo mean, else predicted) over ``limit``.
    fraction_of_causal_limit : float or None
        The same power over ``causal_limit`` (a property).
    monte_carlo_precision : float or None
        The Monte Carlo target: 95 % half-width of the power over the power.
    notes : list of str
        What the numbers do not say themselves (a property): an inactive
        stroke budget, a missed precision target.
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
    limit_hard_stroke: float | None = None
    causal_limit: float | None = None
    causal_limit_kind: str | None = None
    monte_carlo_precision: float | None = None
    objective_scope: str | None = None
    max_first_passage: float | None = None
    duration: float | None = None
    first_passage_probability_predicted: float = float("nan")
    first_passage_probability: Statistic | None = None
    first_passage_probability_confirmed: bool | None = None

    @property
    def power(self) -> float:
        """The optimum's power (W): the Monte Carlo mean, else the prediction."""
        if self.power_monte_carlo is not None:
            return float(self.power_monte_carlo.mean)
        return float(self.power_predicted)

    @property
    def fraction_of_causal_limit(self) -> float | None:
        """The optimum's power over ``causal_limit`` (None without one)."""
        return None if self.causal_limit is None else self.power / self.causal_limit

    @property
    def notes(self) -> list[str]:
        """Statements the numbers need: an inactive stroke budget, a missed precision target."""
        notes, seen = [], []  # the exceedance each source allows, and its words
        predicted = math.isfinite(self.exceedance_predicted)
        if predicted:
            seen.append((self.exceedance_predicted, f"{self.exceedance_predicted:.2g} predicted"))
        x = self.stroke_exceedance_monte_carlo
        if x is not None:
            # A probability's Wilson interval from n paths that saw nothing still reaches
            # about 4 / n, far above a budget of 1e-3: beside a prediction Monte Carlo
            # must not contradict it (its lower end); alone, its upper end must agree.
            lower, upper = x.interval
            seen.append((lower if predicted else upper, f"{x} by Monte Carlo"))
        words = ", ".join(w for _, w in seen)
        if seen and max(v for v, _ in seen) < INACTIVE_BUDGET * self.exceedance_budget:
            notes.append(
                f"the stroke budget is inactive: {self._budget_event()} at the optimum is "
                f"{words}, against {self.exceedance_budget:g} allowed; the ranges or the "
                "device limit the power, not the stroke"
            )
        power, target = self.power_monte_carlo, self.monte_carlo_precision
        if power is not None and target is not None and power.mean != 0:
            reached = power.ci95 / abs(power.mean)
            if reached > target:
                notes.append(
                    f"the Monte Carlo precision target was missed: the power's 95 % interval "
                    f"is ±{reached:.2%} of it against {target:.2%} asked; more paths "
                    "(max_paths, --max-paths) or a looser target"
                )
        return notes

    def _budget_event(self) -> str:
        """``P(|z| > d m)``, or an assembly's strokes by coordinate."""
        if isinstance(self.stroke, dict):
            return "P(" + " or ".join(f"|{k}| > {v:g} m" for k, v in self.stroke.items()) + ")"
        return f"P(|z| > {self.stroke:g} m)"

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
            "limit_hard_stroke": self.limit_hard_stroke,
            "causal_limit": self.causal_limit,
            "causal_limit_kind": self.causal_limit_kind,
            "fraction_of_limit": self.fraction_of_limit,
            "fraction_of_causal_limit": self.fraction_of_causal_limit,
            "monte_carlo_precision": self.monte_carlo_precision,
            "notes": self.notes,
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
        rows += self.limit_rows(formatting.compact)
        return rows

    def limit_rows(self, number) -> list[tuple[str, str, str]]:
        """(label, value, unit) of the limits and fractions, each bound labelled causal or not.

        ``number`` formats a deterministic value (the table's rule).
        """
        rows = []
        for key, label in (
            ("limit", "limit (non-causal)"),
            ("limit_hard_stroke", "limit_hard_stroke (non-causal)"),
            ("causal_limit", "causal_limit"),
        ):
            value = getattr(self, key)
            if value is not None:
                rows.append((label, number(value), unit(key)))
            elif key == "limit" and self.objective_scope is not None:  # an assembly's design
                rows.append((label, "none (not computed for an assembly)", ""))
            elif key == "limit" and self.causal_limit is not None:
                rows.append((label, "none (unbounded for white noise)", ""))
        for key, label in (
            ("fraction_of_limit", "fraction_of_limit (non-causal)"),
            ("fraction_of_causal_limit", "fraction_of_causal_limit"),
        ):
            value = getattr(self, key)
            if value is not None:
                rows.append((label, number(value), unit(key)))
        return rows

    def __repr__(self) -> str:
        chosen = ", ".join(f"{k}={formatting.compact(v)}" for k, v in self.optimum.items())
        mc = "" if self.power_monte_carlo is None else f", monte_carlo={self.power_monte_carlo}"
        return (
            f"DesignResult({chosen}, power_predicted={formatting.compact(self.power_predicted)}"
            f"{mc})"
        )

    def __str__(self) -> str:
        """The table of :meth:`_repr_html_` as plain text (``print(result)``), then the notes."""
        return _display.text_table("Design", self._rows(), "; ".join(self.notes))

    def _repr_html_(self) -> str:
        return _display.html_table("Design", self._rows(), "; ".join(self.notes))


def _columns(name: str, s: Statistic | None) -> dict:
    if s is None:
        return {name: float("nan"), f"{name}_ci95": float("nan")}
    return {name: s.mean, f"{name}_ci95": s.ci95}
