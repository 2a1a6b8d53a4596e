"""The restoring potential U(z) = k z^2/2 + k3 z^4/4 of the device (paper Eq. 1).

One class, :class:`Potential`, says what kind of spring the device has and
what the methods may assume about it:

======================  =====================  ===========================================
kind                    parameters             stationary state
======================  =====================  ===========================================
``monostable``          k > 0, k3 >= 0         z and z' (the paper's device)
``bistable``            k < 0, k3 > 0          z and z'; wells at +-sqrt(-k/k3), barrier
                                               k^2/(4 k3) above them
``pure-cubic``          k = 0, k3 > 0          z and z' (quartic well, no linear stiffness)
``free``                k = k3 = 0             z' only: the mass drifts, z diffuses
                                               without bound, so displacement statistics
                                               are not stationary
``non-confining``       k3 < 0, or k < 0 with  none: the mass escapes to infinity; every
                        k3 = 0                 stationary method refuses it
======================  =====================  ===========================================

A potential is *confining* when U(z) -> inf as |z| -> inf (k3 > 0, or
k3 = 0 and k > 0): then exp(-U/T) is integrable and, with white noise, linear
damping and no friction, the stationary density is the Gibbs density
exp(-H/T), T = m sigma_v^2 = S m^2/(4 c), whatever the shape of U
(docs/conventions.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from randvib._validation import check_finite, scalar_or_array

#: The kinds of :attr:`Potential.kind`.
KINDS = ("monostable", "bistable", "pure-cubic", "free", "non-confining")
#: Kinds whose displacement has a stationary law.
CONFINING = ("monostable", "bistable", "pure-cubic")


@dataclass(frozen=True, eq=False)
class Potential:
    """U(z) = k z^2/2 + k3 z^4/4 (J) with any signs of k and k3.

    Parameters
    ----------
    k : float or ndarray
        Linear stiffness (N/m), any finite value.
    k3 : float or ndarray
        Cubic stiffness (N/m^3), any finite value (k3 < 0 is non-confining).
    """

    k: object
    k3: object = 0.0

    def __post_init__(self):
        object.__setattr__(self, "k", scalar_or_array(check_finite("k", self.k)))
        object.__setattr__(self, "k3", scalar_or_array(check_finite("k3", self.k3)))

    @classmethod
    def from_wells(cls, well: float, barrier: float) -> Potential:
        """The bistable potential with wells at z = +-``well`` (m) and ``barrier`` (J).

        Inverts z_w = sqrt(-k/k3) and Delta U = k^2/(4 k3):
        k = -4 Delta U / z_w^2 (N/m), k3 = 4 Delta U / z_w^4 (N/m^3).

        Examples
        --------
        >>> p = Potential.from_wells(0.002, 1e-4)
        >>> print(f"{p.k:.6g} N/m, {p.k3:.6g} N/m^3, wells at +-{p.wells[1]:.6g} m")
        -100 N/m, 2.5e+07 N/m^3, wells at +-0.002 m
        """
        well = float(check_finite("well", well))
        barrier = float(check_finite("barrier", barrier))
        if not well > 0:
            raise ValueError(f"`well` (the wells' distance from z = 0) must be > 0 m, got {well!r}")
        if not barrier > 0:
            raise ValueError(f"`barrier` (the barrier height) must be > 0 J, got {barrier!r}")
        with np.errstate(all="ignore"):
            k, k3 = -4.0 * barrier / well**2, 4.0 * barrier / well**4
        if not (np.isfinite(k) and np.isfinite(k3) and k < 0 < k3):
            raise ValueError(
                f"wells at +-{well!r} m with a barrier of {barrier!r} J give k = {k!r} N/m, "
                f"k3 = {k3!r} N/m^3, beyond float64"
            )
        return cls(float(k), float(k3))

    # ------------------------------------------------------------ classification
    @property
    def kind(self):
        """One of :data:`KINDS` (an array of them for array parameters)."""
        if isinstance(self.k, float) and isinstance(self.k3, float):
            # the same tests on two numbers without numpy's array machinery: every
            # prediction asks (a design's search thousands of times)
            return _scalar_kind(self.k, self.k3)
        k, k3 = np.broadcast_arrays(np.asarray(self.k, float), np.asarray(self.k3, float))
        if k.ndim == 0:
            return _scalar_kind(float(k), float(k3))
        # the one rule, point by point (a grid of devices is small)
        points = zip(k.ravel().tolist(), k3.ravel().tolist(), strict=True)  # broadcast: equal
        kinds = [_scalar_kind(a, b) for a, b in points]
        return np.array(kinds, dtype=f"<U{max(map(len, KINDS))}").reshape(k.shape)

    @property
    def is_confining(self) -> bool:
        """True when U -> inf as |z| -> inf at every parameter point."""
        return _all_in(self.kind, CONFINING)

    @property
    def is_free(self) -> bool:
        """True for the free mass (k = k3 = 0) at every parameter point."""
        return _all_in(self.kind, ("free",))

    @property
    def velocity_is_stationary(self) -> bool:
        """True when the velocity has a stationary law: confining or free at every point."""
        return _all_in(self.kind, CONFINING + ("free",))

    # ------------------------------------------------------------ shape
    def energy(self, z):
        """U(z) = k z^2/2 + k3 z^4/4 (J)."""
        z = np.asarray(z, dtype=float)
        return 0.5 * self.k * z * z + 0.25 * self.k3 * z**4

    def force(self, z):
        """Restoring force U'(z) = k z + k3 z^3 (N)."""
        z = np.asarray(z, dtype=float)
        return self.k * z + self.k3 * z**3

    @property
    def wells(self):
        """Positions of the minima of U (m): (0,) or (-z_w, z_w), z_w = sqrt(-k/k3).

        Only for a scalar confining potential.
        """
        self._require_confining("wells")
        k, k3 = float(self.k), float(self.k3)
        if k >= 0:
            return (0.0,)
        with np.errstate(all="ignore"):
            z_w = np.sqrt(-k / k3)
        if not np.isfinite(z_w):
            raise ValueError(
                f"the wells of the bistable potential k = {k!r} N/m, k3 = {k3!r} N/m^3 lie "
                "beyond float64 (sqrt(-k/k3) overflows)"
            )
        return (-float(z_w), float(z_w))

    @property
    def stiffness_at_rest(self):
        """U''(z) at the stable rest position (N/m): k at z = 0, or -2 k in the bistable
        wells z = +-sqrt(-k/k3); nan for a non-confining potential."""
        k, k3 = np.broadcast_arrays(np.asarray(self.k, float), np.asarray(self.k3, float))
        kinds = np.asarray(self.kind)
        stiffness = np.where(kinds == "bistable", -2.0 * k, k)
        return scalar_or_array(np.where(kinds == "non-confining", np.nan, stiffness))

    @property
    def minimum(self):
        """min U (J): 0, or -k^2/(4 k3) for the bistable potential."""
        k, k3 = np.broadcast_arrays(np.asarray(self.k, float), np.asarray(self.k3, float))
        with np.errstate(divide="ignore", invalid="ignore"):
            low = np.where((k < 0) & (k3 > 0), -(k * k) / (4.0 * np.where(k3 > 0, k3, 1.0)), 0.0)
        if low.ndim == 0 and not np.isfinite(low):  # a grid keeps its points, -inf included
            raise ValueError(
                f"min U = -k^2/(4 k3) of the bistable potential k = {float(k)!r} N/m, "
                f"k3 = {float(k3)!r} N/m^3 overflows float64"
            )
        return scalar_or_array(low)

    @property
    def barrier_height(self):
        """U(0) - min U (J): k^2/(4 k3) for the bistable potential, 0 otherwise."""
        return scalar_or_array(-np.asarray(self.minimum))

    def outer_turning_point(self, energy):
        """Largest |z| (m) with U(z) = ``energy`` (J), for a confining potential.

        The positive root in z^2 of k3 z^4/4 + k z^2/2 = E, written without
        cancellation for either sign of k: (-k + sqrt(k^2 + 4 k3 E))/k3 for
        k < 0, 4 E/(k + sqrt(k^2 + 4 k3 E)) otherwise. ``energy`` >= min U.
        """
        k, k3, e = np.broadcast_arrays(
            np.asarray(self.k, float), np.asarray(self.k3, float), np.asarray(energy, float)
        )
        root = np.sqrt(np.maximum(k * k + 4.0 * k3 * e, 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            z2 = np.where(k < 0, (root - k) / np.where(k3 > 0, k3, 1.0), 4.0 * e / (k + root))
        return scalar_or_array(np.sqrt(z2))

    # ------------------------------------------------------------ refusals
    def _require_confining(self, what: str):
        self.require(what, CONFINING)

    def require(self, method: str, kinds=CONFINING, alternatives: str = "") -> None:
        """Refuse, with one line, a potential whose kind is not in ``kinds``.

        The line names the potential, what ``method`` accepts and, when given,
        the ``alternatives`` that do treat it. A non-confining potential is
        refused the same way by every stationary method: it has no stationary
        state.
        """
        kind = self.kind
        bad = sorted(set(np.ravel(kind)) - set(kinds))
        if not bad:
            return
        names = [name for name in kinds if name not in CONFINING]
        words = [_DESCRIPTIONS[name] for name in kinds if name in CONFINING]
        if set(CONFINING) <= set(kinds):
            words = ["a confining potential (k3 > 0, or k3 = 0 with k > 0)"]
        accepted = " or ".join(words + [_DESCRIPTIONS[name] for name in names])
        got = f"k = {self.k!r} N/m, k3 = {self.k3!r} N/m^3"
        tail = f"; use {alternatives}" if alternatives else ""
        if "non-confining" in bad:
            reason = "is not confining (k3 < 0, or k < 0 with k3 = 0): no stationary state"
            tail = ""  # no stationary method treats it
        else:
            reason = "is " + " / ".join(_NAMES[name] for name in bad)
        raise ValueError(f"{method} needs {accepted}; the potential with {got} {reason}{tail}")


_NAMES = {
    "monostable": "monostable",
    "bistable": "bistable",
    "pure-cubic": "pure cubic",
    "free": "the free mass (no spring: z is not stationary)",
}

_DESCRIPTIONS = {
    "monostable": "a monostable potential (k > 0, k3 >= 0)",
    "bistable": "a bistable potential (k < 0 < k3)",
    "pure-cubic": "a pure cubic potential (k = 0 < k3)",
    "free": "the free mass (k = k3 = 0)",
}


def _scalar_kind(k: float, k3: float) -> str:
    """:attr:`Potential.kind` of one parameter point: the first test that holds."""
    if k3 < 0 or (k < 0 and k3 == 0):
        return "non-confining"
    if k == 0 and k3 == 0:
        return "free"
    if k < 0:
        return "bistable"
    if k == 0:
        return "pure-cubic"
    return "monostable"


def _all_in(kind, kinds: tuple[str, ...]) -> bool:
    """True when ``kind`` (one kind, or an array of them) is among ``kinds`` at every point."""
    if isinstance(kind, str):
        return kind in kinds
    return bool(np.all(np.isin(kind, kinds)))
