"""Numbers as people read them: one set of rules for every result, command and report.

JSON and CSV output is never rounded; what is printed for a person follows
these rules, whoever prints it (the result types' ``repr``, ``str`` and
notebook tables, the command line's tables, the studies' reports):

- **A deterministic value** (an analytic prediction, a parameter) to
  :data:`SIGNIFICANT` significant digits (:func:`significant`; fewer where a
  caller asks); in a table cell, :func:`cell` also leaves a missing value
  blank and keeps counts and words as they are. A number that is not there
  or not a number reads ``n/a``, an infinite one ``∞``, and no value reads
  ``-0``.
- **An estimate with an interval** (a Monte Carlo mean and its 95 %
  half-width, a fitted value and its standard error) to the decimal of the
  interval's second significant digit, so that no digit is shown that the
  data do not support (:func:`estimate_parts`, :func:`estimate`,
  :func:`with_standard_error`); a probability with its interval's ends
  (:func:`proportion`), which a mean +- half-width would take below 0.
- **A column of a report table** with a fixed format, so that the column
  lines up (:func:`plus_minus`, :func:`formatted`, :func:`percent`).
- **An object holding arrays** by their shape and range (:func:`compact`).
"""

from __future__ import annotations

import math
import re

import numpy as np

__all__ = [
    "MAX_FIGURES",
    "PLAIN_BELOW",
    "SIGNIFICANT",
    "cell",
    "compact",
    "estimate",
    "estimate_parts",
    "formatted",
    "percent",
    "plus_minus",
    "proportion",
    "significant",
    "unsigned_zeros",
    "with_standard_error",
]

#: Significant digits of a deterministic value in a table.
SIGNIFICANT = 6

#: Below this magnitude the leading zeros hide the digits: 9.29e-06, not 0.00000929.
PLAIN_BELOW = 1e-4

#: Most significant digits shown of an estimate (a noise-free fit's interval
#: may support more; eight say all a reader can use).
MAX_FIGURES = 8


def _is_number(value) -> bool:
    """A real number (Python or numpy), not a bool."""
    return isinstance(value, int | float | np.integer | np.floating) and not isinstance(
        value, bool | np.bool_
    )


def _finite(value) -> bool:
    return _is_number(value) and math.isfinite(value)


def significant(value, digits: int = SIGNIFICANT) -> str:
    """``value`` to ``digits`` significant figures.

    None and NaN read ``n/a``, infinities ``∞`` and ``-∞``; zero is never
    signed. Something that is not a number is written as it is.

    Examples
    --------
    >>> significant(0.00246461234)
    '0.00246461'
    >>> significant(-0.0), significant(float("nan")), significant(float("-inf"), 4)
    ('0', 'n/a', '-∞')
    """
    if value is None:
        return "n/a"
    if not _is_number(value):
        return str(value)
    x = float(value)
    if math.isnan(x):
        return "n/a"
    if math.isinf(x):
        return "∞" if x > 0 else "-∞"
    return f"{x + 0.0:.{digits}g}"  # + 0.0: never "-0"


def cell(value, digits: int = SIGNIFICANT) -> str:
    """One cell of a table: a real number as :func:`significant`, a count and a
    word as they are, a missing value (None) blank."""
    if value is None:
        return ""
    if isinstance(value, float | np.floating):
        return significant(value, digits)
    return str(value)


def compact(value, digits: int = 5) -> str:
    """A number to ``digits`` significant figures, an array by its shape and range.

    Examples
    --------
    >>> compact(np.array([[0.5, 2.0, 1.0]]))
    'array(1, 3) 0.5 .. 2'
    """
    array = np.asarray(value) if value is not None else None
    if array is None or array.ndim == 0:
        return significant(value if array is None else array.item(), digits)
    if array.size == 0:
        return f"array{array.shape}"
    return f"array{array.shape} {compact(array.min(), 3)} .. {compact(array.max(), 3)}"


def estimate(mean, ci95) -> str:
    """``mean ± ci95`` with the mean to the precision its interval supports.

    The half-width keeps two significant figures and the mean is written to
    the same decimal place (``0.00246461 ± 0.00000055``): the last digit shown is
    the interval's second. Without an interval (zero or not finite) the mean
    keeps six significant figures. See :func:`estimate_parts`.
    """
    if not (_finite(mean) and _finite(ci95)) or ci95 <= 0:
        return significant(mean, 6)
    return " ± ".join(estimate_parts(mean, ci95))


