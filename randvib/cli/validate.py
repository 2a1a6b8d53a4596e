"""``randvib validate PARAMS.json DATA.csv ...``: score identified parameters on other records."""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys

import numpy as np

from randvib._io import check_output_file, check_output_folder, dumps, existing_file
from randvib._validation import check_finite
from randvib.cli import COMMAND_HELP
from randvib.cli._device import option_flag
from randvib.cli._output import print_table
from randvib.cli._records import (
    BRIDGE_FLAGS,
    add_circuit_arguments,
    add_record_arguments,
    bridge_options,
    output_kinds,
    output_unit,
    parse_assignments,
    plot_units,
    r_loads,
    record_from_args,
    simulation_settings,
)
from randvib.identification.circuit import (
    ALL_COUPLING_PARAMETERS,
    BRIDGE_NOTE,
    OFFSET_NAMES,
    bridge_from_parameters,
    check_coupling_parameter,
    coupling_from_parameters,
    saved_rectifier,
)
from randvib.identification.models import (
    MODELS,
    MeasurementModel,
    check_parameter,
    device_from_parameters,
)
from randvib.identification.prediction import validate
from randvib.identification.settings import SimulationSettings
from randvib.models.record import OUTPUT_CHANNEL
from randvib.quantities import unit

SIMULATION_FIELDS = tuple(SimulationSettings().to_dict())

#: What validate does with the fitted record's sensor offsets.
OFFSETS_NOTE = {
    "per-record": "the sensor offsets belong to a record, not to the device: on each record "
    "the file's, the output offsets re-estimated and (with an input offset) both re-estimated "
    "are scored and the lowest J kept (column `offsets`; `--offsets given` uses the file's "
    "throughout); the other parameters are the file's",
    "given": "the file's sensor offsets are used on every record (`--offsets given`)",
}


