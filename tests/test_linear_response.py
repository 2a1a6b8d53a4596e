"""Linear response and statistical linearisation under any excitation.

References: the white-noise results of docs/conventions.md (E[v^2] = S m/(4c),
Eq. 30/32 through ``randvib.expected_power``) and two independent routes to
the linear device's variances (Lyapunov equation, spectral integral).

Covers :mod:`randvib.analytic.linear_response`,
:mod:`randvib.analytic.statistical_linearisation` and the linear blocks of
:mod:`randvib.models.state_space`.
"""

import numpy as np
import pytest

import randvib
from randvib.analytic.linear_response import (
    frequency_rule,
    mechanical_block,
    output_variances,
)
from randvib.analytic.statistical_linearisation import statistical_linearisation
from randvib.models.excitation import BandLimited, BandPass, KanaiTajimi, Tabulated, White

M, C, K = 0.0226, 0.2, 57.4  # the paper's device at 8 Hz, c_m = c_e = 0.1 Ns/m
RATIONAL = [
    White(0.7),
    BandPass(1.0, 8.0, 0.1),  # at the resonance
    BandPass(1.0, 8.0, 0.02),  # narrow, at the resonance
    BandPass(2.0, 3.0, 0.5),  # below
    BandPass(0.5, 20.0, 0.05),  # above
    KanaiTajimi(1.0, 8.0, 0.3),
    KanaiTajimi(0.3, 30.0, 0.05),
    KanaiTajimi(1.0, 1e4, 0.3),  # nearly white: a long tail for the quadrature
]


@pytest.mark.parametrize("excitation", RATIONAL, ids=repr)
def test_lyapunov_equals_spectral_integral_for_the_linear_device(excitation):
    # The quadrature's accuracy, measured on these cases: 1.5e-9 at worst (the
    # Kanai-Tajimi tail at f0 = 1e4 Hz), 5e-13 elsewhere; the test allows 1e-8.
    block = mechanical_block(M, C, K)
    lyapunov = output_variances(block, excitation, "lyapunov")
    spectral = output_variances(block, excitation, "spectral")
    for name in ("z", "v"):
        assert spectral[name] == pytest.approx(lyapunov[name], rel=1e-8)


@pytest.mark.parametrize("method", ["lyapunov", "spectral"])
def test_white_noise_variances_of_the_linear_oscillator(method):
    s = 0.7
    out = output_variances(mechanical_block(M, C, K), White(s), method)
    assert out["v"] == pytest.approx(s * M / (4 * C), rel=1e-12)
    assert out["z"] == pytest.approx(s * M**2 / (4 * C * K), rel=1e-12)


def test_band_pass_variance_by_hand():
    # A band-pass filter alone (a device that passes the acceleration through):
    # its variance is pi zeta f0 S, so the Lyapunov route reproduces the PSD integral.
    ex = BandPass(1.3, 8.0, 0.1)
    through = randvib.models.state_space.StateSpace(
        np.zeros((0, 0)), [], np.zeros((1, 0)), [1.0], ("a",)
    )
    from randvib.analytic.linear_response import stationary_covariance

    assert stationary_covariance(through, ex.shaping_filter())[0, 0] == pytest.approx(
        ex.variance, rel=1e-12
    )


def test_white_noise_limits_of_coloured_spectra():
    block = mechanical_block(M, C, K)
    white = output_variances(block, White(1.0))["v"]
    # Band-limited [0, f_hi]: the shortfall is the tail int_{f_hi}^inf S |H_v|^2 df,
    # which is S/(4 pi^2 f_hi) to leading order: relative c/(pi^2 m f_hi).
    for f_hi in (1e3, 1e4):
        v = output_variances(block, BandLimited(1.0, 0.0, f_hi))["v"]
        assert (white - v) / white == pytest.approx(C / (np.pi**2 * M * f_hi), rel=2e-3)
    # Kanai-Tajimi -> white as f0 grows, the excess falling like 1/f0
    excess = [
        output_variances(block, KanaiTajimi(1.0, f0, 0.3))["v"] / white - 1
        for f0 in (1e2, 1e3, 1e4)
    ]
    assert excess[2] < 3e-4 and excess[0] / excess[1] > 9 and excess[1] / excess[2] > 9


def test_tabulated_spectrum_by_quadrature_resolves_its_kinks():
    # A table that is a band-limited spectrum with steep ramps: the same response
    # up to the ramps' contribution, which is bounded by their area times max |H_v|^2.
    eps = 1e-6
    table = Tabulated([4.0 - eps, 4.0, 20.0, 20.0 + eps], [0.0, 1.0, 1.0, 0.0])
    block = mechanical_block(M, C, K)
    band = output_variances(block, BandLimited(1.0, 4.0, 20.0))["v"]
    assert output_variances(block, table)["v"] == pytest.approx(band, rel=1e-5)


# ------------------------------------------------------------------ linearisation
FIGURE9 = randvib.preset("figure9")


