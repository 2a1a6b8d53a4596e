"""The quantities randvib reports, with their units: one vocabulary.

Every name that a result, a command's table or a study's report shows beside a
unit is declared here once, with its SI unit, what it is, and the symbol a
report prints for it: the device's parameters (paper Eq. 1-3), the
excitation's, the record's channels, and the statistics that the analytic
methods predict and the Monte Carlo runs estimate. The result types
(:class:`~randvib.montecarlo.results.SimulationResult`,
:class:`~randvib.analytic.power_prediction.PowerPrediction`,
:class:`~randvib.analytic.statistical_linearisation.LinearisationResult`,
:class:`~randvib.identification.result.IdentificationResult`), the command
line and the studies look units up with :func:`unit` rather than keep lists
of their own. A friction law's or a coupling's own parameters are declared by
its class (:func:`randvib.models.parameters.parameter`), so that a law
defined elsewhere brings its units with it.

Units are written in ASCII (``(m/s^2)^2/Hz``, ``N/m^3``); :func:`unicode_unit`
gives the form a Markdown report prints (``(m/s²)²/Hz``).

Examples
--------
>>> unit("power_electrical")
'W'
>>> QUANTITIES["psd"].description
'one-sided PSD level S of the base acceleration (paper Eq. 17)'
>>> report_header("k3")
'k3 (N/m³)'
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["QUANTITIES", "Quantity", "parameter_unit", "report_header", "unicode_unit", "unit"]


class Quantity(NamedTuple):
    """One reported quantity: its SI unit (``""``: dimensionless), meaning and symbol."""

    unit: str
    description: str
    #: How a report's or a time table's header names it; None: by its name.
    symbol: str | None = None


#: Quantity name -> :class:`Quantity`, by kind: device, excitation, record
#: channels, identification's measurement model, predicted and estimated statistics.
QUANTITIES: dict[str, Quantity] = {
    # ------------------------------------------------ the device (Eq. 1-3)
    "m": Quantity("kg", "magnet mass"),
    "c": Quantity("Ns/m", "total viscous damping c_m + c_e"),
    "c_m": Quantity("Ns/m", "mechanical viscous damping"),
    "c_e": Quantity("Ns/m", "electrical damping alpha^2 / (R_L + R_C) (paper Eq. 3)"),
    "k": Quantity("N/m", "linear stiffness"),
    "k3": Quantity("N/m^3", "cubic stiffness", "k3"),
    "stroke": Quantity("m", "stroke: the largest |z| the device allows"),
    # ------------------------------------------------ the excitation
    "psd": Quantity(
        "(m/s^2)^2/Hz", "one-sided PSD level S of the base acceleration (paper Eq. 17)", "S"
    ),
    "level": Quantity("(m/s^2)^2/Hz", "PSD level of a coloured excitation"),
    "f0": Quantity("Hz", "centre (band-pass) or filter (Kanai-Tajimi) frequency", "f0"),
    "zeta": Quantity("", "damping ratio of the shaping filter", "ζ"),
    "f_lo": Quantity("Hz", "lower band edge"),
    "f_hi": Quantity("Hz", "upper band edge"),
    "variance": Quantity("(m/s^2)^2", "variance of the base acceleration"),
    "psd_integral": Quantity(
        "(m/s^2)^2", "integral of the record's Welch PSD (the variance the methods see)"
    ),
    "record_variance": Quantity("(m/s^2)^2", "variance of the recorded base acceleration"),
    "duration": Quantity("s", "duration"),
    "dt": Quantity("s", "time step"),
    "segment_length": Quantity("samples", "Welch segment length"),
    # ------------------------------------------------ a record's channels (CSV columns)
    "time": Quantity("s", "sample time"),
    "base_acceleration": Quantity("m/s^2", "base acceleration y''"),
    "base_velocity": Quantity("m/s", "base velocity y'"),
    "base_displacement": Quantity("m", "base (shaker) displacement y"),
    "force": Quantity("N", "force u on the mass"),
    "relative_displacement": Quantity("m", "displacement z of the mass relative to the base"),
    "relative_velocity": Quantity("m/s", "velocity z' of the mass relative to the base"),
    "voltage": Quantity("V", "load voltage (R_L i of a coil, V of a piezo element)"),
    "current": Quantity("A", "load current (i of a coil, V / R_L of a piezo element)"),
    # ------------------------------------------------ identification's measurement model
    "k2": Quantity("N/m^2", "quadratic stiffness (an asymmetric spring)"),
    "input_offset": Quantity("input unit", "offset of the input channel"),
    "output_offset": Quantity("m", "offset of the measured displacement"),
    "velocity_offset": Quantity("m/s", "offset of the measured relative velocity"),
    "voltage_offset": Quantity("V", "offset of the measured load voltage"),
    "current_offset": Quantity("A", "offset of the measured load current"),
    "r_load": Quantity("ohm", "load resistance R_L"),
    # ------------------------------------------------ statistics, predicted or estimated
    "power_electrical": Quantity(
        "W", "expected electrical power E[P_e] = c_e E[z'^2] (Eq. 32)", "E[P_e]"
    ),
    "power_load": Quantity("W", "expected power into the load E[i^2 R_L]", "E[P_L]"),
    "power_mechanical": Quantity("W", "power dissipated mechanically: c_m E[z'^2] + friction"),
    "friction_power": Quantity("W", "power dissipated by friction E[z' F]"),
    "power_input": Quantity(
        "W",
        "mean power the base acceleration injects (assemblies: r^T M r S / 4 under white noise)",
    ),
    "power_stored": Quantity(
        "W", "power stored through a bridge: V_b E|i| or E[V_C^2] / R_L", "E[P_stored]"
    ),
    "power_coil_loss": Quantity("W", "power lost in the coil's resistance R_C E[i^2]"),
    "power_diode_loss": Quantity("W", "power lost in the bridge's diodes 2 V_d E|i|"),
    "c_eq": Quantity("Ns/m", "equivalent viscous damping (Eq. 19, 30)", "c_eq"),
    "k_eq": Quantity("N/m", "equivalent linear stiffness", "k_eq"),
    "velocity_variance": Quantity("(m/s)^2", "velocity variance E[z'^2] (Eq. 20)", "E[v^2]"),
    "displacement_variance": Quantity("m^2", "displacement variance E[z^2]", "E[z^2]"),
    "mean_abs_velocity": Quantity("m/s", "mean absolute velocity E|z'|"),
    # A circuit state's unit is its coupling's (current A, voltage V): see unit().
    "circuit_mean_square": Quantity("A^2 or V^2", "mean square of the circuit state", "E[x^2]"),
    "circuit_variance": Quantity("A^2 or V^2", "variance of the circuit state"),
    # A probability's unit is 1 (SI's unit of a dimensionless ratio), shown so
    # that a table's unit column does not look like a missing unit.
    "stroke_exceedance": Quantity(
        "1",
        "P(|z| > stroke): stationary probability (Monte Carlo: fraction of time)",
        "P(|z| > stroke)",
    ),
    "stroke_first_passage_time": Quantity("s", "mean first time |z| reaches the stroke"),
    # ------------------------------------------------ events (time-resolved, from t = 0)
    "times": Quantity("s", "times the time-resolved statistics are given at"),
    "t_end": Quantity("s", "end of the computed time"),
    "energy_electrical": Quantity("J", "electrical energy over the whole event: int E[P_e] dt"),
    "cumulative_energy": Quantity(
        "J", "electrical energy from t = 0: int_0^t E[P_e] dt", "energy to t"
    ),
    "stroke_reached": Quantity("1", "probability that |z| reached the stroke by t", "P(reached)"),
    "stroke_reached_poisson": Quantity(
        "1", "P(reached) by the Poisson crossing approximation", "reached, Poisson*"
    ),
    "stroke_reached_vanmarcke": Quantity(
        "1",
        "P(reached) by Vanmarcke's approximation (not conservative early in an event)",
        "reached, Vanmarcke*",
    ),
    "stroke_reached_bound": Quantity(
        "1", "upper bound on P(reached): the expected out-crossings (Rice)", "reached <= (Rice)"
    ),
    # ------------------------------------------------ rare events (randvib.first_passage)
    "probability_first_passage": Quantity(
        "1",
        "P(|z| reaches the stroke within the window, from the stationary state)",
        "P(first passage)",
    ),
    "upcrossing_rate": Quantity(
        "1/s",
        "mean number per second of times |z| rises through the stroke (both ends)",
        "up-crossings/s",
    ),
    "stationary_exceedance": Quantity("1", "P(|z| > stroke) at a fixed time", "P(|z| > D)"),
    "path_steps": Quantity("1", "integration steps spent: paths x steps per path"),
    "crude_path_steps": Quantity(
        "1", "path-steps crude Monte Carlo needs for the same coefficient of variation"
    ),
    "r_load_optimal": Quantity("ohm", "load resistance of the largest load power"),
    "power_load_optimal": Quantity("W", "load power at the optimal load resistance"),
    "battery_optimal": Quantity("V", "battery voltage of the largest stored power"),
    "power_stored_optimal": Quantity("W", "stored power at the optimal bridge output"),
    # ------------------------------------------------ a design (randvib.design)
    "power_predicted": Quantity("W", "the objective's power at the optimum, predicted"),
    "power_monte_carlo": Quantity("W", "the objective's power at the optimum, Monte Carlo"),
    "stroke_exceedance_predicted": Quantity("1", "P(|z| > stroke) at the optimum, predicted"),
    "stroke_exceedance_monte_carlo": Quantity(
        "1", "P(|z| > stroke) at the optimum, Monte Carlo (fraction of time)"
    ),
    "first_passage_predicted": Quantity("s", "mean first time |z| reaches the stroke, predicted"),
    "first_passage_monte_carlo": Quantity(
        "s", "mean first time |z| reaches the stroke, Monte Carlo"
    ),
    "input_power": Quantity("W", "power the excitation delivers to the device"),
    "efficiency": Quantity("1", "the objective's power over the input power"),
    "limit": Quantity(
        "W", "non-causal harvesting limit of the mass with E[z^2] at the budget's Gaussian RMS"
    ),
    "limit_hard_stroke": Quantity(
        "W", "non-causal harvesting limit of the mass held within |z| <= stroke"
    ),
    "causal_limit": Quantity("W", "harvesting limit of a causal device at the budget's RMS"),
    "fraction_of_limit": Quantity("1", "the optimum's power over the non-causal limit"),
    "fraction_of_causal_limit": Quantity("1", "the optimum's power over the causal limit"),
}

#: Quantities measured in the unit of a coupling's circuit state, squared.
_CIRCUIT_SQUARES = ("circuit_mean_square", "circuit_variance")


def unit(name: str, electrical=None) -> str:
    """The SI unit of quantity ``name`` (``""`` for a dimensionless one).

    Parameters
    ----------
    name : str
        A key of :data:`QUANTITIES`.
    electrical : Coupling, optional
        The device's coupling: a circuit state's mean square or variance is then
        in its state's unit squared (A^2 for a coil's current, V^2 for a
        piezo's voltage) rather than ``A^2 or V^2``.

    Raises
    ------
    KeyError
        For a name that is not a reported quantity, naming the known ones.
    """
    quantity = QUANTITIES.get(name)
    if quantity is None:
        raise KeyError(f"{name!r} is not a reported quantity; known: {', '.join(QUANTITIES)}")
    state_unit = getattr(electrical, "state_unit", "")
    if name in _CIRCUIT_SQUARES and state_unit:
        return f"{state_unit}^2"
    return quantity.unit


def parameter_unit(name: str, harvester) -> str:
    """The SI unit of a device parameter ``name`` of ``harvester`` (``""``: unknown).

    The device's own parameters are :data:`QUANTITIES`; a friction law's or a
    coupling's (``fc``, ``alpha``, ``r_load``...) are declared by its class.

    Parameters
    ----------
    name : str
        A parameter name, as :func:`randvib.design` varies it.
    harvester : Harvester or Assembly
        The device whose friction law and coupling declare the other names
        (an assembly names its parameters by dotted path).
    """
    if hasattr(harvester, "parameter_unit"):  # an Assembly: dotted paths
        try:
            return harvester.parameter_unit(name)
        except ValueError:
            return ""
    if name in QUANTITIES:
        return QUANTITIES[name].unit
    for model in (getattr(harvester, "friction", None), getattr(harvester, "electrical", None)):
        specs = type(model).parameter_specs() if hasattr(model, "parameter_specs") else {}
        if name in specs:
            return specs[name].unit
    return ""


def unicode_unit(text: str) -> str:
    """A unit with its powers as superscripts, as a Markdown report prints it.

    >>> unicode_unit("(m/s^2)^2/Hz")
    '(m/s²)²/Hz'
    """
    return text.replace("^2", "²").replace("^3", "³")


def report_header(name: str) -> str:
    """A report table's header for quantity ``name``: its symbol and unit, ``S ((m/s²)²/Hz)``."""
    quantity = QUANTITIES[name]
    label = quantity.symbol or name
    # a probability's symbol P(...) says what it is: no "(1)" after it
    return f"{label} ({unicode_unit(quantity.unit)})" if quantity.unit not in ("", "1") else label
