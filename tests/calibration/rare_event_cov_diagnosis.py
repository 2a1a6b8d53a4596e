"""Why subset simulation's c.o.v. is too small in long windows: one run's spread against its own c.o.v. (by hand).

    NUMBA_NUM_THREADS=1 python tests/calibration/rare_event_cov_diagnosis.py DEVICE STROKE RUNS WINDOW SAMPLES

For tests/calibration/rare_event_long_window.py (devices and settings are
its own). RUNS independent single runs of subset simulation
(:func:`randvib.montecarlo.subset_simulation.subset_simulation`, SAMPLES per
level, no pilot, no pooling) of the same device, seeds 0 .. RUNS - 1.
Printed: the observed c.o.v. of the runs' first-passage estimates against
Au & Beck's (levels uncorrelated: sqrt(sum delta_j^2)) and against the
fully correlated bound sum delta_j (Au & Beck 2001, Eq. 29's upper end);
the mean gamma of each level (the chains' correlation Au & Beck count) and
the acceptance. An observed c.o.v. between the two says the levels are
correlated (the seeds of a level descend from few paths of the level
below); one beyond the upper bound says that even each level's own variance
is underestimated (the chains do not mix between the failure domain's modes).
The results are kept in rare_event_cov_diagnosis_results.txt beside this file.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from rare_event_long_window import device  # noqa: E402

from randvib.montecarlo.path_simulator import HarvesterPaths  # noqa: E402
from randvib.montecarlo.subset_simulation import subset_simulation  # noqa: E402


def main(name: str, stroke: float, runs: int, window: float, samples: int) -> None:
    sim = HarvesterPaths(device(name), 1.0, stroke=stroke, duration=window, dt=1e-3)
    p, cov, upper, gammas, levels = [], [], [], [], []
    for seed in range(runs):
        run = subset_simulation(sim, samples, np.random.default_rng(seed))
        p.append(run.probability)
        cov.append(run.cov)
        upper.append(sum(lv.cov for lv in run.levels))
        gammas.append([lv.gamma for lv in run.levels])
        levels.append(len(run.levels))
    p = np.array(p)
    depth = min(levels)
    gamma = np.mean([g[:depth] for g in gammas], axis=0)
    print(f"{name} D = {stroke} m, T = {window} s, {samples} per level, {runs} single runs: "
          f"P_T mean {p.mean():.3g} (min {p.min():.3g}, max {p.max():.3g}), levels {depth}-{max(levels)}; "
          f"c.o.v. observed {p.std(ddof=1) / p.mean():.3f}, Au-Beck {np.sqrt(np.mean(np.square(cov))):.3f}, "
          f"fully correlated bound {np.sqrt(np.mean(np.square(upper))):.3f}; mean gamma by level "
          f"{' '.join(f'{g:.2f}' for g in gamma)}")  # fmt: skip
    sys.stdout.flush()


if __name__ == "__main__":
    a = sys.argv[1:]
    main(a[0], float(a[1]), int(a[2]), float(a[3]), int(a[4]))
