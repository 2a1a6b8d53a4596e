"""Monte Carlo engine: exact results, pathwise agreement with sdeint, orders, reproducibility.

Statistical tolerances are the estimates' own 95 % confidence half-widths
(fixed seeds), plus the scheme's exactly computed time-step bias where it is
not negligible.
"""

import json

import numba
import numpy as np
import pytest
import sdeint

import randvib as rv
from randvib import exact
from randvib.integrators import INTEGRATORS
from randvib.simulation import SimulationDivergedError, StepSizeWarning, simulate

LINEAR = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4)
DUFFING_COULOMB = rv.preset("figure9").updated(k3=5e5)


def test_linear_oscillator_continuous_time_variances():
    psd = 0.7
    r = simulate(LINEAR, psd, t_end=12.0, dt=2e-4, n_paths=400, burn_in=1.0, seed=3)
    vv = exact.linear_velocity_variance(LINEAR.m, LINEAR.c, psd)
    zz = exact.linear_displacement_variance(LINEAR.m, LINEAR.c, LINEAR.k, psd)
    # the scheme's own bias at this step is exactly computable and far below the CI
    cov = exact.scheme_stationary_covariance("heun", LINEAR.m, LINEAR.c, LINEAR.k, psd, 2e-4)
    assert abs(cov[1, 1] - vv) < 0.05 * r.velocity_variance.ci95
    assert abs(r.velocity_variance.mean - vv) < r.velocity_variance.ci95
    assert abs(r.displacement_variance.mean - zz) < r.displacement_variance.ci95
    assert abs(r.power_electrical.mean - 0.1 * vv) < r.power_electrical.ci95


@pytest.mark.parametrize("method", list(INTEGRATORS))
def test_scheme_matches_its_exact_discrete_stationary_covariance(method):
    # At a coarse step the scheme's stationary covariance differs visibly from
    # the continuous one; the simulation must reproduce the discrete value.
    device = rv.Harvester(m=1.0, c_m=1.0, c_e=0.0, k=4.0)
    dt, psd = 0.05, 2.0
    cov = exact.scheme_stationary_covariance(method, 1.0, 1.0, 4.0, psd, dt)
    r = simulate(
        device,
        psd,
        t_end=200.0,
        dt=dt,
        n_paths=400,
        burn_in=20.0,
        method=method,
        seed=11,
        check_step=False,
    )
    if method == "euler-maruyama":
        # the test discriminates: EM's discrete value is far from the continuous one
        continuous = exact.linear_velocity_variance(1.0, 1.0, psd)
        assert abs(cov[1, 1] - continuous) > 3 * r.velocity_variance.ci95
    assert abs(r.velocity_variance.mean - cov[1, 1]) < r.velocity_variance.ci95
    assert abs(r.displacement_variance.mean - cov[0, 0]) < r.displacement_variance.ci95


def test_duffing_without_friction_matches_gibbs_density():
    device = rv.preset("figure9").updated(friction=None, k3=5e5)
    psd = 1.0
    r = simulate(
        device, psd, t_end=10.0, dt=1e-4, n_paths=256, burn_in=1.0, seed=5, histogram_bins=40
    )
    vv = exact.linear_velocity_variance(device.m, device.c, psd)
    zz = exact.gibbs_displacement_moment(device.m, device.c, device.k, device.k3, psd)
    assert abs(r.velocity_variance.mean - vv) < r.velocity_variance.ci95
    assert abs(r.displacement_variance.mean - zz) < r.displacement_variance.ci95
    # velocity is exactly Gaussian: histogram against the density, bin by bin,
    # within a generous 5-sigma band for correlated samples (effective sample
    # size from the variance estimate's own spread)
    h = r.histogram
    centres = 0.5 * (h.v_edges[1:] + h.v_edges[:-1])
    density = np.exp(-(centres**2) / (2 * vv)) / np.sqrt(2 * np.pi * vv)
    peak = density.max()
    assert np.max(np.abs(h.v_density - density)) < 0.03 * peak


def test_energy_balance_identity_with_coulomb_and_duffing():
    # c E[v^2] + Fc E|v| = S m / 4 exactly, any k3 (CONVENTIONS.md)
    psd = 0.5
    r = simulate(DUFFING_COULOMB, psd, t_end=6.0, dt=1e-4, n_paths=256, burn_in=1.0, seed=2)
    residual = r.energy_balance_residual()
    assert abs(residual.mean) < residual.ci95 + 2e-3 * psd * DUFFING_COULOMB.m / 4
    # friction power equals Fc E|v| path by path
    fp, mav = r.friction_power, r.mean_abs_velocity
    assert fp.mean == pytest.approx(0.0058 * mav.mean, rel=1e-12)


