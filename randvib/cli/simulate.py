"""``randvib simulate``: Monte Carlo ensemble under white, coloured or recorded base acceleration.

``--envelope`` makes the input an event from t = 0 (:mod:`randvib.cli._event`,
:func:`randvib.simulate_transient`): a time-resolved table at ``--times``.

White noise by default (``--psd``); ``--excitation band-pass|kanai-tajimi``
integrates the shaping filter with the device, ``band-limited`` and
``--psd-file`` are synthesised path by path (the options of
:mod:`randvib.cli._excitation`, shared with ``randvib power``); ``--record
FILE`` simulates the device on the record itself
(:func:`randvib.monte_carlo_on_record`), ``--segments`` windows giving the
interval.

``--device FILE.toml`` simulates an assembly (docs/assemblies.md;
:func:`randvib.simulate` with an :class:`~randvib.models.assembly.Assembly`):
``--json`` gives ``transducers`` (a list in file order, each with
``power_electrical`` and, where they apply, ``power_load``, ``power_stored``,
``power_coil_loss``, ``power_diode_loss``, ``circuit_mean_square``, the
coordinate's variances, as {mean, ci95}), ``displacement_variance`` and
``velocity_variance`` (lists per DOF, {mean, ci95}), ``elements``,
``power_dissipated`` and, under white noise, ``power_input`` (r^T M r S / 4).
Tones (``--tone``), shocks (``--shock-*``) and translated input
(``--kurtosis``, ``--marginal``) reach the assembly as they reach the single mass.
"""

from __future__ import annotations

from randvib._io import dumps
from randvib._validation import MAX_SEED, integer_option
from randvib.analytic.prediction import METHODS, predict
from randvib.cli import COMMAND_HELP
from randvib.cli._device import add_device_arguments, assembly_from_args, harvester_from_args
from randvib.cli._event import add_event_arguments, simulate_event, wants_event
from randvib.cli._excitation import add_excitation_arguments, excitation_from_args
from randvib.cli._output import describe_device, describe_excitation, print_table, with_units
from randvib.formatting import cell, estimate_parts, proportion
from randvib.montecarlo.integrators import INTEGRATORS
from randvib.montecarlo.results import STATISTICS
from randvib.quantities import unit


def register(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help=COMMAND_HELP["simulate"],
        description="Simulate an ensemble of the harvester under white-noise, coloured "
        "(filtered or synthesised) or recorded base acceleration; statistics with 95 % "
        "confidence half-widths.",
    )
    add_device_arguments(p)
    add_excitation_arguments(p)
    add_event_arguments(p)
    g = p.add_argument_group("simulation")
    g.add_argument(
        "--paths",
        type=integer_option(2),  # the table's intervals need two paths
        default=None,
        help="number of paths, n_paths, >= 2 for the confidence intervals (default: 1000)",
    )
    g.add_argument(
        "--t-end",
        type=float,
        default=None,
        help="time per path incl. burn-in (s) (default: 20; not with --record, whose length "
        "it is; with --envelope the end of the event window, by default the last of --times)",
    )
    g.add_argument(
        "--dt",
        type=float,
        default=None,
        help="time step (s), default 1e-4; with --record the record's step or a divisor of it",
    )
    g.add_argument(
        "--segments",
        type=integer_option(2),
        default=None,
        help="with --record: windows the record is cut into, one batch mean each (default 10)",
    )
    g.add_argument(
        "--burn-in",
        type=float,
        default=None,
        help="discarded initial time (s) (default: 2; not with --envelope: an event starts "
        "at t = 0)",
    )
    g.add_argument(
        "--method",
        default="heun",
        choices=tuple(INTEGRATORS),
        metavar="SCHEME",
        help=f"integrator (the API's `scheme`): {', '.join(INTEGRATORS)}",
    )
    g.add_argument(
        "--seed", type=integer_option(0, MAX_SEED), default=0, help="random seed (default 0)"
    )
    g.add_argument(
        "--threads", type=integer_option(1), default=None, help="threads (default: all cores)"
    )
    g.add_argument(
        "--control-variates",
        action="store_true",
        help="variance-reduced estimates (energy balance, and under white noise the "
        "friction-free companion); white, band-pass and kanai-tajimi input",
    )
    g.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--force", action="store_true", help="overwrite an existing --plot file")
    p.set_defaults(handler=run)


