"""Stationary response of a linear(ised) device to any excitation spectrum.

The device is a :class:`~randvib.models.state_space.StateSpace` block whose
input is the base acceleration a = y'' and whose outputs are the response
quantities (``z``, ``v``; a coil's current or a piezo's voltage are more
states and outputs of a bigger block). Two independent routes give the
stationary output variances (docs/conventions.md, "Beyond the paper"):

* **Lyapunov** (rational spectra): the block driven by the excitation's
  shaping filter is one augmented linear system ``X' = A X + B w`` with
  E[w(t1) w(t2)] = (S/2) delta(t2 - t1); its stationary covariance solves
  ``A P + P A^T + (S/2) B B^T = 0`` and the outputs' covariance is
  ``C P C^T``.
* **Spectral integral** (any spectrum): ``E[y^2] = int_0^inf |H_y(f)|^2
  S(f) df`` by composite Gauss-Legendre quadrature on panels that resolve
  the block's resonances (from the eigenvalues of ``A``), the spectrum's
  peaks and kinks (:meth:`Excitation.features`, :meth:`Excitation.breakpoints`),
  with the tail beyond the last feature mapped onto a finite interval.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy import linalg

from randvib._validation import check_choice
from randvib.models.excitation import Excitation, ShapingFilter
from randvib.models.state_space import StateSpace

_GEES, _TRSYL = linalg.get_lapack_funcs(("gees", "trsyl"), dtype=np.float64)
#: gees's optimal work size by matrix size (its workspace query, as scipy's schur makes).
_GEES_LWORK: dict = {}

#: How :func:`output_variances` computes the variances: the values of ``method``.
VARIANCE_METHODS = ("auto", "lyapunov", "spectral")

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(20)
# Panels around a peak of half-width w reach w * 2^j from its centre, j from
# _PEAK_POWERS; the global geometric grid has _GRID_POINTS edges (a fixed count,
# so that the rule moves continuously with the device's parameters).
_PEAK_POWERS = np.arange(-3.0, 40.0)
_GRID_POINTS = 160
_TAIL_FACTOR = 20.0  # the tail starts at this multiple of the highest feature
_TAIL_PANELS = 8


def _tail_rule():
    """Nodes u in (0, 1] and weights of the tail's panels, before the map f = f_c / u."""
    u_edges = np.linspace(0.0, 1.0, _TAIL_PANELS + 1)
    u_half = 0.5 * np.diff(u_edges)
    u = ((u_edges[:-1] + u_half)[:, None] + u_half[:, None] * _NODES).ravel()
    return u, (u_half[:, None] * _WEIGHTS).ravel()


# What frequency_rule makes the same for every block and spectrum: computed once
# (the same operations on the same constants, so the same bits as at every call).
_PEAK_OFFSETS = 2.0**_PEAK_POWERS
_TAIL_NODES, _TAIL_WEIGHTS = _tail_rule()


@dataclass(frozen=True, eq=False)
class ResponseSpectra:
    """One-sided PSDs of the linearised response (SI units, f in Hz).

    Attributes
    ----------
    frequency : ndarray
        f (Hz).
    excitation : ndarray
        S(f) of the base acceleration ((m/s^2)^2/Hz).
    displacement, velocity : ndarray
        PSD of z (m^2/Hz) and of v ((m/s)^2/Hz).
    power : ndarray
        Frequency distribution of the electrical power c_e |H_v|^2 S (W/Hz):
        its integral is E[P_e].
    lines : dict or None
        Under tones, their lines: ``frequency`` (Hz) and the mean squares of
        each tone's response, ``displacement`` (m^2), ``velocity`` ((m/s)^2)
        and ``power`` (W), arrays over the tones; the spectra above are then
        the random part's. None without tones.
    """

    frequency: np.ndarray
    excitation: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    power: np.ndarray
    lines: dict | None = None

    def to_frame(self):
        """The spectra as a :class:`pandas.DataFrame`, one row per frequency (lines apart)."""
        import pandas as pd

        names = ("frequency", "excitation", "displacement", "velocity", "power")
        return pd.DataFrame({name: getattr(self, name) for name in names})


def mechanical_block(m, c, k) -> StateSpace:
    """The linear device ``m z'' + c z' + k z = -m a`` (paper Eq. 18) as a block.

    Parameters
    ----------
    m : float
        Mass (kg).
    c : float
        Viscous damping (Ns/m); the equivalent damping c_eq when linearised.
    k : float
        Stiffness (N/m); the equivalent stiffness k_eq when linearised.

    Returns
    -------
    StateSpace
        States and outputs ``z`` (m) and ``v`` (m/s); input the base
        acceleration (m/s^2).
    """
    a = [[0.0, 1.0], [-k / m, -c / m]]
    return StateSpace(a, [0.0, -1.0], np.eye(2), [0.0, 0.0], ("z", "v"))


