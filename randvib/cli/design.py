"""``randvib design``: the harvester that harvests most from a vibration under a stroke budget.

The device and excitation options of ``randvib power`` fix what is fixed;
``--vary NAME=LOW:HIGH`` (repeatable) names each parameter to choose and its
range; ``--stroke`` and ``--exceedance`` set the budget P(|z| > stroke) <=
exceedance. The analytic search's optimum is confirmed (and, where Monte
Carlo contradicts it, refined) by Monte Carlo with common random numbers
(:func:`randvib.design`). ``--json`` prints one object with the keys
``optimum``, ``power_predicted``, ``power_monte_carlo``,
``stroke_exceedance_monte_carlo`` (each ``{"mean", "ci95"}``),
``input_power``, ``limit`` (non-causal; ``limit_kind`` says what it bounds:
the budget's Gaussian RMS for a spectrum, the record itself for ``--record``),
``limit_hard_stroke`` (any device within abs(z) <= stroke), ``causal_limit``
(what a causal device can approach) with ``fraction_of_causal_limit``,
``notes``, with ``--min-first-passage`` the first passage predicted and by
Monte Carlo, and the rest of :meth:`randvib.DesignResult.to_dict`.

``--device FILE`` designs an assembly (docs/assemblies.md): ``--vary`` names a
parameter of the file by its dotted path (``transducer.0.r_load``,
``element.1.k3``), the budget holds on each coordinate with a stroke in the
file (or those ``--stroke-on`` names), and the objective is the sum over
the transducers (or ``--transducer N``'s alone); ``stroke`` in the JSON is
then {coordinate: stroke} and ``objective_scope`` says whose power counts.
"""

from __future__ import annotations

import argparse

from randvib._io import dumps
from randvib._validation import MAX_SEED, integer_option
from randvib.cli import COMMAND_HELP
from randvib.cli._device import add_device_arguments, assembly_from_args, harvester_from_args
from randvib.cli._excitation import add_excitation_arguments, excitation_from_args
from randvib.cli._output import describe_device, describe_excitation, print_table, with_units
from randvib.formatting import cell, estimate, proportion
from randvib.harvester_design.assembly_budget import vary_refusal
from randvib.harvester_design.design import design
from randvib.harvester_design.objectives import OBJECTIVES
from randvib.models.coupling import COUPLINGS
from randvib.models.friction import FRICTION_MODELS
from randvib.models.rectifier import BridgeCoil, BridgePiezo
from randvib.montecarlo.ensembles import GROUP_SEEDS
from randvib.montecarlo.sweep import SweepSettings
from randvib.quantities import parameter_unit, unit


def register(sub) -> None:
    p = sub.add_parser(
        "design",
        help=COMMAND_HELP["design"],
        description="Search the ranges given for the device that harvests most from the "
        "excitation with the fraction of time beyond --stroke at most --exceedance: analytic "
        "search, Monte Carlo "
        "confirmation with common random numbers, and the limit for a mass of this size.",
    )
    add_device_arguments(p)
    add_excitation_arguments(p)
    g = p.add_argument_group("design")
    g.add_argument(
        "--vary",
        action="append",
        metavar="NAME=LOW:HIGH",
        type=vary_option,
        required=True,
        help="a parameter to choose and its range (SI; repeatable): k, k3 (negative k "
        "with k3 > 0 is bistable), c_e, c_m, a friction or coupling parameter (alpha, "
        "r_load, theta, ...) or of a --rectifier bridge (battery, v_diode, ...); with "
        "--device a dotted path of the file (transducer.0.r_load, element.1.k3, "
        "structure.stiffness.0.0)",
    )
    g.add_argument(
        "--stroke-on",
        action="append",
        metavar="PART",
        help="with --device: the coordinate the stroke budget holds on, element.N or "
        "transducer.N (repeatable; default every part with a stroke in the file)",
    )
    g.add_argument(
        "--transducer",
        type=integer_option(0),
        metavar="N",
        help="with --device: maximise transducer N's power alone (default: the sum over "
        "the transducers)",
    )
    g.add_argument(
        "--exceedance",
        type=float,
        default=0.01,
        help="budget on the fraction of time with abs(z) > --stroke (default 0.01)",
    )
    g.add_argument(
        "--min-first-passage",
        type=float,
        metavar="SECONDS",
        help="also require a mean first-passage time to --stroke of at least SECONDS "
        "(predicted where the response is Gaussian, checked by Monte Carlo)",
    )
    g.add_argument(
        "--max-first-passage",
        type=float,
        metavar="P",
        help="also require P(abs(z) reaches --stroke within --duration) <= P, from the stationary "
        "state (predicted where the response is Gaussian, confirmed by the rare-event estimate "
        "of randvib reliability on the candidates)",
    )
    g.add_argument(
        "--duration", type=float, metavar="SECONDS", help="with --max-first-passage: the window T"
    )
    g.add_argument(
        "--objective",
        default="electrical",
        choices=tuple(OBJECTIVES),
        help="the power to maximise: "
        + "; ".join(f"{name}: {o.description}" for name, o in OBJECTIVES.items()),
    )
    _add_monte_carlo_arguments(g)
    p.add_argument("--json", action="store_true", help="print one JSON object")
    # SweepSettings' and design's names of the options, as refusals name them
    p.set_defaults(handler=run, api_flags={"target_rel_ci": "--precision", "stroke": "--stroke"})


