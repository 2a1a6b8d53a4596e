"""Reference solver: the stationary Fokker-Planck equation on a (z, z') grid.

The stationary density p(z, v) of the harvester's SDE (docs/conventions.md; paper
Eq. 1 and 17, noise intensity D = S/2 on the velocity) solves

    0 = -d/dz (v p) + d/dv [ (gamma v + g(z) + f(v)) p + (D/2) dp/dv ],

gamma = c/m, g(z) = (k z + k3 z^3)/m, f(v) = F(v)/m. Nothing is averaged or
closed, so the solution checks stochastic averaging (:mod:`randvib.analytic.averaging`)
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

:func:`fast_fpk_statistics` (``method="fpk-fast"``) solves the same balance in
about 3 ms: Liouville coefficients that keep the frictionless Gibbs density
exact on any grid, Euler-Maclaurin corrections for the Coulomb kink, a box
from the averaged energy exponent, the symmetric half plane as one banded LU,
and Richardson extrapolation over grids of 36 x 48, 36 x 32 and 24 x 32 cells.
It reproduces this reference to a few hundredths of a percent, the change of
power with k3 included, which stochastic averaging cannot (see its docstring).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import integrate, sparse
from scipy.linalg import lapack
from scipy.sparse import linalg as sparse_linalg

from randvib._validation import check_int, check_positive, scalar_or_array
from randvib.analytic.averaging import linear_psi_root, memoryless_parameters
from randvib.analytic.linearisation import equivalent_damping
from randvib.analytic.method import AnalyticMethod, Validity, white_level
from randvib.analytic.power_prediction import PowerPrediction
from randvib.models.friction import Coulomb, Tanh
from randvib.models.harvester import Harvester
from randvib.models.potential import CONFINING, Potential

__all__ = [
    "FPKSolution",
    "FastFokkerPlanck",
    "FokkerPlanck",
    "fast_fpk_statistics",
    "fpk_statistics",
    "solve_fpk",
]

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

    def stroke_exceedance(self, stroke: float) -> float:
        """P(|z| > stroke): the stationary probability beyond the stroke (m).

        Second order in the cell size (:func:`_tail_mass`).
        """
        stroke = float(check_positive("stroke", stroke, "m"))
        hz, hv = self.z[1] - self.z[0], self.v[1] - self.v[0]
        return _tail_mass(self.z, hz, self.density.sum(axis=1) * hz * hv, stroke)


def _tail_mass(z, hz, mass, stroke):
    """P(|z| > stroke) from the masses of equal cells centred at ``z``.

    Whole cells beyond the stroke count by their mass (midpoint rule); the
    cell the stroke cuts contributes the integral of the piecewise-linear
    interpolant of the cell densities from the stroke to its face. The error
    is then -(h^2/24) (p'(-s) - p'(s)) + O(h^3), smooth in h, so Richardson
    extrapolation applies (counting the cut cell by its share of the width
    would leave an O(h^2) error that jumps with the stroke's place in the cell).
    """
    density = mass / hz
    total = 0.0
    for sign in (1.0, -1.0):
        x = sign * z  # this side's coordinate, increasing outwards
        order = np.argsort(x)
        x, d, w = x[order], density[order], mass[order]
        lower = x - 0.5 * hz
        total += float(np.sum(w[lower >= stroke]))
        cut = np.flatnonzero((lower < stroke) & (lower + hz > stroke))
        if cut.size:
            centre, face = x[cut[0]], x[cut[0]] + 0.5 * hz
            knots = np.array([stroke, max(stroke, centre), face])
            total += float(np.trapezoid(np.interp(knots, x, d), knots))
    return max(total, 0.0)  # central fluxes may undershoot in the far tails


def _bernoulli(x):
    """B(x) = x / (e^x - 1), with B(0) = 1 and no overflow."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 1e-6
    safe = np.where(small, 1.0, x)
    out = safe / np.expm1(np.minimum(safe, 700.0))
    return np.where(small, 1.0 - 0.5 * x, out)


def _friction_potential(v, fcm, beta):
    """int_0^v f(u) du per unit mass ((m/s)^2), f = F/m of ``fcm tanh(beta v)``.

    Coulomb (``beta = inf``): fcm |v|; tanh: (fcm/beta) log cosh(beta v).
    """
    if np.isinf(beta):
        return fcm * np.abs(v)
    y = beta * np.abs(v)
    # log cosh y = y + log1p(exp(-2y)) - log 2, stable for any y >= 0
    return fcm / beta * (y + np.log1p(np.exp(-2.0 * y)) - np.log(2.0))


def _sg_weights(v, point):
    """Scharfetter-Gummel weights B(-dW), B(dW) on the faces between v cells.

    W(v) = (2/D) (gamma v^2/2 + int_0^v f) is the potential of damping,
    friction and diffusion; the flux through the face between cells j and
    j+1 is -(D/2)/h_v [B(-dW) p_{j+1} - B(dW) p_j], exact for the velocity
    relaxation at fixed z whatever the cell Peclet number.
    """
    pot = 0.5 * point.gamma * v**2 + _friction_potential(v, point.fcm, point.beta)
    dw = np.diff((2.0 / point.dd) * pot)
    return _bernoulli(-dw), _bernoulli(dw)


def _box_half_widths(point, e_edge):
    """Half-widths (Z, V) (m, m/s) of the box cut at energy ``e_edge`` per unit mass.

    ``e_edge`` counts from the bottom of the potential (for a double well,
    from the wells, not from the barrier top at z = 0). V = sqrt(2 e_edge); Z
    is the outer turning point at that energy: G(Z) - min G = e_edge, so the
    box is sized from the potential (its wells and walls), whatever its kind.
    """
    potential = Potential(point.k, point.k3)
    z_max = potential.outer_turning_point(potential.minimum + point.m * e_edge)
    return float(z_max), np.sqrt(2.0 * e_edge)


@dataclass(frozen=True)
class _Cells:
    """Cell centres and sizes of a (z, v) grid."""

    z: np.ndarray
    v: np.ndarray
    hz: float
    hv: float


@dataclass(frozen=True)
class _Point:
    """One parameter point of the balance, in the per-unit-mass form of the SDE.

    Attributes
    ----------
    m, k, k3 : float
        Mass (kg) and spring constants (N/m, N/m^3) of the well.
    gamma : float
        Viscous damping c/m (1/s).
    fcm, beta : float
        Friction level Fc/m (N/kg) and tanh sharpness (s/m); ``beta = inf``
        is Coulomb friction.
    dd : float
        Noise intensity D = S/2 on the velocity (m^2/s^3).
    """

    m: float
    k: float
    k3: float
    gamma: float
    fcm: float
    beta: float
    dd: float

    @classmethod
    def from_parameters(cls, m, c, k, k3, fc, beta, psd):
        """From the scalars of :func:`randvib.analytic.averaging.memoryless_parameters`."""
        return cls(m=m, k=k, k3=k3, gamma=c / m, fcm=fc / m, beta=beta, dd=0.5 * psd)


def _reference_cells(harvester, point, nz, nv):
    """Equal cells on the whole box, v = 0 on a face (``nv`` even).

    The box is set from the linearised velocity variance: friction only thins
    the tails of the density.
    """
    psd, m = 2.0 * point.dd, point.m
    var_v = psd * m / (4.0 * float(equivalent_damping(harvester, psd)))
    z_max, v_max = _box_half_widths(point, _ENERGY_EDGE * var_v)
    hz, hv = 2.0 * z_max / nz, 2.0 * v_max / nv
    z = -z_max + hz * (np.arange(nz) + 0.5)
    v = -v_max + hv * (np.arange(nv) + 0.5)
    return _Cells(z, v, hz, hv)


def _reference_operator(cells, point):
    """The finite-volume balance d p/dt = A p as COO triplets (rows, cols, values).

    Unknowns are ordered u = i nv + j (cell z_i, v_j); zero flux through the
    box walls.
    """
    nz, nv = len(cells.z), len(cells.v)
    hz, hv, dd = cells.hz, cells.hv, point.dd
    g = (point.k * cells.z + point.k3 * cells.z**3) / point.m
    idx = np.arange(nz * nv).reshape(nz, nv)
    rows, cols, vals = [], [], []

    def add(r, cidx, val):
        rows.append(r.ravel())
        cols.append(cidx.ravel())
        vals.append(np.broadcast_to(val, r.shape).ravel())

    # z-faces between cells i and i+1 (interior only): flux v p_face / hz out
    # of cell i into cell i+1, central face value.
    vz = np.broadcast_to(cells.v[None, :], (nz - 1, nv)) * (0.5 / hz)
    left, right = idx[:-1, :], idx[1:, :]
    for cell, sign in ((left, -1.0), (right, 1.0)):
        add(cell, left, sign * vz)
        add(cell, right, sign * vz)

    # v-faces between cells j and j+1: Scharfetter-Gummel flux in +v.
    # The spring force g(z) is constant along v, so -g p is a Liouville flux
    # like v p and gets the same central face value; damping, friction and
    # diffusion get Scharfetter-Gummel fitting on their potential.
    b_minus, b_plus = _sg_weights(cells.v, point)
    coef = 0.5 * dd / hv / hv
    gv = np.broadcast_to(g[:, None], (nz, nv - 1)) * (0.5 / hv)
    to_lower = coef * b_minus + gv  # multiplies p_{j+1}
    to_upper = coef * b_plus - gv  # multiplies p_j
    lower, upper = idx[:, :-1], idx[:, 1:]
    # d p_lower/dt gets -J/hv, d p_upper/dt gets +J/hv.
    add(lower, upper, to_lower)
    add(lower, lower, -to_upper)
    add(upper, upper, -to_lower)
    add(upper, lower, to_upper)
    return tuple(np.concatenate(a) for a in (rows, cols, vals))


def _normalised_null_vector(rows, cols, vals, size, cell_area):
    """The density p with A p = 0 and unit mass, by one sparse LU solve.

    The balance equations sum to zero (mass conservation), so one is
    redundant: the one of the box corner (row 0) is replaced by the
    normalisation sum(p) cell_area = 1.
    """
    keep = rows != 0
    rows = np.concatenate((rows[keep], np.zeros(size, dtype=rows.dtype)))
    cols = np.concatenate((cols[keep], np.arange(size)))
    vals = np.concatenate((vals[keep], np.full(size, cell_area)))
    matrix = sparse.csc_matrix((vals, (rows, cols)), shape=(size, size))
    rhs = np.zeros(size)
    rhs[0] = 1.0
    return sparse_linalg.spsolve(matrix, rhs)


def _reference_solution(cells, p, friction) -> FPKSolution:
    """Moments of the cell density p (shape (nz, nv)) as an :class:`FPKSolution`."""
    z, v, hz, hv = cells.z, cells.v, cells.hz, cells.hv
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


def solve_fpk(harvester: Harvester, psd: float, n: int = 200, *, nz=None, nv=None):
    """Solve the stationary FPK equation on a grid of ``nz`` x ``nv`` cells.

    Parameters
    ----------
    harvester : Harvester
        Device with scalar parameters, Coulomb, tanh or no friction and a
        confining potential (monostable, bistable, pure cubic; the box is
        sized from the potential's outer turning point).
    psd : float
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0, or a
        :class:`~randvib.models.excitation.White` excitation; white noise is
        assumed, any other excitation is refused with a ValueError (paper Eq. 17).
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
    harvester.potential.require(
        "solve_fpk", CONFINING, "fpk_statistics, which takes the free mass's exact velocity density"
    )
    arrays = memoryless_parameters(harvester, psd, FOKKER_PLANCK)
    if arrays[0].ndim:
        raise ValueError("solve_fpk needs scalar harvester parameters and a scalar `psd`")
    point = _Point.from_parameters(*(float(a) for a in arrays))
    nz = check_int("nz", n if nz is None else nz, 8)
    nv = check_int("nv", n if nv is None else nv, 8)
    nv += nv % 2
    cells = _reference_cells(harvester, point, nz, nv)
    rows, cols, vals = _reference_operator(cells, point)
    p = _normalised_null_vector(rows, cols, vals, nz * nv, cells.hz * cells.hv)
    return _reference_solution(cells, p.reshape(nz, nv), harvester.friction)


def fpk_statistics(harvester: Harvester, psd, n: int = 160):
    """E[z'^2], E[z^2], E|z'| from the FPK solution, Richardson-extrapolated.

    Solves on n x n and n/2 x n/2 grids and combines the moments as
    (4 a_n - a_{n/2}) / 3, which removes the O(h^2) error the convergence
    study measures. Broadcasts over ``psd`` and array-valued harvester
    parameters by looping (about 0.3 s per point at n = 160).

    Parameters
    ----------
    harvester : Harvester
        Device with Coulomb, tanh or no friction and a confining potential
        (monostable, bistable, pure cubic) or the free mass (k = k3 = 0),
        whose velocity density is solved exactly (:func:`free_mass_moments`;
        E[z^2] is then nan: not stationary).
    psd : array_like
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0, or a
        :class:`~randvib.models.excitation.White` excitation; white noise is
        assumed, any other excitation is refused with a ValueError.
    n : int
        Finest grid, cells per direction (>= 16).

    Returns
    -------
    velocity_variance, displacement_variance, mean_abs_velocity : float or ndarray
    """
    return fpk_moments(harvester, psd, n)[:3]


def fpk_moments(harvester: Harvester, psd, n: int = 160):
    """:func:`fpk_statistics` and P(|z| > harvester.stroke) (nan without a stroke).

    The exceedance is Richardson-extrapolated like the moments (the share of
    the cell cut by the stroke keeps it second order).
    """
    n = check_int("n", n, 16)
    FOKKER_PLANCK.require(harvester, psd, FOKKER_PLANCK.title)
    psd = check_positive("psd", white_level(psd), "(m/s^2)^2/Hz")
    friction = harvester.friction
    own = {name: getattr(harvester, name) for name in ("m", "c_m", "c_e", "k", "k3")}
    fric = {} if friction is None else friction.parameters()
    names = list(own) + list(fric) + ["psd"]
    arrays = np.broadcast_arrays(
        *(np.asarray(x, dtype=float) for x in [*own.values(), *fric.values(), psd])
    )
    out = np.empty((4,) + arrays[0].shape)
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
        if device.potential.is_free:
            out[(slice(None),) + index] = free_mass_moments(device, s)
            continue
        too_deep = _too_deep_for_fpk(device, s)
        if too_deep is not None:
            raise FOKKER_PLANCK.beyond_validity(harvester, psd, too_deep)
        fine, coarse = solve_fpk(device, s, n), solve_fpk(device, s, n // 2)
        for row, name in enumerate(
            ("velocity_variance", "displacement_variance", "mean_abs_velocity")
        ):
            a_f, a_c = getattr(fine, name), getattr(coarse, name)
            out[(row,) + index] = (4.0 * a_f - a_c) / 3.0
        out[(3,) + index] = np.nan
        if harvester.stroke is not None:
            a_f, a_c = (x.stroke_exceedance(harvester.stroke) for x in (fine, coarse))
            out[(3,) + index] = (4.0 * a_f - a_c) / 3.0
    return tuple(scalar_or_array(o) for o in out)


def free_mass_moments(harvester: Harvester, psd) -> np.ndarray:
    """(E[v^2], nan, E|v|, nan) of the free mass (k = k3 = 0), from its exact density.

    The velocity decouples: dv = -(gamma v + f(v)) dt + sqrt(D) dW, whose
    stationary FPK equation is solved by p(v) ∝ exp(-(2/D) (gamma v^2/2 +
    int_0^v f)) (Caughey and Dienes for Coulomb friction; tanh by the same
    potential). The moments are integrals of it by adaptive quadrature. The
    displacement diffuses without bound, so E[z^2] and P(|z| > stroke) are
    not stationary: nan.
    """
    arrays = memoryless_parameters(harvester, psd, FOKKER_PLANCK)
    return _free_mass_point(_Point.from_parameters(*(float(np.ravel(a)[0]) for a in arrays)))


def _free_mass_point(point) -> np.ndarray:
    """:func:`free_mass_moments` at one parameter point."""
    b = 2.0 / point.dd

    def weight(v):
        return np.exp(
            -b * (0.5 * point.gamma * v * v + _friction_potential(v, point.fcm, point.beta))
        )

    # v_hi: where the Coulomb exponent reaches _PSI_END_FREE, plus tanh's
    # largest shortfall below Coulomb, fcm log(2)/beta.
    reach = _PSI_END_FREE / b + point.fcm * np.log(2.0) / point.beta
    g, f = point.gamma, point.fcm
    v_hi = 2.0 * reach / (f + np.sqrt(f * f + 2.0 * g * reach))
    moments = [
        integrate.quad(lambda v, q=q: v**q * weight(v), 0.0, v_hi, epsabs=0, epsrel=1e-12)[0]
        for q in (0, 1, 2)
    ]
    return np.array([moments[2] / moments[0], np.nan, moments[1] / moments[0], np.nan])


#: Exponent at the end of the free mass's velocity integrals (density exp(-60) of its peak).
_PSI_END_FREE = 60.0


# ---------------------------------------------------------------------------
# Fast solver: the same balance on a small grid, made exact where it matters.

#: z cells of the fast solver's two main grids (whole box; the symmetric half
#: is solved), and of the coarse grid that extrapolates E[z^2] in z.
FAST_NZ = (36, 24)
#: v cells (whole box) of the two main grids, Richardson-combined in v.
FAST_NV = (48, 32)
#: Box edge of the fast solver: where the linear-spring averaged exponent
#: Psi(H) (randvib.analytic.averaging) reaches this value, i.e. the energy density is
#: down to about exp(-13) of its peak.
FAST_PSI_EDGE = 13.0
#: Mass fraction in the outermost ring of cells above which the box is judged
#: too small (tanh friction, extreme parameters) and enlarged. With the
#: Coulomb estimate of the box it is 2e-6 to 3e-5 (slightly negative where the
#: central fluxes undershoot in the tails).
_FAST_EDGE_MASS = 2e-4


def _box_energy(gamma, fcm, dd, psi_edge):
    """Energy per unit mass (J/kg) where the averaged exponent reaches ``psi_edge``.

    The linear-spring Psi of :func:`randvib.analytic.averaging.linear_psi_root`;
    for the Duffing spring it stays within 10 % of the true one.
    """
    x = linear_psi_root(gamma, fcm, dd, psi_edge)
    return x * x


def _half_moments(point, e_edge, nz, nv, stroke=None):
    """Solve the symmetric half problem on one grid; E[v^2], E[z^2], E|v|, P(|z| > stroke), edge mass.

    Unknowns are the cells with v > 0, ordered v-row by v-row (u = j nz + i);
    the cells with v < 0 follow from p(z, v) = p(-z, -v), which couples the
    first row to itself mirrored in z across the face v = 0. The band of the
    matrix is nz wide, so LAPACK's banded LU (gbsv, partial pivoting) solves
    it in O(nz^3 nv) operations.
    """
    z_max, v_max = _box_half_widths(point, e_edge)
    nh = nv // 2
    hz, hv = 2.0 * z_max / nz, v_max / nh
    cells = _Cells(-z_max + hz * (np.arange(nz) + 0.5), hv * (np.arange(nh) + 0.5), hz, hv)
    zg = -z_max + hz * (np.arange(-1, nz + 1) + 0.5)  # with one ghost cell each side
    pot = (0.5 * point.k * zg**2 + 0.25 * point.k3 * zg**4) / point.m  # G(z) = U(z)/m
    v_lv, g_lv = _gibbs_exact_liouville(cells, pot, point)
    # The pinned cell: the centre, or for a double well the cell at the right
    # well (the centre's density is exp(-barrier/T) smaller there).
    pin = nz // 2 if point.k >= 0 else int(np.argmin(pot[1 + nz // 2 : -1])) + nz // 2
    ab = _half_band_matrix(cells, v_lv, g_lv, point, pin)
    rhs = np.zeros(nz * nh)
    rhs[pin] = 1.0
    _, _, p, info = lapack.dgbsv(nz, nz, ab, rhs, overwrite_ab=1, overwrite_b=1)
    if info != 0:  # pragma: no cover - the pinned matrix is regular
        raise RuntimeError(f"banded LU failed (info = {info})")
    return _half_moments_of_density(cells, p.reshape(nh, nz), point, stroke)


def _gibbs_exact_liouville(cells, pot, point):
    """Liouville coefficients v~ (per v cell) and g~ (per z cell) of the fast solver.

    ``pot`` is G(z) = U(z)/m at the z cells with one ghost cell each side.
    They make the Gibbs density exp(-b H), b = 2 gamma/D, an exact discrete
    null vector: central differences of exp(-b v^2/2) and exp(-b G) divided
    by -b times the function (-> v and G' as h -> 0).
    """
    v, hz, hv = cells.v, cells.hz, cells.hv
    b = 2.0 * point.gamma / point.dd
    if b > 0:
        v_lv = np.exp(-0.5 * b * hv * hv) * np.sinh(b * v * hv) / (b * hv)
        g_lv = -np.expm1(-b * (pot[2:] - pot[1:-1])) + np.expm1(-b * (pot[:-2] - pot[1:-1]))
        g_lv /= 2.0 * hz * b
    else:
        v_lv = v
        g_lv = (pot[2:] - pot[:-2]) / (2.0 * hz)
    return v_lv, g_lv


def _half_band_matrix(cells, v_lv, g_lv, point, pin):
    """The half-plane balance in LAPACK band storage (kl = ku = nz), one row pinned.

    A[r, c] is stored at ab[kl + ku + r - c, c]. Scharfetter-Gummel in v
    (v > 0 branch), central Liouville fluxes with the coefficients v~, g~;
    one balance equation is redundant (mass conservation), so the cell
    ``pin`` of the first row is pinned to 1 instead and the moments normalise.
    """
    nz, nh = len(cells.z), len(cells.v)
    hz, hv = cells.hz, cells.hv
    b_minus, b_plus = _sg_weights(cells.v, point)
    coef = 0.5 * point.dd / hv**2
    gv = (g_lv / (2.0 * hv))[None, :]
    to_lower = coef * b_minus[:, None] + gv  # (nh-1, nz): face j+1/2, multiplies p[j+1]
    to_upper = coef * b_plus[:, None] - gv  # multiplies p[j]
    vz = (v_lv / (2.0 * hz))[:, None]

    ab = np.zeros((3 * nz + 1, nz * nh))
    d = 2 * nz
    diag = np.zeros((nh, nz))
    diag[:, 0] -= vz[:, 0]  # wall z = -Z: only the face on the right
    diag[:, -1] += vz[:, 0]
    diag[:-1] -= to_upper
    diag[1:] -= to_lower
    diag[0] -= coef + gv[0]  # face v = 0, own side
    ab[d] = diag.ravel()
    sup = np.zeros((nh, nz))  # A[u, u+1] stored at column u+1
    sup[:, 1:] = -vz
    ab[d - 1] = sup.ravel()
    sub = np.zeros((nh, nz))  # A[u+1, u] stored at column u
    sub[:, :-1] = vz
    ab[d + 1] = sub.ravel()
    ab[nz, nz:] = to_lower.ravel()  # A[u, u+nz] at column u+nz
    ab[3 * nz, :-nz] = to_upper.ravel()  # A[u+nz, u] at column u
    i = np.arange(nz)
    mirror = nz - 1 - i  # face v = 0, mirrored side: A[(i,0), (nz-1-i,0)]
    ab[d + i - mirror, mirror] += coef - gv[0]
    cols = np.arange(max(0, pin - nz), pin + nz + 1)
    ab[d + pin - cols, cols] = 0.0
    ab[d, pin] = 1.0
    return ab


def _half_moments_of_density(cells, p, point, stroke=None):
    """E[v^2], E[z^2], E|v|, P(|z| > stroke) of the half-plane values p (nh, nz); ring mass.

    The exceedance is :func:`_tail_mass` of the z marginal, kink terms
    included (nan without a stroke).

    The Coulomb jump of f at v = 0 puts a kink in p there, dp/dv(0+) -
    dp/dv(0-) = -(4 f_c/D) p(z, 0), and |v| has one too; the midpoint sums
    then need their Euler-Maclaurin end terms, (h^2/24) (jump of the
    derivative), to stay second order. p(z, 0) is the mean of the two cells
    beside the face, times exp(jump h/4) for the kink. Tanh friction: the
    jump is scaled by tanh(beta h/2) (Coulomb for beta h >> 1, none when the
    layer is resolved).
    """
    z, v, hz, hv = cells.z, cells.v, cells.hz, cells.hv
    fcm, beta, dd = point.fcm, point.beta, point.dd
    jump = 4.0 * fcm / dd * (1.0 if np.isinf(beta) else np.tanh(0.5 * beta * hv))
    # Summed over i, p[0] is the sum of the face means (mirror pairs).
    at_zero = p[0] * np.exp(0.25 * jump * hv)
    cell = hz * hv
    end = 0.5 * hz * hv * hv / 24.0  # half the face (symmetric half domain)
    mass = cell * p.sum() + end * jump * at_zero.sum()
    vv = cell * np.sum(p * (v * v)[:, None]) / mass
    abs_v = (cell * np.sum(p * v[:, None]) - 2.0 * end * at_zero.sum()) / mass
    zz = (cell * np.sum(p * (z * z)[None, :]) + end * jump * np.sum(z * z * at_zero)) / mass
    beyond = np.nan
    if stroke is not None:
        marginal = (cell * p.sum(axis=0) + end * jump * at_zero) / mass
        beyond = _gibbs_weighted_tail(z, hz, marginal, stroke, point)
    ring = (p[-1].sum() + p[:-1, 0].sum() + p[:-1, -1].sum()) * cell / mass
    return np.array([vv, zz, abs_v, beyond]), ring


def _gibbs_weighted_tail(z, hz, marginal, stroke, point):
    """P(|z| > stroke) from a coarse z marginal, as Gibbs density times a smooth ratio.

    The marginal is g(z) r(z) with g = exp(-(2 gamma/D)(G(z) - min G)) the
    friction-free (Gibbs) shape, known exactly, and r a ratio that is
    constant without friction (the fast solver is exact there) and smooth
    with it. r is interpolated linearly between the cell centres (constant
    beyond the outer ones) and g r integrated on a fine grid, so the tail
    keeps the potential's exact decay where a sum over coarse cells would
    not. Measured against the reference :func:`fpk_moments` (n = 200;
    bistable with barrier T and 4 T, pure cubic; Fc = 0.005 and 0.02 N;
    tests/test_potentials.py checks the first two ranges):
    within 0.3 % for P >= 0.1; 0.2-1.5 % for P in 3e-3 .. 0.07 (10 % at
    Fc = 0.02 N, barrier T, P = 6e-3); tens of percent or worse below 1e-3
    with friction, where r's flat extrapolation beyond the fast box (density
    exp(-13) of its peak) misses friction's thinning of the tails. Without
    friction within 1e-5 down to P ~ 1e-2 and 4e-4 at P = 5e-4. For small
    probabilities use the reference ``method="fpk"``. Without viscous
    damping there is no Gibbs shape: :func:`_tail_mass` of the cells.
    """
    b = 2.0 * point.gamma / point.dd
    if b == 0:
        return _tail_mass(z, hz, marginal, stroke)
    potential = Potential(point.k, point.k3)
    low = potential.minimum

    def shape(x):
        return np.exp(-b * (potential.energy(x) - low) / point.m)

    # Central fluxes undershoot slightly in the far tails: no negative ratio.
    ratio = np.maximum(marginal / hz / shape(z), 0.0)

    def integral(lo, hi):  # of g r over lo < |z| < hi, on a fine grid
        x = np.linspace(lo, hi, 4001)
        return np.trapezoid(shape(x) * (np.interp(x, z, ratio) + np.interp(-x, z, ratio)), x)

    # Out to where g is exp(-60) of its peak.
    z_far = float(potential.outer_turning_point(low + 60.0 * point.m / b))
    if stroke >= z_far:
        return 0.0
    return float(integral(stroke, z_far) / integral(0.0, z_far))


def fast_fpk_statistics(harvester: Harvester, psd, *, nz=FAST_NZ, nv=FAST_NV):
    """E[z'^2], E[z^2], E|z'| from small, corrected FPK grids (about 3 ms a point).

    The balance of :func:`solve_fpk`, made accurate on grids of a few hundred
    cells per half plane:

    * Liouville coefficients v~ and g~ chosen so that the frictionless Gibbs
      density exp(-2 gamma H/D) is an exact discrete solution for every k3
      and grid (v~ = exp(-b h^2/2) sinh(b v h)/(b h), g~ the analogous
      difference of exp(-b G(z)), b = 2 gamma/D; both -> v and g(z) as
      h -> 0). Without friction the method is then exact up to the box
      truncation (a few 1e-5), and its error scales with the friction.
    * Euler-Maclaurin end corrections for the Coulomb kink of p at v = 0
      (and for |v|), so that the moments are second order.
    * Box from the averaged energy exponent (edge at Psi = 13) rather than
      the linearised variance, which is far too small a scale at high
      friction; enlarged if more than 2e-4 of the mass sits in its outer
      ring of cells.
    * Only the half plane v > 0 is solved (p(z, v) = p(-z, -v)), ordered so
      that the band is nz wide: one banded LU of nz nv/2 unknowns per grid.
    * Richardson extrapolation: in v from grids (nz[0], nv[0]) and
      (nz[0], nv[1]) for all moments (the v error dominates E[z'^2] and E|z'|
      and is O(h_v^2)); in z for E[z^2] only, from (nz[0], nv[1]) and
      (nz[1], nv[1]). The z error of E[z'^2] is far below its v error from
      nz = 32 on, but is not yet O(h_z^2) on a 24-cell grid, so it is left.

    Measured against :func:`fpk_statistics` (tests/test_fokker_planck.py and
    the study ``linearisation-vs-averaging``): E[z'^2] within 0.05 % for
    friction levels kappa = 4 Fc^2/(pi S m c) up to 3, viscous damping
    ratios 0.09-0.22 and k3 S up to 5e8 N/m^3 (m/s^2)^2/Hz, within 0.25 % at
    the light damping ratio 0.02 (the z grid limits it there); E|z'| alike,
    E[z^2] within 0.3 % (1.3 % at 0.02); the change of E[z'^2] with k3 at
    fixed Fc within 0.01 % (absolute) on the study grid. Tanh friction: the
    kink terms are exact for beta h_v >> 1 (Coulomb) and vanish for
    beta h_v << 1; in between they are an interpolation (E[z'^2] within
    0.06 % of the reference for beta = 3 to 4.8e8 s/m, Fc = 0.03 N, S = 0.5).

    Why a grid and not a corrected averaging: averaging's error is first
    order in the energy lost per cycle, which k3 lowers by raising the
    orbit frequency, so its k3 dependence is as large as the k3 effect
    itself (0.04-0.17 % on the study grid). The next-order correction needs
    boundary layers at the Coulomb turning points and would still leave an
    O(zeta^2) remainder of that size at zeta_eff ~ 0.1-0.5. A hybrid that
    takes the k3 change from a ratio exact without friction has the same
    problem: the friction part is what changes with k3. A discretisation has
    an error that can be driven below the effect and measured.

    Parameters
    ----------
    harvester : Harvester
        Device with Coulomb, tanh or no friction; parameters may be arrays
        broadcasting with ``psd``.
    psd : array_like
        One-sided base-acceleration PSD S ((m/s^2)^2/Hz), > 0, or a
        :class:`~randvib.models.excitation.White` excitation; white noise is
        assumed, any other excitation is refused with a ValueError.
    nz, nv : int or pair of int
        Cells over the whole box in z and in v (even, >= 8; a pair lists the
        finer grid first). A single count switches off the extrapolation in
        that direction.

    Returns
    -------
    velocity_variance, displacement_variance, mean_abs_velocity : float or ndarray
    """
    return fast_fpk_moments(harvester, psd, nz=nz, nv=nv)[:3]


def fast_fpk_moments(harvester: Harvester, psd, *, nz=FAST_NZ, nv=FAST_NV):
    """:func:`fast_fpk_statistics` and P(|z| > harvester.stroke) (nan without a stroke).

    The free mass (k = k3 = 0) takes its exact velocity density
    (:func:`free_mass_moments`); its E[z^2] and exceedance are nan.
    """
    nzs, nvs = _grid_pair("nz", nz), _grid_pair("nv", nv)
    arrays = memoryless_parameters(harvester, psd, FAST_FOKKER_PLANCK)
    shape = arrays[0].shape
    out = np.empty((4,) + shape)
    for index in np.ndindex(shape):
        point = _Point.from_parameters(*(float(a[index]) for a in arrays))
        if point.k == 0 and point.k3 == 0:
            moments = _free_mass_point(point)
        else:
            too_deep = _too_deep_with_friction(point)
            if too_deep is not None:
                raise FAST_FOKKER_PLANCK.beyond_validity(harvester, psd, too_deep)
            moments = _fast_point(point, nzs, nvs, harvester.stroke)
        out[(slice(None),) + index] = moments
    return tuple(scalar_or_array(o) for o in out)


#: Deepest double well with friction that fpk-fast treats: the barrier k^2 /
#: (4 k3) over the noise's energy scale m E[v^2] with friction, E[v^2] = S m /
#: (4 c_eq) and c_eq of equivalent linearisation (Eq. 19-20, 30), which friction
#: raises: its corrections are built for one well. Measured by the cross-check
#: campaign (tests/calibration/crosscheck.py, 85 double wells with Coulomb or
#: tanh friction against Monte Carlo, re-run on 120 more): every one up to a
#: depth of 2.13 was within 3.7 %; the first failure lay at 2.29 (1.19x, with
#: friction taking 93 % of the dissipation), and beyond 2.7 21 of 44 were off
#: by more than 10 % + the Monte Carlo interval (0.29x to 65x); the viscous
#: scale S m / (4 c) that this limit once used missed the devices whose
#: friction takes most of the dissipation (4.8x at a viscous depth of 5.7).
FAST_MAX_BARRIER = 2.0


def friction_barrier_depth(m, c, k, k3, friction, s) -> float:
    """A double well's barrier k^2 / (4 k3) over m E[v^2], E[v^2] = S m / (4 c_eq) (1).

    c_eq is equivalent linearisation's (Eq. 19-20, 30): friction lowers the
    noise's energy, so the same wells are deeper for it. 0 for a single well.
    """
    if not (k < 0 < k3):
        return 0.0
    device = Harvester(m=m, c_m=c, c_e=0.0, k=k, k3=k3, friction=friction)
    c_eq = float(equivalent_damping(device, s))
    return (k**2 / (4.0 * k3)) / (m * s * m / (4.0 * c_eq))


def _too_deep_with_friction(point) -> str | None:
    """Why fpk-fast refuses a double well with friction deeper than :data:`FAST_MAX_BARRIER`, or None."""
    if not (point.k < 0 < point.k3 and point.fcm > 0 and point.gamma > 0):
        return None
    fc = point.fcm * point.m
    friction = Coulomb(fc) if np.isinf(point.beta) else Tanh(fc, point.beta)
    depth = friction_barrier_depth(
        point.m, point.gamma * point.m, point.k, point.k3, friction, 2.0 * point.dd
    )
    if depth <= FAST_MAX_BARRIER:
        return None
    return (
        f"treats double wells with friction up to a barrier of {FAST_MAX_BARRIER:g} m E[v^2] "
        f"(E[v^2] of equivalent linearisation); this one is {depth:.3g} m E[v^2] deep (its "
        "one-well corrections fail there)"
    )


#: Deepest double well (barrier over the noise's energy scale m E[v^2], E[v^2]
#: = S m / (4 c) of the viscous device) that fpk resolves: its fixed grids
#: cannot follow the density into deep wells. Without friction, where the
#: power is exact, its error is 1.5e-4 at a barrier of 32, 7.8e-4 at 48,
#: 4.8e-3 at 64 and -65 % to +41 % at 75 to 750 (S = 0.02 to 0.002 on the
#: viscous device with k = -57.4 N/m, k3 = 5e5 N/m^3); with Coulomb friction
#: +360 % against Monte Carlo at 255.
FPK_MAX_BARRIER = 32.0

#: Deepest double well with friction that fpk resolves, on its viscous scale
#: (as :data:`FPK_MAX_BARRIER`): friction concentrates the density in the wells
#: beyond what its grids, sized on that scale, follow. Measured by the
#: cross-check campaign (tests/calibration/crosscheck.py, 85 double wells with
#: Coulomb or tanh friction against Monte Carlo): every one up to a depth of
#: 10 within 8 %; the six off by more than 10 % + the Monte Carlo interval
#: (0.15x to 1.41x) lay at depths of 10.6 to 31.7, where 16 others were within
#: it (the friction's own scale, :func:`friction_barrier_depth`, did not
#: separate them: 60 failed, 2740 passed).
FPK_MAX_FRICTION_BARRIER = 10.0


def _too_deep_for_fpk(device: Harvester, s: float) -> str | None:
    """Why fpk refuses a double well deeper than its limits, or None.

    The barrier over the viscous device's m E[v^2] = m S m / (4 c): at most
    :data:`FPK_MAX_BARRIER`, and with friction :data:`FPK_MAX_FRICTION_BARRIER`.
    """
    k, k3, c = device.k, device.k3, device.c_m + device.c_e
    if not (k < 0 < k3 and c > 0):
        return None
    depth = (k**2 / (4.0 * k3)) / (device.m * s * device.m / (4.0 * c))
    law = device.friction
    limit = FPK_MAX_BARRIER if law is None or law.vanishes else FPK_MAX_FRICTION_BARRIER
    if depth <= limit:
        return None
    return (
        f"resolves double wells up to a barrier of {limit:g} m E[v^2]"
        f"{'' if limit == FPK_MAX_BARRIER else ' with friction'}; this one is "
        f"{depth:.3g} m E[v^2] deep (its grids cannot follow the density into the wells)"
    )


def _grid_pair(name, value):
    counts = (value,) if np.ndim(value) == 0 else tuple(value)
    if not 1 <= len(counts) <= 2:
        raise ValueError(f"`{name}` must be one or two cell counts, got {value!r}")
    counts = tuple(check_int(name, x, 8) for x in counts)
    if any(x % 2 for x in counts):
        raise ValueError(f"`{name}` must be even cell counts, got {value!r}")
    if len(counts) == 2 and not counts[0] > counts[1]:
        raise ValueError(f"`{name}` must list the finer grid first, got {value!r}")
    return counts


def _fast_point(point, nzs, nvs, stroke=None):
    """E[v^2], E[z^2], E|v|, P(|z| > stroke) at one point: box, grids, extrapolation."""
    gamma, fcm, beta, dd = point.gamma, point.fcm, point.beta, point.dd
    fcm_box = fcm
    if not np.isinf(beta) and fcm > 0:
        # tanh friction is weaker than Coulomb at low speed: take its level at
        # an eighth of the Coulomb box's top speed (the outer-ring check below
        # catches what this misses).
        v_top = np.sqrt(2.0 * _box_energy(gamma, fcm, dd, FAST_PSI_EDGE))
        fcm_box = fcm * np.tanh(beta * v_top / 8.0)
    e_edge = _box_energy(gamma, fcm_box, dd, FAST_PSI_EDGE)
    for _ in range(12):
        best, ring = _half_moments(point, e_edge, nzs[0], nvs[0], stroke)
        if ring <= _FAST_EDGE_MASS:
            break
        e_edge *= 1.5
    if len(nvs) == 2:
        coarse_v, _ = _half_moments(point, e_edge, nzs[0], nvs[1], stroke)
        best = best + (best - coarse_v) / ((nvs[0] / nvs[1]) ** 2 - 1.0)
    if len(nzs) == 2:
        if len(nvs) == 1:
            coarse_v = best
        coarse_z, _ = _half_moments(point, e_edge, nzs[1], nvs[-1], stroke)
        # E[z^2] and the exceedance are the z marginal's: extrapolated in z too.
        zs = [1, 3]
        best[zs] += (coarse_v[zs] - coarse_z[zs]) / ((nzs[0] / nzs[1]) ** 2 - 1.0)
    return best


class FastFokkerPlanck(AnalyticMethod):
    """The stationary FPK equation on small corrected grids (:func:`fast_fpk_statistics`).

    The power and its k3 dependence to about 0.05 % of :class:`FokkerPlanck`
    in about 3 ms a point: fast enough for sweeps. Any confining potential and
    the free mass; double wells with friction up to a barrier of
    :data:`FAST_MAX_BARRIER` m E[v^2], E[v^2] of equivalent linearisation
    (:func:`friction_barrier_depth`; refused beyond).
    """

    name = "fpk-fast"
    title = "the FPK solver"
    summary = "corrected small-grid FPK solution, resolves the k3 effect, 3 ms"
    friction_form = "fc-tanh"
    stroke_exceedance = True
    validity = (
        Validity(
            "barrier_depth",
            FAST_MAX_BARRIER,
            "refuses",
            "a double well's barrier k^2 / (4 k3) over the noise's energy m E[v^2] (E[v^2] "
            "of equivalent linearisation, which friction lowers), with friction: its one-well "
            "corrections fail beyond (off by 0.29x to 65x in the cross-check campaign)",
        ),
    )

    def solve(self, harvester: Harvester, psd) -> PowerPrediction:
        vv, zz, av, beyond = fast_fpk_moments(harvester, psd)
        return PowerPrediction.from_white_noise(harvester, self.name, vv, zz, av, psd, beyond)


class FokkerPlanck(AnalyticMethod):
    """The stationary FPK equation on fine grids, Richardson-extrapolated (:func:`fpk_statistics`).

    The reference the other methods are measured against (converged to about
    1e-5), about 0.5 s a point. Any confining potential and the free mass;
    double wells up to a barrier of :data:`FPK_MAX_BARRIER` m E[v^2], with
    friction :data:`FPK_MAX_FRICTION_BARRIER` (the viscous device's E[v^2];
    refused beyond).
    """

    name = "fpk"
    title = "the FPK solver"
    summary = "fine-grid FPK solution, slow reference"
    friction_form = "fc-tanh"
    stroke_exceedance = True
    reference = True
    validity = (
        Validity(
            "barrier_depth",
            FPK_MAX_BARRIER,
            "refuses",
            "a double well's barrier k^2 / (4 k3) over the noise's energy m E[v^2]: its "
            "grids cannot follow the density into deeper wells",
        ),
        Validity(
            "barrier_depth_with_friction",
            FPK_MAX_FRICTION_BARRIER,
            "refuses",
            "with friction, the same barrier depth: friction concentrates the density in the "
            "wells beyond what the grids follow (off by 0.15x to 1.41x in the cross-check "
            "campaign beyond)",
        ),
    )

    def solve(self, harvester: Harvester, psd) -> PowerPrediction:
        vv, zz, av, beyond = fpk_moments(harvester, psd)
        return PowerPrediction.from_white_noise(harvester, self.name, vv, zz, av, psd, beyond)


#: The methods' declarations, which the functions of this module check their input against
#: (:data:`randvib.analytic.prediction.METHODS` holds them).
FAST_FOKKER_PLANCK = FastFokkerPlanck()
FOKKER_PLANCK = FokkerPlanck()
