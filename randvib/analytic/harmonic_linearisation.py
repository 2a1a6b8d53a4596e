"""Combined harmonic and random linearisation: tones on noise, and the linear devices' exact answer.

Under base acceleration ``a = sum_q A_q cos(omega_q t + phi_q) + (random)``
the response of a linear device is the sum of each tone through its
frequency response, ``|H(i omega_q)| A_q``, and the random part's
stationary response: superposition, exact (docs/conventions.md, "Tones").
Shocks on a linear device are exact the same way: their Campbell spectrum
(:class:`randvib.models.shock.ShockTrain`) is one more independent part.

A nonlinear device (friction, cubic spring) is linearised on the combined
motion (Roberts and Spanos, *Random Vibration and Statistical
Linearization*, Wiley 1990, ch. 6, "combined periodic and random
excitation"; Bulsara, Lindenberg and Shuler, J. Stat. Phys. 27 (1982) 787;
Spanos and Iwan 1979). The response is taken to be

    z = sum_q Z_q cos(theta_q) + z_r,    v = sum_q V_q cos(theta_q + pi/2) + v_r,

the phases theta_q independent and uniform, z_r, v_r a zero-mean Gaussian
random part of variances sigma_z^2, sigma_v^2 independent of them, V_q =
omega_q Z_q. Each part gets its own equivalent linear device, from the
expectations over the *whole* motion:

* the random part (Stein's identity, E[x_r f(x)] = sigma^2 E[f'(x)]):
  ``c_r = c + E[v_r F(v)] / sigma_v^2``, ``k_r = k + 3 k3 E[z^2]``,
  E[z^2] = sigma_z^2 + sum_q Z_q^2 / 2;
* tone q (its describing function averaged over the rest of the motion):
  ``c_q = c + 2 E[F(v) cos(theta_q)] / V_q`` (v's tone-q part written
  V_q cos theta_q), ``k_q = k + 3 k3 E[z^2] - (3/4) k3 Z_q^2`` (the cubic's
  first harmonic, Z_q^3 3/8 + 3 Z_q E[w^2] / 2 with w the rest of z);

then sigma_v^2, sigma_z^2 are the linear device (m, c_r, k_r)'s response to
the random part (:func:`randvib.analytic.linear_response.output_variances`)
and Z_q = |H_z(i omega_q; m, c_q, k_q)| A_q; all are solved together as one
fixed point in their logarithms. The expectations over the phases use the
trapezoid rule (exact for trigonometric polynomials, spectrally accurate
for the smooth averages of a Gaussian); over the random part, Coulomb's
closed forms E[sgn(mu + sigma X)] = erf(mu / (sigma sqrt 2)), E[X sgn(mu +
sigma X)] = 2 phi(mu / sigma), else Gauss-Legendre panels refined at v = 0.

The stroke exceedance is that of the sinusoids plus the Gaussian,
``E_theta[Q((d - h) / sigma_z) + Q((d + h) / sigma_z)]``, h = sum_q Z_q cos theta_q.
With a circuit state (coil inductance, piezo capacitance) the circuit is a
state of each linear block and its mean square adds up the same way.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy import special

from randvib._validation import check_scalar_device
from randvib.analytic.fixed_point import LinearisationDidNotConverge, TrialUndefined, solve
from randvib.analytic.linear_response import (
    ResponseSpectra,
    device_block,
    output_variances,
    response_spectra,
)
from randvib.analytic.linearisation import linear_power
from randvib.analytic.method import is_linear_device
from randvib.models.combined import parts_of
from randvib.models.potential import CONFINING

#: Phase points per tone of the equivalents' phase average (trapezoid rule), by number
#: of tones: a tensor grid of at most 4096 points.
_PHASES = {1: 64, 2: 64, 3: 16, 4: 8}
#: Phase points per tone of the stroke exceedance and E|v| (their integrands are sharper).
_REPORT_PHASES = {1: 512, 2: 64, 3: 16, 4: 8}
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(20)


def phase_grid(n_tones: int, points: dict = _PHASES) -> np.ndarray:
    """cos-argument grid: shape (n_points, n_tones) of phases (rad), equal weights."""
    if n_tones == 0:
        return np.zeros((1, 0))
    m = points.get(n_tones, max(2, int(4096 ** (1.0 / n_tones))))
    one = 2.0 * np.pi * (np.arange(m) + 0.5) / m
    return np.array(list(itertools.product(one, repeat=n_tones)))


def gaussian_friction_moments(law, mean, sigma):
    """(E[F(mu + sigma X)], E[X F(mu + sigma X)]) for X ~ N(0, 1), at each ``mean`` mu.

    ``law`` a memoryless friction law (or None); sigma (m/s) >= 0 one number.
    Coulomb in closed form; other laws by composite Gauss-Legendre in v on
    panels 0.5 sigma wide, refined geometrically near v = 0 down to the
    law's inner scale (1/beta for tanh), where F changes fastest.
    """
    mu = np.asarray(mean, dtype=float)
    if law is None or law.vanishes:
        return np.zeros_like(mu), np.zeros_like(mu)
    if sigma == 0.0:
        return np.asarray(law.force(mu), dtype=float), np.zeros_like(mu)
    form = law.coulomb_tanh_form()
    if form is not None and np.isinf(form[1]):
        fc = float(form[0])
        x = mu / sigma
        return fc * special.erf(x / np.sqrt(2.0)), fc * np.sqrt(2.0 / np.pi) * np.exp(-0.5 * x * x)
    inner = sigma if form is None else min(sigma, 1.0 / float(form[1]))
    lo, hi = float(mu.min()) - 10.0 * sigma, float(mu.max()) + 10.0 * sigma
    edges = np.arange(lo, hi + 0.5 * sigma, 0.5 * sigma)
    near = np.geomspace(1e-3 * inner, 0.5 * sigma, 40)
    edges = np.unique(np.concatenate([edges, near, -near, [0.0]]))
    edges = edges[(edges >= lo) & (edges <= hi)]
    half = 0.5 * np.diff(edges)
    v = ((edges[:-1] + half)[:, None] + half[:, None] * _NODES).ravel()
    w = (half[:, None] * _WEIGHTS).ravel()
    force = np.asarray(law.force(v), dtype=float)
    x = (v[None, :] - mu.ravel()[:, None]) / sigma
    density = np.exp(-0.5 * x * x) / (sigma * np.sqrt(2.0 * np.pi)) * w
    mean_force = density @ force
    return (mean_force.reshape(mu.shape), ((density * x) @ force).reshape(mu.shape))


@dataclass(frozen=True)
class ToneResponse:
    """One tone's share of the response (SI units).

    Attributes
    ----------
    frequency : float
        Hz.
    amplitude : float
        The tone's base-acceleration amplitude A (m/s^2).
    displacement_amplitude, velocity_amplitude : float
        Z = |H_z| A (m) and V = omega Z (m/s).
    circuit_amplitude : float or None
        |H_x| A of a circuit state (A or V).
    c_eq, k_eq : float
        The tone's equivalent damping (Ns/m) and stiffness (N/m).
    """

    frequency: float
    amplitude: float
    displacement_amplitude: float
    velocity_amplitude: float
    circuit_amplitude: float | None
    c_eq: float
    k_eq: float

    def to_dict(self) -> dict:
        out = dict(self.__dict__)
        if out["circuit_amplitude"] is None:
            del out["circuit_amplitude"]
        return out


@dataclass(frozen=True)
class _Motion:
    """The fixed point's unknowns: the random part's variances and the tones' amplitudes."""

    var_v: float
    var_z: float
    amplitudes: np.ndarray  # Z_q (m)

    def mean_square_z(self) -> float:
        return self.var_z + 0.5 * float(np.sum(self.amplitudes**2))


