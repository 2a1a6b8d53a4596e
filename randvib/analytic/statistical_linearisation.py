"""Statistical (equivalent) linearisation of the harvester under any excitation: one route.

The nonlinear device ``m z'' + c z' + k z + k3 z^3 + F(z') = -m y''`` is
replaced by the linear one with

    c_eq = c + E[v F(v)] / E[v^2],    k_eq = k + 3 k3 E[z^2],

the expectations taken under a zero-mean Gaussian response (paper Eq. 19;
docs/conventions.md, "Beyond the paper"). :func:`linearise` is the one route
every caller takes (``randvib.predict(method="linearisation")``, the Monte
Carlo step check and random start):

* under white noise with a resistive coupling, the fast path of
  :mod:`randvib.analytic.linearisation`: E[v^2] = S m / (4 c_eq) for any
  k_eq, so the conditions decouple into Eq. 19-20 and, for Coulomb friction,
  Eq. 30/32 in closed form; it broadcasts over array parameters and levels;
* otherwise, :func:`statistical_linearisation`: the variances E[v^2], E[z^2]
  are those of the linear device (m, c_eq, k_eq) under the excitation
  (:mod:`randvib.analytic.linear_response`: a Lyapunov equation for rational
  spectra, the spectral integral for any), and the two conditions are one
  fixed point in (log E[v^2], log E[z^2]), solved by Powell's hybrid method
  (scipy ``root(method="hybr")``) from the linear device's response. Under
  a coloured spectrum k_eq moves the resonance against the spectrum, and the
  spring matters.

:func:`statistical_linearisation` solves the fixed point under white noise
too, when asked directly (its full result has the response spectra); there
it equals the fast path to rounding.

A coupling with a circuit state (coil inductance, piezo capacitance;
:mod:`randvib.models.coupling`) stays a state of the linear system
(:func:`randvib.analytic.linear_response.device_block`): c_eq then holds the
mechanical and friction damping only, the circuit's mean square E[i^2] or
E[V^2] comes from the same Lyapunov solution (or spectral integral), and the
power from it. The circuit makes the spring matter under white noise too.

:class:`Linearisation` is the method ``"linearisation"`` of
:func:`randvib.predict`, declared as the family of
:mod:`randvib.analytic.method` declares its members.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from randvib import _display, formatting
from randvib._validation import check_choice, check_scalar_device
from randvib.analytic.fixed_point import TrialUndefined, solve
from randvib.analytic.harmonic_linearisation import combined_linearisation
from randvib.analytic.linear_response import (
    VARIANCE_METHODS,
    ResponseSpectra,
    device_block,
    lyapunov_shaping,
    response_spectra,
    variances_through,
)
from randvib.analytic.linearisation import (
    LinearisedDevice,
    linear_power,
    white_noise_linearisation,
)
from randvib.analytic.method import (
    AnalyticMethod,
    Validity,
    is_linear_device,
    non_white,
    white_level,
)
from randvib.analytic.power_prediction import PowerPrediction, gaussian_exceedance
from randvib.analytic.transient import solve_transient
from randvib.models.combined import parts_of
from randvib.models.excitation import Excitation, as_excitation
from randvib.models.harvester import Harvester
from randvib.models.potential import CONFINING
from randvib.quantities import unit


@dataclass(frozen=True, eq=False)
class LinearisationResult(LinearisedDevice):
    """Statistical linearisation of a harvester under an excitation (SI units).

    The numbers of :class:`~randvib.analytic.linearisation.LinearisedDevice`
    (scalars here: c_eq, k_eq, the variances, the powers, the circuit's
    mean square and ``method``, ``lyapunov`` or ``spectral``) with what they
    were computed for.

    Attributes
    ----------
    harvester : Harvester
    excitation : Excitation
    """

    harvester: Harvester
    excitation: Excitation

    def block(self):
        """The linearised device (with its circuit state) as a StateSpace."""
        h = self.harvester
        return device_block(h.m, self.c_eq, self.k_eq, h.electrical)

    def response_spectra(self, frequency) -> ResponseSpectra:
        """PSDs of z, v and the electrical power's distribution at ``frequency`` (Hz)."""
        f = np.asarray(frequency, dtype=float)
        spectra = response_spectra(self.block(), self.excitation, f)
        return ResponseSpectra(
            frequency=f,
            excitation=self.excitation.psd(f),
            displacement=spectra["z"],
            velocity=spectra["v"],
            power=linear_power(self.harvester, spectra["v"], _state(self.harvester, spectra))[0],
        )

    def to_dict(self) -> dict:
        """The numbers and the excitation's parameters, ready for JSON."""
        keys = ("c_eq", "k_eq", "velocity_variance", "displacement_variance")
        out = {key: getattr(self, key) for key in keys}
        out.update(power_electrical=self.power_electrical, power_load=self.power_load)
        if self.circuit_variance is not None:
            out["circuit_variance"] = self.circuit_variance
        out.update(method=self.method, excitation=self.excitation.parameters())
        return out

    def _rows(self):
        named = (
            "power_electrical",
            "power_load",
            "c_eq",
            "k_eq",
            "velocity_variance",
            "displacement_variance",
            "circuit_variance",
        )
        return [
            (name, formatting.compact(getattr(self, name)), unit(name, self.harvester.electrical))
            for name in named
            if getattr(self, name) is not None
        ]

    def to_frame(self):
        """The numbers as a one-row :class:`pandas.DataFrame`.

        Columns as in :meth:`to_dict`, the excitation's parameters flattened
        to ``excitation_<name>`` columns.
        """
        pd = _display.pandas()
        out = self.to_dict()
        excitation = out.pop("excitation")
        # the excitation's kind stays `excitation`; its parameters get the prefix
        out["excitation"] = excitation.pop("excitation", None)
        out.update({f"excitation_{key}": value for key, value in excitation.items()})
        return pd.DataFrame([out])

    def __repr__(self) -> str:
        fields = ", ".join(f"{name}={value}" for name, value, _ in self._rows())
        return f"LinearisationResult({self.excitation!r}, {self.method}; {fields})"

    def __str__(self) -> str:
        """The table of :meth:`_repr_html_` as plain text (``print(result)``)."""
        title = f"Statistical linearisation ({self.method}) under {self.excitation!r}"
        return _display.text_table(title, self._rows())

    def _repr_html_(self) -> str:
        title = f"Statistical linearisation ({self.method}) under {self.excitation!r}"
        return _display.html_table(title, self._rows())