def device_block(m, c, k, coupling=None) -> StateSpace:
    """The linear device with its circuit state, when the coupling has one.

    ``m z'' + c z' + k z + f x = -m a`` and ``x' = a_x x + b_x z'``
    (:meth:`randvib.models.coupling.Coupling.circuit_equation`: a coil's
    current, L i' + (R_L + R_C) i = alpha z', force alpha i; a piezo's voltage,
    C_p V' + V / R_L = theta z', force theta V). Without a circuit state (no
    coupling, or a static one whose c_e is in ``c``) it is
    :func:`mechanical_block`.

    Parameters
    ----------
    m, c, k : float
        Mass (kg), viscous damping (Ns/m; c_eq when linearised, holding c_e for
        a static coupling) and stiffness (N/m; k_eq when linearised).
    coupling : Coupling or None
        The electrical coupling.

    Returns
    -------
    StateSpace
        States and outputs ``z``, ``v`` and, with a circuit state,
        ``coupling.state_name`` (``current`` in A or ``voltage`` in V); input
        the base acceleration (m/s^2).
    """
    if coupling is None or not coupling.is_dynamic:
        return mechanical_block(m, c, k)
    a_x, b_x, f = (float(x) for x in coupling.circuit_equation())
    a = [[0.0, 1.0, 0.0], [-k / m, -c / m, -f / m], [0.0, b_x, a_x]]
    outputs = ("z", "v", coupling.state_name)
    return StateSpace(a, [0.0, -1.0, 0.0], np.eye(3), np.zeros(3), outputs)


def _require_stable(system: StateSpace) -> np.ndarray:
    """The eigenvalues of ``system.a`` (1/s), refused when one has a real part >= 0."""
    eig = np.linalg.eigvals(system.a)
    if (eig.real >= 0).any():  # the method, not np.any: its dispatch cost more than the test
        raise ValueError(
            "the linear(ised) system has an eigenvalue with non-negative real part "
            f"({eig[np.argmax(eig.real)]:.6g} 1/s): it has no stationary response"
        )
    return eig


def stationary_covariance(block: StateSpace, shaping: ShapingFilter) -> np.ndarray:
    """Covariance of the block's outputs driven through a shaping filter (Lyapunov).

    Parameters
    ----------
    block : StateSpace
        The device, input the base acceleration.
    shaping : ShapingFilter
        The excitation's filter of white noise w, E[w w] = (S/2) delta.

    Returns
    -------
    ndarray, shape (p, p)
        E[y y^T] of the block's outputs (their units squared).
    """
    system = block.driven_by(shaping.system, "acceleration")
    if (system.d != 0).any():
        raise ValueError(
            "white noise reaches an output directly: its variance is infinite "
            f"(outputs {', '.join(system.outputs)})"
        )
    _require_stable(system)
    q = shaping.noise_intensity * np.outer(system.b, system.b)
    p = solve_lyapunov(system.a, -q)
    return system.c @ p @ system.c.T


def solve_lyapunov(a: np.ndarray, q: np.ndarray) -> np.ndarray:
    """X with ``A X + X A^T = Q`` (real A, Q): :func:`scipy.linalg.solve_continuous_lyapunov`.

    The same LAPACK calls with the same arguments (the real Schur form by ``gees``,
    then ``trsyl``), so the same X to the last bit, without the wrapper's argument
    handling, which cost twice the solve for the few states of a device: statistical
    linearisation solves one per iteration, a design's search thousands.
    """
    if not (np.isfinite(a).all() and np.isfinite(q).all()):
        raise ValueError("array must not contain infs or NaNs")  # scipy's check_finite
    n = a.shape[0]
    if n not in _GEES_LWORK:
        _GEES_LWORK[n] = int(_GEES(lambda x, y: None, a, lwork=-1)[-2][0])
    r, _, _, _, u, _, info = _GEES(lambda x, y: None, a, lwork=_GEES_LWORK[n])
    if info > 0:
        raise np.linalg.LinAlgError("Schur form not found. Possibly ill-conditioned.")
    y, scale, info = _TRSYL(r, r, u.T @ (q @ u), tranb="T")
    if info == 1:
        warnings.warn(
            'Input "a" has an eigenvalue pair whose sum is very close to or exactly zero. '
            "The solution is obtained via perturbing the coefficients.",
            RuntimeWarning,
            stacklevel=3,
        )
    y *= scale
    return u @ y @ u.T


def _features(block: StateSpace, excitation: Excitation, eig=None):
    """(centre, half-width) pairs (Hz): the block's modes and the spectrum's peaks.

    ``eig``: the eigenvalues of ``block.a`` where the caller has them already.
    """
    if eig is None:
        eig = np.linalg.eigvals(block.a) if block.n_states else np.zeros(0)
    modes = [(abs(e.imag) / (2 * np.pi), abs(e.real) / (2 * np.pi)) for e in eig if e.imag >= 0]
    return [(fc, w) for fc, w in modes + list(excitation.features()) if w > 0]


