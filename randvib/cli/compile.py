"""``randvib compile``: compile every numerical kernel a regular install uses, now, once.

randvib's compiled loops (numba, ``cache=True``) are compiled on their first
use and then loaded from the on-disk cache beside the package. Without this
command each command compiles what it needs the first time it runs (and says
so once per run: :func:`randvib.cli.compile_notice`), so the first
``randvib design``, ``simulate`` or ``identify`` waits minutes. ``randvib
compile`` runs a tiny case through each of them (:data:`WARM_UP`: the Monte
Carlo kernel under white, filtered, synthesised and recorded input, with a
coil, a piezo element and diode bridges, each friction law, events, and the
record simulator of identification), says what it compiled and how long it
took; run again, it loads them from the cache in seconds.
"""

from __future__ import annotations

import sys
import time

from randvib.cli import COMMAND_HELP


def _device(**changes):
    import randvib as rv

    return rv.preset("figure9").updated(**changes)


def _wired(coupling, **changes):
    import randvib as rv

    base = _device(**changes)
    return rv.Harvester.with_coupling(base.m, base.c_m, base.k, coupling, k3=base.k3,
                                      friction=base.friction, stroke=base.stroke)  # fmt: skip


#: A few milliseconds of simulated time: the kernels compile on the first call, whatever its size.
TINY = dict(t_end=0.02, burn_in=0.01, dt=1e-3, n_paths=2, progress=False, check_step=False)


def _simulate(device, psd, **options):
    import randvib as rv

    return lambda: rv.simulate(device, psd, **{**TINY, **options})


def _record_responses():
    """The record simulators of identify, validate and record: each law, one device and a
    batch, and a device behind a bridge."""
    import numpy as np

    import randvib as rv

    record = rv.Record(1e-3, base_acceleration=np.sin(np.arange(64) * 0.1))
    for friction in (None, rv.Coulomb(0.005), rv.Tanh(0.005, 1e3), rv.LuGre(1.0, 0.1, 0.005, 0.006, 0.01)):  # fmt: skip
        device = _device(friction=friction)
        rv.record_response(device, record)
        rv.record_response(device.updated(k=np.array([50.0, 60.0])), record)
    # behind a diode bridge: one compiled batch for every law, bridge and output
    bridge = rv.BridgeCoil(alpha=0.2, r_coil=5.0, v_diode=0.1, storage_capacitance=1e-2, r_load=50)
    rv.record_response(rv.Harvester.with_coupling(0.02, 0.05, 50.0, bridge), record)


def _on_record():
    import numpy as np

    import randvib as rv

    acceleration = np.random.default_rng(0).standard_normal(400)
    record = rv.Measured(rv.Record(1e-3, base_acceleration=acceleration))
    rv.monte_carlo_on_record(_device(), record, segments=2, burn_in=0.05, progress=False)


def _event():
    import randvib as rv

    event = rv.Enveloped(rv.BandPass(1.0, 8.0, 0.2), rv.ShinozukaSato.unit_peak(0.5, 2.0))
    for psd in (event, rv.Enveloped(1.0, rv.Step())):
        rv.simulate_transient(_device(stroke=0.005), psd, t_end=0.02, dt=1e-3, n_paths=2,
                              progress=False, check_step=False)  # fmt: skip


def warm_up_steps() -> list[tuple[str, object]]:
    """(what, call) of every compiled path a regular install uses, on tiny cases."""
    import randvib as rv

    coil = rv.BridgeCoil(0.1992, 0.48, v_diode=0.01, battery=0.02)
    return [
        ("Monte Carlo, white noise, control variates",
         _simulate(_device(stroke=0.005), 1.0, control_variates=True, companion=True)),
        ("Monte Carlo, tanh and LuGre friction",
         lambda: (_simulate(_device(friction=rv.Tanh(0.005, 1e3)), 1.0)(),
                  _simulate(_device(friction=rv.LuGre(1.0, 0.1, 0.005, 0.006, 0.01)), 1.0)())),
        ("Monte Carlo, filtered input", _simulate(_device(), rv.BandPass(1.0, 8.0, 0.2))),
        ("Monte Carlo, synthesised input", _simulate(_device(), rv.BandLimited(1.0, 4.0, 20.0))),
        ("Monte Carlo, coil with inductance", _simulate(_wired(rv.Inductive(0.2, 1.0, 0.5, 1e-3)), 1.0)),
        ("Monte Carlo, piezo element", _simulate(_wired(rv.Piezo(1e-3, 1e-7, 1e5)), 1.0)),
        ("Monte Carlo, diode bridges",
         lambda: (_simulate(_wired(coil), 1.0)(),
                  _simulate(_wired(rv.BridgeCoil(0.1992, 0.48, v_diode=0.01, storage_capacitance=0.1, r_load=2.5)), 1.0)(),
                  _simulate(_wired(rv.BridgeCoil(0.1992, 0.48, v_diode=0.01, battery=0.02, inductance=1e-3)), 1.0)(),
                  _simulate(_wired(rv.BridgePiezo(1e-3, 1e-7, v_diode=0.01, battery=0.5)), 1.0)())),
        ("Monte Carlo on a record", _on_record),
        ("events", _event),
        ("record simulation (identify, validate, record)", _record_responses),
    ]  # fmt: skip


def register(sub) -> None:
    p = sub.add_parser(
        "compile",
        help=COMMAND_HELP["compile"],
        description="Compile (or load from the cache) every numerical kernel randvib's "
        "commands use, on tiny cases, so that no later command waits for the compiler. "
        "Compiled once per install; a second run loads them from the cache.",
    )
    p.set_defaults(handler=run)


def run(args) -> int:
    from numba.core import event

    compiled = []

    class Count(event.Listener):
        def on_start(self, data):
            compiled.append(1)

        def on_end(self, data):
            pass

    steps = warm_up_steps()
    started = time.perf_counter()
    print(f"compiling randvib's numerical kernels ({len(steps)} groups; once per install)")
    with event.install_listener("numba:compile", Count()):
        for i, (what, call) in enumerate(steps, 1):
            before, t0 = len(compiled), time.perf_counter()
            call()
            new = len(compiled) - before
            how = f"{new} compiled" if new else "loaded from the cache"
            print(f"  [{i}/{len(steps)}] {what}: {how}, {time.perf_counter() - t0:.1f} s")
            sys.stdout.flush()
    total = time.perf_counter() - started
    print(
        f"done in {total:.1f} s: {len(compiled)} function(s) compiled"
        if compiled
        else f"done in {total:.1f} s: every kernel was already compiled (loaded from the cache)"
    )
    return 0
