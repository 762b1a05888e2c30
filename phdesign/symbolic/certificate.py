r"""The certificate of one variant: does it hold, with which best constant :math:`\kappa^*`.

On the admissible traces :math:`v = K\tilde y` of the error system (see
:mod:`phdesign.symbolic.observer`) a variant asks for :math:`\kappa > 0` with

.. math::

    \mathrm{LHS}(v) = \tfrac12 \tilde y_m^\top (L + L^\top) \tilde y_m
    \;\ge\; \kappa\, \mathrm{RHS}(v) = \kappa \|S v\|^2 ,

:math:`S` selecting the traces of the variant.  Both sides are positive
semidefinite quadratic forms in :math:`\tilde y`, so a :math:`\kappa > 0` exists iff
:math:`\ker \mathrm{LHS} \subseteq \ker \mathrm{RHS}`, and then the best one is

.. math::

    \kappa^* = \inf_{\mathrm{RHS}(v) > 0} \frac{\mathrm{LHS}(v)}{\mathrm{RHS}(v)}
             = \frac{1}{\mu_{\max}}, \qquad
    \det(B_r - \mu A_r) = 0 ,

with the pencil reduced to a complement of :math:`\ker\mathrm{LHS}`.

*Decision.*  Since :math:`L + L^\top \succ 0`, :math:`\ker\mathrm{LHS} = \{\tilde y :
C_m\tilde y = 0\}`, and there :math:`C_m^\top L C_m \tilde y = 0`, so
:math:`v = T^{-1}(0; \tilde y)`: the kernel does not depend on :math:`L`.  The
variant holds iff :math:`S\,T^{-1}(0; N_C) = 0` for a basis :math:`N_C` of
:math:`\ker C_m` — an exact, gain-free test.  (With the plant's own feedback,
:math:`C_m` and :math:`L` stand for the factor :math:`(C_d, L_d)` of
:attr:`~phdesign.symbolic.observer.ErrorSystem.dissipation`, and the witness is
:math:`v = K_{\mathcal K} n` in the basis of :math:`\mathcal K`, which equals
:math:`T^{-1}(0; n)` whenever :math:`G n = 0`.)  (For unit-row sensors, :math:`N_C`
is the unit vectors of the unmeasured outputs: an unmeasured output :math:`j`
whose column of :math:`T^{-1}` touches a selected trace breaks the variant.)
A failing variant returns that :math:`v` as witness: LHS = 0, RHS > 0.

*Constant.*  Parametrize the complement by the measurement :math:`z = \tilde y_m`:
:math:`\tilde y = C_m^\top (C_m C_m^\top)^{-1} z`, :math:`v = K_m z`,
:math:`A_r = \mathrm{sym}(L)`, :math:`B_r = (S K_m)^\top (S K_m)`.  Exact path:
largest real root of :math:`\det(B_r - \mu A_r)` (rational or algebraic).  Float
path: Cholesky :math:`A_r = R R^\top`, :math:`\mu_{\max} =
\lambda_{\max}(R^{-1} B_r R^{-\top})` with numpy.  Symbolic gains: the pencil is
factored over :math:`\mathbb Q(l_1, \dots)`, :math:`\kappa^* = \min_i 1/\mu_i` over
the non-zero root branches (:mod:`phdesign.symbolic.gain_kappa`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import sympy
from sympy.polys.matrices import DomainMatrix

from phdesign.core.errors import ObserverError
from phdesign.core.limits import EXACT_KAPPA_BITS, EXACT_KAPPA_DEGREE, EXACT_KAPPA_OPERATIONS
from phdesign.symbolic.expressions import vanishes
from phdesign.symbolic.observer import ErrorSystem

__all__ = ["Certificate", "certify", "float_kappa"]

_MU = sympy.Symbol("mu")


@dataclass(frozen=True)
class Certificate:
    r"""Outcome of :func:`certify` for one right-hand side.

    Attributes
    ----------
    holds : bool
        Whether :math:`\ker\mathrm{LHS}|_{\mathcal K} \subseteq \ker\mathrm{RHS}|_{\mathcal K}`.
    kappa : sympy.Expr or None
        Exact :math:`\kappa^*` (a number, or an expression in the gains); ``None``
        when the variant fails, when RHS vanishes on :math:`\mathcal K` (unbounded),
        or when only the float path was run.
    kappa_float : float or None
        :math:`\kappa^*` in floating point (``None`` as above, or for symbolic gains).
    unbounded : bool
        RHS vanishes identically on :math:`\mathcal K` (holds with any :math:`\kappa`).
    witness : tuple of sympy.Expr or None
        A trace vector :math:`v \in \mathcal K` with LHS = 0 < RHS when the variant fails.
    free : tuple of int
        Indices (in :math:`v`) of selected traces that the witness leaves non-zero.
    path : str
        ``"exact"``, ``"float"`` or ``"symbolic"``: how :math:`\kappa^*` was computed
        (the decision itself is always exact).
    conditions : str or None
        For symbolic gains, the range of gains the answer is valid for.
    """

    holds: bool
    kappa: sympy.Expr | None
    kappa_float: float | None
    unbounded: bool
    witness: tuple[sympy.Expr, ...] | None
    free: tuple[int, ...]
    path: str
    conditions: str | None = None
    # reduced pencil, kept for the minimizer (not part of equality)
    pencil: tuple[Any, Any, Any] | None = field(default=None, compare=False, repr=False)

    def minimizer(self) -> Any:
        r"""Return a trace vector :math:`v \in \mathcal K` attaining :math:`\kappa^*` (numpy).

        ``None`` when the variant fails, is unbounded, or has symbolic gains.
        """
        if not self.holds or self.unbounded or self.pencil is None:
            return None
        import numpy as np

        A_r, B_r, K_m = (np.array(M.evalf(17).tolist(), dtype=float) for M in self.pencil)
        _, z = _top_eig(A_r, B_r)
        return K_m @ z


def _nullspace(M: sympy.MatrixBase) -> list[sympy.Matrix]:
    if M.rows == 0:
        return [sympy.eye(M.cols)[:, j] for j in range(M.cols)]
    try:
        dm = DomainMatrix.from_Matrix(M).to_field()
        basis = dm.nullspace().to_Matrix()
        return [basis[i, :].T for i in range(basis.rows)]
    except Exception:  # algebraic domains DomainMatrix cannot handle: sympy fallback
        return list(M.nullspace())


def certify(
    es: ErrorSystem,
    selected: Sequence[int],
    method: str = "auto",
) -> Certificate:
    """Decide one variant and compute its best constant.

    Parameters
    ----------
    es : ErrorSystem
        The error system (sensors, gain, admissible traces).
    selected : sequence of int
        Indices in the trace vector :math:`v` of the traces the right-hand side sums.
    method : {"auto", "exact", "float"}
        ``auto``: exact for numeric gains whose pencil has a computable exact root,
        else float; symbolic gains are always symbolic.

    Returns
    -------
    Certificate
    """
    rows = list(selected)
    # LHS = ½ zᵀ(L + Lᵀ)z, z = C ỹ: the observer's sensors, and the plant's own dampers
    C_m, L = es.dissipation
    failed = _counter_example(es, C_m, rows)  # the decision: exact, independent of L
    if failed is not None:
        return failed
    # ---- constant
    right_inverse = C_m.T * (C_m * C_m.T).inv()
    K_m = sympy.ImmutableMatrix(es.K * right_inverse)
    SK = K_m.extract(rows, list(range(K_m.cols))) if rows else sympy.zeros(0, K_m.cols)
    B_r = sympy.ImmutableMatrix(SK.T * SK)
    A_r = sympy.ImmutableMatrix((L + L.T) / 2)
    symbolic = bool(L.free_symbols)
    if symbolic:
        B_r = B_r.applyfunc(sympy.cancel)
    if B_r.is_zero_matrix:
        return Certificate(True, None, None, True, None, (), "symbolic" if symbolic else "exact")
    pencil = (A_r, B_r, K_m)
    if symbolic:
        from phdesign.symbolic.gain_kappa import symbolic_kappa  # symbolic gains only

        kappa, conditions = symbolic_kappa(A_r, B_r)
        return Certificate(True, kappa, None, False, None, (), "symbolic", conditions, pencil)
    return _numeric_kappa(pencil, method)


def _counter_example(
    es: ErrorSystem, C_m: sympy.MatrixBase, rows: list[int]
) -> Certificate | None:
    r"""Return the failed certificate with its witness, or ``None`` when the variant holds.

    It fails iff an error output in :math:`\ker C_m` (neither measured nor damped) gives an
    admissible trace that does not vanish on the selected rows.
    """
    for trace in _unobserved_traces(es.K, sympy.ImmutableMatrix(C_m)):
        zero = [trace.vanishes(i) for i in rows]
        if not all(zero):
            free = tuple(i for i, z in zip(rows, zero, strict=True) if not z)
            witness = tuple(
                sympy.S.Zero if trace.vanishes(i) else sympy.expand(x)
                for i, x in enumerate(trace.v)
            )
            return Certificate(False, None, None, False, witness, free, "exact")
    return None


@dataclass(frozen=True)
class _UnobservedTrace:
    r"""An admissible trace :math:`v = K n_c`, :math:`n_c \in \ker C_m`, and its zeros.

    Whether an entry vanishes is decided on first use (some need :func:`sympy.simplify`).
    """

    v: sympy.ImmutableMatrix
    zero: dict[int, bool] = field(default_factory=dict)

    def vanishes(self, i: int) -> bool:
        """Return whether entry ``i`` of :math:`v` is identically zero."""
        if i not in self.zero:
            self.zero[i] = vanishes(self.v[i])
        return self.zero[i]


@functools.lru_cache(maxsize=64)
def _unobserved_traces(
    K: sympy.ImmutableMatrix, C_m: sympy.ImmutableMatrix
) -> tuple[_UnobservedTrace, ...]:
    r"""Return the traces :math:`K n_c` over a basis :math:`n_c` of :math:`\ker C_m`.

    The same for every variant of one error system (classify asks up to 14), so they are
    found once: exact matrices are hashable, and a few dozen error systems are kept.
    """
    # K n_c = T⁻¹(0; n_c) when G n_c = 0
    return tuple(_UnobservedTrace(sympy.ImmutableMatrix(K * n_c)) for n_c in _nullspace(C_m))


def _numeric_kappa(
    pencil: tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix, sympy.ImmutableMatrix],
    method: str,
) -> Certificate:
    """κ* of a numeric pencil: exact when affordable (``auto``, ``exact``), else in float."""
    A_r, B_r, _ = pencil
    affordable = _operations(A_r, B_r) <= EXACT_KAPPA_OPERATIONS
    if method == "exact" and not affordable:
        raise ObserverError(
            f"the exact κ* of this pencil is over budget ({_operations(A_r, B_r)} operations "
            f"> {EXACT_KAPPA_OPERATIONS}, phdesign.core.limits.EXACT_KAPPA_OPERATIONS); "
            "use method='float'"
        )
    exact_path = method in ("auto", "exact") and affordable
    characteristic = _characteristic(A_r, B_r) if exact_path else None
    if characteristic is not None and (size := _root_size(characteristic)) is not None:
        # isolating roots factors integers (and polynomials in e or pi) of this size: 598 bits
        # took 55 s, exp(100) (degree 200 in e) 30 s; the float path scales them instead
        if method == "exact":
            raise ObserverError(
                f"the exact κ* of this pencil is over budget ({size}, "
                "phdesign.core.limits.EXACT_KAPPA_BITS and EXACT_KAPPA_DEGREE); use method='float'"
            )
        exact_path = False
    if exact_path and characteristic is not None:
        exact = _exact_kappa(characteristic)
        if exact is not None:
            return Certificate(
                True, exact, _as_float(exact), False, None, (), "exact", None, pencil
            )
        if method == "exact":
            raise ObserverError(
                "method='exact': no exact root is available for this pencil; use "
                "method='float' or 'auto'"
            )
    kappa, kappa_float = _scaled_float_kappa(A_r, B_r)
    return Certificate(True, kappa, kappa_float, False, None, (), "float", None, pencil)


def _operations(*matrices: sympy.MatrixBase) -> int:
    """Size of a pencil's entries: the measure of :data:`EXACT_KAPPA_OPERATIONS`."""
    return sum(sympy.count_ops(x) for M in matrices for x in M)


