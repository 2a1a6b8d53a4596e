"""The analytic methods as a declared family, and statistical linearisation's one route.

Covers randvib/analytic/method.py (the declarations and the refusals made
from them), randvib/analytic/prediction.py (the registry ``METHODS`` and the
driver), the method classes beside their mathematics, ``linearise`` in
randvib/analytic/statistical_linearisation.py and its use by the step check
(randvib/montecarlo/step_check.py), and the CLI's ``--method`` (randvib/cli/power.py).

The declarations must be the truth: on a table of cases (every excitation
kind, coupling, potential and friction form) a method accepts a case exactly
when ``predict`` answers it, and a refusal names exactly the methods that do.
"""

import re
from dataclasses import dataclass

import numpy as np
import pytest
from _cli import one_line_error, run

import randvib as rv
from randvib.analytic.averaging import AVERAGING_ZETA_LIMIT, AveragingValidityWarning
from randvib.analytic.exact_solutions import gibbs_displacement_moment
from randvib.analytic.fokker_planck import FAST_MAX_BARRIER, friction_barrier_depth
from randvib.analytic.linearisation import equivalent_damping, linear_displacement_variance
from randvib.analytic.statistical_linearisation import linearise
from randvib.models.friction import FrictionModel, parameter
from randvib.montecarlo.step_check import effective_linear_device

FIG9 = rv.preset("figure9")  # Coulomb 5.8 mN, Duffing k3, resistive c_e
M, C, K, K3 = 0.0226, 0.2, 57.4, 5e5
S = 0.5
BAND = rv.BandPass(S, 8.0, 0.2)


@dataclass(frozen=True, eq=False)
class CubicDrag(FrictionModel):
    """A memoryless law not of the form Fc tanh(beta v): F = a v^3 (no ``name``: unregistered)."""

    a: float = parameter("N s^3/m^3", description="cubic drag")

    def force(self, v, theta=None):
        return self.a * np.asarray(v, dtype=float) ** 3


def device(k=K, k3=K3, friction="coulomb", coupling=None):
    law = {"coulomb": rv.Coulomb(0.0058), "none": None, "lugre": rv.preset("lugre-td1").friction}
    law["cubic"] = CubicDrag(50.0)
    if coupling is not None:
        return rv.Harvester.with_coupling(M, C / 2, k, coupling, k3=k3, friction=law[friction])
    return rv.Harvester(m=M, c_m=C / 2, c_e=C / 2, k=k, k3=k3, friction=law[friction])


# barrier 1 m E[v^2] (viscous E[v^2]; about 1.2 on the friction's scale): fpk-fast takes it
SHALLOW = -np.sqrt(4.0 * K3 * 1.0 * S * M * M / (4.0 * C))
CASES = {
    "white": (device(), S),
    "White object": (device(), rv.White(S)),
    "band-pass": (device(), BAND),
    "tabulated": (device(), rv.Tabulated([1.0, 5.0, 20.0, 40.0], [0.0, 0.1, 0.1, 0.0])),
    "tanh": (device().updated(friction=rv.Tanh(0.0058, 300.0)), S),
    "cubic drag": (device(friction="cubic"), S),
    "cubic drag, band-pass": (device(friction="cubic"), BAND),
    "lugre": (device(friction="lugre"), S),
    "bistable": (device(k=SHALLOW), S),
    "pure cubic": (device(k=0.0), S),
    "free mass": (device(k=0.0, k3=0.0), S),
    "free mass, band-pass": (device(k=0.0, k3=0.0), BAND),
    "coil": (device(coupling=rv.Inductive(0.1992, 1.0, 0.48, 2e-3)), S),
    "piezo, band-pass": (device(coupling=rv.Piezo(2e-3, 1e-7, 1e5)), BAND),
    "non-confining": (device(k=-10.0, k3=0.0), S),
}
#: The methods each case is accepted by, written out from the methods' documentation.
ACCEPTED = {
    "white": {"linearisation", "averaging", "fpk-fast", "fpk"},
    "White object": {"linearisation", "averaging", "fpk-fast", "fpk"},
    "band-pass": {"linearisation"},
    "tabulated": {"linearisation"},
    "tanh": {"linearisation", "averaging", "fpk-fast", "fpk"},
    "cubic drag": {"linearisation"},
    "cubic drag, band-pass": {"linearisation"},
    "lugre": set(),
    "bistable": {"linearisation", "fpk-fast", "fpk"},
    "pure cubic": {"linearisation", "fpk-fast", "fpk"},
    "free mass": {"linearisation", "fpk-fast", "fpk"},
    "free mass, band-pass": set(),
    "coil": {"linearisation"},
    "piezo, band-pass": {"linearisation"},
    "non-confining": set(),
}


