"""What a design maximises: a declared, pluggable family of objectives.

An :class:`Objective` says how to read its power from an analytic
prediction (:class:`~randvib.analytic.power_prediction.PowerPrediction`) and,
path by path, from a Monte Carlo ensemble
(:class:`~randvib.montecarlo.ensembles.EnsembleResult`), so that the design's
search and its confirmation maximise the same thing. :data:`OBJECTIVES`
lists them by name: the electrical power, the load's share of it, and the
power stored through a diode bridge (:mod:`randvib.models.rectifier`).

For an :class:`~randvib.models.assembly.Assembly` the same objectives are
read per transducer (:class:`AssemblyObjective`): by default the sum over
all its transducers (the device's whole harvest, what an array or a
two-mass harvester is built for), or one transducer's alone
(``transducer=i``: one harvester of an array, the others as they are).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["OBJECTIVES", "AssemblyObjective", "Objective", "objective_named"]


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
    transducer_power : str
        Its name on an assembly's transducer: ``power_electrical``,
        ``power_load`` or ``power_stored`` (:class:`AssemblyObjective`).
    """

    name: str
    description: str
    analytic: Callable
    monte_carlo: Callable
    requires: Callable
    transducer_power: str = "power_electrical"


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
            "power_load",
        ),
        Objective(
            "stored",
            "power stored through a diode bridge (V_b E|i| or E[V_C^2] / R_L)",
            lambda prediction, harvester: float(prediction.power_stored),
            lambda ensembles, index: ensembles.averages(index).stored_power,
            _stored_refusal,
            "power_stored",
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


@dataclass(frozen=True)
class AssemblyObjective:
    """An objective read from an assembly's transducers: their sum, or one transducer's.

    Attributes
    ----------
    objective : Objective
        What is read on each transducer (its :attr:`Objective.transducer_power`).
    transducer : int or None
        The one transducer whose power is maximised (the others as they are);
        None for the sum over every transducer.
    """

    objective: Objective
    transducer: int | None = None

    @property
    def name(self) -> str:
        return self.objective.name

    @property
    def scope(self) -> str:
        """``all transducers`` or ``transducer I``: whose power is maximised."""
        return "all transducers" if self.transducer is None else f"transducer {self.transducer}"

    def counted(self, assembly) -> range | list:
        """The indices of the transducers whose power counts."""
        if self.transducer is None:
            return range(len(assembly.transducers))
        return [self.transducer]

    def requires(self, assembly) -> str | None:
        """Why the objective does not apply to the assembly (one line), or None."""
        n = len(assembly.transducers)
        if n == 0:
            return "the assembly has no transducer: there is no power to maximise"
        if self.transducer is not None and not (
            isinstance(self.transducer, int) and 0 <= self.transducer < n
        ):
            return (
                f"`transducer` = {self.transducer!r}: the assembly has {n} transducer(s), "
                f"indices 0..{n - 1}"
            )
        for index in self.counted(assembly):
            t = assembly.transducers[index]
            if self.name == "load" and not t.has_load:
                return (
                    f"objective 'load' counts transducer {index}, a bare electrical damping "
                    "without a load resistance: give it a coil (flux gradient, load and coil "
                    "resistances), or use objective 'electrical'"
                )
            if self.name == "stored" and not t.is_rectified:
                return (
                    f"objective 'stored' counts transducer {index}, which has no diode bridge: "
                    "give it rectifier = \"bridge\", or use objective 'load' or 'electrical'"
                )
        return None

    def analytic(self, prediction, assembly) -> float:
        """The predicted power (W) from an :class:`~randvib.analytic.assembly_prediction.AssemblyPrediction`."""
        field = self.objective.transducer_power
        values = [getattr(prediction.transducers[i], field, None) for i in self.counted(assembly)]
        if any(v is None for v in values):
            return float("nan")
        return float(sum(values))

    def monte_carlo(self, result) -> np.ndarray:
        """Each path's power (W) from an assembly's Monte Carlo result.

        ``result.transducer_power(i)`` gives per path (electrical, load); a
        bridge's load is its stored power.
        """
        which = 0 if self.objective.transducer_power == "power_electrical" else 1
        return sum(result.transducer_power(i)[which] for i in self.counted(result.assembly))