@pytest.mark.parametrize("fc", [0.0, 0.005, 0.03])
@pytest.mark.parametrize("k3", [0.0, 5e5])
@pytest.mark.parametrize("psd", [1.0, 0.1])
def test_white_noise_reduces_to_eq30_32(fc, k3, psd):
    harvester = FIGURE9.updated(fc=fc, k3=k3)
    result = statistical_linearisation(harvester, White(psd))
    paper = randvib.predict(harvester, psd)
    assert result.power_electrical == pytest.approx(
        randvib.expected_power(harvester, psd), rel=1e-10
    )
    assert result.c_eq == pytest.approx(paper.c_eq, rel=1e-10)
    assert result.displacement_variance == pytest.approx(paper.displacement_variance, rel=1e-10)


def test_white_noise_with_tanh_friction_and_a_circuit():
    harvester = randvib.Harvester.from_electrical(
        m=M, c_m=0.05, k=K, alpha=0.1992, r_load=1.0, r_coil=0.48, k3=1e5,
        friction=randvib.Tanh(fc=0.01, beta=200.0),
    )  # fmt: skip
    result = statistical_linearisation(harvester, 0.5)  # a number is white noise
    assert result.power_electrical == pytest.approx(
        randvib.expected_power(harvester, 0.5), rel=1e-10
    )
    assert result.power_load == pytest.approx(
        randvib.expected_power(harvester, 0.5, into="load"), rel=1e-10
    )


@pytest.mark.parametrize(
    "excitation",
    [BandPass(1.0, 10.0, 0.1), KanaiTajimi(1.0, 8.0, 0.3), BandLimited(1.0, 4.0, 20.0)],
    ids=repr,
)
def test_fixed_point_satisfies_its_conditions(excitation):
    harvester = FIGURE9.updated(fc=0.01, k3=5e5)
    r = statistical_linearisation(harvester, excitation)
    sigma_v = np.sqrt(r.velocity_variance)
    friction = harvester.friction.mean_velocity_force(sigma_v) / r.velocity_variance
    assert r.c_eq == pytest.approx(harvester.c + friction, rel=1e-10)
    assert r.k_eq == pytest.approx(
        harvester.k + 3 * harvester.k3 * r.displacement_variance, rel=1e-10
    )
    linear = output_variances(mechanical_block(harvester.m, r.c_eq, r.k_eq), excitation)
    assert r.velocity_variance == pytest.approx(linear["v"], rel=1e-10)
    assert r.displacement_variance == pytest.approx(linear["z"], rel=1e-10)
    assert r.power_electrical == pytest.approx(harvester.c_e * r.velocity_variance, rel=1e-14)


@pytest.mark.parametrize("excitation", RATIONAL[1:4], ids=repr)
def test_linear_device_is_its_own_linearisation(excitation):
    harvester = randvib.Harvester(m=M, c_m=0.1, c_e=0.1, k=K)
    r = statistical_linearisation(harvester, excitation, method="spectral")
    exact = output_variances(mechanical_block(M, C, K), excitation, "lyapunov")
    assert (r.c_eq, r.k_eq) == (C, K)
    assert r.velocity_variance == pytest.approx(exact["v"], rel=1e-8)


def test_the_spring_matters_only_under_coloured_noise():
    def power(k3, excitation):
        return statistical_linearisation(FIGURE9.updated(k3=k3), excitation).power_electrical

    assert power(5e5, White(1.0)) == pytest.approx(power(0.0, White(1.0)), rel=1e-12)
    narrow = BandPass(1.0, 8.0, 0.05)
    assert power(5e5, narrow) < 0.97 * power(0.0, narrow)  # detuned: about 5 % less


def test_response_spectra_integrate_to_the_variances_and_power():
    r = statistical_linearisation(FIGURE9.updated(fc=0.01), KanaiTajimi(1.0, 8.0, 0.3))
    nodes, weights = frequency_rule(r.block(), r.excitation)
    spectra = r.response_spectra(nodes)
    assert np.sum(spectra.velocity * weights) == pytest.approx(r.velocity_variance, rel=1e-8)
    assert np.sum(spectra.displacement * weights) == pytest.approx(
        r.displacement_variance, rel=1e-8
    )
    assert np.sum(spectra.power * weights) == pytest.approx(r.power_electrical, rel=1e-8)
    frame = r.response_spectra(np.linspace(0, 30, 7)).to_frame()
    assert list(frame.columns) == ["frequency", "excitation", "displacement", "velocity", "power"]
    assert r.to_dict()["excitation"]["excitation"] == "kanai-tajimi"


def test_refusals():
    with pytest.raises(ValueError, match="memoryless friction law; 'lugre'"):
        statistical_linearisation(randvib.preset("lugre-td1"), White(1.0))
    with pytest.raises(ValueError, match="`method`='lyapunov' needs a rational spectrum"):
        statistical_linearisation(FIGURE9, BandLimited(1.0, 4.0, 20.0), method="lyapunov")
    with pytest.raises(ValueError, match="`method` must be one of"):
        statistical_linearisation(FIGURE9, White(1.0), method="exact")
    with pytest.raises(ValueError, match="scalar harvester parameters"):
        statistical_linearisation(FIGURE9.updated(k3=np.array([0.0, 1e5])), White(1.0))
    with pytest.raises(ValueError, match="no stationary response"):
        output_variances(mechanical_block(M, -0.1, K), White(1.0))
