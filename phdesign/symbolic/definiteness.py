r"""One checker for "a matrix function of z is definite on [a, b]".

:func:`check_definite` decides, for a symmetric matrix :math:`M(z)` whose entries are
expressions in :math:`z` and the parameters (substituted by their defaults), one of

.. math::

    M(z) \succ 0, \quad M(z) \succeq 0, \quad M(z) \prec 0, \quad M(z) \preceq 0
    \qquad \text{for every } z \in [a, b],

and returns one line saying how it was verified (it goes into ``BCPHS.checks``), or
raises :class:`~phdesign.errors.ModelError` naming the matrix and giving what was found.
The model uses it for :math:`\mathcal H(z) \succ 0` and :math:`P_0 + P_0^\top \preceq 0`.

Examples
--------
>>> import sympy
>>> from phdesign.symbolic.expressions import Z
>>> check_definite(sympy.Matrix([[1 + Z**2]]), (0, 1), name="H")
'H > 0: exact on [a, b] at the parameter defaults (leading principal minors)'
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import sympy

from phdesign.errors import ModelError
from phdesign.symbolic.expressions import Z

__all__ = ["POSITIVITY_GRID_POINTS", "check_definite"]

#: Points of the grid on which a matrix is checked when exact definiteness is out of reach.
POSITIVITY_GRID_POINTS = 2001


def check_definite(
    matrix: sympy.MatrixBase,
    interval: Sequence[Any],
    *,
    name: str,
    sign: int = 1,
    strict: bool = True,
    defaults: Mapping[sympy.Symbol, sympy.Expr] | None = None,
) -> str:
    r"""Check that ``sign * matrix`` is positive (semi)definite on ``interval``.

    Parameters
    ----------
    matrix : sympy matrix
        Symmetric, entries in :math:`z` and the parameters.
    interval : (a, b)
        Exact endpoints.
    name : str
        The matrix as the user knows it (``"H"``, ``"P0 + P0^T"``).
    sign : {1, -1}
        ``1`` for :math:`\succ 0` / :math:`\succeq 0`, ``-1`` for :math:`\prec 0` /
        :math:`\preceq 0`.
    strict : bool
        Definite (``True``) or semidefinite (``False``).
    defaults : mapping, optional
        Parameter values substituted before the check.

    Returns
    -------
    str
        ``"<name> <relation> 0: <how>"``.

    Raises
    ------
    ModelError
        If the condition fails, with the eigenvalues, minor or point that shows it.
    """
    relation = {(1, True): ">", (1, False): ">=", (-1, True): "<", (-1, False): "<="}[
        (sign, strict)
    ]
    if strict and sign == 1:
        return f"{name} {relation} 0: " + _positive_definite(
            sympy.ImmutableMatrix(matrix), name, interval, defaults or {}
        )
    if not strict and sign == -1:
        return f"{name} {relation} 0: " + _negative_semidefinite(
            sympy.ImmutableMatrix(matrix), name, defaults or {}
        )
    raise NotImplementedError(f"{name}: only > 0 and <= 0 are implemented")


def _at_defaults(matrix: sympy.MatrixBase, defaults: Mapping[sympy.Symbol, sympy.Expr]) -> Any:
    return matrix.xreplace(dict(defaults))


def _negative_semidefinite(
    S: sympy.MatrixBase, name: str, defaults: Mapping[sympy.Symbol, sympy.Expr]
) -> str:
    how = "exact"
    if S.free_symbols:
        S, how = _at_defaults(S, defaults), "exact at the parameter defaults"
    if S.is_negative_semidefinite is False:
        raise ModelError(
            f"{name} must be negative semidefinite ({how}); found eigenvalues "
            f"{sorted(sympy.ImmutableMatrix(S).eigenvals())}"
        )
    return how


def _positive_definite(
    H: sympy.MatrixBase,
    name: str,
    interval: Sequence[Any],
    defaults: Mapping[sympy.Symbol, sympy.Expr],
) -> str:
    if not H.free_symbols:
        if H.is_positive_definite:
            return "exact"
        raise ModelError(
            f"{name} must be positive definite; found eigenvalues "
            f"{sorted(sympy.ImmutableMatrix(H).eigenvals())}"
        )
    H_defaults = _at_defaults(H, defaults)
    if not H_defaults.free_symbols:
        if H_defaults.is_positive_definite:
            return "exact at the parameter defaults"
        raise ModelError(
            f"{name} must be positive definite; at the parameter defaults found eigenvalues "
            f"{sorted(sympy.ImmutableMatrix(H_defaults).eigenvals())}"
        )
    a, b = interval
    exact = _positive_definite_exactly(H_defaults, name, (a, b))
    return exact if exact is not None else _positive_definite_on_grid(H_defaults, name, (a, b))


def _positive_definite_exactly(
    H: sympy.MatrixBase, name: str, interval: tuple[sympy.Expr, sympy.Expr]
) -> str | None:
    """Prove min over [a, b] of every leading principal minor > 0, for rational H(z).

    Returns ``None`` when sympy cannot decide (then the grid check runs).
    """
    from sympy.calculus.util import minimum

    minors = [sympy.cancel(H[:k, :k].det()) for k in range(1, H.shape[0] + 1)]
    if not all(m.is_rational_function(Z) for m in minors):
        return None
    domain = sympy.Interval(*interval)
    for k, minor in enumerate(minors, start=1):
        _, denominator = sympy.fraction(minor)
        if sympy.solveset(denominator, Z, domain) != sympy.EmptySet:
            raise ModelError(
                f"{name} must be bounded on [{interval[0]}, {interval[1]}]; its minor {k} = "
                f"{minor} has a pole there (parameter defaults)"
            )
        try:
            smallest = minimum(minor, Z, domain)
        except (NotImplementedError, ValueError):
            return None
        if not smallest.is_number:
            return None
        if not smallest > 0:
            raise ModelError(
                f"{name} must be positive definite on [{interval[0]}, {interval[1]}]; found "
                f"leading principal minor {k} = {minor} with minimum {smallest} "
                "(parameter defaults)"
            )
    return "exact on [a, b] at the parameter defaults (leading principal minors)"


def _positive_definite_on_grid(
    H: sympy.MatrixBase, name: str, interval: tuple[sympy.Expr, sympy.Expr]
) -> str:
    import numpy as np  # only for the grid check of a z-dependent matrix

    a, b = (float(p) for p in interval)
    grid = np.linspace(a, b, POSITIVITY_GRID_POINTS)
    evaluate = sympy.lambdify(Z, H, modules="numpy")
    with np.errstate(all="ignore"):
        values = np.array([np.asarray(evaluate(z), dtype=float) for z in grid])
    if not np.all(np.isfinite(values)):
        bad = grid[~np.all(np.isfinite(values), axis=(1, 2))][0]
        raise ModelError(
            f"{name} must be bounded on [{a}, {b}]; found a non-finite entry at z = {bad:g}"
        )
    smallest = np.linalg.eigvalsh(values).min(axis=1)
    worst = int(np.argmin(smallest))
    if smallest[worst] <= 0:
        raise ModelError(
            f"{name} must be positive definite on [{a}, {b}]; found smallest eigenvalue "
            f"{smallest[worst]:.6g} at z = {grid[worst]:g} (parameter defaults)"
        )
    return (
        f"on a grid of {POSITIVITY_GRID_POINTS} points at the parameter defaults "
        f"(smallest eigenvalue {smallest[worst]:.6g} at z = {grid[worst]:g})"
    )
