"""The assembly kernel against the single-mass kernel, per path-step, in one run.

Run:  python -m pytest benchmarks/bench_assembly.py --benchmark-only -s

The single mass is the engine benchmark's device: the figure9 preset with
k3 = 5e5 N/m^3 (Duffing + Coulomb, c_e), white noise, dt = 1e-4 s, 4000
paths x 1000 steps, all cores, through the single-mass kernel. Timed against
it, through the assembly kernel:

* ``two_dof``: that harvester (its k3 spring and Coulomb friction as one
  element, its c_e as a transducer, both on (1, host)) on a 0.5 kg host mode
  at 14 Hz; the bar is a ratio <= 2 per path-step (issue 31);
* ``five_dof``: four such harvesters, detuned by +-5 % and +-10 %, on the same
  host; the bar is <= 4;
* ``one_dof``: the same harvester as a one-DOF assembly (what the generic
  kernel costs where the single-mass kernel would do).

Each ratio is the best of 5 runs of each, timed in alternation with the
single mass so that both see the same load (as benchmarks/bench_rectifier.py).
The plain vectorised numpy Euler-Maruyama loop of benchmarks/bench_engine.py
is timed too (``numpy_over_single_mass``, Euler-Maruyama, as there), so the
single-mass kernel's speed is reported beside the ratios. A module fixture
prints everything and writes .benchmarks/assembly_ratios.json.
"""

import time

import numpy as np
import pytest
from conftest import TIMINGS, record, write_report

import randvib as rv
from randvib.montecarlo.simulation import simulate

DEVICE = rv.preset("figure9").updated(k3=5e5)
PSD, DT, N_PATHS, N_STEPS = 1.0, 1e-4, 4_000, 1_000
WORK = N_PATHS * N_STEPS
HOST_MASS, HOST_FREQUENCY, HOST_ZETA = 0.5, 14.0, 0.01


def _on_host(tunings) -> rv.Assembly:
    """The harvester (stiffness scaled by each tuning^2) on DOFs 1.. above a host mode (DOF 0)."""
    n = len(tunings) + 1
    k_host = HOST_MASS * (2 * np.pi * HOST_FREQUENCY) ** 2
    c_host = 2 * HOST_ZETA * np.sqrt(k_host * HOST_MASS)
    mass, stiffness, damping = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    mass[0, 0], stiffness[0, 0], damping[0, 0] = HOST_MASS, k_host, c_host
    elements, transducers = [], []
    for q, tuning in enumerate(tunings, start=1):
        mass[q, q] = DEVICE.m
        for matrix, value in ((stiffness, DEVICE.k * tuning**2), (damping, DEVICE.c_m)):
            matrix[np.ix_([0, q], [0, q])] += value * np.array([[1.0, -1.0], [-1.0, 1.0]])
        spring = rv.Spring(k3=DEVICE.k3)
        elements.append(rv.Element((q, 0), spring, DEVICE.friction))
        transducers.append(rv.Transducer((q, 0), rv.ElectricalDamper(c_e=DEVICE.c_e)))
    return rv.Assembly(mass, stiffness, damping, None, elements, transducers)


DEVICES = {
    "single_mass": DEVICE,
    "one_dof": rv.Assembly.from_harvester(DEVICE),
    "two_dof": _on_host([1.0]),
    "five_dof": _on_host([0.9, 0.95, 1.05, 1.1]),
}


def _run(name, method="heun"):
    return simulate(
        DEVICES[name], PSD, t_end=N_STEPS * DT, dt=DT, n_paths=N_PATHS, scheme=method, seed=1,
        check_step=False, progress=False, initial="rest",
    )  # fmt: skip


def _interleaved(name, method, rounds=5):
    """Best seconds of the single mass and of ``name``, timed in alternation."""
    best = {"single_mass": float("inf"), name: float("inf")}
    for _ in range(rounds):
        for which in best:
            start = time.perf_counter()
            _run(which, method)
            best[which] = min(best[which], time.perf_counter() - start)
    return best["single_mass"], best[name]


RATIOS: dict[str, dict[str, float]] = {}


@pytest.mark.parametrize("method", ["euler-maruyama", "heun"])
@pytest.mark.parametrize("name", list(DEVICES))
def test_kernel(benchmark, name, method):
    _run(name, method)  # compile / load cache
    benchmark.pedantic(_run, args=(name, method), rounds=3, warmup_rounds=1)
    record(benchmark, f"assembly-{name}-{method}", WORK)
    if name != "single_mass":
        single, assembly = _interleaved(name, method)
        RATIOS.setdefault(f"{name}_over_single_mass", {})[method] = assembly / single


def test_numpy_loop(benchmark):
    """benchmarks/bench_engine.py's plain numpy Euler-Maruyama loop over all paths."""
    m, c, k, k3, fc = DEVICE.m, DEVICE.c, DEVICE.k, DEVICE.k3, DEVICE.friction.fc
    amp = np.sqrt(PSD / 2) * np.sqrt(DT)
    n_steps = 200

    def loop():
        rng = np.random.default_rng(0)
        z, v, acc = np.zeros(N_PATHS), np.zeros(N_PATHS), np.zeros(N_PATHS)
        for _ in range(n_steps):
            a = -(c * v + k * z + k3 * z**3 + fc * np.sign(v)) / m
            z = z + v * DT
            v = v + a * DT + amp * rng.standard_normal(N_PATHS)
            acc += v * v
        return acc

    benchmark.pedantic(loop, rounds=3, warmup_rounds=1)
    record(benchmark, "assembly-numpy", N_PATHS * n_steps)


@pytest.fixture(scope="module", autouse=True)
def ratios():
    """After the module: print and store ns per path-step and the ratios to the single mass."""
    yield
    if not RATIOS:
        return  # a subset was run: no ratios
    report = {
        "ns_per_path_step": {
            name.removeprefix("assembly-"): 1e9 * seconds
            for name, seconds in TIMINGS.items()
            if name.startswith("assembly-")
        },
        "bars": {"two_dof_over_single_mass": 2.0, "five_dof_over_single_mass": 4.0},
        **RATIOS,
    }
    single = TIMINGS.get("assembly-single_mass-euler-maruyama")
    if single and "assembly-numpy" in TIMINGS:
        report["numpy_over_single_mass"] = TIMINGS["assembly-numpy"] / single
    print(f"\n{report}")
    write_report("assembly_ratios", report)
