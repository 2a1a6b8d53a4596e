"""``randvib power``: analytic expected power (paper Eq. 19-32 and beyond).

Under white noise (the default) every method of
:data:`randvib.analytic.prediction.METHODS` applies; under another excitation
only the methods that declare they accept it (statistical linearisation) do,
and the JSON gains an ``excitation`` object describing it. The ``--method`` choices, their
help and the refusals come from the methods' declarations
(:mod:`randvib.analytic.method`).

Sweeps: every number of the device, its friction, coupling and excitation
may be given several values (``--psd 1 0.5 0.1``) or a range
``START:STOP:COUNT`` (``--fc 0:0.05:11``: 11 values from 0 to 0.05 N, both
ends included, as :func:`numpy.linspace`); several swept options give every
combination. A sweep prints one row per point (``--json``: a list of the
single-point objects; ``--csv FILE``: all their keys, one row per point).
``--optimal-load`` adds the load resistance that maximises the load power
(:func:`randvib.optimal_load_resistance`) and that power; with a diode
bridge, the battery voltage or the storage capacitor's load that maximises
the stored power, that power, whether the optimum is interior or at a bound
(``optimum``) and which method found it (``optimum_method``): the bridge
closure's search (:func:`randvib.optimal_dc_output`) where the closure takes
the device and input, otherwise -- or when ``--optimal-bounds LOW HIGH`` is
given -- Monte Carlo over that range (:func:`randvib.simulated_dc_optimum`,
ensemble set by ``--optimal-paths``, ``--optimal-t-end``, ``--optimal-grid``);
then the analytic prediction at the given device is left out where no method
takes it (``method`` is ``"monte-carlo"``).

``--device FILE.toml`` predicts an assembly (docs/assemblies.md): the JSON
has ``transducers`` (one entry per transducer in file order, each with
``power_electrical``, and ``power_load`` where the coupling has a load),
``displacement_variance`` and ``velocity_variance`` (one entry per DOF),
``elements`` (each element's closure), ``exact`` (true for a linear
assembly: the Lyapunov solution), ``power_input`` and ``power_mechanical``;
``--optimal-load`` adds each transducer's best load (``r_load_optimal``,
``power_load_optimal``; a bare c_e: ``c_e_optimal``) to its entry, the others
held as given (:func:`randvib.optimal_assembly_loads`).

``--envelope`` makes the input an event from t = 0 (:mod:`randvib.cli._event`):
the moments at ``--times`` and the energy to ``--t-end`` by the Lyapunov
equation (:func:`randvib.transient_response`), one point at a time.
"""

from __future__ import annotations

import argparse
import csv
import io
import itertools
import math

from randvib._io import claim_output_file, dumps, write_or_keep
from randvib._resources import announce_duration, timed
from randvib._validation import check_positive
from randvib.analytic.assembly_prediction import optimal_assembly_loads
from randvib.analytic.bridge import optimal_dc_output
from randvib.analytic.prediction import METHODS, optimal_load_resistance, predict
from randvib.cli import COMMAND_HELP, advice_when_done
from randvib.cli._device import (
    add_device_arguments,
    assembly_from_args,
    fit_is_rectified,
    harvester_from_args,
    option_flag,
)
from randvib.cli._event import add_event_arguments, power_event, wants_event
from randvib.cli._excitation import add_excitation_arguments, excitation_from_args
from randvib.cli._output import describe_device, describe_excitation, print_table, with_units
from randvib.formatting import cell
from randvib.models.assembly import Assembly
from randvib.models.assembly_parts import between_words
from randvib.models.excitation import Excitation
from randvib.montecarlo.bridge_optimum import simulated_dc_optimum
from randvib.quantities import QUANTITIES, unit


