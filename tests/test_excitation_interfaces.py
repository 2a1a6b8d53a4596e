"""Excitations at the interfaces: predict/expected_power, the refusals of the
white-noise methods, Measured read from CSV (randvib.models.excitation) and
``randvib power --excitation ...``."""

import json

import numpy as np
import pytest
from _cli import one_line_error, run

import randvib as rv
from randvib.analytic.averaging import averaging_statistics, energy_density
from randvib.analytic.fokker_planck import fast_fpk_statistics, fpk_statistics, solve_fpk
from randvib.cli._excitation import excitation_choices
from randvib.models.excitation import (
    EXCITATIONS,
    BandLimited,
    BandPass,
    KanaiTajimi,
    Measured,
    Tabulated,
    White,
)

DEVICE = ["--preset", "figure9"]
COLOURED = [
    (BandPass(1.0, 10.0, 0.2), ["--excitation", "band-pass", "--f0", "10", "--zeta", "0.2"]),
    (KanaiTajimi(1.0, 10.0, 0.3), ["--excitation", "kanai-tajimi", "--f0", "10", "--zeta", "0.3"]),
    (BandLimited(1.0, 4.0, 20.0), ["--excitation", "band-limited", "--f-lo", "4", "--f-hi", "20"]),
]


def power_error(capsys, argv, fragment):
    """``randvib power ARGV`` is refused with one line naming ``fragment``."""
    one_line_error(capsys, ["power", *argv], fragment)


@pytest.fixture(scope="module")
def harvester():
    return rv.preset("figure9")


# ------------------------------------------------------------------ Python API
@pytest.mark.parametrize("method", ["linearisation", "averaging", "fpk-fast"])
def test_white_excitation_is_bit_identical_to_a_number(harvester, method):
    assert rv.predict(harvester, White(0.7), method) == rv.predict(harvester, 0.7, method)


@pytest.mark.parametrize("excitation", [e for e, _ in COLOURED], ids=lambda e: e.name)
def test_expected_power_with_an_excitation_is_statistical_linearisation(harvester, excitation):
    reference = rv.statistical_linearisation(harvester, excitation)
    result = rv.predict(harvester, excitation)
    assert result.method == "linearisation"
    assert rv.expected_power(harvester, excitation) == reference.power_electrical
    assert result.velocity_variance == reference.velocity_variance
    assert result.displacement_variance == reference.displacement_variance
    assert result.c_eq == reference.c_eq
    assert result.mean_abs_velocity == pytest.approx(
        np.sqrt(2 / np.pi * reference.velocity_variance)
    )


def test_load_power_with_an_excitation(harvester):
    device = rv.Harvester.from_electrical(
        m=1.0, c_m=0.1, k=100.0, alpha=1.0, r_load=10.0, r_coil=5.0, friction=harvester.friction
    )
    excitation = BandPass(1.0, 1.6, 0.3)
    reference = rv.statistical_linearisation(device, excitation)
    assert rv.expected_power(device, excitation, into="load") == reference.power_load


@pytest.mark.parametrize("method", ["averaging", "fpk-fast", "fpk"])
def test_predict_refuses_coloured_input_for_white_noise_methods(harvester, method):
    with pytest.raises(ValueError, match=f"method='{method}' assumes white noise.*'linearisation'"):
        rv.predict(harvester, BandPass(1.0, 10.0, 0.2), method)


@pytest.mark.parametrize(
    ("solver", "who"),
    [
        (averaging_statistics, "stochastic averaging"),
        (lambda h, e: energy_density(h, e, [1e-4]), "stochastic averaging"),
        (fpk_statistics, "the FPK solver"),
        (fast_fpk_statistics, "the FPK solver"),
        (solve_fpk, "the FPK solver"),
    ],
)
def test_averaging_and_fpk_refuse_coloured_input(harvester, solver, who):
    with pytest.raises(ValueError, match=f"{who} assumes white noise.*method='linearisation'"):
        solver(harvester, KanaiTajimi(1.0, 10.0, 0.3))


def test_averaging_and_fpk_take_white_like_a_number(harvester):
    a = averaging_statistics(harvester, White(0.5))
    b = averaging_statistics(harvester, 0.5)
    assert a.velocity_variance == b.velocity_variance
    assert fast_fpk_statistics(harvester, White(0.5)) == fast_fpk_statistics(harvester, 0.5)


# ------------------------------------------------------------------------- CLI
def test_excitation_choices_come_from_the_registry():
    assert excitation_choices() == ["white", "band-pass", "kanai-tajimi", "band-limited"]
    assert set(excitation_choices()) | {"tabulated", "measured"} == set(EXCITATIONS)


