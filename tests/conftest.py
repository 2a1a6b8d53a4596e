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


@pytest.fixture(scope="module")
def record_csv(tmp_path_factory):
    """A 2 s synthetic record of the Coulomb TD1 device, and its fitted-parameter file."""
    import json

    import randvib as rv

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
