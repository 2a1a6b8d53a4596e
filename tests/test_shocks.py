"""Shocks: a Poisson train of pulses (randvib.models.shock) and Campbell's theorem.

* the pulse's spectrum |P(f)|^2 against its Fourier integral (both shapes,
  the half sine's removable point f = 1/(2D) included), Campbell's PSD
  integrating to lambda E[A^2] int p^2, the kurtosis formula;
* the exact step integrals of a pulse against quadrature;
* the sampled train's step integrals (what Monte Carlo adds to the velocity)
  with the exact variance of a step integral, lambda E[A^2] int (I(s + dt) -
  I(s))^2 ds, within its sampling error;
* Monte Carlo of a linear device under shocks against Campbell's exact
  E[v^2] (the analytic route: the shock train's spectrum through the device),
  and a nonlinear device refused by the analytic methods.

The Monte Carlo statistics (``case_*``) are calibrated over seeds by
``tests/calibration/non_gaussian_tests.py``.
"""

import numpy as np
import pytest
from _stats import assert_matches
from scipy import integrate

import randvib as rv
from randvib.montecarlo.forcing import ForcingInput
from randvib.statistics import estimate

DAMPED = rv.Harvester(m=0.0226, c_m=0.5, c_e=0.5, k=57.4)


def pulse(shape, d):
    if shape == "rectangular":
        return lambda t: 1.0
    return lambda t: np.sin(np.pi * t / d)


@pytest.mark.parametrize("shape", ["half-sine", "rectangular"])
def test_pulse_spectrum_is_its_fourier_integral_and_campbell_integrates_to_the_variance(shape):
    d = 0.01
    train = rv.ShockTrain(3.0, 10.0, d, shape=shape)
    p = pulse(shape, d)
    for f in (0.0, 20.0, 1.0 / (2 * d), 73.0, 150.0, 410.0):
        re = integrate.quad(lambda t, f=f: p(t) * np.cos(2 * np.pi * f * t), 0, d, limit=200)[0]
        im = integrate.quad(lambda t, f=f: p(t) * np.sin(2 * np.pi * f * t), 0, d, limit=200)[0]
        assert train.pulse_spectrum(f) == pytest.approx(re**2 + im**2, rel=1e-9, abs=1e-18)
    # lobe by lobe (zeros at k / D) up to F = 400 / D, and the tail beyond by its
    # asymptote: lambda A^2 / (pi^2 F) for the rectangle, O(F^-3) for the half sine
    top = 400 / d
    lobes = [integrate.quad(train.psd, k / d, (k + 1) / d)[0] for k in range(400)]
    tail = 3.0 * 100.0 / (np.pi**2 * top) if shape == "rectangular" else 0.0
    assert sum(lobes) + tail == pytest.approx(train.variance, rel=1e-6)
    p2 = integrate.quad(lambda t: p(t) ** 2, 0, d)[0]
    p4 = integrate.quad(lambda t: p(t) ** 4, 0, d)[0]
    assert train.variance == pytest.approx(3.0 * 100.0 * p2, rel=1e-12)
    assert train.kurtosis == pytest.approx(3.0 + p4 / (3.0 * p2**2), rel=1e-12)


def test_step_integrals_of_a_pulse_are_exact():
    train = rv.ShockTrain(1.0, 1.0, 0.01)
    dt, t0, peak = 1e-3, 0.01234, -2.0
    steps = train.step_integrals(np.array([t0]), np.array([peak]), 40, dt)
    for j in range(40):
        lo, hi = max(j * dt, t0), min((j + 1) * dt, t0 + 0.01)
        exact = (
            0.0
            if hi <= lo
            else peak * integrate.quad(lambda t: np.sin(np.pi * (t - t0) / 0.01), lo, hi)[0]
        )
        assert steps[j] == pytest.approx(exact, rel=1e-10, abs=1e-16)
    assert steps.sum() == pytest.approx(peak * 2 * 0.01 / np.pi, rel=1e-12)


def case_sampled_step_integrals(seed):
    """Mean square of the kicks (step integrals) of 256 paths x 20 s against the exact one."""
    train = rv.ShockTrain(20.0, 10.0, 0.01, distribution="rayleigh")
    dt, n = 1e-3, 20_000
    kicks = ForcingInput((), train, n, dt, seed).kicks(0, 256)
    d = train.duration

    def running(s):  # the half sine's running integral I(s), written out
        return d / np.pi * (1.0 - np.cos(np.pi * np.clip(s, 0.0, d) / d))

    exact = train.rate * train.amplitude**2 * integrate.quad(
        lambda s: (running(s + dt) - running(s)) ** 2, -dt, train.duration, limit=200)[0]  # fmt: skip
    yield "kick mean square", estimate(np.mean(kicks**2, axis=1)), exact, 0.0, 0.035


def test_sampled_train_has_campbell_s_variance():
    """Calibrated over 30 seeds (tests/calibration/non_gaussian_tests.txt): z mean +0.17,
    SD 1.37, max |z| 3.8."""
    for what, stat, ref, bias, detect in case_sampled_step_integrals(4):
        assert_matches(stat, ref, detect=detect, known_bias=bias, what=what)


def case_campbell_linear(seed):
    """E[v^2] of a linear device under shocks on noise, 64 paths x 20 s, against Campbell."""
    x = rv.White(0.02) + rv.ShockTrain(20.0, 10.0, 0.01)
    r = rv.simulate(DAMPED, x, t_end=21.0, burn_in=1.0, dt=5e-4, n_paths=64, seed=seed,
                    progress=False)  # fmt: skip
    yield "E[v^2]", r.velocity_variance, rv.predict(DAMPED, x).velocity_variance, 0.0, 0.07


def test_linear_device_under_shocks_matches_campbell():
    """Calibrated over 30 seeds (tests/calibration/non_gaussian_tests.txt): z mean -0.03,
    SD 1.12, max |z| 2.6."""
    for what, stat, ref, bias, detect in case_campbell_linear(2):
        assert_matches(stat, ref, detect=detect, known_bias=bias, what=what)


def test_analytic_methods_take_shocks_on_a_linear_device_only():
    shocks = rv.ShockTrain(2.0, 20.0, 0.01)
    with pytest.raises(ValueError, match=r"treats shocks on a linear device only .*with coulomb "
                                         r"friction and a cubic spring"):  # fmt: skip
        rv.predict(rv.preset("figure9"), shocks)
    linear = DAMPED
    exact = output_variances_v(linear, shocks)
    assert rv.predict(linear, shocks).velocity_variance == pytest.approx(exact, rel=1e-6)


def output_variances_v(device, excitation):
    """int |H_v|^2 S df by scipy's quad: an independent route to the spectral integral."""

    def integrand(f):
        w = 2 * np.pi * f
        h = -1j * w * device.m / (device.k - device.m * w**2 + 1j * device.c * w)
        return abs(h) ** 2 * excitation.psd(f)

    return integrate.quad(integrand, 0, np.inf, limit=2000, points=None)[0]
