"""``randvib power``: analytic expected power (paper Eq. 19-32 and beyond)."""

from __future__ import annotations

import json

from randvib.analytic.prediction import METHODS, predict
from randvib.cli._device import add_device_arguments, harvester_from_args, require_psd
from randvib.cli._output import print_table


def register(sub) -> None:
    p = sub.add_parser(
        "power",
        help="analytic expected power under white noise",
        description="Expected power of the harvester under white-noise base "
        "acceleration, by an analytic method.",
    )
    add_device_arguments(p)
    p.add_argument(
        "--method",
        default="linearisation",
        help=f"analytic method: {', '.join(METHODS)} (default linearisation, paper Eq. 32; "
        "averaging: stochastic averaging, non-Gaussian velocity, 0.3 ms; "
        "fpk-fast: corrected small-grid FPK solution, resolves the k3 effect, 2 ms; "
        "fpk: fine-grid FPK solution, slow reference)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(handler=run)


def run(args) -> int:
    harvester = harvester_from_args(args)
    psd = require_psd(args)
    result = predict(harvester, psd, method=args.method)
    out = {
        "method": result.method,
        "psd": psd,
        "friction": harvester.friction_name,
        **result.to_dict(),
    }
    if result.power_load is None:
        out.pop("power_load")
    if args.json:
        print(json.dumps(out))
    else:
        units = {
            "psd": "(m/s^2)^2/Hz",
            "c_eq": "Ns/m",
            "velocity_variance": "(m/s)^2",
            "displacement_variance": "m^2",
            "mean_abs_velocity": "m/s",
            "power_electrical": "W",
            "power_load": "W",
        }
        print_table(
            [(k, v, units.get(k, "")) for k, v in out.items()], ("quantity", "value", "unit")
        )
    return 0
