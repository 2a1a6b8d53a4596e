"""Tones on noise: the model, the exact linear answer, the combined linearisation, Monte Carlo.

* models: :class:`randvib.Tone` and the sum of inputs
  (:mod:`randvib.models.tone`, :mod:`randvib.models.combined`, ``+`` reaching
  the sum through :mod:`randvib.models.composition`), their parameters and refusals;
* analytic: superposition on a linear device (resistive and with a coil's
  inductance) against transfer functions written out by hand; the combined
  harmonic-and-random linearisation (:mod:`randvib.analytic.harmonic_linearisation`)
  against closed forms: Coulomb's describing function 4 Fc / (pi V), the
  cubic spring's k + 3/4 k3 Z^2, and Coulomb's random-part damping under a
  sinusoid 2 Fc e^{-x} I0(x) / (sigma sqrt(2 pi)), x = V^2 / (4 sigma^2);
  the fixed point shared with statistical linearisation (:mod:`randvib.analytic.fixed_point`);
* Monte Carlo (:mod:`randvib.montecarlo.forcing`): pathwise against a plain
  numpy Heun with the tone's step integral written as (A/w)(sin - sin) and a
  shock train's increments on the same Brownian increments; second order in
  dt against the exact response from rest; the linear device under noise and
  a tone against superposition; bit-identical for any threads and batches;
  the Nyquist refusal.

The Monte Carlo statistics (``case_*``) are calibrated over seeds by
``tests/calibration/non_gaussian_tests.py``.
"""

import numpy as np
import pytest
from _stats import assert_matches
from scipy import special

import randvib as rv
from randvib.analytic.harmonic_linearisation import gaussian_friction_moments
from randvib.models.combined import Combined, combine
from randvib.models.tone import parse_tone
from randvib.montecarlo.forcing import ForcingInput
from randvib.statistics import estimate

LINEAR = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4)


def h_velocity(m, c, k, f):
    """v / a of m z'' + c z' + k z = -m a at f (Hz), written out."""
    w = 2 * np.pi * f
    return -1j * w * m / (k - m * w**2 + 1j * c * w)


# ----------------------------------------------------------------- the model
def test_tones_compose_with_every_input_and_say_what_they_are():
    tone = rv.Tone(25.0, 0.5)
    pump = rv.BandPass(1.0, 8.0, 0.1) + tone + rv.Tone(50.0, 0.2, 90.0)
    assert isinstance(pump, Combined) and pump.name == "band-pass + 2 tones"
    assert pump.variance == pytest.approx(rv.BandPass(1.0, 8.0, 0.1).variance + 0.125 + 0.02)
    params = pump.parameters()
    assert params["excitation"] == "band-pass" and params["f0"] == 8.0  # the spectrum's own keys
    assert params["tones"][1] == {"frequency": 50.0, "amplitude": 0.2, "phase": 90.0}
    assert [t.frequency for t in sum([tone, rv.Tone(5.0, 1.0)]).lines()] == [25.0, 5.0]
    alone = rv.as_excitation(tone)
    assert alone.random is None and alone.level == 0.0 and alone.lines() == (tone,)
    # a sum's kurtosis: cumulants add; a tone alone has 1.5
    assert alone.kurtosis == pytest.approx(1.5)
    with pytest.raises(ValueError, match="one random part"):
        combine(rv.BandPass(1.0, 8.0, 0.1), rv.White(1.0))
    with pytest.raises(ValueError, match="`amplitude` must be > 0"):
        rv.Tone(25.0, -1.0)
    with pytest.raises(ValueError, match="`--tone` must be F:A"):
        parse_tone("25")
    with pytest.raises(ValueError, match=r"`--tone` '25:x': .*F:A\[:PHASE\]"):
        parse_tone("25:x")
    assert parse_tone("25:0.5:30").parameters() == {
        "frequency": 25.0,
        "amplitude": 0.5,
        "phase": 30.0,
    }


def test_methods_declare_tones_and_refuse_them_by_name():
    x = rv.White(0.1) + rv.Tone(8.0, 0.5)
    device = rv.preset("figure9")
    assert rv.METHODS["linearisation"].accepts(device, x)
    refusal = rv.METHODS["fpk-fast"].refusal(device, x)
    assert refusal.startswith("method='fpk-fast' treats random input only; the tones (8 Hz)")
    assert "method='linearisation'" in refusal


