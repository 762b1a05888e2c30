r"""The validated symbolic boundary-controlled port-Hamiltonian system (BC-PHS).

.. math::

    \partial_t x(z, t) = \sum_{k=0}^{N} P_k \partial_z^k\big(\mathcal H(z) x(z, t)\big),
    \qquad z \in [a, b],

with :math:`P_k^\top = (-1)^{k-1} P_k` for :math:`k \ge 1`, :math:`P_0 + P_0^\top \preceq 0`,
:math:`P_N` invertible and :math:`\mathcal H(z) = \mathcal H(z)^\top \succeq m I > 0`.
Inputs and outputs are linear combinations of the boundary traces
:math:`\partial_z^k e_i(a)`, :math:`\partial_z^k e_i(b)` of the effort :math:`e = \mathcal H x`
(:mod:`phdesign.symbolic.expressions`), checked against the port identities of
:mod:`phdesign.symbolic.ports` when the model is built.

Examples
--------
>>> wave = BCPHS.define(
...     name="string", interval=(0, 1), order=1,
...     P={1: [[0, 1], [1, 0]]}, H=[["1/rho", 0], [0, "T"]],
...     parameters={"rho": 1, "T": 1},
...     inputs=["e1(0)", "e2(1)"], outputs=["-e2(0)", "e1(1)"],
... )
>>> wave.order, wave.size, [str(s) for s, _ in wave.parameters]
(1, 2, ['rho', 'T'])
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import sympy

from phdesign.errors import ExpressionError, ModelError, ParameterError, check_shape
from phdesign.limits import check_model_dimensions, check_parameter_count
from phdesign.symbolic.definiteness import check_definite
from phdesign.symbolic.expressions import (
    Z,
    canonical,
    check_parameter_name,
    exact_number,
    exactify,
    linear_coefficients,
    parameter_symbol,
    parse_scalar,
    parse_trace_expression,
    trace_of,
    vanishes,
)
from phdesign.symbolic.parser import check_expression

__all__ = ["BCPHS", "Displacement", "Z"]


@dataclass(frozen=True)
class Displacement:
    r"""How to recover a physical displacement :math:`w(z, t)` from the state.

    :math:`w` is ``integrations`` antiderivatives of state component ``component``
    (1-based, of :math:`x`), each from :math:`z = a` with value zero there. For the
    Euler-Bernoulli beam :math:`x_2 = \partial_z^2 w` and the beam is clamped at
    :math:`a`, so ``Displacement(component=2, integrations=2)``.
    """

    component: int
    integrations: int


@dataclass(frozen=True)
class BCPHS:
    r"""A validated symbolic BC-PHS (see the module docstring for the equations).

    Build one with :meth:`define` (from strings and numbers) or from a model file
    with :func:`phdesign.io.read_model`. Construction validates every condition and
    raises :class:`~phdesign.errors.ModelError`, :class:`~phdesign.errors.ExpressionError`
    or :class:`~phdesign.errors.PortError` naming what is wrong.

    Attributes
    ----------
    name : str
        A human-readable name.
    interval : tuple of sympy.Expr
        Exact endpoints ``(a, b)`` with ``a < b``.
    order : int
        The differential order ``N``.
    size : int
        The number ``n`` of state components.
    P : tuple of sympy.ImmutableMatrix
        ``P_0 .. P_N``, constant ``n x n`` matrices (entries may hold parameters).
    H : sympy.ImmutableMatrix
        The energy density :math:`\mathcal H(z)`, in ``z`` and the parameters.
    parameters : tuple of (sympy.Symbol, sympy.Expr)
        Parameters and their exact default values.
    inputs, outputs : tuple of sympy.Expr
        ``N n`` trace expressions each.
    state_names : tuple of str
        One label per state component.
    description : str
        Free text.
    displacement : Displacement or None
        How to recover a displacement field, when the model has one.
    checks : tuple of str
        How each condition was verified (exactly, or at the defaults on a grid).
    """

    name: str
    interval: tuple[sympy.Expr, sympy.Expr]
    order: int
    size: int
    P: tuple[sympy.ImmutableMatrix, ...]
    H: sympy.ImmutableMatrix
    parameters: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    inputs: tuple[sympy.Expr, ...]
    outputs: tuple[sympy.Expr, ...]
    state_names: tuple[str, ...] = ()
    description: str = ""
    displacement: Displacement | None = None
    checks: tuple[str, ...] = field(default=(), compare=False, repr=False)

    def __post_init__(self) -> None:
        if not self.state_names:
            object.__setattr__(self, "state_names", tuple(f"x{i + 1}" for i in range(self.size)))
        object.__setattr__(self, "checks", tuple(_validate(self)))

    # ------------------------------------------------------------------ construction
    @classmethod
    def define(
        cls,
        *,
        name: str,
        interval: Sequence[object],
        order: int,
        P: Mapping[int, Any] | Sequence[Any],
        H: Any,
        inputs: Sequence[str | sympy.Expr],
        outputs: Sequence[str | sympy.Expr],
        parameters: Mapping[str, object] | None = None,
        state_names: Sequence[str] = (),
        description: str = "",
        displacement: Displacement | None = None,
    ) -> BCPHS:
        r"""Build a model from numbers, strings and nested lists.

        Parameters
        ----------
        name : str
            A human-readable name.
        interval : (a, b)
            Numeric endpoints.
        order : int
            The order ``N`` of the differential operator.
        P : mapping {k: matrix} or sequence of matrices
            ``P_k``; omitted ones are zero. Entries are numbers or expression strings
            in the parameters.
        H : matrix
            :math:`\mathcal H(z)`; entries are numbers or strings in ``z`` and the parameters.
        inputs, outputs : sequence of str
            Trace expressions, ``N n`` of each.
        parameters : mapping {name: default value}, optional
            Parameters that may appear in ``P``, ``H`` and the ports.
        state_names : sequence of str, optional
            Labels of the state components.
        description : str, optional
            Free text.
        displacement : Displacement, optional
            How to recover a displacement field.
        """
        if not isinstance(order, int) or isinstance(order, bool) or order < 1:
            raise ModelError(f"order must be an integer N >= 1; found {order!r}")
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
        endpoints = _interval(interval)
        H_matrix = _matrix(H, "H", names, allow_z=True)
        size = H_matrix.shape[0]
        P_by_order = dict(P) if isinstance(P, Mapping) else dict(enumerate(P))
        for k in P_by_order:
            if not isinstance(k, int) or not 0 <= k <= order:
                raise ModelError(
                    f"P{k} is not a matrix of an order-{order} model; expected P0..P{order}"
                )
        P_matrices = tuple(
            _matrix(P_by_order[k], f"P{k}", names, allow_z=False)
            if k in P_by_order
            else sympy.ImmutableMatrix.zeros(size, size)
            for k in range(order + 1)
        )
        ports = {}
        for kind, texts in (("inputs", inputs), ("outputs", outputs)):
            if isinstance(texts, str) or not isinstance(texts, Sequence):
                raise ModelError(f"{kind} must be a list of trace expressions; found {texts!r}")
            ports[kind] = tuple(
                _port(t, endpoints, order, size, names, what=f"{kind}[{i + 1}]")
                for i, t in enumerate(texts)
            )
        return cls(
            name=name,
            interval=endpoints,
            order=order,
            size=size,
            P=P_matrices,
            H=H_matrix,
            parameters=defaults,
            inputs=ports["inputs"],
            outputs=ports["outputs"],
            state_names=tuple(state_names),
            description=description,
            displacement=displacement,
        )

    # ------------------------------------------------------------------ views
    @property
    def parameter_defaults(self) -> dict[sympy.Symbol, sympy.Expr]:
        """The parameters' default values, keyed by symbol."""
        return dict(self.parameters)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """The parameters' names, in declaration order."""
        return tuple(symbol.name for symbol, _ in self.parameters)

    def with_parameters(self, values: Mapping[str, object]) -> BCPHS:
        """Return the same model with new default values for some parameters.

        Raises
        ------
        ParameterError
            If a name is not a parameter of the model or a value is not a finite number.
        """
        known = self.parameter_names
        updated = dict(self.parameters)
        for name, value in values.items():
            if name not in known:
                raise ParameterError(
                    f"unknown parameter {name!r}; the model's parameters are "
                    f"{', '.join(known) if known else 'none'}"
                )
            try:
                updated[parameter_symbol(name)] = exact_number(value, f"parameter {name}")
            except ExpressionError as error:
                raise ParameterError(str(error)) from None
        return replace(self, parameters=tuple(updated.items()))


