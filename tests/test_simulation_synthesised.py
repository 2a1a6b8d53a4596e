"""Monte Carlo under synthesised (band-limited, tabulated) and recorded base acceleration.

The input is a known signal, so the kernel takes its step integrals as
velocity increments (randvib.montecarlo.driven). Exact checks:

* the step integrals are those of the synthesised trigonometric sum (to
  rounding), and their variance and PSD are the spectrum's;
* the linear device (k3 = 0, no friction) under band-limited input against
  the spectral integral, the scheme's exact discrete bias (a sum over the
  synthesis bins) subtracted as ``known_bias``; the white-noise limit;
* the device on a measured record: a sine record against the exact harmonic
  response, a long Gaussian record against the spectral integral with the
  segments' interval.

Covers :mod:`randvib.montecarlo.driven` in :func:`randvib.simulate` and in
:mod:`randvib.montecarlo.on_record`.
"""

import numpy as np
import pytest
from _stats import assert_matches
from scipy import signal

import randvib as rv
from randvib.analytic.exact_solutions import linear_velocity_variance
from randvib.analytic.linear_response import mechanical_block, output_variances
from randvib.models.excitation import BandLimited, Measured, Tabulated, synthesis_power
from randvib.models.excitation import synthesised_increments as increments
from randvib.montecarlo import integrators
from randvib.montecarlo.driven import path_amplitudes
from randvib.montecarlo.simulation import simulate
from randvib.statistics import estimate

LINEAR = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4)
KW = dict(t_end=0.5, dt=1e-3, n_paths=16, burn_in=0.1, progress=False)


def discrete_variances(harvester, excitation, n, dt, scheme="heun"):
    """Exact stationary (E[z_n^2], E[v_n^2]) of the scheme on the linear device, synthesised input.

    Bin k (power P_k) enters as the increments Re[c e^{i w n dt} K_k],
    K_k = (e^{i w dt} - 1)/(i w); the recursion x' = A x + B u answers with
    (e^{i w dt} I - A)^{-1} B, so E[x_n^2] = sum_k P_k |K_k|^2 |T(e^{i w dt})|^2.
    """
    block = mechanical_block(harvester.m, harvester.c, harvester.k)
    a, b = integrators.integrator(scheme).linear_recursion(block.a, [[0.0], [1.0]], dt)
    f, power = synthesis_power(excitation, n, dt)
    w = 2 * np.pi * f
    with np.errstate(invalid="ignore", divide="ignore"):
        step = np.where(w > 0, np.expm1(1j * w * dt) / (1j * w), dt)
    if n % 2 == 0:
        step[-1] = 0.0
    z = np.exp(1j * w * dt)
    t = np.array([np.linalg.solve(zk * np.eye(2) - a, b[:, 0]) for zk in z])
    return tuple(np.sum(power * np.abs(step) ** 2 * np.abs(t[:, i]) ** 2) for i in (0, 1))


def test_increments_are_exact_step_integrals_of_the_synthesised_sum():
    """The step factor (e^{i w dt} - 1)/(i w) against the closed-form integral of each term."""
    ex = Tabulated([0.0, 3.0, 40.0, 60.0], [0.5, 2.0, 1.0, 0.0])
    n, dt = 256, 0.005
    normals = path_amplitudes(3, 0, 1, n)
    got = increments(ex, n, dt, normals)[0]
    f, power = synthesis_power(ex, n, dt)
    g = normals.reshape(2, f.size)
    amp_a, amp_b = np.sqrt(power) * g[0], np.sqrt(power) * g[1]
    amp_b[0] = 0.0
    w, t0 = 2 * np.pi * f[1:], np.arange(n)[:, None] * dt
    sin_part = (np.sin(w * (t0 + dt)) - np.sin(w * t0)) / w
    cos_part = -(np.cos(w * (t0 + dt)) - np.cos(w * t0)) / w
    exact = amp_a[0] * dt + sin_part @ amp_a[1:] + cos_part @ amp_b[1:]
    np.testing.assert_allclose(got, exact, rtol=0, atol=1e-12 * np.abs(exact).max())