# ----------------------------------------------------------------- exact linear answer
def test_superposition_on_a_linear_device_is_exact():
    """White noise and two tones: S m / (4 c) + sum |H_v|^2 A^2 / 2, H_v written out."""
    tones = (rv.Tone(6.0, 0.7), rv.Tone(11.0, 0.3, 45.0))
    p = rv.predict(LINEAR, rv.White(0.2) + tones[0] + tones[1])
    m, c, k = LINEAR.m, LINEAR.c, LINEAR.k
    lines = sum(abs(h_velocity(m, c, k, t.frequency)) ** 2 * t.amplitude**2 / 2 for t in tones)
    assert p.velocity_variance == pytest.approx(0.2 * m / (4 * c) + lines, rel=1e-12)
    assert p.power_electrical == pytest.approx(LINEAR.c_e * p.velocity_variance, rel=1e-12)
    assert [t.velocity_amplitude for t in p.tones] == pytest.approx(
        [abs(h_velocity(m, c, k, t.frequency)) * t.amplitude for t in tones], rel=1e-12
    )


def test_superposition_with_a_coil_inductance_is_exact():
    """The coil's current through m z'' + c z' + k z + alpha i = -m a, L i' + R i = alpha z'."""
    coil = rv.Inductive(alpha=0.1992, r_load=2.0, r_coil=0.48, inductance=0.01)
    device = rv.Harvester.with_coupling(m=0.0226, c_m=0.1, k=57.4, coupling=coil)
    tone = rv.Tone(9.0, 0.8)
    p = rv.predict(device, rv.BandPass(0.5, 8.0, 0.2) + tone)
    noise = rv.predict(device, rv.BandPass(0.5, 8.0, 0.2))  # the Lyapunov route, alone
    w, m, r = 2 * np.pi * tone.frequency, device.m, coil.r_load + coil.r_coil
    admittance = 1j * w * coil.alpha / (r + 1j * w * coil.inductance)  # i / z
    z = -m * tone.amplitude / (device.k - m * w**2 + 1j * w * device.c_m + coil.alpha * admittance)
    current = abs(admittance * z)
    assert p.circuit_mean_square == pytest.approx(
        noise.circuit_mean_square + current**2 / 2, rel=1e-10
    )
    assert p.power_electrical == pytest.approx(r * p.circuit_mean_square, rel=1e-10)
    assert p.velocity_variance == pytest.approx(
        noise.velocity_variance + abs(w * z) ** 2 / 2, rel=1e-10
    )


# ----------------------------------------------------------------- combined linearisation
def test_coulomb_describing_function_under_a_pure_tone():
    """No noise: c_q = c + 4 Fc / (pi V) and V = w |H_z(c_q, k)| A (harmonic balance)."""
    fc = 0.0058
    device = LINEAR.updated(friction=rv.Coulomb(fc))
    r = rv.combined_linearisation(device, rv.Tone(8.0, 0.5))
    (tone,) = r.tones
    v = tone.velocity_amplitude
    # the phase average is a 64-point trapezoid rule of sgn(cos) cos: O(1/64^2)
    assert tone.c_eq == pytest.approx(device.c + 4 * fc / (np.pi * v), rel=1e-3)
    assert v == pytest.approx(abs(h_velocity(device.m, tone.c_eq, device.k, 8.0)) * 0.5, rel=1e-9)


def test_cubic_spring_describing_function_under_a_pure_tone():
    """No noise, no friction: k_q = k + 3/4 k3 Z^2 exactly (the cubic's first harmonic)."""
    device = LINEAR.updated(k3=5e6)
    r = rv.combined_linearisation(device, rv.Tone(7.0, 1.0))
    (tone,) = r.tones
    z = tone.displacement_amplitude
    assert tone.k_eq == pytest.approx(device.k + 0.75 * device.k3 * z**2, rel=1e-12)
    w = 2 * np.pi * 7.0
    assert z == pytest.approx(
        device.m * 1.0 / abs(tone.k_eq - device.m * w**2 + 1j * device.c * w), rel=1e-9
    )


