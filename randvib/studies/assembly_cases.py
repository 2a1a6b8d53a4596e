"""The assemblies study's devices and comparisons: harvesters on a host mode, arrays, two masses.

Three questions of issue 31 (``randvib study assemblies``, studies/assemblies.py):

(a) **When is the single-mass answer right?** A harvester (mass m = mu M,
    tuned to the host) on one host mode (modal mass M, frequency f_h, damping
    ratio zeta_h). The *single-mass answer* is what one gets by measuring the
    host's vibration without the harvester and predicting the harvester on a
    rigid base driven by it: the host's absolute acceleration under the base
    input, fed to the one-DOF harvester, with no back-reaction
    (:func:`single_mass_power`: the host block in series with the harvester's,
    one Lyapunov equation). The *assembly's answer* includes the reaction
    (:func:`randvib.predict` on the two-DOF :class:`~randvib.models.assembly.Assembly`).
    Both are exact for linear devices; :func:`mass_ratio_at_error` finds where
    their ratio passes a threshold by root-finding on the exact answers.
(b) **Does an array beat one tuned harvester?** N harvesters of total mass
    mu M on the host (:func:`harvesters_on_host`), each one's tuning and load
    chosen by :func:`randvib.design` (exact Lyapunov search) against one
    harvester of the same total mass so chosen, confirmed by Monte Carlo on
    common paths (:func:`paired_difference`).
(c) **A two-mass harvester against a single mass** of equal total mass, both
    with Coulomb friction on the magnet's coordinate (:func:`two_mass_harvester`,
    :func:`single_mass_harvester`): statistical linearisation's designs, Monte
    Carlo's paired verdict.

The verdict functions (:func:`single_mass_verdicts`, :func:`array_verdicts`,
:func:`two_mass_verdicts`) compute every number of the report's sentences from
the study's tables. Monte Carlo needs the assembly kernel
(:mod:`randvib.montecarlo.assembly_simulation`; :func:`assembly_monte_carlo`
says whether this build has it): where a table's Monte Carlo columns are NaN
(no kernel, or a run not made) the verdicts rest on the exact and linearised
answers alone, and every Monte Carlo count is over the rows that have one.
"""

from __future__ import annotations

import importlib.util
import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import optimize, special

from randvib.analytic.linear_response import mechanical_block, output_variances
from randvib.analytic.prediction import predict
from randvib.models.assembly import Assembly
from randvib.models.assembly_parts import Element, Spring, Transducer
from randvib.models.friction import Coulomb
from randvib.models.state_space import StateSpace
from randvib.statistics import Statistic, estimate

__all__ = [
    "HostMode",
    "array_verdicts",
    "assembly_monte_carlo",
    "harvesters_on_host",
    "mass_ratio_at_error",
    "paired_difference",
    "path_power",
    "single_mass_error",
    "single_mass_harvester",
    "single_mass_power",
    "single_mass_verdicts",
    "total_power",
    "tuned",
    "two_mass_harvester",
    "two_mass_verdicts",
]

#: The error of the single-mass answer the question (a) is asked at.
ERROR_THRESHOLD = 0.05
#: Mass ratios searched for the threshold's crossing (beyond the study's 0.1 % to 20 %).
CROSSING_BOUNDS = (1e-8, 0.2)
#: A Monte Carlo estimate agrees with an exact value when |z| is at most this.
AGREEMENT_Z = 3.0
#: Two analytic optima whose powers differ by less than this (relative) are equal: far
#: above the rounding of two separate searches (about 1e-9 for (b)'s arrays, whose
#: optimum is N equal harvesters) and far below any difference worth a device.
ANALYTIC_TIE = 1e-6


def _analytic(gain: float) -> str:
    """``above``, ``below`` or ``equal``: an analytic gain's sign, ties within ANALYTIC_TIE."""
    if gain > ANALYTIC_TIE:
        return "above"
    return "below" if gain < -ANALYTIC_TIE else "equal"


