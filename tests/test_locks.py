"""Folder locks: one run at a time writes into a result folder.

Covers :mod:`randvib._locks` through :func:`randvib._io.prepare_output_dir`:
a second run is refused naming the holder, a killed run's lock is taken over
(on this host by its pid, from another host once its heartbeat stops), a
holder keeps its lock alive, and of four runs racing into one new folder
exactly one wins.
"""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from randvib import _io


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
        folder / _locks.LOCK_FILE, json.loads(lock.read_text())
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
