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
        s = 2j * np.pi * f.reshape(-1, 1, 1)
        resolvent = s * np.eye(self.n_states) - self.a
        x = np.linalg.solve(resolvent, np.broadcast_to(self.b[:, None], (f.size, self.n_states, 1)))
        h = (self.c @ x)[..., 0] + self.d  # (nf, p)
        return h.T.reshape((p,) + f.shape)

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
        a[nu:, :nu] = np.outer(self.b, cu)
        a[nu:, nu:] = self.a
        b = np.concatenate([upstream.b, self.b * du])
        c = np.hstack([np.outer(self.d, cu), self.c])
        return StateSpace(a, b, c, self.d * du, self.outputs)
