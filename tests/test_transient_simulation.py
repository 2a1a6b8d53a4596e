"""Monte Carlo of events (randvib.simulate_transient) against exact references.

On the linear device every expectation the ensemble estimates is known
twice: in continuous time (Caughey and Stumpf's closed form, the Lyapunov
equation of randvib.transient_response) and for the scheme at the step dt,
whose second moments follow an exact linear recursion (the scheme on a
linear SDE is ``x_{n+1} = A_n x_n + B_n dW_n``,
:meth:`randvib.Integrator.linear_recursion`, with the step's envelope gain in
A_n or B_n). The difference of the two is the scheme's known bias, removed
before comparing (``known_bias`` of tests/_stats.py); the tolerance is the
ensemble's own standard error (4 sigma), and each comparison must be able
to see a 15 % error (power check). The paths and seeds are fixed.

Covers :mod:`randvib.montecarlo.transient` and its results
(:mod:`randvib.montecarlo.transient_results`).
"""

import numpy as np
import pytest
from _stats import assert_matches
from scipy import linalg, special

import randvib as rv
from randvib.analytic import exact_solutions as exact
from randvib.montecarlo import kernel
from randvib.montecarlo.integrators import INTEGRATORS
from randvib.montecarlo.transient import EventInput, snapshot_steps
from randvib.statistics import Statistic, estimate

M, C, K = 0.0226, 0.2, 57.4
LINEAR = rv.Harvester(m=M, c_m=0.1, c_e=0.1, k=K)
SS = rv.ShinozukaSato.unit_peak(0.5, 2.0)


def scheme_moments(device, event, dt, n_steps, scheme="heun"):
    """The scheme's exact E[z^2], E[v^2] at every step and E[int v^2 dt] (trapezoid), linear device.

    States (filter, z, v); the filter starts in its stationary law, the device at rest.
    """
    excitation = event.excitation
    shaping = excitation.shaping_filter()
    filt = shaping.system
    nf = filt.n_states
    n = nf + 2
    f0 = np.zeros((n, n))
    f0[:nf, :nf] = filt.a
    f0[nf, nf + 1] = 1.0
    f0[nf + 1, nf] = -device.k / device.m
    f0[nf + 1, nf + 1] = -device.c / device.m
    coupling = np.zeros((n, n))
    coupling[nf + 1, :nf] = -filt.c[0]
    noise = np.zeros((n, 1))
    noise[:nf, 0] = filt.b
    noise[nf + 1, 0] = 1.0 if excitation.is_white else 0.0
    noise *= np.sqrt(shaping.noise_intensity)
    p = np.zeros((n, n))
    if nf:
        p[:nf, :nf] = linalg.solve_continuous_lyapunov(filt.a, -np.outer(noise[:nf], noise[:nf]))
    first, second = event.envelope.step_integrals(dt, n_steps)
    gains = np.sqrt(second / dt) if excitation.is_white else first / dt
    integrator = INTEGRATORS[scheme]
    z2, v2 = [p[nf, nf]], [p[nf + 1, nf + 1]]
    energy = 0.0
    for g in gains:
        if excitation.is_white:
            a, b = integrator.linear_recursion(f0, g * noise, dt)
        else:
            a, b = integrator.linear_recursion(f0 + g * coupling, noise, dt)
        p_next = a @ p @ a.T + dt * (b @ b.T)
        energy += 0.5 * dt * (p[nf + 1, nf + 1] + p_next[nf + 1, nf + 1])
        p = p_next
        z2.append(p[nf, nf])
        v2.append(p[nf + 1, nf + 1])
    return np.array(z2), np.array(v2), energy


CASES = {
    "white-step": (rv.Enveloped(rv.White(1.0), rv.Step()), 0.6, 4000, 1),
    "white-shinozuka-sato": (rv.Enveloped(rv.White(2.0), SS), 2.0, 4000, 2),
    "band-pass-shinozuka-sato": (rv.Enveloped(rv.BandPass(2.0, 8.0, 0.2), SS), 2.0, 4000, 3),
    "kanai-tajimi-boxcar": (rv.Enveloped(rv.KanaiTajimi(0.5, 10.0, 0.4),
                                         rv.Boxcar(0.3, 0.6, 0.4)), 1.5, 4000, 4),
}  # fmt: skip


