"""Analytic power prediction: the driver that picks a method by name and checks its answer.

``predict(harvester, psd, method)`` returns a
:class:`~randvib.analytic.power_prediction.PowerPrediction`;
``expected_power`` returns just the expected power. The methods are the
family of :mod:`randvib.analytic.method`, listed in :data:`METHODS`:
each declares what it accepts (coloured input, a circuit state, potentials,
friction laws) and its validity, and the driver asks it before it computes;
a refusal names the methods that do take the case.

Which to use (numbers from the study ``linearisation-vs-averaging``):
``"linearisation"`` for quick estimates (low by up to 9 % at strong
friction, blind to k3 under white noise; the only method for a non-white
excitation or a circuit state); ``"averaging"`` for a closed-form-like
non-Gaussian correction (within 2 %, but it overstates the k3 effect);
``"fpk-fast"`` for the power and its k3 dependence to within the Monte Carlo
intervals (about 3 ms a point); ``"fpk"`` as the slow reference.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
from scipy import optimize

from randvib._validation import (
    check_choice,
    check_nonnegative,
    check_positive,
    check_scalar,
    check_scalar_device,
)
from randvib.analytic.assembly_prediction import predict_assembly
from randvib.analytic.averaging import AVERAGING
from randvib.analytic.bridge import BRIDGE_CLOSURE
from randvib.analytic.fixed_point import LinearisationDidNotConverge
from randvib.analytic.fokker_planck import FAST_FOKKER_PLANCK, FOKKER_PLANCK
from randvib.analytic.method import (
    AnalyticMethod,
    method_named,
    non_white,
    register_methods,
    white_level,
)
from randvib.analytic.power_prediction import PowerPrediction
from randvib.analytic.statistical_linearisation import LINEARISATION
from randvib.models.assembly import Assembly
from randvib.models.excitation import BROADCASTING, Excitation
from randvib.models.harvester import Harvester

#: The analytic methods by name, in the order the CLI and tables show them
#: (as scipy's ``solve_ivp`` METHODS): instances of
#: :class:`~randvib.analytic.method.AnalyticMethod`, whose declarations say
#: what each accepts. ``"linearisation"``: statistical linearisation, paper
#: Eq. 19-32 (:mod:`randvib.analytic.statistical_linearisation`);
#: ``"averaging"``: energy-envelope stochastic averaging
#: (:mod:`randvib.analytic.averaging`); ``"fpk-fast"``: the stationary FPK
#: equation on small grids made exact without friction, with kink corrections
#: and Richardson extrapolation, fast enough for sweeps; ``"fpk"``: the same
#: equation on fine grids, the slow reference (:mod:`randvib.analytic.fokker_planck`).
#: The registry is :data:`randvib.analytic.method.METHODS` (this dict), which
#: the refusals read; :func:`~randvib.analytic.method.method_named` looks a name up.
METHODS: dict[str, AnalyticMethod] = register_methods(
    LINEARISATION, AVERAGING, FAST_FOKKER_PLANCK, FOKKER_PLANCK, BRIDGE_CLOSURE
)


def default_method(harvester: Harvester) -> str:
    """The method used when none is named: the bridge closure for a device with a diode
    bridge (``randvib power`` chooses the same), statistical linearisation otherwise (and
    for an assembly, whose only method it is)."""
    if isinstance(harvester, Assembly):
        return "linearisation"
    return "bridge-closure" if harvester.is_rectified else "linearisation"


def predict(harvester: Harvester, psd, method=None) -> PowerPrediction:
    """Predict the stationary response and power under white noise or another excitation.

    Parameters
    ----------
    harvester : Harvester or Assembly
        Device; parameters may be arrays broadcasting with ``psd`` (scalars
        under a non-white excitation or with a circuit state). An
        :class:`~randvib.models.assembly.Assembly` (several DOFs, elements,
        transducers; scalars) gives an
        :class:`~randvib.analytic.assembly_prediction.AssemblyPrediction`:
        ``method="linearisation"`` only, exact for a linear assembly.
    psd : array_like or Excitation
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0 (white noise,
        paper Eq. 17), or an excitation object: ``White(S)`` is the same as
        S; a non-white one needs a method that declares ``coloured``.
    method : str or AnalyticMethod, optional
        A key of :data:`METHODS` (or a method object). Default
        (:func:`default_method`): ``"bridge-closure"`` for a device with a
        diode bridge, else ``"linearisation"``
        (paper Eq. 19-32), ``"averaging"`` (stochastic averaging, beyond
        Gaussian closure), ``"fpk-fast"`` (small corrected FPK grids; the
        power and its k3 dependence to about 0.05 %, about 3 ms per point) or
        ``"fpk"`` (grid solution of the stationary FPK equation; reference,
        about 0.5 s per point). Only ``"linearisation"`` accepts a non-white
        excitation or a coupling with a circuit state (inductive, piezo: the
        circuit is a state of the linearised system, scalar parameters).

    Returns
    -------
    PowerPrediction

    Raises
    ------
    ValueError
        For an unknown method, a bad ``psd``, a case the method does not
        accept (a non-white excitation, a circuit state, a potential or a
        friction law it cannot treat: one line naming the methods that do),
        a device with neither damping nor friction (no stationary state), or
        values at which the method's result is not a finite float64 (overflow
        at extreme parameters).

    Notes
    -----
    Potentials: every method refuses a non-confining potential (no
    stationary state); ``"averaging"`` treats the monostable one only;
    ``"fpk"``/``"fpk-fast"`` any confining potential and the free mass;
    ``"linearisation"`` any confining potential, and the free mass under
    white noise with a resistive coupling (exact power without friction,
    Gaussian displacement; see :mod:`randvib.analytic.linearisation`). For
    the free mass ``displacement_variance`` and ``stroke_exceedance`` are None.

    Examples
    --------
    >>> import randvib as rv
    >>> result = rv.predict(rv.preset("figure9"), 1.0)
    >>> print(f"{result.power_electrical:.4e} W, E[z'^2] = {result.velocity_variance:.4e} (m/s)^2")
    2.4619e-03 W, E[z'^2] = 2.4619e-02 (m/s)^2
    >>> print(f"{rv.predict(rv.preset('figure9'), 1.0, 'fpk-fast').power_electrical:.4e} W")
    2.4642e-03 W
    >>> rv.METHODS["averaging"].accepts(rv.preset("figure9"), rv.BandPass(1.0, 8.0, 0.1))
    False
    """
    if getattr(psd, "is_event", False):
        raise ValueError(
            f"randvib.predict gives stationary statistics; the {psd.name} event's transient "
            "response is randvib.transient_response (or Monte Carlo, randvib.simulate_transient)"
        )
    solver = method_named(default_method(harvester) if method is None else method)
    if isinstance(harvester, Assembly):  # several DOFs: randvib.analytic.assembly_prediction
        return predict_assembly(harvester, psd, solver)
    solver.require(harvester, psd)
    _refuse_undamped(harvester)
    if not non_white(psd):  # White(S) runs exactly the code of the number S
        psd = check_positive("psd", white_level(psd), "(m/s^2)^2/Hz")
    result = _finite(solver, harvester, psd)
    inputs = _swept_inputs(harvester, psd)
    return dataclasses.replace(result, inputs=inputs) if inputs else result


def _swept_inputs(harvester: Harvester, psd) -> dict:
    """The array-valued inputs of a broadcast call (``psd``, device parameters), by name."""
    values = {"psd": psd} if not isinstance(psd, Excitation) else {}
    values.update(harvester.parameters())
    return {
        name: np.asarray(value, dtype=float)
        for name, value in values.items()
        if not isinstance(value, str) and np.ndim(value) > 0
    }


def _refuse_undamped(harvester: Harvester) -> None:
    """No damping and no friction: the energy grows without bound, nothing is stationary.

    A circuit state (inductive, piezo) dissipates in its resistance: it damps.
    """
    c = np.asarray(harvester.c_m + harvester.c_e, dtype=float)
    friction = harvester.friction
    if harvester.has_circuit or harvester.is_rectified:
        return
    if np.any(c == 0) and (friction is None or friction.vanishes):
        raise ValueError(
            "the device has no damping (c_m + c_e = 0) and no friction: under random "
            "excitation its energy grows without bound and has no stationary power; "
            "give `c_m` or `c_e` > 0"
        )


def _finite(solver: AnalyticMethod, harvester: Harvester, psd) -> PowerPrediction:
    """``solver.solve(harvester, psd)``, refused where it is not a finite float64 (scalar case)."""
    method = solver.name
    try:
        with np.errstate(all="ignore"):
            result = solver.solve(harvester, psd)
    except (ArithmeticError, RuntimeError, ValueError) as exc:
        own = _raised_by_randvib(exc) and not isinstance(exc, ArithmeticError)
        if isinstance(exc, LinearisationDidNotConverge) and _extreme_values(harvester, psd):
            # a parameter such as inductance = 1e-300 H, not the excitation, broke the search
            what = "statistical linearisation found no fixed point"
            raise ValueError(_out_of_range(method, harvester, psd, what)) from None
        if own and isinstance(exc, ValueError):
            raise  # randvib's own explanation (no stationary response, a potential it cannot treat)
        # a library's (scipy: "array must not contain infs or NaNs") after an
        # overflow; randvib's own RuntimeError (no convergence) is not one
        what = f"{type(exc).__name__}: {exc}"
        raise ValueError(_out_of_range(method, harvester, psd, what, overflow=not own)) from None
    values = {
        "velocity_variance": result.velocity_variance,
        "displacement_variance": result.displacement_variance,  # None for the free mass
        "power_electrical": result.power_electrical,  # zero without electrical damping
    }
    values = {name: value for name, value in values.items() if value is not None}
    if any(np.ndim(v) for v in values.values()):
        return result  # arrays: the caller's grid may hold points of any kind
    bad = [
        f"{name} = {value!r}"
        for name, value in values.items()
        if not np.isfinite(value) or (value <= 0 and name != "power_electrical")
    ]
    if bad:
        raise ValueError(_out_of_range(method, harvester, psd, ", ".join(bad)))
    solver.check_answer(harvester, psd, result)
    return result


def _raised_by_randvib(exc: BaseException) -> bool:
    """Whether ``exc`` was raised in randvib's own code (not in numpy or scipy)."""
    from pathlib import Path

    tb = exc.__traceback__
    if tb is None:
        return False
    while tb.tb_next is not None:
        tb = tb.tb_next
    package = Path(__file__).resolve().parents[1]
    return Path(tb.tb_frame.f_code.co_filename).resolve().is_relative_to(package)


#: Magnitudes beyond which a parameter's products and powers leave float64 in
#: the analytic methods (k3 E[z^2]^2, S m / c, ...): 1e100 squared is 1e200.
EXTREME_MAGNITUDE = 1e100


def _extreme_values(harvester: Harvester, psd) -> list[str]:
    """``name = value`` of the parameters (and PSD numbers) of extreme magnitude."""
    level = psd.parameters() if isinstance(psd, Excitation) else {"psd": psd}
    values = {**harvester.parameters(), **level}
    return [
        f"{name} = {value:g}"
        for name, value in values.items()
        if isinstance(value, int | float)
        and value != 0
        and not 1.0 / EXTREME_MAGNITUDE <= abs(value) <= EXTREME_MAGNITUDE
    ]


def _out_of_range(method, harvester, psd, what, overflow: bool = True) -> str:
    """The refusal of a non-finite result; float64's range is blamed only when it is the cause."""
    level = psd.parameters() if isinstance(psd, Excitation) else psd
    if np.ndim(level) == 0 and not isinstance(level, dict):
        level = float(level)  # "psd = 0.005", not "psd = array(0.005)"
    text = f"method {method!r} has no finite result at these values ({what}): psd = {level!r}, "
    extreme = _extreme_values(harvester, psd) if overflow else []
    if not extreme:
        return text + str(harvester.parameters())
    return (
        text + f"{harvester.parameters()}; {', '.join(extreme)} is beyond the range this "
        "method can compute in float64 (|x| within 1e-100 .. 1e100)"
    )


def expected_power(
    harvester: Harvester, psd, method: str | None = None, *, into: str = "electrical"
):
    """Expected power (W) delivered by the harvester under white noise or an excitation.

    ``psd`` is as in :func:`predict` (a number S, or an excitation object;
    a non-white one with ``method="linearisation"``).
    ``into="electrical"`` gives E[P_e] = c_e E[z'^2] (paper Eq. 32);
    ``into="load"`` gives the share dissipated in R_L (needs a circuit).
    Broadcasts over ``psd`` and array-valued harvester parameters.

    Examples
    --------
    >>> import numpy as np
    >>> import randvib as rv
    >>> device = rv.preset("figure9")
    >>> print(f"{rv.expected_power(device, 1.0):.4e} W")  # Eq. 32
    2.4619e-03 W
    >>> rv.expected_power(device, np.array([1.0, 0.5, 0.1])).round(6)  # broadcasts over S
    array([0.002462, 0.001163, 0.000183])
    >>> print(f"{rv.expected_power(device, rv.BandPass(1.0, 8.0, 0.1)):.4e} W")  # coloured input
    1.1147e-03 W
    """
    check_choice("into", into, ("electrical", "load"))
    result = predict(harvester, psd, method)
    if into == "load":
        if result.power_load is None:
            raise ValueError(
                "`into`='load' needs the circuit: build the harvester with Harvester.from_electrical"
            )
        return result.power_load
    return result.power_electrical


def velocity_variance(harvester: Harvester, psd, method: str | None = None):
    """E[z'^2] ((m/s)^2) (paper Eq. 20 for linearisation; ``method`` as :func:`predict`'s)."""
    return predict(harvester, psd, method).velocity_variance


def optimal_load_resistance_linear(c_m, alpha, r_coil):
    """Load resistance (ohm) that maximises load power without friction.

    With Fc = 0, E[v^2] = S m / (4 (c_m + c_e)) and c_e = alpha^2/(R_L + R_C),
    so P_L is proportional to R_L / ((R_L + R_C)(c_m (R_L + R_C) + alpha^2)).
    Setting its logarithmic derivative to zero gives
    R_L* = sqrt(R_C^2 + R_C alpha^2 / c_m), independent of S, m, k and k3.
    """
    c_m = check_positive("c_m", c_m, "Ns/m")
    alpha = check_positive("alpha", alpha, "Wb/m")
    r_coil = check_nonnegative("r_coil", r_coil, "ohm")
    return np.sqrt(r_coil**2 + r_coil * alpha**2 / c_m)


class LoadBoundWarning(RuntimeWarning):
    """The best load of :func:`optimal_load_resistance` lies on a bound of its search: no maximum."""


#: Decades searched on each side of the device's characteristic loads.
LOAD_SEARCH_DECADES = 4.0


def load_search_bounds(harvester: Harvester) -> tuple[float, float]:
    """The interval of R_L (ohm) that :func:`optimal_load_resistance` searches by default.

    Derived from the device, never fixed: the characteristic loads of its
    coupling -- the matched impedance R_C + alpha^2/c_m of a coil (the load at
    which c_e = c_m with R_C = 0), 1/(omega_n C_p) of a piezo element (its
    capacitive impedance at omega_n = sqrt(|k|/m)) or c_m/theta^2 without C_p,
    and the white-noise optimum of the linear device
    (:meth:`~randvib.models.coupling.Coupling.white_noise_optimal_load`) where
    it is positive -- with :data:`LOAD_SEARCH_DECADES` decades on each side.
    """
    coupling = harvester.electrical
    m, c_m, k = (np.float64(v) for v in (harvester.m, harvester.c_m, harvester.k))
    candidates = [lambda: coupling.white_noise_optimal_load(m, c_m, k)]
    if hasattr(coupling, "alpha"):
        candidates.append(lambda: coupling.r_coil + np.float64(coupling.alpha) ** 2 / c_m)
    if hasattr(coupling, "theta"):
        candidates.append(lambda: c_m / np.float64(coupling.theta) ** 2)
        if coupling.is_dynamic:
            candidates.append(lambda: 1.0 / (np.sqrt(abs(k) / m) * coupling.capacitance))
    loads = []
    for candidate in candidates:
        # c_m = 0, k = 0 or extreme parameters give inf or nan, dropped below
        with np.errstate(all="ignore"):
            try:
                loads.append(candidate())
            except (OverflowError, ZeroDivisionError):
                pass
    loads = [float(r) for r in loads if np.isfinite(r) and r > 0]
    if not loads:
        raise ValueError(
            f"optimal_load_resistance cannot derive a search interval from the coupling "
            f"{coupling!r}; give `bounds`=(lower, upper) in ohm"
        )
    span = 10.0**LOAD_SEARCH_DECADES
    return min(loads) / span, max(loads) * span


class OptimalLoad(tuple):
    """``(r_load, power)`` of :func:`optimal_load_resistance`, saying where the optimum lies.

    Unpacks as the pair ``r_load, power``; ``location`` is ``"interior"``
    (a maximum inside ``bounds``), ``"lower bound"`` or ``"upper bound"``
    (the power still rises towards that end of the interval searched: the
    true optimum lies beyond it, or is the limit R_L -> 0, as for a coil
    with R_C = 0); ``bounds`` is the interval searched (ohm).
    """

    def __new__(cls, r_load: float, power: float, location: str, bounds: tuple):
        obj = super().__new__(cls, (r_load, power))
        obj.location = location
        obj.bounds = bounds
        return obj

    @property
    def r_load(self) -> float:
        """Optimal (or best-in-bounds) load resistance (ohm)."""
        return self[0]

    @property
    def power(self) -> float:
        """Expected load power there (W)."""
        return self[1]

    @property
    def interior(self) -> bool:
        """True when the optimum lies strictly inside the interval searched."""
        return self.location == "interior"


def optimal_load_resistance(harvester: Harvester, psd, method: str = "linearisation", bounds=None):
    """Load resistance R_L (ohm) maximising expected load power (scalar inputs).

    The harvester must have a coupling (``Harvester.from_electrical`` or
    ``Harvester.with_coupling``: resistive, inductive or piezo); its
    ``r_load`` is the starting value and is replaced during the search. The
    search is a bounded scalar minimisation over log R_L, with friction
    through ``method`` (a circuit state: ``"linearisation"``). Without
    friction, on the linear device under white noise, it finds the classical
    optima (:meth:`randvib.models.coupling.Coupling.white_noise_optimal_load`:
    sqrt(R_C^2 + R_C alpha^2/c_m) resistive, its inductive extension, and
    sqrt(m / (C_p (C_p k + theta^2))) piezo).

    Parameters
    ----------
    bounds : (float, float), optional
        Interval of R_L searched (ohm). Default: derived from the device
        (:func:`load_search_bounds`).

    Returns
    -------
    OptimalLoad
        The pair ``(r_load, power)``: the load resistance (ohm) and the
        expected load power there (W), with ``location`` "interior",
        "lower bound" or "upper bound". An optimum on a bound is not a
        maximum: it also raises a :class:`LoadBoundWarning` saying so (with
        R_C = 0 the load power of a coil rises as R_L -> 0).

    Examples
    --------
    >>> import randvib as rv
    >>> wired = rv.Harvester.from_electrical(
    ...     m=0.0226, c_m=0.049, k=57.4, alpha=0.1992, r_load=2.0, r_coil=0.48,
    ...     friction=rv.Coulomb(0.0058),
    ... )
    >>> r_load, power = rv.optimal_load_resistance(wired, 1.0)
    >>> print(f"R_L* = {r_load:.3f} ohm, P_L = {power:.4e} W")
    R_L* = 0.745 ohm, P_L = 1.1025e-03 W
    >>> print(f"{rv.optimal_load_resistance_linear(0.049, 0.1992, 0.48):.3f} ohm")  # Fc = 0
    0.787 ohm
    """
    if harvester.electrical is None:
        raise ValueError(
            "optimal_load_resistance needs a coupling: Harvester.from_electrical(...) or "
            "Harvester.with_coupling(...)"
        )
    check_scalar_device(harvester, "optimal_load_resistance")
    if not isinstance(psd, Excitation):
        psd = check_scalar("psd", psd, "a white-noise level S in (m/s^2)^2/Hz", BROADCASTING)
        psd = float(check_positive("psd", psd, "(m/s^2)^2/Hz"))
    if bounds is None:
        bounds = load_search_bounds(harvester)
    lo, hi = (float(check_positive("bounds", b, "ohm")) for b in bounds)
    if not lo < hi:
        raise ValueError(f"`bounds` must satisfy lower < upper, got {bounds!r}")

    def negative_power(log_r):
        device = harvester.updated(r_load=float(np.exp(log_r)))
        return -float(expected_power(device, psd, method, into="load"))

    # Bracket the optimum on a coarse log grid first (12 points a decade):
    # P_L(R) is unimodal in practice but flat tails make a blind bounded
    # search slow to converge.
    # (at most 4001: an interval of 330 decades, float64's whole range)
    decades = np.log10(hi) - np.log10(lo)
    n = int(min(max(61, np.ceil(12 * decades) + 1), 4001))
    grid = np.linspace(np.log(lo), np.log(hi), n)
    values = [negative_power(g) for g in grid]
    if not min(values) < 0:
        # no load takes any power (a coil whose inductance blocks the current,
        # a power below float64's range): no optimum to report
        raise ValueError(
            f"no load resistance in `bounds` ({lo:g}, {hi:g}) ohm takes any power from this "
            f"device (the load power is {-max(values):g} W at every load tried) under {psd!r}; "
            f"check the coupling {harvester.electrical!r}"
        )
    i = int(np.argmin(values))
    if i in (0, len(grid) - 1):
        # the power still rises towards this end: the bound is no maximum
        location = "lower bound" if i == 0 else "upper bound"
        r_load, power = float(np.exp(grid[i])), -float(values[i])
        warnings.warn(
            f"the load power rises up to the {location} of the search, R_L = {r_load:g} ohm "
            f"(bounds ({lo:g}, {hi:g}) ohm): the optimum lies beyond it"
            + (
                " (R_L -> 0 with r_coil = 0)"
                if i == 0 and _coil_without_resistance(harvester)
                else ""
            )
            + "; the value returned is the best load inside the bounds, not a maximum",
            LoadBoundWarning,
            stacklevel=2,
        )
        return OptimalLoad(r_load, power, location, (lo, hi))
    a, b = grid[i - 1], grid[i + 1]
    res = optimize.minimize_scalar(
        negative_power, bounds=(a, b), method="bounded", options={"xatol": 1e-10}
    )
    return OptimalLoad(float(np.exp(res.x)), -float(res.fun), "interior", (lo, hi))


def _coil_without_resistance(harvester: Harvester) -> bool:
    """A coil coupling with R_C = 0 (whose load power rises as R_L -> 0)."""
    return getattr(harvester.electrical, "r_coil", None) == 0
