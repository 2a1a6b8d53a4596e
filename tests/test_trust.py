"""Issue 13: nothing lost, nothing silently wrong, no traceback, interrupts that interrupt.

Each test is one case of the issue (or a sibling found while fixing it) and
fails on the code before the fix: output paths checked before computing,
folder locks, checksummed resume, edited reports kept, parameter rules in
identify/validate, valid JSON, one-line messages at extreme values, memory
refused up front, Ctrl-C and killed parents.
"""

import _thread
import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numba
import numpy as np
import pytest
from _cli import one_line_error, run

import randvib as rv
import randvib.montecarlo.sweep as sweep_module
from randvib import _io, _resources
from randvib._resources import available_memory
from randvib.montecarlo.simulation import simulate
from randvib.montecarlo.sweep import SweepSettings, cartesian, run_sweep

ROOT = Path(__file__).resolve().parents[1]
BASE = rv.preset("figure9")
TINY = SweepSettings(
    dt=2e-4, window=0.2, burn_in=0.05, target_rel_ci=0.5, min_paths=8, batch_paths=8, max_paths=8
)


@pytest.fixture(scope="module")
def record_csv(tmp_path_factory):
    """A 2 s synthetic record of the Coulomb TD1 device, and its fitted-parameter file."""
    folder = tmp_path_factory.mktemp("records")
    path = folder / "rec.csv"
    record = rv.synthetic_record(
        rv.preset("coulomb-td1"), 2.0, duration=2.0, sample_rate=1000.0, seed=1
    )
    record.to_csv(path, float_format=None)
    params = folder / "params.json"
    params.write_text(
        json.dumps(
            {
                "model": "coulomb",
                "parameters": {"m": 0.0226, "c": 0.049, "k": 57.4, "k3": 70742.0, "fc": 0.0058},
                "settings": {"substeps": 4},
            }
        )
    )
    return path, params


def _fit_args(path, *extra):
    return ["identify", path, "--model", "coulomb", "--m", "0.0226", "--popsize", "8",
            "--generations", "2", "--no-progress", "--no-polish", *extra]  # fmt: skip


# ------------------------------------------------------------------ work lost
@pytest.mark.parametrize(
    "option, target, fragment",
    [
        ("--save", "missing/x.json", "does not exist"),
        ("--plot", "missing/x.png", "does not exist"),
        ("--save", "a_file/x.json", "is not a folder"),
        ("--plot", "a_file/x.png", "is not a folder"),
        ("--save", "a_folder", "is a folder"),
    ],
)
def test_identify_output_paths_checked_before_fitting(
    capsys, tmp_path, monkeypatch, record_csv, option, target, fragment
):
    (tmp_path / "a_file").write_text("x")
    (tmp_path / "a_folder").mkdir()
    monkeypatch.chdir(tmp_path)
    fitted = []
    monkeypatch.setattr("randvib.cli.identify.identify", lambda *a, **k: fitted.append(1))
    one_line_error(capsys, _fit_args(record_csv[0], option, target), fragment)
    assert fitted == []  # refused before the fit


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["validate", "{params}", "{rec}", "--plot", "a_file/sub"], "is a file"),
        (["record", "--preset", "figure9", "--rms", "2", "--out", "a_file/x.csv"], "not a folder"),
        (["record", "--preset", "figure9", "--rms", "2", "--out", "a_folder"], "is a folder"),
        (["study", "interaction", "--quick", "--out", "a_file/x"], "is a file"),
    ],
)
def test_other_output_paths_under_a_file_or_a_folder(
    capsys, tmp_path, monkeypatch, record_csv, argv, fragment
):
    (tmp_path / "a_file").write_text("x")
    (tmp_path / "a_folder").mkdir()
    monkeypatch.chdir(tmp_path)
    argv = [a.format(params=record_csv[1], rec=record_csv[0]) for a in argv]
    one_line_error(capsys, argv, fragment)


