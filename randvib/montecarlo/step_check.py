"""The linearised device as a linear test system: step bias, largest step, stationary spread.

A Monte Carlo run checks its time step, sizes its histograms and draws its
random start from one linear Gaussian system, the device linearised under
its input (:class:`LinearTestSystem`), built once per run:

- white noise or a rational spectrum (band-pass, Kanai-Tajimi): the device
  with stiffness k_eff and damping c_eff (:func:`effective_linear_device`),
  driven through the excitation's shaping filter, with the circuit state
  when the coupling has one;
- synthesised or recorded input (no shaping filter): the device linearised by
  statistical linearisation under the (coarsened) spectrum, driven by unit
  white noise, which is how the input's exact step integrals reach the
  velocity in the kernel.

On that system a scheme is a linear recursion whose stationary covariance is
exact (:meth:`randvib.montecarlo.integrators.Integrator.linear_recursion`),
so its departure from the continuous Lyapunov covariance is the scheme's
time-step bias (:meth:`LinearTestSystem.bias`).
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import linalg

from randvib.analytic import exact_solutions as exact
from randvib.analytic.linear_response import device_block, output_variances
from randvib.analytic.linearisation import linear_displacement_variance
from randvib.analytic.statistical_linearisation import linearise
from randvib.models.excitation import Excitation, Tabulated, as_excitation
from randvib.models.harvester import Harvester
from randvib.models.state_space import StateSpace
from randvib.montecarlo import integrators

#: Largest stationary-variance bias (relative) of the scheme on the linearised
#: device for which a step is accepted; see :func:`step_bias`.
MAX_STEP_BIAS = 0.10
#: Bias above which a warning is issued.
WARN_STEP_BIAS = 0.01


class StepSizeWarning(RuntimeWarning):
    """The time step gives a noticeable discretisation bias."""


def effective_linear_device(harvester: Harvester, psd: float) -> tuple[float, float]:
    """(k_eff, c_eff) of the linearised device, for step-size checks.

    Statistical linearisation's one route
    (:func:`randvib.analytic.statistical_linearisation.linearise`) at the
    white-noise level ``psd``, with a friction law that has memory (LuGre)
    left out: it only adds damping. c_eff is its c_eq (Eq. 30 for Coulomb
    friction); with a circuit state k_eff is its k_eq. Otherwise k_eff =
    k + 3 k3 E[z^2] with E[z^2] from the exact friction-free (Gibbs) density
    where there is viscous damping (friction only shrinks the motion, so this
    stiffness is an upper bound in the mean), and the linearisation's k_eq
    without. Any confining potential: for a double well E[z^2] ~ z_w^2 at low
    noise, so k_eff ~ -2 k, the wells' own stiffness; the free mass has k_eff = 0.
    """
    h = harvester
    if h.friction is not None and not h.friction.has_equivalent_damping:
        h = h.updated(friction=None)
    if h.potential.is_free and h.has_circuit:
        # statistical linearisation needs a stationary z; the free mass's
        # velocity and circuit state are stationary without one
        return 0.0, _free_mass_velocity(h, as_excitation(psd))[0]
    lin = linearise(h, psd)
    if h.has_circuit:
        return lin.k_eq, lin.c_eq
    c_eff = float(lin.c_eq)
    if h.potential.is_free:
        return 0.0, c_eff
    if h.c > 0:
        z2 = exact.gibbs_displacement_moment(h.m, h.c, h.k, h.k3, psd)
        return float(h.k + 3.0 * h.k3 * z2), c_eff
    return float(lin.k_eq), c_eff


@dataclass(frozen=True, eq=False)
class LinearTestSystem:
    """The linearised device (with its filter and circuit states) a run is checked on.

    Build it with :meth:`of`. Attributes are SI: ``k_eff`` (N/m), ``c_eff``
    (Ns/m), ``level`` the white-noise level driving it ((m/s^2)^2/Hz: the
    excitation's level, or 1 for synthesised and recorded input, whose step
    integrals the kernel adds to the velocity).

    Attributes
    ----------
    harvester : Harvester
    excitation : Excitation
        The input as given.
    k_eff, c_eff : float
        Stiffness and damping of the linearised device.
    level : float
        Level of the white noise driving the linear system.
    augmented : tuple or None
        (F, G, C) of dx = F x dt + G dW over (filter, z, v, circuit), C picking
        the filter's output, z, v and the circuit state; None for the device
        alone under white noise.
    driven_moments : tuple or None
        (E[z^2], E[v^2]) of the statistical linearisation under synthesised or
        recorded input; None otherwise.
    """

    harvester: Harvester
    excitation: Excitation
    k_eff: float
    c_eff: float
    level: float
    augmented: tuple | None
    driven_moments: tuple | None

    @classmethod
    def of(cls, harvester: Harvester, psd) -> LinearTestSystem:
        """The linear test system of ``harvester`` under ``psd`` (a level or an excitation)."""
        excitation = as_excitation(psd)
        moments = None
        if excitation.shaping_filter() is None:  # synthesised or recorded input
            k_eff, c_eff, z2, v2 = _linearised_under(harvester, excitation)
            level, linear_input, moments = 1.0, as_excitation(1.0), (z2, v2)
        else:
            k_eff, c_eff = effective_linear_device(harvester, excitation.level)
            level, linear_input = excitation.level, excitation
        augmented = None
        if not linear_input.is_white or harvester.has_circuit:
            m = float(harvester.m)
            augmented = _augmented_system(m, k_eff, c_eff, linear_input, harvester.electrical)
        return cls(harvester, excitation, k_eff, c_eff, level, augmented, moments)

    @property
    def m(self) -> float:
        return float(self.harvester.m)

    def bias(self, scheme: str, dt: float) -> float:
        """Relative bias of the scheme's stationary variances at step ``dt`` (inf if unstable).

        The device alone: the bias of E[v^2] (:func:`_scheme_bias`). With the
        filter's or the circuit's states: the largest of those of the picked
        variances, E[y^2] (the filter's own), E[z^2], E[v^2] and the circuit's
        E[x^2] (:func:`_augmented_bias`).
        """
        if self.augmented is None:
            return _scheme_bias(scheme, self.m, self.k_eff, self.c_eff, self.level, dt)
        return _augmented_bias(scheme, *self.augmented, dt)

    def largest_step(self, scheme: str, bias: float = MAX_STEP_BIAS) -> float:
        """Largest dt (s) whose :meth:`bias` stays below ``bias`` (bisection)."""
        m = self.m
        # The fastest linear time scale: the period over pi, or for the free mass m/c.
        if self.k_eff > 0:
            hi = 2.0 / np.sqrt(self.k_eff / m)
        else:
            hi = 2.0 * m / self.c_eff if self.c_eff > 0 else np.inf
        if self.augmented is not None:
            hi = min(hi, 2.0 / max(abs(np.linalg.eigvals(self.augmented[0]))))
        lo = 0.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if self.bias(scheme, mid) <= bias:
                lo = mid
            else:
                hi = mid
        return lo

    @functools.cached_property  # used by the spread and by the circuit's start
    def covariance(self) -> np.ndarray:
        """Stationary covariance of (filter states, z, v, circuit) of the augmented system."""
        f, g, _ = self.augmented
        return linalg.solve_continuous_lyapunov(f, -(g @ g.T))

    @functools.cached_property  # used by the scale check, the start and the histograms
    def spread(self) -> tuple[float, float]:
        """(std of z (m), std of v (m/s)) of the linearised stationary state.

        White noise: Eq. 20 and 30. A rational spectrum or a circuit state: the
        Lyapunov covariance of the augmented system. Synthesised or recorded
        input: statistical linearisation's moments.
        Without a positive k (double well, pure cubic) the displacement's spread
        under white noise is the exact friction-free (Gibbs) one, which sees both
        wells, where the Gaussian closure would put a third of the wells' offset;
        the free mass has no stationary spread in z (0: paths start at z = 0; its
        velocity spread is the white-noise one at the excitation's level, a start
        the burn-in corrects).
        """
        h, psd = self.harvester, self.level
        if self.driven_moments is not None:
            z2, v2 = self.driven_moments
            return float(np.sqrt(z2)), float(np.sqrt(v2))
        if h.potential.is_free:
            return 0.0, float(np.sqrt(psd * h.m / (4.0 * self.c_eff)))
        if self.augmented is not None:
            cov = self.covariance
            n_filter = 0 if self.excitation.is_white else self.n_filter
            return float(np.sqrt(cov[n_filter, n_filter])), float(
                np.sqrt(cov[n_filter + 1, n_filter + 1])
            )
        vv = psd * h.m / (4.0 * self.c_eff)
        if h.k <= 0 and h.c > 0:
            return float(np.sqrt(exact.gibbs_displacement_moment(h.m, h.c, h.k, h.k3, psd))), float(
                np.sqrt(vv)
            )
        return float(np.sqrt(linear_displacement_variance(h, vv))), float(np.sqrt(vv))

    @property
    def n_filter(self) -> int:
        """Number of the shaping filter's states (0 for white, synthesised or recorded input)."""
        shaping = self.excitation.shaping_filter()
        return 0 if shaping is None or self.excitation.is_white else shaping.system.n_states

    def check_step(self, scheme: str, dt: float) -> None:
        """Refuse ``dt`` above :data:`MAX_STEP_BIAS`; warn above :data:`WARN_STEP_BIAS`.

        Both messages give the step that would pass (:meth:`largest_step`).
        """
        bias = self.bias(scheme, dt)
        states = []
        if self.n_filter:
            states.append(f"the {self.excitation.name} filter's states")
        if self.harvester.has_circuit:
            coupling = self.harvester.electrical
            states.append(f"the {coupling.name} circuit's {coupling.state_name}")
        resolves = f" with {' and '.join(states)}" if states else ""
        if bias > MAX_STEP_BIAS:
            limit = self.largest_step(scheme)
            if not limit > 0:
                raise ValueError(
                    f"`dt` = {dt!r} s is too large for this device{resolves} with {scheme}, and "
                    f"no representable step is small enough (its linearised stiffness and "
                    f"damping {(self.k_eff, self.c_eff)} are out of range)"
                )
            # an infinite bias is an unstable recursion: the variance grows without bound
            what = (
                "the scheme is unstable (its variance grows without bound)"
                if not np.isfinite(bias)
                else f"its stationary variance is off by {bias:.0%} (allowed {MAX_STEP_BIAS:.0%})"
            )
            raise ValueError(
                f"`dt` = {dt!r} s is too large for this device{resolves} with {scheme}: on the "
                f"linearised device {what}; use dt <= {limit:.3g} s"
            )
        if bias > WARN_STEP_BIAS:
            # the step that keeps the warning away, so that the message says what to do
            quiet = self.largest_step(scheme, bias=WARN_STEP_BIAS)
            warnings.warn(
                f"dt = {dt!r} s gives {scheme} a stationary-variance bias of about {bias:.2%} "
                f"on the linearised device{resolves}; use dt <= {quiet:.2g} s for less than "
                f"{WARN_STEP_BIAS:.0%}",
                StepSizeWarning,
                stacklevel=3,
            )


def step_bias(scheme: str, harvester: Harvester, psd, dt: float) -> float:
    """Relative bias of the scheme's stationary variances on the linearised device.

    The scheme applied to ``m z'' + c_eff z' + k_eff z = m w`` is a linear
    Gaussian recursion whose stationary variance is exact
    (:func:`randvib.montecarlo.integrators.scheme_stationary_covariance`); its departure from
    S m / (4 c_eff) measures the time-step bias. Euler-Maruyama's bias is about
    x / (1 - x) with x = k_eff dt / c_eff (energy gain per step against
    damping), so it needs far smaller steps than Heun on lightly damped
    devices. Returns inf where the recursion is unstable.

    Under a rational spectrum (``psd`` a band-pass or Kanai-Tajimi
    excitation), or with a circuit state, the recursion is that of the
    linearised device with the filter's and the circuit's states, and the
    bias is the largest of those of E[y^2] (the filter's own), E[z^2], E[v^2]
    and the circuit's E[x^2]; the linearised device is the white-noise one at
    the excitation's level, as for white noise. See :class:`LinearTestSystem`.
    """
    return LinearTestSystem.of(harvester, psd).bias(scheme, dt)


def largest_step(scheme: str, harvester: Harvester, psd, bias: float = MAX_STEP_BIAS) -> float:
    """Largest dt (s) whose :func:`step_bias` stays below ``bias`` (bisection)."""
    return LinearTestSystem.of(harvester, psd).largest_step(scheme, bias)


def _linearised_under(harvester: Harvester, excitation: Excitation) -> tuple:
    """(k_eq, c_eq, E[z^2], E[v^2]) of the device linearised under a non-rational input.

    Statistical linearisation's route (:func:`randvib.analytic.statistical_linearisation.linearise`)
    for memoryless friction; with a friction state (LuGre) the viscous device
    (k, c) and its spectral variances. Used for the step check and the
    random start when the input is synthesised or recorded: there the scheme
    integrates the device alone, the input's step integral being exact.
    """
    h = harvester
    excitation = coarsened(excitation)
    if h.potential.is_free:
        # no stationary z (paths start at z = 0); the velocity's is the free mass's own
        c_eq, v2 = _free_mass_velocity(h, excitation)
        return 0.0, c_eq, 0.0, v2
    if h.friction is None or h.friction.has_equivalent_damping:
        try:
            res = linearise(h, excitation)
        except ValueError:
            # a double well whose response has no zero-mean Gaussian fixed point
            # (or several): the simulation needs none, only a step and a start
            if h.k > 0 or not h.c > 0:
                raise
            return _gibbs_linearised_under(h, excitation)
        return res.k_eq, res.c_eq, res.displacement_variance, res.velocity_variance
    if h.k <= 0 and h.c > 0:  # no stable viscous linear device: the spring's Gibbs stiffness
        return _gibbs_linearised_under(h, excitation)
    block = device_block(float(h.m), float(h.c), float(h.k), h.electrical)
    var = output_variances(block, excitation)
    return float(h.k), float(h.c), var["z"], var["v"]


def driven_circuit_variance(harvester: Harvester, excitation: Excitation) -> float:
    """E[x^2] of the circuit state under synthesised or recorded input (V^2 or A^2).

    The linear device (k_eff, c_eff) of :func:`_linearised_under` with its
    circuit, under the coarsened spectrum: statistical linearisation's circuit
    variance where its fixed point exists, the Gibbs-stiffness device for a
    double well where it does not, the (v, circuit) block for the free mass.
    A friction law with memory is left out (it only adds damping). Used for
    the random start, which the burn-in corrects.
    """
    h = harvester
    if h.friction is not None and not h.friction.has_equivalent_damping:
        h = h.updated(friction=None)
    k_eff, c_eff, _, _ = _linearised_under(h, excitation)
    block = device_block(float(h.m), c_eff, k_eff, h.electrical)
    if h.potential.is_free:
        block = _without_z(block)
    return output_variances(block, coarsened(excitation))[h.electrical.state_name]


def _without_z(block: StateSpace) -> StateSpace:
    """The block without its z state (the first): the free mass's stationary part."""
    keep = list(range(1, block.n_states))
    return StateSpace(
        block.a[np.ix_(keep, keep)],
        block.b[keep],
        block.c[np.ix_(keep, keep)],
        block.d[keep],
        block.outputs[1:],
    )


def _gibbs_linearised_under(harvester: Harvester, excitation: Excitation) -> tuple:
    """(k_eff, c_eff, E[z^2], E[v^2]) without statistical linearisation, for a soft spring (k <= 0).

    The stiffness is k + 3 k3 E[z^2] with E[z^2] of the exact friction-free
    (Gibbs) density at a white level equal to the spectrum's peak height: white
    noise at that level carries at least the input's power at every frequency,
    and friction only shrinks the motion, so the stiffness is an upper bound
    in the mean and the step it admits is conservative. E[z^2] is that Gibbs
    moment (it sees both wells, so it sizes the start and the histograms);
    E[v^2] is the linear device's (k_eff, c) under the input; c_eff adds the
    memoryless friction law's equivalent damping at that spread (Eq. 19).
    """
    h = harvester
    lo, hi = excitation.support
    grid = np.unique(np.concatenate([excitation.breakpoints(), np.linspace(lo, hi, 4097)]))
    grid = grid[np.isfinite(grid) & (grid >= lo) & (grid <= hi)]
    peak = float(np.max(excitation.psd(grid)))
    m, c, k, k3 = (float(x) for x in (h.m, h.c, h.k, h.k3))
    z2 = exact.gibbs_displacement_moment(m, c, k, k3, peak)
    k_eff = k + 3.0 * k3 * z2
    v2 = output_variances(device_block(m, c, k_eff, h.electrical), excitation)["v"]
    c_eff = c
    if h.friction is not None and h.friction.has_equivalent_damping and not h.friction.vanishes:
        c_eff += float(h.friction.equivalent_damping_increment(np.sqrt(v2)))
    return k_eff, c_eff, z2, v2


def _free_mass_velocity(harvester: Harvester, excitation: Excitation) -> tuple[float, float]:
    """(c_eq, E[v^2]) of the free mass (k = k3 = 0) linearised under any excitation.

    Without a spring z feeds back into nothing, so the velocity (and the
    circuit state) form a stationary linear system on their own: the device
    block without its z state, with c_eq = c + the friction law's equivalent
    damping increment at the Gaussian velocity's spread (paper Eq. 19; a
    friction law with memory, LuGre, is left out: it only adds damping). The
    fixed point in log E[v^2] is a contraction (E[v^2] grows at most like
    sqrt(E[v^2]) through the Coulomb increment), so plain iteration converges.
    """
    h = harvester
    friction = h.friction
    if friction is not None and (not friction.has_equivalent_damping or friction.vanishes):
        friction = None
    m, c = float(h.m), float(h.c)

    def velocity_variance(c_eq):
        return output_variances(_without_z(device_block(m, c_eq, 0.0, h.electrical)), excitation)[
            "v"
        ]

    if friction is None:
        return c, velocity_variance(c)
    # start from the friction-free device, or from the friction alone at unit spread
    c_eq = c if c > 0 else float(friction.equivalent_damping_increment(1.0))
    for _ in range(200):
        v2 = velocity_variance(c_eq)
        updated = c + float(friction.equivalent_damping_increment(np.sqrt(v2)))
        if abs(updated / c_eq - 1.0) < 1e-12:
            break
        c_eq = updated
    return c_eq, velocity_variance(c_eq)


def _scheme_bias(scheme, m, k_eff, c_eff, psd, dt) -> float:
    """:func:`step_bias` for an already linearised device (inf where unstable).

    With k_eff = 0 (the free mass) only the velocity is stationary: the bias
    of E[v^2] of the scheme's recursion on dv = -(c_eff/m) v dt + dW.
    """
    if k_eff == 0:
        a, b = integrators.integrator(scheme).linear_recursion([[-c_eff / m]], [[1.0]], dt)
        if abs(a[0, 0]) >= 1:
            return float("inf")
        discrete = dt * b[0, 0] ** 2 / (1.0 - a[0, 0] ** 2)
        return abs(discrete * 2.0 * c_eff / m - 1.0)
    try:
        # near the stability edge the Lyapunov solve is ill-conditioned; the bias
        # is then huge either way, and scipy's warning would precede the refusal
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", linalg.LinAlgWarning)
            cov = integrators.scheme_stationary_covariance(scheme, m, c_eff, k_eff, psd, dt)
    except ValueError:
        return float("inf")
    return abs(cov[1, 1] / exact.linear_velocity_variance(m, c_eff, psd) - 1.0)


def _augmented_system(m, k_eff, c_eff, excitation: Excitation, coupling=None):
    """(F, G, C) of the linear device (and circuit) driven through the excitation's filter.

    dx = F x dt + G dW with the states (filter, z, v, circuit); the rows of C
    pick y (the base acceleration; none under white noise), z, v and the
    circuit state. For the free mass (k_eff = 0) z is left out.
    """
    block = device_block(m, c_eff, k_eff, coupling)
    if excitation.is_white:
        system, q, n_filter, rows = block, excitation.level / 2.0, 0, []
    else:
        shaping = excitation.shaping_filter()
        system = block.driven_by(shaping.system, "acceleration")
        q, n_filter = shaping.noise_intensity, shaping.system.n_states
        rows = [np.concatenate([shaping.system.c[0], np.zeros(block.n_states)])]
    pick = np.vstack(rows + [np.hstack([np.zeros((block.n_states, n_filter)), block.c])])
    g = np.sqrt(q) * system.b[:, None]
    a = system.a
    if k_eff == 0:
        # the free mass: z is not stationary (no Lyapunov solution) and, with
        # no spring, feeds back into nothing; the stationary system is
        # (filter, v, circuit), whose variances the step check compares
        keep = [i for i in range(a.shape[0]) if i != n_filter]
        a, g = a[np.ix_(keep, keep)], g[keep]
        pick = pick[np.abs(pick[:, n_filter]) == 0][:, keep]
    return a, g, pick


def _augmented_bias(scheme, f, g, pick, dt) -> float:
    """Largest relative bias of the picked variances of the scheme on an augmented system.

    The scheme's exact recursion x_{n+1} = A x_n + B dW_n
    (:meth:`Integrator.linear_recursion`) has the stationary covariance
    P = A P A^T + dt B B^T, against the continuous Lyapunov F P + P F^T + G G^T = 0.
    """
    a, b = integrators.integrator(scheme).linear_recursion(f, g, dt)
    if max(abs(np.linalg.eigvals(a))) >= 1:
        return float("inf")
    discrete = np.diag(pick @ linalg.solve_discrete_lyapunov(a, dt * (b @ b.T)) @ pick.T)
    continuous = np.diag(pick @ linalg.solve_continuous_lyapunov(f, -(g @ g.T)) @ pick.T)
    return float(np.max(np.abs(discrete / continuous - 1.0)))


def coarsened(excitation: Excitation, nodes: int = 1024) -> Excitation:
    """A long table (a record's Welch PSD: tens of thousands of bins) as ``nodes`` cells.

    Each cell keeps its exact power (``cumulative_power`` differenced), so the
    variances the step check and the random start need are those of the
    spectrum smoothed over cells of (support width / nodes), computed in a
    fraction of the time of a quadrature over every bin.
    """
    if len(excitation.breakpoints()) <= 2 * nodes:
        return excitation
    lo, hi = excitation.support
    edges = np.linspace(lo, hi, nodes + 1)
    density = np.diff(excitation.cumulative_power(edges)) / np.diff(edges)
    return Tabulated(np.concatenate([[lo], 0.5 * (edges[1:] + edges[:-1]), [hi]]),
                     np.concatenate([[0.0], density, [0.0]]))  # fmt: skip