def register(sub) -> None:
    p = sub.add_parser(
        "power",
        help=COMMAND_HELP["power"],
        description="Expected power of the harvester under base acceleration (white noise "
        "by default), by an analytic method.",
    )
    add_device_arguments(p)
    add_excitation_arguments(p)
    add_event_arguments(p, t_end=True)
    p.add_argument(
        "--method",
        default=None,
        choices=tuple(METHODS),
        metavar="METHOD",
        help=_method_help(),
    )
    p.add_argument(
        "--optimal-load",
        action="store_true",
        help="also the load resistance R_L that maximises the load power, and that power "
        "(needs a coupling: --alpha/--r-load/--r-coil or --coupling; its --r-load is the start); "
        "with --rectifier bridge, the battery voltage or storage load maximising the stored power; "
        "with --device, each transducer's load (the others as given)",
    )
    p.add_argument(
        "--optimal-bounds",
        nargs=2,
        type=float,
        metavar=("LOW", "HIGH"),
        help="with --rectifier bridge --optimal-load: search by Monte Carlo over this range "
        "(V for --battery, ohm for --r-load); needed where the bridge closure does not take "
        "the device or input",
    )
    p.add_argument(
        "--optimal-paths",
        type=int,
        default=64,
        help="paths of the Monte Carlo optimum search (default 64; with --record, windows of "
        "the record)",
    )
    p.add_argument(
        "--optimal-t-end",
        type=float,
        default=12.0,
        help="simulated time of each Monte Carlo optimum point, s, 2 s of it burn-in (default 12)",
    )
    p.add_argument(
        "--optimal-grid",
        type=int,
        default=9,
        help="grid points of the Monte Carlo optimum search, >= 3 (default 9)",
    )
    p.add_argument(
        "--json", action="store_true", help="print one JSON object (a sweep: a list of them)"
    )
    p.add_argument(
        "--csv", metavar="FILE", help="write the sweep's points to a CSV file (a new file)"
    )
    p.add_argument("--force", action="store_true", help="overwrite an existing --csv file")
    p.add_argument(
        "--no-progress",
        action="store_true",
        help="no progress bar (the Monte Carlo optimum shows one on a terminal)",
    )
    _allow_sweeps(p)
    p.set_defaults(handler=run)


def _method_help() -> str:
    """The ``--method`` help, from the methods' declarations."""
    each = "; ".join(f"{name}: {method.summary}" for name, method in METHODS.items())
    coloured = " or ".join(name for name, method in METHODS.items() if method.coloured)
    circuit = " or ".join(name for name, method in METHODS.items() if method.circuit)
    text = (
        f"analytic method ({each}); a non-white excitation: {coloured} only; a coil "
        f"inductance or piezo capacitance: {circuit} only; default linearisation, or "
        "bridge-closure with --rectifier (or a --from-fit made behind a bridge)"
    )
    return text.replace("%", "%%")  # argparse formats help with %


#: The options that take a single value even in ``power`` (not physical numbers).
NOT_SWEPT = ("psd_file", "record", "t_end", "sample_rate", "optimal_bounds", "optimal_t_end")


def _allow_sweeps(parser) -> None:
    """Let every numeric device/excitation option of ``power`` take several values."""
    for action in parser._actions:
        if action.type is float and action.option_strings and action.dest not in NOT_SWEPT:
            action.nargs = "+"
            action.type = sweep_values
            action.help = (action.help or "") + "; several values or START:STOP:COUNT sweep"


def sweep_values(text: str) -> list[float]:
    """One command-line token of a swept option: a number, or ``START:STOP:COUNT``.

    ``START:STOP:COUNT`` is ``COUNT`` evenly spaced values from START to STOP,
    both included (:func:`numpy.linspace`); COUNT is an integer >= 2.
    """
    parts = text.split(":")
    try:
        if len(parts) == 1:
            return [float(text)]
        if len(parts) == 3:
            start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
            if count >= 2 and math.isfinite(start) and math.isfinite(stop):
                # a convex combination: stop - start overflows for ends near the float limit
                steps = [i / (count - 1) for i in range(count)]
                return [start * (1.0 - t) + stop * t for t in steps]
    except ValueError:
        pass
    raise argparse.ArgumentTypeError(
        f"{text!r} is not a number nor START:STOP:COUNT (COUNT an integer >= 2)"
    )


def _sweep(args) -> tuple[list[str], list[argparse.Namespace]]:
    """The swept options and one namespace per point (every combination), in order."""
    given = {
        dest: [x for token in value for x in token]
        for dest, value in vars(args).items()
        if isinstance(value, list) and value and isinstance(value[0], list)
    }
    swept = [dest for dest, values in given.items() if len(values) > 1]
    points = []
    for combination in itertools.product(*given.values()):
        point = argparse.Namespace(**vars(args))
        for dest, value in zip(given, combination, strict=True):
            setattr(point, dest, value)
        points.append(point)
    return swept, points


