"""Where ``+`` and :func:`~randvib.models.excitation.as_excitation` find the sum of inputs.

An excitation or a tone added to another becomes a
:class:`~randvib.models.combined.Combined`, which builds on both of their
modules; they cannot import it without an import cycle (docs/development.md).
They ask this registry instead, which :mod:`randvib.models.combined` fills
when it is loaded, and the package loads it with ``randvib.models``
(``randvib/models/__init__.py``), as :mod:`randvib.analytic.method`'s registry
of methods is filled by its driver.
"""

from __future__ import annotations

from collections.abc import Callable

#: ``"combine"`` (a + b) and ``"as_input"`` (a tone made an input), set by
#: :func:`register` from :mod:`randvib.models.combined`.
COMPOSITE: dict[str, Callable] = {}


def register(*, combine: Callable, as_input: Callable) -> None:
    """Record the composite input's constructors (called once, by :mod:`randvib.models.combined`)."""
    COMPOSITE.update(combine=combine, as_input=as_input)


def combine(a, b):
    """``a + b`` of two inputs: :func:`randvib.models.combined.combine`."""
    return COMPOSITE["combine"](a, b)


def as_input(value):
    """A tone made an input: :func:`randvib.models.combined.as_input`."""
    return COMPOSITE["as_input"](value)