# ---------------------------------------------------------------------- helpers


def _port(
    value: object,
    interval: tuple[sympy.Expr, sympy.Expr],
    order: int,
    size: int,
    parameters: Sequence[str],
    what: str,
) -> sympy.Expr:
    if isinstance(value, str):
        return parse_trace_expression(value, interval, order, size, parameters, what=what)
    if isinstance(value, sympy.Expr):
        return exactify(value)
    raise ExpressionError(
        f'{what} must be a trace expression such as "e1(0)"; found {type(value).__name__} '
        f"{value!r}"
    )


def _interval(interval: Sequence[object]) -> tuple[sympy.Expr, sympy.Expr]:
    if isinstance(interval, str) or not isinstance(interval, Sequence) or len(interval) != 2:
        raise ModelError(f"interval must be a pair [a, b]; found {interval!r}")
    a, b = (exact_number(p, "interval endpoint") for p in interval)
    if not a < b:
        raise ModelError(f"interval must have a < b; found [{a}, {b}]")
    return a, b


def _matrix(
    value: Any, name: str, parameters: Sequence[str], allow_z: bool
) -> sympy.ImmutableMatrix:
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
            f"{name} must be a square matrix given as a list of rows; found {value!r}"
        )
    if not rows or not all(isinstance(r, list) for r in rows):
        raise ModelError(f"{name} must be a non-empty list of rows; found {value!r}")
    width = len(rows[0])
    for i, row in enumerate(rows):
        if len(row) != width:
            raise ModelError(f"{name} row {i + 1} has {len(row)} entries; expected {width}")
    if len(rows) != width:
        raise ModelError(f"{name} must be square; found {len(rows)} x {width}")
    entries = [
        [_entry(x, f"{name}[{i + 1},{j + 1}]", parameters, allow_z) for j, x in enumerate(row)]
        for i, row in enumerate(rows)
    ]
    return sympy.ImmutableMatrix(entries)


