"""Identifying the whole harvester from what users measure: circuits, channels, several loads.

Covers :mod:`randvib.identification.circuit` (the coupling's parameters, circuit
state and output channels), :mod:`randvib.identification.experiment` (records at
their loads and their per-channel J), :mod:`randvib.identification.experiment_fit`
(the fit) and :mod:`randvib.identification.identifiability` (what records can
fix), against the independent generator of ``tests/_electrical.py`` (plain RK4,
none of randvib's simulators).

Tolerances: the record simulation against the generator from the two
integrators' own errors (fourth order for the smooth piezo, the generator's
first-order chatter of ``Fc sign(v)`` for the coil); identified parameters
within 4 standard errors of the truth (the suite's false-failure rate of about
6e-5 per assertion for a correct interval; the coverage of the intervals over
seeds is ``tests/calibration/electrical_coverage.py``'s, quoted where used).
"""

import _electrical as E
import numpy as np
import pytest

import randvib as rv
from randvib.identification.identifiability import (
    Configuration,
    IdentifiabilityError,
    local_identifiability,
    structural_identifiability,
)
from randvib.identification.least_squares import Uncertainty
from randvib.models.record import Record

COIL_LOADS = (3.0, 30.0)
#: The parameters identified with the coil and with the piezo element.
COIL_FREE = ("c", "k", "k3", "fc", "alpha", "r_coil", "inductance")
PIEZO_FREE = ("m", "c", "k", "k3", "theta", "capacitance")


def coil_device(r_load, truth=E.COIL):
    coil = rv.Inductive(truth["alpha"], r_load, truth["r_coil"], truth["inductance"])
    friction = rv.Coulomb(truth["fc"]) if truth["fc"] else None
    return rv.Harvester.with_coupling(
        truth["m"], truth["c"], truth["k"], coil, k3=truth["k3"], friction=friction
    )


def piezo_device(r_load, truth=E.PIEZO):
    piezo = rv.Piezo(truth["theta"], truth["capacitance"], r_load)
    return rv.Harvester.with_coupling(truth["m"], truth["c"], truth["k"], piezo, k3=truth["k3"])


def relative_rms(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.std(b))


# ------------------------------------------------------------ the record simulation
def test_piezo_circuit_state_matches_an_independent_rk4_to_fourth_order():
    """The kernel's piezo voltage (a circuit state integrated with the motion) against
    plain RK4 at 16 kHz on the same linearly interpolated input: at 8 sub-steps the
    kernel's own error is its 4-sub-step error / 16 (measured 2.8e-7 -> 1.6e-8 of
    the voltage's RMS), so 5e-8 bounds it; a 1 % error in the circuit's drive
    theta / C_p would be 1e-2."""
    rec = E.record("piezo", E.PIEZO, r_load=1e5, outputs=("voltage", "relative_velocity"))
    drive = Record(rec.dt, base_acceleration=rec.input)
    errors = {}
    for substeps in (4, 8):
        sim = rv.record_response(piezo_device(1e5), drive, substeps=substeps, hold="linear")
        errors[substeps] = relative_rms(sim.output("voltage")[0], rec["voltage"])
        assert relative_rms(sim.output("relative_velocity")[0], rec["relative_velocity"]) < 3e-6
    assert errors[8] < 5e-8
    assert errors[4] / errors[8] > 8.0  # fourth order: 16 in the limit


def test_coil_with_inductance_and_coulomb_friction_matches_the_generator():
    """Load voltage R_L i and velocity of a coil with inductance and Coulomb friction
    against the generator: its ``Fc sign(v)`` chatter is first order in its step
    (measured 7.6e-5 of the RMS at 16 kHz, 3.5e-5 at 32 kHz), the kernel's stick-slip
    is event-located; 1.5e-4 is twice the generator's error. A 1 % error in
    alpha moves the voltage by about 1e-2."""
    rec = E.record("coil", E.COIL, r_load=3.0, outputs=("voltage", "relative_velocity"))
    sim = rv.record_response(
        coil_device(3.0), Record(rec.dt, base_acceleration=rec.input), hold="linear"
    )
    assert relative_rms(sim.output("voltage")[0], rec["voltage"]) < 1.5e-4
    assert relative_rms(sim.output("relative_velocity")[0], rec["relative_velocity"]) < 1.5e-4
    assert np.allclose(sim.output("current"), sim.output("voltage") / 3.0)


# ------------------------------------------------------------ what records can fix
UNITS = {"fc": "N", "k3": "N/m^3"}
MECHANICS = ("c", "k", "k3", "fc")
V, Z, VEL = ("voltage",), ("relative_displacement",), ("relative_velocity",)

