"""Transient response to an event: the Lyapunov differential equation, exact or linearised.

Under an event ``a(t) = e(t) x(t)`` (:class:`randvib.Enveloped`) the state
``X`` of the linear device (z, z', a circuit's state) and of the
excitation's shaping filter obeys ``dX = A(t) X dt + B(t) dW`` with
E[dW^2] = (S/2) dt, and its mean and covariance obey (docs/conventions.md,
"Transient response from rest")

    d mu/dt = A(t) mu,
    dP/dt   = A(t) P + P A(t)^T + (S/2) B(t) B(t)^T.

White noise enters the velocity through ``B(t) = e(t) b``: this is the
conventions' ``dP/dt = A P + P A^T + e(t)^2 (S/2) b b^T``. A filtered input
keeps its filter, started in its stationary law (the stationary Lyapunov
solution of the filter); the envelope multiplies the filter's output, so
only the coupling block of A from filter to device carries e(t). The device
starts from :class:`~randvib.models.event.EventStart` (rest by default:
P(0) = 0 on the device's rows), a circuit at rest.

For the **linear device** (k3 = 0, no friction) this is exact. For the
nonlinear device it is **time-dependent statistical linearisation**: at
every instant the Gaussian closure of the current covariance gives

    k_eq(t) = k + 3 k3 E[z^2(t)],   c_eq(t) = c + E[v F(v)] / E[v^2]  (v ~ N(0, E[v^2(t)])),

the stationary closure of :mod:`randvib.analytic.statistical_linearisation`
followed in time (Caughey 1963's equivalent linearisation applied to the
moment equations). It needs a zero-mean response: a start at z = 0, z' = 0
(a start in one well of a bistable device has a mean that the zero-mean
closure cannot follow; use Monte Carlo there). Friction with memory (LuGre)
is refused, as in the stationary closure.

The equations are integrated with scipy's DOP853 (LSODA with friction,
whose closure is stiff where the motion is small) at rtol = 1e-10 and
absolute tolerances 1e-14 of each entry's scale (from a stationary
reference solution), segment by segment between the envelope's kinks, so
the moments are accurate to about 1e-9 relative (1e-6 is checked against
Caughey and Stumpf's closed form in the tests). The expected electrical
energy of the event ``int_0^T E[P_e] dt`` (``c_e int E[z'^2] dt``, or the
circuit's ``(R_L + R_C) int E[i^2] dt`` / ``int E[V^2] dt / R_L``) is
integrated with them.

For the linear device with a stroke, the probability of reaching the stroke
during the event is approximated from the out-crossing rate
(:mod:`randvib.analytic.first_passage`: Poisson and Vanmarcke), labelled
approximate (Vanmarcke's is not conservative early in an event), and bounded
above by the expected number of out-crossings (Rice); the Gaussian
P(|z(t)| > stroke) at each time is exact for the linear device.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import integrate, linalg, special

from randvib import _display, formatting
from randvib._validation import check_finite, check_scalar_device
from randvib.analytic.first_passage import (
    crossing_bound,
    outcrossing_rate,
    probability_from_hazard,
    spectral_bandwidth,
    vanmarcke_hazard,
)
from randvib.analytic.linear_response import device_block, stationary_covariance
from randvib.analytic.method import method_named
from randvib.models.event import Enveloped, EventStart
from randvib.models.harvester import Harvester

#: Relative tolerance of the moment equations (DOP853).
RTOL = 1e-10
#: Absolute tolerance of each entry, relative to its stationary reference scale.
ATOL_SCALE = 1e-14
#: Velocity spread (relative to its scale) below which the closure's friction
#: damping is held at its value there (:func:`_equivalent`).
VELOCITY_FLOOR = 1e-6
#: Points on which the default time grid reports the response.
DEFAULT_TIMES = 201


class EventSystem:
    """The augmented linear(ised) system of an event: filter states, z, z', circuit state.

    States are ordered ``[filter (n_f), z, v, circuit (0 or 1)]``, the order of
    :meth:`randvib.models.state_space.StateSpace.driven_by`. :meth:`matrices`
    gives A and B for a damping, a stiffness and an envelope value.

    Parameters
    ----------
    harvester : Harvester
    event : Enveloped
        Its excitation must be rational (white, band-pass, Kanai-Tajimi).
    """

    def __init__(self, harvester: Harvester, event: Enveloped):
        shaping = event.excitation.shaping_filter()
        if shaping is None:
            raise ValueError(
                "the transient Lyapunov equation needs a rational spectrum (a shaping filter: "
                f"white, band-pass, Kanai-Tajimi); the {event.excitation.name} excitation has "
                "none: use Monte Carlo (randvib.simulate_transient)"
            )
        self.harvester = harvester
        self.event = event
        self.shaping = shaping
        filt = shaping.system
        self.n_filter = nf = filt.n_states
        self.iz, self.iv = nf, nf + 1
        self.has_circuit = harvester.has_circuit
        self.ix = nf + 2 if self.has_circuit else None
        self.n = nf + 2 + (1 if self.has_circuit else 0)
        self.m = float(harvester.m)
        self.q = shaping.noise_intensity
        a = np.zeros((self.n, self.n))
        a[:nf, :nf] = filt.a
        a[self.iz, self.iv] = 1.0
        if self.has_circuit:
            a_x, b_x, f = harvester.electrical.circuit_equation()
            a[self.iv, self.ix] = -f / self.m
            a[self.ix, self.iv] = b_x
            a[self.ix, self.ix] = a_x
        self._a = a
        # the base acceleration y = C x_f + D w enters the velocity as -e(t) y
        self._coupling = -filt.c[0]
        self._b_filter = np.concatenate([filt.b, np.zeros(self.n - nf)])
        self._b_direct = float(filt.d[0])

    @property
    def filter_covariance(self) -> np.ndarray:
        """The filter's stationary covariance: A_f P + P A_f^T + (S/2) b_f b_f^T = 0."""
        nf = self.n_filter
        if nf == 0:
            return np.zeros((0, 0))
        filt = self.shaping.system
        return linalg.solve_continuous_lyapunov(filt.a, -self.q * np.outer(filt.b, filt.b))

    def matrices(self, c_eq: float, k_eq: float, e: float) -> tuple[np.ndarray, np.ndarray]:
        """(A, B) with damping ``c_eq`` (Ns/m), stiffness ``k_eq`` (N/m), envelope ``e``."""
        a = self._a.copy()
        a[self.iv, self.iz] = -k_eq / self.m
        a[self.iv, self.iv] = -c_eq / self.m
        a[self.iv, : self.n_filter] = e * self._coupling
        b = self._b_filter.copy()
        b[self.iv] = -e * self._b_direct
        return a, b


