"""Transient response by the Lyapunov differential equation, against exact references.

References, each computed by a route independent of the moment equations:

* Caughey and Stumpf's closed form (1961) of the linear oscillator from rest
  under white noise switched on at t = 0, and its time integral (the energy);
* for an enveloped white noise, the covariance as the convolution integral
  P(t) = int_0^t e(s)^2 (S/2) exp(A (t - s)) b b^T exp(A^T (t - s)) ds
  (scipy ``quad_vec``);
* for an enveloped *filtered* noise, Priestley's evolutionary spectrum of a
  uniformly modulated process: E[z^2(t)] = int_0^inf |M(t, f)|^2 S(f) df with
  M(t, f) = int_0^t h(t - s) e(s) e^(i 2 pi f s) ds, in closed form for an
  exponential envelope (the filter running stationary for all time is
  exactly what this formula assumes);
* the stationary Lyapunov solution and statistical linearisation, which the
  transient must reach after the transient has died out.

The moments must agree to 1e-6 relative (the issue's bar; measured: about
1e-10 against the closed form).

Covers :mod:`randvib.analytic.transient` and the first-passage approximations of
:mod:`randvib.analytic.first_passage`.
"""

import numpy as np
import pytest
from scipy import integrate, linalg

import randvib as rv
from randvib.analytic import exact_solutions as exact
from randvib.analytic.first_passage import (
    outcrossing_rate,
    probability_from_hazard,
    spectral_bandwidth,
    vanmarcke_hazard,
)
from randvib.analytic.linear_response import frequency_rule, mechanical_block

M, C, K = 0.0226, 0.2, 57.4  # the paper's device at 8 Hz, c_m = c_e = 0.1 Ns/m
LINEAR = rv.Harvester(m=M, c_m=0.1, c_e=0.1, k=K)
TIMES = np.array([0.01, 0.05, 0.1, 0.3, 0.7, 1.5, 4.0])
SS = rv.ShinozukaSato.unit_peak(0.5, 2.0)


def test_caughey_stumpf_from_rest_to_1e6():
    event = rv.Enveloped(rv.White(0.7), rv.Step())
    r = rv.transient_response(LINEAR, event, TIMES, t_end=5.0)
    z2, zv, v2 = exact.caughey_stumpf_moments(M, C, K, 0.7, TIMES)
    np.testing.assert_allclose(r.displacement_variance, z2, rtol=1e-6)
    np.testing.assert_allclose(r.velocity_variance, v2, rtol=1e-6)
    np.testing.assert_allclose(r.displacement_velocity, zv, rtol=1e-6, atol=1e-6 * np.max(zv))
    np.testing.assert_allclose(r.power_electrical, 0.1 * v2, rtol=1e-6)
    energy = 0.1 * exact.caughey_stumpf_velocity_integral(M, C, K, 0.7, 5.0)
    assert r.energy_electrical == pytest.approx(energy, rel=1e-6)
    cumulative = 0.1 * exact.caughey_stumpf_velocity_integral(M, C, K, 0.7, TIMES)
    np.testing.assert_allclose(r.cumulative_energy, cumulative, rtol=1e-6)
    assert r.exact and r.method == "linearisation"


def test_caughey_stumpf_closed_form_against_its_own_derivative_and_integral():
    # E[z z'] is half the derivative of E[z^2]; the energy is the integral of E[v^2]
    t = np.linspace(0.02, 3.0, 7)
    h = 1e-6
    up, _, _ = exact.caughey_stumpf_moments(M, C, K, 1.0, t + h)
    down, _, _ = exact.caughey_stumpf_moments(M, C, K, 1.0, t - h)
    _, zv, _ = exact.caughey_stumpf_moments(M, C, K, 1.0, t)
    np.testing.assert_allclose((up - down) / (4 * h), zv, rtol=1e-6, atol=1e-12)
    for t_end in (0.05, 1.3, 10.0):
        by_quad = integrate.quad(
            lambda s: exact.caughey_stumpf_moments(M, C, K, 1.0, s)[2], 0, t_end, limit=500,
            epsabs=0, epsrel=1e-12,
        )[0]  # fmt: skip
        closed = exact.caughey_stumpf_velocity_integral(M, C, K, 1.0, t_end)
        assert closed == pytest.approx(by_quad, rel=1e-10)
    # and the stationary limits S m^2 / (4 c k), S m / (4 c)
    z2, _, v2 = exact.caughey_stumpf_moments(M, C, K, 1.0, 100.0)
    assert z2 == pytest.approx(M * M / (4 * C * K), rel=1e-12)
    assert v2 == pytest.approx(M / (4 * C), rel=1e-12)