class CombinedSystem:
    """The device under tones and random parts, for the fixed point and the report.

    Parameters
    ----------
    harvester : Harvester
        Scalar parameters, memoryless friction, confining potential.
    tones : tuple of Tone
    continuous : tuple of Excitation
        The independent random parts (a Gaussian or translated spectrum, a
        shock train's Campbell spectrum).
    """

    def __init__(self, harvester, tones, continuous):
        self.harvester = harvester
        self.tones = tuple(tones)
        self.continuous = tuple(continuous)
        self.omega = np.array([t.omega for t in self.tones])
        self.base = np.array([t.amplitude for t in self.tones])
        law = harvester.friction
        self.law = None if law is None or law.vanishes else law
        h = harvester
        self.m, self.c, self.k, self.k3 = (float(x) for x in (h.m, h.c, h.k, h.k3))
        self.phases = phase_grid(len(self.tones))
        self.k_floor = -np.inf

    @property
    def has_random(self) -> bool:
        return bool(self.continuous)

    def block(self, c, k):
        return device_block(self.m, c, k, self.harvester.electrical)

    def equivalents(self, motion: _Motion):
        """(c_r, k_r, c_q array, k_q array) on the combined motion."""
        z2 = motion.mean_square_z()
        k_r = self.k + 3.0 * self.k3 * z2
        k_q = k_r - 0.75 * self.k3 * motion.amplitudes**2
        # without a positive k (double well, pure cubic) a trial motion too small would
        # make the linear devices unstable: the floor keeps the solver's trial steps
        # defined, and a solution on it is refused (combined_linearisation)
        k_r, k_q = max(k_r, self.k_floor), np.maximum(k_q, self.k_floor)
        velocity = self.omega * motion.amplitudes
        sigma = float(np.sqrt(motion.var_v)) if self.has_random else 0.0
        mu = np.cos(self.phases) @ velocity if self.tones else np.zeros(1)
        mean_force, mean_x_force = gaussian_friction_moments(self.law, mu, sigma)
        c_r = self.c + (float(np.mean(mean_x_force)) / sigma if sigma > 0 else 0.0)
        projections = np.mean(mean_force[:, None] * np.cos(self.phases), axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):
            c_q = self.c + np.where(velocity > 0, 2.0 * projections / velocity, 0.0)
        return c_r, k_r, c_q, k_q

    def random_outputs(self, c_r, k_r) -> dict:
        """Variances of the block's outputs under the random parts (summed: independent)."""
        block = self.block(c_r, k_r)
        total = {}
        for part in self.continuous:
            for name, value in output_variances(block, part).items():
                total[name] = total.get(name, 0.0) + value
        return total

    def tone_outputs(self, c_q, k_q) -> np.ndarray:
        """|H| A of every output per tone, shape (n_outputs, n_tones)."""
        out = [np.abs(self.block(c, k).frequency_response(t.frequency)) * t.amplitude
               for t, c, k in zip(self.tones, c_q, k_q, strict=True)]  # fmt: skip
        return np.array(out).T if out else np.zeros((len(self.block(self.c, self.k).outputs), 0))

    def respond(self, motion: _Motion) -> _Motion:
        """The linear devices' response on the equivalents of ``motion``: one fixed-point map."""
        c_r, k_r, c_q, k_q = self.equivalents(motion)
        var_v = var_z = 0.0
        if self.has_random:
            out = self.random_outputs(c_r, k_r)
            var_v, var_z = out["v"], out["z"]
        amplitudes = self.tone_outputs(c_q, k_q)[0] if self.tones else np.zeros(0)
        return _Motion(float(var_v), float(var_z), amplitudes)

    # ------------------------------------------------------------ the unknowns as a vector
    def pack(self, motion: _Motion) -> np.ndarray:
        head = [motion.var_v, motion.var_z] if self.has_random else []
        return np.log(np.concatenate([head, motion.amplitudes**2]))

    def unpack(self, x) -> _Motion:
        x = np.exp(np.asarray(x, dtype=float))
        if self.has_random:
            return _Motion(float(x[0]), float(x[1]), np.sqrt(x[2:]))
        return _Motion(0.0, 0.0, np.sqrt(x))

    @property
    def is_linear(self) -> bool:
        return self.law is None and self.k3 == 0.0


