"""Monte Carlo engine: exact results, pathwise agreement, orders, reproducibility.

Every Monte Carlo comparison goes through ``assert_matches`` (tests/_stats.py):
the estimate must lie within 4 standard errors of an independent number, after
subtracting the scheme's exactly computed time-step bias where there is one
(``known_bias``), and the ensemble must be large enough to see the stated
relative bias (``detect``, 1 % of a variance or of a power) with 6 standard
errors to spare. Control variates (the Ito integral and the energy change of
:meth:`SimulationResult.controls`, cross-fitted by ``estimate``) make those
ensembles cheap.

The statistics are functions of the seed (``case_*`` below) so that
``tests/calibration/simulation.py`` can rerun them over many seeds; each test's
docstring records the resulting z-scores (number of seeds, mean, standard
deviation, largest |z|).

Covers :func:`randvib.simulate` and the parts it orchestrates:
:mod:`randvib.montecarlo.simulation`, :mod:`randvib.montecarlo.validation`,
:mod:`randvib.montecarlo.options`, :mod:`randvib.montecarlo.kernel_setup`,
:mod:`randvib.montecarlo.kernel`, :mod:`randvib.montecarlo.batches`,
:mod:`randvib.montecarlo.results` and the step check of
:mod:`randvib.montecarlo.step_check`. The estimators themselves:
tests/test_statistics.py.
"""

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numba
import numpy as np
import pytest
import sdeint
from _stats import assert_matches

import randvib as rv
from randvib.analytic import exact_solutions as exact
from randvib.montecarlo import integrators
from randvib.montecarlo.batches import SimulationDivergedError
from randvib.montecarlo.integrators import INTEGRATORS
from randvib.montecarlo.simulation import simulate
from randvib.montecarlo.step_check import StepSizeWarning
from randvib.statistics import estimate

LINEAR = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4)
DUFFING_COULOMB = rv.preset("figure9").updated(k3=5e5)
#: Linear device with a resistive circuit (paper's alpha and coil, R_L = 1 ohm).
LOADED = rv.Harvester.from_electrical(
    m=0.0226, c_m=0.1, k=57.4, alpha=0.1992, r_load=1.0, r_coil=0.48
)
#: Friction strong enough to take about half the input power S m / 4, so that
#: a 1 % error in the friction force moves the energy balance by about 0.5 %.
STRONG_COULOMB = rv.preset("figure9").updated(k3=5e5, fc=0.02)
LUGRE = rv.preset("lugre-td1").updated(c_e=0.05)

DETECT = 0.01  # relative bias every exact comparison below must be able to see


# --------------------------------------------------------------------- cases
# Each case returns [(what, Statistic, reference, known_bias, detect), ...];
# the tests assert them, tests/calibration/simulation.py collects z-scores.


def case_linear_continuous(seed):
    """Linear oscillator: E[v^2], E[z^2], E[P_e] against the continuous-time values.

    Heun at dt = 5e-4 s; its stationary bias is computed exactly from the
    discrete Lyapunov equation (about -1.4e-4 relative) and subtracted.
    """
    psd, dt = 0.7, 5e-4
    h = LINEAR
    r = simulate(
        h, psd, t_end=6.0, dt=dt, n_paths=800, burn_in=0.5, seed=seed, control_variates=True
    )
    vv = exact.linear_velocity_variance(h.m, h.c, psd)
    zz = exact.linear_displacement_variance(h.m, h.c, h.k, psd)
    cov = integrators.scheme_stationary_covariance("heun", h.m, h.c, h.k, psd, dt)
    return [
        ("E[v^2]", r.velocity_variance, vv, cov[1, 1] - vv, DETECT),
        ("E[z^2]", r.displacement_variance, zz, cov[0, 0] - zz, DETECT),
        ("E[P_e]", r.power_electrical, h.c_e * vv, h.c_e * (cov[1, 1] - vv), DETECT),
    ]


SCHEME_DEVICE = rv.Harvester(m=1.0, c_m=1.0, c_e=0.0, k=4.0)