def _impulse_response(tau):
    """(h, h') of m z'' + c z' + k z = -m a at lag tau: exp(A tau) b in closed form.

    The textbook unit-impulse response of the underdamped oscillator (zeta 0.09),
    h(tau) = -exp(-zeta w tau) sin(w_d tau) / w_d, cheaper than a matrix
    exponential at every quadrature node (the reference cost 8 s per envelope).
    """
    w = np.sqrt(K / M)
    zeta = C / (2.0 * np.sqrt(K * M))
    wd = w * np.sqrt(1.0 - zeta**2)
    decay = np.exp(-zeta * w * tau)
    z = -decay * np.sin(wd * tau) / wd
    v = -decay * (np.cos(wd * tau) - zeta * w / wd * np.sin(wd * tau))
    return np.array([z, v])


def test_impulse_response_is_the_matrix_exponential():
    a = np.array([[0.0, 1.0], [-K / M, -C / M]])
    for tau in (0.0, 0.013, 0.4, 2.7):
        expected = linalg.expm(a * tau) @ np.array([0.0, -1.0])
        np.testing.assert_allclose(_impulse_response(tau), expected, rtol=1e-12, atol=1e-15)


def _convolution_covariance(envelope, level, t):
    """P(t) of the linear oscillator under e(s) w(s) from rest, by quad_vec."""

    def integrand(s):
        phi = _impulse_response(t - s)
        return float(envelope(s)) ** 2 * 0.5 * level * np.outer(phi, phi)

    points = [p for p in envelope.breakpoints() if p < t]
    return integrate.quad_vec(integrand, 0.0, t, epsabs=0, epsrel=1e-11, points=points or None)[0]


@pytest.mark.parametrize(
    "envelope",
    [SS, rv.ShinozukaSato(3.0, 1.0, 6.0), rv.Boxcar(0.2, 0.5, 0.3), rv.TabulatedEnvelope(
        [0.0, 0.1, 0.4, 0.8, 1.2], [0.2, 1.0, 0.6, 0.9, 0.0])],
    ids=repr,
)  # fmt: skip
def test_enveloped_white_noise_against_the_convolution_integral(envelope):
    times = np.array([0.05, 0.35, 0.9, 1.6])
    r = rv.transient_response(LINEAR, rv.Enveloped(rv.White(1.3), envelope), times)
    for i, t in enumerate(times):
        p = _convolution_covariance(envelope, 1.3, t)
        assert r.displacement_variance[i] == pytest.approx(p[0, 0], rel=1e-6)
        assert r.velocity_variance[i] == pytest.approx(p[1, 1], rel=1e-6)
        assert r.displacement_velocity[i] == pytest.approx(p[0, 1], rel=1e-6, abs=1e-9 * p[1, 1])


def _evolutionary_moments(excitation, envelope, t):
    """(E[z^2], E[v^2]) at t under e(t) x(t), x stationary (Priestley), e Shinozuka-Sato.

    M(t, f) = sum_r a_r int_0^t exp(A (t - s)) B exp(lambda_r s) ds with
    lambda_r = i 2 pi f - rate_r, which is (lambda I - A)^-1 (exp(lambda t) - exp(A t)) B.
    """
    block = mechanical_block(M, C, K)
    a, b = block.a, block.b
    nodes, weights = frequency_rule(block, excitation)
    expm_at = linalg.expm(a * t) @ b
    total = np.zeros((nodes.size, 2), dtype=complex)
    for amplitude, rate in ((envelope.a, envelope.b), (-envelope.a, envelope.c)):
        lam = 2j * np.pi * nodes - rate
        resolvent = lam[:, None, None] * np.eye(2) - a
        rhs = np.exp(lam * t)[:, None] * b[None, :] - expm_at[None, :]
        total += amplitude * np.linalg.solve(resolvent, rhs[..., None])[..., 0]
    density = excitation.psd(nodes) * weights
    return tuple(float(np.sum(np.abs(total[:, i]) ** 2 * density)) for i in range(2))