def test_result_that_cannot_be_written_is_kept_beside(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    where = _io.write_or_keep(tmp_path / "gone" / "fit.json", '{"J": 1}', "--save")
    assert where is not None and where.read_text() == '{"J": 1}'
    assert where.parent == Path(".") or where.parent.resolve() == tmp_path
    assert "could not write `--save`" in capsys.readouterr().err


def test_identify_save_failing_after_the_fit_keeps_the_result(
    capsys, tmp_path, monkeypatch, record_csv
):
    # The folder disappears during the fit: the result must still exist somewhere.
    monkeypatch.chdir(tmp_path)
    (tmp_path / "out").mkdir()
    real = rv.identify

    def fit_then_remove_folder(*args, **kwargs):
        result = real(*args, **kwargs)
        (tmp_path / "out").rmdir()
        return result

    monkeypatch.setattr("randvib.cli.identify.identify", fit_then_remove_folder)
    code, out, err = run(capsys, *_fit_args(record_csv[0], "--save", "out/fit.json", "--json"))
    assert code == 0
    kept = list(tmp_path.glob("randvib-unsaved-*.json"))
    assert len(kept) == 1 and json.loads(kept[0].read_text())["model"] == "coulomb"
    assert str(kept[0].name) in err


def _holder_script(folder, seconds):
    return textwrap.dedent(
        f"""
        import sys, time
        from randvib import _io
        _io.lock_folder({str(folder)!r})
        print("locked", flush=True)
        time.sleep({seconds})
        """
    )


def test_second_run_into_a_locked_folder_is_refused_naming_the_holder(tmp_path):
    folder = tmp_path / "res"
    folder.mkdir()
    holder = subprocess.Popen(
        [sys.executable, "-c", _holder_script(folder, 60)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(FileExistsError, match=f"in use by another randvib run.*{holder.pid}"):
            _io.prepare_output_dir(folder, {"grid": 1})
        assert not (folder / _io.METADATA_FILE).exists()  # nothing written
    finally:
        holder.kill()
        holder.wait()


def test_stale_lock_of_a_killed_run_is_recovered(tmp_path):
    folder = tmp_path / "res"
    folder.mkdir()
    holder = subprocess.Popen(
        [sys.executable, "-c", _holder_script(folder, 60)], stdout=subprocess.PIPE, text=True
    )
    assert holder.stdout.readline().strip() == "locked"
    holder.send_signal(signal.SIGKILL)  # no clean-up: the lock file stays
    holder.wait()
    assert (folder / _io.LOCK_FILE).exists()
    out = _io.prepare_output_dir(folder, {"grid": 1})
    assert json.loads((out / _io.LOCK_FILE).read_text())["pid"] == os.getpid()
    _io.unlock_folder(out)
    assert not (out / _io.LOCK_FILE).exists()


def _other_host_lock(folder, silent_seconds):
    """A lock written by a run on another host whose heartbeat stopped ``silent_seconds`` ago."""
    lock = folder / _io.LOCK_FILE
    holder = {"pid": 12345, "host": "node-17.cluster", "started": "2026-11-22T08:00:00+00:00"}
    lock.write_text(json.dumps(holder))
    beat = time.time() - silent_seconds
    os.utime(lock, (beat, beat))
    return lock


def test_another_hosts_lock_is_taken_over_once_its_heartbeat_stops(tmp_path):
    from randvib import _locks

    folder = tmp_path / "shared"
    folder.mkdir()
    lock = _other_host_lock(folder, _locks.STALE_AFTER_SECONDS + 60)
    out = _io.prepare_output_dir(folder, {"grid": 1})
    assert json.loads(lock.read_text())["pid"] == os.getpid()
    _io.unlock_folder(out)


def test_another_hosts_live_lock_is_refused_naming_it(tmp_path):
    from randvib import _locks

    folder = tmp_path / "shared"
    folder.mkdir()
    lock = _other_host_lock(folder, 5.0)  # heard from 5 s ago: alive
    with pytest.raises(FileExistsError, match="12345 on 'node-17.cluster'.*last heard from"):
        _io.prepare_output_dir(folder, {"grid": 1})
    assert json.loads(lock.read_text())["host"] == "node-17.cluster"  # untouched
    assert f"silent for {_locks.STALE_AFTER_SECONDS:.0f} s" in _locks._busy_message(
        folder, json.loads(lock.read_text())
    )


def test_a_holder_keeps_its_lock_alive(tmp_path, monkeypatch):
    """The heartbeat: a run's lock file is touched while the run lives, so another
    host never mistakes a long run for a dead one."""
    from randvib import _locks

    monkeypatch.setattr(_locks, "HEARTBEAT_SECONDS", 0.02)
    folder = tmp_path / "long-run"
    out = _io.prepare_output_dir(folder, {"grid": 1})
    lock = out / _io.LOCK_FILE
    old = time.time() - 3600
    os.utime(lock, (old, old))  # as if the last beat were an hour ago
    deadline = time.time() + 30
    while lock.stat().st_mtime < old + 1800 and time.time() < deadline:
        time.sleep(0.02)
    assert lock.stat().st_mtime > old + 1800, "the heartbeat did not touch the lock"
    _io.unlock_folder(out)


def test_simultaneous_runs_into_one_new_folder_one_wins(tmp_path):
    # Four runs of different grids start together into the same new folder:
    # exactly one owns it; the others are refused, none exits quietly.
    folder = tmp_path / "new"
    script = textwrap.dedent(
        f"""
        import sys, time
        from randvib import _io
        time.sleep(max(0.0, float(sys.argv[2]) - time.time()))
        try:
            _io.prepare_output_dir({str(folder)!r}, {{"grid": int(sys.argv[1])}})
        except FileExistsError as exc:
            print("refused", exc)
            sys.exit(3)
        time.sleep(1.0)
        print("owner")
        """
    )
    start = time.time() + 4.0
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", script, str(i), str(start)], stdout=subprocess.PIPE, text=True
        )
        for i in range(4)
    ]
    outs = [p.communicate(timeout=120)[0] for p in procs]
    codes = [p.returncode for p in procs]
    assert sorted(codes) == [0, 3, 3, 3], outs
    owner = codes.index(0)
    assert json.loads((folder / _io.METADATA_FILE).read_text())["identity"] == {"grid": owner}


def test_atomic_writes_from_many_writers_share_no_temporary_file(tmp_path):
    target = tmp_path / "results.csv"
    errors = []

    def writer(i):
        try:
            for _ in range(50):
                _io.atomic_write_text(target, f"writer {i}\n" * 100)
        except Exception as exc:  # a shared temporary name crashes here
            errors.append(exc)

    threads = [threading.Thread(target=writer, args=(i,)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    lines = set(target.read_text().splitlines())
    assert len(lines) == 1  # one writer's whole file, never a mixture
    assert list(tmp_path.iterdir()) == [target]  # no temporary left behind


def test_edited_report_is_not_overwritten_without_force(tmp_path):
    from randvib.studies.report import write_report

    report = write_report(tmp_path, "T", [("A", "body")])
    write_report(tmp_path, "T", [("A", "body")])  # a rerun may rewrite its own file
    report.write_text(report.read_text() + "\nmy notes\n")
    with pytest.raises(FileExistsError, match="changed since randvib wrote it"):
        write_report(tmp_path, "T", [("A", "new body")])
    assert "my notes" in report.read_text()
    with _io.overwrite_edited():
        write_report(tmp_path, "T", [("A", "new body")])
    assert "new body" in report.read_text() and "my notes" not in report.read_text()


def test_study_rerun_refuses_edited_figure_and_force_allows(capsys, tmp_path, monkeypatch):
    from randvib.studies import report

    def fake_study(out_dir, *, quick, seed, workers, scheduler, progress):
        out = _io.prepare_output_dir(out_dir, {"study": "fake"})
        from randvib.figure_style import new_figure, save_figure

        save_figure(new_figure()[0], out / "figure.png")  # a study's figure style
        return report.write_report(out, "fake", [])

    monkeypatch.setattr("randvib.cli.study.load_study", lambda name: fake_study)
    out = tmp_path / "study"
    assert run(capsys, "study", "interaction", "--out", out)[0] == 0
    (out / "figure.png").write_bytes(b"edited by hand")
    one_line_error(capsys, ["study", "interaction", "--out", out], "--force")
    assert (out / "figure.png").read_bytes() == b"edited by hand"
    assert run(capsys, "study", "interaction", "--out", out, "--force")[0] == 0
    assert (out / "figure.png").read_bytes().startswith(b"\x89PNG")
    assert not (out / _io.LOCK_FILE).exists()  # released when the study ends


@pytest.mark.parametrize("bad", ["list", "folder"])
def test_metadata_that_is_a_list_or_a_folder_is_named(capsys, tmp_path, bad):
    meta = tmp_path / _io.METADATA_FILE
    if bad == "list":
        meta.write_text("[1, 2]")
    else:
        meta.mkdir()
    with pytest.raises(FileExistsError, match="not a randvib metadata file"):
        _io.prepare_output_dir(tmp_path, {"grid": 1})


# ------------------------------------------------------------------ silently wrong
def _corrupt(points, how):
    json0, npy0 = points / "00000.json", points / "00000.npy"
    if how == "doubled power":
        stored = json.loads(json0.read_text())
        stored["row"]["power_electrical"] *= 2
        json0.write_text(json.dumps(stored))
    elif how == "empty object":
        json0.write_text("{}")
    elif how == "zero-byte json":
        json0.write_bytes(b"")
    elif how == "nan in npy":
        arr = np.load(npy0)
        arr[0, 0] = np.nan
        np.save(npy0, arr)
    elif how == "another point's arrays":
        npy0.write_bytes((points / "00001.npy").read_bytes())
    elif how == "truncated npy":
        npy0.write_bytes(npy0.read_bytes()[:-40])
    elif how == "npy missing":
        npy0.unlink()


@pytest.mark.parametrize(
    "how",
    [
        "doubled power",
        "empty object",
        "zero-byte json",
        "nan in npy",
        "another point's arrays",
        "truncated npy",
        "npy missing",
    ],
)
def test_corrupted_point_is_named_and_recomputed(tmp_path, monkeypatch, how):
    pts = cartesian(psd=[1.0], fc=[0.0, 0.01])
    first = run_sweep(BASE, pts, TINY, out_dir=tmp_path, workers=1, progress=False)
    _corrupt(tmp_path / "points", how)
    calls = []
    real = sweep_module.run_point

    def counting(base, point, settings, threads=1):
        calls.append(point["fc"])
        return real(base, point, settings, threads)

    monkeypatch.setattr(sweep_module, "run_point", counting)
    with pytest.warns(UserWarning, match="sweep point 0 .* unusable"):
        again = run_sweep(BASE, pts, TINY, out_dir=tmp_path, workers=1, progress=False)
    assert calls == [0.0]  # only the bad point was recomputed
    cols = ["power_electrical", "velocity_variance", "n_paths"]
    assert again.table[cols].equals(first.table[cols])  # same seed: the same numbers
    assert np.array_equal(again.per_path[0], first.per_path[0])


def test_results_csv_is_rebuilt_from_the_points(tmp_path):
    pts = cartesian(psd=[1.0], fc=[0.0, 0.01])
    run_sweep(BASE, pts, TINY, out_dir=tmp_path, workers=1, progress=False)
    good = (tmp_path / "results.csv").read_text()
    (tmp_path / "results.csv").write_text("point,power_electrical\n0,123\n")
    run_sweep(BASE, pts, TINY, out_dir=tmp_path, workers=1, progress=False)
    assert (tmp_path / "results.csv").read_text() == good


def test_validate_settings_checked_as_identify_does(capsys, tmp_path, record_csv):
    rec, params = record_csv
    one_line_error(capsys, ["validate", params, rec, "--skip", "100000"], "`--skip` = 100000")
    one_line_error(capsys, ["validate", params, rec, "--substeps", "0"], "argument --substeps")
    one_line_error(capsys, ["validate", params, rec, "--set", "bogus=1"], "--set bogus")
    one_line_error(capsys, ["validate", params, rec, "--set", "fc=-1"], "`--set fc` must be >= 0")
    bad = tmp_path / "bad.json"
    data = json.loads(params.read_text())
    for settings, fragment in [
        ({"substeps": 0}, "substeps"),
        ({"hold": "bogus"}, "hold"),
        ({"skip": -5}, "skip"),
    ]:
        bad.write_text(json.dumps({**data, "settings": settings}))
        one_line_error(capsys, ["validate", bad, rec], f"{bad}")
        one_line_error(capsys, ["validate", bad, rec], fragment)
    bad.write_text(json.dumps({**data, "parameters": {**data["parameters"], "k": -1}}))
    one_line_error(capsys, ["validate", bad, rec], "`k` must be > 0")


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--fix", "fc=-1"], "`--fix fc` must be >= 0"),
        (["--bounds", "k=-10:-1"], "`--bounds k` must be > 0"),
        (["--fix", "k=0"], "`--fix k` must be > 0"),
        (["--bounds", "c=0:inf"], "must be finite"),
    ],
)
def test_identify_fixed_values_and_bounds_obey_parameter_rules(capsys, record_csv, extra, fragment):
    one_line_error(capsys, _fit_args(record_csv[0], *extra), fragment)


@pytest.mark.parametrize(
    "extra",
    [["--fix", "k3=1e308"], ["--bounds", "k=1e300:1e308"], ["--bounds", "c=1e300:1e308"]],
)
def test_identify_unsimulable_fixed_values_refused_before_searching(
    capsys, monkeypatch, record_csv, extra
):
    """A fixed value or bound at which the model cannot be simulated is refused
    after one batched probe of the bounds' corners, before the search runs."""

    def no_search(*args, **kwargs):
        raise AssertionError("the search ran")

    monkeypatch.setattr("randvib.identification.identify.sade", no_search)
    one_line_error(capsys, _fit_args(record_csv[0], *extra), "nothing was searched")


def test_identify_probe_refuses_nothing_a_search_can_fit(record_csv):
    from randvib.identification.identify import identify
    from randvib.models.record import read_record

    fit = identify(read_record(record_csv[0]), "coulomb", m=0.0226, popsize=8, maxiter=2,
                   polish=False, fixed={"k3": 70742.0})  # fmt: skip
    assert math.isfinite(fit.cost)


@pytest.mark.parametrize(
    "device, fragment",
    [
        (["--m", "1e308"], "no finite result"),
        (["--c-m", "0", "--c-e", "0", "--friction", "coulomb", "--fc", "0"], "no stationary"),
        (["--c-m", "0", "--c-e", "0", "--friction", "none"], "no stationary"),
        (["--k3", "1e308"], "no finite result"),
        (["--psd", "1e308", "--method", "fpk-fast"], "no finite result"),
        (["--m", "1e-300", "--method", "fpk-fast"], "no finite result"),
        (["--excitation", "band-pass", "--f0", "1e308", "--zeta", "0.1"], "no finite result"),
        (["--alpha", "1e308", "--r-load", "1", "--r-coil", "1"], "not a finite number"),
    ],
)
def test_power_never_prints_nan(capsys, device, fragment):
    argv = ["power", "--preset", "figure9", "--psd", "1", *device]
    one_line_error(capsys, argv, fragment)
    one_line_error(capsys, [*argv, "--json"], fragment)


def test_json_output_is_always_valid_json():
    text = _io.dumps({"a": float("nan"), "b": [1.0, float("inf")], "c": {"d": -math.inf}})
    data = json.loads(text, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    assert data["a"] is None and data["b"] == [1.0, None] and data["c"]["d"] is None
    assert set(data["null_reasons"]) == {"a", "b[1]", "c.d"}


# ------------------------------------------------------------------ one-line messages
@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["--seed", str(2**64)], "argument --seed: must be an integer in 0 .."),
        (["--seed", "-1"], "argument --seed"),
        (["--m", "1e308"], "linearised scales"),
        (["--k3", "1e308"], "linearised scales"),
        (["--psd", "1e308"], "linearised scales"),
        (["--t-end", "1e23"], "steps per path"),
        (["--paths", str(10**23)], "of memory"),
        # found by the fuzz test under another seed: a step warning came before the refusal
        (["--paths", str(2**63), "--dt", "0.001953125"], "reduce `--paths`, `histogram_bins`"),
        (["--dt", "1e-300"], "steps per path"),
    ],
)
def test_simulate_extreme_values_one_line(capsys, argv, fragment):
    base = ["simulate", "--preset", "figure9", "--psd", "1", "--paths", "2"]
    one_line_error(capsys, [*base, "--t-end", "0.1", "--burn-in", "0", *argv], fragment)


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--lowpass", "1e-308"], "`--lowpass` must be at least"),
        (["--seed", "-1"], "argument --seed: must be an integer in 0 .."),
        (["--sample-rate", "1e-308", "--time-column", "none"], "search bounds of"),
    ],
)
def test_identify_extreme_settings_one_line(capsys, record_csv, extra, fragment):
    one_line_error(capsys, _fit_args(record_csv[0], *extra), fragment)