def _equivalent(harvester: Harvester, friction, velocity_floor: float = 0.0):
    """(c_eq, k_eq) of the Gaussian closure as a function of (E[z^2], E[v^2]).

    E[v F(v)] / E[v^2] grows like 1/sigma_v for Coulomb friction as the
    velocity's spread vanishes (its products with the covariances stay
    bounded by sigma_v): from rest the closure is stiff without end. Below
    ``velocity_floor`` (m/s) the increment is that at the floor, which the
    solver can follow; the floor is 1e-6 of the velocity's scale, where the
    response is a millionth of its size and the friction term's error is
    below the tolerance.
    """
    c, k, k3 = (float(x) for x in (harvester.c, harvester.k, harvester.k3))

    def equivalent(z2: float, v2: float) -> tuple[float, float]:
        c_eq = c
        if friction is not None:
            sigma = max(np.sqrt(max(v2, 0.0)), velocity_floor)
            if sigma > 0:
                c_eq += float(friction.equivalent_damping_increment(sigma))
        return c_eq, k + 3.0 * k3 * z2

    return equivalent


def _reference_scales(system: EventSystem, harvester: Harvester, t_end: float, mean) -> np.ndarray:
    """A scale of each state (its unit) from a stationary reference, for the absolute tolerances.

    The stationary covariance of a linear device under the envelope's peak
    intensity, with the device's damping (10 % of critical without one) and
    stiffness (at least m (2 pi / T)^2): an over-estimate is safe (the
    tolerance is 1e-14 of it), a scale far below the response is not needed.
    """
    m = float(harvester.m)
    k = abs(float(harvester.k))
    k_ref = max(k if harvester.k > 0 else 2.0 * k, m * (2.0 * np.pi / t_end) ** 2)
    c_ref = float(harvester.c) if harvester.c > 0 else 0.2 * np.sqrt(k_ref * m)
    peak = system.event.peak_excitation()
    block = device_block(m, c_ref, k_ref, harvester.electrical)
    nf = system.n_filter
    outputs = np.diag(stationary_covariance(block, peak.shaping_filter()))
    filter_var = np.diag(system.filter_covariance)  # the filter runs stationary, unenveloped
    scales = np.sqrt(np.concatenate([filter_var, outputs]))
    scales[nf:] = np.maximum(scales[nf:], np.abs(mean[nf:]))
    return np.where(scales > 0, scales, 1.0)


