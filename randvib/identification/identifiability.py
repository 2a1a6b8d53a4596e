"""What a set of records can determine: structural and local identifiability.

**Structural** (:func:`structural_identifiability`, before any fit). Two
parameter sets that give every measured channel the same response to every
input cannot be told apart by any record. Such families come from symmetries
of the equations (docs/identification.md works them out):

* **mass**: under base excitation Eq. 1 divided by m holds only c/m, k/m,
  k3/m, F/m, so every force may scale with m (a coil's alpha, L and
  R_L + R_C with it, a piezo's theta with sqrt(m) and its voltage too);
* **current** (a coil): alpha -> s alpha, L -> s^2 L, R_L + R_C -> s^2 (R_L +
  R_C) leaves the motion unchanged and scales the current by 1/s;
* **damping split** (a coupling without a circuit state: resistive, L or C_p
  held at 0): the motion sees only c_m + c_e at each load and the output only
  the gain alpha R_L / (R_L + R_C) (theta R_L for a piezo).

What breaks them: the mass given (or a force input) breaks the first; a
voltage or current channel (R_L known) the second; records at two loads
(three with the motion only) or a circuit's own time constant (L / (R_L +
R_C), R_L C_p) the third; fixing one parameter of a family breaks it.

The test here is generic rather than a list of cases: the parameters are
locally identifiable when the Jacobian of what the records can show with
respect to the parameters has full rank at a generic point. What they can
show is (i) each record's linear transfer functions from the input to each
measured channel, at several frequencies (the device linearised about z = 0:
m s^2 + c s + k plus the circuit's impedance), and (ii) each nonlinear force
per unit mass (k3/m, Fc/m, ...; a law's velocity scales as they are). The
rank is computed with Richardson-extrapolated central differences at random
parameter values of order one (a nondimensional device with the records'
load ratios), where identifiable directions have singular values many
decades above the differences' error. The parameters in the null space are
those the records cannot fix; each remedy (fix one of them, a record at
another load, another channel, the mass) is tried the same way, and the
refusal names those that work.

**Local** (:func:`local_identifiability`, after the fit). At the estimate,
the covariance of the mechanical damping, the mass and the coupling's
parameters in relative units says how well the data fix each direction: a
direction along which the relative standard error exceeds
:data:`UNDETERMINED` and that moves two or more of them is a split the data
do not make (the circuit's time constant is there in principle but too short
for the sample rate, two loads too close); identify refuses it rather than
return an arbitrary split.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from randvib.identification.circuit import COUPLING_PARAMETERS, ELECTRICAL_OUTPUTS

#: Relative standard error beyond which a direction of the parameters counts
#: as not determined by the data (its 95 % interval spans a factor of e).
UNDETERMINED = 0.5
#: Loading (of a unit direction) above which a parameter takes part in it.
LOADING = 0.3
#: Singular values below this share of the largest span the null space.
RANK_TOLERANCE = 1e-7
#: Generic frequencies (rad/s) of the nondimensional device, whose resonance is near 1.
FREQUENCIES = np.array([0.23, 0.41, 0.67, 0.93, 1.18, 1.57, 2.3, 3.9])
#: The order in which a refusal proposes parameters to fix: what a bench measures
#: most easily first (the coil's resistance with an ohmmeter, the coupling from a
#: blocked-magnet test), the mechanics' last.
FIX_PREFERENCE = ("r_coil", "alpha", "theta", "capacitance", "inductance", "c", "k")
#: Parameters whose identification the checks are about: the damping split,
#: the mass and the coupling's.
SPLIT_PARAMETERS = ("m", "c", "alpha", "r_coil", "inductance", "theta", "capacitance")


class IdentifiabilityError(ValueError):
    """The records cannot determine what was asked: one line naming what to add.

    ``result`` holds the fit when the local check refused it (None for the
    structural check, which refuses before fitting).
    """

    def __init__(self, message, result=None):
        super().__init__(message)
        self.result = result


@dataclass(frozen=True)
class Identifiability:
    """What the records fix, what they do not, and why.

    Attributes
    ----------
    determined : tuple of str
        Free parameters the records fix (structurally).
    undetermined : tuple of str
        Free parameters they cannot fix (a null direction moves them).
    reasons : tuple of str
        Why: the symmetries of the equations and what breaks or leaves them.
    remedies : tuple of str
        What to add so that the records fix every parameter (empty when they do).
    local : dict
        The check at the estimate (:func:`local_identifiability`), once fitted.
    """

    determined: tuple
    undetermined: tuple
    reasons: tuple
    remedies: tuple = ()
    local: dict = field(default_factory=dict)

    @property
    def identifiable(self) -> bool:
        return not self.undetermined

    def to_dict(self) -> dict:
        return {
            "determined": list(self.determined),
            "undetermined": list(self.undetermined),
            "reasons": list(self.reasons),
            "remedies": list(self.remedies),
            **({"local": self.local} if self.local else {}),
        }

    @classmethod
    def from_dict(cls, d: dict) -> Identifiability:
        return cls(
            determined=tuple(d.get("determined", ())),
            undetermined=tuple(d.get("undetermined", ())),
            reasons=tuple(d.get("reasons", ())),
            remedies=tuple(d.get("remedies", ())),
            local=dict(d.get("local", {})),
        )

    def refusal(self) -> str:
        """The one line that refuses the records (naming what to add)."""
        why = "; ".join(r for r in self.reasons if r.startswith("not fixed"))
        add = " or ".join(self.remedies) if self.remedies else "more informative records"
        return (
            f"the records cannot determine {', '.join(self.undetermined)} "
            f"({why.removeprefix('not fixed: ') or 'a symmetry of the equations'}): {add}"
        )


@dataclass(frozen=True)
class Configuration:
    """What the structural test reads: the model, the records' loads and channels.

    Attributes
    ----------
    coupling : str or None
        ``resistive``, ``inductive``, ``piezo`` or None.
    force_input : bool
        A force on the mass drives it (else base motion).
    records : tuple of (r_load, outputs)
        Each record's load (ohm, None without a coupling) and fitted channels.
    free : tuple of str
        The free parameters (shared ones: device, friction, coupling, k2).
    fixed : dict
        The fixed ones; a value of 0 removes a term (L = 0: a static coil).
    units : dict
        Each parameter's unit (a force-like one, in N..., scales with the mass).
    """

    coupling: str | None
    force_input: bool
    records: tuple
    free: tuple
    fixed: dict
    units: dict


def _generic_values(config: Configuration) -> dict:
    """Parameter values of order one at which the rank is generic (fixed zeros kept)."""
    rng = np.random.default_rng(20240534)
    names = sorted(set(config.free) | set(config.fixed))
    values = {name: float(np.exp(rng.uniform(-0.4, 0.4))) for name in names}
    values.update({"m": 1.0 * values.get("m", 1.0), "k": 1.7 * values.get("k", 1.0)})
    values.update({"c": 0.3 * values.get("c", 1.0), "r_coil": 0.45 * values.get("r_coil", 1.0)})
    for name, value in config.fixed.items():
        if value == 0.0:
            values[name] = 0.0
    return values


def _loads(config: Configuration) -> list:
    """The records' loads relative to the first (the structure depends on their ratios)."""
    first = next((r for r, _ in config.records if r is not None), 1.0)
    return [1.0 if r is None else r / first for r, _ in config.records]


