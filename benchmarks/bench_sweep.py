"""Sweep benchmarks: variance reduction and the full figure9 study.

Run:  python -m pytest benchmarks/bench_sweep.py --benchmark-only -s

* Variance-reduction factors at Figure 9 points: the variance of the plain
  path-mean estimator of E[P_e] over that of the control-variate estimator
  (same paths), and for the interaction contrast the variance of an unpaired
  difference over that of the paired common-random-number contrast.
* The full figure9 study (3 S x 2 k3 x 13 Fc, 0.5 % target) timed end to end on
  all cores, with the precision it reached. Results in .benchmarks/sweep.json.
"""

import tempfile

import numpy as np
import pandas as pd
from conftest import write_report

import randvib as rv
from randvib.montecarlo.simulation import simulate
from randvib.statistics import estimate

BASE = rv.preset("figure9")
KW = dict(t_end=2.5, dt=1e-4, burn_in=0.5, seed=3, companion=True, progress=False)
REPORT: dict = {}


def test_variance_reduction(benchmark):
    rows = []

    def measure():
        rows.clear()
        for psd in (1.0, 0.1):
            for fc_scale in (0.5, 2.0):
                fc = fc_scale * 0.0298 * np.sqrt(psd)  # 0.5x and 2x the half-power level
                pts = {}
                for f in (0.0, fc):
                    for k3 in (0.0, 5e5):
                        pts[(f, k3)] = simulate(BASE.updated(fc=f, k3=k3), psd, n_paths=256, **KW)
                r = pts[(fc, 5e5)]
                y = r.harvester.c_e * r.per_path[:, 0]
                plain, cv = estimate(y), estimate(y, r.controls())

                def power(key, pts=pts):
                    return pts[key].harvester.c_e * pts[key].per_path[:, 0]

                paired = estimate(
                    power((fc, 5e5)) - power((fc, 0.0)) - power((0.0, 5e5)) + power((0.0, 0.0))
                )
                unpaired_var = sum(estimate(power(k)).std_error ** 2 for k in pts)
                rows.append(
                    {
                        "psd": psd,
                        "fc": fc,
                        "cv_factor": (plain.std_error / cv.std_error) ** 2,
                        "crn_factor": unpaired_var / paired.std_error**2,
                    }
                )

    benchmark.pedantic(measure, rounds=1)
    table = pd.DataFrame(rows)
    REPORT["variance_reduction"] = table.to_dict("records")
    print("\n" + table.to_string())


def test_figure9_full_study(benchmark):
    from randvib.studies import load

    run_study = load("figure9").run_study

    def run():
        with tempfile.TemporaryDirectory() as tmp:
            run_study(tmp + "/f9", quick=False, progress=False)
            return pd.read_csv(tmp + "/f9/results.csv")

    table = benchmark.pedantic(run, rounds=1)
    rel = table.power_electrical_ci95 / table.power_electrical
    REPORT["figure9"] = {
        "seconds": benchmark.stats.stats.min,
        "points": len(table),
        "max_relative_ci95": float(rel.max()),
        "paths": int(table.n_paths.sum()),
    }
    path = write_report("sweep", REPORT)
    print(f"\nfigure9 full: {REPORT['figure9']} (written to {path})")
