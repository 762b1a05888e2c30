r"""The exact data a decay-rate proof reads from a closed first-order system.

A closed system of order :math:`N = 1` is

.. math::

    \partial_t x = P_1 \partial_z (\mathcal H x) + P_0 \mathcal H x
    \quad\text{on } [a, b], \qquad
    \mathcal B v = 0, \quad v = (e(b); e(a)), \quad e = \mathcal H x ,

where :math:`\mathcal B = U + G Y` (``n x 2n``) is the closed boundary condition (the
observer's injection and the plant's dampers) and the columns of :math:`K_b`
(``2n x n``) span its kernel, the admissible traces.  :class:`RateProblem` holds these
matrices exactly (sympy); the prover (:mod:`.rate`) and the proof file read nothing else
of the model.

Only what the proof can honour is accepted: the order must be 1 (for the beam,
:math:`N = 2`, the message says what is proved instead); :math:`\mathcal H(z)` and
:math:`P_0(z)` may depend on :math:`z`, but only as **rational functions of z with
rational coefficients** (``1/(1 + z/2)``, ``1 + z**2``): the proof then decides every
pointwise inequality on all of :math:`[a, b]` exactly, by Sturm sequences of
polynomials (:mod:`.rate_poly`), and ``sqrt(z)``, ``exp(z)`` or an irrational
coefficient would leave the rationals; :math:`P_1`, the interval, the boundary rows and
the kernel must be rational numbers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy

from phdesign.core.errors import ArgumentError, RateProofError
from phdesign.numeric.certified.exact_system import ExactClosedSystem
from phdesign.symbolic.expressions import Z

__all__ = [
    "BEAM_REFUSAL",
    "RateProblem",
    "exact_rational_function_matrix",
    "exact_rational_matrix",
    "rate_problem",
    "read_system",
    "require_first_order",
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
    r"""An :math:`N = 1` closed system with rational (or rational-function) coefficients.

    Attributes
    ----------
    name : str
        The model's name (for messages and the proof file).
    interval : tuple of sympy.Rational
        :math:`(a, b)`.
    H, P1, P0 : sympy.ImmutableMatrix
        ``n x n``: :math:`\mathcal H` (symmetric positive definite) and :math:`P_0`,
        rational or rational functions of :data:`z`; :math:`P_1` (symmetric,
        invertible), rational.
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

    z: sympy.Symbol = Z

    @property
    def constant(self) -> bool:
        r"""Whether :math:`\mathcal H` and :math:`P_0` are constant (the exponential proof)."""
        return not (self.H.has(self.z) or self.P0.has(self.z))

    @property
    def size(self) -> int:
        """The number :math:`n` of state components."""
        return int(self.H.rows)

    @property
    def length(self) -> sympy.Rational:
        """:math:`b - a`."""
        return sympy.Rational(self.interval[1] - self.interval[0])


def require_first_order(name: str, order: int) -> None:
    """Refuse a decay-rate proof for an order other than 1, saying what is proved instead.

    Raises
    ------
    RateProofError
        ``order`` is not 1.
    """
    if order != 1:
        raise RateProofError(f"{name}: {BEAM_REFUSAL.format(order=order)}")


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
            "depends on z: only H and P0 may depend on z in a decay-rate proof"
            if "z" in names
            else "is not a rational number (the exact check works in the rationals)"
        )
        raise RateProofError(
            f"{model}: cannot prove a decay rate: {name}[{i + 1},{j + 1}] = {entry} {why}"
        )
    return sympy.ImmutableMatrix(M)


def exact_rational_function_matrix(
    name: str, matrix: Any, model: str, z: sympy.Symbol = Z
) -> sympy.ImmutableMatrix:
    """Return ``matrix`` with every entry a rational function of ``z`` over the rationals.

    Raises
    ------
    RateProofError
        An entry is not a rational function of ``z`` (``sqrt(z)``, ``exp(z)``), has
        another free symbol, or an irrational coefficient; the message names the entry.
    """
    M = sympy.Matrix(matrix)
    for (i, j), entry in sorted(M.todok().items()):
        exact = entry.xreplace({f: sympy.Rational(str(f)) for f in entry.atoms(sympy.Float)})
        value = sympy.cancel(exact)
        numerator, denominator = sympy.fraction(value)
        polynomial = exact.free_symbols <= {z} and exact.is_rational_function(z)
        if polynomial and all(
            c.is_Rational
            for part in (numerator, denominator)
            for c in sympy.Poly(part, z).coeffs()
        ):
            M[i, j] = value
            continue
        why = (
            "has a coefficient that is not a rational number"
            if polynomial
            else "is not a rational function of z with rational coefficients"
        )
        raise RateProofError(
            f"{model}: cannot prove a decay rate: {name}[{i + 1},{j + 1}] = {entry} {why} "
            "(the exact proof decides polynomial inequalities in the rationals)"
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
        The order is not 1 (the message says what is proved instead), an entry of
        :math:`H` or :math:`P_0` is not a rational function of z over the rationals, or
        another entry is z-dependent or irrational.
    """
    require_first_order(name, order)
    exact = {
        label: exact_rational_function_matrix(label, value, name)
        for label, value in (("H", H), ("P0", P[0]))
    }
    exact["P1"] = exact_rational_matrix("P1", P[1], name)
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
    require_first_order(system.name, system.order)
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
