r"""The ports of a coupled model: what each boundary system joins, and what is left outside.

``phdesign ports`` shows the PDE's port structure (:mod:`phdesign.symbolic.ports`); for a
model with boundary systems it adds, for each system, the PDE inputs :math:`u_p` it is
joined to with their conjugate outputs :math:`y_p`, the interconnection solved
(:func:`~phdesign.symbolic.boundary_systems.coupling`),

.. math::

    u_p = -K y_p + F e_c, \qquad e_c = Q_c x_c,

and its own ports :math:`w \to z_c`; then the coupled system's external ports, numbered
as the sensors and gains number them: the PDE's inputs left open (by ``[feedback]``
and by the boundary systems), then every system's own inputs, each with its conjugate
output.  Their power :math:`u_{ext}^\top y_{ext}` is the last term of the energy identity
(:mod:`phdesign.symbolic.boundary_systems`).

Examples
--------
>>> from phdesign.models import load_builtin
>>> for port in external_ports(load_builtin("string-tip-mass")):
...     print(port.index, port.input, "->", port.output, f"({port.source})")
1 e1(0) -> -e2(0) (PDE)
2 force -> mass velocity (mass)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.symbolic.boundary_systems import coupling
from phdesign.symbolic.feedback import external_indices
from phdesign.symbolic.printing import format_expression

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.model import BCPHS

__all__ = ["ExternalPort", "coupled_ports_dict", "coupled_ports_text", "external_ports"]


@dataclass(frozen=True)
class ExternalPort:
    """One external port of the coupled system: 1-based ``index``, input and output labels.

    ``source`` is ``"PDE"`` for an open trace input, else the boundary system's name;
    ``pde_index`` the input's 1-based index in ``[ports].inputs`` (None for a system's own).
    """

    index: int
    input: str
    output: str
    source: str
    pde_index: int | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON form."""
        return {
            "index": self.index,
            "input": self.input,
            "output": self.output,
            "source": self.source,
            "pde_index": self.pde_index,
        }


def external_ports(model: BCPHS) -> tuple[ExternalPort, ...]:
    """Return the coupled system's external ports, in the order the sensors number them."""
    joined = {j for bs in model.boundary_systems for j in bs.joined}
    open_inputs = [
        j for j in external_indices(len(model.inputs), model.feedback) if j not in joined
    ]
    ports = [
        ExternalPort(
            k, _label(model, model.inputs[j]), _label(model, model.outputs[j]), "PDE", j + 1
        )
        for k, j in enumerate(open_inputs, start=1)
    ]
    for bs in model.boundary_systems:
        for u, y in zip(bs.input_labels, bs.output_labels, strict=True):
            ports.append(ExternalPort(len(ports) + 1, u, y, bs.name))
    return tuple(ports)


def _label(model: BCPHS, expr: sympy.Expr) -> str:
    return format_expression(expr, model.interval)


def _rows(M: sympy.MatrixBase) -> list[list[str]]:
    return [[str(x) for x in row] for row in M.tolist()]


def _text(rows: list[list[str]]) -> str:
    return "[" + ", ".join("[" + ", ".join(row) + "]" for row in rows) + "]"


def _systems(model: BCPHS) -> list[dict[str, Any]]:
    out = []
    for bs in getattr(model, "boundary_systems", ()):
        c = coupling(bs)
        out.append(
            {
                "name": bs.name,
                "states": list(bs.state_labels),
                "joined_inputs": [
                    f"u{i} = {_label(model, model.inputs[i - 1])}" for i in bs.ports
                ],
                "joined_outputs": [
                    f"y{i} = {_label(model, model.outputs[i - 1])}" for i in bs.ports
                ],
                "interconnection": "gyrator"
                if bs.interconnection is None
                else _rows(bs.interconnection),
                "K": _rows(c.K),
                "F": _rows(c.to_pde),
                "inputs": list(bs.input_labels),
                "outputs": list(bs.output_labels),
            }
        )
    return out


def coupled_ports_dict(model: Any) -> dict[str, Any]:
    """Return the keys ``phdesign ports --json`` adds: the systems and the external ports."""
    return {
        "boundary_systems": _systems(model),
        "external_ports": [p.to_dict() for p in external_ports(model)],
    }


def coupled_ports_text(model: Any) -> list[str]:
    """Return the lines ``phdesign ports`` adds for a model with boundary systems."""
    if not getattr(model, "boundary_systems", ()):
        return []
    lines = []
    for system in _systems(model):
        how = "gyrator" if system["interconnection"] == "gyrator" else "S"
        lines.append(
            f"boundary system {system['name']}: joined to {', '.join(system['joined_inputs'])}"
            f" with {', '.join(system['joined_outputs'])} ({how})"
        )
        K, F = (_text(system[key]) for key in ("K", "F"))
        lines.append(f"  u_p = -K y_p + F e_c, e_c = Q_c x_c: K = {K}, F = {F}")
        pairs = ", ".join(
            f"{u} -> {y}" for u, y in zip(system["inputs"], system["outputs"], strict=True)
        )
        lines.append(f"  own ports: {pairs or 'none'}")
    lines.append("external ports of the coupled system (the sensors' and gains' numbering):")
    for port in external_ports(model):
        u, y = (
            (f"u{port.pde_index} = ", f"y{port.pde_index} = ")
            if port.pde_index is not None
            else ("", "")
        )
        lines.append(f"  {port.index}: {u}{port.input} -> {y}{port.output} ({port.source})")
    return lines
