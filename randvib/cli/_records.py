"""Record and simulation options shared by ``identify`` and ``validate``."""

from __future__ import annotations

import argparse

from randvib._validation import integer_option
from randvib.identification.circuit import COUPLING_PARAMETERS, OUTPUT_KINDS
from randvib.identification.input_reconstruction import AUTO_HOLD, HOLDS
from randvib.identification.settings import INITIAL_STATES, SimulationSettings
from randvib.models.record import INPUT_KINDS, OUTPUT_CHANNEL, TIME_COLUMN, read_record
from randvib.quantities import unit


def add_record_arguments(parser: argparse.ArgumentParser) -> None:
    g = parser.add_argument_group("record (CSV columns)")
    g.add_argument(
        "--input-column", metavar="NAME", help="input column (default: the one named like its kind)"
    )
    g.add_argument("--input-kind", choices=INPUT_KINDS, help="what the input column holds")
    g.add_argument(
        "--output-kind",
        action="append",
        choices=OUTPUT_KINDS,
        metavar="KIND",
        help=f"what an output column holds, one of {', '.join(OUTPUT_KINDS)}; repeat for several "
        "channels, paired in order with --output-column (default: the column named like its kind, "
        "relative_displacement)",
    )
    g.add_argument(
        "--output-column",
        action="append",
        metavar="NAME",
        help="an output column, fitted only as its --output-kind (a column named like a kind "
        "needs none); repeat for several",
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


def output_pairs(args) -> list[tuple[str, str]]:
    """The (kind, column) pairs of ``--output-kind`` / ``--output-column``, in order.

    A column is fitted only as the kind declared for it: without
    ``--output-kind`` each column must be named like a kind, and without
    ``--output-column`` each kind is the column of its name.
    """
    kinds = list(getattr(args, "output_kind", None) or [])
    columns = list(getattr(args, "output_column", None) or [])
    if not kinds and not columns:
        return [(OUTPUT_CHANNEL, OUTPUT_CHANNEL)]
    if not kinds:
        unknown = [c for c in columns if c not in OUTPUT_KINDS]
        if unknown:
            raise ValueError(
                f"`--output-column` {unknown[0]!r}: say what it holds with `--output-kind "
                f"{'|'.join(OUTPUT_KINDS)}` (a column is fitted only as its declared kind)"
            )
        kinds = list(columns)
    if not columns:
        columns = list(kinds)
    if len(kinds) != len(columns):
        raise ValueError(
            f"`--output-kind` and `--output-column` pair in order: got {len(kinds)} kind(s) and "
            f"{len(columns)} column(s); give one column per kind"
        )
    if len(set(kinds)) != len(kinds):
        raise ValueError(f"`--output-kind` names a kind twice: {', '.join(kinds)}")
    return list(zip(kinds, columns, strict=True))


def output_kinds(args) -> tuple:
    """The kinds of the output channels (see :func:`output_pairs`)."""
    return tuple(kind for kind, _ in output_pairs(args))


def record_from_args(path, args, name=None):
    return read_record(
        path,
        input_column=args.input_column,
        input_kind=args.input_kind,
        outputs=dict(output_pairs(args)),
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


def add_circuit_arguments(parser: argparse.ArgumentParser, *, identified: bool = True) -> None:
    """``--coupling`` and ``--r-load`` (one per record, or one for all) of a record's circuit."""
    g = parser.add_argument_group("circuit (the records' coupling and loads)")
    g.add_argument(
        "--coupling",
        choices=tuple(COUPLING_PARAMETERS),
        help=(
            "identify the coupling with the mechanics: resistive (alpha, r_coil), inductive "
            "(alpha, r_coil, inductance) or piezo (theta, capacitance); c is then c_m"
            if identified
            else "the coupling of the device (default: the saved fit's)"
        ),
    )
    g.add_argument(
        "--r-load",
        type=float,
        action="append",
        metavar="OHM",
        help="each record's known load resistance R_L (ohm), in the records' order; one value "
        "for all records",
    )
    g.add_argument(
        "--rectifier",
        choices=("bridge",),
        help="the coupling's output goes through a known full-wave diode bridge into "
        "--storage-capacitance (each record's --r-load across it) or --battery; voltage is "
        "then the DC output voltage, current the load current (a battery's charging current)"
        + (
            ""
            if identified
            else "; default the saved fit's bridge (flags that contradict it are refused)"
        ),
    )
    g.add_argument("--v-diode", type=float, help="forward drop of each diode V_d (V); bridge")
    g.add_argument("--storage-capacitance", type=float, help="storage capacitor C (F); bridge")
    g.add_argument("--battery", type=float, help="battery voltage V_b (V); bridge")
    if identified:
        g.add_argument(
            "--weight",
            action="append",
            metavar="KIND=W",
            help="weight of an output kind's J in the sum (default 1 each)",
        )


#: The bridge's options of ``identify`` (:func:`bridge_options`).
BRIDGE_FLAGS = ("v_diode", "storage_capacitance", "battery")


def bridge_options(args) -> dict | None:
    """``--rectifier bridge`` and its known values as ``identify``'s ``rectifier`` (None: none)."""
    given = {n: getattr(args, n) for n in BRIDGE_FLAGS if getattr(args, n, None) is not None}
    if getattr(args, "rectifier", None) is None:
        if given:
            flag = "--" + next(iter(given)).replace("_", "-")
            raise ValueError(f"`{flag}` needs `--rectifier bridge`")
        return None
    return given


def parse_weights(items) -> dict:
    """``--weight KIND=W``: positive weights of output kinds."""
    out = {}
    for kind, value in parse_assignments(items, "--weight").items():
        if kind not in OUTPUT_KINDS:
            raise ValueError(f"`--weight {kind}`: not one of {', '.join(OUTPUT_KINDS)}")
        if not (value > 0 and value < float("inf")):
            raise ValueError(f"`--weight {kind}` must be a positive number, got {value!r}")
        out[kind] = value
    return out


def r_loads(args, count: int):
    """The records' loads from ``--r-load`` (None when not given)."""
    loads = getattr(args, "r_load", None)
    if not loads:
        return None
    if len(loads) == 1:
        return loads[0]
    if len(loads) != count:
        raise ValueError(
            f"`--r-load` gives {len(loads)} loads for {count} records: one for all, or one each"
        )
    return loads


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
    """The unit of the first output channel: its kind's (m for the relative displacement),
    except a displacement column named otherwise (``--output-column laser --output-kind
    relative_displacement``), which is read in the column's own units (a sensor's volts)."""
    kind, column = output_pairs(args)[0]
    if kind == OUTPUT_CHANNEL and column != kind:
        return f"{column} units"
    return unit(kind)


def plot_units(args) -> dict:
    """``scale`` and ``unit`` of the output in ``--plot`` figures.

    A channel in its kind's unit is shown as the figures choose (a
    displacement in mm); a displacement column in its own units
    (:func:`output_unit`) is shown as it is.
    """
    kind, column = output_pairs(args)[0]
    if kind != OUTPUT_CHANNEL or column == kind:
        return {}
    return dict(scale=1.0, unit=output_unit(args))
