"""Events on the command line: ``randvib simulate`` and ``randvib power`` with ``--envelope``.

The exact references are those of the issue: the linear oscillator from rest
under a step (Caughey and Stumpf's closed form) and under an envelope (the
Lyapunov equation, itself checked against independent routes in
tests/test_transient_analytic.py), at several times and over the event:
``power`` to 1e-6, ``simulate`` within its 95 % intervals widened to 4
standard errors.

Covers the event options of both commands (:mod:`randvib.cli._event`).
"""

import json

import numpy as np
import pytest
from _stats import assert_matches

import randvib as rv
from randvib.analytic import exact_solutions as exact
from randvib.statistics import Statistic
from tests._cli import one_line_error, run

M, C, K = 0.0226, 0.2, 57.4
DEVICE = ["--m", M, "--c-m", 0.1, "--c-e", 0.1, "--k", K, "--psd", 1.0]
SS = ["--envelope", "shinozuka-sato", "--envelope-b", 0.5, "--envelope-c", 2.0]


def _json(capsys, *argv):
    code, out, err = run(capsys, *argv)
    assert code == 0, err
    return json.loads(out)


def test_power_step_matches_caughey_and_stumpf(capsys):
    out = _json(capsys, "power", *DEVICE, "--envelope", "step", "--times", "0.05,0.2,1,3",
                "--t-end", 4, "--json")  # fmt: skip
    t = np.array([0.05, 0.2, 1.0, 3.0])
    z2, _, v2 = exact.caughey_stumpf_moments(M, C, K, 1.0, t)
    assert out["times"] == list(t)
    np.testing.assert_allclose(out["displacement_variance"], z2, rtol=1e-6)
    np.testing.assert_allclose(out["velocity_variance"], v2, rtol=1e-6)
    np.testing.assert_allclose(out["power_electrical"], 0.1 * v2, rtol=1e-6)
    energy = 0.1 * exact.caughey_stumpf_velocity_integral(M, C, K, 1.0, 4.0)
    assert out["energy_electrical"] == pytest.approx(energy, rel=1e-6)
    assert out["t_end"] == 4.0 and out["start"] == "rest" and out["exact"] is True


def test_power_envelope_is_the_python_result_and_defaults_t_end_to_the_last_time(capsys):
    out = _json(capsys, "power", *DEVICE, *SS, "--times", "0.5,1,2", "--json")
    event = rv.Enveloped(rv.White(1.0), rv.ShinozukaSato.unit_peak(0.5, 2.0))
    linear = rv.Harvester(m=M, c_m=0.1, c_e=0.1, k=K)
    expected = rv.transient_response(linear, event, [0.5, 1.0, 2.0])
    np.testing.assert_allclose(out["displacement_variance"], expected.displacement_variance)
    assert out["energy_electrical"] == pytest.approx(expected.energy_electrical, rel=1e-12)
    assert out["t_end"] == 2.0
    assert out["envelope"]["a"] == pytest.approx(event.envelope.a)  # unit peak by default


def test_power_event_table_and_stroke(capsys):
    code, out, err = run(capsys, "power", *DEVICE, *SS, "--envelope-a", 2.0, "--times", "1,2",
                         "--stroke", 0.004)  # fmt: skip
    assert code == 0, err
    assert "E[z^2] (m^2)" in out and "reached, Poisson*" in out and "approximate" in out
    assert "energy from t = 0 to 2 s" in out and "exact: linear device" in out
    assert "shinozuka-sato envelope (a 2, b 0.5 1/s, c 2 1/s)" in out  # with their units


def test_simulate_step_within_intervals_of_the_closed_form(capsys):
    out = _json(capsys, "simulate", *DEVICE, "--envelope", "step", "--times", "0.1,0.5",
                "--paths", 4000, "--dt", 2.5e-4, "--seed", 4, "--json")  # fmt: skip
    t = np.array(out["times"])
    np.testing.assert_allclose(t, [0.1, 0.5])
    z2, _, v2 = exact.caughey_stumpf_moments(M, C, K, 1.0, t)
    for name, reference in (("displacement_variance", z2), ("velocity_variance", v2)):
        for (mean, half), ref in zip(out[name], reference, strict=True):
            stat = Statistic(mean, half, half / 1.96, out["n_paths"])
            # 2.5e-4 s: the scheme's bias is below 0.3 % here (tests/test_transient_simulation.py)
            assert_matches(stat, ref, detect=0.15, what=name)
    mean, half = out["energy_electrical"]
    energy = 0.1 * exact.caughey_stumpf_velocity_integral(M, C, K, 1.0, 0.5)
    assert_matches(Statistic(mean, half, half / 1.96, 4000), energy, detect=0.06, what="energy")
    assert out["t_end"] == 0.5 and len(out["power_electrical"]) == 2


