"""Synthetic records of assemblies (:mod:`randvib.identification.assembly_record`, ``record --device``).

* the CLI writes ``time``, the input and one column per DOF and per
  transducer, named ``dof.I.KIND`` / ``transducer.T.KIND``, reproducibly by
  seed, with the parameters beside it;
* a one-DOF assembly's record equals the single mass's on the same seed: the
  input bit for bit, the response to the schemes' step error. It cannot be
  bit-identical: the single mass's record is integrated by the RK4 of
  :mod:`randvib.identification.record_integrator`, the assembly by its own
  Heun kernel. The tolerance is the Heun error estimated by step halving
  (Richardson, with the first-order factor 2 as a safety margin) plus the
  RK4's, and the test checks that it is small against the signal;
* a linear two-DOF record's mean squares against the exact stationary
  variances of :func:`randvib.analytic.assembly_linear.linear_response`
  (a band-limited input is not rational, so they come from its spectral
  integral, checked here against an independent numpy transfer function),
  within the record's own exact standard error (a periodic Gaussian
  synthesis: the mean square over one period has variance sum_k |H_k|^4 P_k^2),
  less the input's known linear-hold bias; calibrated over 40 seeds
  (tests/calibration/assembly_record.py, results in assembly_record.txt beside it);
* one-line refusals.
"""

import json
from types import SimpleNamespace

import numpy as np
import pytest
from _cli import one_line_error, run
from _stats import assert_matches

from randvib import BandLimited, Harvester, synthetic_record
from randvib.analytic.assembly_linear import linear_response
from randvib.identification.assembly_record import assembly_record
from randvib.models.assembly import Assembly
from randvib.models.coupling import Inductive
from randvib.models.excitation import synthesis_power, synthesise
from randvib.models.record import Record

#: Two DOFs, linear (a quick step check), a coil and a piezo element: every column kind.
DEVICE_FILE = """
[structure]
mass = [0.5, 0.05]
stiffness = [[3948.0, -197.4], [-197.4, 197.4]]
damping = [[6.0, -0.3], [-0.3, 0.3]]

[[transducer]]
between = [1, 0]
coupling = "inductive"
alpha = 0.2
r_load = 2.0
r_coil = 0.5
inductance = 0.005

[[transducer]]
between = [0, "base"]
coupling = "piezo"
theta = 1e-3
capacitance = 1e-7
r_load = 1e5
"""


def test_cli_writes_a_column_per_dof_and_transducer_reproducibly(capsys, tmp_path):
    device = tmp_path / "device.toml"
    device.write_text(DEVICE_FILE)
    argv = ["record", "--device", device, "--psd", "0.1", "--duration", "1",
            "--sample-rate", "500", "--output-kind", "relative_velocity",
            "--output-kind", "voltage", "--output-kind", "current", "--noise", "voltage=1e-4",
            "--seed", "4"]  # fmt: skip
    code, out, err = run(capsys, *argv, "--out", tmp_path / "a.csv")
    assert code == 0, err
    header = (tmp_path / "a.csv").read_text().splitlines()[0].split(",")
    assert header == [
        "time", "base_acceleration", "dof.0.relative_velocity", "dof.1.relative_velocity",
        "transducer.0.voltage", "transducer.1.voltage", "transducer.0.current",
        "transducer.1.current",
    ]  # fmt: skip
    params = json.loads((tmp_path / "a.json").read_text())
    assert params["columns"] == header[1:] and params["device_file"] == str(device)
    assert params["device"]["transducer.0.r_load"] == 2.0 and params["seed"] == 4
    data = np.loadtxt(tmp_path / "a.csv", delimiter=",", skiprows=1)
    assert data.shape == (500, 8) and np.all(np.std(data[:, 2:], axis=0) > 0)
    # the piezo's current is V / R_L (noise on the voltage column only)
    clean = data[:, 7] * 1e5 - data[:, 5]
    assert np.std(clean) == pytest.approx(1e-4, rel=0.2)
    code, _, err = run(capsys, *argv, "--out", tmp_path / "b.csv")
    assert code == 0, err
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()


#: A Duffing harvester with a coil (its current a state), no friction: both integrators smooth.
COIL = Harvester.with_coupling(
    0.0226, 0.049, 57.4, Inductive(alpha=1.2, r_load=20.0, r_coil=5.0, inductance=0.05), k3=7e4
)
KINDS = ("relative_displacement", "relative_velocity", "voltage", "current")