def test_record_folder_and_constant_column_named(capsys, tmp_path, record_csv):
    one_line_error(capsys, _fit_args(tmp_path), "is a folder")
    one_line_error(capsys, ["validate", tmp_path, record_csv[0]], "is a folder")
    text = record_csv[0].read_text().splitlines()
    const = tmp_path / "const.csv"
    const.write_text(
        "\n".join([text[0]] + [",".join(line.split(",")[:2] + ["0.001"]) for line in text[1:]])
    )
    one_line_error(capsys, _fit_args(const), "constant")


def test_unexpected_exception_is_one_line_exit_1(capsys, monkeypatch):
    def broken(args):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr("randvib.cli.power.run", broken)
    monkeypatch.delenv("RANDVIB_TRACEBACK", raising=False)
    code, out, err = run(capsys, "power", "--preset", "figure9", "--psd", "1")
    assert code == 1 and "internal error: ZeroDivisionError" in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_unreachable_scheduler_fails_fast_with_a_message(monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr(sweep_module, "SCHEDULER_TIMEOUT", 2)
    with pytest.raises(ValueError, match="cannot connect to a Dask scheduler"):
        sweep_module.make_executor(scheduler="tcp://127.0.0.1:1")


# ------------------------------------------------------------------ resources, interrupts
def test_work_that_cannot_fit_is_refused_with_the_estimate():
    with pytest.raises(ValueError, match="needs about .* of memory"):
        simulate(BASE, 1.0, t_end=0.1, dt=1e-4, n_paths=8, histogram_bins=10**12)
    # the case, killed at 24 GB: counts, their sum and densities exceed the memory
    if available_memory() < 8 * 8 * 10**9:
        with pytest.raises(ValueError, match="needs about .* of memory"):
            simulate(BASE, 1.0, t_end=0.1, dt=1e-4, n_paths=8, histogram_bins=10**9)


def test_population_that_cannot_fit_is_refused(capsys, record_csv):
    one_line_error(capsys, _fit_args(record_csv[0], "--popsize", "100000000"), "of memory")


def test_step_advice_never_says_dt_at_most_zero(monkeypatch):
    from randvib.montecarlo.step_check import LinearTestSystem

    monkeypatch.setattr(LinearTestSystem, "largest_step", lambda *a, **k: 0.0)
    with pytest.raises(ValueError, match="too large") as info:
        simulate(BASE, 1.0, t_end=10.0, dt=0.5, n_paths=2, progress=False)
    assert "dt <= 0 s" not in str(info.value)


def _probe_clock(seconds_per_probe):
    """A clock on which the timed probe lasts ``seconds_per_probe``."""
    ticks = iter(np.arange(100) * seconds_per_probe)
    return lambda: float(next(ticks))


@pytest.mark.parametrize("probe_seconds, warned", [(1000.0, True), (1e-9, False)])
def test_long_run_estimate_follows_the_measured_speed(monkeypatch, probe_seconds, warned):
    """The announcement uses the speed of a timed probe, not a fixed rate: the same
    run is announced on a (simulated) slow machine and not on a fast one."""
    import warnings

    from randvib._resources import LongRunWarning, duration_text
    from randvib.montecarlo import kernel, resources

    monkeypatch.setattr(resources, "PATH_STEPS_PER_SECOND", 1.0)  # a run that could be long
    monkeypatch.setattr(_resources, "clock", _probe_clock(probe_seconds))
    n_paths, n_steps = 4, 500
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        simulate(BASE, 1.0, t_end=n_steps * 1e-4, dt=1e-4, n_paths=n_paths, progress=False)
    said = [str(w.message) for w in caught if issubclass(w.category, LongRunWarning)]
    assert bool(said) is warned
    if warned:
        # the probe ran every path (<= LANES x threads) for every step of this short run
        probe_paths = min(n_paths, kernel.LANES * numba.get_num_threads())
        expected = n_paths * n_steps / (probe_paths * n_steps / probe_seconds)
        assert f"will take about {duration_text(expected)} (at the speed measured here)" in said[0]


@pytest.mark.parametrize("probe_seconds, warned", [(1e4, True), (1e-9, False)])
def test_identification_estimate_follows_the_measured_speed(
    monkeypatch, record_csv, probe_seconds, warned
):
    """identify times its probes of the bounds and announces a long search at that speed."""
    import warnings

    import randvib.identification.identify as driver
    from randvib._resources import LongRunWarning, duration_text

    monkeypatch.setattr(_resources, "clock", _probe_clock(probe_seconds))
    probed = []
    points = driver.probe_points
    monkeypatch.setattr(
        driver, "probe_points", lambda space: probed.append(points(space)) or probed[-1]
    )
    record = rv.read_record(record_csv[0])
    settings = rv.SearchSettings(popsize=6, maxiter=1, polish=False)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rv.identify(record, "coulomb", m=0.0226, search=settings)
    said = [str(w.message) for w in caught if issubclass(w.category, LongRunWarning)]
    assert bool(said) is warned
    if warned:
        # popsize x (maxiter + 1) runs at the speed of len(probes) runs in probe_seconds
        expected = 6 * 2 / (len(probed[0]) / probe_seconds)
        assert f"will take about {duration_text(expected)} (at the speed measured here)" in said[0]


def _interrupt_after(seconds):
    timer = threading.Timer(seconds, _thread.interrupt_main)
    timer.start()
    return timer


def test_ctrl_c_stops_a_running_simulation():
    # compiled first, so that the interrupt lands inside the compiled loop
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)
    # 4e9 path-steps: minutes at the least on any machine; Ctrl-C after 1 s
    kwargs = dict(t_end=2000.0, dt=1e-4, n_paths=200, progress=False)
    timer = _interrupt_after(1.0)
    started = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        simulate(BASE, 1.0, **kwargs)
    timer.cancel()
    assert time.perf_counter() - started < 60  # stopped, not run to the end