@dataclass(frozen=True)
class HostMode:
    """One mode of a host structure: modal mass (kg), frequency (Hz), damping ratio."""

    mass: float = 1.0
    frequency: float = 10.0
    damping_ratio: float = 0.02

    @property
    def omega(self) -> float:
        return 2.0 * math.pi * self.frequency

    @property
    def stiffness(self) -> float:
        return self.mass * self.omega**2

    @property
    def damping(self) -> float:
        return 2.0 * self.damping_ratio * self.mass * self.omega

    def absolute_acceleration_block(self) -> StateSpace:
        """The host alone, input the base acceleration a, output its absolute acceleration.

        ``M x'' + C x' + K x = -M a``, so ``a + x'' = -(K x + C x') / M``
        (no direct feed-through).
        """
        k, c = self.stiffness / self.mass, self.damping / self.mass
        return StateSpace([[0.0, 1.0], [-k, -c]], [0.0, -1.0], [[-k, -c]], [0.0],
                          ("absolute_acceleration",))  # fmt: skip


def tuned(host: HostMode, mass: float, frequency_ratio=1.0, mechanical=0.01, electrical=0.04):
    """(k, c_m, c_e) of a harvester of ``mass`` (kg) tuned to ``frequency_ratio`` f_h, with
    the damping ratios ``mechanical`` and ``electrical`` of its own frequency."""
    omega = frequency_ratio * host.omega
    return mass * omega**2, 2 * mechanical * mass * omega, 2 * electrical * mass * omega


def harvesters_on_host(host: HostMode, masses, ks, c_ms, c_es, stroke=None) -> Assembly:
    """The host mode (DOF 0) with harvesters on it (DOFs 1..N).

    Harvester i: mass ``masses[i]`` (kg), spring ``ks[i]`` (N/m) and dashpot
    ``c_ms[i]`` (Ns/m) as element i on ``(i + 1, 0)``, its transducer a bare
    electrical damping ``c_es[i]`` (Ns/m) on the same coordinate with the
    ``stroke`` (m), if any. The base drives every DOF (influence all ones).
    """
    n = len(masses)
    stiffness = np.zeros((n + 1, n + 1))
    damping = np.zeros((n + 1, n + 1))
    stiffness[0, 0], damping[0, 0] = host.stiffness, host.damping
    elements = [Element((i + 1, 0), Spring(k=ks[i]), damping=c_ms[i]) for i in range(n)]
    transducers = [Transducer((i + 1, 0), c_es[i], stroke=stroke) for i in range(n)]
    return Assembly([host.mass, *masses], stiffness, damping, elements=elements,
                    transducers=transducers)  # fmt: skip


def single_mass_power(host: HostMode, m, k, c_m, c_e, excitation) -> float:
    """The single-mass answer: the harvester on a rigid base moving as the host without it (W).

    The host's absolute acceleration under ``excitation`` drives the one-DOF
    harvester ``m z'' + (c_m + c_e) z' + k z = -m a_host``; no reaction on the
    host. One Lyapunov equation of the two blocks in series (exact).
    """
    block = mechanical_block(m, c_m + c_e, k).driven_by(
        host.absolute_acceleration_block(), "absolute_acceleration"
    )
    return float(c_e * output_variances(block, excitation, "lyapunov")["v"])


def single_mass_error(host: HostMode, mass_ratio: float, excitation, **harvester) -> dict:
    """The assembly's and the single-mass answer at one mass ratio, and the relative error.

    ``harvester`` are :func:`tuned`'s ratios. Returns ``power_assembly``,
    ``power_single_mass`` (W) and ``error`` = single / assembly - 1.
    """
    m = mass_ratio * host.mass
    k, c_m, c_e = tuned(host, m, **harvester)
    device = harvesters_on_host(host, [m], [k], [c_m], [c_e])
    assembly = float(predict(device, excitation).transducers[0].power_electrical)
    single = single_mass_power(host, m, k, c_m, c_e, excitation)
    return {"power_assembly": assembly, "power_single_mass": single,
            "error": single / assembly - 1.0}  # fmt: skip


