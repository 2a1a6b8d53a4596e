"""Identification benchmarks (pytest-benchmark).

Run: ``python -m pytest benchmarks/bench_identification.py -s -p no:cacheprovider``
(``-s`` prints the summaries; the numbers also land in ``extra_info``).

1. Coulomb identification of a 10 s record sampled at 1 kHz (target <= 10 s on
   2 cores): the default method (SaDE 30 x 60 with patience 15, then the
   least-squares polish of the simulation error, offsets and initial state
   estimated) against the previous default measured in the same run (SaDE
   50 x 200 with patience 40 and a Nelder-Mead polish, start from the
   record, no offsets); the ratio of wall times and both parameter errors.
4. The nine-test campaign (studies/identification.py, target <= 2 min):
   only with ``--campaign`` (it takes minutes), new settings against the old.
2. Simulations per second of the compiled batched kernel against a plain
   numpy implementation of the same event-driven stick-slip scheme
   (vectorised over the population), measured in the same run; the two
   trajectories are checked to agree.
3. SaDE against ``scipy.optimize.differential_evolution`` on the same
   identification problem and search space: best J reached against
   simulations spent, median over three seeds.
"""

from __future__ import annotations

import time

import numpy as np

from randvib.identification.bounds import default_bounds
from randvib.identification.cost import CostFunction
from randvib.identification.identify import identify
from randvib.identification.input_reconstruction import driving_signal
from randvib.identification.models import device_from_parameters
from randvib.identification.record_integrator import parameter_matrix, run_kernel
from randvib.identification.record_response import record_response
from randvib.identification.sade import _Space, sade
from randvib.models.excitation import band_limited_excitation
from randvib.models.record import Record

TRUE = dict(m=0.0226, c=0.049, k=57.4, k3=70742.0, fc=0.0058)


def coulomb_record(duration=10.0, fs=1000.0, seed=1):
    ex = band_limited_excitation(duration, fs, 1.5, seed=seed)
    device, _ = device_from_parameters("coulomb", TRUE)
    z = record_response(device, ex, input_kind="base_acceleration", substeps=8).z[0]
    return Record(
        1 / fs, name="bench", base_displacement=ex["base_displacement"], relative_displacement=z
    )


# --------------------------------------------------------------- numpy reference
def _hermite_root_np(hh, q0, d0, q1, d1):
    lo = np.zeros_like(q0)
    hi = np.ones_like(q0)
    for _ in range(48):
        mid = 0.5 * (lo + hi)
        t2, t3 = mid * mid, mid * mid * mid
        q = (
            (2 * t3 - 3 * t2 + 1) * q0
            + (t3 - 2 * t2 + mid) * hh * d0
            + (-2 * t3 + 3 * t2) * q1
            + (t3 - t2) * hh * d1
        )
        pos = q > 0
        lo = np.where(pos, mid, lo)
        hi = np.where(pos, hi, mid)
    return hi