def test_white_output_is_unchanged(capsys):
    # The JSON of `--psd 1` before excitations existed (commit c56b597).
    before = {
        "method": "linearisation",
        "psd": 1.0,
        "friction": "coulomb",
        "c_eq": 0.2294936968538776,
        "velocity_variance": 0.024619412547950924,
        "displacement_variance": 9.368825920573607e-06,
        "mean_abs_velocity": 0.12519267076031287,
        "power_electrical": 0.0024619412547950926,
    }
    for extra in ([], ["--excitation", "white"]):
        code, out, _ = run(capsys, "power", *DEVICE, "--psd", "1", *extra, "--json")
        assert code == 0
        got = json.loads(out)
        # the same keys, values and order; keys are only ever added after them
        # (power_mechanical: c_m E[v^2] + friction power)
        assert {key: got[key] for key in before} == before
        assert list(got)[: len(before)] == list(before)
        assert set(got) - set(before) == {"power_mechanical", "units"}


@pytest.mark.parametrize(("excitation", "argv"), COLOURED, ids=lambda x: getattr(x, "name", ""))
def test_cli_numbers_equal_the_api(capsys, harvester, excitation, argv):
    code, out, _ = run(capsys, "power", *DEVICE, "--psd", "1", *argv, "--json")
    assert code == 0
    got = json.loads(out)
    expected = rv.predict(harvester, excitation).to_dict()
    expected.pop("power_load")
    for key, value in expected.items():
        assert got[key] == value, key
    assert got["psd"] == 1.0 and got["friction"] == "coulomb"
    assert got["excitation"] == excitation.parameters()


def write_table(path, frequency, psd):
    path.write_text(
        "frequency,psd\n" + "".join(f"{f},{p}\n" for f, p in zip(frequency, psd, strict=True))
    )
    return str(path)


def test_psd_file_equals_the_api(tmp_path, capsys, harvester):
    file = write_table(tmp_path / "psd.csv", [0.0, 4.0, 12.0, 20.0, 30.0], [0, 0.5, 1.0, 0.5, 0])
    code, out, _ = run(capsys, "power", *DEVICE, "--psd-file", file, "--json")
    assert code == 0
    got = json.loads(out)
    expected = rv.statistical_linearisation(harvester, Tabulated.from_csv(file))
    assert got["power_electrical"] == expected.power_electrical
    assert got["psd"] is None and got["excitation"]["excitation"] == "tabulated"


def write_record(path, time, acceleration):
    rows = "".join(f"{float(t)!r},{float(a)!r}\n" for t, a in zip(time, acceleration, strict=True))
    path.write_text("time,base_acceleration\n" + rows)
    return str(path)


