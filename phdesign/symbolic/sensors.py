r"""Sensors and gains: the one validation of :math:`C_m` and :math:`L`.

The observer measures :math:`y_m = C_m y` and injects :math:`C_m^\top L (y_m - \hat y_m)`
with :math:`L + L^\top \succ 0` (:mod:`phdesign.symbolic.observer`).  Sensors and gains
are given as plain Python: :func:`sensor_matrix` picks outputs by index,
:func:`measurement_matrix` takes :math:`C_m` in full and :func:`gain_matrix` takes
:math:`L` as a number, a diagonal, a matrix or ``"symbolic"``.  These functions are the one
place where sensors and gains are validated (shape, finiteness, full row rank of
:math:`C_m`, :math:`L + L^\top \succ 0`), for the library, the sweeps and every command of
the command line alike; their messages name the argument (``sensors``, ``C_m``, ``gain``).

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
"""

from __future__ import annotations

import operator
import re
from collections.abc import Iterable, Mapping
from functools import lru_cache
from typing import Any

import sympy

from phdesign.core.checks import not_bytes
from phdesign.core.errors import ExpressionError, ObserverError, check_shape
from phdesign.core.limits import MAX_PORTS
from phdesign.symbolic.expressions import exact_matrix, exact_number

__all__ = [
    "caller_matrix",
    "diagonal_values",
    "gain_matrix",
    "gain_symbols",
    "measurement_matrix",
    "no_sensors",
    "observer_sensors",
    "parse_sensor_indices",
    "sensor_matrix",
    "sensors_and_gain",
]


# --------------------------------------------------------------------------- sensors
def sensor_matrix(
    sensors: Iterable[int] | int, n_outputs: int, note: str = ""
) -> sympy.ImmutableMatrix:
    """Return :math:`C_m` whose rows are the unit rows picking outputs ``sensors`` (1-based).

    Parameters
    ----------
    sensors : int or iterable of int
        The measured outputs, 1-based (``[3, 4]`` measures :math:`y_3` and :math:`y_4`).
    n_outputs : int
        The number :math:`Nn` of outputs of the model.
    note : str
        Added to an out-of-range message (how a ``[feedback]`` renumbered the outputs).

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
                + (f" ({note})" if note else "")
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
    """Return the positive symbols ``l1``, ``l2``, ..., ``lq`` of symbolic gains."""
    return tuple(sympy.Symbol(f"l{i + 1}", positive=True) for i in range(q))


def gain_matrix(
    gain: Any, q: int, per: str = "sensor", *, name: str = "gain", symbol: str = "L"
) -> sympy.ImmutableMatrix:
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
    name, symbol : str
        The argument and the matrix the messages name: ``"gain"`` and ``"L"``; the
        observer-based loop reads its feedback gain ``K`` with the same rules.

    Raises
    ------
    ObserverError
        Wrong kind, shape or count, a non-finite entry, or :math:`L + L^\top` not positive
        definite (symbolic gains must be diagonal and positive).
    """
    _check_count(q, "q (the number of sensors)")
    not_bytes(gain, name, ObserverError)
    if isinstance(gain, str):
        text = gain.strip()
        if text == "symbolic":
            return _check_gain(sympy.diag(*gain_symbols(q)), q, symbol)
        if "," in text or text.startswith("["):
            raise ObserverError(
                f"{name}: expected a number, a list of numbers, a matrix or 'symbolic'; found "
                f"the text {gain!r} (write {name.split()[0]}=[0.1, 1] for a diagonal)"
            )
        gain = [text]
    if _is_scalar(gain):
        gain = [gain]
    if isinstance(gain, sympy.MatrixBase) or getattr(gain, "ndim", 1) == 2:
        rows = _rows(gain, name)
    elif isinstance(gain, Iterable) and not isinstance(gain, Mapping | set | frozenset):
        entries = list(gain.tolist() if hasattr(gain, "tolist") else gain)
        if entries and all(_is_scalar(x) for x in entries):
            return _check_gain(sympy.diag(*diagonal_values(entries, q, per, name)), q, symbol)
        rows = _rows(entries, name)
    else:
        raise ObserverError(
            f"{name}: expected a number, a list of numbers, a matrix or 'symbolic'; found "
            f"{type(gain).__name__} {gain!r}"
        )
    L = _exact(rows, symbol)
    if L.shape != (q, q):
        raise ObserverError(
            f"{name}: Incompatible dimensions of {symbol} matrix; expected {(q, q)} "
            f"(one row and column per {per}) but found {L.shape}"
        )
    return _check_gain(L, q, symbol)


def diagonal_values(
    entries: list[Any], count: int, per: str, name: str = "gain"
) -> list[sympy.Expr]:
    """Read diagonal gain entries exactly; a single entry is used ``count`` times.

    ``per`` is what one entry belongs to and ``name`` the argument, for messages.
    """
    for i, entry in enumerate(entries):
        if str(entry).strip().lower().lstrip("+-") in ("nan", "inf", "infinity"):
            raise ObserverError(
                f"{name}: entry {i + 1} must be a finite positive number; found {entry!r}"
            )
    values = [_number(x, f"{name} entry {x!r}") for x in entries]
    if len(values) == 1:
        values = values * count
    if len(values) != count:
        raise ObserverError(
            f"{name}: expected {count} diagonal values (one per {per}) or a single one; "
            f"found {len(values)}"
        )
    return values


