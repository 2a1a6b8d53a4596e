"""Safe result folders: nothing a user saved is lost or overwritten silently.

A study or sweep writes into a folder together with ``metadata.json`` that
describes what produced it (study name, grid, seeds, versions). Re-running
into the same folder with the same description resumes; a different
description is refused, naming the folder and the first differing key.
"""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path

METADATA_FILE = "metadata.json"


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
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise FileExistsError(f"`out` {str(out)!r} exists and is not a folder")
    identity = _jsonable(identity)
    meta_path = out / METADATA_FILE
    if meta_path.exists():
        try:
            old = json.loads(meta_path.read_text())["identity"]
        except (ValueError, KeyError):
            raise FileExistsError(
                f"{str(meta_path)!r} is not a randvib metadata file; choose another `--out` folder"
            ) from None
        if old != identity:
            keys = sorted(set(old) | set(identity))
            diff = next(k for k in keys if old.get(k) != identity.get(k))
            raise FileExistsError(
                f"`out` folder {str(out)!r} holds results of a different run "
                f"({diff}: {old.get(diff)!r} there, {identity.get(diff)!r} now); "
                "choose another folder or delete it yourself"
            )
        return out
    if out.exists() and any(out.iterdir()):
        raise FileExistsError(
            f"`out` folder {str(out)!r} is not empty and has no randvib metadata; "
            "choose an empty or new folder"
        )
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(
        meta_path,
        json.dumps(
            {"identity": identity, "info": _jsonable({**versions(), **(extra or {})})}, indent=2
        ),
    )
    return out


def atomic_write_text(path, text: str) -> None:
    """Write a file via a temporary name and rename, so a crash never leaves half a file."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)