def simulate_coulomb_numpy(params, acc, dt, nsub, z0, v0):
    """The kernel's Coulomb stick-slip scheme in plain numpy, vectorised over candidates.

    One pass of the event loop advances every active candidate by one action
    (a stick stretch, an accepted RK4 slip step, or a located event), exactly
    as one iteration of the compiled loop does.
    """
    m, c, k, k3, fc = (params[:, j].copy() for j in range(5))
    gain = -m
    n_pop, n = params.shape[0], acc.size
    z = np.full(n_pop, float(z0))
    v = np.full(n_pop, float(v0))
    g = gain * acc[0] - c * v - k * z - k3 * z**3
    stick = (v == 0) & (np.abs(g) <= fc)
    sgn = np.where(v != 0, np.sign(v), np.where(g > 0, 1.0, -1.0))
    out = np.empty((n_pop, n))
    out[:, 0] = z
    h = dt / nsub

    def acc_slip(e, zz, vv, cc, kk, kk3, ff, mm, ss):
        return (e - cc * vv - kk * zz - kk3 * zz**3 - ss * ff) / mm

    def rk4(idx, s, hh, zz, vv, u0, du):
        p = (c[idx], k[idx], k3[idx], fc[idx], m[idx], sgn[idx])
        e0, e1, e2 = (gain[idx] * (u0 + du * t) for t in (s, s + 0.5 * hh, s + hh))
        a1 = acc_slip(e0, zz, vv, *p)
        z2, v2 = zz + 0.5 * hh * vv, vv + 0.5 * hh * a1
        a2 = acc_slip(e1, z2, v2, *p)
        z3, v3 = zz + 0.5 * hh * v2, vv + 0.5 * hh * a2
        a3 = acc_slip(e1, z3, v3, *p)
        z4, v4 = zz + hh * v3, vv + hh * a3
        a4 = acc_slip(e2, z4, v4, *p)
        return (
            zz + hh / 6 * (vv + 2 * v2 + 2 * v3 + v4),
            vv + hh / 6 * (a1 + 2 * a2 + 2 * a3 + a4),
            a1,
        )

    for i in range(n - 1):
        u0 = acc[i]
        du = (acc[i + 1] - acc[i]) / dt
        for j in range(nsub):
            a = j * h
            b = dt if j == nsub - 1 else a + h
            s = np.full(n_pop, a)
            for it in range(24):
                active = s < b
                if not active.any():
                    break
                st = np.flatnonzero(active & stick)
                sl = np.flatnonzero(active & ~stick)
                if st.size:
                    zz = z[st]
                    ga = gain[st] * (u0 + du * s[st]) - k[st] * zz - k3[st] * zz**3
                    gb = gain[st] * (u0 + du * b) - k[st] * zz - k3[st] * zz**3
                    f = fc[st]
                    stay = (np.abs(ga) <= f) & (np.abs(gb) <= f)
                    now = np.abs(ga) > f
                    target = np.where(gb > 0, f, -f)
                    denom = np.where(gb != ga, gb - ga, 1.0)
                    frac = np.clip((target - ga) / denom, 0.0, 1.0)
                    s[st] = np.where(stay, b, np.where(now, s[st], s[st] + frac * (b - s[st])))
                    new = np.where(now, np.where(ga > 0, 1.0, -1.0), np.where(gb > 0, 1.0, -1.0))
                    brk = st[~stay]
                    stick[brk] = False
                    sgn[brk] = new[~stay]
                    v[brk] = 0.0
                if sl.size:
                    hh = b - s[sl]
                    tiny = hh <= 1e-14 * dt
                    s[sl[tiny]] = b
                    sl, hh = sl[~tiny], hh[~tiny]
                    z1, v1, a0 = rk4(sl, s[sl], hh, z[sl], v[sl], u0, du)
                    ok = (sgn[sl] * v1 > 0) | (it == 23)
                    acc_idx = sl[ok]
                    z[acc_idx], v[acc_idx], s[acc_idx] = z1[ok], v1[ok], b
                    ev = sl[~ok]
                    if ev.size:
                        hh_e, z1e, v1e = hh[~ok], z1[~ok], v1[~ok]
                        e1 = gain[ev] * (u0 + du * b)
                        a1 = acc_slip(e1, z1e, v1e, c[ev], k[ev], k3[ev], fc[ev], m[ev], sgn[ev])
                        se = sgn[ev]
                        frac = _hermite_root_np(hh_e, se * v[ev], se * a0[~ok], se * v1e, se * a1)
                        hs = frac * hh_e
                        zn, _, _ = rk4(ev, s[ev], hs, z[ev], v[ev], u0, du)
                        z[ev] = zn
                        s[ev] = np.minimum(s[ev] + hs, b)
                        v[ev] = 0.0
                        g = gain[ev] * (u0 + du * s[ev]) - k[ev] * zn - k3[ev] * zn**3
                        sticks = np.abs(g) <= fc[ev]
                        stick[ev[sticks]] = True
                        new = np.where(g > 0, 1.0, -1.0)
                        flip = ~sticks & (new != sgn[ev])
                        sgn[ev[flip]] = new[flip]
        out[:, i + 1] = z
    return out


# --------------------------------------------------------------------- benchmarks
FREE = ("c", "k", "k3", "fc")


def previous_default(record, m, seed=0):
    """The identification before the polish existed: SaDE 50 x 200 (patience 40)
    and a Nelder-Mead polish, from the record's start, no offsets. Returns
    (wall s, parameters, J)."""
    cost = CostFunction(
        record, "coulomb", fixed={"m": m, "k2": 0.0, "input_offset": 0.0}, free=FREE,
        initial_state="record",
    )  # fmt: skip
    box = default_bounds(record, "coulomb", m)
    start = time.perf_counter()
    res = sade(
        cost, [box[n] for n in FREE], log=[n != "k3" for n in FREE], names=FREE, popsize=50,
        maxiter=200, seed=seed, tol=1e-6, patience=40, polish=True,
    )  # fmt: skip
    return time.perf_counter() - start, dict(zip(FREE, res.x, strict=True)), float(res.fun)