def _check_harvester(harvester: Harvester):
    # scalar parameters (device, friction law, coupling), an array refused by name
    check_scalar_device(harvester, "statistical_linearisation")
    friction = harvester.friction
    if friction is not None and not friction.has_equivalent_damping:
        raise ValueError(
            f"statistical linearisation needs a memoryless friction law; {friction.name!r} "
            "has internal state. Use randvib.simulate for it."
        )
    # A spring is needed for a stationary z (the free mass has none; under white
    # noise randvib.predict(method="linearisation") gives its velocity statistics).
    harvester.potential.require(
        "statistical_linearisation", CONFINING, "randvib.predict under white noise"
    )
    return None if friction is None or friction.vanishes else friction


def statistical_linearisation(
    harvester: Harvester, excitation, *, method: str = "auto"
) -> LinearisationResult:
    """Gaussian statistical linearisation for any excitation.

    Parameters
    ----------
    harvester : Harvester
        Device with scalar parameters and a memoryless friction law (or none).
    excitation : Excitation or float
        The base excitation; a number S is white noise of one-sided PSD S
        ((m/s^2)^2/Hz).
    method : {"auto", "lyapunov", "spectral"}
        How the linear device's variances are computed
        (:func:`randvib.analytic.linear_response.output_variances`).

    Returns
    -------
    LinearisationResult

    Raises
    ------
    ValueError
        For a friction law with memory, array parameters, an unknown method,
        a potential that is not confining (the free mass included), or a
        double well for which no zero-mean Gaussian solution with k_eq > 0
        exists (a narrow band far above the wells' frequency).
    RuntimeError
        If the fixed point does not converge.

    Examples
    --------
    >>> import randvib as rv
    >>> device = rv.preset("figure9")
    >>> res = rv.statistical_linearisation(device, rv.BandPass(1.0, 8.0, 0.1))
    >>> print(f"P_e = {res.power_electrical:.4e} W, c_eq = {res.c_eq:.4f} Ns/m, k_eq = {res.k_eq:.2f} N/m")
    P_e = 1.1147e-03 W, c_eq = 0.2438 Ns/m, k_eq = 58.33 N/m
    >>> white = rv.statistical_linearisation(device, rv.White(1.0))  # Eq. 32 exactly
    >>> print(f"{white.power_electrical:.4e} W")
    2.4619e-03 W
    """
    excitation = as_excitation(excitation)
    if has_lines_or_shocks(excitation):
        raise ValueError(
            f"statistical_linearisation takes one random input; the {excitation.name} input's "
            "tones or shocks are linearised with it by randvib.combined_linearisation"
        )
    friction = _check_harvester(harvester)
    m, c, k, k3 = (float(x) for x in (harvester.m, harvester.c, harvester.k, harvester.k3))
    # the route and the excitation's filter, once for the whole fixed point
    check_choice("method", method, VARIANCE_METHODS)
    shaping = lyapunov_shaping(excitation, method)
    used = method if method != "auto" else ("lyapunov" if shaping else "spectral")

    def equivalent(log_variances):
        var_v, var_z = np.exp(log_variances)
        increment = (
            0.0
            if friction is None
            else float(friction.equivalent_damping_increment(np.sqrt(var_v)))
        )
        k_eq = k + 3.0 * k3 * var_z
        if k <= 0:
            # A trial E[z^2] below -k/(3 k3) would make the linear device
            # unstable: the floor keeps the solver's trial steps defined, and a
            # "solution" on the floor is refused below.
            k_eq = max(k_eq, 1e-6 * k_start)
        return c + increment, k_eq

    def variances(c_eq, k_eq):
        return variances_through(
            device_block(m, c_eq, k_eq, harvester.electrical), excitation, shaping
        )

    def response(c_eq, k_eq):
        out = variances(c_eq, k_eq)
        return np.log([out["v"], out["z"]])

    def residual(x):
        # The solver's trial steps may leave the region where the linearised
        # device is stable and its variances finite (a narrow band near the
        # resonance of a soft or double-well device): that is the solver's
        # failure to find a fixed point, reported as such by solve, not a
        # property of the user's device.
        with np.errstate(all="ignore"):
            c_eq, k_eq = equivalent(x)
            trial = TrialUndefined(f"c_eq = {c_eq:.3g} Ns/m, k_eq = {k_eq:.3g} N/m")
            if not (np.isfinite(c_eq) and np.isfinite(k_eq)):
                raise trial
            try:
                out = response(c_eq, k_eq) - x
            except (ValueError, np.linalg.LinAlgError):
                raise trial from None  # unstable, or a stiffness on the floor (rounds to 0)
        if not np.all(np.isfinite(out)):
            raise trial
        return out

    # Start from the linear device; without viscous damping, from 5 % of critical.
    # Without a positive k (double well, pure cubic) the linear device is
    # unstable: start from the white-noise closure's k_eq at the level S instead.
    k_start = k if k > 0 else _white_noise_k_eq(m, c, k, k3, _typical_level(excitation))
    c_start = c if c > 0 else 0.1 * np.sqrt(k_start * m)
    if friction is None and k3 == 0.0 and k > 0 and c > 0:
        # A linear device is its own linearisation: the fixed point is its response,
        # exactly. The root finder would spend six more solutions of the linear device
        # to confirm it (a design's search on a linear device predicts hundreds of them).
        x = response(c, k)
    else:
        x = solve(residual, response(c_start, k_start))
    c_eq, k_eq = equivalent(x)
    var_v, var_z = np.exp(x)
    _require_positive_stiffness(harvester, excitation, k + 3.0 * k3 * var_z)
    state = _state(harvester, variances(c_eq, k_eq))
    power, load = linear_power(harvester, var_v, state)
    return LinearisationResult(
        harvester=harvester,
        excitation=excitation,
        c_eq=float(c_eq),
        k_eq=float(k_eq),
        velocity_variance=float(var_v),
        displacement_variance=float(var_z),
        power_electrical=float(power),
        power_load=None if load is None else float(load),
        method=used,
        circuit_variance=None if state is None else float(state),
    )


