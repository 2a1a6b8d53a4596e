"""Non-Gaussian stationary vibration: a translation process with a target spectrum and marginal.

Vehicles, rail and footsteps give vibration of kurtosis 4 to 10 that a
Gaussian process of the same spectrum does not describe. A translation
process (Grigoriu 1984; docs/conventions.md, "Translation process") is

    x(t) = sigma g(y(t)),    g(y) = Q(Phi(y)),

with y a stationary Gaussian process of unit variance, Phi its distribution
function, Q the quantile function of the target marginal standardised to
mean 0 and variance 1, and sigma^2 the target spectrum's variance. x has the
target marginal exactly; its correlation is ``sigma^2 h(rho_y(tau))`` with
``h(rho) = E[g(Y1) g(Y2)]`` for standard normals of correlation rho, so its
spectrum is not y's. The spectrum of y is therefore corrected until x has
the target: the iterative translation approximation method (ITAM) of
Shields, Deodatis and Bocchini (2011, Probabilistic Engineering Mechanics
26, 511-519),

    S_y <- S_y S_T / S_x(S_y),

on a frequency grid, S_x computed from h applied to S_y's correlation
(:func:`itam`). A spectrum and a marginal need not be compatible; the
residual ``translation_error`` = ||S_x - S_T|| / ||S_T|| is reported, and a
pair whose residual exceeds :data:`MAX_TRANSLATION_ERROR` is refused.

The marginal (:class:`Marginal`) is given by its kurtosis (a generalised
normal distribution, shape beta: kurtosis Gamma(5/b) Gamma(1/b) / Gamma(3/b)^2,
from 1.8, the uniform, at beta -> inf, through 3, the Gaussian, at beta = 2,
to 6, the Laplace, at beta = 1, and beyond), by a table of its density, or
by a record's samples (its histogram: the empirical distribution).

Monte Carlo synthesises y with the corrected spectrum path by path
(:func:`randvib.models.excitation.synthesised_values`, each path's normals
from its own stream) at the steps' midpoints and integrates x over each step
by the midpoint rule (:mod:`randvib.montecarlo.driven`). The analytic
methods are Gaussian: they answer with the target spectrum, exact for the
second moments of a linear device (which depend on the spectrum only), and
warn naming the kurtosis where their measured limit says the Gaussian answer
errs (:mod:`randvib.analytic.method`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, special

from randvib._validation import check_finite, check_nonnegative, check_positive, check_scalar
from randvib.models.excitation import (
    Excitation,
    Tabulated,
    as_excitation,
    synthesised_values,
)

#: Largest relative spectral residual ||S_x - S_T|| / ||S_T|| of the translation
#: accepted: beyond it the spectrum and the marginal are refused as incompatible.
MAX_TRANSLATION_ERROR = 0.05
#: Kurtosis of the uniform distribution: the smallest a generalised normal reaches.
MIN_KURTOSIS = 1.8
#: Share of the spectrum's power the translation may leave above its top frequency
#: (a spectrum with unbounded support, band-pass or Kanai-Tajimi, is cut there).
TAIL_POWER = 1e-3
#: Iterations of ITAM.
ITAM_ITERATIONS = 60

_Y_MAX = 8.5  # standard normal range of the tabulated translation g(y)
_Y_GRID = np.linspace(-_Y_MAX, _Y_MAX, 4097)
_Y_STEP = _Y_GRID[1] - _Y_GRID[0]
_HERMITE_X, _HERMITE_W = np.polynomial.hermite_e.hermegauss(80)
_HERMITE_W = _HERMITE_W / np.sqrt(2.0 * np.pi)  # E[f(Y)] = sum w f(x)


def _generalised_normal_kurtosis(beta):
    lg = special.gammaln
    return np.exp(lg(5.0 / beta) + lg(1.0 / beta) - 2.0 * lg(3.0 / beta))


@dataclass(frozen=True, eq=False)
class Marginal:
    """A marginal distribution, standardised to mean 0 and variance 1, as a translation.

    Build it with :meth:`from_kurtosis`, :meth:`from_table` or
    :meth:`from_samples`. It holds the translation ``g(y) = Q(Phi(y))`` on a
    grid of y (standard normal values), standardised so that E[g(Y)] = 0 and
    E[g(Y)^2] = 1 under the quadrature every consumer uses.

    Attributes
    ----------
    kind : str
        ``"kurtosis"``, ``"table"`` or ``"samples"``.
    translation : ndarray
        g on :data:`_Y_GRID`, non-decreasing.
    description : dict
        What it was built from (JSON-ready).
    """

    kind: str
    translation: np.ndarray = field(repr=False)
    description: dict

    @classmethod
    def from_kurtosis(cls, kurtosis: float) -> Marginal:
        """The generalised normal distribution of this kurtosis (symmetric).

        Raises
        ------
        ValueError
            Below :data:`MIN_KURTOSIS` (the uniform's 1.8: no symmetric
            unimodal distribution is flatter), or beyond 1e3.
        """
        k = float(check_finite("kurtosis", check_scalar("kurtosis", kurtosis, "one marginal")))
        if not MIN_KURTOSIS < k <= 1e3:
            raise ValueError(
                f"`kurtosis` must be > {MIN_KURTOSIS:g} (the uniform distribution, the flattest "
                f"a translation's generalised-normal marginal reaches) and <= 1000, got {k:g}"
            )
        if abs(k - 3.0) < 1e-12:
            beta = 2.0
        else:
            beta = optimize.brentq(lambda b: _generalised_normal_kurtosis(b) - k, 0.05, 1e3)
        from scipy import stats  # here, not at import: see _from_cdf

        law = stats.gennorm(beta)
        y = _Y_GRID
        # the upper half from the survival functions, accurate in the far tail
        upper = law.isf(stats.norm.sf(np.abs(y)))
        values = np.sign(y) * upper
        return cls._standardised("kurtosis", values, {"kurtosis": k, "beta": float(beta)})

    @classmethod
    def from_table(cls, values, density) -> Marginal:
        """A density tabulated at increasing ``values`` (any unit: it is standardised).

        Linearly interpolated, zero outside the table; its mean and scale are
        removed (the spectrum sets the variance).
        """
        x = check_finite("values", values)
        p = check_nonnegative("density", density)
        if x.ndim != 1 or x.size < 3 or p.shape != x.shape or np.any(np.diff(x) <= 0):
            raise ValueError(
                "`values` and `density` must be 1-D of the same length >= 3, `values` strictly "
                f"increasing; got shapes {x.shape} and {p.shape}"
            )
        cdf = np.concatenate([[0.0], np.cumsum(np.diff(x) * 0.5 * (p[1:] + p[:-1]))])
        if not cdf[-1] > 0:
            raise ValueError("`density` must be > 0 somewhere: the table has no probability")
        return cls._from_cdf("table", x, cdf / cdf[-1], {"points": int(x.size)})

    @classmethod
    def from_samples(cls, samples) -> Marginal:
        """The empirical distribution of a record's samples (its histogram, at full resolution)."""
        x = np.sort(check_finite("samples", np.ravel(samples)))
        if x.size < 64 or x[-1] == x[0]:
            raise ValueError(
                f"`samples` must hold at least 64 values that are not all equal, got {x.size}"
            )
        cdf = (np.arange(x.size) + 0.5) / x.size  # plotting positions
        a = x - x.mean()
        kurt = float(np.mean(a**4) / np.mean(a**2) ** 2)
        return cls._from_cdf("samples", x, cdf, {"samples": int(x.size), "sample_kurtosis": kurt})

    @classmethod
    def _from_cdf(cls, kind, x, cdf, description) -> Marginal:
        # scipy.stats is imported here, not with the module: the Monte Carlo layer imports
        # this module (input checks), and a sweep's worker paid a second of CPU for it
        from scipy import stats

        keep = np.concatenate([[True], np.diff(cdf) > 0])  # a strictly increasing cdf to invert
        values = np.interp(stats.norm.cdf(_Y_GRID), cdf[keep], x[keep])
        return cls._standardised(kind, values, description)

    @classmethod
    def _standardised(cls, kind, values, description) -> Marginal:
        mean = float(np.sum(_HERMITE_W * np.interp(_HERMITE_X, _Y_GRID, values)))
        centred = values - mean
        scale = np.sqrt(float(np.sum(_HERMITE_W * np.interp(_HERMITE_X, _Y_GRID, centred) ** 2)))
        return cls(kind, centred / scale, description)

    def g(self, y) -> np.ndarray:
        """The standardised translation g(y) = Q(Phi(y)), linear between the grid's points.

        Constant beyond |y| = 8.5 (probability 2e-17). The grid is uniform: the
        interval is found by arithmetic, not by search (millions of samples a path).
        """
        u = (np.clip(np.asarray(y, dtype=float), -_Y_MAX, _Y_MAX) + _Y_MAX) / _Y_STEP
        i = np.minimum(u.astype(np.int64), _Y_GRID.size - 2)
        t = self.translation
        return t[i] + (u - i) * (t[i + 1] - t[i])

    def moment(self, order: int) -> float:
        """E[g(Y)^order] under the Gauss-Hermite rule (0, 1 for orders 1, 2)."""
        return float(np.sum(_HERMITE_W * self.g(_HERMITE_X) ** order))

    @property
    def kurtosis(self) -> float:
        """E[g^4]: the marginal's kurtosis (its variance is 1)."""
        return self.moment(4)

    @property
    def skewness(self) -> float:
        """E[g^3] (0 for a symmetric marginal, its rounding noise below 1e-12 cleared)."""
        value = self.moment(3)
        return 0.0 if abs(value) < 1e-12 else value

    @functools.cached_property
    def correlation_map(self) -> tuple[np.ndarray, np.ndarray]:
        """(rho, h(rho)): the translation's correlation against the Gaussian's, on [-1, 1].

        h(rho) = E[g(Y1) g(Y2)], Y2 = rho Y1 + sqrt(1 - rho^2) W, by a 2-D
        Gauss-Hermite rule; normalised so that h(1) = 1 exactly. Increasing
        in rho (Grigoriu), so it is inverted by interpolation.
        """
        rho = np.linspace(-1.0, 1.0, 401)
        y1, w = _HERMITE_X[:, None, None], _HERMITE_X[None, :, None]
        y2 = rho * y1 + np.sqrt(1.0 - rho**2) * w
        weights = (_HERMITE_W[:, None] * _HERMITE_W[None, :])[..., None]
        h = np.sum(weights * self.g(y1) * self.g(y2), axis=(0, 1))
        return rho, h / h[-1]


