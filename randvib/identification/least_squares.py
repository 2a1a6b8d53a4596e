"""Local least-squares polish of the simulation error and the parameters' uncertainty.

After the global search (:func:`randvib.identification.sade.sade`) has found
the basin, the simulation error

    e_i(theta) = zhat_i(theta) + z_off - z_i,   i = skip, ..., N - 1

(the measured output is the model's plus the sensor's offset) is minimised
by :func:`scipy.optimize.least_squares` (trust-region reflective, the search
box as bounds for the model's parameters). Its sum of squares is J (paper
Eq. 11) up to the constant ``100 / (N sigma_z^2)``, so the polish lowers the
paper's cost directly. The vector theta holds the model's free parameters
and the measurement model's: output offset, input offset, quadratic
stiffness, and the initial state (z0, z'0) when it is estimated.

The Jacobian is taken by central differences, every perturbed parameter set
simulated in one batched compiled call (:func:`run_kernel`): 2 d
simulations per Jacobian, run in parallel.

Uncertainty (:class:`Uncertainty`): at the optimum, with the Jacobian J of e
and the noise variance estimated from the residuals,
``s^2 = sum e^2 / (N - d)``, the covariance of the estimate is
``s^2 (J^T J)^-1`` (Gauss-Newton / asymptotic least-squares theory: exact to
first order for white Gaussian output noise, the errors-in-the-output
setting). Standard errors are its diagonal's roots, 95 % intervals
``theta +- t_{0.975, N - d} se``. When the residual is not white (Ljung-Box
at 1 %) the covariance is the sandwich with the residual's fitted
autoregressive covariance instead (:func:`covariance`), right for coloured
output noise. Noise on the input makes the model wrong, not only the noise
coloured: its estimates are biased, and no interval covers a bias.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from randvib.identification.record_integrator import (
    OUTPUT_OFFSET_COLUMN,
    SEARCH_SUBCYCLES,
    parameter_matrix,
)

#: Names of the initial-state coordinates in the least-squares vector.
INITIAL_STATE = ("z0", "v0")
#: Relative central-difference step in the optimiser's scaled variables.
JACOBIAN_STEP = 1e-5
#: Relative central-difference step of the Jacobian the covariance is computed from.
#: Larger than the polish's: a response with friction is not smooth in the
#: parameters at the scale of 1e-5 (stick-slip and switching instants move by
#: a sub-step), and differences that small made the standard errors of k and k3
#: vary threefold between noise realisations of one record; at 1e-3 and 1e-2,
#: the scale of the standard errors themselves, they agree within 10 %
#: (measured on tests/calibration/hac_coverage.py's records).
COVARIANCE_STEP = 1e-3


@dataclass(frozen=True)
class Coordinates:
    """The least-squares vector: names, which are log-scaled, scales, bounds.

    A log-scaled parameter is optimised as ``log(theta)``, the others as
    ``theta / scale``, so that every coordinate moves by O(1) and one
    difference step suits all.
    """

    names: tuple
    log: np.ndarray
    scale: np.ndarray
    lower: np.ndarray
    upper: np.ndarray

    def to_u(self, theta):
        theta = np.asarray(theta, dtype=float)
        return np.where(self.log, np.log(np.where(self.log, theta, 1.0)), theta / self.scale)

    def to_theta(self, u):
        u = np.asarray(u, dtype=float)
        return np.where(self.log, np.exp(np.where(self.log, u, 0.0)), u * self.scale)

    def u_bounds(self):
        return self.to_u_bound(self.lower), self.to_u_bound(self.upper)

    def to_u_bound(self, bound):
        out = np.empty_like(bound)
        for j, b in enumerate(bound):
            if not np.isfinite(b):
                out[j] = b
            elif self.log[j]:
                out[j] = np.log(b)
            else:
                out[j] = b / self.scale[j]
        return out


class SimulationError:
    """e(theta) of one model on one record, and its batched Jacobian.

    Parameters
    ----------
    cost : CostFunction
        Gives the record, model, fixed parameters, driving signal, start.
    coordinates : Coordinates
    """

    def __init__(self, cost, coordinates: Coordinates):
        self.cost = cost
        self.coordinates = coordinates
        self.names = coordinates.names
        self.measured = cost.record.z[cost.skip :]
        self.simulations = 0

    def named(self, thetas) -> dict:
        """Rows of theta as named columns, with the fixed values and the start."""
        thetas = np.atleast_2d(thetas)
        out = {name: np.full(thetas.shape[0], float(v)) for name, v in self.cost.fixed.items()}
        out.update({name: thetas[:, j] for j, name in enumerate(self.names)})
        out.setdefault("z0", np.full(thetas.shape[0], self.cost.z0))
        out.setdefault("v0", np.full(thetas.shape[0], self.cost.v0))
        return out

    def responses(self, thetas) -> np.ndarray:
        """Measured-output predictions ``zhat + z_off`` (rows: parameter sets)."""
        named = self.named(thetas)
        z0, v0 = named.pop("z0"), named.pop("v0")
        matrix = parameter_matrix(named, self.cost.friction)
        # bristles stiffer than the search allows are rejected here too (NaN):
        # otherwise one trial step can cost thousands of sub-cycles per step
        z = self.cost.run(matrix, z0=z0, v0=v0, max_subcycles=SEARCH_SUBCYCLES).z
        self.simulations += matrix.shape[0]
        return z[:, self.cost.skip :] + matrix[:, OUTPUT_OFFSET_COLUMN, None]

    def residuals_u(self, u) -> np.ndarray:
        e = self.responses(self.coordinates.to_theta(u))[0] - self.measured
        # a diverged candidate: large finite residuals steer the polish back
        return np.where(np.isfinite(e), e, 1e3 * np.std(self.measured))

    def jacobian_u(self, u, step: float = JACOBIAN_STEP) -> np.ndarray:
        """de/du by central differences of relative ``step``, all 2 d simulations in one batch."""
        d = u.size
        steps = self.difference_steps(u, step)
        lo, hi = self.coordinates.u_bounds()
        plus = np.minimum(u + steps, np.where(np.isfinite(hi), hi, np.inf))
        minus = np.maximum(u - steps, np.where(np.isfinite(lo), lo, -np.inf))
        rows = np.repeat(u[None, :], 2 * d, axis=0)
        rows[np.arange(d), np.arange(d)] = plus
        rows[d + np.arange(d), np.arange(d)] = minus
        z = self.responses(self.coordinates.to_theta(rows))
        ok_plus = np.all(np.isfinite(z[:d]), axis=1)
        ok_minus = np.all(np.isfinite(z[d:]), axis=1)
        if not (ok_plus.all() and ok_minus.all()):
            # a rejected side: one-sided difference from the centre instead
            centre = self.responses(self.coordinates.to_theta(u[None, :]))[0]
            z[:d][~ok_plus] = centre
            z[d:][~ok_minus] = centre
            plus = np.where(ok_plus, plus, u)
            minus = np.where(ok_minus, minus, u)
        width = np.where(plus > minus, plus - minus, 1.0)
        z = np.where(np.isfinite(z), z, 0.0)
        return ((z[:d] - z[d:]) / width[:, None]).T

    def difference_steps(self, u, step: float) -> np.ndarray:
        """The central differences' steps in u: ``step`` relative to max(1, |u|)."""
        return step * np.maximum(1.0, np.abs(u))

    def covariance_jacobian(self, u) -> np.ndarray:
        """de/du for the covariance: central differences of :data:`COVARIANCE_STEP`."""
        return self.jacobian_u(u, COVARIANCE_STEP)


