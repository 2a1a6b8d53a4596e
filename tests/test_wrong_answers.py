"""Answers that were silently wrong: each case refused or flagged rather than returned.

Covers the energy-balance check of the method family (:mod:`randvib.analytic.method`,
called by :mod:`randvib.analytic.prediction`), fpk's barrier limit
(:mod:`randvib.analytic.fokker_planck`), and the refusal of a non-confining
potential in :mod:`randvib.identification.synthetic` (and ``randvib record``,
:mod:`randvib.cli.record`), identify's labels of a parameter on its bound
(:mod:`randvib.identification.result`, :mod:`randvib.cli.identify`) and
validate's per-record offsets (:mod:`randvib.identification.prediction`,
:mod:`randvib.cli.validate`).

The exact reference is the white-noise energy balance: the base does work
m S / 4 on the mass, all dissipated, so c_m E[v^2] + P_e = m S / 4 without
friction and <= m S / 4 with it.
"""

import dataclasses
import warnings

import numpy as np
import pytest
from _cli import one_line_error

import randvib as rv
from randvib.analytic.method import ENERGY_BALANCE_TOLERANCE
from randvib.analytic.prediction import METHODS

M, C_M, C_E = 0.0226, 0.116, 0.05


def _balance(h, s, result):
    """(c_m E[v^2] + P_e) / (m S / 4)."""
    return (h.c_m * result.velocity_variance + result.power_electrical) / (h.m * s / 4)


@pytest.mark.parametrize("fc", [0.0, 0.0058])
def test_fpk_refuses_the_issues_deep_double_well(fc, capsys):
    """k = -57.4 N/m, k3 = 5e5 N/m^3, S = 0.005: fpk gave 0.35x the exact power (+360 %
    against Monte Carlo with Coulomb friction); now refused, naming the alternatives."""
    argv = ["power", "--m", M, "--c-m", C_M, "--c-e", C_E, "--k=-57.4", "--k3", "5e5",
            "--psd", "0.005", "--method", "fpk", "--friction", "coulomb", "--fc", fc]  # fmt: skip
    # 32 m E[v^2] without friction, 10 with it (fokker_planck.FPK_MAX_FRICTION_BARRIER)
    one_line_error(capsys, argv, "barrier of 32" if fc == 0 else "barrier of 10")
    # the friction-free answer that remains is exact: c_e S m / (4 (c_m + c_e))
    h = rv.Harvester(m=M, c_m=C_M, c_e=C_E, k=-57.4, k3=5e5)
    exact = C_E * 0.005 * M / (4 * (C_M + C_E))
    assert rv.expected_power(h, 0.005) == pytest.approx(exact, rel=1e-12)


def test_fpk_is_exact_up_to_its_barrier_limit():
    """At the declared limit (32 m E[v^2]) the friction-free balance holds to 1e-3:
    the limit's measured error is 1.5e-4 (fokker_planck.FPK_MAX_BARRIER)."""
    s = 1.0
    ev2 = s * M / (4 * C_M)
    h = rv.Harvester(m=M, c_m=C_M, c_e=0.0, k=-57.4, k3=57.4**2 / (4 * 31.9 * M * ev2))
    assert _balance(h, s, rv.predict(h, s, "fpk")) == pytest.approx(1.0, abs=1e-3)


@pytest.mark.parametrize(("method", "k3"), [("fpk", 1e100), ("fpk-fast", 1e200)])
def test_huge_k3_answers_are_refused_by_the_energy_balance(method, k3):
    """fpk gave 17x and fpk-fast 0.97x the exact friction-free power at these k3.

    With scipy 1.17 (CI's) fpk's quadrature at k3 = 1e100 returns a negative velocity
    variance instead (-0.906): refused before the balance is computed, as any non-positive
    variance is. Either refusal names what is wrong; a number is never returned.
    """
    h = rv.Harvester(m=M, c_m=C_M, c_e=C_E, k=57.4, k3=k3)
    with pytest.raises(ValueError, match=r"white-noise input power|velocity_variance = -"):
        rv.predict(h, 1.0, method)


def test_energy_refusal_on_the_command_line_keeps_the_formula(capsys):
    """The refusal's formula c_m E[v^2] + P_e is physics: the CLI does not turn its c_m
    into the option `--c-m` as it does for argument names."""
    argv = ["power", "--m", "0.0226", "--c-m", "0.05", "--k", "57.4", "--k3", "1e100",
            "--psd", "1", "--method", "fpk"]  # fmt: skip
    one_line_error(capsys, argv, "dissipated power c_m E[v^2] + P_e =")


