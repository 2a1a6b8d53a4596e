"""Seed calibration of the Monte Carlo assertions of tests/test_assembly_excitation.py.

Run by hand (not collected by pytest), from the repository root:

    NUMBA_NUM_THREADS=2 python tests/calibration/assembly_excitation.py [n_seeds] [--first=SEED] [name ...]

For every ``case_*`` of tests/test_assembly_excitation.py (an assembly under tones
alone and on white noise, a translated kurtosis-6 input, a shock train on white
noise) it reruns the statistic over seeds 1000, 1001, ... and prints, per
assertion, the number of seeds, the mean and standard deviation of the z-scores
and the largest |z| (calibrated: mean near 0, SD near 1, no |z| above 4), plus
the smallest power margin (detect * |reference| / standard error, >= 6). The last
results are in ``assembly_excitation.txt`` beside this file.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # this checkout's randvib

import test_assembly_excitation as t  # noqa: E402
from _stats import calibrate, seeds_and_names  # noqa: E402

import randvib as rv  # noqa: E402

CASES = {
    "tones-alone-heun": lambda s: t.case_tones(s, "heun"),
    "tones-alone-euler": lambda s: t.case_tones(s, "euler-maruyama"),
    "tone-on-white-heun": lambda s: t.case_tones(s, "heun", 0.2, (rv.Tone(14.0, 3.0),)),
    "translated": t.case_translated,
    "shocks": t.case_shocks,
}


def main():
    seeds, names = seeds_and_names(sys.argv[1:], default_seeds=30)
    for name, case in CASES.items():
        if names and name not in names:
            continue
        calibrate(name, case, seeds, widths=(20, 10))


if __name__ == "__main__":
    main()
