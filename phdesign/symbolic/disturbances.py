r"""Disturbances inside the domain and at the boundary, and the outputs a design is judged on.

A model may say where it is pushed by signals that nobody measures and the observer does
not know (``[disturbances]``), and which quantities matter (``[performance]``):

.. math::

    \partial_t x = \sum_{k=0}^{N} P_k\, \partial_z^k (\mathcal H x) + B(z)\, w(t),
    \qquad w(t) \in \mathbb R^q, \qquad
    z_p = \int_a^b \big(c(z)^\top e + d(z)^\top x\big)\, dz
    + \sum_{\text{traces}} r_j\, \partial_z^{k_j} e_{i_j}(\text{end}_j)
    + \sum_{\text{fields}} s_l\, f_l(z_l) .

``B`` is ``n x q`` (numbers or expressions in ``z`` and the parameters).  A boundary
disturbance, a force at the tip that the observer does not know, is an external input of
``[ports]`` marked unknown (``unknown = [2]``, 1-based indices into ``inputs``).  Each
performance output is written in the grammar of :mod:`phdesign.symbolic.parser`:
``integral(expr)`` is :math:`\int_a^b \text{expr}\, dz` with expr linear in the efforts
``e<i>`` or the states ``x<i>`` (coefficients in ``z`` and the parameters), a trace
``e1(1)``, ``e2'(0)`` is a boundary value (:mod:`phdesign.symbolic.traces`) and
``w(1)``, ``rotation(0.5)`` the displacement or a named field at a point
(:mod:`phdesign.symbolic.fields`); an output is a linear combination of these with
constant coefficients::

    [disturbances]
    B = [[1], [0]]
    [performance]
    outputs = ["integral(e1)", "e1(1)", "integral(z*e2)", "w(1)"]

With the disturbance the energy identity of :mod:`phdesign.symbolic.model` gains one term,

.. math::

    \dot{\mathcal E} = \tfrac12 \int_a^b e^\top (P_0 + P_0^\top)\, e\, dz + u^\top y
    + \int_a^b e^\top B\, w\, dz ,

which :func:`power_balance` states exactly for a given effort profile (the tests check it
for polynomial efforts with symbolic coefficients).

Examples
--------
>>> dist = disturbances_from_mapping({"B": [[1], ["z"]], "unknown": [2]}, 2, [])
>>> dist.B.tolist(), dist.q, dist.unknown
([[1], [z]], 1, (2,))
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import sympy

from phdesign.core.errors import ArgumentError, ExpressionError, ModelError, ModelFileError
from phdesign.symbolic.definition import parse_matrix
from phdesign.symbolic.expressions import Z
from phdesign.symbolic.parser import brief, check_expression
from phdesign.symbolic.performance import PerformanceOutput
from phdesign.symbolic.printing import format_expression
from phdesign.symbolic.traces import trace_of

__all__ = [
    "Disturbances",
    "check_disturbances",
    "disturbance_lines",
    "disturbances_from_mapping",
    "file_sections",
    "power_balance",
    "read_sections",
]


@dataclass(frozen=True)
class Disturbances:
    r"""Where the unknown signals enter: :math:`B(z)\, w` in the domain, and unknown inputs.

    Attributes
    ----------
    B : sympy.ImmutableMatrix
        ``n x q`` (``q`` may be 0 when only boundary inputs are unknown), in ``z`` and the
        parameters.
    unknown : tuple of int
        1-based indices into the model's ``[ports].inputs`` of the external inputs that
        are disturbances (the observer does not know them).
    """

    B: sympy.ImmutableMatrix
    unknown: tuple[int, ...] = ()

    @property
    def q(self) -> int:
        """The number of distributed disturbance channels (columns of B)."""
        return int(self.B.shape[1])


def disturbances_from_mapping(
    value: Disturbances | Mapping[str, Any] | Any, size: int, parameters: Sequence[str]
) -> Disturbances:
    """Read ``{"B": [[...]], "unknown": [2]}``, or ``B`` alone, into :class:`Disturbances`.

    Raises
    ------
    ModelError
        Unknown keys, a B that is not a matrix of ``size`` rows, or ``unknown`` that is not
        a list of integers; the message names the entry.
    """
    if isinstance(value, Disturbances):
        return value
    if isinstance(value, Mapping):
        extra = sorted(set(value) - {"B", "unknown"})
        if extra or not value:
            raise ModelError(
                f"disturbances must hold B (n x q) and/or unknown (input indices); found "
                f"{sorted(value) or 'nothing'}"
            )
        B_value, unknown = value.get("B"), value.get("unknown", ())
    else:
        B_value, unknown = value, ()
    if isinstance(unknown, str) or not isinstance(unknown, Sequence):
        raise ModelError(
            f"unknown must be a list of 1-based input indices such as [2]; found {unknown!r}"
        )
    if B_value is None:
        B = sympy.ImmutableMatrix.zeros(size, 0)
    else:
        B = parse_matrix(B_value, "disturbances B", parameters, allow_z=True, square=False)
        if B.shape[1] == 0:
            raise ModelError("disturbances B must have at least one column; found none")
    return Disturbances(B, tuple(unknown))


# ----------------------------------------------------------------------------- validation


def check_disturbances(model: Any) -> list[str]:
    """Refuse disturbances and performance outputs that do not fit the model.

    Returns how each was checked (nothing when the model has neither).

    Raises
    ------
    ModelError
        B with a number of rows other than n, unknown inputs that are not external inputs
        of the model, a performance output naming a field the model does not define.
    ExpressionError
        Entries with unknown symbols or not finite at the parameter defaults.
    """
    checks = []
    symbols = {s for s, _ in model.parameters}
    dist = getattr(model, "disturbances", None)
    if dist is not None:
        checks.append(_check_B(model, dist, symbols))
    performance = getattr(model, "performance", ())
    if not isinstance(performance, tuple) or not all(
        isinstance(p, PerformanceOutput) for p in performance
    ):
        raise ArgumentError(
            f"performance must be a tuple of PerformanceOutput; found {brief(performance, 60)}"
        )
    known = (("w",) if getattr(model, "displacement", None) is not None else ()) + tuple(
        name for name, _ in getattr(model, "fields", ())
    )
    for i, out in enumerate(performance):
        what = f"performance.outputs[{i + 1}] {out.text!r}"
        for field, _, _ in out.points:
            if field not in known:
                raise ModelError(
                    f"{what}: the model defines no field {field!r}; its fields are "
                    f"{', '.join(known) or 'none'}"
                )
        free = set().union(*(c.free_symbols for c in (*out.effort_weights, *out.state_weights)))
        if free - symbols - {Z}:
            raise ExpressionError(f"{what} holds unknown symbols {sorted(map(str, free))}")
    if performance:
        checks.append(f"performance: {len(performance)} outputs, linear in the efforts: exact")
    return checks


def _check_B(model: Any, dist: object, symbols: set[sympy.Symbol]) -> str:
    if not isinstance(dist, Disturbances) or not isinstance(dist.B, sympy.MatrixBase):
        raise ArgumentError(
            f"disturbances must be a Disturbances(B, unknown); found {brief(dist, 60)}"
        )
    n = model.size
    if dist.B.shape[0] != n:
        raise ModelError(
            f"Incompatible dimensions of disturbances B matrix; expected ({n}, q) (one row "
            f"per state component) but found {tuple(dist.B.shape)}"
        )
    for (i, j), entry in dist.B.todok().items():
        what = f"disturbances B[{i + 1},{j + 1}]"
        check_expression(entry, what)
        unknown = entry.free_symbols - symbols - {Z}
        if unknown:
            raise ExpressionError(f"{what} holds unknown symbols {sorted(map(str, unknown))}")
        value = entry.xreplace(dict(model.parameters))
        if value.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan):
            raise ModelError(f"{what} = {entry} is not finite at the parameter defaults")
    feedback = getattr(model, "feedback", None)
    closed = set(feedback.inputs) if feedback is not None else set()
    n_inputs = len(model.inputs)
    seen: set[int] = set()
    for position, index in enumerate(dist.unknown, start=1):
        if isinstance(index, bool) or not isinstance(index, int) or not 1 <= index <= n_inputs:
            raise ModelError(
                f"ports.unknown[{position}] = {index!r} is not an input of the model; "
                f"expected an index in 1..{n_inputs} into [ports].inputs"
            )
        if index in closed or index in seen:
            why = "closed by [feedback]" if index in closed else "repeated"
            raise ModelError(
                f"ports.unknown[{position}] = {index} is {why}; expected distinct external inputs"
            )
        seen.add(index)
    if dist.q == 0 and not dist.unknown:
        raise ModelError("disturbances must hold B or unknown inputs; found neither")
    return (
        f"disturbances: B is {n} x {dist.q} in z and the parameters, finite at the defaults; "
        f"unknown inputs {list(dist.unknown) or 'none'}: exact"
    )


# ----------------------------------------------------------------------------- energy, text


def power_balance(
    model: Any, efforts: Sequence[sympy.Expr], w: Sequence[sympy.Expr]
) -> tuple[sympy.Expr, sympy.Expr]:
    r"""Return both sides of the energy identity for the effort profile ``efforts(z)``.

    The rate :math:`\int_a^b e^\top \partial_t x\, dz` with :math:`\partial_t x = \sum_k
    P_k \partial_z^k e + B w`, and the balance :math:`\tfrac12 \int_a^b e^\top (P_0 +
    P_0^\top) e\, dz + u^\top y + \int_a^b e^\top B w\, dz` with u and y the model's ports
    at the traces of ``efforts``; they are equal exactly for every profile (the
    integration by parts of :mod:`phdesign.symbolic.ports`).

    Returns
    -------
    (sympy.Expr, sympy.Expr)
    """
    e = sympy.Matrix(list(efforts))
    a, b = model.interval
    dist = getattr(model, "disturbances", None)
    Bw = (
        sympy.zeros(model.size, 1)
        if dist is None or dist.q == 0
        else sympy.Matrix(dist.B) * sympy.Matrix(list(w))
    )
    flow = sum((model.P[k] * e.diff(Z, k) for k in range(model.order + 1)), sympy.zeros(*e.shape))
    rate = _integral((e.T * (flow + Bw))[0], a, b)
    values = {}
    for symbol in model.ports.trace_vector:
        trace = trace_of(symbol)
        if trace is None:  # pragma: no cover - the trace vector holds traces only
            continue
        values[symbol] = (
            e[trace.component - 1].diff(Z, trace.derivative).subs(Z, b if trace.side == "b" else a)
        )
    v = sympy.Matrix(list(model.ports.trace_vector)).xreplace(values)
    power = (model.ports.U * v).T * (model.ports.Y * v)
    P0 = model.P[0]
    dissipation = _integral((e.T * (P0 + P0.T) * e)[0], a, b) / 2
    supplied = _integral((e.T * Bw)[0], a, b)
    return rate, dissipation + power[0] + supplied


def _integral(expr: sympy.Expr, a: sympy.Expr, b: sympy.Expr) -> sympy.Expr:
    """Return the exact integral over [a, b], integrating each distinct z-factor once."""
    parts: dict[sympy.Expr, list[sympy.Expr]] = {}
    for term in sympy.Add.make_args(sympy.expand(expr)):
        constant, varying = term.as_independent(Z, as_Add=False)
        parts.setdefault(varying, []).append(constant)
    return sympy.Add(*(sympy.integrate(f, (Z, a, b)) * sympy.Add(*cs) for f, cs in parts.items()))


def disturbance_lines(model: Any) -> list[str]:
    """Return what ``phdesign show`` prints of the disturbances and performance outputs."""
    lines = []
    dist = getattr(model, "disturbances", None)
    if dist is not None and dist.q:
        rows = ", ".join(
            "[" + ", ".join(format_expression(x) for x in row) + "]" for row in dist.B.tolist()
        )
        lines.append(f"disturbances: dx/dt = ... + B w, w in R^{dist.q}, B = [{rows}]")
    if dist is not None and dist.unknown:
        unknown = ", ".join(f"u{j}" for j in dist.unknown)
        lines.append(f"unknown inputs (boundary disturbances): {unknown}")
    for i, out in enumerate(getattr(model, "performance", ())):
        lines.append(f"performance z{i + 1} = {out.text}")
    return lines


# ----------------------------------------------------------------------------- model files

#: The keys of the two sections of a model file.
SECTION_KEYS = {"disturbances": ("B",), "performance": ("outputs",)}


def read_sections(
    data: Mapping[str, Any], ports: Mapping[str, Any], source: str
) -> tuple[dict[str, Any] | None, list[Any] | None]:
    """Return ``(disturbances, performance)`` of a model file, for :meth:`BCPHS.define`.

    ``[disturbances] B`` and ``[ports] unknown`` make the disturbances,
    ``[performance] outputs`` the performance outputs.

    Raises
    ------
    ModelFileError
        A section that is not a table or holds other keys, naming the section.
    """
    tables = {}
    for key, allowed in SECTION_KEYS.items():
        if key not in data:
            continue
        table = data[key]
        if not isinstance(table, Mapping) or set(table) != set(allowed):
            found = sorted(map(str, table)) if isinstance(table, Mapping) else repr(table)
            raise ModelFileError(
                f"{source}: [{key}] must hold exactly {', '.join(allowed)}; found {found}"
            )
        tables[key] = table
    dist: dict[str, Any] = {}
    if "disturbances" in tables:
        dist["B"] = tables["disturbances"]["B"]
    if "unknown" in ports:
        dist["unknown"] = ports["unknown"]
    outputs = tables["performance"]["outputs"] if "performance" in tables else None
    return dist or None, outputs


def file_sections(model: Any, entry: Any) -> dict[str, Any]:
    """Return the ``[disturbances]`` and ``[performance]`` tables of a model file.

    ``entry(x)`` writes one exact matrix entry as the file does.  ``[ports] unknown`` is
    written by the caller from ``model.disturbances.unknown``.
    """
    out: dict[str, Any] = {}
    dist = model.disturbances
    if dist is not None and dist.q:
        out["disturbances"] = {"B": [[entry(x) for x in row] for row in dist.B.tolist()]}
    if model.performance:
        out["performance"] = {"outputs": [p.text for p in model.performance]}
    return out
