"""Statistical assertions shared by the Monte Carlo tests.

Every Monte Carlo test in this suite compares an estimate with an independent
number (an exact result, a converged reference) and must say two things:

* the **threshold**: ``|estimate - reference| <= n_sigma * standard error``
  (default 4 sigma; with a t statistic on hundreds of paths this is a
  two-sided false-failure rate of about 6e-5 per assertion, and the z-scores
  of each test were checked over many seeds, see the test's docstring);
* the **power**: the relative bias the test is meant to detect (``detect``,
  for example 0.01 for a 1 % error). ``assert_matches`` refuses to pass a test
  whose ensemble is too small to see that bias: it requires
  ``detect * |reference| >= (n_sigma + 2) * standard error``, so a bias of
  ``detect`` is flagged with probability at least 97.7 %.

A tolerance therefore comes from the estimate's own standard error, never from
trial and error, and an under-powered test fails loudly instead of passing
vacuously.
"""

from __future__ import annotations

import math

DEFAULT_SIGMA = 4.0
POWER_MARGIN = 2.0  # sigmas between the threshold and the bias to detect


def z_score(stat, reference: float, extra_bias: float = 0.0) -> float:
    """(estimate - reference) in standard errors, after removing a known ``extra_bias``."""
    if stat.std_error <= 0:
        return math.inf if stat.mean - extra_bias != reference else 0.0
    return (stat.mean - extra_bias - reference) / stat.std_error


def assert_matches(
    stat,
    reference: float,
    *,
    detect: float,
    n_sigma: float = DEFAULT_SIGMA,
    known_bias: float = 0.0,
    what: str = "estimate",
) -> float:
    """Assert that a Monte Carlo ``stat`` agrees with ``reference`` and could see ``detect``.

    Parameters
    ----------
    stat : randvib.statistics.Statistic
        Estimate with its standard error.
    reference : float
        The independent value it must equal.
    detect : float
        Relative bias (of ``|reference|``) this comparison is required to detect.
    n_sigma : float
        Threshold in standard errors.
    known_bias : float
        An exactly computed offset of the estimator (e.g. the scheme's own
        time-step bias), subtracted before the comparison.
    what : str
        Name used in the failure message.

    Returns
    -------
    float
        The z-score, so calibration scripts can collect it.
    """
    se = stat.std_error
    scale = abs(reference)
    assert detect * scale >= (n_sigma + POWER_MARGIN) * se, (
        f"{what}: under-powered test, standard error {se:.3g} is "
        f"{se / scale:.3%} of the reference; a {detect:.2%} bias needs <= "
        f"{detect * scale / (n_sigma + POWER_MARGIN):.3g}"
    )
    z = z_score(stat, reference, known_bias)
    assert abs(z) <= n_sigma, (
        f"{what}: {stat.mean:.6g} vs reference {reference:.6g} "
        f"(known bias {known_bias:.3g}) is {z:+.2f} standard errors "
        f"(relative error {(stat.mean - known_bias - reference) / scale:+.3%}, "
        f"threshold {n_sigma} sigma)"
    )
    return z


def calibrate(name: str, case, seeds, widths=(24, 20)) -> dict:
    """Rerun a test's statistic over ``seeds`` and print its z-scores' calibration.

    ``case(seed)`` yields ``(what, stat, reference, known_bias, detect)`` rows, as the
    tests' ``case_*`` functions do. Prints, per row name, the number of seeds, the mean,
    standard deviation and largest |z| (calibrated: mean near 0, SD near 1) and the
    smallest power margin ``detect * |reference| / SE`` (>= 6 for ``assert_matches``).
    Used by the scripts in ``tests/calibration/``; returns the z-scores by row name.
    """
    import numpy as np

    zs, margins = {}, {}
    for seed in seeds:
        for what, stat, ref, bias, detect in case(seed):
            zs.setdefault(what, []).append(z_score(stat, ref, bias))
            margins.setdefault(what, []).append(detect * abs(ref) / stat.std_error)
    for what, z in zs.items():
        z = np.array(z)
        print(
            f"{name:{widths[0]}s} {what:{widths[1]}s} seeds {z.size:4d}  mean z {z.mean():+.3f}  "
            f"SD {z.std(ddof=1):.3f}  max|z| {np.abs(z).max():.2f}  "
            f"min power margin {min(margins[what]):.2f} SE",
            flush=True,
        )
    return zs


def seeds_and_names(argv, default_seeds: int = 40, first: int = 1000):
    """(seeds, names or None) from a calibration script's ``[n_seeds] [--first=SEED] [name ...]``."""
    args = list(argv)
    for arg in [a for a in args if a.startswith("--first=")]:
        first = int(arg.split("=", 1)[1])
        args.remove(arg)
    n = int(args[0]) if args else default_seeds
    return range(first, first + n), (args[1:] or None)