def case_transient(name: str, seed: int):
    """(what, statistic, exact value, known scheme bias, detect) rows of one case at one seed."""
    event, t_end, n_paths, _ = CASES[name]
    dt = 5e-4
    times = np.array([0.1, 0.3, 0.6, t_end]) if t_end > 0.6 else np.array([0.05, 0.2, 0.6])
    mc = rv.simulate_transient(LINEAR, event, t_end=t_end, dt=dt, n_paths=n_paths, times=times,
                               seed=seed, progress=False)  # fmt: skip
    exact_t = rv.transient_response(LINEAR, event, mc.times, t_end=t_end)
    steps = snapshot_steps(times, dt, round(t_end / dt))
    z2, v2, energy = scheme_moments(LINEAR, event, dt, round(t_end / dt))
    rows = []
    for i, step in enumerate(steps):
        ref_z, ref_v = exact_t.displacement_variance[i], exact_t.velocity_variance[i]
        rows.append((f"E[z^2]({mc.times[i]:g})", mc.displacement_variance[i], ref_z,
                     z2[step] - ref_z, 0.15))  # fmt: skip
        rows.append((f"E[v^2]({mc.times[i]:g})", mc.velocity_variance[i], ref_v,
                     v2[step] - ref_v, 0.15))  # fmt: skip
    ref_e = exact_t.energy_electrical
    rows.append(("energy", mc.energy_electrical, ref_e, LINEAR.c_e * energy - ref_e, 0.06))
    return rows


@pytest.mark.parametrize("name", list(CASES))
def test_monte_carlo_matches_the_exact_transient(name):
    """Calibrated with tests/calibration/transient.py: over seeds 1000-1039 (every case) the
    z-scores' means lie in -0.53 .. +0.13 and SDs in 0.85 .. 1.44, the largest |z| 4.13
    (band-pass E[z^2] at 0.6 s; the three cases share their seeds' increments, so their
    fluctuations move together); rerun over 100 fresh seeds (2000-2099 white-step,
    3000-3099 band-pass): means -0.25 .. +0.19, SDs 0.92 .. 1.24, largest |z| 3.66.
    Power margins >= 6.0 SE."""
    for what, stat, reference, bias, detect in case_transient(name, CASES[name][3]):
        assert_matches(stat, reference, detect=detect, known_bias=bias, what=f"{name} {what}")
        # the scheme's own bias at this step is small against the tolerances
        assert abs(bias) < 0.01 * abs(reference) + 1e-3 * abs(bias + reference)


def test_monte_carlo_matches_caughey_and_stumpf_through_the_closed_form():
    mc = rv.simulate_transient(LINEAR, rv.Enveloped(rv.White(1.0), rv.Step()), t_end=1.0,
                               dt=2.5e-4, n_paths=4000, times=[0.05, 0.2, 1.0], seed=11,
                               progress=False)  # fmt: skip
    z2, _, v2 = exact.caughey_stumpf_moments(M, C, K, 1.0, mc.times)
    z2_n, v2_n, energy_n = scheme_moments(LINEAR, mc.event, 2.5e-4, 4000)
    steps = [200, 800, 4000]
    for i, step in enumerate(steps):
        assert_matches(mc.displacement_variance[i], z2[i], detect=0.15,
                       known_bias=z2_n[step] - z2[i], what="E[z^2]")  # fmt: skip
        assert_matches(mc.velocity_variance[i], v2[i], detect=0.15,
                       known_bias=v2_n[step] - v2[i], what="E[v^2]")  # fmt: skip
    closed = 0.1 * exact.caughey_stumpf_velocity_integral(M, C, K, 1.0, 1.0)
    assert_matches(mc.energy_electrical, closed, detect=0.05, known_bias=0.1 * energy_n - closed,
                   what="energy")  # fmt: skip


