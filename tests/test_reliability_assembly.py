"""Rare events of an assembly: first passage of one coordinate of a device of several masses.

Covers :mod:`randvib.montecarlo.assembly_paths` (an assembly as a path
simulator on its compiled kernel: the per-path start and the peak, up-crossing
and beyond columns of :mod:`randvib.montecarlo.assembly_kernel`, checked path by
path against a plain numpy Heun loop), the exact anchors
:mod:`randvib.analytic.assembly_crossings`, ``rv.first_passage(assembly, ...)``
and ``randvib reliability --device``.

The references are exact and computed here independently: for a linear
assembly the scheme's discrete paths are a stationary Gaussian sequence whose
covariance is the discrete Lyapunov solution of Heun's recursion, built below
from M, C, K by hand, so P(|u| > D) = erfc(D / sqrt(2 P_uu)) and the rate of
steps on which |u| rises through D is the bivariate normal probability
(:func:`randvib.analytic.crossings.gaussian_chain_upcrossing_rate`) at any dt.
Tolerances: 4 standard errors of the estimates (tests/_stats.py); the
intervals' coverage is measured for the single mass by
tests/calibration/rare_event_coverage.py and rare_event_long_window.py.
"""

import json
import math

import numpy as np
import pytest
from _cli import one_line_error, run
from _stats import assert_matches
from scipy import linalg, special

import randvib as rv
from randvib.analytic.assembly_crossings import assembly_crossing_prediction
from randvib.analytic.crossings import CROSSING_METHODS, gaussian_chain_upcrossing_rate
from randvib.montecarlo.assembly_paths import AssemblyPaths
from randvib.montecarlo.reliability import estimate_first_passage
from randvib.statistics import Statistic

# a host mode (0.5 kg, 7 Hz) carrying a 50 g harvester (5 Hz), a resistive transducer on it
MASS = np.diag([0.5, 0.05])
STIFFNESS = np.array([[1036.35, -49.35], [-49.35, 49.35]])
DAMPING = np.array([[0.64, -0.02], [-0.02, 0.02]])
C_E = 0.08
DT = 1e-3
LINEAR = rv.Assembly.from_matrices(
    MASS, STIFFNESS, DAMPING, transducers=[rv.Transducer((1, 0), C_E, stroke=0.01)]
)
#: A Duffing spring on the harvester's coordinate (its stroke on the element).
DUFFING = rv.Assembly.from_matrices(
    MASS, STIFFNESS, DAMPING,
    elements=[rv.Element((1, 0), rv.Spring(k3=2e6), stroke=0.01)],
    transducers=[rv.Transducer((1, 0), C_E)],
)  # fmt: skip


def heun_law(dt=DT):
    """(P, A): Heun's exact stationary covariance of (x0, x1, v0, v1) and its transition, by hand."""
    d = np.array([-1.0, 1.0])  # u = x1 - x0
    c = DAMPING + C_E * np.outer(d, d)
    m_inv = linalg.inv(MASS)
    f = np.block([[np.zeros((2, 2)), np.eye(2)], [-m_inv @ STIFFNESS, -m_inv @ c]])
    g = np.array([0.0, 0.0, 1.0, 1.0]) * math.sqrt(0.5)  # r = (1, 1), S = 1
    a = np.eye(4) + dt * f + 0.5 * dt * dt * f @ f
    b = (np.eye(4) + 0.5 * dt * f) @ g
    p = linalg.solve_discrete_lyapunov(a, dt * np.outer(b, b))
    return p, a


def exact_u(u, dt=DT):
    """(D, P(|u| > D), up-crossing rate) of the discrete paths at D = u sigma_u."""
    p, a = heun_law(dt)
    pick = np.array([-1.0, 1.0, 0.0, 0.0])
    var, lag = pick @ p @ pick, pick @ a @ p @ pick
    d = u * math.sqrt(var)
    return (
        d,
        float(special.erfc(u / math.sqrt(2.0))),
        gaussian_chain_upcrossing_rate(var, lag, dt, d),
    )


