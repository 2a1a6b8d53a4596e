"""``randvib validate PARAMS.json DATA.csv ...``: score identified parameters on other records."""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys

from randvib._io import check_output_file, check_output_folder, dumps, existing_file
from randvib.cli import COMMAND_HELP
from randvib.cli._output import print_table
from randvib.cli._records import (
    add_record_arguments,
    output_unit,
    parse_assignments,
    plot_units,
    record_from_args,
    simulation_settings,
)
from randvib.identification.models import MODELS, check_parameter, device_from_parameters
from randvib.identification.prediction import validate
from randvib.identification.settings import SimulationSettings

SIMULATION_FIELDS = tuple(SimulationSettings().to_dict())

#: What validate does with the fitted record's sensor offsets.
OFFSETS_NOTE = {
    "per-record": "the sensor offsets belong to a record, not to the device: on each record "
    "the file's, the output offset re-estimated and both re-estimated are scored and the "
    "lowest J kept (column `offsets`; `--offsets given` uses the file's throughout); the "
    "other parameters are the file's",
    "given": "the file's sensor offsets are used on every record (`--offsets given`)",
}


def register(sub) -> None:
    p = sub.add_parser(
        "validate",
        help=COMMAND_HELP["validate"],
        description="Simulate each record with parameters saved by `randvib identify --save` "
        "(or printed by --json) and report J (Eq. 11) and the RMS error per record.",
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
    return model, parameters, data.get("settings", {})


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
    """``--set NAME=VALUE``: a parameter of ``model``, valued as the model allows."""
    return {
        name: check_parameter(model, name, value, f"--set {name}")
        for name, value in parse_assignments(items, "--set").items()
    }


def run(args) -> int:
    model, parameters, saved = _load_parameters(args.params)
    for name, value in parameters.items():
        try:
            check_parameter(model, name, value)
        except ValueError as exc:
            raise ValueError(f"{str(args.params)!r}: {exc}") from None
    parameters.update(_overrides(args.set, model))
    harvester, measurement = device_from_parameters(model, parameters)
    settings = _settings(args, saved, args.params)
    plot_dir = plot_file = None
    if args.plot is not None and str(args.plot).lower().endswith(".png"):
        if len(args.data) != 1:
            raise ValueError(
                f"`--plot` {args.plot!r} is one file, for one record; got {len(args.data)} "
                "records: give a folder instead"
            )
        plot_file = check_output_file(args.plot, "--plot", overwrite=args.force)
    elif args.plot is not None:
        plot_dir = check_output_folder(args.plot, "--plot")
        if plot_dir.exists() and any(plot_dir.iterdir()) and not args.force:
            raise FileExistsError(
                f"`--plot` folder {str(plot_dir)!r} is not empty; choose another or give --force"
            )
        plot_dir.mkdir(parents=True, exist_ok=True)
    records = [record_from_args(path, args) for path in args.data]
    rows = validate(
        harvester, records, measurement=measurement, offsets=args.offsets, simulation=settings
    )
    status = 0  # 1: the figures could not be written where asked (the table is printed)
    if plot_dir is not None or plot_file is not None:
        status = _figures(args, model, harvester, measurement, settings, records, rows,
                          plot_file, plot_dir)  # fmt: skip
    if args.json:
        print(
            dumps(
                {
                    "model": model,
                    "parameters": parameters,
                    "records": [r.to_dict() for r in rows],
                    "offsets": OFFSETS_NOTE[args.offsets],
                }
            )
        )
        return status
    print(f"model {model}")
    print_table(
        [[r.record, r.samples, r.cost, r.rms_error, r.offsets_source, _verdict(r)] for r in rows],
        ["record", "samples", "J", f"RMS error ({output_unit(args)})", "offsets", "residual"],
    )
    print(f"note: {OFFSETS_NOTE[args.offsets]}")
    if any(r.verdict == "structured" for r in rows):
        print(
            "note: a structured residual (Ljung-Box p < 0.01, or correlated with the input) "
            "is what the model misses on that record: its J is not noise alone"
        )
    return status


def _verdict(row) -> str:
    """The residual's verdict with its Ljung-Box p-value, for the table."""
    if row.residuals is None:
        return ""
    return f"{row.verdict} (p = {row.residuals.ljung_box_p:.2g})"


def _figures(args, model, harvester, measurement, settings, records, rows, plot_file, plot_dir):
    """One figure per record, as validated (its offsets, its residual diagnostics); the exit
    status: 1 if a figure could not be written (the table is printed anyway)."""
    from randvib.identification.plots import figure_fit
    from randvib.identification.prediction import predict_record

    for i, (record, row) in enumerate(zip(records, rows, strict=True)):
        own = dataclasses.replace(measurement, **row.offsets)  # as its J was scored
        pred = predict_record(harvester, record, measurement=own, simulation=settings)
        path = plot_file or plot_dir / f"{i:02d}_{record.name}.png"
        try:
            figure_fit(
                pred,
                path,
                title=f"{model} model on {record.name}",
                validation=True,
                diagnostics=row.residuals,
                **plot_units(args),
            )
        except OSError as exc:  # the table is the result: print it, exit 1
            print(f"randvib: could not write `--plot` {str(path)!r} ({exc})", file=sys.stderr)
            return 1
    print(
        f"wrote {plot_file}" if plot_file else f"wrote {len(records)} figure(s) into {plot_dir}",
        file=sys.stderr if args.json else sys.stdout,
    )
    return 0
