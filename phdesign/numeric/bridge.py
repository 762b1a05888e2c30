r"""The one crossing from the symbolic layer to the numeric one.

:func:`to_numeric` takes a validated symbolic :class:`~phdesign.symbolic.model.BCPHS`,
substitutes its parameters (defaults, overridden by the caller), refuses any symbol
left free, and returns a :class:`NumericModel`: floats and a vectorized callable for
the Hamiltonian density, nothing symbolic.  Everything else in :mod:`phdesign.numeric`
works on :class:`NumericModel` only, so this is the one module of the numeric layer
that imports sympy (and it does so lazily, inside functions).

The port matrices follow the fixed trace ordering of the contract,

.. math::

    v = (\phi(b); \phi(a)), \quad
    \phi = (e, e', \dots, e^{(N-1)}), \quad u = U v, \quad y = Y v,

so that the index of :math:`e_i^{(k)}(\text{side})` in ``v`` is
``(0 if side == "b" else N*n) + k*n + (i - 1)``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np

from phdesign.errors import ExpressionError, ModelError, NumericError, ParameterError, check_shape
from phdesign.symbolic.ports import trace_index

__all__ = [
    "DisplacementSpec",
    "NumericModel",
    "PortFeedback",
    "constant_H",
    "gain_to_numeric",
    "initial_state_function",
    "input_function",
    "to_numeric",
    "trace_index",
    "trace_row",
]


@dataclass(frozen=True)
class DisplacementSpec:
    """Physical displacement: ``integrations`` integrals of state ``component`` from a.

    ``component`` is 1-based (a component of x, not of e).  The beam has x2 = w_zz,
    so ``DisplacementSpec(2, 2)`` gives w(z) = ∫_a^z ∫_a^s x2(r) dr ds.
    """

    component: int
    integrations: int


@dataclass(frozen=True)
class PortFeedback:
    r"""The plant's own boundary feedback :math:`u_c = -K y_c`, with numbers.

    ``closed`` are 0-based indices into the open ports (the rows of ``U`` and ``Y``);
    ``gain`` is :math:`K` (``c x c``, :math:`K + K^\top \succeq 0`).
    """

    closed: tuple[int, ...]
    gain: np.ndarray = field(compare=False)


@dataclass(frozen=True)
class NumericModel:
    r"""A BC-PHS with every parameter substituted: the numeric layer's input.

    .. math::

        \partial_t x = \sum_{k=0}^N P_k \partial_z^k (H(z) x), \quad
        u = U v, \quad y = Y v,

    with ``P[k]`` of shape ``(n, n)``, ``U`` and ``Y`` of shape ``(N n, 2 N n)`` over the
    trace vector ``v`` (see the module docstring) and ``H(z)`` a vectorized callable that
    maps an array of ``m`` points to an array of shape ``(m, n, n)``.  ``U`` and ``Y`` are
    the open plant's ports; with ``feedback`` the inputs ``feedback.closed`` are closed by
    :math:`u_c = -K y_c` and the model's external ports are the others (:attr:`n_ports`
    of them): every discretization returns the closed plant.  When :math:`P_0` depends on
    z, ``P0`` is its vectorized callable and ``P[0]`` is filled with NaN, so that no code
    can use a constant :math:`P_0` by mistake (:meth:`P0_at` serves both cases).

    Parameters
    ----------
    name : str
        Model name (for labels).
    interval : tuple of float
        ``(a, b)`` with ``a < b``.
    order, size : int
        N and n.
    P : tuple of ndarray
        ``P_0 .. P_N``.
    H : callable
        ``H(z) -> (m, n, n)``; symmetric positive definite at every point.
    U, Y : ndarray
        Input and output maps over the trace vector.
    input_labels, output_labels, state_names : tuple of str
        Names used in exports and CSV headers.
    displacement : DisplacementSpec or None
        How to reconstruct a physical displacement, if the model has one.
    H_constant : bool
        True when H does not depend on z (lets discretizations skip quadrature work).
    feedback : PortFeedback or None
        The plant's own boundary feedback.
    P0 : callable or None
        ``P0(z) -> (m, n, n)`` when :math:`P_0` depends on z, else ``None``.
    units : mapping
        Units stated by the model (``t``, ``z``, ``energy``, ``displacement``, parameters,
        states).
    parameters : mapping of str to float
        The parameter values substituted (defaults with the caller's overrides), by name:
        the values an initial state or an input written in the parameters is evaluated with.
    """

    name: str
    interval: tuple[float, float]
    order: int
    size: int
    P: tuple[np.ndarray, ...]
    H: Callable[[np.ndarray], np.ndarray]
    U: np.ndarray
    Y: np.ndarray
    input_labels: tuple[str, ...] = ()
    output_labels: tuple[str, ...] = ()
    state_names: tuple[str, ...] = ()
    displacement: DisplacementSpec | None = None
    H_constant: bool = False
    extra: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)
    feedback: PortFeedback | None = None
    P0: Callable[[np.ndarray], np.ndarray] | None = field(default=None, compare=False)
    units: Mapping[str, str] = field(default_factory=dict, compare=False, repr=False)
    parameters: Mapping[str, float] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        a, b = (float(s) for s in self.interval)
        if not a < b:
            raise ModelError(f"interval must satisfy a < b; found a = {a}, b = {b}")
        N, n = int(self.order), int(self.size)
        if N < 1 or n < 1:
            raise ModelError(f"order and size must be >= 1; found N = {N}, n = {n}")
        if len(self.P) != N + 1:
            raise ModelError(f"expected {N + 1} matrices P_0..P_{N}; found {len(self.P)}")
        for k, Pk in enumerate(self.P):
            check_shape(f"P{k}", np.asarray(Pk), (n, n))
        check_shape("U", np.asarray(self.U), (N * n, 2 * N * n))
        check_shape("Y", np.asarray(self.Y), (N * n, 2 * N * n))
        object.__setattr__(self, "interval", (a, b))
        object.__setattr__(self, "P", tuple(np.asarray(Pk, dtype=float) for Pk in self.P))
        object.__setattr__(self, "U", np.asarray(self.U, dtype=float))
        object.__setattr__(self, "Y", np.asarray(self.Y, dtype=float))
        if self.feedback is not None:
            closed = self.feedback.closed
            if len(set(closed)) != len(closed) or not all(0 <= c < N * n for c in closed):
                raise ModelError(
                    f"feedback must close distinct ports in 0..{N * n - 1}; found {closed}"
                )
            check_shape("feedback gain K", np.asarray(self.feedback.gain), (len(closed),) * 2)
        self._check_dissipative()
        m = self.n_ports
        if not self.input_labels:
            object.__setattr__(self, "input_labels", tuple(f"u{i + 1}" for i in range(m)))
        if not self.output_labels:
            object.__setattr__(self, "output_labels", tuple(f"y{i + 1}" for i in range(m)))
        if not self.state_names:
            object.__setattr__(self, "state_names", tuple(f"x{i + 1}" for i in range(n)))

    def _check_dissipative(self) -> None:
        r"""Refuse a model that is not dissipative (:mod:`phdesign.numeric.invariants`).

        :math:`H(z) \succ 0` (the energy is positive) and :math:`P_0 + P_0^\top \preceq 0`
        on a grid of the interval, and the plant's own feedback :math:`K + K^\top \succeq
        0`, to round-off.
        """
        from phdesign.numeric.invariants import GRID_POINTS, require_definite, require_semidefinite

        z = np.linspace(self.interval[0], self.interval[1], GRID_POINTS)
        require_definite("H(z)", self.H_at(z), ModelError, points=z)

        def _size(M: np.ndarray) -> float:  # round-off is relative to the matrix summed
            return float(np.max(np.abs(M))) if M.size and np.all(np.isfinite(M)) else 0.0

        if self.P0 is None:
            P0 = self.P[0]
            require_semidefinite(
                "P0 + P0^T", P0 + P0.T, negative=True, reference=_size(P0), error=ModelError
            )
        else:
            P0 = self.P0_at(z)
            require_semidefinite(
                "P0(z) + P0(z)^T",
                P0 + P0.transpose(0, 2, 1),
                negative=True,
                points=z,
                reference=_size(P0),
                error=ModelError,
            )
        if self.feedback is not None:
            K = np.asarray(self.feedback.gain, dtype=float)
            require_semidefinite(
                "feedback gain K + K^T", K + K.T, reference=_size(K), error=ModelError
            )

    @property
    def n_ports(self) -> int:
        """Number of external inputs (= outputs): ``N n`` less the closed ones."""
        closed = 0 if self.feedback is None else len(self.feedback.closed)
        return self.order * self.size - closed

    @property
    def P0_constant(self) -> bool:
        """True when :math:`P_0` does not depend on z (then ``P[0]`` holds it)."""
        return self.P0 is None

    def P0_at(self, z: np.ndarray | float) -> np.ndarray:
        """Evaluate :math:`P_0` at the points ``z``; returns shape ``(m, n, n)``."""
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        n = self.size
        if self.P0 is None:
            return np.broadcast_to(self.P[0], (zz.size, n, n)).copy()
        out = np.asarray(self.P0(zz), dtype=float)
        return np.broadcast_to(out, (zz.size, n, n)).copy()

    def H_at(self, z: np.ndarray | float) -> np.ndarray:
        """Evaluate H at the points ``z``; returns shape ``(m, n, n)``."""
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        out = np.asarray(self.H(zz), dtype=float)
        n = self.size
        if out.shape != (zz.size, n, n):
            out = np.broadcast_to(out, (zz.size, n, n)).copy()
        return out


def constant_H(
    matrix: Sequence[Sequence[float]] | np.ndarray,
) -> Callable[[np.ndarray], np.ndarray]:
    """Return a vectorized callable for a constant Hamiltonian density.

    Examples
    --------
    >>> constant_H([[1.0, 0.0], [0.0, 2.0]])(np.array([0.0, 0.5])).shape
    (2, 2, 2)
    """
    Hm = np.asarray(matrix, dtype=float)

    def H(z: np.ndarray) -> np.ndarray:
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        return np.broadcast_to(Hm, (zz.size, *Hm.shape)).copy()

    return H


def _free_symbols_message(what: str, symbols: set[Any]) -> str:
    names = ", ".join(sorted(str(s) for s in symbols))
    return (
        f"{what} still contains free symbols after substitution: {names}; give them with --param"
    )


def _parameter_values(model: Any, parameters: Mapping[str, Any] | None) -> dict[Any, Any]:
    """Defaults of ``model`` overridden by ``parameters`` (keys by name), checked by the model."""
    if parameters:
        model = model.with_parameters({str(k): v for k, v in parameters.items()})
    return dict(model.parameter_defaults)


def to_numeric(model: Any, parameters: Mapping[str, Any] | None = None) -> NumericModel:
    """Substitute parameters into a symbolic BC-PHS and return a :class:`NumericModel`.

    Parameters
    ----------
    model : phdesign.symbolic.model.BCPHS
        The validated symbolic model.
    parameters : mapping of str to number or expression, optional
        Overrides of the model's parameter defaults, by name.

    Returns
    -------
    NumericModel

    Raises
    ------
    ParameterError
        When a parameter is unknown or a symbol other than z stays free (the message
        names them).
    """
    from phdesign.arguments import require_model
    from phdesign.symbolic.expressions import exact_matrix, exact_number
    from phdesign.symbolic.model import Z

    require_model(model)
    if parameters is not None and not isinstance(parameters, Mapping):
        raise ParameterError(
            f"parameters must be a mapping of names to values; found {type(parameters).__name__}"
        )
    values = _parameter_values(model, parameters)
    N, n = int(model.order), int(model.size)

    def subs_matrix(name: str, mat: Any, allow_z: bool) -> Any:
        out = exact_matrix(mat, name, symbols=True).xreplace(values)
        free = set(out.free_symbols) - ({Z} if allow_z else set())
        if free:
            raise ParameterError(_free_symbols_message(name, free))
        return out

    a_s, b_s = (exact_number(s, "interval endpoint") for s in model.interval)
    for nm_, s in (("interval start a", a_s), ("interval end b", b_s)):
        if s.free_symbols:
            raise ParameterError(_free_symbols_message(nm_, set(s.free_symbols)))
    P = [
        np.array(subs_matrix(f"P{k}", Pk, False).evalf(), dtype=float)
        for k, Pk in enumerate(model.P)
        if k > 0
    ]
    P0s = subs_matrix("P0", model.P[0], True)
    P0fun = None
    if Z in P0s.free_symbols:
        P0fun = _matrix_function(P0s, n)
        P.insert(0, np.full((n, n), np.nan))
    else:
        P.insert(0, np.array(P0s.evalf(), dtype=float))
    Hs = subs_matrix("H", model.H, True)
    ports = model.ports
    U = np.array(subs_matrix("U", ports.U, False).evalf(), dtype=float)
    Y = np.array(subs_matrix("Y", ports.Y, False).evalf(), dtype=float)

    H_constant = Z not in Hs.free_symbols
    Hfun = constant_H(np.array(Hs.evalf(), dtype=float)) if H_constant else _matrix_function(Hs, n)
    feedback = None
    if getattr(model, "feedback", None) is not None:
        K = np.array(subs_matrix("feedback gain K", model.feedback.gain, False).evalf(), float)
        feedback = PortFeedback(tuple(model.feedback.closed), K)
    disp = None
    d = getattr(model, "displacement", None)
    if d is not None:
        disp = DisplacementSpec(int(d.component), int(d.integrations))
    inputs = getattr(model, "external_inputs", model.inputs)
    outputs = getattr(model, "external_outputs", model.outputs)
    in_labels = tuple(str(e) for e in inputs)
    out_labels = tuple(str(e) for e in outputs)
    nm = NumericModel(
        name=str(model.name),
        interval=(float(a_s), float(b_s)),
        order=N,
        size=n,
        P=tuple(P),
        H=Hfun,
        U=U,
        Y=Y,
        input_labels=in_labels,
        output_labels=out_labels,
        state_names=tuple(model.state_names),
        displacement=disp,
        H_constant=H_constant,
        feedback=feedback,
        P0=P0fun,
        units=dict(getattr(model, "units", ())),
        parameters={str(k): float(v) for k, v in values.items()},
    )
    # H > 0, P0 + P0^T <= 0 and K + K^T >= 0 after substitution are checked by NumericModel
    # itself (its invariants)
    return nm


def _evaluate_at(expr: Any, variable: Any, t: float) -> Any:
    """``expr`` at ``variable = t`` (the safe evaluator: no code generation)."""
    from phdesign.symbolic.evaluation import evaluate

    return evaluate(expr, np.array(t), variable=variable)


def _matrix_function(matrix: Any, n: int) -> Callable[[np.ndarray], np.ndarray]:
    """Return a vectorized callable ``f(z) -> (m, n, n)`` of a sympy matrix in z."""
    from phdesign.symbolic.evaluation import evaluate

    entries = [matrix[i, j] for i in range(n) for j in range(n)]

    def values(z: np.ndarray) -> np.ndarray:
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        vals = [evaluate(entry, zz) for entry in entries]  # no code generation
        return np.stack(vals, axis=-1).reshape(zz.size, n, n)

    return values


def gain_to_numeric(matrix: Any, name: str = "L") -> np.ndarray:
    """Convert a sympy (or nested list) matrix of numbers to a float array.

    Raises :class:`ParameterError` when a symbol is left (e.g. ``--gain symbolic``).
    """
    import sympy

    if isinstance(matrix, sympy.MatrixBase):
        if matrix.free_symbols:
            raise ParameterError(_free_symbols_message(name, set(matrix.free_symbols)))
        return np.array(matrix.evalf(), dtype=float)
    try:
        return np.array(matrix, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name}: cannot convert to a numeric matrix ({exc})") from exc


def trace_row(text: str, nm: NumericModel, model: Any = None) -> np.ndarray:
    """Read a linear combination of boundary traces, ``"e1(1)"``, as a row over ``v``.

    The text is parsed by the symbolic layer's trace grammar (points ``a``, ``b`` or the
    endpoint values); parameters in coefficients take the values of ``model`` (the
    defaults, or the overrides it carries).

    Returns
    -------
    ndarray (2 N n,)
        ``r`` with ``r @ v`` the combination, in the trace ordering of the module docstring.

    Examples
    --------
    >>> from phdesign.numeric.bridge import NumericModel, constant_H
    >>> P = (np.zeros((1, 1)), np.ones((1, 1)))
    >>> nm = NumericModel("t", (0.0, 1.0), 1, 1, P, constant_H([[1.0]]), [[0, 1]], [[1, 0]])
    >>> trace_row("2*e1(1) - e1(0)", nm).tolist()
    [2.0, -1.0]
    """
    import sympy

    from phdesign.symbolic import expressions as ex

    values = _parameter_values(model, None) if model is not None else {}
    if model is not None:  # exact endpoints, so that "e1(1)" names the endpoint 1
        interval = tuple(
            ex.exact_number(x, "interval endpoint").xreplace(values) for x in model.interval
        )
    else:
        interval = tuple(sympy.Rational(repr(x)) for x in nm.interval)
    expr = ex.parse_trace_expression(
        text, interval, nm.order, nm.size, parameters=[str(s) for s in values]
    )
    row = np.zeros(2 * nm.order * nm.size)  # the trace vector of the open plant
    for trace, coefficient in ex.linear_coefficients(expr).items():
        value = coefficient.subs(values)
        if value.free_symbols:
            message = _free_symbols_message(f"trace expression {text!r}", value.free_symbols)
            raise ParameterError(message)
        index = trace_index(trace.component, trace.derivative, trace.side, nm.order, nm.size)
        row[index] = float(value)
    return row


def initial_state_function(
    text: str | None,
    nm: NumericModel,
    parameters: Mapping[str, Any] | None = None,
    model: Any = None,
    what: str = "initial state",
) -> Callable[[np.ndarray], np.ndarray]:
    """Parse an initial state ``'x1: 0, x2: z - 0.9'`` into a vectorized callable.

    Syntax: comma-separated ``name: expression`` pairs.  A name is a state name of the
    model (``x1``, ...) or ``e<i>`` for the effort ``(H x)_i``; an expression is a
    formula in ``z`` and the model's parameters (``sin(pi*z)``, ``z - 0.9``).  Components
    not mentioned are zero.  Expressions are parsed with the symbolic layer's safe parser
    (no ``eval`` of user text).  Efforts and states cannot be mixed.

    Returns
    -------
    callable
        ``f(z) -> (m, n)``, the state x at the points z.

    Examples
    --------
    >>> from phdesign.numeric.bridge import NumericModel, constant_H
    >>> import numpy as np
    >>> P = (np.zeros((1, 1)), np.ones((1, 1)))
    >>> U = np.array([[0.0, 1.0]]); Y = np.array([[1.0, 0.0]])
    >>> nm = NumericModel("t", (0.0, 1.0), 1, 1, P, constant_H([[2.0]]), U, Y)
    >>> initial_state_function("e1: 2*z", nm)(np.array([0.5]))
    array([[0.5]])
    """
    from phdesign.arguments import require_numeric_model

    require_numeric_model(nm)
    if text is not None and not isinstance(text, str):
        raise ParameterError(
            f"initial state must be text such as 'x1: z - 0.9'; found {type(text).__name__}"
        )
    n = nm.size
    if text is None or not text.strip():
        return lambda z: np.zeros((np.atleast_1d(z).size, n))

    names = {s: i for i, s in enumerate(nm.state_names)}
    names.update({f"x{i + 1}": i for i in range(n)})
    efforts = {f"e{i + 1}": i for i in range(n)}
    exprs: dict[int, Any] = {}
    kind: str | None = None
    for part in _split_top_level(text):
        if ":" not in part:
            raise ParameterError(
                f"{what} item {part.strip()!r}: expected 'name: expression', "
                f"e.g. '{nm.state_names[0]}: z - 0.9'"
            )
        key, expr_text = (s.strip() for s in part.split(":", 1))
        if key in names:
            this, idx = "x", names[key]
        elif key in efforts:
            this, idx = "e", efforts[key]
        else:
            known = ", ".join([*nm.state_names, *(f"x{i + 1}" for i in range(n)), *efforts])
            raise ParameterError(f"{what}: unknown component {key!r}; expected one of {known}")
        if kind is not None and this != kind:
            raise ParameterError(f"{what}: give either state components or efforts, not both")
        kind = this
        if idx in exprs:
            raise ParameterError(f"{what}: component {key!r} given twice")
        exprs[idx] = _parse_z_expression(expr_text, nm, model, parameters, f"{what} expression")
    from phdesign.symbolic.evaluation import evaluate

    funcs = {i: (lambda zz, e=e: evaluate(e, zz)) for i, e in exprs.items()}

    def x0(z: np.ndarray) -> np.ndarray:
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        out = np.zeros((zz.size, n))
        for i, f in funcs.items():
            out[:, i] = np.broadcast_to(np.asarray(f(zz), dtype=float), zz.shape)
        if kind == "e":
            out = np.linalg.solve(nm.H_at(zz), out[:, :, None])[:, :, 0]
        return out

    return x0


def _split_top_level(text: str) -> list[str]:
    """Split on commas that are not inside parentheses or brackets."""
    parts: list[str] = []
    cur: list[str] = []
    depth = 0
    for ch in text:
        if ch in "([":
            depth += 1
        elif ch in ")]":
            depth -= 1
        if ch == "," and depth == 0:
            parts.append("".join(cur))
            cur = []
        else:
            cur.append(ch)
    parts.append("".join(cur))
    return [p for p in parts if p.strip()]


def _exact_value(value: Any) -> Any:
    """Return a parameter value as an exact number (a float by its shortest decimal)."""
    from phdesign.symbolic.expressions import exact_number

    return exact_number(value, "parameter value") if isinstance(value, float) else value


def _substituted_values(
    nm: NumericModel, model: Any, parameters: Mapping[str, Any] | None
) -> dict[str, Any]:
    """Parameter values by name: those ``nm`` was built with, overridden by ``parameters``.

    ``nm.parameters`` holds the defaults and the overrides given to :func:`to_numeric`;
    a NumericModel built by hand has none, and then the model's defaults are used.
    """
    from phdesign.symbolic import expressions as ex

    values: dict[str, Any] = dict(nm.parameters)
    if not values and model is not None:
        values = {str(s): v for s, v in model.parameter_defaults.items()}
    for name, value in (parameters or {}).items():
        if str(name) not in values:
            known = ", ".join(values) or "none"
            raise ParameterError(f"unknown parameter {name!r}; the model's parameters are {known}")
        values[str(name)] = ex.exact_number(value, f"parameter {name}")
    return values


def _parse_z_expression(
    text: str,
    nm: NumericModel,
    model: Any,
    parameters: Mapping[str, Any] | None,
    what: str = "initial state expression",
) -> Any:
    """Parse an expression in z (and parameters) safely and substitute the parameter values.

    The values are those of :func:`_substituted_values`.
    """
    from phdesign.symbolic import expressions as ex
    from phdesign.symbolic.model import Z

    values = _substituted_values(nm, model, parameters)
    expr = ex.parse_scalar(text, parameters=list(values), allow_z=True, what=what)
    # parse_scalar builds its own z and parameter symbols; map them by name.
    subs = {
        s: (Z if str(s) == "z" else _exact_value(values[str(s)]))
        for s in expr.free_symbols
        if str(s) == "z" or str(s) in values
    }
    expr = expr.xreplace(subs)
    free = set(expr.free_symbols) - {Z}
    if free:
        raise ParameterError(_free_symbols_message(f"{what} {text!r}", free))
    return expr


def input_function(
    text: str | None,
    nm: NumericModel,
    parameters: Mapping[str, Any] | None = None,
    model: Any = None,
) -> Callable[[float], np.ndarray] | None:
    """Parse plant inputs ``'u2: sin(2*t), u1: 0.1'`` into ``u(t) -> (n_ports,)``.

    Syntax: comma-separated ``u<i>: expression`` items, ``i`` a 1-based index into the
    model's external inputs and the expression a formula in the time ``t`` and the
    model's parameters, read by the symbolic layer's safe parser (never evaluated as
    Python).  Inputs not named are zero; ``None`` or empty text gives ``None`` (no input).

    Raises
    ------
    ParameterError
        On an unknown or repeated input name, or a missing ``:``.
    ExpressionError
        On a malformed expression or an unknown symbol (named in the message).

    Examples
    --------
    >>> P = (np.zeros((1, 1)), np.ones((1, 1)))
    >>> U = np.array([[0.0, 1.0]]); Y = np.array([[1.0, 0.0]])
    >>> nm = NumericModel("t", (0.0, 1.0), 1, 1, P, constant_H([[1.0]]), U, Y)
    >>> input_function("u1: 2*t", nm)(0.25)
    array([0.5])
    """
    if text is None or not text.strip():
        return None
    import sympy

    from phdesign.symbolic.parser import check_text, parse

    check_text(text, "--u")
    by_name = {
        name: _exact_value(value)
        for name, value in _substituted_values(nm, model, parameters).items()
    }
    time = sympy.Symbol("t", real=True)

    def resolve(name: str, expression: str) -> Any:
        if name == "t":
            return time
        if name in by_name:
            return by_name[name]
        known = ", ".join(["t", *sorted(by_name)])
        raise ExpressionError(f"unknown symbol {name!r} in {expression!r}; expected {known}")

    m = nm.n_ports
    names = {f"u{i + 1}": i for i in range(m)}
    funcs: dict[int, Callable[[float], Any]] = {}
    for part in _split_top_level(text):
        if ":" not in part:
            raise ParameterError(
                f"--u item {part.strip()!r}: expected 'u<i>: expression in t', e.g. 'u1: sin(2*t)'"
            )
        key, body = (x.strip() for x in part.split(":", 1))
        if key not in names:
            expected = ", ".join(names) if names else "none (every input is closed)"
            raise ParameterError(f"--u: unknown input {key!r}; the model's inputs are {expected}")
        if names[key] in funcs:
            raise ParameterError(f"--u: input {key!r} given twice")
        try:
            expr = parse(body, resolve)
        except ExpressionError as error:
            raise ExpressionError(f"--u {key}: {error}") from None
        funcs[names[key]] = partial(_evaluate_at, expr, time)

    def u(t: float) -> np.ndarray:
        out = np.zeros(m)
        for i, f in funcs.items():
            try:
                out[i] = float(f(float(t)))
            except (ArithmeticError, ValueError, TypeError):
                out[i] = np.nan
            if not np.isfinite(out[i]):
                raise NumericError(f"--u: input u{i + 1} is not finite at t = {t:g}")
        return out

    return u
