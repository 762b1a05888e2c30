r"""Outputs derived from the inputs: the power conjugates a user need not work out.

Given the inputs :math:`u = U v` over the trace vector :math:`v`, phdesign derives outputs
:math:`y = Y v` that make the model a BC-PHS.  In port variables
(:math:`W_B = U R_{ext}^{-1}`, :mod:`phdesign.symbolic.ports`) the inputs are admissible
iff :math:`W_B` has full rank :math:`Nn` and :math:`W_B \Sigma W_B^\top = 0`; then

.. math::

    W_C^{(0)} = (W_B W_B^\top)^{-1} W_B \Sigma

satisfies both remaining identities: :math:`W_C^{(0)} \Sigma W_B^\top = (W_B W_B^\top)^{-1}
W_B \Sigma^2 W_B^\top = I` and :math:`W_C^{(0)}\Sigma W_C^{(0)\top} = (W_BW_B^\top)^{-1}
(W_B \Sigma W_B^\top)(W_BW_B^\top)^{-1} = 0`, because :math:`\Sigma^2 = I` and
:math:`\Sigma^3 = \Sigma`.

*Not unique.*  If :math:`W_C` and :math:`W_C'` both satisfy :math:`W_C\Sigma W_B^\top = I`,
the rows of :math:`W_C' - W_C` are :math:`\Sigma`-orthogonal to the rows of :math:`W_B`;
that complement is the row space of :math:`W_B` itself (it is Lagrangian: isotropic of
dimension :math:`Nn`), so :math:`W_C' = W_C + S W_B`, and :math:`W_C'\Sigma W_C'^\top =
S + S^\top = 0` forces :math:`S` skew.  The conjugate outputs are therefore exactly
:math:`y' = y + S u` with :math:`S = -S^\top`: a power-neutral feedthrough
(:math:`u^\top S u = 0`).

*Canonical choice.*  In trace coordinates (the user's notation), phdesign takes the outputs
of least Frobenius norm :math:`\|Y\|_F` among them.  With :math:`Y = Y_0 + S U`,
:math:`Y_0 = W_C^{(0)} R_{ext}`, the gradient of :math:`\|Y\|_F^2` along skew :math:`S` is the
skew part of :math:`Y U^\top`, so the minimizer is the unique :math:`Y` with
:math:`Y U^\top` symmetric: :math:`S` solves the Lyapunov equation
:math:`S G + G S = U Y_0^\top - Y_0 U^\top` with :math:`G = U U^\top \succ 0`, whose
operator :math:`S \mapsto SG + GS` is invertible (its eigenvalues are
:math:`\gamma_i + \gamma_j > 0`) and maps skew matrices to skew matrices.  When the outputs
can avoid the input traces altogether (:math:`Y U^\top = 0`, every built-in model), this is
that choice; the sign is fixed by :math:`W_C\Sigma W_B^\top = +I` (power
:math:`u^\top y` flowing *into* the system), so there is no sign convention left to choose.

Examples
--------
>>> from phdesign.symbolic.traces import parse_trace_expression
>>> from phdesign.symbolic.printing import format_expression
>>> inputs = [parse_trace_expression(t, (0, 1), 1, 2) for t in ("e1(0)", "e2(1)")]
>>> P = [sympy.zeros(2), sympy.Matrix([[0, 1], [1, 0]])]
>>> [format_expression(y, (0, 1)) for y in conjugate_outputs(P, 1, inputs, (0, 1), {})]
['-e2(0)', 'e1(1)']
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import sympy

from phdesign.core.errors import PortError
from phdesign.symbolic.expressions import canonical, vanishes
from phdesign.symbolic.ports import (
    coefficient_matrix,
    extended_matrices,
    inadmissible_inputs_message,
    sigma_matrix,
    trace_vector,
)

__all__ = ["conjugate_outputs"]


def conjugate_outputs(
    P: Sequence[sympy.MatrixBase],
    order: int,
    inputs: Sequence[sympy.Expr],
    interval: Sequence[object],
    defaults: Mapping[sympy.Symbol, sympy.Expr],
) -> tuple[sympy.Expr, ...]:
    r"""Derive the canonical power-conjugate outputs of ``inputs`` (module docstring).

    Parameters
    ----------
    P : sequence of matrices
        ``P_0 .. P_N`` (only ``P_1 .. P_N`` enter, through :math:`Q`).
    order : int
        ``N``.
    inputs : sequence of sympy.Expr
        ``N n`` trace expressions.
    interval : (a, b)
        For messages.
    defaults : mapping
        Parameter defaults (rank decisions are made there).

    Returns
    -------
    tuple of sympy.Expr
        The outputs, as trace expressions.

    Raises
    ------
    PortError
        If the inputs are linearly dependent or not admissible
        (:math:`W_B\Sigma W_B^\top \ne 0`); the message names the input rows.
    """
    n = P[order].shape[0]
    nn = order * n
    U = sympy.Matrix(coefficient_matrix(inputs, order, n, "inputs"))
    rank = U.xreplace(dict(defaults)).rank(iszerofunc=vanishes)
    if rank != nn:
        raise PortError(
            f"the inputs are linearly dependent: rank of W_B is {rank}, expected N*n = {nn}"
        )
    R_ext, R_inv = extended_matrices(P, order)
    W_B = U * R_inv
    Sigma = sigma_matrix(nn)
    residual = (W_B * Sigma * W_B.T).applyfunc(canonical)
    if not all(vanishes(x) for x in residual):
        raise PortError(inadmissible_inputs_message(residual, inputs, interval, defaults))
    W_C0 = (W_B * W_B.T).inv() * W_B * Sigma
    Y0 = (W_C0 * R_ext).applyfunc(canonical)
    G = U * U.T
    S = _lyapunov_skew(G, U * Y0.T - Y0 * U.T)
    Y = (Y0 + S * U).applyfunc(canonical)
    v = sympy.Matrix(trace_vector(order, n))
    return tuple(canonical((Y[i, :] * v)[0]) for i in range(nn))


def _lyapunov_skew(G: sympy.Matrix, C: sympy.Matrix) -> sympy.Matrix:
    r"""Solve :math:`S G + G S = C` exactly for skew :math:`S` (``C`` skew, ``G`` ≻ 0)."""
    m = G.rows
    if all(vanishes(x) for x in C):
        return sympy.zeros(m, m)
    unknowns = sympy.symbols(f"s0:{m * m}")
    S = sympy.Matrix(m, m, unknowns)
    equations = [canonical(x) for x in (S * G + G * S - C)]
    solution = sympy.solve(equations, unknowns, dict=True)
    if len(solution) != 1:  # the operator is invertible; this guards the algebra
        raise PortError("cannot derive the conjugate outputs: the Lyapunov equation is singular")
    return S.xreplace(solution[0]).applyfunc(canonical)
