"""The most power any device of a given mass can harvest under a stroke budget.

A transducer of any kind (linear or not, causal or not, passive or active) on
a mass m with mechanical damping c_m, whose stationary displacement z keeps
E[z^2] <= sigma^2, under a stationary base acceleration a of one-sided PSD
G_a(f), harvests at most (docs/conventions.md, "The limit")

    P_max(sigma) = min_{lambda >= 0} [ int_0^inf m^2 w^2 G_a / (4 (c_m w^2 + lambda)) df
                                        + lambda sigma^2 ],     w = 2 pi f.

Derivation: stationary energy balance gives P <= -m E[a z'] - c_m E[z'^2]
(the spring stores nothing on average, friction only dissipates); by
Cauchy-Schwarz on the cross-spectrum, -m E[a z'] <= m int sqrt(G_a G_z') df
with G_z' = w^2 G_z; for each lambda >= 0 the Lagrangian is maximised
frequency by frequency at sqrt(G_z) = m w sqrt(G_a) / (2 (c_m w^2 + lambda)),
which gives the bracket (weak duality: every lambda gives a bound; the
minimising one is the tightest, and equals the maximum over all cross-spectra
with coherence 1). This is the variance-constrained form of the bound of
Halvorsen, Phys. Rev. E 87, 042129 (2013), for a velocity-damped mass, and
the stationary-spectrum counterpart of the non-causal bound of Haji
Hosseinloo and Turitsyn, Phys. Rev. Applied 4, 064009 (2015). With lambda = 0
it is the unconstrained bound m^2 E[a^2] / (4 c_m).

It is finite when w^2 G_a / (c_m w^2 + lambda) is integrable: for band-pass,
Kanai-Tajimi, band-limited, tabulated and measured spectra with c_m > 0; for
white noise it is infinite (an ideal transducer can take unbounded power
from white acceleration), and :func:`harvesting_limit` returns None.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize, special

from randvib._validation import check_nonnegative, check_positive
from randvib.analytic.linear_response import frequency_rule, mechanical_block
from randvib.models.excitation import Excitation

__all__ = ["gaussian_displacement_budget", "harvesting_limit"]


def gaussian_displacement_budget(stroke, exceedance) -> float:
    """The largest displacement RMS sigma_z with ``P(|z| > stroke) <= exceedance`` for Gaussian z.

    sigma_z = stroke / Phi^-1(1 - exceedance / 2) (docs/conventions.md,
    "Gaussian stroke budget").

    Parameters
    ----------
    stroke : float
        Stroke d (m), > 0.
    exceedance : float
        Budget eps, 0 < eps < 1.
    """
    stroke = float(check_positive("stroke", stroke, "m"))
    eps = float(exceedance)
    if not 0.0 < eps < 1.0:
        raise ValueError(f"`exceedance` must be a probability in (0, 1), got {exceedance!r}")
    return stroke / (math.sqrt(2.0) * special.erfcinv(eps))


def _weights(m, c_m, excitation: Excitation, corner: float):
    """Nodes f (Hz), weights and m^2 w^2 G_a / 4 on a rule resolving the spectrum and the corner."""
    # A critically damped unit block with its poles at the corner frequency
    # sqrt(lambda / c_m): the rule then has panels there as well as at the
    # spectrum's peaks and kinks (Gauss-Legendre panels, mapped infinite tail).
    w_c = 2.0 * np.pi * max(corner, 1e-6)
    nodes, weights = frequency_rule(mechanical_block(1.0, 2.0 * w_c, w_c**2), excitation)
    w = 2.0 * np.pi * nodes
    return w, weights, m**2 * w**2 * excitation.psd(nodes) / 4.0


def harvesting_limit(m, c_m, excitation: Excitation, displacement_rms) -> float | None:
    """Upper bound on the harvested power of any device with E[z^2] <= sigma^2 (W).

    Parameters
    ----------
    m : float
        Moving mass (kg), > 0.
    c_m : float
        Mechanical viscous damping (Ns/m), >= 0. With c_m = 0 the bound is
        m sigma sqrt(E[a'^2]), finite only for a spectrum of bounded support.
    excitation : Excitation
        The base acceleration's spectrum (one-sided, (m/s^2)^2/Hz).
    displacement_rms : float
        sigma (m), > 0; for a stroke budget see :func:`gaussian_displacement_budget`.

    Returns
    -------
    float or None
        P_max (W); None where no finite bound exists (white noise; c_m = 0
        with a spectrum of unbounded support).
    """
    m = float(check_positive("m", m, "kg"))
    c_m = float(check_nonnegative("c_m", c_m, "Ns/m"))
    sigma2 = float(check_positive("displacement_rms", displacement_rms, "m")) ** 2
    if excitation.is_white:
        return None

    def dual(lam: float) -> tuple[float, float]:
        """The bound at lambda and its derivative sigma^2 - int s*^2 df."""
        corner = math.sqrt(lam / c_m) / (2 * math.pi) if c_m > 0 and lam > 0 else 1.0
        w, weights, g = _weights(m, c_m, excitation, corner)
        denom = c_m * w**2 + lam
        bound = float(np.sum(weights * g / denom)) + lam * sigma2
        return bound, sigma2 - float(np.sum(weights * g / denom**2))

    if c_m == 0:
        # The bracket is int g / lambda + lambda sigma^2, least at
        # lambda = sqrt(int g / sigma^2): P_max = m sigma sqrt(E[a'^2]), finite
        # only for a spectrum of bounded support.
        if not math.isfinite(excitation.support[1]):
            return None
        w, weights, g = _weights(m, c_m, excitation, 1.0)
        return 2.0 * math.sqrt(sigma2 * float(np.sum(weights * g)))
    value, slope = dual(0.0)
    if slope >= 0:  # the unconstrained optimum already meets the budget
        return value
    # lambda where the derivative vanishes (it increases with lambda)
    hi = c_m * (2 * math.pi) ** 2
    while dual(hi)[1] < 0:
        hi *= 10.0
    lam = optimize.brentq(lambda x: dual(x)[1], 0.0, hi, xtol=1e-300, rtol=1e-12)
    return dual(lam)[0]