@dataclass(frozen=True)
class TranslationFit:
    """ITAM's result on a frequency grid (one-sided, per-bin powers).

    Attributes
    ----------
    frequency : ndarray
        Bins f_k = k df (Hz) up to ``top``.
    gaussian : ndarray
        PSD of the underlying Gaussian y, normalised to unit variance (1/Hz).
    achieved : ndarray
        PSD of x = sigma g(y) ((m/s^2)^2/Hz): the process Monte Carlo simulates.
    target : ndarray
        The target PSD on the grid ((m/s^2)^2/Hz).
    error : float
        ||S_x - S_T|| / ||S_T|| over the grid.
    iterations : int
    variance : float
        The target's power on the grid ((m/s^2)^2): x = sqrt(variance) g(y).
    """

    frequency: np.ndarray
    gaussian: np.ndarray
    achieved: np.ndarray
    target: np.ndarray
    error: float
    iterations: int
    variance: float


def _covariance(power: np.ndarray) -> np.ndarray:
    """R_j = sum_k P_k cos(2 pi k j / n), n = 2 (N - 1): the cosine series of bin powers."""
    n = 2 * (power.size - 1)
    x = 0.5 * n * power
    x[0], x[-1] = n * power[0], n * power[-1]
    return np.fft.irfft(x, n)


