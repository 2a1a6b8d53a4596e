"""The linearised assembly as a linear test system: step bias, largest step, random start.

An assembly's Monte Carlo run (:func:`randvib.montecarlo.assembly_simulation.simulate_assembly`)
checks its time step and draws its random start from one linear Gaussian
system, as the single mass does (:mod:`randvib.montecarlo.step_check`):

* the **surrogate** assembly (:func:`linear_surrogate`): friction with memory
  (LuGre) left out (it only adds damping), quadratic springs left out (the
  zero-mean closure does not take them), each diode bridge replaced by its
  conducting linear coupling
  (:meth:`~randvib.models.rectifier.Rectified.linear_surrogate`);
* **linearised** by the statistical linearisation of assemblies
  (:func:`randvib.analytic.assembly_linearisation.linearise_assembly`: each
  cubic spring and memoryless friction law on its own coordinate, Gaussian
  closure) under the excitation, or its coarsened spectrum for synthesised
  and recorded input (:func:`~randvib.montecarlo.step_check.coarsened`);
* driven as the kernel drives it: through the shaping filter's states under
  a rational spectrum, by white noise of the excitation's level under white
  noise, by unit white noise under synthesised or recorded input (whose step
  integrals reach the velocities with unit amplitude).

On that system a scheme is a linear recursion with an exact stationary
covariance (:meth:`randvib.montecarlo.integrators.Integrator.linear_recursion`);
its largest relative departure from the continuous Lyapunov covariance, over
every DOF's displacement and velocity, the circuits' states and the filter's
output, is the step's bias (:func:`randvib.montecarlo.step_check._augmented_bias`,
shared with the single mass), refused above
:data:`~randvib.montecarlo.step_check.MAX_STEP_BIAS` and warned about above
:data:`~randvib.montecarlo.step_check.WARN_STEP_BIAS`.
"""

from __future__ import annotations

import dataclasses
import functools
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import linalg

from randvib.analytic.assembly_linear import _spectral
from randvib.analytic.assembly_linearisation import linearise_assembly
from randvib.models.assembly import Assembly
from randvib.models.assembly_parts import Element, Transducer
from randvib.models.excitation import Excitation, as_excitation
from randvib.models.state_space import StateSpace
from randvib.montecarlo.step_check import (
    MAX_STEP_BIAS,
    WARN_STEP_BIAS,
    StepSizeWarning,
    _augmented_bias,
    coarsened,
)


def linear_surrogate(assembly: Assembly) -> Assembly:
    """The assembly the closure takes: no LuGre, no k2, each bridge as its conducting coupling."""
    elements = []
    for element in assembly.elements:
        friction = element.friction
        if friction is not None and not friction.has_equivalent_damping:
            friction = None
        spring = element.spring
        if spring is not None and spring.k2 != 0:
            spring = dataclasses.replace(spring, k2=0.0)
        if spring is None and friction is None and element.damping == 0:
            continue  # nothing linearisable left on this coordinate
        elements.append(Element(element.between, spring, friction, element.damping))
    transducers = [
        Transducer(t.between, t.coupling.linear_surrogate() if t.is_rectified else t.coupling)
        for t in assembly.transducers
    ]
    return Assembly(
        assembly.mass, assembly.stiffness, assembly.damping, assembly.influence,
        tuple(elements), tuple(transducers),
    )  # fmt: skip


