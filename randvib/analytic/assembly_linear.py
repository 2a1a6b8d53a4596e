"""Stationary response of a linear(ised) assembly: the exact second moments, per transducer.

The linear part of an :class:`~randvib.models.assembly.Assembly` (its state
space ``X' = A X + B a`` with ``X = [x, x', circuit states]``,
:meth:`~randvib.models.assembly.Assembly.linear_state_space`), plus the
equivalent dashpots and springs a linearisation adds, is driven by the base
acceleration a of any excitation. Its stationary state covariance P comes
from one of two independent routes (as for the single mass,
:mod:`randvib.analytic.linear_response`):

* **Lyapunov** (rational spectra: white, band-pass, Kanai-Tajimi): the
  assembly driven by the excitation's shaping filter is one linear system
  ``Z' = F Z + G w`` with E[w(t1) w(t2)] = (S/2) delta(t2 - t1); P is the
  device block of the solution of ``F P + P F^T + (S/2) G G^T = 0``.
* **Spectral integral** (any spectrum: band-limited, tabulated, measured):
  ``P = int_0^inf Re(H(f) H(f)^H) S(f) df`` with H the transfer function
  from a to X, on the composite Gauss-Legendre rule of
  :func:`~randvib.analytic.linear_response.frequency_rule`.

Everything reported follows from P: the DOFs' variances; a coordinate's
``E[u^2] = d^T P_xx d`` and ``E[u'^2] = d^T P_vv d``; a static coupling's
power ``c_e E[u'^2]``, a circuit's ``(R_L + R_C) E[i^2]`` or ``E[V^2] / R_L``
and the load's share; the dissipated power ``tr(C_total P_vv)`` plus the
circuits'. The injected power is ``r^T M r S / 4`` under white noise
(docs/conventions.md, "Assemblies") and ``-(M r)^T E[a x']`` otherwise
(``E[a x']`` from the filter's block of the Lyapunov solution, or
``int Re(H_v) S df``); for the linear system the two balance exactly, which
:meth:`AssemblyResponse.energy_balance` reports.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg

from randvib._validation import check_choice
from randvib.analytic.linear_response import VARIANCE_METHODS, frequency_rule, lyapunov_shaping
from randvib.models.assembly import Assembly
from randvib.models.combined import Combined, parts_of
from randvib.models.excitation import Excitation
from randvib.models.state_space import StateSpace


class UnstableAssembly(ValueError):
    """The linear(ised) assembly has a mode that does not decay: no stationary response."""


def assembly_block(assembly: Assembly, extra_damping=None, extra_stiffness=None) -> StateSpace:
    """The assembly's linear part (plus equivalent dashpots and springs) as a block.

    Input the base acceleration (m/s^2); outputs every state, named by
    :meth:`~randvib.models.assembly.Assembly.state_names`.
    """
    a, b = assembly.linear_state_space(extra_damping, extra_stiffness)
    n = b.size
    return StateSpace(a, b, np.eye(n), np.zeros(n), assembly.state_names())


def require_stable(a: np.ndarray) -> None:
    """Refuse a state matrix with an eigenvalue of non-negative real part (one line)."""
    eig = np.linalg.eigvals(a)
    # an undamped mode's eigenvalues come out with real parts of rounding size, either sign
    if np.any(~np.isfinite(eig)) or np.any(eig.real >= -1e-12 * np.max(np.abs(eig))):
        worst = eig[np.argmax(np.where(np.isfinite(eig.real), eig.real, np.inf))]
        raise UnstableAssembly(
            "the linear(ised) assembly has a mode that does not decay (eigenvalue "
            f"{complex(worst):.6g} 1/s): an undamped or free mode, or a negative stiffness, "
            "has no stationary response"
        )


@dataclass(frozen=True, eq=False)
class AssemblyResponse:
    """Stationary second moments of a linear(ised) assembly (SI units).

    Attributes
    ----------
    assembly : Assembly
    covariance : ndarray
        E[X X^T] over the states ``[x, x', circuit states]``.
    extra_damping, extra_stiffness : ndarray
        The equivalent dashpots and springs a linearisation added (zero for
        a linear assembly), N x N.
    power_input : float or None
        Mean power the base acceleration injects (W); None where it is not
        defined by the route (a filter with direct feed-through).
    method : str
        ``lyapunov`` or ``spectral``.
    """

    assembly: Assembly
    covariance: np.ndarray
    extra_damping: np.ndarray
    extra_stiffness: np.ndarray
    power_input: float | None
    method: str

    @property
    def displacement_variance(self) -> np.ndarray:
        """E[x_i^2] (m^2), one per DOF."""
        n = self.assembly.n_dof
        return np.diag(self.covariance)[:n].copy()

    @property
    def velocity_variance(self) -> np.ndarray:
        """E[x_i'^2] ((m/s)^2), one per DOF."""
        n = self.assembly.n_dof
        return np.diag(self.covariance)[n : 2 * n].copy()

    def coordinate_variances(self, part) -> tuple[float, float]:
        """(E[u^2] (m^2), E[u'^2] ((m/s)^2)) of an element's or a transducer's coordinate."""
        n = self.assembly.n_dof
        d = self.assembly.incidence(part)
        p = self.covariance
        return float(d @ p[:n, :n] @ d), float(d @ p[n : 2 * n, n : 2 * n] @ d)

    def circuit_mean_square(self, index: int) -> float | None:
        """E[s^2] of the transducer ``index``'s circuit state (A^2 or V^2); None without one."""
        circuits = self.assembly.circuit_transducers
        if index not in circuits:
            return None
        slot = 2 * self.assembly.n_dof + circuits.index(index)
        return float(self.covariance[slot, slot])

    def transducer_power(self, index: int) -> tuple[float, float | None]:
        """(power_electrical, power_load) of transducer ``index`` (W); power_load None without a load."""
        transducer = self.assembly.transducers[index]
        _, velocity = self.coordinate_variances(transducer)
        coupling = transducer.coupling
        electrical = float(coupling.power_electrical(velocity, self.circuit_mean_square(index)))
        if not transducer.has_load:
            return electrical, None
        return electrical, electrical * float(coupling.load_fraction)

    def dissipated_power(self) -> float:
        """All the power dissipated (W): tr(C_total E[x' x'^T]) plus the circuits' resistances."""
        n = self.assembly.n_dof
        _, c, _ = self.assembly.linear_matrices()
        viscous = float(np.trace((c + self.extra_damping) @ self.covariance[n : 2 * n, n : 2 * n]))
        circuits = sum(self.transducer_power(i)[0] for i in self.assembly.circuit_transducers)
        return viscous + circuits

    def energy_balance(self) -> float | None:
        """Dissipated over injected power: 1 to rounding for the linear(ised) system."""
        if self.power_input is None or not self.power_input > 0:
            return None
        return self.dissipated_power() / self.power_input


def linear_response(
    assembly: Assembly,
    excitation: Excitation,
    extra_damping=None,
    extra_stiffness=None,
    method: str = "auto",
) -> AssemblyResponse:
    """The stationary response of the assembly's linear part under an excitation.

    Parameters
    ----------
    assembly : Assembly
        Its nonlinear parts are ignored here (a linearisation passes their
        equivalents as ``extra_damping`` and ``extra_stiffness``).
    excitation : Excitation
        Any spectrum; rational ones by the Lyapunov equation unless
        ``method="spectral"``.
    extra_damping, extra_stiffness : ndarray or None
        N x N matrices added to the linear part's C and K.
    method : {"auto", "lyapunov", "spectral"}

    Raises
    ------
    UnstableAssembly
        When a mode of the linear(ised) assembly does not decay.
    """
    check_choice("method", method, VARIANCE_METHODS)
    n = assembly.n_dof
    extra_damping = np.zeros((n, n)) if extra_damping is None else np.asarray(extra_damping)
    extra_stiffness = np.zeros((n, n)) if extra_stiffness is None else np.asarray(extra_stiffness)
    block = assembly_block(assembly, extra_damping, extra_stiffness)
    require_stable(block.a)
    continuous, tones = _continuous_and_tones(excitation)
    covariance, power, used = np.zeros_like(block.a), 0.0, "spectral"
    if continuous is not None:
        shaping = lyapunov_shaping(continuous, method)
        if shaping is not None:
            covariance, cross = _lyapunov(block, shaping)
            used = "lyapunov"
        else:
            covariance, cross = _spectral(block, continuous)
        power = _injected_power(assembly, continuous, cross)
    for tone in tones:  # superposition: each line through the frequency response
        h = block.frequency_response(np.array([tone.frequency]))[:, 0]
        covariance = covariance + tone.mean_square * np.real(np.outer(h, h.conj()))
        if power is not None:  # -(M r)^T E[a x'], E[a X] = (A^2 / 2) Re(h)
            n = assembly.n_dof
            mr = assembly.mass @ assembly.influence
            power += float(-mr @ (tone.mean_square * np.real(h[n : 2 * n])))
    return AssemblyResponse(assembly, covariance, extra_damping, extra_stiffness, power, used)


def _continuous_and_tones(excitation: Excitation) -> tuple:
    """(the input's part with a spectral density or None, its tones).

    Tones are lines, which neither the Lyapunov equation nor the spectral
    integral takes: the caller adds each one's response (independent inputs).
    """
    random, tones, shocks = parts_of(excitation)
    if not tones:
        return excitation, ()
    if shocks is None:
        return random, tones
    return Combined(random, (), shocks), tones


def _lyapunov(block: StateSpace, shaping):
    """(P over the block's states, E[a X] or None) by the Lyapunov equation with the filter."""
    system = block.driven_by(shaping.system, "acceleration")
    q = shaping.noise_intensity * np.outer(system.b, system.b)
    full = linalg.solve_continuous_lyapunov(system.a, -q)
    nf = shaping.system.n_states
    covariance = 0.5 * (full[nf:, nf:] + full[nf:, nf:].T)
    row = shaping.system.output("acceleration")
    if nf == 0 or shaping.system.d[row] != 0:
        return covariance, None  # white noise (its input power is exact) or feed-through
    return covariance, shaping.system.c[row] @ full[:nf, nf:]


def _spectral(block: StateSpace, excitation: Excitation):
    """(P, E[a X]) by the spectral integral int Re(H H^H) S df on the quadrature rule."""
    nodes, weights = frequency_rule(block, excitation)
    h = block.frequency_response(nodes)  # (states, nodes)
    density = excitation.psd(nodes) * weights
    covariance = np.real((h * density) @ h.conj().T)
    return 0.5 * (covariance + covariance.T), np.real(h) @ density


def _injected_power(assembly: Assembly, excitation: Excitation, cross) -> float | None:
    """-(M r)^T E[a x'] (W); r^T M r S / 4 under white noise."""
    mr = assembly.mass @ assembly.influence
    if excitation.is_white:
        return float(assembly.influence @ mr * excitation.level / 4.0)
    if cross is None:
        return None
    n = assembly.n_dof
    return float(-mr @ cross[n : 2 * n])
