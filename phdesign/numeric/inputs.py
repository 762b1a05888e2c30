r"""The user's expressions read against a model: initial states, input signals, traces.

The second half of the crossing from the symbolic layer (:mod:`phdesign.numeric.bridge`):

* :func:`initial_state_function`: ``"x1: 0, x2: z - 0.9"`` (state names, efforts
  ``e1: ...`` through :math:`x = \mathcal H^{-1} e`, the model's parameters) as a
  vectorized :math:`x_0(z)`;
* :func:`input_function`: ``"u2: sin(2*t)"`` as :math:`u(t)` over the model's inputs;
* :func:`input_samples`: a caller's :math:`u(t)` (from :func:`input_function` or their
  own function) at the sample times, checked: ``n_ports`` finite numbers at each;
* :func:`trace_row`: a linear combination of boundary traces, ``"e1(1)"``, as a row over
  the trace vector :math:`v` (:mod:`phdesign.numeric.bridge` gives the ordering).

Every expression is read by the safe parser and evaluated without code generation; an
unknown name, a symbol left free or a value that is not finite raises a phdesign error
naming the item.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from phdesign.core.errors import ExpressionError, NumericError, ParameterError, PhdesignError
from phdesign.core.text import did_you_mean, split_top_level
from phdesign.numeric.boundary_start import (
    boundary_items,
    boundary_names,
    constants,
    with_boundary_states,
)
from phdesign.numeric.bridge import (
    NumericModel,
    _free_symbols_message,
    _parameter_values,
    trace_index,
)

__all__ = [
    "Profile",
    "Signals",
    "exact_profile",
    "initial_state_function",
    "input_function",
    "input_samples",
    "substituted",
    "trace_expression_row",
    "trace_row",
]


def _evaluate_at(expr: Any, variable: Any, t: float) -> Any:
    """``expr`` at ``variable = t`` (the safe evaluator: no code generation)."""
    from phdesign.symbolic.evaluation import evaluate

    return evaluate(expr, np.array(t), variable=variable)


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
    from phdesign.symbolic import traces

    values = _parameter_values(model, None) if model is not None else {}
    if model is not None:  # exact endpoints, so that "e1(1)" names the endpoint 1
        interval = tuple(
            ex.exact_number(x, "interval endpoint").xreplace(values) for x in model.interval
        )
    else:
        interval = tuple(sympy.Rational(repr(x)) for x in nm.interval)
    expr = traces.parse_trace_expression(
        text, interval, nm.order, nm.size, parameters=[str(s) for s in values]
    )
    return trace_expression_row(expr, values, nm, f"trace expression {text!r}")


def trace_expression_row(
    expr: Any, values: Mapping[Any, Any], nm: NumericModel, what: str
) -> np.ndarray:
    """Return the row over ``v`` of a linear trace expression, its parameters substituted."""
    from phdesign.symbolic import traces

    row = np.zeros(2 * nm.order * nm.size)  # the trace vector of the open plant
    for trace, coefficient in traces.linear_coefficients(expr).items():
        value = coefficient.subs(values)
        if value.free_symbols:
            raise ParameterError(_free_symbols_message(what, value.free_symbols))
        index = trace_index(trace.component, trace.derivative, trace.side, nm.order, nm.size)
        row[index] = float(value)
    return row


def substituted(model: Any, expr: Any, what: str) -> Any:
    """``expr`` with the model's parameter values in: only z may stay free."""
    from phdesign.symbolic.expressions import Z

    value = expr.xreplace(_parameter_values(model, None))
    if value.free_symbols - {Z}:
        raise ParameterError(_free_symbols_message(what, value.free_symbols - {Z}))
    return value


@dataclass(frozen=True)
class Profile:
    """``profile(z) -> (m, *shape)`` of exact entries; ``key`` (the entries) is hashable.

    Equal keys are the same function: work built from one (an input matrix) serves both.
    """

    key: tuple[Any, ...]
    shape: tuple[int, ...]

    def __call__(self, z: np.ndarray) -> np.ndarray:
        """Evaluate at the points ``z`` (the safe evaluator: no code generation)."""
        from phdesign.symbolic.evaluation import evaluate

        zz = np.atleast_1d(np.asarray(z, dtype=float))
        vals = [np.broadcast_to(evaluate(e, zz), zz.shape) for e in self.key]
        return np.stack(vals, axis=-1).reshape(zz.size, *self.shape)


def exact_profile(model: Any, entries: list[Any], shape: tuple[int, ...], what: str) -> Profile:
    """Return the entries, in z and with the parameters' values, as a :class:`Profile`."""
    return Profile(tuple(substituted(model, e, what) for e in entries), shape)


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
    (no ``eval`` of user text).  Efforts and states cannot be mixed.  A coupled model's
    boundary states are named as :mod:`phdesign.numeric.boundary_start` says
    (``mass momentum: 0.5``; numbers or parameters, no ``z``).

    Returns
    -------
    callable
        ``f(z) -> (m, n)``, the state x at the points z (a
        :class:`~phdesign.numeric.boundary_start.CoupledInitialState` with boundary states).

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
    from phdesign.numeric.bridge import require_numeric_model

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
    parts, boundary = boundary_items(split_top_level(text), nm)
    for part in parts:
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
            known += "".join(f", {name}" for name in boundary_names(nm.boundary))
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

    parse = partial(_parse_z_expression, nm=nm, model=model, parameters=parameters)
    return with_boundary_states(x0, constants(boundary, parse, what), nm, what)


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
            raise ParameterError(
                f"unknown parameter {name!r}{did_you_mean(name, values)}; the model's "
                f"parameters are {known}"
            )
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


