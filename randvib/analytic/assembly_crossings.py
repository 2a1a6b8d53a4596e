"""Exceedance and crossing rate of one coordinate of a linear assembly: the exact anchors.

A linear assembly (:attr:`randvib.models.assembly.Assembly.is_linear`: no
k2, k3, acting friction or diode bridge; any structure, dashpots, linear
springs and circuits) under stationary Gaussian input has a Gaussian
response, so for the relative coordinate u = d^T x of an element or a
transducer (``stroke_on``: ``element.N`` or ``transducer.N``), with
sigma_u^2 = d^T P_xx d and sigma_u'^2 = d^T P_vv d from the Lyapunov
covariance P (:func:`randvib.analytic.assembly_linear.linear_response`):

* P(|u| > D) = erfc(D / (sigma_u sqrt 2)) - **exact**;
* Rice's rate of up-crossings of |u| through D, both ends,
  nu = (sigma_u' / (pi sigma_u)) exp(-D^2 / (2 sigma_u^2)) - **exact** (u
  and u' are jointly Gaussian and uncorrelated in the stationary state);
* the first passage within T from the stationary state: the bounds
  P0 <= P <= P0 + nu T and Poisson's 1 - (1 - P0) exp(-nu T) (approximate:
  independent crossings, conservative for a narrow-band coordinate).
  Vanmarcke's correction is not given here (it needs the coordinate's
  spectral bandwidth, which a single mass has from its oscillator).

These are the references of :func:`randvib.first_passage` on an assembly
(:mod:`randvib.montecarlo.assembly_paths`); its discrete paths at a step dt
have their own exact law (the scheme's discrete Lyapunov covariance), which
tends to this one as dt -> 0.
"""

from __future__ import annotations

import math

from scipy import special

from randvib._validation import check_positive
from randvib.analytic.assembly_linear import linear_response
from randvib.analytic.crossings import CrossingPrediction, _from_rates
from randvib.analytic.first_passage import outcrossing_rate
from randvib.models.assembly import Assembly
from randvib.models.excitation import Measured, as_excitation

__all__ = ["assembly_crossing_prediction", "stroke_coordinate"]

#: What the anchor gives exactly.
EXACT = ("stationary_exceedance", "upcrossing_rate")


def stroke_coordinate(assembly: Assembly, stroke_on=None, stroke=None) -> tuple[str, float]:
    """(``element.N`` or ``transducer.N``, D (m)): the monitored coordinate and its stroke.

    ``stroke_on`` names it; by default the one part of the assembly that
    carries a stroke. ``stroke`` (m) overrides the part's own. One-line
    ValueErrors name the argument and what is allowed.
    """
    carried = [path for path, _, _ in assembly.strokes()]
    if stroke_on is None:
        if len(carried) != 1:
            have = ", ".join(carried) if carried else "none carries one"
            raise ValueError(
                "`stroke_on` must name the coordinate whose stroke is monitored (element.N or "
                f"transducer.N) when the assembly does not carry exactly one stroke ({have})"
            )
        stroke_on = carried[0]
    pieces = stroke_on.split(".") if isinstance(stroke_on, str) else []
    if not (len(pieces) == 2 and pieces[0] in ("element", "transducer") and pieces[1].isdigit()):
        raise ValueError(f"`stroke_on` must be element.N or transducer.N, got {stroke_on!r}")
    parts = assembly.elements if pieces[0] == "element" else assembly.transducers
    index = int(pieces[1])
    if index >= len(parts):
        raise ValueError(
            f"`stroke_on` = {stroke_on!r} is not a coordinate of the assembly: it has "
            f"{len(parts)} {pieces[0]}(s)"
        )
    if stroke is None:
        stroke = parts[index].stroke
        if stroke is None:
            raise ValueError(
                f"`stroke` is needed: {pieces[0]}.{index} carries no stroke in the device file"
            )
    stroke = float(check_positive("stroke", stroke, "m"))
    return f"{pieces[0]}.{index}", stroke


def assembly_crossing_prediction(
    assembly: Assembly, excitation, stroke=None, duration=1.0, stroke_on=None
) -> CrossingPrediction:
    """The exact exceedance and Rice rate of a linear assembly's coordinate (module docstring).

    Parameters
    ----------
    assembly : Assembly
        A linear one (refused otherwise, in one line).
    excitation : float or Excitation
        White-noise level S or any stationary Gaussian spectrum (a record
        through its Welch spectrum).
    stroke : float, optional
        D (m); default the coordinate's own stroke.
    duration : float
        The window T (s) of the first-passage approximations.
    stroke_on : str, optional
        ``element.N`` or ``transducer.N`` (:func:`stroke_coordinate`).

    Returns
    -------
    CrossingPrediction
        ``method`` "rice"; ``first_passage_vanmarcke`` None.
    """
    if not isinstance(assembly, Assembly):
        raise ValueError(f"`assembly` must be a randvib.Assembly, got {type(assembly).__name__}")
    if not assembly.is_linear:
        raise ValueError(
            "the exact crossing anchors need a linear assembly (no k2, k3, acting friction or "
            "diode bridge): the response is Gaussian only then; use randvib.first_passage"
        )
    path, stroke = stroke_coordinate(assembly, stroke_on, stroke)
    duration = float(check_positive("duration", duration, "s"))
    excitation = as_excitation(excitation)
    if isinstance(excitation, Measured):
        excitation = excitation.spectrum
    kind, index = path.split(".")
    part = (assembly.elements if kind == "element" else assembly.transducers)[int(index)]
    u2, v2 = linear_response(assembly, excitation).coordinate_variances(part)
    p0 = float(special.erfc(stroke / math.sqrt(2.0 * u2)))
    rate = float(outcrossing_rate(u2, 0.0, v2, stroke))
    return _from_rates("rice", stroke, duration, p0, rate, None, EXACT)
