"""Events: an excitation switched on and shaped in time by a deterministic envelope.

A stationary excitation (:mod:`randvib.models.excitation`) describes base
motion that has always been going on. An *event* (a vehicle crossing a
bridge, a train passing, an earthquake) is the same random motion shaped by a
deterministic envelope ``e(t)`` that starts at t = 0:

    a(t) = e(t) x(t),   t >= 0,

with ``x`` the stationary base acceleration of the excitation
(docs/conventions.md, "Transient response from rest"). What "multiplied"
means for each kind of excitation:

* **white noise** of level S: e(t) multiplies the noise,
  E[a(t1) a(t2)] = e(t1)^2 (S/2) delta(t2 - t1), so the covariance of the
  linear device obeys ``dP/dt = A P + P A^T + e(t)^2 (S/2) b b^T``;
* **filtered noise** (band-pass, Kanai-Tajimi): ``x`` is the output of the
  shaping filter, started in its stationary state (the ground has always
  been shaking that way; only what reaches the device is shaped); the
  envelope multiplies the filter's output, so the coupling from filter to
  device is ``e(t) C`` and the filter itself is not changed;
* **synthesised input** (band-limited, tabulated): the synthesised
  stationary path multiplied by e(t).

The device starts at rest by default; :class:`EventStart` holds where it
starts (rest, the unexcited device's resting state, or a given state), which
the transient methods take beside the event.

**The envelope family.** An envelope is one class, a frozen dataclass
subclassing :class:`Envelope`, that declares its value ``e(t)``, the
integral of its square (``square_integral``), its kinks and jumps
(``breakpoints``, for quadrature and ODE solvers) and its peak; defining a
subclass with its own ``name`` registers it in :data:`ENVELOPES` (the CLI's
``--envelope`` choices). Its parameters are declared with
:func:`~randvib.models.parameters.parameter`, so the CLI's options and the
validation come from the declarations:

==================  ===============================================  ===================
envelope            e(t), t >= 0                                     parameters
==================  ===============================================  ===================
``step``            1 (noise switched on at t = 0; Caughey and        -
                    Stumpf 1961)
``shinozuka-sato``  A (exp(-b t) - exp(-c t)), c > b > 0              a, b (1/s), c (1/s)
                    (Shinozuka and Sato 1967)
``boxcar``          linear rise over ``rise``, 1 for ``hold``,        rise, hold, fall (s)
                    linear fall over ``fall``, then 0
``table``           linear between the rows (``time``,               from a CSV file
                    ``envelope``), 0 outside the table
==================  ===============================================  ===================
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from randvib._validation import check_finite, check_nonnegative
from randvib.models.excitation import Excitation, read_columns
from randvib.models.parameters import DeclaredParameters, parameter

#: Registered envelopes by name (the CLI's ``--envelope`` choices).
ENVELOPES: dict[str, type] = {}

# Gauss-Legendre rule on each time step: exact for piecewise polynomials of
# degree <= 11 between breakpoints, and to rounding for the smooth exponentials.
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(6)


class Envelope(DeclaredParameters):
    """Base class of the envelopes: the declaration every consumer reads.

    Subclasses are frozen dataclasses; one that sets ``name`` is registered
    in :data:`ENVELOPES`. The value is dimensionless: it multiplies the base
    acceleration, so the intensity (the PSD) is multiplied by its square.
    """

    #: Short name used by the CLI and tables.
    name: str = "envelope"

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "name" in cls.__dict__:
            ENVELOPES[cls.name] = cls

    def __call__(self, t) -> np.ndarray:
        """e(t) at the times ``t`` (s); 0 before the event (t < 0)."""
        t = np.asarray(t, dtype=float)
        return np.where(t >= 0, self._value(np.maximum(t, 0.0)), 0.0)

    def _value(self, t):  # pragma: no cover - abstract
        raise NotImplementedError

    def square_integral(self, t) -> np.ndarray:  # pragma: no cover - abstract
        """int_0^t e(s)^2 ds (s): the event's intensity-weighted duration up to t."""
        raise NotImplementedError

    def breakpoints(self) -> tuple[float, ...]:
        """Times (s) > 0 where e(t) or its slope jumps (quadrature and ODE segments)."""
        return ()

    @property
    def peak_time(self) -> float:  # pragma: no cover - abstract
        """A time (s) at which e(t) is largest."""
        raise NotImplementedError

    @property
    def peak(self) -> float:
        """The largest value of e(t)."""
        return float(self(self.peak_time))

    def equivalent_duration(self, t_end: float) -> float:
        """int_0^T e^2 dt / peak^2 (s): how long the peak intensity would deliver as much.

        For a linear device under white noise, stationary power at the peak
        intensity times this duration is the quasi-static estimate of the
        event's energy (exact only when the device responds instantly).
        """
        return float(self.square_integral(t_end)) / self.peak**2

    def step_integrals(self, dt: float, n_steps: int) -> tuple[np.ndarray, np.ndarray]:
        """int e dt and int e^2 dt (s) over each step [j dt, (j + 1) dt), j < n_steps.

        Gauss-Legendre on each step, split at the breakpoints inside it, so the
        step integrals are exact for piecewise polynomials of degree <= 11
        (step, boxcar, table) and to rounding for Shinozuka-Sato.
        """
        edges = np.arange(n_steps + 1) * dt
        inside = [b for b in self.breakpoints() if 0.0 < b < edges[-1]]
        cut = np.unique(np.concatenate([edges, inside]))
        half = 0.5 * np.diff(cut)
        t = (cut[:-1] + half)[:, None] + half[:, None] * _NODES
        e = self(t)
        first = (e * _WEIGHTS).sum(axis=1) * half
        second = (e * e * _WEIGHTS).sum(axis=1) * half
        step = np.minimum(np.searchsorted(edges, cut[:-1], side="right") - 1, n_steps - 1)
        return (
            np.bincount(step, first, minlength=n_steps),
            np.bincount(step, second, minlength=n_steps),
        )

    def parameters(self) -> dict:
        """The envelope's name and parameters (SI units), ready for JSON."""
        out = {"envelope": self.name}
        out.update({f.name: getattr(self, f.name) for f in fields(self)})
        return out


