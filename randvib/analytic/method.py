"""The analytic methods as a declared family: what a method accepts, and how it is asked.

An analytic method is one class, a subclass of :class:`AnalyticMethod`, and
that class is the only place that describes it (as a friction law is
described by its class in :mod:`randvib.models.friction`). It declares

* ``name`` - its key in :data:`randvib.analytic.prediction.METHODS` and the
  CLI's ``--method`` choice; ``title`` - what sentences call it; ``summary``
  - one line on its cost and accuracy (the CLI's help);
* what it accepts: ``coloured`` (a non-white excitation), ``tones`` (sinusoids
  on or without noise), ``non_gaussian`` (a translation process, shocks on a
  linear device), ``circuit`` (a
  coupling with a circuit state: coil inductance, piezo capacitance),
  ``assemblies`` (an :class:`~randvib.models.assembly.Assembly` of several
  DOFs, :mod:`randvib.analytic.assembly_prediction`),
  ``potentials`` (kinds of :mod:`randvib.models.potential`) and
  ``friction_form`` (a key of :data:`FRICTION_FORMS`: any memoryless law, or
  the form Fc tanh(beta v));
* what it gives: ``stroke_exceedance`` (P(|z| > stroke)); ``transient``
  (the moments through an event, :meth:`AnalyticMethod.solve_transient`,
  for :func:`randvib.transient_response`);
* ``reference`` - a slow reference solver, not one to run at every point of
  a sweep; ``validity`` - its :class:`Validity` limits, beyond which it warns
  or refuses;

and computes in :meth:`AnalyticMethod.solve`. The methods live beside their
mathematics (:mod:`randvib.analytic.statistical_linearisation`,
:mod:`~randvib.analytic.averaging`, :mod:`~randvib.analytic.fokker_planck`);
the driver :mod:`randvib.analytic.prediction` lists them in ``METHODS``.

Consumers ask a method what it can do (:meth:`AnalyticMethod.accepts`,
:meth:`AnalyticMethod.refusal`, the declarations) instead of keeping lists
of method names; a refusal is one line that names, from the same
declarations, the methods that do take the case. Its wording uses
``method='NAME'``, which the CLI shows as ``--method NAME``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from randvib._validation import check_choice
from randvib.models.assembly import Assembly
from randvib.models.combined import parts_of
from randvib.models.excitation import Excitation
from randvib.models.harvester import Harvester
from randvib.models.potential import CONFINING


@dataclass(frozen=True)
class FrictionForm:
    """A kind of friction law a method is written for.

    Attributes
    ----------
    words : str
        How refusals name it ("a memoryless friction law").
    accepts : callable
        ``accepts(law) -> bool`` for a :class:`~randvib.models.friction.FrictionModel`,
        from what the law declares.
    """

    words: str
    accepts: object


#: The friction forms the methods declare, by key: laws that are a function of
#: the velocity alone (E[v F(v)] under a Gaussian v exists: equivalent
#: linearisation), and the family F = Fc tanh(beta v) with Coulomb as beta =
#: inf (the orbit integrals of averaging and the kink corrections of the FPK
#: solvers). No analytic method takes a law with internal state (LuGre).
FRICTION_FORMS = {
    "memoryless": FrictionForm("a memoryless friction law", lambda law: law.has_equivalent_damping),
    "fc-tanh": FrictionForm(
        "a memoryless friction law of the form Fc tanh(beta v) (coulomb, tanh or none)",
        lambda law: law.coulomb_tanh_form() is not None,
    ),
}


@dataclass(frozen=True)
class Validity:
    """A declared limit of a method's validity.

    Attributes
    ----------
    indicator : str
        The dimensionless number the limit is on.
    limit : float
        Its largest value inside the method's validity.
    beyond : str
        What the method does beyond it: ``"warns"`` or ``"refuses"``.
    meaning : str
        What the indicator measures and what goes wrong beyond the limit.
    """

    indicator: str
    limit: float
    beyond: str
    meaning: str


#: Relative tolerance of the white-noise energy balance every answer is checked
#: against (:meth:`AnalyticMethod.check_answer`). Without friction the balance
#: is exact for every potential and coupling; over the presets (friction
#: removed, S = 0.01 to 10) and double wells of barrier 1 to 8 m E[v^2] the
#: methods meet it to 7e-16 (linearisation, averaging: by construction),
#: 1.6e-5 (fpk-fast) and 3e-8 (fpk), and with friction stay below 1 + 3e-8
#: (tests/test_wrong_answers.py re-measures a subset). 1 % is 600 times the
#: largest of these and far inside the factors 0.35 to 13.6 it refuses.
ENERGY_BALANCE_TOLERANCE = 0.01

#: The limit every method is held to: the energy balance under white noise.
ENERGY_BALANCE = Validity(
    "energy_balance",
    ENERGY_BALANCE_TOLERANCE,
    "refuses",
    "the power dissipated in the dampers and the circuit, c_m E[v^2] + P_e, over the "
    "white-noise input power m S / 4: exactly 1 without friction, at most 1 with it "
    "(friction dissipates too)",
)

#: Named as the alternative of every refusal.
MONTE_CARLO = "Monte Carlo (randvib.simulate)"
#: Named as the alternative of every refusal of an event.
MONTE_CARLO_EVENT = "Monte Carlo (randvib.simulate_transient)"


class AnalyticMethod:
    """Base class of the analytic methods: the declaration every consumer reads.

    A subclass sets the class attributes below and implements :meth:`solve`;
    an instance is what :data:`randvib.analytic.prediction.METHODS` holds and
    :func:`randvib.predict` accepts as ``method``. See the module docstring.
    """

    #: Key in METHODS and the CLI's ``--method`` choice.
    name: str = "analytic"
    #: What sentences call the method.
    title: str = "an analytic method"
    #: One line: what it is, its cost and accuracy (the CLI's help).
    summary: str = ""
    #: Accepts a non-white excitation (the others assume white noise, paper Eq. 17).
    coloured: bool = False
    #: Accepts a coupling with a circuit state (the others assume a viscous c_e).
    circuit: bool = False
    #: Accepts a coupling through a diode bridge (:mod:`randvib.models.rectifier`).
    rectifier: bool = False
    #: Accepts an assembly (:class:`~randvib.models.assembly.Assembly`; solved by
    #: :func:`randvib.analytic.assembly_prediction.predict_assembly`).
    assemblies: bool = False
    #: Potential kinds it treats (see :data:`randvib.models.potential.KINDS`).
    potentials: tuple[str, ...] = CONFINING + ("free",)
    #: The friction laws it treats: a key of :data:`FRICTION_FORMS`.
    friction_form: str = "memoryless"
    #: Gives P(|z| > stroke) for a harvester with a stroke.
    stroke_exceedance: bool = False
    #: Solves an event's transient moments (randvib.transient_response); the
    #: others are stationary and refuse an event.
    transient: bool = False
    #: Treats tones (on noise or alone): the combined harmonic-and-random
    #: linearisation (:mod:`randvib.analytic.harmonic_linearisation`).
    tones: bool = False
    #: Answers a non-Gaussian input (a translation process, shocks on a linear
    #: device) by its spectrum: exact second moments for a linear device, the
    #: Gaussian closure beyond it, with a warning past its measured kurtosis limit.
    non_gaussian: bool = False
    #: A slow reference solver (about half a second a point): not for every sweep point.
    reference: bool = False
    #: Its declared validity limits.
    validity: tuple[Validity, ...] = ()

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    # ------------------------------------------------------------ what it takes
    def potentials_under(self, harvester: Harvester, psd) -> tuple[str, ...]:
        """The potential kinds it treats for this coupling and excitation."""
        return self.potentials

    def accepts_friction(self, law) -> bool:
        """Whether it treats the friction law ``law`` (None: no friction)."""
        return law is None or FRICTION_FORMS[self.friction_form].accepts(law)

    def accepts(self, harvester: Harvester, psd) -> bool:
        """Whether it takes the harvester under ``psd`` (a level, array or excitation).

        From the declarations alone, without computing: a method that accepts
        may still refuse a point beyond a validity limit it refuses at.
        """
        return self._reason(harvester, psd, "") is None

    def refusal(self, harvester: Harvester, psd, who: str | None = None) -> str | None:
        """Why it does not take the case, as one line naming the methods that do; or None.

        ``who`` is the subject of the sentence (default ``method='NAME'``; the
        mathematics' own functions name themselves, "stochastic averaging").
        """
        return self._reason(harvester, psd, who or self.called, alternatives=True)

    def require(self, harvester: Harvester, psd, who: str | None = None) -> None:
        """Raise ValueError with :meth:`refusal` unless the method takes the case."""
        refusal = self.refusal(harvester, psd, who)
        if refusal is not None:
            raise ValueError(refusal)

    def beyond_validity(self, harvester: Harvester, psd, reason: str) -> ValueError:
        """The refusal of an accepted case beyond a validity limit the method refuses at.

        One line: ``method='NAME' {reason}: use`` the other methods that take the case.
        """
        return ValueError(f"{self.called} {reason}: use {self._alternatives(harvester, psd)}")

    @property
    def called(self) -> str:
        """``method='NAME'``: how refusals name it (the CLI shows ``--method NAME``)."""
        return f"method={self.name!r}"

    def _reason(self, harvester, psd, who, alternatives: bool = False) -> str | None:
        """The first declaration the case fails, in words (with the alternatives), or None."""
        if isinstance(harvester, Assembly):
            if self.assemblies:
                return _assembly_input_reason(harvester, psd, who)
            others = self._alternatives(harvester, psd) if alternatives else MONTE_CARLO
            return f"{who} treats the single-mass harvester; an assembly needs {others}"
        potential = harvester.potential
        if getattr(psd, "is_event", False) and not self.transient:
            return (
                f"{who} is stationary; the {psd.name} event's transient response needs "
                f"{self._transient_alternatives()}"
            )
        if not potential.velocity_is_stationary:  # no method treats it: no alternatives
            return _potential_refusal(potential, who, CONFINING + ("free",))

        def others() -> str:
            return self._alternatives(harvester, psd) if alternatives else _monte_carlo(psd)

        if harvester.has_circuit and not self.circuit:
            return (
                f"{who} assumes resistive coupling (a viscous electrical damper); the "
                f"{harvester.electrical.name} coupling's circuit state needs {others()}"
            )
        if harvester.is_rectified and not self.rectifier:
            return (
                f"{who} assumes a linear coupling; the {harvester.electrical.name}'s "
                f"switching diodes need {others()}"
            )
        beyond_noise = self._input_reason(harvester, psd, who, others)
        if beyond_noise is not None:
            return beyond_noise
        if non_white(psd) and not self.coloured:
            return f"{who} assumes white noise; the {psd.name} excitation needs {others()}"
        kinds = self.potentials_under(harvester, psd)
        if not set(np.ravel(potential.kind)) <= set(kinds):
            return _potential_refusal(potential, who, kinds, others())
        law = harvester.friction
        if not self.accepts_friction(law):
            why = "has internal state" if law.has_memory else "is not of that form"
            words = FRICTION_FORMS[self.friction_form].words
            return f"{who} needs {words}; {law.name!r} {why}: use {others()}"
        return None

    def _input_reason(self, harvester, psd, who, others) -> str | None:
        """Why tones, shocks or a non-Gaussian input are beyond the method, or None."""
        if not isinstance(psd, Excitation):
            return None
        random, tones, shocks = parts_of(psd)
        if tones and not self.tones:
            listed = ", ".join(f"{tone.frequency:g} Hz" for tone in tones)
            return f"{who} treats random input only; the tones ({listed}) need {others()}"
        gaussian = shocks is None and (random is None or random.is_gaussian)
        if not gaussian and not self.non_gaussian:
            return f"{who} assumes Gaussian input; the {psd.name} input needs {others()}"
        if shocks is not None and not is_linear_device(harvester):
            # Campbell's theorem gives a linear device's second moments; nothing else
            # answers a nonlinear device under a Poisson train of pulses
            return (
                f"{who} treats shocks on a linear device only (Campbell's theorem: no friction, "
                f"no cubic spring); with {_nonlinearity(harvester)} the shock train needs "
                f"{_monte_carlo(psd)}"
            )
        return None

    def _alternatives(self, harvester, psd) -> str:
        """The registered methods that take the case, then Monte Carlo, in words."""
        names = [
            name
            for name, method in METHODS.items()
            if name != self.name and method.accepts(harvester, psd)
        ]
        return " or ".join([f"method={name!r}" for name in names] + [_monte_carlo(psd)])

    def _transient_alternatives(self) -> str:
        """The registered transient methods, then Monte Carlo of an event, in words."""
        names = [f"method={name!r}" for name, method in METHODS.items() if method.transient]
        return " or ".join(names + [MONTE_CARLO_EVENT])

    # ------------------------------------------------------------ checking
    def check_answer(self, harvester: Harvester, psd, result) -> None:
        """Refuse an answer that breaks the white-noise energy balance (:data:`ENERGY_BALANCE`).

        Under white noise of level S the base does work m S / 4 (W) on the
        mass on average, whatever the potential, and all of it is dissipated:
        ``c_m E[v^2] + P_e + E[v F(v)] = m S / 4`` (P_e = c_e E[v^2] for a
        resistive coupling, the circuit resistances' power for a circuit
        state; E[v F(v)] >= 0 is the friction's). Without friction
        ``c_m E[v^2] + P_e`` must equal m S / 4, with friction stay below it,
        both to :data:`ENERGY_BALANCE_TOLERANCE`. Scalar white-noise cases
        only (an array is a grid a caller inspects point by point; a coloured
        input's power has no closed form).

        Raises
        ------
        ValueError
            One line: the method, the dissipated and the input power, and the
            other methods that take the case.
        """
        if non_white(psd) or result.velocity_variance is None:
            return
        level = white_level(psd)
        values = (harvester.m, harvester.c_m, level, result.velocity_variance)
        if any(np.ndim(v) for v in values + (result.power_electrical,)):
            return
        input_power = float(harvester.m) * float(level) / 4.0
        dissipated = float(harvester.c_m) * float(result.velocity_variance) + float(
            result.power_electrical
        )
        if not (np.isfinite(input_power) and input_power > 0 and np.isfinite(dissipated)):
            return  # out-of-range values are refused by the driver's finiteness check
        ratio = dissipated / input_power
        law = harvester.friction
        frictionless = law is None or law.vanishes
        tol = ENERGY_BALANCE_TOLERANCE
        if frictionless and abs(ratio - 1.0) <= tol or not frictionless and ratio <= 1.0 + tol:
            return
        need = "equal" if frictionless else "stay below"
        raise self.beyond_validity(
            harvester,
            psd,
            f"gives a dissipated power c_m E[v^2] + P_e = {dissipated:.4g} W, {ratio:.3g} times "
            f"the white-noise input power m S / 4 = {input_power:.4g} W, which it must {need}"
            f"{' without friction' if frictionless else ' (friction dissipates the rest)'}; "
            "the answer is wrong here",
        )

    # ------------------------------------------------------------ computing
    def solve(self, harvester: Harvester, psd):  # pragma: no cover - abstract
        """The :class:`~randvib.analytic.power_prediction.PowerPrediction` of an accepted case.

        ``psd`` is the white-noise level S ((m/s^2)^2/Hz, > 0; an array
        broadcasting with the harvester's parameters) or, for a method that
        accepts it, a non-white :class:`~randvib.models.excitation.Excitation`.
        :func:`randvib.predict` checks the case and the answer.
        """
        raise NotImplementedError

    def solve_transient(self, harvester: Harvester, event, times, t_end, start):
        """The :class:`~randvib.analytic.transient.TransientPrediction` of an accepted event.

        For a method that declares ``transient``; :func:`randvib.transient_response`
        checks the case and gives the report ``times`` (s), ``t_end`` (s) and
        the :class:`~randvib.models.event.EventStart`.
        """
        raise NotImplementedError(f"{self.called} is stationary: it has no transient solution")


#: The analytic methods by name, in the order the CLI and tables show them: the
#: registry that :func:`method_named` reads and refusals name alternatives from.
#: The driver fills it (:data:`randvib.analytic.prediction.METHODS`, the same
#: dict, through :func:`register_methods`), and the package imports the driver
#: first (``randvib/analytic/__init__.py``), so it is complete before any method
#: can be asked. It lives here, below the methods' modules, so that they and the
#: driver need not import each other.
METHODS: dict[str, AnalyticMethod] = {}


def register_methods(*methods: AnalyticMethod) -> dict[str, AnalyticMethod]:
    """Add ``methods`` to :data:`METHODS` in the order given, and return it."""
    for method in methods:
        METHODS[method.name] = method
    return METHODS


def method_named(method) -> AnalyticMethod:
    """The method ``method`` names: a key of :data:`METHODS`, or an AnalyticMethod (class or instance)."""
    if isinstance(method, type) and issubclass(method, AnalyticMethod):
        return method()
    if isinstance(method, AnalyticMethod):
        return method
    return METHODS[check_choice("method", method, tuple(METHODS))]


def is_linear_device(harvester: Harvester) -> bool:
    """No friction, no cubic spring, no diode bridge: superposition and Campbell hold."""
    law = harvester.friction
    return (
        (law is None or law.vanishes) and np.all(harvester.k3 == 0) and not harvester.is_rectified
    )


def _assembly_input_reason(assembly: Assembly, psd, who: str) -> str | None:
    """Why tones, shocks or a non-Gaussian input are beyond the assembly solver, or None.

    A linear assembly's second moments are its input's spectrum's, whatever
    the marginal (a translation process), for a shock train (Campbell's
    spectrum, part of :meth:`Excitation.psd`) and for tones (each line through
    the frequency response, :func:`randvib.analytic.assembly_linear.linear_response`):
    those are exact. A nonlinear element under tones, non-Gaussian input or
    shocks has no combined closure for assemblies and no measured limit:
    refused, pointing to Monte Carlo (``simulate --device``), which takes them.
    """
    if not isinstance(psd, Excitation):
        return None
    random, tones, shocks = parts_of(psd)
    gaussian = not tones and shocks is None and (random is None or random.is_gaussian)
    if gaussian or assembly.is_linear:
        return None
    if tones:
        listed = ", ".join(f"{tone.frequency:g} Hz" for tone in tones)
        return (
            f"{who} takes tones on a linear assembly only (the tones {listed}; superposition); "
            "with nonlinear elements use Monte Carlo (`randvib simulate --device`, "
            "randvib.simulate)"
        )
    return (
        f"{who} treats the {psd.name} input on a linear assembly only (its spectrum decides "
        "the second moments); with nonlinear elements use Monte Carlo (`randvib simulate "
        "--device`, randvib.simulate)"
    )


def _nonlinearity(harvester: Harvester) -> str:
    """The device's nonlinearities in words: "Coulomb friction and a cubic spring"."""
    words = []
    if harvester.friction is not None and not harvester.friction.vanishes:
        words.append(f"{harvester.friction.name} friction")
    if np.any(harvester.k3 != 0):
        words.append("a cubic spring")
    if harvester.is_rectified:
        words.append(f"the {harvester.electrical.name}'s diodes")
    return " and ".join(words)


def _monte_carlo(psd) -> str:
    """The Monte Carlo alternative for ``psd``: of an event, or stationary."""
    return MONTE_CARLO_EVENT if getattr(psd, "is_event", False) else MONTE_CARLO


def _potential_refusal(potential, who, kinds, alternatives: str = "") -> str | None:
    """The one line :meth:`Potential.require` raises for ``kinds``, as text; None if it passes."""
    try:
        potential.require(who, kinds, alternatives)
    except ValueError as refusal:
        return str(refusal)
    return None


def white_level(psd):
    """The level S of white noise given as a number, an array or :class:`White`."""
    return psd.level if isinstance(psd, Excitation) else psd


def non_white(psd) -> bool:
    """Whether ``psd`` is an excitation other than white noise (a level is white)."""
    return isinstance(psd, Excitation) and not psd.is_white
