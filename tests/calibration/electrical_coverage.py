"""Coverage of identify's 95 % intervals for the whole harvester (run by hand).

    NUMBA_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python tests/calibration/electrical_coverage.py \
        [n_seeds] [--search] [--case coil|coil_one_load|piezo]

Records from the independent generator of tests/_electrical.py (plain RK4 at
16 kHz of the device with its circuit, on a band-limited 4-20 Hz input at
1 kHz, 1 % white sensor noise on every channel), one realisation of the input
and the noise per seed, fitted by ``randvib.identify``:

* ``coil``: Coulomb friction and inductance, the load voltage only, records
  at 3 and 30 ohm (1 s each), the mass given: c, k, k3, Fc, alpha, R_C, L;
* ``coil_one_load``: the same coil at 3 ohm only (1 s), the mass given and
  its resistance measured (``--fix r_coil``): c, k, k3, Fc, alpha, L;
* ``piezo``: Duffing spring, voltage and velocity (1 s), the mass free:
  m, c, k, k3, theta, C_p.

By default each fit starts 5 % from the truth with a small search (the
intervals are the polish's, as in tests/test_electrical_identification.py);
``--search`` runs identify's default search from scratch instead (slow).
Printed per case and parameter: the share of seeds whose interval holds the
truth, with the exact binomial 95 % interval of that share, and the largest
error in standard errors; the last results are kept in
electrical_coverage.txt beside this script.
"""

import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import _electrical as E  # noqa: E402
import test_electrical_identification as T  # noqa: E402

import randvib as rv  # noqa: E402


def coil_fit(seed, search):
    records = [
        E.record("coil", E.COIL, r_load=r, seed=1000 + 2 * seed + i, noise={"voltage": 0.01},
                 duration=1.0)
        for i, r in enumerate(T.COIL_LOADS)
    ]  # fmt: skip
    options = {} if search else dict(popsize=8, maxiter=3, init=T.near_truth(
        T.coil_device, E.COIL, T.COIL_LOADS[0]))  # fmt: skip
    return rv.identify(records, "coulomb", m=E.COIL["m"], coupling="inductive",
                       r_load=T.COIL_LOADS, outputs=("voltage",), seed=seed, progress=False,
                       **options)  # fmt: skip


def piezo_fit(seed, search):
    record = E.record("piezo", E.PIEZO, r_load=1e5, seed=2000 + seed, duration=1.0,
                      noise={"voltage": 0.01, "relative_velocity": 0.01},
                      outputs=("voltage", "relative_velocity"))  # fmt: skip
    options = {} if search else dict(popsize=8, maxiter=3, init=T.near_truth(
        T.piezo_device, E.PIEZO, 1e5))  # fmt: skip
    return rv.identify(record, "viscous", coupling="piezo", r_load=1e5,
                       outputs=("voltage", "relative_velocity"), seed=seed, progress=False,
                       **options)  # fmt: skip


def coil_one_load_fit(seed, search):
    record = E.record("coil", E.COIL, r_load=3.0, seed=3000 + seed, noise={"voltage": 0.01},
                      duration=1.0)  # fmt: skip
    options = {} if search else dict(popsize=8, maxiter=3, init=T.near_truth(
        T.coil_device, E.COIL, 3.0))  # fmt: skip
    return rv.identify(record, "coulomb", m=E.COIL["m"], coupling="inductive", r_load=3.0,
                       outputs=("voltage",), fixed={"r_coil": E.COIL["r_coil"]}, seed=seed,
                       progress=False, **options)  # fmt: skip


CASES = {
    "coil": (coil_fit, E.COIL, T.COIL_FREE),
    "coil_one_load": (coil_one_load_fit, E.COIL, tuple(n for n in T.COIL_FREE if n != "r_coil")),
    "piezo": (piezo_fit, E.PIEZO, T.PIEZO_FREE),
}


def main(n, search, only=None):
    for case, (fit, truth, names) in CASES.items():
        if only is not None and case != only:
            continue
        hits = {name: 0 for name in names}
        worst = {name: 0.0 for name in names}
        refused, started = 0, time.perf_counter()
        for seed in range(n):
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    res = fit(seed, search)
            except rv.IdentifiabilityError as exc:
                refused += 1
                print(f"  seed {seed}: refused ({exc})")
                continue
            for name in names:
                lo, hi = res.confidence_intervals.get(name, (np.nan, np.nan))
                hits[name] += int(lo <= truth[name] <= hi)
                z = abs(res.parameters[name] - truth[name]) / res.standard_errors[name]
                worst[name] = max(worst[name], z)
        fits = n - refused
        print(f"{case}: {fits} fits, {refused} refused, {time.perf_counter() - started:.0f} s"
              f" ({'search from scratch' if search else 'started 5 % from the truth'})")  # fmt: skip
        for name in names:
            k = hits[name]
            lo = stats.beta.ppf(0.025, k, fits - k + 1) if k else 0.0
            hi = stats.beta.ppf(0.975, k + 1, fits - k) if k < fits else 1.0
            print(f"  {name:12s} coverage {k}/{fits} = {k / max(fits, 1):.2f} "
                  f"[{lo:.2f}, {hi:.2f}], largest |error| {worst[name]:.2f} se")  # fmt: skip


if __name__ == "__main__":
    argv = sys.argv[1:]
    only = argv[argv.index("--case") + 1] if "--case" in argv else None
    if only is not None and only not in CASES:
        sys.exit(f"--case {only!r}: one of {', '.join(CASES)}")
    args = [a for a in argv if not a.startswith("--") and a != only]
    main(int(args[0]) if args else 30, "--search" in argv, only)