def case_scheme_discrete(method, seed):
    """Each scheme at a coarse step against its exact discrete stationary covariance."""
    dt, psd = 0.05, 2.0
    cov = integrators.scheme_stationary_covariance(method, 1.0, 1.0, 4.0, psd, dt)
    r = simulate(
        SCHEME_DEVICE,
        psd,
        t_end=200.0,
        dt=dt,
        n_paths=1600,
        burn_in=20.0,
        scheme=method,
        seed=seed,
        check_step=False,
        control_variates=True,
    )
    return [
        ("E[v_n^2]", r.velocity_variance, cov[1, 1], 0.0, DETECT),
        ("E[z_n^2]", r.displacement_variance, cov[0, 0], 0.0, DETECT),
    ]


GIBBS_DEVICE = rv.preset("figure9").updated(friction=None, k3=5e5)


def case_duffing_gibbs(seed):
    """Duffing without friction: E[v^2] = S m/(4c), E|v| Gaussian, Gibbs E[z^2].

    The controls are the Ito integral and the energy change only (no
    companion: this device is its own friction-free companion). Heun at
    dt = 2e-4 s: the scheme's bias on the linearised device is 3e-5 relative,
    below a tenth of the standard errors, and is not subtracted.
    """
    psd = 1.0
    h = GIBBS_DEVICE
    r = simulate(
        h, psd, t_end=3.0, dt=2e-4, n_paths=1280, burn_in=0.5, seed=seed, control_variates=True
    )
    vv = exact.linear_velocity_variance(h.m, h.c, psd)
    zz = exact.gibbs_displacement_moment(h.m, h.c, h.k, h.k3, psd)
    return [
        ("E[v^2]", r.velocity_variance, vv, 0.0, DETECT),
        ("E|v|", r.mean_abs_velocity, np.sqrt(2 * vv / np.pi), 0.0, DETECT),
        ("E[z^2]", r.displacement_variance, zz, 0.0, DETECT),
    ]


def case_energy_balance(seed):
    """c E[v^2] + Fc E|v| = S m / 4 with the *declared* Fc (Coulomb + Duffing).

    Built from the velocity moments, not from ``friction_power`` (which uses
    the kernel's own force and so balances for any force). Required power: 1 %
    of the friction power Fc E|v| (about 0.5 % of S m / 4 here).
    """
    psd = 0.5
    h = STRONG_COULOMB
    fc = h.friction.fc
    r = simulate(h, psd, t_end=5.0, dt=2e-4, n_paths=512, burn_in=1.5, seed=seed)
    balance = r.statistic(
        h.c * r.column(0) + fc * r.column(2),  # engine.ACC_V2, engine.ACC_ABS_V
        control_variates=True,
    )
    input_power = psd * h.m / 4.0
    friction_share = fc * r.mean_abs_velocity.mean / input_power
    return [("c E[v^2] + Fc E|v|", balance, input_power, 0.0, DETECT * friction_share)]


def case_load_power(seed):
    """E[P_L] = R_L alpha^2 / (R_L + R_C)^2 E[v^2] of a linear device from its circuit."""
    psd, dt = 0.7, 5e-4
    h = LOADED
    e = h.electrical
    r = simulate(
        h, psd, t_end=4.0, dt=dt, n_paths=512, burn_in=0.5, seed=seed, control_variates=True
    )
    vv = exact.linear_velocity_variance(h.m, h.c, psd)
    cov = integrators.scheme_stationary_covariance("heun", h.m, h.c, h.k, psd, dt)
    factor = e.r_load * e.alpha**2 / (e.r_load + e.r_coil) ** 2
    return [("E[P_L]", r.power_load, factor * vv, factor * (cov[1, 1] - vv), DETECT)]


