"""Input validation shared by every public entry point.

All checks raise :class:`ValueError` with a message that names the argument,
shows the offending value and states what is allowed, so that a user (or the
CLI, which prints the message as one line) knows what to change.
"""

from __future__ import annotations

import numbers

import numpy as np


def as_float_array(name: str, value) -> np.ndarray:
    """Convert ``value`` to a float array, refusing non-numeric input."""
    if isinstance(value, bool | np.bool_):
        raise ValueError(f"`{name}` must be a real number, got {value!r}")
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be a real number, got {value!r}") from None
    return arr


def _first_bad(arr: np.ndarray, mask: np.ndarray):
    # a Python float, so that messages read "got -1.0", not "got np.float64(-1.0)"
    return arr[mask].ravel()[0].item() if arr.ndim else arr.item()


def check_finite(name: str, value) -> np.ndarray:
    arr = as_float_array(name, value)
    bad = ~np.isfinite(arr)
    if bad.any():  # an ndarray or numpy bool: the method, without np.any's dispatch
        raise ValueError(
            f"`{name}` must be finite, got {_first_bad(arr, bad)!r}; "
            "NaN and infinite values are not allowed"
        )
    return arr


def check_scalar(name: str, value, what: str, broadcast: str = "") -> float:
    """One number, not an array: a clear refusal where a function takes a single value.

    ``what`` says what the number is (``"a white-noise level S ((m/s^2)^2/Hz)"``);
    ``broadcast`` names the functions that do take arrays, if any.
    """
    if np.ndim(value) != 0:
        shape = np.shape(value)
        hint = f"; {broadcast} broadcast over arrays" if broadcast else ""
        raise ValueError(
            f"`{name}` must be one number ({what}), got an array of shape {shape}: "
            f"loop over its values{hint}"
        )
    return value


def check_positive(name: str, value, unit: str = "") -> np.ndarray:
    """Finite and strictly greater than zero (scalar or array)."""
    arr = check_finite(name, value)
    bad = arr <= 0
    if bad.any():  # an ndarray or numpy bool: the method, without np.any's dispatch
        raise ValueError(f"`{name}` must be > 0{_unit(unit)}, got {_first_bad(arr, bad)!r}")
    return arr


def check_nonnegative(name: str, value, unit: str = "") -> np.ndarray:
    """Finite and greater than or equal to zero (scalar or array)."""
    arr = check_finite(name, value)
    bad = arr < 0
    if bad.any():  # an ndarray or numpy bool: the method, without np.any's dispatch
        raise ValueError(f"`{name}` must be >= 0{_unit(unit)}, got {_first_bad(arr, bad)!r}")
    return arr


def check_choice(name: str, value, allowed) -> str:
    if value not in allowed:
        raise ValueError(f"`{name}` must be one of {', '.join(map(repr, allowed))}; got {value!r}")
    return value


def check_int(name: str, value, minimum: int = 0, maximum: int | None = None) -> int:
    """An integer in ``[minimum, maximum]`` (no upper limit when ``maximum`` is None)."""
    allowed = f">= {minimum}" if maximum is None else f"in {minimum} .. {maximum}"
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"`{name}` must be an integer {allowed}, got {value!r}")
    if value < minimum or (maximum is not None and value > maximum):
        raise ValueError(f"`{name}` must be an integer {allowed}, got {value!r}")
    return int(value)


#: Largest seed: the random streams are keyed by an unsigned 64-bit integer.
MAX_SEED = 2**64 - 1


def integer_option(minimum: int = 0, maximum: int | None = None):
    """An argparse ``type`` for an integer count or seed in ``[minimum, maximum]``.

    It takes an integer written as one (``200``) or in float notation when
    that is exactly an integer (``1e5``, ``2.0``), and refuses anything else
    with a message that argparse prefixes with the option's name
    (``argument --paths: must be an integer >= 1, got '0.5'``), instead of
    "invalid int value" or the library argument's name.
    """
    import argparse
    from decimal import Decimal, InvalidOperation

    allowed = f">= {minimum}" if maximum is None else f"in {minimum} .. {maximum}"

    def parse(text: str) -> int:
        try:
            number = Decimal(text.strip())
        except InvalidOperation:
            number = None
        # 40 digits is beyond every count and seed; int() of 1e999999999 would not end
        ok = number is not None and number.is_finite() and number.adjusted() < 40
        if ok and number == number.to_integral_value():
            value = int(number)
            if value >= minimum and (maximum is None or value <= maximum):
                return value
        raise argparse.ArgumentTypeError(f"must be an integer {allowed}, got {text!r}")

    parse.__name__ = "integer"
    return parse


def scalar_or_array(arr: np.ndarray):
    """Return a Python float for 0-d arrays, the array otherwise."""
    return float(arr) if np.ndim(arr) == 0 else arr


def _unit(unit: str) -> str:
    return f" (in {unit})" if unit else ""


def check_scalar_device(harvester, function: str):
    """A harvester whose parameters are single numbers, for a function that runs one device.

    Its own parameters (m, c_m, c_e, k, k3), its friction law's and its
    coupling's are checked; an array is refused, naming it and ``function``.
    """
    values = {name: getattr(harvester, name) for name in ("m", "c_m", "c_e", "k", "k3")}
    for part in (harvester.friction, harvester.electrical):
        if part is not None:
            values.update(part.parameters())
    for name, value in values.items():
        if not isinstance(value, str) and np.ndim(value) != 0:
            raise ValueError(
                f"{function} needs scalar harvester parameters (one device): `{name}` is an "
                f"array of shape "
                f"{np.shape(value)}; loop over its values (only white noise with a resistive "
                "coupling broadcasts over device arrays, in randvib.predict and "
                "randvib.expected_power)"
            )
    return harvester