@dataclass(frozen=True, eq=False)
class _Solution:
    """The moment equations' dense solution, segment by segment."""

    segments: list  # (lo, hi, OdeSolution)
    n: int

    def __call__(self, t) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.empty((t.size, self.segments[0][2](self.segments[0][0]).size))
        for i, ti in enumerate(t):
            for lo, hi, sol in self.segments:
                if ti <= hi:
                    out[i] = sol(min(max(ti, lo), hi))
                    break
            else:
                lo, hi, sol = self.segments[-1]
                out[i] = sol(hi)
        return out

    def steps(self) -> np.ndarray:
        """The solver's own step times, each step refined 8-fold (for rate integrals)."""
        ts = []
        for _, _, sol in self.segments:
            edges = np.asarray(sol.ts)
            fine = edges[:-1, None] + np.diff(edges)[:, None] * np.linspace(0, 1, 9)[None, :-1]
            ts.append(fine.ravel())
        ts.append([self.segments[-1][1]])
        return np.unique(np.concatenate(ts))


#: Evaluations of the moment equations' right-hand side after which a solve is stopped and
#: refused: an ordinary event takes about 1,600 per second of event (a 6 s Shinozuka-Sato
#: event with friction: 9,600), so 2 x 10^5, or 3 x 10^4 per second of a longer event
#: (about 20 times that), stops a closure made too stiff to finish (a level of 1e-300 with
#: friction ran without end) in about a minute.
MAX_EVALUATIONS = 200_000
MAX_EVALUATIONS_PER_SECOND = 30_000


class _TooStiff(Exception):
    """The moment equations took more than :data:`MAX_EVALUATIONS` evaluations."""

    def __init__(self, t, evaluations):
        super().__init__(t)
        self.t, self.evaluations = float(t), int(evaluations)


def _solve(system, event, mu0, scales, t_end, equivalent, nonlinear, stiff) -> _Solution:
    """Integrate the mean, covariance and the energy integrals from 0 to ``t_end``.

    ``mu0`` is the start's mean, ``scales`` each state's reference scale
    (:func:`_reference_scales`) for the absolute tolerances. With friction
    (``stiff``) the closure's damping grows without bound as the motion
    starts from rest or dies out after the event (:func:`_equivalent`), so
    the system is stiff there: LSODA (which switches to BDF where it is),
    else DOP853.
    """
    n = system.n
    iz, iv, ix = system.iz, system.iv, system.ix
    envelope = event.envelope
    p0 = np.zeros((n, n))
    nf = system.n_filter
    p0[:nf, :nf] = system.filter_covariance
    pair = np.outer(scales, scales)
    atol = ATOL_SCALE * np.concatenate(
        [
            pair.ravel(),
            scales,
            [pair[iv, iv] * t_end, (pair[ix, ix] if ix is not None else 1.0) * t_end],
        ]
    )
    y0 = np.concatenate([p0.ravel(), mu0, [0.0, 0.0]])
    fixed = None if nonlinear else equivalent(0.0, 0.0)
    evaluations = [0]
    most = max(MAX_EVALUATIONS, int(MAX_EVALUATIONS_PER_SECOND * t_end))

    def rhs_in(lo, hi):
        # one-sided values at a segment's ends: a jump of e belongs to one side
        inner = 1e-12 * (hi - lo)

        def rhs(t, y):
            evaluations[0] += 1
            if evaluations[0] > most:  # a stiffness beyond reach: refused, not run on
                raise _TooStiff(t, most)
            p = y[: n * n].reshape(n, n)
            mu = y[n * n : n * n + n]
            c_eq, k_eq = fixed if fixed is not None else equivalent(p[iz, iz], p[iv, iv])
            e = float(envelope(min(max(t, lo + inner), hi - inner)))
            a, b = system.matrices(c_eq, k_eq, e)
            ap = a @ p
            dp = ap + ap.T + system.q * np.outer(b, b)
            v2 = p[iv, iv] + mu[iv] ** 2
            x2 = p[ix, ix] + mu[ix] ** 2 if ix is not None else 0.0
            return np.concatenate([dp.ravel(), a @ mu, [v2, x2]])

        return rhs

    edges = [0.0] + [b for b in envelope.breakpoints() if 0.0 < b < t_end] + [t_end]
    segments = []
    y = y0
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        try:
            sol = integrate.solve_ivp(
                rhs_in(lo, hi),
                (lo, hi),
                y,
                method="LSODA" if stiff else "DOP853",
                rtol=RTOL,
                atol=atol,
                dense_output=True,
            )
        except _TooStiff as stopped:
            raise ValueError(
                f"the transient moment equations were stopped at t = {stopped.t:.3g} s after "
                f"{stopped.evaluations} evaluations (about 20 times an ordinary event's): the "
                "closure is too stiff here (friction, or the parameters' scales, against the "
                f"input's level; {event.name}); use Monte Carlo (randvib.simulate_transient)"
            ) from None
        if not sol.success:
            raise ValueError(
                f"the transient moment equations could not be integrated: {sol.message}"
            )
        segments.append((lo, hi, sol.sol))
        y = sol.y[:, -1]
    return _Solution(segments, n)


