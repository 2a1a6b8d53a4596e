"""Rectified couplings: a coil or a piezo element into a full-wave diode bridge (DC output).

The harvester's output goes through a full-wave bridge (two diodes conduct at
a time, each with the forward drop ``V_d``) into either a **battery** (a
constant voltage ``V_b``) or a **storage capacitor** ``C`` with the load
``R_L`` across it. The bridge is a nonlinear, switching element, so these
couplings are neither a viscous damper nor a linear circuit state: Monte
Carlo integrates them in the compiled kernel (:class:`kernel.Rectifier
<randvib.montecarlo.kernel.Rectifier>`), and an analytic method must declare
that it takes them (:attr:`randvib.analytic.method.AnalyticMethod.rectifier`).

* :class:`BridgeCoil`: back-EMF ``e = alpha z'``, threshold
  ``V_th = V_out + 2 V_d``; ``i = sgn(e) max(0, |e| - V_th) / R_C`` (L = 0;
  with an inductance the current is a state, and Shockley diodes replace
  the constant drop); force ``alpha i`` on the magnet.
* :class:`BridgePiezo`: ``C_p V_p' = theta z' - i_b`` with ``|V_p| <= V_th``;
  the bridge current ``i_b`` flows only while ``|V_p| = V_th``; force
  ``theta V_p`` on the mass.

Storage capacitor: ``C V_C' = |i| - V_C / R_L`` with ``V_out = V_C``. Stored
power: ``V_b E|i|`` into a battery, ``E[V_C^2] / R_L`` from a storage
capacitor. Every dissipation path is a mean power: stored (above), coil ``R_C E[i^2]``,
diodes ``2 V_d E|i|``; under white noise they and the mechanical dissipation
``c_m E[z'^2] + E[z' F]`` sum to ``m S / 4`` (docs/conventions.md).
"""

from __future__ import annotations

from dataclasses import MISSING, dataclass, field, fields

import numpy as np

from randvib._validation import check_nonnegative, check_positive
from randvib.models.coupling import Coupling, Inductive, Piezo, Resistive
from randvib.models.parameters import Parameter, parameter

#: The rectified couplings by the name of the transducer they rectify (the
#: CLI's ``--coupling`` with ``--rectifier bridge``).
RECTIFIED: dict[str, type] = {}

#: Thermal voltage k T / q at 300 K (V), the Shockley diodes' default.
THERMAL_VOLTAGE = 0.025852

#: Kernel codes of the transducer and of the output (:class:`randvib.montecarlo.kernel.Rectifier`).
COIL, PIEZO, INDUCTIVE_COIL = 1, 2, 3
BATTERY, CAPACITOR = 0, 1


def _optional(unit: str, description: str, positive: bool = False):
    """A declared parameter that may be left out (None)."""
    return field(
        default=None,
        metadata={"parameter": Parameter(unit, positive=positive, description=description)},
    )


def _with_default(unit: str, default: float, description: str):
    """A declared parameter >= 0 with a default."""
    return field(default=default, metadata={"parameter": Parameter(unit, description=description)})


