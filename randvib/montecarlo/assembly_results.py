"""What :func:`randvib.simulate` returns for an assembly: per DOF, per transducer, per element.

:class:`AssemblySimulationResult` holds the per-path time averages of an
assembly's run (the columns of
:class:`randvib.montecarlo.assembly_kernel.Columns`) and computes every
statistic from them with its 95 % interval (:func:`randvib.statistics.estimate`):

* per DOF: ``displacement_variance`` E[x_i^2] and ``velocity_variance``
  E[x_i'^2], from the per-path averages of x x^T and v v^T;
* per transducer (:class:`TransducerStatistics`, in the assembly's order):
  ``power_electrical`` (c_e E[u'^2] of a static coupling; the circuit's
  (R_L + R_C) E[i^2] or E[V^2] / R_L; a bridge's stored power plus coil and
  diode losses), ``power_load`` where the coupling names a load (a bridge's:
  its stored power, as for the single mass), a bridge's ``power_stored``,
  ``power_coil_loss`` and ``power_diode_loss``, the circuit's mean square,
  the coordinate's variances and the stroke exceedance;
* per element (:class:`ElementStatistics`): its friction power E[u' F],
  E|u'|, the coordinate's variances and the stroke exceedance;
* the **energy balance** under white noise: ``power_dissipated`` (structure
  and element dashpots and static couplings tr(C_lin E[v v^T]), friction,
  circuits, bridges) against ``power_input`` = r^T M r S / 4
  (docs/conventions.md, "Assemblies"): :meth:`energy_balance_residual`.

Every statistic is a mean over paths of a per-path time average, so one
estimator serves them all, with the energy-balance control variates
(:meth:`AssemblySimulationResult.controls`) when ``control_variates``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from randvib import _display, formatting
from randvib.models.assembly import Assembly
from randvib.models.assembly_parts import between_words
from randvib.models.excitation import Excitation
from randvib.montecarlo import assembly_kernel as ak
from randvib.montecarlo.assembly_setup import PartOrder, upper_index
from randvib.statistics import Statistic, estimate


def _between(between) -> list:
    return [between[0], "base" if between[1] is None else between[1]]


def _to_dict(stat):
    return None if stat is None else stat.to_dict()


@dataclass(frozen=True)
class TransducerStatistics:
    """One transducer's Monte Carlo statistics (SI units; None where they do not apply)."""

    between: tuple
    coupling: str
    displacement_variance: Statistic
    velocity_variance: Statistic
    power_electrical: Statistic
    power_load: Statistic | None = None
    power_stored: Statistic | None = None
    power_coil_loss: Statistic | None = None
    power_diode_loss: Statistic | None = None
    circuit_mean_square: Statistic | None = None
    stroke_exceedance: Statistic | None = None

    def to_dict(self) -> dict:
        """{name: {mean, ci95}} of the statistics that apply, with ``between`` and ``coupling``."""
        out = {"between": _between(self.between), "coupling": self.coupling}
        for name in (
            "power_electrical", "power_load", "power_stored", "power_coil_loss",
            "power_diode_loss", "circuit_mean_square", "displacement_variance",
            "velocity_variance", "stroke_exceedance",
        ):  # fmt: skip
            value = getattr(self, name)
            if value is not None:
                out[name] = value.to_dict()
        return out


@dataclass(frozen=True)
class ElementStatistics:
    """One element's Monte Carlo statistics (SI units)."""

    between: tuple
    displacement_variance: Statistic
    velocity_variance: Statistic
    friction_power: Statistic
    mean_abs_velocity: Statistic
    stroke_exceedance: Statistic | None = None

    def to_dict(self) -> dict:
        out = {"between": _between(self.between)}
        for name in (
            "friction_power", "mean_abs_velocity", "displacement_variance", "velocity_variance",
            "stroke_exceedance",
        ):  # fmt: skip
            value = getattr(self, name)
            if value is not None:
                out[name] = value.to_dict()
        return out


