"""Output files and folders: nothing a user saved is lost or overwritten silently.

Covers :mod:`randvib._io` (output paths checked before computing, a result
that cannot be written kept beside, atomic writes, ``metadata.json``, files
edited since randvib wrote them) as the commands use it
(:mod:`randvib.cli.identify`, :mod:`randvib.cli.validate`, :mod:`randvib.cli.record`,
:mod:`randvib.cli.study`) and the studies' report writer
(:mod:`randvib.studies.report`). Folder locks: tests/test_locks.py.
"""

import json
import shutil
import threading
from pathlib import Path

import pytest
from _cli import fit_args, one_line_error, run

import randvib as rv
from randvib import _io


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
    one_line_error(capsys, fit_args(record_csv[0], option, target), fragment)
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
        shutil.rmtree(tmp_path / "out")  # with the lock of out/fit.json in it
        return result

    monkeypatch.setattr("randvib.cli.identify.identify", fit_then_remove_folder)
    code, out, err = run(capsys, *fit_args(record_csv[0], "--save", "out/fit.json", "--json"))
    assert code == 1  # not saved where asked
    kept = list(tmp_path.glob("randvib-unsaved-*.json"))
    assert len(kept) == 1 and json.loads(kept[0].read_text())["model"] == "coulomb"
    assert str(kept[0].name) in err


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


def test_different_run_names_the_one_entry_that_differs_not_every_case(tmp_path):
    """A study's identity lists every case; the refusal to mix runs in one folder names
    the first entry that differs (its path and both values) and stays short."""
    cases = [{"seed": i, "device": {"m": 0.0226, "k": 57.4 + i}} for i in range(200)]
    _io.unlock_folder(_io.prepare_output_dir(tmp_path, {"cases": cases}))
    changed = [dict(c, device=dict(c["device"])) for c in cases]
    changed[7]["device"]["inductance"] = 0.0
    with pytest.raises(FileExistsError) as info:
        _io.prepare_output_dir(tmp_path, {"cases": changed})
    message = str(info.value)
    assert "cases[7].device.inductance: missing there, 0.0 now" in message
    assert len(message) < 300, message
    with pytest.raises(FileExistsError, match=r"cases: 200 entries there, 3 entries now"):
        _io.prepare_output_dir(tmp_path, {"cases": cases[:3]})


@pytest.mark.parametrize("umask", [0o022, 0o077, 0o002])
def test_written_files_follow_the_umask_like_open(tmp_path, monkeypatch, umask):
    """Atomic writes and kept-beside results get the mode ``open()`` would give (0666 less
    the umask), not mkstemp's 0600, so PNG, study and CSV/JSON outputs share one rule."""
    import os
    import stat

    old = os.umask(umask)
    try:
        _io.atomic_write_bytes(tmp_path / "a.png", b"x")
        _io.write_tracked(tmp_path / "b.csv", "x\n")
        monkeypatch.chdir(tmp_path)
        kept = _io.write_or_keep(tmp_path / "missing" / "c.json", "{}", "--save")
        (tmp_path / "plain.txt").write_text("x")
    finally:
        os.umask(old)
    expected = stat.S_IMODE((tmp_path / "plain.txt").stat().st_mode)
    assert expected == 0o666 & ~umask
    for path in (tmp_path / "a.png", tmp_path / "b.csv", kept):
        assert stat.S_IMODE(Path(path).stat().st_mode) == expected, path


# ------------------------------------------------- one writer per file, full disk
def _held_by_another_run(target: Path) -> None:
    """The lock of ``target`` as a live run of this host holds it (our parent process)."""
    import os
    import socket

    from randvib import _locks

    _locks.file_lock_path(target).write_text(
        json.dumps({"pid": os.getppid(), "host": socket.gethostname(), "started": "now"})
    )


@pytest.mark.parametrize(
    "argv, option",
    [
        (["power", "--preset", "figure9", "--psd", "0.1", "--csv", "race.csv"], "--csv"),
        (["record", "--preset", "figure9", "--rms", "2", "--duration", "2", "--out", "race.csv"],
         "--out"),
    ],
)  # fmt: skip
def test_second_writer_of_one_output_file_is_refused(capsys, tmp_path, monkeypatch, argv, option):
    monkeypatch.chdir(tmp_path)
    _held_by_another_run(tmp_path / "race.csv")
    one_line_error(capsys, argv, f"`{option}` 'race.csv' is in use by another randvib run")
    assert not (tmp_path / "race.csv").exists()


def test_identify_second_writer_of_save_is_refused(capsys, tmp_path, monkeypatch, record_csv):
    monkeypatch.chdir(tmp_path)
    _held_by_another_run(tmp_path / "race.json")
    fitted = []
    monkeypatch.setattr("randvib.cli.identify.identify", lambda *a, **k: fitted.append(1))
    one_line_error(capsys, fit_args(record_csv[0], "--save", "race.json"), "is in use")
    assert fitted == []  # refused before the fit