def linearise(harvester: Harvester, psd) -> LinearisedDevice:
    """The one route of statistical linearisation: the fast path where it applies.

    White noise (a level S, an array of levels, or :class:`White`) with a
    resistive coupling: the closed forms of Eq. 19-20/30
    (:func:`~randvib.analytic.linearisation.white_noise_linearisation`,
    broadcasting). A non-white excitation or a circuit state: the fixed point
    (:func:`statistical_linearisation`, scalar parameters).

    Returns
    -------
    LinearisedDevice
        A :class:`LinearisationResult` on the fixed point.
    """
    if takes_fast_path(harvester, psd):
        return white_noise_linearisation(harvester, white_level(psd))
    return statistical_linearisation(harvester, psd)


def takes_fast_path(harvester: Harvester, psd) -> bool:
    """White noise with a resistive coupling: Eq. 19-20 hold for any k_eq (E[v^2] = S m/(4 c_eq))."""
    return not harvester.has_circuit and not non_white(psd)


class LinearisationValidityWarning(RuntimeWarning):
    """Statistical linearisation is used where friction dominates the dissipation."""


#: Largest share of the dissipation taken by friction, 1 - c / c_eq (from the
#: candidate's own c_eq, white noise), at which statistical linearisation is
#: used without a warning. Its power against fpk (the reference), Coulomb
#: friction, monostable devices (c = 0.001 to 0.1 Ns/m, S = 0.005 to 1):
#: -3.4 % at a share of 0.62, -5.6 % at 0.74, -7.5 % at 0.82, -11.3 % at
#: 0.92, -12.9 % at 0.955, -16.6 % at 0.999 (the light-damping case
#: c_m = c_e = 0.0005, Fc = 5.8 mN, S = 0.005), growing monotonically with the
#: share; 0.85 warns before the error reaches 10 %.
LINEARISATION_FRICTION_SHARE_LIMIT = 0.85

