"""Analytic power prediction: one entry point, methods chosen by name.

``predict(harvester, psd, method)`` returns a :class:`PowerPrediction`;
``expected_power`` returns just the expected power. Methods register in
:data:`METHODS`; ``"linearisation"`` is the paper's Eq. 19-32.

Which to use (numbers from the study ``linearisation-vs-averaging``):
``"linearisation"`` for quick estimates (low by up to 9 % at strong
friction, blind to k3); ``"averaging"`` for a closed-form-like
non-Gaussian correction (within 2 %, but it overstates the k3 effect);
``"fpk-fast"`` for the power and its k3 dependence to within the Monte Carlo
intervals (about 3 ms a point); ``"fpk"`` as the slow reference.

``psd`` may also be an excitation object (:mod:`randvib.models.excitation`):
:class:`~randvib.models.excitation.White` runs exactly the code of its
level; a non-white one is accepted by the methods of :data:`COLOURED`
(``"linearisation"``: statistical linearisation for any spectrum) and
refused by the others, which assume white noise.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy import optimize, special

from randvib import _display
from randvib._validation import (
    check_choice,
    check_nonnegative,
    check_positive,
    check_scalar,
    check_scalar_device,
    scalar_or_array,
)
from randvib.analytic.averaging import averaging_statistics
from randvib.analytic.fokker_planck import fast_fpk_moments, fpk_moments
from randvib.analytic.linearisation import equivalent_damping, linear_displacement_variance
from randvib.analytic.statistical_linearisation import statistical_linearisation
from randvib.models.excitation import BROADCASTING, Excitation, as_excitation
from randvib.models.harvester import Harvester
from randvib.models.potential import CONFINING


@dataclass(frozen=True)
class PowerPrediction:
    """Stationary statistics predicted by an analytic method (SI units).

    Attributes
    ----------
    method : str
    c_eq : float or ndarray
        Equivalent viscous damping (Ns/m), defined as S m / (4 E[v^2]) under
        white noise; under another excitation the statistical linearisation's
        c + E[v F(v)] / E[v^2] (the two agree under white noise).
    velocity_variance : float or ndarray
        E[z'^2] ((m/s)^2) (paper Eq. 20).
    displacement_variance : float or ndarray
        E[z^2] (m^2).
    mean_abs_velocity : float or ndarray
        E|z'| (m/s).
    power_electrical : float or ndarray
        E[P_e] = c_e E[z'^2] (W) (paper Eq. 31-32).
    power_load : float, ndarray or None
        E[i^2 R_L] (W), when the harvester has a circuit.
    circuit_mean_square : float or None
        E[i^2] (A^2) or E[V^2] (V^2) of a circuit state (inductive or piezo
        coupling); None without one (and left out of :meth:`to_dict`).
    stroke_exceedance : float, ndarray or None
        P(|z| > stroke), the stationary fraction of time beyond the
        harvester's stroke; None without a stroke, for the free mass and for
        methods that do not give it (averaging). Linearisation's is the
        Gaussian estimate erfc(stroke / sqrt(2 E[z^2])) (approximate; far off
        for a double well, see :mod:`randvib.analytic.linearisation`).

    ``displacement_variance`` is None for the free mass (k = k3 = 0): its
    displacement has no stationary law.
    """

    method: str
    c_eq: object
    velocity_variance: object
    displacement_variance: object
    mean_abs_velocity: object
    power_electrical: object
    power_load: object = None
    circuit_mean_square: object = None
    stroke_exceedance: object = None

    def to_dict(self) -> dict:
        """Plain dict with floats or lists, ready for JSON.

        ``circuit_mean_square`` and ``stroke_exceedance`` only when given.
        """
        out = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in asdict(self).items()}
        for optional in ("circuit_mean_square", "stroke_exceedance"):
            if out[optional] is None:
                del out[optional]
        return out

    def _quantities(self) -> list[tuple[str, object, str]]:
        """(name, value, unit) of every field with a value."""
        out = [(name, getattr(self, name), unit) for name, unit in _UNITS.items()]
        return [(name, value, unit) for name, value, unit in out if value is not None]

    def to_frame(self):
        """The prediction as a :class:`pandas.DataFrame`.

        One row for scalar inputs; for a broadcast sweep one row per point
        (the fields broadcast together and are flattened in C order, so row
        ``i`` is ``numpy.unravel_index(i, shape)`` of the sweep's shape).
        Columns are the fields (SI units, see the class) and ``method``.
        """
        pd = _display.pandas()
        names = [name for name, _, _ in self._quantities()]
        values = np.broadcast_arrays(
            *(np.asarray(v, dtype=float) for _, v, _ in self._quantities())
        )
        frame = pd.DataFrame({n: v.ravel() for n, v in zip(names, values, strict=True)})
        frame.insert(0, "method", self.method)
        return frame

    def _rows(self):
        return [(name, _display.number(value), unit) for name, value, unit in self._quantities()]

    def __repr__(self) -> str:
        fields = ", ".join(
            f"{name}={_display.number(value)}" for name, value, _ in self._quantities()
        )
        return f"PowerPrediction(method={self.method!r}, {fields})"

    def _repr_html_(self) -> str:
        return _display.html_table(f"Prediction ({self.method})", self._rows())


#: Units of the fields of :class:`PowerPrediction`, in the order they are shown.
_UNITS = {
    "power_electrical": "W",
    "power_load": "W",
    "c_eq": "Ns/m",
    "velocity_variance": "(m/s)^2",
    "displacement_variance": "m^2",
    "mean_abs_velocity": "m/s",
    "circuit_mean_square": "A^2 or V^2",
    "stroke_exceedance": "probability",
}


def _finish(
    harvester: Harvester,
    method: str,
    velocity_variance,
    displacement_variance,
    mean_abs_velocity,
    psd,
    stroke_exceedance=None,
) -> PowerPrediction:
    """Fill the derived fields common to every method.

    The free mass's displacement statistics (not stationary) become None.
    """
    vv = np.asarray(velocity_variance, dtype=float)
    c_eq = np.asarray(psd, dtype=float) * harvester.m / (4.0 * vv)
    power = harvester.c_e * vv
    power_load = None
    if harvester.electrical is not None:
        power_load = power * harvester.electrical.load_fraction

    def clean(x):
        return scalar_or_array(np.asarray(x, dtype=float))

    free = harvester.potential.is_free
    if free or harvester.stroke is None:
        stroke_exceedance = None
    return PowerPrediction(
        method=method,
        c_eq=clean(c_eq),
        velocity_variance=clean(vv),
        displacement_variance=None if free else clean(displacement_variance),
        mean_abs_velocity=clean(mean_abs_velocity),
        power_electrical=clean(power),
        power_load=None if power_load is None else clean(power_load),
        stroke_exceedance=None if stroke_exceedance is None else clean(stroke_exceedance),
    )


def _linearisation(harvester: Harvester, psd) -> PowerPrediction:
    c_eq = equivalent_damping(harvester, psd)
    vv = np.asarray(psd) * harvester.m / (4.0 * np.asarray(c_eq))  # Eq. 20
    zz = None if harvester.potential.is_free else linear_displacement_variance(harvester, vv)
    return _finish(
        harvester,
        "linearisation",
        vv,
        zz,
        np.sqrt(2.0 / np.pi * vv),
        psd,
        None if zz is None else _gaussian_exceedance(harvester.stroke, zz),
    )


def _gaussian_exceedance(stroke, displacement_variance):
    """P(|z| > stroke) = erfc(stroke / sqrt(2 E[z^2])) of a zero-mean Gaussian z (or None)."""
    if stroke is None:
        return None
    return special.erfc(stroke / np.sqrt(2.0 * np.asarray(displacement_variance, dtype=float)))


def _averaging(harvester: Harvester, psd) -> PowerPrediction:
    r = averaging_statistics(harvester, psd)
    return _finish(
        harvester,
        "averaging",
        r.velocity_variance,
        r.displacement_variance,
        r.mean_abs_velocity,
        psd,
    )


def _fpk(harvester: Harvester, psd) -> PowerPrediction:
    vv, zz, av, beyond = fpk_moments(harvester, psd)
    return _finish(harvester, "fpk", vv, zz, av, psd, beyond)


def _fpk_fast(harvester: Harvester, psd) -> PowerPrediction:
    vv, zz, av, beyond = fast_fpk_moments(harvester, psd)
    return _finish(harvester, "fpk-fast", vv, zz, av, psd, beyond)


def _coloured_linearisation(harvester: Harvester, excitation: Excitation) -> PowerPrediction:
    """Statistical linearisation under a non-white excitation (scalar parameters)."""
    r = statistical_linearisation(harvester, excitation)
    beyond = _gaussian_exceedance(harvester.stroke, r.displacement_variance)
    return PowerPrediction(
        method="linearisation",
        c_eq=r.c_eq,
        velocity_variance=r.velocity_variance,
        displacement_variance=r.displacement_variance,
        mean_abs_velocity=float(np.sqrt(2.0 / np.pi * r.velocity_variance)),  # Gaussian v
        power_electrical=r.power_electrical,
        power_load=r.power_load,
        circuit_mean_square=r.circuit_variance,
        stroke_exceedance=None if beyond is None else float(beyond),
    )


#: Analytic methods by name: callables (harvester, psd) -> PowerPrediction.
#: ``"averaging"``: energy-envelope stochastic averaging (randvib.analytic.averaging);
#: ``"fpk"``: finite-volume stationary FPK solution (randvib.analytic.fokker_planck),
#: the slow reference; ``"fpk-fast"``: the same equation on small grids made
#: exact without friction, with kink corrections and Richardson
#: extrapolation (fokker_planck.fast_fpk_statistics), fast enough for sweeps.
METHODS = {
    "linearisation": _linearisation,
    "averaging": _averaging,
    "fpk-fast": _fpk_fast,
    "fpk": _fpk,
}

#: The methods of :data:`METHODS` that accept a non-white excitation:
#: callables (harvester, excitation) -> PowerPrediction. The others assume
#: white noise (paper Eq. 17) and refuse it.
COLOURED = {"linearisation": _coloured_linearisation}


def _refuse_coloured(method: str, excitation: Excitation):
    accepted = ", ".join(repr(name) for name in COLOURED)
    raise ValueError(
        f"method {method!r} assumes white noise; the {excitation.name!r} excitation is "
        f"accepted by method {accepted} (and randvib.statistical_linearisation)"
    )


#: The methods of :data:`METHODS` that accept a coupling with a circuit state
#: (coil inductance, piezo capacitance), under any excitation they accept:
#: statistical linearisation with the circuit state in the linear system.
CIRCUIT = {"linearisation": _coloured_linearisation}


def _refuse_circuit(method: str, harvester: Harvester):
    accepted = ", ".join(repr(name) for name in CIRCUIT)
    raise ValueError(
        f"method {method!r} assumes resistive coupling (a viscous c_e); the "
        f"{harvester.electrical.name} coupling's circuit state is handled by method "
        f"{accepted} (and randvib.simulate)"
    )


def predict(harvester: Harvester, psd, method: str = "linearisation") -> PowerPrediction:
    """Predict the stationary response and power under white noise or another excitation.

    Parameters
    ----------
    harvester : Harvester
        Device; parameters may be arrays broadcasting with ``psd`` (scalars
        under a non-white excitation).
    psd : array_like or Excitation
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0 (white noise,
        paper Eq. 17), or an excitation object: ``White(S)`` is the same as
        S; a non-white one needs a method of :data:`COLOURED`.
    method : str
        A key of :data:`METHODS`: ``"linearisation"`` (paper Eq. 19-32),
        ``"averaging"`` (stochastic averaging, beyond Gaussian closure),
        ``"fpk-fast"`` (small corrected FPK grids; the power and its k3
        dependence to about 0.05 %, about 3 ms per point) or ``"fpk"`` (grid
        solution of the stationary FPK equation; reference, about 0.5 s per
        point). Only ``"linearisation"`` accepts a non-white excitation or
        a coupling with a circuit state (inductive, piezo: the circuit is a
        state of the linearised system, scalar parameters).

    Returns
    -------
    PowerPrediction

    Raises
    ------
    ValueError
        For an unknown method, a bad ``psd``, a non-white excitation with
        a method that assumes white noise, a potential the method cannot
        treat (one line naming what it accepts), a device with neither
        damping nor friction (no stationary state), or values at which the
        method's result is not a finite float64 (overflow at extreme parameters).

    Notes
    -----
    Potentials: every method refuses a non-confining potential (no
    stationary state); ``"averaging"`` treats the monostable one only;
    ``"fpk"``/``"fpk-fast"`` any confining potential and the free mass;
    ``"linearisation"`` any confining potential and the free mass (exact
    power without friction, Gaussian displacement; see
    :mod:`randvib.analytic.linearisation`). For the free mass
    ``displacement_variance`` and ``stroke_exceedance`` are None.

    Examples
    --------
    >>> import randvib as rv
    >>> result = rv.predict(rv.preset("figure9"), 1.0)
    >>> print(f"{result.power_electrical:.4e} W, E[z'^2] = {result.velocity_variance:.4e} (m/s)^2")
    2.4619e-03 W, E[z'^2] = 2.4619e-02 (m/s)^2
    >>> print(f"{rv.predict(rv.preset('figure9'), 1.0, 'fpk-fast').power_electrical:.4e} W")
    2.4642e-03 W
    """
    check_choice("method", method, tuple(METHODS))
    harvester.potential.require(f"method {method!r}", CONFINING + ("free",))
    _refuse_undamped(harvester)
    if harvester.has_circuit:
        if method not in CIRCUIT:
            _refuse_circuit(method, harvester)
        if not isinstance(psd, Excitation):
            psd = as_excitation(float(check_positive("psd", psd, "(m/s^2)^2/Hz")))
        return _finite(method, harvester, psd, CIRCUIT[method])
    if isinstance(psd, Excitation):
        if not psd.is_white:
            if method not in COLOURED:
                _refuse_coloured(method, psd)
            return _finite(method, harvester, psd, COLOURED[method])
        psd = psd.level  # white: exactly the code of a plain number
    check_positive("psd", psd, "(m/s^2)^2/Hz")
    return _finite(method, harvester, psd, METHODS[method])


def _refuse_undamped(harvester: Harvester) -> None:
    """No damping and no friction: the energy grows without bound, nothing is stationary.

    A circuit state (inductive, piezo) dissipates in its resistance: it damps.
    """
    c = np.asarray(harvester.c_m + harvester.c_e, dtype=float)
    friction = harvester.friction
    if harvester.has_circuit:
        return
    if np.any(c == 0) and (friction is None or friction.vanishes):
        raise ValueError(
            "the device has no damping (c_m + c_e = 0) and no friction: under random "
            "excitation its energy grows without bound and has no stationary power; "
            "give `c_m` or `c_e` > 0"
        )


def _finite(method: str, harvester: Harvester, psd, solver) -> PowerPrediction:
    """``solver(harvester, psd)``, refused where it is not a finite float64 (scalar case)."""
    try:
        with np.errstate(all="ignore"):
            result = solver(harvester, psd)
    except (ArithmeticError, RuntimeError, ValueError) as exc:
        own = _raised_by_randvib(exc) and not isinstance(exc, ArithmeticError)
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
    text = f"method {method!r} has no finite result at these values ({what}): psd = {level!r}, "
    extreme = _extreme_values(harvester, psd) if overflow else []
    if not extreme:
        return text + str(harvester.parameters())
    return (
        text + f"{harvester.parameters()}; {', '.join(extreme)} is beyond the range this "
        "method can compute in float64 (|x| within 1e-100 .. 1e100)"
    )


def expected_power(
    harvester: Harvester, psd, method: str = "linearisation", *, into: str = "electrical"
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


def velocity_variance(harvester: Harvester, psd, method: str = "linearisation"):
    """E[z'^2] ((m/s)^2) (paper Eq. 20 for linearisation)."""
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


def optimal_load_resistance(
    harvester: Harvester, psd, method: str = "linearisation", bounds=(1e-6, 1e6)
):
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

    Returns
    -------
    r_load : float
        Optimal load resistance (ohm).
    power : float
        Expected load power there (W).

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
    lo, hi = (float(check_positive("bounds", b, "ohm")) for b in bounds)
    if not lo < hi:
        raise ValueError(f"`bounds` must satisfy lower < upper, got {bounds!r}")

    def negative_power(log_r):
        device = harvester.updated(r_load=float(np.exp(log_r)))
        return -float(expected_power(device, psd, method, into="load"))

    # Bracket the optimum on a coarse log grid first: P_L(R) is unimodal in
    # practice but flat tails make a blind bounded search slow to converge.
    grid = np.linspace(np.log(lo), np.log(hi), 61)
    values = [negative_power(g) for g in grid]
    if not min(values) < 0:
        # no load takes any power (a coil whose inductance blocks the current,
        # a power below float64's range): no optimum to report
        raise ValueError(
            f"no load resistance in `bounds` {bounds!r} ohm takes any power from this device "
            f"(the load power is {-max(values):g} W at every load tried) under {psd!r}; "
            f"check the coupling {harvester.electrical!r}"
        )
    i = int(np.argmin(values))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    res = optimize.minimize_scalar(
        negative_power, bounds=(a, b), method="bounded", options={"xatol": 1e-10}
    )
    return float(np.exp(res.x)), -float(res.fun)
