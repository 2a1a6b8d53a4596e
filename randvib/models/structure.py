"""The linear structure of an assembly: mass, damping and stiffness matrices, three ways.

An assembly's structure is ``M x'' + C x' + K x = -M r a`` in coordinates x
relative to the base (docs/conventions.md, "Assemblies"). It may be given

* as **matrices** (:func:`structure_matrices`): M a list (its diagonal) or a
  symmetric positive-definite matrix (kg), C symmetric positive semi-definite
  (Ns/m), K symmetric (N/m), r the influence vector (default all ones);
* as a **chain** of lumped masses (:func:`chain_matrices`): mass i joined to
  mass i - 1 by spring ``stiffness[i]`` and dashpot ``damping[i]``, mass 0 to
  the base;
* as **modes** of a host (:func:`modal_matrices`): natural frequencies f_n
  (Hz), damping ratios zeta_n, modal masses m_n (kg), participation factors
  gamma_n = L_n / m_n (dimensionless, L_n = phi_n^T M_host r_host) and the
  mode shapes at the attachment points, Phi[p, n] = phi_n(p). The DOFs are
  the attachment points' displacements w = Phi q, so Phi must be square and
  invertible (as many points as modes; add a point where the modes differ if
  fewer are used). From ``m_n q_n'' + 2 zeta_n m_n omega_n q_n' + m_n
  omega_n^2 q_n = -L_n a + phi_n^T F``:

      M = Phi^-T diag(m_n) Phi^-1,  C = Phi^-T diag(2 zeta_n m_n omega_n) Phi^-1,
      K = Phi^-T diag(m_n omega_n^2) Phi^-1,  r = Phi gamma.

  Extra lumped ``masses`` (the harvesters' magnets) are appended as DOFs with
  no structural spring or damper of their own (their elements join them to
  the points) and influence 1.

Every check names the argument, the offending entry and what is allowed.
"""

from __future__ import annotations

import numpy as np

from randvib._validation import as_float_array

#: Relative tolerance of the symmetry checks (of the largest entry).
SYMMETRY_TOLERANCE = 1e-10


def _finite_array(name: str, value, unit: str) -> np.ndarray:
    if isinstance(value, str):
        raise ValueError(f"`{name}` must be numbers ({unit}), got {value!r}")
    try:
        arr = as_float_array(name, value)
    except ValueError:
        raise ValueError(
            f"`{name}` must be a list of numbers or a matrix (rows of equal length) in {unit}, "
            f"got {value!r}"
        ) from None
    if arr.dtype == object:  # pragma: no cover - numpy refuses ragged lists above
        raise ValueError(f"`{name}` must have rows of equal length, got {value!r}")
    bad = ~np.isfinite(arr)
    if np.any(bad):
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ValueError(
            f"`{name}` must be finite ({unit}); entry {where} is {float(arr[bad][0])!r}"
        )
    return arr


def square_matrix(name: str, value, unit: str, n: int | None = None, diagonal: bool = False):
    """A finite square matrix (a list is its diagonal when ``diagonal``); its size n if given."""
    arr = _finite_array(name, value, unit)
    if arr.ndim == 1 and diagonal:
        arr = np.diag(arr)
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1] or arr.shape[0] == 0:
        shape = "a list (its diagonal) or a square matrix" if diagonal else "a square matrix"
        raise ValueError(f"`{name}` must be {shape} ({unit}), got shape {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ValueError(
            f"`{name}` is {arr.shape[0]} x {arr.shape[0]} but `mass` is {n} x {n}: one row and "
            "column per DOF"
        )
    return arr


def check_symmetric(name: str, matrix: np.ndarray, unit: str) -> None:
    """Refuse a non-symmetric matrix, naming the first pair of entries that differ."""
    scale = np.max(np.abs(matrix)) if matrix.size else 0.0
    gap = np.abs(matrix - matrix.T) > SYMMETRY_TOLERANCE * scale
    if np.any(gap):
        i, j = (int(x) for x in np.argwhere(gap)[0])
        raise ValueError(
            f"`{name}` must be symmetric: entry ({i}, {j}) = {float(matrix[i, j])!r} {unit} but "
            f"({j}, {i}) = {float(matrix[j, i])!r} {unit}"
        )


def _eigenvalues(matrix: np.ndarray) -> np.ndarray:
    return np.linalg.eigvalsh(0.5 * (matrix + matrix.T))


def structure_matrices(mass, stiffness, damping, influence=None):
    """(M, C, K, r) from matrices, validated: the form a device file's ``[structure]`` has.

    Parameters
    ----------
    mass : array_like
        A list (the diagonal) or a symmetric positive-definite matrix (kg).
    stiffness : array_like
        Symmetric matrix (N/m), any definiteness (elements may add stiffness).
    damping : array_like
        Symmetric positive semi-definite matrix (Ns/m).
    influence : array_like or None
        Influence vector r, one entry per DOF (default all ones).
    """
    m = square_matrix("mass", mass, "kg", diagonal=True)
    n = m.shape[0]
    check_symmetric("mass", m, "kg")
    lowest = _eigenvalues(m)[0]
    if not lowest > 1e-12 * np.max(np.abs(m)):
        what = "singular" if abs(lowest) <= 1e-12 * np.max(np.abs(m)) else "indefinite"
        raise ValueError(
            f"`mass` must be positive definite (every DOF needs inertia); this {n} x {n} mass "
            f"matrix is {what} (smallest eigenvalue {lowest:.6g} kg)"
        )
    k = square_matrix("stiffness", stiffness, "N/m", n)
    check_symmetric("stiffness", k, "N/m")
    c = square_matrix("damping", damping, "Ns/m", n)
    check_symmetric("damping", c, "Ns/m")
    lowest = _eigenvalues(c)[0]
    if lowest < -1e-10 * max(np.max(np.abs(c)), 1e-300):
        raise ValueError(
            f"`damping` must be positive semi-definite (a damper only dissipates); its smallest "
            f"eigenvalue is {lowest:.6g} Ns/m"
        )
    r = np.ones(n) if influence is None else _finite_array("influence", influence, "")
    if r.shape != (n,):
        raise ValueError(f"`influence` must have one entry per DOF ({n}), got shape {r.shape}")
    return 0.5 * (m + m.T), 0.5 * (c + c.T), 0.5 * (k + k.T), r