def _entry(value: object, what: str, parameters: Sequence[str], allow_z: bool) -> sympy.Expr:
    if isinstance(value, str):
        return parse_scalar(value, parameters, allow_z=allow_z, what=what)
    if isinstance(value, sympy.Expr):
        return exactify(value)
    return exact_number(value, what)


def _validate(model: BCPHS) -> list[str]:
    """Check every structural condition; return how each one was verified."""
    checks: list[str] = []
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

    symbols = {s for s, _ in model.parameters}
    for s, value in model.parameters:
        if not value.is_number:
            raise ParameterError(f"default of parameter {s} must be a number; found {value}")
    for k, P_k in enumerate(model.P):
        _check_symbols(P_k, f"P{k}", symbols)
    _check_symbols(model.H, "H", symbols | {Z})
    for matrix, label in ((model.H, "H"), *((P_k, f"P{k}") for k, P_k in enumerate(model.P))):
        for (i, j), entry in sympy.ImmutableMatrix(matrix).todok().items():
            check_expression(entry, f"{label}[{i + 1},{j + 1}]")

    defaults = model.parameter_defaults
    for k, P_k in enumerate(model.P):
        _check_finite(P_k, f"P{k}", defaults)
    _check_finite(model.H, "H", defaults)
    for k in range(1, N + 1):
        sign = (-1) ** (k - 1)
        residual = (model.P[k].T - sign * model.P[k]).applyfunc(canonical)
        if not all(vanishes(x) for x in residual):
            relation = f"P{k}^T = P{k}" if sign == 1 else f"P{k}^T = -P{k}"
            raise ModelError(
                f"P{k} must satisfy {relation} (k = {k}); found P{k}^T - ({sign})*P{k} = "
                f"{residual.tolist()}"
            )
    checks.append("P_k symmetry: exact")
    checks.append(
        check_definite(
            model.P[0] + model.P[0].T,
            model.interval,
            name="P0 + P0^T",
            sign=-1,
            strict=False,
            defaults=defaults,
        )
    )
    checks.append(_check_invertible(model.P[N], f"P{N}", defaults))
    residual = (model.H - model.H.T).applyfunc(canonical)
    if not all(vanishes(x) for x in residual):
        raise ModelError(f"H must be symmetric; found H - H^T = {residual.tolist()}")
    checks.append(check_definite(model.H, model.interval, name="H", defaults=defaults))
    if model.displacement is not None:
        d = model.displacement
        if not (1 <= d.component <= n) or d.integrations < 0:
            raise ModelError(
                f"displacement must name a component in 1..{n} and integrations >= 0; "
                f"found component {d.component}, integrations {d.integrations}"
            )
    _check_ports(model, symbols)
    from phdesign.symbolic.ports import derive_ports  # ports depend on a built model

    derive_ports(model)
    checks.append("port identities: exact")
    return checks


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


def _check_finite(
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


def _check_symbols(matrix: sympy.MatrixBase, name: str, allowed: set[sympy.Symbol]) -> None:
    unknown = sorted(str(s) for s in matrix.free_symbols - allowed)
    if unknown:
        raise ExpressionError(f"{name} holds unknown symbols {', '.join(unknown)}")


def _check_ports(model: BCPHS, symbols: set[sympy.Symbol]) -> None:
    expected = model.order * model.size
    for kind, exprs in (("inputs", model.inputs), ("outputs", model.outputs)):
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