def run(args) -> int:
    from randvib.montecarlo.simulation import simulate

    assembly = assembly_from_args(args)
    if assembly is not None:
        return _run_assembly(args, assembly)
    harvester = harvester_from_args(args)
    psd = excitation_from_args(args)
    if wants_event(args):
        return simulate_event(args, harvester, psd)
    burn_in = 2.0 if args.burn_in is None else args.burn_in
    white = isinstance(psd, float | int)
    _refuse_what_the_input_cannot_take(args, psd, white)
    if args.record is not None:
        result = _on_record(harvester, psd, args, burn_in)
    else:
        if args.segments is not None:
            raise ValueError("`--segments` cuts a record into paths; it needs `--record`")
        result = simulate(
            harvester,
            psd,
            t_end=20.0 if args.t_end is None else args.t_end,
            dt=1e-4 if args.dt is None else args.dt,
            n_paths=1000 if args.paths is None else args.paths,
            burn_in=burn_in,
            scheme=args.method,  # the CLI keeps its option name `--method`
            seed=args.seed,
            threads=args.threads,
            progress=False if args.no_progress or args.json else None,
            # the friction-free companion's exact moments hold under white noise
            # and the resistive coupling only; the energy-balance controls hold
            # for every coupling
            companion=args.control_variates
            and white
            and not (harvester.has_circuit or harvester.is_rectified),
            control_variates=args.control_variates,
        )
    summary = result.summary()
    if args.json:
        print(dumps(with_units(summary, harvester.electrical)))
        return 0
    analytic = None
    if METHODS["linearisation"].accepts(harvester, psd):
        try:
            analytic = predict(harvester, psd, "linearisation")
        except ValueError:  # e.g. no zero-mean Gaussian solution for this double well
            analytic = None
    rows = []
    for name in (*STATISTICS, "stroke_first_passage_time"):
        if summary.get(name) is None:
            continue
        s = summary[name]
        lin = getattr(analytic, name, None) if analytic is not None else None
        shown = _plus_minus(s["mean"], s["ci95"])
        if "ci95_lower" in s:  # a probability: its Wilson interval, which stays >= 0
            shown = proportion(s["mean"], s["ci95_lower"], s["ci95_upper"]).split(" ", 1)
        rows.append(
            (
                name,
                *shown,
                cell(lin),
                unit(name, harvester.electrical),
            )
        )
    first = summary.get("stroke_first_passage")
    if first is not None and first["mean"] is None:
        restricted = first["restricted_mean"]
        rows.append(
            (
                f"E[min(first passage, {first['horizon']:g} s)]",
                *_plus_minus(restricted["mean"], restricted["ci95"]),
                f"{first['paths_reached']}/{first['n_paths']} paths reached the stroke",
                unit("stroke_first_passage_time"),
            )
        )
    print(describe_device(harvester))
    print(describe_excitation(psd) if args.record is None else f"excitation: record {args.record}")
    # a half-width (± x), or a probability's interval [lower, upper]
    print_table(rows, ("statistic", "Monte Carlo", "95 %", "linearisation", "unit"))
    if args.record is not None:
        # one record is one realisation: its windows are batch means, not independent paths
        print(
            f"{result.n_paths} windows of the record x {result.averaging_time:g} s averaged "
            f"(batch means; lag-1 correlation between windows {result.lag1_correlation:+.2f}; "
            f"dt {result.dt:g} s, {result.scheme}), {result.wall_time:.2f} s wall"
        )
        return 0
    print(
        f"{result.n_paths} paths x {result.averaging_time:g} s averaged (dt {result.dt:g} s, "
        f"{result.scheme}, seed {result.seed}), {result.wall_time:.2f} s wall"
    )
    return 0


