"""Exceptions raised by phdesign and the one shared checker for matrix shapes.

Every exception a user can provoke with bad input derives from
:class:`PhdesignError` and from :class:`ValueError` (a bad value) or :class:`TypeError`
(an argument of the wrong kind, :class:`ArgumentError`), so callers may catch either the
phdesign family or the builtin one.  Any other exception escaping phdesign is a bug.  Messages
name the matrix, parameter or expression at fault and give what was expected
against what was found.

A library user has no command-line flags, so a message names an argument as Python
spells it: at the head of the message (``tol must be a finite positive number``,
``gain: entry 2 ...``) or as code in backquotes (```reduction='none'```, ```force=True```,
```x0```).  The command line prints each with the option that sets it (``--tol``,
``--reduce none``, ``--force``, ``--x0``: :mod:`phdesign.cli.messages`).

Examples
--------
>>> import numpy as np
>>> check_shape("B", np.zeros((2, 2)), (3, 2))
Traceback (most recent call last):
...
phdesign.core.errors.ShapeError: Incompatible dimensions of B matrix; expected (3, 2) but found (2,
2)
"""

from __future__ import annotations

from typing import Any


class PhdesignError(Exception):
    """Base class of every error phdesign raises on bad input."""


class ExpressionError(PhdesignError, ValueError):
    """A trace expression or matrix entry is malformed, nonlinear or unknown."""


class ModelError(PhdesignError, ValueError):
    """A model violates a structural condition (symmetry, definiteness, sizes)."""


class ShapeError(ModelError):
    """A matrix has the wrong shape."""


class PortError(PhdesignError, ValueError):
    """Inputs and outputs violate rank or the port identities."""


class ParameterError(PhdesignError, ValueError):
    """A parameter is unknown, has a bad value, or is left free at the bridge."""


class ObserverError(PhdesignError, ValueError):
    """Sensor selection or observer gain is invalid."""


class LoopError(PhdesignError, ValueError):
    """Actuation or feedback of an observer-based loop is invalid."""


class ModelFileError(PhdesignError, ValueError):
    """A model file cannot be read: bad TOML, missing or unknown keys."""


class NumericError(PhdesignError, ValueError):
    """A numeric request cannot be honoured (bad resolution, time span, method)."""


class CertificateError(NumericError):
    """A certificate cannot be made for this system (z-dependent, singular, not proved)."""


class VerificationError(NumericError):
    """A strict export whose verification failed (``strict=True``: nothing is returned)."""


class OutputFileError(PhdesignError, ValueError):
    """An output path is not writable or would overwrite a file without ``force``."""


class ArgumentError(PhdesignError, TypeError):
    """An argument of a library function is of the wrong kind (e.g. a name for a model)."""


class SweepError(PhdesignError, ValueError):
    """A sweep's grid, store or scheduler is invalid or unreachable."""


class RateProofError(PhdesignError, ValueError):
    """No decay rate can be proved for a closed system (its order, its data or the search)."""


def check_shape(
    name: str,
    matrix: Any,
    expected: tuple[int, ...],
    error: type[PhdesignError] = ShapeError,
) -> None:
    """Raise ``error`` (:class:`ShapeError` by default) unless ``matrix.shape == expected``.

    Parameters
    ----------
    name : str
        The matrix's name as the user knows it, e.g. ``"P2"`` or ``"L"``.
    matrix : array-like with a ``shape`` attribute
        The matrix to check (numpy array or sympy matrix).
    expected : tuple of int
        The required shape.
    error : PhdesignError subclass
        The exception to raise, for callers whose family is not the model's (e.g. an
        :class:`ObserverError` for sensors and gains).
    """
    found = tuple(int(s) for s in matrix.shape)
    if found != tuple(expected):
        raise error(
            f"Incompatible dimensions of {name} matrix; "
            f"expected {tuple(expected)} but found {found}"
        )
