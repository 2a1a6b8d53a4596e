"""Identification of friction models (randvib.identification, CLI identify/validate)."""

import json

import numpy as np
import pytest

from randvib.cli import main
from randvib.deterministic import simulate_record
from randvib.excitation import band_limited_excitation
from randvib.identification import (
    Record,
    default_bounds,
    identify,
    normalised_cost,
    predict,
    read_record,
    validate,
)

TRUE = dict(m=0.0226, c=0.049, k=57.4, k3=70742.0, fc=0.0058)


def synthetic(
    seed=0, rms=1.07, duration=3.0, fs=500.0, kind="base_displacement", model="coulomb", params=TRUE
):
    ex = band_limited_excitation(duration, fs, rms, seed=seed)
    inp = ex.displacement if kind == "base_displacement" else ex.acceleration
    drive = ex.acceleration
    z = simulate_record(params, model, drive, 1 / fs, substeps=8).z[0]
    return Record(1 / fs, kind, inp, z, f"test{seed}")


@pytest.fixture(scope="module")
def record():
    return synthetic(kind="base_acceleration")


def test_cost_is_eq11():
    z = np.array([1.0, 2.0, 3.0, 4.0])
    assert normalised_cost(z, np.full(4, z.mean())) == pytest.approx(100.0)  # Eq. 12
    assert normalised_cost(z, z) == 0.0
    assert normalised_cost(z, z + 0.1) == pytest.approx(100 * 0.01 / np.var(z))


def test_noise_free_coulomb_recovered_within_one_percent(record):
    res = identify(record, "coulomb", m=TRUE["m"], popsize=30, maxiter=120, seed=1)
    assert res.cost < 1.0
    for name in ("c", "k", "k3", "fc"):
        assert res.parameters[name] == pytest.approx(TRUE[name], rel=0.01), name
    assert res.nfev >= 30 * 121
    assert set(res.to_dict()["parameters"]) == {"m", "c", "k", "k3", "fc"}


def test_true_parameters_score_zero_and_model_ranking(record):
    assert predict(TRUE, "coulomb", record).cost < 1e-6  # 4 vs 8 substeps, estimated v0
    viscous = identify(record, "viscous", m=TRUE["m"], popsize=20, maxiter=40, seed=0)
    # without friction the record cannot be matched as well (paper Fig. 7)
    assert viscous.cost > 10 * predict(TRUE, "coulomb", record).cost
    assert viscous.cost < 100


def test_force_input_identifies_the_mass():
    params = dict(m=0.5, c=2.0, k=800.0, k3=2e7)
    ex = band_limited_excitation(3.0, 400.0, 1.0, f_lo=2.0, f_hi=40.0, seed=2)
    force = ex.acceleration
    z = simulate_record(params, "none", force, 1 / 400, input_kind="force", substeps=8).z[0]
    rec = Record(1 / 400, "force", force, z)
    res = identify(rec, "viscous", popsize=30, maxiter=150, seed=0)
    assert "m" in res.free
    for name, value in params.items():
        assert res.parameters[name] == pytest.approx(value, rel=0.01), name
    lin = identify(rec, "viscous", fixed={"k3": 0}, popsize=20, maxiter=40, seed=0)
    assert lin.parameters["k3"] == 0.0 and "k3" not in lin.free


def test_default_bounds_contain_table2_values(record):
    box = default_bounds(record, "lugre", m=TRUE["m"])
    table2_lugre = dict(
        c=0.055, k=59.7, k3=64926, sigma0=1.98, sigma1=0.18, fc=0.0008, fs=0.008, vs=0.007
    )
    for name, value in table2_lugre.items():
        lo, hi = box[name]
        assert lo < value < hi, (name, lo, hi)
    assert 4.8e8 < default_bounds(record, "tanh", m=TRUE["m"])["beta"][1]


def test_validate_scores_each_record(record):
    other = synthetic(seed=1, rms=1.5, kind="base_acceleration")
    rows = validate(TRUE, "coulomb", [record, other])
    assert [r.record for r in rows] == ["test0", "test1"]
    assert all(r.cost < 1e-6 for r in rows)


# ------------------------------------------------------------------- CSV and CLI
def write_csv(path, record, **rename):
    frame = record.to_frame().rename(columns=rename)
    frame.to_csv(path, index=False)
    return path


def test_read_record_round_trip_and_mapping(tmp_path, record):
    path = write_csv(tmp_path / "r.csv", record)
    before = path.read_bytes()
    back = read_record(path)
    np.testing.assert_allclose(back.z, record.z)
    assert back.dt == pytest.approx(record.dt) and back.input_kind == "base_acceleration"
    assert path.read_bytes() == before  # input never modified
    mapped = write_csv(
        tmp_path / "m.csv", record, base_acceleration="acc", relative_displacement="laser"
    )
    frame = read_record(
        mapped, input_column="acc", input_kind="base_acceleration", output_column="laser"
    )
    np.testing.assert_allclose(frame.input, record.input)
    no_time = tmp_path / "nt.csv"
    record.to_frame().drop(columns="time").to_csv(no_time, index=False)
    assert read_record(no_time, sample_rate=500).dt == pytest.approx(1 / 500)
    assert read_record(path, rows=(10, 110)).n == 100