class Rectified(Coupling):
    """Base class of the rectified couplings: the bridge and its output, validated once.

    A subclass declares its transducer's fields and ``v_diode``, ``battery``,
    ``storage_capacitance`` and ``r_load``; exactly one output is given:
    ``battery`` (V_b, V) or ``storage_capacitance`` (C, F) with ``r_load``
    (R_L, ohm).
    """

    rectified = True
    #: The transducer this rectifies (``inductive`` or ``piezo``).
    transducer: str = ""

    def __init_subclass__(cls, **kwargs):
        # Registered under the transducer's name in RECTIFIED, not in COUPLINGS:
        # the CLI's --coupling names the transducer, --rectifier the bridge.
        transducer = cls.__dict__.get("transducer")
        super(Coupling, cls).__init_subclass__(**kwargs)
        if transducer:
            RECTIFIED[transducer] = cls

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if value is None and f.default is not MISSING:
                continue
            if isinstance(value, bool) or value is None:
                raise ValueError(f"`{f.name}` must be a number, got {value!r}")
            spec = f.metadata["parameter"]
            check = check_positive if spec.positive else check_nonnegative
            arr = check(f.name, value, spec.unit)
            if np.ndim(arr):
                raise ValueError(f"`{f.name}` must be one number ({spec.unit}), got {value!r}")
            object.__setattr__(self, f.name, float(arr))
        storage = self.storage_capacitance is not None or self.r_load is not None
        if (self.battery is None) == (not storage):
            raise ValueError(
                "the bridge's output must be either `battery` (V_b, V) or "
                "`storage_capacitance` (C, F) with `r_load` (R_L, ohm), not "
                + ("both" if storage else "neither")
            )
        for name in ("storage_capacitance", "r_load"):
            if storage and getattr(self, name) is None:
                other = "r_load" if name == "storage_capacitance" else "storage_capacitance"
                raise ValueError(f"`{other}` needs `{name}`: the storage capacitor's load")
            if storage and getattr(self, name) <= 0:
                unit = "F" if name == "storage_capacitance" else "ohm"
                raise ValueError(f"`{name}` must be > 0 ({unit}), got {getattr(self, name)!r}")

    # -------------------------------------------------------- what it is
    def parameters(self) -> dict:
        """The bridge's parameters by name (SI units), the output left out omitted."""
        return {k: v for k, v in super().parameters().items() if v is not None}

    @property
    def has_battery(self) -> bool:
        """True for a battery output, False for a storage capacitor with its load."""
        return self.battery is not None

    @property
    def output_words(self) -> str:
        """The output in words, for tables and messages."""
        if self.has_battery:
            return f"battery V_b = {self.battery:g} V"
        return f"capacitor C = {self.storage_capacitance:g} F, R_L = {self.r_load:g} ohm"

    @property
    def electrical_damping(self):
        """0: the bridge's force is computed by the kernel, not a viscous c_e."""
        return 0.0

    def power_electrical(self, velocity_square, state_square=None):
        raise ValueError(
            f"the {self.name}'s power is not a function of E[z'^2]: simulate it "
            "(randvib.simulate: power_stored, power_coil_loss, power_diode_loss)"
        )

    power_load = power_electrical

    def white_noise_optimal_load(self, m, c_m, k):
        raise ValueError(
            f"the {self.name} has no closed-form optimum: use randvib.optimal_dc_output"
        )

    # ------------------------------------------------------ for the kernel
    def kernel_parameters(self) -> tuple[int, int, np.ndarray]:
        """(transducer code, output code, p) of :class:`randvib.montecarlo.kernel.Rectifier`.

        ``p = (gain, r_or_cp, V_d, V_b, C, R_L, I_s, n V_T)``: alpha (Wb/m)
        and R_C (ohm) for the coil, theta (N/V) and C_p (F) for the piezo; V_b
        is 0 and C, R_L are 1 where the output does not use them; I_s (A) and
        n V_T (V) of Shockley diodes, I_s = 0 for a constant drop.
        """
        output = BATTERY if self.has_battery else CAPACITOR
        gain, second = self._transducer_parameters()
        p = np.array(
            [
                gain,
                second,
                self.v_diode,
                self.battery if self.has_battery else 0.0,
                1.0 if self.has_battery else self.storage_capacitance,
                1.0 if self.has_battery else self.r_load,
                self._shockley[0],
                self._shockley[1],
                getattr(self, "inductance", 0.0),
            ]
        )
        return self._kernel_code, output, p

    @property
    def _kernel_code(self) -> int:
        return self._code

    def _transducer_parameters(self):  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def _shockley(self) -> tuple[float, float]:
        """(I_s (A), n V_T (V)) of Shockley diodes; (0, 0) for a constant drop."""
        return 0.0, 0.0

    def threshold(self, v_out: float = 0.0) -> float:
        """V_out + 2 V_d (V): the transducer voltage at which the bridge conducts."""
        out = self.battery if self.has_battery else v_out
        return out + 2.0 * self.v_diode

    #: The transducer's voltage that must exceed the threshold, in words (for messages).
    input_words: str = ""

    def idle_advice(self, input_rms: float, v_out: float = 0.0) -> str:
        """Why a bridge that never conducted stored nothing, and what would help (one sentence).

        Parameters
        ----------
        input_rms : float
            RMS of the transducer's open-circuit voltage (V): the coil's EMF
            ``alpha z'``, the piezo's ``theta z / C_p``.
        v_out : float
            The storage capacitor's voltage (V); a battery's is its own.
        """
        threshold = self.threshold(v_out)
        ratio = threshold / input_rms if input_rms > 0 else np.inf
        output = "V_b + 2 V_d" if self.has_battery else "V_C + 2 V_d"
        helps = [
            f"a {ratio:.2g}-fold larger voltage, from more turns or a stronger coupling "
            f"({self._coupling_name}), or a step-up transformer or converter of that ratio"
        ]
        if 2.0 * self.v_diode >= input_rms:
            helps.append(
                f"a lower-drop rectifier (Schottky or active diodes): the drops 2 V_d = "
                f"{2.0 * self.v_diode:.3g} V alone are {2.0 * self.v_diode / input_rms:.2g} "
                "times the RMS"
            )
        return (
            f"the bridge never conducted: the {self.input_words} (RMS {input_rms:.3g} V) never "
            f"reached {output} = {threshold:.3g} V ({ratio:.3g} times its RMS), so nothing "
            f"was stored; what would help: {'; '.join(helps)}"
        )

    #: The coupling parameter that scales the transducer's voltage.
    _coupling_name: str = ""

    def linear_surrogate(self) -> Coupling:  # pragma: no cover - abstract
        """A linear coupling with the bridge's largest damping, for the step check and start."""
        raise NotImplementedError

    def fastest_rate(self) -> float:
        """Largest rate (1/s) of the output circuit: 1/(R C) of the charging and the load."""
        if self.has_battery:
            return 0.0
        return 1.0 / (self.r_load * self.storage_capacitance)