def mass_ratio_at_error(host: HostMode, excitation, threshold=ERROR_THRESHOLD, **harvester):
    """The mass ratio where |single-mass answer / assembly's - 1| reaches ``threshold``.

    Root-finding (Brent, on log mu, to 1e-10) of the exact error within
    :data:`CROSSING_BOUNDS`. Returns ``(mass_ratio, where)``: ``where`` is
    ``"crossed"``, ``"below"`` (the error is above the threshold already at the
    smallest ratio: ``mass_ratio`` is that bound) or ``"never"`` (below the
    threshold up to the largest: None).
    """

    def excess(log_mu):
        return (
            abs(single_mass_error(host, math.exp(log_mu), excitation, **harvester)["error"])
            - threshold
        )

    lo, hi = (math.log(b) for b in CROSSING_BOUNDS)
    if excess(lo) >= 0:
        return CROSSING_BOUNDS[0], "below"
    if excess(hi) < 0:
        return None, "never"
    return math.exp(optimize.brentq(excess, lo, hi, xtol=1e-10)), "crossed"


# --------------------------------------------------------------------- (c) two masses
def two_mass_harvester(outer, inner, k_outer, k_inner, damping_ratio, frequency, fc, c_e,
                       stroke) -> Assembly:  # fmt: skip
    """An outer mass on the base and the magnet (inner mass) on it, friction on the magnet.

    DOF 0 the outer mass (kg), joined to the base by the structure's spring
    ``k_outer`` and a dashpot; DOF 1 the magnet, joined to the outer mass by
    element 1 (spring ``k_inner``, Coulomb friction ``fc`` (N), a dashpot) with
    the transducer ``c_e`` on that coordinate. The dashpots have the damping
    ratio ``damping_ratio`` of ``frequency`` (Hz) for their mass. Both moving
    coordinates carry ``stroke`` (m): element 0 (outer against the base) and
    the transducer (magnet against the outer mass).
    """
    omega = 2 * math.pi * frequency
    friction = Coulomb(fc=fc) if fc > 0 else None
    elements = [Element((0, None), stroke=stroke),
                Element((1, 0), Spring(k=k_inner), friction,
                        damping=2 * damping_ratio * inner * omega)]  # fmt: skip
    return Assembly([outer, inner], [[k_outer, 0.0], [0.0, 0.0]],
                    [[2 * damping_ratio * outer * omega, 0.0], [0.0, 0.0]],
                    elements=elements, transducers=[Transducer((1, 0), c_e, stroke=stroke)])  # fmt: skip


def single_mass_harvester(mass, k, damping_ratio, frequency, fc, c_e, stroke) -> Assembly:
    """The one-DOF harvester of the same total mass (kg), friction and stroke, as an assembly."""
    omega = 2 * math.pi * frequency
    friction = Coulomb(fc=fc) if fc > 0 else None
    elements = [Element((0, None), friction=friction, stroke=stroke)] if friction else []
    return Assembly([mass], [[k]], [[2 * damping_ratio * mass * omega]], elements=elements,
                    transducers=[Transducer((0, None), c_e, stroke=stroke)])  # fmt: skip


# --------------------------------------------------------------------- Monte Carlo
def path_power(result) -> np.ndarray:
    """Each path's electrical power of all the transducers together (W)."""
    return sum(result.transducer_power(i)[0] for i in range(len(result.assembly.transducers)))


def _controls(result):
    return result.controls() if result.control_variates else None


def total_power(result) -> Statistic:
    """The transducers' electrical power together (W), with the run's control variates."""
    return estimate(path_power(result), _controls(result))


def paired_difference(a, b) -> Statistic:
    """Power of run ``a`` minus run ``b`` (W), path by path on their common paths.

    Both runs on one seed and the same number of paths: path i of each sees
    the same base excitation, so the difference is far more precise than
    either power. The control variates of both runs are used together.
    """
    x, y = path_power(a), path_power(b)
    if len(x) != len(y):
        raise ValueError(f"paired runs need the same paths: {len(x)} and {len(y)} paths")
    controls = None
    if a.control_variates and b.control_variates:
        controls = np.hstack([a.controls(), b.controls()])
    return estimate(x - y, controls)


# --------------------------------------------------------------------- verdicts
def assembly_monte_carlo() -> bool:
    """Whether this build simulates assemblies (:mod:`randvib.montecarlo.assembly_simulation`)."""
    return importlib.util.find_spec("randvib.montecarlo.assembly_simulation") is not None


def _measured(mean, ci95) -> bool:
    """Whether a Monte Carlo column holds an estimate (NaN: no run)."""
    return bool(np.isfinite(mean) and np.isfinite(ci95))


