"""Friction laws of the paper (Eq. 4-10), each declared once.

A friction law is one class, a frozen dataclass subclassing
:class:`FrictionModel`, and that class is the only place that describes it.
It declares everything the rest of randvib needs:

* **parameters** - the dataclass fields, each made with
  :func:`~randvib.models.parameters.parameter` (:mod:`randvib.models.parameters`),
  which records its unit, whether it must be > 0 or >= 0, and how
  identification searches it (default bounds from a record's scales, log or
  linear scale). Validation, ``parameters()``, the CLI options, the
  identification bounds and the kernel parameter vector all read these.
* **the force** - ``force(v, theta)`` with numpy (analytic methods, FPK
  moments, plots) and ``kernel(p, v, theta) -> (F, theta')``, a
  numba-compilable function of the kernel parameter vector ``p`` (the fields
  in declaration order) used by the Monte Carlo engine
  (:mod:`randvib.montecarlo.kernel`) and the record simulator
  (:mod:`randvib.identification.record_integrator`). The built-in laws also carry a
  ``kernel_code`` so that the compiled loops inline their force (see
  :func:`evaluate_friction`); any other law is compiled on first use into a
  C callback (``numba.cfunc``) that the same cached loops call through a
  function pointer, so a new law needs no edit anywhere else.
* **memory** - ``n_states`` (LuGre's bristle deflection: 1) and, for the
  record simulator's sub-cycling, :meth:`FrictionModel.kernel_relaxation_rate`.
* **what the analytic methods read** - ``has_equivalent_damping`` and
  ``mean_velocity_force`` (E[v F(v)] for Gaussian v, paper Eq. 19:
  equivalent linearisation; by quadrature unless a law gives a closed form,
  refused for laws with memory); ``closed_form_equivalent_damping``
  (Coulomb: Eq. 30); ``coulomb_tanh_form`` (``F = Fc tanh(beta v)``, beta =
  inf for Coulomb: the form stochastic averaging and the FPK solvers are
  written for). Which methods take a law is theirs to say: each declares the
  friction form it treats (:data:`randvib.analytic.method.FRICTION_FORMS`;
  ``randvib.METHODS[name].accepts_friction(law)``);
* **stick-slip** - ``stick_slip`` (how the record simulator's event-located
  stick-slip integrator reads ``p``).
* **a name** - ``name``, used by the CLI, identification and tables.

Defining a subclass with its own ``name`` registers it in
:data:`FRICTION_MODELS`, the registry the CLI and identification read.

Parameters may be numpy arrays: the analytic methods broadcast over them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields, replace

import numba
import numpy as np
from numba import types

from randvib import _quadrature
from randvib._validation import scalar_or_array
from randvib.models.parameters import DeclaredParameters, parameter

#: Length of the parameter vector handed to the compiled kernels.
N_KERNEL_PARAMETERS = 5

#: Kernel codes of the built-in laws, whose force the compiled loops inline.
KERNEL_GENERIC = -1  # any other law: called through its compiled C callback
KERNEL_NONE = 0
KERNEL_COULOMB = 1
KERNEL_TANH = 2
KERNEL_LUGRE = 3

#: How the record simulator's stick-slip integrator reads a law's ``p``.
STICK_SLIP_NONE = 0  # smooth: plain RK4
STICK_SLIP_SIGN = 1  # F = p[0] sgn(v)
STICK_SLIP_TANH = 2  # F = p[0] tanh(p[1] v)

#: Signature of a law's compiled kernel: (p, v, theta) -> (F, theta').
KERNEL_SIGNATURE = types.UniTuple(types.float64, 2)(
    types.float64[::1], types.float64, types.float64
)

#: Name -> friction law class; filled by :class:`FrictionModel` subclasses.
FRICTION_MODELS: dict[str, type] = {}


@numba.cfunc(KERNEL_SIGNATURE, cache=True)
def _no_generic_kernel(p, v, theta):
    # Placeholder callback for built-in laws and no friction: the compiled
    # loops take a callback argument of one fixed type (so they are compiled
    # and cached once) but never call it unless the kind is KERNEL_GENERIC.
    return 0.0, 0.0


_COMPILED_KERNELS: dict[type, object] = {}


class FrictionModel(DeclaredParameters):
    """Base class of the friction laws: the declaration every consumer reads.

    Subclasses are frozen dataclasses whose fields are made with
    :func:`~randvib.models.parameters.parameter`; a subclass that sets
    ``name`` is registered in :data:`FRICTION_MODELS`. See the module
    docstring for what a law declares.
    """

    #: Short name used by the CLI, presets, identification and tables.
    name: str = "friction"
    #: Number of internal state variables the law carries (LuGre: 1).
    n_states: int = 0
    #: Built-in code selecting the inlined force in :func:`evaluate_friction`;
    #: KERNEL_GENERIC (any law defined outside this module) uses ``kernel``.
    kernel_code: int = KERNEL_GENERIC
    #: How the record simulator's stick-slip integrator reads ``p``
    #: (STICK_SLIP_SIGN: F = p[0] sgn v; STICK_SLIP_TANH: F = p[0] tanh(p[1] v));
    #: STICK_SLIP_NONE integrates the law with plain RK4, which needs it smooth
    #: on the scale of the step.
    stick_slip: int = STICK_SLIP_NONE

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "name" not in cls.__dict__:
            return
        known = FRICTION_MODELS.get(cls.name)
        if known is not None and (known.__module__, known.__qualname__) != (
            cls.__module__,
            cls.__qualname__,
        ):
            raise ValueError(
                f"friction law name {cls.name!r} is taken by {known.__module__}."
                f"{known.__qualname__}; choose another `name`"
            )
        FRICTION_MODELS[cls.name] = cls

    # ------------------------------------------------------------ parameters
    def parameters(self) -> dict:
        """The law's parameters by name (SI units)."""
        return {f.name: scalar_or_array(np.asarray(getattr(self, f.name))) for f in fields(self)}

    # ------------------------------------------------------------------ force
    def force(self, v, theta=None):  # pragma: no cover - abstract
        """Friction force F (N) at relative velocity ``v`` (m/s), numpy-vectorised."""
        raise NotImplementedError

    @property
    def vanishes(self) -> bool:
        """True when the law exerts no force at all (e.g. Fc = 0)."""
        return False

    @property
    def has_memory(self) -> bool:
        """True when the force depends on the velocity history (internal state)."""
        return self.n_states > 0

    # ------------------------------------------------------- analytic methods
    @property
    def has_equivalent_damping(self) -> bool:
        """Whether E[v F(v)] under a Gaussian v is defined (memoryless laws)."""
        return not self.has_memory

    def mean_velocity_force(self, sigma_v):
        """E[v F(v)] (W) for v ~ N(0, sigma_v^2), by quadrature (paper Eq. 19).

        Needs an odd, memoryless force; laws with memory raise.
        """
        if self.has_memory:
            raise NotImplementedError(
                f"{self.name} friction has memory (internal state), so E[v F(v)] under a "
                "Gaussian velocity is not defined; use Monte Carlo (randvib.simulate)"
            )
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

    def closed_form_equivalent_damping(self, c, psd, m):
        """c_eq (Ns/m) in closed form where the law has one (Coulomb: Eq. 30), else None."""
        return None

    def coulomb_tanh_form(self):
        """(Fc, beta) when the law is ``F = Fc tanh(beta v)`` (beta = inf: Coulomb), else None.

        Stochastic averaging and the FPK solvers are written for this family
        (their orbit integrals and kink corrections use Fc and beta).
        """
        return None

    # --------------------------------------------------------- compiled code
    @staticmethod
    def kernel(p, v, theta):  # pragma: no cover - abstract
        """(F, theta') from the parameter vector ``p``; numba-compilable."""
        raise NotImplementedError

    def kernel_parameters(self) -> np.ndarray:
        """Parameter vector for the compiled integrators (scalars only)."""
        values = [getattr(self, f.name) for f in fields(self)]
        if any(np.ndim(v) != 0 for v in values):
            raise ValueError(
                f"{type(self).__name__} parameters must be scalars to be simulated; "
                f"got {dict((f.name, getattr(self, f.name)) for f in fields(self))}"
            )
        return kernel_vector(type(self), values)

    @classmethod
    def compiled_kernel(cls):
        """``kernel`` compiled into a C callback of :data:`KERNEL_SIGNATURE` (once per law)."""
        if cls not in _COMPILED_KERNELS:
            fn = getattr(cls.kernel, "py_func", cls.kernel)
            _COMPILED_KERNELS[cls] = numba.cfunc(KERNEL_SIGNATURE)(fn)
        return _COMPILED_KERNELS[cls]

    @classmethod
    def kernel_callback(cls):
        """What the compiled loops get as their friction callback."""
        return cls.compiled_kernel() if cls.kernel_code == KERNEL_GENERIC else _no_generic_kernel

    def kernel_arguments(self):
        """(kind, p, callback): the friction arguments of the compiled loops."""
        return self.kernel_code, self.kernel_parameters(), self.kernel_callback()

    @classmethod
    def kernel_relaxation_rate(cls, p):
        """Relaxation rate of the internal state per unit speed (1/m), per row of ``p``.

        The record simulator sub-cycles a step h so that
        ``|v| * rate * h < 1``; 0 for memoryless laws.
        """
        return np.zeros(np.shape(p)[0])