def test_increments_have_the_spectrum_variance_and_psd():
    """Mean square and Welch PSD of the step-averaged input y_n = u_n / dt.

    E[y_n^2] = sum_k P_k sinc^2(f_k dt) (exact; between the continuous
    int S df and its sinc^2(f_hi dt) = 0.968 at 20 Hz); the in-band PSD
    is S sinc^2. 100 paths of 2000 bins in band: relative SE 0.25 %, powered for 2 %.
    """
    ex = BandLimited(0.5, 4.0, 20.0)
    n, dt = 20000, 0.005
    y = increments(ex, n, dt, path_amplitudes(1, 0, 100, n)) / dt
    f, power = synthesis_power(ex, n, dt)
    expected = np.sum(power * np.sinc(f * dt) ** 2)
    assert ex.variance * np.sinc(20.0 * dt) ** 2 < expected < ex.variance
    assert_matches(estimate(np.mean(y**2, axis=1)), expected, detect=0.02, what="variance")
    fw, p = signal.welch(y, fs=1 / dt, nperseg=2000)
    inside = (fw > 5) & (fw < 19)
    truth = 0.5 * np.mean(np.sinc(fw[inside] * dt) ** 2)
    assert_matches(estimate(p[:, inside].mean(axis=1)), truth, detect=0.02, what="in-band PSD")
    assert p[:, (fw < 3) | (fw > 21)].mean(axis=0).max() < 1e-3 * 0.5


def case_band_limited_linear(excitation, seed, n_paths=1600):
    """Linear device, Heun dt = 1e-3 s, 16 s windows: spectral integral + the scheme's exact bias."""
    dt, t_end, burn = 1e-3, 18.0, 2.0
    exact = output_variances(mechanical_block(LINEAR.m, LINEAR.c, LINEAR.k), excitation)
    disc_z, disc_v = discrete_variances(LINEAR, excitation, round(t_end / dt), dt)
    r = simulate(
        LINEAR, excitation, t_end=t_end, dt=dt, n_paths=n_paths, burn_in=burn, seed=seed,
        progress=False,
    )  # fmt: skip
    return r, [
        ("E[v^2]", r.velocity_variance, exact["v"], disc_v - exact["v"], 0.02),
        ("E[z^2]", r.displacement_variance, exact["z"], disc_z - exact["z"], 0.02),
    ]


def test_band_limited_linear_device_matches_the_spectral_integral():
    """MC within its interval of int |H|^2 S df; the known bias (scheme, bins) is below 0.1 %."""
    r, rows = case_band_limited_linear(BandLimited(1.0, 4.0, 20.0), seed=21)
    for what, stat, ref, bias, detect in rows:
        assert abs(bias) < 1e-3 * ref
        assert_matches(stat, ref, detect=detect, known_bias=bias, what=what)
    assert r.summary()["excitation"]["excitation"] == "band-limited"


def test_white_noise_limit_of_a_wide_flat_table():
    """A table flat at S up to 400 Hz: the linear device's E[v^2] is S m / (4 c) to 0.3 %."""
    wide = Tabulated([0.0, 400.0, 401.0], [1.0, 1.0, 0.0])
    white = linear_velocity_variance(LINEAR.m, LINEAR.c, 1.0)
    exact = output_variances(mechanical_block(LINEAR.m, LINEAR.c, LINEAR.k), wide)["v"]
    assert 0 < 1 - exact / white < 3e-3
    _, rows = case_band_limited_linear(wide, seed=22, n_paths=1600)
    what, stat, ref, bias, detect = rows[0]
    assert_matches(stat, white, detect=detect, known_bias=bias + ref - white, what="white limit")


def test_synthesised_results_do_not_depend_on_batching_or_threads():
    ex = BandLimited(1.0, 4.0, 20.0)
    dev = rv.preset("figure9")
    a = simulate(dev, ex, seed=4, **KW)
    b = simulate(dev, ex, seed=4, batch_paths=5, threads=1, **KW)
    np.testing.assert_array_equal(a.per_path, b.per_path)
    c = simulate(dev, ex, seed=4, first_path=8, **{**KW, "n_paths": 8})
    np.testing.assert_array_equal(a.per_path[8:], c.per_path)
    assert not np.array_equal(a.per_path, simulate(dev, ex, seed=5, **KW).per_path)


