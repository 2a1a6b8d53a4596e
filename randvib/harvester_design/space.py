"""The parameters a design chooses, their ranges and the devices they make.

A :class:`DesignSpace` maps the unit box [0, 1]^d onto the ranges the user
gives (``vary={"k": (20, 120), "c_e": (0.01, 1)}``): logarithmically for a
positive range spanning a factor of 4 or more (stiffness, damping and
resistance act multiplicatively), linearly otherwise (a range through zero,
such as k from negative to positive for bistable devices). The search works
in the box; the devices are the fixed harvester with the chosen values
(:meth:`randvib.Harvester.updated`).

An :class:`~randvib.models.assembly.Assembly` is varied by dotted paths
(``transducer.0.r_load``, ``element.1.k3``, ``structure.stiffness.0.0``;
:meth:`Assembly.get`, :meth:`Assembly.updated`), refused where
:func:`randvib.harvester_design.assembly_budget.vary_refusal` says why (an
unknown path, a mass, a stroke, a derived c_e); its stroke budget is a
:class:`~randvib.harvester_design.assembly_budget.StrokeBudget`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from randvib.harvester_design.assembly_budget import StrokeBudget, vary_refusal
from randvib.models.assembly import Assembly
from randvib.models.harvester import Harvester

__all__ = ["DesignSpace", "Range", "designable_parameters"]

#: A positive range spanning at least this factor is searched in log scale.
LOG_RATIO = 4.0
#: What a design never varies: the mass is the user's, and so is the stroke.
FIXED = ("m", "stroke", "c")


def designable_parameters(harvester: Harvester) -> tuple[str, ...]:
    """The names :class:`DesignSpace` accepts for ``harvester``: device, friction and circuit parameters."""
    names = ["c_m", "c_e", "k", "k3"]
    if harvester.friction is not None:
        names += list(harvester.friction.parameter_names())
    if harvester.electrical is not None:
        names += list(harvester.electrical.parameter_names())
    else:
        names += ["alpha", "r_load", "r_coil"]
    return tuple(dict.fromkeys(names))


@dataclass(frozen=True)
class Range:
    """One varied parameter: its name, range and scale."""

    name: str
    low: float
    high: float
    log: bool

    def value(self, u: float) -> float:
        """The parameter at the box coordinate u in [0, 1]."""
        u = min(max(float(u), 0.0), 1.0)
        if self.log:
            return math.exp(math.log(self.low) + u * (math.log(self.high) - math.log(self.low)))
        return self.low + u * (self.high - self.low)

    def coordinate(self, value: float) -> float:
        """The box coordinate of ``value``."""
        if self.log:
            return (math.log(value) - math.log(self.low)) / (
                math.log(self.high) - math.log(self.low)
            )
        return (value - self.low) / (self.high - self.low)


class DesignSpace:
    """The varied parameters of a fixed harvester and the devices they make.

    Parameters
    ----------
    harvester : Harvester or Assembly
        Everything that is fixed (mass, mechanical damping, friction, the
        coupling's fixed values); the varied parameters' own values in it
        are ignored. A coupling's parameter (``alpha``, ``r_load``, ...)
        needs the harvester built with that coupling; without one,
        ``alpha``/``r_load``/``r_coil`` are refused with the reason.
    vary : mapping of str to (low, high)
        Parameter name (an assembly's: dotted path) -> range, in SI units
        (:mod:`randvib.quantities`), low < high, both finite.
    budget : StrokeBudget, optional
        An assembly's stroke budget (its coordinates); the single mass's is
        its own stroke.

    Raises
    ------
    ValueError
        One line naming an unknown parameter (and the allowed ones), an empty
        or non-finite range, or a range the harvester cannot take.
    """

    def __init__(self, harvester, vary: Mapping, budget: StrokeBudget | None = None):
        if not isinstance(harvester, Harvester | Assembly):
            raise ValueError(
                f"`harvester` must be a randvib Harvester or Assembly, got {harvester!r}"
            )
        if not isinstance(vary, Mapping) or not vary:
            example = "'k': (20.0, 120.0)"
            if isinstance(harvester, Assembly):
                example = "'transducer.0.c_e': (0.01, 1.0)"
            raise ValueError(
                "`vary` must name at least one parameter with its range, e.g. "
                f"{{{example}}}; got {vary!r}"
            )
        ranges = []
        for name, bounds in vary.items():
            _check_name(harvester, name)
            try:
                low, high = (float(x) for x in bounds)
            except (TypeError, ValueError):
                raise ValueError(
                    f"`vary[{name!r}]` must be a (low, high) pair of numbers, got {bounds!r}"
                ) from None
            if not (math.isfinite(low) and math.isfinite(high)) or not low < high:
                raise ValueError(
                    f"`vary[{name!r}]` = ({low!r}, {high!r}) is an empty range: "
                    "need finite low < high"
                )
            ranges.append(Range(name, low, high, low > 0 and high / low >= LOG_RATIO))
        self.harvester = harvester
        self.ranges = tuple(ranges)
        self.budget = budget
        for u in (0.0, 1.0):  # both corners must make devices (a bad coupling is named here)
            self.device(np.full(self.dimension, u))

    @property
    def dimension(self) -> int:
        return len(self.ranges)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(r.name for r in self.ranges)

    def values(self, u) -> dict[str, float]:
        """Parameter name -> value at the box point ``u``."""
        return {r.name: r.value(x) for r, x in zip(self.ranges, np.ravel(u), strict=True)}

    def coordinates(self, values: Mapping) -> np.ndarray:
        """The box point of parameter ``values``."""
        return np.array([r.coordinate(values[r.name]) for r in self.ranges])

    @property
    def is_assembly(self) -> bool:
        return isinstance(self.harvester, Assembly)

    def budget_words(self) -> str:
        """The stroke budget's event in words: ``P(|z| > 0.003 m)``, or an assembly's."""
        if self.budget is not None:
            return self.budget.words()
        return f"P(|z| > {self.harvester.stroke:g} m)"

    def device(self, u):
        """The harvester (or assembly) at the box point ``u``."""
        if self.is_assembly:
            return self.harvester.updated(self.values(u))
        return self.harvester.updated(**self.values(u))

    def builds(self, u) -> bool:
        """Whether the point ``u`` makes a device (damping, coupling values allowed)."""
        try:
            self.device(u)
        except ValueError:
            return False
        return True

    def grid(self, per_dimension: int) -> np.ndarray:
        """Every point of a regular grid of the box, shape (per_dimension^d, d)."""
        axes = [np.linspace(0.0, 1.0, per_dimension)] * self.dimension
        return np.stack([a.ravel() for a in np.meshgrid(*axes, indexing="ij")], axis=-1)


def _check_name(harvester, name) -> None:
    """Refuse a parameter the design cannot vary on ``harvester``, in one line naming it."""
    if isinstance(harvester, Assembly):
        why = vary_refusal(harvester, name)
        if why is not None:
            raise ValueError(f"`vary`: {why}")
        return
    allowed = designable_parameters(harvester)
    if name in FIXED:
        raise ValueError(
            f"`vary` cannot choose {name!r}: the design keeps the mass, the stroke and "
            f"the damping split fixed; allowed: {', '.join(allowed)}"
        )
    if name not in allowed:
        raise ValueError(f"`vary` names unknown parameter {name!r}; allowed: {', '.join(allowed)}")
