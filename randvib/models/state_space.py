"""Linear time-invariant blocks in state-space form.

A block is ``x' = A x + B u``, ``y = C x + D u`` with a scalar input ``u``
and named outputs (the rows of ``C``). Shaping filters of rational excitation
spectra (:mod:`randvib.models.excitation`) and the linear(ised) device of
:mod:`randvib.analytic.linear_response` are blocks; :meth:`StateSpace.driven_by`
connects two in series, so a device with more states (a coil's current, a
piezo's voltage) is one more block, not a new solver.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class StateSpace:
    """Single-input LTI block ``x' = A x + B u``, ``y = C x + D u``.

    Parameters
    ----------
    a : array_like, shape (n, n)
        State matrix (1/s).
    b : array_like, shape (n,)
        Input vector.
    c : array_like, shape (p, n)
        Output matrix, one row per output.
    d : array_like, shape (p,)
        Direct feed-through of the input to each output.
    outputs : tuple of str
        Names of the outputs (rows of ``c``).
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    outputs: tuple[str, ...]

    def __post_init__(self):
        n = np.size(self.b)
        a = np.asarray(self.a, dtype=float).reshape(n, n)
        b = np.asarray(self.b, dtype=float).reshape(n)
        c = np.asarray(self.c, dtype=float).reshape(len(self.outputs), n)
        d = np.asarray(self.d, dtype=float).reshape(len(self.outputs))
        for name, value in zip("abcd", (a, b, c, d), strict=True):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "outputs", tuple(self.outputs))

    @property
    def n_states(self) -> int:
        return self.a.shape[0]

    def output(self, name: str) -> int:
        """Row index of the output called ``name``."""
        try:
            return self.outputs.index(name)
        except ValueError:
            raise ValueError(
                f"unknown output {name!r}; this block has {', '.join(self.outputs)}"
            ) from None

    def frequency_response(self, frequency) -> np.ndarray:
        """Transfer function ``H(i 2 pi f) = C (i 2 pi f I - A)^-1 B + D``.

        Parameters
        ----------
        frequency : array_like
            Frequencies f (Hz).

        Returns
        -------
        ndarray, complex, shape (p,) + shape(frequency)
            One row per output.
        """
        f = np.asarray(frequency, dtype=float)
        p = len(self.outputs)
        if self.n_states == 0:
            return np.broadcast_to(self.d.reshape((p,) + (1,) * f.ndim), (p,) + f.shape) + 0j
        s = 2j * np.pi * f.reshape(-1)
        h = self.c @ _resolvent_times_b(s, self.a, self.b) + self.d[:, None]  # (p, nf)
        return h.reshape((p,) + f.shape)

    def driven_by(self, upstream: StateSpace, output: str) -> StateSpace:
        """This block with its input taken from ``upstream``'s ``output``.

        The series connection has the states ``[upstream, self]``, the input
        of ``upstream`` and the outputs of ``self``.
        """
        row = upstream.output(output)
        cu, du = upstream.c[row], upstream.d[row]
        nu, n = upstream.n_states, self.n_states
        a = np.zeros((nu + n, nu + n))
        a[:nu, :nu] = upstream.a
        # outer products and the column stack written out as np.outer and np.hstack
        # compute them (the same products), without their wrappers' cost: every
        # Lyapunov solve of a linearisation's fixed point connects two blocks
        a[nu:, :nu] = self.b[:, None] * cu[None, :]
        a[nu:, nu:] = self.a
        b = np.concatenate([upstream.b, self.b * du])
        c = np.concatenate([self.d[:, None] * cu[None, :], self.c], axis=1)
        return StateSpace(a, b, c, self.d * du, self.outputs)


def _resolvent_times_b(s: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x = (s I - A)^-1 b at every s, shape (n, len(s)).

    A single-mass device has two states (the most common block by far: every
    spectral integral and bandwidth of a design's search): there Cramer's rule,
    forward stable for 2 x 2 systems (Higham, *Accuracy and Stability of Numerical
    Algorithms*, 2nd ed., sec. 1.10.1), in a few whole-array operations instead of
    one LAPACK call per frequency, whose overhead dominated (0.7 us per system at
    the thousands of nodes of a quadrature rule). Other sizes: LAPACK. An exactly
    singular s I - A raises :class:`numpy.linalg.LinAlgError`, as LAPACK does.
    """
    n = a.shape[0]
    if n == 2:
        m00, m11 = s - a[0, 0], s - a[1, 1]
        det = m00 * m11 - a[0, 1] * a[1, 0]
        if np.any(det == 0):
            raise np.linalg.LinAlgError("Singular matrix")
        return np.stack([m11 * b[0] + a[0, 1] * b[1], m00 * b[1] + a[1, 0] * b[0]]) / det
    resolvent = s[:, None, None] * np.eye(n) - a
    x = np.linalg.solve(resolvent, np.broadcast_to(b[:, None], (s.size, n, 1)))
    return x[..., 0].T