@dataclass(frozen=True, eq=False)
class BridgeCoil(Rectified):
    """Electromagnetic coil into a full-wave bridge.

    Back-EMF ``e = alpha z'``; the bridge conducts when ``|e| > V_out + 2 V_d``
    and then ``i = sgn(e) (|e| - V_out - 2 V_d) / R_C``, else ``i = 0``; force
    ``alpha i`` on the magnet (opposing its motion). ``V_out`` is the battery's
    ``V_b``, or the storage capacitor's ``V_C`` with ``C V_C' = |i| - V_C / R_L``.
    With an inductance L > 0 the current is a state:
    ``L i' = e - R_C i - sgn(i) (V_out + 2 V_d)`` while it flows; the diodes
    hold it at 0 when it would reverse, until ``|e|`` exceeds the threshold.

    Parameters
    ----------
    alpha : float
        Flux gradient (Wb/m), > 0. The paper's device: 0.1992 Wb/m.
    r_coil : float
        Coil resistance R_C (ohm), > 0 (the current is (|e| - V_th) / R_C).
    v_diode : float
        Forward drop of each diode V_d (V), >= 0 (default 0: ideal diodes).
    battery : float, optional
        Battery voltage V_b (V), >= 0; stored power V_b E|i|.
    storage_capacitance, r_load : float, optional
        Storage capacitor C (F) and its load R_L (ohm), both > 0; stored
        power E[V_C^2] / R_L.
    saturation_current : float, optional
        Shockley diodes instead of a constant drop (then ``v_diode`` = 0):
        each conducting diode drops ``n V_T ln(1 + |i| / I_s)``, so
        ``|e| - V_out = R_C |i| + 2 n V_T ln(1 + |i| / I_s)``. I_s (A), > 0.
    ideality, thermal_voltage : float
        The Shockley law's n (default 1) and V_T = k T / q (V, default
        0.025852, 300 K).
    inductance : float
        Coil inductance L (H), >= 0 (default 0: the algebraic current).

    Examples
    --------
    >>> import randvib as rv
    >>> coil = rv.BridgeCoil(alpha=0.1992, r_coil=0.48, v_diode=0.2, battery=0.5)
    >>> coil.name, coil.threshold()
    ('inductive bridge', 0.9)
    """

    alpha: float = parameter("Wb/m", positive=True, description="flux gradient alpha")
    r_coil: float = parameter("ohm", positive=True, description="coil resistance R_C")
    v_diode: float = _with_default("V", 0.0, "forward drop of each diode V_d")
    battery: float | None = _optional("V", "battery voltage V_b")
    storage_capacitance: float | None = _optional("F", "storage capacitance C", True)
    r_load: float | None = _optional("ohm", "load resistance R_L across C", True)
    saturation_current: float | None = _optional("A", "Shockley diodes' I_s", True)
    ideality: float = _with_default("", 1.0, "Shockley diodes' ideality factor n")
    thermal_voltage: float = _with_default("V", THERMAL_VOLTAGE, "thermal voltage k T / q")
    inductance: float = _with_default("H", 0.0, "coil inductance L")

    transducer = "inductive"
    name = "inductive bridge"
    input_words = "coil's EMF alpha z'"
    _code = COIL
    _coupling_name = "alpha"

    def __post_init__(self):
        super().__post_init__()
        # the conducting bridge's damping alpha^2 / R_C, which every method uses
        if not np.isfinite(np.float64(self.alpha) * self.alpha / self.r_coil):
            raise ValueError(
                f"`alpha` = {self.alpha!r} Wb/m with `r_coil` = {self.r_coil!r} ohm: the "
                "conducting bridge's damping alpha^2 / R_C is beyond float64; give coupling "
                "parameters of a physical size"
            )
        if self.saturation_current is not None:
            if self.v_diode != 0.0:
                raise ValueError(
                    "give either `v_diode` (a constant drop) or `saturation_current` "
                    f"(Shockley diodes), not both; got v_diode = {self.v_diode!r}"
                )
            if self.inductance > 0:
                raise ValueError(
                    "Shockley diodes are implemented for the algebraic-current coil only: give "
                    f"`inductance` = 0 with `saturation_current`; got {self.inductance!r} H"
                )
            if not (self.ideality > 0 and self.thermal_voltage > 0):
                raise ValueError(
                    f"`ideality` and `thermal_voltage` must be > 0 for Shockley diodes; got "
                    f"{self.ideality!r} and {self.thermal_voltage!r}"
                )

    @property
    def is_shockley(self) -> bool:
        """True for Shockley diodes (``saturation_current`` given), False for a constant drop."""
        return self.saturation_current is not None

    def parameters(self) -> dict:
        """The bridge's parameters; the Shockley law's ``ideality`` and ``thermal_voltage``
        only for Shockley diodes (a constant drop ``v_diode`` does not use them)."""
        out = super().parameters()
        if not self.is_shockley:
            out.pop("ideality", None)
            out.pop("thermal_voltage", None)
        return out

    @property
    def _shockley(self) -> tuple[float, float]:
        if not self.is_shockley:
            return 0.0, 0.0
        return self.saturation_current, self.ideality * self.thermal_voltage

    def _transducer_parameters(self):
        return self.alpha, self.r_coil

    @property
    def _kernel_code(self) -> int:
        return INDUCTIVE_COIL if self.inductance > 0 else COIL

    def linear_surrogate(self) -> Coupling:
        """The conducting bridge: the damper alpha^2 / R_C, or the coil with its L > 0."""
        if self.inductance > 0:
            return Inductive(self.alpha, self.r_coil, 0.0, self.inductance)
        return Resistive(self.alpha, self.r_coil, 0.0)

    def fastest_rate(self) -> float:
        if self.has_battery:
            return 0.0
        return 1.0 / (self.storage_capacitance * self.r_coil) + super().fastest_rate()