#: Largest share of the equivalent stiffness taken by the cubic spring,
#: 1 - k / k_eq = 3 k3 E[z^2] / k_eq, at which statistical linearisation is
#: used without a warning under a non-white excitation or with a circuit state
#: (there k_eq shapes the response; under white noise with a resistive
#: coupling it drops out of Eq. 20). From the cross-check campaign
#: (tests/calibration/crosscheck.py, 260 sampled devices against Monte Carlo,
#: a coil's L/R resolved by the step): of the 32 monostable devices there
#: whose friction share is below 0.85, the 11 with a share below 0.2 all
#: agreed, and all 6 off by more than 10 % + the Monte Carlo interval (0.52x to
#: 1.33x) had a share of 0.26 or more (21 devices); a double well (k < 0,
#: share above 1) was off on 23 of 36 devices (0.29x to 47x), at barriers of
#: 0.1 to 35 m E[v^2] alike, so it always warns.
LINEARISATION_STIFFNESS_SHARE_LIMIT = 0.2

#: Largest |kurtosis - 3| of a non-Gaussian random input (a translation process,
#: a record) at which statistical linearisation's Gaussian answer is given
#: without a warning on a nonlinear device. Measured
#: (tests/calibration/non_gaussian_limits.py, results in non_gaussian_limits.txt:
#: the paper's and a Duffing device, with and without friction, band-pass and
#: Kanai-Tajimi floors, kurtosis 3, 4, 6, 10, 128 paths x 20 s): the power stays
#: within 5 % (+ its 95 % interval) up to kurtosis 10 (largest 5.1 +- 2.8 %), but
#: the Gaussian stroke exceedance, within its interval at kurtosis 3 for the
#: paper's device without friction (+5.8 +- 10 %), is 11 to 37 % low there at
#: kurtosis 4 and 36 to 59 % low at 10: the limit lies below |kurtosis - 3| = 1,
#: the first step measured; half of it is taken.
NON_GAUSSIAN_KURTOSIS_LIMIT = 0.5


