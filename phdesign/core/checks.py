"""Checkers for the arguments of phdesign's public functions (standard library only).

Every public function checks what it is given before any work and raises phdesign's
errors (:mod:`phdesign.core.errors`) naming the argument, with what was expected against what
was found: a wrong kind of argument is an :class:`~phdesign.core.errors.ArgumentError` (a
:class:`TypeError`), a bad value one of the domain errors (a :class:`ValueError`).  The
checkers import nothing heavy, so any layer may use them.

Examples
--------
>>> positive_int(3, "count")
3
>>> positive_int(2.5, "samples")
Traceback (most recent call last):
...
phdesign.core.errors.NumericError: samples must be a positive integer; found 2.5
"""

from __future__ import annotations

import math
import operator
from collections.abc import Sequence

from phdesign.core.errors import ArgumentError, NumericError, PhdesignError

__all__ = [
    "EXPORT_FORMATS",
    "GAIN_DESIGNS",
    "REDUCTIONS",
    "SAMPLERS",
    "choice",
    "found_text",
    "not_bytes",
    "positive_int",
    "positive_number",
    "require_path",
]


#: The samplers a controller's front end may have; the first is the default
#: (:mod:`phdesign.numeric.sampled.samplers`).  Here, with the export formats, so that the
#: command line offers them as choices without loading the numeric layer.
SAMPLERS = ("average", "point")

#: How an exported observer's order is reduced
#: (:func:`phdesign.numeric.sampled.order.select_order`).
REDUCTIONS = ("none", "modal", "balanced")

#: The gain designs of an exported observer; the first is the default
#: (:mod:`phdesign.numeric.sampled.gain_design`).
GAIN_DESIGNS = ("auto", "passive", "kalman", "given")

#: The formats an exported observer is written in (:func:`phdesign.codegen.write_observer`).
EXPORT_FORMATS = ("json", "c", "npz", "statespace")


def found_text(value: object) -> str:
    """Return a short description of ``value`` for a message: its type and a shortened repr."""
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{type(value).__name__} {text}"


def not_bytes(value: object, what: str, error: type[PhdesignError]) -> None:
    """Raise ``error`` when ``value`` is bytes-like: ``list(b"1")`` is ``[49]``, not a number.

    A sequence of numbers is read by iterating over it; bytes iterate as their code points,
    so ``gain=b"1"`` was read as ``diag(49, 49)``.
    """
    if isinstance(value, bytes | bytearray | memoryview):
        raise error(
            f"{what} is {type(value).__name__} {bytes(value)[:40]!r}; expected numbers "
            "(bytes are not numbers: decode them)"
        )


def require_path(value: object, name: str = "path") -> None:
    """Raise :class:`ArgumentError` unless ``value`` names a file (``str`` or ``os.PathLike``).

    Integers are refused: :func:`open` would take them for file descriptors (``0`` is the
    standard input); so are bytes, as every path phdesign writes is text.
    """
    import os

    if isinstance(value, bool | int) or not isinstance(value, str | os.PathLike):
        raise ArgumentError(
            f"{name}: expected a file name (str or os.PathLike); found {found_text(value)}"
        )


def positive_int(
    value: object, name: str, error: type[PhdesignError] = NumericError, minimum: int = 1
) -> int:
    """Return ``value`` as an int if it is an integer ``>= minimum``, else raise ``error``."""
    if isinstance(value, bool | float | complex | str):
        number = None
    else:
        try:
            number = operator.index(value)  # type: ignore[arg-type]
        except TypeError:
            number = None
    if number is None or number < minimum:
        what = "a positive integer" if minimum == 1 else f"an integer >= {minimum}"
        raise error(f"{name} must be {what}; found {value!r}")
    return number


def positive_number(value: object, name: str, error: type[PhdesignError] = NumericError) -> float:
    """Return ``value`` as a float if it is a finite number > 0, else raise ``error``."""
    number: float | None
    if isinstance(value, bool | str | complex):
        number = None
    else:
        try:
            number = float(value)  # type: ignore[arg-type]
        except (TypeError, ValueError, OverflowError):
            number = None
    if number is None or not math.isfinite(number) or number <= 0:
        raise error(f"{name} must be a finite positive number; found {value!r}")
    return number


def choice(
    value: object, name: str, options: Sequence[str], error: type[PhdesignError] = NumericError
) -> str:
    """Return ``value`` if it is one of ``options``, else raise ``error`` listing them."""
    if not isinstance(value, str) or value not in options:
        listed = ", ".join(repr(o) for o in options)
        raise error(f"{name} must be one of {listed}; found {value!r}")
    return value