def estimate_parts(mean, half_width) -> tuple[str, str]:
    """A Monte Carlo mean and its 95 % half-width, as the half-width allows.

    The half-width is shown to two significant digits and the mean to the same
    decimal place (``0.0024619 +- 0.00027`` -> ``0.00246``, ``0.00027``), both
    in one notation, chosen by the mean's size; a mean known to more than
    :data:`MAX_FIGURES` digits is shown to that many. A zero or missing half-width
    leaves both as table cells (:func:`cell`: six significant digits, blank
    if missing, ``n/a`` if not a number). One rule for the terminal tables, the
    reprs and the notebook.

    Examples
    --------
    >>> estimate_parts(0.0024619412547950926, 0.000272784)
    ('0.00246', '0.00027')
    >>> estimate_parts(12345.678, 140.0)
    ('12350', '140')
    >>> estimate_parts(9.2912e-06, 9.81e-07)
    ('9.29e-06', '9.8e-07')
    >>> estimate_parts(0.0490000000112, 2.09e-12)
    ('0.049000000', '2.1e-12')
    """
    if not (_finite(mean) and _finite(half_width) and half_width > 0):
        return cell(mean), cell(half_width)
    decimals = 1 - math.floor(math.log10(half_width))  # the 2nd significant digit's place
    half = round(half_width, decimals)
    if half > 0 and math.floor(math.log10(half)) > math.floor(math.log10(half_width)):
        decimals -= 1  # 0.0996 rounded up to 0.10: two digits are now one place earlier
    shown = decimals
    if mean != 0:  # no more than MAX_FIGURES digits, however small the interval
        shown = min(decimals, MAX_FIGURES - 1 - math.floor(math.log10(abs(mean))))
    # the pair in one notation, chosen by the mean: 0.000722 and 0.000042;
    # a half-width past the eighth decimal in exponent notation (2.1e-12)
    plain = round(mean, shown) == 0 or abs(mean) >= PLAIN_BELOW
    return _fixed(mean, shown, plain), _fixed(half_width, decimals, plain and decimals <= 8)


def _fixed(value: float, decimals: int, plain: bool) -> str:
    """``value`` rounded to ``decimals`` places (negative: tens, hundreds...), in plain
    notation if ``plain``, else in exponent notation with the same digits."""
    rounded = round(value, decimals) + 0.0  # + 0.0: never "-0"
    if decimals >= 0 and plain:
        return f"{rounded:.{decimals}f}"
    if decimals < 0 and abs(rounded) < 1e9:
        return f"{rounded:.0f}"
    digits = max(1, math.floor(math.log10(abs(rounded))) + decimals + 1) if rounded else 1
    return f"{rounded:.{digits - 1}e}"


def proportion(mean, lower, upper) -> str:
    """A probability with its (asymmetric) 95 % interval: ``0.0010 [0.00018, 0.0057]``.

    The three numbers to the decimal of the second significant digit of the
    interval's longer side, as :func:`estimate_parts` writes an estimate.

    Examples
    --------
    >>> proportion(0.001, 0.000177, 0.00566)
    '0.0010 [0.0002, 0.0057]'
    """
    half = max(mean - lower, upper - mean) if _finite(lower) and _finite(upper) else 0.0
    if not half > 0:
        return f"{significant(mean, 6)} [{significant(lower, 2)}, {significant(upper, 2)}]"
    shown = [estimate_parts(x, half)[0] for x in (mean, lower, upper)]
    return f"{shown[0]} [{shown[1]}, {shown[2]}]"


def with_standard_error(value, se, interval=None) -> list[str]:
    """A fitted value, its standard error and its interval, to the digits the error supports.

    The standard error keeps two significant digits and the value and the
    interval's ends are written to its decimal place, as Monte Carlo means are
    (:func:`estimate_parts`); without a standard error the value keeps
    six digits and the interval is left blank.

    Returns
    -------
    [value, standard error, interval] : list of str
        The interval as ``[lo, hi]`` (blank when not given).
    """
    if se is None or not np.isfinite(se) or se <= 0:
        return [cell(value), cell(se), ""]
    shown, se_shown = estimate_parts(value, se)
    if interval is None:
        return [shown, se_shown, ""]
    lo, hi = (estimate_parts(end, se)[0] for end in interval)
    return [shown, se_shown, f"[{lo}, {hi}]"]


def plus_minus(value, ci, scale: float = 100.0, fmt: str = "+.2f") -> list[str]:
    """'value ± ci' strings for a report table's column (default: fractions as percent).

    Every row of the column has the format ``fmt`` (the sign dropped from the
    half-width), so that the column lines up.

    Examples
    --------
    >>> plus_minus([0.0123, -0.004], [0.001, 0.0005])
    ['+1.23 ± 0.10', '-0.40 ± 0.05']
    """
    return [
        f"{scale * v:{fmt}} ± {scale * c:{fmt.lstrip('+')}}"
        for v, c in zip(np.atleast_1d(value), np.atleast_1d(ci), strict=True)
    ]


def percent(fraction, digits: int = 2, sign: bool = False) -> str:
    """A fraction written as a percentage ('1.23 %'), 'n/a' for NaN, no '-0.00 %'."""
    if fraction is None or float(fraction) != float(fraction):
        return "n/a"
    text = f"{100 * float(fraction):{'+' if sign else ''}.{digits}f}"
    if float(text) == 0:
        text = f"{0:.{digits}f}"
    return f"{text} %"


def formatted(value: float, spec: str) -> str:
    """``value`` with the format ``spec`` (a report column's), 'n/a' for NaN, no '-0'."""
    if value != value:
        return "n/a"
    text = format(value, spec)
    try:
        zero = float(text) == 0
    except ValueError:
        return text
    return text.lstrip("-") if zero else text


def unsigned_zeros(text: str) -> str:
    """``text`` with every signed zero ('-0', '+0.000') written unsigned ('0', '0.000')."""
    return re.sub(r"(?<![\w.])[-+](0(?:\.0+)?)(?![\d.])", r"\1", text)