def _as_float(value: sympy.Expr) -> float | None:
    """``value`` as a float, or ``None`` when a double cannot hold it (1e-500, 1e400)."""
    number = float(value.evalf(30))
    if value != 0 and (number == 0.0 or not math.isfinite(number)):
        return None
    return number


def _scaled_float_kappa(
    A_r: sympy.MatrixBase, B_r: sympy.MatrixBase
) -> tuple[sympy.Expr | None, float | None]:
    r"""Float :math:`\kappa^*` of a pencil whose entries may lie beyond double range.

    With :math:`\alpha = \max|A_{ij}|`, :math:`\beta = \max|B_{ij}|` (exact), the pencil
    :math:`(A/\alpha, B/\beta)` has entries of order one and
    :math:`\kappa^* = \kappa^*(A/\alpha, B/\beta)\, \alpha/\beta`: gains of 1e200 neither
    overflow nor turn κ* into 0. Before that both are scaled by the same diagonal
    :func:`_equilibrated`, so that ``L = diag(1e-300, 1e300)`` keeps both diagonal entries
    of :math:`A` (one scale for the whole matrix would lose the small one). Returns κ* as a
    15-digit sympy number when a double cannot hold it (then the float is ``None``), else
    ``(None, float)``.
    """
    A_r, B_r = _equilibrated(A_r, B_r)
    alpha = max((abs(x) for x in A_r), key=lambda x: float(sympy.log(x + 1e-300).evalf(15)))
    beta = max((abs(x) for x in B_r), key=lambda x: float(sympy.log(x + 1e-300).evalf(15)))
    if alpha == 0 or beta == 0:
        return None, float_kappa(A_r, B_r)
    scaled = float_kappa(A_r / alpha, B_r / beta)
    if scaled is None:
        return None, None
    value = sympy.Float(scaled, 15) * sympy.N(alpha / beta, 15)
    as_float = _as_float(value)
    return (None, as_float) if as_float is not None else (value, None)