def _powers(covariance: np.ndarray, size: int) -> np.ndarray:
    """The bin powers P_k whose cosine series is ``covariance`` (inverse of :func:`_covariance`)."""
    n = covariance.size
    x = np.fft.rfft(covariance).real
    power = 2.0 * x / n
    power[0], power[-1] = x[0] / n, x[-1] / n
    return power[:size]


def itam(target, marginal: Marginal, top: float, df: float, iterations=ITAM_ITERATIONS):
    """The iterative translation approximation method (Shields, Deodatis and Bocchini 2011).

    Parameters
    ----------
    target : Excitation
        Target spectrum S_T.
    marginal : Marginal
        Standardised marginal.
    top : float
        Highest frequency of the grid (Hz).
    df : float
        Grid step (Hz).

    Returns
    -------
    TranslationFit
        The corrected Gaussian spectrum of the iteration with the smallest residual.
    """
    f = np.arange(int(np.floor(top / df * (1 + 1e-12))) + 1) * df  # the last bin at or below top
    target_psd = np.asarray(target.psd(f), dtype=float)
    p_target = target_psd * df
    p_target[0] *= 0.5
    p_target[-1] *= 0.5
    variance = float(np.sum(p_target))
    rho_grid, h_grid = marginal.correlation_map
    p_gauss = p_target / variance
    norm = np.sqrt(np.sum(p_target**2))
    best = None
    history = []
    for i in range(iterations + 1):
        r = _covariance(p_gauss)
        rho = np.clip(r / r[0], -1.0, 1.0)
        p_x = np.maximum(_powers(variance * np.interp(rho, rho_grid, h_grid), f.size), 0.0)
        error = float(np.sqrt(np.sum((p_x - p_target) ** 2)) / norm)
        history.append(error)
        if best is None or error < best[0]:
            best = (error, p_gauss / np.sum(p_gauss), p_x, i)
        # done, converged, or stalled (no 1 % gain in five iterations: the residual
        # left is what no Gaussian spectrum can remove, such as power the
        # translation puts outside a band-limited target)
        if i == iterations or error < 1e-6 or (i >= 5 and history[-6] - error < 0.01 * error):
            break
        ratio = np.divide(p_target, p_x, out=np.zeros_like(p_x), where=p_x > 0)
        p_gauss = np.where(p_x > 0, p_gauss * ratio, p_gauss)
        p_gauss = np.where(p_target > 0, p_gauss, 0.0)
    error, p_gauss, p_x, used = best
    cell = np.full(f.size, df)
    cell[0] = cell[-1] = 0.5 * df
    return TranslationFit(f, p_gauss / cell, p_x / cell, target_psd, error, used, variance)


