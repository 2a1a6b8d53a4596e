"""Engine speed and memory, as ratios to baselines measured in the same run.

Run:  python -m pytest benchmarks/bench_engine.py --benchmark-only -s

Device: figure9 preset with k3 = 5e5 N/m^3 (Duffing + Coulomb), dt = 1e-4 s,
10^4 paths, all cores. Baselines:
* the random-number floor: numpy's default Generator drawing the same number
  of standard normals, one generator per core, in threads;
* sdeint.itoEuler on one path;
* a plain vectorised numpy Euler-Maruyama loop over all paths.
* the same engine under band-pass input: the kernel then
  integrates the shaping filter's 2 states with the device; the target is at
  most 1.5x the white-noise kernel per path-step (``filter_over_white``).
* the same engine with a coil inductance: the kernel integrates the
  circuit's current as an auxiliary state (the same compiled block as the
  filter's), reported as ``circuit_over_white`` per path-step.
* the same engine under band-limited input (4-20 Hz), synthesised per path
  and fed to the kernel as given increments (``synthesised_over_white``, the
  whole simulation), and the synthesis alone (``synthesis_over_white``: the
  per-path spectral synthesis of the increments, per path-step, against the
  white-noise kernel).
* the same engine (Heun) with tones on the white noise, as forcing inside the
  kernel: one and four tones (``tones_over_white``, per path-step, and
  ``ns_per_tone``, the added cost of one tone per path-step, whose claim is
  one cosine), and a shock train (``shocks_over_white``: its step integrals
  drawn per path, then one more addition per step).
A module fixture prints ns per path-step and the ratios, and writes
.benchmarks/engine_ratios.json. Set RANDVIB_BENCH_FULL_MEMORY=1 to also run the
10^5 paths x 10^6 steps memory case (about 10 minutes on 2 cores).
"""

import os
import subprocess
import sys
import textwrap
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np
import pytest
import sdeint
from conftest import TIMINGS, record, write_report

import randvib as rv
from randvib.models.excitation import BandLimited, BandPass
from randvib.montecarlo.driven import SynthesisedInput
from randvib.montecarlo.simulation import simulate

DEVICE = rv.preset("figure9").updated(k3=5e5)
PSD, DT, N_PATHS, N_STEPS = 1.0, 1e-4, 10_000, 1_000
WORK = N_PATHS * N_STEPS
CORES = numba.config.NUMBA_NUM_THREADS
#: Band-pass input centred at the device's linear resonance (8 Hz).
BAND_PASS = BandPass(PSD, 8.0, 0.2)
#: The same device with the paper's coil, load and a 1 mH inductance (L/R = 0.7 ms).
COIL = rv.Harvester.with_coupling(
    DEVICE.m,
    DEVICE.c_m,
    DEVICE.k,
    rv.Inductive(alpha=0.1992, r_load=1.0, r_coil=0.48, inductance=1e-3),
    k3=DEVICE.k3,
    friction=DEVICE.friction,
)

#: The paper's shaker band, synthesised per path.
BAND_LIMITED = BandLimited(PSD, 4.0, 20.0)

#: Tones and shocks on the white floor, as the kernel's forcing.
FORCING = {
    "1-tone": rv.White(PSD) + rv.Tone(8.0, 1.0),
    "4-tones": rv.White(PSD)
    + rv.Tone(8.0, 1.0)
    + rv.Tone(16.0, 0.5)
    + rv.Tone(24.0, 0.3)
    + rv.Tone(50.0, 0.2),
    "shocks": rv.White(PSD) + rv.ShockTrain(2.0, 20.0, 0.01),
}


def _run(method, excitation=PSD, device=DEVICE):
    return simulate(
        device,
        excitation,
        t_end=N_STEPS * DT,
        dt=DT,
        n_paths=N_PATHS,
        scheme=method,
        seed=1,
        check_step=False,
        progress=False,
    )