def kernel_vector(law, values) -> np.ndarray:
    """Pad a law's parameter values to the kernels' fixed-length vector."""
    if len(values) > N_KERNEL_PARAMETERS:
        raise ValueError(
            f"{law.__name__} has {len(values)} parameters; the compiled kernels take at most "
            f"{N_KERNEL_PARAMETERS}"
        )
    out = np.zeros(N_KERNEL_PARAMETERS)
    out[: len(values)] = values
    return out


def kernel_arguments(friction):
    """(kind, p, callback) for a friction law or None (no friction)."""
    if friction is None:
        return KERNEL_NONE, np.zeros(N_KERNEL_PARAMETERS), _no_generic_kernel
    return friction.kernel_arguments()


def friction_law(name: str):
    """The registered friction law class called ``name`` (``none``: None)."""
    if name == "none":
        return None
    try:
        return FRICTION_MODELS[name]
    except KeyError:
        raise ValueError(
            f"unknown friction law {name!r}; known: none, {', '.join(FRICTION_MODELS)}"
        ) from None


def kernel_callback(friction_class):
    """The compiled loops' friction callback for a law class (or None: no friction)."""
    return _no_generic_kernel if friction_class is None else friction_class.kernel_callback()


class RegistryView(Mapping):
    """Live read-only mapping over ``none`` and the registered laws.

    ``RegistryView(value)[name]`` is ``value(law)`` for the law registered as
    ``name`` (``value(None)`` for the no-friction key). Tables keyed by law
    name are views like this, so a law defined later (in a user's script or
    a test) appears in them without editing them.

    Parameters
    ----------
    value : callable
        ``value(law_class_or_None)``.
    none_key : str
        Key standing for "no friction" (``none``; identification: ``viscous``).
    """

    def __init__(self, value, none_key: str = "none"):
        self._value = value
        self._none_key = none_key

    def __getitem__(self, key):
        if key == self._none_key:
            return self._value(None)
        if key not in FRICTION_MODELS:
            raise KeyError(key)
        return self._value(FRICTION_MODELS[key])

    def __iter__(self):
        yield self._none_key
        yield from list(FRICTION_MODELS)

    def __len__(self):
        return 1 + len(FRICTION_MODELS)

    def __repr__(self):
        return repr(dict(self))


