r"""Reading the parts of a model definition from numbers, text and nested lists, exactly.

:meth:`BCPHS.define <phdesign.symbolic.model.BCPHS.define>` (and a model file, through
:mod:`phdesign.io`) gives the parameters and their defaults, the interval, the matrices
:math:`P_0, \dots, P_N` and :math:`\mathcal H(z)`, and the inputs and outputs as trace
expressions.  The functions here read each part exactly (floats through their shortest
decimal form, text through the safe parser) and refuse what is malformed with an error
that names the part; the conditions *between* the parts (symmetries, definiteness, the
port identities) are checked by :mod:`phdesign.symbolic.validation` once the model is
built.  Every expression is kept in the form that reads back as itself, so that a written
model reads back exactly.

Examples
--------
>>> parse_matrix([[0, "1/rho"], ["1/rho", 0]], "P1", ["rho"])
Matrix([
[    0, 1/rho],
[1/rho,     0]])
>>> parse_interval([0, 0.5])
(0, 1/2)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import sympy

from phdesign.core.errors import ExpressionError, ModelError
from phdesign.core.limits import check_model_dimensions, check_parameter_count
from phdesign.symbolic.expressions import (
    check_parameter_name,
    exact_number,
    exactify,
    parameter_symbol,
    parse_scalar,
)
from phdesign.symbolic.fields import Displacement
from phdesign.symbolic.parser import check_expression
from phdesign.symbolic.printing import format_expression
from phdesign.symbolic.traces import parse_trace_expression

__all__ = [
    "Displacement",
    "parse_P",
    "parse_interval",
    "parse_matrix",
    "parse_parameters",
    "parse_ports",
    "parse_units",
]


def parse_parameters(
    parameters: Mapping[str, object] | None, order: int, H: Any
) -> tuple[list[str], tuple[tuple[sympy.Symbol, sympy.Expr], ...]]:
    """Return the parameter names and their exact defaults ``(symbol, value)``.

    The budgets come first: the number of parameters, and the model's dimensions from the
    rows of ``H`` before any entry is parsed.
    """
    if parameters is not None and not isinstance(parameters, Mapping):
        raise ModelError(f"parameters must be a table of name = value; found {parameters!r}")
    check_parameter_count(len(parameters or {}))
    if isinstance(H, Sequence) and not isinstance(H, str):
        check_model_dimensions(order, len(H))  # before any entry is parsed
    names = list(parameters or {})
    for parameter in names:
        check_parameter_name(parameter)
    defaults = tuple(
        (parameter_symbol(p), exact_number(v, f"parameter {p}"))
        for p, v in (parameters or {}).items()
    )
    return names, defaults


def parse_interval(interval: Sequence[object]) -> tuple[sympy.Expr, sympy.Expr]:
    """Return the exact endpoints ``(a, b)``, refusing anything but a pair with ``a < b``."""
    if isinstance(interval, str) or not isinstance(interval, Sequence) or len(interval) != 2:
        raise ModelError(f"interval must be a pair [a, b]; found {interval!r}")
    a, b = (exact_number(p, "interval endpoint") for p in interval)
    if not a < b:
        raise ModelError(f"interval must have a < b; found [{a}, {b}]")
    return a, b


def parse_P(
    P: Mapping[int, Any] | Sequence[Any], order: int, size: int, parameters: Sequence[str]
) -> tuple[sympy.ImmutableMatrix, ...]:
    """Return ``P_0 .. P_N`` from ``{k: P_k}`` or a list; the omitted ones are zero."""
    if isinstance(P, str) or not isinstance(P, Mapping | Sequence):
        raise ModelError(f"P must map k to P_k (or list P_0..P_N); found {P!r}")
    P_by_order = dict(P) if isinstance(P, Mapping) else dict(enumerate(P))
    for k in P_by_order:
        if not isinstance(k, int) or not 0 <= k <= order:
            raise ModelError(
                f"P{k} is not a matrix of an order-{order} model; expected P0..P{order}"
            )
    return tuple(
        parse_matrix(P_by_order[k], f"P{k}", parameters, allow_z=True)
        if k in P_by_order
        else sympy.ImmutableMatrix.zeros(size, size)
        for k in range(order + 1)
    )


def parse_ports(
    inputs: Sequence[str | sympy.Expr],
    outputs: Sequence[str | sympy.Expr] | str | None,
    interval: tuple[sympy.Expr, sympy.Expr],
    order: int,
    size: int,
    parameters: Sequence[str],
) -> tuple[tuple[sympy.Expr, ...], tuple[sympy.Expr, ...], bool]:
    r"""Return ``(inputs, outputs, derived)``: the trace expressions, read exactly.

    ``outputs`` of ``"conjugate"`` or ``None`` are derived: the returned outputs are then
    empty (the validation derives them once :math:`P_1, \dots, P_N` are known to be valid)
    and ``derived`` is true.
    """
    derived = outputs is None or outputs == "conjugate"
    ports: dict[str, tuple[sympy.Expr, ...]] = {"outputs": ()}
    for kind, texts in (("inputs", inputs), ("outputs", outputs)):
        if kind == "outputs" and derived:
            continue
        if isinstance(texts, str) or not isinstance(texts, Sequence):
            expected = ' or "conjugate"' if kind == "outputs" else ""
            raise ModelError(
                f"{kind} must be a list of trace expressions{expected}; found {texts!r}"
            )
        ports[kind] = tuple(
            _port(t, interval, order, size, parameters, what=f"{kind}[{i + 1}]")
            for i, t in enumerate(texts)
        )
    return ports["inputs"], ports["outputs"], derived


def _port(
    value: object,
    interval: tuple[sympy.Expr, sympy.Expr],
    order: int,
    size: int,
    parameters: Sequence[str],
    what: str,
) -> sympy.Expr:
    if isinstance(value, str):
        expr = parse_trace_expression(value, interval, order, size, parameters, what=what)
    elif isinstance(value, sympy.Expr):
        expr = check_expression(exactify(value), what)
    else:
        raise ExpressionError(
            f'{what} must be a trace expression such as "e1(0)"; found {type(value).__name__} '
            f"{value!r}"
        )
    # the form that reads back as itself (module docstring of phdesign.io: exact round trips)
    text = format_expression(expr, interval)
    return parse_trace_expression(text, interval, order, size, parameters, what=what)


def parse_units(units: object) -> tuple[tuple[Any, Any], ...]:
    """Return the stated units as ``(quantity, unit)`` pairs (checked by the validation)."""
    if units is None:
        return ()
    if not isinstance(units, Mapping):
        raise ModelError(
            f"units must be a mapping {{quantity: unit}} such as {{'t': 's'}}; found {units!r}"
        )
    return tuple(units.items())


def parse_matrix(
    value: Any, name: str, parameters: Sequence[str], allow_z: bool = False, square: bool = True
) -> sympy.ImmutableMatrix:
    """Read a matrix of numbers or expression strings (rows of a list) exactly.

    It must be square unless ``square`` is false (a boundary system's input matrices,
    the disturbances' ``B``, n x q).
    """
    if isinstance(value, sympy.MatrixBase):
        rows = value.tolist()
    elif isinstance(value, Sequence) and not isinstance(value, str):
        rows = [
            list(r) if isinstance(r, Sequence) and not isinstance(r, str) else r for r in value
        ]
    elif hasattr(value, "tolist"):  # numpy arrays, without importing numpy here
        rows = value.tolist()
    else:
        raise ModelError(
            f"{name} must be a {'square ' if square else ''}matrix given as a list of rows; "
            f"found {value!r}"
        )
    if not rows or not all(isinstance(r, list) for r in rows):
        raise ModelError(f"{name} must be a non-empty list of rows; found {value!r}")
    width = len(rows[0])
    for i, row in enumerate(rows):
        if len(row) != width:
            raise ModelError(f"{name} row {i + 1} has {len(row)} entries; expected {width}")
    if square and len(rows) != width:
        raise ModelError(f"{name} must be square; found {len(rows)} x {width}")
    entries = [
        [_entry(x, f"{name}[{i + 1},{j + 1}]", parameters, allow_z) for j, x in enumerate(row)]
        for i, row in enumerate(rows)
    ]
    return sympy.ImmutableMatrix(entries)


def _entry(value: object, what: str, parameters: Sequence[str], allow_z: bool) -> sympy.Expr:
    if isinstance(value, str):
        expr = parse_scalar(value, parameters, allow_z=allow_z, what=what)
    elif isinstance(value, sympy.Expr):
        expr = check_expression(exactify(value), what)
    else:
        return exact_number(value, what)
    # sympy builds (z + d)/atan(1) as 4*(d + z)/pi, which reads back as (4*d + 4*z)/pi:
    # keep the form that reads back as itself, so that written models read back exactly
    return parse_scalar(format_expression(expr), parameters, allow_z=allow_z, what=what)