#: The translation's harmonics reach this multiple of the frequency below which 99 %
#: of the target's power lies (a cubic-like g triples frequencies; more is negligible).
HARMONIC_REACH = 4.0


def _top_frequency(spectrum: Excitation) -> float:
    """The top of the translation's grid (Hz): room for the target and the harmonics g adds.

    The larger of the top of the target's support (or, for an unbounded one,
    where the tail above holds :data:`TAIL_POWER` of the power) and
    :data:`HARMONIC_REACH` times the frequency below which 99 % of it lies:
    the translation x = g(y) puts power at sums of y's frequencies, which a
    grid ending at the target's top would fold back (alias) into the band.
    """
    lo, hi = spectrum.support
    scale = max([fc + w for fc, w in spectrum.features()] + list(spectrum.breakpoints()) + [1e-3])
    end = hi if np.isfinite(hi) else 1e6 * scale
    grid = np.unique(
        np.concatenate([np.geomspace(1e-6 * scale, end, 20001), spectrum.breakpoints()])
    )
    grid = grid[(grid >= lo) & (grid <= end)]
    density = spectrum.psd(grid)
    cumulative = np.concatenate(
        [[0.0], np.cumsum(np.diff(grid) * 0.5 * (density[1:] + density[:-1]))]
    )
    total = cumulative[-1]
    main = float(grid[np.searchsorted(cumulative, 0.99 * total)])
    top = hi if np.isfinite(hi) else grid[np.searchsorted(cumulative, (1.0 - TAIL_POWER) * total)]
    return float(max(top, HARMONIC_REACH * main))