@dataclass(frozen=True)
class Signals:
    """The signals of t a text names: ``argument`` (``u``), a ``noun`` and their ``names``."""

    argument: str
    noun: str
    names: tuple[str, ...]


def input_function(
    text: str | None,
    nm: NumericModel,
    parameters: Mapping[str, Any] | None = None,
    model: Any = None,
    *,
    channels: Signals | None = None,
) -> Callable[[float], np.ndarray] | None:
    """Parse plant inputs ``'u2: sin(2*t), u1: 0.1'`` into ``u(t) -> (n_ports,)``.

    Syntax: comma-separated ``u<i>: expression`` items, ``i`` a 1-based index into the
    model's external inputs and the expression a formula in the time ``t`` and the
    model's parameters, read by the symbolic layer's safe parser (never evaluated as
    Python).  Inputs not named are zero; ``None`` or empty text gives ``None`` (no input).
    ``channels`` reads other signals of t the same way (the disturbances ``w1..wq``:
    :func:`phdesign.numeric.disturbance_inputs.disturbance_signal`).

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
    >>> from phdesign.numeric.bridge import constant_H
    >>> nm = NumericModel("t", (0.0, 1.0), 1, 1, P, constant_H([[1.0]]), U, Y)
    >>> input_function("u1: 2*t", nm)(0.25)
    array([0.5])
    """
    if text is None or not text.strip():
        return None
    import sympy

    from phdesign.symbolic.parser import check_text, parse

    kind = channels or Signals("u", "input", tuple(f"u{i + 1}" for i in range(nm.n_ports)))
    arg = f"`{kind.argument}`"
    check_text(text, arg)
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

    names = {name: i for i, name in enumerate(kind.names)}
    funcs: dict[int, Callable[[float], Any]] = {}
    for part in split_top_level(text):
        if ":" not in part:
            raise ParameterError(
                f"{arg} item {part.strip()!r}: expected '{kind.argument}<i>: expression in t', "
                f"e.g. '{kind.argument}1: sin(2*t)'"
            )
        key, body = (x.strip() for x in part.split(":", 1))
        if key not in names:
            expected = ", ".join(names) if names else f"none (every {kind.noun} is closed)"
            raise ParameterError(
                f"{arg}: unknown {kind.noun} {key!r}; the model's {kind.noun}s are {expected}"
            )
        if names[key] in funcs:
            raise ParameterError(f"{arg}: {kind.noun} {key!r} given twice")
        try:
            expr = parse(body, resolve)
        except ExpressionError as error:
            raise ExpressionError(f"{arg} {key}: {error}") from None
        funcs[names[key]] = partial(_evaluate_at, expr, time)

    return partial(_signal_values, funcs, kind)


def _signal_values(
    funcs: Mapping[int, Callable[[float], Any]], kind: Signals, t: float
) -> np.ndarray:
    """Return the signals of :func:`input_function` at ``t`` (those not named are zero)."""
    out = np.zeros(len(kind.names))
    for i, f in funcs.items():
        try:
            out[i] = float(f(float(t)))
        except (ArithmeticError, ValueError, TypeError):
            out[i] = np.nan
        if not np.isfinite(out[i]):
            name = kind.names[i]
            raise NumericError(f"`{kind.argument}`: {kind.noun} {name} is not finite at t = {t:g}")
    return out


def input_samples(
    u: Callable[[float], Any], times: Any, count: int, name: str = "u"
) -> np.ndarray:
    """Return ``u`` at each time, one row of ``count`` finite numbers per time.

    The one evaluation of a caller's input signal.  The function may return any array of
    ``count`` numbers (a list, a column); anything else is refused before it reaches the
    time stepping, where numpy's reshape error or a series of NaN would have followed,
    with the time and the input it was found at.

    Raises
    ------
    ArgumentError
        ``u(t)`` is not numbers, or not ``count`` of them.
    NumericError
        ``u(t)`` is not finite.

    Examples
    --------
    >>> input_samples(lambda t: [t, 1], [0.0, 0.5], 2)
    array([[0. , 1. ],
           [0.5, 1. ]])
    >>> input_samples(lambda t: [1], [0.0], 2)
    Traceback (most recent call last):
    ...
    phdesign.core.errors.ArgumentError: u(t) must return 2 numbers (one per input); found 1 at t =
    0
    >>> input_samples(lambda t: [1.0, np.log(t)], [1.0, 0.0], 2)
    Traceback (most recent call last):
    ...
    phdesign.core.errors.NumericError: u(t) must be finite; found -inf in input u2 at t = 0
    """
    from phdesign.core.errors import ArgumentError

    rows = []
    for t in np.asarray(times, dtype=float).ravel():
        try:
            with np.errstate(all="ignore"):  # a division by zero is reported below, by value
                value = np.asarray(u(float(t)), dtype=float)
        except PhdesignError:  # the input's own refusal (input_function's), as it is
            raise
        except (TypeError, ValueError) as error:
            raise ArgumentError(f"{name}(t) must return numbers; at t = {t:g}: {error}") from None
        if value.size != count:
            raise ArgumentError(
                f"{name}(t) must return {count} numbers (one per input); found {value.size} "
                f"at t = {t:g}"
            )
        bad = np.flatnonzero(~np.isfinite(value.ravel()))
        if bad.size:
            raise NumericError(
                f"{name}(t) must be finite; found {value.ravel()[bad[0]]} in input "
                f"u{bad[0] + 1} at t = {t:g}"
            )
        rows.append(value.reshape(count))
    return np.array(rows).reshape(len(rows), count)
