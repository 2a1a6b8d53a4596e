"""The normalised cost of paper Eq. 11 and its batched evaluation.

    J(theta) = 100 / (N sigma_z^2) * sum_i (z_i - zhat_i(theta))^2

A model that predicts the mean scores 100 (Eq. 12), J < 5 is a good fit and
J < 1 excellent. :class:`CostFunction` scores a whole population of
parameter sets on one record in one parallel compiled call
(:mod:`randvib.identification.record_integrator`), as SaDE and the
least-squares polish need. By default the simulation starts from the first
sample (less the output offset) and a velocity estimated from the first five
samples (:func:`initial_velocity`, fourth-order one-sided difference);
LuGre's bristle state starts at zero.
"""

from __future__ import annotations

import time

import numpy as np

from randvib.identification.input_reconstruction import driving_signal, reconstruct_input
from randvib.identification.models import check_model
from randvib.identification.record_integrator import SEARCH_SUBCYCLES, parameter_matrix, run_kernel
from randvib.models.record import OUTPUT_CHANNEL, Record


def initial_velocity(z, dt):
    """Velocity at the first sample from the first five (fourth-order one-sided, m/s)."""
    return (-25 * z[0] + 48 * z[1] - 36 * z[2] + 16 * z[3] - 3 * z[4]) / (12 * dt)


def normalised_cost(z_measured, z_model):
    """J of paper Eq. 11 for one or many simulated responses (last axis: time)."""
    z_measured = np.asarray(z_measured, dtype=float)
    err = np.mean((np.asarray(z_model) - z_measured) ** 2, axis=-1)
    return 100.0 * err / np.var(z_measured)


class CostFunction:
    """Batched J(theta) (Eq. 11) of one model on one record.

    Calling it with an array ``X`` of shape (n, d), columns in the order of
    :attr:`free`, returns the n costs; every row is simulated in one
    parallel compiled call. Diverged candidates cost ``inf``.

    With ``profile_offset`` the output offset is not a column of ``X``:
    each candidate is scored with its best constant output offset (J
    minimised over it in closed form), as the search does when the offset
    is estimated. The simulation starts from ``z0`` (default: the first
    sample less the output offset, fixed or guessed as the record's mean)
    and ``v0`` (default: :func:`initial_velocity`).
    """

    def __init__(
        self,
        record: Record,
        model: str,
        *,
        fixed: dict,
        free,
        substeps: int = 4,
        hold: str = "linear",
        lowpass: float | None = None,
        skip: int = 0,
        initial_state: str = "record",
        profile_offset: bool = False,
        z0: float | None = None,
        v0: float | None = None,
    ):
        self.record = record
        self.model = model
        self.friction = check_model(model)
        self.fixed = dict(fixed)
        self.free = tuple(free)
        self.substeps = substeps
        self.hold = hold
        self.skip = skip
        self.profile_offset = bool(profile_offset)
        self.drive, self.base_input = driving_signal(
            record.input, record.dt, record.input_kind, lowpass
        )
        if skip > record.n - 2:
            raise ValueError(
                f"`skip` = {skip} leaves fewer than 2 of the {record.n} samples of record "
                f"{record.name!r} to score; use --skip <= {max(record.n - 2, 0)}"
            )
        self.fine = (
            None if hold == "zero" else reconstruct_input(self.drive, record.dt, substeps, hold)
        )
        scored = record.z[skip:]
        self.variance = float(np.var(scored))
        if self.variance == 0 or np.ptp(scored) == 0 or not np.isfinite(self.variance):
            raise ValueError(
                f"`{OUTPUT_CHANNEL}` of record {record.name!r} is constant; J (Eq. 11) is undefined"
            )
        self.n_scored = scored.size
        offset = self.fixed.get(
            "output_offset", float(np.mean(record.z)) if profile_offset else 0.0
        )
        self.z0 = float(record.z[0] - offset) if z0 is None else float(z0)
        self.v0 = float(initial_velocity(record.z, record.dt)) if v0 is None else float(v0)
        self.limit = 100.0 * float(np.max(np.abs(record.z - offset)))
        self.evaluations = 0
        self.seconds = 0.0

    def parameters(self, X) -> dict:
        X = np.atleast_2d(np.asarray(X, dtype=float))
        out = {name: X[:, j] for j, name in enumerate(self.free)}
        for name, value in self.fixed.items():
            out[name] = np.full(X.shape[0], float(value))
        return out

    def run(self, matrix, **options):
        """The compiled batch on this record's input, start and sub-steps."""
        options.setdefault("z0", self.z0)
        options.setdefault("v0", self.v0)
        return run_kernel(
            matrix,
            self.friction,
            self.drive,
            self.base_input,
            self.record.dt,
            substeps=self.substeps,
            hold=self.hold,
            response_limit=self.limit,
            fine=self.fine,
            **options,
        )

    def __call__(self, X):
        params = self.parameters(X)
        matrix = parameter_matrix(params, self.friction)
        start = time.perf_counter()
        sse = self.run(
            matrix,
            reference=self.record.z,
            skip=self.skip,
            store=False,
            max_subcycles=SEARCH_SUBCYCLES,
            profile_offset=self.profile_offset,
        ).sse
        self.seconds += time.perf_counter() - start
        self.evaluations += matrix.shape[0]
        return 100.0 * sse / (self.n_scored * self.variance)

    def simulate(self, parameters: dict, electrical=None, z0=None, v0=None):
        """Responses (z, v) of one parameter set, c raised by c_e when a circuit is given."""
        params = {k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in parameters.items()}
        if electrical is not None:
            params["c"] = params["c"] + electrical.electrical_damping
        matrix = parameter_matrix(params, self.friction)
        start = {k: v for k, v in (("z0", z0), ("v0", v0)) if v is not None}
        run = self.run(matrix, **start)
        return run.z[0], run.v[0]