def _transfer(config: Configuration, p: dict, r_load: float, kind: str, s):
    """The linearised device's transfer function from the input to channel ``kind``."""
    coupling = config.coupling
    current = np.zeros_like(s)  # the circuit's current (coil) or voltage (piezo) per unit z
    if coupling == "piezo":
        cp = p["capacitance"]
        voltage_per_z = p["theta"] * s / (cp * s + 1.0 / r_load)
        impedance = p["theta"] * voltage_per_z
        current = voltage_per_z
    elif coupling in ("resistive", "inductive"):
        ind = p.get("inductance", 0.0)
        current = p["alpha"] * s / (ind * s + r_load + p["r_coil"])
        impedance = p["alpha"] * current
    else:
        impedance = np.zeros_like(s)
    z = (1.0 if config.force_input else -p["m"]) / (p["m"] * s**2 + p["c"] * s + p["k"] + impedance)
    if kind == "relative_displacement":
        return z
    if kind == "relative_velocity":
        return s * z
    if coupling == "piezo":
        return z * current * (1.0 if kind == "voltage" else 1.0 / r_load)
    return z * current * (r_load if kind == "voltage" else 1.0)


def _invariants(config: Configuration, p: dict, motion: bool = False) -> np.ndarray:
    """What the records can show: transfer functions and the nonlinear forces per unit mass.

    ``motion``: the motion's own transfer functions (to z at every load)
    instead of the measured channels': a parameter change that leaves them
    unchanged leaves the whole trajectory, and so every nonlinear force, as
    it was (an exact symmetry of the nonlinear equations).
    """
    s = 1j * FREQUENCIES
    parts = []
    for r_load, (_, kinds) in zip(_loads(config), config.records, strict=True):
        for kind in ("relative_displacement",) if motion else kinds:
            h = _transfer(config, p, r_load, kind, s)
            parts += [h.real, h.imag]
    linear = {"m", "c", "k", *COUPLING_PARAMETERS.get(config.coupling, ())}
    for name in sorted(set(config.free) | set(config.fixed)):
        if name in linear or name not in p:
            continue
        force_like = config.units.get(name, "").startswith("N")
        parts.append(np.atleast_1d(p[name] / p["m"] if force_like else p[name]))
    return np.concatenate(parts)


