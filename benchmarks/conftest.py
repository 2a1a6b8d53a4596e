"""Shared helpers for the benchmarks: ratios are taken between runs of one session."""

import json
import os
from pathlib import Path

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")


def pytest_addoption(parser):
    parser.addoption(
        "--campaign",
        action="store_true",
        help="also run the identification campaign benchmark (minutes)",
    )


#: Seconds per unit of work of each benchmark in this session, by name.
TIMINGS: dict[str, float] = {}


def record(benchmark, name: str, units_of_work: float) -> float:
    """Store the benchmark's best time per unit of work (s) under ``name``."""
    per_unit = benchmark.stats.stats.min / units_of_work
    TIMINGS[name] = per_unit
    benchmark.extra_info["seconds_per_unit"] = per_unit
    return per_unit


def write_report(name: str, payload: dict) -> Path:
    out = Path(".benchmarks")
    out.mkdir(exist_ok=True)
    path = out / f"{name}.json"
    path.write_text(json.dumps(payload, indent=2))
    return path


@pytest.fixture
def timings():
    return TIMINGS