def _scalar(value) -> float:
    return float(value)


@dataclass(frozen=True, eq=False)
class Step(Envelope):
    """The unit step: stationary noise switched on at t = 0, e(t) = 1.

    The classical transient of random vibration: Caughey and Stumpf (1961)
    give the linear oscillator's moments from rest in closed form
    (:func:`randvib.analytic.exact_solutions.caughey_stumpf_moments`).
    """

    name = "step"

    def _value(self, t):
        return np.ones_like(t)

    def square_integral(self, t):
        return np.maximum(np.asarray(t, dtype=float), 0.0)

    @property
    def peak_time(self) -> float:
        return 0.0


@dataclass(frozen=True, eq=False)
class ShinozukaSato(Envelope):
    """Shinozuka and Sato (1967): e(t) = A (exp(-b t) - exp(-c t)), c > b > 0.

    Rises from 0 with slope A (c - b), peaks at t* = ln(c/b) / (c - b) and
    decays like exp(-b t); :meth:`unit_peak` gives the A that makes the peak 1.

    Parameters
    ----------
    a : float
        Amplitude A, > 0 (dimensionless).
    b : float
        Decay rate (1/s), > 0.
    c : float
        Rise rate (1/s), > b.
    """

    a: float = parameter("", positive=True, description="Shinozuka-Sato amplitude A")
    b: float = parameter("1/s", positive=True, description="Shinozuka-Sato decay rate b")
    c: float = parameter("1/s", positive=True, description="Shinozuka-Sato rise rate c, > b")

    name = "shinozuka-sato"

    def __post_init__(self):
        for name in ("a", "b", "c"):
            if np.ndim(getattr(self, name)) != 0:
                raise ValueError(f"`{name}` must be one number, got {getattr(self, name)!r}")
        super().__post_init__()
        for name in ("a", "b", "c"):
            object.__setattr__(self, name, _scalar(getattr(self, name)))
        if not self.c > self.b:
            raise ValueError(
                f"`c` must be > `b` = {self.b!r} 1/s (the rise is faster than the decay), "
                f"got {self.c!r} 1/s"
            )

    @classmethod
    def unit_peak(cls, b: float, c: float) -> ShinozukaSato:
        """The envelope with decay b and rise c (1/s) whose peak value is 1."""
        shape = cls(1.0, b, c)
        peak = shape.peak
        if not (np.isfinite(peak) and peak > 0 and np.isfinite(1.0 / peak)):
            raise ValueError(
                f"the envelope of `b` = {shape.b!r} 1/s and `c` = {shape.c!r} 1/s peaks at "
                f"{peak!r}, which no amplitude `a` can scale to 1 in float64; give rates of a "
                "physical size (1/s)"
            )
        return cls(1.0 / peak, shape.b, shape.c)

    def _value(self, t):
        return self.a * (np.exp(-self.b * t) - np.exp(-self.c * t))

    def square_integral(self, t):
        t = np.maximum(np.asarray(t, dtype=float), 0.0)
        b, c = self.b, self.c
        # int_0^t exp(-r s) ds = -expm1(-r t) / r, accurate at small t
        return self.a**2 * (
            -np.expm1(-2 * b * t) / (2 * b)
            + 2 * np.expm1(-(b + c) * t) / (b + c)
            - np.expm1(-2 * c * t) / (2 * c)
        )

    @property
    def peak_time(self) -> float:
        # log c - log b: c / b overflows for a decay rate near float64's smallest
        return float((np.log(self.c) - np.log(self.b)) / (self.c - self.b))


