r"""Point outputs: the displacement and the named fields of a model, read at points.

A point output is a field of the model (:mod:`phdesign.symbolic.fields`) at one point
:math:`z_0` of :math:`[a, b]`: the displacement ``w(1)`` or a named field such as the
Timoshenko beam's rotation ``rotation(1)`` = :math:`\phi(1) = \int_0^1 x_3\, dz`.  It is a
:class:`~phdesign.numeric.discretization.functionals.Functional` of kind
``"displacement"``, so its row on a discretization is
:meth:`~phdesign.numeric.discretization.functionals.Functional.row`.  ``simulate``
(``at``), ``export`` (``points``) and the state-space exports (``at``) read them here, as
``noise`` and ``tune`` read their performance outputs: a number is the displacement
there, text ``name(z0)`` a field.

Names: the output is called ``rotation(1)`` (:attr:`Functional.name`); its estimate in a
simulation is ``rotation_hat(1)`` (:func:`estimate_name`), as ``w_hat`` is ``w``'s.

Examples
--------
>>> from phdesign.models import load_builtin
>>> from phdesign.numeric.bridge import to_numeric
>>> nm = to_numeric(load_builtin("timoshenko"))
>>> [f.name for f in point_outputs(nm, [1, "rotation(0.5)"])]
['w(1)', 'rotation(0.5)']
>>> estimate_name(point_outputs(nm, "rotation(1)")[0])
'rotation_hat(1)'
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.functionals import Functional, displacement_at, field_names
from phdesign.numeric.discretization.phs import DiscretePHS

__all__ = [
    "estimate_name",
    "field_names",
    "point_outputs",
    "point_rows",
    "point_series",
    "unit_key",
]

_FIELD_AT = re.compile(r"\s*(?P<field>[^\W\d]\w*)\s*\((?P<point>[^()]*)\)\s*\Z")


def point_outputs(nm: NumericModel, items: Any, name: str = "at") -> tuple[Functional, ...]:
    """Read point outputs: numbers (the displacement there) or ``"field(z0)"``.

    Parameters
    ----------
    nm : NumericModel
    items : number, str, Functional or a sequence of them, or None
        ``1`` and ``"1"`` are ``w(1)``; ``"rotation(0.5)"`` is a named field. None: none.
    name : str
        How the argument is called in the messages (``"--at"`` on the command line).

    Raises
    ------
    NumericError
        An unknown field (the message names the model's fields and the closest one), a
        displacement point of a model without displacement, a point outside [a, b], or two
        items that give one output name (6 significant digits).
    """
    if items is None:
        return ()
    if isinstance(items, (str, Functional)) or np.ndim(items) == 0:
        items = [items]
    given = list(items)
    out = tuple(_point(nm, item, name) for item in given)
    labels = [f.name for f in out]
    for i, label in enumerate(labels):
        if label in labels[:i]:
            first = given[labels.index(label)]
            raise NumericError(
                f"{name}: {_shown(first)} and {_shown(given[i])} both give the output "
                f"{label}; expected distinct points (6 significant digits)"
            )
    return out


def _shown(item: Any) -> str:
    """Return an item as a message shows it: a number as a float (``1.0``), else its text."""
    try:
        return repr(float(item))
    except (TypeError, ValueError):
        return str(item).strip()


def _point(nm: NumericModel, item: Any, name: str) -> Functional:
    """Read one point output (:func:`point_outputs`)."""
    if isinstance(item, Functional) and item.kind == "displacement":
        return item
    text = item.strip() if isinstance(item, str) else None
    match = _FIELD_AT.match(text) if text is not None else None
    if match is None:
        return _displacement(nm, item, name)
    try:  # an unknown field: the message names the model's fields and the closest one
        return displacement_at(nm, match.group("point"), match.group("field"))
    except NumericError as error:
        raise NumericError(f"{name}: {error}") from None


def _displacement(nm: NumericModel, item: Any, name: str) -> Functional:
    """Read a number, or text of one, as the displacement at that point."""
    a, b = nm.interval
    if nm.displacement is None:
        raise NumericError(
            f"{name}: model {nm.name!r} has no displacement: drop the displacement points"
        )
    try:
        if isinstance(item, bool):
            raise TypeError
        value = float(item)
    except (TypeError, ValueError):
        raise NumericError(
            f"{name}: expected numbers in [{a:g}, {b:g}] or fields at a point such as "
            f"{field_names(nm)[-1]}({b:g}); found {item!r}"
        ) from None
    if not (math.isfinite(value) and a <= value <= b):
        raise NumericError(f"{name}: expected numbers in [{a:g}, {b:g}]; found {value:g}")
    return displacement_at(nm, value)


def point_rows(d: DiscretePHS, outputs: Sequence[Functional]) -> np.ndarray:
    """Return the rows ``(len(outputs), dim)`` of the point outputs on ``d``."""
    if not outputs:
        return np.zeros((0, d.dim))
    return np.vstack([f.row(d) for f in outputs])


def point_series(
    outputs: Sequence[Functional],
    d: DiscretePHS,
    states: np.ndarray,
    states_hat: np.ndarray | None = None,
    d_hat: DiscretePHS | None = None,
) -> dict[str, Any]:
    r"""Return the point outputs of a run, as the fields of a simulation result.

    ``at`` (the names), ``at_values`` = :math:`X r^\top` for the states X ``(nt, dim)`` on
    ``d`` and ``at_values_hat`` likewise for the observer's states on ``d_hat`` (default
    ``d``; a lower-order observer has its own discretization, so its rows are its own).
    Empty without outputs: the result's defaults (no point outputs) stand.
    """
    if not outputs:
        return {}
    hat = None
    if states_hat is not None:
        hat = states_hat @ point_rows(d if d_hat is None else d_hat, outputs).T
    return {
        "at": tuple(f.name for f in outputs),
        "at_values": states @ point_rows(d, outputs).T,
        "at_values_hat": hat,
    }


def estimate_name(output: Functional, suffix: str = "_hat") -> str:
    """Return ``rotation_hat(1)`` for ``rotation(1)``: the estimate's (or error's) name."""
    return f"{output.field_name}{suffix}({output.point:g})"


def unit_key(output: Functional) -> str:
    """Return the key of the output's unit in a model's units: ``displacement`` for w."""
    return "displacement" if output.field_name == "w" else output.field_name