@pytest.mark.parametrize(
    "excitation", [rv.BandPass(1.0, 8.0, 0.2), rv.BandPass(2.0, 5.0, 0.05),
                   rv.KanaiTajimi(0.5, 10.0, 0.4)], ids=repr,
)  # fmt: skip
def test_enveloped_filtered_noise_against_the_evolutionary_spectrum(excitation):
    times = np.array([0.1, 0.6, 1.5, 3.0])
    r = rv.transient_response(LINEAR, rv.Enveloped(excitation, SS), times)
    for i, t in enumerate(times):
        z2, v2 = _evolutionary_moments(excitation, SS, t)
        assert r.displacement_variance[i] == pytest.approx(z2, rel=1e-6)
        assert r.velocity_variance[i] == pytest.approx(v2, rel=1e-6)


@pytest.mark.parametrize(
    "device",
    [
        rv.preset("figure9"),
        rv.Harvester.with_coupling(0.0226, 0.1, 57.4, rv.Inductive(0.1992, 0.5, 0.48, 2e-3),
                                   k3=7e4, friction=rv.Tanh(0.0058, 1e3)),
        rv.Harvester.with_coupling(0.0226, 0.05, 57.4, rv.Piezo(2e-3, 1e-7, 1e5)),
    ],
    ids=["figure9", "coil-tanh", "piezo"],
)  # fmt: skip
@pytest.mark.parametrize("excitation", [rv.White(1.0), rv.BandPass(1.0, 8.0, 0.2)], ids=repr)
def test_a_step_event_reaches_the_stationary_linearisation(device, excitation):
    r = rv.transient_response(device, rv.Enveloped(excitation, rv.Step()), [12.0])
    stationary = rv.statistical_linearisation(device, excitation)
    assert r.displacement_variance[-1] == pytest.approx(stationary.displacement_variance, rel=1e-7)
    assert r.velocity_variance[-1] == pytest.approx(stationary.velocity_variance, rel=1e-7)
    assert r.power_electrical[-1] == pytest.approx(stationary.power_electrical, rel=1e-7)
    assert r.k_eq[-1] == pytest.approx(stationary.k_eq, rel=1e-7)
    assert r.c_eq[-1] == pytest.approx(stationary.c_eq, rel=1e-7)
    if device.has_circuit:
        assert r.circuit_mean_square[-1] == pytest.approx(stationary.circuit_variance, rel=1e-7)


def test_the_envelope_scales_a_linear_response_by_its_square_under_a_step():
    # a constant envelope A is white noise of level A^2 S (linear device)
    boxed = rv.transient_response(LINEAR, rv.Enveloped(rv.White(1.0), rv.Boxcar(0, 5.0, 0)), TIMES)
    scaled = rv.transient_response(LINEAR, rv.Enveloped(rv.White(1.0), rv.Step()), TIMES)
    np.testing.assert_allclose(boxed.velocity_variance, scaled.velocity_variance, rtol=1e-8)


def test_a_start_away_from_rest_adds_the_free_response_of_the_linear_device():
    z0, v0 = 2e-3, -0.05
    r = rv.transient_response(LINEAR, rv.Enveloped(rv.White(1.0), rv.Step()), TIMES,
                              start=(z0, v0))  # fmt: skip
    a = np.array([[0.0, 1.0], [-K / M, -C / M]])
    free = np.array([linalg.expm(a * t) @ [z0, v0] for t in TIMES])
    z2, _, v2 = exact.caughey_stumpf_moments(M, C, K, 1.0, TIMES)
    np.testing.assert_allclose(r.displacement_mean, free[:, 0], rtol=1e-7, atol=1e-12)
    np.testing.assert_allclose(r.displacement_variance, z2 + free[:, 0] ** 2, rtol=1e-6)
    np.testing.assert_allclose(r.velocity_variance, v2 + free[:, 1] ** 2, rtol=1e-6)


