"""Event options: ``--envelope`` and its parameters, ``--envelope-file``, ``--times``, ``--start``.

Shared by ``randvib simulate`` (Monte Carlo, :func:`randvib.simulate_transient`)
and ``randvib power`` (the Lyapunov equation, :func:`randvib.transient_response`).
The options come from the envelope registry (:data:`randvib.models.event.ENVELOPES`):
``--envelope`` offers every registered envelope, and each declared parameter
is one option ``--envelope-NAME`` (``--envelope-a/-b/-c`` for Shinozuka-Sato,
``--envelope-rise/-hold/-fall`` for the boxcar); the table is read from
``--envelope-file``. An option of another envelope is refused, as ``--beta``
is with Coulomb friction.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from randvib.cli._device import option_flag, options_by_parameter, refuse_foreign_options
from randvib.cli._output import with_units
from randvib.models.event import ENVELOPES, STARTS, Enveloped, EventStart, ShinozukaSato

#: The envelope read from ``--envelope-file``.
FILE_ENVELOPE = "table"
#: How many report times ``--times`` defaults to on (0, t_end].
DEFAULT_TIMES = 10


def _dest(parameter: str) -> str:
    return f"envelope_{parameter}"


def _envelope_options() -> dict[str, list[str]]:
    """Parameter name -> the envelopes declaring it (the table has none: it is a file)."""
    return options_by_parameter(
        {name: cls.parameter_names() for name, cls in ENVELOPES.items() if name != FILE_ENVELOPE}
    )


def add_event_arguments(parser: argparse.ArgumentParser, *, t_end: bool = False) -> None:
    """Add the event options to ``parser`` (``t_end``: also ``--t-end``, for ``power``)."""
    g = parser.add_argument_group(
        "event (transient: the excitation times an envelope e(t) from t = 0, the device from "
        "rest; time-resolved tables and the event's energy)"
    )
    g.add_argument(
        "--envelope",
        choices=tuple(ENVELOPES),
        help="envelope e(t): step (switched on at t = 0), shinozuka-sato "
        "A (exp(-b t) - exp(-c t)), boxcar (linear ramps), table (--envelope-file)",
    )
    for name, owners in _envelope_options().items():
        spec = ENVELOPES[owners[0]].parameter_specs()[name]
        unit = f" ({spec.unit})" if spec.unit else ""
        extra = ""
        if name == "a":
            extra = "; default: the A that makes the peak 1"
        g.add_argument(
            option_flag(_dest(name)),
            dest=_dest(name),
            type=float,
            metavar="X",
            help=f"{spec.description}{unit}{extra}; {', '.join(owners)}",
        )
    g.add_argument(
        "--envelope-file",
        metavar="FILE",
        help="table envelope: CSV with the columns time (s, increasing) and envelope "
        "(>= 0), linear between rows, 0 outside the table",
    )
    g.add_argument(
        "--times",
        metavar="T1,T2,...",
        help=f"report times (s) in [0, --t-end], increasing, separated by commas "
        f"(default: {DEFAULT_TIMES} evenly spaced up to --t-end)",
    )
    g.add_argument(
        "--start",
        choices=STARTS,
        default="rest",
        help="rest (z = 0, v = 0) or unexcited (at rest at the bottom of the potential: "
        "a bistable device in its well at z = +sqrt(-k/k3))",
    )
    g.add_argument(
        "--plot",
        metavar="FILE.png",
        help="with --envelope: the event's figure (mean squares, power, energy since t = 0, "
        "P(stroke reached)); a new file",
    )
    if t_end:
        g.add_argument(
            "--t-end",
            type=float,
            default=None,
            help="end of the event window (s): the energy is integrated from 0 to it "
            "(default: the last of --times)",
        )


#: The event options other than ``--envelope`` (argparse dests) and their defaults.
def _event_dests() -> dict:
    dests = {_dest(name): None for name in _envelope_options()}
    dests.update(envelope_file=None, times=None, start="rest", plot=None)
    return dests


def wants_event(args) -> bool:
    """Whether the command line asks for an event (``--envelope`` or any event option)."""
    given = [d for d, default in _event_dests().items() if getattr(args, d, default) != default]
    if args.envelope is None and given:
        raise ValueError(f"`{option_flag(given[0])}` describes an event: it needs `--envelope`")
    return args.envelope is not None


def event_from_args(args, excitation) -> Enveloped:
    """The event: ``excitation`` (a number S is white noise) times the envelope of the options.

    Raises
    ------
    ValueError
        One line naming the option: an option of another envelope, a missing
        parameter or file, a bad value (c <= b, an unsorted table, ...).
    """
    name = args.envelope
    options = _envelope_options()
    given = {p: getattr(args, _dest(p)) for p in options if getattr(args, _dest(p)) is not None}
    cls = ENVELOPES[name]
    own = cls.parameter_names() if name != FILE_ENVELOPE else ()
    owners = {p: who for p, who in options.items()}
    refuse_foreign_options(
        {_dest(p): v for p, v in given.items()},
        [_dest(p) for p in own],
        {_dest(p): who for p, who in owners.items()},
        "the {owners} envelope",
        name,
    )
    if name == FILE_ENVELOPE:
        if args.envelope_file is None:
            raise ValueError(
                "`--envelope table` needs `--envelope-file FILE` (columns time, envelope)"
            )
        envelope = _read(args.envelope_file)
    else:
        if args.envelope_file is not None:
            raise ValueError(
                f"`--envelope-file` gives a table envelope; not with `--envelope {name}`"
            )
        envelope = _build(cls, own, given)
    try:
        return Enveloped(excitation, envelope)
    except ValueError as exc:  # the envelope as the user gave it: the file, or its amplitude
        flag = "--envelope-file" if name == FILE_ENVELOPE else option_flag(_dest("a"))
        flag = flag if name in (FILE_ENVELOPE, ShinozukaSato.name) else "--envelope"
        raise ValueError(str(exc).replace("`envelope`", f"`{flag}`")) from None


def _build(cls, own, given):
    """``cls(**given)``, Shinozuka-Sato's A defaulting to the unit peak; errors name the flags."""
    optional = {"a"} if cls is ShinozukaSato else set()
    missing = [p for p in own if p not in given and p not in optional]
    if missing:
        flags = ", ".join(f"`{option_flag(_dest(p))}`" for p in missing)
        raise ValueError(f"{flags} required for the {cls.name} envelope")
    try:
        if cls is ShinozukaSato and "a" not in given:
            return ShinozukaSato.unit_peak(given["b"], given["c"])
        return cls(**given)
    except ValueError as exc:  # name the options, not the class's fields
        message = str(exc)
        for p in own:
            message = message.replace(f"`{p}`", f"`{option_flag(_dest(p))}`")
        raise ValueError(message) from None


