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

Sensors and gains are given as plain Python: :func:`sensor_matrix` picks outputs by
index, :func:`measurement_matrix` takes :math:`C_m` in full and :func:`gain_matrix` takes
:math:`L` as a number, a diagonal, a matrix or ``"symbolic"``.  These three functions are
the one place where sensors and gains are validated (shape, finiteness, full row rank of
:math:`C_m`, :math:`L + L^\top \succ 0`), for the library and for every command of the
command line alike; their messages name the argument (``sensors``, ``C_m``, ``gain``).

Examples
--------
>>> sensor_matrix([3, 4], n_outputs=4)
Matrix([
[0, 0, 1, 0],
[0, 0, 0, 1]])
>>> gain_matrix([0.1, 1], q=2)
Matrix([
[1/10, 0],
[   0, 1]])
>>> gain_matrix("symbolic", q=2)
Matrix([
[l1,  0],
[ 0, l2]])
"""

from __future__ import annotations

import operator
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import sympy
from sympy.polys.matrices import DomainMatrix
from sympy.polys.matrices.exceptions import DMNonInvertibleMatrixError

from phdesign.errors import ExpressionError, ObserverError, check_shape
from phdesign.symbolic.expressions import exact_matrix, exact_number, vanishes
from phdesign.symbolic.feedback import error_dissipation, plant_feedback
from phdesign.symbolic.model import BCPHS

__all__ = [
    "ErrorSystem",
    "ObserverDesign",
    "diagonal_values",
    "error_system",
    "gain_matrix",
    "gain_symbols",
    "measurement_matrix",
    "parse_sensor_indices",
    "port_inverse",
    "port_matrices",
    "sensor_matrix",
]


# --------------------------------------------------------------------------- sensors
def sensor_matrix(sensors: Iterable[int] | int, n_outputs: int) -> sympy.ImmutableMatrix:
    """Return :math:`C_m` whose rows are the unit rows picking outputs ``sensors`` (1-based).

    Parameters
    ----------
    sensors : int or iterable of int
        The measured outputs, 1-based (``[3, 4]`` measures :math:`y_3` and :math:`y_4`).
    n_outputs : int
        The number :math:`Nn` of outputs of the model.

    Raises
    ------
    ObserverError
        If an index is out of ``1..n_outputs``, repeated, not an integer, or there is none.
    """
    _check_count(n_outputs, "n_outputs")
    if isinstance(sensors, str | bytes):
        raise ObserverError(
            f"sensors: expected a list of output indices such as [3, 4]; found the text "
            f"{sensors!r}"
        )
    if isinstance(sensors, int) and not isinstance(sensors, bool):
        sensors = [sensors]
    if not isinstance(sensors, Iterable):
        raise ObserverError(
            f"sensors: expected a list of output indices such as [3, 4]; found "
            f"{type(sensors).__name__} {sensors!r}"
        )
    picked: list[int] = []
    for index in sensors:
        try:
            if isinstance(index, bool):
                raise TypeError
            value = operator.index(index)
        except TypeError:
            raise ObserverError(
                f"sensors: expected integer output indices; found {index!r}"
            ) from None
        if not 1 <= value <= n_outputs:
            raise ObserverError(
                f"sensors: output index {value} is out of range; expected 1..{n_outputs}"
            )
        if value in picked:
            raise ObserverError(
                f"sensors: output index {value} is repeated; expected distinct indices"
            )
        picked.append(value)
    if not picked:
        raise ObserverError("sensors: expected at least one output index; found none")
    return sympy.ImmutableMatrix(
        len(picked), n_outputs, lambda r, c: 1 if c == picked[r] - 1 else 0
    )


def parse_sensor_indices(text: str, name: str = "sensors") -> list[int]:
    """Read ``"3,4"`` into ``[3, 4]`` (range and repetition are checked by :func:`sensor_matrix`).

    ``name`` is the argument or option named in the message.

    Examples
    --------
    >>> parse_sensor_indices(" 3, 4")
    [3, 4]
    """
    indices = []
    for part in (p.strip() for p in str(text).split(",")):
        if not re.fullmatch(r"[+-]?\d+", part):
            raise ObserverError(
                f"{name}: expected comma-separated output indices like 3,4; "
                f"found {part!r} in {text!r}"
            )
        indices.append(int(part))
    return indices


def measurement_matrix(C_m: Any, n_outputs: int) -> sympy.ImmutableMatrix:
    """Return :math:`C_m` given in full, exact and checked (``q x n_outputs``, full row rank).

    Parameters
    ----------
    C_m : matrix
        Rows of numbers (nested lists), a numpy array or a sympy matrix; floats are read
        exactly through their shortest decimal form (``0.5`` is :math:`1/2`).
    n_outputs : int
        The number :math:`Nn` of outputs of the model.

    Raises
    ------
    ObserverError
        Wrong kind or shape, an entry that is not a finite number, or dependent rows.

    Examples
    --------
    >>> measurement_matrix([[0, 0, 1, 0.5]], 4)
    Matrix([[0, 0, 1, 1/2]])
    """
    _check_count(n_outputs, "n_outputs")
    rows = _rows(C_m, "C_m")
    if len(rows) > n_outputs:
        raise ObserverError(
            f"Incompatible dimensions of C_m matrix; expected (q, {n_outputs}) with "
            f"1 <= q <= {n_outputs} but found ({len(rows)}, {len(rows[0])})"
        )
    if len(rows[0]) != n_outputs:
        raise ObserverError(
            f"Incompatible dimensions of C_m matrix; expected (q, {n_outputs}) but found "
            f"({len(rows)}, {len(rows[0])})"
        )
    matrix = _exact(rows, "C_m")
    if matrix.free_symbols:
        raise ObserverError(
            f"C_m must be numeric; found symbols {sorted(map(str, matrix.free_symbols))}"
        )
    rank = matrix.rank()
    if rank != matrix.rows:
        raise ObserverError(
            f"C_m must have full row rank (independent measurements); expected rank "
            f"{matrix.rows} but found {rank}"
        )
    return matrix


# --------------------------------------------------------------------------- gains
@lru_cache(maxsize=64)
def gain_symbols(q: int) -> tuple[sympy.Symbol, ...]:
    """Return the positive symbols ``l1 .. lq`` used for symbolic gains."""
    return tuple(sympy.Symbol(f"l{i + 1}", positive=True) for i in range(q))


def gain_matrix(gain: Any, q: int, per: str = "sensor") -> sympy.ImmutableMatrix:
    r"""Return the observer gain :math:`L` (``q x q``), exact and checked.

    Parameters
    ----------
    gain : number, sequence of numbers, matrix or "symbolic"
        A number :math:`g` (:math:`L = gI`), one number per sensor (the diagonal), the
        matrix in full (nested lists, numpy array, sympy matrix), or ``"symbolic"``:
        :math:`L = \mathrm{diag}(l_1, \dots, l_q)` with positive symbols.  Numbers may be
        ints, floats (read exactly: ``0.1`` is :math:`1/10`), sympy numbers or text such
        as ``"1/3"``.
    q : int
        The number of sensors.
    per : str
        What one diagonal entry belongs to, for messages (``"sensor"`` or ``"output"``).

    Raises
    ------
    ObserverError
        Wrong kind, shape or count, a non-finite entry, or :math:`L + L^\top` not positive
        definite (symbolic gains must be diagonal and positive).
    """
    _check_count(q, "q (the number of sensors)")
    if isinstance(gain, str):
        text = gain.strip()
        if text == "symbolic":
            return _check_gain(sympy.diag(*gain_symbols(q)), q)
        if "," in text or text.startswith("["):
            raise ObserverError(
                f"gain: expected a number, a list of numbers, a matrix or 'symbolic'; found "
                f"the text {gain!r} (write gain=[0.1, 1] for a diagonal)"
            )
        gain = [text]
    if _is_scalar(gain):
        gain = [gain]
    if isinstance(gain, sympy.MatrixBase) or getattr(gain, "ndim", 1) == 2:
        rows = _rows(gain, "gain")
    elif isinstance(gain, Iterable) and not isinstance(gain, Mapping | set | frozenset):
        entries = list(gain.tolist() if hasattr(gain, "tolist") else gain)
        if entries and all(_is_scalar(x) for x in entries):
            return _check_gain(sympy.diag(*diagonal_values(entries, q, per)), q)
        rows = _rows(entries, "gain")
    else:
        raise ObserverError(
            "gain: expected a number, a list of numbers, a matrix or 'symbolic'; found "
            f"{type(gain).__name__} {gain!r}"
        )
    L = _exact(rows, "gain")
    if L.shape != (q, q):
        raise ObserverError(
            f"gain: Incompatible dimensions of L matrix; expected {(q, q)} "
            f"(one row and column per {per}) but found {L.shape}"
        )
    return _check_gain(L, q)


def diagonal_values(entries: list[Any], count: int, per: str) -> list[sympy.Expr]:
    """Read diagonal gain entries exactly; a single entry is used ``count`` times.

    ``per`` is what one entry belongs to, for messages (``"sensor"``).
    """
    for i, entry in enumerate(entries):
        if str(entry).strip().lower().lstrip("+-") in ("nan", "inf", "infinity"):
            raise ObserverError(
                f"gain: entry {i + 1} must be a finite positive number; found {entry!r}"
            )
    values = [_number(x, f"gain entry {x!r}") for x in entries]
    if len(values) == 1:
        values = values * count
    if len(values) != count:
        raise ObserverError(
            f"gain: expected {count} diagonal values (one per {per}) or a single one; "
            f"found {len(values)}"
        )
    return values


def _safe_matrix(value: object, what: str) -> sympy.ImmutableMatrix:
    """Return a caller's matrix as sympy, its text read by the safe parser (no sympify)."""
    if (
        isinstance(value, sympy.MatrixBase)
        or getattr(getattr(value, "dtype", None), "kind", "O") in "biuf"
    ):
        return sympy.ImmutableMatrix(value)  # sympy or numeric numpy: no text to parse
    try:
        return exact_matrix(value, what, symbols=True)
    except ExpressionError as error:
        raise ObserverError(str(error)) from None