def test_linear_start_is_the_schemes_own_stationary_law():
    """The exact start's covariance equals the discrete Lyapunov solution computed by hand."""
    sim = AssemblyPaths(LINEAR, 1.0, duration=0.02, dt=DT)
    p, _ = heun_law()
    chol = sim._start.chol
    np.testing.assert_allclose(chol @ chol.T, p, rtol=1e-9, atol=1e-12 * np.abs(p).max())
    assert sim.start.startswith("exact") and sim.burn_in == 0.0 and sim.exactly_linear


def test_paths_match_a_plain_numpy_heun_loop_on_the_same_rows():
    """Nonlinear assembly (Duffing element), linearised start and a burn-in: each row's peak
    |u|, up-crossings and fraction of steps beyond D from the kernel equal a numpy Heun loop
    driven by the same start and increments."""
    sim = AssemblyPaths(DUFFING, 1.0, stroke=0.012, duration=0.2, dt=DT, burn_in=0.04)
    rows = np.random.default_rng(3).standard_normal((24, sim.dimension))
    out = sim(rows)
    start = sim.starts(rows[:, : sim.dimension - sim.steps_per_path])
    x, v = start[:, :2].copy(), start[:, 3:5].copy()  # rows of x, then the base's, then v
    dw = math.sqrt(DT) * rows[:, sim.dimension - sim.steps_per_path :]
    d = np.array([-1.0, 1.0])
    c = DAMPING + C_E * np.outer(d, d)
    m_inv = linalg.inv(MASS)

    def accel(x, v):
        u = x @ d
        return -(x @ STIFFNESS.T + v @ c.T + np.outer(2e6 * u**3, d)) @ m_inv.T

    n_burn = round(sim.burn_in / DT)
    u_path = []
    for n in range(sim.steps_per_path):
        if n >= n_burn:
            u_path.append(np.abs(x @ d))
        noise = math.sqrt(0.5) * dw[:, n][:, None] * np.ones(2)
        xp, vp = x + v * DT, v + accel(x, v) * DT + noise
        x, v = x + 0.5 * (v + vp) * DT, v + 0.5 * (accel(x, v) + accel(xp, vp)) * DT + noise
    u_path = np.array([*u_path, np.abs(x @ d)])  # the window's states, the last included
    beyond = u_path > 0.012
    np.testing.assert_allclose(out.peak, u_path.max(axis=0), rtol=1e-10)
    np.testing.assert_array_equal(out.upcrossings, np.sum(beyond[1:] & ~beyond[:-1], axis=0))
    np.testing.assert_allclose(out.beyond, beyond[:-1].mean(axis=0), rtol=1e-12)
    assert 0 < out.upcrossings.sum() and np.any(out.peak < 0.012)  # both kinds of path


def test_rice_anchor_of_a_one_mass_assembly_is_the_single_mass_one():
    """The assembly anchor (Lyapunov covariance of the coordinate) against the single-mass
    Rice anchor (its own linear response) on the same device, to rounding; a nonlinear
    assembly is refused in one line."""
    h = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4, stroke=0.01)
    one = rv.Assembly.from_harvester(h)
    a = assembly_crossing_prediction(one, 1.0, 0.01, 0.5)
    b = CROSSING_METHODS["rice"].solve(h, 1.0, 0.01, 0.5)
    assert a.stationary_exceedance == pytest.approx(b.stationary_exceedance, rel=1e-9)
    assert a.upcrossing_rate == pytest.approx(b.upcrossing_rate, rel=1e-9)
    assert a.exact == ("stationary_exceedance", "upcrossing_rate")
    with pytest.raises(ValueError, match="linear assembly"):
        assembly_crossing_prediction(DUFFING, 1.0, 0.01, 0.5)


def test_subset_simulation_matches_the_exact_law_at_one_in_a_million():
    """Linear assembly, white noise: subset simulation's stationary exceedance and crossing
    rate of the harvester's coordinate at P(|u| > D) = 1e-6 against the exact discrete law,
    and importance sampling (exact design points of the linear assembly) at 1e-6 too."""
    d, exceedance, rate = exact_u(4.892)
    sim = AssemblyPaths(LINEAR, 1.0, stroke=d, duration=0.1, dt=DT)
    r = estimate_first_passage(sim, target_cov=0.25, seed=1, samples_per_level=300, progress=False)
    assert r.details["stroke_on"] == "transducer.0"
    assert_matches(r.stationary_exceedance, exceedance, detect=2.0, what="subset exceedance")
    assert_matches(r.upcrossing_rate, rate, detect=2.0, what="subset crossing rate")
    r = estimate_first_passage(sim, method="importance", target_cov=0.05, seed=2, progress=False)
    assert_matches(r.stationary_exceedance, exceedance, detect=0.25, what="importance exceedance")
    assert_matches(r.upcrossing_rate, rate, detect=0.25, what="importance crossing rate")


