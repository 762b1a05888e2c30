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

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import sympy
from sympy.polys.constructor import construct_domain
from sympy.polys.matrices import DomainMatrix
from sympy.polys.matrices.exceptions import DMNonInvertibleMatrixError

from phdesign.core.errors import PortError
from phdesign.symbolic import display
from phdesign.symbolic.expressions import canonical, exact_matrix, vanishes
from phdesign.symbolic.printing import format_expression
from phdesign.symbolic.system import PortedSystem, require_model
from phdesign.symbolic.traces import Trace, linear_coefficients, trace_symbol

__all__ = [
    "IDENTITY_NAMES",
    "Ports",
    "coefficient_matrix",
    "derive_ports",
    "extended_matrices",
    "inadmissible_inputs_message",
    "q_matrix",
    "sigma_matrix",
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
        Trace(i, k, side) for side in ("b", "a") for k in range(order) for i in range(1, size + 1)
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
    rows = []
    for i in range(1, order + 1):
        blocks = [
            (-1) ** (i - 1) * exact_matrix(P[i + j - 1], f"P{i + j - 1}", symbols=True)
            if i + j - 1 <= order
            else sympy.zeros(n, n)
            for j in range(1, order + 1)
        ]
        rows.append(sympy.Matrix.hstack(*blocks))
    return sympy.ImmutableMatrix(sympy.Matrix.vstack(*rows))


def extended_matrices(
    P: Sequence[sympy.MatrixBase], order: int
) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
    r"""Return :math:`R_{ext} = \tfrac{1}{\sqrt2}[[Q, -Q], [I, I]]` and its inverse."""
    Q = q_matrix(P, order)
    (exact,) = _exact_matrices(Q)
    Q_inv = exact.inv().to_Matrix()
    eye = sympy.eye(Q.rows)
    half = sympy.sqrt(2) / 2

    def blocks(top_left: Any, top_right: Any, bottom_left: Any) -> sympy.ImmutableMatrix:
        M = sympy.Matrix.vstack(
            sympy.Matrix.hstack(top_left, top_right), sympy.Matrix.hstack(bottom_left, eye)
        )
        return sympy.ImmutableMatrix(M.applyfunc(lambda x: half * x))

    return blocks(Q, -Q, eye), blocks(Q_inv, eye, -Q_inv)


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
class Ports:
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

    def to_dict(self) -> dict[str, Any]:
        """Return the JSON of ``phdesign ports --json`` (matrices as rows of exact strings)."""
        return display.ports_dict(self)

    def __str__(self) -> str:
        """Return what ``phdesign ports`` prints (:mod:`phdesign.symbolic.display`)."""
        return display.ports_text(self)

    def __repr__(self) -> str:
        """Short form: the model, the trace vector and whether the identities are exact."""
        return display.ports_repr(self)

    def _repr_html_(self) -> str:
        return display.ports_html(self)


def sigma_matrix(dimension: int) -> sympy.ImmutableMatrix:
    r"""Return :math:`\Sigma = [[0, I], [I, 0]]` with ``I`` of size ``dimension``."""
    return sympy.ImmutableMatrix(
        2 * dimension, 2 * dimension, lambda i, j: 1 if abs(i - j) == dimension else 0
    )


def _exact_matrices(*matrices: sympy.MatrixBase) -> tuple[DomainMatrix, ...]:
    """Return the matrices over one exact domain (rationals, algebraic, rational functions).

    Products and inverses cost far less there than in sympy's generic matrices, and
    zero is recognized exactly.
    """
    entries = [x for M in matrices for x in M]
    try:
        domain, elements = construct_domain(entries, extension=True, field=True)
    except (sympy.PolynomialError, NotImplementedError, ValueError):
        domain, elements = construct_domain(entries, field=True)
    out = []
    offset = 0
    for M in matrices:
        rows, cols = M.shape
        block = elements[offset : offset + rows * cols]
        offset += rows * cols
        dense = DomainMatrix(
            [block[i * cols : (i + 1) * cols] for i in range(rows)], (rows, cols), domain
        )
        out.append(dense)
    zeros = sum(1 for x in elements if not x)
    if zeros > 0.8 * len(elements):  # mostly zeros (most models): products skip them
        return tuple(M.to_sparse() for M in out)
    return tuple(out)


def _integral(M: DomainMatrix) -> tuple[Any, DomainMatrix]:
    """``(s, N)`` with ``M = N / s``: ``N`` over the integers when ``M`` is rational."""
    if M.domain == sympy.QQ:
        scale, integral = M.clear_denoms(convert=True)
        return scale.element, integral
    return M.domain.one, M


def _identity(size: int, like: DomainMatrix) -> DomainMatrix:
    eye = DomainMatrix.eye(size, like.domain)
    return eye.to_sparse() if like.rep.fmt == "sparse" else eye.to_dense()


def _exact_zero(M: DomainMatrix) -> bool:
    """Whether ``M`` vanishes identically (decided by the domain, or by :func:`vanishes`)."""
    if not M.domain.is_EX:
        return bool(M.is_zero_matrix)
    return all(vanishes(x) for x in M.to_Matrix())


def _rank(M: sympy.MatrixBase) -> int:
    (exact,) = _exact_matrices(M)
    if exact.domain.is_EX:
        return int(M.rank(iszerofunc=vanishes))
    return int(exact.rank())


def derive_ports(model: PortedSystem) -> Ports:
    r"""Derive and check the port structure of ``model`` (a model caches it as ``model.ports``).

    With :math:`u = U v`, :math:`U = (U_b\ U_a)` split by the halves
    :math:`\phi(b), \phi(a)` of :math:`v`, :math:`R_{ext}^{-1} = \tfrac{1}{\sqrt2}
    \begin{pmatrix} Q^{-1} & I \\ -Q^{-1} & I \end{pmatrix}` gives
    :math:`W_B = \tfrac{1}{\sqrt 2}\big((U_b - U_a) Q^{-1} \;\; U_b + U_a\big)`, and
    (with :math:`Q` symmetric) :math:`W_B \Sigma W_B^\top = U_b Q^{-1} U_b^\top -
    U_a Q^{-1} U_a^\top`, likewise :math:`W_C \Sigma W_C^\top` and
    :math:`W_C \Sigma W_B^\top = Y_b Q^{-1} U_b^\top - Y_a Q^{-1} U_a^\top`: the
    identities are checked in exact rational (or algebraic) arithmetic, without the
    :math:`\sqrt 2` of :math:`R_{ext}`.

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
    nn = N * n
    Q = q_matrix(model.P, N)
    U = coefficient_matrix(model.inputs, N, n, "inputs")
    Y = coefficient_matrix(model.outputs, N, n, "outputs")
    defaults = model.parameter_defaults
    for name, M in (("inputs", U), ("outputs", Y)):
        rank = _rank(M.xreplace(defaults))
        if rank != nn:
            raise PortError(
                f"the {name} are linearly dependent: rank of "
                f"{'W_B' if name == 'inputs' else 'W_C'} "
                f"is {rank}, expected N*n = {nn}"
            )
    dQ, dU, dY = _exact_matrices(Q, U, Y)
    try:
        Q_inv = dQ.inv()
    except (DMNonInvertibleMatrixError, ZeroDivisionError):
        raise PortError(f"Q is singular: P{N} must be invertible") from None
    # over the rationals, clear the denominators: integer products are far cheaper, and
    # each residual below is the true one times a positive constant (same zero test)
    s_Q, Qi = _integral(Q_inv)
    u, y = _Halves.of(dU, Qi, nn), _Halves.of(dY, Qi, nn)
    identities = _identities(u, y, Qi, s_Q, model)
    half = sympy.sqrt(2) / 2
    eye = sympy.eye(nn)
    R_ext = sympy.ImmutableMatrix(
        sympy.Matrix.vstack(sympy.Matrix.hstack(Q, -Q), sympy.Matrix.hstack(eye, eye)).applyfunc(
            lambda x: half * x
        )
    )
    return Ports(
        trace_vector=trace_vector(N, n),
        Q=Q,
        R_ext=R_ext,
        U=U,
        Y=Y,
        W_B=u.port_map(Qi, s_Q),
        W_C=y.port_map(Qi, s_Q),
        Sigma=sigma_matrix(nn),
        identities=identities,
        model=model,
    )


@dataclass(frozen=True)
class _Halves:
    r"""A port matrix :math:`M = (M_b\ M_a)/s` over an exact domain, split by the halves of ``v``.

    ``b``, ``a`` are the halves of :math:`sM` (integers over the rationals), ``bq``, ``aq``
    the halves times the cleared :math:`s_Q Q^{-1}`.
    """

    b: DomainMatrix
    a: DomainMatrix
    bq: DomainMatrix
    aq: DomainMatrix
    scale: Any

    @classmethod
    def of(cls, M: DomainMatrix, Qi: DomainMatrix, nn: int) -> _Halves:
        scale, Mi = _integral(M)
        b, a = Mi[:, :nn], Mi[:, nn:]
        return cls(b, a, b * Qi, a * Qi, scale)

    def form(self, other: _Halves) -> DomainMatrix:
        r"""Return :math:`M_b Q^{-1} N_b^\top - M_a Q^{-1} N_a^\top`.

        That is :math:`W_M \Sigma W_N^\top` times the positive scales cleared by
        :func:`_integral` (:func:`derive_ports`).
        """
        return self.bq * other.b.transpose() - self.aq * other.a.transpose()

    def port_map(self, Qi: DomainMatrix, s_Q: Any) -> sympy.ImmutableMatrix:
        r"""Return :math:`W = (1/\sqrt 2)((M_b - M_a) Q^{-1}, M_b + M_a)`, exact."""
        half = sympy.sqrt(2) / 2
        c_left = half / Qi.domain.to_sympy(self.scale * s_Q)
        c_right = half / Qi.domain.to_sympy(self.scale)
        left = (self.bq - self.aq).to_Matrix().applyfunc(lambda x: c_left * x)
        right = (self.b + self.a).to_Matrix().applyfunc(lambda x: c_right * x)
        return sympy.ImmutableMatrix(sympy.Matrix.hstack(left, right))


def _identities(
    u: _Halves, y: _Halves, Qi: DomainMatrix, s_Q: Any, model: PortedSystem
) -> dict[str, sympy.Expr]:
    r"""Check the three identities exactly; return their residuals (all zero) by name.

    Raises
    ------
    PortError
        Naming the identity that fails (the input rows, when :math:`W_B\Sigma W_B^\top \ne 0`).
    """
    nn = u.b.shape[0]
    residuals = {
        "WB_Sigma_WBt": (u.form(u), u.scale * u.scale * s_Q),
        "WC_Sigma_WCt": (y.form(y), y.scale * y.scale * s_Q),
        "WC_Sigma_WBt_minus_I": (
            y.form(u) - _identity(nn, Qi) * (y.scale * u.scale * s_Q),
            y.scale * u.scale * s_Q,
        ),
    }
    defaults = model.parameter_defaults
    identities: dict[str, sympy.Expr] = {}
    for key in IDENTITY_NAMES:
        exact, cleared = residuals[key]
        if _exact_zero(exact):
            identities[key] = sympy.Integer(0)
            continue
        scale = Qi.domain.to_sympy(cleared)
        residual = exact.to_Matrix().applyfunc(lambda x, c=scale: canonical(x / c))
        largest = _max_abs(residual, defaults)
        if key == "WB_Sigma_WBt":  # the inputs alone are wrong: say so, naming them
            raise PortError(
                inadmissible_inputs_message(residual, model.inputs, model.interval, defaults)
            )
        at = " at the parameter defaults" if residual.free_symbols else ""
        raise PortError(
            f"port identity {display.IDENTITY_STATEMENTS[key]} fails: largest residual "
            f"|entry| = {_short(largest)}{at}; the outputs must be the "
            "power conjugates of the inputs"
        )
    return identities


def inadmissible_inputs_message(
    residual: sympy.MatrixBase,
    inputs: Sequence[sympy.Expr],
    interval: Sequence[object],
    defaults: Mapping[sympy.Symbol, sympy.Expr],
) -> str:
    r"""Explain why :math:`W_B \Sigma W_B^\top \ne 0`, naming the input rows.

    Entry :math:`(i, j)` is twice the power that inputs ``i`` and ``j`` exchange: an
    input pair such as a velocity and a force at the same end cannot both be imposed, and
    a diagonal entry means input ``i`` carries power by itself (an impedance condition
    such as ``e2(1) + c*e1(1)``: a feedback, which ``[feedback]`` expresses).
    """
    pairs = [
        (i, j)
        for i in range(residual.rows)
        for j in range(i, residual.cols)
        if not vanishes(residual[i, j])
    ]

    def name(i: int) -> str:
        return f"inputs[{i + 1}] = {format_expression(inputs[i], interval)}"

    parts = []
    for i, j in pairs[:3]:
        value = canonical(residual[i, j])
        at = value.xreplace(dict(defaults))
        shown = value if len(str(value)) < 30 else sympy.Float(at, 6)
        if i == j:
            parts.append(f"{name(i)} carries power by itself (entry ({i + 1}, {i + 1}) = {shown})")
        else:
            parts.append(
                f"{name(i)} and {name(j)} exchange power (entry ({i + 1}, {j + 1}) = {shown})"
            )
    hint = (
        "; an impedance or damper condition is a feedback: write the plain input in "
        "[ports] and close it with [feedback]"
        if any(i == j for i, j in pairs)
        else "; impose only one of each power-conjugate pair"
    )
    more = f" (and {len(pairs) - 3} more)" if len(pairs) > 3 else ""
    return "the inputs are not admissible: W_B Σ W_Bᵀ = 0 fails: " + "; ".join(parts) + more + hint


def _max_abs(matrix: sympy.MatrixBase, defaults: dict[sympy.Symbol, sympy.Expr]) -> sympy.Expr:
    values = [sympy.Abs(x.xreplace(defaults)) for x in matrix]
    return max(values, key=lambda x: float(x)) if values else sympy.Integer(0)


def _short(value: sympy.Expr) -> str:
    return str(value) if len(str(value)) < 30 else f"{float(value):.6g}"
