"""What :func:`randvib.simulate` returns: per-path averages, their statistics, histograms, paths.

:class:`SimulationResult` holds the per-path time averages of a run (the
kernel's accumulators, named by :class:`randvib.montecarlo.kernel.PathAverages`)
and computes every statistic from them with its interval
(:mod:`randvib.statistics`); :class:`Histogram` holds the stationary
histograms of z and v counted per group of paths, :class:`Histories` the
recorded paths. Numbers are computed here; tables and reprs are drawn by
:mod:`randvib._display`, with the units of :mod:`randvib.quantities` and the
digits of :mod:`randvib.formatting`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import special  # Student t quantile; lighter than scipy.stats

from randvib import _display, formatting
from randvib._validation import check_choice
from randvib.analytic import exact_solutions as exact
from randvib.models.excitation import Excitation, as_excitation
from randvib.models.harvester import Harvester
from randvib.montecarlo import kernel
from randvib.quantities import unit
from randvib.statistics import FirstPassage, Statistic, estimate, proportion

#: The statistics of a :class:`SimulationResult` that are shown, in order (their
#: units: :mod:`randvib.quantities`).
STATISTICS = (
    "power_electrical",
    "power_load",
    "velocity_variance",
    "displacement_variance",
    "mean_abs_velocity",
    "friction_power",
    "circuit_mean_square",
    "power_stored",
    "power_coil_loss",
    "power_diode_loss",
    "power_mechanical",
    "stroke_exceedance",
)

#: The statistics of a bridge (:mod:`randvib.models.rectifier`), None without one.
BRIDGE_STATISTICS = ("power_stored", "power_coil_loss", "power_diode_loss", "power_mechanical")


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

    @classmethod
    def from_counts(
        cls, recording: kernel.Recording, groups: np.ndarray, sizes: list, window_steps: int
    ) -> Histogram:
        """Densities of z and v from the kernel's counts per group of paths.

        ``groups`` (n_groups, 2, bins) are the counts of the kernel's chunks of
        paths, ``sizes`` their numbers of paths, ``window_steps`` the samples
        per path; the bins are those of ``recording``.
        """
        bins = recording.hist_bins
        counts = groups.sum(axis=0)
        n_samples = sum(sizes) * window_steps
        z_edges = np.linspace(recording.hist_lo[0], recording.hist_hi[0], bins + 1)
        v_edges = np.linspace(recording.hist_lo[1], recording.hist_hi[1], bins + 1)
        return cls(
            z_edges,
            counts[0] / (n_samples * np.diff(z_edges)),
            v_edges,
            counts[1] / (n_samples * np.diff(v_edges)),
            (1 - counts[0].sum() / n_samples, 1 - counts[1].sum() / n_samples),
            group_counts=groups,
            group_paths=np.array(sizes),
            window_steps=window_steps,
        )

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

    @classmethod
    def from_records(cls, records: np.ndarray, record_every: int, dt: float) -> Histories:
        """From the kernel's records (n_paths, n_records, 3) of (z, v, theta), every
        ``record_every`` steps of ``dt`` (s) from t = 0."""
        n_rec = records.shape[1]
        return cls(
            np.arange(n_rec) * record_every * dt,
            records[:, :, 0].copy(),
            records[:, :, 1].copy(),
            records[:, :, 2].copy(),
        )


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

        Its 95 % interval is the Wilson interval (:func:`randvib.statistics.proportion`).

        For the free mass it is the fraction over this window (z is not
        stationary, so it grows with the run), not a stationary probability.
        """
        if self.harvester.stroke is None:
            return None
        # a probability: the Wilson interval stays in [0, 1] where mean +- t SE would not
        controls = self.controls() if self.control_variates else None
        return proportion(self.averages.beyond_stroke, controls)

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
        With a bridge: everything the circuit takes, stored plus coil and diode losses.
        """
        if self.harvester.is_rectified:
            avg = self.averages
            return self.statistic(avg.stored_power + avg.coil_loss + avg.diode_loss)
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
    def power_stored(self) -> Statistic | None:
        """Power stored through a bridge (W): V_b E|i| (battery), E[V_C^2] / R_L (capacitor).

        None without a bridge.
        """
        if not self.harvester.is_rectified:
            return None
        return self.statistic(self.averages.stored_power)

    @property
    def power_coil_loss(self) -> Statistic | None:
        """R_C E[i^2] (W) of a rectified coil (0 for a piezo bridge); None without a bridge."""
        if not self.harvester.is_rectified:
            return None
        return self.statistic(self.averages.coil_loss)

    @property
    def power_diode_loss(self) -> Statistic | None:
        """2 V_d E|i| (W) of a bridge; None without one."""
        if not self.harvester.is_rectified:
            return None
        return self.statistic(self.averages.diode_loss)

    @property
    def power_mechanical(self) -> Statistic | None:
        """Mechanical dissipation c_m E[z'^2] + E[z' F] (W) beside a bridge; None without one."""
        if not self.harvester.is_rectified:
            return None
        return self.statistic(self.harvester.c * self.averages.v2 + self.averages.friction_power)

    @property
    def power_load(self) -> Statistic | None:
        """E[i^2 R_L] (W), with a circuit; the stored power with a bridge; else None."""
        e = self.harvester.electrical
        if e is None:
            return None
        if self.harvester.is_rectified:
            return self.power_stored
        if self.harvester.has_circuit:
            return self.statistic(self._circuit_power("power_load"))
        return self.statistic(self.harvester.c_e * e.load_fraction * self.averages.v2)

    def energy_balance_residual(self, control_variates: bool | None = None) -> Statistic:
        """c E[v^2] + E[v F] + P_x - S m / 4 (W): zero up to O(dt) and noise (white only).

        ``P_x`` is the power of a circuit state ((R_L + R_C) i^2 or V^2 / R_L;
        docs/conventions.md: the coupling's force f x does the work
        f x v = R x^2 + d/dt(stored energy)) or of a bridge (stored, coil and
        diode losses); without one, c holds c_e. ``control_variates`` (default:
        the result's setting) narrows the interval with :meth:`controls`.
        """
        self._require_white("the energy-balance residual and its S m / 4")
        h = self.harvester
        samples = h.c * self.averages.v2 + self.averages.friction_power - self.psd * h.m / 4.0
        if h.is_rectified:
            avg = self.averages
            samples = samples + avg.stored_power + avg.coil_loss + avg.diode_loss
        elif h.has_circuit:
            samples = samples + self._circuit_power("power_electrical")
        return self.statistic(samples, control_variates)

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
        if self.harvester.is_rectified:
            out.update({name: getattr(self, name).to_dict() for name in BRIDGE_STATISTICS})
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
            method=self.scheme,  # the JSON key is the CLI's: `--method`
            seed=self.seed,
            psd=self.psd,
            control_variates=self.control_variates,
            wall_time=self.wall_time,
        )
        # the input in full (a coloured one has more than a level); `psd` stays the level S
        excitation = self.excitation or as_excitation(self.psd)
        out["excitation"] = excitation.parameters()
        return out

    def to_dict(self, per_path: bool = False) -> dict:
        """The same as :meth:`summary` (JSON-ready).

        With ``per_path=True``, also what :meth:`from_dict` rebuilds the
        result from: ``device`` (:meth:`Harvester.parameters`), ``first_path``
        and ``per_path`` (the per-path averages, one list per path; the
        histograms and recorded paths are not saved).
        """
        out = self.summary()
        if per_path:
            out["device"] = self.harvester.parameters()
            out["first_path"] = self.first_path
            out["per_path"] = self.per_path.tolist()
        return out

    @classmethod
    def from_dict(cls, d: dict, excitation: Excitation | None = None) -> SimulationResult:
        """The result that :meth:`to_dict` ``(per_path=True)`` wrote (a run saved as JSON).

        Every statistic is recomputed from the saved per-path averages, so it
        equals the saved run's. ``excitation``: the input, needed only for one
        that its parameters do not describe in full (a table, a record); white
        noise and the named spectra are rebuilt from the saved ones.
        """
        from randvib.models.harvester import harvester_from_parameters

        if "per_path" not in d or "device" not in d:
            raise ValueError(
                "this dict has the statistics only: save the run with "
                "`to_dict(per_path=True)` to reload it"
            )
        return cls(
            harvester=harvester_from_parameters(d["device"]),
            psd=d["psd"],
            scheme=d["method"],
            dt=d["dt"],
            t_end=d["t_end"],
            burn_in=d["burn_in"],
            seed=d["seed"],
            first_path=d.get("first_path", 0),
            per_path=np.array(d["per_path"], dtype=float),
            control_variates=d["control_variates"],
            wall_time=d.get("wall_time", 0.0),
            excitation=_saved_excitation(d.get("excitation"), excitation),
        )

    def _statistics(self) -> list[tuple[str, Statistic, str]]:
        """(name, Statistic, unit) of every statistic this run has."""
        out = [(name, getattr(self, name)) for name in STATISTICS]
        electrical = self.harvester.electrical
        return [(name, stat, unit(name, electrical)) for name, stat in out if stat is not None]

    def _settings_line(self) -> str:
        if self.is_white:
            excitation = f"white, S = {self.psd:g}"
        else:  # the name and level, not the repr (a table's or record's arrays)
            level = "" if self.psd is None else f", S = {self.psd:g}"
            excitation = f"{self.excitation.name}{level}"
        cv = ", control variates" if self.control_variates else ""
        return (
            f"{self.n_paths} paths x {formatting.compact(self.averaging_time, 4)} s averaged, "
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
                "unit": units,
            }
            for name, stat, units in self._statistics()
        }
        return pd.DataFrame.from_dict(rows, orient="index").rename_axis("statistic")

    def _rows(self):
        return [(n, formatting.estimate(s.mean, s.ci95), u) for n, s, u in self._statistics()]

    def __repr__(self) -> str:
        power = self.power_electrical
        return (
            f"{type(self).__name__}({self._settings_line()}; power_electrical = "
            f"{formatting.estimate(power.mean, power.ci95)} W)"
        )

    def __str__(self) -> str:
        return _display.text_table(
            "Monte Carlo (mean ± 95 % half-width)", self._rows(), self._settings_line()
        )

    def _repr_html_(self) -> str:
        return _display.html_table(
            "Monte Carlo (mean ± 95 % half-width)", self._rows(), self._settings_line()
        )


def _saved_excitation(saved: dict | None, given: Excitation | None) -> Excitation | None:
    """The excitation of a saved run: ``given``, else rebuilt from its saved parameters
    (None for white noise, which ``psd`` describes)."""
    from dataclasses import fields

    from randvib.models.excitation import EXCITATIONS

    if given is not None:
        return given
    if saved is None or saved.get("excitation") == "white":
        return None
    values = {k: v for k, v in saved.items() if k != "excitation"}
    cls = EXCITATIONS.get(saved.get("excitation"))
    if cls is None or set(values) != {f.name for f in fields(cls)}:
        raise ValueError(
            f"the {saved.get('excitation')!r} excitation is saved by its summary only: pass it "
            "as `excitation` to rebuild the run"
        )
    return cls(**values)