def coulomb_equivalent_damping(c, fc, psd, m):
    """Closed-form equivalent damping for Coulomb friction, paper Eq. 30 (Ns/m).

    ``c_eq = c + 4 Fc^2/(pi S m) + 1/2 sqrt((2c + 8 Fc^2/(pi S m))^2 - 4 c^2)``

    Parameters
    ----------
    c : array_like
        Viscous damping c_m + c_e (Ns/m).
    fc : array_like
        Coulomb friction level (N).
    psd : array_like
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz).
    m : array_like
        Mass (kg).
    """
    c, fc, psd, m = (np.asarray(x, dtype=float) for x in (c, fc, psd, m))
    a = 4.0 * fc**2 / (np.pi * psd * m)
    # (2c + 2a)^2 - 4c^2 = 4a(2c + a): written this way it never goes negative
    # by cancellation when a << c.
    return c + a + np.sqrt(a * (2.0 * c + a))


# ------------------------------------------------------------------ the laws
def _force_scale(lo):
    # Friction levels: a fraction of the RMS external force up to all of it.
    return lambda s: (lo * s.force, s.force)


@numba.njit(cache=True, inline="always")
def _coulomb_kernel(p, v, theta):
    # sgn(0) = 0 as in paper Eq. 5.
    if v > 0.0:
        return p[0], 0.0
    elif v < 0.0:
        return -p[0], 0.0
    return 0.0, 0.0


@dataclass(frozen=True, eq=False)
class Coulomb(FrictionModel):
    """Coulomb friction F = Fc sgn(v), with sgn(0) = 0 (paper Eq. 4-5).

    Parameters
    ----------
    fc : float or array_like
        Coulomb friction level Fc (N), >= 0.
    """

    fc: float = parameter("N", search=_force_scale(1e-4), description="friction level Fc")

    name = "coulomb"
    kernel_code = KERNEL_COULOMB
    stick_slip = STICK_SLIP_SIGN
    kernel = staticmethod(_coulomb_kernel)

    def force(self, v, theta=None):
        return self.fc * np.sign(v)

    @property
    def vanishes(self) -> bool:
        return bool(np.all(np.asarray(self.fc) == 0))

    def mean_velocity_force(self, sigma_v):
        # E[v Fc sgn v] = Fc E|v| = Fc sqrt(2/pi) sigma_v (paper Eq. 22-26).
        return self.fc * np.sqrt(2.0 / np.pi) * np.asarray(sigma_v, dtype=float)

    def closed_form_equivalent_damping(self, c, psd, m):
        return coulomb_equivalent_damping(c, self.fc, psd, m)

    def coulomb_tanh_form(self):
        return self.fc, np.inf