# the methods of a resistive device (bridge-closure treats only a bridge)
@pytest.mark.parametrize("method", [m for m in METHODS if not METHODS[m].rectifier])
@pytest.mark.parametrize("fc", [0.0, 0.0058])
def test_every_method_meets_the_balance_and_a_broken_answer_is_refused(method, fc):
    """The family's check passes the methods' answers on the paper's device (their
    measured balance error is at most 1.6e-5, method.ENERGY_BALANCE_TOLERANCE) and
    refuses the same answer with E[v^2] raised by 3 % (power 3 % above the balance)."""
    h = rv.Harvester(m=M, c_m=C_M, c_e=C_E, k=57.4, k3=1e5, friction=rv.Coulomb(fc))
    solver = METHODS[method]
    result = rv.predict(h, 1.0, method)
    ratio = _balance(h, 1.0, result)
    if fc == 0:
        assert ratio == pytest.approx(1.0, abs=1e-4)
    else:
        assert ratio < 1.0
    factor = (1 + 3 * ENERGY_BALANCE_TOLERANCE) / ratio
    broken = dataclasses.replace(
        result,
        velocity_variance=result.velocity_variance * factor,
        power_electrical=result.power_electrical * factor,
    )
    with pytest.raises(ValueError, match="white-noise input power"):
        solver.check_answer(h, 1.0, broken)


def test_synthetic_record_refuses_a_non_confining_potential():
    """k = -28.7 N/m, k3 = 0: the mass escapes (|z| ~ 1e269 m); no record to write."""
    device = rv.Harvester(m=0.0226, c_m=0.05, c_e=0.05, k=-28.7, k3=0.0)
    with pytest.raises(ValueError, match="not confining"):
        rv.synthetic_record(device, 1.0, duration=1.0, sample_rate=200.0, seed=0)


def test_record_command_refuses_a_non_confining_potential(capsys, tmp_path):
    out = tmp_path / "r.csv"
    argv = ["record", "--preset", "viscous-td1", "--k=-28.7", "--k3", "0", "--rms", "1",
            "--out", out]  # fmt: skip
    one_line_error(capsys, argv, "not confining")
    assert not out.exists()


def _fit(parameters, bounds, interval):
    """An IdentificationResult with the given values, boxes and local 95 % intervals."""
    from randvib.identification.least_squares import Uncertainty
    from randvib.identification.result import IdentificationResult

    names = tuple(interval)
    unc = Uncertainty(
        names=names,
        estimate={n: parameters[n] for n in names},
        standard_error={n: (interval[n][1] - interval[n][0]) / 4 for n in names},
        interval=interval,
        correlation=np.eye(len(names)),
        noise_std=1.0,
        dof=100,
    )
    return IdentificationResult(
        model="coulomb", parameters=parameters, free=names, cost=1.0, bounds=bounds,
        nfev=1, generations=1, elapsed=1.0, simulations_per_second=1.0, message="",
        uncertainty=unc,
    )  # fmt: skip


def test_identification_on_a_bound_is_labelled_and_has_no_interval():
    """k left on its upper bound 2: 'at upper bound', no interval; c inside its box:
    interval cut at the box; the JSON says the same."""
    fit = _fit(
        {"c": 0.05, "k": 2.0},
        {"c": (0.01, 0.06), "k": (1.0, 2.0)},
        {"c": (0.04, 0.07), "k": (-22.0, 26.0)},
    )
    assert fit.at_bound == {"k": "upper"}
    assert fit.confidence_intervals == {"c": (0.04, 0.06)}
    out = fit.to_dict()
    assert out["at_bound"] == {"k": "upper"}
    assert out["confidence_intervals_95"] == {"c": [0.04, 0.06]}


def test_identification_on_a_bound_warns_naming_bounds():
    """identify ends by warning when a free parameter stopped on its box, naming
    the parameter, the side and --bounds; a fit inside its box says nothing."""
    import warnings

    from randvib.identification.identify import _warn_at_bound

    local = {"c": (0.04, 0.07), "k": (-22.0, 26.0)}
    on = _fit({"c": 0.05, "k": 2.0}, {"c": (0.01, 0.06), "k": (1.0, 2.0)}, local)
    with pytest.warns(UserWarning, match=r"k = 2 N/m on its upper bound.*--bounds k=LO:HI"):
        _warn_at_bound(on)
    inside = _fit({"c": 0.05, "k": 1.5}, {"c": (0.01, 0.06), "k": (1.0, 2.0)}, local)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _warn_at_bound(inside)