def _characteristic(A_r: sympy.MatrixBase, B_r: sympy.MatrixBase) -> sympy.Poly:
    r"""Return the characteristic polynomial of :math:`A^{-1}B` in :math:`\mu` (exact)."""
    try:
        dA = DomainMatrix.from_Matrix(A_r).to_field()
        dB = DomainMatrix.from_Matrix(B_r).to_field()
        unify = dA.unify(dB)
        dA, dB = unify if isinstance(unify, tuple) else (dA, dB)
        M = dA.inv() * dB
        coefficients = M.charpoly()
        domain = M.domain
        return sympy.Poly([domain.to_sympy(c) for c in coefficients], _MU)
    except Exception:
        return sympy.Poly((B_r - _MU * A_r).det(method="berkowitz"), _MU)


def _root_size(poly: sympy.Poly) -> str | None:
    r"""Say why isolating the roots of ``poly`` is over budget, or ``None`` when it is not.

    The measure: the bits of the integer coefficients of its numerator, a polynomial in
    :math:`\mu` and the constants it holds (``E`` for ``exp(1)``, ``pi``), and its degree
    in those constants (``exp(100)`` is ``E**100``).  Degree 1 is a division: no budget.
    With rational coefficients :math:`c_i = p_i/q_i` (no constants: degree 0) that numerator
    is :math:`\operatorname{lcm}(q_i)` times ``poly``, read off without building the
    expression (tests/symbolic/test_certificate_budget.py compares the two).
    """
    if poly.degree() <= 1:
        return None
    if poly.domain.is_ZZ or poly.domain.is_QQ:
        _, full = poly.clear_denoms(convert=True)
        return _over_budget(_bits(full), 0)
    try:
        numerator, _ = sympy.fraction(sympy.together(poly.as_expr()))
        _, full = sympy.Poly(numerator).clear_denoms(convert=True)
        bits = _bits(full)
    except (sympy.PolynomialError, sympy.DomainError, TypeError, ValueError):
        return "coefficients that are not polynomials in constants"
    degree = max(
        (d for gen, d in zip(full.gens, full.degree_list(), strict=True) if gen != _MU), default=0
    )
    return _over_budget(bits, degree)