def test_coulomb_random_damping_under_a_sinusoid_is_the_bessel_closed_form():
    """E[v_r F] / sigma^2 = 2 Fc E_theta[phi(V cos / sigma)] / sigma = 2 Fc e^{-x} I0(x) / (sigma sqrt(2 pi))."""
    fc = 0.0058
    device = LINEAR.updated(friction=rv.Coulomb(fc))
    r = rv.combined_linearisation(device, rv.White(0.3) + rv.Tone(8.0, 0.3))
    sigma, v = np.sqrt(r.random_velocity_variance), r.tones[0].velocity_amplitude
    x = v**2 / (4 * sigma**2)
    closed = 2 * fc * special.i0e(x) / (sigma * np.sqrt(2 * np.pi))
    assert r.random_c_eq - device.c == pytest.approx(closed, rel=1e-10)
    # and the white-noise random part answers S m / (4 c_r) on its own device
    assert r.random_velocity_variance == pytest.approx(
        0.3 * device.m / (4 * r.random_c_eq), rel=1e-12
    )


def test_friction_moments_of_a_generic_law_match_coulomb_and_quadrature():
    """The panel route (tanh) against Coulomb's closed forms (beta sigma = 1e5) and scipy's quad."""
    from scipy import integrate

    mu = np.array([-0.05, 0.0, 0.02, 0.1])
    coulomb = gaussian_friction_moments(rv.Coulomb(0.01), mu, 0.03)
    steep = gaussian_friction_moments(rv.Tanh(0.01, 3e6), mu, 0.03)
    np.testing.assert_allclose(steep, coulomb, rtol=1e-5, atol=1e-12)
    law = rv.Tanh(0.01, 50.0)
    mean_force, mean_x_force = gaussian_friction_moments(law, mu, 0.03)
    for i, m in enumerate(mu):

        def density(v, m=m):
            return np.exp(-0.5 * ((v - m) / 0.03) ** 2) / (0.03 * np.sqrt(2 * np.pi))

        f = integrate.quad(lambda v: law.force(v) * density(v), m - 0.4, m + 0.4, points=[0.0])[0]
        g = integrate.quad(lambda v, m=m: (v - m) / 0.03 * law.force(v) * density(v), m - 0.4, m + 0.4,
                           points=[0.0])[0]  # fmt: skip
        assert mean_force[i] == pytest.approx(f, rel=1e-9, abs=1e-15)
        assert mean_x_force[i] == pytest.approx(g, rel=1e-9, abs=1e-15)


# ----------------------------------------------------------------- Monte Carlo
def numpy_heun(device, dw, s_level, tones, kicks, dt, z0, v0):
    """Plain numpy stochastic Heun with the forcing's exact step integral in two half kicks.

    The tone's integral is written (A/w)(sin(w t_{n+1} + phi) - sin(w t_n + phi)),
    not as the kernel's cosine at the midpoint; tanh friction (smooth).
    """
    m, c, k, k3 = device.m, device.c, device.k, device.k3
    fc, beta = device.friction.fc, device.friction.beta
    amp = np.sqrt(s_level / 2)

    def acc(z, v):
        return -(c * v + k * z + k3 * z**3 + fc * np.tanh(beta * v)) / m

    z, v = np.full(dw.shape[0], z0), np.full(dw.shape[0], v0)
    out = [(z.copy(), v.copy())]
    for n in range(dw.shape[1]):
        u = kicks[:, n].copy()
        for t in tones:
            w, phi = t.omega, np.deg2rad(t.phase)
            u -= t.amplitude / w * (np.sin(w * (n + 1) * dt + phi) - np.sin(w * n * dt + phi))
        vs = v + 0.5 * u
        a1 = acc(z, vs)
        zp, vp = z + vs * dt, vs + a1 * dt + amp * dw[:, n]
        z, v = z + 0.5 * (vs + vp) * dt, vs + 0.5 * (a1 + acc(zp, vp)) * dt + amp * dw[:, n]
        v = v + 0.5 * u
        out.append((z.copy(), v.copy()))
    return np.array([o[0] for o in out]).T, np.array([o[1] for o in out]).T