def _closure_friction(harvester: Harvester, start: EventStart):
    """(friction law of the closure or None, whether the device is linear); refusals named."""
    check_scalar_device(harvester, "transient_response")
    friction = harvester.friction
    friction = None if friction is None or friction.vanishes else friction
    linear = friction is None and float(harvester.k3) == 0.0
    if not linear and not start.is_zero:
        raise ValueError(
            f"time-dependent statistical linearisation is a zero-mean Gaussian closure; the start "
            f"{start.describe()} gives the nonlinear device a mean it cannot follow: start from "
            "rest, or use Monte Carlo (randvib.simulate_transient)"
        )
    return friction, linear


def _times(times, t_end):
    """(times, t_end): the report times, sorted and inside [0, t_end]."""
    if times is None:
        if t_end is None:
            raise ValueError("give `times` or `t_end` (s): when to report the response")
        t_end = float(check_finite("t_end", t_end))
        if not t_end > 0:
            raise ValueError(f"`t_end` must be > 0 s, got {t_end!r}")
        return np.linspace(0.0, t_end, DEFAULT_TIMES), t_end
    times = check_finite("times", np.atleast_1d(times)).astype(float)
    if times.ndim != 1 or times.size == 0:
        raise ValueError(f"`times` must be a 1-D list of times (s), got shape {times.shape}")
    if np.any(np.diff(times) <= 0):
        i = int(np.argmax(np.diff(times) <= 0))
        raise ValueError(
            f"`times` must be increasing, got {float(times[i + 1])!r} s after {float(times[i])!r} s"
        )
    t_end = float(times[-1]) if t_end is None else float(check_finite("t_end", t_end))
    if not t_end > 0:
        raise ValueError(f"`t_end` must be > 0 s, got {t_end!r}")
    if times[0] < 0 or times[-1] > t_end:
        bad = float(times[0] if times[0] < 0 else times[-1])
        raise ValueError(f"`times` must lie in [0, t_end] = [0, {t_end!r}] s, got {bad!r} s")
    return times, t_end