def test_friction_slows_the_start_and_the_closure_stays_below_the_linear_device():
    # time-dependent linearisation of the paper's device: friction and the
    # spring only take energy out, so its E[v^2] stays below the linear one's
    device = rv.preset("figure9")
    event = rv.Enveloped(rv.BandPass(2.0, 8.0, 0.2), SS)
    nonlinear = rv.transient_response(device, event, TIMES)
    linear = rv.transient_response(device.updated(fc=0.0, k3=0.0), event, TIMES)
    assert not nonlinear.exact
    assert np.all(nonlinear.velocity_variance < linear.velocity_variance)
    assert np.all(nonlinear.c_eq > device.c)
    assert nonlinear.energy_electrical < linear.energy_electrical


def test_refusals_name_the_argument_and_the_alternative():
    event = rv.Enveloped(rv.White(1.0), rv.Step())
    with pytest.raises(ValueError, match="`times` must be increasing"):
        rv.transient_response(LINEAR, event, [1.0, 0.5])
    with pytest.raises(ValueError, match=r"`times` must lie in \[0, t_end\]"):
        rv.transient_response(LINEAR, event, [0.5, 2.0], t_end=1.0)
    with pytest.raises(ValueError, match="rational spectrum"):
        rv.transient_response(LINEAR, rv.Enveloped(rv.BandLimited(1.0, 4, 20), SS), [1.0])
    with pytest.raises(ValueError, match="simulate_transient"):
        rv.transient_response(rv.preset("lugre-td1"), event, [1.0])
    with pytest.raises(ValueError, match="zero-mean Gaussian closure"):
        bistable = rv.Harvester(m=M, c_m=0.05, c_e=0.05, k=-K, k3=5e5)
        rv.transient_response(bistable, event, [1.0], start="unexcited")
    with pytest.raises(ValueError, match="method='fpk' is stationary"):
        rv.transient_response(LINEAR, event, [1.0], method="fpk")
    with pytest.raises(ValueError, match="transient_response"):
        rv.predict(LINEAR, event)
    with pytest.raises(ValueError, match="simulate_transient"):
        rv.simulate(LINEAR, event, t_end=1.0, dt=1e-3, n_paths=4)
    with pytest.raises(ValueError, match="`event` must be a randvib.Enveloped"):
        rv.transient_response(LINEAR, rv.White(1.0), [1.0])


# ------------------------------------------------------------ first passage
def test_rice_rate_of_a_stationary_process_is_the_classical_one():
    # stationary (E[z z'] = 0): nu_b = (sigma_v / (pi sigma_z)) exp(-b^2 / (2 sigma_z^2))
    sz2, sv2, b = 2.0e-5, 0.03, 0.006
    rate = outcrossing_rate(sz2, 0.0, sv2, b)
    assert rate == pytest.approx(np.sqrt(sv2 / sz2) / np.pi * np.exp(-(b * b) / (2 * sz2)))
    assert outcrossing_rate(0.0, 0.0, 0.0, b) == 0.0
    # a growing variance (E[z z'] > 0) crosses more often than a stationary one
    assert outcrossing_rate(sz2, 1e-4, sv2, b) > rate


def test_vanmarcke_lies_below_poisson_and_tends_to_it_for_a_broad_band():
    t = np.linspace(0, 10, 2001)
    rate = np.full(t.size, 0.3)
    z2 = np.full(t.size, 1e-5)
    poisson = probability_from_hazard(t, rate)
    assert poisson[-1] == pytest.approx(1 - np.exp(-3.0), rel=1e-12)
    narrow = probability_from_hazard(t, vanmarcke_hazard(rate, z2, 0.004, 0.1))
    broad = probability_from_hazard(t, vanmarcke_hazard(rate, z2, 0.004, 1.0))
    assert narrow[-1] < broad[-1] < poisson[-1] * 1.5


def test_bandwidth_of_the_oscillator_under_white_noise_is_vanmarckes_closed_form():
    zeta = C / (2 * np.sqrt(K * M))
    s = np.sqrt(1 - zeta**2)
    closed = np.sqrt(1 - (1 - 2 / np.pi * np.arctan(zeta / s)) ** 2 / s**2)
    assert spectral_bandwidth(mechanical_block(M, C, K), rv.White(1.0)) == pytest.approx(
        closed, rel=1e-6
    )
