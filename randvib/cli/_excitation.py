"""Excitation options: ``--excitation`` and its parameters, ``--psd-file``, ``--record``, tones,
non-Gaussian input and shocks.

The options come from the excitation registry (:data:`randvib.models.excitation.EXCITATIONS`):
``--excitation`` offers every registered excitation built from numbers, each
of its parameters (dataclass fields) other than the level is one option, and
``--psd`` is the level of each. The excitations read from a file have an
option each (:data:`FILE_OPTIONS`). An option that does not apply to the
chosen excitation is refused, as ``--beta`` is with Coulomb friction.

Beyond stationary Gaussian noise: ``--tone F:A[:PHASE]`` (repeatable),
``--kurtosis K`` or ``--marginal FILE`` (a translation process of the
spectrum, :mod:`randvib.models.translation`) and ``--shock-rate``,
``--shock-amplitude``, ``--shock-duration`` (with ``--shock-shape`` and
``--shock-distribution``; :mod:`randvib.models.shock`). Tones and shocks are
added to the spectrum (:class:`randvib.models.combined.Combined`), or stand
alone with ``--psd 0``.
"""

from __future__ import annotations

import argparse
from dataclasses import fields
from pathlib import Path

from randvib.cli._device import (
    option_flag,
    options_by_parameter,
    refuse_foreign_options,
    require_psd,
)
from randvib.models.combined import Combined
from randvib.models.excitation import EXCITATIONS
from randvib.models.record import read_csv
from randvib.models.shock import DISTRIBUTIONS, SHAPES, ShockTrain
from randvib.models.tone import parse_tone
from randvib.models.translation import Marginal, Translated

#: File option (argparse dest) -> the registered excitation read from it (``from_csv``).
FILE_OPTIONS = {"psd_file": "tabulated", "record": "measured"}

#: Metavar and help of the parameter options; a parameter not listed gets its name.
_HELP = {
    "f0": ("HZ", "centre (band-pass) or filter (Kanai-Tajimi) frequency (Hz), > 0"),
    "zeta": ("Z", "damping ratio of the shaping filter, > 0 (narrow band: small)"),
    "f_lo": ("HZ", "lower band edge (Hz), >= 0"),
    "f_hi": ("HZ", "upper band edge (Hz), > --f-lo"),
}


def excitation_choices() -> list[str]:
    """``--excitation`` choices: the registered excitations not read from a file."""
    return [name for name in EXCITATIONS if name not in FILE_OPTIONS.values()]


def _parameters(name: str) -> list[str]:
    """The parameters of a registered excitation other than its level ``--psd``."""
    return [f.name for f in fields(EXCITATIONS[name]) if f.name != "level"]


def _parameter_options() -> dict[str, list[str]]:
    """Parameter name -> the excitations declaring it, over the ``--excitation`` choices."""
    return options_by_parameter({name: _parameters(name) for name in excitation_choices()})