def test_identify_command_labels_a_parameter_on_its_bound(capsys, tmp_path):
    """`--bounds k=100:200` on a record of a k = 57 N/m device: k stops at 100."""
    from _cli import fit_args, run

    path = tmp_path / "r.csv"
    rv.synthetic_record("coulomb-td1", 1.0, duration=2.0, sample_rate=1000.0, seed=0).to_csv(path)
    argv = [*fit_args(path, "--bounds", "k=100:200")]
    argv.remove("--no-polish")  # the polish gives the intervals
    code, out, err = run(capsys, *argv)
    assert code == 0, err
    k_row = next(line for line in out.splitlines() if line.startswith("k "))
    assert k_row.rstrip().endswith("at lower bound") and "[" not in k_row


def test_validate_re_estimates_the_offsets_on_each_record(capsys, tmp_path):
    """The true device with record A's offsets on record B (other offsets, no noise):
    J far from 0 when A's offsets are reused; ~0 with B's re-estimated (the truth)."""

    from randvib.identification.models import MeasurementModel
    from randvib.identification.prediction import validate

    device = rv.preset("coulomb-td1")
    kw = dict(duration=2.0, sample_rate=1000.0)
    b = rv.synthetic_record(device, 1.0, seed=2, offset_z=-0.003, offset_input=-0.2, **kw)
    fitted_a = MeasurementModel(input_offset=0.3, output_offset=0.002)
    (given,) = validate(device, [b], measurement=fitted_a, offsets="given")
    (own,) = validate(device, [b], measurement=fitted_a)
    assert given.cost > 1.0
    # the exact offsets give J = 0 up to the simulation's rounding: 1e-4 is far
    # below any misfit and far above the offsets' search tolerance (1e-9 of the box)
    assert own.cost < 1e-4
    # the two offsets are nearly interchangeable with a weak k3 (a constant input
    # mostly shifts z): J, not each offset, is what is determined
    assert own.offsets["output_offset"] == pytest.approx(-0.003, rel=0.1)
    with pytest.raises(ValueError, match="`offsets` must be one of"):
        validate(device, [b], measurement=fitted_a, offsets="fitted")


def test_free_mass_under_band_pass_input_is_simulated():
    """The free mass (k = k3 = 0) under band-pass input: the step check used to find
    no step (z has no stationary variance). Its E[v^2] against the exact Lyapunov
    solution of the (filter, v) system, within the Monte Carlo interval."""
    from _stats import assert_matches
    from scipy import linalg

    from randvib.montecarlo.step_check import LinearTestSystem

    h = rv.Harvester(m=M, c_m=0.1, c_e=0.0, k=0.0, k3=0.0)
    excitation = rv.BandPass(1.0, 8.0, 0.3)
    f, g, pick = LinearTestSystem.of(h, excitation).augmented
    exact = np.diag(pick @ linalg.solve_continuous_lyapunov(f, -(g @ g.T)) @ pick.T)[-1]
    res = rv.simulate(h, excitation, t_end=20.0, dt=2e-4, n_paths=64, burn_in=2.0, seed=3)
    # detect: a 10 % error in E[v^2] must lie outside the interval
    assert_matches(res.velocity_variance, exact, detect=0.10)


def test_linearisation_warns_where_friction_dominates():
    """c_m = c_e = 0.0005 Ns/m, Fc = 5.8 mN, S = 0.005: linearisation 16.6 % below Monte
    Carlo (fpk agrees with Monte Carlo); its friction share 1 - c/c_eq is 0.999."""
    from randvib.analytic.statistical_linearisation import LinearisationValidityWarning

    light = rv.Harvester(m=M, c_m=5e-4, c_e=5e-4, k=57.4, k3=0.0, friction=rv.Coulomb(0.0058))
    with pytest.warns(LinearisationValidityWarning, match="of the dissipation"):
        low = rv.predict(light, 0.005)
    assert low.power_electrical < 0.9 * rv.predict(light, 0.005, "fpk").power_electrical
    # the paper's device at S = 1 (share 0.24, error 0.3 %): no warning
    with warnings.catch_warnings():
        warnings.simplefilter("error", LinearisationValidityWarning)
        rv.predict(rv.preset("coulomb-td1").updated(c_e=0.05), 1.0)
