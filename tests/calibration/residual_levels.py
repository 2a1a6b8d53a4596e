"""Finite-sample levels of the residual diagnostics' tests (run by hand).

    python tests/calibration/residual_levels.py [white_pairs] [coloured_pairs]

On the series of tests/test_residuals.py, many more of them (other seeds):

* white residual and independent white input, 2048 samples, M = 10 lags
  (default 40 000 pairs): the share of Ljung-Box p-values below LEVEL and
  below 0.5, of Holm's cross test rejecting, and of 'structured' verdicts
  (``WHITE_NOMINAL``);
* independent AR(1) residual and input (phi = 0.8), 1024 samples, M = 25
  (default 20 000 pairs): the share of r_eu(0) outside the cross band and of
  Holm's cross test rejecting (``COLOURED_NOMINAL``).

Each share with its exact (Clopper-Pearson) 95 % interval, the nominal rate and
its claim, the test's binomial region for its own number of pairs (in shares),
and the test's false failure if the true rate were at either end of the interval
(to compare with its share of 1e-3). Results of the last run:
residual_levels_results.txt beside this file.
"""

import sys
from pathlib import Path

from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import test_residuals as T  # noqa: E402

CHUNK = 10_000


def measured(counting, pairs, seed):
    """Summed counts of ``counting(seed, size)`` over chunks of at most CHUNK pairs."""
    total = {}
    for i, start in enumerate(range(0, pairs, CHUNK)):
        for name, c in counting(seed=seed + i, pairs=min(CHUNK, pairs - start)).items():
            total[name] = total.get(name, 0) + c
    return total


def report(title, counts, pairs, nominal, test_pairs):
    print(title)
    print("  count             share [95 % CI]                nominal          test region"
          "        false failure at the CI's ends (allowed)")  # fmt: skip
    for name, (p, sided) in nominal.items():
        c = counts[name]
        lo_ci = stats.beta.ppf(0.025, c, pairs - c + 1) if c > 0 else 0.0
        hi_ci = stats.beta.ppf(0.975, c + 1, pairs - c)
        allowed = 1e-3 / len(nominal)
        lo, hi = T.acceptance(test_pairs, p, allowed, sided)
        fails = [stats.binom.cdf(lo - 1, test_pairs, q) + stats.binom.sf(hi, test_pairs, q)
                 for q in (lo_ci, hi_ci)]  # fmt: skip
        print(
            f"  {name:16s}  {c / pairs:.5f} [{lo_ci:.5f}, {hi_ci:.5f}]  {sided:9s} {p:.3f}  "
            f"[{lo / test_pairs:.4f}, {hi / test_pairs:.4f}]  "
            f"{fails[0]:.1e}, {fails[1]:.1e} ({allowed:.1e})"
        )


def main(white_pairs, coloured_pairs):
    counts = measured(T.white_alarm_counts, white_pairs, 1000)
    title = (f"white residual, white input, {T.WHITE_SAMPLES} samples, M = {T.WHITE_LAGS}, "
             f"{white_pairs} pairs (the test: {T.WHITE_PAIRS})")  # fmt: skip
    report(title, counts, white_pairs, T.WHITE_NOMINAL, T.WHITE_PAIRS)
    counts = measured(T.band_alarm_counts, coloured_pairs, 2000)
    title = (f"AR(1) residual and input (phi 0.8), {T.COLOURED_SAMPLES} samples, M = 25, "
             f"{coloured_pairs} pairs (the test: {T.COLOURED_PAIRS})")  # fmt: skip
    report(title, counts, coloured_pairs, T.COLOURED_NOMINAL, T.COLOURED_PAIRS)


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:3])) if len(sys.argv) > 2 else main(40_000, 20_000)
