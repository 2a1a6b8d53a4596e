"""Exceedance, crossing rate and first passage of the stroke: the analytic anchors, as a family.

Each :class:`CrossingMethod` declares which cases it takes and what it gives
exactly, as the power methods of :mod:`randvib.analytic.method` do, and
returns a :class:`CrossingPrediction` for a stroke D and a window T:

* ``gibbs`` - white noise, linear damping, no friction, a resistive coupling,
  any confining potential: the stationary density is Gibbs's
  (:class:`~randvib.analytic.gibbs_marginal.GibbsDisplacement`), so
  P(|z| > D) and the up-crossing rate of |z| through D,
  2 p_z(D) sigma_v / sqrt(2 pi) (Rice, exact: z' is Gaussian and independent
  of z), are **exact** at every level;
* ``rice`` - a linear device (k > 0, k3 = 0, no friction, no bridge; any
  coupling) under any spectrum: z Gaussian, so P(|z| > D) =
  erfc(D / (sigma_z sqrt 2)) and Rice's rate 2 (sigma_v / (2 pi sigma_z))
  exp(-D^2 / (2 sigma_z^2)) are **exact**, sigma_z and sigma_v from the
  linear response (:func:`randvib.analytic.linear_response.output_variances`);
* ``gaussian`` - the Gaussian answer the design search uses
  (:mod:`randvib.harvester_design.search`): statistical linearisation's (or
  the bridge closure's) sigma_z, sigma_v and equivalent oscillator; approximate.

The first passage within T from the stationary state is never exact here:
every method gives the bounds P(|z(0)| > D) <= P <= P(|z(0)| > D) + nu T,
the **Poisson** approximation 1 - (1 - P0) exp(-nu T) (independent crossings;
conservative for a narrow-band response, whose crossings come in clumps) and,
where the response is Gaussian, **Vanmarcke**'s (the hazard of
:func:`randvib.analytic.first_passage.vanmarcke_hazard`, with the spectral
bandwidth of the linear(ised) oscillator: the approximation the design's
first-passage constraint uses).

:func:`gaussian_chain_upcrossing_rate` is the exact crossing rate of a
stationary Gaussian sequence sampled at dt, the reference for a scheme's own
discrete paths of a linear device.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import integrate, special

from randvib._validation import check_positive
from randvib.analytic.first_passage import outcrossing_rate, spectral_bandwidth, vanmarcke_hazard
from randvib.analytic.gibbs_marginal import GibbsDisplacement
from randvib.analytic.linear_response import device_block, mechanical_block, output_variances
from randvib.analytic.method import Validity
from randvib.models.excitation import Measured, as_excitation
from randvib.models.harvester import Harvester

__all__ = [
    "CROSSING_METHODS",
    "CrossingMethod",
    "CrossingPrediction",
    "crossing_prediction",
    "gaussian_chain_upcrossing_rate",
]


class GaussianTailWarning(RuntimeWarning):
    """A Gaussian answer for a nonlinear device far in the tail, where it is least reliable."""


@dataclass(frozen=True)
class CrossingPrediction:
    """Stationary exceedance, crossing rate and first-passage approximations of a stroke.

    Attributes
    ----------
    method : str
    stroke, duration : float
        D (m) and the window T (s).
    stationary_exceedance : float
        P(|z| > D).
    upcrossing_rate : float
        Mean up-crossings of |z| through D per second, both ends (1/s).
    first_passage_poisson : float
        1 - (1 - P0) exp(-nu T).
    first_passage_vanmarcke : float or None
        1 - (1 - P0) exp(-h T) with Vanmarcke's hazard h; None where the
        response is not Gaussian.
    first_passage_bounds : (float, float)
        P0 <= P(reached within T) <= min(1, P0 + nu T).
    exact : tuple of str
        The attributes that are exact for this case.
    """

    method: str
    stroke: float
    duration: float
    stationary_exceedance: float
    upcrossing_rate: float
    first_passage_poisson: float
    first_passage_vanmarcke: float | None
    first_passage_bounds: tuple
    exact: tuple

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def _from_rates(method, stroke, duration, p0, rate, hazard, exact) -> CrossingPrediction:
    """The prediction from the exceedance P0, Rice's rate and (optional) Vanmarcke's hazard."""
    survive = 1.0 - p0
    return CrossingPrediction(
        method=method,
        stroke=stroke,
        duration=duration,
        stationary_exceedance=float(p0),
        upcrossing_rate=float(rate),
        first_passage_poisson=float(1.0 - survive * math.exp(-rate * duration)),
        first_passage_vanmarcke=None
        if hazard is None
        else float(1.0 - survive * math.exp(-hazard * duration)),
        first_passage_bounds=(float(p0), float(min(1.0, p0 + rate * duration))),
        exact=exact,
    )


class CrossingMethod:
    """Base class of the crossing anchors: a declaration and :meth:`solve` (module docstring)."""

    name = "crossings"
    title = ""
    #: The quantities it gives exactly (``stationary_exceedance``, ``upcrossing_rate``).
    exact: tuple = ()
    validity: tuple = ()

    def refusal(self, harvester: Harvester, excitation) -> str | None:  # pragma: no cover
        """Why it does not take the case (one line), or None."""
        raise NotImplementedError

    def accepts(self, harvester: Harvester, excitation) -> bool:
        return self.refusal(harvester, as_excitation(excitation)) is None

    def solve(self, harvester, excitation, stroke, duration) -> CrossingPrediction:
        """The prediction for stroke D (m) and window T (s); ValueError if refused."""
        excitation = as_excitation(excitation)
        if isinstance(excitation, Measured):
            excitation = excitation.spectrum
        refusal = self.refusal(harvester, excitation)
        if refusal is not None:
            raise ValueError(f"method={self.name!r} {refusal}")
        stroke = float(check_positive("stroke", stroke, "m"))
        duration = float(check_positive("duration", duration, "s"))
        return self._solve(harvester, excitation, stroke, duration)

    def _solve(self, harvester, excitation, stroke, duration):  # pragma: no cover
        raise NotImplementedError


def _frictionless(h: Harvester) -> bool:
    return h.friction is None or h.friction.vanishes


class GibbsCrossings(CrossingMethod):
    """Exact anchors of a friction-free device under white noise (Gibbs density)."""

    name = "gibbs"
    title = "the exact Gibbs density"
    exact = ("stationary_exceedance", "upcrossing_rate")
    validity = (
        Validity(
            "friction_power_share", 0.0, "refuses",
            "E[v F] / (m S / 4), the input power friction dissipates: the Gibbs density holds "
            "only without friction (and with white noise, linear damping, a resistive coupling)",
        ),
    )  # fmt: skip

    def refusal(self, harvester, excitation) -> str | None:
        if not excitation.is_white:
            return f"needs white noise; the {excitation.name} input has no Gibbs density"
        if not _frictionless(harvester):
            return f"needs a device without friction; {harvester.friction.name!r} dissipates"
        if harvester.has_circuit or harvester.is_rectified:
            return "needs a resistive coupling (viscous c_e); a circuit state has no Gibbs density"
        if not harvester.potential.is_confining or not harvester.c > 0:
            return "needs a confining potential and linear damping c > 0"
        return None

    def _solve(self, harvester, excitation, stroke, duration):
        h = harvester
        g = GibbsDisplacement(h.m, h.c, h.k, h.k3, excitation.level)
        p0 = float(g.exceedance(stroke))
        rate = float(g.upcrossing_rate(stroke))
        return _from_rates(self.name, stroke, duration, p0, rate, None, self.exact)


def _gaussian_rates(z2, v2, stroke, block, excitation):
    """(P0, Rice's rate, Vanmarcke's hazard) of a Gaussian (z, z') with these variances."""
    p0 = float(special.erfc(stroke / math.sqrt(2.0 * z2)))
    rate = float(outcrossing_rate(z2, 0.0, v2, stroke))
    hazard = None
    if block is not None and rate > 0:
        q = spectral_bandwidth(block, excitation)
        hazard = float(vanmarcke_hazard(rate, z2, stroke, q))
    return p0, rate, hazard


class RiceLinear(CrossingMethod):
    """Exact anchors of a linear device under any spectrum (Gaussian response, Rice)."""

    name = "rice"
    title = "Rice's formula for the linear device"
    exact = ("stationary_exceedance", "upcrossing_rate")
    validity = (
        Validity(
            "k3_over_k", 0.0, "refuses",
            "the cubic stiffness relative to the linear one: the response is Gaussian only for "
            "a linear spring (and without friction or a diode bridge)",
        ),
    )  # fmt: skip

    def refusal(self, harvester, excitation) -> str | None:
        h = harvester
        if not (np.all(h.k3 == 0) and np.all(h.k > 0)):
            return "needs a linear spring (k > 0, k3 = 0): the response is Gaussian only then"
        if not _frictionless(h) or h.is_rectified:
            return (
                "needs a linear device: friction and diode bridges make the response non-Gaussian"
            )
        return None

    def _solve(self, harvester, excitation, stroke, duration):
        h = harvester
        block = device_block(float(h.m), float(h.c), float(h.k), h.electrical)
        var = output_variances(block, excitation)
        p0, rate, hazard = _gaussian_rates(var["z"], var["v"], stroke, block, excitation)
        return _from_rates(self.name, stroke, duration, p0, rate, hazard, self.exact)


class GaussianLinearised(CrossingMethod):
    """The design search's Gaussian answer: statistical linearisation (bridge closure)."""

    name = "gaussian"
    title = "the Gaussian (linearised) response"
    exact = ()
    validity = (
        Validity(
            "stroke_over_sigma_z", 3.0, "warns",
            "D / sigma_z of a nonlinear device: beyond about three standard deviations its tail "
            "departs from the Gaussian one (randvib.first_passage estimates it)",
        ),
    )  # fmt: skip

    def refusal(self, harvester, excitation) -> str | None:
        from randvib.analytic.prediction import METHODS

        name = "bridge-closure" if harvester.is_rectified else "linearisation"
        return METHODS[name].refusal(harvester, excitation)

    def _solve(self, harvester, excitation, stroke, duration):
        from randvib.analytic.prediction import predict

        h = harvester
        name = "bridge-closure" if h.is_rectified else "linearisation"
        prediction = predict(h, excitation, name)
        z2 = float(prediction.displacement_variance)
        v2 = float(prediction.velocity_variance)
        k_eq = float(h.k) + 3.0 * float(h.k3) * z2
        block = mechanical_block(float(h.m), float(prediction.c_eq), k_eq) if k_eq > 0 else None
        linear = np.all(h.k3 == 0) and _frictionless(h) and not h.is_rectified
        if not linear and stroke > self.validity[0].limit * math.sqrt(z2):
            warnings.warn(
                f"the Gaussian answer at D = {stroke / math.sqrt(z2):.3g} sigma_z of a nonlinear "
                "device is outside its validity (<= 3 sigma_z): use randvib.first_passage",
                GaussianTailWarning,
                stacklevel=3,
            )
        p0, rate, hazard = _gaussian_rates(z2, v2, stroke, block, excitation)
        return _from_rates(self.name, stroke, duration, p0, rate, hazard, self.exact)


#: The crossing anchors by name, the exact ones first.
CROSSING_METHODS = {m.name: m for m in (GibbsCrossings(), RiceLinear(), GaussianLinearised())}


def crossing_prediction(harvester, excitation, stroke, duration, method=None):
    """The first of :data:`CROSSING_METHODS` that takes the case (or ``method``, by name)."""
    excitation = as_excitation(excitation)
    if method is not None:
        if method not in CROSSING_METHODS:
            raise ValueError(
                f"`method` must be one of {', '.join(map(repr, CROSSING_METHODS))}, got {method!r}"
            )
        return CROSSING_METHODS[method].solve(harvester, excitation, stroke, duration)
    for m in CROSSING_METHODS.values():
        if m.accepts(harvester, excitation):
            return m.solve(harvester, excitation, stroke, duration)
    raise ValueError(
        "no crossing anchor takes this device and input (friction or a bridge under "
        "coloured input beyond linearisation): use randvib.first_passage"
    )


def gaussian_chain_upcrossing_rate(variance, lag_covariance, dt, stroke) -> float:
    """Mean rate (1/s) of steps on which |x| rises through D, for a stationary Gaussian sequence.

    x_n zero-mean, E[x_n^2] = ``variance``, E[x_n x_(n+1)] = ``lag_covariance``,
    sampled every ``dt`` (s): P(|x_n| <= D, |x_(n+1)| > D) / dt, by quadrature
    of the conditional law of x_(n+1) given x_n (to relative precision 1e-10
    at any level). The exact reference for a linear device's discrete paths
    (a scheme's stationary covariance and its one-step transition).
    """
    s = math.sqrt(float(check_positive("variance", variance)))
    dt = float(check_positive("dt", dt, "s"))
    d = float(check_positive("stroke", stroke, "m"))
    rho = float(lag_covariance) / (s * s)
    sc = s * math.sqrt(max(1.0 - rho * rho, 0.0))
    if not sc > 0:
        return 0.0

    def integrand(x):  # symmetric in x: both ends of the stroke
        density = math.exp(-0.5 * (x / s) ** 2) / (s * math.sqrt(2.0 * math.pi))
        return density * (special.ndtr((rho * x - d) / sc) + special.ndtr((-rho * x - d) / sc))

    # the mass sits within a few conditional spreads of x = D: break the range there
    points = sorted({max(0.0, d - j * sc / max(abs(rho), 1e-12)) for j in (1, 3, 10, 30)})
    value = integrate.quad(integrand, 0.0, d, points=points, epsabs=0.0, epsrel=1e-10, limit=400)
    return 2.0 * value[0] / dt
