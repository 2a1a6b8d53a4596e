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

A tone, a line of mean square A^2 / 2 at omega, adds the term
m^2 omega^2 A^2 / (8 (c_m omega^2 + lambda)) to the bracket (the same
frequency-by-frequency optimum, on a line spectrum).

It is finite when w^2 G_a / (c_m w^2 + lambda) is integrable: for band-pass,
Kanai-Tajimi, band-limited, tabulated and measured spectra with c_m > 0; for
white noise it is infinite (a transducer that sees the future can take
unbounded power from white acceleration), and :func:`harvesting_limit`
returns None.

What it bounds: every device whose **E[z^2]** is at most sigma^2. A hard
stroke |z| <= d gives E[z^2] <= d^2, so the bound at sigma = d holds for any
device held inside end stops at +-d. A budget on the tail, P(|z| > d) <=
eps, does not bound E[z^2] (a rare large excursion costs little
probability): the bound at the Gaussian sigma_z = d / Phi^-1(1 - eps/2)
holds for every linear (Gaussian) device that meets the budget, not for a
nonlinear one; for any device meeting only the tail budget the bound is the
unconstrained m^2 E[a^2] / (4 c_m).

**The causal bound** (:func:`causal_harvesting_limit`). The optimum above
is a zero-phase filter of the acceleration: it needs the future. A causal
transducer (its force depends on the past only, linear or not, passive or
active) takes at most (docs/conventions.md, "The causal limit")

    P_c(sigma) = min_{lambda >= 0} [ P(lambda) - m^2 L(p)^2 p / (16 c_m) + lambda sigma^2 ],
    p = sqrt(lambda / c_m),

