"""How a model and its ports show themselves (``str`` is what ``phdesign show``/``ports`` print).

The presenters of :class:`~phdesign.symbolic.model.BCPHS` and
:class:`~phdesign.symbolic.ports.Ports`, which delegate their ``repr``, ``str``,
``_repr_html_`` and (for ports) ``to_dict`` here: a short ``repr``, ``str`` as the command
line prints it, ``_repr_html_`` for notebooks and the JSON of ``phdesign ports --json``.
They only read the objects' fields; the closed plant of a model with ``[feedback]`` is
read from the model (:attr:`BCPHS.closed_ports <phdesign.symbolic.model.BCPHS.closed_ports>`),
so this module imports neither the model nor the ports.

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

from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.text import REPR_LIMIT, html_table, number_text, shorten
from phdesign.symbolic.coupled_ports import coupled_ports_dict, coupled_ports_text
from phdesign.symbolic.disturbances import disturbance_lines
from phdesign.symbolic.feedback import external_numbering
from phdesign.symbolic.printing import format_expression

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.model import BCPHS
    from phdesign.symbolic.ports import Ports

__all__ = [
    "IDENTITY_STATEMENTS",
    "model_html",
    "model_repr",
    "model_text",
    "ports_dict",
    "ports_html",
    "ports_repr",
    "ports_text",
]

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


# ---------------------------------------------------------------------- the model


def _parameter_text(model: BCPHS) -> dict[str, Any]:
    return {str(s): int(v) if v.is_Integer else float(v) for s, v in model.parameters}


def _port_text(model: BCPHS, exprs: tuple[sympy.Expr, ...], letter: str) -> str:
    return ", ".join(
        f"{letter}{i + 1} = {format_expression(e, model.interval)}" for i, e in enumerate(exprs)
    )


def model_repr(model: BCPHS) -> str:
    """Return one line: name, order, size, interval and parameter defaults."""
    text = (
        f"BCPHS(name={model.name!r}, N={model.order}, n={model.size}, "
        f"interval={_interval_text(model.interval)}, parameters={_parameter_text(model)})"
    )
    return shorten(text, REPR_LIMIT)


def model_text(model: BCPHS) -> str:
    """Return the summary ``phdesign show`` prints: matrices, ports and the checks."""
    lines = [f"model {model.name}: N = {model.order}, n = {model.size}"]
    if model.description:
        lines.append(model.description)
    lines.append(
        f"z in {_interval_text(model.interval)}; states x = ({', '.join(model.state_names)})"
    )
    if model.parameters:
        values = ", ".join(f"{s} = {number_text(v)}" for s, v in model.parameters)
        lines.append(f"parameters: {values}")
    lines += [f"P{k} = {_rows(P)}" for k, P in enumerate(model.P) if not P.is_zero_matrix]
    lines.append(f"H = {_rows(model.H)}")
    lines.append(f"inputs:  {_port_text(model, model.inputs, 'u')}")
    lines.append(f"outputs: {_port_text(model, model.outputs, 'y')}")
    if model.feedback is not None:  # what --sensors, --u and the exports index
        lines.append(external_numbering(len(model.inputs), model.feedback))
    lines += boundary_text(model)
    lines += disturbance_lines(model)
    lines += [f"check: {c}" for c in model.checks]
    return "\n".join(lines)


def model_html(model: BCPHS) -> str:
    """Return the summary as an HTML table, for notebooks."""
    rows = [
        ["description", model.description],
        ["interval", _interval_text(model.interval)],
        ["states", ", ".join(model.state_names)],
        ["parameters", ", ".join(f"{s} = {number_text(v)}" for s, v in model.parameters)],
        *([f"P{k}", _rows(P)] for k, P in enumerate(model.P) if not P.is_zero_matrix),
        ["H", _rows(model.H)],
        ["inputs", _port_text(model, model.inputs, "u")],
        ["outputs", _port_text(model, model.outputs, "y")],
        ["checks", "; ".join(model.checks)],
    ]
    caption = f"{model.name}: N = {model.order}, n = {model.size}"
    return html_table(["", ""], [r for r in rows if r[1]], caption=caption)


# ---------------------------------------------------------------------- the ports


def _traces(ports: Ports) -> list[str]:
    interval = None if ports.model is None else ports.model.interval
    return [format_expression(s, interval) for s in ports.trace_vector]


def _heading(ports: Ports) -> str:
    m = ports.model
    return "ports" if m is None else f"model {m.name}: N = {m.order}, n = {m.size}"


def _closed(ports: Ports) -> Any:
    """Return the closed ports of the plant's own ``[feedback]``, or ``None``."""
    return None if ports.model is None else ports.model.closed_ports