def test_the_registry_lists_the_methods_in_order():
    assert list(rv.METHODS) == ["linearisation", "averaging", "fpk-fast", "fpk", "bridge-closure"]
    for name, method in rv.METHODS.items():
        assert isinstance(method, rv.AnalyticMethod) and method.name == name
        assert method.summary and method.title
    # the bridge closure takes model spectra (its coloured closure), not a circuit state
    assert [n for n, m in rv.METHODS.items() if m.coloured or m.circuit] == [
        "linearisation",
        "bridge-closure",
    ]
    assert [n for n, m in rv.METHODS.items() if not m.stroke_exceedance] == [
        "averaging",
        "bridge-closure",
    ]
    assert [n for n, m in rv.METHODS.items() if m.rectifier] == ["bridge-closure"]
    assert [n for n, m in rv.METHODS.items() if m.reference] == ["fpk"]


@pytest.mark.parametrize("case", CASES)
def test_a_method_accepts_a_case_exactly_when_it_answers_it(case):
    harvester, psd = CASES[case]
    accepting = {name for name, method in rv.METHODS.items() if method.accepts(harvester, psd)}
    assert accepting == ACCEPTED[case]
    for name, method in rv.METHODS.items():
        if name in accepting:
            result = rv.predict(harvester, psd, name)
            assert np.isfinite(result.power_electrical) and result.power_electrical > 0
            continue
        refusal = method.refusal(harvester, psd)
        with pytest.raises(ValueError) as raised:
            rv.predict(harvester, psd, name)
        assert str(raised.value) == refusal
        assert refusal.startswith(f"method='{name}' ")
        # the alternatives it names are the methods that take the case
        named = set(re.findall(r"method='([\w-]+)'", refusal)) - {name}
        if case == "non-confining":
            assert "no stationary state" in refusal and not named
        else:
            assert named == accepting and refusal.endswith("Monte Carlo (randvib.simulate)")


def test_the_solvers_own_refusals_come_from_the_same_declarations():
    harvester, psd = CASES["piezo, band-pass"]
    refusal = rv.METHODS["averaging"].refusal(harvester, S, "stochastic averaging")
    with pytest.raises(ValueError) as raised:
        rv.averaging_statistics(harvester, S)
    assert str(raised.value) == refusal
    assert refusal.startswith("stochastic averaging assumes resistive coupling")
    with pytest.raises(ValueError, match="^the FPK solver needs a memoryless friction law of"):
        rv.fast_fpk_statistics(*CASES["cubic drag"])


def test_the_cli_takes_its_method_choices_and_refusals_from_the_declarations(capsys):
    one_line_error(
        capsys,
        ["power", "--preset", "figure9", "--psd", 1, "--method", "exact"],
        f"`--method` must be one of {', '.join(rv.METHODS)}; got 'exact'",
    )
    with pytest.raises(SystemExit):
        run(capsys, "power", "--help")
    help_text = "".join(capsys.readouterr().out.split())  # wrapped lines, hyphens kept
    for name, method in rv.METHODS.items():
        assert "".join(f"{name}: {method.summary}".split()) in help_text
    piezo = ["--coupling", "piezo", "--theta", 2e-3, "--capacitance", 1e-7, "--r-load", 1e5]
    harvester = rv.Harvester.with_coupling(
        0.0226, 0.1, 57.4, rv.Piezo(2e-3, 1e-7, 1e5), k3=70742.0, friction=rv.Coulomb(0.0058)
    )
    refusal = rv.METHODS["fpk"].refusal(harvester, 1.0)
    wording = refusal.replace("method='fpk'", "`--method fpk`")
    wording = wording.replace("method='linearisation'", "`--method linearisation`")
    wording = wording.replace("randvib.simulate", "`randvib simulate`")
    argv = ["power", "--preset", "figure9", "--psd", 1, *piezo, "--method", "fpk"]
    one_line_error(capsys, argv, f"randvib power: error: {wording}")


def test_predict_takes_a_method_object_and_a_new_method_is_one_class():
    class FrictionFree(rv.AnalyticMethod):
        """The exact white-noise power of a friction-free device: S m / (4 c) (Gibbs)."""

        name = "friction-free-test"
        summary = "exact without friction"

        def accepts_friction(self, law):
            return law is None or law.vanishes

        def solve(self, harvester, psd):
            m, c = harvester.m, harvester.c
            vv = psd * m / (4.0 * c)
            zz = gibbs_displacement_moment(m, c, harvester.k, harvester.k3, psd)
            return rv.PowerPrediction.from_white_noise(
                harvester, self.name, vv, zz, np.sqrt(2.0 / np.pi * vv), psd
            )

    free = device(friction="none")
    for method in (FrictionFree, FrictionFree()):
        result = rv.predict(free, S, method)
        assert result.method == "friction-free-test"
        assert result.power_electrical == pytest.approx(rv.expected_power(free, S), rel=1e-14)
    with pytest.raises(ValueError, match="band-pass excitation needs method='linearisation' or"):
        rv.predict(free, BAND, FrictionFree)
    with pytest.raises(ValueError, match="`method` must be one of 'linearisation', 'averaging'"):
        rv.predict(free, S, "friction-free-test")


