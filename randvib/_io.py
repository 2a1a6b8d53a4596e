"""Safe result folders: nothing a user saved is lost or overwritten silently.

A study or sweep writes into a folder together with ``metadata.json`` that
describes what produced it (study name, grid, seeds, versions). Re-running
into the same folder with the same description resumes; a different
description is refused, naming the folder and the first differing key.

While a run writes into a folder it holds the folder's lock
(:data:`LOCK_FILE`: pid, host, start time); a second run is refused with the
holder named, and the lock of a run that was killed (its pid gone on this
host) is taken over. Files that a user may edit (reports, figures, tables)
are written with :func:`write_tracked`, which records their checksums in
:data:`WRITTEN_FILE` and refuses to replace a file changed since, unless
:func:`overwrite_edited` allows it (``--force``). Output paths are checked
before any computation (:func:`check_output_file`, :func:`check_output_folder`).
"""

from __future__ import annotations

import contextlib
import contextvars
import hashlib
import json
import math
import os
import platform
import tempfile
from pathlib import Path

# the folder locks, used here and re-exported for callers of this module
from randvib._locks import LOCK_FILE as LOCK_FILE
from randvib._locks import lock_file as lock_file
from randvib._locks import lock_folder as lock_folder
from randvib._locks import release_all as release_all
from randvib._locks import unlock_folder as unlock_folder

METADATA_FILE = "metadata.json"
#: Checksums (SHA-256) of the files written with :func:`write_tracked`.
WRITTEN_FILE = ".randvib-written.json"


def versions() -> dict:
    """Versions of randvib and its numerical dependencies, for metadata."""
    import matplotlib
    import numba
    import numpy
    import scipy

    from randvib import __version__

    return {
        "randvib": __version__,
        "numpy": numpy.__version__,
        "scipy": scipy.__version__,
        "numba": numba.__version__,
        "matplotlib": matplotlib.__version__,
        "python": platform.python_version(),
    }


def _jsonable(obj):
    return json.loads(
        json.dumps(obj, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o))
    )


def prepare_output_dir(out_dir, identity: dict, extra: dict | None = None) -> Path:
    """Create or reopen ``out_dir`` for results identified by ``identity``.

    Parameters
    ----------
    out_dir : path-like
        Target folder; created if missing.
    identity : dict
        What makes results comparable (study name, grid, seed, sizes...). If
        the folder already holds a ``metadata.json`` whose identity differs,
        :class:`FileExistsError` is raised and nothing is touched.
    extra : dict, optional
        Informational metadata (versions, timings) stored beside the identity.

    Returns
    -------
    Path
        The folder.
    """
    out = check_output_folder(out_dir, "out")
    identity = _jsonable(identity)
    if out.exists() and not (out / METADATA_FILE).exists() and _foreign_entries(out):
        raise FileExistsError(
            f"`out` folder {str(out)!r} is not empty and has no randvib metadata; "
            "choose an empty or new folder"
        )
    out.mkdir(parents=True, exist_ok=True)
    lock_folder(out)
    try:
        return _open_locked(out, identity, extra)
    except BaseException:
        unlock_folder(out)
        raise


_MISSING = object()


def _first_difference(old, new, where: str = "") -> tuple[str, str, str]:
    """The first place two run identities differ: its path and both values, short.

    A study's identity holds every case (devices, excitations, seeds): the
    refusal names the one entry that differs (``cases[1].device.inductance``),
    not the whole lists, so that it stays one readable line.
    """
    if isinstance(old, dict) and isinstance(new, dict):
        for key in sorted(set(old) | set(new), key=str):
            a, b = old.get(key, _MISSING), new.get(key, _MISSING)
            if a != b:
                return _first_difference(a, b, f"{where}.{key}" if where else str(key))
    if isinstance(old, list) and isinstance(new, list):
        if len(old) != len(new):
            return where or "entries", f"{len(old)} entries", f"{len(new)} entries"
        for i, (a, b) in enumerate(zip(old, new, strict=True)):
            if a != b:
                return _first_difference(a, b, f"{where}[{i}]")
    return where or "identity", _short(old), _short(new)


def _short(value, limit: int = 60) -> str:
    """``repr(value)`` cut to ``limit`` characters; "missing" for an absent entry."""
    if value is _MISSING:
        return "missing"
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _foreign_entries(out: Path) -> list:
    return [p for p in out.iterdir() if p.name not in (LOCK_FILE, WRITTEN_FILE)]


