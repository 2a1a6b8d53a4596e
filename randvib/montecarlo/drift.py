"""The device's drift, shared by the compiled step functions.

Its own module so that the resistive steps (:mod:`randvib.montecarlo.kernel`)
and the bridge's steps (:mod:`randvib.montecarlo.rectified_kernel`) inline
the same definition without importing each other.
"""

from __future__ import annotations

import numba

from randvib.models.friction import evaluate_friction


@numba.njit(cache=True, inline="always")
def _acceleration(z, v, theta, drift, kind, p, fn):
    """(acceleration (m/s^2), friction state's rate, friction force (N)) of the device.

    ``drift = (1/m, c, k, k3)``: paper Eq. 15-17 without the noise,
    ``-(c v + k z + k3 z^3 + F) / m``; ``kind, p, fn`` the friction law
    (:class:`randvib.montecarlo.kernel.Friction`).
    """
    inv_m, c, k, k3 = drift
    force, rate = evaluate_friction(kind, fn, p, v, theta)
    return -(c * v + k * z + k3 * z * z * z + force) * inv_m, rate, force