@dataclass(frozen=True, eq=False)
class BridgePiezo(Rectified):
    """Piezoelectric element into a full-wave bridge (the standard piezo circuit).

    ``C_p V_p' = theta z' - i_b``, force ``theta V_p`` on the mass; the bridge
    current ``i_b`` flows only while ``|V_p|`` is clamped at ``V_out + 2 V_d``
    and the motion pushes it further; ``V_out`` is ``V_b`` or ``V_C``
    (``C V_C' = |i_b| - V_C / R_L``; while conducting, C_p and C charge together).

    Parameters
    ----------
    theta : float
        Electromechanical coupling theta (N/V), > 0.
    capacitance : float
        Clamped capacitance C_p (F), > 0.
    v_diode, battery, storage_capacitance, r_load
        As for :class:`BridgeCoil`.
    """

    theta: float = parameter("N/V", positive=True, description="piezo coupling theta")
    capacitance: float = parameter("F", positive=True, description="piezo capacitance C_p")
    v_diode: float = _with_default("V", 0.0, "forward drop of each diode V_d")
    battery: float | None = _optional("V", "battery voltage V_b")
    storage_capacitance: float | None = _optional("F", "storage capacitance C", True)
    r_load: float | None = _optional("ohm", "load resistance R_L across C", True)

    transducer = "piezo"
    name = "piezo bridge"
    input_words = "piezo's open-circuit voltage theta z / C_p"
    _code = PIEZO
    _coupling_name = "theta"

    def _transducer_parameters(self):
        return self.theta, self.capacitance

    def linear_surrogate(self) -> Coupling:
        """The piezo on a load matched to its own capacitance at the open-circuit frequency.

        A linear circuit state with the piezo's time scale; its R_L is that of
        the storage capacitor's load where there is one.
        """
        r_load = self.r_load if self.r_load is not None else 1.0 / self.capacitance
        return Piezo(self.theta, self.capacitance, r_load)


def rectified(coupling: str, **parameters) -> Rectified:
    """The rectified coupling of the transducer ``coupling`` (``inductive`` or ``piezo``)."""
    try:
        cls = RECTIFIED[coupling]
    except KeyError:
        raise ValueError(
            f"`coupling` with a rectifier must be one of {', '.join(RECTIFIED)}; got {coupling!r}"
        ) from None
    return cls(**parameters)