def test_coulomb_identification_10s_1khz(benchmark):
    record = coulomb_record()
    # compile (or load the cache) outside the timing
    identify(record.rows(0, 200), "coulomb", m=TRUE["m"], popsize=8, maxiter=1)
    old_s, old_p, old_j = previous_default(record, TRUE["m"])

    def run():
        return identify(record, "coulomb", m=TRUE["m"], seed=0)

    res = benchmark.pedantic(run, rounds=1, iterations=1)
    errors = {n: res.parameters[n] / TRUE[n] - 1 for n in FREE}
    old_errors = {n: old_p[n] / TRUE[n] - 1 for n in FREE}
    worst, old_worst = (max(map(abs, e.values())) for e in (errors, old_errors))
    benchmark.extra_info.update(
        wall_s=res.elapsed,
        previous_wall_s=old_s,
        speedup=old_s / res.elapsed,
        simulations=res.nfev,
        kernel_sims_per_s=res.simulations_per_second,
        cost=res.cost,
        previous_cost=old_j,
        max_relative_error=worst,
        previous_max_relative_error=old_worst,
    )
    print(
        f"\nCoulomb identification, 10 s at 1 kHz: SaDE 30 x 60 + least squares "
        f"{res.elapsed:.1f} s wall ({res.nfev} simulations, J = {res.cost:.3g}, max parameter "
        f"error {100 * worst:.2g} %); previous default (SaDE 50 x 200 + Nelder-Mead) "
        f"{old_s:.1f} s (J = {old_j:.3g}, max error {100 * old_worst:.2g} %); "
        f"ratio {old_s / res.elapsed:.1f}x"
    )
    assert res.cost < 1.0


#: The last commit before the measurement model and the least-squares polish.
BASELINE_COMMIT = "42e0b20"