def transient_response(
    harvester: Harvester,
    event: Enveloped,
    times=None,
    *,
    t_end=None,
    start="rest",
    method="linearisation",
) -> TransientPrediction:
    """Time-dependent moments and energy of the device under an event, by the Lyapunov ODE.

    Parameters
    ----------
    harvester : Harvester
        Scalar parameters; any coupling; a memoryless friction law or none;
        a confining potential or the free mass. Exact for the linear device
        (k3 = 0, no friction); time-dependent statistical linearisation
        otherwise (from a zero-mean start).
    event : Enveloped
        A rational excitation (white, band-pass, Kanai-Tajimi) times an envelope.
    times : array_like, optional
        Increasing times (s) in [0, t_end] at which the moments are reported;
        default 201 points on [0, t_end].
    t_end : float, optional
        End of the event window (s): the energy is integrated from 0 to t_end.
        Default: the last of ``times``.
    start : "rest", "unexcited" or (z0, v0)
        Where the device starts (:class:`~randvib.models.event.EventStart`).
    method : str or AnalyticMethod
        A method of :data:`randvib.analytic.prediction.METHODS` that declares
        ``transient`` (``"linearisation"``); the stationary ones refuse an event.

    Returns
    -------
    TransientPrediction

    Examples
    --------
    White noise switched on at t = 0 on the linear oscillator (Caughey and
    Stumpf 1961): E[z^2] rises to the stationary S m^2 / (4 c k).

    >>> import randvib as rv
    >>> linear = rv.Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4)
    >>> r = rv.transient_response(linear, rv.Enveloped(rv.White(1.0), rv.Step()), [0.1, 1.0, 5.0])
    >>> print(", ".join(f"{x:.4e}" for x in r.displacement_variance), "m^2; exact:", r.exact)
    6.7010e-06, 1.1121e-05, 1.1123e-05 m^2; exact: True
    >>> print(f"energy from 0 to 5 s: {r.energy_electrical:.4e} J")
    energy from 0 to 5 s: 1.3806e-02 J
    """
    if not isinstance(harvester, Harvester):
        raise ValueError(f"`harvester` must be a randvib.Harvester, got {type(harvester).__name__}")
    if not isinstance(event, Enveloped):
        raise ValueError(
            "`event` must be a randvib.Enveloped (an excitation times an envelope, e.g. "
            f"rv.Enveloped(rv.White(1.0), rv.Step()) for noise switched on at t = 0), got {event!r}"
        )
    start = EventStart.of(start, harvester)
    times, t_end = _times(times, t_end)
    solver = method_named(method)
    solver.require(harvester, event)
    return solver.solve_transient(harvester, event, times, t_end, start)


def solve_transient(method: str, harvester, event, times, t_end, start) -> TransientPrediction:
    """The moment equations of an accepted event (the engine of :func:`transient_response`).

    ``method`` is the declaring method's name; ``times`` (s) and ``t_end``
    (s) are checked, ``start`` an :class:`~randvib.models.event.EventStart`.
    """
    friction, linear = _closure_friction(harvester, start)
    system = EventSystem(harvester, event)
    mean = np.zeros(system.n)
    mean[system.iz], mean[system.iv] = start.z, start.v
    scales = _reference_scales(system, harvester, t_end, mean)
    equivalent = _equivalent(harvester, friction, VELOCITY_FLOOR * scales[system.iv])
    solution = _solve(
        system, event, mean, scales, t_end, equivalent, not linear, stiff=friction is not None
    )
    return TransientPrediction._from_solution(
        method, harvester, event, start, times, t_end, system, solution, equivalent, linear
    )


