"""Seed calibration of the Monte Carlo assertions in tests/test_claims.py and test_sweep.py.

Run by hand (not collected by pytest), from the repository root::

    NUMBA_NUM_THREADS=1 python tests/calibration/claims.py grid 24
    NUMBA_NUM_THREADS=1 python tests/calibration/claims.py trust 24
    NUMBA_NUM_THREADS=1 python tests/calibration/claims.py coverage 2000   # claims_coverage.txt
    NUMBA_NUM_THREADS=1 python tests/calibration/claims.py sweep 40
    NUMBA_NUM_THREADS=1 python tests/calibration/claims.py steps 1024

Each mode evaluates the statistic a test asserts on, as a function of the seed,
over seeds the tests do not use (from 1000 on), and prints the z-scores'
mean, standard deviation and largest |z| (or the empirical coverage), which
the tests' docstrings record. A calibrated test has z-scores of mean near 0
and SD near 1.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT)]  # this checkout's tests/ and randvib

import randvib  # noqa: E402

assert Path(randvib.__file__).resolve().parents[1] == ROOT, randvib.__file__

from _stats import z_score  # noqa: E402

FIRST_SEED = 1000


def summary(name, z):
    z = np.asarray(z, dtype=float)
    print(
        f"{name}: {z.size} values, mean {z.mean():+.3f}, SD {z.std(ddof=1):.3f}, "
        f"largest |z| {np.abs(z).max():.2f}",
        flush=True,
    )


def grid(n_seeds):
    import test_claims as tc

    z = []
    per_method = {m: [] for m in ("linearisation", "averaging", "fpk-fast", "fpk")}
    for s in range(FIRST_SEED, FIRST_SEED + n_seeds):
        t0 = time.perf_counter()
        for psd, k3, kappa, n in tc.GRID:
            mc, pred = tc.grid_point(psd, k3, kappa, n, s)
            z.append(z_score(mc, pred["fpk"]))
            for m in per_method:
                per_method[m].append(tc.relative_error(pred[m], mc)[0])
            se = mc.std_error / mc.mean
            print(f"seed {s} S={psd} k3={k3:g} kappa={kappa}: z {z[-1]:+.2f}, se {se:.3%}")
        print(f"seed {s}: {time.perf_counter() - t0:.1f} s", flush=True)
        summary("grid, MC vs FPK", z)
    for m, e in per_method.items():
        e = np.reshape(e, (-1, len(tc.GRID)))
        print(m, "mean relative error per point:", np.round(100 * e.mean(axis=0), 3), "%")


def trust(n_seeds):
    import test_claims as tc

    z = []
    for s in range(FIRST_SEED, FIRST_SEED + n_seeds):
        for phi, _, _ in tc.TRUST_LIMITS:
            mc, lin, fpk, _ = tc.trust_point(phi, tc.TRUST_PATHS, s)
            z.append(z_score(mc, fpk))
            err, se = tc.relative_error(lin, mc)
            print(f"seed {s} phi {phi}: z {z[-1]:+.2f}, Eq. 32 error {err:+.3%} ± {se:.3%}")
        summary("trust, MC vs FPK", z)


def coverage(n_seeds):
    import test_sweep as ts

    hits, z = [], []
    t0 = time.perf_counter()
    for s in range(FIRST_SEED, FIRST_SEED + n_seeds):
        stat, ref = ts.contrast_and_reference(s)
        z.append(z_score(stat, ref))
        hits.append(abs(stat.mean - ref) <= stat.ci95)
        if (s - FIRST_SEED + 1) % 100 == 0:
            print(
                f"{s - FIRST_SEED + 1} seeds, coverage {np.mean(hits):.4f}, "
                f"{time.perf_counter() - t0:.0f} s",
                flush=True,
            )
            summary("contrast vs FPK", z)
    print(f"coverage of the 95 % interval: {np.sum(hits)} of {len(hits)} = {np.mean(hits):.4f}")
    summary("contrast vs FPK", z)
    spread_blocks(np.square(z), ts.SPREAD_SEEDS)


def spread_blocks(z2, block):
    """test_paired_contrast_intervals_have_their_nominal_size's statistic (the sum of
    ``block`` squared z-scores, chi-square(block)) over consecutive blocks of seeds."""
    from scipy import stats

    sums = np.asarray(z2)[: len(z2) // block * block].reshape(-1, block).sum(axis=1)
    lo, hi = stats.chi2.ppf(5e-4, block), stats.chi2.isf(5e-4, block)
    outside = int(np.sum((sums < lo) | (sums > hi)))
    print(
        f"sum of {block} squared z-scores over {sums.size} blocks: {outside} outside "
        f"[{lo:.1f}, {hi:.1f}], range {sums.min():.1f} .. {sums.max():.1f}, "
        f"mean {sums.mean():.1f} (chi-square({block}): {block})"
    )


def steps(n_paths):
    """Time-step bias of Heun with Coulomb friction, on common noise.

    Paths run at dt = 5e-5, 1e-4, 2e-4, 4e-4 s with the same Brownian path
    (increments summed in pairs), so P(dt) - P(5e-5) is estimated far more
    precisely than either; printed relative to the FPK power.
    """
    import test_claims as tc

    from randvib.statistics import estimate

    for psd, k3, kappa in ((1.0, 0.0, 2.0), (1.0, 5e5, 1.0)):
        h = tc.BASE.updated(fc=tc.fc_at_kappa(kappa, psd), k3=k3)
        ref = float(tc.rv.expected_power(h, psd, method="fpk"))
        dt0, t_end = 5e-5, tc.BURN_IN + tc.WINDOW
        n_steps = int(round(t_end / dt0))
        y, c = {}, {}
        for lo in range(0, n_paths, 128):
            dw = np.random.default_rng([5, lo]).standard_normal((128, n_steps)) * np.sqrt(dt0)
            for level in range(4):
                dt = dt0 * 2**level
                r = tc.rv.simulate(
                    h, psd, t_end=t_end, burn_in=tc.BURN_IN, dt=dt, dW=dw, n_paths=128,
                    seed=5, first_path=lo, companion=True, progress=False,
                )  # fmt: skip
                y.setdefault(dt, []).append(h.c_e * r.per_path[:, 0])
                c.setdefault(dt, []).append(r.controls())
                if level < 3:
                    dw = dw[:, ::2] + dw[:, 1::2]
        dts = sorted(y)
        y = {d: np.concatenate(v) for d, v in y.items()}
        controls = np.column_stack([np.vstack(c[d]) for d in dts])
        for d in dts[1:]:
            diff = estimate(y[d] - y[dts[0]], controls)
            print(
                f"S={psd} k3={k3:g} kappa={kappa}: P({d:g}) - P({dts[0]:g}) = "
                f"{diff.mean / ref:+.4%} ± {diff.std_error / ref:.4%} of the power",
                flush=True,
            )


def sweep(n_seeds):
    import test_sweep as ts

    z = []
    for s in range(FIRST_SEED, FIRST_SEED + n_seeds):
        z.extend(ts.sweep_z_scores(s))
        summary("sweep points vs FPK", z)


if __name__ == "__main__":
    mode, n = sys.argv[1], int(sys.argv[2])
    if len(sys.argv) > 3:  # optional first seed, to extend a run
        FIRST_SEED = int(sys.argv[3])
    {"grid": grid, "trust": trust, "coverage": coverage, "sweep": sweep, "steps": steps}[mode](n)