def _row(name: str, value, unit: str, n: int | None, positive: bool) -> np.ndarray:
    arr = _finite_array(name, value, unit)
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"`{name}` must be a list of numbers ({unit}), got shape {arr.shape}")
    if n is not None and arr.size != n:
        raise ValueError(f"`{name}` must have {n} entries (one per mass or mode), got {arr.size}")
    bad = arr <= 0 if positive else arr < 0
    if np.any(bad):
        i = int(np.argmax(bad))
        sign = "> 0" if positive else ">= 0"
        raise ValueError(
            f"`{name}` entries must be {sign} ({unit}); entry {i} is {float(arr[i])!r}"
        )
    return arr


def chain_matrices(mass, stiffness, damping):
    """(M, C, K, r) of a chain: mass i joined to mass i-1 (mass 0 to the base).

    Parameters
    ----------
    mass : list of float
        The lumped masses (kg), > 0.
    stiffness, damping : list of float
        ``stiffness[i]`` (N/m) and ``damping[i]`` (Ns/m), >= 0, join mass i
        to mass i - 1, and mass 0 to the base.
    """
    m = _row("mass", mass, "kg", None, positive=True)
    n = m.size
    k = _row("stiffness", stiffness, "N/m", n, positive=False)
    c = _row("damping", damping, "Ns/m", n, positive=False)
    return np.diag(m), _chain(c), _chain(k), np.ones(n)


def _chain(values: np.ndarray) -> np.ndarray:
    """The tridiagonal matrix of springs (or dashpots) joining neighbours, the first to ground."""
    n = values.size
    out = np.zeros((n, n))
    for i, value in enumerate(values):
        out[i, i] += value
        if i > 0:
            out[i - 1, i - 1] += value
            out[i, i - 1] -= value
            out[i - 1, i] -= value
    return out


def modal_matrices(frequency, damping_ratio, modal_mass, participation, shapes, masses=()):
    """(M, C, K, r) of a host given by its modes, at its attachment points, plus lumped masses.

    Parameters
    ----------
    frequency : list of float
        Undamped natural frequencies f_n (Hz), > 0.
    damping_ratio : list of float
        zeta_n, >= 0.
    modal_mass : list of float
        m_n (kg), > 0, in the normalisation of ``shapes``.
    participation : list of float
        gamma_n = L_n / m_n (dimensionless): the base acceleration drives mode n
        with the force -gamma_n m_n a.
    shapes : array_like, shape (points, modes)
        phi_n at each attachment point; square and invertible.
    masses : list of float
        Lumped masses (kg), > 0, appended as DOFs after the points.
    """
    f = _row("frequency", frequency, "Hz", None, positive=True)
    n = f.size
    zeta = _row("damping_ratio", damping_ratio, "", n, positive=False)
    m = _row("modal_mass", modal_mass, "kg", n, positive=True)
    gamma = _finite_array("participation", participation, "")
    if gamma.shape != (n,):
        raise ValueError(f"`participation` must have {n} entries (one per mode), got {gamma.shape}")
    phi = _finite_array("shapes", shapes, "")
    if phi.ndim == 1 and n == 1 and phi.size == 1:
        phi = phi.reshape(1, 1)
    if phi.shape != (n, n):
        raise ValueError(
            f"`shapes` must be {n} x {n} (attachment points x modes: as many points as modes), "
            f"got shape {phi.shape}"
        )
    if np.linalg.cond(phi) > 1e12:
        raise ValueError(
            f"`shapes` must be invertible: these {n} attachment points do not tell the modes "
            "apart (place a point where the modes differ)"
        )
    inv = np.linalg.inv(phi)
    omega = 2.0 * np.pi * f

    def physical(diagonal):
        return inv.T @ np.diag(diagonal) @ inv

    host = physical(m), physical(2.0 * zeta * m * omega), physical(m * omega**2)
    r = phi @ gamma
    extra = np.zeros(0) if len(masses) == 0 else _row("masses", masses, "kg", None, positive=True)
    if extra.size == 0:
        return (*(0.5 * (x + x.T) for x in host), r)
    size = n + extra.size
    out = []
    for block, tail in zip(host, (extra, np.zeros(extra.size), np.zeros(extra.size)), strict=True):
        full = np.zeros((size, size))
        full[:n, :n] = 0.5 * (block + block.T)
        full[n:, n:] = np.diag(tail)
        out.append(full)
    return (*out, np.concatenate([r, np.ones(extra.size)]))