def test_validity_limits_are_declared_with_the_limits_the_methods_use():
    (averaging,) = rv.METHODS["averaging"].validity
    (fast,) = rv.METHODS["fpk-fast"].validity
    assert (averaging.limit, averaging.beyond) == (AVERAGING_ZETA_LIMIT, "warns")
    assert (fast.limit, fast.beyond) == (FAST_MAX_BARRIER, "refuses")
    heavy = device().updated(fc=0.2)  # friction removes most of the energy per cycle
    with pytest.warns(AveragingValidityWarning, match=f"exceeds {AVERAGING_ZETA_LIMIT}"):
        rv.predict(heavy, S, "averaging")
    deep = device(k=-np.sqrt(4.0 * K3 * 20.0 * S * M * M / (4.0 * C)))  # barrier 20 m E[v^2]
    depth = friction_barrier_depth(deep.m, deep.c, deep.k, deep.k3, deep.friction, S)
    assert depth > 20.0  # friction lowers E[v^2]: the wells are deeper on its scale
    refusal = (
        f"method='fpk-fast' treats double wells with friction up to a barrier of "
        f"{FAST_MAX_BARRIER:g} m E[v^2] (E[v^2] of equivalent linearisation); this one is "
        f"{depth:.3g} m E[v^2] deep (its one-well corrections fail there): use "
        "method='linearisation' or method='fpk' or Monte Carlo (randvib.simulate)"
    )
    with pytest.raises(ValueError) as raised:
        rv.predict(deep, S, "fpk-fast")
    assert str(raised.value) == refusal


# ------------------------------------------------------- the one linearisation route
def test_the_white_noise_fast_path_is_eq30_and_broadcasts():
    levels = np.array([0.1, 0.5, 2.0])
    lin = linearise(FIG9, levels)
    assert lin.method == "white-noise"
    c_eq = equivalent_damping(FIG9, levels)
    np.testing.assert_array_equal(lin.c_eq, c_eq)
    np.testing.assert_array_equal(lin.velocity_variance, levels * FIG9.m / (4.0 * c_eq))
    zz = linear_displacement_variance(FIG9, lin.velocity_variance)
    np.testing.assert_array_equal(lin.displacement_variance, zz)
    np.testing.assert_array_equal(lin.k_eq, FIG9.k + 3.0 * FIG9.k3 * zz)
    np.testing.assert_array_equal(lin.power_electrical, rv.expected_power(FIG9, levels))
    free = linearise(device(k=0.0, k3=0.0), S)
    assert free.displacement_variance is None and free.k_eq == 0.0


@pytest.mark.parametrize("case", ["white", "tanh", "bistable", "pure cubic"])
def test_the_fast_path_is_the_fixed_point_under_white_noise(case):
    harvester, psd = CASES[case]
    fast = linearise(harvester, psd)
    fixed = rv.statistical_linearisation(harvester, psd)
    assert fixed.method == "lyapunov"
    for name in ("c_eq", "k_eq", "velocity_variance", "displacement_variance", "power_electrical"):
        assert getattr(fast, name) == pytest.approx(getattr(fixed, name), rel=1e-9), name


@pytest.mark.parametrize("case", ["band-pass", "tabulated", "coil", "piezo, band-pass"])
def test_the_route_takes_the_fixed_point_beyond_white_noise(case):
    harvester, psd = CASES[case]
    lin = linearise(harvester, psd)
    reference = rv.statistical_linearisation(harvester, psd)
    assert isinstance(lin, rv.LinearisationResult) and lin.method == reference.method
    assert (lin.c_eq, lin.k_eq, lin.power_electrical, lin.circuit_variance) == (
        reference.c_eq,
        reference.k_eq,
        reference.power_electrical,
        reference.circuit_variance,
    )
    result = rv.predict(harvester, psd)
    assert (result.c_eq, result.power_electrical) == (reference.c_eq, reference.power_electrical)


def test_the_step_check_asks_the_route():
    k_eff, c_eff = effective_linear_device(FIG9, 1.0)
    assert c_eff == equivalent_damping(FIG9, 1.0)  # Eq. 30
    coil, _ = CASES["coil"]
    lin = rv.statistical_linearisation(coil, 1.0)
    assert effective_linear_device(coil, 1.0) == (lin.k_eq, lin.c_eq)
    # a law with memory only adds damping: left out, the viscous c remains
    lugre, _ = CASES["lugre"]
    assert effective_linear_device(lugre, 1.0)[1] == lugre.c
    undamped = rv.Harvester(m=M, c_m=0.0, c_e=0.0, k=K, k3=K3, friction=rv.Coulomb(0.0058))
    k_eff, c_eff = effective_linear_device(undamped, 1.0)
    assert (k_eff, c_eff) == (linearise(undamped, 1.0).k_eq, linearise(undamped, 1.0).c_eq)
