"""The deterministic response of the device to a record's input (paper Eq. 1).

:func:`simulate_record` integrates Eq. 1 driven by a recorded input for one
device or a whole batch of parameter sets at once (the compiled integrator of
:mod:`randvib.identification.record_integrator`, on the input reconstructed by
:mod:`randvib.identification.input_reconstruction`). A candidate whose
response leaves a sanity bound (``response_limit``) or becomes non-finite is
stopped and gets NaN samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from randvib._validation import check_finite, check_int, check_positive
from randvib.identification.input_reconstruction import HOLDS, driving_signal
from randvib.identification.record_integrator import parameter_matrix, run_kernel
from randvib.models.harvester import Harvester


@dataclass(frozen=True, eq=False)
class BatchSimulation:
    """Responses of a population of parameter sets to one recorded input.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times (s).
    z, v : ndarray, shape (n_pop, n)
        Relative displacement (m) and velocity (m/s) at the samples; NaN after
        a candidate diverged.
    """

    time: np.ndarray
    z: np.ndarray
    v: np.ndarray


def device_parameters(device, friction=None) -> tuple[dict, str]:
    """Named record-simulation parameters and friction name of a device.

    The record simulator and identification work with the total viscous
    damping ``c = c_m + c_e`` (Eq. 1): a record cannot separate the two.

    Parameters
    ----------
    device : Harvester or dict
        A :class:`~randvib.models.harvester.Harvester` (a preset included); the dict
        of its :meth:`~randvib.models.harvester.Harvester.parameters` (``c_m``,
        ``c_e``, ``friction`` and the friction and circuit parameters); or
        ``m, c, k, k3`` and the friction parameters, with ``friction``
        naming the law.
    friction : str, optional
        Friction law name; required for the last form, checked against the
        device's own law for the others.

    Returns
    -------
    parameters : dict
        ``m`` (kg), ``c`` (Ns/m), ``k`` (N/m), ``k3`` (N/m^3) and the law's
        parameters.
    friction : str
    """
    if isinstance(device, Harvester):
        params = {"m": device.m, "c": device.c, "k": device.k, "k3": device.k3}
        if device.friction is not None:
            params.update(device.friction.parameters())
        own = device.friction_name
    elif isinstance(device, dict) and ("c_m" in device or "friction" in device):
        # Harvester.parameters(): total damping; the circuit's alpha, r_load,
        # r_coil only explain c_e, which is already in it.
        params = {k: v for k, v in device.items() if k not in _HARVESTER_ONLY}
        params["c"] = np.asarray(device.get("c_m", 0.0)) + np.asarray(device.get("c_e", 0.0))
        own = device.get("friction", "none")
    else:
        if friction is None:
            raise ValueError(
                "`friction` is required with a parameter dict (m, c, k, k3, ...); "
                "or pass a randvib.Harvester"
            )
        return dict(device), friction
    if friction is not None and friction != own:
        raise ValueError(f"`friction` = {friction!r} disagrees with the device's {own!r}")
    return params, own


#: Harvester.parameters() keys that the record simulator does not take.
_HARVESTER_ONLY = ("c_m", "c_e", "friction", "alpha", "r_load", "r_coil")


def simulate_record(
    parameters,
    friction=None,
    input_values=None,
    dt: float | None = None,
    *,
    input_kind: str = "base_acceleration",
    substeps: int = 4,
    hold: str = "linear",
    lowpass: float | None = None,
    z0=0.0,
    v0=0.0,
    theta0=0.0,
    response_limit: float = np.inf,
) -> BatchSimulation:
    """Simulate Eq. 1 driven by a recorded input, for many parameter sets at once.

    Called as ``simulate_record(harvester, input_values, dt, ...)`` with a
    :class:`~randvib.models.harvester.Harvester` (a preset included) or its
    ``parameters()`` dict, or as ``simulate_record(parameters, friction,
    input_values, dt, ...)`` with a dict of named parameters.

    Parameters
    ----------
    parameters : Harvester or dict
        A device (simulated with c = c_m + c_e), or ``m`` (kg), ``c`` (Ns/m),
        ``k`` (N/m), ``k3`` (N/m^3) and the friction parameters (``fc`` N;
        ``beta`` s/m; ``sigma0`` N/m, ``sigma1`` Ns/m, ``fs`` N, ``vs`` m/s;
        see :data:`~randvib.identification.record_integrator.FRICTION_PARAMETERS`); scalars or 1-D arrays (one row per
        candidate).
    friction : str, optional
        Friction law name: ``none`` or a registered law (paper Eq. 4-10:
        ``coulomb``, ``tanh``, ``lugre``); only with a parameter dict.
    input_values : array_like, shape (n,)
        Input samples on the uniform grid ``i dt``: base displacement (m),
        base acceleration (m/s^2) or force on the mass (N).
    dt : float
        Sample interval (s).
    input_kind : {'base_displacement', 'base_acceleration', 'force'}
    substeps : int, optional
        Integration steps per sample interval (default 4).
    hold : {'linear', 'zero', 'cubic', 'bandlimited'}
        Reconstruction of the input between samples
        (:func:`~randvib.identification.input_reconstruction.reconstruct_input`).
    lowpass : float, optional
        Zero-phase low-pass cut-off (Hz) for the driving signal.
    z0, v0, theta0 : float or array_like
        Initial displacement (m), velocity (m/s), LuGre bristle state (m).
    response_limit : float, optional
        |z| above which a candidate counts as diverged (m).

    Returns
    -------
    BatchSimulation
    """
    if not (friction is None or isinstance(friction, str | type)):
        # simulate_record(device, input_values, dt): the device names its law.
        friction, input_values, dt = None, friction, input_values
    parameters, friction = device_parameters(parameters, friction)
    values, dt, substeps = _check_record_input(input_values, dt, substeps, hold)
    matrix = parameter_matrix(parameters, friction)
    drive, base_input = driving_signal(values, dt, input_kind, lowpass)
    _, z, v = run_kernel(
        matrix,
        friction,
        drive,
        base_input,
        dt,
        substeps=substeps,
        hold=hold,
        z0=z0,
        v0=v0,
        theta0=theta0,
        response_limit=response_limit,
    )
    return BatchSimulation(time=np.arange(values.shape[0]) * dt, z=z, v=v)


def _check_record_input(input_values, dt, substeps, hold):
    """(values, dt, substeps) of :func:`simulate_record`, checked."""
    if input_values is None or dt is None:
        raise ValueError("`input_values` and `dt` are required")
    dt = float(check_positive("dt", dt, "s"))
    substeps = check_int("substeps", substeps, minimum=1)
    if hold not in HOLDS:
        raise ValueError(f"`hold` must be one of {', '.join(HOLDS)}; got {hold!r}")
    values = check_finite("input_values", input_values)
    if values.ndim != 1 or values.shape[0] < 2:
        raise ValueError(
            f"`input_values` must be 1-D with at least 2 samples, got shape {values.shape}"
        )
    return values, dt, substeps
