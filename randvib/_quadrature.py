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


#: Uniform panel edges on [0, X_MAX] in units of sigma (half a sigma wide).
_UNIFORM = np.arange(0.0, _X_MAX + 0.25, 0.5)


def _rule(edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Standardised nodes on the panels ``edges`` and their weights times the half-normal density."""
    lo, hi = edges[:-1], edges[1:]
    half = 0.5 * (hi - lo)
    x = ((lo + half)[:, None] + half[:, None] * _NODES[None, :]).ravel()
    w = (half[:, None] * _WEIGHTS[None, :]).ravel()
    density = 2.0 * np.exp(-0.5 * x * x) / np.sqrt(2.0 * np.pi)  # two half-lines
    weight = w * density
    x.setflags(write=False)  # the shared rules below are handed out as they are
    weight.setflags(write=False)
    return x, weight


#: The rule without refinement, and that of its panels beyond 0.5 sigma, which every
#: refined rule shares: computed once, not at every call (an ODE of the transient
#: linearisation calls this tens of thousands of times, each with a new inner scale).
_UNIFORM_RULE = _rule(_UNIFORM)
_OUTER_RULE = _rule(_UNIFORM[1:])


def _standard_rule(inner: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weighted densities on [0, X_MAX] (units of sigma), refined down to ``inner``.

    Panels geometric from ``inner`` / 1000 up to 0.5, uniform beyond.
    """
    if inner >= 0.5:
        return _UNIFORM_RULE
    geometric = np.geomspace(max(inner, 1e-300) * 1e-3, 0.5, 40)
    x, weight = _rule(np.concatenate(([0.0], geometric[:-1], _UNIFORM[1:2])))
    return np.concatenate((x, _OUTER_RULE[0])), np.concatenate((weight, _OUTER_RULE[1]))


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
    x, weight = _standard_rule(smallest)
    v = sigma[..., None] * x
    values = g(v)
    return np.sum(values * weight, axis=-1)