class _PiecewiseLinear(Envelope):
    """Linear between nodes (t_i, e_i), zero outside [t_0, t_last] (subclasses give the nodes)."""

    def _nodes(self) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - abstract
        raise NotImplementedError

    def _value(self, t):
        times, values = self._nodes()
        inside = (t >= times[0]) & (t <= times[-1])
        return np.where(inside, np.interp(t, times, values), 0.0)

    def square_integral(self, t):
        times, values = self._nodes()
        t = np.clip(np.asarray(t, dtype=float), times[0], times[-1])
        e0, e1 = values[:-1], values[1:]
        # int of a line squared over [t_i, t_i+1]: (t_i+1 - t_i)(e0^2 + e0 e1 + e1^2)/3
        full = np.concatenate([[0.0], np.cumsum(np.diff(times) * (e0 * e0 + e0 * e1 + e1 * e1))])
        full /= 3.0
        i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2)
        u = t - times[i]
        start = values[i]
        end = np.interp(t, times, values)
        return full[i] + u * (start * start + start * end + end * end) / 3.0

    def breakpoints(self) -> tuple[float, ...]:
        return tuple(float(t) for t in self._nodes()[0] if t > 0)

    @property
    def peak_time(self) -> float:
        times, values = self._nodes()
        return float(times[np.argmax(values)])


@dataclass(frozen=True, eq=False)
class Boxcar(_PiecewiseLinear):
    """A boxcar with linear ramps: up over ``rise``, 1 for ``hold``, down over ``fall``.

    e(t) = t / rise on [0, rise], 1 on [rise, rise + hold], falling linearly
    to 0 at rise + hold + fall, and 0 after. A zero ramp is a jump.

    Parameters
    ----------
    rise, hold, fall : float
        Durations (s), >= 0; ``hold`` > 0.
    """

    rise: float = parameter("s", description="boxcar rise time")
    hold: float = parameter("s", positive=True, description="boxcar hold time at e = 1")
    fall: float = parameter("s", description="boxcar fall time")

    name = "boxcar"

    def __post_init__(self):
        for name in ("rise", "hold", "fall"):
            if np.ndim(getattr(self, name)) != 0:
                raise ValueError(f"`{name}` must be one number, got {getattr(self, name)!r}")
        super().__post_init__()
        for name in ("rise", "hold", "fall"):
            object.__setattr__(self, name, _scalar(getattr(self, name)))

    def _nodes(self):
        times, values = [0.0], [0.0 if self.rise > 0 else 1.0]
        if self.rise > 0:
            times.append(self.rise)
            values.append(1.0)
        times.append(self.rise + self.hold)
        values.append(1.0)
        if self.fall > 0:
            times.append(self.rise + self.hold + self.fall)
            values.append(0.0)
        return np.array(times), np.array(values)


