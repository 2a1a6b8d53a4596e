"""Reference solver: the stationary Fokker-Planck equation on a (z, z') grid.

The stationary density p(z, v) of the harvester's SDE (CONVENTIONS; paper
Eq. 1 and 17, noise intensity D = S/2 on the velocity) solves

    0 = -d/dz (v p) + d/dv [ (gamma v + g(z) + f(v)) p + (D/2) dp/dv ],

gamma = c/m, g(z) = (k z + k3 z^3)/m, f(v) = F(v)/m. Nothing is averaged or
closed, so the solution checks stochastic averaging (:mod:`randvib.averaging`)
and equivalent linearisation without Monte Carlo noise.

Discretisation (finite volumes, zero-flux box):

* cells of equal size on [-Z, Z] x [-V, V], with v = 0 on a cell face so that
  the Coulomb jump of f(v) never falls inside a cell;
* z-flux v p with the central (second-order) face value: the Liouville part
  is then skew-symmetric and adds no numerical dissipation;
* v-flux by Scharfetter-Gummel exponential fitting on the potential
  W(v) = (2/D) (gamma v^2/2 + g(z) v + int_0^v f): exact for the fast
  velocity relaxation at fixed z and robust at cell Peclet numbers > 1;
* the null vector of the sparse matrix, normalised to unit mass, by one
  sparse LU solve with one balance equation replaced by the normalisation.

Central fluxes do not guarantee positivity: the density undershoots by
about 1e-8 of its peak in the far tails, which no moment notices.

The scheme is second order in the cell size (the Coulomb kink sits on a
face and does not spoil it); the
convergence test (tests/test_fokker_planck.py) measures the order against the
exact Gibbs density of the frictionless oscillator. Domain size is set from
the frictionless Gibbs density, whose tails bound the frictional ones: the
box is cut where the energy reaches 30 times the linearised velocity
variance (density below exp(-30) times its peak).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse import linalg as sparse_linalg

from randvib._validation import check_int, check_positive
from randvib.friction import Coulomb, Tanh
from randvib.harvester import Harvester
from randvib.linearisation import equivalent_damping

__all__ = ["FPKSolution", "fpk_statistics", "solve_fpk"]

#: Energy (in units of the linearised velocity variance) at the box edge.
_ENERGY_EDGE = 30.0


@dataclass(frozen=True)
class FPKSolution:
    """Stationary density on the grid and its moments (SI units).

    Attributes
    ----------
    z, v : ndarray
        Cell centres (m, m/s).
    density : ndarray
        p(z, v) at the cells, shape (len(z), len(v)) (1/(m m/s)); sums to 1
        times the cell area.
    velocity_variance, mean_abs_velocity, displacement_variance : float
        E[z'^2] ((m/s)^2), E|z'| (m/s), E[z^2] (m^2).
    friction_power : float
        E[z' F(z')] (W).
    """

    z: np.ndarray
    v: np.ndarray
    density: np.ndarray
    velocity_variance: float
    mean_abs_velocity: float
    displacement_variance: float
    friction_power: float


def _bernoulli(x):
    """B(x) = x / (e^x - 1), with B(0) = 1 and no overflow."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 1e-6
    safe = np.where(small, 1.0, x)
    out = safe / np.expm1(np.minimum(safe, 700.0))
    return np.where(small, 1.0 - 0.5 * x, out)


def _friction_potential(v, friction, m):
    """int_0^v f(u) du (J/kg^1 per (m/s)): Coulomb f_c |v|; tanh (f_c/beta) log cosh."""
    if friction is None:
        return np.zeros_like(v)
    fcm = friction.fc / m
    if isinstance(friction, Coulomb):
        return fcm * np.abs(v)
    y = friction.beta * np.abs(v)
    # log cosh y = y + log1p(exp(-2y)) - log 2, stable for any y >= 0
    return fcm / friction.beta * (y + np.log1p(np.exp(-2.0 * y)) - np.log(2.0))