@dataclass(frozen=True)
class AssemblyHistories:
    """The whole state of the first paths every ``record_every`` steps (t = 0 included).

    ``x`` and ``v`` (n_paths, n_times, N) in m and m/s; ``state`` the
    kernel's rows (:func:`randvib.montecarlo.assembly_kernel.row_offsets`).
    """

    time: np.ndarray
    x: np.ndarray
    v: np.ndarray
    state: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class AssemblySimulationResult:
    """Result of :func:`randvib.simulate` for an :class:`~randvib.models.assembly.Assembly`."""

    assembly: Assembly
    #: White-noise level S, or the excitation's level; None for a table or a record.
    psd: float | None
    excitation: Excitation
    scheme: str
    dt: float
    t_end: float
    burn_in: float
    seed: int
    first_path: int
    per_path: np.ndarray = field(repr=False)
    columns: ak.Columns = field(repr=False)
    control_variates: bool = False
    histories: AssemblyHistories | None = field(default=None, repr=False)
    wall_time: float = 0.0

    # ------------------------------------------------------------ basics
    @property
    def n_paths(self) -> int:
        return self.per_path.shape[0]

    @property
    def averaging_time(self) -> float:
        """Length of the averaging window per path (s)."""
        return self.t_end - self.burn_in

    @property
    def is_white(self) -> bool:
        return self.excitation.is_white

    def controls(self) -> np.ndarray:
        """The zero-mean controls per path: the Ito sum and the energy change (white or filter).

        (1/T) sum (M r)^T v_n dW_n has mean exactly zero for any adapted v; the
        energy change (H(T) - H(0)) / T has zero mean in the stationary state.
        Under synthesised or recorded input the increments are not Brownian.
        """
        if self.excitation.shaping_filter() is None:
            raise ValueError(
                "control variates need Brownian increments (white noise or a shaping filter); "
                f"the {self.excitation.name} input is synthesised or recorded"
            )
        c = self.columns
        change = (self.per_path[:, c.h1] - self.per_path[:, c.h0]) / self.averaging_time
        return np.column_stack([self.per_path[:, c.ito], change])

    def statistic(self, samples, control_variates: bool | None = None) -> Statistic:
        """The mean of per-path ``samples`` with its interval (controlled if asked)."""
        use = self.control_variates if control_variates is None else control_variates
        return estimate(np.asarray(samples, dtype=float), self.controls() if use else None)

    # ---------------------------------------------------------- per path
    def second_moment(self, which: str, weights) -> np.ndarray:
        """Per path, the time average of (w^T x)^2 (``which`` "x") or (w^T v)^2 ("v")."""
        return self.quadratic(which, np.outer(weights, weights))

    def quadratic(self, which: str, matrix) -> np.ndarray:
        """Per path, the time average of x^T Q x (``which`` "x") or v^T Q v ("v")."""
        n = self.assembly.n_dof
        first = self.columns.xx if which == "x" else self.columns.vv
        q = np.asarray(matrix, dtype=float)
        out = np.zeros(self.n_paths)
        for a in range(n):
            for b in range(a, n):
                weight = q[a, a] if a == b else q[a, b] + q[b, a]
                if weight != 0.0:
                    out += weight * self.per_path[:, first + upper_index(n, a, b)]
        return out

    def _coordinate(self, part) -> np.ndarray:
        return self.assembly.incidence(part)

    def transducer_power(self, index: int) -> tuple[np.ndarray, np.ndarray | None]:
        """Per path (power_electrical, power_load or None) of transducer ``index`` (W)."""
        transducer = self.assembly.transducers[index]
        coupling = transducer.coupling
        if transducer.is_rectified:
            stored, coil, diode = self._bridge(index)
            return stored + coil + diode, stored
        du2 = self.second_moment("v", self._coordinate(transducer))
        s2 = self._circuit_square(index)
        electrical = coupling.power_electrical(du2, s2)
        if not transducer.has_load:
            return electrical, None
        return electrical, coupling.power_load(du2, s2)

    def _circuit_square(self, index: int) -> np.ndarray | None:
        order = PartOrder.of(self.assembly)
        if index not in order.circuits:
            return None
        return self.per_path[:, self.columns.circuit + order.circuits.index(index)]

    def _bridge(self, index: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        col = self.columns.bridge + ak.N_BRIDGE_ACC * PartOrder.of(self.assembly).bridges.index(
            index
        )
        return tuple(
            self.per_path[:, col + q] for q in (ak.BRIDGE_STORED, ak.BRIDGE_COIL, ak.BRIDGE_DIODE)
        )

    def _stroke(self, kind: str, index: int) -> Statistic | None:
        paths = [path for path, _, _ in self.assembly.strokes()]
        name = f"{kind}.{index}"
        if name not in paths:
            return None
        return self.statistic(self.per_path[:, self.columns.stroke + paths.index(name)])

    def dissipated_power(self) -> np.ndarray:
        """Per path, every dissipation (W): tr(C_lin v v^T), friction, circuits and bridges."""
        _, c, _ = self.assembly.linear_matrices()
        total = self.quadratic("v", c)
        e = len(self.assembly.elements)
        total = total + self.per_path[:, self.columns.friction : self.columns.friction + e].sum(
            axis=1
        )
        for index, transducer in enumerate(self.assembly.transducers):
            if transducer.is_dynamic or transducer.is_rectified:
                total = total + self.transducer_power(index)[0]
        return total

    # -------------------------------------------------------- statistics
    @property
    def displacement_variance(self) -> list[Statistic]:
        """E[x_i^2] (m^2), one per DOF (displacements relative to the base)."""
        n = self.assembly.n_dof
        return [
            self.statistic(self.per_path[:, self.columns.xx + upper_index(n, i, i)])
            for i in range(n)
        ]

    @property
    def velocity_variance(self) -> list[Statistic]:
        """E[x_i'^2] ((m/s)^2), one per DOF."""
        n = self.assembly.n_dof
        return [
            self.statistic(self.per_path[:, self.columns.vv + upper_index(n, i, i)])
            for i in range(n)
        ]

    @property
    def transducers(self) -> list[TransducerStatistics]:
        """One :class:`TransducerStatistics` per transducer, in the assembly's order."""
        out = []
        for index, transducer in enumerate(self.assembly.transducers):
            d = self._coordinate(transducer)
            electrical, load = self.transducer_power(index)
            extra = {}
            if transducer.is_rectified:
                stored, coil, diode = self._bridge(index)
                extra = dict(
                    power_stored=self.statistic(stored),
                    power_coil_loss=self.statistic(coil),
                    power_diode_loss=self.statistic(diode),
                )
            square = self._circuit_square(index)
            out.append(
                TransducerStatistics(
                    between=transducer.between,
                    coupling=transducer.coupling.name,
                    displacement_variance=self.statistic(self.second_moment("x", d)),
                    velocity_variance=self.statistic(self.second_moment("v", d)),
                    power_electrical=self.statistic(electrical),
                    power_load=None if load is None else self.statistic(load),
                    circuit_mean_square=None if square is None else self.statistic(square),
                    stroke_exceedance=self._stroke("transducer", index),
                    **extra,
                )
            )
        return out

    @property
    def elements(self) -> list[ElementStatistics]:
        """One :class:`ElementStatistics` per element, in the assembly's order."""
        out = []
        c = self.columns
        for index, element in enumerate(self.assembly.elements):
            d = self._coordinate(element)
            out.append(
                ElementStatistics(
                    between=element.between,
                    displacement_variance=self.statistic(self.second_moment("x", d)),
                    velocity_variance=self.statistic(self.second_moment("v", d)),
                    friction_power=self.statistic(self.per_path[:, c.friction + index]),
                    mean_abs_velocity=self.statistic(self.per_path[:, c.abs_du + index]),
                    stroke_exceedance=self._stroke("element", index),
                )
            )
        return out

    @property
    def power_electrical(self) -> Statistic:
        """The transducers' electrical power together (W)."""
        total = np.zeros(self.n_paths)
        for index in range(len(self.assembly.transducers)):
            total = total + self.transducer_power(index)[0]
        return self.statistic(total)

    @property
    def power_input(self) -> float | None:
        """r^T M r S / 4 (W) under white noise (docs/conventions.md, "Assemblies"); else None."""
        if not self.is_white:
            return None
        r = self.assembly.influence
        return float(r @ self.assembly.mass @ r * self.psd / 4.0)

    @property
    def power_dissipated(self) -> Statistic:
        """Every dissipation path together (W); equals :attr:`power_input` under white noise."""
        return self.statistic(self.dissipated_power())

    def energy_balance_residual(self, control_variates: bool | None = None) -> Statistic:
        """power_dissipated - r^T M r S / 4 (W): zero up to O(dt) and noise (white only)."""
        if not self.is_white:
            raise ValueError(
                "the energy balance r^T M r S / 4 holds under white noise; this result was "
                f"simulated under {self.excitation.name} excitation"
            )
        return self.statistic(self.dissipated_power() - self.power_input, control_variates)

    # ------------------------------------------------------------ output
    def summary(self) -> dict:
        """JSON-ready: ``transducers``, ``displacement_variance``, ``velocity_variance``, ...

        Per transducer (file order) and per DOF, each statistic as {mean, ci95};
        the run's settings beside them.
        """
        out = {
            "transducers": [t.to_dict() for t in self.transducers],
            "displacement_variance": [s.to_dict() for s in self.displacement_variance],
            "velocity_variance": [s.to_dict() for s in self.velocity_variance],
            "elements": [e.to_dict() for e in self.elements],
            "power_electrical": self.power_electrical.to_dict(),
            "power_dissipated": self.power_dissipated.to_dict(),
            "power_input": self.power_input,
        }
        out.update(
            n_paths=self.n_paths, dt=self.dt, t_end=self.t_end, burn_in=self.burn_in,
            method=self.scheme, seed=self.seed, psd=self.psd,
            control_variates=self.control_variates, wall_time=self.wall_time,
            excitation=self.excitation.parameters(),
        )  # fmt: skip
        return out

    def to_dict(self) -> dict:
        """The same as :meth:`summary`."""
        return self.summary()

    def _rows(self):
        rows = []
        for index, t in enumerate(self.transducers):
            where = f"transducer {index} {between_words(t.between)} ({t.coupling})"
            for name in ("power_electrical", "power_load", "power_stored"):
                stat = getattr(t, name)
                if stat is not None:
                    rows.append((f"{where} {name}", formatting.estimate(stat.mean, stat.ci95), "W"))
        pairs = zip(self.displacement_variance, self.velocity_variance, strict=True)
        for i, (zz, vv) in enumerate(pairs):
            rows.append(
                (f"DOF {i} displacement_variance", formatting.estimate(zz.mean, zz.ci95), "m^2")
            )
            rows.append(
                (f"DOF {i} velocity_variance", formatting.estimate(vv.mean, vv.ci95), "(m/s)^2")
            )
        return rows

    def _settings_line(self) -> str:
        level = "" if self.psd is None else f", S = {self.psd:g}"
        cv = ", control variates" if self.control_variates else ""
        return (
            f"{self.n_paths} paths x {formatting.compact(self.averaging_time, 4)} s averaged, "
            f"dt {self.dt:g} s, {self.scheme}, seed {self.seed}, {self.excitation.name}{level}{cv}"
        )

    def __str__(self) -> str:
        return _display.text_table(
            "Assembly Monte Carlo (mean ± 95 % half-width)", self._rows(), self._settings_line()
        )

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.assembly.describe()}; {self._settings_line()})"