def _jacobian(config: Configuration, values: dict, names, motion=False) -> np.ndarray:
    """d invariants / d log(parameter): Richardson-extrapolated central differences."""

    def column(name, h):
        up, down = dict(values), dict(values)
        up[name] *= np.exp(h)
        down[name] *= np.exp(-h)
        return (_invariants(config, up, motion) - _invariants(config, down, motion)) / (2 * h)

    h = 1e-3
    cols = [(4 * column(n, h / 2) - column(n, h)) / 3 for n in names]
    return np.column_stack(cols) if cols else np.zeros((1, 0))


def null_directions(config: Configuration, exact: bool = False) -> tuple[tuple, list]:
    """(free parameters the structure leaves undetermined, the null directions).

    With ``exact``, only the directions that also leave the motion unchanged
    (exact symmetries of the nonlinear equations, which no nonlinearity can
    break); the others change the unmeasured motion, so that a friction
    force or a cubic spring acting on it may still fix them.
    """
    values = _generic_values(config)
    names = [n for n in config.free if n in values]
    if not names:
        return (), []
    jac = _jacobian(config, values, names)
    norms = np.maximum(np.linalg.norm(jac, axis=0), 1e-300)
    _, sv, vt = np.linalg.svd(jac / norms, full_matrices=True)  # columns to unit length
    sv = np.concatenate([sv, np.zeros(max(0, len(names) - sv.size))])
    null = [vt[i] for i in range(len(names)) if sv[i] <= RANK_TOLERANCE * max(sv[0], 1e-300)]
    if exact and null:
        # the null space's part that keeps the motion's own transfer functions too
        motion = _jacobian(config, values, names, motion=True) / norms
        basis = np.array(null).T
        _, msv, mvt = np.linalg.svd(motion @ basis, full_matrices=True)
        msv = np.concatenate([msv, np.zeros(max(0, basis.shape[1] - msv.size))])
        top = max(np.linalg.norm(motion, 2), 1e-300)
        null = [basis @ mvt[i] for i in range(basis.shape[1]) if msv[i] <= RANK_TOLERANCE * top]
    loose = {names[j] for v in null for j in range(len(names)) if abs(v[j]) > 1e-6}
    return tuple(n for n in names if n in loose), null


def _blocking(config: Configuration) -> tuple:
    """The free parameters the records' linear response leaves undetermined."""
    return null_directions(config)[0]


def structural_identifiability(config: Configuration) -> Identifiability:
    """What the records of ``config`` fix, with the reasons and, if not all, the remedies.

    ``undetermined`` lists the free parameters that the records' linear
    response leaves free. Some such families are exact symmetries of the
    nonlinear equations too (the motion is unchanged: the mass, the coil's
    current scale, the static split); the others change the unmeasured
    motion, so that a friction force or a cubic spring could in principle
    fix them, but it does so too weakly to be relied on (measured in
    docs/identification.md: a coil with Coulomb friction seen through its
    voltage fits as well at the truth as at a point 55 % away along the
    family), so they are refused alike and the reasons say which kind each is.
    """
    undetermined = _blocking(config)
    exact = null_directions(config, exact=True)[0] if undetermined else ()
    determined = tuple(n for n in config.free if n not in undetermined)
    reasons = _reasons(config, undetermined)
    hidden = tuple(n for n in undetermined if n not in exact)
    if hidden:
        reasons += (
            f"not fixed: {', '.join(hidden)} move along a family that changes only the "
            "unmeasured motion, which the nonlinear forces alone fix too weakly to be relied on",
        )
    remedies = _remedies(config, undetermined) if undetermined else ()
    return Identifiability(determined, undetermined, reasons, remedies)


def _with(config: Configuration, **changes) -> Configuration:
    return Configuration(**{**config.__dict__, **changes})


