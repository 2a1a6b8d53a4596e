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
    from randvib.models.record import read_record

    return read_record(
        silverbox_path(),
        input_column="V1",
        input_kind="force",
        output_column="V2",
        sample_rate=SILVERBOX_SAMPLE_RATE,
        rows=_PARTS[part],
        name=part,
    )
