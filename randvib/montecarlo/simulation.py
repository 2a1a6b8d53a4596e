"""Monte Carlo simulation of the harvester under white or rational noise: ``simulate``.

The SDE (docs/conventions.md, paper Eq. 1 and 15-17) for the state (z, v = z') and,
for LuGre friction, the bristle state theta:

    dz = v dt
    dv = -(c v + k z + k3 z^3 + F(v, theta)) / m dt + sqrt(S/2) dW
    dtheta = theta'(v, theta) dt

with sqrt(S/2) dW the paper's white base acceleration (Eq. 17). Under a
rational spectrum (band-pass, Kanai-Tajimi) the base acceleration is instead
the output y of the spectrum's 2-state shaping filter driven by that white
noise, and dv gets -y dt in place of the noise (paper Eq. 18 with a
coloured base); the filter states are integrated with the device by the same
scheme (:func:`randvib.montecarlo.kernel.auxiliary_step`). Under a
band-limited or tabulated spectrum y is synthesised per path and dv gets the
exact step integral -int y dt through the kernel's given-increments path
(:mod:`randvib.montecarlo.driven`).

A coupling with a circuit state (coil inductance, piezo capacitance;
:mod:`randvib.models.coupling`) adds that state, ``x' = a x + b v``, with the
force ``f x`` on the magnet, to the same linear auxiliary block; the kernel
averages x^2 per path, so the circuit's power comes with its interval.

Each path is an independent realisation; statistics are time averages over
the window [burn_in, t_end) on each path, and their confidence intervals come
from the spread between paths (independent by construction), so they do not
depend on any assumption about correlation times.
"""

from __future__ import annotations

import functools
import threading
import time
import warnings
from dataclasses import dataclass, field

import numba
import numpy as np
from scipy import linalg, special  # Student t quantile; lighter than scipy.stats

from randvib import _display
from randvib._progress import progress_bar, progress_wanted
from randvib._resources import LONG_RUN_SECONDS, announce_duration, check_memory, timed
from randvib._validation import (
    MAX_SEED,
    check_choice,
    check_int,
    check_positive,
    check_scalar_device,
)
from randvib.analytic import exact_solutions as exact
from randvib.analytic.statistical_linearisation import statistical_linearisation
from randvib.models.excitation import Excitation, as_excitation
from randvib.models.friction import kernel_arguments
from randvib.models.harvester import Harvester
from randvib.models.potential import CONFINING
from randvib.montecarlo import driven, integrators, kernel
from randvib.montecarlo.integrators import Integrator, integrator
from randvib.montecarlo.rng import ZIG_FI, ZIG_KI, ZIG_WI
from randvib.montecarlo.step_check import (
    LinearTestSystem,
    coarsened,
)
from randvib.statistics import FirstPassage, Statistic, estimate

#: Most steps per path (int64 step counters, with room to spare).
MAX_STEPS = 2**62
#: Largest path index (streams are keyed by unsigned 64-bit integers).
MAX_PATH_INDEX = 2**62


class SimulationDivergedError(ValueError):
    """The state became non-finite during a simulation."""


@dataclass(frozen=True)
class Histogram:
    """Stationary histograms of displacement and velocity over the window."""

    z_edges: np.ndarray
    z_density: np.ndarray
    v_edges: np.ndarray
    v_density: np.ndarray
    #: Fraction of samples that fell outside the ranges.
    outside: tuple
    #: Counts of z and v per group of paths (the kernel's chunks of up to
    #: kernel.LANES independent paths), shape (n_groups, 2, bins), and the
    #: paths in each group: the groups are independent, so they give intervals.
    group_counts: np.ndarray | None = field(default=None, repr=False)
    group_paths: np.ndarray | None = field(default=None, repr=False)
    window_steps: int = 0

    def density_statistics(self, variable: str = "z") -> list[Statistic]:
        """The density (1/m or s/m) in each bin with its 95 % interval, over path groups.

        Ratio estimator over the independent groups g with n_g paths:
        mean = sum(counts) / (sum(n_g) T h) (= ``z_density``), standard error
        from the groups' spread about it, weighted by n_g / sum(n_g).
        """
        row = check_choice("variable", variable, ("z", "v"))
        edges = self.z_edges if row == "z" else self.v_edges
        counts = self.group_counts[:, 0 if row == "z" else 1, :].astype(float)
        n = self.group_paths.astype(float)
        g = n.size
        if g < 2:
            raise ValueError(f"need at least 2 groups of paths for an interval, got {g}")
        scale = self.window_steps * np.diff(edges)  # samples per path x bin width
        per_group = counts / (n[:, None] * scale)
        mean = counts.sum(axis=0) / (n.sum() * scale)
        weight = (n / n.sum())[:, None]
        se = np.sqrt(g / (g - 1) * np.sum(weight**2 * (per_group - mean) ** 2, axis=0))
        t = float(special.stdtrit(g - 1, 0.975))
        return [
            Statistic(float(a), t * float(b), float(b), g) for a, b in zip(mean, se, strict=True)
        ]


@dataclass(frozen=True)
class Histories:
    """Decimated time histories of the first few paths."""

    time: np.ndarray  # (n_records,) s
    z: np.ndarray  # (n_paths, n_records) m
    v: np.ndarray  # (n_paths, n_records) m/s
    theta: np.ndarray  # (n_paths, n_records) m (LuGre bristle state, else 0)


