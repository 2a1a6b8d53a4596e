"""Coverage of the rare-event estimators' 95 % intervals on cases with exact answers (by hand).

    NUMBA_NUM_THREADS=1 python tests/calibration/rare_event_coverage.py [repetitions] [case ...]

For tests/test_reliability.py. Each case reruns ``randvib.estimate_first_passage``
over independent seeds and counts how often mean +- ci95 holds the exact value,
beside the exact binomial 99 % acceptance region of that count at 95 %, the
z-scores' mean and SD ((estimate - exact) / standard error), the mean reported
and the observed coefficient of variation, and the mean path-steps:

* ``linear-1e-6``, ``linear-1e-9`` - the linear device (m 0.0226 kg, c 0.2 Ns/m,
  k 57.4 N/m) under white noise S = 1, dt = 2e-3 s, T = 0.25 s, subset
  simulation at the default target c.o.v. 0.1 (1000 samples per level); exact:
  the scheme's Gaussian law (exceedance, crossing rate); the first passage
  against importance sampling at c.o.v. 0.005;
* ``duffing-1e-6`` - k3 = 5e5 N/m^3, dt = 2.5e-4 s, T = 0.1 s, subset
  simulation at 0.1; exact: the Gibbs density (the scheme's bias at this step
  is below 1 % of the exceedance);
* ``importance-1e-9`` - the linear device by importance sampling at c.o.v. 0.05;
* ``single-1e-3`` - the cheap test's configuration (one run of 200 samples per
  level, P(|z| > D) = 1e-3, T = 0.1 s).

The results of the last run are in rare_event_coverage_results.txt beside this file.
"""

import sys
import time
from pathlib import Path

import numpy as np
from scipy import special, stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import test_reliability as T  # noqa: E402

import randvib as rv  # noqa: E402
from randvib.analytic.gibbs_marginal import GibbsDisplacement  # noqa: E402
from randvib.montecarlo.path_simulator import HarvesterPaths  # noqa: E402


def linear(u, duration=0.25):
    d, exceedance, rate = T.exact_linear(u)
    sim = HarvesterPaths(T.LINEAR, 1.0, stroke=d, duration=duration, dt=T.DT)
    reference = rv.estimate_first_passage(
        sim, method="importance", target_cov=0.005, seed=10**6, progress=False
    ).probability_first_passage.mean
    return sim, {"exceedance": exceedance, "rate": rate, "first passage": reference}


def duffing():
    g = GibbsDisplacement(T.M, T.C_M + T.C_E, T.K, 5e5, 1.0)
    stroke = float(g.from_normal(-special.ndtri(0.5e-6)))
    sim = HarvesterPaths(T.DUFFING, 1.0, stroke=stroke, duration=0.1, dt=2.5e-4)
    return sim, {"exceedance": 1e-6, "rate": float(g.upcrossing_rate(stroke))}


CASES = {  # name: (simulator and references, estimator options)
    "linear-1e-6": (lambda: linear(4.9), {}),
    "linear-1e-9": (lambda: linear(6.1), {}),
    "duffing-1e-6": (duffing, {}),
    "importance-1e-9": (lambda: linear(6.1), {"method": "importance", "target_cov": 0.05}),
    "single-1e-3": (
        lambda: linear(3.29, duration=0.1),
        {"target_cov": 0.99, "samples_per_level": 200},
    ),
}


def campaign(name, repetitions):
    build, options = CASES[name]
    sim, references = build()
    hits = {k: 0 for k in references}
    z = {k: [] for k in references}
    estimates = {k: [] for k in references}
    covs, steps = [], []
    started = time.perf_counter()
    for seed in range(repetitions):
        r = rv.estimate_first_passage(sim, seed=seed, progress=False, **options)
        got = {"exceedance": r.stationary_exceedance, "rate": r.upcrossing_rate,
               "first passage": r.probability_first_passage}  # fmt: skip
        for k, ref in references.items():
            stat = got[k]
            hits[k] += abs(stat.mean - ref) <= stat.ci95
            z[k].append((stat.mean - ref) / stat.std_error)
            estimates[k].append(stat.mean / ref)
        covs.append(r.cov)
        steps.append(r.path_steps)
    lo, hi = stats.binom.ppf(0.005, repetitions, 0.95), stats.binom.ppf(0.995, repetitions, 0.95)
    print(f"{name}: {repetitions} estimates, {time.perf_counter() - started:.0f} s, mean "
          f"path-steps {np.mean(steps):.3g}, reported c.o.v. {np.mean(covs):.3f}; 99 % region "
          f"of the count at 95 %: [{lo:.0f}, {hi:.0f}]", flush=True)  # fmt: skip
    for k in references:
        values, ratio = np.array(z[k]), np.array(estimates[k])
        print(f"  {k:>14}: covered {hits[k]}/{repetitions} ({100 * hits[k] / repetitions:.1f} %), "
              f"z mean {values.mean():+.3f} SD {values.std(ddof=1):.3f}; estimate / exact "
              f"{ratio.mean():.4f}, observed c.o.v. {ratio.std(ddof=1) / ratio.mean():.3f}",
              flush=True)  # fmt: skip
    return hits


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    for name in sys.argv[2:] or list(CASES):
        campaign(name, n if not name.startswith("single") else 4 * n)