def _bits(integer_poly: sympy.Poly) -> int:
    """Return the bits of the largest integer coefficient of ``integer_poly``."""
    return max(abs(int(c)).bit_length() for c in integer_poly.coeffs())


def _over_budget(bits: int, degree: int) -> str | None:
    """Say which of :func:`_root_size`'s budgets ``bits`` and ``degree`` exceed, if any."""
    if bits > EXACT_KAPPA_BITS:
        return f"coefficients of {bits} bits > {EXACT_KAPPA_BITS}"
    if degree > EXACT_KAPPA_DEGREE:
        return f"degree {degree} in a constant > {EXACT_KAPPA_DEGREE}"
    return None


def _equilibrated(
    A_r: sympy.MatrixBase, B_r: sympy.MatrixBase
) -> tuple[sympy.MatrixBase, sympy.MatrixBase]:
    r"""Return the pencil :math:`(DAD, DBD)` scaled by powers of two on the diagonal.

    :math:`D = \operatorname{diag}(2^{-k_i})` with :math:`4^{k_i} \approx A_{ii}`.  The
    pencil keeps its eigenvalues (:math:`Bv = \mu Av` with :math:`v = Dw`), the diagonal
    of :math:`A` (positive: :math:`A \succ 0`) comes within a factor 2 of 1 and, by
    Cauchy-Schwarz, so does every entry of :math:`A`.  Powers of two keep it exact.
    """
    exponents = []
    for i in range(A_r.rows):
        entry = A_r[i, i]
        if not entry.is_positive:
            return A_r, B_r  # not definite: left to the float path as it is
        exponents.append(round(float(sympy.log(entry, 2).evalf(15)) / 2))
    D = sympy.diag(*[sympy.Rational(2) ** -k for k in exponents])
    return sympy.ImmutableMatrix(D * A_r * D), sympy.ImmutableMatrix(D * B_r * D)