@dataclass(frozen=True, eq=False)
class CombinedLinearisation:
    """The harmonic-and-random linearisation of a device under tones and random input (SI).

    Attributes
    ----------
    harvester : Harvester
    excitation : Excitation
        The whole input.
    c_eq : float
        c + E[v F(v)] / E[v^2] over the whole motion (Ns/m): every part's
        friction power over the total mean square velocity.
    k_eq : float
        The random part's k + 3 k3 E[z^2] (N/m).
    random_c_eq : float
        c_r, the random part's equivalent damping (Ns/m); c without a random part.
    velocity_variance, displacement_variance : float
        E[v^2] and E[z^2] of the whole response: random part plus sum_q V_q^2 / 2.
    random_velocity_variance, random_displacement_variance : float
        The random part's alone.
    mean_abs_velocity : float
        E|v| (m/s): the Gaussian part's mean about each phase of the sinusoids.
    power_electrical : float
        E[P_e] (W).
    power_load : float or None
    circuit_variance : float or None
        E[x^2] of a circuit state (A^2 or V^2).
    tones : tuple of ToneResponse
    method : str
        ``"harmonic"`` (the fixed point) or ``"superposition"`` (a linear device: exact).
    """

    harvester: object
    excitation: object
    c_eq: float
    k_eq: float
    random_c_eq: float
    velocity_variance: float
    displacement_variance: float
    random_velocity_variance: float
    random_displacement_variance: float
    mean_abs_velocity: float
    power_electrical: float
    power_load: float | None
    circuit_variance: float | None
    tones: tuple
    method: str

    def response_spectra(self, frequency) -> ResponseSpectra:
        """The random part's PSDs at ``frequency`` (Hz) and the tones' lines (mean squares).

        The continuous spectra are the random parts through the random part's
        linear device (m, c_r, k_r); each tone is a line of mean square
        |H|^2 A^2 / 2 on its own linear device (m, c_q, k_q).
        """
        h = self.harvester
        f = np.asarray(frequency, dtype=float)
        random, _, shocks = parts_of(self.excitation)
        block = device_block(h.m, self.random_c_eq, self.k_eq, h.electrical)
        spectra = {name: np.zeros(f.shape) for name in block.outputs}
        source = np.zeros(f.shape)
        for part in (random, shocks):
            if part is not None:
                source = source + part.psd(f)
                for name, value in response_spectra(block, part, f).items():
                    spectra[name] = spectra[name] + value
        state = h.electrical.state_name if h.has_circuit else None
        lines = None
        if self.tones:
            z2 = np.array([0.5 * t.displacement_amplitude**2 for t in self.tones])
            v2 = np.array([0.5 * t.velocity_amplitude**2 for t in self.tones])
            x2 = (
                None
                if state is None
                else np.array([0.5 * t.circuit_amplitude**2 for t in self.tones])
            )
            lines = {
                "frequency": np.array([t.frequency for t in self.tones]),
                "displacement": z2,
                "velocity": v2,
                "power": np.asarray(linear_power(h, v2, x2)[0], dtype=float) * np.ones(z2.size),
            }
        return ResponseSpectra(
            frequency=f,
            excitation=source,
            displacement=spectra["z"],
            velocity=spectra["v"],
            power=linear_power(h, spectra["v"], None if state is None else spectra[state])[0]
            * np.ones(f.shape),
            lines=lines,
        )

    def stroke_exceedance(self, stroke: float | None):
        """P(|z| > stroke) of the sinusoids plus the Gaussian random part; None without a stroke."""
        if stroke is None:
            return None
        amplitudes = np.array([t.displacement_amplitude for t in self.tones])
        sigma = float(np.sqrt(self.random_displacement_variance))
        if amplitudes.size == 1 and sigma == 0.0:  # one sinusoid: the share of its phase
            ratio = stroke / amplitudes[0]
            return float(2.0 / np.pi * np.arccos(ratio)) if ratio < 1.0 else 0.0
        h = np.cos(phase_grid(amplitudes.size, _REPORT_PHASES)) @ amplitudes
        if sigma == 0.0:
            return float(np.mean(np.abs(h) > stroke))
        tail = special.ndtr(-(stroke - h) / sigma) + special.ndtr(-(stroke + h) / sigma)
        return float(np.mean(tail))