with P(lambda) the bracket's integral above and L the causal (outer)
spectral factor of G_a = |L(i w)|^2, evaluated at the real point s = p:
the Wiener-Hopf solution of max E[-m a z' - c_m z'^2 - lambda z^2] over
causal velocity responses (the anti-causal part of L(s) s / (sqrt(c_m)
(s - p)) is its residue at p, whose share m^2 L(p)^2 p / (16 c_m) a causal
device cannot take). For a rational spectrum L is the shaping filter
(minimum phase); the value is the limit of the linear-quadratic
(Riccati) optimum of the device and the filter as the control penalty
vanishes, and over all causal devices the linear one is best (Gaussian
input, quadratic criterion). Without a budget (lambda = 0) it is the
non-causal m^2 E[a^2] / (4 c_m): z' = -m a / (2 c_m) is causal. Under white
noise it is m S / 4: every device whose force is a finite-variance process
takes the injected m S / 4 less c_m E[z'^2], approached by a stiff, heavily
damped one. A spectrum that vanishes on a band (band-limited, tabulated,
measured: zero outside the table or above Nyquist) fails Paley-Wiener's
condition: its past determines its future, and the causal bound is the
non-causal one (approached only by long-memory prediction).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import linalg as scipy_linalg
from scipy import optimize, sparse, special

from randvib._validation import check_nonnegative, check_positive
from randvib.analytic.linear_response import frequency_rule, mechanical_block
from randvib.models.combined import parts_of
from randvib.models.excitation import Excitation, Measured

__all__ = [
    "RecordLimitCertificate",
    "RecordLimitWarning",
    "causal_harvesting_limit",
    "gaussian_displacement_budget",
    "harvesting_limit",
    "predictable_spectrum",
    "record_harvesting_limit",
    "record_limit_certificate",
]

#: Samples per least-squares problem of :func:`record_harvesting_limit`.
RECORD_CHUNK = 4096
#: Iterations allowed to each least-squares problem of the record bound.
RECORD_MAX_ITER = 2000
#: A record bound whose solver gap exceeds this fraction of it is reported as loose.
RECORD_GAP_TOLERANCE = 1e-6


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


def _lines(m: float, excitation: Excitation) -> tuple[np.ndarray, np.ndarray]:
    """The tones' omega (rad/s) and m^2 omega^2 (A^2 / 2) / 4: lines of the bracket's sum."""
    # a tone is a line of power A^2 / 2 at omega: a term of the sum, not of the integral
    tones = excitation.lines()
    w_lines = np.array([tone.omega for tone in tones], dtype=float)
    return w_lines, m**2 * w_lines**2 * np.array([t.mean_square for t in tones], dtype=float) / 4.0


def _dual(m: float, c_m: float, excitation: Excitation, sigma2: float, lam: float):
    """The non-causal bracket at lambda and its derivative sigma^2 - int s*^2 df (tones included)."""
    corner = math.sqrt(lam / c_m) / (2 * math.pi) if c_m > 0 and lam > 0 else 1.0
    w, weights, g = _weights(m, c_m, excitation, corner)
    w_lines, g_lines = _lines(m, excitation)
    denom = c_m * w**2 + lam
    line_denom = c_m * w_lines**2 + lam
    bound = float(np.sum(weights * g / denom) + np.sum(g_lines / line_denom)) + lam * sigma2
    squares = float(np.sum(weights * g / denom**2) + np.sum(g_lines / line_denom**2))
    return bound, sigma2 - squares


def _least(dual, lam0: float) -> float:
    """The least value of a convex ``dual(lambda) -> (value, slope)`` over lambda >= 0.

    Brackets the zero of the slope (increasing) by factors of 10 from
    ``lam0``; a slope still >= 0 at 1e-20 lam0 puts the least value at 0.
    """
    lo, hi = lam0, lam0
    if dual(lam0)[1] < 0:
        while dual(hi)[1] < 0:
            lo, hi = hi, hi * 10.0
    else:
        while dual(lo)[1] >= 0:
            if lo < lam0 * 1e-20:
                return dual(0.0)[0]
            lo, hi = lo / 10.0, lo
    lam = optimize.brentq(lambda x: dual(x)[1], lo, hi, xtol=1e-300, rtol=1e-12)
    return dual(lam)[0]


def harvesting_limit(m, c_m, excitation: Excitation, displacement_rms) -> float | None:
    """Upper bound on the harvested power of any device with E[z^2] <= sigma^2 (W).

    Non-causal: the bound's optimum needs the acceleration's future (see
    :func:`causal_harvesting_limit` for devices that act on the past). It
    bounds every device with E[z^2] <= sigma^2, hence every device held
    within |z| <= sigma; a budget on P(|z| > d) alone does not bound E[z^2]
    (module docstring).

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
    random = parts_of(excitation)[0]
    if excitation.is_white or (random is not None and random.is_white):
        return None
    if c_m == 0:
        # The bracket is int g / lambda + lambda sigma^2, least at
        # lambda = sqrt(int g / sigma^2): P_max = m sigma sqrt(E[a'^2]), finite
        # only for a spectrum of bounded support.
        if not math.isfinite(excitation.support[1]):
            return None
        w, weights, g = _weights(m, c_m, excitation, 1.0)
        return 2.0 * math.sqrt(
            sigma2 * float(np.sum(weights * g) + np.sum(_lines(m, excitation)[1]))
        )
    value, slope = _dual(m, c_m, excitation, sigma2, 0.0)
    if slope >= 0:  # the unconstrained optimum already meets the budget
        return value
    return _least(lambda x: _dual(m, c_m, excitation, sigma2, x), c_m * (2 * math.pi) ** 2)


def predictable_spectrum(excitation: Excitation) -> bool:
    """True where the spectrum vanishes on a band, so that its past determines its future.

    Paley-Wiener (Szego): a stationary process is regular (has a causal
    innovation) only if ``int log G_a(f) / (1 + f^2) df > -inf``; a spectrum
    that is zero outside ``excitation.support`` (band-limited, tabulated,
    measured: zero above the Nyquist frequency) is not, and there the causal
    bound equals the non-causal one.
    """
    lo, hi = excitation.support
    return not excitation.is_white and (lo > 0.0 or math.isfinite(hi))


def _outer_factor(excitation: Excitation):
    """``p -> (L(p), L'(p))``: the causal spectral factor of a rational spectrum at real p > 0.

    L = sqrt(S) H, H the shaping filter's transfer function
    C (sI - A)^-1 b + D: minimum phase for the band-pass (a zero at s = 0)
    and Kanai-Tajimi (a zero at -omega0 / (2 zeta)) filters, so that
    |L(i w)|^2 is the one-sided PSD and L has no zero in the right
    half-plane. Refuses a filter with a zero there.
    """
    filt = excitation.shaping_filter()
    system = filt.system
    a, b, c, d = system.a, system.b, system.c[0], float(system.d[0])
    n = a.shape[0]
    if n:  # zeros of the filter: the finite eigenvalues of the pencil [[A, b], [C, D]]
        pencil = np.block([[a, b[:, None]], [c[None, :], np.array([[d]])]])
        unit = np.eye(n + 1)
        unit[n, n] = 0.0
        zeros = scipy_linalg.eigvals(pencil, unit)
        zeros = zeros[np.isfinite(zeros)]
        if np.any(zeros.real > 1e-9 * max(1.0, float(np.max(np.abs(np.linalg.eigvals(a)))))):
            raise ValueError(
                f"the {excitation.name} shaping filter has a zero in the right half-plane: "
                "it is not the spectrum's causal factor"
            )
    gain = math.sqrt(filt.noise_psd)

    def factor(p: float) -> tuple[float, float]:
        if not n:
            return gain * d, 0.0
        resolvent = np.linalg.solve(p * np.eye(n) - a, b)
        value = float(c @ resolvent) + d
        slope = -float(c @ np.linalg.solve(p * np.eye(n) - a, resolvent))
        return gain * value, gain * slope

    return factor


def causal_harvesting_limit(m, c_m, excitation: Excitation, displacement_rms) -> float | None:
    """Upper bound on the power of any causal device with E[z^2] <= sigma^2 (W).

    Causal: the transducer's force depends on the past of the motion and of
    the acceleration only (any law, passive or active). The Wiener-Hopf
    bound of the module docstring, ``min_lambda [P(lambda) - m^2 L(p)^2 p /
    (16 c_m) + lambda sigma^2]``: the best linear active transducer under
    the variance budget, approached by the linear-quadratic (Riccati)
    optimum of the device and the excitation's shaping filter as its
    control penalty vanishes; no causal device exceeds it.

    Parameters
    ----------
    m : float
        Moving mass (kg), > 0.
    c_m : float
        Mechanical viscous damping (Ns/m), >= 0.
    excitation : Excitation
        The base acceleration's spectrum.
    displacement_rms : float
        sigma (m), > 0.

    Returns
    -------
    float or None
        P_c (W): ``m S / 4`` under white noise (the injected power, whatever
        the budget: a stiff spring meets it); the non-causal
        :func:`harvesting_limit` for a spectrum that vanishes on a band
        (:func:`predictable_spectrum`); the Wiener-Hopf bound for a rational
        spectrum with c_m > 0; None where no finite bound exists (c_m = 0
        under a rational coloured spectrum) or none is computed (a
        non-rational spectrum of unbounded support; a sum with tones or
        shocks whose spectrum does not vanish on a band).
    """
    m = float(check_positive("m", m, "kg"))
    c_m = float(check_nonnegative("c_m", c_m, "Ns/m"))
    sigma = float(check_positive("displacement_rms", displacement_rms, "m"))
    if excitation.is_white:
        return m * float(excitation.level) / 4.0
    if predictable_spectrum(excitation):
        return harvesting_limit(m, c_m, excitation, sigma)
    if excitation.shaping_filter() is None or c_m == 0:
        return None
    outer = _outer_factor(excitation)
    # a budget whose square is beyond float64 never binds: the largest float keeps lambda = 0
    sigma2 = min(sigma * sigma, np.finfo(float).max)

    def dual(lam: float) -> tuple[float, float]:
        """The causal bracket at lambda and its derivative."""
        value, slope = _dual(m, c_m, excitation, sigma2, lam)
        if lam <= 0.0:
            return value, slope
        p = math.sqrt(lam / c_m)
        factor, dfactor = outer(p)
        share = m * m / (16.0 * c_m)
        # d(L^2 p)/d lambda with dp/d lambda = 1 / (2 c_m p)
        return value - share * factor**2 * p, slope - share * (
            2.0 * factor * dfactor * p + factor**2
        ) / (2.0 * c_m * p)

    f_ref = max((centre for centre, _ in excitation.features()), default=1.0)
    return _least(dual, c_m * (2 * math.pi * f_ref) ** 2)


class RecordLimitWarning(RuntimeWarning):
    """The record bound's least-squares solver stopped short: the bound is valid but loose."""


@dataclass(frozen=True)
class RecordLimitCertificate:
    """The record bound and how far its solver left it from the relaxation's exact value (W).

    Attributes
    ----------
    bound : float
        The certified upper bound (W): the least-squares residual bounded
        below by a dual (Lagrangian) point, so it holds whatever the
        solver's status, plus the initial kinetic energy over the record's
        length.
    at_solver_point : float
        The same expression at the solver's primal point (W): the relaxation's
        exact value lies between it and ``bound``.
    gap : float
        ``bound - at_solver_point`` (W), >= 0.
    converged : bool
        Every least-squares problem met its tolerance (``lsq_linear`` status > 0).
    duration : float
        The record's length T (s).
    """

    bound: float
    at_solver_point: float
    gap: float
    converged: bool
    duration: float


def record_limit_certificate(
    m, c_m, record: Measured, stroke, *, initial_kinetic_energy=0.0, progress: bool = False
) -> RecordLimitCertificate:
    """:func:`record_harvesting_limit` with its dual certificate (see there).

    Each chunk's bounded least-squares problem ``min ||D x - b||^2``,
    ``-1 <= x <= 1``, has the Lagrangian dual
    ``g(y) = -||y||^2 - 2 y.b - 2 ||D^T y||_1 <= min`` for every y; at
    ``y = t r`` with r the solver's residual and the best t,
    ``g = max(0, -(r.b + ||D^T r||_1))^2 / ||r||^2``, equal to the minimum
    at the exact solution. The bound uses g (a residual never above the
    true least one), so a solver that stopped early gives a looser bound,
    never a wrong one.
    """
    m = float(check_positive("m", m, "kg"))
    c_m = float(check_positive("c_m", c_m, "Ns/m"))
    stroke = float(check_positive("stroke", stroke, "m"))
    kinetic = float(check_nonnegative("initial_kinetic_energy", initial_kinetic_energy, "J"))
    if not isinstance(record, Measured):
        raise ValueError(f"`record` must be a randvib.Measured record, got {type(record).__name__}")
    a = np.asarray(record.acceleration, dtype=float)
    a = a - a.mean()
    dt = float(record.dt)
    # mean square of the line between samples, interval by interval
    square = (a[:-1] ** 2 + a[:-1] * a[1:] + a[1:] ** 2) / 3.0
    target = -m * (a[:-1] + a[1:]) / (4.0 * c_m)  # the unconstrained optimal mean velocity (m/s)
    lower = upper = 0.0  # sums of squared displacement residuals (m^2): dual and primal
    converged = True
    starts = range(0, target.size, RECORD_CHUNK)
    bar = None
    if progress:
        from randvib._progress import progress_bar

        bar = progress_bar(len(starts), desc="limit on the record", unit="chunk", transient=True)
    for start in starts:
        if bar is not None:
            bar.update(1)
        b = target[start : start + RECORD_CHUNK] * dt  # displacement steps (m)
        dual, primal, ok = _chunk_residual(b, stroke)
        lower, upper, converged = lower + dual, upper + primal, converged and ok
    if bar is not None:
        bar.close()
    duration = target.size * dt
    unconstrained = m**2 * float(np.mean(square)) / (4.0 * c_m) + kinetic / duration
    per_time = c_m / dt**2 / target.size  # (W/m^2): <r^2> c_m from a sum of squared steps
    bound, at_point = unconstrained - per_time * lower, unconstrained - per_time * upper
    return RecordLimitCertificate(bound, at_point, bound - at_point, converged, duration)


def _chunk_residual(b: np.ndarray, stroke: float) -> tuple[float, float, bool]:
    """(dual lower bound, solver's value, converged) of min ||D z - b||^2 with |z| <= stroke (m^2).

    D the (n, n + 1) difference matrix; solved in units of the stroke, so the
    tolerances are relative.
    """
    n = b.size
    path = np.concatenate([[0.0], np.cumsum(b)])
    if np.ptp(path) <= 2.0 * stroke:
        return 0.0, 0.0, True  # the unconstrained path fits (centred in the stroke): no residual
    d = sparse.diags([-np.ones(n), np.ones(n)], [0, 1], shape=(n, n + 1), format="csr")
    scaled = b / stroke
    fit = optimize.lsq_linear(d, scaled, bounds=(-1.0, 1.0), method="trf", tol=1e-10,
                              lsmr_tol="auto", max_iter=RECORD_MAX_ITER)  # fmt: skip
    x = np.clip(fit.x, -1.0, 1.0)
    r = d @ x - scaled
    squares = float(r @ r)
    weight = -(float(r @ scaled) + float(np.sum(np.abs(d.T @ r))))
    dual = max(weight, 0.0) ** 2 / squares if squares > 0 else 0.0
    return min(dual, squares) * stroke**2, squares * stroke**2, fit.status > 0


def record_harvesting_limit(
    m, c_m, record: Measured, stroke, *, initial_kinetic_energy=0.0, progress: bool = False
) -> float:
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

        P_max = m^2 <a^2> / (4 c_m) - c_m <r^2> + KE(0) / T,

    with <a^2> the mean square of the interpolated record and r the
    interval velocities' residual: an upper bound on the continuous
    problem. Without an active stroke constraint r = 0 and the optimum is
    z' = -m a / (2 c_m). The kinetic energy's change is bounded by its value
    at the start, ``initial_kinetic_energy`` (0: a device at rest when the
    record starts; one already moving can take up to KE(0) / T more). The
    record is solved in chunks of :data:`RECORD_CHUNK` intervals with the
    displacement free to jump between chunks, which relaxes the problem
    further (an upper bound still, slightly looser than the whole-record
    one). The least-squares residual is certified from below by a dual
    point (:func:`record_limit_certificate`), so the bound holds whatever
    the iterative solver's status; where it stopped short and the gap
    exceeds :data:`RECORD_GAP_TOLERANCE` of the bound, a
    :class:`RecordLimitWarning` says by how much the bound may be loose.

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
    initial_kinetic_energy : float
        KE(0) = m z'(0)^2 / 2 (J), >= 0, of the device when the record starts.
    progress : bool
        A progress bar over the chunks (about 3 s of CPU per 1000 samples where
        the stroke binds, measured on the development machine; the design on a
        record shows it).

    Returns
    -------
    float
        P_max (W), the time average over the record.
    """
    certificate = record_limit_certificate(
        m, c_m, record, stroke, initial_kinetic_energy=initial_kinetic_energy, progress=progress
    )
    if certificate.gap > RECORD_GAP_TOLERANCE * abs(certificate.bound):
        how = "met its tolerance" if certificate.converged else "stopped at its iteration limit"
        warnings.warn(
            f"the record bound's least-squares solver {how}: the bound "
            f"{certificate.bound:.6g} W holds (a dual certificate), but the relaxation's exact "
            f"value may be up to {certificate.gap:.3g} W "
            f"({certificate.gap / certificate.bound:.2%}) lower",
            RecordLimitWarning,
            stacklevel=2,
        )
    return certificate.bound
