r"""The validated symbolic boundary-controlled port-Hamiltonian system (BC-PHS).

.. math::

    \partial_t x(z, t) = \sum_{k=0}^{N} P_k \partial_z^k\big(\mathcal H(z) x(z, t)\big),
    \qquad z \in [a, b],

with constant :math:`P_k^\top = (-1)^{k-1} P_k` for :math:`k \ge 1`,
:math:`P_0(z) + P_0(z)^\top \preceq 0` on :math:`[a, b]`, :math:`P_N` invertible and
:math:`\mathcal H(z) = \mathcal H(z)^\top \succeq m I > 0`.  Only :math:`P_0` and
:math:`\mathcal H` may depend on :math:`z`: the boundary port variables (:math:`Q`,
:math:`W_B`, :math:`W_C`) and the energy identity are derived for constant
:math:`P_1, \dots, P_N`, while :math:`P_0` enters the energy balance only through
:math:`\tfrac12\int e^\top (P_0 + P_0^\top) e\,dz \le 0`, pointwise in :math:`z`.
Inputs and outputs are linear combinations of the boundary traces
:math:`\partial_z^k e_i(a)`, :math:`\partial_z^k e_i(b)` of the effort :math:`e = \mathcal H x`
(:mod:`phdesign.symbolic.expressions`), checked against the port identities of
:mod:`phdesign.symbolic.ports` when the model is built (:mod:`phdesign.symbolic.validation`
runs every check).

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

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.checks import found_text
from phdesign.core.errors import ArgumentError, ExpressionError, ModelError, ParameterError
from phdesign.core.limits import check_model_dimensions, check_parameter_count
from phdesign.symbolic.display import ModelDisplay
from phdesign.symbolic.expressions import (
    Z,
    check_parameter_name,
    exact_number,
    exactify,
    parameter_symbol,
    parse_scalar,
)
from phdesign.symbolic.feedback import (
    Feedback,
    external_indices,
    feedback_from_mapping,
)
from phdesign.symbolic.parser import check_expression
from phdesign.symbolic.printing import format_expression
from phdesign.symbolic.traces import parse_trace_expression
from phdesign.symbolic.validation import validate

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.ports import Ports

__all__ = ["BCPHS", "Displacement", "Feedback", "Z", "parse_matrix", "require_model"]


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


@dataclass(frozen=True, repr=False)
class BCPHS(ModelDisplay):
    r"""A validated symbolic BC-PHS (see the module docstring for the equations).

    Build one with :meth:`define` (from strings and numbers) or from a model file
    with :func:`phdesign.io.read_model`. Construction validates every condition and
    raises :class:`~phdesign.core.errors.ModelError`,
    :class:`~phdesign.core.errors.ExpressionError`
    or :class:`~phdesign.core.errors.PortError` naming what is wrong.

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
        ``P_0 .. P_N``, ``n x n`` (entries may hold parameters); only ``P_0`` may depend
        on ``z``.
    H : sympy.ImmutableMatrix
        The energy density :math:`\mathcal H(z)`, in ``z`` and the parameters.
    parameters : tuple of (sympy.Symbol, sympy.Expr)
        Parameters and their exact default values.
    inputs, outputs : tuple of sympy.Expr
        ``N n`` trace expressions each: the ports of the open plant, before any feedback.
    state_names : tuple of str
        One label per state component.
    description : str
        Free text.
    displacement : Displacement or None
        How to recover a displacement field, when the model has one.
    feedback : Feedback or None
        The plant's own boundary feedback :math:`u_c = -K y_c` (``[feedback]``); the
        external ports are then :attr:`external_inputs` and :attr:`external_outputs`.
    units : tuple of (str, str)
        Units stated for parameters, states and ``t``, ``z``, ``energy``, ``displacement``.
    derived_outputs : bool
        The outputs were derived from the inputs (``outputs = "conjugate"``).
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
    feedback: Feedback | None = None
    units: tuple[tuple[str, str], ...] = ()
    derived_outputs: bool = False
    checks: tuple[str, ...] = field(default=(), compare=False, repr=False)

    def __post_init__(self) -> None:
        if not self.state_names:
            object.__setattr__(self, "state_names", tuple(f"x{i + 1}" for i in range(self.size)))
        object.__setattr__(self, "checks", tuple(validate(self)))

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
        outputs: Sequence[str | sympy.Expr] | str | None = None,
        parameters: Mapping[str, object] | None = None,
        state_names: Sequence[str] = (),
        description: str = "",
        displacement: Displacement | None = None,
        feedback: Feedback | Mapping[str, Any] | None = None,
        units: Mapping[str, str] | None = None,
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
        inputs : sequence of str
            Trace expressions, ``N n`` of them.
        outputs : sequence of str, "conjugate" or None, optional
            Trace expressions, ``N n`` of them; ``"conjugate"`` or ``None`` derives the
            power-conjugate outputs of the inputs (:mod:`phdesign.symbolic.conjugate`).
        parameters : mapping {name: default value}, optional
            Parameters that may appear in ``P``, ``H`` and the ports.
        state_names : sequence of str, optional
            Labels of the state components.
        description : str, optional
            Free text.
        displacement : Displacement, optional
            How to recover a displacement field.
        feedback : Feedback or {"inputs": [...], "gain": [[...]]}, optional
            Close inputs with :math:`u_c = -K y_c`, :math:`K + K^\top \succeq 0`
            (:mod:`phdesign.symbolic.feedback`).
        units : mapping {quantity: unit}, optional
            Units of parameters, states, ``t``, ``z``, ``energy``, ``displacement``.
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
        H_matrix = parse_matrix(H, "H", names, allow_z=True)
        size = H_matrix.shape[0]
        if isinstance(P, str) or not isinstance(P, Mapping | Sequence):
            raise ModelError(f"P must map k to P_k (or list P_0..P_N); found {P!r}")
        P_by_order = dict(P) if isinstance(P, Mapping) else dict(enumerate(P))
        for k in P_by_order:
            if not isinstance(k, int) or not 0 <= k <= order:
                raise ModelError(
                    f"P{k} is not a matrix of an order-{order} model; expected P0..P{order}"
                )
        P_matrices = tuple(
            parse_matrix(P_by_order[k], f"P{k}", names, allow_z=True)
            if k in P_by_order
            else sympy.ImmutableMatrix.zeros(size, size)
            for k in range(order + 1)
        )
        derived = outputs is None or outputs == "conjugate"
        ports = {}
        for kind, texts in (("inputs", inputs), ("outputs", outputs)):
            if kind == "outputs" and derived:
                continue
            if isinstance(texts, str) or not isinstance(texts, Sequence):
                expected = ' or "conjugate"' if kind == "outputs" else ""
                raise ModelError(
                    f"{kind} must be a list of trace expressions{expected}; found {texts!r}"
                )
            ports[kind] = tuple(
                _port(t, endpoints, order, size, names, what=f"{kind}[{i + 1}]")
                for i, t in enumerate(texts)
            )
        if derived:  # derived in validation, once P_1..P_N are known to be valid
            ports["outputs"] = ()
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
            feedback=None if feedback is None else feedback_from_mapping(feedback, names),
            units=_unit_pairs(units),
            derived_outputs=derived,
        )

    # ------------------------------------------------------------------ views
    @cached_property
    def ports(self) -> Ports:
        """The boundary port structure (:func:`~phdesign.symbolic.ports.derive_ports`), cached."""
        from phdesign.symbolic.ports import derive_ports

        return derive_ports(self)

    @property
    def n_ports(self) -> int:
        """Number of external inputs (= outputs): ``N n`` less the closed ones."""
        return len(external_indices(self.order * self.size, self.feedback))

    @property
    def external_inputs(self) -> tuple[sympy.Expr, ...]:
        """The inputs left open by :attr:`feedback` (all inputs without feedback)."""
        return tuple(self.inputs[j] for j in external_indices(len(self.inputs), self.feedback))

    @property
    def external_outputs(self) -> tuple[sympy.Expr, ...]:
        """The outputs conjugate to :attr:`external_inputs`."""
        return tuple(self.outputs[j] for j in external_indices(len(self.outputs), self.feedback))

    @property
    def unit_map(self) -> dict[str, str]:
        """The stated units, keyed by quantity."""
        return dict(self.units)

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
        if not isinstance(values, Mapping):
            raise ParameterError(
                f"expected a mapping of parameter names to values; found {values!r}"
            )
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


