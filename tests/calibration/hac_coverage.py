"""Coverage of identify's 95 % intervals when the residual is not white (run by hand).

    NUMBA_NUM_THREADS=1 python tests/calibration/hac_coverage.py [n_seeds]

Records from the independent generator of tests/test_hold_choice.py (filtered
noise at 1 kHz with content to 350 Hz, RK4 of Eq. 1 at 16 kHz, offsets on both
channels), each fitted by ``randvib.identify`` with default options. Two cases:

* ``ar1-output``: AR(1) output noise (rho = 0.9, 2 % of the response RMS): the
  model is right, the noise coloured;
* ``input-noise`` (misspecified): white noise on the input sensor (5 % of its
  RMS), which the model takes as exact (errors in variables), plus white
  output noise (1 %).

Printed per case and parameter: the share of seeds whose interval holds the
truth, the exact binomial 95 % interval of that share, and which covariance
the fits used (``white`` or ``hac``).
"""

import sys
from pathlib import Path

import numpy as np
from scipy import signal, stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import test_hold_choice as T  # noqa: E402

from randvib import identify  # noqa: E402
from randvib.models.record import Record  # noqa: E402

CASES = ("ar1-output", "input-noise")


def noisy(rig, case, seed):
    rng = np.random.default_rng(1000 + seed)
    z, u = rig.z.copy(), rig.input.copy()
    if case == "ar1-output":
        e = signal.lfilter([1.0], [1.0, -0.9], rng.standard_normal(z.size))
        z += 0.02 * np.std(rig.z) * e / np.std(e)
    else:
        u += 0.05 * np.std(rig.input) * rng.standard_normal(u.size)
        z += 0.01 * np.std(rig.z) * rng.standard_normal(z.size)
    return Record(rig.dt, base_acceleration=u, relative_displacement=z, name=f"{case}{seed}")


def main(n):
    truth = {**T.TRUTH, **T.OFFSETS}
    for case in CASES:
        hits = {name: 0 for name in truth}
        methods, verdicts = [], []
        for seed in range(n):
            rig = T.shaker_record(seed=seed)
            res = identify(noisy(rig, case, seed), "coulomb", m=T.M, progress=False, seed=seed)
            methods.append(res.uncertainty.method)
            verdicts.append(res.residuals.verdict)
            intervals = res.confidence_intervals
            if res.at_bound:
                print(f"  seed {seed}: {res.at_bound} on a search bound (no interval: a miss)")
            for name, value in truth.items():
                lo, hi = intervals.get(name, (np.nan, np.nan))
                hits[name] += lo <= value <= hi
        used = {m: methods.count(m) for m in sorted(set(methods))}
        said = {v: verdicts.count(v) for v in sorted(set(verdicts))}
        print(f"{case}: {n} seeds, covariance used: {used}, residual verdicts: {said}")
        for name, k in hits.items():
            ci = stats.binomtest(k, n).proportion_ci(0.95)
            print(f"  {name:>13}: {k}/{n} = {k / n:.2f} [{ci.low:.2f}, {ci.high:.2f}]")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 40)