def solve_fpk(harvester: Harvester, psd: float, n: int = 200, *, nz=None, nv=None):
    """Solve the stationary FPK equation on a grid of ``nz`` x ``nv`` cells.

    Parameters
    ----------
    harvester : Harvester
        Device with scalar parameters and Coulomb, tanh or no friction.
    psd : float
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0 (paper Eq. 17).
    n : int
        Cells per direction (>= 8) unless ``nz``/``nv`` are given. The cost is
        one sparse LU of n^2 unknowns: about 0.1 s at n = 100, 2 s at 300.
    nz, nv : int, optional
        Cells in z and v; ``nv`` is rounded up to an even number so that
        v = 0 is a cell face.

    Returns
    -------
    FPKSolution
    """
    friction = harvester.friction
    if friction is not None and not isinstance(friction, Coulomb | Tanh):
        raise ValueError(
            f"the FPK solver needs a memoryless friction law (coulomb, tanh or none); "
            f"{friction.name!r} has internal state (the density would need a third "
            "dimension). Use randvib.simulate for it."
        )
    values = [harvester.m, harvester.c, harvester.k, harvester.k3]
    if friction is not None:
        values += [getattr(friction, f) for f in ("fc", "beta") if hasattr(friction, f)]
    if any(np.ndim(v) for v in values) or np.ndim(psd):
        raise ValueError("solve_fpk needs scalar harvester parameters and a scalar `psd`")
    psd = float(check_positive("psd", psd, "(m/s^2)^2/Hz"))
    nz = check_int("nz", n if nz is None else nz, 8)
    nv = check_int("nv", n if nv is None else nv, 8)
    nv += nv % 2
    m, c, k, k3 = (float(x) for x in (harvester.m, harvester.c, harvester.k, harvester.k3))
    fc = 0.0 if friction is None else float(friction.fc)
    if c <= 0 and fc <= 0:
        raise ValueError("`c_m + c_e` and `fc` are both 0: no stationary state")

    dd = 0.5 * psd
    # Box from the linearised velocity variance: friction only thins the tails.
    var_v = psd * m / (4.0 * float(equivalent_damping(harvester, psd)))
    e_edge = _ENERGY_EDGE * var_v
    v_max = np.sqrt(2.0 * e_edge)
    # Largest z with (k z^2/2 + k3 z^4/4)/m = e_edge, without cancellation.
    z_max = np.sqrt(4.0 * m * e_edge / k / (1.0 + np.sqrt(1.0 + 4.0 * k3 * m * e_edge / k**2)))
    hz, hv = 2.0 * z_max / nz, 2.0 * v_max / nv
    z = -z_max + hz * (np.arange(nz) + 0.5)
    v = -v_max + hv * (np.arange(nv) + 0.5)
    gamma = c / m
    g = (k * z + k3 * z**3) / m

    idx = np.arange(nz * nv).reshape(nz, nv)
    rows, cols, vals = [], [], []

    def add(r, cidx, val):
        rows.append(r.ravel())
        cols.append(cidx.ravel())
        vals.append(np.broadcast_to(val, r.shape).ravel())

    # z-faces between cells i and i+1 (interior only): flux v p_face / hz out
    # of cell i into cell i+1, central face value.
    vz = np.broadcast_to(v[None, :], (nz - 1, nv)) * (0.5 / hz)
    left, right = idx[:-1, :], idx[1:, :]
    for cell, sign in ((left, -1.0), (right, 1.0)):
        add(cell, left, sign * vz)
        add(cell, right, sign * vz)

    # v-faces between cells j and j+1: Scharfetter-Gummel flux in +v,
    # J = -(D/2)/hv [B(-dW) p_{j+1} - B(dW) p_j].
    # The spring force g(z) is constant along v, so -g p is a Liouville flux
    # like v p and gets the same central face value; damping, friction and
    # diffusion get Scharfetter-Gummel fitting on their potential.
    potential = (2.0 / dd) * (0.5 * gamma * v**2 + _friction_potential(v, friction, m))
    dw = np.broadcast_to(np.diff(potential), (nz, nv - 1))
    coef = 0.5 * dd / hv / hv
    gv = np.broadcast_to(g[:, None], (nz, nv - 1)) * (0.5 / hv)
    to_lower = coef * _bernoulli(-dw) + gv  # multiplies p_{j+1}
    to_upper = coef * _bernoulli(dw) - gv  # multiplies p_j
    lower, upper = idx[:, :-1], idx[:, 1:]
    # d p_lower/dt gets -J/hv, d p_upper/dt gets +J/hv.
    add(lower, upper, to_lower)
    add(lower, lower, -to_upper)
    add(upper, upper, -to_lower)
    add(upper, lower, to_upper)

    size = nz * nv
    rows, cols, vals = (np.concatenate(a) for a in (rows, cols, vals))
    # The balance equations sum to zero (mass conservation), so one is
    # redundant: replace the one of the box corner by the normalisation.
    keep = rows != 0
    rows = np.concatenate((rows[keep], np.zeros(size, dtype=rows.dtype)))
    cols = np.concatenate((cols[keep], np.arange(size)))
    vals = np.concatenate((vals[keep], np.full(size, hz * hv)))
    matrix = sparse.csc_matrix((vals, (rows, cols)), shape=(size, size))
    rhs = np.zeros(size)
    rhs[0] = 1.0
    p = sparse_linalg.spsolve(matrix, rhs).reshape(nz, nv)

    cell = hz * hv
    pv = p.sum(axis=0) * cell
    pz = p.sum(axis=1) * cell
    # Cell averages of v^2 and z^2 (midpoint + h^2/12) keep the moments second order.
    vel_var = float(np.sum(pv * (v**2 + hv**2 / 12.0)))
    abs_v = float(np.sum(pv * np.abs(v)))
    disp_var = float(np.sum(pz * (z**2 + hz**2 / 12.0)))
    fpow = 0.0 if friction is None else float(np.sum(pv * v * friction.force(v)))
    return FPKSolution(
        z=z,
        v=v,
        density=p,
        velocity_variance=vel_var,
        mean_abs_velocity=abs_v,
        displacement_variance=disp_var,
        friction_power=fpow,
    )


