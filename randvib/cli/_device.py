"""Device options shared by the commands that take a harvester."""

from __future__ import annotations

import argparse

from randvib.friction import Coulomb, Tanh
from randvib.harvester import Harvester
from randvib.presets import PRESETS, preset

FRICTION_CHOICES = ("none", "coulomb", "tanh")


def add_device_arguments(parser: argparse.ArgumentParser) -> None:
    """Add --preset, the device parameters and --psd to ``parser``."""
    g = parser.add_argument_group("device (SI units; values override --preset)")
    g.add_argument(
        "--preset", metavar="NAME", help=f"start from a paper preset: {', '.join(PRESETS)}"
    )
    g.add_argument("--m", type=float, help="mass (kg)")
    g.add_argument("--c-m", type=float, help="mechanical damping (Ns/m)")
    g.add_argument("--c-e", type=float, help="electrical damping (Ns/m)")
    g.add_argument("--k", type=float, help="linear stiffness (N/m)")
    g.add_argument("--k3", type=float, help="cubic stiffness (N/m^3)")
    g.add_argument("--friction", help=f"friction model: {', '.join(FRICTION_CHOICES)}")
    g.add_argument("--fc", type=float, help="friction level Fc (N)")
    g.add_argument("--beta", type=float, help="tanh sharpness beta (s/m)")
    g.add_argument(
        "--alpha", type=float, help="flux gradient (Wb/m), with --r-load/--r-coil instead of --c-e"
    )
    g.add_argument("--r-load", type=float, help="load resistance (ohm)")
    g.add_argument("--r-coil", type=float, help="coil resistance (ohm)")
    g.add_argument(
        "--psd", type=float, default=None, help="one-sided base-acceleration PSD S ((m/s^2)^2/Hz)"
    )


def harvester_from_args(args) -> Harvester:
    """Build the harvester from a preset and/or explicit options."""
    if args.preset is not None:
        base = preset(args.preset)
        values = {"m": base.m, "c_m": base.c_m, "c_e": base.c_e, "k": base.k, "k3": base.k3}
        friction = base.friction
    else:
        values = {"m": None, "c_m": None, "c_e": None, "k": None, "k3": 0.0}
        friction = None
    for name in values:
        given = getattr(args, name)
        if given is not None:
            values[name] = given

    if args.friction is not None:
        if args.friction not in FRICTION_CHOICES:
            raise ValueError(
                f"`--friction` must be one of {', '.join(FRICTION_CHOICES)}; got {args.friction!r}"
            )
        if args.friction == "none":
            friction = None
        elif args.friction == "coulomb":
            if args.beta is not None:
                raise ValueError("`--beta` applies to tanh friction, not 'coulomb'")
            fc = args.fc if args.fc is not None else getattr(friction, "fc", None)
            friction = Coulomb(_need(fc, "--fc", "coulomb friction"))
        else:
            fc = args.fc if args.fc is not None else getattr(friction, "fc", None)
            beta = args.beta if args.beta is not None else getattr(friction, "beta", None)
            friction = Tanh(
                _need(fc, "--fc", "tanh friction"), _need(beta, "--beta", "tanh friction")
            )
    elif friction is not None and (args.fc is not None or args.beta is not None):
        changes = {}
        if args.fc is not None:
            changes["fc"] = args.fc
        if args.beta is not None:
            if not isinstance(friction, Tanh):
                raise ValueError(f"`--beta` applies to tanh friction, not {friction.name!r}")
            changes["beta"] = args.beta
        friction = type(friction)(**{**friction.parameters(), **changes})
    elif friction is None and (args.fc is not None or args.beta is not None):
        raise ValueError(
            "`--fc`/`--beta` need `--friction coulomb|tanh` (or a preset with friction)"
        )

    circuit = [args.alpha, args.r_load, args.r_coil]
    if any(x is not None for x in circuit):
        if args.c_e is not None:
            raise ValueError("give either `--c-e` or `--alpha/--r-load/--r-coil`, not both")
        if any(x is None for x in circuit):
            raise ValueError("`--alpha`, `--r-load` and `--r-coil` must be given together")
        for name in ("m", "c_m", "k"):
            _need(values[name], "--" + name.replace("_", "-"), "the device")
        return Harvester.from_electrical(
            m=values["m"],
            c_m=values["c_m"],
            k=values["k"],
            k3=values["k3"],
            alpha=args.alpha,
            r_load=args.r_load,
            r_coil=args.r_coil,
            friction=friction,
        )
    for name in ("m", "c_m", "c_e", "k"):
        _need(values[name], "--" + name.replace("_", "-"), "the device (or use --preset)")
    return Harvester(friction=friction, **values)


def require_psd(args) -> float:
    return _need(args.psd, "--psd", "the excitation")


def _need(value, option: str, what: str):
    if value is None:
        raise ValueError(f"`{option}` is required for {what}")
    return value
