"""Device options shared by the commands that take a harvester, or an assembly (``--device``).

``--device FILE.toml`` (or the name of a shipped example, ``randvib.datasets.device_names``)
reads an :class:`~randvib.models.assembly.Assembly` from a device file
(:mod:`randvib.models.device_file`); it replaces every other device option.
:func:`assembly_from_args` reads it; :func:`harvester_from_args` refuses it, so a
command that does not take assemblies yet says so in one line (``power`` takes it).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from randvib.datasets import device_names, device_path
from randvib.models.assembly import Assembly
from randvib.models.coupling import COUPLINGS, coupling_class
from randvib.models.friction import FRICTION_MODELS, RegistryView
from randvib.models.harvester import ElectricalDampingOverflow, Harvester
from randvib.models.potential import Potential
from randvib.models.presets import PRESETS, preset
from randvib.models.rectifier import RECTIFIED

#: The bridge's own options (the transducer's come from its coupling's declaration).
BRIDGE_OPTIONS = (
    "v_diode", "battery", "storage_capacitance", "saturation_current", "ideality",
    "thermal_voltage",
)  # fmt: skip

#: ``--friction`` choices: ``none`` and every registered law (live view).
FRICTION_CHOICES = RegistryView(lambda law: law)


def option_flag(dest: str) -> str:
    """The command-line flag of an argparse ``dest`` (``f_lo`` -> ``--f-lo``)."""
    return "--" + dest.replace("_", "-")


def options_by_parameter(members: dict) -> dict[str, list]:
    """Parameter name -> the members declaring it, from ``{member: parameter names}``.

    Model families (friction laws, excitations) declare their parameters; the
    CLI makes one option per parameter name and remembers who owns it.
    """
    out: dict[str, list] = {}
    for member, names in members.items():
        for name in names:
            out.setdefault(name, []).append(member)
    return out


def refuse_foreign_options(given, own, owners: dict, describe: str, chosen: str) -> None:
    """Refuse, rather than silently ignore, an option of another member of the family.

    ``describe`` formats the owners' names, e.g. ``"{owners} friction"``.
    """
    for name in given:
        if name not in own:
            whose = describe.format(owners=", ".join(owners[name]))
            raise ValueError(f"`{option_flag(name)}` applies to {whose}, not {chosen!r}")


def _friction_options() -> dict[str, list]:
    """Parameter name -> the laws declaring it, over the registered laws."""
    return options_by_parameter({law: law.parameter_names() for law in FRICTION_MODELS.values()})


def _coupling_options() -> dict[str, list]:
    """Parameter name -> the couplings declaring it, over the registered couplings."""
    return options_by_parameter({c: c.parameter_names() for c in COUPLINGS.values()})


def add_device_arguments(parser: argparse.ArgumentParser) -> None:
    """Add --device, --preset, the device parameters and --psd to ``parser``."""
    g = parser.add_argument_group("device (SI units; values override --preset or --from-fit)")
    g.add_argument(
        "--device",
        metavar="FILE",
        help="an assembly from a device file (TOML: structure, elements, transducers; "
        f"docs/assemblies.md) or a shipped example ({', '.join(device_names())}); instead of "
        "every other device option",
    )
    g.add_argument(
        "--preset",
        metavar="NAME",
        choices=tuple(PRESETS),
        help=f"start from a paper preset: {', '.join(PRESETS)}",
    )
    g.add_argument(
        "--from-fit",
        metavar="FILE.json",
        help="start from an identified device (`randvib identify --save`): its mechanics, "
        "friction and, when identified, its coupling at the first record's load, through the "
        "diode bridge it was fitted behind (--r-load and the other options override)",
    )
    g.add_argument("--m", type=float, help="mass (kg)")
    g.add_argument("--c-m", type=float, help="mechanical damping (Ns/m)")
    g.add_argument("--c-e", type=float, help="electrical damping (Ns/m), default 0")
    g.add_argument(
        "--k",
        type=float,
        help="linear stiffness (N/m); 0 or negative allowed: bistable with k < 0 < k3, "
        "pure cubic with k = 0, free mass with k = k3 = 0",
    )
    g.add_argument("--k3", type=float, help="cubic stiffness (N/m^3)")
    g.add_argument(
        "--wells",
        type=float,
        help="bistable device by its wells at z = +-WELLS (m, > 0), with --barrier; "
        "instead of --k/--k3 (k = -4 barrier/wells^2, k3 = 4 barrier/wells^4)",
    )
    g.add_argument(
        "--barrier", type=float, help="barrier height between the wells (J, > 0), with --wells"
    )
    g.add_argument(
        "--stroke",
        type=float,
        help="stroke limit (m, > 0): report the time fraction with abs(z) beyond it "
        "(and, from Monte Carlo, the mean first time to reach it)",
    )
    g.add_argument(
        "--friction",
        metavar="LAW",
        choices=FRICTION_CHOICES,
        help=f"friction model: {', '.join(FRICTION_CHOICES)}",
    )
    # One option per friction parameter, as the laws declare them.
    for name, laws in _friction_options().items():
        spec = laws[0].parameter_specs()[name]
        g.add_argument(
            option_flag(name),
            type=float,
            help=f"{spec.description or name} ({spec.unit}); {', '.join(law.name for law in laws)}",
        )
    g.add_argument(
        "--coupling",
        metavar="NAME",
        choices=tuple(COUPLINGS),
        help=f"electrical coupling: {', '.join(COUPLINGS)} (default resistive when its options "
        "are given; instead of --c-e)",
    )
    # One option per coupling parameter, as the couplings declare them.
    for name, couplings in _coupling_options().items():
        spec = couplings[0].parameter_specs()[name]
        g.add_argument(
            option_flag(name),
            type=float,
            help=f"{spec.description} ({spec.unit}); {', '.join(c.name for c in couplings)}",
        )
    g.add_argument(
        "--rectifier",
        choices=("bridge",),
        help="rectify the inductive or piezo coupling's output with a full-wave diode bridge "
        "into --battery or --storage-capacitance with --r-load (--inductance then defaults "
        "to 0, the algebraic-current case)",
    )
    g.add_argument("--v-diode", type=float, help="forward drop of each diode V_d (V); bridge")
    g.add_argument("--battery", type=float, help="battery voltage V_b (V); bridge")
    g.add_argument(
        "--storage-capacitance", type=float, help="storage capacitor C (F), with --r-load; bridge"
    )
    g.add_argument(
        "--saturation-current",
        type=float,
        help="Shockley diodes' saturation current I_s (A) instead of --v-diode; inductive bridge",
    )
    g.add_argument("--ideality", type=float, help="Shockley diodes' ideality factor n (default 1)")
    g.add_argument(
        "--thermal-voltage", type=float, help="Shockley diodes' k T / q (V, default 0.025852)"
    )
    g.add_argument(
        "--psd", type=float, default=None, help="one-sided base-acceleration PSD S ((m/s^2)^2/Hz)"
    )
    # the options --device replaces (not --psd, the excitation's level)
    own = tuple(a.dest for a in g._group_actions if a.dest not in ("device", "psd"))
    parser.set_defaults(device_options=own)


def _potential_from_wells(args) -> dict:
    """``{"k": ..., "k3": ...}`` from ``--wells``/``--barrier`` (empty when neither is given)."""
    wells, barrier = getattr(args, "wells", None), getattr(args, "barrier", None)
    if wells is None and barrier is None:
        return {}
    if wells is None or barrier is None:
        missing = "--barrier" if barrier is None else "--wells"
        raise ValueError(f"`--wells` and `--barrier` go together: `{missing}` is missing")
    if args.k is not None or args.k3 is not None:
        raise ValueError("give either `--wells/--barrier` or `--k/--k3`, not both")
    try:
        potential = Potential.from_wells(wells, barrier)
    except ValueError as error:
        text = str(error).replace("`well`", "`--wells`").replace("`barrier`", "`--barrier`")
        raise ValueError(text) from None
    return {"k": potential.k, "k3": potential.k3}


def assembly_from_args(args) -> Assembly | None:
    """The assembly of ``--device`` (a file, or a shipped example's name), or None without it.

    Refuses any other device option beside it, naming the first.
    """
    name = getattr(args, "device", None)
    if name is None:
        return None
    if getattr(args, "from_fit", None) is not None:
        raise ValueError("give either `--device` or `--from-fit`, not both")
    given = [d for d in getattr(args, "device_options", ()) if getattr(args, d, None) is not None]
    if given:
        raise ValueError(
            f"`--device` gives the whole device; drop `{option_flag(given[0])}` (change the file, "
            "or give the single-mass device by its options without --device)"
        )
    path = Path(name)
    if not path.exists() and path.suffix != ".toml":
        try:
            path = device_path(name)
        except ValueError:
            raise ValueError(
                f"`--device`: no such file {name} (nor a shipped example: "
                f"{', '.join(device_names())})"
            ) from None
    return Assembly.from_toml(path)


def fitted_device(path) -> Harvester:
    """The device a saved identification holds (``randvib identify --save`` / ``--json``).

    Its c is the mechanical damping c_m when the fit identified its coupling
    (wired at the first record's load, through the diode bridge it was fitted
    behind: :mod:`randvib.models.rectifier`); otherwise c is the total damping
    of the record it was fitted to and the device has no coupling.
    """
    import json

    from randvib._io import existing_file
    from randvib.identification.result import IdentificationResult

    path = existing_file(path, "`--from-fit` file", "JSON")
    try:
        data = json.loads(path.read_text())
        result = IdentificationResult.from_dict(data)
        return result.harvester()
    except (ValueError, KeyError, TypeError, AttributeError, IndexError) as exc:
        detail = f": {exc}" if isinstance(exc, ValueError) and str(exc) else ""
        raise ValueError(
            f"`--from-fit` {str(path)!r} is not a saved identification (the JSON of `randvib "
            f"identify --save`){detail}"
        ) from None


def fit_is_rectified(args) -> bool:
    """True when ``--from-fit`` holds a device fitted behind a diode bridge (and no other
    ``--coupling`` replaces it): the commands choose the bridge's own defaults for it."""
    path = getattr(args, "from_fit", None)
    return path is not None and _keeps_fitted_bridge(args, fitted_device(path).electrical)


def _keeps_fitted_bridge(args, fitted) -> bool:
    """Whether the fit's coupling ``fitted`` has a bridge that ``args`` keep: no other
    transducer asked for with ``--coupling``."""
    return getattr(fitted, "rectified", False) and getattr(args, "coupling", None) in (
        None,
        fitted.transducer,
    )


def _base_device(args):
    """(values, friction, coupling) of ``--preset`` or ``--from-fit`` (or none)."""
    from_fit = getattr(args, "from_fit", None)
    if args.preset is not None and from_fit is not None:
        raise ValueError("give either `--preset` or `--from-fit`, not both")
    base = preset(args.preset) if args.preset is not None else None
    if from_fit is not None:
        base = fitted_device(from_fit)
    if base is None:
        return {"m": None, "c_m": None, "c_e": None, "k": None, "k3": 0.0}, None, None
    values = {"m": base.m, "c_m": base.c_m, "c_e": base.c_e, "k": base.k, "k3": base.k3}
    if base.electrical is not None:
        values["c_e"] = None  # follows the coupling
    return values, base.friction, base.electrical


def harvester_from_args(args) -> Harvester:
    """Build the harvester from a preset, a saved fit and/or explicit options.

    ``--device`` (an assembly) is refused here: the commands that take it
    read it with :func:`assembly_from_args` first.
    """
    if getattr(args, "device", None) is not None:
        raise ValueError(
            "`--device` (an assembly of several masses) is not taken here yet; "
            "`randvib power --device FILE` predicts its stationary power"
        )
    values, friction, fitted_coupling = _base_device(args)
    for name in values:
        given = getattr(args, name)
        if given is not None:
            values[name] = given
    values.update(_potential_from_wells(args))

    friction = _friction_from_args(args, friction)

    coupling = _coupling_from_args(args, fitted_coupling)
    if coupling is not None:
        for name in ("m", "c_m", "k"):
            _need(values[name], option_flag(name), "the device")
        try:
            return Harvester.with_coupling(
                values["m"],
                values["c_m"],
                values["k"],
                coupling,
                k3=values["k3"],
                friction=friction,
                stroke=args.stroke,
            )
        except (OverflowError, ZeroDivisionError, ElectricalDampingOverflow):
            flags = ", ".join(f"`{option_flag(n)}`" for n in coupling.parameter_names())
            raise ValueError(
                f"{flags}: the {coupling.name} coupling's electrical damping is not a finite number"
            ) from None
    if values["c_e"] is None:
        values["c_e"] = 0.0  # no coupling given: no electrical damping, as the identified presets
    for name in ("m", "c_m", "k"):
        _need(values[name], option_flag(name), "the device (or use --preset)")
    return Harvester(friction=friction, stroke=args.stroke, **values)


def _bridge_from_args(args):
    """The rectified coupling of ``--rectifier bridge`` (:mod:`randvib.models.rectifier`)."""
    if args.c_e is not None:
        raise ValueError("give either `--c-e` or `--rectifier bridge`, not both")
    if args.coupling not in RECTIFIED:
        raise ValueError(
            f"`--rectifier bridge` needs `--coupling {'|'.join(RECTIFIED)}`; "
            + ("none given" if args.coupling is None else f"got {args.coupling!r}")
        )
    cls = RECTIFIED[args.coupling]
    transducer = COUPLINGS[args.coupling]
    options = _coupling_options()
    given = {n: getattr(args, n) for n in options if getattr(args, n, None) is not None}
    given.update({n: getattr(args, n) for n in BRIDGE_OPTIONS if getattr(args, n) is not None})
    own = cls.parameter_names()
    owners = {name: [c.name for c in couplings] for name, couplings in options.items()}
    for name in BRIDGE_OPTIONS:  # the bridges' own options, by the bridges that declare them
        owners[name] = [c.name for c in RECTIFIED.values() if name in c.parameter_names()]
    refuse_foreign_options(given, own, owners, "the {owners} coupling", cls.name)
    optional = ("r_load", "inductance")  # the storage load; L defaults to 0
    required = [n for n in transducer.parameter_names() if n in own and n not in optional]
    missing = [n for n in required if n not in given]
    if missing:
        raise ValueError(
            f"the {cls.name} needs {', '.join(f'`{option_flag(n)}`' for n in missing)}"
        )
    return _built(cls, given, own)


def _fitted_bridge(args, fitted):
    """A saved fit's coupling through its diode bridge, the options given overriding it.

    ``--battery`` replaces a storage capacitor and its load, ``--storage-capacitance``
    a battery (with ``--r-load``); ``--rectifier bridge`` and the transducer's
    ``--coupling`` may be repeated. The bridge is never dropped.
    """
    if args.c_e is not None:
        raise ValueError(
            "`--from-fit` holds the coupling and its bridge; `--c-e` cannot replace it"
        )
    cls = type(fitted)
    options = _coupling_options()
    given = {n: getattr(args, n) for n in options if getattr(args, n, None) is not None}
    given.update({n: getattr(args, n) for n in BRIDGE_OPTIONS if getattr(args, n) is not None})
    owners = {name: [c.name for c in couplings] for name, couplings in options.items()}
    for name in BRIDGE_OPTIONS:
        owners[name] = [c.name for c in RECTIFIED.values() if name in c.parameter_names()]
    refuse_foreign_options(given, cls.parameter_names(), owners, "the {owners} coupling", cls.name)
    values = fitted.parameters()
    if "battery" in given:  # another output: the fit's is replaced, not mixed in
        values.pop("storage_capacitance", None)
        values.pop("r_load", None)
    if "storage_capacitance" in given or "r_load" in given:
        values.pop("battery", None)
    return _built(cls, {**values, **given}, given)


def _coupling_from_args(args, fitted=None):
    """The coupling from ``--coupling`` and its parameter options, or None (``--c-e``).

    ``fitted``: a saved fit's coupling, whose parameters the options override
    (``--r-load 20`` wires it to another load).
    """
    if _keeps_fitted_bridge(args, fitted):
        return _fitted_bridge(args, fitted)
    if getattr(args, "rectifier", None) is not None:
        return _bridge_from_args(args)
    bridge = [n for n in BRIDGE_OPTIONS if getattr(args, n, None) is not None]
    if bridge:
        raise ValueError(f"`{option_flag(bridge[0])}` needs `--rectifier bridge`")
    options = _coupling_options()
    given = {n: getattr(args, n) for n in options if getattr(args, n, None) is not None}
    if fitted is not None and args.coupling in (None, fitted.name):
        if args.c_e is not None:
            raise ValueError("`--from-fit` holds the coupling; `--c-e` cannot replace it")
        owners = {name: [c.name for c in couplings] for name, couplings in options.items()}
        refuse_foreign_options(
            given, fitted.parameter_names(), owners, "the {owners} coupling", fitted.name
        )
        return _built(type(fitted), {**fitted.parameters(), **given}, given)
    if args.coupling is None and not given:
        return None
    if args.c_e is not None:
        raise ValueError(
            "give either `--c-e` or `--alpha/--r-load/--r-coil` (or another coupling's options), "
            "not both"
        )
    if args.coupling is not None and args.coupling not in COUPLINGS:
        raise ValueError(
            f"`--coupling` must be one of {', '.join(COUPLINGS)}; got {args.coupling!r}"
        )
    cls = coupling_class(args.coupling or "resistive")
    owners = {name: [c.name for c in couplings] for name, couplings in options.items()}
    refuse_foreign_options(given, cls.parameter_names(), owners, "the {owners} coupling", cls.name)
    missing = [n for n in cls.parameter_names() if n not in given]
    if missing:
        flags = ", ".join(f"`{option_flag(n)}`" for n in cls.parameter_names())
        raise ValueError(
            f"{flags} must be given together for the {cls.name} coupling "
            f"(missing {', '.join(f'`{option_flag(n)}`' for n in missing)})"
        )
    return _built(cls, given, given)


def _built(cls, given: dict, names):
    """``cls(**given)``, its refusal naming the flags of ``names``, not the parameters."""
    try:
        return cls(**given)
    except ValueError as exc:
        message = str(exc)
        for name in names:
            message = message.replace(f"`{name}`", f"`{option_flag(name)}`")
        raise ValueError(message) from None


def _friction_from_args(args, friction):
    """The friction law from ``--friction`` and its parameter options (over a preset's)."""
    options = _friction_options()
    owners = {name: [law.name for law in laws] for name, laws in options.items()}
    given = {n: getattr(args, n) for n in options if getattr(args, n, None) is not None}
    if args.friction is not None:
        if args.friction not in FRICTION_CHOICES:
            raise ValueError(
                f"`--friction` must be one of {', '.join(FRICTION_CHOICES)}; got {args.friction!r}"
            )
        if args.friction == "none":
            return None
        law = FRICTION_MODELS[args.friction]
        refuse_foreign_options(given, law.parameter_names(), owners, "{owners} friction", law.name)
        # A parameter not given keeps the preset's value where its law has it.
        values = {n: given.get(n, getattr(friction, n, None)) for n in law.parameter_names()}
        return law(
            **{n: _need(x, option_flag(n), f"{law.name} friction") for n, x in values.items()}
        )
    if not given:
        return friction
    if friction is None:
        flags = "/".join(f"`{option_flag(n)}`" for n in given)
        laws = sorted({law.name for n in given for law in options[n]})
        verb = "needs" if len(given) == 1 else "need"
        raise ValueError(
            f"{flags} {verb} `--friction {'|'.join(laws)}` (or a preset with friction)"
        )
    refuse_foreign_options(
        given, friction.parameter_names(), owners, "{owners} friction", friction.name
    )
    return type(friction)(**{**friction.parameters(), **given})


def require_psd(args) -> float:
    return _need(args.psd, "--psd", "the excitation")


def _need(value, option: str, what: str):
    if value is None:
        raise ValueError(f"`{option}` is required for {what}")
    return value
