"""Assemblies beyond stationary Gaussian input: tones, translated (non-Gaussian) input, shocks.

Covers the forcing of :mod:`randvib.montecarlo.assembly_kernel` (tones and
shock trains as the single mass's :class:`randvib.montecarlo.kernel.Forcing`,
through the influence vector r), the inputs :mod:`randvib.montecarlo.assembly_simulation`
now takes (:class:`~randvib.models.tone.Tone`, :class:`~randvib.models.shock.ShockTrain`,
:class:`~randvib.models.translation.Translated`), the forced start of
:mod:`randvib.montecarlo.assembly_setup` and
:meth:`~randvib.montecarlo.assembly_step_check.AssemblyTestSystem.forced_covariance`.

* **Pathwise**: a one-DOF assembly under tones on noise, shocks on noise and
  a translated input equals the single-mass ``rv.simulate`` path by path;
  the independent numpy simulator of tests/test_assembly_simulation.py, given
  the tones' step integrals computed here from their phases
  (``-int a dt = -sum A/w [sin(w t_{n+1} + phi) - sin(w t_n + phi)]``), agrees
  with every state of the three-DOF SPEC (full mass matrix, r = (1, 1, 0.8)).
* **Exact linear**: the two-DOF CHAIN under two tones alone (``psd`` 0) and
  under a tone on white noise: per-DOF variances and the transducer's power
  against superposition (each tone through the assembly's frequency response,
  mean square ``|h|^2 A^2 / 2``, plus the random part's Lyapunov solution),
  the scheme's exact discrete response (the kernel's step as a linear
  recursion driven by the tone's step integrals) as the known time-step bias.
* **Translated** input (kurtosis 6): a linear assembly's second moments are the
  spectral integral of the simulated process's spectrum, whatever the marginal.
* **Shocks** (Campbell): the linear CHAIN's variances under a shock train on
  white noise against the spectral integral of their sum.
* The CLI ``simulate --device`` with ``--tone`` and ``--kurtosis``; refusals.
"""

import json

import numpy as np
import pytest
from _cli import run as run_cli
from _stats import assert_matches
from test_assembly_simulation import (
    CHAIN,
    HARVESTERS,
    SPEC,
    _quantities,
    assembly_of,
    covariances,
    linear_system,
    numpy_paths,
)
from test_translation import ratio_statistic

import randvib as rv
from randvib.analytic.assembly_linear import linear_response
from randvib.datasets import device_path
from randvib.montecarlo.driven import TranslatedInput
from randvib.montecarlo.forcing import ForcingInput

pytestmark = pytest.mark.filterwarnings("ignore::randvib.montecarlo.step_check.StepSizeWarning")


def tone_step_integrals(tones, phases, steps, dt):
    """u_n = -int_{n dt}^{(n+1) dt} sum_q A_q cos(w_q t + phi_q) dt, shape (paths, steps)."""
    t = np.arange(steps + 1) * dt
    u = np.zeros((phases.shape[0], steps))
    for q, tone in enumerate(tones):
        w = tone.omega
        s = np.sin(w * t[None, :] + phases[:, q : q + 1])
        u -= tone.amplitude / w * np.diff(s, axis=1)
    return u


# ------------------------------------------------------------------- pathwise
@pytest.mark.parametrize("scheme", ["euler-maruyama", "heun"])
@pytest.mark.parametrize(
    "name, extra",
    [
        ("duffing-coulomb", rv.Tone(8.0, 2.0) + rv.Tone(21.0, 1.0, 30.0)),
        ("coil-bridge", rv.Tone(9.0, 60.0)),
        ("piezo", rv.ShockTrain(40.0, 20.0, 0.004)),
    ],
    ids=["tones-coulomb", "tone-bridge", "shocks-piezo"],
)
def test_one_dof_assembly_under_forcing_equals_the_single_mass(name, extra, scheme):
    """Tones (random and given phase) and shocks on white noise: z, v at every step, to rounding.

    The forcing's streams are the single mass's (keyed by seed and path), so the
    same seed gives the same phases, the same shock trains and the same noise.
    """
    h = HARVESTERS[name]
    common = dict(t_end=0.04, dt=1e-4, n_paths=3, seed=5, progress=False, record_paths=3,
                  check_step=False, scheme=scheme, initial="rest")  # fmt: skip
    single = rv.simulate(h, 1.0 + extra, **common)
    assembly = rv.simulate(rv.Assembly.from_harvester(h), 1.0 + extra, **common)
    assert np.max(np.abs(single.histories.v)) > 0.0
    np.testing.assert_allclose(
        assembly.histories.x[:, :, 0], single.histories.z, rtol=1e-10, atol=1e-16
    )
    np.testing.assert_allclose(
        assembly.histories.v[:, :, 0], single.histories.v, rtol=1e-10, atol=1e-14
    )
    np.testing.assert_allclose(
        assembly.per_path[:, assembly.columns.vv], single.averages.v2, rtol=1e-9
    )