def _plus_minus(mean, half_width) -> tuple[str, str]:
    """A Monte Carlo mean and ``± half-width`` as table cells (the digits the interval allows)."""
    mean, half = estimate_parts(mean, half_width)
    return mean, f"± {half}" if half else ""


def _refuse_what_the_input_cannot_take(args, psd, white: bool) -> None:
    """The control variates without Gaussian noise alone, tones or shocks on a record: one line."""
    beyond = not white and (bool(psd.lines()) or not psd.is_gaussian)
    if args.control_variates and beyond:
        raise ValueError(
            f"`--control-variates` needs Gaussian noise alone: under the {psd.name} input no "
            "control has a known mean"
        )
    if args.control_variates and not white and psd.shaping_filter() is None:
        raise ValueError(
            "`--control-variates` needs white noise or a filtered spectrum (band-pass, "
            f"kanai-tajimi): under the synthesised or recorded {psd.name} input no control "
            "has a known mean"
        )
    if args.record is not None and beyond:
        extra = "`--tone`" if psd.lines() else "`--shock-rate`"
        raise ValueError(
            f"{extra} adds to a spectrum the device is simulated under; `--record` drives it "
            "with the record itself: simulate on the record alone, or give its spectrum "
            "(`--psd-file`)"
        )


def _on_record(harvester, record, args, burn_in):
    """``--record``: :func:`randvib.monte_carlo_on_record`, the options checked one line each."""
    from randvib.montecarlo.on_record import monte_carlo_on_record

    for flag in ("paths", "t_end"):
        if getattr(args, flag) is not None:
            option = "--" + flag.replace("_", "-")
            raise ValueError(
                f"`{option}` does not apply to `--record`: the record fixes the paths "
                "(use `--segments`) and their length"
            )
    substeps = 1
    if args.dt is not None:
        if not args.dt > 0:
            raise ValueError(f"`--dt` must be > 0 s, got {args.dt!r}")
        ratio = record.dt / args.dt
        substeps = round(ratio)
        if substeps < 1 or abs(ratio - substeps) > 1e-6 * ratio:
            raise ValueError(
                f"`--dt` must divide the record's step {record.dt:.6g} s "
                f"(record step / dt an integer), got {args.dt!r}"
            )
    try:
        return monte_carlo_on_record(
            harvester,
            record,
            segments=10 if args.segments is None else args.segments,
            burn_in=burn_in,
            substeps=substeps,
            scheme=args.method,
            seed=args.seed,
            threads=args.threads,
            progress=False if args.no_progress or args.json else None,
        )
    except ValueError as exc:  # name the options, not the function's arguments
        message = str(exc).replace("`segments`", "`--segments`").replace("`burn_in`", "`--burn-in`")
        raise ValueError(message) from None


def _run_assembly(args, assembly) -> int:
    """``--device``: Monte Carlo of the assembly; JSON per transducer and per DOF, or a table."""
    from randvib.montecarlo.simulation import simulate

    if wants_event(args):
        raise ValueError("`--envelope` (an event) is not implemented for `--device` assemblies")
    psd = excitation_from_args(args)
    burn_in = 2.0 if args.burn_in is None else args.burn_in
    _refuse_what_the_input_cannot_take(args, psd, isinstance(psd, float | int))
    if args.record is not None:
        result = _on_record(assembly, psd, args, burn_in)
    else:
        if args.segments is not None:
            raise ValueError("`--segments` cuts a record into paths; it needs `--record`")
        result = simulate(
            assembly,
            psd,
            t_end=20.0 if args.t_end is None else args.t_end,
            dt=1e-4 if args.dt is None else args.dt,
            n_paths=1000 if args.paths is None else args.paths,
            burn_in=burn_in,
            scheme=args.method,
            seed=args.seed,
            threads=args.threads,
            progress=False if args.no_progress or args.json else None,
            control_variates=args.control_variates,
        )
    summary = {"device": args.device, "n_dof": assembly.n_dof, **result.summary()}
    if args.json:
        print(dumps(summary))
        return 0
    print(f"device: {args.device}: {assembly.describe()}")
    print(describe_excitation(psd) if args.record is None else f"excitation: record {args.record}")
    print(str(result))
    return 0
