"""Stochastic integrators for the white-noise driven harvester: a table of methods.

The device SDE (docs/conventions.md) has additive noise,

    dz = v dt,   dv = a(z, v, theta) dt + sqrt(S/2) dW,   dtheta = r(v, theta) dt,

so Ito and Stratonovich solutions coincide and stochastic Heun (a
Stratonovich scheme) is consistent for it. Each method declares its orders for
additive noise and smooth drift; the kernels in :mod:`randvib.engine` run the
method selected by ``kernel_code``. Non-smooth drifts (Coulomb friction) lower
the observed orders.
"""

from __future__ import annotations

from dataclasses import dataclass

from randvib._validation import check_choice


@dataclass(frozen=True)
class Integrator:
    """Declaration of a fixed-step SDE scheme.

    Attributes
    ----------
    name : str
        Name used by ``simulate(method=...)`` and the CLI.
    strong_order : float
        Strong (pathwise) order for additive noise and smooth drift.
    weak_order : float
        Weak order (of moments) for additive noise and smooth drift.
    calculus : str
        ``"ito"`` or ``"stratonovich"``; equivalent here as the noise is additive.
    drift_evaluations : int
        Drift evaluations per step (cost).
    kernel_code : int
        Branch of the compiled step in :mod:`randvib.engine`.
    """

    name: str
    strong_order: float
    weak_order: float
    calculus: str
    drift_evaluations: int
    kernel_code: int


#: Euler-Maruyama: x_{n+1} = x_n + f(x_n) dt + g dW_n. With additive noise its
#: strong order rises from 1/2 to 1 (Kloeden & Platen 1992, Sec. 10.2).
EULER_MARUYAMA = Integrator("euler-maruyama", 1.0, 1.0, "ito", 1, 0)

#: Stochastic Heun (predictor-corrector trapezoid). For additive noise it is
#: strong order 1 and weak order 2 (Kloeden & Platen 1992, Sec. 15.1; Rumelin 1982).
HEUN = Integrator("heun", 1.0, 2.0, "stratonovich", 2, 1)

INTEGRATORS = {i.name: i for i in (EULER_MARUYAMA, HEUN)}


def integrator(name: str) -> Integrator:
    """Look up an integrator by name (``euler-maruyama`` or ``heun``)."""
    check_choice("method", name, tuple(INTEGRATORS))
    return INTEGRATORS[name]
