"""Settings of an identification: how a record is simulated and how the search runs.

:class:`SimulationSettings` (sub-steps, the input between samples, low-pass,
skipped samples, the initial state) serve :func:`randvib.identify`,
:func:`randvib.predict_record` and validation alike; :class:`SearchSettings`
are SaDE's and the least-squares polish's. Every field may also be given as a
keyword of those functions (:func:`resolve_settings`).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from randvib._validation import MAX_SEED, check_int
from randvib.identification.input_reconstruction import (
    AUTO_HOLD,
    HOLDS,
    choose_hold,
    driving_signal,
)

#: The polish's evaluations for one displacement record, and for any other fit.
POLISH_MAXFEV = 40
EXPERIMENT_POLISH_MAXFEV = 200
#: How the simulation's initial state is obtained (SimulationSettings.initial_state).
INITIAL_STATES = ("estimate", "record")


@dataclass(frozen=True)
class SimulationSettings:
    """How a record is simulated and scored (:func:`randvib.identify`, :func:`randvib.predict_record`).

    Attributes
    ----------
    substeps : int
        Integration steps per sample interval (default 4).
    hold : {'auto', 'linear', 'zero', 'cubic', 'bandlimited'}
        Reconstruction of the input between samples
        (:func:`~randvib.identification.input_reconstruction.reconstruct_input`);
        ``auto`` (default) chooses linear or band-limited from the record's
        input (:func:`~randvib.identification.input_reconstruction.choose_hold`,
        :meth:`for_record`).
    lowpass : float or None
        Zero-phase low-pass cut-off (Hz) for the driving signal (useful for a
        base displacement differentiated twice).
    skip : int
        Samples at the start left out of J.
    initial_state : {'estimate', 'record'}
        ``estimate`` (default): the initial displacement and velocity are
        estimated with the parameters (by the least-squares polish in
        :func:`~randvib.identification.identify.identify`; by a two-parameter fit in
        :func:`~randvib.identification.prediction.predict_record` and
        :func:`~randvib.identification.prediction.validate`), so a correct model is never penalised for its
        start. ``record``: start from the first sample (less the output
        offset) and the velocity of
        :func:`~randvib.identification.cost.initial_velocity`.
    """

    substeps: int = 4
    hold: str = AUTO_HOLD
    lowpass: float | None = None
    skip: int = 0
    initial_state: str = "estimate"

    def __post_init__(self):
        object.__setattr__(self, "substeps", check_int("substeps", self.substeps, minimum=1))
        object.__setattr__(self, "skip", check_int("skip", self.skip, minimum=0))
        if self.hold != AUTO_HOLD and self.hold not in HOLDS:
            raise ValueError(
                f"`hold` must be one of {', '.join((AUTO_HOLD,) + HOLDS)}; got {self.hold!r}"
            )
        if self.initial_state not in INITIAL_STATES:
            raise ValueError(
                f"`initial_state` must be one of {', '.join(INITIAL_STATES)}; "
                f"got {self.initial_state!r}"
            )

    def to_dict(self) -> dict:
        return _fields_of(self)

    def for_record(self, record) -> tuple[SimulationSettings, str]:
        """These settings with the reconstruction resolved for ``record``'s input.

        Returns the settings with ``hold`` one of the concrete reconstructions
        and a sentence on the choice ('' when there is nothing to say); warns
        when the reconstruction cannot represent the input (see
        :func:`~randvib.identification.input_reconstruction.choose_hold`).
        """
        drive, _ = driving_signal(record.input, record.dt, record.input_kind, self.lowpass)
        hold, why = choose_hold(drive, record.dt, self.hold)
        return replace(self, hold=hold), why


@dataclass(frozen=True)
class SearchSettings:
    """SaDE settings of an identification (see :func:`randvib.identification.sade.sade`).

    Attributes
    ----------
    popsize : int
        Population size.
    maxiter : int
        Most generations.
    seed : int, numpy.random.Generator or None
        Random seed or generator of the search.
    tol : float
        Stop when the population's spread of J falls below this.
    patience : int or None
        Stop after this many generations without improvement (None: never).
    polish : bool
        Finish with the least-squares polish of the simulation error
        (:mod:`randvib.identification.least_squares`), which also estimates
        the initial state and gives the parameters' uncertainty.
    polish_maxfev : int or None
        Most residual evaluations of the polish (each Jacobian costs 2 d
        more simulations, run in one batch); None: 40 for one displacement
        record, :data:`EXPERIMENT_POLISH_MAXFEV` for several records or
        channels (more offsets and initial states to estimate, and the
        coupling's parameters in narrower valleys).
    search_samples : int or None
        Search on the record's first ``search_samples`` samples only (None:
        all); the polish always fits the whole record. The search only has
        to find the optimum's basin, so a window of a few periods of the
        slowest dynamics is enough and makes it proportionally cheaper.
    """

    popsize: int = 30
    maxiter: int = 60
    seed: int | np.random.Generator | None = 0
    tol: float = 1e-6
    patience: int | None = 15
    polish: bool = True
    polish_maxfev: int | None = None
    search_samples: int | None = None

    def __post_init__(self):
        if isinstance(self.seed, int | np.integer) and not isinstance(self.seed, bool):
            check_int("seed", self.seed, 0, MAX_SEED)

    def to_dict(self) -> dict:
        return _fields_of(self)

    def sade_options(self) -> dict:
        """The fields that are :func:`~randvib.identification.sade.sade`'s keywords."""
        return {k: v for k, v in self.to_dict().items() if k not in _NOT_SADE}


#: SearchSettings fields that are not SaDE's.
_NOT_SADE = ("polish", "polish_maxfev", "search_samples")


def _fields_of(settings) -> dict:
    # not dataclasses.asdict: that deep-copies, and a seed Generator must be
    # the caller's own (it advances)
    return {f.name: getattr(settings, f.name) for f in fields(settings)}


def resolve_settings(caller, options: dict, **given):
    """The settings objects ``given`` (name -> object or None), with fields named
    as keywords in ``options`` replacing theirs: ``identify(..., popsize=20)``
    is ``identify(..., search=SearchSettings(popsize=20))``."""
    options = dict(options)
    out = []
    for name, value in given.items():
        cls = _SETTINGS[name]
        if value is not None and not isinstance(value, cls):
            raise ValueError(f"`{name}` must be a {cls.__name__}, got {type(value).__name__}")
        mine = {f.name: options.pop(f.name) for f in fields(cls) if f.name in options}
        out.append(replace(value if value is not None else cls(), **mine))
    if options:
        raise TypeError(f"{caller}() got unexpected keyword argument(s) {', '.join(options)}")
    return out


_SETTINGS = {"search": SearchSettings, "simulation": SimulationSettings}