def caller_matrix(value: object, what: str) -> sympy.ImmutableMatrix:
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


def _check_gain(L: sympy.MatrixBase, q: int, symbol: str = "L") -> sympy.ImmutableMatrix:
    L = caller_matrix(L, symbol)
    check_shape(symbol, L, (q, q), error=ObserverError)
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
                f"{symbol} + {symbol}ᵀ must be positive definite; expected every leading "
                f"principal minor > 0 but found minor {k} = {2**k * minor}"
            )
    return L


# --------------------------------------------------------------------------- entries
def _check_count(value: object, what: str) -> None:
    """Refuse a count that is not a positive integer, or more ports than any model has."""
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
    items = list(value)
    for i, r in enumerate(items):
        not_bytes(r, f"{what}: row {i + 1}", ObserverError)
    rows = [list(r) if isinstance(r, Iterable) and not isinstance(r, str) else r for r in items]
    if not rows or not all(isinstance(r, list) and r for r in rows):
        raise ObserverError(f"{what}: expected a non-empty list of non-empty rows; found {rows!r}")
    width = len(rows[0])
    for i, row in enumerate(rows):
        if len(row) != width:
            raise ObserverError(
                f"{what}: row {i + 1} has {len(row)} entries; expected {width} like row 1"
            )
    return rows


def _exact(rows: list[list[Any]], name: str) -> sympy.ImmutableMatrix:
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


def no_sensors(C_m: Any, n_outputs: int) -> bool:
    """Whether ``C_m`` says *no sensors*: ``[]``, or a matrix with no rows.

    A matrix with no rows must have ``n_outputs`` columns (or none: ``np.zeros((0, 0))``
    and ``[]`` say the same); any other width is refused, as for a matrix with rows.

    Raises
    ------
    ObserverError
        For a matrix with no rows and a width other than 0 or ``n_outputs``.

    Examples
    --------
    >>> no_sensors([], 4), no_sensors([[0, 0, 1, 0]], 4)
    (True, False)
    """
    shape = getattr(C_m, "shape", None)
    if shape is None:
        return isinstance(C_m, list | tuple) and len(C_m) == 0
    if len(shape) == 1 or shape[0] != 0:
        return len(shape) == 1 and shape[0] == 0
    if len(shape) != 2 or shape[1] not in (0, n_outputs):
        raise ObserverError(
            f"Incompatible dimensions of C_m matrix; expected (0, {n_outputs}) for no sensors "
            f"but found {tuple(shape)}"
        )
    return True


def _no_gain(L: Any) -> bool:
    """Whether ``L`` is absent or empty (the gain of no sensors)."""
    shape = getattr(L, "shape", None)
    if shape is not None:
        return 0 in tuple(shape)
    return L is None or (isinstance(L, list | tuple) and len(L) == 0)


def sensors_and_gain(
    C_m: Any, L: Any, n_outputs: int
) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
    r"""Read :math:`C_m` and :math:`L` (:func:`measurement_matrix`, :func:`gain_matrix`).

    One case more than those readers take: *no sensors* (:func:`no_sensors`: ``C_m`` is
    ``[]`` or has no rows, and ``L`` is ``None``, ``[]`` or empty).  The error system is
    then the plant closed by its own ``[feedback]`` (:math:`\tilde u_r = 0`), and the
    propositions' left-hand side holds only :math:`\tilde y_c^\top \operatorname{sym}(K)
    \tilde y_c`: the plant is classified by its own boundary dissipation (observer-based
    control classifies the controlled plant so).  Without a ``[feedback]`` that side is
    zero and no proposition holds.

    Raises
    ------
    ObserverError
        What :func:`measurement_matrix` and :func:`gain_matrix` raise, and a gain given
        with no sensors.
    """
    if no_sensors(C_m, n_outputs):
        if not _no_gain(L):
            raise ObserverError(
                f"gain: no sensors (C_m has no rows) take no gain; expected none or an empty "
                f"matrix but found {L!r}"
            )
        return sympy.ImmutableMatrix.zeros(0, n_outputs), sympy.ImmutableMatrix.zeros(0, 0)
    exact = measurement_matrix(C_m, n_outputs)
    return exact, gain_matrix(L, exact.rows)


def observer_sensors(
    sensors: Any, C_m: Any, gain: Any, n_outputs: int, note: str = ""
) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix | None]:
    """Read an observer's ``sensors`` or ``C_m``, and its ``gain`` (``None``: no gain yet).

    Exactly one of ``sensors`` (:func:`sensor_matrix`, with ``note``) and ``C_m``
    (:func:`measurement_matrix`, or *no sensors*: :func:`sensors_and_gain`) is given.

    Raises
    ------
    ObserverError
        Neither or both given, or what the readers raise.
    """
    if (sensors is None) == (C_m is None):
        raise ObserverError(
            "an observer needs either sensors=[...] (outputs by index, e.g. [3, 4]) or "
            "C_m=[[...]] (the sensor matrix); found " + ("neither" if sensors is None else "both")
        )
    if sensors is None and no_sensors(C_m, n_outputs):  # classified by its own dampers
        return sensors_and_gain(C_m, gain, n_outputs)
    exact = (
        sensor_matrix(sensors, n_outputs, note)
        if sensors is not None
        else measurement_matrix(C_m, n_outputs)
    )
    return exact, None if gain is None else gain_matrix(gain, exact.rows)
