"""Gaussian expectations by composite Gauss-Legendre quadrature.

Equivalent linearisation needs E[g(v)] for v ~ N(0, sigma^2) and even g
(g(v) = v F(v) with F odd). Gauss-Hermite rules are inaccurate here because
g has a kink at v = 0 (Coulomb: g = Fc |v|) or a boundary layer of width
1/beta (tanh friction with beta ~ 1e9 s/m). We integrate over v >= 0 only, on
panels that are geometric near zero (resolving any inner scale) and uniform
further out, with a 20-point Gauss-Legendre rule on each panel; the integrand
is then smooth on every panel and the rule is accurate to rounding for
polynomial-times-Gaussian integrands.
"""

from __future__ import annotations

import numpy as np

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(20)
#: Standardised upper limit: the Gaussian tail beyond 40 sigma is exp(-800).
_X_MAX = 40.0


def _panels(inner: float) -> np.ndarray:
    """Panel edges on [0, X_MAX] in units of sigma."""
    uniform = np.arange(0.0, _X_MAX + 0.25, 0.5)
    if inner >= 0.5:
        return uniform
    geometric = np.geomspace(max(inner, 1e-300) * 1e-3, 0.5, 40)
    return np.concatenate(([0.0], geometric[:-1], uniform[1:]))


def gaussian_even_expectation(g, sigma, inner_scale=None) -> np.ndarray:
    """E[g(v)] for v ~ N(0, sigma^2) and even g, broadcasting over ``sigma``.

    Parameters
    ----------
    g : callable
        Even function, vectorised over numpy arrays; it may close over arrays
        that broadcast with ``sigma``.
    sigma : array_like
        Standard deviation(s), > 0.
    inner_scale : array_like, optional
        Length scale of fine structure near v = 0 (same units as v); panels
        are refined down to it.
    """
    sigma = np.asarray(sigma, dtype=float)
    ratio = 1.0 if inner_scale is None else np.asarray(inner_scale, dtype=float) / sigma
    smallest = float(np.min(ratio)) if np.size(ratio) else 1.0
    edges = _panels(smallest)
    lo, hi = edges[:-1], edges[1:]
    half = 0.5 * (hi - lo)
    x = (lo + half)[:, None] + half[:, None] * _NODES[None, :]  # standardised nodes
    w = (half[:, None] * _WEIGHTS[None, :]).ravel()
    x = x.ravel()
    density = 2.0 * np.exp(-0.5 * x * x) / np.sqrt(2.0 * np.pi)  # two half-lines
    v = sigma[..., None] * x
    values = g(v)
    return np.sum(values * (w * density), axis=-1)
