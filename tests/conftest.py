import os
from pathlib import Path

import pytest  # imports no matplotlib, so the backend below is still in time

os.environ.setdefault("MPLBACKEND", "Agg")

ROOT = Path(__file__).resolve().parents[1]


def _visible_entries(folder: Path) -> set[str]:
    return {p.name for p in folder.iterdir() if not p.name.startswith(".")}


@pytest.fixture(autouse=True, scope="session")
def _nothing_written_into_the_checkout():
    """The tests write only under pytest's tmp_path: three CSV records named
    -1, 0 and nan (a test giving `--out` bad values from the checkout) were once
    committed by accident. Fails the session if the project root gains a file."""
    before = _visible_entries(ROOT)
    yield
    new = sorted(_visible_entries(ROOT) - before - {"__pycache__"})
    assert not new, f"the tests wrote {new} into {ROOT}; write under tmp_path"
