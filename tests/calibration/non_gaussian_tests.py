"""Seed calibration of the Monte Carlo assertions of the tones, shocks and translation tests.

Run by hand (not collected by pytest), from the repository root:

    NUMBA_NUM_THREADS=2 python tests/calibration/non_gaussian_tests.py [n_seeds] [--first=SEED] [name ...]

For every ``case_*`` of tests/test_tones.py, tests/test_shocks.py and
tests/test_translation.py it reruns the statistic over seeds 1000, 1001, ...
and prints, per assertion, the number of seeds, the mean and standard
deviation of the z-scores and the largest |z| (calibrated: mean near 0, SD
near 1, no |z| above 4), plus the smallest power margin (detect * |reference|
/ standard error, which must be >= 6). The last results are in
``non_gaussian_tests.txt`` beside this file.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # this checkout's randvib

import test_shocks  # noqa: E402
import test_tones  # noqa: E402
import test_translation  # noqa: E402
from _stats import calibrate, seeds_and_names  # noqa: E402

import randvib as rv  # noqa: E402

CASES = {
    "tone-white": lambda s: test_tones.case_linear_noise_and_tone(s),
    "tone-band-pass": lambda s: test_tones.case_linear_noise_and_tone(
        s, rv.BandPass(0.02, 8.0, 0.2) + rv.Tone(11.0, 1.5)
    ),
    "shock-kicks": test_shocks.case_sampled_step_integrals,
    "campbell": test_shocks.case_campbell_linear,
    "translation-input": test_translation.case_synthesised_input,
    "translation-linear": test_translation.case_translated_linear,
}


def main():
    seeds, names = seeds_and_names(sys.argv[1:], default_seeds=40)
    for name, case in CASES.items():
        if names and name not in names:
            continue
        calibrate(name, case, seeds, widths=(20, 18))


if __name__ == "__main__":
    main()