def _add_monte_carlo_arguments(g) -> None:
    """The options of the Monte Carlo confirmation (precision, paths, seed, where it runs)."""
    g.add_argument(
        "--no-monte-carlo", action="store_true", help="the analytic search's answer only"
    )
    g.add_argument(
        "--precision",
        type=float,
        default=0.01,
        help="Monte Carlo target: 95 %% half-width of the power over the power (default 0.01)",
    )
    g.add_argument(
        "--max-paths",
        type=integer_option(2),
        default=2048,
        help="most Monte Carlo paths per candidate (default 2048)",
    )
    g.add_argument(
        "--seed",
        # its Monte Carlo runs as paired-ensemble group 0 on seed GROUP_SEEDS * seed
        type=integer_option(0, MAX_SEED // GROUP_SEEDS),
        default=0,
        help="random seed",
    )
    g.add_argument(
        "--segments",
        type=integer_option(2),
        default=None,
        help="with --record: windows the record is cut into, the Monte Carlo paths of every "
        "candidate (default 10)",
    )
    g.add_argument("--out-dir", help="folder to keep the Monte Carlo cases in and resume from")
    g.add_argument("--scheduler", help="address of a Dask scheduler to run the cases on")
    g.add_argument("--no-progress", action="store_true", help="no progress bar")


def vary_option(text: str) -> tuple[str, float, float]:
    """``NAME=LOW:HIGH`` -> (name, low, high)."""
    name, _, bounds = text.partition("=")
    parts = bounds.split(":")
    try:
        if name and len(parts) == 2:
            return name.strip(), float(parts[0]), float(parts[1])
    except ValueError:
        pass
    raise argparse.ArgumentTypeError(f"{text!r} is not NAME=LOW:HIGH (for example k=20:120)")


def _single_mass_vary(args) -> dict:
    """``--vary`` of a single mass: names checked, the device given a value for each."""
    for flag, value in (("--stroke-on", args.stroke_on), ("--transducer", args.transducer)):
        if value is not None:
            raise ValueError(
                f"`{flag}` names a part of an assembly: give the device with --device FILE"
            )
    vary = {}
    known = _known_names()
    for name, low, high in args.vary:
        if name in vary:
            raise ValueError(f"`--vary {name}` is given twice")
        if name not in known:
            raise ValueError(
                f"`--vary` names unknown parameter {name!r}; allowed: {', '.join(known)}"
            )
        if not low < high:
            raise ValueError(f"`--vary {name}={low:g}:{high:g}` is an empty range: need LOW < HIGH")
        vary[name] = (low, high)
        # the device needs a value for a varied parameter it has no other value for
        if getattr(args, name, 0) is None:
            setattr(args, name, 0.5 * (low + high))
    if args.stroke is None:
        raise ValueError("`--stroke` is needed: the budget is on P(|z| > stroke)")
    return vary


def _assembly_vary(args, assembly) -> dict:
    """``--vary`` of ``--device``: dotted paths checked against the file, in one line each."""
    for flag, dest in (("--out-dir", "out_dir"), ("--scheduler", "scheduler"),
                       ("--min-first-passage", "min_first_passage")):  # fmt: skip
        if getattr(args, dest, None) is not None:
            raise ValueError(
                f"`{flag}` is not taken with --device: an assembly's candidates run in this "
                "process, without a resume folder, a cluster or a first-passage bound"
            )
    vary = {}
    for name, low, high in args.vary:
        if name in vary:
            raise ValueError(f"`--vary {name}` is given twice")
        why = vary_refusal(assembly, name)
        if why is not None:
            raise ValueError(f"`--vary {name}={low:g}:{high:g}`: {why}")
        if not low < high:
            raise ValueError(f"`--vary {name}={low:g}:{high:g}` is an empty range: need LOW < HIGH")
        vary[name] = (low, high)
    return vary


def _known_names() -> tuple[str, ...]:
    """Every parameter some device can vary: the device's, every friction law's, coupling's
    and bridge's (``battery``, ``r_load``, ``v_diode``, ...)."""
    names = ["c_m", "c_e", "k", "k3"]
    for family in (FRICTION_MODELS, COUPLINGS, {"coil": BridgeCoil, "piezo": BridgePiezo}):
        for member in family.values():
            names += list(member.parameter_names())
    return tuple(dict.fromkeys(names))


def run(args) -> int:
    assembly = assembly_from_args(args)
    if assembly is None:
        vary = _single_mass_vary(args)
        device = harvester_from_args(args)
    else:
        vary = _assembly_vary(args, assembly)
        device = assembly
    excitation = excitation_from_args(args)
    if args.segments is not None and getattr(args, "record", None) is None:
        raise ValueError("`--segments` cuts a record into paths; it needs `--record`")
    settings = SweepSettings(
        target_rel_ci=args.precision,
        max_paths=args.max_paths,
        seed=args.seed,
        control_variates=not hasattr(excitation, "is_white") or excitation.is_white,
    )
    result = design(
        device,
        excitation,
        vary,
        exceedance=args.exceedance,
        objective=args.objective,
        min_first_passage=args.min_first_passage,
        max_first_passage=args.max_first_passage,
        duration=args.duration,
        monte_carlo=not args.no_monte_carlo,
        settings=settings,
        segments=10 if args.segments is None else args.segments,
        out_dir=args.out_dir,
        scheduler=args.scheduler,
        progress=not args.no_progress and not args.json,
        stroke_on=args.stroke_on,
        transducer=args.transducer,
    )
    if args.json:
        optimum = {k: u for k in result.optimum if (u := parameter_unit(k, result.device))}
        print(dumps(with_units(result.to_dict(), extra=optimum)))
        return 0
    _print_design(args, result, excitation, vary, assembly is not None)
    return 0


def _estimate(value: dict) -> str:
    """A Monte Carlo ``{"mean", "ci95"}`` to the digits its interval supports."""
    return estimate(value["mean"], value["ci95"])


def _print_design(args, result, excitation, vary: dict, is_assembly: bool) -> None:
    """The device chosen (not the ranges' midpoints), the table, and the notes."""
    if is_assembly:
        print(f"device at the optimum: {result.device.describe()}")
    else:
        print(describe_device(result.device).replace("device:", "device at the optimum:", 1))
    print("varied: " + ", ".join(
        f"{k} {cell(lo)} to {cell(hi)} {parameter_unit(k, result.device)}".rstrip()
        for k, (lo, hi) in vary.items()
    ))  # fmt: skip
    print(describe_excitation(excitation))
    out = result.to_dict()
    rows = [
        (f"optimum {k}", cell(v), parameter_unit(k, result.device))
        for k, v in result.optimum.items()
    ]
    for key in ("power_predicted", "stroke_exceedance_predicted"):
        rows.append((key, cell(out[key]), unit(key)))
    for key in ("power_monte_carlo", "stroke_exceedance_monte_carlo", "input_power"):
        value = out[key]
        if value is None:
            continue
        if isinstance(value, dict) and "ci95_lower" in value:  # a probability's interval
            value = proportion(value["mean"], value["ci95_lower"], value["ci95_upper"])
        elif isinstance(value, dict):
            value = _estimate(value)
        rows.append((key, value if isinstance(value, str) else cell(value), unit(key)))
    if args.min_first_passage is not None:
        rows.append(
            (
                "first_passage_predicted",
                cell(out["first_passage_predicted"]),
                unit("first_passage_predicted"),
            )
        )
        first = result.first_passage_monte_carlo
        if first is not None:
            lower = first.restricted_mean
            rows.append(("first_passage_monte_carlo",
                         estimate(first.mean.mean, first.mean.ci95) if first.mean
                         else f">= {estimate(lower.mean, lower.ci95)} (censored)", "s"))  # fmt: skip
            rows.append(("first_passage_confirmed", str(out["first_passage_confirmed"]), ""))
    if args.max_first_passage is not None:
        rows += _strike_rows(out)
    rows.append(("efficiency", cell(out["efficiency"]), unit("efficiency")))
    rows += result.limit_rows(cell)
    if out.get("monte_carlo_input") is not None:
        rows.append(("monte_carlo_input", out["monte_carlo_input"], ""))
    if result.refined:
        cost = result.analytic_cost
        rows.append(("analytic optimum's cost", estimate(cost.mean, cost.ci95), "W"))
    print_table(rows, ("quantity", "value", "unit"))
    for key in ("limit_kind", "causal_limit_kind"):  # words: below the table, not in a column
        if out.get(key) is not None:
            print(f"{key.replace('_kind', '')}: {out[key]}")
    for note in result.notes:
        print(f"note: {note}")
    return 0


def _strike_rows(out) -> list:
    """The table's rows of the strike limit (--max-first-passage): predicted, estimated."""
    rows = [("P(first passage) predicted", cell(out["first_passage_probability_predicted"]), "1")]
    strikes = out["first_passage_probability"]
    if strikes is not None:
        rows.append(
            (
                "P(first passage), rare-event estimate",
                estimate(strikes["mean"], strikes["ci95"]),
                "1",
            )
        )
        verdict = str(out["first_passage_probability_confirmed"])
        rows.append(("first_passage_probability_confirmed", verdict, ""))
    return rows
