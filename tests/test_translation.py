"""Non-Gaussian stationary input: translation processes (randvib.models.translation).

* the marginal: generalised-normal kurtosis exact, standardised tables and
  samples, the correlation map h(rho) (the identity for the Gaussian,
  increasing, odd for a symmetric marginal);
* ITAM: the achieved spectrum near the target, the Gaussian case exact,
  incompatible pairs and kurtosis below the uniform's 1.8 refused by name;
* the synthesised input: its variance, kurtosis and band power against the
  process's exact values within their sampling error (paths are independent:
  per-path time averages are batch means; the kurtosis is a ratio of means,
  its standard error by the delta method over paths);
* Monte Carlo (:class:`randvib.montecarlo.driven.TranslatedInput`): a linear
  device's E[v^2] is the spectral integral of the simulated process's spectrum
  whatever its marginal;
* the analytic methods answer with the spectrum, exactly the Gaussian answer,
  and warn naming the kurtosis on a nonlinear device only.

The Monte Carlo statistics (``case_*``) are calibrated over seeds by
``tests/calibration/non_gaussian_tests.py``.
"""

import warnings

import numpy as np
import pytest
from _stats import assert_matches

import randvib as rv
from randvib.analytic.linear_response import mechanical_block, output_variances
from randvib.analytic.statistical_linearisation import LinearisationValidityWarning
from randvib.models.assembly import Assembly
from randvib.models.translation import MAX_TRANSLATION_ERROR, Marginal
from randvib.statistics import Statistic, estimate

BAND = rv.BandLimited(0.1, 4.0, 20.0)
DAMPED = rv.Harvester(m=0.0226, c_m=0.5, c_e=0.5, k=57.4)  # zeta 0.44: short memory


# ----------------------------------------------------------------- the marginal
@pytest.mark.parametrize("kurtosis", [2.0, 3.0, 6.0, 10.0])
def test_generalised_normal_marginal_has_its_kurtosis(kurtosis):
    m = Marginal.from_kurtosis(kurtosis)
    assert m.moment(1) == pytest.approx(0.0, abs=1e-12)
    assert m.moment(2) == pytest.approx(1.0, rel=1e-12)
    assert m.kurtosis == pytest.approx(kurtosis, rel=2e-4)
    rho, h = m.correlation_map
    assert np.all(np.diff(h) > 0) and h[0] == pytest.approx(-1.0, abs=1e-9)  # odd, increasing
    if kurtosis == 3.0:
        np.testing.assert_allclose(h, rho, atol=1e-12)  # the Gaussian translates to itself


def test_tabulated_and_sampled_marginals_are_standardised():
    """A Laplace density table and Laplace samples: mean 0, variance 1, kurtosis near 6."""
    x = np.linspace(-30.0, 30.0, 6001)
    table = Marginal.from_table(x + 5.0, 0.5 * np.exp(-np.abs(x)))  # shifted: the mean is removed
    assert table.moment(1) == pytest.approx(0.0, abs=1e-12)
    assert table.moment(2) == pytest.approx(1.0, rel=1e-12)
    assert table.kurtosis == pytest.approx(6.0, rel=2e-2)
    samples = Marginal.from_samples(np.random.default_rng(1).laplace(2.0, 3.0, 200_000))
    assert samples.kurtosis == pytest.approx(6.0, rel=0.1)
    assert samples.description["sample_kurtosis"] == pytest.approx(6.0, rel=0.1)
    with pytest.raises(ValueError, match="at least 64 values"):
        Marginal.from_samples(np.ones(100))


def test_kurtosis_the_translation_cannot_reach_is_refused():
    with pytest.raises(ValueError, match=r"`kurtosis` must be > 1.8 \(the uniform"):
        rv.Translated(BAND, 1.5)
    with pytest.raises(ValueError, match=r"no translation process has the band-limited spectrum"):
        rv.Translated(BAND, 10.0)  # its harmonics leave the band: 5.6 % off the target
    with pytest.raises(ValueError, match="finite variance"):
        rv.Translated(rv.White(1.0), 6.0)


# ----------------------------------------------------------------- ITAM
def test_itam_reaches_the_target_spectrum():
    x = rv.Translated(rv.BandPass(1.0, 8.0, 0.1), 6.0)
    assert x.translation_error < 0.01 < MAX_TRANSLATION_ERROR
    f = np.linspace(2.0, 20.0, 50)
    np.testing.assert_allclose(x.achieved_spectrum().psd(f), x.psd(f), rtol=0.03)
    gaussian = rv.Translated(rv.BandPass(1.0, 8.0, 0.1), 3.0)
    assert gaussian.translation_error < 1e-12
    fit = gaussian.fit
    np.testing.assert_allclose(fit.gaussian * fit.variance, fit.target, rtol=1e-9, atol=1e-15)


# ----------------------------------------------------------------- the synthesised input
def ratio_statistic(numerator, denominator, power: int = 2) -> Statistic:
    """mean(a) / mean(b)^power over independent paths, its standard error by the delta method."""
    a, b = np.asarray(numerator), np.asarray(denominator)
    n = a.size
    ma, mb = a.mean(), b.mean()
    gradient = np.array([1.0 / mb**power, -power * ma / mb ** (power + 1)])
    covariance = np.cov(np.vstack([a, b])) / n
    se = float(np.sqrt(gradient @ covariance @ gradient))
    return Statistic(ma / mb**power, 1.96 * se, se, n)