@pytest.mark.parametrize(
    "mutate, kwargs, match",
    [
        (
            lambda f: f.drop(columns="relative_displacement"),
            {},
            "output column `relative_displacement` not found",
        ),
        (lambda f: f.drop(columns="base_acceleration"), {}, "no input column"),
        (lambda f: f.rename(columns={"base_acceleration": "acc"}), {}, "no input column"),
        (lambda f: f.assign(force=1.0), {}, "several input columns"),
        (
            lambda f: f.assign(relative_displacement=f.relative_displacement.where(f.index != 7)),
            {},
            "column `relative_displacement` has 1 NaN.*row 7",
        ),
        (
            lambda f: f.assign(base_acceleration=f.base_acceleration.where(f.index != 3, np.inf)),
            {},
            "column `base_acceleration` has 1 NaN or infinite",
        ),
        (
            lambda f: f.assign(time=f.time.where(f.index != 50, f.time + 1e-4)),
            {},
            "column `time` is not uniformly sampled",
        ),
        (lambda f: f.drop(columns="time"), {}, "no `time` column; give the sample rate"),
        (lambda f: f, dict(sample_rate=1000), "`sample_rate` = 1000 Hz disagrees"),
        (lambda f: f.iloc[:3], {}, "at least 5"),
        (lambda f: f, dict(input_column="acc"), "input column `acc` not found"),
    ],
)
def test_bad_records(tmp_path, record, mutate, kwargs, match):
    path = tmp_path / "bad.csv"
    mutate(record.to_frame()).to_csv(path, index=False)
    with pytest.raises(ValueError, match=match):
        read_record(path, **kwargs)


def test_bad_identify_arguments(record):
    with pytest.raises(ValueError, match="`model` must be one of"):
        identify(record, "dry", m=0.02)
    with pytest.raises(ValueError, match="`m` \\(kg\\) is required"):
        identify(record, "coulomb")
    with pytest.raises(ValueError, match="`--bounds k`: lower 5.0 > upper 1.0"):
        identify(record, "coulomb", m=0.02, bounds={"k": (5, 1)})
    with pytest.raises(ValueError, match="`--fix beta`: unknown parameter for model 'coulomb'"):
        identify(record, "coulomb", m=0.02, fixed={"beta": 1.0})
    with pytest.raises(
        ValueError, match="has 30 samples; the lugre model with 8 free parameters needs at least 80"
    ):
        identify(record.rows(0, 30), "lugre", m=0.02)


def test_cli_identify_json_and_validate(tmp_path, capsys, record):
    data = write_csv(tmp_path / "r.csv", record.rows(0, 600))
    other = write_csv(tmp_path / "o.csv", synthetic(seed=3, duration=1.2, kind="base_acceleration"))
    params = tmp_path / "p.json"
    argv = [
        "identify", str(data), "--model", "coulomb", "--m", "0.0226", "--seed", "1",
        "--popsize", "16", "--generations", "15", "--json", "--save", str(params), "--no-polish",
    ]  # fmt: skip
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["model"] == "coulomb" and set(out["parameters"]) == {"m", "c", "k", "k3", "fc"}
    assert out["cost"] == pytest.approx(json.loads(params.read_text())["cost"])
    assert main(["validate", str(params), str(data), str(other), "--json"]) == 0
    scores = json.loads(capsys.readouterr().out)
    assert [r["record"] for r in scores["records"]] == ["r", "o"]
    assert scores["records"][0]["cost"] == pytest.approx(out["cost"], rel=1e-9)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--model", "dry", "--m", "1"], "argument --model: invalid choice: 'dry'"),
        (["--model", "coulomb"], "`m` (kg) is required"),
        (["--model", "coulomb", "--m", "0.02", "--fix", "k3"], "`--fix` expects NAME=VALUE"),
        (
            ["--model", "coulomb", "--m", "0.02", "--bounds", "k=1"],
            "`--bounds` expects NAME=LOWER:UPPER",
        ),
        (["--model", "coulomb", "--m", "0.02", "--rows", "a:b"], "`--rows` must be START:STOP"),
    ],
)
def test_cli_errors_are_one_line(tmp_path, capsys, record, extra, message):
    data = write_csv(tmp_path / "r.csv", record.rows(0, 200))
    assert main(["identify", str(data), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err


def test_cli_missing_file(capsys):
    assert main(["identify", "nope.csv", "--model", "coulomb", "--m", "1"]) == 2
    assert "does not exist" in capsys.readouterr().err