@dataclass(frozen=True)
class SimulationResult:
    """Result of :func:`simulate`: per-path averages and statistics.

    The statistics (``power_electrical``, ``velocity_variance``,
    ``displacement_variance``, ``mean_abs_velocity``, ``friction_power``,
    ``power_load``, ``stroke_exceedance``) are :class:`Statistic` objects
    (``displacement_variance`` None for the free mass, the stroke ones None
    without a stroke); ``stroke_first_passage`` is a :class:`FirstPassage`; with
    ``control_variates=True`` they use the zero-mean controls of
    :meth:`controls`, otherwise plain path means.
    """

    harvester: Harvester
    #: White-noise level S, or the excitation's level ((m/s^2)^2/Hz); None
    #: where no single level describes the input (a table, a measured record).
    psd: float | None
    scheme: str
    dt: float
    t_end: float
    burn_in: float
    seed: int
    first_path: int
    per_path: np.ndarray = field(repr=False)
    control_variates: bool = False
    histogram: Histogram | None = field(default=None, repr=False)
    histories: Histories | None = field(default=None, repr=False)
    wall_time: float = 0.0
    #: The excitation simulated; None stands for white noise of level ``psd``.
    excitation: Excitation | None = None

    @property
    def is_white(self) -> bool:
        """True when the base acceleration was ideal white noise (level ``psd``)."""
        return self.excitation is None or self.excitation.is_white

    def _require_white(self, what: str) -> None:
        if not self.is_white:
            raise ValueError(
                f"{what} rest on the white-noise energy balance (c E[v^2] + E[vF] = S m/4); "
                f"this result was simulated under {self.excitation.name} excitation"
            )

    @property
    def n_paths(self) -> int:
        return self.per_path.shape[0]

    @property
    def method(self) -> str:
        """Deprecated alias of :attr:`scheme` (the integrator's name)."""
        warnings.warn(
            "SimulationResult.method is deprecated; use SimulationResult.scheme",
            DeprecationWarning,
            stacklevel=2,
        )
        return self.scheme

    @property
    def averaging_time(self) -> float:
        """Length of the averaging window per path (s)."""
        return self.t_end - self.burn_in

    def column(self, index: int) -> np.ndarray:
        return self.per_path[:, index]

    @property
    def averages(self) -> kernel.PathAverages:
        """The per-path time averages by name (:class:`randvib.montecarlo.kernel.PathAverages`)."""
        return kernel.PathAverages(self.per_path)

    def controls(self) -> np.ndarray:
        """Zero-mean control variates per path, shape (n_paths, p).

        * the Ito integral (1/T) sum v_n dW_n: mean exactly zero;
        * the energy change (H(T) - H(0)) / T: zero mean in the stationary state;
        * with ``companion=True``, the friction-free companion's mean v^2 and
          z^2 minus their exact values (S m / (4c), Gibbs E[z^2]): same noise,
          exactly known mean in continuous time (bias O(dt) at finite step).

        Under a rational spectrum (shaping filter) the first two stay valid:
        v_n is adapted to the Brownian motion that drives the filter, so the
        Ito sum still has mean exactly zero, and the energy change has zero
        mean in any stationary state (measured: 4-6x less variance of E[P_e]
        under band-pass input). Under synthesised or recorded input the
        increments are the input's integrals, not Brownian, and the sum is
        the input power: no control is valid there.
        """
        if not self.is_white:
            if self.excitation.shaping_filter() is None:
                raise ValueError(
                    "control variates need Brownian increments (white noise or a shaping "
                    f"filter); the {self.excitation.name} input is synthesised or recorded"
                )
            return np.column_stack(self.averages.energy_balance_controls(self.averaging_time))
        h = self.harvester
        avg = self.averages
        cols = avg.energy_balance_controls(self.averaging_time)
        if np.any(avg.companion_v2 != 0) and h.c > 0:
            cols.append(avg.companion_v2 - exact.linear_velocity_variance(h.m, h.c, self.psd))
            cols.append(
                avg.companion_z2 - exact.gibbs_displacement_moment(h.m, h.c, h.k, h.k3, self.psd)
            )
        return np.column_stack(cols)

    def statistic(self, samples, control_variates: bool | None = None) -> Statistic:
        use = self.control_variates if control_variates is None else control_variates
        return estimate(samples, self.controls() if use else None)

    @property
    def velocity_variance(self) -> Statistic:
        """E[z'^2] ((m/s)^2); the mean velocity is zero by symmetry."""
        return self.statistic(self.averages.v2)

    @property
    def displacement_variance(self) -> Statistic | None:
        """E[z^2] (m^2); None for the free mass (k = k3 = 0), whose z is not stationary."""
        if self.harvester.potential.is_free:
            return None
        return self.statistic(self.averages.z2)

    @property
    def stroke_exceedance(self) -> Statistic | None:
        """Fraction of the window's time with |z| > stroke; None without a stroke.

        For the free mass it is the fraction over this window (z is not
        stationary, so it grows with the run), not a stationary probability.
        """
        if self.harvester.stroke is None:
            return None
        return self.statistic(self.averages.beyond_stroke)

    @property
    def stroke_first_passage(self) -> FirstPassage | None:
        """First time |z| > stroke from the start (:class:`FirstPassage`); None without a stroke."""
        if self.harvester.stroke is None:
            return None
        return FirstPassage.from_times(self.averages.first_hit_time, self.t_end)

    @property
    def mean_abs_velocity(self) -> Statistic:
        """E|z'| (m/s)."""
        return self.statistic(self.averages.abs_v)

    @property
    def power_electrical(self) -> Statistic:
        """E[P_e] (W): c_e E[z'^2] (paper Eq. 31), or from the circuit state.

        With a circuit state: (R_L + R_C) E[i^2] (inductive), E[V^2] / R_L (piezo).
        """
        if self.harvester.has_circuit:
            return self.statistic(self._circuit_power("power_electrical"))
        return self.statistic(self.harvester.c_e * self.averages.v2)

    def _circuit_power(self, which: str) -> np.ndarray:
        """Per-path electrical or load power of a circuit state (``which``: the method)."""
        avg = self.averages
        return getattr(self.harvester.electrical, which)(avg.v2, avg.circuit_square)

    @property
    def circuit_mean_square(self) -> Statistic | None:
        """E[i^2] (A^2) or E[V^2] (V^2) of a circuit state; None without one."""
        if not self.harvester.has_circuit:
            return None
        return self.statistic(self.averages.circuit_square)

    @property
    def friction_power(self) -> Statistic:
        """E[z' F] (W): power dissipated by friction."""
        return self.statistic(self.averages.friction_power)

    @property
    def power_load(self) -> Statistic | None:
        """E[i^2 R_L] (W), with a circuit; else None."""
        e = self.harvester.electrical
        if e is None:
            return None
        if self.harvester.has_circuit:
            return self.statistic(self._circuit_power("power_load"))
        return self.statistic(self.harvester.c_e * e.load_fraction * self.averages.v2)

    def energy_balance_residual(self) -> Statistic:
        """c E[v^2] + E[v F] + P_x - S m / 4 (W): zero up to O(dt) and noise (white only).

        ``P_x`` is the power of a circuit state ((R_L + R_C) i^2 or V^2 / R_L;
        docs/conventions.md: the coupling's force f x does the work
        f x v = R x^2 + d/dt(stored energy)); without one, c holds c_e.
        """
        self._require_white("the energy-balance residual and its S m / 4")
        h = self.harvester
        samples = h.c * self.averages.v2 + self.averages.friction_power - self.psd * h.m / 4.0
        if h.has_circuit:
            samples = samples + self._circuit_power("power_electrical")
        return self.statistic(samples)

    def response_spectra(self, segment_duration: float | None = None):
        """Welch PSDs of z, v and c_e S_v from the recorded paths (:mod:`.spectra`)."""
        from randvib.montecarlo.spectra import response_spectra

        return response_spectra(self, segment_duration)

    def summary(self) -> dict:
        """Statistics as {name: {"mean", "ci95"}} plus run settings (JSON-ready)."""
        out = {
            name: getattr(self, name).to_dict()
            for name in (
                "power_electrical",
                "velocity_variance",
                "mean_abs_velocity",
                "friction_power",
            )
        }
        # null for the free mass: its displacement has no stationary law
        z2 = self.displacement_variance
        out["displacement_variance"] = None if z2 is None else z2.to_dict()
        if self.power_load is not None:
            out["power_load"] = self.power_load.to_dict()
        if self.harvester.has_circuit:
            out["circuit_mean_square"] = self.circuit_mean_square.to_dict()
        if self.harvester.stroke is not None:
            out["stroke"] = self.harvester.stroke
            out["stroke_exceedance"] = self.stroke_exceedance.to_dict()
            first = self.stroke_first_passage
            out["stroke_first_passage_time"] = None if first.mean is None else first.mean.to_dict()
            out["stroke_first_passage"] = first.to_dict()
        out.update(
            n_paths=self.n_paths,
            dt=self.dt,
            t_end=self.t_end,
            burn_in=self.burn_in,
            method=self.scheme,  # the JSON key predates the name `scheme`
            seed=self.seed,
            psd=self.psd,
            control_variates=self.control_variates,
            wall_time=self.wall_time,
        )
        # Added with coloured input (issue 10); `psd` stays the level S.
        excitation = self.excitation or as_excitation(self.psd)
        out["excitation"] = excitation.parameters()
        return out

    def to_dict(self) -> dict:
        """The same as :meth:`summary` (JSON-ready)."""
        return self.summary()

    def _statistics(self) -> list[tuple[str, Statistic, str]]:
        """(name, Statistic, unit) of every statistic this run has."""
        circuit_unit = "V^2" if self.harvester.coupling_name == "piezo" else "A^2"
        named = (
            ("power_electrical", "W"),
            ("power_load", "W"),
            ("velocity_variance", "(m/s)^2"),
            ("displacement_variance", "m^2"),
            ("mean_abs_velocity", "m/s"),
            ("friction_power", "W"),
            ("circuit_mean_square", circuit_unit),
            ("stroke_exceedance", "fraction of time"),
        )
        out = [(name, getattr(self, name), unit) for name, unit in named]
        return [(name, stat, unit) for name, stat, unit in out if stat is not None]

    def _settings_line(self) -> str:
        if self.is_white:
            excitation = f"white, S = {self.psd:g}"
        else:  # the name and level, not the repr (a table's or record's arrays)
            level = "" if self.psd is None else f", S = {self.psd:g}"
            excitation = f"{self.excitation.name}{level}"
        cv = ", control variates" if self.control_variates else ""
        return (
            f"{self.n_paths} paths x {_display.number(self.averaging_time, 4)} s averaged, "
            f"dt {self.dt:g} s, {self.scheme}, seed {self.seed}, {excitation}{cv}"
        )

    def to_frame(self):
        """The statistics as a :class:`pandas.DataFrame`, one row per statistic.

        Columns ``mean``, ``ci95`` (95 % half-width), ``std_error``,
        ``n_paths`` and ``unit``; the index is the statistic's name.
        """
        pd = _display.pandas()
        rows = {
            name: {
                "mean": stat.mean,
                "ci95": stat.ci95,
                "std_error": stat.std_error,
                "n_paths": stat.n_paths,
                "unit": unit,
            }
            for name, stat, unit in self._statistics()
        }
        return pd.DataFrame.from_dict(rows, orient="index").rename_axis("statistic")

    def _rows(self):
        return [(n, _display.estimate(s.mean, s.ci95), u) for n, s, u in self._statistics()]

    def __repr__(self) -> str:
        power = self.power_electrical
        return (
            f"{type(self).__name__}({self._settings_line()}; power_electrical = "
            f"{_display.estimate(power.mean, power.ci95)} W)"
        )

    def __str__(self) -> str:
        return _display.text_table(
            "Monte Carlo (mean ± 95 % half-width)", self._rows(), self._settings_line()
        )

    def _repr_html_(self) -> str:
        return _display.html_table(
            "Monte Carlo (mean ± 95 % half-width)", self._rows(), self._settings_line()
        )