@dataclass(frozen=True)
class Uncertainty:
    """Standard errors, 95 % intervals and correlations of least-squares estimates.

    Attributes
    ----------
    names : tuple of str
        Estimated quantities (model parameters, offsets, initial state).
    estimate, standard_error : dict
        name -> value (SI units of the parameter).
    interval : dict
        name -> (lower, upper), the 95 % confidence interval.
    correlation : ndarray, shape (d, d)
        Correlation matrix, rows and columns in the order of ``names``.
    noise_std : float
        Residual standard deviation s (units of z).
    dof : int
        Residual degrees of freedom N - d.
    method : str
        How the covariance was estimated (:func:`covariance`): ``white``
        (``s^2 (J^T J)^-1``, exact to first order for white noise), ``ar``
        (the sandwich with the residual's fitted autoregressive covariance,
        used when the residual is not white) or ``hac`` (the sandwich with a
        Newey-West middle, on request).
    bandwidth : int
        The Newey-West bandwidth L in samples (``hac``; 0 otherwise).
    ar_order : int
        The order p of the residual's autoregression (``ar``; 0 otherwise).
    """

    names: tuple
    estimate: dict
    standard_error: dict
    interval: dict
    correlation: np.ndarray
    noise_std: float
    dof: int
    method: str = "white"
    bandwidth: int = 0
    ar_order: int = 0

    def to_dict(self) -> dict:
        return {
            "standard_errors": {k: float(v) for k, v in self.standard_error.items()},
            "confidence_intervals_95": {
                k: [float(a), float(b)] for k, (a, b) in self.interval.items()
            },
            "correlation": {
                "names": list(self.names),
                "matrix": [[float(x) for x in row] for row in self.correlation],
            },
            "noise_std": float(self.noise_std),
            "dof": int(self.dof),
            "covariance": self.method,
            "covariance_description": COVARIANCE_METHODS[self.method],
            "bandwidth": int(self.bandwidth),
            "ar_order": int(self.ar_order),
        }

    @classmethod
    def from_dict(cls, d: dict, estimate: dict) -> Uncertainty:
        """The :class:`Uncertainty` that :meth:`to_dict` wrote, with the ``estimate`` values.

        The intervals are recomputed from the estimates, standard errors and
        degrees of freedom as :func:`uncertainty` computes them (``to_dict``'s
        may have been cut at a search box by the result that saved them).
        """
        from scipy import stats

        names = tuple(d["correlation"]["names"])
        se = {k: float(d["standard_errors"][k]) for k in names}
        values = {k: float(estimate[k]) for k in names}
        t = float(stats.t.ppf(0.975, int(d["dof"])))
        return cls(
            names=names,
            estimate=values,
            standard_error=se,
            interval={k: (values[k] - t * se[k], values[k] + t * se[k]) for k in names},
            correlation=np.array(d["correlation"]["matrix"], dtype=float),
            noise_std=float(d["noise_std"]),
            dof=int(d["dof"]),
            method=d.get("covariance", "white"),
            bandwidth=int(d.get("bandwidth", 0)),
            ar_order=int(d.get("ar_order", 0)),
        )


