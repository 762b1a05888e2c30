r"""The exact data a decay-rate proof reads from a closed first-order system.

A closed system of order :math:`N = 1` with constant coefficients is

.. math::

    \partial_t x = P_1 \mathcal H\, \partial_z x + P_0 \mathcal H x
    \quad\text{on } [a, b], \qquad
    \mathcal B v = 0, \quad v = (e(b); e(a)), \quad e = \mathcal H x ,

where :math:`\mathcal B = U + G Y` (``n x 2n``) is the closed boundary condition (the
observer's injection and the plant's dampers) and the columns of :math:`K_b`
(``2n x n``) span its kernel, the admissible traces.  :class:`RateProblem` holds these
matrices as exact rationals (sympy); the prover (:mod:`.rate`) and the proof file read
nothing else of the model.

Only what the proof can honour is accepted: the order must be 1 (for the beam,
:math:`N = 2`, the message says what is proved instead), :math:`\mathcal H` and
:math:`P_0` must not depend on :math:`z` (the pointwise inequality is then checked at
finitely many exact corners; for a :math:`z`-dependent one phdesign has no rigorous
bound and refuses rather than sample :math:`z`), and every entry must be rational.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy

from phdesign.core.errors import ArgumentError, RateProofError
from phdesign.numeric.certified.exact_system import ExactClosedSystem

__all__ = [
    "BEAM_REFUSAL",
    "RateProblem",
    "exact_rational_matrix",
    "rate_problem",
    "read_system",
]

#: What is proved for a model of order N >= 2 instead of a decay rate.
BEAM_REFUSAL = (
    "a decay rate is proved only for first-order models (N = 1: strings, Timoshenko, "
    "coupled strings, transport); this model has order N = {order}. For it phdesign proves "
    "the spectral bound (the certified spectral abscissa, `certify` without `rate`); the "
    "decay rate equals that bound only if the eigenvectors of the closed system form a "
    "Riesz basis, which phdesign does not check"
)


@dataclass(frozen=True)
class RateProblem:
    r"""An :math:`N = 1` closed system with constant rational coefficients.

    Attributes
    ----------
    name : str
        The model's name (for messages and the proof file).
    interval : tuple of sympy.Rational
        :math:`(a, b)`.
    H, P1, P0 : sympy.ImmutableMatrix
        ``n x n`` rational matrices: :math:`\mathcal H` (symmetric positive definite),
        :math:`P_1` (symmetric, invertible), :math:`P_0`.
    boundary : sympy.ImmutableMatrix
        :math:`\mathcal B`, ``n x 2n``, over :math:`v = (e(b); e(a))`.
    kernel : sympy.ImmutableMatrix
        :math:`K_b`, ``2n x n``: :math:`\mathcal B K_b = 0`, full column rank.
    """

    name: str
    interval: tuple[sympy.Rational, sympy.Rational]
    H: sympy.ImmutableMatrix
    P1: sympy.ImmutableMatrix
    P0: sympy.ImmutableMatrix
    boundary: sympy.ImmutableMatrix
    kernel: sympy.ImmutableMatrix

    @property
    def size(self) -> int:
        """The number :math:`n` of state components."""
        return int(self.H.rows)

    @property
    def length(self) -> sympy.Rational:
        """:math:`b - a`."""
        return sympy.Rational(self.interval[1] - self.interval[0])


def exact_rational_matrix(name: str, matrix: Any, model: str) -> sympy.ImmutableMatrix:
    """Return ``matrix`` with every entry a sympy Rational, or refuse naming the entry.

    Raises
    ------
    RateProofError
        An entry depends on ``z`` or on a free parameter, or is irrational (``sqrt(2)``):
        the exact check works in the rationals.
    """
    M = sympy.Matrix(matrix)
    for (i, j), entry in sorted(M.todok().items()):
        # a decimal written in a model file means that decimal, not its binary neighbour
        value = sympy.Rational(str(entry)) if isinstance(entry, sympy.Float) else entry
        if getattr(value, "is_Rational", False):
            M[i, j] = value
            continue
        names = {s.name for s in getattr(entry, "free_symbols", set())}
        why = (
            "depends on z: for a z-dependent coefficient phdesign has no rigorous bound on "
            "the pointwise inequality over [a, b] and refuses rather than sample z"
            if "z" in names
            else "is not a rational number (the exact check works in the rationals)"
        )
        raise RateProofError(
            f"{model}: cannot prove a decay rate: {name}[{i + 1},{j + 1}] = {entry} {why}"
        )
    return sympy.ImmutableMatrix(M)


def rate_problem(
    *,
    name: str,
    order: int,
    interval: tuple[Any, Any],
    H: Any,
    P: tuple[Any, ...],
    boundary: Any,
    kernel: Any,
) -> RateProblem:
    r"""Read the exact data of a closed system, refusing what the proof cannot honour.

    ``P`` is :math:`(P_0, P_1)`; ``boundary`` and ``kernel`` are :math:`\\mathcal B` and
    :math:`K_b` over :math:`v = (e(b); e(a))`.

    Raises
    ------
    RateProofError
        The order is not 1 (the message says what is proved instead), or an entry is
        z-dependent or irrational.
    """
    if order != 1:
        raise RateProofError(f"{name}: {BEAM_REFUSAL.format(order=order)}")
    exact = {
        label: exact_rational_matrix(label, value, name)
        for label, value in (("H", H), ("P0", P[0]), ("P1", P[1]))
    }
    ends = exact_rational_matrix("interval", [list(interval)], name)
    return RateProblem(
        name=name,
        interval=(ends[0, 0], ends[0, 1]),
        H=exact["H"],
        P1=exact["P1"],
        P0=exact["P0"],
        boundary=exact_rational_matrix("boundary matrix U + G Y", boundary, name),
        kernel=exact_rational_matrix("kernel basis", kernel, name),
    )


def read_system(system: ExactClosedSystem) -> RateProblem:
    r"""Read an exact closed system (:func:`~.exact_system.closed_system`) for the proof.

    The kernel basis :math:`K_b` is the exact rational nullspace of the boundary rows
    :math:`U + GY`; it has dimension :math:`n` for every admissible closed system.

    Raises
    ------
    ArgumentError
        ``system`` is not an :class:`~.exact_system.ExactClosedSystem`.
    RateProofError
        As :func:`rate_problem`.
    """
    if not isinstance(system, ExactClosedSystem):
        raise ArgumentError(
            "system must be an ExactClosedSystem (phdesign.numeric.certified.exact_system."
            f"closed_system(model, C_m, L)); found {type(system).__name__}"
        )
    if system.order != 1:
        raise RateProofError(f"{system.name}: {BEAM_REFUSAL.format(order=system.order)}")
    boundary = exact_rational_matrix("boundary matrix U + G Y", system.boundary, system.name)
    null = boundary.nullspace()
    if len(null) != system.size:  # pragma: no cover - closed_system checked dim K = Nn
        raise RateProofError(
            f"{system.name}: the closed boundary rows must leave an n = {system.size} "
            f"dimensional kernel; found {len(null)}"
        )
    return rate_problem(
        name=system.name,
        order=system.order,
        interval=system.interval,
        H=system.H,
        P=system.P,
        boundary=boundary,
        kernel=sympy.Matrix.hstack(*null),
    )