def _check_scales(run: _Run, linear) -> None:
    """Refuse parameters whose linearised scales are not finite float64 numbers.

    Extreme values (m = 1e308, k3 = 1e308, S = 1e308) overflow the
    step-size check and the stationary start; they are named here instead.
    ``linear`` gives the run's :class:`LinearTestSystem` (built on first use).
    """
    h = run.harvester
    try:
        # quadrature warnings at such values would only precede the refusal
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            system = linear()
            k_eff, c_eff = system.k_eff, system.c_eff
            spread = system.spread
    except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
        problem = f"{type(exc).__name__}: {exc}"
    else:
        values = (k_eff, c_eff, *spread)
        # the free mass has no stiffness and no stationary spread in z
        positive = values[1:2] + values[3:] if h.potential.is_free else values
        if all(np.isfinite(values)) and all(v > 0 for v in positive):
            return
        problem = f"k_eff = {k_eff:.3g}, c_eff = {c_eff:.3g}, std z, v = {spread}"
    raise ValueError(
        f"the device's linearised scales are not finite positive float64 numbers ({problem}) "
        f"at psd = {run.psd!r} and {run.harvester.parameters()}: the parameters are out of "
        "range, or the device has neither damping nor friction"
    )


#: Rough speed of the compiled loop, path-steps per second per thread (Heun,
#: Coulomb friction on a laptop core, about 3e7): it only decides whether a run
#: could be long enough to time a probe of it (:func:`_announce_long_run`).
PATH_STEPS_PER_SECOND = 3e7
#: A run shorter than LONG_RUN_SECONDS / PROBE_MARGIN at the rough speed is
#: not probed: the machine would have to be this many times slower to make it long.
PROBE_MARGIN = 30.0
#: Path-steps per thread of the timed probe (about 0.1 s at the rough speed).
PROBE_PATH_STEPS = 3e6


def _announce_long_run(run: _Run, setup: _KernelSetup) -> None:
    """Say how long a long run will take, at the speed measured on this machine.

    A run that could be long (more than LONG_RUN_SECONDS / PROBE_MARGIN at the
    rough speed) is timed on a short probe first: the first paths for a few
    thousand steps, after a call that compiles the loop, so that neither the
    compilation nor the machine's guessed speed enters the estimate. Input
    synthesised per path is not probed (its synthesis is per whole path); its
    estimate uses the rough speed and the synthesis' measured cost (about 3x
    the white-noise loop, ``benchmarks/bench_engine.py``).
    """
    threads = numba.get_num_threads()
    work = float(run.n_paths) * run.grid.n_steps * (2 if run.companion else 1)
    rough = work / (PATH_STEPS_PER_SECOND * threads)
    if rough <= LONG_RUN_SECONDS / PROBE_MARGIN:
        return
    what = f"simulating {run.n_paths} paths x {run.grid.n_steps} steps"
    if run.driver is not None:
        announce_duration(what, 3.0 * rough, stacklevel=5, basis="a rough estimate")
    else:
        announce_duration(what, work / _measured_speed(run, setup, threads), stacklevel=5)


