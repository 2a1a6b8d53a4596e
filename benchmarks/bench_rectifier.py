"""The bridge's kernel against the resistive kernel, per path-step, in one run.

Run:  python -m pytest benchmarks/bench_rectifier.py --benchmark-only -s

Device: figure9 preset with k3 = 5e5 N/m^3 (Duffing + Coulomb), white noise,
dt = 1e-4 s, 4000 paths x 1000 steps, Heun, all cores. Baseline: the same
device with the paper's coil into a resistive load (a viscous c_e, the
kernel's plain loop). Timed against it: the coil into a bridge and a battery
(no state), into a bridge and a storage capacitor (V_C), and the piezo into
a bridge and a storage capacitor (V_p, V_C). The bar is a ratio <= 2
(``bridge_over_resistive``: the best of 9 runs of each, timed in alternation
so that both see the same load); a module fixture prints the ratios and writes
.benchmarks/rectifier_ratios.json.

The piezo's bridge is also timed against the same piezo on a resistive load
(``piezo_bridge_over_piezo_resistive``): that circuit integrates V_p too, so
this ratio is what the bridge itself costs for that transducer, where the
first ratio also counts the piezo's state against the coil's algebraic current.
"""

import time

import pytest
from conftest import TIMINGS, record, write_report

import randvib as rv
from randvib.montecarlo.simulation import simulate

BASE = rv.preset("figure9").updated(k3=5e5)
PSD, DT, N_PATHS, N_STEPS = 1.0, 1e-4, 4_000, 1_000
WORK = N_PATHS * N_STEPS
ALPHA, R_COIL = 0.1992, 0.48


def _device(coupling):
    return rv.Harvester.with_coupling(
        BASE.m, BASE.c_m, BASE.k, coupling, k3=BASE.k3, friction=BASE.friction
    )


DEVICES = {
    "resistive": _device(rv.Resistive(ALPHA, 1.0, R_COIL)),
    "coil-battery": _device(rv.BridgeCoil(ALPHA, R_COIL, v_diode=0.01, battery=0.03)),
    "coil-capacitor": _device(rv.BridgeCoil(ALPHA, R_COIL, 0.01, None, 1e-2, 10.0)),
    "piezo-capacitor": _device(rv.BridgePiezo(1e-3, 1e-7, 0.1, None, 1e-6, 1e6)),
    "piezo-resistive": _device(rv.Piezo(1e-3, 1e-7, 1e6)),
}


def _run(name):
    return simulate(
        DEVICES[name], PSD, t_end=N_STEPS * DT, dt=DT, n_paths=N_PATHS, scheme="heun",
        seed=1, check_step=False, progress=False,
    )  # fmt: skip


def _interleaved(name, rounds=9, baseline="resistive"):
    """Best seconds of ``baseline`` and of ``name``, timed in alternation.

    The machine is shared: alternating the two runs exposes both to the same
    load, so their ratio is steadier than that of two separate benchmarks.
    """
    best = {baseline: float("inf"), name: float("inf")}
    for _ in range(rounds):
        for which in best:
            start = time.perf_counter()
            _run(which)
            best[which] = min(best[which], time.perf_counter() - start)
    return best[baseline], best[name]


@pytest.mark.parametrize("name", list(DEVICES))
def test_kernel(benchmark, name):
    _run(name)  # compile / load cache
    benchmark.pedantic(_run, args=(name,), rounds=5, warmup_rounds=1)
    record(benchmark, f"rectifier-{name}", WORK)
    if name not in ("resistive", "piezo-resistive"):
        resistive, bridge = _interleaved(name)
        RATIOS[name] = bridge / resistive
    if name == "piezo-capacitor":
        piezo, bridge = _interleaved(name, baseline="piezo-resistive")
        SAME_TRANSDUCER[name] = bridge / piezo


RATIOS: dict[str, float] = {}
SAME_TRANSDUCER: dict[str, float] = {}


@pytest.fixture(scope="module", autouse=True)
def ratios():
    """After the module: print and store ns per path-step and the ratios to the resistive."""
    yield
    names = [n for n in DEVICES if f"rectifier-{n}" in TIMINGS]
    if not RATIOS:
        return  # a subset was run: no ratios
    report = {
        "ns_per_path_step": {n: 1e9 * TIMINGS[f"rectifier-{n}"] for n in names},
        "bridge_over_resistive": RATIOS,
        "piezo_bridge_over_piezo_resistive": SAME_TRANSDUCER,
    }
    print(f"\n{report}")
    write_report("rectifier_ratios", report)
