"""Monte Carlo on a measured base-acceleration record: ``monte_carlo_on_record``.

A user's accelerometer record (:class:`randvib.Measured`, built from a
:class:`randvib.Record` with a ``base_acceleration`` channel, or read from
CSV columns ``time``, ``base_acceleration``) is the input itself, not a
spectrum to draw from: the stochastic simulation of :func:`randvib.simulate`
(its schemes, friction laws, circuits and step check) is driven by the record
(linearly interpolated between samples, each device step taking the exact
integral of that line, :class:`randvib.montecarlo.driven.RecordedInput`), and
its segments are the paths of a confidence interval. The deterministic
response to a record's input, for identification, is
:func:`randvib.record_response`.

**Confidence interval: segments as paths (batch means).** One record is one
realisation, so there are no independent paths. The record after a first
burn-in is cut into K equal windows; window i is simulated as path i,
starting ``burn_in`` seconds earlier on the record itself (its burn-in is
the record just before it, so the state entering the window is the state
the record drove the device into, up to a start forgotten over the
burn-in). The windows' time averages are then the batch means of the one
long response, and the 95 % interval is Student's t over the K means.
This is preferred to independent burn-ins from rest (which would discard
the record before every window, or overlap windows) and to a single long
run with a correlation-time estimate (which needs a model of the
autocorrelation): it is valid when each window is much longer than the
response's correlation time (the device's decay time 2 m / c_eq and the
record's own correlation), so that the K means are nearly independent;
:attr:`RecordSimulation.lag1_correlation` reports the correlation of
successive means as a check (near zero: the interval is honest; clearly
positive: use fewer, longer segments).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from randvib._validation import check_int, check_positive
from randvib.models.assembly import Assembly
from randvib.models.excitation import Measured
from randvib.models.harvester import Harvester
from randvib.montecarlo import driven
from randvib.montecarlo.assembly_results import AssemblySimulationResult
from randvib.montecarlo.assembly_simulation import execute_assembly, validated_assembly
from randvib.montecarlo.results import SimulationResult
from randvib.montecarlo.simulation import execute
from randvib.montecarlo.validation import validated


def monte_carlo_on_record(
    harvester: Harvester | Assembly,
    record: Measured,
    *,
    segments: int = 10,
    burn_in: float = 1.0,
    substeps: int = 1,
    scheme: str = "heun",
    seed: int = 0,
    initial="stationary",
    record_paths: int = 0,
    record_every: int = 1,
    threads: int | None = None,
    progress: bool | None = None,
    check_step: bool = True,
) -> SimulationResult:
    """Monte Carlo of the harvester driven by a measured record; CI from segments.

    Parameters
    ----------
    harvester : Harvester or Assembly
        Device with scalar parameters; any friction law. An
        :class:`~randvib.models.assembly.Assembly` takes the record as its
        base acceleration (through its influence vector) and returns an
        :class:`~randvib.montecarlo.assembly_results.AssemblySimulationResult`
        with the same paths (one per window).
    record : Measured
        The measured base acceleration (``rv.Measured(record)`` of a
        :class:`randvib.Record`, or ``rv.Measured.from_csv(path)``). Its mean
        is removed: a constant base
        acceleration cannot persist, and an offset is the sensor's.
    segments : int
        Number K of windows (paths), >= 2; see the module docstring.
    burn_in : float
        Record time (s) simulated before each window and discarded, >= 0;
        several decay times 2 m / c_eq of the device.
    substeps : int
        Device steps per record sample interval, >= 1 (dt = record step /
        substeps); the step check says when more are needed.
    scheme, seed, initial, record_paths, record_every, threads, progress, check_step
        As for :func:`randvib.simulate`; ``seed`` only draws the random
        start (``initial="stationary"``: the linearised spread under the
        record's Welch PSD), which the burn-in forgets.

    Returns
    -------
    SimulationResult
        One path per window (``n_paths`` = K), ``excitation`` the record,
        ``psd`` None; ``t_end`` and ``burn_in`` those of each path.
    """
    if not isinstance(record, Measured):
        raise ValueError(
            "`record` must be a randvib.Measured (rv.Measured(record) of a Record with a "
            f"base_acceleration channel), got {type(record).__name__}"
        )
    segments = check_int("segments", segments, 2)
    substeps = check_int("substeps", substeps, 1)
    burn_in = float(np.asarray(burn_in, dtype=float))
    if not (np.isfinite(burn_in) and burn_in >= 0):
        raise ValueError(f"`burn_in` must be a finite number of seconds >= 0, got {burn_in!r}")
    source = driven.RecordedInput.cut(record, segments, burn_in, substeps)
    dt = check_positive("dt", source.dt, "s")
    if isinstance(harvester, Assembly):
        return _assembly_on_record(
            harvester, record, source, segments, scheme=scheme, seed=seed, initial=initial,
            keep=(record_paths, record_every), threads=threads, progress=progress,
            check_step=check_step,
        )  # fmt: skip
    run = validated(
        harvester,
        record.spectrum,  # validated as a spectrum; the record replaces it below
        scheme,
        t_end=source.n_steps * dt,
        dt=dt,
        burn_in=source.n_burn * substeps * dt,
        n_paths=segments,
        seed=seed,
        first_path=0,
        initial=initial,
        dW=None,
        companion=False,
        record=(0, None, record_paths, record_every),
    )
    run = dataclasses.replace(run, excitation=record, input=record, psd=None, driver=source)
    result = execute(
        run,
        control_variates=False,
        check_step=check_step,
        threads=threads,
        batch_paths=None,
        progress=progress,
    )
    return RecordSimulation(**{f.name: getattr(result, f.name) for f in dataclasses.fields(result)})


# repr=False: keep SimulationResult's compact repr (a generated one would print the record's arrays)
@dataclasses.dataclass(frozen=True, repr=False)
class RecordSimulation(SimulationResult):
    """:class:`SimulationResult` of :func:`monte_carlo_on_record`: paths are successive windows."""

    @property
    def lag1_correlation(self) -> float:
        """Correlation of successive windows' mean v^2 (near 0: the interval is honest)."""
        v2 = self.averages.v2
        if v2.size < 3 or np.std(v2) == 0:
            return float("nan")
        return float(np.corrcoef(v2[:-1], v2[1:])[0, 1])


def _assembly_on_record(
    assembly, record, source, segments, *, scheme, seed, initial, keep, threads, progress,
    check_step,
) -> AssemblySimulationResult:  # fmt: skip
    """:func:`monte_carlo_on_record` of an assembly: the same windows, the assembly's kernel.

    ``keep`` is (record_paths, record_every).
    """
    dt = source.dt
    run = validated_assembly(
        assembly, record.spectrum, scheme, t_end=source.n_steps * dt, dt=dt,
        burn_in=source.n_burn * source.substeps * dt, n_paths=segments, seed=seed, first_path=0,
        initial=initial, dW=None, record=keep,
    )  # fmt: skip
    run = dataclasses.replace(run, excitation=record, psd=None, driver=source)
    return execute_assembly(
        run, control_variates=False, check_step=check_step, threads=threads, batch_paths=None,
        progress=progress,
    )  # fmt: skip