def _read(path: str):
    """The table envelope of ``--envelope-file``, its errors as one line naming the option."""
    from randvib.models.event import TabulatedEnvelope

    file = Path(path)
    if file.is_dir():
        raise ValueError(f"`--envelope-file` must be a CSV file, got the folder {path}")
    if not file.exists():
        raise ValueError(f"`--envelope-file`: no such file {path}")
    try:
        return TabulatedEnvelope.from_csv(file)
    except (ValueError, OSError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        # the file's columns ('time'), not the command's options (`--times`)
        raise ValueError(f"`--envelope-file` {path}: {first.replace('`', chr(39))}") from None


def parse_times(text: str | None, t_end: float | None) -> tuple[list[float], float]:
    """(report times, t_end) from ``--times`` and ``--t-end`` (either may be missing, not both)."""
    times = None
    if text is not None:
        try:
            times = [float(x) for x in text.split(",") if x.strip()]
        except ValueError:
            raise ValueError(
                f"`--times` must be times in seconds separated by commas (0.5,1,2), got {text!r}"
            ) from None
        if not times:
            raise ValueError(f"`--times` must give at least one time, got {text!r}")
    if t_end is None:
        if times is None:
            raise ValueError("an event needs `--t-end` or `--times`: when to report the response")
        t_end = max(times)
    if not t_end > 0:
        raise ValueError(f"`--t-end` must be > 0 s, got {t_end!r}")
    if times is None:
        times = [t_end * (i + 1) / DEFAULT_TIMES for i in range(DEFAULT_TIMES)]
    return times, t_end


def start_from_args(args, harvester) -> EventStart:
    """The device's start of ``--start``."""
    return EventStart.of(args.start, harvester)


def event_settings(event: Enveloped, start: EventStart) -> str:
    """One line: the event and the start, for the tables."""
    numbers = {k: v for k, v in event.envelope.parameters().items() if not isinstance(v, str)}
    try:  # a tabulated envelope's fields are a table, not declared parameters
        specs = type(event.envelope).parameter_specs()
    except KeyError:
        specs = {}
    shown = ", ".join(
        f"{k} {v:.4g} {specs[k].unit if k in specs else ''}".rstrip() for k, v in numbers.items()
    )
    return (
        f"event: {event.envelope.name} envelope{f' ({shown})' if shown else ''}, "
        f"peak e = {event.envelope.peak:.4g} at t = {event.envelope.peak_time:.4g} s; "
        f"start {start.describe()}"
    )


# ------------------------------------------------------------ the two commands
def _level(psd):
    """The JSON's ``psd``: the white level, or the excitation's level (None for a table)."""
    return psd if isinstance(psd, int | float) else getattr(psd, "level", None)


def _refuse_with_event(flags: dict) -> None:
    """Refuse stationary options given with ``--envelope`` (``{flag: given?}``)."""
    for flag, given in flags.items():
        if given:
            raise ValueError(
                f"`{flag}` does not apply to an event (`--envelope`): {flag_reason(flag)}"
            )


def flag_reason(flag: str) -> str:
    """Why a stationary option has no meaning for an event."""
    return {
        "--record": "a record is one realisation, not an ensemble; give its spectrum as "
        "`--psd-file` for Gaussian paths",
        "--burn-in": "an event starts at t = 0 from `--start`",
        "--control-variates": "the energy-balance controls hold in the stationary state only",
        "--segments": "it cuts a record into paths",
        "--optimal-load": "it maximises stationary power",
        "--csv": "a sweep's table; print the event with `--json`",
    }[flag]


def simulate_event(args, harvester, psd) -> int:
    """``randvib simulate --envelope ...``: :func:`randvib.simulate_transient`, a time table."""
    from randvib._io import dumps
    from randvib.montecarlo.transient import simulate_transient

    _refuse_with_event(
        {
            "--record": args.record is not None,
            "--burn-in": args.burn_in is not None,
            "--control-variates": args.control_variates,
            "--segments": args.segments is not None,
        }
    )
    event = event_from_args(args, psd)
    start = start_from_args(args, harvester)
    plot = _claimed_plot(args)
    # without either, simulate's own default window (20 s)
    t_end = 20.0 if args.t_end is None and args.times is None else args.t_end
    times, t_end = parse_times(args.times, t_end)
    result = simulate_transient(
        harvester,
        event,
        t_end=t_end,
        dt=1e-4 if args.dt is None else args.dt,
        n_paths=1000 if args.paths is None else args.paths,
        times=times,
        start=start,
        scheme=args.method,
        seed=args.seed,
        threads=args.threads,
        progress=False if args.no_progress or args.json else None,
    )
    out = {"psd": _level(psd), "friction": harvester.friction_name, **result.to_dict()}
    analytic = _analytic_beside(harvester, event, result.times, result.t_end, start)
    if args.json:
        print(dumps(with_units(out, harvester.electrical)))
    else:
        _print_simulated(harvester, psd, event, start, result, analytic)
    if plot is not None and analytic is not None:  # the curves on a fine grid
        fine = np.linspace(0.0, result.t_end, 401)
        analytic = _analytic_beside(harvester, event, fine, result.t_end, start)
    return _draw_event(plot, result, analytic, args.json)


def _claimed_plot(args):
    """``--plot``'s file, checked before the run (a new file unless ``--force``)."""
    from randvib._io import claim_output_file

    if args.plot is None:
        return None
    return claim_output_file(args.plot, "--plot", overwrite=getattr(args, "force", False))


def _draw_event(plot, simulated, analytic, json_out: bool) -> int:
    """The event's figure at ``plot`` (:func:`randvib.plot_transient`); 1 if it cannot be written."""
    import sys

    from randvib.studies.transient_figure import plot_transient

    if plot is None:
        return 0
    group = tuple(r for r in (simulated, analytic) if r is not None)
    try:
        plot_transient({"device": group}, path=plot)
    except OSError as exc:
        print(f"randvib: could not write `--plot` {str(plot)!r} ({exc})", file=sys.stderr)
        return 1
    print(f"wrote {plot}", file=sys.stderr if json_out else sys.stdout)
    return 0


def _analytic_beside(harvester, event, times, t_end, start):
    """The Lyapunov solution beside the Monte Carlo table, where linearisation takes the case."""
    from randvib.analytic.prediction import METHODS
    from randvib.analytic.transient import transient_response

    if event.excitation.shaping_filter() is None or not METHODS["linearisation"].accepts(
        harvester, event
    ):
        return None
    try:
        return transient_response(harvester, event, times, t_end=t_end, start=start)
    except ValueError:  # e.g. a start in one well: the zero-mean closure refuses it
        return None


def _print_simulated(harvester, psd, event, start, result, analytic) -> None:
    from randvib.cli._output import describe_device, describe_excitation, print_table
    from randvib.formatting import cell, estimate_parts

    print(describe_device(harvester))
    print(describe_excitation(psd))
    print(event_settings(event, start))
    headers = ["time (s)", "E[z^2] (m^2)", "± 95 %", "E[v^2] ((m/s)^2)", "± 95 %"]
    headers += ["E[P_e] (W)", "± 95 %"]
    columns = [result.displacement_variance, result.velocity_variance, result.power_electrical]
    reached = result.stroke_reached
    if reached is not None:  # a probability: its Wilson interval, never below 0
        headers += ["P(stroke reached)", "95 % interval"]
    if analytic is not None:
        headers.append("E[P_e] analytic (W)")
    rows = []
    for i, t in enumerate(result.times):
        row = [cell(float(t))]
        for stat in columns:
            row += list(estimate_parts(float(stat.mean[i]), float(stat.ci95[i])))
        if reached is not None:
            mean, interval = format(reached[i], "").split(" ", 1)
            row += [mean, interval]
        if analytic is not None:
            row.append(cell(float(analytic.power_electrical[i])))
        rows.append(row)
    print_table(rows, headers)
    energy = result.energy_electrical
    line = f"energy from t = 0 to {result.t_end:g} s: {' ± '.join(estimate_parts(energy.mean, energy.ci95))} J"
    if analytic is not None:
        line += f" (analytic {cell(analytic.energy_electrical)} J)"
    print(line)
    quantiles = ", ".join(f"{100 * q:g} % {v:.4g} m" for q, v in result.peak_quantiles().items())
    print(f"peak |z| over the event: {quantiles}")
    if reached is not None:
        p = result.peak_exceedance(harvester.stroke)
        text = f"P(peak |z| > stroke {harvester.stroke:g} m): {p} (95 % interval)"
        if analytic is not None and analytic.stroke_reached_poisson is not None:
            text += (
                f" (approximate: Poisson {analytic.stroke_reached_poisson[-1]:.4g}, "
                f"Vanmarcke {analytic.stroke_reached_vanmarcke[-1]:.4g}, not conservative early "
                f"in an event; at most {analytic.stroke_reached_bound[-1]:.4g}, Rice's bound; "
                f"at t = {result.times[-1]:g} s)"
            )
        print(text)
    print(
        f"{result.n_paths} paths from t = 0 (dt {result.dt:g} s, {result.scheme}, seed "
        f"{result.seed}), {result.wall_time:.2f} s wall"
    )


def power_event(args, swept: list, points: list) -> int:
    """``randvib power --envelope ...``: :func:`randvib.transient_response`, a time table."""
    from randvib._io import dumps
    from randvib.analytic.transient import transient_response
    from randvib.cli._device import harvester_from_args

    if swept:
        raise ValueError(
            f"`{option_flag(swept[0])}` has several values: an event (`--envelope`) is computed "
            "one point at a time"
        )
    _refuse_with_event({"--optimal-load": args.optimal_load, "--csv": args.csv is not None})
    (point,) = points
    harvester = harvester_from_args(point)
    from randvib.cli._excitation import excitation_from_args

    psd = excitation_from_args(point)
    event = event_from_args(point, psd)
    start = start_from_args(point, harvester)
    plot = _claimed_plot(args)
    times, t_end = parse_times(point.times, point.t_end)
    result = transient_response(
        harvester, event, times, t_end=t_end, start=start, method=point.method
    )
    out = {"psd": _level(psd), "friction": harvester.friction_name, **result.to_dict()}
    if args.json:
        print(dumps(with_units(out, harvester.electrical)))
    else:
        _print_predicted(harvester, psd, event, start, result)
    if plot is not None:  # the curves on a fine grid, not only at the report times
        fine = np.linspace(0.0, t_end, 401)
        result = transient_response(harvester, event, fine, t_end=t_end, start=start,
                                    method=point.method)  # fmt: skip
    return _draw_event(plot, None, result, args.json)


def _print_predicted(harvester, psd, event, start, result) -> None:
    from randvib.cli._output import describe_device, describe_excitation, print_table
    from randvib.formatting import cell

    print(describe_device(harvester))
    print(describe_excitation(psd))
    print(event_settings(event, start))
    names = {
        "displacement_variance": "E[z^2] (m^2)",
        "velocity_variance": "E[v^2] ((m/s)^2)",
        "power_electrical": "E[P_e] (W)",
        "power_load": "E[P_L] (W)",
        "cumulative_energy": "energy to t (J)",
        "stroke_exceedance": "P(|z| > stroke)",
        "stroke_reached_poisson": "reached, Poisson*",
        "stroke_reached_vanmarcke": "reached, Vanmarcke*",
        "stroke_reached_bound": "reached <= (Rice)",
    }
    shown = [(label, getattr(result, name)) for name, label in names.items()]
    shown = [(label, values) for label, values in shown if values is not None]
    rows = [
        [cell(float(t))] + [cell(float(values[i])) for _, values in shown]
        for i, t in enumerate(result.times)
    ]
    print_table(rows, ["time (s)"] + [label for label, _ in shown])
    how = "exact: linear device" if result.exact else "time-dependent statistical linearisation"
    print(
        f"energy from t = 0 to {result.t_end:g} s: {cell(result.energy_electrical)} J "
        f"({result.method}, {how})"
    )
    if result.stroke_reached_poisson is not None:
        print(
            "* approximate: out-crossing rates (Poisson; Vanmarcke with bandwidth "
            f"q = {result.bandwidth:.3g}, not conservative early in an event), checked against "
            "Monte Carlo (randvib simulate); 'reached <=' is an upper bound, the expected number "
            "of out-crossings (Rice)"
        )
