"""Subset simulation's reported c.o.v. against its observed spread over seeds, long windows (by hand).

    NUMBA_NUM_THREADS=1 python tests/calibration/rare_event_long_window.py DEVICE STROKE RUNS WINDOW SAMPLES [BUDGET]

For tests/test_reliability.py and the study ``rare-events``. DEVICE is ``paper``,
``duffing`` (k3 = 5e5 N/m^3) or ``bistable`` (wells at +-2.5 mm), each the
study's device without friction, under white noise S = 1, Heun at dt = 1e-3 s
(the study's step), subset simulation at a target c.o.v. of 0.2 with SAMPLES
samples per level, window WINDOW (s), seeds 0 .. RUNS - 1, at most BUDGET
path-steps per estimate (default first_passage's). Printed: the
stationary exceedance over the exact Gibbs value (mean, observed and reported
c.o.v., how often mean +- ci95 holds it) and the first-passage probability's
observed and reported c.o.v., the mean number of independent runs and
path-steps per estimate. The last results are in
rare_event_long_window_results.txt beside this file.
"""

import sys

import numpy as np

import randvib as rv
from randvib.analytic.gibbs_marginal import GibbsDisplacement


def device(name: str) -> rv.Harvester:
    p = rv.preset("figure9")
    return {
        "paper": p.updated(friction=None),
        "duffing": p.updated(k3=5e5, friction=None),
        "bistable": p.updated(k=-p.k, k3=p.k / 0.0025**2, friction=None),
    }[name]


def main(name: str, stroke: float, runs: int, window: float, samples: int, budget=2e9) -> None:
    h = device(name)
    exact = float(GibbsDisplacement(h.m, h.c_m + h.c_e, h.k, h.k3, 1.0).exceedance(stroke))
    ratios, covs, covered, pf, pf_covs, cost, n_runs = [], [], 0, [], [], [], []
    for seed in range(runs):
        r = rv.first_passage(h, 1.0, stroke=stroke, duration=window, dt=1e-3, seed=seed,
                             target_cov=0.2, samples_per_level=samples, max_path_steps=budget,
                             progress=False)  # fmt: skip
        s = r.stationary_exceedance
        ratios.append(s.mean / exact)
        covs.append(s.std_error / s.mean)
        covered += abs(s.mean - exact) <= s.ci95
        pf.append(r.probability_first_passage.mean)
        pf_covs.append(r.cov)
        cost.append(r.path_steps)
        n_runs.append(r.details["runs"])
        print(f"  seed {seed}: exceedance / exact {ratios[-1]:.3f} (c.o.v. {covs[-1]:.3f}), P_T "
              f"{pf[-1]:.3g} (c.o.v. {r.cov:.3f}), {n_runs[-1]} runs", flush=True)  # fmt: skip
    ratios, pf = np.array(ratios), np.array(pf)
    print(f"{name} D = {stroke} m, T = {window} s, {samples} samples per level: exact exceedance "
          f"{exact:.3g}; {runs} runs: estimate / exact {ratios.mean():.3f}, observed c.o.v. "
          f"{ratios.std(ddof=1) / ratios.mean():.3f}, reported {np.mean(covs):.3f}, covered "
          f"{covered}/{runs}; P_T {pf.mean():.3g}, observed c.o.v. {pf.std(ddof=1) / pf.mean():.3f}, "
          f"reported {np.mean(pf_covs):.3f}; {np.mean(n_runs):.1f} runs, {np.mean(cost):.3g} "
          f"path-steps per estimate")  # fmt: skip


if __name__ == "__main__":
    a = sys.argv[1:]
    main(a[0], float(a[1]), int(a[2]), float(a[3]), int(a[4]), *map(float, a[5:6]))
