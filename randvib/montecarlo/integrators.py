"""Stochastic integrators for the white-noise driven harvester: a table of schemes.

The device SDE (docs/conventions.md) has additive noise,

    dz = v dt,   dv = a(z, v, theta) dt + sqrt(S/2) dW,   dtheta = r(v, theta) dt,

so Ito and Stratonovich solutions coincide and stochastic Heun (a
Stratonovich scheme) is consistent for it. Each scheme declares its orders for
additive noise and smooth drift and its step as a table of stage weights
(:class:`Integrator`); the compiled kernel and the exact linear recursions
read that table. Non-smooth drifts (Coulomb friction) lower the observed
orders.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg

from randvib._validation import check_choice


@dataclass(frozen=True)
class Integrator:
    """Declaration of a fixed-step SDE scheme: its orders and its step, as data.

    Both schemes belong to one family of additive-noise predictor-corrector
    steps with drift ``f`` and noise increment ``g dW``:

        x_p     = x_n + f(x_n) dt + g dW_n                 (Euler predictor)
        x_{n+1} = x_n + (b_1 f(x_n) + b_2 f(x_p)) dt + g dW_n

    so a scheme is its weights ``(b_1, b_2)`` (``b_2 = 0``: no predictor
    stage). The compiled kernel (:func:`randvib.montecarlo.kernel.scheme_step`) takes the
    weights, the device and its friction-free companion use the same step, and
    :meth:`linear_recursion` gives the exact recursion of the same step on a
    linear system (the tests' exact discrete references).

    Attributes
    ----------
    name : str
        Name used by ``simulate(scheme=...)`` and the CLI (``--method``).
    strong_order : float
        Strong (pathwise) order for additive noise and smooth drift.
    weak_order : float
        Weak order (of moments) for additive noise and smooth drift.
    calculus : str
        ``"ito"`` or ``"stratonovich"``; equivalent here as the noise is additive.
    weights : tuple of float
        Drift weights ``(b_1,)`` or ``(b_1, b_2)`` of the stages; they sum to 1.
    """

    name: str
    strong_order: float
    weak_order: float
    calculus: str
    weights: tuple[float, ...]

    @property
    def drift_evaluations(self) -> int:
        """Drift evaluations per step (cost)."""
        return len(self.weights)

    @property
    def kernel_weights(self) -> tuple[float, float]:
        """``(b_1, b_2)`` for the compiled step, ``b_2 = 0`` for one stage."""
        return (float(self.weights[0]), float(self.weights[1]) if len(self.weights) > 1 else 0.0)

    def linear_recursion(self, drift_matrix, noise_matrix, dt):
        """Exact recursion of this step on a linear SDE ``dx = F x dt + G dW``.

        Writing the two stages out for ``f(x) = F x`` gives
        ``x_{n+1} = A x_n + B dW_n`` with
        ``A = I + (b_1 + b_2) dt F + b_2 dt^2 F^2`` and ``B = (I + b_2 dt F) G``.

        Parameters
        ----------
        drift_matrix : ndarray, shape (d, d)
            ``F``.
        noise_matrix : ndarray, shape (d, q)
            ``G``.
        dt : float
            Step (s).

        Returns
        -------
        A : ndarray, shape (d, d)
        B : ndarray, shape (d, q)
        """
        f = np.asarray(drift_matrix, dtype=float)
        g = np.asarray(noise_matrix, dtype=float)
        b1, b2 = self.kernel_weights
        eye = np.eye(f.shape[0])
        a = eye + (b1 + b2) * dt * f + b2 * dt * dt * f @ f
        return a, (eye + b2 * dt * f) @ g


#: Euler-Maruyama: x_{n+1} = x_n + f(x_n) dt + g dW_n. With additive noise its
#: strong order rises from 1/2 to 1 (Kloeden & Platen 1992, Sec. 10.2).
EULER_MARUYAMA = Integrator("euler-maruyama", 1.0, 1.0, "ito", (1.0,))

#: Stochastic Heun (Euler predictor, trapezoidal corrector). For additive noise
#: it is strong order 1 and weak order 2 (Kloeden & Platen 1992, Sec. 15.1;
#: Rumelin 1982).
HEUN = Integrator("heun", 1.0, 2.0, "stratonovich", (0.5, 0.5))

#: The integration schemes by name (``euler-maruyama``, ``heun``), as ``scheme=`` takes them.
INTEGRATORS = {i.name: i for i in (EULER_MARUYAMA, HEUN)}


def integrator(name: str, argument: str = "scheme") -> Integrator:
    """Look up an integrator by name (``euler-maruyama`` or ``heun``).

    ``argument`` is the keyword named in the error message for an unknown name.
    """
    check_choice(argument, name, tuple(INTEGRATORS))
    return INTEGRATORS[name]


def scheme_matrices(scheme: str, m, c, k, psd, dt):
    """Transition matrix A and noise matrix B of a scheme on the linear oscillator.

    The recursion is x_{n+1} = A x_n + B dW_n with x = (z, v), dW_n ~ N(0, dt),
    from the scheme's own step table
    (:meth:`randvib.montecarlo.integrators.Integrator.linear_recursion`). Euler-Maruyama:
    A = I + dt F. Heun: A = I + dt F + dt^2 F^2 / 2 and B = (I + dt F / 2) b.
    """
    f = np.array([[0.0, 1.0], [-k / m, -c / m]])
    b = np.array([[0.0], [np.sqrt(psd / 2.0)]])
    return integrator(scheme).linear_recursion(f, b, dt)


def scheme_stationary_covariance(scheme: str, m, c, k, psd, dt) -> np.ndarray:
    """Exact stationary covariance of (z, v) for a scheme on the linear oscillator.

    Solves P = A P A^T + dt B B^T. Raises if the recursion is unstable
    (spectral radius of A >= 1), where no stationary state exists.
    """
    a, b = scheme_matrices(scheme, m, c, k, psd, dt)
    radius = max(abs(np.linalg.eigvals(a)))
    if radius >= 1:
        raise ValueError(
            f"{scheme} with dt = {dt!r} s is unstable for this oscillator "
            f"(spectral radius {radius:.6g} >= 1)"
        )
    return linalg.solve_discrete_lyapunov(a, dt * (b @ b.T))
