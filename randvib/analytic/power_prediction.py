"""What an analytic method predicts: :class:`PowerPrediction`.

Every method of the family (:mod:`randvib.analytic.method`) returns one;
:meth:`PowerPrediction.from_white_noise` fills the fields that follow from
the velocity variance under white noise (the electrical power, c_eq, the load's
share), which every method computes the same way.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
from scipy import special

from randvib import _display, formatting
from randvib._validation import scalar_or_array
from randvib.models.harvester import Harvester
from randvib.quantities import unit


@dataclass(frozen=True)
class PowerPrediction:
    """Stationary statistics predicted by an analytic method (SI units).

    Attributes
    ----------
    method : str
    c_eq : float or ndarray
        Equivalent viscous damping (Ns/m), defined as S m / (4 E[v^2]) under
        white noise; under another excitation the statistical linearisation's
        c + E[v F(v)] / E[v^2] (the two agree under white noise).
    velocity_variance : float or ndarray
        E[z'^2] ((m/s)^2) (paper Eq. 20).
    displacement_variance : float or ndarray
        E[z^2] (m^2).
    mean_abs_velocity : float or ndarray
        E|z'| (m/s).
    power_electrical : float or ndarray
        E[P_e] = c_e E[z'^2] (W) (paper Eq. 31-32).
    power_load : float, ndarray or None
        E[i^2 R_L] (W), when the harvester has a circuit.
    circuit_mean_square : float or None
        E[i^2] (A^2) or E[V^2] (V^2) of a circuit state (inductive or piezo
        coupling); None without one (and left out of :meth:`to_dict`).
    electrical : Coupling or None
        The device's coupling, which sets the unit shown for
        ``circuit_mean_square``; not a result (left out of :meth:`to_dict`).
    inputs : dict or None
        For a broadcast prediction, its array-valued inputs by name (``psd``,
        device parameters such as ``c_m``), which :meth:`to_frame` writes as
        columns so that its rows can be told apart; not a result.
    stroke_exceedance : float, ndarray or None
        P(|z| > stroke), the stationary fraction of time beyond the
        harvester's stroke; None without a stroke, for the free mass and for
        methods that do not give it (their ``stroke_exceedance`` declaration
        is False).
    tones : tuple of ToneResponse or None
        Under tones, each one's response amplitudes and equivalents
        (:mod:`randvib.analytic.harmonic_linearisation`); None otherwise
        (and left out of :meth:`to_dict`).
    power_stored, power_coil_loss, power_diode_loss, power_mechanical : float or None
        With a diode bridge (:mod:`randvib.models.rectifier`): the stored
        power, the coil's and the diodes' losses and c_m E[z'^2] + E[z' F]
        (W); None otherwise (and left out of :meth:`to_dict`). Linearisation's is the Gaussian estimate
        erfc(stroke / sqrt(2 E[z^2])) (approximate; far off for a double
        well, see :mod:`randvib.analytic.linearisation`).

    ``displacement_variance`` is None for the free mass (k = k3 = 0): its
    displacement has no stationary law.
    """

    method: str
    c_eq: object
    velocity_variance: object
    displacement_variance: object
    mean_abs_velocity: object
    power_electrical: object
    power_load: object = None
    circuit_mean_square: object = None
    stroke_exceedance: object = None
    power_stored: object = None
    power_coil_loss: object = None
    power_diode_loss: object = None
    power_mechanical: object = None
    #: under tones: each tone's share of the response (a tuple of
    #: :class:`~randvib.analytic.harmonic_linearisation.ToneResponse`); None otherwise
    tones: object = None
    #: the device's coupling, for the circuit state's unit (A^2 for a coil, V^2 for a piezo)
    electrical: object = field(default=None, repr=False, compare=False)
    #: the array-valued inputs of a broadcast prediction (name -> values), its sweep's axes
    inputs: object = field(default=None, repr=False, compare=False)

    @classmethod
    def from_white_noise(
        cls,
        harvester: Harvester,
        method: str,
        velocity_variance,
        displacement_variance,
        mean_abs_velocity,
        psd,
        stroke_exceedance=None,
    ) -> PowerPrediction:
        """A prediction under white noise of level ``psd`` from the method's moments.

        c_eq = S m / (4 E[v^2]) (Eq. 20), E[P_e] = c_e E[v^2] (Eq. 32) and the
        load's share follow; the free mass's displacement statistics (not
        stationary) and an exceedance without a stroke become None.
        """
        vv = np.asarray(velocity_variance, dtype=float)
        c_eq = np.asarray(psd, dtype=float) * harvester.m / (4.0 * vv)
        power = harvester.c_e * vv
        power_load = None
        if harvester.electrical is not None:
            power_load = power * harvester.electrical.load_fraction

        def clean(x):
            return scalar_or_array(np.asarray(x, dtype=float))

        free = harvester.potential.is_free
        if free or harvester.stroke is None:
            stroke_exceedance = None
        return cls(
            method=method,
            c_eq=clean(c_eq),
            velocity_variance=clean(vv),
            displacement_variance=None if free else clean(displacement_variance),
            mean_abs_velocity=clean(mean_abs_velocity),
            power_electrical=clean(power),
            power_load=None if power_load is None else clean(power_load),
            stroke_exceedance=None if stroke_exceedance is None else clean(stroke_exceedance),
            electrical=harvester.electrical,
        )

    def to_dict(self) -> dict:
        """Plain dict with floats or lists, ready for JSON.

        ``circuit_mean_square`` and ``stroke_exceedance`` only when given.
        """
        fields = asdict(self)
        del fields["electrical"], fields["inputs"]  # the device's and the sweep's, not results
        out = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in fields.items()}
        if self.tones is not None:
            out["tones"] = [tone.to_dict() for tone in self.tones]
        for optional in ("circuit_mean_square", "stroke_exceedance", "tones", *BRIDGE_POWERS):
            if out[optional] is None:
                del out[optional]
        return out

    def _quantities(self) -> list[tuple[str, object, str]]:
        """(name, value, unit) of every field with a value."""
        out = [(name, getattr(self, name)) for name in SHOWN]
        return [
            (name, value, unit(name, self.electrical)) for name, value in out if value is not None
        ]

    def to_frame(self):
        """The prediction as a :class:`pandas.DataFrame`.

        One row for scalar inputs; for a broadcast sweep one row per point
        (the fields broadcast together and are flattened in C order, so row
        ``i`` is ``numpy.unravel_index(i, shape)`` of the sweep's shape).
        Columns are ``method``, the swept inputs (``inputs``: ``psd``, array-valued
        device parameters) and the fields (SI units, see the class).
        """
        pd = _display.pandas()
        inputs = dict(self.inputs or {})
        columns = [*inputs.items()] + [(name, v) for name, v, _ in self._quantities()]
        values = np.broadcast_arrays(*(np.asarray(v, dtype=float) for _, v in columns))
        frame = pd.DataFrame({n: v.ravel() for (n, _), v in zip(columns, values, strict=True)})
        frame.insert(0, "method", self.method)
        return frame

    def _rows(self):
        return [
            (name, formatting.compact(value), units) for name, value, units in self._quantities()
        ]

    def __repr__(self) -> str:
        fields = ", ".join(
            f"{name}={formatting.compact(value)}" for name, value, _ in self._quantities()
        )
        return f"PowerPrediction(method={self.method!r}, {fields})"

    def __str__(self) -> str:
        """The table of :meth:`_repr_html_` as plain text (``print(prediction)``)."""
        return _display.text_table(f"Prediction ({self.method})", self._rows())

    def _repr_html_(self) -> str:
        return _display.html_table(f"Prediction ({self.method})", self._rows())


#: The fields of :class:`PowerPrediction` shown, in order (their units: :mod:`randvib.quantities`).
SHOWN = (
    "power_electrical",
    "power_load",
    "c_eq",
    "velocity_variance",
    "displacement_variance",
    "mean_abs_velocity",
    "circuit_mean_square",
    "stroke_exceedance",
    "power_stored",
    "power_coil_loss",
    "power_diode_loss",
    "power_mechanical",
)

#: A bridge's powers (:mod:`randvib.analytic.bridge`), None without one.
BRIDGE_POWERS = ("power_stored", "power_coil_loss", "power_diode_loss", "power_mechanical")


def gaussian_exceedance(stroke, displacement_variance):
    """P(|z| > stroke) = erfc(stroke / sqrt(2 E[z^2])) of a zero-mean Gaussian z (or None)."""
    if stroke is None:
        return None
    return special.erfc(stroke / np.sqrt(2.0 * np.asarray(displacement_variance, dtype=float)))
