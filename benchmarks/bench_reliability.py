"""Subset simulation against crude Monte Carlo, in path-steps, at a first passage near 1e-6.

Run:  python -m pytest benchmarks/bench_reliability.py --benchmark-only -s

Bar (issue 33): P(|z| reaches D within T) near 1e-6 at a 10 % coefficient of
variation with at most 1 % of the path-steps crude Monte Carlo needs for the
same coefficient of variation, (1 - p) / (p cov^2) paths of the same length.
Devices, white noise S = 1 (m/s^2)^2/Hz, T = 0.5 s, Heun at the default step
(``randvib.montecarlo.path_simulator.default_step`` at a 2 cm stroke):

* ``paper`` - the paper's device with friction (preset ``figure9``: Coulomb
  friction, Duffing spring): a linearised start and ten decay times of burn-in,
  counted in both costs;
* ``duffing`` - the same without friction (k3 = 5e5 N/m^3): the exact Gibbs start.

The stroke of each is read off a pilot run's intermediate levels (the level
whose probability is p0^6 = 1e-6); the estimate at that stroke is then run
once at ``target_cov`` 0.1 (seeded, so the path-steps are reproducible). A
module fixture prints the ratios and writes .benchmarks/reliability_ratios.json.
"""

import numpy as np
import pytest
from conftest import write_report

import randvib as rv
from randvib.montecarlo.path_simulator import default_step
from randvib.montecarlo.subset_simulation import subset_simulation

DEVICES = {"paper": rv.preset("figure9"), "duffing": rv.preset("figure9").updated(friction=None, k3=5e5)}  # fmt: skip
DURATION, TARGET = 0.5, 0.1
RESULTS: dict = {}


def stroke_near_one_in_a_million(device, dt) -> float:
    """A pilot's sixth intermediate level (P(peak > b_6) ~ 0.1^6), from a stroke far out."""
    far = 0.05
    sim = rv.HarvesterPaths(device, 1.0, stroke=far, duration=DURATION, dt=dt)
    pilot = subset_simulation(sim, 500, np.random.default_rng(99), max_levels=7)
    return pilot.levels[5].threshold * far


@pytest.mark.parametrize("name", list(DEVICES))
def test_subset_against_crude_in_path_steps(benchmark, name):
    device = DEVICES[name]
    dt = default_step(device, 1.0, "heun", 0.02)  # the default at a stroke of about 2 cm
    stroke = stroke_near_one_in_a_million(device, dt)

    def estimate():
        return rv.first_passage(device, 1.0, stroke=stroke, duration=DURATION, dt=dt,
                                target_cov=TARGET, seed=1, progress=False)  # fmt: skip

    result = benchmark.pedantic(estimate, rounds=1, iterations=1)
    ratio = result.path_steps / result.crude_path_steps
    RESULTS[name] = {
        "stroke_m": stroke,
        "probability_first_passage": result.probability_first_passage.mean,
        "cov": result.cov,
        "path_steps": result.path_steps,
        "crude_path_steps": result.crude_path_steps,
        "ratio": ratio,
        "dt": result.dt,
        "burn_in": result.burn_in,
        "runs": result.details["runs"],
    }
    benchmark.extra_info.update(RESULTS[name])
    assert result.cov <= TARGET
    assert ratio <= 0.01, RESULTS[name]


@pytest.fixture(scope="module", autouse=True)
def ratios():
    yield
    if RESULTS:
        print(f"\n{RESULTS}")
        write_report("reliability_ratios", RESULTS)