def _time_campaign(source_root, out):
    """Wall time of ``python studies/identification.py OUT`` run from ``source_root``."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, PYTHONPATH=str(source_root))
    start = time.perf_counter()
    subprocess.run(
        [sys.executable, "studies/identification.py", str(out), "--no-progress"],
        cwd=source_root, env=env, check=True, capture_output=True,
    )  # fmt: skip
    return time.perf_counter() - start


def test_campaign_against_the_previous_method(benchmark, request, tmp_path):
    """The full nine-test campaign (studies/identification.py), this tree against
    :data:`BASELINE_COMMIT` exported by ``git archive`` (minutes: only with
    ``--campaign``). Each run compiles from its own cache first (a 1-sample
    warm-up is not possible for a study), so both include compilation."""
    import subprocess
    from pathlib import Path

    import pytest

    if not request.config.getoption("--campaign"):
        pytest.skip("the campaign benchmark runs only with --campaign")
    root = Path(__file__).resolve().parents[1]
    old_root = tmp_path / "baseline"
    old_root.mkdir()
    archive = subprocess.run(
        ["git", "archive", BASELINE_COMMIT], cwd=root, check=True, capture_output=True
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(old_root)], input=archive, check=True)
    new_s = benchmark.pedantic(
        lambda: _time_campaign(root, tmp_path / "new"), rounds=1, iterations=1
    )
    old_s = _time_campaign(old_root, tmp_path / "old")
    benchmark.extra_info.update(wall_s=new_s, previous_wall_s=old_s, speedup=old_s / new_s)
    print(f"\ncampaign: {new_s:.0f} s; at {BASELINE_COMMIT}: {old_s:.0f} s; {old_s / new_s:.1f}x")


def test_kernel_vs_numpy_simulations_per_second(benchmark):
    record = coulomb_record()
    rng = np.random.default_rng(0)
    n_pop = 50
    cost = CostFunction(
        record, "coulomb", fixed={"m": TRUE["m"]}, free=("c", "k", "k3", "fc"), substeps=4
    )
    box = default_bounds(record, "coulomb", TRUE["m"])
    scale = rng.uniform(0.7, 1.3, (n_pop, 4))
    X = np.array([TRUE[n] for n in ("c", "k", "k3", "fc")]) * scale
    for j, n in enumerate(("c", "k", "k3", "fc")):
        X[:, j] = np.clip(X[:, j], *box[n])
    cost(X[:2])  # compile/load

    def numba_run():
        start = time.perf_counter()
        cost(X)
        return time.perf_counter() - start

    benchmark.pedantic(numba_run, rounds=5, iterations=1)
    t_numba = min(numba_run() for _ in range(5))  # best of five, as for a timing floor
    drive, _ = driving_signal(record.input, record.dt, record.input_kind)
    params = parameter_matrix(cost.parameters(X), "coulomb")[:, :5]
    start = time.perf_counter()
    z_np = simulate_coulomb_numpy(params, drive, record.dt, 4, cost.z0, cost.v0)
    t_numpy = time.perf_counter() - start
    z_nb = run_kernel(
        parameter_matrix(cost.parameters(X), "coulomb"), "coulomb", drive, True, record.dt,
        substeps=4, z0=cost.z0, v0=cost.v0,
    ).z  # fmt: skip
    agree = float(np.max(np.abs(z_np - z_nb)) / np.std(record.z))
    ratio = t_numpy / t_numba
    benchmark.extra_info.update(
        numba_sims_per_s=n_pop / t_numba,
        numpy_sims_per_s=n_pop / t_numpy,
        speedup=ratio,
        max_difference_over_std=agree,
    )
    print(
        f"\nbatched kernel: {n_pop / t_numba:.0f} sims/s; plain numpy (same scheme, vectorised "
        f"over {n_pop} candidates): {n_pop / t_numpy:.2f} sims/s; ratio {ratio:.0f}x; "
        f"max |z_numba - z_numpy| / std(z) = {agree:.1e}"
    )
    assert agree < 1e-6


def _trace(cost, space):
    nfev, best = [], []

    def f(unit):
        unit = np.atleast_2d(unit)
        values = cost(space.to_x(unit))
        values = np.where(np.isfinite(values), values, 1e10)
        nfev.append((nfev[-1] if nfev else 0) + len(values))
        best.append(min(best[-1] if best else np.inf, float(values.min())))
        return values

    return f, nfev, best


def test_sade_vs_scipy_differential_evolution(benchmark):
    from scipy.optimize import differential_evolution

    record = coulomb_record(duration=5.0, fs=500.0, seed=2)
    names = ("c", "k", "k3", "fc")
    box = default_bounds(record, "coulomb", TRUE["m"])
    space = _Space([box[n] for n in names], [n != "k3" for n in names], names)
    budget = 6000
    checkpoints = (500, 1000, 2000, 4000, 6000)
    results = {"SaDE": [], "scipy DE": []}

    def one_round():
        for seed in (0, 1, 2):
            cost = CostFunction(record, "coulomb", fixed={"m": TRUE["m"]}, free=names)
            f, nfev, best = _trace(cost, space)
            sade(f, [(0, 1)] * 4, popsize=48, maxiter=budget // 48, seed=seed, tol=0)
            results["SaDE"].append((list(nfev), list(best)))
            cost = CostFunction(record, "coulomb", fixed={"m": TRUE["m"]}, free=names)
            f, nfev, best = _trace(cost, space)
            differential_evolution(
                lambda u, f=f: f(np.asarray(u).T), [(0, 1)] * 4, popsize=12, maxiter=budget // 48,
                seed=seed, tol=0, polish=False, vectorized=True, updating="deferred",
                init="latinhypercube",
            )  # fmt: skip
            results["scipy DE"].append((list(nfev), list(best)))

    benchmark.pedantic(one_round, rounds=1, iterations=1)
    table = {}
    for name, runs in results.items():
        row = []
        for cp in checkpoints:
            row.append(
                float(
                    np.median(
                        [
                            best[np.searchsorted(nfev, cp)] if nfev[-1] >= cp else best[-1]
                            for nfev, best in runs
                        ]
                    )
                )
            )
        table[name] = row
    benchmark.extra_info.update({f"{k} J at {checkpoints}": v for k, v in table.items()})
    print("\nmedian best J (3 seeds) against simulations spent:")
    print("sims      " + "".join(f"{cp:>11d}" for cp in checkpoints))
    for name, row in table.items():
        print(f"{name:<10}" + "".join(f"{x:11.3g}" for x in row))
    assert table["SaDE"][-1] < 1.0