def add_excitation_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--excitation``, its parameters, ``--psd-file`` and ``--record`` to ``parser``."""
    g = parser.add_argument_group(
        "excitation (one-sided base-acceleration PSD; default: white noise of level --psd)"
    )
    g.add_argument(
        "--excitation",
        choices=excitation_choices(),
        help="spectrum; --psd is its level: white S, band-pass peak S at --f0 (half-power "
        "bandwidth 2 zeta f0), kanai-tajimi S at f = 0, band-limited S on [--f-lo, --f-hi]",
    )
    for name, owners in _parameter_options().items():
        metavar, text = _HELP.get(name, (name.upper(), name))
        g.add_argument(
            option_flag(name),
            dest=name,
            type=float,
            metavar=metavar,
            help=f"{text}; {', '.join(owners)}",
        )
    g.add_argument(
        "--psd-file",
        metavar="FILE",
        help="tabulated PSD: CSV with the columns frequency (Hz) and psd ((m/s^2)^2/Hz), "
        "linearly interpolated, zero outside",
    )
    g.add_argument(
        "--record",
        metavar="FILE",
        help="measured base acceleration: CSV with the columns time (s, evenly spaced) and "
        "base_acceleration (m/s^2); its PSD by Welch's method",
    )
    g.add_argument(
        "--input-column",
        metavar="NAME",
        help="with --record: the base-acceleration column (default: base_acceleration)",
    )
    g.add_argument(
        "--sample-rate",
        type=float,
        metavar="HZ",
        help="with --record: sample rate when the file has no time column",
    )
    _add_beyond_gaussian_arguments(parser)


def _add_beyond_gaussian_arguments(parser: argparse.ArgumentParser) -> None:
    """``--tone``, the translation's ``--kurtosis``/``--marginal`` and the ``--shock-*`` options."""
    g = parser.add_argument_group(
        "beyond stationary Gaussian noise (added to the spectrum above, or alone with --psd 0)"
    )
    g.add_argument(
        "--tone",
        action="append",
        metavar="F:A[:PHASE]",
        help="a tone a(t) = A cos(2 pi F t + PHASE): F in Hz, A the base-acceleration amplitude "
        "in m/s^2, PHASE in degrees (random per path when omitted: stationary); repeatable",
    )
    g.add_argument(
        "--kurtosis",
        type=float,
        metavar="K",
        help="non-Gaussian input: a translation process with the spectrum above and a "
        "generalised-normal marginal of kurtosis K (> 1.8; 3 is Gaussian, 6 Laplace)",
    )
    g.add_argument(
        "--marginal",
        metavar="FILE",
        help="non-Gaussian input: the marginal of the translation process, a CSV with the "
        "columns value and density, or a record's base_acceleration samples (its histogram)",
    )
    g.add_argument(
        "--shock-rate", type=float, metavar="RATE", help="shocks: Poisson pulses per second (1/s)"
    )
    g.add_argument(
        "--shock-amplitude",
        type=float,
        metavar="A",
        help="shocks: peak base acceleration of each pulse (m/s^2, sign random; the RMS peak "
        "with --shock-distribution)",
    )
    g.add_argument(
        "--shock-duration", type=float, metavar="S", help="shocks: duration of each pulse (s)"
    )
    g.add_argument(
        "--shock-shape",
        choices=tuple(SHAPES),
        default=None,
        help="shocks: pulse shape (default half-sine)",
    )
    g.add_argument(
        "--shock-distribution",
        choices=tuple(DISTRIBUTIONS),
        default=None,
        help="shocks: distribution of the peaks' sizes, same RMS (default fixed)",
    )


def excitation_from_args(args):
    """The ``psd`` argument of :func:`randvib.predict` from the options.

    Returns
    -------
    float or Excitation
        ``--psd`` itself for white noise (a number, checked downstream as
        every white-noise level is), else the excitation object.

    Raises
    ------
    ValueError
        One line naming the option: options that do not apply, missing ones,
        bad values, unreadable or invalid files.
    """
    tones = [parse_tone(text) for text in (getattr(args, "tone", None) or [])]
    shocks = _shocks(args)
    alone = bool(tones) or shocks is not None
    base = _spectrum_from_args(args, alone)
    base = _translated(args, base)
    if not alone:
        return base
    random = None if isinstance(base, int | float) and base == 0 else base
    return Combined(random, tuple(tones), shocks)


def _spectrum_from_args(args, alone: bool):
    """The spectrum of ``--excitation``, ``--psd-file`` or ``--record``; 0 for tones or shocks alone."""
    files = {dest: getattr(args, dest) for dest in FILE_OPTIONS if getattr(args, dest) is not None}
    columns = {"input_column": args.input_column, "sample_rate": args.sample_rate}
    if "record" not in files:
        for dest, value in columns.items():
            if value is not None:
                raise ValueError(f"`{option_flag(dest)}` reads a record: it needs `--record`")
    options = _parameter_options()
    given = {name: getattr(args, name) for name in options if getattr(args, name) is not None}
    if files:
        if len(files) > 1:
            raise ValueError("give one of `--psd-file` and `--record`, not both")
        ((dest, path),) = files.items()
        extra = [option_flag(name) for name in given]
        extra += [flag for flag in ("--excitation", "--psd") if getattr(args, flag[2:]) is not None]
        if extra:
            flags = ", ".join(f"`{flag}`" for flag in extra)
            raise ValueError(f"`{option_flag(dest)}` gives the whole spectrum; drop {flags}")
        return _read(
            option_flag(dest), FILE_OPTIONS[dest], path, columns if dest == "record" else {}
        )

    name = args.excitation or "white"
    own = _parameters(name)
    foreign = [parameter for parameter in given if parameter not in own]
    if foreign and args.excitation is None:
        first = foreign[0]
        raise ValueError(f"`{option_flag(first)}` needs `--excitation {'|'.join(options[first])}`")
    refuse_foreign_options(given, own, options, "the {owners} excitation", name)
    level = require_psd(args)
    if EXCITATIONS[name].is_white:
        if alone and level == 0:
            return 0.0  # the tones or shocks alone (checked downstream: a level is > 0)
        return level
    for parameter in own:
        if parameter not in given:
            raise ValueError(f"`{option_flag(parameter)}` is required for the {name} excitation")
    try:
        return EXCITATIONS[name](level, **given)
    except ValueError as exc:  # name the options, not the class's fields
        message = str(exc).replace("`level`", "`--psd`")
        for parameter in own:
            message = message.replace(f"`{parameter}`", f"`{option_flag(parameter)}`")
        raise ValueError(message) from None