def test_simulate_envelope_table(capsys, tmp_path):
    table = tmp_path / "event.csv"
    table.write_text("time,envelope\n0,0\n0.2,1\n0.5,0.3\n0.8,0\n")
    code, out, err = run(capsys, "simulate", *DEVICE, "--stroke", 0.004, "--envelope", "table",
                         "--envelope-file", table, "--times", "0.2,0.8", "--paths", 64,
                         "--dt", 5e-4, "--no-progress")  # fmt: skip
    assert code == 0, err
    assert "E[P_e] analytic (W)" in out and "P(stroke reached)" in out
    assert "energy from t = 0 to 0.8 s" in out and "peak |z| over the event" in out
    assert "table envelope" in out


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["power", *DEVICE, "--envelope", "shinozuka-sato", "--envelope-b", 2, "--envelope-c",
          0.5, "--times", 1], "`--envelope-c` must be > `--envelope-b` = 2.0"),
        (["power", *DEVICE, "--envelope", "step", "--times", "2,1"], "`--times` must be increasing"),
        (["power", *DEVICE, "--envelope", "step", "--times", "1", "--t-end", 0.5],
         "`--times` must lie in [0, --t-end]"),
        (["power", *DEVICE, "--envelope", "step", "--times", "a,b"], "`--times` must be times"),
        (["power", *DEVICE, "--envelope", "step"], "needs `--t-end` or `--times`"),
        (["power", *DEVICE, "--envelope-b", 3, "--times", 1], "it needs `--envelope`"),
        (["power", *DEVICE, "--times", 1], "`--times` describes an event"),
        (["power", *DEVICE, "--envelope", "step", "--envelope-rise", 1, "--times", 1],
         "`--envelope-rise` applies to the boxcar envelope"),
        (["power", *DEVICE, "--envelope", "shinozuka-sato", "--envelope-b", 1, "--times", 1],
         "`--envelope-c` required"),
        (["power", *DEVICE, "--envelope", "table", "--times", 1], "needs `--envelope-file"),
        (["power", *DEVICE, "--envelope", "step", "--times", 1, "--method", "fpk"],
         "`--method fpk` is stationary"),
        (["power", *DEVICE, "--envelope", "step", "--times", 1, "--optimal-load"],
         "`--optimal-load` does not apply to an event"),
        (["power", "--m", M, "--c-m", 0.1, "--c-e", 0.1, "--k", K, "--psd", 1, 2, "--envelope",
          "step", "--times", 1], "`--psd` has several values"),
        (["simulate", *DEVICE, "--envelope", "step", "--times", 1, "--burn-in", 1],
         "`--burn-in` does not apply to an event"),
        (["simulate", *DEVICE, "--envelope", "step", "--times", 1, "--control-variates"],
         "`--control-variates` does not apply"),
        (["simulate", *DEVICE, "--envelope", "step", "--times", "0.2,0.2001,1", "--dt", 1e-3],
         "fall on the same step"),
        (["simulate", *DEVICE, "--envelope", "step", "--times", "2", "--t-end", 1],
         "`--times` must lie in [0, --t-end] = [0, 1] s"),
    ],
)  # fmt: skip
def test_bad_event_options_are_one_line(capsys, argv, fragment):
    one_line_error(capsys, argv, fragment)


def test_envelope_file_errors(capsys, tmp_path):
    unsorted = tmp_path / "unsorted.csv"
    unsorted.write_text("time,envelope\n0,0\n1,1\n0.5,0\n")
    one_line_error(capsys, ["power", *DEVICE, "--envelope", "table", "--envelope-file", unsorted,
                            "--times", 1], "strictly increasing")  # fmt: skip
    one_line_error(capsys, ["power", *DEVICE, "--envelope", "table", "--envelope-file",
                            tmp_path / "missing.csv", "--times", 1], "no such file")  # fmt: skip


def test_events_plot_from_both_commands_and_probabilities_as_intervals(capsys, tmp_path):
    """`--plot` draws an event's figure (issue 35, item 10) from `power` (analytic) and
    `simulate` (Monte Carlo beside it), refused without `--envelope` and over an existing
    file; P(stroke reached) is printed with its Wilson interval, never mean +- half."""
    figure = tmp_path / "event.png"
    code, out, err = run(capsys, "power", *DEVICE, *SS, "--t-end", 1, "--stroke", 0.004,
                         "--plot", figure)  # fmt: skip
    assert code == 0, err
    assert f"wrote {figure}" in out and figure.stat().st_size > 10_000
    one_line_error(capsys, ["power", *DEVICE, *SS, "--t-end", 1, "--plot", figure],
                   "exists")  # fmt: skip
    one_line_error(capsys, ["simulate", *DEVICE, "--plot", tmp_path / "x.png"],
                   "`--plot` describes an event: it needs `--envelope`")  # fmt: skip
    simulated = tmp_path / "simulated.png"
    code, out, err = run(capsys, "simulate", *DEVICE, *SS, "--times", "0.5,1", "--paths", 32,
                         "--dt", 5e-4, "--stroke", 0.004, "--plot", simulated, "--json")  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    assert simulated.stat().st_size > 10_000 and f"wrote {simulated}" in err
    for (mean, _), (lower, upper) in zip(data["stroke_reached"], data["stroke_reached_interval"],
                                         strict=True):  # fmt: skip
        assert 0.0 <= lower <= mean <= upper <= 1.0
    lower, upper = data["stroke_reached_event_interval"]
    assert 0.0 <= lower <= data["stroke_reached_event"][0] <= upper <= 1.0
