r"""The structural checks of a BC-PHS, run once when the model is built.

:func:`validate` checks every condition of :mod:`phdesign.symbolic.model`: sizes and
budgets, parameter defaults, :math:`P_k^\top = (-1)^{k-1} P_k` exactly for :math:`k \ge 1`,
:math:`P_0(z) + P_0(z)^\top \preceq 0` and :math:`\mathcal H(z) \succ 0` on :math:`[a, b]`
(:mod:`phdesign.symbolic.definiteness`), :math:`P_N` invertible, finite entries at the
parameter defaults, the inputs and outputs (derived as power conjugates when asked), the
port identities and the plant's feedback; it returns how each condition was verified.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import sympy

from phdesign.core.errors import (
    ArgumentError,
    ExpressionError,
    ModelError,
    ParameterError,
    PortError,
    check_shape,
)
from phdesign.core.limits import check_model_dimensions, check_parameter_count
from phdesign.symbolic.closing import closed_ports
from phdesign.symbolic.conjugate import conjugate_outputs
from phdesign.symbolic.definiteness import check_definite
from phdesign.symbolic.disturbances import check_disturbances
from phdesign.symbolic.expressions import Z, canonical, vanishes
from phdesign.symbolic.feedback import check_feedback_indices
from phdesign.symbolic.fields import check_fields
from phdesign.symbolic.parser import brief, check_expression
from phdesign.symbolic.traces import linear_coefficients, trace_of
from phdesign.symbolic.units import check_units

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.model import BCPHS

__all__ = ["check_feedback", "check_finite", "check_symbols", "validate"]


def validate(model: BCPHS) -> list[str]:
    """Check every structural condition; return how each one was verified."""
    _check_sizes(model)
    symbols = {s for s, _ in model.parameters}
    defaults = model.parameter_defaults
    _check_entries(model, symbols, defaults)
    checks = _check_matrices(model, defaults)
    names = tuple(name for name, _ in model.fields)
    object.__setattr__(
        model,
        "units",
        check_units(model.units, model.parameter_names, model.state_names, fields=names),
    )
    _check_fields(model)
    checks += _check_all_ports(model, symbols, defaults)
    if model.feedback is not None:
        checks += check_feedback(model, symbols, defaults)
    checks += check_disturbances(model)
    return checks


def _check_sizes(model: BCPHS) -> None:
    """Check the name, N, n, the interval, the shapes of P_k and H, budgets and labels."""
    if not isinstance(model.name, str) or not model.name.strip():
        raise ModelError(f"name must be non-empty text; found {model.name!r}")
    if not isinstance(model.order, int) or isinstance(model.order, bool) or model.order < 1:
        raise ModelError(f"order must be an integer N >= 1; found {model.order!r}")
    if not isinstance(model.size, int) or model.size < 1:
        raise ModelError(f"size must be an integer n >= 1; found {model.size!r}")
    N, n = model.order, model.size
    a, b = model.interval
    if not (a.is_number and b.is_number and bool(a < b)):
        raise ModelError(f"interval must hold numbers a < b; found [{a}, {b}]")
    if len(model.P) != N + 1:
        raise ModelError(f"P must hold P0..P{N}, {N + 1} matrices; found {len(model.P)}")
    check_shape("H", model.H, (n, n))
    for k, P_k in enumerate(model.P):
        check_shape(f"P{k}", P_k, (n, n))
    check_model_dimensions(N, n)
    check_parameter_count(len(model.parameters))
    _check_state_names(model.state_names, n)


def _check_entries(
    model: BCPHS, symbols: set[sympy.Symbol], defaults: Mapping[sympy.Symbol, sympy.Expr]
) -> None:
    """Numeric defaults; z only in P_0 and H; known symbols; entries the parser could build."""
    for s, value in model.parameters:
        if not value.is_number:
            raise ParameterError(f"default of parameter {s} must be a number; found {value}")
    _check_constant_P(model.P)
    for k, P_k in enumerate(model.P):
        check_symbols(P_k, f"P{k}", symbols | ({Z} if k == 0 else set()))
    check_symbols(model.H, "H", symbols | {Z})
    for matrix, label in ((model.H, "H"), *((P_k, f"P{k}") for k, P_k in enumerate(model.P))):
        for (i, j), entry in sympy.ImmutableMatrix(matrix).todok().items():
            check_expression(entry, f"{label}[{i + 1},{j + 1}]")
    for k, P_k in enumerate(model.P):
        check_finite(P_k, f"P{k}", defaults)
    check_finite(model.H, "H", defaults)


def _check_matrices(model: BCPHS, defaults: Mapping[sympy.Symbol, sympy.Expr]) -> list[str]:
    r"""Check the conditions on the matrices; return how each one was verified.

    :math:`P_k^\top = (-1)^{k-1} P_k`, :math:`P_0 + P_0^\top \preceq 0`, :math:`P_N`
    invertible, :math:`\mathcal H = \mathcal H^\top \succ 0`.
    """
    N = model.order
    for k in range(1, N + 1):
        sign = (-1) ** (k - 1)
        residual = (model.P[k].T - sign * model.P[k]).applyfunc(canonical)
        if not all(vanishes(x) for x in residual):
            relation = f"P{k}^T = P{k}" if sign == 1 else f"P{k}^T = -P{k}"
            raise ModelError(
                f"P{k} must satisfy {relation} (k = {k}); found P{k}^T - ({sign})*P{k} = "
                f"{residual.tolist()}"
            )
    checks = ["P_k symmetry: exact"]
    P0_sym = model.P[0] + model.P[0].T
    checks.append(
        check_definite(P0_sym, "P0 + P0^T", model.interval, defaults, sign=-1, strict=False)
    )
    checks.append(_check_invertible(model.P[N], f"P{N}", defaults))
    residual = (model.H - model.H.T).applyfunc(canonical)
    if not all(vanishes(x) for x in residual):
        raise ModelError(f"H must be symmetric; found H - H^T = {residual.tolist()}")
    checks.append(check_definite(model.H, "H", model.interval, defaults))
    return checks


def _check_all_ports(
    model: BCPHS, symbols: set[sympy.Symbol], defaults: Mapping[sympy.Symbol, sympy.Expr]
) -> list[str]:
    """Check the inputs, the outputs (derived when asked) and the port identities."""
    checks = []
    _check_ports(model, symbols, ("inputs",))
    if model.derived_outputs and not model.outputs:
        outputs = conjugate_outputs(model.P, model.order, model.inputs, model.interval, defaults)
        object.__setattr__(model, "outputs", outputs)
        checks.append("outputs: derived, the least-norm power conjugates of the inputs")
    _check_ports(model, symbols, ("outputs",))
    try:
        model.ports  # noqa: B018 - derives the ports (checking the identities) and caches them
    except PortError as exc:
        # the outputs at fault, named (imported on a failure only: a valid model never asks)
        from phdesign.symbolic.output_faults import outputs_fault_message

        located = outputs_fault_message(model, defaults)
        if not located:
            raise
        raise PortError(f"{exc}; {located}") from None
    checks.append("port identities: exact")
    return checks


def check_feedback(
    model: BCPHS, symbols: set[sympy.Symbol], defaults: Mapping[sympy.Symbol, sympy.Expr]
) -> list[str]:
    r"""Validate the model's feedback: indices, gain, :math:`K + K^\top \succeq 0`, identities.

    Returns how each condition was checked (nothing without a feedback).
    """
    feedback = model.feedback
    if feedback is None:
        return []
    check_feedback_indices(feedback, model.order * model.size)
    K = feedback.gain
    if Z in K.free_symbols:
        raise ModelError("feedback gain K must not depend on z; it acts at the boundary")
    check_symbols(K, "feedback gain K", symbols)
    check_finite(K, "feedback gain K", defaults)
    dissipative = check_definite(
        K + K.T, "K + K^T", model.interval, defaults, sign=1, strict=False
    )
    closed_ports(model)
    return [f"feedback {dissipative}", "closed-plant identities: exact"]


def _check_fields(model: BCPHS) -> None:
    """Refuse a displacement or named field that is not well-formed (:mod:`~.fields`)."""
    fields = model.fields
    if not isinstance(fields, tuple) or not all(
        isinstance(item, tuple) and len(item) == 2 and isinstance(item[0], str) for item in fields
    ):
        raise ArgumentError(
            f"fields must be pairs (name, Field); found {type(fields).__name__} "
            f"{brief(fields, 60)}"
        )
    pairs = [("displacement", model.displacement)] if model.displacement is not None else []
    check_fields(
        [*pairs, *fields],
        model.size,
        [s for s, _ in model.parameters],
        dict(model.units),
        model.state_names,
    )


#: Characters a state label may not hold: they separate the items of an initial state.
_LABEL_SEPARATORS = frozenset(":,()[]")


def _check_state_names(names: Sequence[object], n: int) -> None:
    """Refuse labels that are not text, repeat, or could be read as another component.

    ``--x0 'x2: ...'`` and ``'e2: ...'`` address components by position; a label ``x2``
    on component 1, or any label ``e<i>``, would make such an item ambiguous.
    """
    if len(names) != n:
        raise ModelError(f"state_names must hold {n} labels; found {len(names)}")
    for i, label in enumerate(names):
        if not isinstance(label, str) or not label.strip():
            raise ModelError(f"state label {i + 1} must be non-empty text; found {label!r}")
        if any(c in _LABEL_SEPARATORS or not c.isprintable() for c in label):
            raise ModelError(
                f"state label {label!r} holds a separator or control character; expected "
                "none of : , ( ) [ ] and no control characters"
            )
        match = _COMPONENT_NAME.fullmatch(label.strip())
        if match is not None and (match[1] == "e" or int(match[2]) != i + 1):
            raise ModelError(
                f"state label {label!r} of component {i + 1} is ambiguous: it names "
                f"{'the effort' if match[1] == 'e' else 'state component'} {match[2]}; "
                f"expected a label other than x<j> (j != {i + 1}) and e<j>"
            )
    if len({str(label).strip() for label in names}) != n:
        raise ModelError(f"state labels must be distinct; found {list(names)}")


_COMPONENT_NAME = re.compile(r"([xe])(\d+)")


def _check_constant_P(P: Sequence[sympy.MatrixBase]) -> None:
    """Refuse z in P_1..P_N, saying why (only P_0 and H may vary along the domain)."""
    for k, P_k in enumerate(P):
        if k == 0:
            continue
        for (i, j), entry in sympy.ImmutableMatrix(P_k).todok().items():
            if Z in entry.free_symbols:
                raise ExpressionError(
                    f"P{k}[{i + 1},{j + 1}] = {entry}: the spatial variable z is not allowed in "
                    f"P{k}: the boundary port variables (Q, W_B, W_C) and the energy identity "
                    "are derived for constant P_1..P_N; only P0 and H may depend on z"
                )


def check_finite(
    matrix: sympy.MatrixBase, name: str, defaults: Mapping[sympy.Symbol, sympy.Expr]
) -> None:
    """Refuse entries that are infinite or undefined at the parameter defaults (1/rho, rho = 0)."""
    for (i, j), entry in sympy.ImmutableMatrix(matrix).todok().items():
        value = entry.xreplace(dict(defaults))
        if value.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan):
            values = ", ".join(
                f"{s} = {v}" for s, v in defaults.items() if s in entry.free_symbols
            )
            raise ModelError(
                f"{name}[{i + 1},{j + 1}] = {entry} is not finite at the parameter defaults "
                f"({values or 'no parameters'}); expected a finite value"
            )


def check_symbols(matrix: sympy.MatrixBase, name: str, allowed: set[sympy.Symbol]) -> None:
    """Refuse symbols other than ``allowed`` (parameters, and z where it may appear)."""
    unknown = sorted(str(s) for s in matrix.free_symbols - allowed)
    if unknown:
        raise ExpressionError(f"{name} holds unknown symbols {', '.join(unknown)}")


def _check_ports(model: BCPHS, symbols: set[sympy.Symbol], kinds: Sequence[str]) -> None:
    expected = model.order * model.size
    for kind in kinds:
        exprs = getattr(model, kind)
        if len(exprs) != expected:
            raise ModelError(
                f"{kind}: an order-{model.order} model of size {model.size} needs "
                f"N*n = {expected} {kind}; found {len(exprs)}"
            )
        for i, expr in enumerate(exprs):
            what = f"{kind}[{i + 1}]"
            coefficients = linear_coefficients(expr, what=what)
            for trace in coefficients:
                if not (1 <= trace.component <= model.size and trace.derivative < model.order):
                    raise ExpressionError(
                        f"{what} uses {trace.label(model.interval)}, outside components "
                        f"1..{model.size} "
                        f"and derivatives 0..{model.order - 1}"
                    )
            other = {s for s in expr.free_symbols if trace_of(s) is None} - symbols
            if other:
                names = ", ".join(sorted(str(s) for s in other))
                raise ExpressionError(f"{what} holds unknown symbols {names}")


def _check_invertible(
    P: sympy.MatrixBase, name: str, defaults: Mapping[sympy.Symbol, sympy.Expr]
) -> str:
    det = canonical(P.det())
    if det == 0:
        raise ModelError(f"{name} must be invertible; found det({name}) = 0")
    if det.free_symbols:
        value = canonical(det.xreplace(dict(defaults)))
        if value == 0:
            raise ModelError(
                f"{name} must be invertible; found det({name}) = 0 at the parameter defaults"
            )
        return f"{name} invertible: det = {det}, nonzero at the parameter defaults"
    return f"{name} invertible: exact"