def _open_locked(out: Path, identity: dict, extra) -> Path:
    """:func:`prepare_output_dir` once the folder's lock is held."""
    meta_path = out / METADATA_FILE
    if meta_path.exists() or meta_path.is_symlink():
        old = _read_identity(meta_path)
        if old != identity:
            where, there, now = _first_difference(old, identity)
            raise FileExistsError(
                f"`out` folder {str(out)!r} holds results of a different run "
                f"({where}: {there} there, {now} now); "
                "choose another folder or delete it yourself"
            )
        return out
    if _foreign_entries(out):  # filled by another run between our look and our lock
        raise FileExistsError(
            f"`out` folder {str(out)!r} is not empty and has no randvib metadata; "
            "choose an empty or new folder"
        )
    atomic_write_text(
        meta_path,
        json.dumps(
            {"identity": identity, "info": _jsonable({**versions(), **(extra or {})})}, indent=2
        ),
    )
    return out


def _read_identity(meta_path: Path) -> dict:
    """The identity stored in ``metadata.json``, or a refusal naming the file."""
    try:
        old = json.loads(meta_path.read_text())["identity"]
        if not isinstance(old, dict):
            raise TypeError
    except (OSError, ValueError, KeyError, TypeError, UnicodeDecodeError):
        raise FileExistsError(
            f"{str(meta_path)!r} is not a randvib metadata file (a JSON object with an "
            "'identity'); choose another `--out` folder"
        ) from None
    return old


# ------------------------------------------------------------------- input files
def existing_file(path, what: str, kind: str = "CSV") -> Path:
    """``path`` as a Path, refused when it is a folder or does not exist.

    ``what`` names the file in the message (``"record file"``), ``kind`` its
    format (``"CSV"``, ``"JSON"``).
    """
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(f"{what} {str(path)!r} is a folder; give a {kind} file")
    if not path.is_file():
        raise FileNotFoundError(f"{what} {str(path)!r} does not exist")
    return path


# ------------------------------------------------------------------ output paths
def check_output_file(path, option: str, *, overwrite: bool = False) -> Path:
    """Check, before any computation, that ``path`` can be written as a new file.

    Its folder must exist, be a folder and be writable; ``path`` must not be a
    folder, nor (unless ``overwrite``) an existing file.

    Raises
    ------
    FileExistsError, FileNotFoundError, PermissionError
        Naming ``option`` and the path.
    """
    path = Path(path)
    parent = path.parent
    if path.is_dir():
        raise FileExistsError(f"`{option}` {str(path)!r} is a folder; give a file name")
    if path.exists() and not overwrite:
        raise FileExistsError(f"`{option}` {str(path)!r} exists; choose a new file name")
    if not parent.exists():
        raise FileNotFoundError(
            f"`{option}` {str(path)!r}: folder {str(parent)!r} does not exist; create it first"
        )
    if not parent.is_dir():
        raise FileExistsError(f"`{option}` {str(path)!r}: {str(parent)!r} is not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise PermissionError(f"`{option}` {str(path)!r}: folder {str(parent)!r} is not writable")
    return path


def check_output_folder(path, option: str) -> Path:
    """Check that ``path`` is, or can be created as, a writable folder.

    The nearest existing ancestor must be a writable folder (``path`` is
    created with its missing parents when the run starts).
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise FileExistsError(f"`{option}` {str(path)!r} exists and is not a folder")
    existing = path
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        raise FileExistsError(
            f"`{option}` {str(path)!r}: {str(existing)!r} is a file, not a folder"
        )
    if not os.access(existing, os.W_OK | os.X_OK):
        raise PermissionError(f"`{option}` {str(path)!r}: {str(existing)!r} is not writable")
    return path


def claim_output_file(path, option: str, *, overwrite: bool = False) -> Path:
    """:func:`check_output_file`, then hold the file's lock until the run ends.

    A second run given the same output file while this one computes is
    refused at once (one writer per file, as per folder), naming ``option``.
    """
    path = check_output_file(path, option, overwrite=overwrite)
    lock_file(path, option)
    return path


def write_or_keep(path, text: str | bytes, option: str, *, overwrite: bool = False) -> Path | None:
    """Write ``text`` atomically to ``path``; if that fails, keep it beside, saying where.

    For results of long runs: the path was checked (and locked, see
    :func:`claim_output_file`) before the run, but the disk may have filled,
    the folder gone or (without ``overwrite``) a file of that name appeared
    since. The target is written whole or not at all (:func:`atomic_write_bytes`:
    never a truncated file, never a 0-byte one); on failure the result goes to
    a new file in the current folder (or, failing that, to stderr) and a note
    naming ``option`` and the file says so; the returned path is where the
    result is (None: printed). Compare it with ``path`` before saying "wrote".
    """
    import sys

    data = text.encode() if isinstance(text, str) else text
    try:
        atomic_write_bytes(path, data, overwrite=overwrite)
        return Path(path)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        if isinstance(exc, FileExistsError):
            reason = "a file of that name appeared while the run computed"
        try:
            fd, spare = tempfile.mkstemp(
                prefix="randvib-unsaved-", suffix=Path(path).suffix, dir="."
            )
            _fill_new_file(fd, spare, data)
        except OSError:
            print(f"randvib: could not write `{option}` {str(path)!r} ({reason}); the result:",
                  file=sys.stderr)  # fmt: skip
            print(data.decode(errors="replace"), file=sys.stderr)
            return None
        print(f"randvib: could not write `{option}` {str(path)!r} ({reason}); "
              f"the result is kept in {spare!r}", file=sys.stderr)  # fmt: skip
        return Path(spare)


# ------------------------------------------------------------------ atomic writes
def _new_file_mode() -> int:
    """The mode ``open()`` gives a new file: 0666 less the process umask.

    ``tempfile.mkstemp`` creates its file 0600 whatever the umask; files written
    through it are set to this mode, so every file randvib writes follows one rule.
    """
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _fill_new_file(fd: int, name: str, data: bytes) -> None:
    """Write ``data`` into the new file ``fd`` (named ``name``) with ``open()``'s mode, fsynced.

    The file is removed if that fails, so no half-written file is left behind.
    """
    try:
        os.fchmod(fd, _new_file_mode())
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(name)
        raise


def atomic_write_bytes(path, data: bytes, *, overwrite: bool = True) -> None:
    """Write a file via a unique temporary name in its folder, fsync and rename.

    A crash or a full disk never leaves half a file (the temporary file is
    removed), and two writers never share a temporary file. With
    ``overwrite=False`` an existing ``path`` is never replaced
    (:class:`FileExistsError`): the file is linked into place, which fails
    when the name exists.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        _fill_new_file(fd, tmp, data)
        if overwrite:
            os.replace(tmp, path)
        else:
            os.link(tmp, path)
            os.unlink(tmp)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, FileExistsError):
            # name the target, not the temporary file (a full disk: ENOSPC)
            raise OSError(exc.errno, exc.strerror or type(exc).__name__, str(path)) from None
        raise


