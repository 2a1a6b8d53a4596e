"""Friction models of the paper (Eq. 4-10) behind one interface.

Every model is a small immutable class with

* ``force(v, theta=None)`` - the friction force F (N) for relative velocity
  ``v`` (m/s), vectorised with numpy; ``theta`` is the internal state for
  models that have one (LuGre's bristle deflection, m);
* ``n_states`` - number of internal states (0 for memoryless models);
* ``mean_velocity_force(sigma_v)`` - E[v F(v)] for a zero-mean Gaussian
  velocity of standard deviation ``sigma_v``; this is what equivalent
  linearisation needs (paper Eq. 19). Memoryless odd models get it by
  quadrature, Coulomb in closed form; LuGre has no such expectation because
  its force depends on the velocity history, and raises.
* ``kernel_code`` and ``kernel_parameters()`` - how the compiled integrators
  evaluate the model: one integer and a fixed-length parameter vector handed to
  :func:`friction_force_and_rate`. A new model is one new class plus one branch
  there; the integrators themselves never change.

Parameters may be numpy arrays: the analytic methods broadcast over them.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numba
import numpy as np

from randvib import _quadrature
from randvib._validation import check_nonnegative, check_positive, scalar_or_array

#: Length of the parameter vector handed to the compiled kernels.
N_KERNEL_PARAMETERS = 5

KERNEL_NONE = 0
KERNEL_COULOMB = 1
KERNEL_TANH = 2
KERNEL_LUGRE = 3


class FrictionModel:
    """Base class: the interface every friction model implements."""

    #: Number of internal state variables the model carries.
    n_states: int = 0
    #: Integer selecting the branch of :func:`friction_force_and_rate`.
    kernel_code: int = KERNEL_NONE
    #: Whether ``mean_velocity_force`` is defined (memoryless odd models).
    has_equivalent_damping: bool = True
    #: Short name used by the CLI, presets and tables.
    name: str = "friction"

    def force(self, v, theta=None):  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def vanishes(self) -> bool:
        """True when the model exerts no force at all (e.g. Fc = 0)."""
        return False

    def mean_velocity_force(self, sigma_v):
        """E[v F(v)] (W) for v ~ N(0, sigma_v^2), by quadrature (paper Eq. 19)."""
        sigma_v = np.asarray(sigma_v, dtype=float)
        # Parameters get a trailing axis so that they broadcast against the
        # quadrature nodes, which the quadrature appends as the last axis.
        expanded = replace(
            self, **{f.name: np.asarray(getattr(self, f.name))[..., None] for f in fields(self)}
        )
        return _quadrature.gaussian_even_expectation(lambda v: v * expanded.force(v), sigma_v)

    def equivalent_damping_increment(self, sigma_v):
        """E[v F(v)] / E[v^2] (Ns/m): the friction's share of c_eq (Eq. 19)."""
        sigma_v = np.asarray(sigma_v, dtype=float)
        return self.mean_velocity_force(sigma_v) / sigma_v**2

    def kernel_parameters(self) -> np.ndarray:
        """Parameter vector for the compiled integrators (scalars only)."""
        values = [getattr(self, f.name) for f in fields(self)]
        if any(np.ndim(v) != 0 for v in values):
            raise ValueError(
                f"{type(self).__name__} parameters must be scalars to be simulated; "
                f"got {dict((f.name, getattr(self, f.name)) for f in fields(self))}"
            )
        out = np.zeros(N_KERNEL_PARAMETERS)
        out[: len(values)] = values
        return out

    def parameters(self) -> dict:
        """The model's parameters by name (SI units)."""
        return {f.name: scalar_or_array(np.asarray(getattr(self, f.name))) for f in fields(self)}


@dataclass(frozen=True, eq=False)
class Coulomb(FrictionModel):
    """Coulomb friction F = Fc sgn(v), with sgn(0) = 0 (paper Eq. 4-5).

    Parameters
    ----------
    fc : float or array_like
        Coulomb friction level Fc (N), >= 0.
    """

    fc: float

    name = "coulomb"
    kernel_code = KERNEL_COULOMB

    def __post_init__(self):
        object.__setattr__(self, "fc", scalar_or_array(check_nonnegative("fc", self.fc, "N")))

    def force(self, v, theta=None):
        return self.fc * np.sign(v)

    @property
    def vanishes(self) -> bool:
        return bool(np.all(np.asarray(self.fc) == 0))

    def mean_velocity_force(self, sigma_v):
        # E[v Fc sgn v] = Fc E|v| = Fc sqrt(2/pi) sigma_v (paper Eq. 22-26).
        return self.fc * np.sqrt(2.0 / np.pi) * np.asarray(sigma_v, dtype=float)