def test_first_passage_of_a_nonlinear_assembly_agrees_with_crude_monte_carlo():
    """Duffing element, a linearised start and a short burn-in: subset simulation against
    independent crude paths of the same simulator at P(first passage) near 1e-3."""
    sim = AssemblyPaths(DUFFING, 1.0, stroke=0.0194, duration=0.1, dt=DT, burn_in=0.1)
    sub = estimate_first_passage(sim, target_cov=0.2, seed=4, samples_per_level=300,
                                 progress=False).probability_first_passage  # fmt: skip
    crude = estimate_first_passage(sim, method="crude", target_cov=0.25, seed=5,
                                   progress=False).probability_first_passage  # fmt: skip
    assert 3e-4 < crude.mean < 3e-3  # the level the test is about
    difference = Statistic(sub.mean - crude.mean, 0.0,
                           math.hypot(sub.std_error, crude.std_error), 0)  # fmt: skip
    assert_matches(difference + crude.mean, crude.mean, detect=2.0, what="subset - crude")


def test_refusals_name_the_argument():
    with pytest.raises(ValueError, match="method='importance' on an assembly.*method='subset'"):
        rv.first_passage(DUFFING, 1.0, duration=0.1, dt=DT, method="importance")
    with pytest.raises(ValueError, match="`stroke_on` = 'element.3'.*1 element"):
        rv.first_passage(DUFFING, 1.0, duration=0.1, dt=DT, stroke_on="element.3")
    with pytest.raises(ValueError, match="`stroke_on` must name"):
        rv.first_passage(LINEAR.updated({"transducer.0.stroke": None}), 1.0, duration=0.1, dt=DT)
    with pytest.raises(ValueError, match="Brownian increments"):
        rv.first_passage(LINEAR, rv.BandLimited(1.0, 4.0, 20.0), duration=0.1, dt=DT)


def test_reliability_device_json(capsys, tmp_path):
    path = tmp_path / "host.toml"
    path.write_text(LINEAR.to_toml())
    code, out, _ = run(capsys, "reliability", "--device", path, "--psd", 1, "--stroke", 0.006,
                       "--stroke-on", "transducer.0", "--duration", 0.05, "--dt", DT,
                       "--method", "importance", "--target-cov", 0.2, "--json")  # fmt: skip
    assert code == 0
    result = json.loads(out)
    assert result["stroke_on"] == "transducer.0" and result["stroke"] == 0.006
    for key in ("probability_first_passage", "upcrossing_rate", "stationary_exceedance"):
        assert set(result[key]) == {"mean", "ci95"} and result[key]["mean"] > 0
    one_line_error(capsys, ["reliability", "--preset", "figure9", "--psd", "1", "--stroke",
                            "0.01", "--duration", "1", "--stroke-on", "element.0"],
                   "`--stroke-on` names a part of an assembly")  # fmt: skip


def test_linear_surrogate_is_the_kernel_on_the_same_rows():
    """A coil with inductance (a circuit state) under band-pass input (a shaping filter): the
    linear surrogate built from the kernel's tables (importance sampling's design points, the
    exact start) gives every row the kernel's peak |u| to rounding."""
    coil = rv.Inductive(alpha=2.0, r_load=20.0, r_coil=5.0, inductance=0.05)
    device = rv.Assembly.from_matrices(
        MASS, STIFFNESS, DAMPING, transducers=[rv.Transducer((1, 0), coil, stroke=0.01)]
    )
    sim = AssemblyPaths(device, rv.BandPass(1.0, 5.0, 0.2), duration=0.1, dt=DT)
    rows = np.random.default_rng(6).standard_normal((16, sim.dimension))
    z = sim.linear_surrogate.responses(rows)
    np.testing.assert_allclose(sim(rows).peak, np.abs(z).max(axis=1), rtol=1e-9)
    assert sim.setup.layout.n_circuits == 1 and sim.setup.layout.n_filter == 2