def _remedies(config: Configuration, undetermined) -> tuple:
    """The single additions after which the structural test passes, as the user would give them."""
    out = []
    outputs = config.records[0][1]
    if "m" in undetermined:
        trial = _with(config, free=tuple(n for n in config.free if n != "m"), fixed={
            **config.fixed, "m": 1.0})  # fmt: skip
        if not _blocking(trial):
            out.append("the mass (`--m`)")
    if config.coupling is not None:
        first = config.records[0][0] or 1.0
        loads = {r for r, _ in config.records}
        for extra in (1, 2):
            added = tuple((first * (1.7 + 1.3 * i), outputs) for i in range(extra))
            if not _blocking(_with(config, records=config.records + added)):
                count = len(loads) + extra
                out.append(
                    f"records at {count} different loads (`identify A.csv B.csv ... --r-load RA "
                    "--r-load RB ...`)"
                )
                break
        electrical = [k for k in ELECTRICAL_OUTPUTS if k not in outputs]
        if electrical and not any(k in outputs for k in ELECTRICAL_OUTPUTS):
            trial = _with(config, records=tuple((r, k + ("voltage",)) for r, k in config.records))
            if not _blocking(trial):
                out.append("a voltage or current channel (`--output-kind voltage`)")
    if not any(k in outputs for k in ("relative_displacement", "relative_velocity")):
        trial = _with(
            config, records=tuple((r, k + ("relative_velocity",)) for r, k in config.records)
        )
        if not _blocking(trial):
            out.append("a displacement or velocity channel (`--output-kind relative_velocity`)")
    order = sorted(undetermined, key=lambda n: FIX_PREFERENCE.index(n) if n in FIX_PREFERENCE
                   else len(FIX_PREFERENCE))  # fmt: skip
    fixable = [
        n for n in order if n != "m" and not _blocking(_with(
            config, free=tuple(f for f in config.free if f != n), fixed={**config.fixed, n: 1.0}))
    ]  # fmt: skip
    if fixable:
        out.append(f"fix one of {', '.join(fixable)} (`--fix {fixable[0]}=VALUE`)")
    return tuple(out)


def _reasons(config: Configuration, undetermined) -> tuple:
    """Sentences on the symmetries: what breaks each, or that it stays (``not fixed: ...``)."""
    out = []
    outputs = {k for _, kinds in config.records for k in kinds}
    electrical = bool(outputs & set(ELECTRICAL_OUTPUTS))
    loads = {r for r, _ in config.records}
    if "m" in config.fixed:
        out.append("the mass is given, which fixes the forces' scale")
    elif config.force_input:
        out.append("a force input fixes the mass (Eq. 1 is not divided by an unknown m)")
    elif "m" in undetermined:
        out.append(
            "not fixed: under base excitation every force scales with the mass (Eq. 1 divided "
            "by m holds c/m, k/m, k3/m, F/m) and no channel fixes the forces' scale"
        )
    else:
        out.append(
            "the mass is fixed by the circuit: under base excitation the forces scale with m, "
            "but the measured voltage or current, at a known load, does not"
        )
    coupling = config.coupling
    if coupling is None:
        out.append(
            "no coupling is identified: c is the total damping c_m + c_e at the record's load"
        )
        return tuple(out)
    static = _is_static(config)
    split = {"c", *COUPLING_PARAMETERS[coupling]} & set(undetermined)
    if coupling != "piezo":
        if electrical:
            out.append(
                "a voltage or current channel at the known load fixes the coil's current scale "
                "(alpha, L and R_L + R_C, which the motion alone sees only as alpha^2/L and "
                "(R_L + R_C)/L)"
            )
        elif split:
            out.append(
                "not fixed: with the motion only, alpha -> s alpha, L -> s^2 L, R_L + R_C -> "
                "s^2 (R_L + R_C) leaves every measured channel unchanged"
            )
    if static:
        if split:
            out.append(
                "not fixed: without a circuit state the motion sees only the total damping "
                "c_m + c_e at each load and the output only the gain "
                + ("theta R_L" if coupling == "piezo" else "alpha R_L/(R_L + R_C)")
                + f"; {len(loads)} load(s) cannot split them"
            )
        else:
            out.append(
                f"records at {len(loads)} loads split the mechanical from the electrical damping"
            )
    elif not split and len(loads) >= 2:
        out.append(
            f"records at {len(loads)} loads split the mechanical from the electrical damping"
        )
    elif not split:
        tau = "L/(R_L + R_C)" if coupling == "inductive" else "R_L C_p"
        out.append(
            f"the circuit's time constant {tau} separates the mechanical from the electrical "
            "damping (resolving it needs a sample rate well above 1/(2 pi tau))"
        )
    return tuple(out)


def _is_static(config: Configuration) -> bool:
    if config.coupling == "resistive":
        return True
    name = "inductance" if config.coupling == "inductive" else "capacitance"
    return config.fixed.get(name) == 0.0