# JSON: the keys of PowerPrediction.to_dict(); `displacement_variance` is null for
# the free mass (k = k3 = 0); with --stroke, `stroke` and `stroke_exceedance`
# (P(|z| > stroke): FPK's stationary probability, linearisation's Gaussian estimate).


def run(args) -> int:
    csv_file = (
        None if args.csv is None else claim_output_file(args.csv, "--csv", overwrite=args.force)
    )
    # a bridge's optimum falls back to Monte Carlo where the closure refuses, unless a
    # method was asked for by name
    args.method_defaulted = args.method is None
    if args.method is None:  # a bridge's own method (a fit's too), else statistical linearisation
        bridged = args.rectifier is not None or fit_is_rectified(args)
        args.method = "bridge-closure" if bridged else "linearisation"
    swept, points = _sweep(args)
    if wants_event(args):
        return power_event(args, swept, points)
    with advice_when_done():  # a refused point leaves one line, not another point's advice
        results = _points(points, csv_file, args.force)
    saved = None
    if csv_file is not None:
        saved = _write_csv(csv_file, [out for out, _, _ in results], args.force)
    if args.json:
        outs = [with_units(out, getattr(h, "electrical", None)) for out, h, _ in results]
        print(dumps(outs[0] if len(outs) == 1 and not swept else outs))
    elif swept:
        _print_sweep(swept, points, results)
    else:
        _print_point(*results[0])
    if saved is not None and saved == csv_file and not args.json:
        print(f"wrote {csv_file} ({len(results)} points)")
    # not saved where asked (a full disk): the table is kept elsewhere, and the exit says so
    return 0 if csv_file is None or saved == csv_file else 1


def _points(points, csv_file, overwrite: bool) -> list:
    """Every point, in order; on Ctrl-C or SIGTERM the finished ones go to ``--csv``.

    A sweep whose first point shows it will take long says so first
    (:func:`randvib._resources.announce_duration`).
    """
    results = []
    try:
        for i, point in enumerate(points):
            result, seconds = timed(lambda point=point: _point(point))
            results.append(result)
            if i == 0 and len(points) > 1:
                announce_duration(
                    f"this sweep of {len(points)} points",
                    seconds * (len(points) - 1),
                    basis="at the speed of its first point",
                )
    except KeyboardInterrupt as exc:
        exc.kept = _keep_finished(results, len(points), csv_file, overwrite)
        raise
    return results


def _keep_finished(results, n_points: int, csv_file, overwrite: bool) -> str:
    """Write the finished points of a stopped sweep to ``--csv``; what was kept, in words."""
    if csv_file is None:
        return f"{len(results)} of {n_points} points were finished; nothing was saved (no --csv)"
    if not results:
        return f"no point was finished; {str(csv_file)!r} was not written"
    saved = _write_csv(csv_file, [out for out, _, _ in results], overwrite)
    where = "printed above" if saved is None else repr(str(saved))
    return f"the {len(results)} finished points of {n_points} were kept in {where}"