def test_pathwise_equal_to_a_numpy_heun_on_the_same_input():
    """White noise, two tones (fixed phases) and shocks: every step to rounding."""
    device = LINEAR.updated(k3=5e5, friction=rv.Tanh(0.0058, 300.0))
    tones = (rv.Tone(8.0, 0.6, 30.0), rv.Tone(21.0, 0.4, -70.0))
    shocks = rv.ShockTrain(5.0, 8.0, 0.02)
    dt, n, paths = 5e-4, 2000, 4
    dw = np.random.default_rng(3).normal(0.0, np.sqrt(dt), (paths, n))
    x = rv.White(0.2) + tones[0] + tones[1] + shocks
    r = rv.simulate(device, x, t_end=n * dt, dt=dt, n_paths=paths, dW=dw, initial=(1e-3, 0.0),
                    record_paths=paths, progress=False, seed=5)  # fmt: skip
    kicks = ForcingInput(tones, shocks, n, dt, 5).kicks(0, paths)
    assert np.count_nonzero(kicks) > 0  # the shocks are there
    z, v = numpy_heun(device, dw, 0.2, tones, kicks, dt, 1e-3, 0.0)
    np.testing.assert_allclose(r.histories.z, z, rtol=0, atol=1e-12 * np.abs(z).max())
    np.testing.assert_allclose(r.histories.v, v, rtol=0, atol=1e-12 * np.abs(v).max())


def exact_tone_response(device, tone, t):
    """(z, v) at t of m z'' + c z' + k z = -m A cos(w t + phi) from rest (linear device)."""
    m, c, k = device.m, device.c, device.k
    w, phi = tone.omega, np.deg2rad(tone.phase)
    big_z = -m * tone.amplitude / (k - m * w**2 + 1j * c * w)  # steady state Re(Z e^{i(wt+phi)})
    lam = np.roots([m, c, k])  # homogeneous part a e^{l1 t} + b e^{l2 t} cancels the start
    zs0, vs0 = (big_z * np.exp(1j * phi)).real, (1j * w * big_z * np.exp(1j * phi)).real
    a, b = np.linalg.solve([[1, 1], lam], [-zs0, -vs0])
    z = (big_z * np.exp(1j * (w * t + phi))).real + (
        a * np.exp(lam[0] * t) + b * np.exp(lam[1] * t)
    ).real
    v = (1j * w * big_z * np.exp(1j * (w * t + phi))).real + (
        a * lam[0] * np.exp(lam[0] * t) + b * lam[1] * np.exp(lam[1] * t)
    ).real
    return z, v


def test_tone_forcing_is_second_order_in_dt():
    """A tone alone from rest: the error at t = 1 s falls about 4 times when dt halves."""
    tone = rv.Tone(12.0, 1.0, 20.0)
    errors = []
    for dt in (2e-3, 1e-3, 5e-4):
        r = rv.simulate(LINEAR, tone, t_end=1.0, dt=dt, n_paths=2, initial="rest",
                        record_paths=1, progress=False, check_step=False)  # fmt: skip
        z, v = exact_tone_response(LINEAR, tone, 1.0)
        errors.append(np.hypot(r.histories.z[0, -1] - z, (r.histories.v[0, -1] - v) / tone.omega))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3.4) & (ratios < 4.6)), ratios


def case_linear_noise_and_tone(seed, excitation=None):
    """E[v^2] of the linear device under noise and a random-phase tone, against superposition."""
    x = excitation or rv.White(0.01) + rv.Tone(11.0, 1.5)
    r = rv.simulate(LINEAR, x, t_end=22.0, burn_in=2.0, dt=2e-4, n_paths=64, seed=seed,
                    progress=False)  # fmt: skip
    # detect 5 %: the tone's cross term with the noise, 2 v_tone v_noise, carries the
    # spread (its time average's variance grows with the noise's PSD at the tone)
    yield "E[v^2]", r.velocity_variance, rv.predict(LINEAR, x).velocity_variance, 0.0, 0.05


@pytest.mark.parametrize(
    "name, excitation",
    [
        ("white", rv.White(0.01) + rv.Tone(11.0, 1.5)),
        ("band-pass", rv.BandPass(0.02, 8.0, 0.2) + rv.Tone(11.0, 1.5)),
    ],
)
def test_linear_device_under_noise_and_a_tone_matches_superposition(name, excitation):
    """Calibrated over 30 seeds (tests/calibration/non_gaussian_tests.txt): z mean -0.18 / -0.42,
    SD 1.06 / 0.99, max |z| 2.2 / 3.5 (white / band-pass floor), power margin >= 7.3 SE."""
    for what, stat, ref, bias, detect in case_linear_noise_and_tone(1, excitation):
        assert_matches(stat, ref, detect=detect, known_bias=bias, what=f"{name}: {what}")