@numba.njit(cache=True, inline="always")
def _tanh_kernel(p, v, theta):
    return p[0] * np.tanh(p[1] * v), 0.0


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

    fc: float = parameter("N", search=_force_scale(1e-4), description="friction level Fc")
    beta: float = parameter(
        "s/m",
        positive=True,
        search=lambda s: (1.0 / s.v_rms, 1e10 / s.v_rms),
        description="tanh sharpness beta",
    )

    name = "tanh"
    kernel_code = KERNEL_TANH
    stick_slip = STICK_SLIP_TANH
    kernel = staticmethod(_tanh_kernel)

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
            lambda v: np.abs(v) * one_minus_tanh(beta_nodes * np.abs(v)),
            sigma_v,
            inner_scale=1.0 / beta,
        )
        return self.fc * (coulomb_part - correction)

    def coulomb_tanh_form(self):
        return self.fc, self.beta


def one_minus_tanh(x):
    """1 - tanh(x) for x >= 0, accurate where tanh(x) rounds to 1.

    Written as 2 / (1 + exp(2x)); the boundary-layer corrections of tanh
    friction (here and in :mod:`randvib.analytic.averaging`) integrate it.
    """
    return 2.0 / (1.0 + np.exp(np.minimum(2.0 * x, 700.0)))


@numba.njit(cache=True, inline="always")
def _lugre_kernel(p, v, theta):
    # p = (sigma0, sigma1, fc, fs, vs); Eq. 8-10.
    ratio = v / p[4]
    g = (p[2] + (p[3] - p[2]) * np.exp(-ratio * ratio)) / p[0]
    rate = v - abs(v) * theta / g
    return p[0] * theta + p[1] * rate, rate


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

    sigma0: float = parameter(
        "N/m",
        positive=True,
        search=lambda s: (1e-3 * s.k_ref, 10 * s.k_ref),
        description="LuGre bristle stiffness sigma0",
    )
    sigma1: float = parameter(
        "Ns/m",
        search=lambda s: (1e-4 * s.c_ref, 10 * s.c_ref),
        description="LuGre bristle damping sigma1",
    )
    fc: float = parameter(
        "N", positive=True, search=_force_scale(1e-4), description="friction level Fc"
    )
    fs: float = parameter(
        "N", positive=True, search=_force_scale(1e-4), description="stiction level Fs"
    )
    vs: float = parameter(
        "m/s",
        positive=True,
        search=lambda s: (1e-4 * s.v_rms, 10 * s.v_rms),
        description="Stribeck velocity vs",
    )

    name = "lugre"
    n_states = 1
    kernel_code = KERNEL_LUGRE
    kernel = staticmethod(_lugre_kernel)

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

    @classmethod
    def kernel_relaxation_rate(cls, p):
        # theta' = v - |v| theta / g relaxes at |v| / g; g >= min(fc, fs) / sigma0.
        p = np.asarray(p, dtype=float)
        return p[:, 0] / np.maximum(np.minimum(p[:, 2], p[:, 3]), 1e-300)


# ------------------------------------------------------------ compiled switch
@numba.njit(cache=True, inline="always")
def friction_force_and_rate(kind, p, v, theta):
    """Friction force F (N) and state rate theta' (m/s) of a built-in law.

    ``kind`` is the law's ``kernel_code`` and ``p`` its ``kernel_parameters()``.
    The built-in laws are inlined here so that the Monte Carlo loop keeps
    their speed; every other law goes through :func:`evaluate_friction`.
    """
    if kind == KERNEL_COULOMB:
        return _coulomb_kernel(p, v, theta)
    elif kind == KERNEL_TANH:
        return _tanh_kernel(p, v, theta)
    elif kind == KERNEL_LUGRE:
        return _lugre_kernel(p, v, theta)
    return 0.0, 0.0


@numba.njit(cache=True, inline="always")
def evaluate_friction(kind, callback, p, v, theta):
    """(F, theta') of any law: the inlined built-ins, or ``callback`` for KERNEL_GENERIC.

    ``(kind, p, callback)`` come from :func:`kernel_arguments`. The callback
    has one type for every law (:data:`KERNEL_SIGNATURE`), so the loops that
    call this are compiled and cached once.
    """
    if kind == KERNEL_GENERIC:
        return callback(p, v, theta)
    return friction_force_and_rate(kind, p, v, theta)