def _z(mean, ci95, exact, n_paths):
    """z-score of a Monte Carlo mean against an exact value (the t-based 95 % half-width)."""
    se = ci95 / special.stdtrit(int(n_paths) - 1, 0.975)
    return (mean - exact) / se if se > 0 else math.inf


def significance(mean, ci95) -> str | None:
    """``above``, ``below`` or ``neither``: where a paired difference's 95 % interval lies.

    None where there is no estimate (NaN).
    """
    if not _measured(mean, ci95):
        return None
    if mean - ci95 > 0:
        return "above"
    if mean + ci95 < 0:
        return "below"
    return "neither"


def single_mass_verdicts(errors: pd.DataFrame, crossings: pd.DataFrame,
                         checks: pd.DataFrame, harvester_zeta: float) -> dict:  # fmt: skip
    """The numbers behind question (a)'s sentences.

    ``errors``: input, host_zeta, mass_ratio, power_assembly, power_single_mass,
    error. ``crossings``: input, host_zeta, mass_ratio_crossing, where.
    ``checks``: input, host_zeta, mass_ratio, power_assembly (exact), power_mc,
    power_mc_ci95, n_paths (Monte Carlo of the assembly). ``harvester_zeta``:
    the harvester's total damping ratio zeta_a; the crossings are also given
    as multiples of zeta_h zeta_a (``crossing_over_damping``: the smallest and
    largest per input), the scale on which they collapse.
    """
    smallest = errors[errors.mass_ratio == errors.mass_ratio.min()]
    worst = errors.loc[errors.error.abs().idxmax()]
    right = smallest[smallest.error.abs() < ERROR_THRESHOLD]
    monotone = []
    for _, sub in crossings.groupby("input", sort=False):
        ordered = sub.sort_values("host_zeta")
        values = ordered.mass_ratio_crossing.fillna(np.inf).to_numpy()
        monotone.append(bool(np.all(np.diff(values) >= 0)))
    z = [_z(r.power_mc, r.power_mc_ci95, r.power_assembly, r.n_paths)
         for r in checks.itertuples() if _measured(r.power_mc, r.power_mc_ci95)]  # fmt: skip
    crossed = crossings[crossings["where"] == "crossed"]
    scaled = crossed.mass_ratio_crossing / (crossed.host_zeta * harvester_zeta)
    over_damping = {name: [float(sub.min()), float(sub.max())]
                    for name, sub in scaled.groupby(crossed.input, sort=False)}  # fmt: skip
    return {
        "threshold": ERROR_THRESHOLD,
        "overestimates_everywhere": bool((errors.error > 0).all()),
        "largest_error": float(worst.error),
        "largest_error_at": {
            "input": worst.input,
            "host_zeta": float(worst.host_zeta),
            "mass_ratio": float(worst.mass_ratio),
        },  # fmt: skip
        "smallest_mass_ratio": float(smallest.mass_ratio.iloc[0]),
        "right_at_smallest_ratio": [
            f"{r.input}, zeta_h = {r.host_zeta:g}" for r in right.itertuples()
        ],  # fmt: skip
        "cases": int(len(smallest)),
        "crossings": {
            f"{r.input}, zeta_h = {r.host_zeta:g}": (
                None if r.where == "never" else float(r.mass_ratio_crossing)
            )
            for r in crossings.itertuples()
        },  # fmt: skip
        "crossing_where": {
            f"{r.input}, zeta_h = {r.host_zeta:g}": r.where for r in crossings.itertuples()
        },  # fmt: skip
        "crossing_grows_with_host_damping": bool(all(monotone)),
        "harvester_zeta": float(harvester_zeta),
        "crossing_over_damping": over_damping,
        "monte_carlo_checks": len(z),
        "monte_carlo_agree": int(sum(abs(v) <= AGREEMENT_Z for v in z)),
        "monte_carlo_largest_z": float(max(map(abs, z))) if z else None,
    }


