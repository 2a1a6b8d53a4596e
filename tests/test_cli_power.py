"""``randvib power`` (:mod:`randvib.cli.power`): JSON and table output, circuits, errors.

Values given on the command line override a preset's; a circuit adds the load
power; bad input ends with one line and exit status 2; the installed console
script and ``python -m randvib`` (:mod:`randvib.__main__`) exit as ``main`` does.
"""

import json
import subprocess
import sys

import pytest
from _cli import error_lines, run

import randvib as rv


def test_power_json_section5(capsys):
    code, out, _ = run(capsys, "power", "--preset", "figure9", "--psd", "1", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["c_eq"] == pytest.approx(rv.equivalent_damping(rv.preset("figure9"), 1.0))
    assert data["power_electrical"] == pytest.approx(2.4619412547950926e-3, rel=1e-12)
    assert {"c_eq", "velocity_variance", "power_electrical"} <= data.keys()


def test_power_with_circuit_reports_load_power(capsys):
    code, out, _ = run(
        capsys,
        "power",
        "--m",
        "0.0226",
        "--c-m",
        "0.1",
        "--k",
        "57.4",
        "--friction",
        "coulomb",
        "--fc",
        "0.0058",
        "--alpha",
        "0.1992",
        "--r-load",
        "2",
        "--r-coil",
        "0.48",
        "--psd",
        "0.5",
        "--json",
    )
    assert code == 0
    data = json.loads(out)
    h = rv.Harvester.from_electrical(
        m=0.0226, c_m=0.1, k=57.4, alpha=0.1992, r_load=2, r_coil=0.48, friction=rv.Coulomb(0.0058)
    )
    assert data["power_load"] == pytest.approx(rv.expected_power(h, 0.5, into="load"), rel=1e-12)


def test_cli_values_override_preset(capsys):
    _, out, _ = run(capsys, "power", "--preset", "figure9", "--fc", "0", "--psd", "1", "--json")
    assert json.loads(out)["c_eq"] == pytest.approx(0.2, rel=1e-12)
    _, out, _ = run(
        capsys,
        "power",
        "--preset",
        "figure9",
        "--friction",
        "tanh",
        "--beta",
        "1e9",
        "--psd",
        "1",
        "--json",
    )
    assert json.loads(out)["friction"] == "tanh"


def test_table_output(capsys):
    code, out, _ = run(capsys, "power", "--preset", "figure9", "--psd", "0.1")
    assert code == 0 and "power_electrical" in out and "W" in out


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (["--preset", "figure9", "--psd", "0"], "`--psd` must be > 0"),
        (["--preset", "figure9", "--psd", "nan"], "finite"),
        (["--preset", "nope", "--psd", "1"], "`--preset` must be one of"),
        (
            ["--preset", "figure9", "--friction", "magic", "--psd", "1"],
            "`--friction` must be one of",
        ),
        (
            ["--m", "-1", "--c-m", "0.1", "--c-e", "0.1", "--k", "57", "--psd", "1"],
            "`--m` must be > 0",
        ),
        (["--preset", "figure9", "--c-m", "-0.1", "--psd", "1"], "`--c-m` must be >= 0"),
        (["--preset", "figure9", "--fc", "-1", "--psd", "1"], "`--fc` must be >= 0"),
        (["--preset", "figure9"], "`--psd` is required"),
        (["--preset", "figure9", "--psd", "1", "--bogus"], "unrecognized arguments"),
    ],
)
def test_bad_input_one_line_exit_2(capsys, argv, fragment):
    code, out, err = run(capsys, "power", *argv)
    assert code == 2
    assert fragment in err
    assert len(error_lines(err)) == 1 and "Traceback" not in err


def test_console_script_exit_code():
    proc = subprocess.run(
        [sys.executable, "-m", "randvib", "power", "--preset", "x", "--psd", "1"],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1