def test_one_dof_assembly_under_translated_input_equals_the_single_mass():
    """A kurtosis-6 translation process: the same synthesised input, the same paths."""
    h = HARVESTERS["duffing-coulomb"]
    x = rv.Translated(rv.BandLimited(1.0, 4.0, 40.0), 6.0)
    common = dict(t_end=0.05, dt=1e-4, n_paths=3, seed=2, progress=False, record_paths=3,
                  check_step=False, initial="rest")  # fmt: skip
    single = rv.simulate(h, x, **common)
    assembly = rv.simulate(rv.Assembly.from_harvester(h), x, **common)
    assert np.max(np.abs(single.histories.v)) > 0.0
    np.testing.assert_allclose(
        assembly.histories.v[:, :, 0], single.histories.v, rtol=1e-10, atol=1e-14
    )


@pytest.mark.parametrize("scheme", ["euler-maruyama", "heun"])
def test_every_state_under_tones_equals_the_numpy_simulator(scheme):
    """SPEC (three DOFs, r = (1, 1, 0.8)) under two tones on white noise, the same increments.

    The numpy simulator gets the tones' exact step integrals computed here from
    the run's phases (:meth:`ForcingInput.phases`, the single mass's streams),
    not the package's formula; x, v, friction and circuit states agree at every step.
    """
    psd, dt, steps, paths, seed = 2.0, 1e-4, 300, 3, 4
    tones = (rv.Tone(30.0, 4.0), rv.Tone(75.0, 6.0, 45.0))
    dw = np.random.default_rng(8).normal(0.0, np.sqrt(dt), (paths, steps))
    x0, v0 = np.array([1e-4, 2e-3, -1e-3]), np.array([0.01, -0.05, 0.08])
    phases = ForcingInput(tones, None, steps, dt, seed).phases(0, paths)
    u = tone_step_integrals(tones, phases, steps, dt)
    states, _ = numpy_paths(SPEC, dw, dt, psd, x0, v0, scheme, forcing=u)
    unforced, _ = numpy_paths(SPEC, dw, dt, psd, x0, v0, scheme)
    result = rv.simulate(
        assembly_of(SPEC), psd + tones[0] + tones[1], t_end=steps * dt, dt=dt, n_paths=paths,
        dW=dw, initial=(x0, v0), scheme=scheme, seed=seed, record_paths=paths, progress=False,
        check_step=False,
    )  # fmt: skip
    record = result.histories
    n = 3
    # the tones move the states by far more than the tolerance
    assert np.max(np.abs(states[-1][1] - unforced[-1][1])) > 1e-3
    for step, (x, v, theta, s) in enumerate(states):
        got = record.state[:, step]
        np.testing.assert_allclose(got[:, :n], x, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(got[:, n + 1 : 2 * n + 1], v, rtol=1e-9, atol=1e-13)
        np.testing.assert_allclose(got[:, 2 * n + 2 : 2 * n + 5], theta, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(got[:, 2 * n + 5 : 2 * n + 7], s[:, :2], rtol=1e-9, atol=1e-12)


# ---------------------------------------------------------- exact linear cases
def tone_covariances(a, g, tone, dt, scheme):
    """(continuous, discrete) time-averaged state covariance under one random-phase tone.

    Continuous: ``X = Re(h A e^{i w t})``, ``h = (i w - A)^-1 (-g)`` (the base
    acceleration reaches the velocities as -r a), covariance ``A^2/2 Re(h h^H)``.
    Discrete: the kernel's step y_s = y_n + g k_n, y_{n+1} = S y_s + g k_n with
    k_n = u_n / 2 = -(A sin(w dt / 2) / w) cos(w (n + 1/2) dt + phi) and S the
    scheme's deterministic step; y_n = Re(Y e^{i w n dt}) with
    ``(z - S) Y = (S + 1) g k`` (z = e^{i w dt}), covariance ``Re(Y Y^H) / 2``.
    """
    eye = np.eye(a.shape[0])
    w = tone.omega
    h = np.linalg.solve(1j * w * eye - a, -g) * tone.amplitude
    continuous = 0.5 * np.real(np.outer(h, h.conj()))
    step = eye + a * dt if scheme == "euler-maruyama" else eye + a * dt + a @ a * dt**2 / 2
    k = -tone.amplitude * np.sin(0.5 * w * dt) / w * np.exp(0.5j * w * dt)
    y = np.linalg.solve(np.exp(1j * w * dt) * eye - step, (step + eye) @ g * k)
    return continuous, 0.5 * np.real(np.outer(y, y.conj()))


#: Two tones near CHAIN's modes (9.4 and 17.0 Hz), for tones alone.
TWO_TONES = (rv.Tone(9.0, 3.0), rv.Tone(17.0, 2.0))


def case_tones(seed, scheme="heun", level=0.0, tones=TWO_TONES):
    """CHAIN under tones (on white noise of ``level``): rows of per-DOF variances and power.

    Each row ``(what, stat, exact, known bias, detect)``: the exact value by
    superposition (:func:`tone_covariances` per tone, the random part's
    Lyapunov solution), the scheme's exact discrete response minus it as the
    known bias. dt = 5e-4 s. Tones alone: 64 paths x 2.57 s after 3 s burn-in;
    a path's average varies only with its phases, over a window of no whole
    number of periods (about 0.1 % here; a whole number would leave the start's
    transient as the only spread), so 2 % is seen. The start's transient decays
    as exp(-3.85 t) (the slowest mode): after 3 s its bias is below 1e-6
    relative (measured 2e-4 after 1.5 s, 2e-8 after 4 s). With noise: 128 paths
    x 5 s after 1 s, 12 % seen (the inner mass's standard error about 2 %).
    """
    dt = 5e-4
    a, g = linear_system(CHAIN)
    continuous, discrete = np.zeros_like(a), np.zeros_like(a)
    if level:
        continuous, discrete = (level / 2.0 * c for c in covariances(a, g, dt, scheme))
    for tone in tones:
        c, d = tone_covariances(a, g, tone, dt, scheme)
        continuous, discrete = continuous + c, discrete + d
    exact, stepped = _quantities(CHAIN, continuous), _quantities(CHAIN, discrete)
    excitation = sum(tones[1:], tones[0] + level) if level else sum(tones[1:], tones[0])
    burn_in, window, paths = (1.0, 5.0, 128) if level else (3.0, 2.57, 64)
    result = rv.simulate(
        assembly_of(CHAIN), excitation, t_end=burn_in + window, dt=dt, n_paths=paths,
        burn_in=burn_in, scheme=scheme, seed=seed, progress=False, check_step=False,
    )  # fmt: skip
    assert result.power_input is None  # r^T M r S / 4 is white noise's alone
    detect = 0.12 if level else 0.02
    for i in range(2):
        for kind, stats in (("x", result.displacement_variance), ("v", result.velocity_variance)):
            key = f"{kind}{i}"
            yield f"E[{key}^2]", stats[i], exact[key], stepped[key] - exact[key], detect
    key = "power0"
    power = result.transducers[0].power_electrical
    yield key, power, exact[key], stepped[key] - exact[key], detect


@pytest.mark.parametrize(
    "scheme, level, tones",
    [
        ("heun", 0.0, TWO_TONES),
        ("euler-maruyama", 0.0, TWO_TONES),
        ("heun", 0.2, (rv.Tone(14.0, 3.0),)),
    ],
    ids=["tones-alone-heun", "tones-alone-euler", "tone-on-white-heun"],
)
def test_linear_assembly_under_tones_matches_superposition(scheme, level, tones):
    """CHAIN: each tone through the frequency response plus the random part's Lyapunov solution.

    Per DOF E[x^2], E[v^2] and the transducer's power (:func:`case_tones`), each
    within 4 standard errors of the exact value plus the scheme's exact
    discrete bias and powered to see 2 % (tones alone) or 12 % (on noise).
    Calibrated over seeds by tests/calibration/assembly_excitation.py (results
    in its .txt).
    """
    for what, stat, ref, bias, detect in case_tones(11, scheme, level, tones):
        assert_matches(stat, ref, detect=detect, known_bias=bias, what=what)


# ------------------------------------------------------------ translated input
def case_translated(seed):
    """Kurtosis 6 on a band-limited spectrum: CHAIN's second moments and the input's kurtosis.

    The reference is the linear response to the simulated process's achieved
    spectrum (cut at the step's Nyquist frequency), exact for any marginal;
    96 paths x 8 s after 1 s burn-in, powered to see 15 % (the lightly damped
    inner mass's long memory: its standard errors are about 2.2 %). The input
    the kernel took (the run's own increments,
    :class:`~randvib.montecarlo.driven.TranslatedInput`) against the marginal's
    kurtosis, its standard error by the delta method over paths (heavy-tailed:
    1.7 % to 4.4 % over seeds), 30 % seen: the Gaussian's 3 is far outside.
    """
    x = rv.Translated(rv.BandLimited(0.2, 4.0, 30.0), 6.0)
    dt = 1e-3
    result = rv.simulate(
        assembly_of(CHAIN), x, t_end=9.0, burn_in=1.0, dt=dt, n_paths=96, seed=seed,
        progress=False,
    )  # fmt: skip
    response = linear_response(assembly_of(CHAIN), x.achieved_spectrum(0.5 / dt))
    for i in range(2):
        yield f"E[v{i}^2]", result.velocity_variance[i], response.velocity_variance[i], 0.0, 0.15
        yield (f"E[x{i}^2]", result.displacement_variance[i], response.displacement_variance[i],
               0.0, 0.15)  # fmt: skip
    (transducer,) = result.transducers
    yield "power", transducer.power_electrical, response.transducer_power(0)[0], 0.0, 0.15
    a = -TranslatedInput(x, 9000, dt, seed)(0, 96) / dt  # the run's base acceleration
    m2, m4 = np.mean(a**2, axis=1), np.mean(a**4, axis=1)
    yield "kurtosis", ratio_statistic(m4, m2), x.marginal.kurtosis, 0.0, 0.3


def test_linear_assembly_under_translated_input_has_the_spectrum_s_moments():
    """A linear assembly's second moments are its input's spectrum's, whatever the marginal
    (:func:`case_translated`); calibrated by tests/calibration/assembly_excitation.py."""
    for what, stat, ref, bias, detect in case_translated(3):
        assert_matches(stat, ref, detect=detect, known_bias=bias, what=what)


# ---------------------------------------------------------------------- shocks
def case_shocks(seed):
    """A shock train on white noise: CHAIN's variances against the spectral integral of the sum.

    Campbell's spectrum ``2 lambda E[A^2] |P(f)|^2`` plus the white level, through
    the assembly (:func:`linear_response`, exact); 96 paths x 6 s after 1 s,
    dt = 2e-4 s (the pulses of 4 ms resolved; the fastest mode's w dt = 0.02),
    powered to see 17 % (standard errors 1.4 to 2.6 % over seeds).
    """
    excitation = rv.White(0.02) + rv.ShockTrain(20.0, 10.0, 0.004)
    result = rv.simulate(
        assembly_of(CHAIN), excitation, t_end=7.0, burn_in=1.0, dt=2e-4, n_paths=96, seed=seed,
        progress=False,
    )  # fmt: skip
    response = linear_response(assembly_of(CHAIN), excitation)
    for i in range(2):
        yield f"E[v{i}^2]", result.velocity_variance[i], response.velocity_variance[i], 0.0, 0.17
        yield (f"E[x{i}^2]", result.displacement_variance[i], response.displacement_variance[i],
               0.0, 0.17)  # fmt: skip


def test_linear_assembly_under_shocks_matches_campbell():
    """:func:`case_shocks`, calibrated by tests/calibration/assembly_excitation.py."""
    for what, stat, ref, bias, detect in case_shocks(6):
        assert_matches(stat, ref, detect=detect, known_bias=bias, what=what)


# ------------------------------------------------------------------------ CLI
@pytest.mark.parametrize(
    "extra, excitation",
    [
        (["--psd", "0.1", "--tone", "8:0.5"], 0.1 + rv.Tone(8.0, 0.5)),
        (["--psd", "0", "--tone", "8:0.5:90"], rv.Tone(8.0, 0.5, 90.0)),
        (
            ["--excitation", "band-limited", "--psd", "0.1", "--f-lo", "4", "--f-hi", "20",
             "--kurtosis", "5"],
            rv.Translated(rv.BandLimited(0.1, 4.0, 20.0), 5.0),
        ),
        (
            ["--psd", "0.1", "--shock-rate", "5", "--shock-amplitude", "3", "--shock-duration",
             "0.01"],
            0.1 + rv.ShockTrain(5.0, 3.0, 0.01),
        ),
    ],
    ids=["tone-on-white", "tone-alone", "kurtosis", "shocks"],
)  # fmt: skip
def test_cli_simulate_device_takes_tones_and_kurtosis(capsys, extra, excitation):
    """``simulate --device FILE`` with ``--tone F:A``, ``--kurtosis K``, ``--shock-*``: the
    JSON equals rv.simulate's."""
    path = device_path("two_harvesters_on_host")
    argv = ["simulate", "--device", "two_harvesters_on_host", *extra, "--t-end", "0.3",
            "--burn-in", "0.1", "--paths", "8", "--seed", "3", "--json"]  # fmt: skip
    code, out, err = run_cli(capsys, *argv)
    assert code == 0, err
    data = json.loads(out)
    expected = rv.simulate(
        rv.Assembly.from_toml(path), excitation, t_end=0.3, dt=1e-4, n_paths=8, burn_in=0.1,
        seed=3, progress=False,
    )  # fmt: skip
    for got, want in zip(data["transducers"], expected.transducers, strict=True):
        assert got["power_electrical"]["mean"] == want.power_electrical.mean
    assert data["power_input"] is None


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        ({"control_variates": True, "psd": 0.2 + rv.Tone(8.0, 1.0)}, "`control_variates` needs"),
        ({"psd": rv.Tone(8000.0, 1.0)}, "Nyquist"),
    ],
)
def test_forced_assembly_refusals_name_the_argument(kwargs, fragment):
    psd = kwargs.pop("psd")
    with pytest.raises(ValueError, match=fragment):
        rv.simulate(assembly_of(CHAIN), psd, t_end=0.01, dt=1e-4, n_paths=2, progress=False,
                    check_step=False, **kwargs)  # fmt: skip