def lugre_reference(device, psd, dw, dt, n_burn, initial):
    """Stochastic Heun for (z, v, theta) with LuGre friction, in plain numpy.

    Written from docs/conventions.md (theta' = v - |v| theta / g(v), F = sigma0
    theta + sigma1 theta', sigma0 g = Fc + (Fs - Fc) exp(-(v/vs)^2)), not from
    the package's friction code. Returns per-path window means of v^2, z^2, v F.
    """
    m, c, k, k3 = device.m, device.c, device.k, device.k3
    f = device.friction
    s0, s1, fc, fs, vs = f.sigma0, f.sigma1, f.fc, f.fs, f.vs
    amp = np.sqrt(psd / 2.0)

    def drift(z, v, th):
        g = (fc + (fs - fc) * np.exp(-((v / vs) ** 2))) / s0
        rate = v - np.abs(v) * th / g
        force = s0 * th + s1 * rate
        return -(c * v + k * z + k3 * z**3 + force) / m, rate, force

    n_paths, n_steps = dw.shape
    z = np.full(n_paths, float(initial[0]))
    v = np.full(n_paths, float(initial[1]))
    th = np.zeros(n_paths)
    sums = np.zeros((3, n_paths))
    for n in range(n_steps):
        a1, r1, f1 = drift(z, v, th)
        if n >= n_burn:
            sums[0] += v * v
            sums[1] += z * z
            sums[2] += v * f1
        noise = amp * dw[:, n]
        zp, vp, tp = z + v * dt, v + a1 * dt + noise, th + r1 * dt
        a2, r2, _ = drift(zp, vp, tp)
        z, v, th = (
            z + 0.5 * dt * (v + vp),
            v + 0.5 * dt * (a1 + a2) + noise,
            th + 0.5 * dt * (r1 + r2),
        )
    return sums / (n_steps - n_burn)


def case_lugre_fine_reference(seed):
    """LuGre engine at dt = 1e-4 s against the numpy reference at dt / 2, same noise.

    Pathwise coupled: the engine is driven by sums of the reference's Brownian
    increments, so per-path differences carry only discretisation error and
    their standard error is small. The statistic is the engine's mean with the
    standard error of the coupled difference; the reference is the fine mean.
    """
    psd, dt, t_end, burn_in, n_paths = 1.0, 1e-4, 0.6, 0.3, 32
    fine = dt / 2
    n_fine = int(round(t_end / fine))
    dw = np.random.default_rng(seed).normal(0.0, np.sqrt(fine), (n_paths, n_fine))
    ref = lugre_reference(LUGRE, psd, dw, fine, int(round(burn_in / fine)), (0.0, 0.0))
    r = simulate(
        LUGRE,
        psd,
        t_end=t_end,
        dt=dt,
        n_paths=n_paths,
        burn_in=burn_in,
        dW=dw.reshape(n_paths, -1, 2).sum(axis=2),
        initial=(0.0, 0.0),
    )
    out = []
    for what, col, row in (("E[v^2]", 0, 0), ("E[z^2]", 1, 1), ("E[v F]", 3, 2)):
        coupled = estimate(r.column(col) - ref[row] + ref[row].mean())
        out.append((what, coupled, float(ref[row].mean()), 0.0, DETECT))
    return out


def _check(case):
    for what, stat, reference, bias, detect in case:
        assert_matches(stat, reference, detect=detect, known_bias=bias, what=what)


# --------------------------------------------------------------------- tests
def test_linear_oscillator_continuous_time_variances():
    """E[v^2] = S m/(4c), E[z^2] = S m^2/(4ck), E[P_e] = c_e E[v^2] (Heun bias subtracted).

    Detects 1 % in each (e.g. 1 % too much noise variance). Calibration
    (tests/calibration/simulation.py, 800 paths): 120 seeds, z mean / SD /
    largest |z|: E[v^2] and E[P_e] +0.09 / 1.08 / 3.1, E[z^2] -0.04 / 1.13 /
    3.2 (300 seeds at 512 paths: +0.01 / 1.02 / 3.2 and +0.00 / 1.08 / 2.6);
    smallest power margin 7.3 standard errors (>= 6 required).
    """
    _check(case_linear_continuous(seed=3))


def test_load_power_matches_circuit_formula():
    """power_load of a device built from its circuit: R_L alpha^2/(R_L+R_C)^2 E[v^2].

    Detects 1 % of E[P_L] (e.g. a wrong load fraction or 1 % too much noise).
    Calibration: 300 seeds, z mean -0.03, SD 1.07, largest |z| 2.8; smallest
    power margin 11.6 standard errors.
    """
    _check(case_load_power(seed=4))


@pytest.mark.parametrize("method", list(INTEGRATORS))
def test_scheme_matches_its_exact_discrete_stationary_covariance(method):
    """At a coarse step each scheme must hit its own discrete stationary covariance.

    Detects 1 % in E[v_n^2] and E[z_n^2]. Calibration (1600 paths): 120 seeds,
    z mean / SD / largest |z|: EM v +0.03 / 1.03 / 2.3, EM z +0.04 / 0.99 /
    3.9, Heun v +0.03 / 1.04 / 2.4, Heun z +0.02 / 0.96 / 3.8; smallest power
    margin 7.1 standard errors.
    """
    case = case_scheme_discrete(method, seed=11)
    if method == "euler-maruyama":
        # the test discriminates: EM's discrete value is far from the continuous one
        continuous = exact.linear_velocity_variance(1.0, 1.0, 2.0)
        assert abs(case[0][2] - continuous) > 0.2 * continuous
    _check(case)