def test_tones_are_bit_identical_for_any_threads_and_batches():
    x = rv.BandPass(0.5, 8.0, 0.2) + rv.Tone(8.0, 0.5) + rv.ShockTrain(3.0, 5.0, 0.01)
    device = rv.preset("figure9")
    kw = dict(t_end=0.6, dt=5e-4, n_paths=20, seed=9, progress=False)
    one = rv.simulate(device, x, threads=1, **kw).per_path
    split = rv.simulate(device, x, threads=2, batch_paths=8, **kw).per_path
    np.testing.assert_array_equal(one, split)
    later = rv.simulate(device, x, first_path=12, **{**kw, "n_paths": 8}).per_path
    np.testing.assert_array_equal(one[12:], later)  # a path's tone phase and shocks are its own


def test_a_tone_above_the_nyquist_frequency_is_refused():
    with pytest.raises(ValueError, match=r"tone at 3000 Hz .*Nyquist frequency 2500 Hz"):
        rv.simulate(LINEAR, rv.White(0.1) + rv.Tone(3000.0, 1.0), t_end=1.0, dt=2e-4, n_paths=2,
                    progress=False)  # fmt: skip


def test_random_phases_are_uniform_and_fixed_phases_kept():
    forcing = ForcingInput((rv.Tone(5.0, 1.0), rv.Tone(9.0, 1.0, 90.0)), None, 10, 1e-3, 4)
    phases = forcing.phases(0, 4000)
    assert np.all(phases[:, 1] == np.pi / 2)
    # uniform on [0, 2 pi): the mean of cos and sin is 0 within 4 standard errors of 1/sqrt(2 n)
    for moment in (np.cos(phases[:, 0]), np.sin(phases[:, 0])):
        stat = estimate(moment)
        assert abs(stat.mean) <= 4 * stat.std_error


def test_monte_carlo_lines_are_the_tones_mean_squares():
    """A tone alone (random phases), 40 periods a window: the projection gives |H|^2 A^2 / 2."""
    tone = rv.Tone(10.0, 1.0)
    r = rv.simulate(LINEAR, tone, t_end=6.0, burn_in=2.0, dt=5e-4, n_paths=4, record_paths=4,
                    record_every=2, progress=False)  # fmt: skip
    lines = r.response_spectra(segment_duration=1.0).lines
    h = h_velocity(LINEAR.m, LINEAR.c, LINEAR.k, 10.0)
    # the scheme's error at w dt = 0.03 is of order (w dt)^2 / 12 (second order)
    assert lines["velocity"][0] == pytest.approx(abs(h) ** 2 / 2, rel=1e-3)
    assert lines["displacement"][0] == pytest.approx(abs(h / tone.omega) ** 2 / 2, rel=1e-3)
    assert lines["power"][0] == pytest.approx(LINEAR.c_e * lines["velocity"][0], rel=1e-12)


def test_the_limit_the_optimal_load_and_the_design_take_tones():
    """A tone is a line in the harvesting limit (unconstrained: m^2 A^2 / (8 c_m) exactly);
    the optimal load under a tone is a maximum; the design search answers under a tone."""
    m, c_m, a = 0.0226, 0.05, 0.7
    limit = rv.harvesting_limit(m, c_m, rv.as_excitation(rv.Tone(9.0, a)), 1.0)
    assert limit == pytest.approx(m**2 * a**2 / (8 * c_m), rel=1e-12)
    # a linear device (superposition, no fixed point per point: a second for the searches)
    wired = rv.Harvester.from_electrical(m=m, c_m=c_m, k=57.4, alpha=0.1992, r_load=2.0,
                                         r_coil=0.48)  # fmt: skip
    x = rv.White(0.2) + rv.Tone(8.0, 0.5)
    best = rv.optimal_load_resistance(wired, x)
    assert best.location == "interior"
    for factor in (0.95, 1.05):
        other = rv.expected_power(wired.updated(r_load=best.r_load * factor), x, into="load")
        assert other < best.power
    linear = LINEAR.updated(stroke=0.004)
    result = rv.design(linear, rv.BandPass(0.3, 8.0, 0.2) + rv.Tone(8.0, 0.5),
                       {"k": (30.0, 150.0)}, monte_carlo=False)  # fmt: skip
    assert result.exceedance_predicted <= 0.01 + 1e-9 and np.isnan(result.first_passage_predicted)