@dataclass(frozen=True, eq=False)
class TransientPrediction:
    """Analytic transient moments of the device under an event (SI units; arrays over ``times``).

    Attributes
    ----------
    method : str
        The analytic method (``linearisation``: time-dependent statistical
        linearisation).
    exact : bool
        True for the linear device (k3 = 0, no friction), whose Lyapunov
        solution is exact; False where the closure approximates.
    harvester : Harvester
    event : Enveloped
    start : EventStart
    times : ndarray
        Report times (s).
    t_end : float
        End of the event window (s).
    displacement_variance, velocity_variance : ndarray
        E[z^2(t)] (m^2) and E[z'^2(t)] ((m/s)^2): mean squares about z = 0
        (variances for a start at rest, whose mean stays 0).
    displacement_mean : ndarray
        E[z(t)] (m): zero from rest.
    displacement_velocity : ndarray
        E[z z'] (m^2/s) = d E[z^2]/dt / 2.
    power_electrical : ndarray
        E[P_e(t)] (W): c_e E[z'^2], or from the circuit state.
    power_load : ndarray or None
        The share reaching R_L (W), with a coupling.
    circuit_mean_square : ndarray or None
        E[i^2] (A^2) or E[V^2] (V^2) of a circuit state.
    energy_electrical : float
        int_0^t_end E[P_e] dt (J): the expected energy the event delivers.
    energy_load : float or None
        The share reaching R_L (J).
    cumulative_energy : ndarray
        int_0^t E[P_e] dt (J) at ``times``.
    c_eq, k_eq : ndarray
        The (equivalent) damping (Ns/m) and stiffness (N/m) at ``times``.
    stroke_exceedance : ndarray or None
        P(|z(t)| > stroke) of the Gaussian response (exact for the linear device).
    stroke_reached_poisson, stroke_reached_vanmarcke : ndarray or None
        P(|z| has reached the stroke by t), **approximate** (out-crossing
        rates, :mod:`randvib.analytic.first_passage`); the linear device from
        a zero-mean start only. Vanmarcke's is not conservative early in an
        event (below Monte Carlo while the response builds up).
    stroke_reached_bound : ndarray or None
        An upper bound on the same probability: the expected number of
        out-crossings by t (Rice), at most 1.
    bandwidth : float or None
        Vanmarcke's spectral bandwidth q of the stationary displacement.
    """

    method: str
    exact: bool
    harvester: Harvester
    event: Enveloped
    start: EventStart
    times: np.ndarray
    t_end: float
    displacement_variance: np.ndarray
    velocity_variance: np.ndarray
    displacement_mean: np.ndarray
    displacement_velocity: np.ndarray
    power_electrical: np.ndarray
    power_load: np.ndarray | None
    circuit_mean_square: np.ndarray | None
    energy_electrical: float
    energy_load: float | None
    cumulative_energy: np.ndarray
    c_eq: np.ndarray
    k_eq: np.ndarray
    stroke_exceedance: np.ndarray | None = None
    stroke_reached_poisson: np.ndarray | None = None
    stroke_reached_vanmarcke: np.ndarray | None = None
    bandwidth: float | None = None
    stroke_reached_bound: np.ndarray | None = None
    covariance: np.ndarray = field(default=None, repr=False)

    @classmethod
    def _from_solution(
        cls, method, harvester, event, start, times, t_end, system, solution, equivalent, linear
    ):
        n, iz, iv, ix = system.n, system.iz, system.iv, system.ix
        y = solution(times)
        p = y[:, : n * n].reshape(-1, n, n)
        mu = y[:, n * n : n * n + n]
        second = p + mu[:, :, None] * mu[:, None, :]
        z2, v2, zv = second[:, iz, iz], second[:, iv, iv], second[:, iz, iv]
        x2 = second[:, ix, ix] if ix is not None else None
        end = solution([t_end])[0]
        int_v2, int_x2 = y[:, -2], y[:, -1]
        power, load = _powers(harvester, v2, x2)
        energy, energy_load = _powers(harvester, end[-2], end[-1] if ix is not None else None)
        cumulative, _ = _powers(harvester, int_v2, int_x2 if ix is not None else None)
        pairs = [equivalent(a, b) for a, b in zip(p[:, iz, iz], p[:, iv, iv], strict=True)]
        stroke = harvester.stroke
        exceedance = reached_poisson = reached_vanmarcke = bandwidth = reached_bound = None
        if stroke is not None:
            exceedance = _gaussian_exceedance(stroke, mu[:, iz], p[:, iz, iz])
            if linear and start.is_zero and not harvester.potential.is_free:
                reached_poisson, reached_vanmarcke, reached_bound, bandwidth = _first_passage(
                    system, harvester, event, solution, times, stroke
                )
        return cls(
            method=method,
            exact=linear,
            harvester=harvester,
            event=event,
            start=start,
            times=times,
            t_end=t_end,
            displacement_variance=z2,
            velocity_variance=v2,
            displacement_mean=mu[:, iz],
            displacement_velocity=zv,
            power_electrical=power,
            power_load=load,
            circuit_mean_square=x2,
            energy_electrical=float(energy),
            energy_load=None if energy_load is None else float(energy_load),
            cumulative_energy=cumulative,
            c_eq=np.array([c for c, _ in pairs]),
            k_eq=np.array([k for _, k in pairs]),
            stroke_exceedance=exceedance,
            stroke_reached_poisson=reached_poisson,
            stroke_reached_vanmarcke=reached_vanmarcke,
            bandwidth=bandwidth,
            stroke_reached_bound=reached_bound,
            covariance=p,
        )

    # ------------------------------------------------------------ presenting
    def _series(self) -> list[tuple[str, np.ndarray, str]]:
        """(name, values over times, unit) of every time-resolved quantity this result has."""
        names = [
            "displacement_variance",
            "velocity_variance",
            "power_electrical",
            "power_load",
            "circuit_mean_square",
            "cumulative_energy",
            "stroke_exceedance",
            "stroke_reached_poisson",
            "stroke_reached_vanmarcke",
            "stroke_reached_bound",
        ]
        return _display.time_series(self, names + ([] if self.exact else ["c_eq", "k_eq"]))

    def to_frame(self):
        """One row per time: ``time`` (s) and every time-resolved quantity (SI units)."""
        pd = _display.pandas()
        frame = pd.DataFrame({"time": self.times})
        for name, values, _ in self._series():
            frame[name] = values
        return frame

    def to_dict(self) -> dict:
        """JSON-ready: ``times``, the quantities as lists over them, the energies and settings."""
        out = {"method": self.method, "exact": self.exact, "times": self.times.tolist()}
        out.update({name: np.asarray(v).tolist() for name, v, _ in self._series()})
        out["energy_electrical"] = self.energy_electrical
        if self.energy_load is not None:
            out["energy_load"] = self.energy_load
        if self.bandwidth is not None:
            out["bandwidth"] = self.bandwidth
        if self.harvester.stroke is not None:
            out["stroke"] = self.harvester.stroke
        out.update(t_end=self.t_end, **self.start.to_dict(), **self.event.parameters())
        return out

    def _note(self) -> str:
        how = "exact (linear device)" if self.exact else "time-dependent closure"
        approximate = (
            "; * approximate (Vanmarcke's not conservative early in an event; the bound is "
            "an upper bound)"
            if self.stroke_reached_poisson is not None
            else ""
        )
        return (
            f"{self.method}, {how}, {self.event.name}, start {self.start.describe()}; energy "
            f"int_0^{self.t_end:g} E[P_e] dt = {formatting.compact(self.energy_electrical)} J"
            f"{approximate}"
        )

    def _table(self):
        return _display.time_rows(
            self.times, self._series(), lambda values, i: formatting.compact(values[i])
        )

    def __repr__(self) -> str:
        return (
            f"TransientPrediction({self.method}, exact={self.exact}, {self.event.name}, {self.times.size} times to "
            f"{self.t_end:g} s; energy_electrical = {formatting.compact(self.energy_electrical)} J)"
        )

    def __str__(self) -> str:
        return _display.time_table("Transient response (analytic)", *self._table(), self._note())

    def _repr_html_(self) -> str:
        return _display.time_html_table(
            "Transient response (analytic)", *self._table(), self._note()
        )