def test_ctrl_c_in_the_cli_exits_130(capsys):
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)
    timer = _interrupt_after(1.0)
    code, out, err = run(capsys, "simulate", "--preset", "figure9", "--psd", "1",
                         "--paths", "200", "--t-end", "2000", "--dt", "1e-4")  # fmt: skip
    timer.cancel()
    assert code == 130 and "interrupted" in err and "Traceback" not in err


def test_sweep_workers_end_when_the_sweep_is_killed(tmp_path):
    script = textwrap.dedent(
        """
        import os, sys, time
        sys.path.insert(0, sys.argv[1])
        from trust_worker import pid
        from randvib.montecarlo.sweep import make_executor
        if __name__ == "__main__":
            pool, close = make_executor(workers=2)
            print(" ".join(map(str, set(pool.map(pid, range(16))))), flush=True)
            time.sleep(120)
        """
    )
    (tmp_path / "trust_worker.py").write_text(
        "import os, time\ndef pid(_):\n    time.sleep(0.2)\n    return os.getpid()\n"
    )
    (tmp_path / "main.py").write_text(script)
    parent = subprocess.Popen(
        [sys.executable, str(tmp_path / "main.py"), str(tmp_path)],
        stdout=subprocess.PIPE,
        text=True,
        env={
            **os.environ,
            "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
        },
    )
    workers = [int(p) for p in parent.stdout.readline().split()]
    assert workers
    parent.send_signal(signal.SIGKILL)
    parent.wait()
    deadline = time.monotonic() + 30
    alive = workers
    while alive and time.monotonic() < deadline:
        time.sleep(0.2)
        alive = [p for p in workers if _alive(p)]
    assert alive == []


