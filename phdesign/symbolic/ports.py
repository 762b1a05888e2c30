r"""Boundary port variables of a BC-PHS: traces, Q, R_ext, W_B and W_C.

With :math:`\phi(z) = (e, \partial_z e, \dots, \partial_z^{N-1} e)(z)` and the trace
vector :math:`v = (\phi(b); \phi(a)) \in \mathbb R^{2Nn}`, integration by parts gives,
for :math:`k \ge 1`,

.. math::

    \sum_{k=1}^{N} \int_a^b e^\top P_k \partial_z^k e \, dz
    = \tfrac12 \big[\phi^\top Q \phi\big]_a^b,
    \qquad Q_{ij} = (-1)^{i-1} P_{i+j-1} \ (i + j - 1 \le N), \ 0 \text{ otherwise},

(block indices :math:`i, j = 1..N`). The paper prints :math:`(-1)^{j-1}`, which has the
wrong sign for every even :math:`k` (see the conventions in the documentation).
Proof sketch: moving :math:`j-1`
derivatives of :math:`\partial_z^k e` onto :math:`e^\top` leaves boundary terms
:math:`(-1)^{i-1} (\partial^{i-1} e)^\top P_k \partial^{k-i} e`, :math:`i = 1..k`, whose
symmetrization is the :math:`(i, k+1-i)` block of :math:`Q`, and the remaining integral
vanishes by the symmetry :math:`P_k^\top = (-1)^{k-1} P_k`.

The boundary port variables are :math:`(f_\partial; e_\partial) = R_{ext} v` with

.. math::

    R_{ext} = \frac{1}{\sqrt2}\begin{pmatrix} Q & -Q \\ I & I \end{pmatrix},
    \qquad f_\partial^\top e_\partial = \tfrac12 v^\top \operatorname{diag}(Q, -Q) v .

Users give :math:`u = U v` and :math:`y = Y v`; then :math:`W_B = U R_{ext}^{-1}`,
:math:`W_C = Y R_{ext}^{-1}`, and the model is a BC-PHS iff both have full rank and

.. math::

    W_B \Sigma W_B^\top = 0, \quad W_C \Sigma W_C^\top = 0, \quad W_C \Sigma W_B^\top = I,
    \qquad \Sigma = \begin{pmatrix} 0 & I \\ I & 0 \end{pmatrix} \in \mathbb R^{2Nn\times 2Nn}.

Examples
--------
>>> from phdesign.models import load_builtin
>>> ports = derive_ports(load_builtin("wave"))
>>> ports.W_C * ports.Sigma * ports.W_B.T
Matrix([
[1, 0],
[0, 1]])
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Protocol

import sympy

from phdesign.arguments import require_model
from phdesign.errors import PortError
from phdesign.symbolic.display import PortsDisplay
from phdesign.symbolic.expressions import (
    Trace,
    canonical,
    linear_coefficients,
    trace_symbol,
    vanishes,
)


class PortedSystem(Protocol):
    """What the port derivation reads of a model (a :class:`~phdesign.symbolic.model.BCPHS`).

    A protocol rather than an import keeps this module below the model module, which
    calls :func:`derive_ports` to validate itself.
    """

    @property
    def order(self) -> int: ...
    @property
    def size(self) -> int: ...
    @property
    def P(self) -> tuple[sympy.ImmutableMatrix, ...]: ...
    @property
    def inputs(self) -> tuple[sympy.Expr, ...]: ...
    @property
    def outputs(self) -> tuple[sympy.Expr, ...]: ...
    @property
    def parameter_defaults(self) -> dict[sympy.Symbol, sympy.Expr]: ...
    @property
    def interval(self) -> tuple[sympy.Expr, sympy.Expr]: ...


__all__ = [
    "IDENTITY_NAMES",
    "Ports",
    "coefficient_matrix",
    "derive_ports",
    "extended_matrices",
    "q_matrix",
    "trace_index",
    "trace_list",
    "trace_vector",
]

#: Keys of :attr:`Ports.identities`, in the order of the JSON contract of ``phdesign ports``.
IDENTITY_NAMES = ("WB_Sigma_WBt", "WC_Sigma_WCt", "WC_Sigma_WBt_minus_I")


def trace_index(component: int, derivative: int, side: str, order: int, size: int) -> int:
    r"""Return the 0-based position of trace :math:`\partial^k e_i(\text{side})` in ``v``.

    Examples
    --------
    >>> trace_index(2, 1, "a", order=2, size=2)   # e2'(a): after phi(b) (4 entries), then e1'(a)
    7
    """
    offset = 0 if side == "b" else order * size
    return offset + derivative * size + (component - 1)


@lru_cache(maxsize=64)
def trace_list(order: int, size: int) -> tuple[Trace, ...]:
    """Return the traces of ``v = (phi(b); phi(a))`` in order."""
    return tuple(
        Trace(i, k, side)  # type: ignore[arg-type]
        for side in ("b", "a")
        for k in range(order)
        for i in range(1, size + 1)
    )


def trace_vector(order: int, size: int) -> tuple[sympy.Symbol, ...]:
    """Return the symbols of ``v = (phi(b); phi(a))``, of length ``2 N n``."""
    return tuple(trace_symbol(t.component, t.derivative, t.side) for t in trace_list(order, size))


def q_matrix(P: Sequence[sympy.MatrixBase], order: int) -> sympy.ImmutableMatrix:
    """Return :math:`Q` with blocks :math:`Q_{ij} = (-1)^{i-1} P_{i+j-1}` (the corrected sign).

    Parameters
    ----------
    P : sequence of matrices
        ``P_0 .. P_N`` (``P_0`` is not used).
    order : int
        ``N``.
    """
    n = P[order].shape[0]
    blocks = [
        [
            (-1) ** (i - 1) * sympy.Matrix(P[i + j - 1])
            if i + j - 1 <= order
            else sympy.zeros(n, n)
            for j in range(1, order + 1)
        ]
        for i in range(1, order + 1)
    ]
    return sympy.ImmutableMatrix(sympy.BlockMatrix(blocks).as_explicit())


def extended_matrices(
    P: Sequence[sympy.MatrixBase], order: int
) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
    r"""Return :math:`R_{ext} = \tfrac{1}{\sqrt2}[[Q, -Q], [I, I]]` and its inverse."""
    Q = q_matrix(P, order)
    eye = sympy.eye(Q.rows)
    R_ext = sympy.ImmutableMatrix(
        sympy.BlockMatrix([[Q, -Q], [eye, eye]]).as_explicit() / sympy.sqrt(2)
    )
    Q_inv = Q.inv()
    R_inv = sympy.ImmutableMatrix(
        sympy.BlockMatrix([[Q_inv, eye], [-Q_inv, eye]]).as_explicit() / sympy.sqrt(2)
    )
    return R_ext, R_inv


def coefficient_matrix(
    exprs: Sequence[sympy.Expr], order: int, size: int, what: str
) -> sympy.ImmutableMatrix:
    """Return the matrix ``M`` with ``exprs = M v`` (one row per expression)."""
    traces = trace_list(order, size)
    position = {t: j for j, t in enumerate(traces)}
    rows = []
    for i, expr in enumerate(exprs):
        row = [sympy.Integer(0)] * len(traces)
        for trace, coefficient in linear_coefficients(expr, what=f"{what}[{i + 1}]").items():
            row[position[trace]] = coefficient
        rows.append(row)
    return sympy.ImmutableMatrix(rows)


@dataclass(frozen=True, repr=False)
class Ports(PortsDisplay):
    """The boundary port structure of a model (all matrices exact).

    Attributes
    ----------
    trace_vector : tuple of sympy.Symbol
        ``v = (phi(b); phi(a))``.
    Q : sympy.ImmutableMatrix
        ``N n x N n``.
    R_ext : sympy.ImmutableMatrix
        ``(f_d; e_d) = R_ext v``.
    U, Y : sympy.ImmutableMatrix
        ``u = U v`` and ``y = Y v``, each ``N n x 2 N n``.
    W_B, W_C : sympy.ImmutableMatrix
        ``U R_ext^-1`` and ``Y R_ext^-1``.
    Sigma : sympy.ImmutableMatrix
        ``[[0, I], [I, 0]]`` of size ``2 N n``.
    identities : dict
        Largest absolute entry of each identity's residual (zero for a valid model),
        keyed by :data:`IDENTITY_NAMES`.
    model : BCPHS or None
        The model the ports belong to (for printing: names and endpoints).
    """

    trace_vector: tuple[sympy.Symbol, ...]
    Q: sympy.ImmutableMatrix
    R_ext: sympy.ImmutableMatrix
    U: sympy.ImmutableMatrix
    Y: sympy.ImmutableMatrix
    W_B: sympy.ImmutableMatrix
    W_C: sympy.ImmutableMatrix
    Sigma: sympy.ImmutableMatrix
    identities: dict[str, sympy.Expr]
    model: PortedSystem | None = field(default=None, compare=False)

    def boundary_variables(self) -> sympy.ImmutableMatrix:
        r"""Return :math:`(f_\partial; e_\partial)` as expressions in the traces."""
        return self.R_ext * sympy.ImmutableMatrix(self.trace_vector)


def sigma_matrix(dimension: int) -> sympy.ImmutableMatrix:
    r"""Return :math:`\Sigma = [[0, I], [I, 0]]` with ``I`` of size ``dimension``."""
    eye, zero = sympy.eye(dimension), sympy.zeros(dimension)
    return sympy.ImmutableMatrix(sympy.BlockMatrix([[zero, eye], [eye, zero]]).as_explicit())


def derive_ports(model: PortedSystem) -> Ports:
    """Derive and check the port structure of ``model`` (a model caches it as ``model.ports``).

    Raises
    ------
    ArgumentError
        If ``model`` is not a model.
    PortError
        If the inputs or the outputs are linearly dependent, or an identity fails;
        the message names the identity and its largest residual.
    """
    require_model(model)
    N, n = model.order, model.size
    Q = q_matrix(model.P, N)
    eye = sympy.eye(N * n)
    R_ext, R_inv = extended_matrices(model.P, N)
    U = coefficient_matrix(model.inputs, N, n, "inputs")
    Y = coefficient_matrix(model.outputs, N, n, "outputs")
    defaults = model.parameter_defaults
    for name, M in (("inputs", U), ("outputs", Y)):
        rank = M.xreplace(defaults).rank(iszerofunc=vanishes)
        if rank != N * n:
            raise PortError(
                f"the {name} are linearly dependent: rank of "
                f"{'W_B' if name == 'inputs' else 'W_C'} "
                f"is {rank}, expected N*n = {N * n}"
            )
    W_B = (U * R_inv).applyfunc(canonical)
    W_C = (Y * R_inv).applyfunc(canonical)
    Sigma = sigma_matrix(N * n)
    residuals = {
        "WB_Sigma_WBt": W_B * Sigma * W_B.T,
        "WC_Sigma_WCt": W_C * Sigma * W_C.T,
        "WC_Sigma_WBt_minus_I": W_C * Sigma * W_B.T - eye,
    }
    statements = {
        "WB_Sigma_WBt": "W_B Σ W_Bᵀ = 0",
        "WC_Sigma_WCt": "W_C Σ W_Cᵀ = 0",
        "WC_Sigma_WBt_minus_I": "W_C Σ W_Bᵀ = I",
    }
    identities: dict[str, sympy.Expr] = {}
    for key in IDENTITY_NAMES:
        residual = residuals[key].applyfunc(canonical)
        largest = _max_abs(residual, defaults)
        identities[key] = largest
        if not all(vanishes(x) for x in residual):
            if key == "WB_Sigma_WBt":  # the inputs alone are wrong: say so, naming them
                from phdesign.symbolic.conjugate import inadmissible_inputs_message

                raise PortError(
                    inadmissible_inputs_message(residual, model.inputs, model.interval, defaults)
                )
            at = " at the parameter defaults" if residual.free_symbols else ""
            raise PortError(
                f"port identity {statements[key]} fails: largest residual |entry| = "
                f"{_short(largest)}{at}; the outputs must be the power conjugates of the inputs"
            )
    return Ports(
        trace_vector=trace_vector(N, n),
        Q=Q,
        R_ext=R_ext,
        U=U,
        Y=Y,
        W_B=sympy.ImmutableMatrix(W_B),
        W_C=sympy.ImmutableMatrix(W_C),
        Sigma=Sigma,
        identities=identities,
        model=model,
    )


def _max_abs(matrix: sympy.MatrixBase, defaults: dict[sympy.Symbol, sympy.Expr]) -> sympy.Expr:
    values = [sympy.Abs(x.xreplace(defaults)) for x in matrix]
    return max(values, key=lambda x: float(x)) if values else sympy.Integer(0)


def _short(value: sympy.Expr) -> str:
    return str(value) if len(str(value)) < 30 else f"{float(value):.6g}"