def test_duffing_without_friction_matches_gibbs_density():
    """E[v^2] = S m/(4c) and E|v| = sqrt(2/pi) sigma_v for every k3; E[z^2] from Gibbs.

    Controlled estimates against exact numbers: a 1 % error in a controlled
    mean (e.g. in the control-variate arithmetic) or in the noise is detected.
    Calibration (1280 paths): 120 seeds, z mean / SD / largest |z|: E[v^2]
    -0.10 / 1.07 / 2.5, E|v| -0.01 / 1.10 / 4.02 (one seed of 120 just above
    the threshold), E[z^2] +0.04 / 0.96 / 2.3; 160 further seeds (3000-3159):
    E[v^2] -0.13 / 1.08 / 3.0, E|v| +0.08 / 0.95 / 2.9, E[z^2] +0.03 / 1.00 /
    2.4. Smallest power margin 7.0 standard errors.
    """
    _check(case_duffing_gibbs(seed=5))


def test_energy_balance_identity_with_coulomb_and_duffing():
    """c E[v^2] + Fc E|v| = S m / 4 exactly, any k3 (docs/conventions.md), declared Fc.

    Detects a 1 % error in the friction force applied by the kernel (about
    0.5 % of the balance). Calibration: 100 seeds, z mean -0.06, SD 0.97,
    largest |z| 2.6; smallest power margin 9.3 standard errors. The kernel
    with a Coulomb force 1.01 Fc fails it at about -10 standard errors.
    """
    _check(case_energy_balance(seed=2))
    # the kernel's friction power is the declared Fc times E|v|, path by path
    r = simulate(DUFFING_COULOMB, 0.5, t_end=0.5, dt=1e-4, n_paths=16, burn_in=0.1, seed=2)
    fp, mav = r.friction_power, r.mean_abs_velocity
    assert fp.mean == pytest.approx(DUFFING_COULOMB.friction.fc * mav.mean, rel=1e-12)


def case_control_variate_gain(seed):
    """Half-width ratio plain / controlled for E[P_e] with a companion (Coulomb)."""
    r = simulate(
        DUFFING_COULOMB,
        1.0,
        t_end=3.0,
        dt=1e-4,
        n_paths=128,
        burn_in=0.5,
        seed=seed,
        companion=True,
    )
    y = r.harvester.c_e * r.column(0)
    return r.statistic(y, control_variates=False).ci95 / r.statistic(y, control_variates=True).ci95


def test_control_variates_shrink_the_interval():
    """The controls shrink the 95 % half-width of E[P_e] at least five-fold.

    (Agreement of controlled estimates with exact values is tested above.)
    Calibration: 50 seeds, smallest ratio 21.5, median 28.6.
    """
    assert case_control_variate_gain(seed=8) > 5


def test_lugre_against_independent_fine_step_reference():
    """LuGre: engine at dt against a numpy Heun at dt/2 on the same Brownian path.

    Detects a 1 % error in E[v^2], E[z^2] or the friction power E[v F] of the
    LuGre engine: a wrong bristle law or force in the kernel, or a time-step
    bias of the engine at dt above 1 %. The engine's own bias at dt = 1e-4 s
    (against dt/2) is below the standard error (see calibration).
    Calibration: 40 seeds, z mean / SD / largest |z|: E[v^2] -0.15 / 1.07 /
    2.7, E[z^2] -0.19 / 1.05 / 3.2, E[v F] +0.54 / 1.02 / 2.4 (the engine's
    residual time-step bias in the friction power, about 0.5 standard
    error, i.e. about 0.01 %); smallest power margin 23.6 standard errors.
    """
    _check(case_lugre_fine_reference(seed=1))


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


