"""How a model and its ports show themselves (``str`` is what ``phdesign show``/``ports`` print).

Mixins for :class:`~phdesign.symbolic.model.BCPHS` and
:class:`~phdesign.symbolic.ports.Ports`: a short ``repr``, ``str`` as the command line
prints it, ``_repr_html_`` for notebooks and, for ports, ``to_dict`` (the JSON of
``phdesign ports --json``).  They only read the objects' fields.

Examples
--------
>>> from phdesign.models import load_builtin
>>> wave = load_builtin("wave")
>>> wave
BCPHS(name='wave', N=1, n=2, interval=[0, 1], parameters={'rho': 1, 'T': 1})
>>> wave.ports
Ports(model='wave', v=(e1(1), e2(1), e1(0), e2(0)), identities exact)
"""

from __future__ import annotations

from typing import Any

import sympy

from phdesign.core.text import REPR_LIMIT, html_table, number_text, shorten

__all__ = ["IDENTITY_STATEMENTS", "ModelDisplay", "PortsDisplay"]

#: The port identities, as the printouts state them.
IDENTITY_STATEMENTS = {
    "WB_Sigma_WBt": "W_B Σ W_Bᵀ = 0",
    "WC_Sigma_WCt": "W_C Σ W_Cᵀ = 0",
    "WC_Sigma_WBt_minus_I": "W_C Σ W_Bᵀ = I",
}


def _rows(M: sympy.MatrixBase) -> str:
    return (
        "[" + ", ".join("[" + ", ".join(number_text(x) for x in r) + "]" for r in M.tolist()) + "]"
    )


def _interval_text(interval: Any) -> str:
    return f"[{number_text(interval[0])}, {number_text(interval[1])}]"


class ModelDisplay:
    """Printing of a model: one-line ``repr``, a readable summary as ``str``."""

    name: str
    order: int
    size: int
    interval: tuple[Any, Any]
    parameters: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    P: tuple[sympy.ImmutableMatrix, ...]
    H: sympy.ImmutableMatrix
    inputs: tuple[sympy.Expr, ...]
    outputs: tuple[sympy.Expr, ...]
    state_names: tuple[str, ...]
    description: str
    checks: tuple[str, ...]

    def _parameter_text(self) -> dict[str, Any]:
        return {str(s): int(v) if v.is_Integer else float(v) for s, v in self.parameters}

    def _port_text(self, exprs: tuple[sympy.Expr, ...], letter: str) -> str:
        from phdesign.symbolic.printing import format_expression

        return ", ".join(
            f"{letter}{i + 1} = {format_expression(e, self.interval)}" for i, e in enumerate(exprs)
        )

    def __repr__(self) -> str:
        text = (
            f"BCPHS(name={self.name!r}, N={self.order}, n={self.size}, "
            f"interval={_interval_text(self.interval)}, parameters={self._parameter_text()})"
        )
        return shorten(text, REPR_LIMIT)

    def __str__(self) -> str:
        lines = [f"model {self.name}: N = {self.order}, n = {self.size}"]
        if self.description:
            lines.append(self.description)
        lines.append(
            f"z in {_interval_text(self.interval)}; states x = ({', '.join(self.state_names)})"
        )
        if self.parameters:
            values = ", ".join(f"{s} = {number_text(v)}" for s, v in self.parameters)
            lines.append(f"parameters: {values}")
        lines += [f"P{k} = {_rows(P)}" for k, P in enumerate(self.P) if not P.is_zero_matrix]
        lines.append(f"H = {_rows(self.H)}")
        lines.append(f"inputs:  {self._port_text(self.inputs, 'u')}")
        lines.append(f"outputs: {self._port_text(self.outputs, 'y')}")
        lines += [f"check: {c}" for c in self.checks]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rows = [
            ["description", self.description],
            ["interval", _interval_text(self.interval)],
            ["states", ", ".join(self.state_names)],
            ["parameters", ", ".join(f"{s} = {number_text(v)}" for s, v in self.parameters)],
            *([f"P{k}", _rows(P)] for k, P in enumerate(self.P) if not P.is_zero_matrix),
            ["H", _rows(self.H)],
            ["inputs", self._port_text(self.inputs, "u")],
            ["outputs", self._port_text(self.outputs, "y")],
            ["checks", "; ".join(self.checks)],
        ]
        caption = f"{self.name}: N = {self.order}, n = {self.size}"
        return html_table(["", ""], [r for r in rows if r[1]], caption=caption)


class PortsDisplay:
    """Printing of the ports: ``str`` is ``phdesign ports``, ``to_dict`` its JSON."""

    trace_vector: tuple[sympy.Symbol, ...]
    Q: sympy.ImmutableMatrix
    W_B: sympy.ImmutableMatrix
    W_C: sympy.ImmutableMatrix
    identities: dict[str, sympy.Expr]
    model: Any

    def _traces(self) -> list[str]:
        from phdesign.symbolic.printing import format_expression

        interval = None if self.model is None else self.model.interval
        return [format_expression(s, interval) for s in self.trace_vector]

    def _heading(self) -> str:
        m = self.model
        return "ports" if m is None else f"model {m.name}: N = {m.order}, n = {m.size}"

    def to_dict(self) -> dict[str, Any]:
        """Return the JSON of ``phdesign ports --json`` (matrices as rows of exact strings)."""
        m = self.model

        def rows(M: sympy.MatrixBase) -> list[list[str]]:
            return [[str(x) for x in row] for row in M.tolist()]

        return {
            "model": None if m is None else m.name,
            "order": None if m is None else m.order,
            "size": None if m is None else m.size,
            "traces": self._traces(),
            "Q": rows(self.Q),
            "W_B": rows(self.W_B),
            "W_C": rows(self.W_C),
            "identities": {key: float(value) for key, value in self.identities.items()},
            "feedback": None if self._closed() is None else self._closed().to_dict(),
        }

    def _closed(self) -> Any:
        """Return the closed ports of the plant's own ``[feedback]``, or ``None``."""
        if self.model is None or getattr(self.model, "feedback", None) is None:
            return None
        from phdesign.symbolic.feedback import closed_ports

        return closed_ports(self.model)

    def __str__(self) -> str:
        lines = [
            self._heading(),
            f"v = ({', '.join(self._traces())})",
            "Q =",
            sympy.pretty(self.Q),
            "W_B =",
            sympy.pretty(self.W_B),
            "W_C =",
            sympy.pretty(self.W_C),
            *(f"max |{key}| = {float(value):g}" for key, value in self.identities.items()),
        ]
        closed = self._closed()
        if closed is not None:  # the plant's own dampers close some of the ports
            lines.append(str(closed))
        return "\n".join(lines)

    def __repr__(self) -> str:
        exact = all(value == 0 for value in self.identities.values())
        name = None if self.model is None else self.model.name
        text = (
            f"Ports(model={name!r}, v=({', '.join(self._traces())}), "
            f"identities {'exact' if exact else 'FAIL'})"
        )
        return shorten(text, REPR_LIMIT)

    def _repr_html_(self) -> str:
        rows = [
            ["v", ", ".join(self._traces())],
            ["Q", _rows(self.Q)],
            ["W_B", _rows(self.W_B)],
            ["W_C", _rows(self.W_C)],
            *(
                [IDENTITY_STATEMENTS.get(key, key), f"max |residual| = {float(value):g}"]
                for key, value in self.identities.items()
            ),
        ]
        return html_table(["", ""], rows, caption=self._heading())