def test_random_number_floor(benchmark):
    generators = [np.random.default_rng(i) for i in range(CORES)]
    out = np.empty((CORES, WORK // CORES))

    def draw():
        with ThreadPoolExecutor(CORES) as pool:
            list(pool.map(lambda i: generators[i].standard_normal(out=out[i]), range(CORES)))

    benchmark.pedantic(draw, rounds=5, warmup_rounds=1)
    record(benchmark, "floor", WORK)


@pytest.mark.parametrize("method", ["euler-maruyama", "heun"])
def test_engine(benchmark, method):
    _run(method)  # compile / load cache
    benchmark.pedantic(_run, args=(method,), rounds=5, warmup_rounds=1)
    record(benchmark, method, WORK)


@pytest.mark.parametrize("method", ["euler-maruyama", "heun"])
def test_engine_filter_states(benchmark, method):
    """The same run under band-pass input: 2 filter states integrated with the device."""
    _run(method, BAND_PASS)  # compile / load cache
    benchmark.pedantic(_run, args=(method, BAND_PASS), rounds=5, warmup_rounds=1)
    record(benchmark, f"{method}-band-pass", WORK)


@pytest.mark.parametrize("method", ["euler-maruyama", "heun"])
def test_engine_circuit_state(benchmark, method):
    """The same run with a coil inductance: the current integrated with the device."""
    _run(method, PSD, COIL)  # compile / load cache
    benchmark.pedantic(_run, args=(method, PSD, COIL), rounds=5, warmup_rounds=1)
    record(benchmark, f"{method}-circuit", WORK)


@pytest.mark.parametrize("method", ["euler-maruyama", "heun"])
def test_engine_synthesised_input(benchmark, method):
    """The same run under band-limited input: synthesis per path + the given-increments kernel."""
    _run(method, BAND_LIMITED)  # compile / load cache
    benchmark.pedantic(_run, args=(method, BAND_LIMITED), rounds=5, warmup_rounds=1)
    record(benchmark, f"{method}-band-limited", WORK)


@pytest.mark.parametrize("case", list(FORCING))
def test_engine_forcing(benchmark, case):
    """Heun on white noise with tones or shocks added as forcing in the kernel."""
    _run("heun", FORCING[case])  # compile / load cache
    benchmark.pedantic(_run, args=("heun", FORCING[case]), rounds=5, warmup_rounds=1)
    record(benchmark, f"heun-{case}", WORK)


def _forcing_ratios():
    """Tones and shocks over the white Heun kernel, and one tone's cost (ns per path-step)."""
    if "heun" not in TIMINGS:
        return {}
    out = {
        f"{case}_over_white": TIMINGS[f"heun-{case}"] / TIMINGS["heun"]
        for case in FORCING
        if f"heun-{case}" in TIMINGS
    }
    if "heun-4-tones" in TIMINGS:
        out["ns_per_tone"] = (TIMINGS["heun-4-tones"] - TIMINGS["heun"]) / 4 * 1e9
    return out


def test_synthesis_alone(benchmark):
    """The increments of all paths (one generator per path, FFT), without the kernel."""
    source = SynthesisedInput(BAND_LIMITED, N_STEPS, DT, 1)
    benchmark.pedantic(source, args=(0, N_PATHS), rounds=5, warmup_rounds=1)
    record(benchmark, "synthesis", WORK)


def _over_white(suffix):
    """``{scheme}-{suffix}`` over the white-noise kernel, per path-step, for the schemes timed."""
    return {
        m: TIMINGS[f"{m}-{suffix}"] / TIMINGS[m]
        for m in ("euler-maruyama", "heun")
        if m in TIMINGS and f"{m}-{suffix}" in TIMINGS
    }


def _filter_over_white():
    """Filter-state kernel over white-noise kernel, per path-step, for the schemes timed."""
    return _over_white("band-pass")


def _synthesis_ratios():
    """Synthesised input (whole run, and the synthesis alone) over the white kernel."""
    out = {"synthesised_over_white": _over_white("band-limited")}
    if "synthesis" in TIMINGS:
        out["synthesis_over_white"] = {
            m: TIMINGS["synthesis"] / TIMINGS[m] for m in ("euler-maruyama", "heun") if m in TIMINGS
        }
    return out


def test_sdeint_one_path(benchmark):
    m, c, k, k3, fc = DEVICE.m, DEVICE.c, DEVICE.k, DEVICE.k3, DEVICE.friction.fc
    amp = np.sqrt(PSD / 2)
    n = 2_000
    tspan = np.linspace(0, n * DT, n + 1)
    dw = np.random.default_rng(0).normal(0, np.sqrt(DT), (n, 1))

    def f(y, t):
        return np.array([y[1], -(c * y[1] + k * y[0] + k3 * y[0] ** 3 + fc * np.sign(y[1])) / m])

    def g(y, t):
        return np.array([[0.0], [amp]])

    benchmark.pedantic(lambda: sdeint.itoEuler(f, g, np.zeros(2), tspan, dW=dw), rounds=3)
    record(benchmark, "sdeint", n)


def test_numpy_loop(benchmark):
    m, c, k, k3, fc = DEVICE.m, DEVICE.c, DEVICE.k, DEVICE.k3, DEVICE.friction.fc
    amp = np.sqrt(PSD / 2) * np.sqrt(DT)
    n_steps = 200

    def loop():
        rng = np.random.default_rng(0)
        z = np.zeros(N_PATHS)
        v = np.zeros(N_PATHS)
        acc = np.zeros(N_PATHS)
        for _ in range(n_steps):
            a = -(c * v + k * z + k3 * z**3 + fc * np.sign(v)) / m
            z = z + v * DT
            v = v + a * DT + amp * rng.standard_normal(N_PATHS)
            acc += v * v
        return acc

    benchmark.pedantic(loop, rounds=3, warmup_rounds=1)
    record(benchmark, "numpy", N_PATHS * n_steps)


MEMORY_SCRIPT = textwrap.dedent(
    """
    import sys
    import randvib as rv
    from randvib.montecarlo.simulation import simulate

    def status(field):  # kB -> MB, from /proc/self/status
        for line in open("/proc/self/status"):
            if line.startswith(field):
                return int(line.split()[1]) / 1024

    device = rv.preset("figure9").updated(k3=5e5)
    n_paths, n_steps = int(sys.argv[1]), int(sys.argv[2])
    simulate(device, 1.0, t_end=0.01, dt=1e-4, n_paths=16, progress=False)  # compile / load
    baseline = status("VmRSS")
    with open("/proc/self/clear_refs", "w") as f:  # reset the peak (VmHWM) to the current RSS
        f.write("5")
    simulate(device, 1.0, t_end=n_steps * 1e-4, dt=1e-4, n_paths=n_paths, progress=False)
    print(baseline, status("VmHWM"))
    """
)


def _peak_memory(n_paths, n_steps):
    out = subprocess.run(
        [sys.executable, "-c", MEMORY_SCRIPT, str(n_paths), str(n_steps)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    return float(out[0]), float(out[1])


@pytest.fixture(scope="module", autouse=True)
def ratios_and_memory():
    """After the module: print and store ns per path-step, ratios and peak memory."""
    yield
    if _filter_over_white():
        print(f"\nfilter_over_white (target <= 1.5): {_filter_over_white()}")
    if _over_white("circuit"):
        print(f"\ncircuit_over_white: {_over_white('circuit')}")
    if any(_synthesis_ratios().values()):
        print(f"\n{_synthesis_ratios()}")
    if _forcing_ratios():
        print(f"\nforcing (heun): {_forcing_ratios()}")
    needed = {"floor", "euler-maruyama", "heun", "sdeint", "numpy"}
    if not needed <= TIMINGS.keys():
        return  # a subset was run: no ratios
    ns = {name: TIMINGS[name] * 1e9 for name in needed}
    cases = [(100_000, 1_000), (100_000, 10_000)]
    if os.environ.get("RANDVIB_BENCH_FULL_MEMORY"):
        cases.append((100_000, 1_000_000))
    memory = {f"{p}x{s}": _peak_memory(p, s) for p, s in cases}
    report = {
        "cores": CORES,
        "ns_per_path_step": ns,
        "euler_maruyama_over_floor": ns["euler-maruyama"] / ns["floor"],
        "heun_over_floor": ns["heun"] / ns["floor"],
        "sdeint_over_euler_maruyama": ns["sdeint"] / ns["euler-maruyama"],
        "numpy_loop_over_euler_maruyama": ns["numpy"] / ns["euler-maruyama"],
        "filter_over_white": _filter_over_white(),
        "circuit_over_white": _over_white("circuit"),
        **_synthesis_ratios(),
        "forcing_over_white_heun": _forcing_ratios(),
        # (RSS before the run, peak RSS during it) in MB; the difference is
        # what the simulation itself needs
        "rss_mb_baseline_and_peak": memory,
    }
    path = write_report("engine_ratios", report)
    print("\n" + "\n".join(f"{k}: {v}" for k, v in report.items()) + f"\n(written to {path})")
