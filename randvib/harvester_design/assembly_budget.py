"""The stroke budget of an assembly's design: on which coordinates, and how far it is kept.

A single mass has one stroke, on z. An
:class:`~randvib.models.assembly.Assembly` carries strokes on the relative
coordinates of its elements and transducers (:meth:`Assembly.strokes`: "the
magnet relative to its host"). A design's budget ``P(|u| > stroke) <= eps``
holds on each coordinate it names (``stroke_on``: ``"element.0"``,
``"transducer.1"``); by default on every coordinate that carries a stroke,
so that every harvester of an array keeps within its own. The exceedance
the design reads is the worst of them:

* **predicted**: the largest Gaussian exceedance ``erfc(d / (sigma_u sqrt 2))``
  of the linear(ised) assembly's coordinates
  (:class:`~randvib.analytic.assembly_prediction.AssemblyPrediction`; exact
  for a linear assembly's Gaussian response);
* **Monte Carlo**: among the coordinates' estimates, the one most likely to
  break the budget, the largest lower end of its 95 % interval (the budget is
  met when every interval reaches down to it).

:func:`stroke_budget` resolves ``stroke_on`` and ``stroke`` against an
assembly, :func:`vary_refusal` says why a dotted path cannot be varied.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from randvib.models.assembly import Assembly
from randvib.models.assembly_parts import ElectricalDamper, between_words

__all__ = ["StrokeBudget", "stroke_budget", "vary_refusal"]

#: What an assembly's design never varies, with the reason.
FIXED_PATHS = {
    "structure.mass": "the masses are the device's own (a design keeps them, as the single "
    "mass's m)",
    "structure.influence": "the influence vector says how the base drives the DOFs; it is "
    "not a design choice",
}


def vary_refusal(assembly: Assembly, path) -> str | None:
    """Why the dotted ``path`` cannot be varied on ``assembly`` (one clause), or None.

    Refused: a path the assembly does not have (its message lists what it
    has), the masses and the influence vector, a stroke (the budget's, not a
    choice), and a derived parameter: a circuit's c_e follows from alpha,
    r_load and r_coil.
    """
    try:
        value = assembly.get(path)
    except ValueError as error:
        return str(error)
    for prefix, why in FIXED_PATHS.items():
        if path.startswith(prefix + "."):
            return f"{path!r} cannot be varied: {why}"
    kind, index, name = path.split(".") if path.count(".") == 2 else (None, None, None)
    if name == "stroke":
        return f"{path!r} cannot be varied: a stroke is the budget's, not a design choice"
    if kind == "transducer" and name == "c_e":
        coupling = assembly.transducers[int(index)].coupling
        if not isinstance(coupling, ElectricalDamper):
            # dotted paths: the command line would take a bare name for its own flag
            names = ", ".join(f"{kind}.{index}.{n}" for n in coupling.parameter_names())
            return (
                f"{path!r} is derived: the {coupling.name} coupling's electrical damping "
                f"follows from its circuit; vary {names} instead"
            )
    if value is None:
        return f"{path!r} has no value on this assembly"
    return None


@dataclass(frozen=True)
class StrokeBudget:
    """The coordinates of an assembly whose stroke a design's budget holds on.

    Attributes
    ----------
    paths : tuple of str
        ``element.N`` or ``transducer.N``, each with a stroke.
    strokes : dict
        Path -> stroke (m).
    betweens : dict
        Path -> its coordinate ``(i, j)``.
    """

    paths: tuple
    strokes: dict
    betweens: dict

    def words(self) -> str:
        """``P(|u| > 0.004 m) on transducer.0 [1, 0]`` (and the others): the budget in words."""
        return " and ".join(
            f"P(|u| > {self.strokes[p]:g} m) on {p} {between_words(self.betweens[p])}"
            for p in self.paths
        )

    def predicted(self, prediction) -> float:
        """The largest predicted exceedance of the coordinates (an AssemblyPrediction)."""
        worst = 0.0
        for path in self.paths:
            kind, index = path.split(".")
            parts = prediction.elements if kind == "element" else prediction.transducers
            value = parts[int(index)].stroke_exceedance
            if value is None or not math.isfinite(value):
                return math.nan
            worst = max(worst, float(value))
        return worst

    def simulated(self, result):
        """The coordinates' Monte Carlo exceedance most likely to break the budget.

        ``result`` is an assembly's Monte Carlo result: its ``elements`` and
        ``transducers`` carry ``stroke_exceedance`` ({mean, ci95}). The one
        whose 95 % interval has the largest lower end is returned.
        """
        found = []
        for path in self.paths:
            kind, index = path.split(".")
            parts = result.elements if kind == "element" else result.transducers
            found.append(parts[int(index)].stroke_exceedance)
        return max(found, key=lambda s: s.mean - s.ci95)


def stroke_budget(assembly: Assembly, stroke=None, stroke_on=None) -> tuple[Assembly, StrokeBudget]:
    """The assembly (with ``stroke`` set) and the coordinates its budget holds on.

    Parameters
    ----------
    assembly : Assembly
    stroke : float, optional
        d (m), > 0: set as the stroke of each ``stroke_on`` coordinate
        (default: the strokes the assembly carries).
    stroke_on : str or sequence of str, optional
        ``element.N`` / ``transducer.N``; default every part with a stroke.

    Raises
    ------
    ValueError
        One line: no stroke anywhere, an unknown part, a part without a
        stroke (and no ``stroke``), a bad stroke.
    """
    if isinstance(stroke_on, str):
        stroke_on = [stroke_on]
    if stroke_on is None:
        paths = [path for path, _, _ in assembly.strokes()]
        if not paths:
            raise ValueError(
                "the design's budget is on P(|u| > stroke) of a coordinate, and no element or "
                "transducer of the assembly has a stroke: give one a stroke in the device file "
                "(element.N.stroke or transducer.N.stroke)"
            )
    else:
        paths = [_part_path(assembly, p) for p in stroke_on]
        if not paths:
            raise ValueError("`stroke_on` names no coordinate: give element.N or transducer.N")
    if stroke is not None:
        assembly = assembly.updated({f"{p}.stroke": stroke for p in paths})
    strokes, betweens = {}, {}
    for path in dict.fromkeys(paths):
        kind, index = path.split(".")
        part = (assembly.elements if kind == "element" else assembly.transducers)[int(index)]
        if part.stroke is None:
            raise ValueError(
                f"`stroke_on` = {path!r} has no stroke: give {path}.stroke in the device file"
            )
        strokes[path], betweens[path] = part.stroke, part.between
    return assembly, StrokeBudget(tuple(strokes), strokes, betweens)


def _part_path(assembly: Assembly, path) -> str:
    """``element.N`` or ``transducer.N`` checked against the assembly."""
    pieces = path.split(".") if isinstance(path, str) else []
    if len(pieces) == 2 and pieces[0] in ("element", "transducer") and pieces[1].isdigit():
        parts = assembly.elements if pieces[0] == "element" else assembly.transducers
        if int(pieces[1]) < len(parts):
            return f"{pieces[0]}.{int(pieces[1])}"
        return _refuse(path, f"the assembly has {len(parts)} {pieces[0]}(s)")
    return _refuse(path, "name element.N or transducer.N")


def _refuse(path, why: str):
    raise ValueError(f"`stroke_on` = {path!r} is not a coordinate of the assembly: {why}")