def test_a_unit_step_reproduces_the_stationary_loop_path_by_path():
    # white noise switched on at t = 0 from a given state is what simulate does
    # from that state: the same increments give the same final states
    t_end, dt, n_paths = 0.4, 2e-4, 12
    dw = np.random.default_rng(3).standard_normal((n_paths, 2000)) * np.sqrt(dt)
    start = (1e-3, -0.02)
    device = rv.preset("figure9")
    plain = rv.simulate(device, 1.0, t_end=t_end, dt=dt, n_paths=n_paths, dW=dw, initial=start,
                        progress=False)  # fmt: skip
    event = rv.simulate_transient(device, rv.Enveloped(rv.White(1.0), rv.Step()), t_end=t_end,
                                  dt=dt, n_paths=n_paths, dW=dw, start=start, times=[t_end],
                                  progress=False)  # fmt: skip
    z, v = event.snapshots[:, -1, kernel.SNAP_Z], event.snapshots[:, -1, kernel.SNAP_V]
    energy = 0.5 * device.m * v**2 + 0.5 * device.k * z**2 + 0.25 * device.k3 * z**4
    np.testing.assert_allclose(energy, plain.per_path[:, kernel.ACC_H1], rtol=1e-9)
    # and the running peak is at least every snapshot's |z|
    assert np.all(event.peak_displacement >= np.abs(z))


def test_envelope_gains_and_snapshot_steps():
    run_dt, n = 0.01, 100
    event = rv.Enveloped(rv.White(1.0), rv.Boxcar(0.25, 0.5, 0.0))
    first, second = event.envelope.step_integrals(run_dt, n)

    class _Run:  # what EventInput reads of a run
        driver = None

        class grid:
            dt, n_steps = run_dt, n

    white = EventInput.of(_Run, event)
    np.testing.assert_allclose(white.gain, np.sqrt(second / run_dt))
    assert white.scale_noise and white.n_start == 0
    filtered = EventInput.of(_Run, rv.Enveloped(rv.BandPass(1.0, 8.0, 0.2), event.envelope))
    np.testing.assert_allclose(filtered.gain, first / run_dt)
    assert not filtered.scale_noise and filtered.n_start == 2
    np.testing.assert_array_equal(filtered.filter_mask, [1.0, 1.0, 0.0])
    assert white.gain[-1] == 0.0  # after the boxcar
    np.testing.assert_array_equal(snapshot_steps([0.0, 0.5, 1.0], 0.01, 100), [0, 50, 100])
    assert snapshot_steps(None, 0.01, 100).size == 51
    for times, fragment in [
        ([0.5, 0.2], "`times` must be increasing"),
        ([0.5, 2.0], r"`times` must lie in \[0, t_end\] = \[0, 1\] s"),
        ([-0.1], "must lie in"),
        ([0.5, 0.501], "fall on the same step"),
    ]:
        with pytest.raises(ValueError, match=fragment):
            snapshot_steps(times, 0.01, 100)


def test_stroke_first_passage_and_its_approximations():
    """P(stroke reached) from Monte Carlo between Vanmarcke's and Poisson's approximations.

    Measured (seed 5, 4000 paths, strokes 4-10 mm, white and band-pass
    input): Poisson over-estimates by 0.02-0.24 (crossings come in clumps),
    Vanmarcke with the stationary bandwidth under-estimates by 0.01-0.23;
    the ensemble lies between them here.
    """
    device = LINEAR.updated(stroke=0.008)
    event = rv.Enveloped(rv.White(1.0), SS)
    mc = rv.simulate_transient(device, event, t_end=4.0, dt=2.5e-4, n_paths=2000,
                               times=[1.0, 2.0, 4.0], seed=5, progress=False)  # fmt: skip
    approx = rv.transient_response(device, event, mc.times)
    reached = mc.stroke_reached
    for i in range(len(reached)):
        assert approx.stroke_reached_vanmarcke[i] < reached.mean[i] + 2 * reached.ci95[i]
        assert reached.mean[i] - 2 * reached.ci95[i] < approx.stroke_reached_poisson[i]
    # one event's answer three ways: the first passage, the peak, the last snapshot
    first = mc.stroke_first_passage
    assert first.paths_reached == int(np.sum(mc.peak_displacement > 0.008))
    assert mc.peak_exceedance(0.008).mean == pytest.approx(reached.mean[-1])
    # and P(|z(t)| > b) is the Gaussian law's at each time (exact, linear device):
    # at 3 mm and the first two times, where it is large enough to be measured
    b = 0.003
    for i in range(2):
        beyond = estimate(np.abs(mc.snapshots[:, i, kernel.SNAP_Z]) > b)
        gaussian = special.erfc(b / np.sqrt(2 * approx.displacement_variance[i]))
        assert_matches(beyond, gaussian, detect=0.3, what=f"P(|z| > b) at {mc.times[i]:g} s")
    np.testing.assert_allclose(
        approx.stroke_exceedance, special.erfc(0.008 / np.sqrt(2 * approx.displacement_variance))
    )