def _point(args) -> tuple[dict, object, object]:
    """The JSON object of one point, with its harvester (or assembly) and excitation."""
    assembly = assembly_from_args(args)
    if assembly is not None:
        return _assembly_point(args, assembly)
    harvester = harvester_from_args(args)
    psd = excitation_from_args(args)
    coloured = isinstance(psd, Excitation)
    if args.optimal_load and harvester.electrical is None:
        raise ValueError(
            "`--optimal-load` needs a coupling: give `--alpha/--r-load/--r-coil` (resistive) "
            "or `--coupling NAME` with its options, not `--c-e`"
        )
    if args.optimal_bounds is not None and not (args.optimal_load and harvester.is_rectified):
        raise ValueError("`--optimal-bounds` needs `--optimal-load` and `--rectifier bridge`")
    if args.optimal_load and harvester.is_rectified:
        simulated = _simulated_optimum_point(args, harvester, psd)
        if simulated is not None:
            return simulated, harvester, psd
    _check_method(args.method, harvester, psd)
    result = predict(harvester, psd, method=args.method)
    out = {
        "method": result.method,
        # The level --psd; a tabulated or measured spectrum has none (null).
        "psd": getattr(psd, "level", None) if coloured else psd,
        "friction": harvester.friction_name,
        **result.to_dict(),
    }
    if result.power_load is None:
        out.pop("power_load")
    if harvester.electrical is not None:
        out["coupling"] = harvester.coupling_name
    else:
        # what is not converted: c_m E[v^2] + friction power, c_eq E[v^2] being all
        # that is dissipated (c_eq = S m / (4 E[v^2]) under white noise)
        out["power_mechanical"] = (result.c_eq - harvester.c_e) * result.velocity_variance
    if harvester.stroke is not None:
        out["stroke"] = harvester.stroke
        # null where not stationary (the free mass)
        out["stroke_exceedance"] = result.stroke_exceedance
    if args.optimal_load and harvester.is_rectified:
        # the battery voltage or the capacitor's load maximising the stored power
        out.update(optimal_dc_output(harvester, psd).to_dict())
        out["optimum_method"] = "bridge-closure"
    elif args.optimal_load:
        best = optimal_load_resistance(harvester, psd, method=args.method)
        out["r_load_optimal"], out["power_load_optimal"] = best
        # "interior", or the bound of the device-derived search the power still rises to
        out["r_load_optimal_location"] = best.location
    if coloured:
        out["excitation"] = psd.parameters()
    return out, harvester, psd


def _assembly_point(args, assembly: Assembly) -> tuple[dict, object, object]:
    """The JSON object of one point of ``--device`` (module docstring), with its assembly."""
    psd = excitation_from_args(args)
    coloured = isinstance(psd, Excitation)
    if args.optimal_bounds is not None:
        raise ValueError(
            "`--optimal-bounds` is for a single bridge (`--rectifier bridge`), not `--device`"
        )
    result = predict(assembly, psd, method=args.method)
    out = {
        "method": result.method,
        "psd": getattr(psd, "level", None) if coloured else psd,
        "device": args.device,
        "n_dof": assembly.n_dof,
        **result.to_dict(),
    }
    if args.optimal_load:
        for best in optimal_assembly_loads(assembly, psd):
            out["transducers"][best.transducer].update(best.to_dict())
    if coloured:
        out["excitation"] = psd.parameters()
    return out, assembly, psd


def _simulated_optimum_point(args, harvester, psd) -> dict | None:
    """A bridge's optimum by Monte Carlo, or None where the closure's search is used.

    Monte Carlo when ``--optimal-bounds`` is given, or when the method was not
    named and the bridge closure does not take this device and input (then
    the analytic prediction at the given device is left out: no method takes
    it). A closure that refuses only beyond its validity (the search finds no
    output within it) falls back the same way.
    """
    if not isinstance(psd, Excitation):  # a bad level is the user's, not the closure's limit
        check_positive("psd", psd, "(m/s^2)^2/Hz")
    if args.optimal_bounds is None:
        if not args.method_defaulted:
            return None
        if METHODS[args.method].accepts(harvester, psd):
            try:  # the closure's own range: refused beyond its validity at this level
                optimal_dc_output(harvester, psd)
                predict(harvester, psd, method=args.method)
            except ValueError:
                pass
            else:
                return None
        refusal = METHODS[args.method].refusal(harvester, psd) or (
            f"`--method {args.method}` refuses it beyond its validity"
        )
        raise ValueError(
            f"the optimum of this bridge needs Monte Carlo ({refusal.rstrip('.')}): give "
            f"`--optimal-bounds LOW HIGH` ({_bounds_words(harvester)})"
        )
    low, high = args.optimal_bounds
    battery = harvester.electrical.has_battery
    if not (math.isfinite(low) and math.isfinite(high) and 0.0 <= low < high) or (
        not battery and low == 0.0
    ):
        raise ValueError(
            f"`--optimal-bounds` must be {'0 <=' if battery else '0 <'} LOW < HIGH "
            f"({_bounds_words(harvester)}), finite; got {low:g} {high:g}"
        )
    if args.optimal_paths < 2:
        raise ValueError(f"`--optimal-paths` must be >= 2; got {args.optimal_paths}")
    if not args.optimal_t_end > 2.0:
        raise ValueError(
            f"`--optimal-t-end` must be > 2 s (the 2 s burn-in); got {args.optimal_t_end:g}"
        )
    if args.optimal_grid < 3:
        raise ValueError(f"`--optimal-grid` must be >= 3; got {args.optimal_grid}")
    best = simulated_dc_optimum(
        harvester, psd, (low, high), n_grid=args.optimal_grid, t_end=args.optimal_t_end,
        n_paths=args.optimal_paths, progress=False if args.no_progress or args.json else None,
    )  # fmt: skip
    coloured = isinstance(psd, Excitation)
    out = {
        "method": "monte-carlo",
        "psd": getattr(psd, "level", None) if coloured else psd,
        "friction": harvester.friction_name,
        "coupling": harvester.coupling_name,
        **best.to_dict(),
        "optimum_method": "monte-carlo",
        "optimal_paths": args.optimal_paths,
    }
    if coloured:
        out["excitation"] = psd.parameters()
    return out