def test_synthesised_input_refusals_name_what_to_use():
    record = Measured(
        rv.Record(
            time=np.arange(4096) * 1e-3,
            base_acceleration=np.random.default_rng(0).standard_normal(4096),
        )
    )
    with pytest.raises(ValueError, match="monte_carlo_on_record"):
        simulate(LINEAR, record, **KW)
    with pytest.raises(ValueError, match="`dW` drives white noise"):
        simulate(LINEAR, BandLimited(1.0, 4.0, 20.0), dW=np.zeros((16, 500)), **KW)
    with pytest.raises(ValueError, match="`dt` = 0.05 s resolves"):
        simulate(LINEAR, BandLimited(1.0, 4.0, 20.0), **{**KW, "dt": 0.05, "check_step": False})


# ------------------------------------------------------------------ records
def test_device_on_a_sine_record_gives_the_harmonic_response():
    """a(t) = A sin(w t) at 6 Hz: each window's mean v^2, z^2 are the exact periodic response.

    The record's linear interpolation gives the increments -dt (a_n + a_{n+1}) / 2,
    i.e. -Re[-i A e^{i w t_n}] dt (1 + z) / 2 with z = e^{i w dt}; the Heun
    recursion answers with (z I - A)^{-1} B, so over whole periods
    E[v_n^2] = |A dt (1 + z) / 2 T_v(z)|^2 / 2 exactly (no time-step
    tolerance); the continuous |H_v|^2 A^2 / 2 is 0.25 % away at this step.
    """
    fs, f0, amp = 1200.0, 6.0, 2.0
    t = np.arange(int(60 * fs) + 1) / fs
    record = Measured(rv.Record(time=t, base_acceleration=amp * np.sin(2 * np.pi * f0 * t)))
    r = rv.monte_carlo_on_record(LINEAR, record, segments=6, burn_in=4.0, initial="rest")
    dt, w = 1 / fs, 2 * np.pi * f0
    block = mechanical_block(LINEAR.m, LINEAR.c, LINEAR.k)
    a, b = integrators.integrator("heun").linear_recursion(block.a, [[0.0], [1.0]], dt)
    z = np.exp(1j * w * dt)
    response = np.linalg.solve(z * np.eye(2) - a, b[:, 0]) * amp * dt * (1 + z) / 2
    # 56 whole periods per window; the start is forgotten (e^{-4 c / m} ~ 1e-15)
    np.testing.assert_allclose(r.averages.z2, np.abs(response[0]) ** 2 / 2, rtol=1e-9)
    np.testing.assert_allclose(r.averages.v2, np.abs(response[1]) ** 2 / 2, rtol=1e-9)
    h = block.frequency_response(f0)
    assert abs(r.averages.v2[0] / (amp**2 * np.abs(h[1]) ** 2 / 2) - 1) < 5e-3
    assert (
        r.n_paths == 6 and r.psd is None and r.summary()["excitation"]["excitation"] == "measured"
    )


def test_device_on_a_long_gaussian_record_matches_the_spectral_integral():
    """One 2000 s band-limited record, 20 segments: the spectral integral within the interval.

    The record is one periodic synthesis of exact variance; the segments'
    means are batch means of one response, and the test is powered for 10 %.
    """
    ex = BandLimited(1.0, 4.0, 20.0)
    dt = 2e-3
    x = ex.sample(2000.0, dt, 1, seed=9)[0]
    record = Measured(rv.Record(time=np.arange(x.size) * dt, base_acceleration=x))
    r = rv.monte_carlo_on_record(LINEAR, record, segments=20, burn_in=2.0, substeps=2)
    exact = output_variances(mechanical_block(LINEAR.m, LINEAR.c, LINEAR.k), ex)
    assert_matches(r.velocity_variance, exact["v"], detect=0.1, what="record E[v^2]")
    assert abs(r.lag1_correlation) < 0.6


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        (dict(segments=1), "`segments` must be"),
        (dict(segments=5000), "hold no window"),
        (dict(burn_in=-1.0), "`burn_in` must be"),
        (dict(substeps=0), "`substeps` must be"),
    ],
)
def test_record_simulation_bad_arguments(kwargs, fragment):
    record = Measured(
        rv.Record(
            time=np.arange(4096) * 1e-3,
            base_acceleration=np.random.default_rng(0).standard_normal(4096),
        )
    )
    with pytest.raises(ValueError, match=fragment):
        rv.monte_carlo_on_record(LINEAR, record, **kwargs)