@dataclass(frozen=True, eq=False)
class TabulatedEnvelope(_PiecewiseLinear):
    """An envelope given as a table, linear between rows, 0 outside the table.

    Parameters
    ----------
    time : array_like
        Times (s), >= 0, strictly increasing, at least two.
    envelope : array_like
        e at those times, finite and >= 0, not all zero.
    """

    time: np.ndarray
    envelope: np.ndarray

    name = "table"

    def __post_init__(self):
        t = check_finite("time", self.time)
        e = check_finite("envelope", self.envelope)
        if t.ndim != 1 or t.size < 2 or e.shape != t.shape:
            raise ValueError(
                "`time` and `envelope` must be 1-D of the same length >= 2, got shapes "
                f"{t.shape} and {e.shape}"
            )
        check_nonnegative("time", t, "s")
        check_nonnegative("envelope", e)
        steps = np.diff(t)
        if np.any(steps <= 0):
            i = int(np.argmax(steps <= 0))
            raise ValueError(
                f"`time` must be strictly increasing, got {float(t[i + 1])!r} s after "
                f"{float(t[i])!r} s (rows {i} and {i + 1}); sort the table"
            )
        if not np.any(e > 0):
            raise ValueError("`envelope` must be > 0 somewhere; the table has no event")
        object.__setattr__(self, "time", t)
        object.__setattr__(self, "envelope", e)

    @classmethod
    def from_csv(cls, path) -> TabulatedEnvelope:
        """Read a table with the columns ``time`` (s) and ``envelope`` (dimensionless)."""
        frame = read_columns(path, ("time", "envelope"))
        return cls(frame["time"], frame["envelope"])

    def _nodes(self):
        return self.time, self.envelope

    def parameters(self) -> dict:
        return {
            "envelope": self.name,
            "t_first": float(self.time[0]),
            "t_last": float(self.time[-1]),
            "peak": self.peak,
            "rows": int(self.time.size),
        }

    def __repr__(self) -> str:  # the size and range, not the arrays
        return (
            f"TabulatedEnvelope({self.time.size} rows, {self.time[0]:g}-{self.time[-1]:g} s, "
            f"peak {self.peak:.4g})"
        )


@dataclass(frozen=True, eq=False)
class Enveloped:
    """An event: a stationary excitation multiplied by a deterministic envelope.

    The base acceleration is ``a(t) = e(t) x(t)`` for t >= 0, ``x`` the
    stationary process of ``excitation`` (a filtered one with its filter in
    its stationary state); see the module docstring for what that means for
    each kind of excitation. Not an :class:`Excitation` itself: it has no
    stationary PSD, and the stationary methods refuse it; the transient ones
    (:func:`randvib.simulate_transient`, :func:`randvib.transient_response`)
    take it.

    Parameters
    ----------
    excitation : Excitation or float
        The stationary excitation (a number S is white noise of level S).
    envelope : Envelope
        The deterministic envelope e(t).

    Examples
    --------
    >>> import randvib as rv
    >>> event = rv.Enveloped(rv.BandPass(1.0, 8.0, 0.2), rv.ShinozukaSato.unit_peak(0.5, 2.0))
    >>> print(f"peak at {event.envelope.peak_time:.3f} s, e = {event.envelope.peak:.3f}")
    peak at 0.924 s, e = 1.000
    >>> event.peak_excitation()  # the stationary spectrum at the envelope's peak
    BandPass(level=1.0, f0=8.0, zeta=0.2)
    """

    excitation: Excitation
    envelope: Envelope

    #: Marks an event for the stationary methods, which refuse it by name.
    is_event = True

    def __post_init__(self):
        from randvib.models.excitation import as_excitation

        if isinstance(self.excitation, Enveloped):
            raise ValueError("`excitation` must be a stationary excitation, not another event")
        object.__setattr__(self, "excitation", as_excitation(self.excitation))
        if self.excitation.lines() or not self.excitation.is_gaussian:
            # the envelope modulates a Gaussian process (Priestley); tones, shocks and
            # translation processes are stationary inputs of randvib.simulate
            raise ValueError(
                f"an Enveloped event's excitation must be a Gaussian spectrum; the "
                f"{self.excitation.name} input (tones, shocks or a non-Gaussian marginal) is "
                "simulated stationary by randvib.simulate"
            )
        if not isinstance(self.envelope, Envelope):
            raise ValueError(
                f"`envelope` must be a randvib envelope ({', '.join(ENVELOPES)}), "
                f"got {self.envelope!r}"
            )
        peak = float(self.envelope.peak)
        level = getattr(self.excitation, "level", 1.0)
        if not (np.isfinite(peak * peak) and np.isfinite(float(level) * peak * peak)):
            raise ValueError(
                f"`envelope` peaks at {peak:.3g}: the intensity at its peak, S e^2, is beyond "
                "float64; scale the envelope (a peak of 1 keeps S the peak's level) or the "
                "excitation's level down"
            )

    @property
    def name(self) -> str:
        """``<excitation> x <envelope>``, for tables and messages."""
        return f"{self.excitation.name} x {self.envelope.name}"

    @property
    def level(self):
        """The stationary excitation's level S ((m/s^2)^2/Hz), or None for a table."""
        return getattr(self.excitation, "level", None)

    def peak_excitation(self) -> Excitation:
        """The stationary excitation at the envelope's peak: the PSD times peak^2."""
        return self.excitation.scaled(self.envelope.peak * self.envelope.peak)

    def parameters(self) -> dict:
        """The excitation's and the envelope's parameters, ready for JSON."""
        return {"excitation": self.excitation.parameters(), "envelope": self.envelope.parameters()}