def _bounds_words(harvester) -> str:
    """What ``--optimal-bounds`` holds for this bridge."""
    if harvester.electrical.has_battery:
        return "the battery voltage V_b, V"
    return "the storage capacitor's load R_L, ohm"


def _check_method(name: str, harvester, psd) -> None:
    """Refuse a method that does not take this case, or gives no stroke exceedance for `--stroke`.

    One line from the methods' declarations, naming those that do.
    """
    method = METHODS[name]
    method.require(harvester, psd)
    if harvester.stroke is not None and not method.stroke_exceedance:
        allowed = " or ".join(
            f"`--method {other}`"
            for other, declared in METHODS.items()
            if declared.stroke_exceedance and declared.accepts(harvester, psd)
        )
        raise ValueError(
            f"`--stroke` needs {allowed}: `--method {name}` gives no stroke exceedance"
        )


def _unit(key: str, harvester) -> str:
    """The unit of a key of the JSON object (none for words: method, friction...)."""
    return unit(key, getattr(harvester, "electrical", None)) if key in QUANTITIES else ""


def _print_assembly_point(out: dict, assembly: Assembly, psd) -> None:
    """One point of ``--device``: the assembly, then per transducer and per DOF."""
    print(f"device: {out['device']}: {assembly.describe()}")
    print(describe_excitation(psd))
    what = "exact (Lyapunov)" if out["exact"] else f"{out['method']} ({out['variance_method']})"
    rows = [("method", what, "")]
    for index, entry in enumerate(out["transducers"]):
        where = f"transducer {index} {between_words(assembly.transducers[index].between)}"
        for key in ("power_electrical", "power_load", "circuit_mean_square", "stroke_exceedance",
                    "r_load_optimal", "power_load_optimal", "c_e_optimal", "power_electrical_optimal"):  # fmt: skip
            if entry.get(key) is not None:
                electrical = assembly.transducers[index].coupling
                shown = unit(key, electrical) if key in QUANTITIES else _OPTIMAL_UNITS.get(key, "")
                rows.append((f"{where} {key}", entry[key], shown))
    for i, (zz, vv) in enumerate(
        zip(out["displacement_variance"], out["velocity_variance"], strict=True)
    ):
        rows += [
            (f"DOF {i} displacement_variance", zz, "m^2"),
            (f"DOF {i} velocity_variance", vv, "(m/s)^2"),
        ]
    rows += [
        (k, out[k], "W") for k in ("power_input", "power_mechanical") if out.get(k) is not None
    ]
    print_table(rows, ("quantity", "value", "unit"))


#: Units of the optimum keys of a transducer entry.
_OPTIMAL_UNITS = {"r_load_optimal": "ohm", "power_load_optimal": "W", "c_e_optimal": "Ns/m",
                  "power_electrical_optimal": "W"}  # fmt: skip