def _exact_kappa(poly: sympy.Poly) -> sympy.Expr | None:
    r"""Exact :math:`1/\mu_{\max}` from the pencil's characteristic polynomial ``poly``.

    ``None`` if its roots cannot be isolated exactly.
    """
    roots = _rational_quadratic_roots(poly)
    if roots is not None:
        return _reciprocal_of_largest(roots)
    try:
        roots = sympy.real_roots(poly)
    except (sympy.PolynomialError, NotImplementedError, sympy.DomainError):
        try:
            all_roots = sympy.roots(poly, _MU)
        except Exception:
            return None
        if sum(all_roots.values()) != poly.degree():  # not every root has a closed form
            return None
        roots = [r for r in all_roots if r.is_real]
    return _reciprocal_of_largest(roots)


def _rational_quadratic_roots(poly: sympy.Poly) -> list[sympy.Rational] | None:
    r"""Return the roots of a rational quadratic whose discriminant is a rational square.

    ``None`` for any other polynomial.

    :math:`a\mu^2 + b\mu + c` has the roots :math:`(-b \pm \sqrt{b^2 - 4ac})/(2a)`: with
    :math:`b^2 - 4ac = (p/q)^2` they are rational, what :func:`sympy.real_roots` returns
    after factoring (two Rationals, a double root twice), at a fraction of its cost.
    """
    if poly.degree() != 2 or not (poly.domain.is_QQ or poly.domain.is_ZZ):
        return None
    a, b, c = (sympy.Rational(x) for x in poly.all_coeffs())
    discriminant = b * b - 4 * a * c
    if discriminant < 0:
        return None
    p, q = discriminant.p, discriminant.q
    root_p, root_q = math.isqrt(p), math.isqrt(q)
    if root_p * root_p != p or root_q * root_q != q:
        return None
    s = sympy.Rational(root_p, root_q)
    return sorted([(-b - s) / (2 * a), (-b + s) / (2 * a)])


def _reciprocal_of_largest(roots: Sequence[sympy.Expr]) -> sympy.Expr | None:
    r"""Return :math:`1/\mu_{\max}` over real roots (radicals rationalized); None without one."""
    if not roots:
        return None
    mu_max = max(roots, key=lambda r: float(r.evalf(30)))
    if mu_max == 0:
        return None
    # radsimp rationalizes denominators like 1/(4 sqrt(2)/7 + 16/7) = (4 - sqrt(2))/4
    return 1 / mu_max if mu_max.is_rational else sympy.radsimp(1 / mu_max)


def _top_eig(A: Any, B: Any) -> tuple[float, Any]:
    r"""Largest :math:`\mu` with :math:`\det(B - \mu A) = 0` and its eigenvector (numpy)."""
    import numpy as np

    R = np.linalg.cholesky(A)
    R_inv = np.linalg.inv(R)
    C = R_inv @ B @ R_inv.T
    w, V = np.linalg.eigh((C + C.T) / 2)
    z = R_inv.T @ V[:, -1]
    return float(w[-1]), z


def float_kappa(A_r: Any, B_r: Any) -> float | None:
    r"""Floating-point :math:`\kappa^* = 1/\mu_{\max}` (``None`` when :math:`B_r = 0`)."""
    import numpy as np

    A = (
        np.array(sympy.Matrix(A_r).evalf(17).tolist(), dtype=float)
        if hasattr(A_r, "evalf")
        else np.asarray(A_r, float)
    )
    B = (
        np.array(sympy.Matrix(B_r).evalf(17).tolist(), dtype=float)
        if hasattr(B_r, "evalf")
        else np.asarray(B_r, float)
    )
    if not np.any(B):
        return None
    mu, _ = _top_eig(A, B)
    return 1.0 / mu
