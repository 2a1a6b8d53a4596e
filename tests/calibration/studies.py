"""Seed calibration of the studies' Monte Carlo assertions (run by hand, not by pytest).

    NUMBA_NUM_THREADS=1 python tests/calibration/studies.py [n_seeds]
    NUMBA_NUM_THREADS=1 python tests/calibration/studies.py 20 interaction

Runs the figure9 quick study for seeds 0..n-1 (about 8 s each) and reports,
over all seeds, the z-scores used by tests/test_study_figure9.py: Monte Carlo
power against the FPK grids at every point with friction, paired interaction
contrasts against the FPK contrasts, and the half-step differences; plus how
often the Holm count at k3 = 5e5 is zero and how often Eq. 32 is more than
4 standard errors low at every series' highest friction.

Result (seeds 0-19, recorded in tests/test_study_figure9.py):
power 720 z-scores, mean -0.219, SD 0.904, max |z| 2.48; contrast 360,
mean +0.043, SD 1.114, max |z| 3.42; step 120, mean -0.240, SD 0.862,
max |z| 1.89; Holm count 0 at k3 = 5e5 in 18 of 20 seeds; largest Eq. 32
z at the top friction -10.89. Tiny interaction run of tests/test_studies.py
(seeds 0-19): contrast z mean +0.228, SD 1.071, max |z| 2.39.
"""

import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from study_checks import contrast_zscores, power_zscores, step_zscores  # noqa: E402

from randvib.studies import load  # noqa: E402

run_study = load("figure9").run_study


def figure9_seed(seed: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "f9"
        run_study(out, quick=True, seed=seed, workers=1, progress=False)
        table = pd.read_csv(out / "results.csv")
        inter = pd.read_csv(out / "interaction.csv")
        check = pd.read_csv(out / "step_check.csv")
    top = table[table.fc == table.groupby(["psd", "k3"]).fc.transform("max")]
    lin_z = (top.linearisation_power - top.power_electrical) / (top.power_electrical_ci95 / 1.96)
    return {
        "power": power_zscores(table).z.to_numpy(),
        "contrast": contrast_zscores(inter).z.to_numpy(),
        "step": step_zscores(check),
        "holm_zero": int(inter.detectable_holm.sum()) == 0,
        "lin_top_max_z": float(lin_z.max()),
    }


def interaction_tiny_seed(seed: int) -> float:
    """z of the tiny interaction run's contrast (tests/test_studies.py) against the FPK grids."""
    from dataclasses import replace

    from randvib.montecarlo.sweep import SweepSettings
    from randvib.studies import load

    interaction = load("interaction")

    tiny = SweepSettings(
        dt=1e-4, window=0.3, burn_in=0.1, min_paths=48, max_paths=48, batch_paths=48
    )
    grid = {"psds": (1.0,), "k3s": (0.0, 5e7), "n_fc": 2}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "inter"
        interaction.run_study(
            out,
            seed=seed,
            workers=1,
            progress=False,
            _grid=grid,
            _settings=replace(tiny, seed=seed),
        )
        inter = pd.read_csv(out / "interaction.csv")
    return float(contrast_zscores(inter).z[0])


def summary(name, z):
    z = np.concatenate(z)
    print(
        f"{name}: {z.size} z-scores, mean {z.mean():+.3f}, SD {z.std(ddof=1):.3f}, max |z| {np.abs(z).max():.2f}"
    )


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    if len(sys.argv) > 2 and sys.argv[2] == "interaction":
        summary("interaction tiny contrast", [[interaction_tiny_seed(s) for s in range(n)]])
        sys.exit()
    runs = [figure9_seed(s) for s in range(n)]
    print(f"figure9 quick, seeds 0..{n - 1}")
    for key in ("power", "contrast", "step"):
        summary(key, [r[key] for r in runs])
    print(f"Holm count 0 at k3 = 5e5 in {sum(r['holm_zero'] for r in runs)} of {n} seeds")
    print(
        f"largest Eq. 32 z at the top friction over seeds: {max(r['lin_top_max_z'] for r in runs):+.2f}"
    )