def test_sweep_workers_ignore_ctrl_c_while_they_are_still_starting(tmp_path):
    """Found by CI: a Ctrl-C that reached a worker while it was still importing
    (before its initializer could ignore SIGINT) printed a KeyboardInterrupt
    traceback from multiprocessing's spawn_main. SIGINT sent to every worker
    the moment they are spawned, long before any has imported randvib: the pool
    still works and nothing is written to stderr."""
    script = textwrap.dedent(
        """
        import os, signal
        from randvib.montecarlo.sweep import make_executor
        if __name__ == "__main__":
            pool, close = make_executor(workers=2)
            futures = [pool.submit(abs, i) for i in range(-8, 0)]  # spawns both workers
            pids = [p.pid for p in pool._processes.values()]
            for pid in pids:
                os.kill(pid, signal.SIGINT)
            print(len(pids), sum(f.result() for f in futures), flush=True)
            close()
        """
    )
    (tmp_path / "main.py").write_text(script)
    done = subprocess.run(
        [sys.executable, str(tmp_path / "main.py")],
        capture_output=True,
        text=True,
        timeout=120,
        env=_subprocess_env(),
    )
    assert (done.returncode, done.stdout.split(), done.stderr) == (0, ["2", "36"], "")


def _alive(pid):
    try:
        os.waitpid(pid, os.WNOHANG)  # reap if it happens to be our child
    except ChildProcessError:
        pass
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    status = Path(f"/proc/{pid}/status")
    return not (status.exists() and "zombie" in status.read_text())


