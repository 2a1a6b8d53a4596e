"""``randvib power --device`` (:mod:`randvib.cli.power`, :mod:`randvib.cli._device`): assemblies.

The JSON keys the issue fixes (``transducers`` in file order with their
powers, ``displacement_variance`` and ``velocity_variance`` per DOF) and their
values, equal to :func:`randvib.predict` on the same file; the optimal loads;
one-line refusals (a device option beside ``--device``, a bad file, a method
that does not take assemblies, the commands that do not take ``--device`` yet).
"""

import json

import pytest
from _cli import one_line_error, run

import randvib as rv
from randvib.datasets import device_path
from randvib.models.assembly import Assembly


def test_power_device_json_has_the_issues_keys(capsys, tmp_path):
    path = tmp_path / "host.toml"
    path.write_text(device_path("host_with_harvester").read_text())
    code, out, err = run(capsys, "power", "--device", path, "--psd", "0.1", "--json")
    assert code == 0, err
    data = json.loads(out)
    expected = rv.predict(Assembly.from_toml(path), 0.1)
    assert data["n_dof"] == 2 and data["exact"] is False and data["method"] == "linearisation"
    assert data["displacement_variance"] == pytest.approx(expected.displacement_variance, rel=1e-14)
    assert data["velocity_variance"] == pytest.approx(expected.velocity_variance, rel=1e-14)
    (transducer,) = data["transducers"]
    assert transducer["power_electrical"] == pytest.approx(
        expected.transducers[0].power_electrical, rel=1e-14
    )
    assert "power_load" not in transducer  # a bare c_e has no load
    assert transducer["between"] == [1, 0] and transducer["coupling"] == "resistive"
    assert data["power_input"] == pytest.approx(0.55 * 0.1 / 4, rel=1e-14)
    assert data["units"]["velocity_variance"] == "(m/s)^2"


@pytest.mark.filterwarnings(
    "ignore::randvib.analytic.statistical_linearisation.LinearisationValidityWarning"
)
def test_power_device_transducers_in_file_order_with_loads(capsys):
    argv = ["power", "--device", "two_harvesters_on_host", "--excitation", "band-pass",
            "--psd", "0.5", "--f0", "8", "--zeta", "0.1", "--json"]  # fmt: skip
    code, out, _ = run(capsys, *argv)
    assert code == 0
    data = json.loads(out)
    expected = rv.predict(Assembly.from_toml(device_path("two_harvesters_on_host")),
                          rv.BandPass(0.5, 8.0, 0.1))  # fmt: skip
    assert [t["between"] for t in data["transducers"]] == [[1, 0], [2, 0]]
    for entry, predicted in zip(data["transducers"], expected.transducers, strict=True):
        assert entry["power_load"] == pytest.approx(predicted.power_load, rel=1e-14)
        assert entry["circuit_mean_square"] == pytest.approx(
            predicted.circuit_mean_square, rel=1e-14
        )
    assert len(data["displacement_variance"]) == len(data["velocity_variance"]) == 3
    assert data["excitation"]["f0"] == 8.0


def test_power_device_optimal_load_per_transducer(capsys, tmp_path):
    # the shipped file without its cubic springs and friction: linear, so each of the
    # search's points is one Lyapunov solution
    a = Assembly.from_toml(device_path("two_harvesters_on_host"))
    linear = a.updated({"element.0.k3": 0.0, "element.1.k3": 0.0, "element.1.fc": 0.0})
    path = tmp_path / "linear.toml"
    path.write_text(linear.to_toml())
    code, out, _ = run(
        capsys, "power", "--device", path, "--psd", "0.2", "--optimal-load", "--json"
    )
    assert code == 0
    data = json.loads(out)
    assert data["exact"]
    for index, entry in enumerate(data["transducers"]):
        assert entry["r_load_optimal_location"] == "interior"
        assert entry["power_load_optimal"] > entry["power_load"]
        there = linear.updated({f"transducer.{index}.r_load": entry["r_load_optimal"]})
        power = rv.predict(there, 0.2).transducers[index].power_load
        assert entry["power_load_optimal"] == pytest.approx(power, rel=1e-12)


def test_power_device_sweep_and_table(capsys):
    code, out, _ = run(capsys, "power", "--device", "two_mass_harvester", "--psd", "0.1", "0.2")
    assert code == 0
    assert "transducers.0.power_load (W)" in out
    code, out, _ = run(capsys, "power", "--device", "two_mass_harvester", "--psd", "0.1")
    assert code == 0
    assert "transducer 0 [1, 0] power_load" in out and "DOF 1 velocity_variance" in out


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["power", "--device", "host_with_harvester", "--psd", "0.1", "--k3", "1"],
         "`--device` gives the whole device; drop `--k3`"),
        (["power", "--device", "nowhere.toml", "--psd", "0.1"], "device file nowhere.toml: no such file"),
        (["power", "--device", "nowhere", "--psd", "0.1"], "nor a shipped example"),
        (["power", "--device", "host_with_harvester", "--psd", "0.1", "--method", "averaging"],
         "`--method averaging` treats the single-mass harvester; an assembly needs `--method "
         "linearisation`"),
        (["simulate", "--device", "host_with_harvester", "--psd", "0.1", "--envelope", "boxcar"],
         "not implemented for `--device` assemblies"),
    ],
)  # fmt: skip
def test_device_refusals_are_one_line(capsys, argv, fragment):
    one_line_error(capsys, argv, fragment)


def test_record_refuses_a_device(capsys, tmp_path):
    argv = [
        "record",
        "--device",
        "host_with_harvester",
        "--psd",
        "0.1",
        "--out",
        tmp_path / "r.csv",
    ]
    one_line_error(capsys, argv, "is not taken here yet")
    assert not (tmp_path / "r.csv").exists()


def test_bad_device_file_is_one_line(capsys, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[structure]\nmass = [1.0]\nstiffness = [[1.0]]\ndamping = [[0.1]]\n"
                    "[[element]]\nbetween = [2, 0]\ndamping = 1.0\n")  # fmt: skip
    one_line_error(capsys, ["power", "--device", path, "--psd", "0.1"],
                   "[[element]] 0: `between` = [2, 0] names DOF 2")  # fmt: skip