def atomic_write_text(path, text: str) -> None:
    """Write a text file atomically (:func:`atomic_write_bytes`)."""
    atomic_write_bytes(path, text.encode())


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


# ------------------------------------------------------------------ edited files
_OVERWRITE_EDITED = contextvars.ContextVar("overwrite_edited", default=False)


@contextlib.contextmanager
def overwrite_edited(allowed: bool = True):
    """Within this block :func:`write_tracked` replaces files edited since written (--force)."""
    token = _OVERWRITE_EDITED.set(bool(allowed))
    try:
        yield
    finally:
        _OVERWRITE_EDITED.reset(token)


def _written(folder: Path) -> dict:
    try:
        data = json.loads((folder / WRITTEN_FILE).read_text())
        return data if isinstance(data, dict) else {}
    except (OSError, ValueError):
        return {}


def write_tracked(path, data: bytes | str) -> Path:
    """Write ``path`` atomically unless the user changed it since randvib wrote it.

    The SHA-256 of every file written here is kept in the folder's
    :data:`WRITTEN_FILE`. An existing file whose content differs from the
    recorded checksum (edited, or not written by randvib) is not replaced:
    :class:`FileExistsError` names it, unless inside :func:`overwrite_edited`.
    """
    path = Path(path)
    data = data.encode() if isinstance(data, str) else data
    record = _written(path.parent)
    if path.exists() and not _OVERWRITE_EDITED.get():
        old = sha256(path.read_bytes())
        if record.get(path.name) != old:
            raise FileExistsError(
                f"{str(path)!r} was changed since randvib wrote it (or randvib did not write "
                "it); move it away, or give --force to overwrite it"
            )
    atomic_write_bytes(path, data)
    record[path.name] = sha256(data)
    atomic_write_text(path.parent / WRITTEN_FILE, json.dumps(record, indent=1, sort_keys=True))
    return path


# ------------------------------------------------------------------ JSON
def finite_json(obj, reason: str = "not a finite number at these values"):
    """``obj`` with every non-finite float replaced by None, and the reasons by key.

    Returns
    -------
    clean : object
        JSON-ready: NaN and infinities become None (JSON ``null``).
    nulls : dict
        Dotted key -> why that value is null.
    """
    nulls: dict = {}

    def clean(value, key):
        if isinstance(value, dict):
            return {k: clean(v, f"{key}.{k}" if key else str(k)) for k, v in value.items()}
        if isinstance(value, list | tuple):
            return [clean(v, f"{key}[{i}]") for i, v in enumerate(value)]
        if hasattr(value, "tolist") and not isinstance(value, str):
            return clean(value.tolist(), key)
        if isinstance(value, float) and not math.isfinite(value):
            nulls[key] = f"{reason} ({value!r})"
            return None
        return value

    return clean(obj, ""), nulls


def dumps(obj, **kwargs) -> str:
    """Valid JSON of ``obj`` (never NaN or Infinity): non-finite numbers become null,
    and a top-level ``null_reasons`` object says why (when ``obj`` is a dict)."""
    clean, nulls = finite_json(obj)
    if nulls and isinstance(clean, dict):
        clean["null_reasons"] = nulls
    return json.dumps(clean, allow_nan=False, **kwargs)