def test_one_dof_assembly_matches_the_single_mass_record():
    options = dict(duration=1.0, sample_rate=500.0, seed=5, outputs=KINDS)
    single = {s: synthetic_record(COIL, 1.07, substeps=s, **options) for s in (8, 16)}
    one_dof = Assembly.from_harvester(COIL)
    assembly = {s: assembly_record(one_dof, 1.07, substeps=s, **options) for s in (8, 16)}
    np.testing.assert_array_equal(assembly[8].columns["base_acceleration"], single[8].input)
    for kind in KINDS:
        column = "dof.0." + kind if kind.startswith("relative") else "transducer.0." + kind
        got, reference = assembly[8].columns[column], single[8][kind]
        heun = 2.0 * np.max(np.abs(got - assembly[16].columns[column]))
        rk4 = 2.0 * np.max(np.abs(reference - single[16][kind]))
        tolerance = 2.0 * (heun + rk4)
        assert tolerance < 2e-3 * np.max(np.abs(reference)), kind  # the check has power
        assert np.max(np.abs(got - reference)) <= tolerance, kind


#: A host (1 kg, 10.6 Hz) carrying a 0.1 kg harvester (10 Hz), both about 10 % damped.
TWO_DOF = Assembly.from_matrices(
    mass=[1.0, 0.1],
    stiffness=[[4400.0, -400.0], [-400.0, 400.0]],
    damping=[[14.0, -1.3], [-1.3, 1.3]],
)


def _transfer(assembly, frequency):
    """X(f) / A(f) of every x and x' by a direct solve (independent of the package's)."""
    m, c, k = assembly.mass, assembly.damping, assembly.stiffness
    w = 2 * np.pi * np.asarray(frequency)[:, None, None]
    rhs = np.broadcast_to(-m @ assembly.influence, (w.shape[0], m.shape[0]))[..., None]
    x = np.linalg.solve(k - w**2 * m + 1j * w * c, rhs)[..., 0]
    return np.concatenate([x, 1j * w[:, :, 0] * x], axis=1)


def case_two_dof(seed):
    """(what, stat, reference, known bias, detect) per DOF's mean square x^2 and x'^2.

    One period of a Gaussian synthesis, repeated: the second period is the
    steady state. Over one period of n samples the mean square of a state is
    exactly sum_k |H_k|^2 (A_k^2 + B_k^2) / 2 with A_k, B_k ~ N(0, P_k): mean
    sum |H_k|^2 P_k (the spectral integral's, checked), standard error
    sqrt(sum |H_k|^4 P_k^2). The kernel sees the samples joined by straight
    lines, whose tone at f_k has the power sinc(f_k / rate)^4 of the sampled
    one: a known bias sum |H_k|^2 P_k (sinc^4 - 1), about -1 % (-0.4 SE).
    """
    excitation, period, rate = BandLimited(0.05, 4.0, 20.0), 240.0, 250.0
    n = int(period * rate)
    a = synthesise(excitation, period, 1 / rate, seed=seed)[0]
    motion = Record(1 / rate, base_acceleration=np.tile(a, 2))
    record = assembly_record(
        TWO_DOF, motion, duration=2 * period, sample_rate=rate, substeps=4,
        outputs=("relative_displacement", "relative_velocity"),
    )  # fmt: skip
    exact = linear_response(TWO_DOF, excitation)
    f, power = synthesis_power(excitation, n, 1 / rate)
    f, power = f[power > 0], power[power > 0]
    gain = np.abs(_transfer(TWO_DOF, f)) ** 2
    names = [f"dof.{i}.relative_displacement" for i in (0, 1)]
    names += [f"dof.{i}.relative_velocity" for i in (0, 1)]
    references = [*exact.displacement_variance, *exact.velocity_variance]
    for state, (name, reference) in enumerate(zip(names, references, strict=True)):
        se = np.sqrt(gain[:, state] ** 2 @ power**2)
        assert abs(gain[:, state] @ power - reference) < 0.05 * se, name
        steady = record.columns[name][n:]
        stat = SimpleNamespace(mean=float(np.mean(steady**2)), std_error=float(se))
        hold = gain[:, state] @ (power * (np.sinc(f / rate) ** 4 - 1.0))
        yield name, stat, reference, float(hold), 0.2


def test_linear_two_dof_mean_squares_match_the_exact_variances():
    """Calibrated over 40 seeds: tests/calibration/assembly_record.txt (mean z, SD, max |z|)."""
    for what, stat, reference, bias, detect in case_two_dof(11):
        assert_matches(stat, reference, known_bias=bias, detect=detect, what=what)


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--output-kind", "voltage"], "transducer 0 is an electrical damping without a load"),
        (["--m", "0.1"], "`--device` gives the whole device; drop `--m`"),
    ],
)
def test_record_device_refusals_are_one_line(capsys, tmp_path, extra, fragment):
    argv = ["record", "--device", "host_with_harvester", "--psd", "0.1", "--duration", "1",
            "--out", tmp_path / "r.csv", *extra]  # fmt: skip
    one_line_error(capsys, argv, fragment)
    assert not (tmp_path / "r.csv").exists()