def frequency_rule(block: StateSpace, excitation: Excitation, eig=None):
    """Nodes and weights for int_0^inf g(f) df with g = |H|^2 S (composite Gauss-Legendre).

    ``eig``, optional: the eigenvalues of ``block.a`` (1/s), as
    :func:`numpy.linalg.eigvals` gives them, where the caller has computed them.

    Returns
    -------
    nodes, weights : ndarray
        ``sum(weights * g(nodes))`` approximates the integral over the
        spectrum's support; the part above a finite cut-off is mapped by
        f = f_c / u onto u in (0, 1], where |H|^2 S is smooth.
    """
    lo, hi = excitation.support
    features = _features(block, excitation, eig)
    kinks = [b for b in excitation.breakpoints() if lo <= b <= hi]
    scales = [fc + w for fc, w in features] + [b for b in kinks if b > 0]
    if not scales:
        raise ValueError("the block has no mode and the spectrum no feature to integrate over")
    top = min(hi, _TAIL_FACTOR * max(scales))
    small = 1e-3 * min([w for _, w in features] + [b for b in kinks if b > 0])
    # a band edge at a subnormal frequency (f_lo = 5e-324 Hz) would make the grid
    # start at 0; below 1e-12 of the top, one panel holds a negligible, bounded integrand
    small = max(small, 1e-12 * top)
    # the edges in arrays, not a list of numpy scalars (the same values in the same
    # order; building the list cost most of the rule)
    edges = [np.array([lo, top, *kinks], dtype=float), np.geomspace(small, top, _GRID_POINTS)]
    for fc, w in features:
        offsets = w * _PEAK_OFFSETS
        edges += [np.array([fc], dtype=float), fc + offsets, fc - offsets[offsets < fc]]
    edges = np.unique(np.clip(np.concatenate(edges), lo, top))
    half = 0.5 * np.diff(edges)
    nodes = (edges[:-1] + half)[:, None] + half[:, None] * _NODES
    weights = half[:, None] * _WEIGHTS
    nodes, weights = [nodes.ravel()], [weights.ravel()]
    if np.isinf(hi):
        nodes.append(top / _TAIL_NODES)
        weights.append(_TAIL_WEIGHTS * top / _TAIL_NODES**2)
    return np.concatenate(nodes), np.concatenate(weights)


def spectral_variances(block: StateSpace, excitation: Excitation) -> np.ndarray:
    """E[y^2] = int_0^inf |H_y(f)|^2 S(f) df for each output y of the block.

    Accurate to about 1e-9 relative or better for the device's resonance and the
    built-in spectra (checked against the Lyapunov solution in the tests).
    """
    # the stability check's eigenvalues place the rule's panels too (the same call on
    # the same matrix: computed once)
    eig = _require_stable(block)
    nodes, weights = frequency_rule(block, excitation, eig)
    h = block.frequency_response(nodes)
    return np.sum(np.abs(h) ** 2 * excitation.psd(nodes) * weights, axis=-1)


def lyapunov_shaping(excitation: Excitation, method: str):
    """The shaping filter whose Lyapunov equation gives the variances, or None (spectral).

    ``method`` is one of :data:`VARIANCE_METHODS`: ``auto`` takes the Lyapunov
    route where the spectrum is rational, ``spectral`` never, ``lyapunov``
    always (refused, naming the excitation, for a spectrum with no shaping filter).
    """
    shaping = excitation.shaping_filter()
    if method == "lyapunov" and shaping is None:
        raise ValueError(
            f"`method`='lyapunov' needs a rational spectrum (a shaping filter); the "
            f"{excitation.name} spectrum has none: use 'spectral'"
        )
    return None if method == "spectral" else shaping


def output_variances(block: StateSpace, excitation: Excitation, method: str = "auto") -> dict:
    """Stationary variances of the block's outputs under an excitation.

    Parameters
    ----------
    block : StateSpace
        The linear(ised) device, input the base acceleration.
    excitation : Excitation
        Any excitation.
    method : {"auto", "lyapunov", "spectral"}
        ``lyapunov`` needs a rational spectrum (a shaping filter);
        ``spectral`` works for any; ``auto`` takes the Lyapunov solution
        where it exists.

    Returns
    -------
    dict
        Output name -> variance (the output's units squared).
    """
    check_choice("method", method, VARIANCE_METHODS)
    return variances_through(block, excitation, lyapunov_shaping(excitation, method))


def variances_through(block: StateSpace, excitation: Excitation, shaping) -> dict:
    """:func:`output_variances` with the route chosen: Lyapunov through ``shaping``, or
    the spectral integral where it is None (:func:`lyapunov_shaping` chooses it).

    For a caller that solves many blocks under one excitation (a linearisation's
    fixed point): the excitation's filter is built once, not at every solve.
    """
    if shaping is not None:
        values = np.diag(stationary_covariance(block, shaping))
    else:
        values = spectral_variances(block, excitation)
    return dict(zip(block.outputs, map(float, values), strict=True))


def response_spectra(block: StateSpace, excitation: Excitation, frequency) -> dict:
    """One-sided PSD |H_y(f)|^2 S(f) of each output y at ``frequency`` (Hz).

    Returns
    -------
    dict
        Output name -> PSD array (the output's units squared per Hz).
    """
    f = np.asarray(frequency, dtype=float)
    h = block.frequency_response(f)
    s = excitation.psd(f)
    return {name: np.abs(h[i]) ** 2 * s for i, name in enumerate(block.outputs)}