def array_verdicts(arrays: pd.DataFrame) -> dict:
    """The numbers behind question (b)'s sentences.

    ``arrays``: bandwidth, n, power (exact optimum), gain (exact, over n = 1),
    difference_mc, difference_mc_ci95 (paired, array - single; NaN for n = 1),
    power_mc, power_mc_ci95, n_paths (the Monte Carlo columns NaN where
    there is no run). ``exact``: an array's sign of gain on the exact optimum
    (the devices are linear), ``equal`` within :data:`ANALYTIC_TIE`;
    ``monte_carlo``: its paired interval's verdict, None without a run.
    """
    by_band = {}
    for bandwidth, sub in arrays.groupby("bandwidth", sort=True):
        best = sub.loc[sub.power.idxmax()]
        arrays_only = sub[sub.n > 1]
        verdicts = {int(r.n): significance(r.difference_mc, r.difference_mc_ci95)
                    for r in arrays_only.itertuples()}  # fmt: skip
        by_band[f"{bandwidth:g}"] = {
            "best_n": int(best.n),
            "best_gain": float(best.gain),
            "largest_gain": float(arrays_only.gain.max()) if len(arrays_only) else 0.0,
            "exact": {int(r.n): _analytic(r.gain) for r in arrays_only.itertuples()},
            "monte_carlo": verdicts,
        }  # fmt: skip
    z = [_z(r.power_mc, r.power_mc_ci95, r.power, r.n_paths)
         for r in arrays.itertuples() if _measured(r.power_mc, r.power_mc_ci95)]  # fmt: skip
    differences = arrays[arrays.n > 1]
    measured = [_measured(r.difference_mc, r.difference_mc_ci95) for r in differences.itertuples()]
    return {
        "by_bandwidth": by_band,
        "largest_gain": float(differences.gain.max()) if len(differences) else 0.0,
        "array_significantly_better": int(
            sum(r.difference_mc - r.difference_mc_ci95 > 0 for r in differences.itertuples())
        ),  # fmt: skip
        "single_significantly_better": int(
            sum(r.difference_mc + r.difference_mc_ci95 < 0 for r in differences.itertuples())
        ),  # fmt: skip
        "comparisons": int(len(differences)),
        "array_better_exact": int((differences.gain > ANALYTIC_TIE).sum()),
        "array_equal_exact": int((differences.gain.abs() <= ANALYTIC_TIE).sum()),
        "monte_carlo_comparisons": int(sum(measured)),
        "monte_carlo_agree": int(sum(abs(v) <= AGREEMENT_Z for v in z)),
        "monte_carlo_checks": len(z),
    }


def two_mass_verdicts(pairs: pd.DataFrame) -> dict:
    """The numbers behind question (c)'s sentences.

    ``pairs``: input, fc, power_single, power_two_mass (linearisation's, at
    each design's optimum), single_mc, single_mc_ci95, two_mass_mc,
    two_mass_mc_ci95, difference_mc, difference_mc_ci95 (paired, two-mass -
    single; the Monte Carlo columns NaN where there is no run). Per case:
    ``linearisation``, the better device by the predicted powers;
    ``monte_carlo``, the paired interval's verdict (None without a run).
    """
    names = {"above": "two-mass", "below": "single mass", "neither": "neither", None: None}
    rows = {}
    for r in pairs.itertuples():
        measured = _measured(r.difference_mc, r.difference_mc_ci95)
        rows[f"{r.input}, Fc = {1e3 * r.fc:g} mN"] = {
            "linearisation": {"above": "two-mass", "below": "single mass", "equal": "neither"}[
                _analytic(r.power_two_mass / r.power_single - 1.0)
            ],
            "monte_carlo": names[significance(r.difference_mc, r.difference_mc_ci95)],
            "ratio_predicted": float(r.power_two_mass / r.power_single),
            "ratio_monte_carlo": float(r.two_mass_mc / r.single_mc) if measured else None,
        }  # fmt: skip
    errors = np.concatenate([(pairs.power_single / pairs.single_mc - 1).to_numpy(),
                             (pairs.power_two_mass / pairs.two_mass_mc - 1).to_numpy()])  # fmt: skip
    errors = errors[np.isfinite(errors)]
    winners = [v["monte_carlo"] for v in rows.values()]
    predicted = [v["linearisation"] for v in rows.values()]
    return {
        "cases": rows,
        "two_mass_better_linearisation": predicted.count("two-mass"),
        "monte_carlo_cases": len(winners) - winners.count(None),
        "two_mass_better": winners.count("two-mass"),
        "single_better": winners.count("single mass"),
        "undecided": winners.count("neither"),
        "linearisation_largest_error": float(np.max(np.abs(errors))) if len(errors) else None,
    }