#: (coupling, records (load, channels), free coupling parameters, fixed, force input,
#: the parameters left undetermined): the cases worked out by hand in
#: docs/identification.md ("What records can fix").
STRUCTURE = [
    # resistive coil: the motion sees c_m + alpha^2/(R_L + R_C), the voltage alpha R_L/(R_L + R_C)
    ("resistive", [(10, V)], ("alpha", "r_coil"), {"m": 1}, False, {"c", "alpha", "r_coil"}),
    ("resistive", [(10, V), (22, V)], ("alpha", "r_coil"), {"m": 1}, False, set()),
    ("resistive", [(10, Z), (22, Z)], ("alpha", "r_coil"), {"m": 1}, False,
     {"c", "alpha", "r_coil"}),
    ("resistive", [(10, Z), (22, Z), (47, Z)], ("alpha", "r_coil"), {"m": 1}, False, set()),
    ("resistive", [(10, V)], ("alpha",), {"m": 1, "r_coil": 0.5}, False, set()),
    # coil with inductance: V/a has 4 coefficients for c, k, alpha, R_C, L
    ("inductive", [(10, V)], ("alpha", "r_coil", "inductance"), {"m": 1}, False,
     {"c", "k", "alpha", "r_coil", "inductance"}),
    ("inductive", [(10, V), (22, V)], ("alpha", "r_coil", "inductance"), {}, False, set()),
    # the current's scale: alpha s, L s^2, R s^2 leave the motion as it was
    ("inductive", [(10, Z)], ("alpha", "r_coil", "inductance"), {"m": 1}, False,
     {"alpha", "r_coil", "inductance"}),
    ("inductive", [(10, Z + V)], ("alpha", "r_coil", "inductance"), {"m": 1}, False, set()),
    ("inductive", [(10, V)], ("alpha", "r_coil"), {"m": 1, "inductance": 0.0}, False,
     {"c", "alpha", "r_coil"}),
    # piezo: R_L C_p is known through R_L, so the motion fixes C_p; the mass scales theta
    ("piezo", [(1e5, Z)], ("theta", "capacitance"), {"m": 1}, False, set()),
    ("piezo", [(1e5, Z)], ("theta", "capacitance"), {}, False,
     {"m", "c", "k", "k3", "fc", "theta"}),
    ("piezo", [(1e5, V + VEL)], ("theta", "capacitance"), {}, False, set()),
    ("piezo", [(1e5, V)], ("theta", "capacitance"), {"m": 1}, False, set()),
    ("piezo", [(1e5, V)], ("theta", "capacitance"), {}, False,
     {"m", "c", "k", "k3", "fc", "theta", "capacitance"}),
    # a force input fixes the mass; without a coupling nothing is electrical
    (None, [(None, Z)], (), {}, True, set()),
    (None, [(None, Z)], (), {}, False, {"m", "c", "k", "k3", "fc"}),
]  # fmt: skip


@pytest.mark.parametrize("coupling, records, circuit, fixed, force, expected", STRUCTURE)
def test_what_records_can_fix_agrees_with_the_symmetries_worked_out_by_hand(
    coupling, records, circuit, fixed, force, expected
):
    free = MECHANICS + circuit + (("m",) if "m" not in fixed else ())
    config = Configuration(coupling, force, tuple(records), free, fixed, UNITS)
    ident = structural_identifiability(config)
    assert set(ident.undetermined) == expected
    assert set(ident.determined) == set(free) - expected
    if expected:  # the refusal names what to add, each tried and found to work
        assert ident.remedies and "cannot determine" in ident.refusal()


def test_remedies_are_the_additions_that_work():
    """One voltage record of a resistive coil: a second load or a known coupling
    parameter splits the damping, nothing else does (a velocity channel does not)."""
    config = Configuration(
        "resistive", False, ((10.0, V),), MECHANICS + ("alpha", "r_coil"), {"m": 0.02}, UNITS
    )
    remedies = structural_identifiability(config).remedies
    assert any("2 different loads" in r for r in remedies)
    assert any(r.startswith("fix one of r_coil, alpha, c") for r in remedies)
    assert not any("velocity" in r for r in remedies) and len(remedies) == 2


