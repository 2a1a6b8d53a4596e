"""``randvib simulate``: Monte Carlo ensemble of the harvester under white or filtered noise.

White noise as before; ``--excitation band-pass|kanai-tajimi`` integrates the
shaping filter with the device (the options of :mod:`randvib.cli._excitation`,
shared with ``randvib power``); spectra without a shaping filter are refused
by :func:`randvib.simulate` with a message naming the method that takes them.
"""

from __future__ import annotations

from randvib._io import dumps
from randvib.analytic.prediction import predict
from randvib.cli._device import add_device_arguments, harvester_from_args
from randvib.cli._excitation import add_excitation_arguments, excitation_from_args
from randvib.cli._output import print_table
from randvib.montecarlo.integrators import INTEGRATORS


def register(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="Monte Carlo simulation under white or filtered (band-pass, Kanai-Tajimi) noise",
        description="Simulate an ensemble of the harvester under white-noise or filtered "
        "base acceleration; statistics with 95 % confidence half-widths.",
    )
    add_device_arguments(p)
    add_excitation_arguments(p)
    g = p.add_argument_group("simulation")
    g.add_argument("--paths", type=int, default=1000, help="number of paths (default 1000)")
    g.add_argument("--t-end", type=float, default=20.0, help="time per path incl. burn-in (s)")
    g.add_argument("--dt", type=float, default=1e-4, help="time step (s), default 1e-4")
    g.add_argument("--burn-in", type=float, default=2.0, help="discarded initial time (s)")
    g.add_argument("--method", default="heun", help=f"integrator: {', '.join(INTEGRATORS)}")
    g.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    g.add_argument("--threads", type=int, default=None, help="threads (default: all cores)")
    g.add_argument(
        "--control-variates",
        action="store_true",
        help="variance-reduced estimates (energy balance and friction-free companion)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(handler=run)


def run(args) -> int:
    from randvib.montecarlo.simulation import simulate

    harvester = harvester_from_args(args)
    psd = excitation_from_args(args)
    if args.control_variates and not isinstance(psd, float | int):
        raise ValueError(
            "`--control-variates` needs white noise: the energy-balance controls and the "
            f"friction-free companion's exact moments do not hold under {psd.name} excitation"
        )
    if args.method not in INTEGRATORS:
        raise ValueError(f"`--method` must be one of {', '.join(INTEGRATORS)}; got {args.method!r}")
    result = simulate(
        harvester,
        psd,
        t_end=args.t_end,
        dt=args.dt,
        n_paths=args.paths,
        burn_in=args.burn_in,
        scheme=args.method,  # the CLI keeps its option name `--method`
        seed=args.seed,
        threads=args.threads,
        companion=args.control_variates,
        control_variates=args.control_variates,
    )
    summary = result.summary()
    if args.json:
        print(dumps(summary))
        return 0
    analytic = None
    if harvester.friction is None or harvester.friction.has_equivalent_damping:
        analytic = predict(harvester, psd)
    rows = []
    units = {
        "power_electrical": "W",
        "power_load": "W",
        "velocity_variance": "(m/s)^2",
        "displacement_variance": "m^2",
        "mean_abs_velocity": "m/s",
        "friction_power": "W",
    }
    for name, unit in units.items():
        if name not in summary:
            continue
        s = summary[name]
        lin = getattr(analytic, name, None) if analytic is not None else None
        rows.append((name, s["mean"], s["ci95"], "" if lin is None else lin, unit))
    print_table(rows, ("statistic", "Monte Carlo", "± 95 %", "linearisation", "unit"))
    print(
        f"{result.n_paths} paths x {result.averaging_time:g} s averaged (dt {result.dt:g} s, "
        f"{result.scheme}, seed {result.seed}), {result.wall_time:.2f} s wall"
    )
    return 0
