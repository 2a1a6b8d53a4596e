"""Analytic prediction for assemblies: the result, the driver and the optimal loads.

:func:`randvib.predict` hands an :class:`~randvib.models.assembly.Assembly`
to :func:`predict_assembly`, which asks the method whether it takes
assemblies (:attr:`~randvib.analytic.method.AnalyticMethod.assemblies`: only
``linearisation`` does), runs the statistical linearisation of
:mod:`randvib.analytic.assembly_linearisation` (exact for a linear assembly:
one Lyapunov solution), refuses an answer that breaks the energy balance or
is not finite, and returns an :class:`AssemblyPrediction`: one entry per
transducer in the assembly's order (``power_electrical``, ``power_load``
where the coupling names a load, the circuit's mean square), the variances of
every DOF, each element's closure and the powers injected and dissipated.

:func:`optimal_assembly_loads` finds, for one transducer or each, the load
resistance (a bare damper: its c_e) that maximises that transducer's load
power with the others held as given.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import optimize, special

from randvib import _display, formatting
from randvib._validation import check_int, check_positive, check_scalar
from randvib.analytic.assembly_linearisation import linearise_assembly
from randvib.analytic.method import ENERGY_BALANCE_TOLERANCE, MONTE_CARLO, AnalyticMethod
from randvib.analytic.statistical_linearisation import LINEARISATION
from randvib.models.assembly import Assembly
from randvib.models.assembly_parts import between_words
from randvib.models.excitation import Excitation, as_excitation


@dataclass(frozen=True)
class CoordinatePrediction:
    """What is predicted on one element's or transducer's coordinate u (SI units).

    Attributes
    ----------
    between : (int, int or None)
    displacement_variance, velocity_variance : float
        E[u^2] (m^2) and E[u'^2] ((m/s)^2).
    stroke : float or None
        The part's stroke (m).
    stroke_exceedance : float or None
        P(|u| > stroke) of a zero-mean Gaussian u (the closure's estimate).
    """

    between: tuple
    displacement_variance: float
    velocity_variance: float
    stroke: float | None = None
    stroke_exceedance: float | None = None

    def to_dict(self) -> dict:
        out = dataclasses.asdict(self)
        out["between"] = [self.between[0], "base" if self.between[1] is None else self.between[1]]
        return {k: v for k, v in out.items() if v is not None or k in ("power_load",)}


@dataclass(frozen=True)
class TransducerPrediction(CoordinatePrediction):
    """One transducer's powers (W) and circuit state, beside its coordinate's statistics.

    Attributes
    ----------
    coupling : str
        ``resistive``, ``inductive``, ``piezo``.
    power_electrical : float
        Mean power into the electrical domain (W).
    power_load : float or None
        Its share in the load resistance (W); None for a bare damper c_e.
    circuit_mean_square : float or None
        E[i^2] (A^2) or E[V^2] (V^2) of a circuit state.
    """

    coupling: str = ""
    power_electrical: float = 0.0
    power_load: float | None = None
    circuit_mean_square: float | None = None

    def to_dict(self) -> dict:
        out = super().to_dict()
        if self.power_load is None:
            del out["power_load"]
        return out


@dataclass(frozen=True)
class ElementPrediction(CoordinatePrediction):
    """One element's Gaussian closure, beside its coordinate's statistics.

    Attributes
    ----------
    stiffness_eq : float
        3 k3 E[u^2] (N/m), the spring the closure adds (0 for a linear element).
    damping_eq : float
        E[u' F] / E[u'^2] (Ns/m), the friction's equivalent dashpot.
    power_friction : float
        damping_eq E[u'^2] (W): the friction's dissipation under the closure.
    friction_share, stiffness_share : float
        The validity indicators (:mod:`randvib.analytic.assembly_linearisation`).
    """

    stiffness_eq: float = 0.0
    damping_eq: float = 0.0
    power_friction: float = 0.0
    friction_share: float = 0.0
    stiffness_share: float = 0.0


@dataclass(frozen=True)
class AssemblyPrediction:
    """Stationary statistics of an assembly predicted by an analytic method (SI units).

    Attributes
    ----------
    method : str
        ``linearisation``.
    exact : bool
        True for a linear assembly (the Lyapunov solution, no closure).
    variance_method : str
        ``lyapunov`` (rational spectra) or ``spectral``.
    displacement_variance, velocity_variance : tuple of float
        E[x_i^2] (m^2) and E[x_i'^2] ((m/s)^2), one per DOF.
    transducers : tuple of TransducerPrediction
        In the assembly's (the device file's) order.
    elements : tuple of ElementPrediction
    power_input : float or None
        Mean power injected by the base (W): r^T M r S / 4 under white noise.
    power_dissipated : float
        All the power dissipated (W); equals ``power_input`` for the
        linear(ised) assembly.
    """

    method: str
    exact: bool
    variance_method: str
    displacement_variance: tuple
    velocity_variance: tuple
    transducers: tuple
    elements: tuple
    power_input: float | None
    power_dissipated: float

    @property
    def power_electrical(self) -> float:
        """The transducers' electrical power together (W)."""
        return float(sum(t.power_electrical for t in self.transducers))

    @property
    def power_load(self) -> float | None:
        """The load power of the transducers that have a load, together (W); None if none has."""
        loads = [t.power_load for t in self.transducers if t.power_load is not None]
        return float(sum(loads)) if loads else None

    @property
    def power_mechanical(self) -> float:
        """What is dissipated outside the transducers: dashpots and friction (W)."""
        return self.power_dissipated - self.power_electrical

    def to_dict(self) -> dict:
        """Plain dict ready for JSON: the issue's keys ``transducers``, ``displacement_variance``,
        ``velocity_variance``, and the rest."""
        return {
            "method": self.method,
            "exact": self.exact,
            "variance_method": self.variance_method,
            "transducers": [t.to_dict() for t in self.transducers],
            "displacement_variance": list(self.displacement_variance),
            "velocity_variance": list(self.velocity_variance),
            "elements": [e.to_dict() for e in self.elements],
            "power_electrical": self.power_electrical,
            "power_mechanical": self.power_mechanical,
            "power_input": self.power_input,
        }

    def _rows(self):
        rows = []
        for index, t in enumerate(self.transducers):
            where = f"transducer {index} {between_words(t.between)} ({t.coupling})"
            rows.append((f"{where} power_electrical", formatting.compact(t.power_electrical), "W"))
            if t.power_load is not None:
                rows.append((f"{where} power_load", formatting.compact(t.power_load), "W"))
        for i, (zz, vv) in enumerate(
            zip(self.displacement_variance, self.velocity_variance, strict=True)
        ):
            rows.append((f"DOF {i} displacement_variance", formatting.compact(zz), "m^2"))
            rows.append((f"DOF {i} velocity_variance", formatting.compact(vv), "(m/s)^2"))
        return rows

    def __str__(self) -> str:
        what = "exact" if self.exact else self.method
        return _display.text_table(f"Assembly prediction ({what})", self._rows())


def _coordinate(response, part) -> dict:
    u, du = response.coordinate_variances(part)
    exceedance = None
    if part.stroke is not None:
        exceedance = float(special.erfc(part.stroke / np.sqrt(2.0 * u)))
    return {
        "between": part.between,
        "displacement_variance": u,
        "velocity_variance": du,
        "stroke": part.stroke,
        "stroke_exceedance": exceedance,
    }


def _prediction(assembly: Assembly, lin, method: str) -> AssemblyPrediction:
    response = lin.response
    transducers = []
    for index, transducer in enumerate(assembly.transducers):
        electrical, load = response.transducer_power(index)
        transducers.append(
            TransducerPrediction(
                **_coordinate(response, transducer),
                coupling=transducer.coupling.name,
                power_electrical=electrical,
                power_load=load,
                circuit_mean_square=response.circuit_mean_square(index),
            )  # fmt: skip
        )
    elements = []
    for element, closure in zip(assembly.elements, lin.closures, strict=True):
        numbers = _coordinate(response, element)
        elements.append(
            ElementPrediction(
                **numbers,
                stiffness_eq=closure.stiffness,
                damping_eq=closure.damping,
                power_friction=closure.damping * numbers["velocity_variance"],
                friction_share=closure.friction_share,
                stiffness_share=closure.stiffness_share,
            )  # fmt: skip
        )
    return AssemblyPrediction(
        method=method,
        exact=lin.exact,
        variance_method=response.method,
        displacement_variance=tuple(map(float, response.displacement_variance)),
        velocity_variance=tuple(map(float, response.velocity_variance)),
        transducers=tuple(transducers),
        elements=tuple(elements),
        power_input=response.power_input,
        power_dissipated=response.dissipated_power(),
    )


def assembly_excitation(psd) -> Excitation:
    """The excitation of an assembly: an Excitation, or one white-noise level S."""
    if getattr(psd, "is_event", False):
        raise ValueError(
            f"an assembly's prediction is stationary; the {psd.name} event's transient response "
            "is not implemented for assemblies"
        )
    if isinstance(psd, Excitation):
        return psd
    level = check_scalar("psd", psd, "a white-noise level S in (m/s^2)^2/Hz", "")
    return as_excitation(float(check_positive("psd", level, "(m/s^2)^2/Hz")))


def predict_assembly(
    assembly: Assembly, psd, solver: AnalyticMethod = LINEARISATION
) -> AssemblyPrediction:
    """The stationary prediction of an assembly (module docstring); see :func:`randvib.predict`."""
    excitation = assembly_excitation(psd)
    solver.require(assembly, excitation)
    with np.errstate(all="ignore"):
        lin = linearise_assembly(assembly, excitation)
    result = _prediction(assembly, lin, solver.name)
    _check(result, solver)
    return result


def _check(result: AssemblyPrediction, solver: AnalyticMethod) -> None:
    """Refuse a non-finite answer, or one whose dissipation does not balance the input."""
    numbers = list(result.displacement_variance) + list(result.velocity_variance)
    numbers += [t.power_electrical for t in result.transducers] + [result.power_dissipated]
    if not all(np.isfinite(x) for x in numbers) or min(result.velocity_variance) <= 0:
        raise ValueError(
            f"{solver.called} has no finite result for this assembly (a variance or power is "
            f"not a positive finite number); use {MONTE_CARLO}"
        )
    if result.power_input is None or not result.power_input > 0:
        return
    ratio = result.power_dissipated / result.power_input
    if abs(ratio - 1.0) > ENERGY_BALANCE_TOLERANCE:
        raise ValueError(
            f"{solver.called} gives a dissipated power {result.power_dissipated:.4g} W, {ratio:.3g} "
            f"times the injected {result.power_input:.4g} W, which it must equal: the answer is "
            f"wrong here (ill-conditioned); use {MONTE_CARLO}"
        )


# ------------------------------------------------------------------ optimal loads
class AssemblyLoadBoundWarning(RuntimeWarning):
    """A transducer's best load lies on a bound of its search: the power still rises beyond it."""


#: Decades searched on each side of a transducer's characteristic loads.
ASSEMBLY_LOAD_DECADES = 3.0
#: Points a decade of the bracketing grid: the load power is smooth and unimodal in
#: log R_L (a resonance of the circuit is a decade wide at least), and each point of a
#: nonlinear assembly is a fixed-point solution (about 0.1 s), so the grid is coarse and
#: the bounded search refines between its neighbours.
ASSEMBLY_LOAD_GRID = 6


@dataclass(frozen=True)
class AssemblyLoad:
    """The load of one transducer that maximises its load power, the others as given.

    Attributes
    ----------
    transducer : int
        Its index.
    parameter : str
        ``r_load`` (ohm), or ``c_e`` (Ns/m) for a bare damper.
    value : float
        The best value found.
    power : float
        That transducer's load power there (W); electrical power for a bare damper.
    location : str
        ``interior``, ``lower bound`` or ``upper bound`` of the search.
    bounds : (float, float)
        The interval searched.
    """

    transducer: int
    parameter: str
    value: float
    power: float
    location: str
    bounds: tuple

    def to_dict(self) -> dict:
        name = self.parameter
        power = "power_load_optimal" if name == "r_load" else "power_electrical_optimal"
        return {
            f"{name}_optimal": self.value,
            power: self.power,
            f"{name}_optimal_location": self.location,
        }


def _load_bounds(assembly: Assembly, index: int) -> tuple[str, float, float]:
    """(parameter, lower, upper) of a transducer's search: its characteristic loads +- decades."""
    transducer = assembly.transducers[index]
    coupling = transducer.coupling
    if transducer.is_rectified:
        raise ValueError(
            f"transducer {index}'s {coupling.name} has no closed-form optimum for assemblies: "
            f"use {MONTE_CARLO}"
        )
    name = "r_load" if transducer.has_load else "c_e"
    candidates = [float(getattr(coupling, name))]
    m, c, _ = assembly.linear_matrices()
    if hasattr(coupling, "alpha"):
        d = assembly.incidence(transducer)
        c_dir = float(d @ c @ d) - transducer.electrical_damping
        if c_dir > 0:
            candidates.append(coupling.r_coil + coupling.alpha**2 / c_dir)
    if hasattr(coupling, "capacitance") and coupling.capacitance > 0:
        for f in assembly.natural_frequencies():
            if f > 0:
                candidates.append(1.0 / (2.0 * np.pi * f * coupling.capacitance))
    candidates = [x for x in candidates if np.isfinite(x) and x > 0]
    if not candidates:
        raise ValueError(
            f"transducer {index}'s `{name}` is 0: give it a value > 0 to search around"
        )
    span = 10.0**ASSEMBLY_LOAD_DECADES
    return name, min(candidates) / span, max(candidates) * span


def optimal_assembly_loads(
    assembly: Assembly, psd, transducer: int | None = None, solver: AnalyticMethod = LINEARISATION
) -> list[AssemblyLoad]:
    """The load resistance of one transducer, or of each, maximising its own load power.

    Each transducer's ``r_load`` (a bare damper's ``c_e``) is searched on a
    log grid (:data:`ASSEMBLY_LOAD_GRID` points a decade, :data:`ASSEMBLY_LOAD_DECADES` decades
    around its characteristic loads) and refined by a bounded scalar
    search, the other transducers held at their given values. A best value
    on a bound of the search is reported as such (``location``) with an
    :class:`AssemblyLoadBoundWarning`: the power still rises beyond it.

    Parameters
    ----------
    assembly : Assembly
    psd : float or Excitation
    transducer : int or None
        Its index; None for each transducer in turn.
    """
    excitation = assembly_excitation(psd)
    if not assembly.transducers:
        raise ValueError("the assembly has no transducer: no load to optimise")
    indices = range(len(assembly.transducers))
    if transducer is not None:
        indices = [check_int("transducer", transducer, 0, len(assembly.transducers) - 1)]
    return [_optimal_load(assembly, excitation, index, solver) for index in indices]


def _optimal_load(assembly, excitation, index, solver) -> AssemblyLoad:
    name, lo, hi = _load_bounds(assembly, index)
    path = f"transducer.{index}.{name}"

    def negative_power(log_x):
        device = assembly.updated({path: float(np.exp(log_x))})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t = predict_assembly(device, excitation, solver).transducers[index]
        return -(t.power_load if t.power_load is not None else t.power_electrical)

    n = int(min(np.ceil(ASSEMBLY_LOAD_GRID * np.log10(hi / lo)) + 1, 2001))
    grid = np.linspace(np.log(lo), np.log(hi), n)
    values = [negative_power(g) for g in grid]
    i = int(np.argmin(values))
    if i in (0, n - 1):
        location = "lower bound" if i == 0 else "upper bound"
        value = float(np.exp(grid[i]))
        warnings.warn(
            f"transducer {index}'s load power rises up to the {location} of the search, "
            f"{name} = {value:g} (bounds {lo:g} .. {hi:g}): the optimum lies beyond it",
            AssemblyLoadBoundWarning,
            stacklevel=3,
        )
        return AssemblyLoad(index, name, value, -float(values[i]), location, (lo, hi))
    best = optimize.minimize_scalar(
        negative_power, bounds=(grid[i - 1], grid[i + 1]), method="bounded",
        options={"xatol": 1e-10},
    )  # fmt: skip
    return AssemblyLoad(index, name, float(np.exp(best.x)), -float(best.fun), "interior", (lo, hi))