def test_identify_refuses_an_arbitrary_split_before_fitting():
    """The voltage across one load: refused in one line before any simulation, naming
    a second load and a known coupling parameter; the CLI's `--r-load` per record."""
    rec = E.record("coil", E.COIL, r_load=3.0, duration=0.2, outputs=("voltage",))
    with pytest.raises(IdentifiabilityError, match="cannot determine c, alpha, r_coil") as err:
        rv.identify(rec, "coulomb", m=0.0226, coupling="resistive", r_load=3.0,
                    outputs=("voltage",), progress=False)  # fmt: skip
    assert "2 different loads" in str(err.value) and "\n" not in str(err.value)
    with pytest.raises(ValueError, match="needs each record's load"):
        rv.identify(rec, "coulomb", m=0.0226, coupling="inductive", outputs=("voltage",))
    with pytest.raises(ValueError, match="voltage` output is the circuit's"):
        rv.identify(rec, "coulomb", m=0.0226, outputs=("voltage",))
    with pytest.raises(ValueError, match="no relative_displacement channel; fit its voltage"):
        rv.identify(rec, "coulomb", m=0.0226)


def uncertainty_of(names, values, se, corr):
    """An :class:`Uncertainty` with given standard errors and correlations."""
    return Uncertainty(
        names=tuple(names), estimate=dict(zip(names, values, strict=True)),
        standard_error=dict(zip(names, se, strict=True)), interval={},
        correlation=np.asarray(corr, float), noise_std=1.0, dof=100,
    )  # fmt: skip


def test_local_check_finds_a_split_and_a_lone_poorly_determined_value():
    """Relative standard errors: c and alpha 80 % each, correlated -0.99 (a split
    the data do not make: refused); the inductance alone at 70 % (poorly
    determined, reported); r_coil at 1 % (fixed)."""
    names, values = ("c", "alpha", "r_coil", "inductance"), (0.05, 1.0, 2.0, 0.02)
    se = (0.04, 0.8, 0.02, 0.014)
    corr = np.eye(4)
    corr[0, 1] = corr[1, 0] = -0.99
    given = dict(zip(names, values, strict=True))
    local = local_identifiability(uncertainty_of(names, values, se, corr), given)
    assert [sorted(g) for g in local["split"]] == [["alpha", "c"]]
    assert local["poorly_determined"] == ["inductance"]
    assert local["relative_errors"]["r_coil"] == pytest.approx(0.01)


# ------------------------------------------------------------ recovery within the intervals
def within(result, truth, names, bound=4.0):
    """Each parameter's error in its standard errors (|z| <= bound)."""
    z = {n: (result.parameters[n] - truth[n]) / result.standard_errors[n] for n in names}
    assert all(abs(v) <= bound for v in z.values()), z
    return z


def near_truth(device_of, truth, load):
    """A start 5 % off every parameter: the tests check the polish and its intervals,
    the search is the study's and the calibration's (identify's default 30 x 60)."""
    return device_of(load, {k: v * 1.05 for k, v in truth.items()})


@pytest.fixture(scope="module")
def coil_fit():
    """Load voltage only (1 % sensor noise), two loads, the mass known."""
    records = [
        E.record("coil", E.COIL, r_load=r, seed=i, noise={"voltage": 0.01}, duration=1.0)
        for i, r in enumerate(COIL_LOADS)
    ]
    fit = rv.identify(
        records, "coulomb", m=E.COIL["m"], coupling="inductive", r_load=COIL_LOADS,
        outputs=("voltage",), popsize=8, maxiter=3, seed=1, progress=False,
        init=near_truth(coil_device, E.COIL, COIL_LOADS[0]),
    )  # fmt: skip
    return fit, records


def test_coil_with_friction_and_inductance_recovered_from_voltages_at_two_loads(coil_fit):
    """alpha, R_C and L beside c_m, k, k3 and Fc, each within 4 standard errors.
    Calibrated over 30 seeds of the same generator (tests/calibration/electrical_coverage.py,
    results beside it): the 95 % intervals cover the truth 28 to 30 times of 30 per
    parameter, the largest error 3.1 standard errors. J is the noise's: 1 % of each
    channel's RMS gives 100 x 0.01^2 per channel, to within its chi-squared spread
    (4.5 % per channel of 1000 samples; 15 % is 4 of those over the two)."""
    fit, _ = coil_fit
    within(fit, E.COIL, COIL_FREE)
    assert fit.cost == pytest.approx(2 * 100 * 0.01**2, rel=0.15)
    assert set(fit.identifiability.determined) == set(COIL_FREE)
    assert any("2 loads split" in r for r in fit.identifiability.reasons)
    assert [row["output"] for row in fit.channel_costs] == ["voltage", "voltage"]
    assert fit.coupling == "inductive" and fit.r_loads == COIL_LOADS


