"""Folder and file locks: one run at a time writes into a result folder or an output file.

While a run writes into a folder it holds the folder's lock
(:data:`LOCK_FILE`, JSON: pid, host, start time), taken atomically
(``O_CREAT | O_EXCL``). A second run is refused with the holder named; a
lock is re-entrant within its process. An output file (``power --csv``,
``identify --save``, ``record --out``) is locked the same way by a lock file
beside it (:func:`lock_file`), from the check of its path to the end of the run. Locks are released by
:func:`unlock_folder` / :func:`release_all`, and at exit.

A lock left by a run that was killed is taken over:

- on this host, when its pid no longer exists;
- from another host (a folder on a shared file system, a cluster's nodes),
  when its heartbeat has stopped: a live holder touches its lock file every
  :data:`HEARTBEAT_SECONDS`, and a lock not touched for
  :data:`STALE_AFTER_SECONDS` is a dead run's. The margin between the two
  covers a busy machine and clocks that differ by a few minutes.
"""

from __future__ import annotations

import atexit
import contextlib
import datetime
import json
import os
import socket
import threading
import time
from pathlib import Path

#: The lock of a folder a run is writing into.
LOCK_FILE = ".randvib.lock"
#: A holder touches its lock files this often (s).
HEARTBEAT_SECONDS = 30.0
#: Another host's lock untouched this long (s) is a dead run's.
STALE_AFTER_SECONDS = 600.0

_HELD: dict[Path, int] = {}  # lock file -> nesting depth, in this process
_HEARTBEAT: list = []  # the one heartbeat thread of this process, once started


def _beat() -> None:
    """Touch every lock this process holds, every HEARTBEAT_SECONDS, while it lives.

    It wakes twice a second and beats when the period has passed, so that a
    changed period takes effect at once.
    """
    last = time.monotonic()
    while True:
        if time.monotonic() - last >= HEARTBEAT_SECONDS:
            last = time.monotonic()
            for lock in list(_HELD):
                with contextlib.suppress(OSError):  # released meanwhile, or a vanished folder
                    os.utime(lock)
        time.sleep(min(0.5, HEARTBEAT_SECONDS))


def _start_heartbeat() -> None:
    if not _HEARTBEAT:
        thread = threading.Thread(target=_beat, name="randvib-lock-heartbeat", daemon=True)
        thread.start()
        _HEARTBEAT.append(thread)


def _lock_text() -> str:
    return json.dumps(
        {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "started": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        }
    )


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True  # someone else's live process (or unknowable): not stale
    return True


def _holder(lock: Path) -> dict | None:
    try:
        data = json.loads(lock.read_text())
        return data if isinstance(data, dict) and isinstance(data.get("pid"), int) else None
    except (OSError, ValueError):
        return None


def lock_folder(folder) -> None:
    """Take ``folder``'s lock for this process (re-entrant), or refuse naming the holder.

    A lock left by a process of this host that no longer exists (a killed
    run) is taken over. Released by :func:`unlock_folder` or at exit.
    """
    folder = Path(folder).resolve()
    _acquire(folder / LOCK_FILE, f"folder {str(folder)!r}")


def file_lock_path(path) -> Path:
    """The lock file of the output file ``path``: a hidden file beside it."""
    path = Path(path).resolve()
    return path.parent / f".{path.name}{LOCK_FILE}"


def lock_file(path, option: str) -> None:
    """Take the lock of the output file ``path`` (re-entrant), or refuse naming ``option``.

    One run at a time writes a given file: a second run given the same
    ``--csv``/``--save``/``--out`` while the first computes is refused at
    once, before it computes anything. Released by :func:`unlock_file` or at exit.
    """
    _acquire(file_lock_path(path), f"`{option}` {str(path)!r}")


def unlock_file(path) -> None:
    """Release one hold of the output file ``path``'s lock."""
    _release(file_lock_path(path))


def _acquire(lock: Path, what: str) -> None:
    if lock in _HELD:
        _HELD[lock] += 1
        return
    for _ in range(3):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            holder = _holder(lock)
            if holder is None:  # being written this instant, or garbage: look again
                time.sleep(0.05)
                holder = _holder(lock)
            if _is_stale(holder, lock):
                _break_stale(lock, holder)
                continue
            raise FileExistsError(_busy_message(lock, holder, what)) from None
        with os.fdopen(fd, "w") as f:
            f.write(_lock_text())
        _HELD[lock] = 1
        _start_heartbeat()
        return
    raise FileExistsError(_busy_message(lock, _holder(lock), what))


def _silent_for(lock: Path) -> float:
    """Seconds since the lock's holder last touched it (its heartbeat)."""
    try:
        return time.time() - lock.stat().st_mtime
    except FileNotFoundError:
        return 0.0


def _is_stale(holder, lock: Path) -> bool:
    if holder is None:
        return False
    if holder.get("host") != socket.gethostname():
        # a process on another host cannot be asked; its heartbeat can
        return _silent_for(lock) > STALE_AFTER_SECONDS
    return holder["pid"] != os.getpid() and not _pid_alive(holder["pid"])


def _break_stale(lock: Path, holder: dict) -> None:
    """Remove a dead run's lock, unless it changed meanwhile (another run took it over)."""
    if _holder(lock) == holder:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(lock)


def _busy_message(lock: Path, holder, what: str | None = None) -> str:
    if what is None:  # a folder's lock
        what = f"folder {str(lock.parent)!r}"
    if holder is None:
        who = "an unreadable lock"
    else:
        who = f"process {holder['pid']} on {holder.get('host')!r} since {holder.get('started')}"
        if holder.get("host") != socket.gethostname():
            who += (
                f", last heard from {_silent_for(lock):.0f} s ago; its lock is taken over once "
                f"silent for {STALE_AFTER_SECONDS:.0f} s"
            )
    return (
        f"{what} is in use by another randvib run ({who}); wait for it to "
        f"finish, or if no such run exists delete {str(lock)!r}"
    )


def unlock_folder(folder) -> None:
    """Release one hold of ``folder``'s lock (the file goes with the last)."""
    _release(Path(folder).resolve() / LOCK_FILE)


def _release(lock: Path) -> None:
    if lock not in _HELD:
        return
    _HELD[lock] -= 1
    if _HELD[lock] == 0:
        del _HELD[lock]
        holder = _holder(lock)
        if holder is not None and holder["pid"] == os.getpid():
            with contextlib.suppress(FileNotFoundError):
                os.unlink(lock)


def release_since(before: set) -> None:
    """Release every lock taken since ``before`` (a copy of :func:`held`), keeping older ones."""
    for lock in [lock for lock in _HELD if lock not in before]:
        _HELD[lock] = 1
        _release(lock)


def held() -> set:
    """The locks this process holds now (for :func:`release_since`)."""
    return set(_HELD)


@atexit.register
def release_all() -> None:
    """Release every folder and file lock this process holds (end of a run, and at exit)."""
    for lock in list(_HELD):
        _HELD[lock] = 1
        _release(lock)
