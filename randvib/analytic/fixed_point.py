"""The fixed point of statistical linearisation: Powell's hybrid method on log variances.

Shared by the Gaussian linearisation of one random input
(:mod:`randvib.analytic.statistical_linearisation`) and the combined
harmonic-and-random one (:mod:`randvib.analytic.harmonic_linearisation`):
the unknowns are logarithms of variances (and of tones' squared amplitudes),
the residual the linear response on their equivalents minus themselves.
"""

from __future__ import annotations

import numpy as np
from scipy import optimize

#: Largest |log residual| accepted as converged.
TOLERANCE = 1e-10


class LinearisationDidNotConverge(ValueError):
    """No fixed point of the statistical linearisation was found.

    A ValueError: the device and excitation admit no Gaussian linearisation
    the solver can find, and callers report it as a refusal, one line.
    """


class TrialUndefined(ArithmeticError):
    """A trial step of the solver left the region where the linearised device has a response."""


def solve(residual, x0) -> np.ndarray:
    """Root of ``residual`` (log variances) by Powell's hybrid method.

    If it stalls (a coloured spectrum can make the map stiff), damped
    fixed-point steps x <- x + r(x)/2 bring it closer and it is tried again.
    A trial step with no finite stable response ends the search: no fixed
    point was found (:class:`LinearisationDidNotConverge`).
    """
    x = np.asarray(x0, dtype=float)
    try:
        for _ in range(3):
            solution = optimize.root(residual, x, method="hybr", options={"xtol": 1e-14})
            if np.max(np.abs(residual(solution.x))) <= TOLERANCE:
                return solution.x
            for _ in range(50):
                x = x + 0.5 * residual(x)
    except TrialUndefined as trial:
        raise LinearisationDidNotConverge(
            "statistical linearisation found no fixed point: the search reached a linearised "
            f"device ({trial}) with no finite stationary response; a narrow-band excitation near the "
            "resonance of a soft or double-well device can leave the Gaussian closure without "
            "a solution: use Monte Carlo (randvib.simulate)"
        ) from None
    raise LinearisationDidNotConverge(
        "statistical linearisation did not converge (largest log-variance residual "
        f"{np.max(np.abs(residual(solution.x))):.3g}); a narrow-band excitation near the "
        "resonance can admit several solutions: use Monte Carlo (randvib.simulate)"
    )