def _mean_abs_velocity(velocity_amplitudes, sigma) -> float:
    """E|sum_q V_q cos psi_q + sigma X|: the folded normal's mean, averaged over the phases."""
    mu = np.cos(phase_grid(len(velocity_amplitudes), _REPORT_PHASES)) @ velocity_amplitudes
    if sigma == 0.0:
        return float(np.mean(np.abs(mu)))
    folded = sigma * np.sqrt(2.0 / np.pi) * np.exp(-0.5 * (mu / sigma) ** 2)
    folded += mu * special.erf(mu / (sigma * np.sqrt(2.0)))
    return float(np.mean(folded))


def combined_linearisation(harvester, excitation) -> CombinedLinearisation:
    """Linearise ``harvester`` under the tones and random parts of ``excitation``.

    Parameters
    ----------
    harvester : Harvester
        Scalar parameters, memoryless friction, confining potential.
    excitation : Excitation
        An input with tones and/or random parts
        (:func:`randvib.models.combined.parts_of`).

    Returns
    -------
    CombinedLinearisation
        ``method`` ``"superposition"`` for a linear device (no friction, no
        cubic spring: exact), ``"harmonic"`` otherwise.

    Raises
    ------
    LinearisationDidNotConverge
        Where the fixed point is not found (a strongly driven Duffing spring
        near its resonance can have several).
    """
    random, tones, shocks = parts_of(excitation)
    _check_case(harvester, shocks)
    system = CombinedSystem(harvester, tones, [p for p in (random, shocks) if p is not None])
    start = _Motion(1.0, 1.0, np.ones(len(tones)))  # any motion: a linear device ignores it
    if system.is_linear:
        return _report(system, excitation, system.respond(start), "superposition")
    # start from a linear device: the viscous damping (5 % of critical without any)
    # and the spring's stiffness (without a positive one, the wells' or a tone's)
    linear = CombinedSystem(harvester.updated(friction=None, k3=0.0), tones, system.continuous)
    reference = system.omega[0] if tones else 2.0 * np.pi
    linear.k = system.k if system.k > 0 else max(-2.0 * system.k, 0.5 * system.m * reference**2)
    linear.c = system.c if system.c > 0 else 0.1 * np.sqrt(linear.k * system.m)

    def residual(x):
        with np.errstate(all="ignore"):
            try:
                out = system.pack(system.respond(system.unpack(x))) - np.asarray(x)
            except (ValueError, np.linalg.LinAlgError):
                raise TrialUndefined("an unstable linearised device") from None
        if not np.all(np.isfinite(out)):
            raise TrialUndefined("no finite response")
        return out

    if system.k <= 0:
        system.k_floor = 1e-6 * linear.k
    motion = system.unpack(solve(residual, system.pack(linear.respond(start))))
    _, k_r, _, k_q = system.equivalents(motion)
    if min(k_r, *k_q) <= system.k_floor:
        raise LinearisationDidNotConverge(
            f"the combined linearisation has no solution with positive equivalent stiffness for "
            f"this {harvester.potential.kind} device under the {excitation.name} input (its "
            "motion is not a zero-mean Gaussian and sinusoids about the barrier): use Monte "
            "Carlo (randvib.simulate)"
        )
    return _report(system, excitation, motion, "harmonic")


