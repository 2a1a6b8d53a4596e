"""Statistical linearisation of an assembly: each element on its own relative motion.

Every nonlinear element of an :class:`~randvib.models.assembly.Assembly` acts
on one relative coordinate u = d^T x. Under a zero-mean Gaussian closure
(paper Eq. 19; docs/conventions.md, "Beyond the paper") it is replaced by the
linear spring and dashpot on that coordinate

    k_eq,e = 3 k3 E[u^2]             (added to its linear spring k),
    c_eq,e = E[u' F(u')] / E[u'^2]    (memoryless friction, as the single mass),

placed in the assembly's stiffness and damping as ``k d d^T`` and
``c d d^T``; the variances E[u^2], E[u'^2] are those of the linearised
assembly under the excitation (:mod:`randvib.analytic.assembly_linear`:
Lyapunov for rational spectra, the spectral integral for any). The
conditions are one fixed point in the log variances, solved by Powell's
hybrid method with damped fixed-point steps as the single mass's
(:func:`randvib.analytic.statistical_linearisation.statistical_linearisation`).
A linear assembly needs no closure: its Lyapunov solution is exact.

For one DOF this is the single-mass statistical linearisation: the same
closure on the same coordinate, so ``rv.predict(Assembly.from_harvester(h))``
equals ``rv.predict(h)`` to the solver's tolerance (tests/test_assembly_analytic.py).

Refused (Monte Carlo treats them): friction with memory (LuGre), a quadratic
spring k2 (its mean force shifts the mean: not a zero-mean closure), diode
bridges (switching).

Validity (``element_friction_share`` and ``element_stiffness_share`` in the
``validity`` of the method ``linearisation``), per element: the single-mass
limits (:data:`~randvib.analytic.statistical_linearisation.LINEARISATION_FRICTION_SHARE_LIMIT`
and ``LINEARISATION_STIFFNESS_SHARE_LIMIT``, measured against FPK and the
Monte Carlo cross-check campaign), **checked on assemblies** by
tests/calibration/assembly_linearisation.py (an independent Heun simulator, 200
paths of 40 s; the shipped host_with_harvester, white and band-pass input;
results in assembly_linearisation.txt). Inside both limits the closure's
transducer power was within 6.0 % of Monte Carlo (largest +6.0 % +- 2.9 %,
stiffness share 0.10 under band-pass); friction shares 0.60 to 0.80 gave
-1.4 % to -5.0 %, 0.92 gave -21 %; stiffness shares 0.35 to 0.64 gave -7.5 %
to -21.5 %. The compiled assembly kernel's calibration is to widen the grid:

* friction share ``E[u'F] / (E[u'F] + c_dir E[u'^2] + P_e,coordinate)``: the
  element's friction power over all the power dissipated on its coordinate
  (the structure's direct dashpot c_dir between its DOFs, the dashpots and
  transducers on the same coordinate); for one DOF the single mass's
  1 - c / c_eq. Warns beyond 0.85.
* stiffness share ``1 - k_dir / k_eq``: the cubic spring's share of the
  stiffness on the coordinate, k_dir the structure's direct spring plus the
  linear springs on it, k_eq = k_dir + 3 k3 E[u^2]. Warns beyond 0.2 (and
  always for a double well, k_dir < 0), except on one DOF under white noise
  without a circuit state, where k_eq drops out of the power (as for the
  single mass).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from randvib.analytic.assembly_linear import AssemblyResponse, UnstableAssembly, linear_response
from randvib.analytic.fixed_point import LinearisationDidNotConverge, TrialUndefined, solve
from randvib.analytic.statistical_linearisation import (
    LINEARISATION_FRICTION_SHARE_LIMIT,
    LINEARISATION_STIFFNESS_SHARE_LIMIT,
    LinearisationValidityWarning,
)
from randvib.models.assembly import Assembly
from randvib.models.excitation import Excitation

MONTE_CARLO = "Monte Carlo (randvib.simulate)"


@dataclass(frozen=True, eq=False)
class ElementClosure:
    """The Gaussian closure of one element (SI units).

    Attributes
    ----------
    index : int
        The element's index in the assembly.
    stiffness : float
        3 k3 E[u^2] (N/m), added to its linear spring.
    damping : float
        E[u' F] / E[u'^2] (Ns/m) of its friction.
    friction_share, stiffness_share : float
        The validity indicators of the module docstring.
    """

    index: int
    stiffness: float
    damping: float
    friction_share: float
    stiffness_share: float


@dataclass(frozen=True, eq=False)
class AssemblyLinearisation:
    """The linearised assembly's response and its elements' closures.

    Attributes
    ----------
    response : AssemblyResponse
        Second moments of the linearised assembly.
    closures : tuple of ElementClosure
        One per element (zeros for a linear one).
    exact : bool
        True when no element needed a closure (a linear assembly).
    """

    response: AssemblyResponse
    closures: tuple
    exact: bool


def refusal(assembly: Assembly) -> str | None:
    """Why the closure does not take the assembly (one line naming Monte Carlo), or None."""
    for index, element in enumerate(assembly.elements):
        law = element.friction
        if law is not None and not law.has_equivalent_damping:
            return (
                f"statistical linearisation of an assembly needs memoryless friction; element "
                f"{index}'s {law.name!r} has internal state: use {MONTE_CARLO}"
            )
        if element.spring is not None and element.spring.k2 != 0:
            return (
                f"statistical linearisation of an assembly is a zero-mean closure; element "
                f"{index}'s quadratic spring k2 = {element.spring.k2:g} N/m^2 shifts the mean: "
                f"use {MONTE_CARLO}"
            )
    for index, transducer in enumerate(assembly.transducers):
        if transducer.is_rectified:
            return (
                f"statistical linearisation of an assembly takes linear couplings; transducer "
                f"{index}'s {transducer.coupling.name} switches: use {MONTE_CARLO}"
            )
    return None


def _closed(assembly: Assembly):
    """(index, needs E[u^2], needs E[u'^2]) of the elements the closure replaces."""
    out = []
    for index, element in enumerate(assembly.elements):
        cubic = element.spring is not None and element.spring.k3 != 0
        friction = element.friction is not None and not element.friction.vanishes
        if cubic or friction:
            out.append((index, cubic, friction))
    return out


def linearise_assembly(
    assembly: Assembly, excitation: Excitation, method: str = "auto"
) -> AssemblyLinearisation:
    """Statistical linearisation of the assembly under the excitation (module docstring).

    Raises
    ------
    ValueError
        A part the closure does not take (:func:`refusal`), a linearised
        assembly without a stationary response, or no fixed point
        (:class:`~randvib.analytic.fixed_point.LinearisationDidNotConverge`).
    """
    why = refusal(assembly)
    if why:
        raise ValueError(why)
    closed = _closed(assembly)
    n = assembly.n_dof
    if not closed:
        response = linear_response(assembly, excitation, method=method)
        zero = [ElementClosure(i, 0.0, 0.0, 0.0, 0.0) for i in range(len(assembly.elements))]
        return AssemblyLinearisation(response, tuple(zero), exact=True)
    slots = [(index, "u") for index, cubic, _ in closed if cubic]
    slots += [(index, "du") for index, _, friction in closed if friction]

    def equivalent(log_variances):
        values = dict(zip(slots, np.exp(log_variances), strict=True))
        c, k = np.zeros((n, n)), np.zeros((n, n))
        for (index, kind), variance in values.items():
            element = assembly.elements[index]
            d = assembly.incidence(element)
            if kind == "u":
                k += 3.0 * element.spring.k3 * variance * np.outer(d, d)
            else:
                sigma = np.sqrt(variance)
                c += float(element.friction.equivalent_damping_increment(sigma)) * np.outer(d, d)
        return c, k

    def respond(c, k) -> AssemblyResponse:
        return linear_response(assembly, excitation, c, k, method)

    def logs(response: AssemblyResponse) -> np.ndarray:
        out = []
        for index, kind in slots:
            u, du = response.coordinate_variances(assembly.elements[index])
            out.append(u if kind == "u" else du)
        return np.log(out)

    def residual(x):
        with np.errstate(all="ignore"):
            c, k = equivalent(x)
            if not (np.all(np.isfinite(c)) and np.all(np.isfinite(k))):
                raise TrialUndefined("equivalent dashpots or springs not finite")
            try:
                out = logs(respond(c, k)) - x
            except (ValueError, np.linalg.LinAlgError):
                raise TrialUndefined("the linearised assembly has no stationary response") from None
        if not np.all(np.isfinite(out)):
            raise TrialUndefined("variances not finite")
        return out

    x = solve(residual, _start(assembly, excitation, closed, slots, respond, logs))
    c, k = equivalent(x)
    response = respond(c, k)
    closures = _closures(assembly, response)
    _warn(assembly, excitation, closures)
    return AssemblyLinearisation(response, closures, exact=False)


def _start(assembly, excitation, closed, slots, respond, logs) -> np.ndarray:
    """Log variances to start from: the linear part's response, made stable where it is not.

    A double-well element (negative direct stiffness) or an assembly damped
    only by friction has no linear response; a trial closure with 3 k3 E[u^2]
    = 3 |k_dir| and a friction dashpot of 10 % of critical on the coordinate
    gives one.
    """
    n = assembly.n_dof
    try:
        return logs(respond(np.zeros((n, n)), np.zeros((n, n))))
    except UnstableAssembly:
        pass
    m, _, _ = assembly.linear_matrices()
    c, k = np.zeros((n, n)), np.zeros((n, n))
    for index, cubic, friction in closed:
        element = assembly.elements[index]
        d = assembly.incidence(element)
        k_dir = abs(_direct(assembly, element)[1]) or 1.0
        if cubic and element.spring.k3 > 0:
            k += 3.0 * k_dir * np.outer(d, d)
        if friction:
            mass = float(d @ m @ d) if element.between[1] is None else float(np.trace(m)) / n
            c += 0.2 * np.sqrt(k_dir * mass) * np.outer(d, d)
    try:
        return logs(respond(c, k))
    except UnstableAssembly:
        raise LinearisationDidNotConverge(
            "statistical linearisation of the assembly found no stable starting point (a "
            "double well or an undamped mode the closure cannot steady): use "
            f"{MONTE_CARLO}"
        ) from None


def _direct(assembly: Assembly, part) -> tuple[float, float]:
    """(c_dir, k_dir): the structure's dashpot and spring joining the part's two DOFs directly.

    -C_ij and -K_ij between DOFs i and j; the row sums C_i1 + ... and
    K_i1 + ... (what joins DOF i to the base) for a part on the base; plus the
    linear dashpots and springs of every element on the same coordinate.
    """
    m, c, k = assembly.linear_matrices()
    i, j = part.between
    if j is None:
        c_dir, k_dir = float(c[i].sum()), float(k[i].sum())
    else:
        c_dir, k_dir = float(-c[i, j]), float(-k[i, j])
    # linear_matrices() put the parts' own dashpots and c_e in C; the transducers'
    # c_e are counted as their power instead (friction share), so remove them here
    for transducer in assembly.transducers:
        if set(transducer.between) == set(part.between):
            c_dir -= transducer.electrical_damping
    return c_dir, k_dir


def _closures(assembly: Assembly, response: AssemblyResponse) -> tuple:
    """One :class:`ElementClosure` per element at the fixed point, with its validity indicators."""
    out = []
    for index, element in enumerate(assembly.elements):
        u, du = response.coordinate_variances(element)
        spring, law = element.spring, element.friction
        closure_k = 3.0 * spring.k3 * u if spring is not None else 0.0
        acting = law is not None and not law.vanishes
        closure_c = float(law.equivalent_damping_increment(np.sqrt(du))) if acting else 0.0
        out.append(_indicators(assembly, response, index, closure_k, closure_c))
    return tuple(out)


def _indicators(assembly, response, index, closure_k, closure_c) -> ElementClosure:
    """The element's friction and stiffness shares (module docstring)."""
    element = assembly.elements[index]
    _, du = response.coordinate_variances(element)
    c_dir, k_dir = _direct(assembly, element)
    electrical = sum(
        response.transducer_power(t)[0]
        for t, transducer in enumerate(assembly.transducers)
        if set(transducer.between) == set(element.between)
    )
    friction_power = closure_c * du
    dissipated = friction_power + max(c_dir, 0.0) * du + electrical
    friction_share = friction_power / dissipated if dissipated > 0 else 0.0
    k_eq = k_dir + closure_k
    if closure_k == 0:
        stiffness_share = 0.0
    else:
        stiffness_share = 1.0 - k_dir / k_eq if k_eq > 0 and k_dir >= 0 else np.inf
    return ElementClosure(index, closure_k, closure_c, friction_share, stiffness_share)


def _warn(assembly: Assembly, excitation: Excitation, closures) -> None:
    """LinearisationValidityWarning for elements beyond the declared limits (one warning)."""
    stiffness_matters = not (
        assembly.n_dof == 1 and excitation.is_white and not assembly.circuit_transducers
    )
    why = []
    for closure in closures:
        if closure.friction_share > LINEARISATION_FRICTION_SHARE_LIMIT:
            why.append(
                f"element {closure.index}'s friction takes {closure.friction_share:.1%} of the "
                f"power dissipated on its coordinate, beyond {LINEARISATION_FRICTION_SHARE_LIMIT:.0%}"
            )
        if stiffness_matters and closure.stiffness_share > LINEARISATION_STIFFNESS_SHARE_LIMIT:
            share = (
                "a double well" if np.isinf(closure.stiffness_share)
                else f"{closure.stiffness_share:.0%} of the stiffness on its coordinate"
            )  # fmt: skip
            why.append(
                f"element {closure.index}'s cubic spring takes {share}, beyond "
                f"{LINEARISATION_STIFFNESS_SHARE_LIMIT:.0%}"
            )
    if why:
        warnings.warn(
            f"{'; '.join(why)}: statistical linearisation of the assembly can then be off by "
            f"more than 10 % (tests/calibration/assembly_linearisation.py); use {MONTE_CARLO}",
            LinearisationValidityWarning,
            stacklevel=5,  # the caller of randvib.predict
        )