#: The named starts of an event (besides a given state (z0, v0)).
STARTS = ("rest", "unexcited")


@dataclass(frozen=True)
class EventStart:
    """Where the device is when the event begins (t = 0).

    * ``rest``: z = 0, z' = 0 (the default; for a bistable device the top of
      the barrier);
    * ``unexcited``: the stationary state of the device with no input, at rest
      at the bottom of its potential: z = 0 for a monostable, pure-cubic or
      free device, and the well at z = +sqrt(-k/k3) for a bistable one (the
      unexcited device stays in whichever well it was left in; by symmetry
      the positive one stands for both);
    * a given state ``(z0, v0)`` (m, m/s).

    The start is deterministic: every path of an ensemble starts from it (a
    shaping filter's states, which belong to the excitation, start in their
    stationary law; a circuit's state at rest). Build it with :meth:`of`.

    Attributes
    ----------
    kind : {"rest", "unexcited", "state"}
    z, v : float
        The start (m, m/s).
    """

    kind: str
    z: float = 0.0
    v: float = 0.0

    @classmethod
    def of(cls, start, harvester) -> EventStart:
        """From ``"rest"``, ``"unexcited"`` or a finite pair (z0, v0), for ``harvester``."""
        if isinstance(start, EventStart):
            return start
        if isinstance(start, str):
            if start not in STARTS:
                raise ValueError(
                    f"`start` must be one of {', '.join(map(repr, STARTS))} or a state (z0, v0); "
                    f"got {start!r}"
                )
            if start == "rest":
                return cls("rest")
            # the bottom of the potential: a bistable device's positive well, else z = 0
            # (the free mass rests anywhere; z = 0 is its rest too)
            bottom = (
                max(harvester.potential.wells) if harvester.potential.kind == "bistable" else 0.0
            )
            return cls("unexcited", bottom, 0.0)
        try:
            z0, v0 = (float(x) for x in start)
        except (TypeError, ValueError):
            raise ValueError(
                f"`start` must be {', '.join(map(repr, STARTS))} or a state (z0, v0) in (m, m/s); "
                f"got {start!r}"
            ) from None
        if not (np.isfinite(z0) and np.isfinite(v0)):
            raise ValueError(f"`start` state must be finite, got {start!r}")
        return cls("state", z0, v0)

    @property
    def is_zero(self) -> bool:
        """True when the device starts at z = 0, z' = 0 (zero-mean response by symmetry)."""
        return self.z == 0.0 and self.v == 0.0

    def describe(self) -> str:
        """A few words for tables: ``rest``, ``unexcited (z = 0.0107 m)``, ``z = .., v = ..``."""
        if self.kind == "rest":
            return "rest"
        state = f"z = {self.z:.4g} m, v = {self.v:.4g} m/s"
        return f"unexcited ({state})" if self.kind == "unexcited" else state

    def to_dict(self) -> dict:
        return {"start": self.kind, "z0": self.z, "v0": self.v}


def envelope_class(name: str) -> type:
    """The registered envelope called ``name``, or a ValueError naming the choices."""
    try:
        return ENVELOPES[name]
    except KeyError:
        raise ValueError(
            f"`envelope` must be one of {', '.join(ENVELOPES)}; got {name!r}"
        ) from None
