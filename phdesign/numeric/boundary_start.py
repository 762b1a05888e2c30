r"""Initial states of the boundary systems: where a coupled simulation starts them.

A coupled model's state is the field :math:`x(z)` and the boundary systems' states
:math:`x_c` (:mod:`phdesign.numeric.boundary`).  The user gives :math:`x_c(0)` in the
model's own states (a mass's momentum, a winding's flux), in the same text as the field:

    ``"x1: sin(pi*z), mass momentum: 0.5"``

each boundary state by its label (the model's ``states`` of the boundary system) or by
``<name>.x<i>`` (``mass.x1``), its value a number or an expression in the parameters (no
``z``: a boundary state is one number).  The discretizations carry the effort
:math:`e_c = Q_c x_c = E_c^{-1} x_c`, so that :math:`H_c = \tfrac12 x_c^\top Q_c x_c =
\tfrac12 e_c^\top E_c e_c` (:mod:`phdesign.numeric.discretization.coupled`).  States not
given start at rest.

Examples
--------
>>> from phdesign.models import load_builtin
>>> from phdesign.numeric.bridge import to_numeric
>>> nm = to_numeric(load_builtin("string-tip-mass"), {"m": 2})
>>> x0 = with_boundary_states(None, {"mass momentum": 0.5}, nm)
>>> x0.boundary, boundary_efforts(nm.boundary, x0)  # e_c = x_c / m: the mass's velocity
(array([0.5]), array([0.25]))
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.errors import ParameterError
from phdesign.numeric.boundary import NumericBoundary

__all__ = [
    "CoupledInitialState",
    "boundary_efforts",
    "boundary_items",
    "boundary_names",
    "constants",
    "difference",
    "with_boundary_states",
]

Field = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class CoupledInitialState:
    r"""An initial state of a coupled model: the field :math:`x_0(z)` and :math:`x_c(0)`.

    Called with the points z it is the field (``(m, n)``), as any initial state; the
    discretizations append :math:`e_c(0) = Q_c x_c(0)` from ``boundary``.

    Parameters
    ----------
    field : callable
        ``x0(z) -> (m, n)``.
    boundary : ndarray
        :math:`x_c(0)` of every boundary system, in the model's order.
    """

    field: Field = field(repr=False)
    boundary: np.ndarray

    def __call__(self, z: np.ndarray) -> np.ndarray:
        """Return the field at the points z."""
        return self.field(z)


def boundary_names(boundaries: Sequence[NumericBoundary]) -> dict[str, int]:
    """Return each boundary state's names (label and ``<name>.x<i>``) -> its index."""
    names: dict[str, int] = {}
    offset = 0
    for b in boundaries:
        for i, label in enumerate(b.state_labels):
            names[label] = names[f"{b.name}.x{i + 1}"] = offset + i
        offset += b.size
    return names


def _field_at_rest(size: int) -> Field:
    return lambda z: np.zeros((np.atleast_1d(z).size, size))


def with_boundary_states(
    x0: Field | None,
    values: Mapping[str, Any] | Sequence[Any] | np.ndarray | None,
    nm: Any,
    what: str = "initial state",
) -> Field:
    """Return ``x0`` (None: at rest) with the boundary states ``values``.

    ``values`` maps names (module docstring) to numbers, or lists every boundary state in
    the model's order; None leaves ``x0`` as it is.

    Raises
    ------
    ParameterError
        The model has no boundary systems, a name is unknown or given twice, the list has
        the wrong length, or a value is not a finite number.
    """
    base = x0 if x0 is not None else _field_at_rest(nm.size)
    if values is None:
        return base
    names = boundary_names(nm.boundary)
    size = sum(b.size for b in nm.boundary)
    labels = [label for b in nm.boundary for label in b.state_labels]
    if not size:
        raise ParameterError(
            f"{what}: boundary states given, but model {nm.name!r} has no boundary systems"
        )
    state = np.zeros(size)
    if isinstance(values, Mapping):
        for key, value in values.items():
            if key not in names:
                raise ParameterError(
                    f"{what}: unknown boundary state {key!r}; expected one of {', '.join(names)}"
                )
            state[names[key]] = _number(value, f"{what} boundary state {key!r}")
    else:
        given = np.atleast_1d(np.asarray(values, dtype=object))
        if given.ndim != 1 or given.size != size:
            raise ParameterError(
                f"{what}: expected {size} boundary states ({', '.join(labels)}); found "
                f"{given.size}"
            )
        state = np.array(
            [_number(v, f"{what} boundary state {labels[i]!r}") for i, v in enumerate(given)]
        )
    return CoupledInitialState(getattr(base, "field", base), state)


def _number(value: Any, what: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{what} must be a number; found {value!r}") from None
    if not np.isfinite(number):
        raise ParameterError(f"{what} must be finite; found {value!r}")
    return number


def boundary_items(items: Sequence[str], nm: Any) -> tuple[list[str], dict[str, str]]:
    """Split ``name: expression`` items into the field's and the boundary states' (by name)."""
    names = boundary_names(nm.boundary)
    field_items: list[str] = []
    boundary: dict[str, str] = {}
    for item in items:
        key = item.partition(":")[0].strip()
        if key not in names:
            field_items.append(item)
            continue
        if any(names[other] == names[key] for other in boundary):
            raise ParameterError(f"initial state: boundary state {key!r} given twice")
        boundary[key] = item.partition(":")[2].strip()
    return field_items, boundary


def constants(
    texts: Mapping[str, str], parse: Callable[..., Any], what: str
) -> dict[str, float] | None:
    """Return the boundary states' values from their expressions (parameters, no ``z``).

    ``parse(text, what=...)`` reads an expression in z and the parameters, substituted
    (:mod:`phdesign.numeric.inputs`); None when ``texts`` is empty.
    """
    if not texts:
        return None
    values = {}
    for name, text in texts.items():
        label = f"{what} boundary state {name!r}"
        expr = parse(text, what=label)
        if any(str(s) == "z" for s in expr.free_symbols):
            raise ParameterError(f"{label} is one number, not a function of z; found {text!r}")
        values[name] = _number(expr, label)
    return values


def boundary_efforts(boundaries: Sequence[NumericBoundary], x0: Any) -> np.ndarray:
    r"""Return :math:`e_c(0) = E_c^{-1} x_c(0)` of every system (zero when ``x0`` has none)."""
    size = sum(b.size for b in boundaries)
    state = getattr(x0, "boundary", None)
    if state is None:
        return np.zeros(size)
    out, offset = [], 0
    for b in boundaries:
        out.append(np.linalg.solve(b.E, state[offset : offset + b.size]))
        offset += b.size
    return np.concatenate(out) if out else np.zeros(0)


def difference(f: Field, g: Field) -> Field:
    """Return the initial estimation error ``f - g``, boundary states included."""

    def diff(z: np.ndarray) -> np.ndarray:
        return np.asarray(np.asarray(f(z), dtype=float) - np.asarray(g(z), dtype=float))

    fb: Any = getattr(f, "boundary", None)
    gb: Any = getattr(g, "boundary", None)
    if fb is None and gb is None:
        return diff
    state = np.asarray((0.0 if fb is None else fb) - (0.0 if gb is None else gb), dtype=float)
    return CoupledInitialState(diff, state)
