"""Seed study for tests/test_identification.py (run by hand, not by pytest).

    NUMBA_NUM_THREADS=1 python tests/calibration/identification.py [n_noise_seeds]

1. z-scores of the noisy-record test over noise seeds (should be mean ~0, SD ~1).
2. Precision reached by SaDE + polish on the noise-free records (optimiser seeds):
   the largest |ln(theta_hat / theta) - bias| over the parameters.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import _identification as H  # noqa: E402
import test_identification as T  # noqa: E402

from randvib.identification.identify import identify  # noqa: E402


def noise_study(n):
    clean, _ = H.noisy_coulomb_record(0)
    lin = H.Linearisation(H.COULOMB, "coulomb", clean, H.FREE, skip=H.NOISY["skip"])
    zs = np.array([H.noisy_coulomb_z(s, lin)[1] for s in range(n)])
    print(f"noisy record, {n} noise seeds")
    for j, name in enumerate(H.FREE):
        z = zs[:, j]
        print(
            f"  {name:3s} mean {z.mean():+.2f} SD {z.std(ddof=1):.2f} max|z| {np.abs(z).max():.2f}"
        )


def optimiser_study(seeds):
    coul = T.not_at_rest("coulomb", H.COULOMB)
    lugre = T.not_at_rest("lugre", T.LUGRE)
    held = {n: T.LUGRE[n] for n in ("sigma0", "sigma1", "fs", "vs")}
    tanh = dict(H.COULOMB, beta=100.0)
    ex = H.excitation(0, 1.5, 500.0)
    y, acc = H.tapered(ex)
    motion = H.Record(ex.dt, base_acceleration=acc)
    z = H.record_response(H.harvester(tanh, "tanh"), motion, substeps=8, z0=T.Z0, v0=T.V0).z[0]
    trec = H.Record(ex.dt, name="tanh", base_displacement=y, relative_displacement=z)
    cases = {
        "coulomb": (coul, H.COULOMB, "coulomb", H.FREE, dict(popsize=30, maxiter=80)),
        "lugre": (lugre, T.LUGRE, "lugre", H.FREE, dict(popsize=16, maxiter=40, fixed=held)),
        "tanh": (
            trec, tanh, "tanh", H.FREE + ("beta",),
            dict(popsize=20, maxiter=60, bounds={"beta": (10, 1e4)}),
        ),
    }  # fmt: skip
    for label, (rec, truth, model, free, kw) in cases.items():
        lin = H.Linearisation(truth, model, rec, free)
        worst = []
        for seed in seeds:
            res = identify(rec, model, m=truth["m"], seed=seed, **kw)
            err = np.array([np.log(res.parameters[n] / truth[n]) for n in free])
            worst.append(np.max(np.abs(err - lin.bias)))
        print(f"{label}: largest |ln(theta/true) - bias| over {len(seeds)} seeds {max(worst):.2e}")


if __name__ == "__main__":
    noise_study(int(sys.argv[1]) if len(sys.argv) > 1 else 40)
    optimiser_study(range(8))