def test_bistable_device_from_its_well_stays_near_it_under_a_weak_event():
    bistable = rv.Harvester(m=M, c_m=0.05, c_e=0.05, k=-K, k3=5e5, stroke=0.02)
    weak = rv.Enveloped(rv.White(0.01), SS)
    mc = rv.simulate_transient(bistable, weak, t_end=2.0, dt=2.5e-4, n_paths=64,
                               times=[0.0, 1.0, 2.0], start="unexcited", progress=False)  # fmt: skip
    well = np.sqrt(K / 5e5)
    assert mc.start.z == pytest.approx(well)
    np.testing.assert_allclose(mc.snapshots[:, 0, kernel.SNAP_Z], well)
    assert np.all(np.abs(mc.displacement_mean.mean - well) < 0.1 * well)
    assert mc.stroke_reached.mean[-1] == 0.0


def test_result_tables_and_json():
    device = rv.Harvester.with_coupling(M, 0.1, K, rv.Inductive(0.1992, 0.5, 0.48, 2e-3),
                                        stroke=0.005)  # fmt: skip
    event = rv.Enveloped(rv.BandPass(1.0, 8.0, 0.2), SS)
    mc = rv.simulate_transient(device, event, t_end=1.0, dt=2.5e-4, n_paths=64,
                               times=[0.5, 1.0], progress=False)  # fmt: skip
    out = mc.to_dict()
    assert out["times"] == [0.5, 1.0]
    for key in ("displacement_variance", "velocity_variance", "power_electrical", "power_load",
                "circuit_mean_square", "stroke_reached", "stroke_exceedance"):  # fmt: skip
        assert len(out[key]) == 2 and len(out[key][0]) == 2, key
    assert len(out["energy_electrical"]) == 2 and out["energy_electrical"][0] > 0
    assert out["envelope"]["envelope"] == "shinozuka-sato" and out["start"] == "rest"
    frame = mc.to_frame()
    assert list(frame.time) == [0.5, 1.0] and "power_electrical_ci95" in frame
    # the circuit's power is (R_L + R_C) E[i^2], path by path
    r = device.electrical.resistance
    np.testing.assert_allclose(mc.power_electrical.mean, r * mc.circuit_mean_square.mean)
    text = str(mc)
    assert "Monte Carlo transient" in text and "±" in text and "energy" in text
    assert "<table>" in mc._repr_html_() and "TransientResult(64 paths" in repr(mc)
    assert isinstance(mc.velocity_variance[0], Statistic)


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        (dict(event=rv.White(1.0)), "`event` must be a randvib.Enveloped"),
        (dict(times=[2.0]), r"`times` must lie in \[0, t_end\]"),
        (dict(n_paths=1), "`n_paths` must be >= 2"),
        (dict(start="well"), "`start` must be one of"),
        (
            dict(
                event=rv.Enveloped(
                    rv.Measured(
                        rv.Record(
                            time=np.arange(200) * 0.01, base_acceleration=np.sin(np.arange(200))
                        )
                    ),
                    rv.Step(),
                )
            ),
            "measured record is one",
        ),  # fmt: skip
    ],
)
def test_refusals(kwargs, fragment):
    with pytest.raises(ValueError, match="`harvester` must be a randvib.Harvester"):
        rv.simulate_transient("device", rv.Enveloped(1.0, rv.Step()), t_end=1, dt=1e-3, n_paths=4)
    arguments = dict(event=rv.Enveloped(rv.White(1.0), rv.Step()), t_end=1.0, dt=1e-3,
                     n_paths=8, progress=False)  # fmt: skip
    arguments.update(kwargs)
    event = arguments.pop("event")
    with pytest.raises(ValueError, match=fragment):
        rv.simulate_transient(LINEAR, event, **arguments)