def test_readme_sweep_example_has_the_main_guard():
    readme = (ROOT / "README.md").read_text()
    block = readme[readme.index("from randvib.montecarlo.sweep import SweepSettings") :]
    block = block[: block.index("```")]
    assert 'if __name__ == "__main__":' in block
    assert block.index("__main__") < block.index("run_sweep(")
    assert "trust" in readme[readme.index("scheduler=` (and `--scheduler`)") :][:300]


def test_unreadable_stored_fit_is_named_and_fitted_again(tmp_path, record_csv):
    from randvib.models.record import read_record
    from randvib.studies.campaign import identify_cached

    path = tmp_path / "fit.json"
    path.write_text("")  # a zero-byte file left by a crash
    record = read_record(record_csv[0])
    kwargs = dict(m=0.0226, popsize=8, maxiter=2, polish=False)
    with pytest.warns(UserWarning, match="fit.json.* unusable"):
        fit = identify_cached(path, record, "coulomb", **kwargs)
    again = identify_cached(path, record, "coulomb", **kwargs)  # now loaded, not refitted
    assert again.parameters == fit.parameters and json.loads(path.read_text())["model"] == "coulomb"


def test_record_seed_out_of_range_named(capsys, tmp_path):
    argv = ["record", "--preset", "figure9", "--rms", "2", "--out", tmp_path / "x.csv"]
    one_line_error(capsys, [*argv, "--seed", "-1"], "argument --seed: must be an integer in 0 ..")
    one_line_error(capsys, [*argv, "--duration", "1e23"], "of memory")


def test_ctrl_c_in_a_study_exits_130_and_releases_its_folder(capsys, tmp_path, monkeypatch):
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)

    def long_study(out_dir, *, quick, seed, workers, scheduler, progress):
        out = _io.prepare_output_dir(out_dir, {"study": "long"})
        _io.write_tracked(out / "first.csv", "finished part\n")
        simulate(BASE, 1.0, t_end=2000.0, dt=1e-4, n_paths=200, progress=False)

    monkeypatch.setattr("randvib.cli.study.load_study", lambda name: long_study)
    timer = _interrupt_after(1.0)
    code, out, err = run(capsys, "study", "interaction", "--out", tmp_path / "s")
    timer.cancel()
    assert code == 130 and "Traceback" not in err
    assert (tmp_path / "s" / "first.csv").read_text() == "finished part\n"  # kept
    assert not (tmp_path / "s" / _io.LOCK_FILE).exists()


# ------------------------------------------------------------------ SIGTERM, Ctrl-C on a pool
def _subprocess_env():
    return {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
        "NUMBA_NUM_THREADS": "1",
    }