def test_identified_coil_predicts_its_power_at_another_load(coil_fit):
    """The identified device wired to a third load gives the truth's load power
    (statistical linearisation, the same method for both) to within its parameters'
    errors: a few per mille here, far below the 30 % a wrong split would make."""
    fit, _ = coil_fit
    identified = rv.expected_power(fit.harvester(r_load=10.0), 0.5, into="load")
    truth = rv.expected_power(coil_device(10.0), 0.5, into="load")
    assert identified == pytest.approx(truth, rel=0.02)


def test_coil_at_one_load_recovered_from_its_voltage_with_its_resistance_measured():
    """The voltage across one load, the mass known: refused as it stands (the four
    coefficients of V/a cannot give c, k, alpha, R_C and L), identified once R_C is
    measured (an ohmmeter, ``--fix r_coil=2``): c, k, k3, Fc, alpha and L each within 4
    standard errors, J at the noise's 100 x 0.01^2 to within 4 of its chi-squared
    spreads (4.5 % each). Over 30 seeds (tests/calibration/electrical_coverage.txt,
    ``coil_one_load``) the 95 % intervals cover the truth 29 or 30 times of 30 per
    parameter, the largest error 2.3 standard errors; from scratch (identify's default
    search, 4 seeds) all cover."""
    rec = E.record("coil", E.COIL, r_load=3.0, seed=0, noise={"voltage": 0.01}, duration=1.0)
    options = dict(m=E.COIL["m"], coupling="inductive", r_load=3.0, outputs=("voltage",),
                   progress=False)  # fmt: skip
    with pytest.raises(IdentifiabilityError, match="fix one of"):
        rv.identify(rec, "coulomb", **options)
    fit = rv.identify(
        rec, "coulomb", fixed={"r_coil": E.COIL["r_coil"]}, popsize=8, maxiter=3, seed=1,
        init=near_truth(coil_device, E.COIL, 3.0), **options,
    )  # fmt: skip
    names = tuple(n for n in COIL_FREE if n != "r_coil")
    within(fit, E.COIL, names)
    assert fit.cost == pytest.approx(100 * 0.01**2, rel=0.18)
    assert set(fit.identifiability.determined) == set(names) and "r_coil" not in fit.free


def test_piezo_duffing_recovered_from_voltage_and_velocity_with_the_mass_free():
    """Voltage and velocity (1 % noise each) fix the mass too: the piezo's voltage
    scales with sqrt(m) under base excitation, so the mass symmetry is broken; the
    mass's search box comes from an equation-error estimate. Each of m, c, k, k3,
    theta, C_p within 4 standard errors. Over 30 seeds (tests/calibration/
    electrical_coverage.txt) the intervals cover 25 to 30 times of 30: two seeds end
    in local minima of the polish started 5 % off with this small search (J 0.138
    against the noise's 0.02; the other a likelihood ratio of 70 from the truth),
    which identify's default search avoids."""
    rec = E.record(
        "piezo", E.PIEZO, r_load=1e5, seed=5, duration=1.0,
        noise={"voltage": 0.01, "relative_velocity": 0.01}, outputs=("voltage", "relative_velocity"),
    )  # fmt: skip
    fit = rv.identify(
        rec, "viscous", coupling="piezo", r_load=1e5, outputs=("voltage", "relative_velocity"),
        popsize=8, maxiter=3, seed=1, progress=False, init=near_truth(piezo_device, E.PIEZO, 1e5),
    )  # fmt: skip
    within(fit, E.PIEZO, PIEZO_FREE)
    assert "m" in fit.free and fit.identifiability.identifiable


# ------------------------------------------------------------ the cost's building blocks
def test_blocked_covariance_gives_each_channel_its_own_noise():
    """Least squares of a linear model whose two blocks of rows (two channels) carry
    white noise of standard deviations 1 and 10: the covariance with blocks is the exact
    sandwich B X^T Sigma X B (B = (X^T X)^-1) up to each block's estimated variance
    (relative error sqrt(2/N) = 1.4 % here, so 6 %, four of them, bounds it); one
    pooled variance would be off by a factor of about 25 on the quiet block's slope."""
    from randvib.identification.least_squares import covariance

    rng = np.random.default_rng(34)
    n = 10_000
    x = np.column_stack([np.ones(2 * n), np.r_[rng.standard_normal(n), np.zeros(n)],
                         np.r_[np.zeros(n), rng.standard_normal(n)]])  # fmt: skip
    sigma = np.r_[np.full(n, 1.0), np.full(n, 10.0)]
    e = sigma * rng.standard_normal(2 * n)
    beta = np.linalg.lstsq(x, e, rcond=None)[0]
    residual = e - x @ beta
    blocks = [slice(0, n), slice(n, 2 * n)]
    cov, method, _ = covariance(x, residual, method="white", blocks=blocks)
    bread = np.linalg.inv(x.T @ x)
    exact = bread @ (x.T * sigma**2) @ x @ bread
    assert method == "white"
    assert np.allclose(np.diag(cov), np.diag(exact), rtol=0.06)


