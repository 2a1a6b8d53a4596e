"""Folder locks: one run at a time writes into a result folder.

While a run writes into a folder it holds the folder's lock
(:data:`LOCK_FILE`, JSON: pid, host, start time), taken atomically
(``O_CREAT | O_EXCL``). A second run is refused with the holder named; the
lock of a run that was killed (its pid gone on this host) is taken over,
and a lock is re-entrant within its process. Locks are released by
:func:`unlock_folder` / :func:`release_all`, and at exit.
"""

from __future__ import annotations

import atexit
import contextlib
import datetime
import json
import os
import socket
from pathlib import Path

#: The lock of a folder a run is writing into.
LOCK_FILE = ".randvib.lock"

_HELD: dict[Path, int] = {}  # folder -> nesting depth, in this process


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
    if folder in _HELD:
        _HELD[folder] += 1
        return
    lock = folder / LOCK_FILE
    for _ in range(3):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            holder = _holder(lock)
            if holder is None:  # being written this instant, or garbage: look again
                import time

                time.sleep(0.05)
                holder = _holder(lock)
            if _is_stale(holder):
                _break_stale(lock, holder)
                continue
            raise FileExistsError(_busy_message(folder, holder)) from None
        with os.fdopen(fd, "w") as f:
            f.write(_lock_text())
        _HELD[folder] = 1
        return
    raise FileExistsError(_busy_message(folder, _holder(lock)))


def _is_stale(holder) -> bool:
    if holder is None:
        return False
    if holder.get("host") != socket.gethostname():
        return False  # cannot tell whether a process on another host lives
    return holder["pid"] != os.getpid() and not _pid_alive(holder["pid"])


def _break_stale(lock: Path, holder: dict) -> None:
    """Remove a dead run's lock, unless it changed meanwhile (another run took it over)."""
    if _holder(lock) == holder:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(lock)


def _busy_message(folder: Path, holder) -> str:
    who = (
        "an unreadable lock"
        if holder is None
        else f"process {holder['pid']} on {holder.get('host')!r} since {holder.get('started')}"
    )
    return (
        f"folder {str(folder)!r} is in use by another randvib run ({who}); wait for it to "
        f"finish, or if no such run exists delete {str(folder / LOCK_FILE)!r}"
    )


def unlock_folder(folder) -> None:
    """Release one hold of ``folder``'s lock (the file goes with the last)."""
    folder = Path(folder).resolve()
    if folder not in _HELD:
        return
    _HELD[folder] -= 1
    if _HELD[folder] == 0:
        del _HELD[folder]
        lock = folder / LOCK_FILE
        holder = _holder(lock)
        if holder is not None and holder["pid"] == os.getpid():
            with contextlib.suppress(FileNotFoundError):
                os.unlink(lock)


@atexit.register
def release_all() -> None:
    """Release every folder lock this process holds (end of a run, and at exit)."""
    for folder in list(_HELD):
        _HELD[folder] = 1
        unlock_folder(folder)