def _grid_step(spectrum: Excitation, top: float) -> float:
    """A step that resolves the spectrum's narrowest peak (a tenth of its half-width)."""
    widths = [w for _, w in spectrum.features() if w > 0]
    step = top / 4096
    if widths:
        step = min(step, 0.1 * min(widths))
    return max(step, top / 2**19)


@dataclass(frozen=True, eq=False)
class Translated(Excitation, registered=False):
    """Non-Gaussian stationary base acceleration: a target spectrum and a target marginal.

    Parameters
    ----------
    spectrum : Excitation
        The target spectrum: any excitation of finite variance (band-pass,
        Kanai-Tajimi, band-limited, tabulated, measured); not white noise.
        One of unbounded support is cut at the translation's :attr:`top`,
        where :data:`TAIL_POWER` of its power lies above: the process
        described (``psd``, ``variance``, ``support``) is the one simulated.
    marginal : Marginal or float
        The target marginal (standardised; the spectrum sets its variance),
        or a number: its kurtosis (:meth:`Marginal.from_kurtosis`).

    Raises
    ------
    ValueError
        For white noise, a kurtosis out of range, or a spectrum and marginal
        that no translation reaches (:data:`MAX_TRANSLATION_ERROR`).

    Examples
    --------
    >>> import randvib as rv
    >>> x = rv.Translated(rv.BandLimited(0.1, 4.0, 20.0), 6.0)
    >>> round(x.kurtosis, 3), round(x.translation_error, 3)
    (6.0, 0.022)
    """

    spectrum: Excitation
    marginal: Marginal
    name = "translated"
    is_gaussian = False

    def __post_init__(self):
        spectrum = as_excitation(self.spectrum)
        if spectrum.is_white or not spectrum.is_gaussian:
            what = "white noise (infinite variance)" if spectrum.is_white else spectrum.name
            raise ValueError(
                f"`spectrum` of a translation process must be a Gaussian spectrum of finite "
                f"variance (band-pass, kanai-tajimi, band-limited, tabulated), got {what}"
            )
        marginal = self.marginal
        if not isinstance(marginal, Marginal):
            marginal = Marginal.from_kurtosis(marginal)
        object.__setattr__(self, "spectrum", spectrum)
        object.__setattr__(self, "marginal", marginal)
        if self.translation_error > MAX_TRANSLATION_ERROR:
            raise ValueError(
                f"no translation process has the {spectrum.name} spectrum with this marginal "
                f"(kurtosis {marginal.kurtosis:.3g}): the closest differs from the target "
                f"spectrum by {self.translation_error:.1%} (allowed "
                f"{MAX_TRANSLATION_ERROR:.0%}); use a marginal closer to the Gaussian's "
                "(`kurtosis` nearer 3)"
            )

    @functools.cached_property
    def fit(self) -> TranslationFit:
        """ITAM's corrected Gaussian spectrum (:func:`itam`) on its own grid, computed once."""
        return self.fit_below(_top_frequency(self.spectrum))

    def fit_below(self, top: float) -> TranslationFit:
        """ITAM's fit on a grid ending at ``top`` (Hz), computed once per top.

        A simulation whose Nyquist frequency lies below the translation's own
        top (:attr:`top`) simulates the translation of the spectrum cut there,
        as it simulates any input only up to its Nyquist frequency.
        """
        fits = self.__dict__.setdefault("_fits", {})
        if top not in fits:
            fits[top] = itam(self.spectrum, self.marginal, top, _grid_step(self.spectrum, top))
        return fits[top]

    @property
    def translation_error(self) -> float:
        """||S_x - S_T|| / ||S_T||: how far the translation's spectrum is from the target."""
        return self.fit.error

    @property
    def top(self) -> float:
        """The highest frequency the translation holds (Hz); the simulation must resolve it."""
        return float(self.fit.frequency[-1])

    def gaussian_spectrum(self, top: float | None = None) -> Tabulated:
        """The underlying Gaussian's corrected PSD, unit variance (1/Hz), up to ``top`` (Hz)."""
        fit = self.fit if top is None or top >= self.top else self.fit_below(top)
        return Tabulated(fit.frequency, fit.gaussian)

    def achieved_spectrum(self, top: float | None = None) -> Tabulated:
        """The translation's own PSD ((m/s^2)^2/Hz) up to ``top`` (Hz): the process simulated.

        Near the target (:attr:`translation_error`); ``top`` below the
        translation's own top gives that of the spectrum cut there, which a
        simulation of Nyquist frequency ``top`` draws.
        """
        fit = self.fit if top is None or top >= self.top else self.fit_below(top)
        return Tabulated(fit.frequency, fit.achieved)

    # The declarations every consumer reads are the target spectrum's up to the
    # translation's top, above which the process holds no power (a spectrum of
    # unbounded support is cut where TAIL_POWER of its power lies above).
    def psd(self, frequency):
        f = np.asarray(frequency, dtype=float)
        return np.where(f <= self.top, self.spectrum.psd(f), 0.0)

    @property
    def variance(self) -> float:
        """The target's power below the translation's top ((m/s^2)^2): the process's variance."""
        return self.fit.variance

    @property
    def support(self):
        lo, hi = self.spectrum.support
        return lo, min(hi, self.top)

    def features(self):
        return self.spectrum.features()

    def breakpoints(self):
        return tuple(b for b in self.spectrum.breakpoints() if b <= self.top) + (self.top,)

    def cumulative_power(self, frequency):
        return self.spectrum.cumulative_power(np.minimum(frequency, self.top))

    @property
    def kurtosis(self) -> float:
        return self.marginal.kurtosis

    @property
    def level(self):
        """The target spectrum's level ((m/s^2)^2/Hz), where it has one."""
        return getattr(self.spectrum, "level", None)

    def scaled(self, factor: float) -> Translated:
        factor = float(check_positive("factor", factor))
        return Translated(self.spectrum.scaled(factor), self.marginal)

    def values(self, n: int, dt: float, normals, offset: float = 0.0) -> np.ndarray:
        """x at the times j dt + offset of the paths whose Gaussian normals are ``normals``.

        The Gaussian y is synthesised with the corrected spectrum
        (:func:`randvib.models.excitation.synthesised_values`, unit variance)
        and translated: x = sigma g(y), sigma^2 the target's power on the fit's
        grid; a Nyquist frequency 1/(2 dt) below the translation's top
        simulates the translation of the spectrum cut there (:meth:`fit_below`).
        """
        fit = self.fit if 0.5 / dt >= self.top else self.fit_below(0.5 / dt)
        y = synthesised_values(Tabulated(fit.frequency, fit.gaussian), n, dt, normals, offset)
        return np.sqrt(fit.variance) * self.marginal.g(y)

    def sample(self, duration: float, dt: float, n_paths: int = 1, seed=None) -> np.ndarray:
        """Paths of the translation process (m/s^2) at the times j dt, shape (n_paths, n)."""
        n = int(round(float(check_positive("duration", duration, "s")) / dt))
        size = n // 2 + 1
        normals = np.random.default_rng(seed).standard_normal((n_paths, 2 * size))
        return self.values(n, dt, normals)

    def parameters(self) -> dict:
        spectrum = self.spectrum.parameters()
        out = {"excitation": self.name, "spectrum": spectrum.pop("excitation")}
        out.update(spectrum)
        out.update(
            marginal=self.marginal.kind,
            kurtosis=self.kurtosis,
            skewness=self.marginal.skewness,
            translation_error=self.translation_error,
            **{f"marginal_{k}": v for k, v in self.marginal.description.items() if k != "kurtosis"},
        )
        return out

    def __repr__(self) -> str:
        return (
            f"Translated({self.spectrum!r}, kurtosis {self.kurtosis:.4g}, "
            f"spectral residual {self.translation_error:.2%})"
        )
