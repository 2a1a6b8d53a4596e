"""Records: channels on one uniform time grid and their CSV reader (randvib.models.record)."""

import pickle

import numpy as np
import pytest

import randvib as rv
from randvib.models.record import GRID_TOLERANCE, Record, read_record

DT = 0.002


@pytest.fixture(scope="module")
def record():
    """A base-acceleration input and a relative displacement, 500 Hz, 2 s."""
    t = np.arange(1000) * DT
    rng = np.random.default_rng(0)
    return Record(
        DT,
        base_acceleration=rng.standard_normal(t.size),
        relative_displacement=1e-3 * np.sin(2 * np.pi * 8 * t),
        name="test",
    )


def write_csv(path, record, **rename):
    frame = record.to_frame().rename(columns=rename)
    frame.to_csv(path, index=False)
    return path


def test_channels_in_their_order_and_roles(record):
    assert list(record.channels) == ["base_acceleration", "relative_displacement"]
    assert record.input_kind == "base_acceleration"
    np.testing.assert_array_equal(record.input, record["base_acceleration"])
    np.testing.assert_array_equal(record.z, record["relative_displacement"])
    assert record.voltage is None and "voltage" not in record
    assert record.n == 1000 and record.dt == DT and record.sample_rate == 1 / DT
    np.testing.assert_array_equal(record.time, np.arange(1000) * DT)
    assert repr(record) == (
        "Record('test': 1000 samples at 500 Hz, 2 s; base_acceleration, relative_displacement)"
    )
    with pytest.raises(AttributeError, match="immutable"):
        record.dt = 1.0


def test_base_motion_has_several_inputs_named_in_the_refusal():
    motion = rv.band_limited_excitation(1.0, 200.0, 1.0, seed=0)
    assert list(motion.channels) == ["base_acceleration", "base_velocity", "base_displacement"]
    assert motion.dt == 1 / 200.0
    with pytest.raises(ValueError, match="several input channels.*choose one with `input_kind`"):
        motion.input_kind  # noqa: B018
    with pytest.raises(ValueError, match="no 'relative_displacement' channel"):
        motion.z  # noqa: B018


def test_rows_keep_the_samples_times_and_step(record):
    part = record.rows(100, 300)
    assert part.n == 200 and part.dt == record.dt and part.name == "test[100:300]"
    np.testing.assert_array_equal(part.time, record.time[100:300])
    np.testing.assert_array_equal(part.z, record.z[100:300])
    with pytest.raises(ValueError, match="has 3 samples; at least 5"):
        record.rows(0, 3)


def test_pickles(record):
    back = pickle.loads(pickle.dumps(record))
    assert back.dt == record.dt and back.name == record.name
    np.testing.assert_array_equal(back.z, record.z)


