"""Speed of a three-parameter design with Monte Carlo confirmation, as a ratio to its analytic search.

Run:  python -m pytest benchmarks/bench_design.py --benchmark-only -s

The design chooses k, k3 and c_e of the paper's magnet mass under a band-pass
input (8 Hz, zeta 0.1) with P(|z| > 3 mm) <= 1 %, and confirms the optimum and
two runners-up by Monte Carlo to 1 % (95 % half-width of the power) on common
random numbers. Target: under a minute on 2 cores. The analytic search alone
is timed in the same session; the fixture prints both and their ratio and
writes .benchmarks/design_ratios.json.
"""

import pytest
from conftest import TIMINGS, record, write_report

import randvib as rv
from randvib.montecarlo.sweep import SweepSettings

FIXED = rv.Harvester(m=0.0226, c_m=0.049, c_e=0.1, k=57.4, stroke=0.003)
INPUT = rv.BandPass(1.0, 8.0, 0.1)
VARY = {"k": (20.0, 200.0), "k3": (0.0, 1e6), "c_e": (0.01, 1.0)}
#: Long paths: the burn-in is paid once per path, and the precision follows the
#: total simulated time.
SETTINGS = SweepSettings(dt=1e-4, window=8.0, burn_in=0.5, target_rel_ci=0.01, min_paths=16,
                         max_paths=4096, batch_paths=16, control_variates=False)  # fmt: skip


@pytest.fixture(scope="module", autouse=True)
def report():
    yield
    a, b = TIMINGS.get("design:monte-carlo"), TIMINGS.get("design:analytic")
    if not (a and b):
        return
    payload = {"analytic_s": b, "with_monte_carlo_s": a, "ratio_monte_carlo_to_analytic": a / b}
    path = write_report("design_ratios", payload)
    print("\ndesign benchmark (s, ratio):")
    for key, value in payload.items():
        print(f"  {key:35s} {value:10.4g}")
    print(f"written to {path}")


def test_analytic_search(benchmark):
    result = benchmark.pedantic(rv.design, (FIXED, INPUT, VARY), {"monte_carlo": False}, rounds=3)
    assert set(result.optimum) == set(VARY)
    record(benchmark, "design:analytic", 1)


def test_design_with_monte_carlo(benchmark):
    result = benchmark.pedantic(rv.design, (FIXED, INPUT, VARY), {"settings": SETTINGS}, rounds=1)
    print(f"\n  optimum {result.optimum}, power {result.power_monte_carlo} W, "
          f"predicted {result.power_predicted:.5g} W, exceedance "
          f"{result.stroke_exceedance_monte_carlo}, cases {result.monte_carlo_cases}, "
          f"refined {result.refined}")  # fmt: skip
    assert result.power_monte_carlo.relative_ci95 <= 0.01
    record(benchmark, "design:monte-carlo", 1)