def _print_point(out: dict, harvester, psd) -> None:
    """One point: the device and excitation used, then quantity / value / unit."""
    if isinstance(harvester, Assembly):
        return _print_assembly_point(out, harvester, psd)
    print(describe_device(harvester))
    print(describe_excitation(psd))
    # a tabulated or measured spectrum has no level: the excitation line describes it;
    # tones and shocks are lists and objects: the excitation line, and a table of the tones
    shown = {k: v for k, v in out.items() if k != "excitation" and not (k == "psd" and v is None)}
    excitation = out.get("excitation", {})
    rows = [(k, v, _unit(k, harvester)) for k, v in shown.items() if not _nested(v)]
    rows += [(k, v, _unit(k, harvester)) for k, v in excitation.items() if not _nested(v)]
    print_table(rows, ("quantity", "value", "unit"))
    if out.get("tones"):
        _print_tones(out["tones"])
    if harvester.electrical is None and harvester.c_e == 0:
        print(
            "note: this device has no electrical damping (c_e = 0, as the presets identified "
            "without the coil), so the power it delivers is 0 W; give --alpha/--r-load/--r-coil "
            f"or --c-e. It dissipates {cell(out['power_mechanical'], 4)} W mechanically "
            "(c_m E[v^2] + friction)."
        )


def _nested(value) -> bool:
    return isinstance(value, list | dict)


def _print_tones(tones: list) -> None:
    """Each tone's response: its frequency and amplitude, the displacement and velocity amplitudes."""
    print()
    rows = [
        (t["frequency"], t["amplitude"], t["displacement_amplitude"], t["velocity_amplitude"],
         t["c_eq"], t["k_eq"])
        for t in tones
    ]  # fmt: skip
    headers = ("tone (Hz)", "A (m/s^2)", "Z (m)", "V (m/s)", "c_eq (Ns/m)", "k_eq (N/m)")
    print_table(rows, headers)


#: The columns of a sweep's table, after the swept options, where present.
SWEEP_COLUMNS = (
    "power_electrical",
    "power_load",
    "power_stored",
    "battery_optimal",
    "power_stored_optimal",
    "power_mechanical",
    "r_load_optimal",
    "power_load_optimal",
    "c_eq",
    "velocity_variance",
    "stroke_exceedance",
)


#: The columns of a sweep's table for each transducer of an assembly.
TRANSDUCER_COLUMNS = ("power_electrical", "power_load", "r_load_optimal", "power_load_optimal")


def _print_sweep(swept: list[str], points, results) -> None:
    """One row per point: the swept values, then the powers and main statistics."""
    first = results[0][0]
    columns = [c for c in SWEEP_COLUMNS if c in first and not isinstance(first[c], list)]
    # an assembly's (--device): each transducer's powers and optimum, by its index
    columns += [
        key
        for key in _flat(first.get("transducers", []), "transducers.")
        if key.rpartition(".")[2] in TRANSDUCER_COLUMNS
    ]
    print(f"method {first['method']}; swept {', '.join(option_flag(d) for d in swept)}")
    rows = [
        [getattr(point, dest) for dest in swept] + [_flat(out).get(c) for c in columns]
        for point, (out, _, _) in zip(points, results, strict=True)
    ]
    harvester = results[0][1]
    headers = [option_flag(d) for d in swept] + [
        f"{c} ({_unit(c.rpartition('.')[2], harvester)})"
        if _unit(c.rpartition(".")[2], harvester)
        else c
        for c in columns
    ]
    print_table(rows, headers)


def _flat(value, prefix: str = "") -> dict:
    """A JSON object as one CSV row: nested keys dotted (``excitation.f0``, ``transducers.0.power_load``)."""
    if isinstance(value, dict):
        items = value.items()
    elif (
        isinstance(value, list)
        and any(isinstance(x, dict | list) for x in value)
        or (
            isinstance(value, list)
            and prefix.rstrip(".") in ("displacement_variance", "velocity_variance")
        )
    ):
        items = enumerate(value)
    else:
        return {prefix.rstrip("."): value}
    out = {}
    for key, item in items:
        out.update(_flat(item, f"{prefix}{key}."))
    return out


def _write_csv(path, outs: list[dict], overwrite: bool):
    """Every point's keys (the excitation's as ``excitation.NAME``), one row per point.

    Written whole or not at all; where it could not be written, the table is
    kept in an ``randvib-unsaved-*`` file, whose path is returned.
    """
    rows = [_flat(out) for out in outs]
    names = list(dict.fromkeys(k for row in rows for k in row))
    text = io.StringIO(newline="")
    writer = csv.DictWriter(text, fieldnames=names)
    writer.writeheader()
    writer.writerows(rows)
    return write_or_keep(path, text.getvalue(), "--csv", overwrite=overwrite)
