r"""The boundary observer and its error system.

The observer copies the plant and corrects its input with the measured outputs,

.. math::

    \hat u = u + C_m^\top L\, (y_m - \hat y_m), \qquad y_m = C_m y,
    \qquad L + L^\top \succ 0 ,

so the error :math:`\tilde x = x - \hat x` is the same BC-PHS with the boundary condition

.. math::

    \tilde u = -C_m^\top L C_m \tilde y
    \quad\Longleftrightarrow\quad
    (U + C_m^\top L C_m Y)\, v = 0 ,

where :math:`u = U v`, :math:`y = Y v` over the trace vector :math:`v` (ports layer).
The admissible traces form :math:`\mathcal K = \ker(U + C_m^\top L C_m Y)`.
Because :math:`T = \begin{pmatrix} U \\ Y \end{pmatrix}` is invertible (the port
identities make :math:`(W_B; W_C)` invertible), :math:`\mathcal K` has the explicit basis

.. math::

    K = T^{-1} \begin{pmatrix} -C_m^\top L C_m \\ I \end{pmatrix}
    \qquad (v = K \tilde y),

parametrized by the error output :math:`\tilde y` itself, for every gain: no rank
decision on :math:`L` is involved, so a symbolic gain cannot hide a generic-rank
answer here.  :math:`\dim \mathcal K = Nn` is still checked.

A plant with its own boundary feedback :math:`u_c = -K y_c` (``[feedback]``,
:mod:`phdesign.symbolic.feedback`) is observed through its external outputs: ``C_m``
picks among them, and the error boundary condition over all :math:`Nn` open ports is
:math:`\tilde u = -G\tilde y` with :math:`G = E_c^\top K E_c + E_r^\top C_m^\top L C_m
E_r`, whose symmetric part (the plant's dampers and the observer's injection) is the
left-hand side of every proposition.

Examples
--------
>>> sensor_matrix([3, 4], n_outputs=4)
Matrix([
[0, 0, 1, 0],
[0, 0, 0, 1]])
>>> parse_gain("0.1, 1", q=2)
Matrix([
[1/10, 0],
[   0, 1]])
>>> parse_gain("symbolic", q=2)
Matrix([
[l1,  0],
[ 0, l2]])
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import sympy
from sympy.polys.matrices import DomainMatrix
from sympy.polys.matrices.exceptions import DMNonInvertibleMatrixError

from phdesign.errors import ExpressionError, ObserverError, check_shape
from phdesign.symbolic.expressions import exact_number, vanishes
from phdesign.symbolic.feedback import error_dissipation, plant_feedback
from phdesign.symbolic.model import BCPHS

__all__ = [
    "ErrorSystem",
    "ObserverDesign",
    "diagonal_values",
    "error_system",
    "gain_symbols",
    "parse_cm",
    "parse_gain",
    "parse_sensors",
    "port_matrices",
    "sensor_matrix",
    "vanishes",
]


# --------------------------------------------------------------------------- sensors
def sensor_matrix(indices: Sequence[int], n_outputs: int) -> sympy.ImmutableMatrix:
    """Return :math:`C_m` whose rows are the unit rows picking outputs ``indices`` (1-based).

    Raises
    ------
    ObserverError
        If an index is out of ``1..n_outputs``, repeated, or the list is empty.
    """
    picked = list(indices)
    if not picked:
        raise ObserverError("sensors: expected at least one output index; found none")
    seen: set[int] = set()
    for index in picked:
        if isinstance(index, bool) or not isinstance(index, int):
            raise ObserverError(f"sensors: expected integer output indices; found {index!r}")
        if not 1 <= index <= n_outputs:
            raise ObserverError(
                f"sensors: output index {index} is out of range; expected 1..{n_outputs}"
            )
        if index in seen:
            raise ObserverError(
                f"sensors: output index {index} is repeated; expected distinct indices"
            )
        seen.add(index)
    return sympy.ImmutableMatrix(
        len(picked), n_outputs, lambda r, c: 1 if c == picked[r] - 1 else 0
    )


def parse_sensors(text: str, n_outputs: int) -> sympy.ImmutableMatrix:
    """Parse ``"3,4"`` into :math:`C_m` (see :func:`sensor_matrix`)."""
    parts = [p.strip() for p in str(text).split(",")]
    indices = []
    for part in parts:
        try:
            indices.append(int(part))
        except ValueError:
            raise ObserverError(
                f"--sensors: expected comma-separated output indices like 3,4; "
                f"found {part!r} in {text!r}"
            ) from None
    return sensor_matrix(indices, n_outputs)


def _numbers_from_json(text: str, what: str) -> object:
    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise ObserverError(
            f"{what}: expected a JSON list of rows like [[0, 1], [1, 0]]; found {text!r} "
            f"({error.msg} at character {error.pos})"
        ) from None


def _exact_matrix(rows: object, what: str) -> sympy.ImmutableMatrix:
    if not isinstance(rows, list) or not rows or not all(isinstance(r, list) and r for r in rows):
        raise ObserverError(f"{what}: expected a non-empty list of non-empty rows; found {rows!r}")
    width = len(rows[0])  # type: ignore[arg-type]
    for i, row in enumerate(rows):  # type: ignore[arg-type]
        if len(row) != width:
            raise ObserverError(
                f"{what}: row {i + 1} has {len(row)} entries; expected {width} like row 1"
            )
    try:
        entries = [
            [exact_number(x, f"{what}[{i + 1}][{j + 1}]") for j, x in enumerate(row)]
            for i, row in enumerate(rows)  # type: ignore[arg-type]
        ]
    except ExpressionError as error:
        raise ObserverError(str(error)) from None
    return sympy.ImmutableMatrix(entries)


def parse_cm(text: str, n_outputs: int) -> sympy.ImmutableMatrix:
    """Parse ``"[[0,0,1,0]]"`` into :math:`C_m` (``q x n_outputs``), exactly."""
    C_m = _exact_matrix(_numbers_from_json(text, "--cm"), "--cm")
    if C_m.shape[1] != n_outputs:
        raise ObserverError(
            f"--cm: Incompatible dimensions of C_m matrix; expected (q, {n_outputs}) "
            f"but found {C_m.shape}"
        )
    return C_m


def diagonal_values(entries: Sequence[object], count: int, meaning: str) -> list[sympy.Expr]:
    """Read diagonal gain entries exactly; a single entry is used ``count`` times.

    Raises
    ------
    ObserverError
        If an entry is not a finite number, or there are neither 1 nor ``count`` entries.
    """
    for i, part in enumerate(entries):
        if str(part).lower().lstrip("+-") in ("nan", "inf", "infinity"):
            raise ObserverError(
                f"--gain: entry {i + 1} must be a finite positive number; found {part!r}"
            )
    try:
        values = [exact_number(p, f"--gain entry {p!r}") for p in entries]
    except ExpressionError as error:
        raise ObserverError(f"--gain: {error}") from None
    if len(values) == 1:
        values = values * count
    if len(values) != count:
        raise ObserverError(
            f"--gain: expected {count} diagonal values ({meaning}) or a single one; "
            f"found {len(values)}"
        )
    return values


@lru_cache(maxsize=64)
def gain_symbols(q: int) -> tuple[sympy.Symbol, ...]:
    """Return the positive symbols ``l1 .. lq`` used for symbolic gains."""
    return tuple(sympy.Symbol(f"l{i + 1}", positive=True) for i in range(q))


def parse_gain(text: str, q: int) -> sympy.ImmutableMatrix:
    r"""Parse a gain: ``"0.1,1"`` (diagonal), ``"[[..]]"`` (full) or ``"symbolic"``.

    A single diagonal value is used for every sensor.  Numbers are read exactly
    (``0.1`` is :math:`1/10`).  ``symbolic`` gives :math:`L = \mathrm{diag}(l_1..l_q)`
    with positive symbols.
    """
    text = str(text).strip()
    if text == "symbolic":
        return _check_gain(sympy.diag(*gain_symbols(q)), q)
    if text.startswith("["):
        L = _exact_matrix(_numbers_from_json(text, "--gain"), "--gain")
        if L.shape != (q, q):
            raise ObserverError(
                f"--gain: Incompatible dimensions of L matrix; expected {(q, q)} "
                f"(one row and column per sensor) but found {L.shape}"
            )
        return _check_gain(L, q)
    values = diagonal_values([p.strip() for p in text.split(",")], q, "one per sensor")
    return _check_gain(sympy.diag(*values), q)


# --------------------------------------------------------------------------- checks
def _check_cm(C_m: sympy.MatrixBase, n_outputs: int) -> sympy.ImmutableMatrix:
    C_m = sympy.ImmutableMatrix(C_m)
    # q = 0 (no sensors) is the plant's own classification: the propositions' left-hand
    # side then carries only the plant's boundary dissipation (its [feedback])
    if C_m.rows > n_outputs:
        raise ObserverError(
            f"Incompatible dimensions of C_m matrix; expected (q, {n_outputs}) with "
            f"0 <= q <= {n_outputs} but found {C_m.shape}"
        )
    try:
        check_shape("C_m", C_m, (C_m.rows, n_outputs))
    except ValueError as error:
        raise ObserverError(str(error)) from None
    C_m = _exactify_entries(C_m, "C_m")
    if C_m.free_symbols:
        raise ObserverError(
            f"C_m must be numeric; found symbols {sorted(map(str, C_m.free_symbols))}"
        )
    rank = C_m.rank()
    if rank != C_m.rows:
        raise ObserverError(
            f"C_m must have full row rank (independent measurements); expected rank "
            f"{C_m.rows} but found {rank}"
        )
    return C_m


def _exactify_entries(M: sympy.MatrixBase, what: str) -> sympy.ImmutableMatrix:
    entries = []
    for i in range(M.rows):
        row = []
        for j in range(M.cols):
            x = M[i, j]
            if isinstance(x, sympy.Basic) and x.has(sympy.nan, sympy.zoo, sympy.oo, -sympy.oo):
                raise ObserverError(f"{what}[{i + 1}][{j + 1}] must be a finite number; found {x}")
            if isinstance(x, sympy.Basic) and x.free_symbols:
                row.append(x)
                continue
            try:
                row.append(
                    exact_number(
                        x if isinstance(x, sympy.Basic) else _py(x), f"{what}[{i + 1}][{j + 1}]"
                    )
                )
            except ExpressionError as error:
                raise ObserverError(str(error)) from None
        entries.append(row)
    # rows x cols, not from the list: a matrix with no rows keeps its columns
    return sympy.ImmutableMatrix(M.rows, M.cols, [x for row in entries for x in row])


def _py(x: object) -> object:
    # numpy scalars -> python numbers, without importing numpy
    item = getattr(x, "item", None)
    return item() if callable(item) else x


def _check_gain(L: sympy.MatrixBase, q: int) -> sympy.ImmutableMatrix:
    L = sympy.ImmutableMatrix(L)
    try:
        check_shape("L", L, (q, q))
    except ValueError as error:
        raise ObserverError(f"{error} (one row and column per sensor)") from None
    L = _exactify_entries(L, "L")
    sym = (L + L.T) / 2
    if L.free_symbols:
        # Symbolic gains: only a diagonal of positive expressions is decidable for all values.
        off = [sym[i, j] for i in range(q) for j in range(q) if i != j and sym[i, j] != 0]
        if off or not all(sym[i, i].is_positive for i in range(q)):
            raise ObserverError(
                "symbolic L must be diagonal with positive entries (e.g. --gain symbolic) "
                "so that L + Lᵀ > 0 holds for every value; found "
                f"{L.tolist()}"
            )
        return L
    # Exact Sylvester test on leading principal minors (q is small).
    for k in range(1, q + 1):
        minor = sympy.expand(sym[:k, :k].det()) if k > 1 else sym[0, 0]
        if not minor.is_positive:
            raise ObserverError(
                f"L + Lᵀ must be positive definite; expected every leading principal minor "
                f"> 0 but found minor {k} = {2**k * minor}"
            )
    return L


# --------------------------------------------------------------------------- design
@lru_cache(maxsize=64)
def port_matrices(model: BCPHS) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
    r"""Return :math:`(U, Y)` of ``model`` with the parameter defaults substituted.

    The classification lives in trace coordinates: only :math:`U` and :math:`Y`
    enter it (not :math:`\mathcal H`, and :math:`P_k` only through Assumption 3.1).
    """
    from phdesign.symbolic.ports import derive_ports

    ports = derive_ports(model)
    defaults = model.parameter_defaults
    U, Y = (sympy.ImmutableMatrix(M.xreplace(defaults)) for M in (ports.U, ports.Y))
    return U, Y


@lru_cache(maxsize=64)
def _inverse(T: sympy.ImmutableMatrix) -> sympy.ImmutableMatrix:
    dm = DomainMatrix.from_Matrix(T).to_field()
    try:
        return sympy.ImmutableMatrix(dm.inv().to_Matrix())
    except DMNonInvertibleMatrixError:
        raise ObserverError(
            "the stacked port matrix (U; Y) is singular, so the admissible traces "
            f"K = ker(U + C_mᵀ L C_m Y) cannot have dimension Nn = {T.rows // 2}; "
            "the outputs must be the power conjugates of the inputs"
        ) from None


@dataclass(frozen=True)
class ErrorSystem:
    r"""The boundary data of the observer error system.

    Attributes
    ----------
    order, size : int
        :math:`N` and :math:`n`.
    U, Y : sympy.ImmutableMatrix
        :math:`u = U v`, :math:`y = Y v` (parameters substituted).
    T_inv : sympy.ImmutableMatrix
        :math:`T^{-1}`, :math:`T = (U; Y)`: the trace vector with inputs ``u`` and
        outputs ``y`` is :math:`v = T^{-1}(u; y)`.
    C_m, L : sympy.ImmutableMatrix
        Sensors and gain.
    boundary_matrix : sympy.ImmutableMatrix
        :math:`U + G Y` (:math:`G = C_m^\top L C_m` without plant feedback), whose kernel
        is :math:`\mathcal K`.
    K : sympy.ImmutableMatrix
        Basis of :math:`\mathcal K`, :math:`2Nn \times Nn`, coordinates :math:`\tilde y`.
    dissipation_C, dissipation_L : sympy.ImmutableMatrix or None
        The left-hand side of the propositions as
        :math:`\tfrac12 (C_d\tilde y)^\top (L_d + L_d^\top) (C_d\tilde y)`
        (:func:`phdesign.symbolic.feedback.error_dissipation`); ``None`` means
        :math:`C_d = C_m`, :math:`L_d = L` (no plant feedback).
    """

    order: int
    size: int
    U: sympy.ImmutableMatrix
    Y: sympy.ImmutableMatrix
    T_inv: sympy.ImmutableMatrix
    C_m: sympy.ImmutableMatrix
    L: sympy.ImmutableMatrix
    boundary_matrix: sympy.ImmutableMatrix
    K: sympy.ImmutableMatrix
    dissipation_C: sympy.ImmutableMatrix | None = None
    dissipation_L: sympy.ImmutableMatrix | None = None

    @property
    def dissipation(self) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
        r"""Return :math:`(C_d, L_d)`, the factor of the propositions' left-hand side.

        LHS :math:`= \tfrac12 (C_d\tilde y)^\top(L_d + L_d^\top)(C_d\tilde y)`, with
        :math:`C_d` of full row rank and :math:`L_d + L_d^\top \succ 0`.
        """
        if self.dissipation_C is None or self.dissipation_L is None:
            return self.C_m, self.L
        return self.dissipation_C, self.dissipation_L

    @property
    def lhs_matrix(self) -> sympy.ImmutableMatrix:
        r"""Return :math:`M = C_d^\top \mathrm{sym}(L_d) C_d` (LHS is its quadratic form in ỹ)."""
        C_d, L_d = self.dissipation
        return sympy.ImmutableMatrix(C_d.T * (L_d + L_d.T) / 2 * C_d)


def error_system(
    order: int,
    size: int,
    U: sympy.MatrixBase,
    Y: sympy.MatrixBase,
    C_m: sympy.MatrixBase,
    L: sympy.MatrixBase,
    feedback: tuple[tuple[int, ...], sympy.ImmutableMatrix] | None = None,
) -> ErrorSystem:
    r"""Build the error boundary condition and the admissible traces.

    Parameters
    ----------
    order, size : int
        :math:`N` and :math:`n`.
    U, Y : sympy matrix
        The open plant's ports over the traces (``Nn x 2Nn``).
    C_m, L : sympy matrix
        Sensors over the external outputs and their gain.
    feedback : (closed 0-based indices, K), optional
        The plant's own boundary feedback (:func:`~phdesign.symbolic.feedback.plant_feedback`).

    Raises
    ------
    ObserverError
        If ``C_m`` or ``L`` is malformed, or :math:`\dim \mathcal K \ne Nn`.
    """
    nn = order * size
    C_m = _check_cm(C_m, nn - (0 if feedback is None else len(feedback[0])))
    L = _check_gain(L, C_m.rows)
    U = sympy.ImmutableMatrix(U)
    Y = sympy.ImmutableMatrix(Y)
    T_inv = _inverse(sympy.ImmutableMatrix(sympy.Matrix.vstack(U, Y)))
    G, C_d, L_d = error_dissipation(nn, C_m, L, feedback)
    boundary = sympy.ImmutableMatrix(U + G * Y)
    K = sympy.ImmutableMatrix(T_inv * sympy.Matrix.vstack(-G, sympy.eye(nn)))
    # dim K = Nn: K has Nn columns and its lower part through Y is the identity
    # (Y K = I), so the columns are independent; K solves the boundary condition.
    residuals = [*(boundary * K), *(Y * K - sympy.eye(nn))]
    if not all(vanishes(x) for x in residuals):
        raise ObserverError(
            f"the admissible traces K = ker(U + C_mᵀ L C_m Y) must have dimension Nn = {nn}; "
            "the port matrices are inconsistent"
        )
    if feedback is None:
        return ErrorSystem(order, size, U, Y, T_inv, C_m, L, boundary, K)
    return ErrorSystem(order, size, U, Y, T_inv, C_m, L, boundary, K, C_d, L_d)


@dataclass(frozen=True)
class ObserverDesign:
    r"""A sensor set and gain for a model: the observer of the module docstring.

    Parameters
    ----------
    model : BCPHS
        The plant (with its own boundary feedback, if any).
    C_m : sympy matrix
        ``q x n_ports`` over the model's external outputs, full row rank.
    L : sympy matrix
        ``q x q`` with :math:`L + L^\top > 0` (checked), or diagonal positive symbols.
    """

    model: BCPHS
    C_m: sympy.ImmutableMatrix
    L: sympy.ImmutableMatrix

    def __post_init__(self) -> None:
        object.__setattr__(self, "C_m", _check_cm(self.C_m, self.model.n_ports))
        object.__setattr__(self, "L", _check_gain(self.L, self.C_m.rows))

    @property
    def error_boundary_matrix(self) -> sympy.ImmutableMatrix:
        r""":math:`U + C_m^\top L C_m Y` (``Nn x 2Nn``)."""
        return self.error_system().boundary_matrix

    def error_system(self) -> ErrorSystem:
        """Return the :class:`ErrorSystem` of this design."""
        U, Y = port_matrices(self.model)
        return error_system(
            self.model.order, self.model.size, U, Y, self.C_m, self.L, plant_feedback(self.model)
        )