def _check_gain(L: sympy.MatrixBase, q: int) -> sympy.ImmutableMatrix:
    L = _safe_matrix(L, "L")
    check_shape("L", L, (q, q), error=ObserverError)
    sym = (L + L.T) / 2
    if L.free_symbols:
        # Symbolic gains: only a diagonal of positive expressions is decidable for all values.
        off = [sym[i, j] for i in range(q) for j in range(q) if i != j and sym[i, j] != 0]
        if off or not all(sym[i, i].is_positive for i in range(q)):
            raise ObserverError(
                "symbolic L must be diagonal with positive entries (e.g. gain='symbolic') "
                f"so that L + Lᵀ > 0 holds for every value; found {L.tolist()}"
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


# --------------------------------------------------------------------------- entries
def _check_count(value: object, what: str) -> None:
    """Refuse a count that is not a positive integer, or more ports than any model has."""
    from phdesign.limits import MAX_PORTS

    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ObserverError(f"{what} must be a positive integer; found {value!r}")
    if value > MAX_PORTS:  # before any q x q or q x n_outputs matrix is allocated
        raise ObserverError(f"{what} must be at most {MAX_PORTS} (N n ports); found {value}")


def _is_scalar(x: object) -> bool:
    if isinstance(x, sympy.MatrixBase):
        return False
    if isinstance(x, str | int | float | sympy.Expr):
        return True
    return getattr(x, "ndim", None) == 0  # numpy scalars and 0-d arrays


def _rows(value: Any, what: str) -> list[list[Any]]:
    """Return a matrix given as nested lists, a numpy array or a sympy matrix as rows."""
    if isinstance(value, str | bytes) or _is_scalar(value):
        raise ObserverError(
            f"{what}: expected a matrix (rows of numbers, a numpy array or a sympy Matrix); "
            f"found {type(value).__name__} {value!r}"
        )
    if isinstance(value, sympy.MatrixBase) or hasattr(value, "tolist"):
        value = value.tolist()
    if isinstance(value, Mapping) or not isinstance(value, Iterable):
        raise ObserverError(
            f"{what}: expected a matrix (rows of numbers); found {type(value).__name__}"
        )
    rows = [list(r) if isinstance(r, Iterable) and not isinstance(r, str) else r for r in value]
    if not rows or not all(isinstance(r, list) and r for r in rows):
        raise ObserverError(f"{what}: expected a non-empty list of non-empty rows; found {rows!r}")
    width = len(rows[0])
    for i, row in enumerate(rows):
        if len(row) != width:
            raise ObserverError(
                f"{what}: row {i + 1} has {len(row)} entries; expected {width} like row 1"
            )
    return rows


def _exact(rows: list[list[Any]], what: str) -> sympy.ImmutableMatrix:
    name = "L" if what == "gain" else what
    return sympy.ImmutableMatrix(
        [
            [_number(x, f"{name}[{i + 1}][{j + 1}]") for j, x in enumerate(row)]
            for i, row in enumerate(rows)
        ]
    )


def _number(x: object, what: str) -> sympy.Expr:
    """Return ``x`` as an exact number (symbols kept), or raise ObserverError."""
    if isinstance(x, sympy.Basic) and x.has(sympy.nan, sympy.zoo, sympy.oo, -sympy.oo):
        raise ObserverError(f"{what} must be a finite number; found {x}")
    if isinstance(x, sympy.Expr) and x.free_symbols:
        return x
    item = getattr(x, "item", None)  # numpy scalars -> python numbers, without numpy
    try:
        return exact_number(item() if callable(item) else x, what)
    except ExpressionError as error:
        raise ObserverError(str(error)) from None


def sensors_and_gain(
    C_m: Any, L: Any, n_outputs: int
) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
    r"""Read :math:`C_m` and :math:`L` (:func:`measurement_matrix`, :func:`gain_matrix`).

    One case more than those readers take: ``C_m`` of shape ``(0, n_outputs)`` with ``L``
    of shape ``(0, 0)`` means *no sensors*, which classifies the plant by its own boundary
    dissipation (its ``[feedback]``): the propositions' left-hand side then holds only
    :math:`	ilde y_c^	op \operatorname{sym}(K) 	ilde y_c` (observer-based control
    classifies the controlled plant so).  An empty list is not that case: it is refused.
    """
    if getattr(C_m, "shape", None) == (0, n_outputs) and getattr(L, "shape", None) == (0, 0):
        return sympy.ImmutableMatrix.zeros(0, n_outputs), sympy.ImmutableMatrix.zeros(0, 0)
    exact = measurement_matrix(C_m, n_outputs)
    return exact, gain_matrix(L, exact.rows)


# --------------------------------------------------------------------------- design
def port_matrices(model: BCPHS) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
    r"""Return :math:`(U, Y)` of ``model`` with the parameter defaults substituted.

    The classification lives in trace coordinates: only :math:`U` and :math:`Y`
    enter it (not :math:`\mathcal H`, and :math:`P_k` only through Assumption 3.1).
    """
    ports = model.ports
    defaults = model.parameter_defaults
    U, Y = (sympy.ImmutableMatrix(M.xreplace(defaults)) for M in (ports.U, ports.Y))
    return U, Y


def port_inverse(model: BCPHS) -> sympy.ImmutableMatrix:
    r"""Return :math:`T^{-1}` for :math:`T = (U; Y)` at the parameter defaults (exact).

    Column :math:`j` of :math:`T^{-1}` is the trace vector :math:`v` whose inputs and
    outputs are all zero but the :math:`j`-th of :math:`(u; y)`; the port identities make
    :math:`T` invertible, so the traces of the error system are :math:`v = T^{-1}(\tilde u;
    \tilde y)`.

    Raises
    ------
    ObserverError
        If :math:`T` is singular (the outputs are not the power conjugates of the inputs).

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> port_inverse(load_builtin("wave"))  # v = (e1(1), e2(1), e1(0), e2(0))
    Matrix([
    [0, 0,  0, 1],
    [0, 1,  0, 0],
    [1, 0,  0, 0],
    [0, 0, -1, 0]])
    """
    from phdesign.arguments import require_model

    require_model(model)
    return _inverse(sympy.ImmutableMatrix(sympy.Matrix.vstack(*port_matrices(model))))


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
    C_m: Any,
    L: Any,
    feedback: tuple[tuple[int, ...], sympy.ImmutableMatrix] | None = None,
) -> ErrorSystem:
    r"""Build the error boundary condition and the admissible traces.

    Parameters
    ----------
    order, size : int
        :math:`N` and :math:`n`.
    U, Y : sympy matrix
        The open plant's ports over the traces (``Nn x 2Nn``).
    C_m, L
        Sensors over the external outputs and their gain, read by
        :func:`measurement_matrix` and :func:`gain_matrix`.
    feedback : (closed 0-based indices, K), optional
        The plant's own boundary feedback (:func:`~phdesign.symbolic.feedback.plant_feedback`).

    Raises
    ------
    ObserverError
        If ``C_m`` or ``L`` is malformed, or :math:`\dim \mathcal K \ne Nn`.
    """
    nn = order * size
    C_m, L = sensors_and_gain(C_m, L, nn - (0 if feedback is None else len(feedback[0])))
    U = _safe_matrix(U, "U")
    Y = _safe_matrix(Y, "Y")
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

    The symbolic core of :class:`phdesign.Observer`: exact, validated :math:`C_m` and
    :math:`L` and the error system they define.

    Parameters
    ----------
    model : BCPHS
        The plant (with its own boundary feedback, if any).
    C_m : matrix
        ``q x n_ports`` over the model's external outputs, full row rank (read by
        :func:`measurement_matrix`).
    L : number, sequence, matrix or "symbolic"
        Read by :func:`gain_matrix`: :math:`L + L^\top > 0`, or diagonal positive symbols.
    """

    model: BCPHS
    C_m: sympy.ImmutableMatrix
    L: sympy.ImmutableMatrix

    def __post_init__(self) -> None:
        from phdesign.arguments import require_model

        require_model(self.model)
        C_m, L = sensors_and_gain(self.C_m, self.L, self.model.n_ports)
        object.__setattr__(self, "C_m", C_m)
        object.__setattr__(self, "L", L)

    def error_system(self) -> ErrorSystem:
        """Return the :class:`ErrorSystem` of this design."""
        U, Y = port_matrices(self.model)
        return error_system(
            self.model.order, self.model.size, U, Y, self.C_m, self.L, plant_feedback(self.model)
        )
