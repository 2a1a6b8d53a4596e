"""Where a study puts its points: friction levels, Coulomb grids, burn-in.

The dimensionless levels used across the studies: the friction level
phi = Fc / (c sigma_v0) (:func:`friction_level`) and the Duffing strength
mu = k3 sigma_z0^2 / k (:func:`duffing_strength`), with sigma_v0, sigma_z0 the
friction-free linear oscillator's rms velocity and displacement (paper Eq. 20).
Coloured inputs are compared with white noise at equal response
(:func:`response_matched`, :func:`matched_band`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from randvib.analytic.linear_response import mechanical_block, output_variances
from randvib.analytic.linearisation import coulomb_equivalent_damping
from randvib.models.excitation import BandPass, Excitation
from randvib.models.harvester import Harvester
from randvib.montecarlo.sweep import SweepSettings, cartesian, point_device


def fc_where_power_halves(device: Harvester, psd: float) -> float:
    """Coulomb level (N) at which Eq. 32 predicts half the friction-free power.

    Half power means c_eq = 2c; Eq. 27 then gives
    Fc = c sqrt(2 pi) / 4 * sqrt(S m / (2c)).
    """
    c, m = float(device.c), float(device.m)
    fc = c * np.sqrt(2 * np.pi) / 4 * np.sqrt(psd * m / (2 * c))
    assert np.isclose(coulomb_equivalent_damping(c, fc, psd, m), 2 * c)
    return float(fc)


def friction_level(device: Harvester, psd, fc):
    """Dimensionless Coulomb level phi = Fc / (c sigma_v0).

    sigma_v0^2 = S m / (4 c) is the friction-free velocity variance (paper
    Eq. 20). Eq. 30-32 depend on Fc only through phi: with
    kappa = phi^2 / pi, P / P(0) = 1 / (1 + kappa + sqrt(kappa (2 + kappa))),
    so Eq. 32 halves the power at phi = sqrt(pi) / 2 (about 0.886). For
    k3 = 0 the SDE itself scales exactly (z, z' and Fc all with sqrt(S)), so
    any statistic of P / P(0) depends on phi and the damping ratio only.
    """
    c, m = float(device.c), float(device.m)
    return np.asarray(fc, dtype=float) / (c * np.sqrt(np.asarray(psd, dtype=float) * m / (4 * c)))


def fc_at_friction_level(device: Harvester, psd, phi):
    """Coulomb level Fc (N) of the dimensionless level phi (inverse of :func:`friction_level`)."""
    c, m = float(device.c), float(device.m)
    return np.asarray(phi, dtype=float) * c * np.sqrt(np.asarray(psd, dtype=float) * m / (4 * c))


def power_ratio(phi):
    """Eq. 32's P / P(0) at friction level phi: 1 / (1 + kappa + sqrt(kappa (2 + kappa))),
    kappa = phi^2 / pi (Eq. 30-32 through :func:`friction_level`)."""
    kappa = np.asarray(phi, dtype=float) ** 2 / np.pi
    return 1.0 / (1.0 + kappa + np.sqrt(kappa * (2.0 + kappa)))


def damping_ratio(device: Harvester) -> float:
    """zeta = c / (2 sqrt(k m)) of the linear part (c = c_m + c_e)."""
    return float(device.c / (2.0 * np.sqrt(device.k * device.m)))


def duffing_strength(device, psd, k3):
    """mu = k3 sigma_z0^2 / k: cubic against linear spring force at the friction-free rms z.

    sigma_z0^2 = S m^2 / (4 c k) (linear oscillator, Eq. 20 with E[z^2] = E[z'^2] m / k).
    With z scaled by sqrt(S), the Duffing-Coulomb SDE depends on S and k3 only
    through phi and mu, so grid points with equal k3 S repeat one problem.
    """
    c, m, k = float(device.c), float(device.m), float(device.k)
    return np.asarray(k3, dtype=float) * np.asarray(psd, dtype=float) * m**2 / (4 * c * k**2)


def coulomb_grid(base: Harvester, psds, k3s, n_fc: int, reach: float = 2.0) -> list[dict]:
    """(psd, k3, fc) points: at each S, ``n_fc`` Coulomb levels from 0 to ``reach`` times
    the level where Eq. 32 halves the power (:func:`fc_where_power_halves`).

    ``reach = 2`` takes the friction level phi from 0 to sqrt(pi) at every S,
    well past half power. Points come S by S, then k3, then Fc (the order of
    :func:`randvib.montecarlo.sweep.cartesian`).
    """
    if n_fc < 2:
        raise ValueError(f"`n_fc` must be >= 2 (Fc = 0 and at least one level), got {n_fc}")
    points = []
    for psd in psds:
        fc_max = reach * fc_where_power_halves(base, psd)
        points += cartesian(psd=[psd], k3=list(k3s), fc=np.linspace(0.0, fc_max, n_fc))
    return points


def friction_level_points(base: Harvester, series, phis) -> list[dict]:
    """(psd, k3, c_m, c_e, fc) points: each series at the friction levels ``phis``.

    ``series`` holds (S ((m/s^2)^2/Hz), k3 (N/m^3), c_m = c_e (Ns/m)); Fc is
    set by phi = Fc / (c sigma_v0) (:func:`fc_at_friction_level`) for that
    series' device and S. Points come series by series, phi by phi.
    """
    if min(phis) <= 0:
        raise ValueError(f"`phis` must be > 0 (the error at phi = 0 is zero), got {phis}")
    return [{"psd": psd, "k3": k3, "c_m": c_each, "c_e": c_each,
             "fc": float(fc_at_friction_level(base.updated(c_m=c_each, c_e=c_each), psd, phi))}
            for psd, k3, c_each in series for phi in phis]  # fmt: skip


def point_levels(base: Harvester, points) -> pd.DataFrame:
    """The friction level phi (:func:`friction_level`) and damping ratio zeta
    (:func:`damping_ratio`) of every point's device (``base`` updated by the point)."""
    devices = [point_device(base, p) for p in points]
    return pd.DataFrame({
        "phi": [float(friction_level(d, p["psd"], p["fc"])) for d, p in zip(devices, points, strict=True)],
        "zeta": [damping_ratio(d) for d in devices],
    })  # fmt: skip


def highest_friction_points(points: list, group=("psd",)) -> list:
    """The points with the largest Fc within each group: the hardest dynamics."""
    top: dict = {}
    for p in points:
        key = tuple(p[g] for g in group)
        top[key] = max(top.get(key, -np.inf), p["fc"])
    return [p for p in points if p["fc"] == top[tuple(p[g] for g in group)]]


def hardest_at_largest_psd(points: list, series=("k3", "c_m")) -> list:
    """The strongest friction of each ``series`` at its largest S: the hardest dynamics of a
    grid whose series differ in more than S (:func:`highest_friction_points` of those)."""
    largest = {}
    for p in points:
        key = tuple(p[g] for g in series)
        largest[key] = max(largest.get(key, 0.0), p["psd"])
    hardest = [p for p in points if p["psd"] == largest[tuple(p[g] for g in series)]]
    return highest_friction_points(hardest, ("psd", *series))


def burn_in_for(devices, relaxation_times: float = 6.0, resolution: float = 0.5) -> float:
    """Burn-in (s): ``relaxation_times`` energy relaxation times m/c of the slowest device.

    Paths start from the linearised (Gaussian, Eq. 30) state, which is not
    the stationary law of a friction-affected device; the mean energy relaxes
    as exp(-c t / m), so a burn-in of a few m/c makes the start's bias in the
    time averages (and in the energy-change control) negligible. (The
    friction-free companion starts from its own stationary spread.) Rounded
    up to ``resolution``.
    """
    tau = max(float(d.m) / float(d.c) for d in devices)
    return float(np.ceil(relaxation_times * tau / resolution) * resolution)


def response_matched(shape: Excitation, device: Harvester, psd: float) -> Excitation:
    """``shape`` rescaled so that the linear device responds as to white noise of level ``psd``.

    The level makes E[z'^2] of ``device``'s linear, friction-free part
    (m, c = c_m + c_e, k; no cubic term, no friction) equal to white noise's
    S m / (4 c) (paper Eq. 20) at S = ``psd`` ((m/s^2)^2/Hz). That device then
    dissipates c E[z'^2] = S m / 4, the power white noise injects into any
    device: the coloured input delivers the same power to the reference
    device as the white one. E[z'^2] under ``shape`` is the Lyapunov solution
    of device and shaping filter.

    Parameters
    ----------
    shape : BandPass or KanaiTajimi
        The spectrum's shape, at any level.
    device : Harvester
    psd : float
        The white-noise level S to match ((m/s^2)^2/Hz).
    """
    linear = output_variances(mechanical_block(device.m, device.c, device.k), shape)["v"]
    level = shape.level * psd * device.m / (4 * device.c) / linear
    return type(shape)(level, shape.f0, shape.zeta)


def matched_band(device: Harvester, centre: float, zeta: float, psd: float) -> BandPass:
    """Band-pass noise centred at ``centre`` times ``device``'s linear natural frequency, with
    damping ratio ``zeta``, at the level of :func:`response_matched` to white noise ``psd``."""
    f_n = device.natural_frequency / (2 * np.pi)
    return response_matched(BandPass(1.0, centre * f_n, zeta), device, psd)


def fixed_paths(
    n_paths: int, window: float, *, dt: float, burn_in: float, seed: int, scheme: str = "heun",
    control_variates: bool = False,
) -> SweepSettings:  # fmt: skip
    """Settings of ensembles of exactly ``n_paths`` paths (no precision target).

    ``window`` and ``burn_in`` (s) per path, step ``dt`` (s), the run's
    ``seed``. Plain means by default: the control variates need white noise,
    and a study that compares inputs keeps one estimator for all; a
    white-noise study may ask for them (``control_variates=True``: the
    friction-free companion and the energy-balance controls).
    """
    return SweepSettings(dt=dt, window=window, burn_in=burn_in, scheme=scheme, min_paths=n_paths,
                         max_paths=n_paths, batch_paths=n_paths, seed=seed,
                         control_variates=control_variates)  # fmt: skip