class Linearisation(AnalyticMethod):
    """Statistical linearisation (paper Eq. 19-32 under white noise, the fixed point beyond).

    The Gaussian closure of :func:`linearise`: exact power without friction
    under white noise for any potential, low by up to 9 % at strong friction
    and blind to k3 there (Eq. 30 has no spring); under a coloured spectrum or
    with a circuit state the spring and the circuit enter through the linear
    response. Its displacement and stroke exceedance are Gaussian estimates
    (far off for a double well, see :mod:`randvib.analytic.linearisation`).
    """

    name = "linearisation"
    title = "statistical linearisation"
    summary = "Gaussian closure, paper Eq. 32, microseconds, low by up to 9 % at strong friction"
    coloured = True
    tones = True
    non_gaussian = True
    circuit = True
    assemblies = True
    stroke_exceedance = True
    transient = True
    validity = (
        Validity(
            "friction_share",
            LINEARISATION_FRICTION_SHARE_LIMIT,
            "warns",
            "the share of the dissipation taken by friction, 1 - c / c_eq (white noise): "
            "the Gaussian closure underestimates the power increasingly beyond it (by 10 % "
            "near 0.9, 17 % near 1); with a circuit state or coloured input the share is "
            "E[v F] over all the dissipation, and the power is 0.29x to 1.14x",
        ),
        Validity(
            "stiffness_share",
            LINEARISATION_STIFFNESS_SHARE_LIMIT,
            "warns",
            "the share of the equivalent stiffness taken by the cubic spring, 1 - k / k_eq, "
            "under a non-white excitation or with a circuit state (where k_eq shapes the "
            "response): the Gaussian closure misplaces the resonance beyond it (0.52x to "
            "1.33x for a hardening spring, 0.29x to 47x for a double well)",
        ),
        Validity(
            "tone_stiffness_share",
            LINEARISATION_STIFFNESS_SHARE_LIMIT,
            "warns",
            "under tones, the combined harmonic-and-random linearisation's stiffness share, "
            "1 - k / k_eq of the random part (the largest; each tone's is smaller), with the "
            "friction share as above: of 72 cases (tests/calibration/non_gaussian_limits.py: "
            "the paper's and a Duffing device, Fc 0 and 5.8 mN, tones of 0.25 to 4 m/s^2 at "
            "0.8, 1 and 1.25 f_n on band-pass and Kanai-Tajimi floors) the 36 inside both "
            "limits erred by at most 1.7 % in power; beyond, by more than 5 % (+ the interval) "
            "from a share of 0.34, up to 25 % (a strong tone above a Duffing's resonance)",
        ),
        Validity(
            "input_kurtosis",
            NON_GAUSSIAN_KURTOSIS_LIMIT,
            "warns",
            "|kurtosis - 3| of a non-Gaussian random input (translation process, record) on a "
            "nonlinear device, answered as the Gaussian input of its spectrum: the power held "
            "within 5 % up to kurtosis 10, the stroke exceedance was 11 to 37 % low at "
            "kurtosis 4 (tests/calibration/non_gaussian_limits.py); a linear device's second "
            "moments are exact for any marginal",
        ),
        # assemblies (randvib.analytic.assembly_linearisation): per element, the
        # single-mass limits, checked against an independent simulator of assemblies
        Validity(
            "element_friction_share",
            LINEARISATION_FRICTION_SHARE_LIMIT,
            "warns",
            "an assembly element's friction power over all the power dissipated on its "
            "coordinate; the single-mass limit, checked on a host with a harvester "
            "(tests/calibration/assembly_linearisation.py): -5 % at 0.76, -21 % at 0.92",
        ),
        Validity(
            "element_stiffness_share",
            LINEARISATION_STIFFNESS_SHARE_LIMIT,
            "warns",
            "the cubic spring's share 1 - k_dir / k_eq of the stiffness on an assembly "
            "element's coordinate; the single-mass limit, checked on a host with a harvester "
            "(tests/calibration/assembly_linearisation.py): within 6 % up to 0.14, -7.5 % to "
            "-21.5 % from 0.35 to 0.64",
        ),
    )

    def potentials_under(self, harvester: Harvester, psd) -> tuple[str, ...]:
        # The free mass has no stationary z for the fixed point's linear device;
        # under white noise with a resistive coupling its velocity is all Eq. 20 needs.
        return self.potentials if takes_fast_path(harvester, psd) else CONFINING

    def solve(self, harvester: Harvester, psd) -> PowerPrediction:
        if not takes_fast_path(harvester, psd) and np.ndim(psd) > 0:
            # the fixed point takes one white level at a time (a circuit state):
            # solve each and broadcast the fields over the levels' shape, as the fast path does
            levels = np.asarray(psd, dtype=float)
            points = [self.solve(harvester, float(level)) for level in levels.ravel()]
            return _stacked(points, levels.shape)
        if has_lines_or_shocks(psd):
            return _combined_prediction(self.name, harvester, psd)
        _warn_non_gaussian(harvester, psd)
        lin = linearise(harvester, psd)
        vv, zz = lin.velocity_variance, lin.displacement_variance
        exceedance = None if zz is None else gaussian_exceedance(harvester.stroke, zz)
        if lin.method == "white-noise":
            _warn_friction_dominated(harvester, lin.c_eq, vv)
            mean_abs = np.sqrt(2.0 / np.pi * np.asarray(vv))  # Gaussian v
            return PowerPrediction.from_white_noise(
                harvester, self.name, vv, zz, mean_abs, psd, exceedance
            )
        _warn_general(harvester, lin)
        return PowerPrediction(
            method=self.name,
            c_eq=lin.c_eq,
            velocity_variance=vv,
            displacement_variance=zz,
            mean_abs_velocity=float(np.sqrt(2.0 / np.pi * vv)),  # Gaussian v
            power_electrical=lin.power_electrical,
            power_load=lin.power_load,
            circuit_mean_square=lin.circuit_variance,
            stroke_exceedance=None if exceedance is None else float(exceedance),
            electrical=harvester.electrical,
        )

    def solve_transient(self, harvester: Harvester, event, times, t_end, start):
        """Time-dependent statistical linearisation (:mod:`randvib.analytic.transient`).

        The Lyapunov differential equation of the linear(ised) system with
        k_eq(t), c_eq(t) from the Gaussian closure at each time: exact for the
        linear device.
        """
        return solve_transient(self.name, harvester, event, times, t_end, start)


