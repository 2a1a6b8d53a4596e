"""What a design maximises: a declared, pluggable family of objectives.

An :class:`Objective` says how to read its power from an analytic
prediction (:class:`~randvib.analytic.power_prediction.PowerPrediction`) and,
path by path, from a Monte Carlo ensemble
(:class:`~randvib.montecarlo.ensembles.EnsembleResult`), so that the design's
search and its confirmation maximise the same thing. :data:`OBJECTIVES`
lists them by name: the electrical power, the load's share of it, and the
power stored through a diode bridge (:mod:`randvib.models.rectifier`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["OBJECTIVES", "Objective", "objective_named"]


@dataclass(frozen=True)
class Objective:
    """A power to maximise (W).

    Attributes
    ----------
    name : str
        Key in :data:`OBJECTIVES` and the CLI's ``--objective``.
    description : str
        What it is, in words.
    analytic : callable
        ``analytic(prediction, harvester) -> float``: the predicted power (W).
    monte_carlo : callable
        ``monte_carlo(ensembles, index) -> ndarray``: each path's time-averaged
        power (W) in case ``index``.
    requires : callable
        ``requires(harvester) -> str | None``: why the objective does not
        apply to the harvester, or None.
    """

    name: str
    description: str
    analytic: Callable
    monte_carlo: Callable
    requires: Callable


def _load_refusal(harvester) -> str | None:
    if harvester.electrical is None:
        return (
            "objective 'load' needs the circuit: build the harvester with "
            "Harvester.from_electrical (alpha, r_load, r_coil) or with_coupling"
        )
    return None


def _stored_refusal(harvester) -> str | None:
    if not harvester.is_rectified:
        return (
            "objective 'stored' needs a diode bridge: build the harvester with "
            "Harvester.with_coupling(m, c_m, k, BridgeCoil(...) or BridgePiezo(...))"
        )
    return None


def _load_fraction_samples(ensembles, index) -> np.ndarray:
    device = ensembles.cases[index].device
    if device.has_circuit:
        averages = ensembles.averages(index)
        return device.electrical.power_load(averages.v2, averages.circuit_square)
    return ensembles.power_samples(index) * device.electrical.load_fraction


#: The objectives by name: ``electrical`` (E[P_e], the power converted by the
#: transducer, paper Eq. 31), ``load`` (the load's share of it, E[i^2 R_L]) and
#: ``stored`` (the DC power a diode bridge delivers: V_b E|i| into a battery,
#: E[V_C^2] / R_L from a storage capacitor; docs/conventions.md).
OBJECTIVES: dict[str, Objective] = {
    o.name: o
    for o in (
        Objective(
            "electrical",
            "power into the electrical domain E[P_e] (paper Eq. 31)",
            lambda prediction, harvester: float(prediction.power_electrical),
            lambda ensembles, index: ensembles.power_samples(index),
            lambda harvester: None,
        ),
        Objective(
            "load",
            "power into the load resistance E[i^2 R_L]",
            lambda prediction, harvester: float(prediction.power_load),
            _load_fraction_samples,
            _load_refusal,
        ),
        Objective(
            "stored",
            "power stored through a diode bridge (V_b E|i| or E[V_C^2] / R_L)",
            lambda prediction, harvester: float(prediction.power_stored),
            lambda ensembles, index: ensembles.averages(index).stored_power,
            _stored_refusal,
        ),
    )
}


def objective_named(objective) -> Objective:
    """The objective ``objective`` names (a key of :data:`OBJECTIVES`) or is."""
    if isinstance(objective, Objective):
        return objective
    if objective not in OBJECTIVES:
        raise ValueError(
            f"`objective` must be one of {', '.join(map(repr, OBJECTIVES))}, got {objective!r}"
        )
    return OBJECTIVES[objective]
