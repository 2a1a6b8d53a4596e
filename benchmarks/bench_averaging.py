"""Speed of the fast power predictors, with ratios to linearisation.

Run:  python -m pytest benchmarks/bench_averaging.py --benchmark-only -s

Targets, for averaging and for the fast FPK grids (method "fpk-fast"): one
parameter point in under 10 ms, a 100-point sweep (one broadcast call over
Fc) in under 1 s. Linearisation (Eq. 32, closed form) is timed in the same
session; a module fixture prints ms per call and the ratios, and writes
.benchmarks/averaging_ratios.json. The FPK reference is timed once per point
for scale (it is not meant for sweeps).
"""

import numpy as np
import pytest
from conftest import TIMINGS, record, write_report

import randvib as rv

DEVICE = rv.preset("figure9").updated(k3=5e5)
PSD = 1.0
SWEEP = DEVICE.updated(fc=np.linspace(0.0, 0.06, 100))
#: The methods held to the speed targets above.
FAST = ("averaging", "fpk-fast")


@pytest.fixture(scope="module", autouse=True)
def report():
    yield
    if not TIMINGS:
        return
    payload = {name: TIMINGS[name] * 1e3 for name in TIMINGS if name.startswith("avg:")}
    for case in ("point", "sweep100"):
        b = TIMINGS.get(f"avg:linearisation-{case}")
        for method in FAST:
            a = TIMINGS.get(f"avg:{method}-{case}")
            if a and b:
                payload[f"ratio_{method}_to_linearisation_{case}"] = a / b
    path = write_report("averaging_ratios", payload)
    print("\naveraging benchmark (ms per call, ratios):")
    for key, value in payload.items():
        print(f"  {key:45s} {value:10.4g}")
    print(f"written to {path}")


@pytest.mark.parametrize("method", ["linearisation", *FAST])
def test_one_point(benchmark, method):
    benchmark(rv.expected_power, DEVICE, PSD, method)
    per_call = record(benchmark, f"avg:{method}-point", 1)
    if method in FAST:
        assert per_call < 10e-3


@pytest.mark.parametrize("method", ["linearisation", *FAST])
def test_sweep_of_100_points(benchmark, method):
    if method == "fpk-fast":  # about 0.3 s a call: a few rounds suffice
        power = benchmark.pedantic(rv.expected_power, (SWEEP, PSD, method), rounds=5)
    else:
        power = benchmark(rv.expected_power, SWEEP, PSD, method)
    assert power.shape == (100,)
    per_call = record(benchmark, f"avg:{method}-sweep100", 1)
    if method in FAST:
        assert per_call < 1.0


def test_fpk_reference_point(benchmark):
    benchmark.pedantic(rv.expected_power, (DEVICE, PSD, "fpk"), rounds=3, warmup_rounds=1)
    record(benchmark, "avg:fpk-point", 1)