def test_the_grid_check_allows_one_percent_of_a_step():
    """Every sample within GRID_TOLERANCE of a step of t_0 + i dt, dt from the ends."""
    t = np.arange(100) * DT
    jitter = np.zeros(100)
    jitter[40] = 0.9 * GRID_TOLERANCE * DT
    inside = Record(time=t + jitter, force=np.ones(100))
    assert inside.dt == (t[-1] - t[0]) / 99
    jitter[40] = 1.1 * GRID_TOLERANCE * DT
    with pytest.raises(
        ValueError, match="`time` must be evenly spaced: sample 40 .* 1 % of a step"
    ):
        Record(time=t + jitter, force=np.ones(100))
    dropped = np.delete(np.arange(101) * DT, 60)  # one sample missing: a whole step
    with pytest.raises(ValueError, match="evenly spaced"):
        Record(time=dropped, force=np.ones(100))
    with pytest.raises(ValueError, match="`time` must increase"):
        Record(time=t[::-1], force=np.ones(100))
    # a step given beside the times is the record's step; the times must lie on its grid
    assert Record(DT, time=t, force=np.ones(100)).dt == DT
    with pytest.raises(ValueError, match="evenly spaced"):
        Record(1.05 * DT, time=t, force=np.ones(100))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(dt=DT, speed=np.ones(10)), "unknown channel\\(s\\) 'speed'.*channels are"),
        (dict(dt=DT), "has no channel"),
        (dict(force=np.ones(10)), "needs its sample interval `dt`"),
        (dict(dt=-1.0, force=np.ones(10)), "`dt` must be > 0"),
        (dict(dt=DT, force=np.ones(10), voltage=np.ones(9)), "differ in length"),
        (dict(dt=DT, force=np.ones((2, 5))), "`force` must be one-dimensional"),
        (dict(dt=DT, force=["a"] * 10), "`force` must be numeric"),
        (dict(time=np.arange(9) * DT, force=np.ones(10)), "`time` .* has 9 samples"),
        (dict(dt=DT, force=np.ones(4)), "has 4 samples; at least 5"),
    ],
)
def test_bad_records_are_refused_by_name(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Record(**kwargs)


def test_to_csv_never_overwrites_unless_asked(tmp_path, record):
    path = tmp_path / "r.csv"
    record.to_csv(path)
    with pytest.raises(FileExistsError, match="not overwritten"):
        record.to_csv(path)
    record.to_csv(path, overwrite=True)


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
        mapped,
        input_column="acc",
        input_kind="base_acceleration",
        output_column="laser",
        output_kind="relative_displacement",
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
            "`relative_displacement` must be finite: 1 NaN.*sample 7",
        ),
        (
            lambda f: f.assign(base_acceleration=f.base_acceleration.where(f.index != 3, np.inf)),
            {},
            "`base_acceleration` must be finite: 1 NaN or infinite",
        ),
        (
            lambda f: f.assign(time=f.time.where(f.index != 50, f.time + 1e-4)),
            {},
            "`time` must be evenly spaced: sample 50",
        ),
        (
            lambda f: f.drop(columns="time"),
            {},
            "no 'time' column \\(`time_column`\\); give the sample rate",
        ),
        (lambda f: f, dict(sample_rate=1000), "`sample_rate` = 1000 Hz disagrees"),
        (lambda f: f.iloc[:3], {}, "at least 5"),
        (
            lambda f: f,
            dict(input_column="acc"),
            "input column 'acc' \\(`input_column`\\) not found",
        ),
    ],
)
def test_bad_records(tmp_path, record, mutate, kwargs, match):
    path = tmp_path / "bad.csv"
    mutate(record.to_frame()).to_csv(path, index=False)
    with pytest.raises(ValueError, match=match):
        read_record(path, **kwargs)


# ------------------------------------------ files that are not CSV text, or too large
def test_sparse_file_refused_before_parsing_in_one_short_line(tmp_path, capsys):
    from _cli import one_line_error

    big = tmp_path / "big.csv"
    with open(big, "wb") as f:
        f.write(b"time,base_acceleration,relative_displacement\n")
        f.truncate(2 * 10**9)  # 2 GB, sparse: NUL bytes to the end, no disk used
    with pytest.raises(ValueError, match="holds NUL bytes") as info:
        read_record(big)
    assert len(str(info.value)) < 300  # the file's size named, none of its content
    code_argv = ["identify", str(big), "--model", "coulomb", "--m", "0.0226"]
    one_line_error(capsys, code_argv, "is not a CSV text file")
    one_line_error(capsys, ["power", "--preset", "figure9", "--record", str(big)], "NUL bytes")


def test_csv_that_cannot_fit_in_memory_is_refused_before_parsing(tmp_path, monkeypatch):
    from randvib import _resources

    path = tmp_path / "r.csv"
    path.write_text("time,base_acceleration,relative_displacement\n" + "0,0,0\n" * 1000)
    monkeypatch.setattr(_resources, "available_memory", lambda: 1000)
    with pytest.raises(ValueError, match=r"\(6.04 kB\) needs about 24.2 kB of memory"):
        read_record(path)


def test_message_about_columns_is_bounded(tmp_path):
    path = tmp_path / "wide.csv"
    header = ",".join(f"column_with_a_long_name_{i}" * 20 for i in range(500))
    path.write_text(header + "\n" + ",".join("0" * 500) + "\n")
    with pytest.raises(ValueError, match="no input column") as info:
        read_record(path)
    assert len(str(info.value)) < 600 and "492 more" in str(info.value)