def test_control_variates_agree_and_shrink_the_interval():
    psd = 1.0
    plain = simulate(
        DUFFING_COULOMB, psd, t_end=6.0, dt=1e-4, n_paths=200, burn_in=1.0, seed=8, companion=True
    )
    cv = plain.statistic(plain.harvester.c_e * plain.column(0), control_variates=True)
    p = plain.power_electrical
    assert abs(cv.mean - p.mean) < p.ci95
    assert cv.ci95 < p.ci95 / 5


def _sde_functions(device, psd):
    m, c, k, k3 = device.m, device.c, device.k, device.k3
    fr = device.friction
    amp = np.sqrt(psd / 2)

    if fr is not None and fr.n_states:

        def f(y, t):
            z, v, th = y
            rate = float(fr.bristle_rate(v, th))
            force = fr.sigma0 * th + fr.sigma1 * rate
            return np.array([v, -(c * v + k * z + k3 * z**3 + force) / m, rate])

        def g(y, t):
            return np.array([[0.0], [amp], [0.0]])
    else:

        def f(y, t):
            z, v = y
            force = 0.0 if fr is None else float(fr.force(v))
            return np.array([v, -(c * v + k * z + k3 * z**3 + force) / m])

        def g(y, t):
            return np.array([[0.0], [amp]])

    return f, g


@pytest.mark.filterwarnings("ignore::randvib.simulation.StepSizeWarning")  # EM at 1e-4 on purpose
@pytest.mark.parametrize(
    ("method", "reference"), [("euler-maruyama", sdeint.itoEuler), ("heun", sdeint.stratHeun)]
)
@pytest.mark.parametrize(
    "device",
    [
        rv.preset("figure9").updated(friction=rv.Tanh(0.0058, 500.0), k3=5e5),
        DUFFING_COULOMB,
        rv.preset("lugre-td1").updated(c_e=0.05),
    ],
    ids=["tanh", "coulomb", "lugre"],
)
def test_pathwise_equal_to_sdeint(method, reference, device):
    psd, dt, n = 1.0, 1e-4, 3000
    dw = np.random.default_rng(4).normal(0, np.sqrt(dt), (2, n))
    r = simulate(
        device,
        psd,
        t_end=n * dt,
        dt=dt,
        n_paths=2,
        dW=dw,
        initial=(0.002, -0.05),
        method=method,
        record_paths=2,
        record_every=1,
    )
    f, g = _sde_functions(device, psd)
    tspan = np.linspace(0, n * dt, n + 1)
    for p in range(2):
        y0 = np.array([0.002, -0.05] + ([0.0] if device.friction.n_states else []))
        y = reference(f, g, y0, tspan, dW=dw[p][:, None])
        scale = np.max(np.abs(y[:, :2]), axis=0)
        assert np.max(np.abs(r.histories.z[p] - y[:, 0])) <= 1e-9 * scale[0]
        assert np.max(np.abs(r.histories.v[p] - y[:, 1])) <= 1e-9 * scale[1]


STRONG_ORDER_ROWS = [(name, integ.strong_order) for name, integ in INTEGRATORS.items()]