def _read(flag: str, name: str, path: str, columns: dict):
    """``EXCITATIONS[name].from_csv(path, **columns)``, its errors as one line naming ``flag``."""
    file = Path(path)
    if file.is_dir():
        raise ValueError(f"`{flag}` must be a CSV file, got the folder {path}")
    if not file.exists():
        raise ValueError(f"`{flag}`: no such file {path}")
    try:
        return EXCITATIONS[name].from_csv(file, **columns)
    except (ValueError, OSError) as exc:  # pandas' parse errors are ValueErrors
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        # names inside the file's message are its columns ('psd'), not options
        # (`--psd`): quoted, they are left alone by the CLI's flag wording
        raise ValueError(f"`{flag}` {path}: {first.replace('`', chr(39))}") from None


#: The shock train's options (argparse dest) -> the ShockTrain argument each sets.
SHOCK_OPTIONS = {
    "shock_rate": "rate",
    "shock_amplitude": "amplitude",
    "shock_duration": "duration",
    "shock_shape": "shape",
    "shock_distribution": "distribution",
}


def _shocks(args) -> ShockTrain | None:
    """The shock train of the ``--shock-*`` options; None without them."""
    given = {dest: getattr(args, dest, None) for dest in SHOCK_OPTIONS}
    given = {dest: value for dest, value in given.items() if value is not None}
    if not given:
        return None
    needed = ("shock_rate", "shock_amplitude", "shock_duration")
    missing = [option_flag(dest) for dest in needed if dest not in given]
    if missing:
        have = ", ".join(f"`{option_flag(d)}`" for d in given)
        raise ValueError(
            f"{have} describe{'s' * (len(given) == 1)} a shock train, which also needs "
            + " and ".join(f"`{flag}`" for flag in missing)
        )
    try:
        return ShockTrain(**{SHOCK_OPTIONS[dest]: value for dest, value in given.items()})
    except ValueError as exc:  # name the options, not the class's fields
        message = str(exc)
        for dest, field in SHOCK_OPTIONS.items():
            message = message.replace(f"`{field}`", f"`{option_flag(dest)}`")
        raise ValueError(message) from None


def _translated(args, base):
    """``base`` as a translation process with ``--kurtosis`` or ``--marginal``; else itself."""
    kurtosis, marginal_file = getattr(args, "kurtosis", None), getattr(args, "marginal", None)
    if kurtosis is None and marginal_file is None:
        return base
    if kurtosis is not None and marginal_file is not None:
        raise ValueError("give one of `--kurtosis` and `--marginal`, not both")
    flag = "--kurtosis" if kurtosis is not None else "--marginal"
    if getattr(args, "record", None) is not None:
        raise ValueError(
            f"`{flag}` makes a translation process of a spectrum; a `--record` already carries "
            "its own marginal (simulate on it as it is)"
        )
    if isinstance(base, int | float):
        raise ValueError(
            f"`{flag}` needs a spectrum of finite variance for the translation process "
            "(`--excitation band-pass|kanai-tajimi|band-limited` or `--psd-file`): white noise "
            "has none"
        )
    try:
        marginal = (
            Marginal.from_kurtosis(kurtosis)
            if kurtosis is not None
            else _read_marginal(marginal_file)
        )
        return Translated(base, marginal)
    except ValueError as exc:
        message = str(exc).replace("`kurtosis`", "`--kurtosis`").replace("`dt`", "`--dt`")
        raise ValueError(message) from None


def _read_marginal(path: str) -> Marginal:
    """``--marginal FILE``: a density table (value, density) or a record's samples."""
    file = Path(path)
    if not file.is_file():
        raise ValueError(f"`--marginal`: no such file {path}")
    try:
        frame = read_csv(file, "file")
    except (ValueError, OSError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ValueError(f"`--marginal` {path}: {first.replace('`', chr(39))}") from None
    columns = set(frame.columns)
    try:
        if {"value", "density"} <= columns:
            return Marginal.from_table(
                frame["value"].to_numpy(float), frame["density"].to_numpy(float)
            )
        if "base_acceleration" in columns:
            return Marginal.from_samples(frame["base_acceleration"].to_numpy(float))
    except ValueError as exc:
        raise ValueError(f"`--marginal` {path}: {str(exc).replace('`', chr(39))}") from None
    raise ValueError(
        f"`--marginal` {path} must have the columns value and density (a table of the "
        f"density) or base_acceleration (a record's samples); found {', '.join(frame.columns)}"
    )