#: What each covariance estimate means (the report and the JSON say which was used).
COVARIANCE_METHODS = {
    "white": "least squares, white residual assumed: s^2 (J^T J)^-1",
    "ar": "sandwich (J^T J)^-1 J^T Sigma J (J^T J)^-1 with Sigma the covariance of an "
    "autoregression fitted to the residual (Yule-Walker, order by BIC), the residual being "
    "correlated (Ljung-Box rejects whiteness at 1 %)",
    "hac": "sandwich with a Newey-West (Bartlett kernel) middle; bandwidth by Andrews' AR(1) rule",
}
#: Largest autoregressive order tried for the residual (``ar``), at most N / 10.
MAX_AR_ORDER = 40


def autoregression(residual, max_order: int = MAX_AR_ORDER) -> tuple[np.ndarray, float]:
    """AR(p) model of ``residual``: ``e_i = sum_k a_k e_{i-k} + w_i``, w white.

    Yule-Walker estimates (stable by construction) for p = 0..``max_order``
    (at most N / 10), p chosen by the Bayesian information criterion
    ``N log(sigma_p^2) + p log N``.

    Returns
    -------
    a : ndarray, shape (p,)
        a_1..a_p.
    sigma2 : float
        Variance of the innovation w (units of the residual, squared).
    """
    from scipy.linalg import solve_toeplitz

    e = np.asarray(residual, dtype=float) - np.mean(residual)
    n = e.shape[0]
    top = int(max(0, min(max_order, n // 10)))
    acov = np.array([e[k:] @ e[: n - k] / n for k in range(top + 1)])
    best = (n * np.log(max(acov[0], 1e-300)), np.zeros(0), float(acov[0]))
    if acov[0] <= 0:
        return best[1], best[2]
    for p in range(1, top + 1):
        a = solve_toeplitz(acov[:p], acov[1 : p + 1])
        sigma2 = float(acov[0] - a @ acov[1 : p + 1])
        if sigma2 <= 0:
            break
        bic = n * np.log(sigma2) + p * np.log(n)
        if bic < best[0]:
            best = (bic, a, sigma2)
    return best[1], best[2]


def newey_west_bandwidth(residual) -> int:
    """Andrews' (1991) AR(1) plug-in bandwidth of the Bartlett kernel (samples).

    ``L = 1.1447 (alpha N)^(1/3)`` with ``alpha = 4 rho^2 / ((1 - rho)^2 (1 + rho)^2)``,
    rho the residual's lag-1 autocorrelation; at most N / 4.
    """
    e = np.asarray(residual, dtype=float) - np.mean(residual)
    n = e.shape[0]
    denom = float(e @ e)
    rho = float(e[1:] @ e[:-1]) / denom if denom > 0 else 0.0
    rho = min(max(rho, -0.999), 0.999)
    alpha = 4 * rho**2 / ((1 - rho) ** 2 * (1 + rho) ** 2)
    return int(min(np.ceil(1.1447 * (alpha * n) ** (1 / 3)), n // 4))


def covariance(
    jacobian, residuals, method: str = "auto", blocks=None
) -> tuple[np.ndarray, str, int]:
    """Covariance of least-squares estimates (in the Jacobian's coordinates).

    To first order the estimate errs by ``-(J^T J)^-1 J^T e`` (e the output
    noise), so its covariance is the sandwich ``B J^T Sigma J B``,
    ``B = (J^T J)^-1``, Sigma the noise's covariance matrix.

    Parameters
    ----------
    jacobian : ndarray, shape (N, d)
        d e / d u at the optimum.
    residuals : ndarray, shape (N,)
    method : {'auto', 'white', 'ar', 'hac'}
        ``white``: ``Sigma = s^2 I``, ``s^2 = |e|^2 / (N - d)``.
        ``ar``: Sigma of the autoregression fitted to the residual
        (:func:`autoregression`, ``e = H w``, H the lower-triangular
        convolution by the AR model's impulse response): ``J^T Sigma J =
        sigma^2 (H^T J)^T (H^T J)``, H^T J being the columns of J filtered by
        ``1 / A(q)`` backwards in time. Right to first order when the model
        is right and the noise is (near) autoregressive; its one estimated
        noise model makes it far less variable than a kernel estimate when
        the correlation is long (a lightly damped response sampled fast).
        ``hac``: ``(J^T J)^-1 S (J^T J)^-1`` with the Newey-West middle
        ``S = sum_{|l| <= L} (1 - |l| / (L + 1)) sum_i g_i g_{i-l}^T``,
        ``g_i = J_i e_i`` (Newey and West 1987), L from
        :func:`newey_west_bandwidth`.
        ``auto``: ``ar`` when the Ljung-Box test rejects whiteness at 1 %
        (:func:`randvib.identification.residuals.ljung_box`), else ``white``.
    blocks : sequence of slice, optional
        Rows whose noise is its own (one record's channel each, when several
        channels or records are fitted together): the middle is the sum of
        the blocks' own (white: ``s_b^2 J_b^T J_b``; ``ar``: each block's own
        autoregression), the noise independent between blocks. ``auto``
        chooses ``ar`` when any block's residual is not white.

    Returns
    -------
    cov : ndarray, shape (d, d)
    method : str
        ``white``, ``ar`` or ``hac``.
    lag : int
        The Newey-West bandwidth (``hac``) or the AR order (``ar``); 0 for ``white``.
    """
    from scipy import signal

    from randvib.identification.residuals import LEVEL, ljung_box

    j = np.asarray(jacobian, dtype=float)
    e = np.asarray(residuals, dtype=float)
    n, d = j.shape
    bread = np.linalg.pinv(j.T @ j)
    if blocks is not None and len(blocks) > 1:
        return _blocked_covariance(j, e, bread, method, blocks)
    if method == "auto":
        method = "ar" if ljung_box(e)[1] < LEVEL else "white"
    if method == "white":
        return float(e @ e) / max(n - d, 1) * bread, "white", 0
    # small-sample scaling N / (N - d), as s^2 has
    scaling = n / max(n - d, 1)
    if method == "ar":
        a, sigma2 = autoregression(e)
        filtered = signal.lfilter([1.0], np.r_[1.0, -a], j[::-1], axis=0)[::-1]
        middle = sigma2 * scaling * (filtered.T @ filtered)
        return bread @ middle @ bread, "ar", int(a.size)
    if method != "hac":
        raise ValueError(f"`method` must be one of auto, white, ar, hac; got {method!r}")
    g = j * e[:, None]
    lag = newey_west_bandwidth(e)
    middle = g.T @ g
    for k in range(1, lag + 1):
        gamma = g[k:].T @ g[:-k]
        middle += (1 - k / (lag + 1)) * (gamma + gamma.T)
    middle *= scaling
    return bread @ middle @ bread, "hac", lag


def _blocked_covariance(j, e, bread, method, blocks):
    """:func:`covariance` with each block's noise its own (white or autoregressive)."""
    from scipy import signal

    from randvib.identification.residuals import LEVEL, ljung_box

    if method not in ("auto", "white", "ar"):
        raise ValueError(f"`method` with blocks must be one of auto, white, ar; got {method!r}")
    n, d = j.shape
    if method == "auto":
        coloured = any(ljung_box(e[b])[1] < LEVEL for b in blocks)
        method = "ar" if coloured else "white"
    middle = np.zeros((d, d))
    order = 0
    for b in blocks:
        jb, eb = j[b], e[b]
        nb = eb.size
        dof = max(nb - d * nb / n, 1.0)  # the parameters' degrees of freedom shared pro rata
        if method == "white":
            middle += float(eb @ eb) / dof * (jb.T @ jb)
            continue
        a, sigma2 = autoregression(eb)
        order = max(order, int(a.size))
        filtered = signal.lfilter([1.0], np.r_[1.0, -a], jb[::-1], axis=0)[::-1]
        middle += sigma2 * (nb / dof) * (filtered.T @ filtered)
    return bread @ middle @ bread, method, order


def uncertainty(problem: SimulationError, u, residuals, jacobian_u) -> Uncertainty:
    """:class:`Uncertainty` at the optimum ``u`` from the residuals and de/du there."""
    from scipy import stats

    coords = problem.coordinates
    theta = coords.to_theta(u)
    # covariance in the well-scaled u, then to physical units by the chain
    # rule dtheta/du = theta (log) or scale: inverting J^T J in physical
    # units would mix columns many decades apart
    dtheta_du = np.where(coords.log, theta, coords.scale)
    n, d = jacobian_u.shape
    dof = max(n - d, 1)
    s2 = float(residuals @ residuals) / dof
    cov_u, method, lag = covariance(jacobian_u, residuals, blocks=getattr(problem, "blocks", None))
    cov = cov_u * np.outer(dtheta_du, dtheta_du)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    t = float(stats.t.ppf(0.975, dof))
    names = coords.names
    return Uncertainty(
        names=names,
        estimate=dict(zip(names, map(float, theta), strict=True)),
        standard_error=dict(zip(names, map(float, se), strict=True)),
        interval={
            nm: (float(x - t * e), float(x + t * e))
            for nm, x, e in zip(names, theta, se, strict=True)
        },
        correlation=corr,
        noise_std=float(np.sqrt(s2)),
        dof=dof,
        method=method,
        bandwidth=lag if method == "hac" else 0,
        ar_order=lag if method == "ar" else 0,
    )


def polish(problem: SimulationError, theta0, *, max_nfev=None, with_uncertainty: bool = True):
    """Minimise |e(theta)|^2 from theta0; returns (theta, residuals, Uncertainty, message).

    ``with_uncertainty=False`` returns None for the Uncertainty, sparing its
    Jacobian (2 d more simulations) and covariance when only the optimum is
    wanted (the initial-state estimate of a prediction).
    """
    from scipy.optimize import least_squares

    coords = problem.coordinates
    lo, hi = coords.u_bounds()
    u0 = np.clip(coords.to_u(theta0), lo, hi)
    res = least_squares(
        problem.residuals_u,
        u0,
        jac=problem.jacobian_u,
        bounds=(lo, hi),
        method="trf",
        x_scale="jac",
        max_nfev=max_nfev or 50,
        xtol=1e-12,
        ftol=1e-12,
        gtol=1e-12,
    )
    unc = None
    if with_uncertainty:
        unc = uncertainty(problem, res.x, res.fun, problem.covariance_jacobian(res.x))
    return coords.to_theta(res.x), res.fun, unc, res.message
