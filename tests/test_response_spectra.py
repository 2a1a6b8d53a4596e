"""Response spectra from Monte Carlo (Welch on recorded paths) against exact ones.

The linear device under white noise at Heun dt = 1e-3 s is a linear Gaussian
recursion x_{n+1} = A x_n + B dW_n with the exact stationary covariance P
(discrete Lyapunov) and autocovariance R(tau) = A^tau P. The expected Welch
estimate is then exact: (2 D / sum w^2) sum_tau c_w(tau) R(tau) cos(2 pi f tau D),
c_w the Hann window's autocorrelation and D the recorded step, so the
comparison has neither time-step nor leakage tolerance; the Monte Carlo
interval is over independent paths.

Covers :mod:`randvib.montecarlo.spectra`.
"""

import numpy as np
import pytest
from _stats import assert_matches
from scipy import linalg, signal

import randvib as rv
from randvib.analytic.linear_response import mechanical_block
from randvib.montecarlo import integrators
from randvib.montecarlo.simulation import simulate
from randvib.statistics import Statistic

LINEAR = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4)


def expected_welch(harvester, psd, dt, every, length, frequency):
    """Exact mean of the Hann-window Welch PSD of (z, v) sampled every ``every`` steps."""
    block = mechanical_block(harvester.m, harvester.c, harvester.k)
    g = np.sqrt(psd / 2) * np.array([[0.0], [1.0]])
    a, b = integrators.integrator("heun").linear_recursion(block.a, g, dt)
    cov = linalg.solve_discrete_lyapunov(a, dt * (b @ b.T))
    step = np.linalg.matrix_power(a, every)
    lags = np.empty((length, 2))
    r = cov
    for tau in range(length):
        lags[tau] = np.diag(r)
        r = step @ r
    w = signal.get_window("hann", length)
    cw = np.correlate(w, w, "full")[length - 1 :]
    d = every * dt
    weights = cw[:, None] * lags
    weights[1:] *= 2.0
    phase = np.cos(2 * np.pi * np.outer(frequency, np.arange(length)) * d)
    return 2 * d / np.sum(w**2) * phase @ weights  # (n_f, 2): z, v


@pytest.fixture(scope="module")
def linear_run():
    return simulate(
        LINEAR, 1.0, t_end=21.0, dt=1e-3, n_paths=160, burn_in=1.0, seed=31,
        record_paths=160, record_every=2, progress=False,
    )  # fmt: skip


def test_linear_device_spectra_match_the_exact_expected_welch_estimate(linear_run):
    """S_z, S_v, c_e S_v at 2-30 Hz within their intervals; powered for 10 % at each."""
    spectra = linear_run.response_spectra(segment_duration=1.0)
    assert spectra.n_paths == 160 and spectra.segment_duration == pytest.approx(1.0)
    pick = np.searchsorted(spectra.frequency, [2.0, 6.0, 8.0, 10.0, 30.0])
    f = spectra.frequency[pick]
    exact = expected_welch(LINEAR, 1.0, 1e-3, 2, 500, f)
    t = 1.9757  # Student t, 159 dof, 97.5 %: back from the half-width to the standard error
    for i, fi in enumerate(f):
        for j, name in enumerate(("displacement", "velocity")):
            half = getattr(spectra, f"{name}_ci95")[pick[i]]
            stat = Statistic(getattr(spectra, name)[pick[i]], half, half / t, spectra.n_paths)
            assert_matches(stat, exact[i, j], detect=0.1, what=f"S_{name[0]}({fi:g} Hz)")
    np.testing.assert_allclose(spectra.power, LINEAR.c_e * spectra.velocity)
    # the power density integrates to the simulated E[P_e] (Welch's Parseval, Hann)
    total = np.sum(spectra.power) * (spectra.frequency[1] - spectra.frequency[0])
    assert total == pytest.approx(linear_run.power_electrical.mean, rel=0.02)


def test_linearisation_and_plot_share_the_frequency_axis(linear_run, tmp_path):
    spectra = linear_run.response_spectra(segment_duration=1.0)
    lin = rv.statistical_linearisation(LINEAR, rv.White(1.0)).response_spectra(spectra.frequency)
    out = rv.plot_response_spectra(
        {"Monte Carlo": spectra, "linearisation": lin},
        excitation=rv.White(1.0),
        path=tmp_path / "spectra.png",
    )
    assert out.stat().st_size > 10_000
    frame = spectra.to_frame()
    assert list(frame.columns)[:4] == ["frequency", "displacement", "velocity", "power"]


def test_spectra_need_recorded_paths_and_a_fitting_segment(linear_run):
    bare = simulate(LINEAR, 1.0, t_end=0.5, dt=1e-3, n_paths=8, progress=False)
    with pytest.raises(ValueError, match="record_paths >= 2"):
        bare.response_spectra()
    with pytest.raises(ValueError, match="`segment_duration` must hold"):
        linear_run.response_spectra(segment_duration=100.0)
