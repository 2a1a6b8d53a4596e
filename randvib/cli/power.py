"""``randvib power``: analytic expected power (paper Eq. 19-32 and beyond).

Under white noise (the default) every method of
:data:`randvib.analytic.prediction.METHODS` applies and the output is what
it was before excitations existed; under another excitation only the methods
of :data:`~randvib.analytic.prediction.COLOURED` (statistical linearisation)
do, and the JSON gains an ``excitation`` object describing it.
"""

from __future__ import annotations

from randvib._io import dumps
from randvib.analytic.prediction import CIRCUIT, COLOURED, METHODS, predict
from randvib.cli._device import add_device_arguments, harvester_from_args
from randvib.cli._excitation import add_excitation_arguments, excitation_from_args
from randvib.cli._output import print_table
from randvib.models.excitation import Excitation

#: The methods that report the stationary probability beyond the stroke.
STROKE_METHODS = ("linearisation", "fpk-fast", "fpk")


def register(sub) -> None:
    p = sub.add_parser(
        "power",
        help="analytic expected power under white noise or a coloured excitation",
        description="Expected power of the harvester under base acceleration (white noise "
        "by default), by an analytic method.",
    )
    add_device_arguments(p)
    add_excitation_arguments(p)
    p.add_argument(
        "--method",
        default="linearisation",
        choices=tuple(METHODS),
        metavar="METHOD",
        help=f"analytic method: {', '.join(METHODS)} (default linearisation, paper Eq. 32; "
        "averaging: stochastic averaging, non-Gaussian velocity, 0.3 ms; "
        "fpk-fast: corrected small-grid FPK solution, resolves the k3 effect, 2 ms; "
        "fpk: fine-grid FPK solution, slow reference); a non-white excitation: "
        f"{', '.join(COLOURED)} only",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(handler=run)


# JSON: the keys of PowerPrediction.to_dict(); `displacement_variance` is null for
# the free mass (k = k3 = 0); with --stroke, `stroke` and `stroke_exceedance`
# (P(|z| > stroke): FPK's stationary probability, linearisation's Gaussian estimate).


def run(args) -> int:
    harvester = harvester_from_args(args)
    psd = excitation_from_args(args)
    coloured = isinstance(psd, Excitation)
    if coloured and args.method not in COLOURED:
        accepted = ", ".join(f"`--method {name}`" for name in COLOURED)
        raise ValueError(
            f"`--method {args.method}` assumes white noise; the {psd.name} excitation needs "
            f"{accepted}"
        )
    if harvester.has_circuit and args.method not in CIRCUIT:
        accepted = ", ".join(f"`--method {name}`" for name in CIRCUIT)
        raise ValueError(
            f"`--method {args.method}` assumes the resistive coupling; the "
            f"{harvester.coupling_name} coupling's circuit state needs {accepted}"
        )
    if harvester.stroke is not None and args.method not in STROKE_METHODS:
        allowed = " or ".join(f"`--method {name}`" for name in STROKE_METHODS)
        raise ValueError(
            f"`--stroke` needs {allowed}: `--method {args.method}` gives no stroke exceedance"
        )
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
    if harvester.electrical is not None:  # added with the couplings (issue 11)
        out["coupling"] = harvester.coupling_name
    if harvester.stroke is not None:
        out["stroke"] = harvester.stroke
        # null where not stationary (the free mass)
        out["stroke_exceedance"] = result.stroke_exceedance
    if coloured:
        out["excitation"] = psd.parameters()
    if args.json:
        print(dumps(out))
    else:
        units = {
            "psd": "(m/s^2)^2/Hz",
            "c_eq": "Ns/m",
            "velocity_variance": "(m/s)^2",
            "displacement_variance": "m^2",
            "mean_abs_velocity": "m/s",
            "power_electrical": "W",
            "power_load": "W",
            "circuit_mean_square": "A^2 or V^2",
            "stroke": "m",
            # the excitation's parameters
            "level": "(m/s^2)^2/Hz",
            "f0": "Hz",
            "f_lo": "Hz",
            "f_hi": "Hz",
            "variance": "(m/s^2)^2",
            "duration": "s",
            "dt": "s",
            "segment_length": "samples",
        }
        rows = [(k, v, units.get(k, "")) for k, v in out.items() if k != "excitation"]
        rows += [(k, v, units.get(k, "")) for k, v in out.get("excitation", {}).items()]
        print_table(rows, ("quantity", "value", "unit"))
    return 0