@pytest.mark.filterwarnings(
    "ignore::randvib.montecarlo.step_check.StepSizeWarning"
)  # EM at 1e-4 on purpose
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
        scheme=method,
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
            scheme=method,
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
        abs(
            integrators.scheme_stationary_covariance(method, 1.0, 0.5, 4.0, 1.0, dt)[1, 1] / 0.5 - 1
        )
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


def _proc_status_bytes(key):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024
    raise KeyError(key)


def _peak_memory_growth(run):
    """Peak resident memory during ``run()`` above the resident memory before it (bytes).

    Linux: writing 5 to /proc/self/clear_refs resets the peak (VmHWM).
    """
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")
    before = _proc_status_bytes("VmRSS")
    run()
    return _proc_status_bytes("VmHWM") - before


def _can_reset_peak_memory():
    try:
        _peak_memory_growth(lambda: None)
    except OSError:
        return False
    return True


@pytest.mark.skipif(
    not sys.platform.startswith("linux") or not _can_reset_peak_memory(),
    reason="needs Linux /proc/self/clear_refs to reset the peak resident memory",
)
def test_memory_does_not_grow_with_steps_without_histories():
    """Peak memory of a 200 000-step run is that of a 100-step run (no per-step storage).

    A buffer of one float per path and step would take 16 * 2e5 * 8 B = 25.6 MB;
    the growth of the peak resident memory must stay below a quarter of that,
    and the same measurement must see such a buffer when one is allocated.
    Measured in a fresh process: in a long test session the allocator reuses
    pages that are already resident, and the check that the measurement sees
    a buffer then fails (seen twice in full runs: 11 MB for a 25.6 MB buffer).
    """
    probe = textwrap.dedent(
        """
        import json, numpy as np, randvib as rv
        from randvib.montecarlo.simulation import simulate

        def status(key):
            for line in open("/proc/self/status"):
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
            raise KeyError(key)

        def growth(run):
            with open("/proc/self/clear_refs", "w") as f:
                f.write("5")
            before = status("VmRSS")
            run()
            return status("VmHWM") - before

        seen = growth(lambda: np.ones(16 * 200_000).sum())  # before anything is freed
        device = rv.preset("figure9").updated(k3=5e5)
        kw = dict(n_paths=16, dt=1e-4, seed=1, progress=False)
        simulate(device, 1.0, t_end=0.01, **kw)  # compiled code loaded, threads up
        short = growth(lambda: simulate(device, 1.0, t_end=0.01, **kw))
        long = growth(lambda: simulate(device, 1.0, t_end=20.0, **kw))
        print(json.dumps({"seen": seen, "short": short, "long": long}))
        """
    )
    root = Path(__file__).resolve().parents[1]
    proc = subprocess.run(
        [sys.executable, "-c", probe], cwd=root, capture_output=True, text=True, check=True
    )
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    per_step_buffer = 16 * 200_000 * 8
    assert out["seen"] > per_step_buffer / 2, out  # the measurement can see such a buffer
    assert out["long"] - out["short"] < per_step_buffer / 4, out


def test_blow_up_is_reported_with_step_and_parameters():
    with pytest.raises(SimulationDivergedError, match=r"non-finite by step \d+.*dt = 0.05"):
        simulate(
            LINEAR.updated(k3=1e6),
            1.0,
            t_end=500.0,
            dt=0.05,
            n_paths=8,
            scheme="euler-maruyama",
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
        simulate(LINEAR, 1.0, t_end=0.1, dt=1e-4, n_paths=2, scheme="euler-maruyama")


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"n_paths": 0}, "`n_paths`"),
        ({"t_end": -1.0}, "`t_end`"),
        ({"dt": 0.0}, "`dt`"),
        ({"burn_in": 2.0}, "`burn_in`"),
        ({"scheme": "rk4"}, "`scheme`"),
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


def test_the_integrator_is_named_scheme_only():
    """``scheme`` names the integrator; ``method`` (the analytic methods' word) is no alias."""
    base = dict(t_end=0.05, dt=1e-4, n_paths=4, seed=2, check_step=False, progress=False)
    result = simulate(LINEAR, 1.0, scheme="euler-maruyama", **base)
    # the JSON key stays `method`, as the CLI's --method
    assert result.scheme == "euler-maruyama" and result.summary()["method"] == "euler-maruyama"
    assert not hasattr(result, "method")
    with pytest.raises(TypeError, match="method"):
        simulate(LINEAR, 1.0, method="heun", **base)


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