LINEAR_CHAIN = """[structure]
chain = { mass = [0.2, 0.05], stiffness = [2000.0, 200.0], damping = [2.0, 0.3] }

[[transducer]]
between = [1, 0]
coupling = "resistive"
c_e = 0.2
"""


def test_cli_power_device_takes_tones_on_a_linear_assembly_and_refuses_them_otherwise(
    capsys, tmp_path
):
    """``power --device --tone``: a linear assembly's exact answer (the API's); a nonlinear
    one is refused in one line that points to ``simulate --device``."""
    path = tmp_path / "chain.toml"
    path.write_text(LINEAR_CHAIN)
    code, out, err = run_cli(capsys, "power", "--device", path, "--psd", "0.1", "--tone", "8:0.5",
                             "--json")  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    api = rv.predict(rv.Assembly.from_toml(path), 0.1 + rv.Tone(8.0, 0.5))
    without = rv.predict(rv.Assembly.from_toml(path), 0.1)
    got = data["transducers"][0]["power_electrical"]
    assert got == api.transducers[0].power_electrical > without.transducers[0].power_electrical
    code, out, err = run_cli(capsys, "power", "--device", "two_mass_harvester", "--psd", "0.1",
                             "--tone", "8:0.5")  # fmt: skip
    assert code == 2 and "simulate --device" in err and len(err.strip().splitlines()) == 1