def test_output_file_lock_released_after_the_run(capsys, tmp_path, monkeypatch):
    from randvib import _locks

    monkeypatch.chdir(tmp_path)
    code, _, _ = run(capsys, "power", "--preset", "figure9", "--psd", "0.1", "--csv", "a.csv")
    assert code == 0 and not _locks.file_lock_path(tmp_path / "a.csv").exists()
    # a file that appeared meanwhile is not replaced without --force: kept beside instead
    assert _io.write_or_keep(tmp_path / "a.csv", "other", "--csv") != tmp_path / "a.csv"
    assert "other" not in (tmp_path / "a.csv").read_text()


def _disk_full_in(monkeypatch, folder: Path) -> None:
    """fsync of any file under ``folder`` fails as on a full disk (ENOSPC)."""
    import errno
    import os

    real = os.fsync

    def fsync(fd):
        if os.readlink(f"/proc/self/fd/{fd}").startswith(str(folder.resolve())):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(fd)

    monkeypatch.setattr(os, "fsync", fsync)


@pytest.mark.parametrize(
    "argv, target, option",
    [
        (["power", "--preset", "figure9", "--psd", "0.1:1:5", "--csv", "full/p.csv"],
         "full/p.csv", "--csv"),
        (["record", "--preset", "figure9", "--rms", "2", "--duration", "2", "--out",
          "full/r.csv"], "full/r.csv", "--out"),
    ],
)  # fmt: skip
def test_full_disk_leaves_no_partial_file_and_keeps_the_result(
    capsys, tmp_path, monkeypatch, argv, target, option
):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "full").mkdir()
    _disk_full_in(monkeypatch, tmp_path / "full")
    code, out, err = run(capsys, *argv)
    assert code == 1 and "wrote" not in out
    assert (
        sorted(p.name for p in (tmp_path / "full").iterdir()) == []
    )  # no target, no temp, no lock
    assert f"could not write `{option}` {target!r} (No space left on device)" in err
    kept = list(tmp_path.glob("randvib-unsaved-*.csv"))
    assert len(kept) == 1 and kept[0].name in err
    assert kept[0].read_text().count("\n") > 5  # the whole table: header and rows


def test_identify_full_disk_leaves_no_empty_save(capsys, tmp_path, monkeypatch, record_csv):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "full").mkdir()
    _disk_full_in(monkeypatch, tmp_path / "full")
    code, _, err = run(capsys, *fit_args(record_csv[0], "--save", "full/fit.json"))
    assert code == 1 and list((tmp_path / "full").iterdir()) == []
    kept = list(tmp_path.glob("randvib-unsaved-*.json"))
    assert len(kept) == 1 and json.loads(kept[0].read_text())["model"] == "coulomb"


# ------------------------------------------------- a stopped or long power sweep
@pytest.mark.parametrize("stop, code", [(KeyboardInterrupt, 130), ("sigterm", 143)])
def test_stopped_power_sweep_keeps_its_finished_points_in_the_csv(
    capsys, tmp_path, monkeypatch, stop, code
):
    from randvib._interrupts import Terminated
    from randvib.cli import power

    monkeypatch.chdir(tmp_path)
    real, calls = power._point, []

    def stop_at_the_third(args):
        calls.append(1)
        if len(calls) == 3:
            raise Terminated() if stop == "sigterm" else KeyboardInterrupt()
        return real(args)

    monkeypatch.setattr(power, "_point", stop_at_the_third)
    argv = ["power", "--preset", "figure9", "--psd", "0.1:1:5", "--csv", "big.csv"]
    code_, out, err = run(capsys, *argv)
    assert code_ == code
    assert "the 2 finished points of 5 were kept in 'big.csv'" in err
    rows = (tmp_path / "big.csv").read_text().strip().splitlines()
    assert len(rows) == 3 and rows[0].startswith("method,psd")  # header and 2 points
    # without --csv, the line does not claim that anything was kept
    calls.clear()
    code_, out, err = run(capsys, *argv[:-2])
    assert code_ == code and "nothing was saved (no --csv)" in err


def test_long_power_sweep_says_how_long_first(capsys, tmp_path, monkeypatch):
    import itertools

    from randvib import _resources

    ticks = itertools.count(step=100.0)  # every point "takes" 100 s on this clock
    monkeypatch.setattr(_resources, "clock", lambda: next(ticks))
    code, out, err = run(capsys, "power", "--preset", "figure9", "--psd", "0.1:1:10")
    assert code == 0 and "this sweep of 10 points will take about 15 minutes" in err


# ------------------------------------------------- exit status 1: computed, not saved where asked
def _figures_fail(monkeypatch):
    import errno

    def full_disk(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("randvib.identification.plots.figure_fit", full_disk)


@pytest.mark.parametrize("command", ["identify", "validate"])
def test_figure_not_written_prints_the_result_and_exits_1(
    capsys, tmp_path, monkeypatch, record_csv, command
):
    """As for --save, --csv and --out: a result computed but not saved where asked exits 1."""
    rec, params = record_csv
    _figures_fail(monkeypatch)
    plot = tmp_path / "fig.png"
    if command == "identify":
        argv = fit_args(rec, "--plot", plot)
    else:
        argv = ["validate", params, rec, "--plot", plot]
    code, out, err = run(capsys, *argv)
    assert code == 1, err
    assert "J" in out or "cost" in out  # the result is printed
    assert f"could not write `--plot` {str(plot)!r}" in err and len(err.strip().splitlines()) == 1
    assert not plot.exists() and "wrote" not in out