@dataclass(frozen=True, eq=False)
class Tanh(FrictionModel):
    """Hyperbolic-tangent friction F = Fc tanh(beta v) (paper Eq. 6).

    Parameters
    ----------
    fc : float or array_like
        Friction level Fc (N), >= 0.
    beta : float or array_like
        Sharpness beta (s/m), > 0; beta -> infinity recovers Coulomb (Eq. 7).
    """

    fc: float
    beta: float

    name = "tanh"
    kernel_code = KERNEL_TANH

    def __post_init__(self):
        object.__setattr__(self, "fc", scalar_or_array(check_nonnegative("fc", self.fc, "N")))
        object.__setattr__(self, "beta", scalar_or_array(check_positive("beta", self.beta, "s/m")))

    def force(self, v, theta=None):
        return self.fc * np.tanh(self.beta * np.asarray(v, dtype=float))

    @property
    def vanishes(self) -> bool:
        return bool(np.all(np.asarray(self.fc) == 0))

    def mean_velocity_force(self, sigma_v):
        # Written as Fc E|v| minus a boundary-layer correction of width 1/beta so
        # that beta up to 1e9 s/m (paper Table 2) is integrated accurately: the
        # correction Fc E[|v| (1 - tanh(beta |v|))] lives on v ~ 1/beta.
        sigma_v = np.asarray(sigma_v, dtype=float)
        beta = np.asarray(self.beta, dtype=float)
        beta_nodes = beta[..., None]  # broadcasts against the trailing node axis
        coulomb_part = np.sqrt(2.0 / np.pi) * sigma_v
        correction = _quadrature.gaussian_even_expectation(
            lambda v: np.abs(v) * _one_minus_tanh(beta_nodes * np.abs(v)),
            sigma_v,
            inner_scale=1.0 / beta,
        )
        return self.fc * (coulomb_part - correction)


def _one_minus_tanh(x):
    # 1 - tanh(x) = 2 / (1 + exp(2x)), accurate where tanh(x) rounds to 1.
    return 2.0 / (1.0 + np.exp(np.minimum(2.0 * x, 700.0)))


@dataclass(frozen=True, eq=False)
class LuGre(FrictionModel):
    """LuGre friction (paper Eq. 8-10, Canudas de Wit et al. 1995).

    Bristle state theta (m): ``theta' = v - |v| theta / g(v)``, force
    ``F = sigma0 theta + sigma1 theta'`` with
    ``sigma0 g(v) = fc + (fs - fc) exp(-(v / vs)^2)``.

    Parameters
    ----------
    sigma0 : float
        Bristle stiffness (N/m), > 0.
    sigma1 : float
        Bristle damping (Ns/m), >= 0.
    fc : float
        Coulomb level (N), > 0.
    fs : float
        Stiction level (N), > 0.
    vs : float
        Stribeck velocity (m/s), > 0.
    """

    sigma0: float
    sigma1: float
    fc: float
    fs: float
    vs: float

    name = "lugre"
    n_states = 1
    kernel_code = KERNEL_LUGRE
    has_equivalent_damping = False

    def __post_init__(self):
        object.__setattr__(
            self, "sigma0", scalar_or_array(check_positive("sigma0", self.sigma0, "N/m"))
        )
        object.__setattr__(
            self, "sigma1", scalar_or_array(check_nonnegative("sigma1", self.sigma1, "Ns/m"))
        )
        object.__setattr__(self, "fc", scalar_or_array(check_positive("fc", self.fc, "N")))
        object.__setattr__(self, "fs", scalar_or_array(check_positive("fs", self.fs, "N")))
        object.__setattr__(self, "vs", scalar_or_array(check_positive("vs", self.vs, "m/s")))

    def g(self, v):
        """Bristle deflection scale g(v) (m), paper Eq. 10."""
        v = np.asarray(v, dtype=float)
        return (self.fc + (self.fs - self.fc) * np.exp(-((v / self.vs) ** 2))) / self.sigma0

    def bristle_rate(self, v, theta):
        """theta' (m/s), paper Eq. 8."""
        v = np.asarray(v, dtype=float)
        return v - np.abs(v) * theta / self.g(v)

    def force(self, v, theta=None):
        if theta is None:
            raise ValueError("LuGre.force needs the bristle state `theta` (m)")
        return self.sigma0 * theta + self.sigma1 * self.bristle_rate(v, theta)

    def steady_state_force(self, v):
        """Force in steady sliding (theta' = 0): sgn(v) sigma0 g(v) (N)."""
        return np.sign(v) * self.sigma0 * self.g(v)

    def mean_velocity_force(self, sigma_v):
        raise NotImplementedError(
            "LuGre friction has memory (bristle state), so E[v F(v)] under a "
            "Gaussian velocity is not defined; use Monte Carlo (randvib.simulate)"
        )


@numba.njit(cache=True, inline="always")
def friction_force_and_rate(kind, p, v, theta):
    """Friction force F (N) and bristle rate theta' (m/s) for the kernels.

    ``kind`` is a model's ``kernel_code`` and ``p`` its ``kernel_parameters()``.
    Coulomb uses sgn(0) = 0 as in paper Eq. 5.
    """
    if kind == KERNEL_COULOMB:
        if v > 0.0:
            return p[0], 0.0
        elif v < 0.0:
            return -p[0], 0.0
        return 0.0, 0.0
    elif kind == KERNEL_TANH:
        return p[0] * np.tanh(p[1] * v), 0.0
    elif kind == KERNEL_LUGRE:
        ratio = v / p[4]
        g = (p[2] + (p[3] - p[2]) * np.exp(-ratio * ratio)) / p[0]
        rate = v - abs(v) * theta / g
        return p[0] * theta + p[1] * rate, rate
    return 0.0, 0.0


FRICTION_MODELS = {"coulomb": Coulomb, "tanh": Tanh, "lugre": LuGre}
