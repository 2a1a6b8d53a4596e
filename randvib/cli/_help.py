"""A command's ``--help`` kept once printed, so that the next one imports nothing heavy.

Building ``randvib COMMAND``'s parser imports the command's module, and with
it numba, scipy and pandas (seconds), only to print text that changes only
when randvib does. The text is kept beside the package's bytecode (the
``__pycache__`` folder numba's kernels are cached in), keyed by randvib's
version, the size and modification time of each of its source files and the
terminal's width, so that an edited or upgraded package prints its own help;
where that folder cannot be written, nothing is kept and help is built each
time.
"""

from __future__ import annotations

import hashlib
import os
import shutil
from pathlib import Path

#: The package's root folder (randvib/).
_PACKAGE = Path(__file__).resolve().parent.parent


def _path(command: str) -> Path:
    """Where ``command``'s help for this source tree and terminal width is kept."""
    from randvib import __version__

    digest = hashlib.sha256(__version__.encode())
    for source in sorted(_PACKAGE.rglob("*.py")):
        stat = source.stat()
        digest.update(f"{source.relative_to(_PACKAGE)}:{stat.st_size}:{stat.st_mtime_ns};".encode())
    digest.update(str(shutil.get_terminal_size().columns).encode())
    return _PACKAGE / "cli" / "__pycache__" / f"help-{command}-{digest.hexdigest()[:16]}.txt"


def kept_help(command: str) -> str | None:
    """``randvib COMMAND --help`` as printed before for this package, or None."""
    try:
        return _path(command).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None


def keep_help(command: str, text: str) -> None:
    """Keep ``command``'s help text (atomically; silently nothing where it cannot be written)."""
    try:
        path = _path(command)
        path.parent.mkdir(exist_ok=True)
        temporary = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        temporary.write_text(text, encoding="utf-8")
        os.replace(temporary, path)
    except OSError:
        pass