def ports_dict(ports: Ports) -> dict[str, Any]:
    """Return the JSON of ``phdesign ports --json`` (matrices as rows of exact strings)."""
    m = ports.model

    def rows(M: sympy.MatrixBase) -> list[list[str]]:
        return [[str(x) for x in row] for row in M.tolist()]

    closed = _closed(ports)
    return {
        "model": None if m is None else m.name,
        "order": None if m is None else m.order,
        "size": None if m is None else m.size,
        "traces": _traces(ports),
        "Q": rows(ports.Q),
        "W_B": rows(ports.W_B),
        "W_C": rows(ports.W_C),
        "identities": {key: float(value) for key, value in ports.identities.items()},
        "feedback": None if closed is None else closed.to_dict(),
        **({} if m is None else coupled_ports_dict(m)),
    }


def ports_text(ports: Ports) -> str:
    """Return what ``phdesign ports`` prints: v, Q, W_B, W_C, residuals, the closed plant."""
    lines = [
        _heading(ports),
        f"v = ({', '.join(_traces(ports))})",
        "Q =",
        sympy.pretty(ports.Q),
        "W_B =",
        sympy.pretty(ports.W_B),
        "W_C =",
        sympy.pretty(ports.W_C),
        *(f"max |{key}| = {float(value):g}" for key, value in ports.identities.items()),
    ]
    closed = _closed(ports)
    if closed is not None:  # the plant's own dampers close some of the ports
        lines.append(str(closed))
    if ports.model is not None:
        lines += coupled_ports_text(ports.model)
    return "\n".join(lines)


def ports_repr(ports: Ports) -> str:
    """Return one line: the model, the trace vector and whether the identities are exact."""
    exact = all(value == 0 for value in ports.identities.values())
    name = None if ports.model is None else ports.model.name
    text = (
        f"Ports(model={name!r}, v=({', '.join(_traces(ports))}), "
        f"identities {'exact' if exact else 'FAIL'})"
    )
    return shorten(text, REPR_LIMIT)


def ports_html(ports: Ports) -> str:
    """Return the port structure as an HTML table, for notebooks."""
    rows = [
        ["v", ", ".join(_traces(ports))],
        ["Q", _rows(ports.Q)],
        ["W_B", _rows(ports.W_B)],
        ["W_C", _rows(ports.W_C)],
        *(
            [IDENTITY_STATEMENTS.get(key, key), f"max |residual| = {float(value):g}"]
            for key, value in ports.identities.items()
        ),
    ]
    return html_table(["", ""], rows, caption=_heading(ports))


def energy_identity_text(model: BCPHS) -> str:
    """Return the coupled energy identity of ``model`` as ``phdesign show`` prints it."""
    terms = ["1/2 int e^T (P0 + P0^T) e dz"]
    for bs in model.boundary_systems:
        if not bs.R.is_zero_matrix:
            terms.append(f"- e_c^T R_c e_c ({bs.name})")
        if bs.D is not None and not (bs.D + bs.D.T).is_zero_matrix:
            terms.append(f"- u_c^T D_c u_c ({bs.name})")
    if model.feedback is not None:
        terms.append("- y_f^T K y_f ([feedback])")
    terms.append("+ u_ext^T y_ext")
    return (
        "dH_tot/dt = d/dt (H + "
        + " + ".join(f"H_{bs.name}" for bs in model.boundary_systems)
        + ") = "
        + " ".join(terms)
    )


def boundary_text(model: BCPHS) -> list[str]:
    """Return the lines ``phdesign show`` prints for the boundary systems (none without)."""
    lines = []
    for bs in model.boundary_systems:
        joined = ", ".join(f"u{i}" for i in bs.ports)
        how = "gyrator u_p = -y_c, u_c = y_p" if bs.interconnection is None else "S"
        lines.append(
            f"boundary system {bs.name}: x_c = ({', '.join(bs.state_labels)}) joined to "
            f"{joined} ({how})"
        )
        for key in ("J", "R", "Q", "G", "D", "B"):
            matrix = getattr(bs, key)
            if matrix is not None:
                lines.append(f"  {key}_c = {_rows(matrix)}")
        if bs.interconnection is not None:
            lines.append(f"  S = {_rows(bs.interconnection)}")
        if bs.n_external:
            pairs = ", ".join(
                f"{u} -> {y}" for u, y in zip(bs.input_labels, bs.output_labels, strict=True)
            )
            lines.append(f"  external inputs -> outputs: {pairs}")
    if lines:
        lines.append(energy_identity_text(model))
    return lines