def _check_case(harvester, shocks) -> None:
    """Scalar parameters, a memoryless law, a confining potential; shocks on a linear device."""
    check_scalar_device(harvester, "combined_linearisation")
    law = harvester.friction
    if law is not None and not law.has_equivalent_damping:
        raise ValueError(
            f"combined_linearisation needs a memoryless friction law; {law.name!r} has internal "
            "state: use Monte Carlo (randvib.simulate)"
        )
    harvester.potential.require(
        "combined_linearisation", CONFINING, "Monte Carlo (randvib.simulate)"
    )
    if shocks is not None and not is_linear_device(harvester):
        raise ValueError(
            "combined_linearisation treats shocks on a linear device only (Campbell's theorem: "
            "no friction, no cubic spring): use Monte Carlo (randvib.simulate)"
        )


def _report(system: CombinedSystem, excitation, motion: _Motion, method: str):
    """The :class:`CombinedLinearisation` of a solved motion."""
    h = system.harvester
    c_r, k_r, c_q, k_q = system.equivalents(motion)
    outputs = system.tone_outputs(c_q, k_q)
    block_outputs = system.block(system.c, system.k).outputs
    state = h.electrical.state_name if h.has_circuit else None
    random_state = 0.0
    if system.has_random:
        random_state = system.random_outputs(c_r, k_r).get(state, 0.0) if state else 0.0
    velocity = system.omega * motion.amplitudes
    var_v = motion.var_v + 0.5 * float(np.sum(velocity**2))
    var_z = motion.mean_square_z()
    circuit = None
    if state is not None:
        circuit = random_state + 0.5 * float(np.sum(outputs[block_outputs.index(state)] ** 2))
    power, load = linear_power(h, var_v, circuit)
    friction_power = (c_r - system.c) * motion.var_v + float(
        np.sum((c_q - system.c) * velocity**2)
    ) / 2
    tones = tuple(
        ToneResponse(t.frequency, t.amplitude, float(z), float(v),
                     None if state is None else float(outputs[block_outputs.index(state)][q]),
                     float(c_q[q]), float(k_q[q]))
        for q, (t, z, v) in enumerate(zip(system.tones, motion.amplitudes, velocity, strict=True))
    )  # fmt: skip
    return CombinedLinearisation(
        harvester=h,
        excitation=excitation,
        c_eq=float(h.c + friction_power / var_v),
        k_eq=float(k_r),
        random_c_eq=float(c_r),
        velocity_variance=float(var_v),
        displacement_variance=float(var_z),
        random_velocity_variance=float(motion.var_v),
        random_displacement_variance=float(motion.var_z),
        mean_abs_velocity=_mean_abs_velocity(velocity, float(np.sqrt(motion.var_v))),
        power_electrical=float(power),
        power_load=None if load is None else float(load),
        circuit_variance=circuit,
        tones=tones,
        method=method,
    )