def _powers(harvester: Harvester, v2, x2):
    """(electrical, load) power from E[v^2] and a circuit's E[x^2] (or their time integrals)."""
    coupling = harvester.electrical
    if coupling is None:
        return harvester.c_e * np.asarray(v2), None
    if not coupling.is_dynamic:
        power = harvester.c_e * np.asarray(v2)
        return power, power * coupling.load_fraction
    return coupling.power_electrical(v2, x2), coupling.power_load(v2, x2)


def _gaussian_exceedance(stroke, mean, variance):
    """P(|z| > stroke) for z ~ N(mean, variance) (an indicator where the variance is 0)."""
    sd = np.sqrt(np.maximum(variance, 0.0))
    safe = np.where(sd > 0, sd, 1.0)
    spread = special.ndtr((-stroke - mean) / safe) + special.ndtr((mean - stroke) / safe)
    return np.where(sd > 0, spread, (np.abs(mean) > stroke).astype(float))


def _first_passage(system, harvester, event, solution, times, stroke):
    """(Poisson, Vanmarcke, Rice's bound) P(stroke reached by t) at ``times``, and q."""
    n, iz, iv = system.n, system.iz, system.iv
    grid = np.union1d(solution.steps(), times)
    p = solution(grid)[:, : n * n].reshape(-1, n, n)
    rate = outcrossing_rate(p[:, iz, iz], p[:, iz, iv], p[:, iv, iv], stroke)
    block = device_block(
        float(harvester.m), float(harvester.c), float(harvester.k), harvester.electrical
    )
    q = spectral_bandwidth(block, event.excitation)
    hazard = vanmarcke_hazard(rate, p[:, iz, iz], stroke, q)
    at = np.searchsorted(grid, times)
    poisson = probability_from_hazard(grid, rate)[at]
    vanmarcke = probability_from_hazard(grid, hazard)[at]
    return poisson, vanmarcke, crossing_bound(grid, rate)[at], q