def _measured_speed(run: _Run, setup: _KernelSetup, threads: int) -> float:
    """Path-steps per second of this run's compiled loop on this machine (a timed probe)."""
    paths = min(run.n_paths, kernel.LANES * threads)
    steps = int(min(run.grid.n_steps, max(100, PROBE_PATH_STEPS * threads / paths)))

    def probe(n_paths, n_steps):
        timing = kernel.pack(kernel.Timing, run.grid.dt, n_steps, min(run.grid.n_burn, n_steps - 1))
        arguments = setup.arguments(run, 0, n_paths)
        arguments["timing"] = timing
        arguments["recording"] = arguments["recording"]._replace(n_record=0)
        kernel.run_ensemble(stop=np.zeros(1, dtype=np.int64), **arguments)

    probe(1, 2)  # compiles (or loads) the loop: not part of the speed
    _, elapsed = timed(lambda: probe(paths, steps))
    return paths * steps * (2 if run.companion else 1) / elapsed


def _check_resources(run: _Run, batch_paths, progress) -> None:
    """Refuse a run whose arrays cannot fit in memory."""
    n_steps, n_paths = run.grid.n_steps, run.n_paths
    batch = n_paths if batch_paths is None else min(int(batch_paths), n_paths)
    chunks = -(-batch // kernel.LANES)
    rec = run.record
    n_bytes = 8.0 * (
        2 * n_paths * kernel.N_ACC  # per-path averages, and one batch's
        # histogram counts per chunk, their sum, then densities and bin edges
        + (chunks * 2 + 6) * rec.histogram_bins
        + min(rec.record_paths, n_paths) * (n_steps // rec.record_every + 1) * 3
    )
    check_memory(
        f"simulating {n_paths} paths of {n_steps} steps",
        n_bytes,
        "reduce `n_paths`, `histogram_bins` or `record_paths`, or run in parts with `first_path`",
    )


# ----------------------------------------------------------------- options
@dataclass(frozen=True)
class TimeGrid:
    """The time steps of every path: ``n_steps`` of ``dt``, the first ``n_burn`` discarded.

    Attributes
    ----------
    dt : float
        Time step (s).
    n_steps : int
        Steps per path, burn-in included.
    n_burn : int
        Steps before the averaging window.
    """

    dt: float
    n_steps: int
    n_burn: int

    @classmethod
    def from_times(cls, t_end, dt, burn_in) -> TimeGrid:
        """Validated grid for ``t_end`` and ``burn_in`` (s), rounded to whole steps."""
        t_end = float(check_positive("t_end", t_end, "s"))
        dt = float(check_positive("dt", dt, "s"))
        burn_in = float(np.asarray(burn_in, dtype=float))
        if not (np.isfinite(burn_in) and 0.0 <= burn_in < t_end):
            raise ValueError(
                f"`burn_in` must satisfy 0 <= burn_in < t_end = {t_end!r} s, got {burn_in!r}"
            )
        if not t_end / dt <= MAX_STEPS:
            raise ValueError(
                f"`t_end` / `dt` = {t_end:g} s / {dt:g} s = {t_end / dt:.3g} steps per path; "
                f"at most {MAX_STEPS:.3g} can be counted: shorten `t_end` or enlarge `dt`"
            )
        grid = cls(dt, int(round(t_end / dt)), int(round(burn_in / dt)))
        if grid.window_steps < 1:
            raise ValueError(
                f"`t_end` - `burn_in` = {t_end - burn_in!r} s holds no step of dt = {dt!r} s"
            )
        return grid

    @property
    def window_steps(self) -> int:
        """Steps inside the averaging window."""
        return self.n_steps - self.n_burn

    @property
    def t_end(self) -> float:
        """Simulated time per path (s)."""
        return self.n_steps * self.dt

    @property
    def burn_in(self) -> float:
        """Discarded time per path (s)."""
        return self.n_burn * self.dt


@dataclass(frozen=True)
class InitialState:
    """Where each path starts: ``simulate(initial=...)``, validated.

    Attributes
    ----------
    kind : {"stationary", "rest", "state"}
        Independent Gaussians with the linearised stationary variances (drawn
        from each path's stream), rest, or the given state (z, v).
    z, v : float
        The given state (m, m/s) for ``kind == "state"``.
    """

    kind: str
    z: float = 0.0
    v: float = 0.0

    @classmethod
    def from_argument(cls, initial) -> InitialState:
        """From ``"stationary"``, ``"rest"`` or a finite pair (z0, v0)."""
        if isinstance(initial, str):
            return cls(check_choice("initial", initial, ("stationary", "rest")))
        z0, v0 = (float(x) for x in initial)
        if not (np.isfinite(z0) and np.isfinite(v0)):
            raise ValueError(f"`initial` state must be finite, got {initial!r}")
        return cls("state", z0, v0)


@dataclass(frozen=True)
class RecordOptions:
    """What :func:`simulate` records besides the per-path time averages.

    Attributes
    ----------
    histogram_bins : int
        Bins of the stationary histograms of z and v (0: none).
    histogram_range : ((float, float), (float, float)) or None
        ((z_lo, z_hi), (v_lo, v_hi)) (m, m/s); None: +-5 linearised std.
    record_paths : int
        Number of first paths whose (z, v, theta) are kept.
    record_every : int
        Keep every ``record_every``-th step of them (the initial state included).
    """

    histogram_bins: int = 0
    histogram_range: tuple | None = None
    record_paths: int = 0
    record_every: int = 1

    @classmethod
    def validated(cls, histogram_bins, histogram_range, record_paths, record_every):
        """Checked options; a given ``histogram_range`` as nested float tuples."""
        record_paths = check_int("record_paths", record_paths, 0)
        record_every = check_int("record_every", record_every, 1)
        histogram_bins = check_int("histogram_bins", histogram_bins, 0)
        if histogram_bins > 0 and histogram_range is not None:
            histogram_range = _checked_range(histogram_range)
        return cls(histogram_bins, histogram_range, record_paths, record_every)


def _checked_range(histogram_range) -> tuple:
    arr = np.asarray(histogram_range, dtype=float)
    if arr.shape != (2, 2) or np.any(arr[:, 1] <= arr[:, 0]):
        raise ValueError(
            "`histogram_range` must be ((z_lo, z_hi), (v_lo, v_hi)) with lo < hi, "
            f"got {histogram_range!r}"
        )
    return tuple(tuple(float(x) for x in row) for row in arr)


@dataclass(frozen=True)
class _Run:
    """:func:`simulate`'s arguments, validated and grouped."""

    harvester: Harvester
    psd: float
    excitation: Excitation
    scheme: Integrator
    grid: TimeGrid
    n_paths: int
    seed: int
    first_path: int
    initial: InitialState
    record: RecordOptions
    dW: np.ndarray | None
    companion: bool
    #: Velocity increments of a given base acceleration, ``driver(first, count)``
    #: -> (count, n_steps) (m/s): synthesised or recorded input (:mod:`randvib.montecarlo.driven`).
    driver: object = None


# ----------------------------------------------------------------- simulate
def simulate(
    harvester: Harvester,
    psd: float | Excitation,
    *,
    t_end: float,
    dt: float,
    n_paths: int,
    burn_in: float = 0.0,
    scheme: str | None = None,
    seed: int = 0,
    dW=None,
    initial="stationary",
    first_path: int = 0,
    companion: bool = False,
    control_variates: bool = False,
    histogram_bins: int = 0,
    histogram_range=None,
    record_paths: int = 0,
    record_every: int = 1,
    threads: int | None = None,
    batch_paths: int | None = None,
    progress: bool | None = None,
    check_step: bool = True,
    method: str | None = None,
) -> SimulationResult:
    """Simulate an ensemble of the harvester under white or coloured base excitation.

    Parameters
    ----------
    harvester : Harvester
        Device with scalar parameters; any friction model; any coupling
        (:mod:`randvib.models.coupling`): a coil's current or a piezo's
        voltage is integrated as an auxiliary state with the device, under
        white or rational input, and its mean square is averaged per path
        (``circuit_mean_square``, the power from it); the companion then is
        refused (it assumes a viscous c_e), the control variates are not.
        Any confining potential (monostable, bistable, pure cubic) or the
        free mass (k = k3 = 0: velocity statistics only,
        ``displacement_variance`` is None); a non-confining one is refused.
        With a ``stroke`` the result reports
        :attr:`SimulationResult.stroke_exceedance` and
        :attr:`SimulationResult.stroke_first_passage`.
    psd : float or Excitation
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0: the velocity
        noise is sqrt(S/2) dW (paper Eq. 17). Or an excitation
        (:mod:`randvib.models.excitation`): ``White`` as a number;
        ``BandPass`` and ``KanaiTajimi`` through their shaping filter's two
        states, driven by sqrt(S/2) dW (S their ``level``) and integrated with
        the device by the same scheme. ``BandLimited`` and ``Tabulated`` by a
        stationary Gaussian synthesis per path (:mod:`randvib.montecarlo.driven`:
        path i's input from the stream (seed, i), the kernel taking its exact
        step integrals; batches bound the memory). ``Measured`` is refused:
        simulate on the record with :func:`randvib.monte_carlo_on_record`.
        Under coloured input the companion and the control variates
        (white-noise energy balance) are refused, and the step check covers
        the filter too.
    t_end : float
        Simulated time per path (s), burn-in included.
    dt : float
        Time step (s). Steps whose scheme bias on the linearised device exceeds
        :data:`~randvib.montecarlo.step_check.MAX_STEP_BIAS` are refused (see
        :func:`~randvib.montecarlo.step_check.step_bias`).
    n_paths : int
        Number of independent paths (>= 2 for confidence intervals).
    burn_in : float
        Initial time discarded from the statistics (s), 0 <= burn_in < t_end.
    scheme : {"heun", "euler-maruyama"}
        Integrator (:data:`randvib.montecarlo.integrators.INTEGRATORS`);
        default "heun".
    seed : int
        Seed; path i uses stream (seed, first_path + i) (:mod:`randvib.montecarlo.rng`).
    dW : array_like, optional
        Brownian increments of shape (n_paths, n_steps) (s^0.5, variance dt)
        to drive the simulation instead of the internal streams.
    initial : "stationary", "rest" or (z0, v0)
        Start from independent Gaussians with the linearised stationary
        variances (drawn from each path's stream), from rest, or from a state.
    first_path : int
        Index of the first path's stream; a later batch with
        first_path = n_paths continues the same ensemble.
    companion : bool
        Integrate the friction-free device with the same noise alongside
        (control variates, :meth:`SimulationResult.controls`); white noise only.
    control_variates : bool
        Report control-variate estimates (plain path means otherwise): white
        noise, and band-pass / Kanai-Tajimi input (the Ito-sum and
        energy-change controls, :meth:`SimulationResult.controls`).
    histogram_bins, histogram_range
        Stationary histograms of z and v: number of bins and
        ((z_lo, z_hi), (v_lo, v_hi)) (default +-5 linearised std).
    record_paths, record_every : int
        Keep (z, v, theta) of the first ``record_paths`` paths every
        ``record_every`` steps.
    threads : int, optional
        Number of threads (default: all cores). Results do not depend on it.
    batch_paths : int, optional
        Paths per compiled call (default: all, or chunks of about a second when
        a progress bar is shown). Results do not depend on it.
    progress : bool, optional
        Progress bar (default: on in a notebook or when stderr is a terminal,
        off in CI and in logs).
    check_step : bool
        Refuse steps that are too large (default True).
    method : str, optional
        Deprecated alias of ``scheme``.

    Returns
    -------
    SimulationResult

    Examples
    --------
    A small ensemble (64 paths, 2 s) of the Section 5 device; the 95 %
    half-width comes from the spread between paths:

    >>> import randvib as rv
    >>> result = rv.simulate(
    ...     rv.preset("figure9"), 1.0, t_end=2.0, burn_in=0.5, dt=5e-4, n_paths=64,
    ...     scheme="heun", seed=0, progress=False,
    ... )
    >>> power = result.power_electrical
    >>> print(f"{power.mean:.3e} +- {power.ci95:.1e} W")
    2.426e-03 +- 2.5e-04 W
    """
    run = _validated(
        harvester,
        psd,
        integrators.scheme_argument(scheme, method),
        t_end=t_end,
        dt=dt,
        burn_in=burn_in,
        n_paths=n_paths,
        seed=seed,
        first_path=first_path,
        initial=initial,
        dW=dW,
        companion=companion,
        record=(histogram_bins, histogram_range, record_paths, record_every),
    )
    return execute(
        run,
        control_variates=control_variates,
        check_step=check_step,
        threads=threads,
        batch_paths=batch_paths,
        progress=progress,
    )


def execute(run: _Run, *, control_variates, check_step, threads, batch_paths, progress):
    """Run a validated :class:`_Run` (see :func:`simulate` for the options)."""
    _check_coloured_options(run.excitation, run.companion, control_variates)
    _check_circuit_options(run.harvester, run.companion)
    # refusals before advice: a run that cannot fit is refused before any step warning
    _check_resources(run, batch_paths, progress)
    # One linear test system per run, built when first needed (a fixed start
    # without a step check may need none): the step check, the random start,
    # the default histogram ranges and the circuit's start all use it.
    linear = functools.cache(lambda: LinearTestSystem.of(run.harvester, run.excitation))
    if check_step or run.initial.kind == "stationary":
        _check_scales(run, linear)
    if check_step:
        linear().check_step(run.scheme.name, run.grid.dt)
    setup = _KernelSetup.prepare(run, linear)
    if threads is not None:
        threads = check_int("threads", threads, 1)
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    _announce_long_run(run, setup)
    if progress is None:
        progress = progress_wanted()
    if batch_paths is None and run.driver is not None:  # the input's memory stays bounded
        batch_paths = driven.batch_paths(run.grid.n_steps)
    batches = _batches(
        run.n_paths, batch_paths, run.grid.n_steps, progress, run.record.record_paths
    )
    started = time.perf_counter()
    per_path, hist_groups, records = _run_batches(run, setup, batches, progress)
    wall = time.perf_counter() - started
    return SimulationResult(
        harvester=run.harvester,
        psd=run.psd,
        scheme=run.scheme.name,
        dt=run.grid.dt,
        t_end=run.grid.t_end,
        burn_in=run.grid.burn_in,
        seed=run.seed,
        first_path=run.first_path,
        per_path=per_path,
        control_variates=control_variates,
        histogram=_histogram(setup.recording, hist_groups, batches, run.grid.window_steps),
        histories=_histories(records, run.record.record_every, run.grid.dt),
        wall_time=wall,
        excitation=run.excitation,
    )


# ----------------------------------------------------------------- validation
def _validated(
    harvester,
    psd,
    scheme_argument,
    *,
    t_end,
    dt,
    burn_in,
    n_paths,
    seed,
    first_path,
    initial,
    dW,
    companion,
    record,
) -> _Run:
    """:func:`simulate`'s arguments checked, in one place; messages name the argument.

    ``scheme_argument`` is (scheme name, keyword it came by) and ``record``
    (histogram_bins, histogram_range, record_paths, record_every).
    """
    if not isinstance(harvester, Harvester):
        raise ValueError(f"`harvester` must be a randvib.Harvester, got {type(harvester).__name__}")
    check_scalar_device(harvester, "simulate")  # device, friction and coupling parameters
    # Statistics are time averages of a stationary state: a confining
    # potential, or the free mass for its velocity.
    harvester.potential.require("simulate", CONFINING + ("free",))
    if companion and harvester.potential.is_free:
        raise ValueError(
            "`companion` needs a confining potential: the friction-free companion's exact "
            "E[z^2] (Gibbs) does not exist for the free mass (k = k3 = 0)"
        )
    scheme = integrator(*scheme_argument)
    excitation = _simulated_excitation(psd)
    grid = TimeGrid.from_times(t_end, dt, burn_in)
    n_paths = check_int("n_paths", n_paths, 1)
    seed = check_int("seed", seed, 0, MAX_SEED)
    driver = None
    if excitation.shaping_filter() is None:  # synthesised input: the kernel takes its increments
        if dW is not None:
            raise ValueError(
                f"`dW` drives white noise or a shaping filter; the {excitation.name} input is "
                "synthesised from the seed (leave dW=None)"
            )
        driver = driven.SynthesisedInput(excitation, grid.n_steps, grid.dt, seed)
    return _Run(
        harvester=harvester,
        psd=getattr(excitation, "level", None),
        excitation=excitation,
        driver=driver,
        scheme=scheme,
        grid=grid,
        n_paths=n_paths,
        seed=seed,
        first_path=check_int("first_path", first_path, 0, MAX_PATH_INDEX),
        initial=InitialState.from_argument(initial),
        record=RecordOptions.validated(*record),
        dW=_checked_increments(dW, n_paths, grid.n_steps),
        companion=bool(companion),
    )


def _simulated_excitation(psd) -> Excitation:
    """``psd`` as an excitation that :func:`simulate` can drive, or a clear refusal.

    White noise and the rational spectra with a 2-state shaping filter
    (band-pass, Kanai-Tajimi) are integrated with the device; band-limited
    and tabulated spectra are synthesised (:class:`driven.SynthesisedInput`);
    a measured record is simulated on the record itself by
    :func:`randvib.montecarlo.on_record.monte_carlo_on_record`.
    """
    if not isinstance(psd, Excitation):
        return as_excitation(psd)  # one positive number (an array refused by name)
    if psd.is_white:
        return psd
    if psd.name == "measured":
        raise ValueError(
            "simulate draws its own paths; to simulate the device on the measured record "
            "itself use randvib.monte_carlo_on_record(harvester, record, ...), for Gaussian "
            "paths with the record's Welch PSD pass record.spectrum"
        )
    shaping = psd.shaping_filter()
    if shaping is not None and (shaping.system.n_states != 2 or np.any(shaping.system.d != 0)):
        raise ValueError(
            f"simulate integrates shaping filters of 2 states without feed-through; the "
            f"{psd.name} filter has {shaping.system.n_states}"
        )
    return psd


def _check_coloured_options(excitation: Excitation, companion: bool, control_variates: bool):
    """Refuse the white-noise-only options under coloured input, saying why."""
    if excitation.is_white:
        return
    if companion:
        raise ValueError(
            "`companion` needs white noise: the friction-free companion's exact moments "
            f"(S m/(4c), Gibbs E[z^2]) do not hold under {excitation.name} excitation"
        )
    if control_variates and excitation.shaping_filter() is None:
        raise ValueError(
            "`control_variates` needs Brownian increments (white noise, or band-pass and "
            "Kanai-Tajimi through their filter): under the synthesised or recorded "
            f"{excitation.name} input the Ito sum is the input power, not a zero-mean control; "
            "use control_variates=False"
        )


def _check_circuit_options(harvester: Harvester, companion: bool):
    """Refuse the friction-free companion with a circuit state, saying why.

    The energy-balance controls (the Ito integral, mean exactly zero; the
    change of mechanical energy, zero in the stationary state) hold for any
    coupling, so ``control_variates`` stays available.
    """
    if harvester.has_circuit and companion:
        raise ValueError(
            "`companion` needs the resistive coupling: its exact moments (S m/(4c), Gibbs "
            f"E[z^2]) assume a viscous c_e, not the {harvester.electrical.name} coupling's "
            "circuit state; use companion=False"
        )


def _checked_increments(dW, n_paths, n_steps):
    """Given Brownian increments as a contiguous (n_paths, n_steps) array, or None."""
    if dW is None:
        return None
    dW = np.ascontiguousarray(dW, dtype=float)
    if dW.shape != (n_paths, n_steps):
        raise ValueError(
            f"`dW` must have shape (n_paths, n_steps) = {(n_paths, n_steps)}, got {dW.shape}"
        )
    if not np.all(np.isfinite(dW)):
        raise ValueError("`dW` must be finite")
    return dW


# ----------------------------------------------------------------- kernel set-up
@dataclass(frozen=True)
class _KernelSetup:
    """The compiled loop's argument groups (:mod:`randvib.montecarlo.kernel`) for a run.

    Everything but the paths, the noise and the number of recorded paths is
    the same for every batch; :meth:`arguments` adds those for one batch.
    """

    scheme: tuple
    device: kernel.Device
    friction: kernel.Friction
    timing: kernel.Timing
    initial: kernel.Start
    companion: kernel.Companion
    recording: kernel.Recording
    auxiliary: kernel.Auxiliary | None

    @classmethod
    def prepare(cls, run: _Run, linear) -> _KernelSetup:
        """The argument groups; ``linear()`` gives the run's :class:`LinearTestSystem`."""
        h = run.harvester
        # Given base-acceleration input arrives as velocity increments (m/s): amplitude 1.
        amplitude = 1.0 if run.driver is not None else np.sqrt(run.psd / 2.0)
        device = (h.m, h.c, h.k, h.k3, amplitude)
        initial, companion = _start_states(run, linear)
        return cls(
            scheme=run.scheme.kernel_weights,
            device=kernel.pack(kernel.Device, *device),
            friction=kernel.pack(kernel.Friction, *kernel_arguments(h.friction)),
            timing=kernel.pack(kernel.Timing, run.grid.dt, run.grid.n_steps, run.grid.n_burn),
            initial=initial,
            companion=companion,
            recording=_recording(run, linear),
            auxiliary=_auxiliary(run, linear),
        )

    def arguments(self, run: _Run, lo: int, hi: int) -> dict:
        """:func:`kernel.run_ensemble`'s keyword arguments for paths ``lo .. hi - 1``."""
        n_record = max(0, min(run.record.record_paths - lo, hi - lo))
        if run.driver is not None:
            dw = run.driver(run.first_path + lo, hi - lo)
        else:
            dw = run.dW[lo:hi] if run.dW is not None else np.zeros((0, 0))
        return dict(
            scheme=self.scheme,
            device=self.device,
            friction=self.friction,
            timing=self.timing,
            paths=kernel.pack(kernel.Paths, run.seed, run.first_path + lo, hi - lo),
            initial=self.initial,
            companion=self.companion,
            recording=self.recording._replace(n_record=n_record),
            noise=kernel.Noise(dw, ZIG_KI, ZIG_WI, ZIG_FI),
            auxiliary=self.auxiliary,
        )


def _auxiliary(run: _Run, linear) -> kernel.Auxiliary | None:
    """The kernel's linear auxiliary block: the excitation's filter and the circuit state.

    None for white noise with a resistive (or no) circuit. The filter's states
    (A, G, C: :class:`randvib.models.excitation.ShapingFilter`) come first, the
    circuit's (``x' = a x + b v``, acceleration ``-(f/m) x``) last. With a
    random start the filter alone starts from its exact stationary law N(0, P),
    A P + P A^T + q G G^T = 0; with a circuit the block starts from its
    marginal law under the linearised device (:meth:`LinearTestSystem.covariance`).
    Synthesised or recorded input (``run.driver``) reaches the velocity as
    given increments, like white noise: only a circuit needs the block, and it
    starts from its statistical-linearisation variance under that input.
    """
    h, excitation = run.harvester, run.excitation
    driven_input = run.driver is not None
    if (excitation.is_white or driven_input) and not h.has_circuit:
        return None
    n = kernel.N_AUX
    a, b, g, c, square = np.zeros((n, n)), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    n_filter = 0
    if not (excitation.is_white or driven_input):
        shaping = excitation.shaping_filter()
        system = shaping.system
        n_filter = system.n_states
        a[:n_filter, :n_filter] = system.a
        g[:n_filter] = system.b
        c[:n_filter] = system.c[0]
        q = shaping.noise_intensity
        start = linalg.solve_continuous_lyapunov(system.a, -q * np.outer(system.b, system.b))
    n_states = n_filter
    if h.has_circuit:
        a_x, b_x, f = h.electrical.circuit_equation()
        a[n_filter, n_filter], b[n_filter], c[n_filter] = a_x, b_x, f / h.m
        square[n_filter] = 1.0
        n_states += 1
        if driven_input:
            start = np.array([[_driven_circuit_variance(h, excitation)]])
        else:
            cov = linear().covariance  # (filter, z, v, circuit)
            keep = [*range(n_filter), cov.shape[0] - 1]
            start = cov[np.ix_(keep, keep)]
    chol = np.zeros((n, n))
    chol[:n_states, :n_states] = np.linalg.cholesky(start)
    # white noise (or the given increments) drives the velocity itself
    gain = 1.0 if excitation.is_white or driven_input else 0.0
    coefficients = np.concatenate([a.ravel(), b, g, c, [gain]])
    return kernel.pack(kernel.Auxiliary, n_states, coefficients, square, chol)


def _driven_circuit_variance(harvester: Harvester, excitation: Excitation) -> float:
    """E[x^2] of the circuit state under synthesised or recorded input, for the random start.

    Statistical linearisation under the (coarsened) spectrum; a friction law
    with memory is left out (it only adds damping, and the burn-in corrects
    the start).
    """
    h = harvester
    if h.friction is not None and not h.friction.has_equivalent_damping:
        h = h.updated(friction=None)
    return float(statistical_linearisation(h, coarsened(excitation)).circuit_variance)


def _start_states(run: _Run, linear) -> tuple[kernel.Start, kernel.Companion]:
    """Initial states of the device and of its friction-free companion."""
    h, psd = run.harvester, run.psd
    random = run.initial.kind == "stationary"
    z, v = linear().spread if random else (run.initial.z, run.initial.v)
    # The friction-free companion starts from its own stationary spread (exact
    # Gaussian velocity, Gibbs displacement variance), so its known moments
    # hold from t = 0 and its control mean is right without a long burn-in.
    comp_z, comp_v = z, v
    if run.companion and random and h.c > 0:
        comp_v = float(np.sqrt(exact.linear_velocity_variance(h.m, h.c, psd)))
        comp_z = float(np.sqrt(exact.gibbs_displacement_moment(h.m, h.c, h.k, h.k3, psd)))
        if h.friction is None or h.friction.vanishes:  # the device is its own companion
            z, v = comp_z, comp_v
    return (
        kernel.pack(kernel.Start, random, z, v),
        kernel.pack(kernel.Companion, run.companion, comp_z, comp_v),
    )


def _recording(run: _Run, linear) -> kernel.Recording:
    """Histogram ranges and bins (default ranges +-5 linearised std); records per batch.

    The free mass's z spreads like a random walk: its default range is
    +-5 sqrt(2 sigma_v^2 (m/c_eff) t_end), five times the walk's spread at the end.
    """
    bins = run.record.histogram_bins
    if bins == 0:
        lo, hi = np.zeros(2), np.ones(2)  # unused
    else:
        ranges = run.record.histogram_range
        if ranges is None:
            sz, sv = linear().spread
            if run.harvester.potential.is_free:
                c_eff = linear().c_eff
                sz = sv * np.sqrt(2.0 * run.harvester.m / c_eff * run.grid.t_end)
            ranges = ((-5 * sz, 5 * sz), (-5 * sv, 5 * sv))
        arr = np.asarray(ranges, dtype=float)
        lo, hi = arr[:, 0], arr[:, 1]
    stroke = np.inf if run.harvester.stroke is None else run.harvester.stroke
    return kernel.pack(kernel.Recording, lo, hi, bins, 0, run.record.record_every, stroke)


# ----------------------------------------------------------------- compiled calls
def _run_batches(run: _Run, setup: _KernelSetup, batches, progress: bool):
    """Run the compiled loop batch by batch.

    Returns
    -------
    per_path : ndarray, shape (n_paths, N_ACC)
        Per-path time averages.
    hist_groups : ndarray of int64, shape (n_groups, 2, bins)
        Histogram counts of z and v per chunk of paths, batches in order.
    records : ndarray or None
        Recorded histories of the first paths (from the first batch).
    """
    per_path = np.empty((run.n_paths, kernel.N_ACC))
    hist_groups = []
    records = None
    bar = None
    if progress:
        bar = progress_bar(run.n_paths, desc="simulate", unit="path", transient=True)
    try:
        for lo, hi in batches:
            acc, failed, hist, rec = interruptible(
                kernel.run_ensemble, **setup.arguments(run, lo, hi)
            )
            _raise_if_diverged(run, lo, failed)
            per_path[lo:hi] = acc
            if run.record.histogram_bins > 0:
                hist_groups.append(hist)
            if lo == 0 and run.record.record_paths > 0:
                records = rec
            if bar is not None:
                bar.update(hi - lo)
    finally:
        if bar is not None:
            bar.close()
    hist_groups = np.concatenate(hist_groups) if hist_groups else None
    return per_path, hist_groups, records


def interruptible(compiled, **kwargs):
    """Call a compiled (nogil) loop so that Ctrl-C stops it within a fraction of a second.

    A compiled loop does not see signals, so it runs in a worker thread while
    this (main) thread waits; on KeyboardInterrupt the shared ``stop`` flag is
    set, the loop ends at its next check, and KeyboardInterrupt is raised
    (finished batches, points and fits are kept by the callers).
    """
    stop = np.zeros(1, dtype=np.int64)
    if threading.current_thread() is not threading.main_thread():
        return compiled(stop=stop, **kwargs)  # signals only reach the main thread
    outcome = {}

    def target():
        try:
            outcome["value"] = compiled(stop=stop, **kwargs)
        except BaseException as exc:  # handed to the caller's thread
            outcome["error"] = exc

    worker = threading.Thread(target=target, name="randvib-kernel", daemon=True)
    worker.start()
    try:
        while worker.is_alive():
            worker.join(0.05)
    except KeyboardInterrupt:
        stop[0] = 1
        worker.join()
        raise
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]


def _raise_if_diverged(run: _Run, lo: int, failed: np.ndarray) -> None:
    bad = np.flatnonzero(failed >= 0)
    if bad.size:
        p = bad[0]
        dt = run.grid.dt
        raise SimulationDivergedError(
            f"simulation diverged: path {run.first_path + lo + p} became non-finite by step "
            f"{failed[p]} (t = {failed[p] * dt:.6g} s) with dt = {dt!r} s, "
            f"scheme {run.scheme.name}, psd = {run.psd!r}, "
            f"parameters {run.harvester.parameters()}"
        )


def _batches(n_paths, batch_paths, n_steps, progress, record_paths):
    if batch_paths is None:
        if progress:
            # about 1e8 path-steps per call: a second or so, for a live bar
            batch_paths = max(kernel.LANES * numba.get_num_threads(), int(1e8 // max(n_steps, 1)))
        else:
            batch_paths = n_paths
    batch_paths = check_int("batch_paths", batch_paths, 1)
    batch_paths = max(batch_paths, min(record_paths, n_paths))  # records come from batch 0
    edges = list(range(0, n_paths, batch_paths)) + [n_paths]
    return list(zip(edges[:-1], edges[1:], strict=True))


# ----------------------------------------------------------------- result assembly
def _histogram(recording: kernel.Recording, groups, batches, window_steps: int):
    """Densities of z and v from the per-chunk counts ``groups`` (or None without bins)."""
    bins = recording.hist_bins
    if bins == 0:
        return None
    # The kernel's chunks: LANES paths each, the last of each batch possibly fewer.
    sizes = [
        min(kernel.LANES, hi - start) for lo, hi in batches for start in range(lo, hi, kernel.LANES)
    ]
    counts = groups.sum(axis=0)
    n_samples = sum(sizes) * window_steps
    z_edges = np.linspace(recording.hist_lo[0], recording.hist_hi[0], bins + 1)
    v_edges = np.linspace(recording.hist_lo[1], recording.hist_hi[1], bins + 1)
    return Histogram(
        z_edges,
        counts[0] / (n_samples * np.diff(z_edges)),
        v_edges,
        counts[1] / (n_samples * np.diff(v_edges)),
        (1 - counts[0].sum() / n_samples, 1 - counts[1].sum() / n_samples),
        group_counts=groups,
        group_paths=np.array(sizes),
        window_steps=window_steps,
    )


def _histories(records, record_every: int, dt: float) -> Histories | None:
    """Recorded (z, v, theta) of the first paths with their times (s)."""
    if records is None:
        return None
    n_rec = records.shape[1]
    return Histories(
        np.arange(n_rec) * record_every * dt,
        records[:, :, 0].copy(),
        records[:, :, 1].copy(),
        records[:, :, 2].copy(),
    )