def test_the_unmeasured_start_is_profiled_out_of_the_search_cost():
    """A velocity and voltage record of the linear piezo (no Duffing term) from rest: z0
    is measured by no channel. Profiled, the search's J at the truth is the generator's
    own error (below 1e-9); started from the record's guess of z0 (the mean of the
    velocity's running integral) it is not."""
    from randvib.identification.experiment import ExperimentCost, recorded_tests
    from randvib.identification.settings import SimulationSettings

    truth = {**E.PIEZO, "k3": 0.0}
    rec = E.record("piezo", truth, r_load=1e5, duration=1.0,
                   outputs=("relative_velocity", "voltage"))  # fmt: skip
    tests = recorded_tests(rec, ("relative_velocity", "voltage"), 1e5, "piezo")
    fixed = {**truth, "k2": 0.0, "input_offset": 0.0, "output_offset": 0.0,
             "velocity_offset": 0.0, "voltage_offset": 0.0}  # fmt: skip
    cost = ExperimentCost(tests, "viscous", "piezo", fixed=fixed, free=(),
                          simulation=SimulationSettings(hold="linear"))  # fmt: skip
    named = cost.parameters(np.zeros((1, 0)))
    assert cost.unmeasured_start(named, 0) == ("z0",)
    profiled, shift = cost.record_cost(named, 0)
    assert profiled[0] < 1e-9 and abs(cost.start(named, 0)[0][0] + shift[0, 0]) < 1e-6
    guessed = cost.record_cost({**named, "z0": cost.start(named, 0)[0]}, 0)[0]
    assert guessed[0] > 1e3 * profiled[0]


def test_weights_multiply_each_channels_own_j_in_the_sum():
    """The summed cost with ``weights`` is sum_k w_k J_k exactly (the start and the
    offsets held, so nothing is profiled jointly): on a voltage and velocity record
    of the piezo, J_voltage weighted 3 and J_velocity 1, at parameters 1 % off (so
    that neither J is the generator's error alone)."""
    from randvib.identification.experiment import ExperimentCost, recorded_tests
    from randvib.identification.settings import SimulationSettings

    kinds = ("relative_velocity", "voltage")
    rec = E.record("piezo", E.PIEZO, r_load=1e5, duration=0.3, outputs=kinds)
    tests = recorded_tests(rec, kinds, 1e5, "piezo")
    fixed = {**E.PIEZO, "k": 1.01 * E.PIEZO["k"], "k2": 0.0, "input_offset": 0.0,
             "velocity_offset": 0.0, "voltage_offset": 0.0, "z0": 0.0}  # fmt: skip
    settings = SimulationSettings(hold="linear")
    costs = {}
    for weights in (None, {"voltage": 3.0}):
        cost = ExperimentCost(tests, "viscous", "piezo", fixed=fixed, free=(),
                              weights=weights, simulation=settings)  # fmt: skip
        named = cost.parameters(np.zeros((1, 0)))
        costs[bool(weights)] = float(cost.record_cost(named, 0)[0][0])
        rows = {row["output"]: row["cost"] for row in cost.channel_costs(named)[0]}
    assert min(rows.values()) > 1e-3
    assert costs[False] == pytest.approx(rows["voltage"] + rows["relative_velocity"], rel=1e-9)
    assert costs[True] == pytest.approx(3 * rows["voltage"] + rows["relative_velocity"], rel=1e-9)


@pytest.mark.parametrize(
    "weights, match",
    [({"current": 2.0}, "names 'current', which no record fits"),
     ({"voltage": -1.0}, "voltage=-1.0: a weight must be positive"),
     ({"voltage": float("nan")}, "a weight must be positive"),
     ([("voltage", 2.0)], "must be a dict")],
)  # fmt: skip
def test_weights_refused_unless_positive_and_on_a_fitted_channel(weights, match):
    """A weight on a channel no record fits would be ignored, a negative one would
    reward a misfit: both refused before any simulation."""
    rec = E.record("coil", E.COIL, r_load=3.0, duration=0.2, outputs=("voltage",))
    with pytest.raises(ValueError, match=match):
        rv.identify([rec, rec], "coulomb", m=0.0226, coupling="inductive", r_load=(3.0, 30.0),
                    outputs=("voltage",), weights=weights, progress=False)  # fmt: skip