@dataclass(frozen=True, eq=False)
class AssemblyTestSystem:
    """The linearised assembly (with its filter and circuit states) a run is checked on.

    Build it with :meth:`of`.

    Attributes
    ----------
    assembly : Assembly
        The assembly as given.
    surrogate : Assembly
        :func:`linear_surrogate` of it.
    excitation : Excitation
    drift, noise : ndarray
        F and G of ``dX = F X dt + G dW`` over ``[filter states, x, v,
        surrogate circuit states]``.
    pick : ndarray
        Rows picking the filter's output, every x and v, and the circuit states.
    covariance : ndarray
        E[X X^T] over ``[x, v, surrogate circuit states]`` under the excitation
        itself (the linearisation's response).
    n_filter : int
        The shaping filter's states in ``drift`` (0 under white, synthesised or
        recorded input).
    """

    assembly: Assembly
    surrogate: Assembly
    excitation: Excitation
    drift: np.ndarray
    noise: np.ndarray
    pick: np.ndarray
    covariance: np.ndarray
    n_filter: int

    @classmethod
    def of(cls, assembly: Assembly, psd) -> AssemblyTestSystem:
        """The linear test system of ``assembly`` under ``psd`` (a level or an excitation)."""
        excitation = as_excitation(psd)
        surrogate = linear_surrogate(assembly)
        shaping = excitation.shaping_filter()
        driven = shaping is None
        under = coarsened(excitation) if driven else excitation
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")  # the closure's validity is the analytic method's
            lin = linearise_assembly(surrogate, under)
        response = lin.response
        a, b = surrogate.linear_state_space(response.extra_damping, response.extra_stiffness)
        if driven or excitation.is_white:
            level = 1.0 if driven else excitation.level
            drift, noise, n_filter = a, np.sqrt(level / 2.0) * b[:, None], 0
            pick = np.eye(a.shape[0])
        else:
            fa, fb = shaping.system.a, shaping.system.b
            fc = shaping.system.c[shaping.system.output("acceleration")]
            n_filter = fa.shape[0]
            drift = np.block([[fa, np.zeros((n_filter, a.shape[0]))], [np.outer(b, fc), a]])
            noise = np.sqrt(shaping.noise_intensity) * np.concatenate([fb, 0.0 * b])[:, None]
            pick = np.zeros((1 + a.shape[0], drift.shape[0]))
            pick[0, :n_filter] = fc
            pick[1:, n_filter:] = np.eye(a.shape[0])
        return cls(
            assembly, surrogate, excitation, drift, noise, pick, response.covariance, n_filter
        )

    @functools.cached_property
    def start_covariance(self) -> np.ndarray:
        """E[X X^T] over ``[filter states, x, v, surrogate circuit states]``: the random start.

        The Lyapunov solution of the test system under white noise or a
        rational spectrum (the filter's states jointly with the assembly's);
        under synthesised or recorded input, which the test system sees as unit
        white noise, the linearisation's response to the spectrum itself.
        """
        if self.excitation.shaping_filter() is None:
            return self.covariance
        p = linalg.solve_continuous_lyapunov(self.drift, -(self.noise @ self.noise.T))
        return 0.5 * (p + p.T)

    def forced_covariance(self, tones, shocks) -> np.ndarray:
        """E[X X^T] of tones and a shock train alone on the test system (a random start's part).

        Over the states of :attr:`start_covariance` (the filter's rows 0: the
        forcing does not pass through it). A tone of amplitude A reaches the
        velocities as -r A cos(omega t + phi): its response X = Re(h A e^{i(omega t + phi)})
        with ``h = (i omega - F)^-1 b``, covariance (A^2 / 2) Re(h h^H) over
        the random phase; the shock train by its Campbell spectrum
        (:func:`randvib.analytic.assembly_linear._spectral`).
        """
        nf, n = self.n_filter, self.assembly.n_dof
        a = self.drift[nf:, nf:]
        size = a.shape[0]
        b = np.zeros(size)
        b[n : 2 * n] = -self.assembly.influence
        names = tuple(f"s{i}" for i in range(size))
        block = StateSpace(a, b, np.eye(size), np.zeros(size), names)
        part = np.zeros((size, size))
        for tone in tones:
            h = block.frequency_response(np.array([tone.frequency]))[:, 0]
            part += tone.mean_square * np.real(np.outer(h, h.conj()))
        if shocks is not None:
            part += _spectral(block, shocks)[0]
        out = np.zeros_like(self.drift)
        out[nf:, nf:] = part
        return out

    def bias(self, scheme: str, dt: float) -> float:
        """Largest relative bias of the scheme's stationary variances at ``dt`` (inf if unstable)."""
        return _augmented_bias(scheme, self.drift, self.noise, self.pick, dt)

    def largest_step(self, scheme: str, bias: float = MAX_STEP_BIAS) -> float:
        """Largest dt (s) whose :meth:`bias` stays below ``bias`` (bisection)."""
        lo, hi = 0.0, 2.0 / max(abs(np.linalg.eigvals(self.drift)))
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if self.bias(scheme, mid) <= bias:
                lo = mid
            else:
                hi = mid
        return lo

    def check_step(self, scheme: str, dt: float) -> None:
        """Refuse ``dt`` above MAX_STEP_BIAS; warn above WARN_STEP_BIAS, with the step that passes."""
        bias = self.bias(scheme, dt)
        where = "the linearised assembly (every DOF, circuit and filter state)"
        if bias > MAX_STEP_BIAS:
            limit = self.largest_step(scheme)
            what = (
                "the scheme is unstable (its variance grows without bound)"
                if not np.isfinite(bias)
                else f"a stationary variance is off by {bias:.0%} (allowed {MAX_STEP_BIAS:.0%})"
            )
            raise ValueError(
                f"`dt` = {dt!r} s is too large for this assembly with {scheme}: on {where} "
                f"{what}; use dt <= {limit:.3g} s"
            )
        if bias > WARN_STEP_BIAS:
            quiet = self.largest_step(scheme, bias=WARN_STEP_BIAS)
            warnings.warn(
                f"dt = {dt!r} s gives {scheme} a stationary-variance bias of about {bias:.2%} on "
                f"{where}; use dt <= {quiet:.2g} s for less than {WARN_STEP_BIAS:.0%}",
                StepSizeWarning,
                stacklevel=4,
            )
