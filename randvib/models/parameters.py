"""Parameter declarations of the model families: :func:`parameter`, :class:`DeclaredParameters`.

A model family (friction laws, :mod:`randvib.models.friction`; electrical
couplings, :mod:`randvib.models.coupling`) declares each parameter once, as a
dataclass field made with :func:`parameter`: its unit, whether it must be
> 0 or >= 0, and how identification searches it (default bounds from a
record's :class:`RecordScales`, log or linear scale). The family's base class
inherits :class:`DeclaredParameters`, which reads the declarations in field
order and validates every value from them; ``parameters()``, the CLI
options, the identification bounds and the kernel parameter vector read the
same declarations.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, fields

from randvib._validation import check_nonnegative, check_positive, scalar_or_array


@dataclass(frozen=True)
class RecordScales:
    """Characteristic scales of a record, from which search bounds follow.

    Attributes
    ----------
    m : float
        Mass (kg), given or estimated.
    omega : float
        Characteristic angular frequency rms(z')/rms(z) (rad/s).
    z_max : float
        Largest |z| (m).
    v_rms : float
        RMS velocity (m/s).
    force : float
        RMS external force, m rms(y'') or rms(u) (N).
    """

    m: float
    omega: float
    z_max: float
    v_rms: float
    force: float

    @property
    def k_ref(self) -> float:
        """Stiffness scale m omega^2 (N/m)."""
        return self.m * self.omega**2

    @property
    def c_ref(self) -> float:
        """Damping scale 2 m omega (Ns/m): critical damping at omega."""
        return 2.0 * self.m * self.omega


@dataclass(frozen=True)
class Parameter:
    """What a model declares about one of its parameters.

    Attributes
    ----------
    unit : str
        SI unit, as printed in messages and tables.
    positive : bool
        True: must be > 0; False: must be >= 0.
    search : callable or None
        ``search(scales: RecordScales) -> (lower, upper)``: identification's
        default bounds. None: the parameter has no default bounds and must
        be fixed or bounded by the user.
    log : bool
        Search on a log scale (parameters that span decades).
    description : str
        One line for the CLI help.
    """

    unit: str
    positive: bool = False
    search: Callable | None = None
    log: bool = True
    description: str = ""


def parameter(
    unit: str,
    *,
    positive: bool = False,
    search: Callable | None = None,
    log: bool = True,
    description: str = "",
):
    """A model field with its declaration (see :class:`Parameter`)."""
    return field(metadata={"parameter": Parameter(unit, positive, search, log, description)})


class DeclaredParameters:
    """What every model family declared with :func:`parameter` fields shares.

    The family's base class (friction laws, couplings) inherits it: the
    declarations by name, in field order (the kernel's order for friction
    laws), and one validation from them, so a bad value is named the same
    way in every family.
    """

    @classmethod
    def parameter_specs(cls) -> dict[str, Parameter]:
        """Declared parameters by name, in field order."""
        return {f.name: f.metadata["parameter"] for f in fields(cls)}

    @classmethod
    def parameter_names(cls) -> tuple[str, ...]:
        """Parameter names in field order."""
        return tuple(f.name for f in fields(cls))

    def __post_init__(self):
        # One validation from the declarations: a message names the
        # parameter, its value, the allowed range and the unit.
        for name, spec in self.parameter_specs().items():
            check = check_positive if spec.positive else check_nonnegative
            object.__setattr__(
                self, name, scalar_or_array(check(name, getattr(self, name), spec.unit))
            )
