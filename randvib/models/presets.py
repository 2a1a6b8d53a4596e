"""Parameter presets from the paper (Table 2 and Section 5).

The magnet mass is never printed in the paper. All presets use
``m = 0.0226 kg``: the mass that gives the identified k = 57.4 N/m the
measured natural frequency of about 8 Hz (m = k / (2 pi 8 Hz)^2). With base
excitation m cannot be identified from displacement records (dividing Eq. 1
by m leaves c/m, k/m, k3/m, Fc/m), so this is an assumption, not a result.

Table 2 presets (``<model>-td1``, ``<model>-td2`` for training data 1 = test 3
and 2 = test 8) were identified with no coil attached: the identified viscous
damping is all mechanical (``c_m = c``, ``c_e = 0``), so their electrical power
is zero until a circuit or ``c_e`` is given. ``figure9`` is the paper's
Section 5 / Figure 9 device: Coulomb training-data-1 parameters with
c_m = c_e = 0.1 Ns/m.
"""

from __future__ import annotations

from randvib.models.friction import Coulomb, LuGre, Tanh
from randvib.models.harvester import Harvester

#: Assumed centre-magnet mass (kg): k / (2 pi 8 Hz)^2 with k = 57.4 N/m.
MAGNET_MASS = 0.0226
#: Flux gradient of the paper's coil, 83 turns x 0.0024 Wb/m (Wb/m).
ALPHA = 0.1992
#: Coil resistance measured in the paper (ohm).
R_COIL = 0.48

# (c, k, k3, friction) for training data 1 and 2, paper Table 2.
_TABLE2 = {
    "viscous": ((0.116, 54.8, 112620.0, None), (0.079, 54.2, 119210.0, None)),
    "coulomb": ((0.049, 57.4, 70742.0, Coulomb(0.0058)), (0.047, 56.1, 91894.0, Coulomb(0.0065))),
    "tanh": (
        (0.049, 57.5, 68956.0, Tanh(0.0058, 4.8e8)),
        (0.047, 56.1, 91798.0, Tanh(0.0065, 8.3e8)),
    ),
    "lugre": (
        (0.055, 59.7, 64926.0, LuGre(1.98, 0.18, 0.0008, 0.008, 0.007)),
        (0.051, 58.1, 79788.0, LuGre(4.9, 0.19, 0.0007, 0.0006, 0.0006)),
    ),
}


def _table2(model: str, training_set: int) -> Harvester:
    c, k, k3, friction = _TABLE2[model][training_set - 1]
    return Harvester(m=MAGNET_MASS, c_m=c, c_e=0.0, k=k, k3=k3, friction=friction)


#: The named devices: ``<model>-td<n>`` for every row of the paper's Table 2
#: (model viscous, coulomb, tanh or lugre; training data n = 1 or 2; no coil,
#: c_e = 0) and ``figure9``, the Section 5 device (c_m = c_e = 0.1 Ns/m).
PRESETS: dict[str, Harvester] = {
    f"{model}-td{n}": _table2(model, n) for model in _TABLE2 for n in (1, 2)
}
PRESETS["figure9"] = PRESETS["coulomb-td1"].updated(c_m=0.1, c_e=0.1)

PRESET_DESCRIPTIONS = {
    **{
        f"{model}-td{n}": f"Table 2, {model} model, training data {n} (test {3 if n == 1 else 8}); c_e = 0"
        for model in _TABLE2
        for n in (1, 2)
    },
    "figure9": "Section 5 / Figure 9: Coulomb training data 1 with c_m = c_e = 0.1 Ns/m",
}


def preset(name: str) -> Harvester:
    """The harvester of a named preset (see :data:`PRESETS`).

    Raises
    ------
    ValueError
        If ``name`` is not a preset; the message lists them.

    Examples
    --------
    >>> import randvib as rv
    >>> device = rv.preset("figure9")
    >>> device
    Harvester(m=0.0226, c_m=0.1, c_e=0.1, k=57.4, k3=70742.0, friction=Coulomb(fc=0.0058), electrical=None, stroke=None)
    >>> print(f"{device.natural_frequency:.2f} rad/s")
    50.40 rad/s
    """
    try:
        return PRESETS[name]
    except KeyError:
        raise ValueError(f"unknown preset {name!r}; available: {', '.join(PRESETS)}") from None
