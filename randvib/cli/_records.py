"""Record and simulation options shared by ``identify`` and ``validate``."""

from __future__ import annotations

import argparse

from randvib._validation import integer_option
from randvib.identification.input_reconstruction import AUTO_HOLD, HOLDS
from randvib.identification.settings import INITIAL_STATES, SimulationSettings
from randvib.models.record import (
    INPUT_KINDS,
    OUTPUT_CHANNEL,
    OUTPUT_KINDS,
    TIME_COLUMN,
    read_record,
)
from randvib.quantities import unit


def add_record_arguments(parser: argparse.ArgumentParser) -> None:
    g = parser.add_argument_group("record (CSV columns)")
    g.add_argument(
        "--input-column", metavar="NAME", help="input column (default: the one named like its kind)"
    )
    g.add_argument("--input-kind", choices=INPUT_KINDS, help="what the input column holds")
    g.add_argument(
        "--output-column",
        metavar="NAME",
        default=OUTPUT_CHANNEL,
        help="relative-displacement column",
    )
    g.add_argument(
        "--output-kind",
        choices=OUTPUT_KINDS,
        help="what --output-column holds; needed for a column not named as its kind "
        "(its values are then used in the column's own units)",
    )
    g.add_argument(
        "--time-column", metavar="NAME", default=TIME_COLUMN, help="time column (s, uniform)"
    )
    g.add_argument(
        "--sample-rate", type=float, metavar="HZ", help="sample rate when there is no time column"
    )
    g.add_argument(
        "--rows",
        metavar="START:STOP",
        help="use data rows START:STOP only (0-based, STOP excluded)",
    )
    s = parser.add_argument_group("simulation")
    s.add_argument(
        "--substeps",
        type=integer_option(1),
        default=None,
        help="integration steps per sample (default: 4)",
    )
    s.add_argument(
        "--hold",
        choices=(AUTO_HOLD,) + HOLDS,
        default=None,
        help="input between samples (default: auto, linear or bandlimited chosen from the "
        "input's content against the sample rate)",
    )
    s.add_argument("--lowpass", type=float, metavar="HZ", help="low-pass the driving signal")
    s.add_argument(
        "--skip",
        type=integer_option(0),
        default=None,
        help="samples left out of J at the start (default: 0)",
    )
    s.add_argument(
        "--initial-state",
        choices=INITIAL_STATES,
        default=None,
        help="estimate the initial state (default) or start from the record's first samples",
    )


def parse_rows(text):
    if text is None:
        return None
    parts = text.split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        return tuple(int(p) if p.strip() else None for p in parts)
    except ValueError:
        raise ValueError(f"`--rows` must be START:STOP with integers, got {text!r}") from None


def record_from_args(path, args, name=None):
    return read_record(
        path,
        input_column=args.input_column,
        input_kind=args.input_kind,
        output_column=args.output_column,
        output_kind=args.output_kind,
        time_column=args.time_column,
        sample_rate=args.sample_rate,
        rows=parse_rows(args.rows),
        name=name,
    )


def simulation_settings(args, defaults=None) -> SimulationSettings:
    """The simulation options given on the command line, else ``defaults`` (a
    saved result's settings), else the library's."""
    out = SimulationSettings().to_dict()
    out.update({k: v for k, v in (defaults or {}).items() if k in out})
    for key in out:
        value = getattr(args, key)
        if value is not None:
            out[key] = value
    return SimulationSettings(**out)


def parse_assignments(items, option: str) -> dict:
    """``NAME=VALUE`` strings to a dict of floats."""
    out = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise ValueError(f"`{option}` expects NAME=VALUE, got {item!r}")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise ValueError(f"`{option} {name}`: value {value!r} is not a number") from None
    return out


def parse_bounds(items) -> dict:
    out = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        lo, sep2, hi = value.partition(":")
        try:
            if not sep or not sep2:
                raise ValueError
            out[name.strip()] = (float(lo), float(hi))
        except ValueError:
            raise ValueError(f"`--bounds` expects NAME=LOWER:UPPER, got {item!r}") from None
    return out


def output_unit(args) -> str:
    """The unit of the output column: m for the relative displacement, else the column's own."""
    if args.output_column == OUTPUT_CHANNEL:
        return unit(OUTPUT_CHANNEL)
    return f"{args.output_column} units"


def plot_units(args) -> dict:
    """``scale`` and ``unit`` of the output in ``--plot`` figures.

    The default output column is the relative displacement in m, which the
    figures show in mm (their default); a column the user named
    (``--output-column``) is shown as it is, in the record's own units.
    """
    if args.output_column == OUTPUT_CHANNEL:
        return {}
    return dict(scale=1.0, unit=output_unit(args))
