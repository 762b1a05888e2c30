r"""Locate an outputs error: which outputs break the port identities, and what they should be.

When the inputs are admissible (:math:`W_B \Sigma W_B^\top = 0`) but an output identity
fails, row i of :math:`W_C \Sigma W_B^\top` is the power that output :math:`y_i` pairs
with each input; it must be :math:`e_i^\top`, and entry :math:`(i, j)` of
:math:`W_C \Sigma W_C^\top` is twice the power outputs i and j exchange, which must
vanish.  So the outputs at fault are the rows where either residual is nonzero, and for
each of them the message prints the conjugate output phdesign derives for that input
(:func:`~phdesign.symbolic.conjugate.conjugate_outputs`; any other admissible choice
differs from it by a power-neutral :math:`S u`, :math:`S = -S^\top`).

A sign slip in a :math:`P_k` is told apart: when the three identities hold with one
:math:`P_k` negated (each :math:`P_k` enters through :math:`Q`), the message says so and
names :math:`P_k` first.  With :math:`P_N` the only nonzero :math:`P_k` (the beam) this is
the case :math:`W_C \Sigma W_B^\top = -I`: every output or :math:`P_N`'s sign is wrong, and
no single output is named as the fault.
"""

from __future__ import annotations

from collections.abc import Mapping

import sympy

from phdesign.symbolic.conjugate import conjugate_outputs
from phdesign.symbolic.expressions import canonical, vanishes
from phdesign.symbolic.ports import coefficient_matrix, extended_matrices, sigma_matrix
from phdesign.symbolic.printing import format_expression
from phdesign.symbolic.system import PortedSystem

__all__ = ["outputs_fault_message"]


def _forms(
    P: list[sympy.MatrixBase], model: PortedSystem
) -> tuple[sympy.Matrix, sympy.Matrix, sympy.Matrix]:
    """Return W_B Σ W_Bᵀ, W_C Σ W_Bᵀ − I and W_C Σ W_Cᵀ for the matrices ``P``."""
    N, n = model.order, model.size
    U = sympy.Matrix(coefficient_matrix(model.inputs, N, n, "inputs"))
    Y = sympy.Matrix(coefficient_matrix(model.outputs, N, n, "outputs"))
    _, R_inv = extended_matrices(P, N)
    W_B, W_C = U * R_inv, Y * R_inv
    S = sigma_matrix(N * n)
    clean = lambda M: M.applyfunc(canonical)  # noqa: E731
    return (
        clean(W_B * S * W_B.T),
        clean(W_C * S * W_B.T - sympy.eye(N * n)),
        clean(W_C * S * W_C.T),
    )


def _zero(M: sympy.MatrixBase) -> bool:
    return all(vanishes(x) for x in M)


def slipped_signs(model: PortedSystem) -> list[int]:
    """Return the k for which the three identities hold with ``P_k`` negated."""
    out = []
    for k in range(1, model.order + 1):
        if _zero(model.P[k]):
            continue
        P = [(-M if j == k else M) for j, M in enumerate(model.P)]
        if all(_zero(M) for M in _forms(P, model)):
            out.append(k)
    return out


def outputs_fault_message(model: PortedSystem, defaults: Mapping[sympy.Symbol, sympy.Expr]) -> str:
    """Return the located message of an output identity that fails (module docstring).

    Returns "" when the inputs are not admissible or every identity holds (nothing to
    locate here).
    """
    wb, pairing, exchange = _forms(list(model.P), model)
    if not _zero(wb) or (_zero(pairing) and _zero(exchange)):
        return ""
    rows = [
        i for i in range(pairing.rows) if not _zero(pairing[i, :]) or not _zero(exchange[i, :])
    ]
    a_b = model.interval
    signs = slipped_signs(model)
    if signs:
        ks = ", ".join(f"P{k}" for k in signs)
        head = (
            f"the port identities hold with the sign of {ks} reversed: a sign slip in {ks} "
            "(check it against the PDE) or, equally, every output with the wrong sign"
        )
        return head
    derived = conjugate_outputs(model.P, model.order, model.inputs, a_b, defaults)
    parts = []
    for i in rows:
        row = (pairing[i, :] + sympy.eye(pairing.rows)[i, :]).applyfunc(canonical)
        pairs = ", ".join(
            f"{canonical(row[j])}·u{j + 1}" for j in range(row.cols) if not vanishes(row[j])
        )
        parts.append(
            f"y{i + 1} = {format_expression(model.outputs[i], a_b)} pairs with "
            f"{pairs or 'no input'} (expected 1·u{i + 1}); phdesign derives "
            f"y{i + 1} = {format_expression(derived[i], a_b)} as the conjugate of "
            f"u{i + 1} = {format_expression(model.inputs[i], a_b)}"
        )
    return "outputs at fault: " + "; ".join(parts)