def has_lines_or_shocks(psd) -> bool:
    """Whether ``psd`` holds tones or a shock train (the combined linearisation's inputs)."""
    if not isinstance(psd, Excitation):
        return False
    _, tones, shocks = parts_of(psd)
    return bool(tones) or shocks is not None


def _combined_prediction(name: str, harvester: Harvester, psd) -> PowerPrediction:
    """The prediction of the combined harmonic-and-random linearisation (tones, shocks)."""
    check_scalar_device(harvester, "statistical linearisation under tones")
    _check_harvester(harvester)
    _warn_non_gaussian(harvester, psd)
    lin = combined_linearisation(harvester, psd)
    _warn_general(harvester, lin, where="tones" if lin.tones else "shocks")
    return PowerPrediction(
        method=name,
        c_eq=lin.c_eq,
        velocity_variance=lin.velocity_variance,
        displacement_variance=lin.displacement_variance,
        mean_abs_velocity=lin.mean_abs_velocity,
        power_electrical=lin.power_electrical,
        power_load=lin.power_load,
        circuit_mean_square=lin.circuit_variance,
        stroke_exceedance=lin.stroke_exceedance(harvester.stroke),
        tones=lin.tones or None,
        electrical=harvester.electrical,
    )


def _warn_friction_dominated(harvester: Harvester, c_eq, velocity_variance) -> None:
    """LinearisationValidityWarning at the point of largest friction share beyond the limit.

    Only at points with a finite positive answer: the others are refused by
    the driver, which a warning must not precede.
    """
    with np.errstate(all="ignore"):
        c = np.asarray(harvester.c_m + harvester.c_e, dtype=float)
        share = 1.0 - c / np.asarray(c_eq, dtype=float)
        vv = np.asarray(velocity_variance, dtype=float)
        answered = np.isfinite(vv) & (vv > 0) & np.isfinite(c_eq) & np.isfinite(c)
    share = np.where(np.isfinite(share) & answered, share, 0.0)
    worst = float(np.max(share)) if share.size else 0.0
    if worst > LINEARISATION_FRICTION_SHARE_LIMIT:
        warnings.warn(
            f"friction takes {worst:.1%} of the dissipation (1 - c / c_eq), beyond "
            f"{LINEARISATION_FRICTION_SHARE_LIMIT:.0%}: statistical linearisation is then low "
            "by about 8 % to 17 % (as the share nears 1); method='fpk-fast' or method='fpk' "
            "resolves it",
            LinearisationValidityWarning,
            stacklevel=4,
        )