def register(sub) -> None:
    p = sub.add_parser(
        "validate",
        help=COMMAND_HELP["validate"],
        description="Simulate each record with parameters saved by `randvib identify --save` "
        "(or printed by --json) and report J (Eq. 11) and the RMS error per record and "
        "channel (a voltage's in volts, each record at its own --r-load).",
    )
    p.add_argument(
        "params", metavar="PARAMS.json", help="output of `randvib identify --json/--save`"
    )
    p.add_argument("data", nargs="+", metavar="DATA.csv", help="records to score")
    p.add_argument(
        "--set", action="append", metavar="NAME=VALUE", help="override a parameter value"
    )
    p.add_argument(
        "--offsets",
        choices=("per-record", "given"),
        default="per-record",
        help="sensor offsets: re-estimated on each record (default; they belong to a "
        "record) or the file's on every record",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument(
        "--no-progress",
        action="store_true",
        help="no progress display (validate shows none; accepted as by every command)",
    )
    p.add_argument(
        "--plot",
        metavar="FILE.png|DIR",
        help="measured-vs-simulated figure: FILE.png (a new file) for one record, as identify "
        "--plot takes; DIR for one PNG per record",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="overwrite an existing --plot file, or write into a folder that is not empty",
    )
    add_record_arguments(p)
    add_circuit_arguments(p, identified=False)
    p.set_defaults(handler=run)


def _load_parameters(path):
    path = existing_file(path, "parameter file", "JSON")
    try:
        data = json.loads(path.read_text())
        model = data["model"]
        parameters = {k: float(v) for k, v in data["parameters"].items()}
    except (ValueError, KeyError, TypeError, AttributeError):
        raise ValueError(
            f"{str(path)!r} is not an identification result (JSON with 'model' and 'parameters')"
        ) from None
    if not isinstance(model, str) or model not in MODELS:
        raise ValueError(f"{str(path)!r}: model {model!r} is not one of {', '.join(MODELS)}")
    if not isinstance(data, dict):
        raise ValueError(f"{str(path)!r} is not an identification result (a JSON object)")
    return model, parameters, data


def _settings(args, saved: dict, path):
    """The simulation settings: the command line's over the file's, each checked as identify's."""
    if not isinstance(saved, dict):
        raise ValueError(f"{str(path)!r}: 'settings' must be a JSON object, got {saved!r}")
    try:
        simulation_settings(argparse.Namespace(**dict.fromkeys(SIMULATION_FIELDS)), saved)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{str(path)!r}: settings: {exc}") from None
    return simulation_settings(args, saved)


def _overrides(items, model: str) -> dict:
    """``--set NAME=VALUE``: a parameter of ``model`` (or its coupling), valued as allowed."""
    out = {}
    for name, value in parse_assignments(items, "--set").items():
        if name in ALL_COUPLING_PARAMETERS:
            out[name] = check_coupling_parameter(name, value, f"--set {name}")
        else:
            out[name] = check_parameter(model, name, value, f"--set {name}")
    return out


def _device(model, parameters, data, path, args):
    """The saved device and its measurement model (the first record's offsets).

    A fit that identified its coupling is wired to each record's load
    (``--r-load``, default the fit's first), through the diode bridge it was
    fitted behind (:func:`_bridge`); returns (harvester, measurement, loads or
    None: a battery has no load).
    """
    own = {k.partition("[")[0]: v for k, v in parameters.items() if not k.endswith("]")}
    own.update({k.partition("[")[0]: v for k, v in parameters.items() if k.endswith("[0]")})
    measurement = MeasurementModel.from_parameters(own)
    coupling = data.get("coupling") or None
    bridge = _bridge(data, path, args)
    if coupling is None:
        if args.coupling is not None or args.r_load or bridge:
            raise ValueError(
                f"{str(path)!r} holds no identified coupling: `--coupling`/`--r-load`/"
                "`--rectifier` need a fit made with `identify --coupling`"
            )
        return device_from_parameters(model, own)[0], measurement, None
    if args.coupling not in (None, coupling):
        raise ValueError(f"{str(path)!r} identified the {coupling} coupling, not {args.coupling!r}")
    loads = data.get("r_loads") or []
    default = float(loads[0]) if loads else None
    given = r_loads(args, len(args.data))
    if given is None and default is None:
        raise ValueError(f"{str(path)!r} saves no load: give each record's `--r-load`")
    loads = given if given is not None else default
    if bridge:
        electrical = bridge_from_parameters(coupling, own, bridge, np.ravel(loads)[0])
        loads = None if "battery" in bridge else loads  # the battery's is no load
    else:
        electrical = coupling_from_parameters(coupling, own, np.ravel(loads)[0])
    return device_from_parameters(model, own, electrical)[0], measurement, loads


def _bridge(data: dict, path, args) -> dict:
    """The known diode bridge to simulate through ({} for none).

    The file's ``rectifier`` (a fit made behind a bridge); the bridge flags
    may repeat its values, and one that differs is refused. A fit made
    without a bridge is scored behind the one the flags give
    (``--rectifier bridge`` with ``--storage-capacitance`` or ``--battery``).
    """
    saved = saved_rectifier(data.get("rectifier"), f"{str(path)!r}: `rectifier`")
    given = {n: getattr(args, n) for n in BRIDGE_FLAGS if getattr(args, n, None) is not None}
    if not saved:
        notes = data.get("notes") or []
        if not given and any(str(n).startswith(BRIDGE_NOTE) for n in notes):
            raise ValueError(
                f'{str(path)!r} was fitted behind a diode bridge but saves no "rectifier" field (an '
                "older file): give it with `--rectifier bridge --v-diode V --storage-capacitance "
                "C | --battery V`"
            )
        options = bridge_options(args) or {}
        if args.rectifier is not None and ("battery" in options) == (
            "storage_capacitance" in options
        ):
            raise ValueError(
                "`--rectifier bridge` needs exactly one output: `--storage-capacitance C` (each "
                "record's `--r-load` across it) or `--battery V`"
            )
        return {"v_diode": 0.0, **options} if options else {}
    for name, value in given.items():
        if name not in saved or not math.isclose(value, saved[name], rel_tol=1e-9):
            held = ", ".join(f"{k} = {v:g}" for k, v in saved.items())
            raise ValueError(
                f"`{option_flag(name)} {value:g}` contradicts {str(path)!r}, fitted behind a "
                f"bridge with {held}: drop the flag (the file's bridge is used)"
            )
    return saved


def _kinds(args, data) -> tuple:
    """The channels scored: the command line's, else the fit's."""
    if args.output_kind or args.output_column:
        return output_kinds(args)
    saved = tuple(data.get("outputs") or ("relative_displacement",))
    args.output_kind = list(saved)  # the records are read with these channels
    return saved


def run(args) -> int:
    model, parameters, data = _load_parameters(args.params)
    for name, value in parameters.items():
        base = name.partition("[")[0]
        try:
            if base in ALL_COUPLING_PARAMETERS:
                check_coupling_parameter(base, value)
            elif base in OFFSET_NAMES.values():
                check_finite(name, value)
            else:
                check_parameter(model, base, value)
        except ValueError as exc:
            raise ValueError(f"{str(args.params)!r}: {exc}") from None
    parameters.update(_overrides(args.set, model))
    harvester, measurement, loads = _device(model, parameters, data, args.params, args)
    kinds = _kinds(args, data)
    settings = _settings(args, data.get("settings", {}), args.params)
    plot_dir, plot_file = _plot_target(args)
    records = [record_from_args(path, args) for path in args.data]
    channels = kinds != ("relative_displacement",) or loads is not None
    rows = validate(
        harvester, records, measurement=measurement, offsets=args.offsets, simulation=settings,
        **({"outputs": kinds, "r_load": loads} if channels else {}),
    )  # fmt: skip
    status = 0  # 1: the figures could not be written where asked (the table is printed)
    if plot_dir is not None or plot_file is not None:
        status = _figures(harvester, records, rows, measurement, settings, kinds, channels,
                          plot_dir, plot_file, model, args)  # fmt: skip
    if args.json:
        print(dumps(_json(model, parameters, rows, kinds, args)))
        return status
    _print(model, rows, kinds, args)
    return status


def _plot_target(args):
    """(folder, file) of ``--plot``, checked before anything is computed."""
    if args.plot is None:
        return None, None
    if str(args.plot).lower().endswith(".png"):
        if len(args.data) != 1:
            raise ValueError(
                f"`--plot` {args.plot!r} is one file, for one record; got {len(args.data)} "
                "records: give a folder instead"
            )
        return None, check_output_file(args.plot, "--plot", overwrite=args.force)
    plot_dir = check_output_folder(args.plot, "--plot")
    if plot_dir.exists() and any(plot_dir.iterdir()) and not args.force:
        raise FileExistsError(
            f"`--plot` folder {str(plot_dir)!r} is not empty; choose another or give --force"
        )
    plot_dir.mkdir(parents=True, exist_ok=True)
    return plot_dir, None


def _figures(harvester, records, rows, measurement, settings, kinds, channels, plot_dir,
             plot_file, model, args) -> int:  # fmt: skip
    """One figure per record, as validated (its offsets, its residual diagnostics): time history,
    residual, densities (the voltage's spike at 0 V); the exit status: 1 if a figure could not
    be written (the table is printed anyway)."""
    from randvib.identification.plots import figure_fit
    from randvib.identification.prediction import predict_record

    for i, (record, row) in enumerate(zip(records, rows, strict=True)):
        # the offsets re-estimated on this record, as its J
        device = harvester if row.r_load is None else harvester.updated(r_load=row.r_load)
        own = _offsets(measurement, row.offsets)
        pred = predict_record(device, record, measurement=own, simulation=settings,
                              **({"outputs": kinds} if channels else {}))  # fmt: skip
        path = plot_file or plot_dir / f"{i:02d}_{record.name}.png"
        try:
            # the residual diagnostics the table reports (the first channel's)
            figure_fit(pred, path, title=f"{model} model on {record.name}", validation=True,
                       diagnostics=row.residuals, **plot_units(args))  # fmt: skip
        except OSError as exc:  # the table is the result: print it, exit 1
            print(f"randvib: could not write `--plot` {str(path)!r} ({exc})", file=sys.stderr)
            return 1
    print(
        f"wrote {plot_file}" if plot_file else f"wrote {len(records)} figure(s) into {plot_dir}",
        file=sys.stderr if args.json else sys.stdout,
    )
    return 0


def _offsets(measurement, used: dict):
    """``measurement`` with the offsets a validation row used on its record."""
    channel = {k: used[n] for k, n in OFFSET_NAMES.items() if k != OUTPUT_CHANNEL and n in used}
    return dataclasses.replace(
        measurement,
        input_offset=used.get("input_offset", measurement.input_offset),
        output_offset=used.get("output_offset", measurement.output_offset),
        channel_offsets={**measurement.channel_offsets, **channel},
    )


def _json(model, parameters, rows, kinds, args) -> dict:
    return {
        "model": model,
        "parameters": parameters,
        "outputs": list(kinds),
        "records": [
            {
                **r.to_dict(),
                **(
                    {"channels": {k: {**v, "unit": unit(k)} for k, v in r.channels.items()}}
                    if r.channels
                    else {}
                ),
            }
            for r in rows
        ],
        "offsets": OFFSETS_NOTE[args.offsets],
    }


def _print(model, rows, kinds, args) -> None:
    print(f"model {model}")
    if not any(r.channels for r in rows):
        print_table(
            [[r.record, r.samples, r.cost, r.rms_error, r.offsets_source, _verdict(r)]
             for r in rows],
            ["record", "samples", "J", f"RMS error ({output_unit(args)})", "offsets", "residual"],
        )  # fmt: skip
    else:
        print_table(
            [
                [r.record, "" if r.r_load is None else r.r_load, kind, r.samples, v["cost"],
                 f"{v['rms_error']:.4g} {unit(kind)}", r.offsets_source,
                 _verdict(r) if i == 0 else ""]
                for r in rows
                for i, (kind, v) in enumerate(r.channels.items())
            ],
            ["record", "R_L (ohm)", "channel", "samples", "J", "RMS error", "offsets",
             "residual"],
        )  # fmt: skip
    print(f"note: {OFFSETS_NOTE[args.offsets]}")
    if any(r.verdict == "structured" for r in rows):
        print(
            "note: a structured residual (Ljung-Box p < 0.01, or correlated with the input) "
            "is what the model misses on that record: its J is not noise alone"
            + ("" if not any(r.channels for r in rows) else " (the first channel's residual)")
        )


def _verdict(row) -> str:
    """The residual's verdict with its Ljung-Box p-value, for the table."""
    if row.residuals is None:
        return ""
    return f"{row.verdict} (p = {row.residuals.ljung_box_p:.2g})"
