"""The most power any device of a given mass can harvest under a stroke budget.

A transducer of any kind (linear or not, causal or not, passive or active) on
a mass m with mechanical damping c_m, whose stationary displacement z keeps
E[z^2] <= sigma^2, under a stationary base acceleration a of one-sided PSD
G_a(f), harvests at most (docs/conventions.md, "The limit")

    P_max(sigma) = min_{lambda >= 0} [ int_0^inf m^2 w^2 G_a / (4 (c_m w^2 + lambda)) df
                                        + lambda sigma^2 ],     w = 2 pi f.

Derivation: stationary energy balance gives P <= -m E[a z'] - c_m E[z'^2]
(the spring stores nothing on average, friction only dissipates); by
Cauchy-Schwarz on the cross-spectrum, -m E[a z'] <= m int sqrt(G_a G_z') df
with G_z' = w^2 G_z; for each lambda >= 0 the Lagrangian is maximised
frequency by frequency at sqrt(G_z) = m w sqrt(G_a) / (2 (c_m w^2 + lambda)),
which gives the bracket (weak duality: every lambda gives a bound; the
minimising one is the tightest, and equals the maximum over all cross-spectra
with coherence 1). This is the variance-constrained form of the bound of
Halvorsen, Phys. Rev. E 87, 042129 (2013), for a velocity-damped mass, and
the stationary-spectrum counterpart of the non-causal bound of Haji
Hosseinloo and Turitsyn, Phys. Rev. Applied 4, 064009 (2015). With lambda = 0
it is the unconstrained bound m^2 E[a^2] / (4 c_m).

It is finite when w^2 G_a / (c_m w^2 + lambda) is integrable: for band-pass,
Kanai-Tajimi, band-limited, tabulated and measured spectra with c_m > 0; for
white noise it is infinite (an ideal transducer can take unbounded power
from white acceleration), and :func:`harvesting_limit` returns None.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize, sparse, special

from randvib._validation import check_nonnegative, check_positive
from randvib.analytic.linear_response import frequency_rule, mechanical_block
from randvib.models.excitation import Excitation, Measured

__all__ = ["gaussian_displacement_budget", "harvesting_limit", "record_harvesting_limit"]

#: Samples per least-squares problem of :func:`record_harvesting_limit`.
RECORD_CHUNK = 4096


def gaussian_displacement_budget(stroke, exceedance) -> float:
    """The largest displacement RMS sigma_z with ``P(|z| > stroke) <= exceedance`` for Gaussian z.

    sigma_z = stroke / Phi^-1(1 - exceedance / 2) (docs/conventions.md,
    "Gaussian stroke budget").

    Parameters
    ----------
    stroke : float
        Stroke d (m), > 0.
    exceedance : float
        Budget eps, 0 < eps < 1.
    """
    stroke = float(check_positive("stroke", stroke, "m"))
    eps = float(exceedance)
    if not 0.0 < eps < 1.0:
        raise ValueError(f"`exceedance` must be a probability in (0, 1), got {exceedance!r}")
    return stroke / (math.sqrt(2.0) * special.erfcinv(eps))


def _weights(m, c_m, excitation: Excitation, corner: float):
    """Nodes f (Hz), weights and m^2 w^2 G_a / 4 on a rule resolving the spectrum and the corner."""
    # A critically damped unit block with its poles at the corner frequency
    # sqrt(lambda / c_m): the rule then has panels there as well as at the
    # spectrum's peaks and kinks (Gauss-Legendre panels, mapped infinite tail).
    w_c = 2.0 * np.pi * max(corner, 1e-6)
    nodes, weights = frequency_rule(mechanical_block(1.0, 2.0 * w_c, w_c**2), excitation)
    w = 2.0 * np.pi * nodes
    return w, weights, m**2 * w**2 * excitation.psd(nodes) / 4.0


def harvesting_limit(m, c_m, excitation: Excitation, displacement_rms) -> float | None:
    """Upper bound on the harvested power of any device with E[z^2] <= sigma^2 (W).

    Parameters
    ----------
    m : float
        Moving mass (kg), > 0.
    c_m : float
        Mechanical viscous damping (Ns/m), >= 0. With c_m = 0 the bound is
        m sigma sqrt(E[a'^2]), finite only for a spectrum of bounded support.
    excitation : Excitation
        The base acceleration's spectrum (one-sided, (m/s^2)^2/Hz).
    displacement_rms : float
        sigma (m), > 0; for a stroke budget see :func:`gaussian_displacement_budget`.

    Returns
    -------
    float or None
        P_max (W); None where no finite bound exists (white noise; c_m = 0
        with a spectrum of unbounded support).
    """
    m = float(check_positive("m", m, "kg"))
    c_m = float(check_nonnegative("c_m", c_m, "Ns/m"))
    rms = float(check_positive("displacement_rms", displacement_rms, "m"))
    # a budget whose square is beyond float64 never binds: the largest float keeps lambda = 0
    sigma2 = min(rms * rms, np.finfo(float).max)
    if excitation.is_white:
        return None

    def dual(lam: float) -> tuple[float, float]:
        """The bound at lambda and its derivative sigma^2 - int s*^2 df."""
        corner = math.sqrt(lam / c_m) / (2 * math.pi) if c_m > 0 and lam > 0 else 1.0
        w, weights, g = _weights(m, c_m, excitation, corner)
        denom = c_m * w**2 + lam
        bound = float(np.sum(weights * g / denom)) + lam * sigma2
        return bound, sigma2 - float(np.sum(weights * g / denom**2))

    if c_m == 0:
        # The bracket is int g / lambda + lambda sigma^2, least at
        # lambda = sqrt(int g / sigma^2): P_max = m sigma sqrt(E[a'^2]), finite
        # only for a spectrum of bounded support.
        if not math.isfinite(excitation.support[1]):
            return None
        w, weights, g = _weights(m, c_m, excitation, 1.0)
        return 2.0 * math.sqrt(sigma2 * float(np.sum(weights * g)))
    value, slope = dual(0.0)
    if slope >= 0:  # the unconstrained optimum already meets the budget
        return value
    # lambda where the derivative vanishes (it increases with lambda)
    hi = c_m * (2 * math.pi) ** 2
    while dual(hi)[1] < 0:
        hi *= 10.0
    lam = optimize.brentq(lambda x: dual(x)[1], 0.0, hi, xtol=1e-300, rtol=1e-12)
    return dual(lam)[0]


def record_harvesting_limit(m, c_m, record: Measured, stroke, *, progress: bool = False) -> float:
    """Upper bound on the mean power any transducer takes on this record with |z(t)| <= stroke (W).

    The non-causal bound of Haji Hosseinloo and Turitsyn, Phys. Rev. Applied
    4, 064009 (2015), computed on the record (docs/conventions.md, "The
    limit on a record"): with m z'' + c_m z' + f = -m a, the energy the
    transducer force f takes is int f z' dt = -m int a z' dt - c_m int z'^2 dt
    - (the change of kinetic energy). The record a(t) is the line between
    its samples (as :func:`randvib.monte_carlo_on_record` drives the
    device), its mean removed. Split z' on each sample interval into its
    mean v_i = (z_{i+1} - z_i) / dt and the rest: the rest meets only a's
    departure from its interval mean and takes at most
    m^2 (a_{i+1} - a_i)^2 / (48 c_m) per unit time; the means v_i, with the
    stroke imposed at the samples only (a relaxation), take most when
    ``sum_i (z_{i+1} - z_i - dt b_i)^2``, ``b_i = -m (a_i + a_{i+1}) / (4 c_m)``,
    is least subject to ``-Z <= z_i <= Z`` (a bounded linear least-squares
    problem, :func:`scipy.optimize.lsq_linear`). Together

        P_max = m^2 <a^2> / (4 c_m) - c_m <r^2>,

    with <a^2> the mean square of the interpolated record and r the
    interval velocities' residual: an upper bound on the continuous
    problem. Without an active stroke constraint r = 0 and the optimum is
    z' = -m a / (2 c_m). The kinetic energy's change, a boundary term of at
    most its largest value over the record's length T, is left out. The
    record is solved in chunks of :data:`RECORD_CHUNK` intervals with the
    displacement free to jump between chunks, which relaxes the problem
    further (an upper bound still, slightly looser than the whole-record
    one). The least-squares solution is iterative: its tolerance (1e-10,
    relative) bounds how far below the true minimum residual it can stop.

    Parameters
    ----------
    m : float
        Moving mass (kg), > 0.
    c_m : float
        Mechanical viscous damping (Ns/m), > 0 (with c_m = 0 the optimum
        takes unbounded power).
    record : Measured
        The base acceleration record (m/s^2).
    stroke : float
        Z (m), > 0: the hard bound on |z|.
    progress : bool
        A progress bar over the chunks (about 3 s of CPU per 1000 samples where
        the stroke binds, measured on the development machine; the design on a
        record shows it).

    Returns
    -------
    float
        P_max (W), the time average over the record.
    """
    m = float(check_positive("m", m, "kg"))
    c_m = float(check_positive("c_m", c_m, "Ns/m"))
    stroke = float(check_positive("stroke", stroke, "m"))
    if not isinstance(record, Measured):
        raise ValueError(f"`record` must be a randvib.Measured record, got {type(record).__name__}")
    a = np.asarray(record.acceleration, dtype=float)
    a = a - a.mean()
    dt = float(record.dt)
    # mean square of the line between samples, interval by interval
    square = (a[:-1] ** 2 + a[:-1] * a[1:] + a[1:] ** 2) / 3.0
    target = -m * (a[:-1] + a[1:]) / (4.0 * c_m)  # the unconstrained optimal mean velocity (m/s)
    squares = 0.0
    starts = range(0, target.size, RECORD_CHUNK)
    bar = None
    if progress:
        from randvib._progress import progress_bar

        bar = progress_bar(len(starts), desc="limit on the record", unit="chunk", transient=True)
    for start in starts:
        if bar is not None:
            bar.update(1)
        b = target[start : start + RECORD_CHUNK] * dt  # displacement steps (m)
        n = b.size
        path = np.concatenate([[0.0], np.cumsum(b)])
        if np.ptp(path) <= 2.0 * stroke:
            continue  # the unconstrained path fits (centred in the stroke): no residual
        d = sparse.diags([-np.ones(n), np.ones(n)], [0, 1], shape=(n, n + 1), format="csr")
        scale = stroke  # solve in units of the stroke: the tolerances are then relative
        fit = optimize.lsq_linear(d, b / scale, bounds=(-1.0, 1.0), method="trf",
                                  tol=1e-10, lsmr_tol="auto", max_iter=2000)  # fmt: skip
        squares += float(np.sum((d @ fit.x - b / scale) ** 2)) * scale**2
    if bar is not None:
        bar.close()
    mean_square_residual = squares / dt**2 / target.size  # <r^2>, (m/s)^2
    return m**2 * float(np.mean(square)) / (4.0 * c_m) - c_m * mean_square_residual