def fpk_statistics(harvester: Harvester, psd, n: int = 160):
    """E[z'^2], E[z^2], E|z'| from the FPK solution, Richardson-extrapolated.

    Solves on n x n and n/2 x n/2 grids and combines the moments as
    (4 a_n - a_{n/2}) / 3, which removes the O(h^2) error the convergence
    study measures. Broadcasts over ``psd`` and array-valued harvester
    parameters by looping (about 0.3 s per point at n = 160).

    Parameters
    ----------
    harvester : Harvester
        Device with Coulomb, tanh or no friction.
    psd : array_like
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0.
    n : int
        Finest grid, cells per direction (>= 16).

    Returns
    -------
    velocity_variance, displacement_variance, mean_abs_velocity : float or ndarray
    """
    n = check_int("n", n, 16)
    psd = check_positive("psd", psd, "(m/s^2)^2/Hz")
    friction = harvester.friction
    own = {name: getattr(harvester, name) for name in ("m", "c_m", "c_e", "k", "k3")}
    fric = {} if friction is None else friction.parameters()
    names = list(own) + list(fric) + ["psd"]
    arrays = np.broadcast_arrays(
        *(np.asarray(x, dtype=float) for x in [*own.values(), *fric.values(), psd])
    )
    out = np.empty((3,) + arrays[0].shape)
    for index in np.ndindex(arrays[0].shape):
        point = dict(zip(names, (float(a[index]) for a in arrays), strict=True))
        s = point.pop("psd")
        device = Harvester(
            m=point.pop("m"),
            c_m=point.pop("c_m"),
            c_e=point.pop("c_e"),
            k=point.pop("k"),
            k3=point.pop("k3"),
            friction=None if friction is None else type(friction)(**point),
        )
        fine, coarse = solve_fpk(device, s, n), solve_fpk(device, s, n // 2)
        for row, name in enumerate(
            ("velocity_variance", "displacement_variance", "mean_abs_velocity")
        ):
            a_f, a_c = getattr(fine, name), getattr(coarse, name)
            out[(row,) + index] = (4.0 * a_f - a_c) / 3.0
    return tuple(float(o) if o.ndim == 0 else o for o in out)
