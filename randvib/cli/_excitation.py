"""Excitation options: ``--excitation`` and its parameters, ``--psd-file``, ``--record``.

The options come from the excitation registry (:data:`randvib.models.excitation.EXCITATIONS`):
``--excitation`` offers every registered excitation built from numbers, each
of its parameters (dataclass fields) other than the level is one option, and
``--psd`` is the level of each. The excitations read from a file have an
option each (:data:`FILE_OPTIONS`). An option that does not apply to the
chosen excitation is refused, as ``--beta`` is with Coulomb friction.
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
from randvib.models.excitation import EXCITATIONS

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