def local_identifiability(uncertainty, parameters: dict) -> dict:
    """The data's grip on the damping split, the mass and the coupling at the estimate.

    From the covariance of the estimated ``SPLIT_PARAMETERS`` in relative
    units (standard errors over |values|): its eigen-directions whose
    relative standard error exceeds :data:`UNDETERMINED`. A direction moving
    two or more parameters (loading above :data:`LOADING`) is an
    undetermined split (``split``); one moving a single parameter leaves
    only that one poorly determined (``poorly_determined``).

    Returns
    -------
    dict
        ``relative_errors`` (name -> se / |value|), ``split`` (list of
        parameter lists) and ``poorly_determined`` (names).
    """
    if uncertainty is None:
        return {}
    names = [n for n in SPLIT_PARAMETERS if n in uncertainty.names and parameters.get(n)]
    if not names:
        return {}
    index = [uncertainty.names.index(n) for n in names]
    se = np.array([uncertainty.standard_error[n] for n in names])
    scale = np.array([abs(parameters[n]) for n in names])
    corr = np.asarray(uncertainty.correlation)[np.ix_(index, index)]
    corr = np.where(np.isfinite(corr), corr, 0.0)
    rel = se / scale
    return undetermined_directions(names, corr * np.outer(rel, rel))


def undetermined_directions(names, relative_covariance) -> dict:
    """The eigen-directions of a relative covariance with a standard error above
    :data:`UNDETERMINED`: ``split`` (moving two or more parameters) and
    ``poorly_determined`` (one), with each parameter's ``relative_errors``."""
    cov = np.asarray(relative_covariance, dtype=float)
    eig, vec = np.linalg.eigh(cov)
    split, poor = [], []
    for k in range(len(names)):
        if not np.sqrt(max(eig[k], 0.0)) > UNDETERMINED:
            continue
        moved = [names[j] for j in range(len(names)) if abs(vec[j, k]) > LOADING]
        if len(moved) >= 2:
            split.append(moved)
        else:
            poor.extend(moved)
    rel = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return {
        "relative_errors": {n: float(r) for n, r in zip(names, rel, strict=True)},
        "split": split,
        "poorly_determined": sorted(set(poor)),
    }


def linear_information(config: Configuration, values: dict, spectra) -> dict:
    """The linearised device's own grip on the damping split, the mass and the coupling.

    A second opinion on :func:`local_identifiability`, free of the fit's own
    derivatives (which stick-slip and narrow valleys can make too sharp): the
    Fisher information of the device linearised about z = 0 at the estimate
    ``values``, each record's measured channels seen through their transfer
    functions H from the input, under the record's own input spectrum and the
    channel's residual noise (white, variance s^2):

        F_ij = sum_records sum_channels sum_f 2 Re(dH/du_i conj(dH/du_j)) |A(f)|^2 / (N s^2)

    (u = log of a parameter; positive frequencies of the DFT A of the N-sample
    input). It sees what the linear response carries: two loads too close, a
    circuit time constant below what the sample rate resolves. The other
    parameters (k3, friction) are held at the estimate.

    Parameters
    ----------
    config : Configuration
        The fit's records (their actual loads) and free parameters.
    values : dict
        The estimate (SI units).
    spectra : sequence of (frequencies (rad/s), |A|^2 weights, {kind: noise variance})
        One per record, in the records' order.
    """
    linear = {"m", "c", "k", *COUPLING_PARAMETERS.get(config.coupling, ())}
    names = [n for n in config.free if n in linear and values.get(n)]
    if not names:
        return {}
    p = {n: float(v) for n, v in values.items() if np.ndim(v) == 0}
    info = np.zeros((len(names), len(names)))
    for (r_load, _), (omega, weight, noise) in zip(config.records, spectra, strict=True):
        s = 1j * omega
        for kind, variance in noise.items():
            derivatives = []
            for name in names:
                up, down = dict(p), dict(p)
                up[name] *= np.exp(1e-6)
                down[name] *= np.exp(-1e-6)
                derivatives.append(
                    (
                        _transfer(config, up, r_load, kind, s)
                        - _transfer(config, down, r_load, kind, s)
                    )
                    / 2e-6
                )
            d = np.array(derivatives)
            info += 2.0 * np.real(d @ (np.conj(d) * weight).T) / variance
    covariance = np.linalg.pinv(info)
    split = [n for n in names if n in SPLIT_PARAMETERS]
    index = [names.index(n) for n in split]
    return undetermined_directions(split, covariance[np.ix_(index, index)]) if split else {}