def _warn_non_gaussian(harvester: Harvester, psd) -> None:
    """LinearisationValidityWarning naming the kurtosis of a non-Gaussian random input.

    Beyond :data:`NON_GAUSSIAN_KURTOSIS_LIMIT` (|kurtosis - 3|) on a nonlinear
    device; a linear device's second moments depend on the spectrum alone
    and are exact for any marginal.
    """
    if not isinstance(psd, Excitation) or is_linear_device(harvester):
        return
    random = parts_of(psd)[0]
    if random is None:
        return
    kurtosis = float(random.kurtosis)
    if abs(kurtosis - 3.0) > NON_GAUSSIAN_KURTOSIS_LIMIT:
        warnings.warn(
            f"the {random.name} input has kurtosis {kurtosis:.3g} (a Gaussian's is 3): "
            "statistical linearisation answers as for the Gaussian input of the same spectrum; "
            f"beyond |kurtosis - 3| = {NON_GAUSSIAN_KURTOSIS_LIMIT:g} its stroke exceedance "
            "errs by more than 5 % (11 to 37 % low at kurtosis 4, Monte Carlo campaign; the "
            "power held within 5 % up to kurtosis 10 there); use Monte Carlo (randvib.simulate)",
            LinearisationValidityWarning,
            stacklevel=4,
        )


