"""Measured data shipped with randvib.

The Silverbox benchmark record (an electronic forced Duffing oscillator,
measured on real hardware; citation in ``randvib/data/silverbox/README.md``)
is part of the package, so tests, examples and studies run from a fresh clone
or an installed copy without anything outside it.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

SILVERBOX_SAMPLE_RATE = 1e7 / 2**14  # Hz (610.35 Hz)
SILVERBOX_ARROW_HEAD = (0, 40_700)  # samples: the arrow-head validation signal
SILVERBOX_MULTISINE = (40_700, None)  # samples: the odd random-phase multisines
_PARTS = {"arrow-head": SILVERBOX_ARROW_HEAD, "multisine": SILVERBOX_MULTISINE}

# The benchmark's official split, as its own data loader defines it
# (nonlinear_benchmarks.Silverbox(), github.com/GerbenBeintema/nonlinear_benchmarks):
# the multisines are samples 40,650 to 127,400, their first 75 % the training
# data and the rest the multisine test; the arrow-head test is samples 100 to
# 40,575 and its first 32,000 samples the part without extrapolation.
_BENCHMARK_MULTISINE = (40_650, 127_400)
_BENCHMARK_TRAIN_END = _BENCHMARK_MULTISINE[0] + int(
    0.75 * (_BENCHMARK_MULTISINE[1] - _BENCHMARK_MULTISINE[0])
)
#: The official split: part name -> (first sample, end) (end exclusive).
SILVERBOX_SPLIT = {
    "multisine train": (_BENCHMARK_MULTISINE[0], _BENCHMARK_TRAIN_END),
    "multisine test": (_BENCHMARK_TRAIN_END, _BENCHMARK_MULTISINE[1]),
    "arrow-head full": (100, 40_575),
    "arrow-head no extrapolation": (100, 100 + 32_000),
}
#: Samples at the start of each test part not scored (the benchmark's state
#: initialisation window: a model may use the output there, and nowhere else).
SILVERBOX_INITIALISATION = 50


def silverbox_path() -> Path:
    """Path of the shipped ``SNLS80mV.csv`` (columns ``V1`` input, ``V2`` output, in V)."""
    return Path(str(resources.files("randvib").joinpath("data", "silverbox", "SNLS80mV.csv")))


def silverbox(part: str = "multisine"):
    """The Silverbox record as a :class:`randvib.Record`.

    Parameters
    ----------
    part : {'multisine', 'arrow-head'}
        ``'multisine'``: samples 40,700 to the end, the usual estimation data;
        ``'arrow-head'``: samples 0 to 40,700, the usual validation data
        (larger amplitudes than the multisines).

    Returns
    -------
    Record
        Force input ``u = V1`` (V, playing the role of a force), output
        ``y = V2`` (V), sampled at 610.35 Hz.
    """
    if part not in _PARTS:
        raise ValueError(f"part must be one of {sorted(_PARTS)}, got {part!r}")
    return _read(_PARTS[part], part)


def silverbox_split() -> dict:
    """The Silverbox record on the benchmark's official split (:data:`SILVERBOX_SPLIT`).

    Returns
    -------
    dict
        ``"multisine train"`` (65,062 samples), ``"multisine test"``
        (21,688), ``"arrow-head full"`` (40,475) and ``"arrow-head no
        extrapolation"`` (32,000): :class:`randvib.Record` named so. The
        first :data:`SILVERBOX_INITIALISATION` samples of each test part are
        not scored by the benchmark.
    """
    return {name: _read(rows, name) for name, rows in SILVERBOX_SPLIT.items()}


def _read(rows, name):
    from randvib.models.record import read_record

    return read_record(
        silverbox_path(),
        input_column="V1",
        input_kind="force",
        output_column="V2",
        output_kind="relative_displacement",  # the circuit's response, Eq. 1's z, in volts
        sample_rate=SILVERBOX_SAMPLE_RATE,
        rows=rows,
        name=name,
    )


def device_names() -> list[str]:
    """Names of the example device files shipped in ``randvib/data/devices`` (docs/assemblies.md)."""
    folder = resources.files("randvib").joinpath("data", "devices")
    return sorted(
        p.name.removesuffix(".toml") for p in folder.iterdir() if p.name.endswith(".toml")
    )


def device_path(name: str) -> Path:
    """Path of a shipped example device file, by its name (``host_with_harvester``)."""
    stem = name.removesuffix(".toml").replace("-", "_")
    if stem not in device_names():
        raise ValueError(f"no shipped device file {name!r}; shipped: {', '.join(device_names())}")
    return Path(str(resources.files("randvib").joinpath("data", "devices", f"{stem}.toml")))
