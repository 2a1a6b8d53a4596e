"""``randvib reliability``: end-stop strikes at rare levels (:func:`randvib.first_passage`).

The device, excitation and simulation options are ``simulate``'s
(:mod:`randvib.cli._device`, :mod:`randvib.cli._excitation`); ``--stroke``
is required and ``--duration`` is the window. The table gives each estimate
with its 95 % half-width beside the analytic anchor of the case, when one
takes it (:mod:`randvib.analytic.crossings`: exact for a linear device, and
for a friction-free one under white noise, in the stationary exceedance and
the crossing rate; Poisson's approximation for the first passage).

``--device FILE.toml`` estimates an assembly's (docs/assemblies.md) on one
relative coordinate, ``--stroke-on element.N`` or ``transducer.N`` (default:
the file's one part with a stroke), with ``--stroke`` overriding that part's
stroke; under white noise or a rational spectrum (its Brownian increments),
importance sampling for a linear assembly only. Its anchor is exact for a
linear assembly (:mod:`randvib.analytic.assembly_crossings`); the JSON adds
``device`` and ``stroke_on``.
"""

from __future__ import annotations

from randvib._io import dumps
from randvib._validation import MAX_SEED, integer_option
from randvib.cli import COMMAND_HELP
from randvib.cli._device import add_device_arguments, assembly_from_args, harvester_from_args
from randvib.cli._excitation import add_excitation_arguments, excitation_from_args
from randvib.cli._output import describe_device, describe_excitation, print_table, with_units
from randvib.formatting import cell, estimate_parts
from randvib.montecarlo.integrators import INTEGRATORS
from randvib.quantities import unit

#: The estimators (randvib.montecarlo.reliability.METHODS; listed here so that the
#: parser does not import the Monte Carlo stack).
METHODS = ("subset", "importance", "crude")
#: The table's estimates, in order.
ROWS = ("probability_first_passage", "upcrossing_rate", "stationary_exceedance")


def register(sub) -> None:
    p = sub.add_parser(
        "reliability",
        help=COMMAND_HELP["reliability"],
        description="Estimate the probability that abs(z) reaches the stroke within a window "
        "from the stationary state, the rate of up-crossings of the stroke and the stationary "
        "exceedance, down to 1e-9, by subset simulation, importance sampling or crude Monte "
        "Carlo; 95 % half-widths.",
    )
    add_device_arguments(p)
    add_excitation_arguments(p)
    g = p.add_argument_group("rare-event estimate")
    g.add_argument("--duration", type=float, required=True, help="window T (s), > 0")
    g.add_argument(
        "--stroke-on",
        metavar="PART",
        default=None,
        help="with --device: the coordinate whose stroke is monitored, element.N or "
        "transducer.N (default: the file's one part with a stroke; --stroke overrides its stroke)",
    )
    g.add_argument(
        "--method",
        default="subset",
        choices=METHODS,
        help="estimator: subset simulation (any device), importance sampling (a change of "
        "drift to the design points; exact for linear devices, refused where its weights "
        "degenerate) or crude Monte Carlo",
    )
    g.add_argument(
        "--target-cov",
        type=float,
        default=0.1,
        help="coefficient of variation of the first-passage probability to reach, in (0, 1)",
    )
    g.add_argument(
        "--dt",
        type=float,
        default=None,
        help="time step (s) (default: a stationary-variance bias below 1e-4 on the linearised "
        "device and at the stroke's stiffness)",
    )
    g.add_argument("--scheme", default="heun", choices=tuple(INTEGRATORS), help="integrator")
    g.add_argument(
        "--burn-in",
        type=float,
        default=None,
        help="unmonitored time before the window (s) (default: 0 where the start is exact, "
        "10 m / c_eq where it is linearised)",
    )
    g.add_argument(
        "--samples-per-level",
        type=integer_option(100),
        default=1000,
        help="subset simulation's samples per level (and per run)",
    )
    g.add_argument(
        "--max-path-steps",
        type=float,
        default=2e9,
        help="budget of integration steps (paths x steps); the run stops there",
    )
    g.add_argument(
        "--seed", type=integer_option(0, MAX_SEED), default=0, help="random seed (default 0)"
    )
    g.add_argument(
        "--threads", type=integer_option(1), default=None, help="threads (default: all cores)"
    )
    g.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(handler=run)


