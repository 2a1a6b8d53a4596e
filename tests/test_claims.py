"""The documented headline accuracy claims (docs/methods.md, docs/studies.md), each against Monte Carlo with its standard error.

docs/methods.md quotes, for the figure9 device (c = 0.2 Ns/m, damping ratio 0.088):

* Eq. 32 (equivalent linearisation) under-predicts the power, by 2.0-2.1 % at
  the half-power friction level (kappa = 4 Fc^2/(pi S m c) = 0.25) and by
  6.0-6.2 % at twice it (kappa = 1), with the other rows of its accuracy table
  (kappa = 0.1, 0.5, 2);
* stochastic averaging errs by -0.05 % to -1.7 % along the same rows, fpk-fast
  and the FPK reference by at most 0.03-0.13 %;
* Eq. 32 is trusted to 1 % for phi = Fc/(c sigma_v0) <= 0.51, 5 % for
  phi <= 1.47 and 10 % for phi <= 2.7.

Each claim is checked at points of its own (a grid over S, k3 and kappa, not
one point) against a Monte Carlo estimate with the engine's control variates
(Ito integral, energy change, friction-free companion; cross-fitted,
:func:`randvib.statistics.estimate`) at a step small enough for its bias:

* **time step**: stochastic Heun's stationary bias is O(dt^2) on smooth
  devices, but the Coulomb jump at v = 0 makes it about O(dt^1.5), positive:
  on common noise (tests/calibration/claims.py, ``steps``), P(dt) - P(5e-5 s)
  at kappa = 2 is +0.008 %, +0.024 %, +0.079 % of the power for dt = 1e-4,
  2e-4, 4e-4 s (standard errors 0.004-0.013 %; at kappa = 1: +0.003 %, +0.009 %,
  +0.027 %), so the bias at dt = 1e-4 s is
  about 0.01 %, a seventh of the standard error here (a Richardson
  combination 2 P(dt) - P(2 dt), which assumes O(dt), over-corrects by
  0.03 %, which the seed calibration showed as a mean z of -0.4).

The FPK reference (``method="fpk"``, converged to about 1e-5) is the
independent number the Monte Carlo estimate must match (``assert_matches``,
4 sigma, powered to see a 0.5 % bias: the Coulomb force off by 1 % moves the
power by 0.45-1.4 % on this grid). The quoted ranges are then asserted
for every method as ``lo - 4 se <= error <= hi + 4 se``, the error taken
against the same Monte Carlo estimate.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from _stats import assert_matches

import randvib as rv

BASE = rv.preset("figure9")  # m = 0.0226 kg, c = 0.2 Ns/m, k = 57.4 N/m
DT = 1e-4  # s; the Coulomb kink's O(dt^1.5) bias is then about 0.01 %
BURN_IN, WINDOW = 0.5, 4.0  # s; the energy relaxes at c/m ~ 9 /s
N_SIGMA = 4.0


def fc_at_kappa(kappa, psd, device=BASE):
    """Fc (N) of friction level kappa = 4 Fc^2 / (pi S m c) (docs/methods.md, paper Eq. 30)."""
    return float(np.sqrt(kappa * np.pi * psd * device.m * device.c / 4))


def fc_at_phi(phi, psd, device=BASE):
    """Fc (N) of friction level phi = Fc / (c sigma_v0), sigma_v0^2 = S m / (4 c)."""
    return float(phi * device.c * np.sqrt(psd * device.m / (4 * device.c)))


def mc_power(device, psd, n_paths, seed, dt=DT):
    """E[P_e] (a :class:`randvib.statistics.Statistic`) with the control variates."""
    return rv.simulate(
        device, psd, t_end=BURN_IN + WINDOW, burn_in=BURN_IN, dt=dt, n_paths=n_paths,
        seed=seed, companion=True, control_variates=True, progress=False,
    ).power_electrical  # fmt: skip


def relative_error(analytic, stat):
    """(analytic / MC - 1, its standard error to first order)."""
    return analytic / stat.mean - 1.0, abs(analytic) * stat.std_error / stat.mean**2


def assert_in_range(name, error, se, lo, hi):
    assert lo - N_SIGMA * se <= error <= hi + N_SIGMA * se, (
        f"{name}: relative error {error:+.3%} (standard error {se:.3%}) outside the "
        f"documented range [{lo:+.2%}, {hi:+.2%}] widened by {N_SIGMA} standard errors"
    )


def predictions(device, psd):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rv.AveragingValidityWarning)
        return {
            m: float(rv.expected_power(device, psd, method=m))
            for m in ("linearisation", "averaging", "fpk-fast", "fpk")
        }


# ------------------------------------------------------------ the accuracy table
#: docs/methods.md "Accuracy against Monte Carlo": relative error ranges (lo, hi) per
#: friction level kappa, over S = 1, 0.5, 0.1 and k3 = 0 ... 7e6 N/m^3.
DOCUMENTED_TABLE = {
    0.1: {
        "linearisation": (-0.010, -0.009),
        "averaging": (-0.001, -0.0005),
        "fpk-fast": (-0.0003, 0.0003),
        "fpk": (-0.0003, 0.0003),
    },
    0.25: {
        "linearisation": (-0.021, -0.020),
        "averaging": (-0.002, -0.001),
        "fpk-fast": (-0.0004, 0.0004),
        "fpk": (-0.0004, 0.0004),
    },
    0.5: {
        "linearisation": (-0.037, -0.036),
        "averaging": (-0.0045, -0.0026),
        "fpk-fast": (-0.0005, 0.0005),
        "fpk": (-0.0005, 0.0005),
    },
    1.0: {
        "linearisation": (-0.062, -0.060),
        "averaging": (-0.009, -0.006),
        "fpk-fast": (-0.0006, 0.0006),
        "fpk": (-0.0005, 0.0005),
    },
    2.0: {
        "linearisation": (-0.093, -0.092),
        "averaging": (-0.017, -0.013),
        "fpk-fast": (-0.0013, -0.0004),
        "fpk": (-0.0011, 0.0011),
    },
}

#: (psd, k3, kappa, paths): every row of the table, every S and k3 of it at
#: least once; kappa = 0.25 and 1 on the figure9 device itself (k3 = 5e5 is
#: the paper's Figure 9b) are docs/studies.md's "half-power friction level" and
#: "twice it". Paths give a standard error of about 0.06 % of the power.
GRID = [
    (0.5, 7.07e4, 0.1, 1024),
    (1.0, 5e5, 0.25, 1536),
    (0.1, 0.0, 0.5, 1536),
    (1.0, 5e5, 1.0, 2048),
    (0.5, 7e6, 1.0, 2048),
    (1.0, 0.0, 2.0, 2048),
    (0.1, 7e6, 2.0, 2048),
]
GRID_SEED = 20


def grid_point(psd, k3, kappa, n_paths, seed):
    """(MC Statistic, predictions) at one grid point; shared with the calibration.

    Each point draws its own streams (``seed`` offset by the point's index), so
    the points are independent checks, not one noise realisation seen seven times.
    """
    index = [g[:3] for g in GRID].index((psd, k3, kappa))
    seed = seed * len(GRID) + index
    device = BASE.updated(k3=k3, fc=fc_at_kappa(kappa, psd))
    return mc_power(device, psd, n_paths, seed), predictions(device, psd)


@pytest.mark.parametrize(("psd", "k3", "kappa", "n_paths"), GRID)
def test_accuracy_table_against_monte_carlo(psd, k3, kappa, n_paths):
    """Every method's error at a grid point lies in the documented range.

    First the Monte Carlo estimate must equal the FPK reference within
    4 standard errors, powered to detect a 0.5 % bias (a 1 % error in the
    engine's Coulomb force moves the power by 0.45 % at kappa = 0.1 and by
    0.7-1.4 % at kappa >= 0.25). Then, for linearisation (also: negative
    with significance, "it always under-predicts"), averaging, fpk-fast
    and fpk, ``lo - 4 se <= P_method / P_MC - 1 <= hi + 4 se``.

    Calibration (tests/calibration/claims.py, ``grid``; seeds 1000-1023):
    z-scores of the Monte Carlo estimate against the FPK reference at the
    7 points over 24 seeds (168 independent values): mean +0.04, SD 1.05,
    largest |z| 2.7. Standard errors 0.04-0.07 % of the power. Mean errors
    over those seeds (standard error about 0.013 %): linearisation -0.90,
    -2.07, -3.61, -6.05, -6.11, -9.16, -9.18 %; averaging -0.08, -0.19,
    -0.41, -0.81, -0.66, -1.65, -1.56 %; fpk-fast within 0.04 %, fpk within
    0.015 %. (At kappa = 2 the documented -9.2 to -9.3 % and fpk-fast's -0.04 to
    -0.13 % carry its study's own time-step bias, dt = 2.5e-4 s: about
    +0.05-0.1 % on the Monte Carlo power.) Runtime about 16 s for the 7 points.
    """
    mc, pred = grid_point(psd, k3, kappa, n_paths, GRID_SEED)
    assert_matches(mc, pred["fpk"], detect=0.005, what=f"MC vs FPK at kappa {kappa}")
    for method, (lo, hi) in DOCUMENTED_TABLE[kappa].items():
        err, se = relative_error(pred[method], mc)
        assert_in_range(f"{method} at S={psd}, k3={k3:g}, kappa={kappa}", err, se, lo, hi)
    err, se = relative_error(pred["linearisation"], mc)
    assert err + N_SIGMA * se < 0, "Eq. 32 must under-predict with significance"


# -------------------------------------------------- where Eq. 32 can be trusted
#: docs/studies.md (linearisation-accuracy): trusted to `tol` for phi <= `phi`; Eq. 32
#: then predicts at least `ratio` of the friction-free power.
TRUST_LIMITS = [(0.51, 0.01, 0.67), (1.47, 0.05, 0.33), (2.7, 0.10, 0.15)]
TRUST_PATHS = 512
TRUST_SEED = 30


def trust_point(phi, n_paths, seed, psd=1.0):
    seed = seed * len(TRUST_LIMITS) + [t[0] for t in TRUST_LIMITS].index(phi)
    device = BASE.updated(k3=0.0, fc=fc_at_phi(phi, psd))
    return (
        mc_power(device, psd, n_paths, seed),
        float(rv.expected_power(device, psd)),
        float(rv.expected_power(device, psd, method="fpk")),
        float(rv.expected_power(device.updated(fc=0.0), psd)),
    )


@pytest.mark.parametrize(("phi", "tol", "ratio"), TRUST_LIMITS)
def test_eq32_trusted_up_to_the_quoted_friction_levels(phi, tol, ratio):
    """|Eq. 32 / MC - 1| <= tol + 4 se at the largest phi the documentation trusts to tol.

    Also negative with significance, and Eq. 32's share of the friction-free
    power as quoted (two digits). The MC estimate (512 paths, standard error
    0.1-0.2 %) must match FPK within 4 sigma, powered to see a 1 % bias.

    Calibration (tests/calibration/claims.py, ``trust``; seeds 1000-1069):
    z-scores against FPK at the 3 levels over 70 seeds (210 values): mean
    -0.02, SD 1.04, largest |z| 3.2. Eq. 32's error there is about -0.75 %,
    -4.6 % and -9.9 %. Runtime about 3 s.
    """
    mc, lin, fpk, friction_free = trust_point(phi, TRUST_PATHS, TRUST_SEED)
    assert_matches(mc, fpk, detect=0.01, what=f"MC vs FPK at phi {phi}")
    err, se = relative_error(lin, mc)
    assert abs(err) <= tol + N_SIGMA * se, f"Eq. 32 off by {err:+.3%} ± {se:.3%} at phi {phi}"
    assert err + N_SIGMA * se < 0
    assert round(lin / friction_free, 2) == ratio
