"""``randvib identify DATA.csv ... --model M``: fit a friction model (and a circuit) to records.

Paper Sec. 3, and beyond it: several records of one device at their loads,
any of the displacement, velocity, load voltage and current channels
(:mod:`randvib.identification.experiment_fit`).
"""

from __future__ import annotations

import sys
from pathlib import Path

from randvib._io import claim_output_file, dumps, write_or_keep
from randvib._validation import MAX_SEED, integer_option
from randvib.cli import COMMAND_HELP
from randvib.cli._output import print_table
from randvib.cli._records import (
    add_circuit_arguments,
    add_record_arguments,
    bridge_options,
    output_kinds,
    output_unit,
    parse_assignments,
    parse_bounds,
    parse_weights,
    plot_units,
    r_loads,
    record_from_args,
    simulation_settings,
)
from randvib.formatting import with_standard_error
from randvib.identification.identify import identify
from randvib.identification.least_squares import COVARIANCE_METHODS
from randvib.identification.models import MODELS
from randvib.identification.settings import SearchSettings
from randvib.models.record import OUTPUT_CHANNEL
from randvib.quantities import unit

DEFAULT = SearchSettings()


def register(sub) -> None:
    p = sub.add_parser(
        "identify",
        help=COMMAND_HELP["identify"],
        description="Fit the device model (Eq. 1) with a friction model, and with --coupling "
        "its circuit, to CSV records of one device (each at its own --r-load) by minimising J "
        "(Eq. 11, per channel and summed) with self-adaptive differential evolution; what the "
        "records cannot fix is refused first, naming what to add.",
    )
    p.add_argument(
        "data",
        nargs="+",
        metavar="DATA.csv",
        help="record(s) of one device: time, input and output columns (one record per load)",
    )
    p.add_argument(
        "--model",
        required=True,
        choices=tuple(MODELS),
        help="friction model (viscous = the paper's no-friction model)",
    )
    p.add_argument(
        "--m",
        type=float,
        help="mass (kg); required for base excitation unless the records fix it (identify says), "
        "identified if omitted with a force input",
    )
    p.add_argument("--seed", type=integer_option(0, MAX_SEED), default=0, help="random seed")
    p.add_argument(
        "--fix", action="append", metavar="NAME=VALUE", help="hold a parameter, e.g. --fix k3=0"
    )
    p.add_argument(
        "--bounds", action="append", metavar="NAME=LO:HI", help="override a search range"
    )
    p.add_argument(
        "--quadratic", action="store_true", help="also estimate k2: force k z + k2 z^2 + k3 z^3"
    )
    p.add_argument(
        "--popsize",
        type=integer_option(6),
        default=DEFAULT.popsize,
        help="SaDE population, popsize",
    )
    p.add_argument(
        "--generations",
        type=integer_option(0),
        default=DEFAULT.maxiter,
        help="SaDE generations, the API's maxiter",
    )
    p.add_argument(
        "--search-samples",
        type=integer_option(1),
        metavar="N",
        help="search on the record's first N samples only; the polish fits all of it",
    )
    p.add_argument(
        "--no-polish",
        action="store_true",
        help="skip the least-squares polish (and the standard errors it gives)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument(
        "--save", metavar="FILE.json", help="also write the JSON result (a new file unless --force)"
    )
    p.add_argument(
        "--plot",
        metavar="FILE.png",
        help="measured vs simulated figure (a new file unless --force)",
    )
    p.add_argument(
        "--force", action="store_true", help="overwrite an existing --save or --plot file"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_record_arguments(p)
    add_circuit_arguments(p)
    p.set_defaults(handler=run)


def _new_file(path, option, overwrite=False):
    """Checked before the fit, so that a long fit is never thrown away at the end."""
    return None if path is None else claim_output_file(path, option, overwrite=overwrite)


def _save_plot(result, record, plot: Path, title: str, units: dict, json: bool = False) -> bool:
    """The figure of the first record; if it cannot be written now, say so and keep going
    (the result is printed).

    Returns whether the figure was written where asked (the exit status is 1 if not).
    """
    from randvib.identification.plots import figure_fit

    try:
        figure_fit(
            result.predict(record),
            plot,
            title=title,
            validation=False,
            diagnostics=result.residuals,
            **units,
        )
    except OSError as exc:
        print(f"randvib: could not write `--plot` {str(plot)!r} ({exc})", file=sys.stderr)
        return False
    print(f"wrote {plot}", file=sys.stderr if json else sys.stdout)
    return True


def run(args) -> int:
    save = _new_file(args.save, "--save", args.force)
    plot = _new_file(args.plot, "--plot", args.force)
    records = [record_from_args(path, args) for path in args.data]
    kinds = output_kinds(args)
    record = records[0]
    search = SearchSettings(
        popsize=args.popsize,
        maxiter=args.generations,
        seed=args.seed,
        polish=not args.no_polish,
        search_samples=args.search_samples,
    )
    rectifier = bridge_options(args)
    plain = len(records) == 1 and args.coupling is None and kinds == (OUTPUT_CHANNEL,)
    plain = plain and rectifier is None
    result = identify(
        record if plain else records,
        args.model,
        m=args.m,
        coupling=args.coupling,
        r_load=r_loads(args, len(records)),
        rectifier=rectifier,
        outputs=None if plain else kinds,
        weights=parse_weights(args.weight) or None,
        fixed=parse_assignments(args.fix, "--fix"),
        quadratic=args.quadratic,
        bounds=parse_bounds(args.bounds),
        search=search,
        simulation=simulation_settings(args),
        progress=not (args.no_progress or args.json),
    )
    out = result.to_dict()
    # not saved where asked (a full disk): the result is kept elsewhere, and the exit says so
    status = 0
    if (
        save is not None
        and write_or_keep(save, dumps(out, indent=2), "--save", overwrite=args.force) != save
    ):
        status = 1
    if plot is not None and not _save_plot(
        result, record, plot, f"{args.model} model on {record.name}", plot_units(args), args.json
    ):
        status = 1
    if args.json:
        print(dumps(out))
        return status
    print_report(result, records, output_unit(args))
    return status


def _status(name, se, free, at_bound) -> str:
    """``fixed``, ``identified`` or ``at lower/upper bound`` (where the search stopped: no estimate)."""
    if name in at_bound:
        return f"at {at_bound[name]} bound"
    return "identified" if name in se or name in free else "fixed"


def print_report(result, records, offset_unit: str | None = None) -> None:
    """The parameters with standard errors and 95 % intervals, J (per channel), what the
    records fix and why, the correlations.

    ``offset_unit``: the unit of the record's displacement column where it is not m (a
    column declared ``relative_displacement`` under another name is read in its own
    units), shown for ``output_offset``.
    """
    records = [records] if not isinstance(records, list | tuple) else records
    se, ci, at_bound = result.standard_errors, result.confidence_intervals, result.at_bound
    rows = [
        [
            name,
            *with_standard_error(value, se.get(name), ci.get(name)),
            offset_unit if name == "output_offset" and offset_unit else result.unit(name),
            _status(name, se, result.free, at_bound),
        ]
        for name, value in result.parameters.items()
    ]
    coupling = f" with the {result.coupling} coupling" if result.coupling else ""
    for record in records:
        print(
            f"model {result.model}{coupling} on {record.name} ({record.n} samples, "
            f"{record.input_kind} input; fitted: {', '.join(result.outputs)})"
        )
    print_table(rows, ["parameter", "value", "std. error", "95 % interval", "unit", "status"])
    print(
        f"J = {result.cost:.6g} (Eq. 11{', summed over channels' if result.channel_costs else ''}"
        f"); {result.nfev} simulations in {result.elapsed:.1f} s "
        f"({result.simulations_per_second:.0f} sims/s); {result.message}"
    )
    _print_channels(result)
    _print_start(result)
    if result.residuals is not None:
        print(result.residuals.summary())
    if result.identifiability is not None:
        ident = result.identifiability
        print(f"the records fix: {', '.join(ident.determined) or 'no free parameter'}")
        for reason in ident.reasons:
            print(f"  because {reason}")
    for note in result.notes:
        print(f"note: {note}")
    unc = result.uncertainty
    if unc is not None:
        names = list(unc.names)
        band = f", bandwidth {unc.bandwidth} samples" if unc.bandwidth else ""
        band += f", AR order {unc.ar_order}" if unc.ar_order else ""
        print(f"intervals: {COVARIANCE_METHODS[unc.method]}{band}")
        print(f"correlation matrix (residual noise s = {unc.noise_std:.4g}, {unc.dof} dof):")
        print_table(
            [
                [n, *(f"{x:+.3f}" for x in row)]
                for n, row in zip(names, unc.correlation, strict=True)
            ],
            ["", *names],
        )


def _print_channels(result) -> None:
    """J and RMS error of each record's channels (several channels or records)."""
    if not result.channel_costs:
        return
    print_table(
        [
            [row["record"], row["output"], "" if row["r_load"] is None else row["r_load"],
             row["cost"], f"{row['rms_error']:.4g} {unit(row['output'])}"]
            for row in result.channel_costs
        ],
        ["record", "channel", "R_L (ohm)", "J", "RMS error"],
    )  # fmt: skip


def _print_start(result) -> None:
    """Each record's initial state (z0 m, v0 m/s and the circuit's x0)."""
    units = {
        "z0": "m",
        "v0": "m/s",
        "x0": {"inductive": "A", "piezo": "V"}.get(result.coupling, ""),
    }
    parts = [
        f"{name} = {value:.6g} {units[name.partition('[')[0]]}".rstrip()
        for name, value in result.initial_state.items()
    ]
    print(f"initial state {', '.join(parts)}")