def case_synthesised_input(seed):
    """Variance, kurtosis and the 6-18 Hz band's power of 192 paths x 100 s."""
    x = rv.Translated(BAND, 6.0)
    dt = 5e-3  # the translation's grid ends at 79.4 Hz, below the Nyquist frequency 100 Hz
    a = x.sample(100.0, dt, n_paths=192, seed=seed)
    m2, m4 = np.mean(a**2, axis=1), np.mean(a**4, axis=1)
    yield "variance", estimate(m2), x.fit.variance, 0.0, 0.02
    yield "kurtosis", ratio_statistic(m4, m2), x.marginal.kurtosis, 0.0, 0.08
    f = np.fft.rfftfreq(a.shape[1], dt)
    band = (f >= 6.0) & (f <= 18.0)
    periodogram = 2.0 * np.abs(np.fft.rfft(a, axis=1)[:, band]) ** 2 / a.shape[1] ** 2
    grid = np.linspace(6.0, 18.0, 4001)
    achieved = np.trapezoid(x.achieved_spectrum().psd(grid), grid)
    yield "6-18 Hz power", estimate(periodogram.sum(axis=1)), achieved, 0.0, 0.03


def test_synthesised_translation_has_its_variance_kurtosis_and_spectrum():
    """Calibrated over 30 seeds (tests/calibration/non_gaussian_tests.txt): z means +0.26,
    +0.04, +0.53, SDs 0.96, 0.97, 1.01, max |z| 2.5 (variance, kurtosis, band power)."""
    for what, stat, ref, bias, detect in case_synthesised_input(7):
        assert_matches(stat, ref, detect=detect, known_bias=bias, what=what)


def case_translated_linear(seed):
    """E[v^2] of a linear device under a kurtosis-6 input against its spectral integral."""
    x = rv.Translated(BAND, 6.0)
    r = rv.simulate(DAMPED, x, t_end=21.0, burn_in=1.0, dt=1e-3, n_paths=128, seed=seed,
                    progress=False)  # fmt: skip
    block = mechanical_block(DAMPED.m, DAMPED.c, DAMPED.k)
    exact = output_variances(block, x.achieved_spectrum(0.5e3))["v"]
    yield "E[v^2]", r.velocity_variance, exact, 0.0, 0.06


def test_linear_device_second_moments_are_the_spectrum_s_whatever_the_marginal():
    """Calibrated over 30 seeds (tests/calibration/non_gaussian_tests.txt): z mean -0.11,
    SD 0.98, max |z| 2.4."""
    for what, stat, ref, bias, detect in case_translated_linear(3):
        assert_matches(stat, ref, detect=detect, known_bias=bias, what=what)


# ----------------------------------------------------------------- analytic methods
def test_analytic_methods_answer_with_the_spectrum_and_warn_naming_the_kurtosis():
    x = rv.Translated(rv.BandPass(1.0, 8.0, 0.1), 6.0)
    linear = rv.preset("figure9").updated(friction=None, k3=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a linear device: exact, no warning
        exact = rv.predict(linear, x)
    # the spectral integral of the spectrum cut at the translation's top (1019 Hz) against
    # Lyapunov's of the whole band-pass: the tail above holds 0.1 % of the input's power,
    # where the device's velocity responds as 1/f
    assert exact.power_electrical == pytest.approx(
        rv.predict(linear, x.spectrum).power_electrical, rel=1e-6
    )
    with pytest.warns(LinearisationValidityWarning, match="kurtosis 6"):
        nonlinear = rv.predict(rv.preset("figure9"), x)
    gaussian = rv.predict(rv.preset("figure9"), x.spectrum)
    assert nonlinear.power_electrical == pytest.approx(gaussian.power_electrical, rel=1e-6)
    refusal = rv.METHODS["fpk-fast"].refusal(linear, x)
    assert "assumes Gaussian input; the translated input needs method='linearisation'" in refusal


def test_assemblies_take_tones_shocks_and_translations_when_linear():
    """A linear assembly's second moments are its input's spectrum's (Campbell's for shocks)
    plus each tone's line through its frequency response: a one-DOF assembly must equal the
    single-mass answer. Tones, non-Gaussian input and shocks on nonlinear elements are
    refused by name, pointing to Monte Carlo, rather than answered as the continuous part."""
    x = rv.Translated(rv.BandPass(1.0, 8.0, 0.1), 6.0)
    shocks = rv.White(0.02) + rv.ShockTrain(20.0, 10.0, 0.01)
    tones = rv.White(0.02) + rv.Tone(8.0, 1.0) + rv.Tone(30.0, 2.0)
    one_dof = Assembly.from_harvester(DAMPED)
    for excitation in (x, shocks, tones, shocks + rv.Tone(8.0, 1.0)):
        single = rv.predict(DAMPED, excitation)
        result = rv.predict(one_dof, excitation)
        (transducer,) = result.transducers
        assert transducer.power_electrical == pytest.approx(single.power_electrical, rel=1e-6)
        assert result.velocity_variance[0] == pytest.approx(single.velocity_variance, rel=1e-6)
        assert result.power_input == pytest.approx(result.power_dissipated, rel=1e-6)
    nonlinear = Assembly.from_harvester(rv.preset("figure9"))
    with pytest.raises(ValueError, match=r"takes tones on a linear assembly only \(the tones 8 Hz"):
        rv.predict(nonlinear, rv.White(0.02) + rv.Tone(8.0, 1.0))
    for excitation in (x, shocks):
        with pytest.raises(ValueError, match="input on a linear assembly only.*simulate --device"):
            rv.predict(nonlinear, excitation)