def _unit_pairs(units: object) -> tuple[tuple[Any, Any], ...]:
    if units is None:
        return ()
    if not isinstance(units, Mapping):
        raise ModelError(
            f"units must be a mapping {{quantity: unit}} such as {{'t': 's'}}; found {units!r}"
        )
    return tuple(units.items())


def _interval(interval: Sequence[object]) -> tuple[sympy.Expr, sympy.Expr]:
    if isinstance(interval, str) or not isinstance(interval, Sequence) or len(interval) != 2:
        raise ModelError(f"interval must be a pair [a, b]; found {interval!r}")
    a, b = (exact_number(p, "interval endpoint") for p in interval)
    if not a < b:
        raise ModelError(f"interval must have a < b; found [{a}, {b}]")
    return a, b


def parse_matrix(
    value: Any, name: str, parameters: Sequence[str], allow_z: bool = False
) -> sympy.ImmutableMatrix:
    """Read a square matrix of numbers or expression strings (rows of a list) exactly."""
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
        expr = parse_scalar(value, parameters, allow_z=allow_z, what=what)
    elif isinstance(value, sympy.Expr):
        expr = check_expression(exactify(value), what)
    else:
        return exact_number(value, what)
    # sympy builds (z + d)/atan(1) as 4*(d + z)/pi, which reads back as (4*d + 4*z)/pi:
    # keep the form that reads back as itself, so that written models read back exactly
    return parse_scalar(format_expression(expr), parameters, allow_z=allow_z, what=what)


def require_model(value: object, name: str = "model") -> None:
    """Raise :class:`ArgumentError` unless ``value`` is a :class:`~phdesign.BCPHS`."""
    if not isinstance(value, BCPHS):
        hint = ""
        if isinstance(value, str):
            hint = f" (phdesign.load({value!r}) reads a built-in model or a TOML file)"
        raise ArgumentError(f"{name}: expected a BCPHS model{hint}; found {found_text(value)}")
