"""Exact rational matrices for the checker (fractions only)."""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

Matrix = list[list[Fraction]]

__all__ = [
    "Matrix",
    "determinant",
    "identity",
    "inverse",
    "matmul",
    "number",
    "read_matrix",
    "semidefinite",
]


def number(text: object) -> Fraction:
    """Read ``"p/q"`` (or an integer) exactly; anything else is refused."""
    if isinstance(text, bool) or not isinstance(text, str | int):
        raise ValueError(f"expected an exact number 'p/q'; found {text!r}")
    return Fraction(text)


def read_matrix(rows: Sequence[Sequence[object]]) -> Matrix:
    """Read a matrix of ``"p/q"`` strings."""
    return [[number(x) for x in row] for row in rows]


def identity(size: int) -> Matrix:
    """Return the identity."""
    return [[Fraction(int(i == j)) for j in range(size)] for i in range(size)]


def matmul(X: Matrix, Y: Matrix) -> Matrix:
    """Return the product."""
    columns = list(zip(*Y, strict=True)) if Y else []
    return [
        [sum((a * b for a, b in zip(row, col, strict=True)), Fraction(0)) for col in columns]
        for row in X
    ]


def determinant(X: Matrix) -> Fraction:
    """Return the determinant, by Bareiss-free elimination with row swaps."""
    A = [row[:] for row in X]
    det = Fraction(1)
    for c in range(len(A)):
        r = next((r for r in range(c, len(A)) if A[r][c]), None)
        if r is None:
            return Fraction(0)
        if r != c:
            A[c], A[r] = A[r], A[c]
            det = -det
        det *= A[c][c]
        for s in range(c + 1, len(A)):
            f = A[s][c] / A[c][c]
            A[s] = [x - f * y for x, y in zip(A[s], A[c], strict=True)]
    return det


def inverse(X: Matrix) -> Matrix | None:
    """Return the inverse by Gauss-Jordan elimination, or None if singular."""
    size = len(X)
    A = [row[:] + e for row, e in zip(X, identity(size), strict=True)]
    for c in range(size):
        r = next((r for r in range(c, size) if A[r][c]), None)
        if r is None:
            return None
        A[c], A[r] = A[r], A[c]
        pivot = A[c][c]
        A[c] = [x / pivot for x in A[c]]
        for s in range(size):
            if s != c and A[s][c]:
                f = A[s][c]
                A[s] = [x - f * y for x, y in zip(A[s], A[c], strict=True)]
    return [row[size:] for row in A]


def semidefinite(X: Matrix) -> bool:
    """Whether the symmetric rational X is positive semidefinite (exact LDLᵀ).

    Symmetric elimination: a zero pivot is allowed only with a zero row (else an
    indefinite 2x2 minor exists); a negative pivot refutes.
    """
    A = [row[:] for row in X]
    size = len(A)
    for c in range(size):
        if A[c][c] < 0:
            return False
        if A[c][c] == 0:
            if any(A[c][j] for j in range(c, size)):
                return False
            continue
        for s in range(c + 1, size):
            f = A[s][c] / A[c][c]
            if f:
                A[s] = [x - f * y for x, y in zip(A[s], A[c], strict=True)]
    return True