def test_sigterm_stops_simulate_and_exits_143():
    simulate(BASE, 1.0, t_end=0.01, dt=1e-4, n_paths=2, progress=False)  # numba cache warm
    # 4e10 path-steps: its LongRunWarning is printed once the run starts
    argv = ["simulate", "--preset", "figure9", "--psd", "1", "--paths", "200",
            "--t-end", "20000", "--dt", "1e-4"]  # fmt: skip
    child = subprocess.Popen(
        [sys.executable, "-m", "randvib", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_subprocess_env(),
    )
    assert "will take about" in child.stderr.readline()
    time.sleep(0.5)
    child.send_signal(signal.SIGTERM)
    out, err = child.communicate(timeout=60)
    assert child.returncode == 143, err
    assert "terminated" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


SWEEP_STUDY = """
import sys
import randvib as rv
import randvib.cli.study
from randvib.cli import main
from randvib.montecarlo.sweep import SweepSettings, cartesian, run_sweep


def sweep_study(out_dir, *, quick, seed, workers, scheduler, progress):
    # 2000 small points on 2 worker processes: minutes, far longer than the test waits
    settings = SweepSettings(dt=2e-4, window=1.0, burn_in=0.05, target_rel_ci=0.5,
                             min_paths=8, batch_paths=8, max_paths=8)
    points = cartesian(psd=[1.0 + i / 1000 for i in range(2000)])
    run_sweep(rv.preset("figure9"), points, settings, out_dir=out_dir, workers=workers,
              progress=False)


if __name__ == "__main__":
    randvib.cli.study.load_study = lambda name: sweep_study
    sys.exit(main(["study", "interaction", "--out", sys.argv[1], "--workers", "2"]))
"""


def _children(pid):
    """Process ids whose parent is ``pid`` (Linux /proc)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


@pytest.mark.parametrize(
    "how, code",
    [("ctrl-c", 130), ("sigterm", 143)],
)
def test_interrupted_process_pool_sweep_keeps_points_and_ends_workers(tmp_path, how, code):
    """Ctrl-C (SIGINT to the whole process group, as a terminal sends it) or
    SIGTERM (to the parent only) on a sweep over 2 worker processes: exit
    130 / 143, no worker left, the finished points kept and valid, the lock gone."""
    simulate(BASE, 1.0, t_end=0.01, dt=2e-4, n_paths=2, progress=False)  # numba cache warm
    script, out = tmp_path / "sweep_study.py", tmp_path / "out"
    script.write_text(SWEEP_STUDY)
    child = subprocess.Popen(
        [sys.executable, str(script), str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_subprocess_env(),
        start_new_session=True,  # its own process group, as a shell job
    )
    deadline = time.monotonic() + 120
    while not list(out.glob("points/*.json")) and time.monotonic() < deadline:
        assert child.poll() is None, child.communicate()
        time.sleep(0.1)
    workers = _children(child.pid)
    assert len(workers) >= 2  # the two workers (and spawn's resource tracker)
    if how == "ctrl-c":
        os.killpg(child.pid, signal.SIGINT)
    else:
        child.send_signal(signal.SIGTERM)
    _, err = child.communicate(timeout=60)
    assert child.returncode == code, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    deadline = time.monotonic() + 30
    while any(_alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not [p for p in workers if _alive(p)]
    assert not (out / _io.LOCK_FILE).exists()
    points = sorted(out.glob("points/*.json"))
    assert 1 <= len(points) < 2000
    for p in points:
        stored = json.loads(p.read_text())
        assert math.isfinite(stored["row"]["power_electrical"])


def test_record_extreme_excitation_names_the_excitation(capsys, tmp_path):
    argv = ["record", "--preset", "figure9", "--out", tmp_path / "x.csv"]
    for extra in (["--rms", "1e308"], ["--psd", "1e308"]):
        one_line_error(capsys, [*argv, *extra], "`excitation`")
    code, _, err = run(capsys, *argv, "--rms", "1e308")
    assert "input_values" not in err


INTEGER_OPTIONS = [
    (["simulate", "--preset", "figure9", "--psd", "1"], "--paths", 1),
    (["simulate", "--preset", "figure9", "--psd", "1"], "--threads", 1),
    (["simulate", "--preset", "figure9", "--psd", "1"], "--seed", 0),
    (["simulate", "--preset", "figure9"], "--segments", 2),
    (["record", "--preset", "figure9", "--rms", "1", "--out", "x.csv"], "--substeps", 1),
    (["identify", "rec.csv", "--model", "coulomb"], "--popsize", 6),
    (["identify", "rec.csv", "--model", "coulomb"], "--generations", 0),
    (["validate", "p.json", "rec.csv"], "--skip", 0),
    (["validate", "p.json", "rec.csv"], "--substeps", 1),
    (["study", "figure9", "--out", "o"], "--workers", 1),
]


@pytest.mark.parametrize("argv, option, minimum", INTEGER_OPTIONS)
def test_integer_options_named_and_accept_float_notation(capsys, argv, option, minimum):
    """Every integer option: a non-integer, 'nan', a value below its minimum or
    beyond any count is refused naming the option (never 'invalid int value' or
    a library argument); float notation of an integer (1e1) is parsed."""
    from randvib._validation import integer_option

    for bad in ("0.5", "nan", "1e999999999", "abc", str(minimum - 1)):
        one_line_error(capsys, [*argv, f"{option}={bad}"], f"argument {option}: must be an integer")
    parse = integer_option(minimum)
    assert parse("1e1") == 10 and parse(f"{minimum}.0") == minimum and parse("1e23") == 10**23


def test_own_refusal_is_not_called_a_float64_overflow(capsys):
    """Found by the fuzz test over the new options: a free mass (k = k3 = 0) under a
    band-pass input was refused with "outside the range float64 can represent"
    appended to the real reason."""
    code, _, err = run(capsys, "power", "--preset", "figure9", "--psd", "1", "--excitation",
                       "band-pass", "--f0", "1", "--zeta", "0.1", "--k", "0", "--k3", "0")  # fmt: skip
    assert code == 2 and "confining potential" in err and "float64" not in err


def test_coupling_overflow_is_a_value_error():
    """Found by the fuzz test: alpha = 1e308 raised OverflowError from alpha**2."""
    from randvib.models.coupling import Resistive

    with pytest.raises(ValueError, match="overflows float64"):
        rv.Harvester.with_coupling(0.02, 0.1, 50.0, Resistive(1e308, 100.0, 10.0))


@pytest.mark.parametrize(
    "stop, code",
    [(KeyboardInterrupt, 130), ("sigterm", 143)],
)
def test_study_script_main_stops_with_one_line(capsys, tmp_path, stop, code):
    """``python studies/NAME.py OUT``: Ctrl-C and SIGTERM end with 130 / 143 and
    one line (they printed a KeyboardInterrupt traceback)."""
    from randvib.studies import script_main

    def run_study(out_dir, *, quick, seed, workers, scheduler, progress):
        """A study stopped while it runs."""
        if stop == "sigterm":
            os.kill(os.getpid(), signal.SIGTERM)  # handled: raises Terminated here
            time.sleep(5)
        raise stop()

    run_study.__module__ = __name__
    assert script_main(run_study, [str(tmp_path / "o")]) == code
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


NARROW_BAND = ["--preset", "figure9", "--psd", "1", "--excitation", "band-pass", "--f0", "1",
               "--zeta", "0.01"]  # fmt: skip


@pytest.mark.parametrize(
    "device",
    [
        # a soft device with a coil at the band's centre: the search's trial c_eq overflows
        [
            "--coupling",
            "inductive",
            "--alpha",
            "1",
            "--r-load",
            "10",
            "--r-coil",
            "1",
            "--inductance",
            "1e-4",
            "--k",
            "1",
            "--k3",
            "10",
        ],  # fmt: skip
        # a double well: a trial k_eq on the solver's floor (an eigenvalue rounding to 0)
        ["--k", "-1", "--k3", "1"],
    ],
    ids=["soft-coil", "double-well"],
)
def test_linearisation_without_a_fixed_point_says_so(capsys, device):
    """At ordinary values these were refused as "outside the range float64 can represent"
    (soft coil) or as the device having "an eigenvalue with non-negative real part
    (0+0j)" (double well): both were the solver's trial steps, not the device."""
    code, _, err = run(capsys, "power", *NARROW_BAND, *device)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "statistical linearisation found no fixed point" in err
    assert "`randvib simulate`" in err and "float64" not in err and "0+0j" not in err


def test_float64_is_blamed_only_for_extreme_values():
    from randvib.analytic.prediction import _out_of_range

    ordinary = _out_of_range("fpk", rv.preset("figure9"), 1.0, "LinAlgError: x")
    assert "float64" not in ordinary
    extreme = _out_of_range("fpk", rv.preset("figure9").updated(k3=1e250), 1.0, "LinAlgError: x")
    assert "k3 = 1e+250 is beyond the range this method can compute in float64" in extreme
    tiny = _out_of_range("fpk", rv.preset("figure9"), 1e-300, "LinAlgError: x")
    assert "psd = 1e-300 is beyond" in tiny


def _value_options(command: str):
    """(flag, dest) of every option of ``command`` that takes a value (not a choice or a switch)."""
    from randvib.cli import build_parser

    parser = next(a for a in build_parser()._actions if a.dest == "command").choices[command]
    for action in parser._actions:
        longs = [o for o in action.option_strings if o.startswith("--")]
        if longs and action.nargs != 0 and action.choices is None and action.dest != "help":
            yield longs[0], action.dest


def _base_argv(command, record_csv, tmp_path):
    path, params = (str(p) for p in record_csv)
    return {
        "power": ["power", "--preset", "figure9", "--psd", "1"],
        "simulate": ["simulate", "--preset", "figure9", "--psd", "1", "--paths", "4",
                     "--t-end", "0.2", "--burn-in", "0.05"],
        "record": ["record", "--preset", "figure9", "--rms", "1", "--duration", "1",
                   "--out", str(tmp_path / "r.csv"), "--force"],
        "identify": _fit_args(path),
        "validate": ["validate", params, path],
    }[command]  # fmt: skip


@pytest.mark.parametrize("command", ["power", "simulate", "record", "identify", "validate"])
def test_messages_name_the_flag_the_user_typed(capsys, record_csv, tmp_path, monkeypatch, command):
    """Every value option of every command, given a bad value: the refusal names the
    flag (`--burn-in`), never the API argument behind it (`burn_in`, `dt`, `k`)."""
    # `--out -1` is a valid file name: run where such files may be written
    monkeypatch.chdir(tmp_path)
    checked = 0
    for flag, dest in _value_options(command):
        for bad in ("-1", "nan", "0"):
            code, _, err = run(capsys, *_base_argv(command, record_csv, tmp_path), flag, bad)
            if code == 2:
                break
        if code != 2:
            continue  # every value of the option is allowed (a seed, a column name...)
        checked += 1
        if dest != flag.removeprefix("--"):  # the API's spelling differs from the flag's
            assert f"`{dest}`" not in err and f" {dest} " not in err, (flag, err)
        if f"`{flag}`" not in err and f"argument {flag}" not in err:
            # the few refusals that explain the device (not confining) name its parameters
            assert "not confining" in err, (flag, err)
    assert checked >= 3


def test_optimal_load_of_a_device_that_delivers_nothing_is_refused():
    """Found by the fuzz test with another seed: a coil of 1e308 H passes no current,
    and the 'optimum' was the search's lower bound at 0 W, returned as a result."""
    from randvib.models.coupling import Inductive

    device = rv.Harvester.with_coupling(
        1.0, 0.5, 180.0, Inductive(alpha=50.0, r_load=700.0, r_coil=60.0, inductance=1e308)
    )
    with pytest.raises(ValueError, match="no load resistance in `bounds`.*takes any power"):
        rv.optimal_load_resistance(device, 1.0)


def test_circuit_time_constant_beyond_float64_is_refused():
    """Found by the fuzz test under another seed: R_L C_p = 1e-616 underflowed to 0 and
    ended in a ZeroDivisionError inside statistical linearisation."""
    from randvib.models.coupling import Piezo

    device = rv.Harvester.with_coupling(
        1.0, 0.0, 0.0, Piezo(theta=0.0078125, capacitance=1e-308, r_load=1e-308), k3=1.0
    )
    with pytest.raises(ValueError, match="time constant beyond float64's range"):
        rv.statistical_linearisation(device, rv.BandPass(1.0, 1.0, 1.0))