def run(args) -> int:
    import numba

    from randvib.analytic.crossings import crossing_prediction
    from randvib.montecarlo.reliability import first_passage

    if getattr(args, "device", None) is not None:
        return _run_assembly(args)
    if args.stroke_on is not None:
        raise ValueError("`--stroke-on` names a part of an assembly: give it with --device FILE")
    harvester = harvester_from_args(args)
    excitation = excitation_from_args(args)
    if harvester.stroke is None:
        raise ValueError("`--stroke` is required: the first passage is to |z| = stroke")
    if args.threads is not None:
        numba.set_num_threads(min(args.threads, numba.config.NUMBA_NUM_THREADS))
    result = first_passage(
        harvester, excitation, duration=args.duration, method=args.method,
        target_cov=args.target_cov, dt=args.dt, scheme=args.scheme, seed=args.seed,
        burn_in=args.burn_in, samples_per_level=args.samples_per_level,
        max_path_steps=args.max_path_steps,
        progress=False if args.no_progress or args.json else None,
    )  # fmt: skip
    summary = result.to_dict()
    if args.json:
        print(dumps(with_units(summary, harvester.electrical)))
        return 0
    try:
        anchor = crossing_prediction(harvester, excitation, result.stroke, result.duration)
    except ValueError:
        anchor = None
    rows = _rows(summary, anchor)
    print(describe_device(harvester))
    print(describe_excitation(excitation))
    title = "analytic" if anchor is None else f"analytic ({anchor.method})"
    print_table(rows, ("quantity", args.method, "± 95 %", title, "unit"))
    if anchor is not None:
        print("* approximate (Poisson crossings); unmarked analytic values are exact")
    ratio = result.path_steps / result.crude_path_steps if result.crude_path_steps else None
    print(
        f"stroke {result.stroke:g} m, window {result.duration:g} s, dt {result.dt:g} s, start: "
        f"{result.start}; {result.path_steps:.3g} path-steps"
        + ("" if ratio is None else f" ({ratio:.2g} of crude Monte Carlo's for this c.o.v.)")
    )
    return 0


def _run_assembly(args) -> int:
    """``--device``: the first passage of one coordinate of an assembly."""
    import numba

    from randvib.analytic.assembly_crossings import assembly_crossing_prediction
    from randvib.montecarlo.reliability import first_passage

    stroke, args.stroke = args.stroke, None  # here the monitored coordinate's, not a device's
    assembly = assembly_from_args(args)
    excitation = excitation_from_args(args)
    if args.threads is not None:
        numba.set_num_threads(min(args.threads, numba.config.NUMBA_NUM_THREADS))
    result = first_passage(
        assembly, excitation, duration=args.duration, stroke=stroke, stroke_on=args.stroke_on,
        method=args.method, target_cov=args.target_cov, dt=args.dt, scheme=args.scheme,
        seed=args.seed, burn_in=args.burn_in, samples_per_level=args.samples_per_level,
        max_path_steps=args.max_path_steps,
        progress=False if args.no_progress or args.json else None,
    )  # fmt: skip
    summary = {"device": args.device, "stroke_on": result.details["stroke_on"], **result.to_dict()}
    if args.json:
        print(dumps(with_units(summary)))
        return 0
    anchor = None
    if assembly.is_linear:
        anchor = assembly_crossing_prediction(assembly, excitation, result.stroke, result.duration,
                                              summary["stroke_on"])  # fmt: skip
    rows = _rows(summary, anchor)
    print(f"device: {args.device}: {assembly.describe()}")
    print(describe_excitation(excitation))
    title = "analytic" if anchor is None else "analytic (rice)"
    print_table(rows, ("quantity", args.method, "± 95 %", title, "unit"))
    if anchor is not None:
        print("* approximate (Poisson crossings); unmarked analytic values are exact")
    print(
        f"coordinate {summary['stroke_on']}, stroke {result.stroke:g} m, window "
        f"{result.duration:g} s, dt {result.dt:g} s, start: {result.start}; "
        f"{result.path_steps:.3g} path-steps"
    )
    return 0


def _rows(summary: dict, anchor) -> list[tuple]:
    """The table's rows: each quantity's estimate and 95 % half-width beside the analytic
    value of ``anchor`` (None: none), marked * where that is the Poisson approximation."""
    rows = []
    for name in ROWS:
        s = summary[name]
        reference = ""
        if anchor is not None:
            value = anchor.first_passage_poisson if name == ROWS[0] else getattr(anchor, name)
            reference = cell(value) + ("" if name in anchor.exact else "*")
        rows.append((name, *estimate_parts(s["mean"], s["ci95"]), reference, unit(name)))
    return rows