@pytest.mark.parametrize(("method", "order"), STRONG_ORDER_ROWS)
def test_strong_order_against_fine_reference(method, order):
    # Smooth drift (Duffing, tanh friction with moderate beta); the coarse runs
    # use sums of the reference's Brownian increments (same path).
    device = rv.Harvester(m=1.0, c_m=0.5, c_e=0.0, k=4.0, k3=2.0, friction=rv.Tanh(0.2, 5.0))
    t_end, n_fine, n_paths = 2.0, 2**12, 64
    dt_fine = t_end / n_fine
    dw = np.random.default_rng(9).normal(0, np.sqrt(dt_fine), (n_paths, n_fine))

    def final_state(factor):
        coarse = dw.reshape(n_paths, n_fine // factor, factor).sum(axis=2)
        r = simulate(
            device,
            1.0,
            t_end=t_end,
            dt=dt_fine * factor,
            n_paths=n_paths,
            dW=coarse,
            initial=(0.5, 0.0),
            method=method,
            record_paths=n_paths,
            record_every=n_fine // factor,
            check_step=False,
        )
        return r.histories.z[:, -1], r.histories.v[:, -1]

    z_ref, v_ref = final_state(1)
    factors = [16, 32, 64, 128]
    errors = []
    for fct in factors:
        z, v = final_state(fct)
        errors.append(np.sqrt(np.mean((z - z_ref) ** 2 + (v - v_ref) ** 2)))
    slope = np.polyfit(np.log(factors), np.log(errors), 1)[0]
    assert abs(slope - order) < 0.25, (slope, errors)


@pytest.mark.parametrize(("method", "order"), [(n, i.weak_order) for n, i in INTEGRATORS.items()])
def test_weak_order_of_stationary_variance_bias(method, order):
    # Exact stationary bias of each scheme on the linear oscillator (discrete
    # Lyapunov): it must fall like dt^weak_order.
    dts = np.array([2e-3, 1e-3, 5e-4, 2.5e-4])
    bias = [
        abs(exact.scheme_stationary_covariance(method, 1.0, 0.5, 4.0, 1.0, dt)[1, 1] / 0.5 - 1)
        for dt in dts
    ]
    slope = np.polyfit(np.log(dts), np.log(bias), 1)[0]
    assert abs(slope - order) < 0.1


def test_bit_identical_across_threads_and_batches():
    kw = dict(t_end=0.3, dt=1e-4, burn_in=0.05, seed=21, n_paths=37)
    numba.set_num_threads(1)
    one = simulate(DUFFING_COULOMB, 1.0, **kw)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    many = simulate(DUFFING_COULOMB, 1.0, batch_paths=5, **kw)
    assert np.array_equal(one.per_path, many.per_path)
    assert one.power_electrical == many.power_electrical
    # an ensemble continued in a later call is the same ensemble
    kw.pop("n_paths")
    head = simulate(DUFFING_COULOMB, 1.0, n_paths=20, **kw)
    tail = simulate(DUFFING_COULOMB, 1.0, n_paths=17, first_path=20, **kw)
    assert np.array_equal(np.vstack([head.per_path, tail.per_path]), one.per_path)
    # a different seed gives different noise
    other = simulate(DUFFING_COULOMB, 1.0, n_paths=20, **{**kw, "seed": 22})
    assert not np.array_equal(other.per_path, head.per_path)


def test_memory_is_independent_of_steps_without_histories():
    short = simulate(DUFFING_COULOMB, 1.0, t_end=0.01, dt=1e-4, n_paths=16)
    long = simulate(DUFFING_COULOMB, 1.0, t_end=0.5, dt=1e-4, n_paths=16)
    assert short.per_path.nbytes == long.per_path.nbytes
    assert long.histories is None and long.histogram is None


def test_lugre_runs_and_sticks_less_than_it_slides():
    device = rv.preset("lugre-td1").updated(c_e=0.05)
    r = simulate(device, 1.0, t_end=3.0, dt=1e-4, n_paths=32, burn_in=0.5, seed=1)
    assert r.power_electrical.mean > 0 and np.isfinite(r.power_electrical.ci95)
    # LuGre dissipates: friction power is positive
    assert r.friction_power.mean - r.friction_power.ci95 > 0


def test_blow_up_is_reported_with_step_and_parameters():
    with pytest.raises(SimulationDivergedError, match=r"non-finite by step \d+.*dt = 0.05"):
        simulate(
            LINEAR.updated(k3=1e6),
            1.0,
            t_end=500.0,
            dt=0.05,
            n_paths=8,
            method="euler-maruyama",
            check_step=False,
        )


def test_too_large_step_refused_with_bound():
    with pytest.raises(ValueError, match=r"`dt` = 0.01 s is too large.*use dt <= ") as err:
        simulate(DUFFING_COULOMB, 1.0, t_end=1.0, dt=0.01, n_paths=4)
    bound = float(str(err.value).split("use dt <= ")[1].split(" s")[0])
    with pytest.warns(StepSizeWarning):  # accepted, with a warning (bias between 1 and 10 %)
        simulate(DUFFING_COULOMB, 1.0, t_end=0.2, dt=bound * 0.99, n_paths=2)
    with pytest.warns(StepSizeWarning):
        # EM on this device: bias about k dt / c = 2.9 % (warned, not refused)
        simulate(LINEAR, 1.0, t_end=0.1, dt=1e-4, n_paths=2, method="euler-maruyama")


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"n_paths": 0}, "`n_paths`"),
        ({"t_end": -1.0}, "`t_end`"),
        ({"dt": 0.0}, "`dt`"),
        ({"burn_in": 2.0}, "`burn_in`"),
        ({"method": "rk4"}, "`method`"),
        ({"dW": np.zeros((3, 3))}, "`dW` must have shape"),
        ({"initial": "somewhere"}, "`initial`"),
        ({"seed": -1}, "`seed`"),
    ],
)
def test_bad_arguments(kwargs, fragment):
    base = dict(t_end=1.0, dt=1e-4, n_paths=4)
    with pytest.raises(ValueError, match=fragment):
        simulate(LINEAR, 1.0, **{**base, **kwargs})
    with pytest.raises(ValueError, match="`psd`"):
        simulate(LINEAR, -1.0, **base)


def test_cli_simulate_json(capsys):
    from randvib.cli import main

    code = main(
        [
            "simulate",
            "--preset",
            "figure9",
            "--psd",
            "1",
            "--paths",
            "16",
            "--t-end",
            "1",
            "--burn-in",
            "0.2",
            "--json",
        ]
    )
    data = json.loads(capsys.readouterr().out)
    assert code == 0
    for key in (
        "power_electrical",
        "velocity_variance",
        "displacement_variance",
        "mean_abs_velocity",
    ):
        assert set(data[key]) == {"mean", "ci95"}
    code = main(["simulate", "--preset", "figure9", "--psd", "1", "--method", "rk4"])
    assert code == 2 and "`--method`" in capsys.readouterr().err