def _warn_general(harvester: Harvester, lin, where: str | None = None) -> None:
    """LinearisationValidityWarning for a fixed point off the white-noise fast path.

    Under a non-white excitation or with a circuit state: friction's share of
    all the dissipation, (c_eq - c) E[v^2] / ((c_eq - c_m) E[v^2] + P_e) with
    c the viscous damping the linear device already has, beyond
    :data:`LINEARISATION_FRICTION_SHARE_LIMIT`, and the cubic spring's share
    of k_eq beyond :data:`LINEARISATION_STIFFNESS_SHARE_LIMIT`. Only for a
    finite positive answer: the others are refused by the driver first.
    """
    vv, power = float(lin.velocity_variance), float(lin.power_electrical)
    if not (np.isfinite(vv) and vv > 0 and np.isfinite(power)):
        return
    friction_power = max(float(lin.c_eq) - float(harvester.c), 0.0) * vv
    dissipated = friction_power + float(harvester.c_m) * vv + power
    share = friction_power / dissipated if dissipated > 0 else 0.0
    stiffness = 1.0 - float(harvester.k) / float(lin.k_eq) if lin.k_eq > 0 else np.inf
    limit = LINEARISATION_STIFFNESS_SHARE_LIMIT
    why = []
    if share > LINEARISATION_FRICTION_SHARE_LIMIT:
        why.append(
            f"friction takes {share:.1%} of the dissipation, beyond "
            f"{LINEARISATION_FRICTION_SHARE_LIMIT:.0%}"
        )
    if harvester.k < 0:
        why.append(
            "the double well's Gaussian closure (k_eq from E[z^2] about z = 0) misplaces its "
            "resonance under this input"
        )
    elif stiffness > limit:
        why.append(
            f"the cubic spring takes {stiffness:.0%} of the equivalent stiffness k_eq "
            f"= {float(lin.k_eq):.4g} N/m, beyond {limit:.0%}"
        )
    if why:
        if where is None:
            where = "a circuit state" if harvester.has_circuit else "a non-white excitation"
        warnings.warn(
            f"{'; '.join(why)}: with {where} statistical linearisation can then be off by "
            "more than 10 % (Monte Carlo campaign); use Monte Carlo (randvib.simulate)",
            LinearisationValidityWarning,
            stacklevel=4,
        )


#: The method's declaration (:data:`randvib.analytic.prediction.METHODS` holds it).
LINEARISATION = Linearisation()


def _stacked(points: list[PowerPrediction], shape: tuple) -> PowerPrediction:
    """One prediction whose fields are arrays of ``shape`` over the scalar ``points``."""
    fields = {}
    for name in ("c_eq", "velocity_variance", "displacement_variance", "mean_abs_velocity",
                 "power_electrical", "power_load", "circuit_mean_square", "stroke_exceedance"):  # fmt: skip
        values = [getattr(point, name) for point in points]
        fields[name] = None if values[0] is None else np.asarray(values, dtype=float).reshape(shape)
    return PowerPrediction(method=points[0].method, electrical=points[0].electrical, **fields)


def _state(harvester: Harvester, outputs: dict):
    """The circuit state's entry of ``outputs`` (variance or PSD), or None without one."""
    return outputs[harvester.electrical.state_name] if harvester.has_circuit else None


def _require_positive_stiffness(harvester, excitation, k_eq):
    """Refuse a fixed point on the solver's stiffness floor: no zero-mean solution exists."""
    if k_eq <= 0:
        raise ValueError(
            "statistical linearisation has no zero-mean Gaussian solution with k_eq > 0 for "
            f"this {harvester.potential.kind} device under the {excitation.name} excitation "
            "(the response is not a zero-mean Gaussian about the barrier): use Monte Carlo "
            "(randvib.simulate)"
        )


def _white_noise_k_eq(m, c, k, k3, level):
    """k_eq = (k + sqrt(k^2 + 12 k3 m sigma_v^2))/2 with sigma_v^2 = S m/(4c) (N/m)."""
    var_v = level * m / (4.0 * c) if c > 0 else level  # any positive scale will do
    return 0.5 * (k + np.sqrt(k * k + 12.0 * k3 * m * var_v))


def _typical_level(excitation) -> float:
    """A PSD level ((m/s^2)^2/Hz) of the excitation: its ``level``, else variance / band."""
    level = getattr(excitation, "level", None)
    if level is None:
        lo, hi = excitation.support
        level = excitation.variance / (hi - lo)
    return float(level)