def test_record_equals_the_api(tmp_path, capsys, harvester):
    time = np.arange(4096) / 200.0
    acceleration = BandLimited(1.0, 4.0, 20.0).sample(time.size / 200.0, 1 / 200.0, seed=3)[0]
    file = write_record(tmp_path / "rec.csv", time, acceleration)
    code, out, _ = run(capsys, "power", *DEVICE, "--record", file, "--json")
    assert code == 0
    got = json.loads(out)
    expected = rv.statistical_linearisation(harvester, Measured.from_csv(file))
    assert got["power_electrical"] == expected.power_electrical
    assert got["excitation"]["excitation"] == "measured"
    code, out, _ = run(capsys, "power", *DEVICE, "--record", file)  # the table, too
    assert code == 0 and "segment_length" in out


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        # options that do not apply
        (["--psd", "1", "--f0", "10"], "`--f0` needs `--excitation band-pass|kanai-tajimi`"),
        (["--psd", "1", "--excitation", "white", "--zeta", "0.1"], "`--zeta` applies to"),
        (
            ["--psd", "1", "--excitation", "band-pass", "--f0", "1", "--zeta", "1", "--f-lo", "1"],
            "`--f-lo` applies to the band-limited excitation, not 'band-pass'",
        ),
        (
            [
                "--psd",
                "1",
                "--excitation",
                "band-limited",
                "--f-lo",
                "1",
                "--f-hi",
                "2",
                "--f0",
                "1",
            ],
            "`--f0` applies to the band-pass, kanai-tajimi excitation, not 'band-limited'",
        ),
        (
            [
                "--psd",
                "1",
                "--excitation",
                "band-pass",
                "--f0",
                "10",
                "--zeta",
                "0.2",
                "--method",
                "averaging",
            ],
            "`--method averaging` assumes white noise; the band-pass excitation needs "
            "`--method linearisation`",
        ),
        (
            [
                "--psd",
                "1",
                "--excitation",
                "kanai-tajimi",
                "--f0",
                "10",
                "--zeta",
                "0.2",
                "--method",
                "fpk-fast",
            ],
            "`--method fpk-fast` assumes white noise",
        ),
        (["--excitation", "pink", "--psd", "1"], "`--excitation` must be one of"),
        # missing values
        (["--psd", "1", "--excitation", "band-pass", "--f0", "10"], "`--zeta` is required"),
        (["--excitation", "band-pass", "--f0", "10", "--zeta", "0.1"], "`--psd` is required"),
        (["--psd", "1", "--excitation", "band-limited", "--f-lo", "4"], "`--f-hi` is required"),
        # bad values
        (
            ["--psd", "1", "--excitation", "band-pass", "--f0", "0", "--zeta", "0.1"],
            "`--f0` must be > 0",
        ),
        (
            ["--psd", "1", "--excitation", "kanai-tajimi", "--f0", "-2", "--zeta", "0.1"],
            "`--f0` must be > 0",
        ),
        (
            ["--psd", "1", "--excitation", "band-pass", "--f0", "10", "--zeta", "0"],
            "`--zeta` must be > 0",
        ),
        (
            ["--psd", "1", "--excitation", "band-pass", "--f0", "nan", "--zeta", "0.1"],
            "`--f0` must be finite",
        ),
        (
            ["--psd", "-1", "--excitation", "band-pass", "--f0", "10", "--zeta", "0.1"],
            "`--psd` must be > 0",
        ),
        (
            ["--psd", "1", "--excitation", "band-limited", "--f-lo", "20", "--f-hi", "4"],
            "`--f-hi` must be > `--f-lo` = 20.0 Hz",
        ),
        (
            ["--psd", "1", "--excitation", "band-limited", "--f-lo", "5", "--f-hi", "5"],
            "`--f-hi` must be > `--f-lo`",
        ),
        (
            ["--psd", "1", "--excitation", "band-limited", "--f-lo", "-1", "--f-hi", "5"],
            "`--f-lo` must be >= 0",
        ),
    ],
)
def test_refusals_and_bad_values(capsys, argv, fragment):
    power_error(capsys, [*DEVICE, *argv], fragment)


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        # the file's columns, quoted (not the option `--psd`)
        ("frequency,psd\n0,1\n10,-1\n20,0\n", "'psd' must be >= 0"),
        ("frequency,psd\n0,1\n10,1\n10,0\n", "'frequency' must be strictly increasing"),
        ("frequency,psd\n0,1\n20,1\n10,0\n", "'frequency' must be strictly increasing"),
        ("freq,psd\n0,1\n10,1\n", "must have the columns frequency, psd"),
        ("frequency,psd\n0,1\n10,x\n", "could not convert"),
        ("", "No columns"),
    ],
)
def test_bad_psd_file(tmp_path, capsys, content, fragment):
    file = tmp_path / "psd.csv"
    file.write_text(content)
    power_error(capsys, [*DEVICE, "--psd-file", str(file)], f"`--psd-file` {file}: ")
    power_error(capsys, [*DEVICE, "--psd-file", str(file)], fragment)


def test_bad_record(tmp_path, capsys):
    time = np.arange(256) / 100.0
    acceleration = np.sin(2 * np.pi * 5 * time)
    with_nan = acceleration.copy()
    with_nan[10] = np.nan
    file = write_record(tmp_path / "nan.csv", time, with_nan)
    power_error(capsys, [*DEVICE, "--record", file], "'base_acceleration' must be finite")
    uneven = time.copy()
    uneven[100] += 0.004
    file = write_record(tmp_path / "uneven.csv", uneven, acceleration)
    power_error(capsys, [*DEVICE, "--record", file], "'time' must be evenly spaced")
    power_error(capsys, [*DEVICE, "--record", file], f"`--record` {file}: ")
    nan_time = time.copy()
    nan_time[5] = np.nan
    file = write_record(tmp_path / "nan_time.csv", nan_time, acceleration)
    power_error(capsys, [*DEVICE, "--record", file], "'time' must be finite")


@pytest.mark.parametrize("option", ["--psd-file", "--record"])
def test_missing_files_and_folders(tmp_path, capsys, option):
    power_error(capsys, [*DEVICE, option, str(tmp_path / "none.csv")], f"`{option}`: no such file")
    power_error(
        capsys, [*DEVICE, option, str(tmp_path)], f"`{option}` must be a CSV file, got the folder"
    )


def test_file_options_exclude_the_others(tmp_path, capsys):
    file = write_table(tmp_path / "psd.csv", [0.0, 10.0, 20.0], [1.0, 1.0, 0.0])
    power_error(
        capsys,
        [*DEVICE, "--psd-file", file, "--psd", "1"],
        "`--psd-file` gives the whole spectrum; drop `--psd`",
    )
    power_error(
        capsys,
        [*DEVICE, "--psd-file", file, "--excitation", "band-pass", "--f0", "3"],
        "drop `--f0`, `--excitation`",
    )
    power_error(capsys, [*DEVICE, "--psd-file", file, "--record", file], "not both")
    power_error(
        capsys,
        [*DEVICE, "--psd-file", file, "--method", "averaging"],
        "`--method averaging` assumes white noise",
    )
