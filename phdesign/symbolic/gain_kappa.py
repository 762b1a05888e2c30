r"""The best constant :math:`\kappa^*` of a symbolic gain, in closed form.

With gains :math:`l_1, \dots` left as symbols (positive), the reduced pencil of
:mod:`phdesign.symbolic.certificate` is factored over :math:`\mathbb Q(l_1, \dots)`:

.. math::

    \det(B_r - \mu A_r) = c \prod_j f_j(\mu)^{m_j}, \qquad
    \kappa^* = \min_i \frac{1}{\mu_i},

the minimum over the non-zero roots :math:`\mu_i` of the factors of degree one or two.
A branch that another is proved not to exceed for every positive gain is dropped
(exact Sturm counting of the sign of their difference), so ``Min(1, l/(1 + l²))`` is
``l/(1 + l²)``.
"""

from __future__ import annotations

import sympy

__all__ = ["symbolic_kappa"]

_MU = sympy.Symbol("mu")


def symbolic_kappa(A_r: sympy.MatrixBase, B_r: sympy.MatrixBase) -> tuple[sympy.Expr | None, str]:
    r"""Return :math:`\kappa^* = \min_i 1/\mu_i` over the pencil's non-zero root branches.

    Parameters
    ----------
    A_r, B_r : sympy.MatrixBase
        The reduced pencil (:mod:`phdesign.symbolic.certificate`), entries rational in the
        gains.

    Returns
    -------
    kappa : sympy.Expr or None
        The closed form (a ``Min`` of the branches no other is proved below), or None when a
        factor of degree > 2 has no closed form or the right-hand side vanishes.
    conditions : str
        When it holds, in words.
    """
    det = sympy.factor((B_r - _MU * A_r).det(method="berkowitz"))
    branches: list[sympy.Expr] = []
    unresolved = False
    _, factors = sympy.factor_list(det, _MU)
    for factor, _multiplicity in factors:
        degree = sympy.degree(factor, _MU)
        if degree == 0:
            continue
        if degree > 2:
            unresolved = True
            continue
        for root in sympy.roots(sympy.Poly(factor, _MU)):
            root = _tidy(root)
            if root == 0:
                continue
            branch = _tidy(1 / root)
            numerator, _ = sympy.fraction(sympy.together(root))
            if not numerator.is_positive and not numerator.is_negative:
                # μ_i vanishes at some gains (e.g. (l - 1)²/(2 l) at l = 1): there the
                # branch is absent from the pencil and must not enter the minimum
                branch = sympy.Piecewise((branch, sympy.Ne(numerator, 0)), (sympy.oo, True))
            branches.append(branch)
    gains = sorted(A_r.free_symbols | B_r.free_symbols, key=str)
    names = ", ".join(map(str, gains))
    if unresolved:
        return None, (
            f"holds for all positive {names}; κ* is 1/(largest root) of a pencil "
            "factor of degree > 2 (no closed form)"
        )
    if not branches:
        return None, f"holds for all positive {names}; RHS vanishes on K"
    branches = _undominated(branches)
    kappa = branches[0] if len(branches) == 1 else sympy.Min(*branches)
    return kappa, f"holds for all positive {names}"


def _tidy(expr: sympy.Expr) -> sympy.Expr:
    """Return a compact exact form: ``simplify``, or for radicals one common denominator.

    ``simplify`` of the root of a quadratic factor in two gains (a square root of a
    polynomial of degree 8) costs about 0.15 s and shortens it by 5 %; the common
    denominator with the common factors pulled out costs a sixth of that, for the same
    size (measured on the random models of tests/symbolic/test_classify_properties.py).
    """
    if any(not p.exp.is_Integer for p in expr.atoms(sympy.Pow)):
        return sympy.factor_terms(sympy.together(expr))
    return sympy.simplify(expr)


def _sign_for_positive(poly: sympy.Poly) -> int | None:
    """Return the sign (+1 or -1) a polynomial keeps on s > 0, zeros aside; None if it changes.

    Its square-free factors of odd multiplicity (``sqf_list``) must have no root in
    (0, ∞) (``count_roots``, exact Sturm counting); the sign is then read at the first
    positive integer that is not a root.
    """
    _, factors = poly.sqf_list()
    for factor, multiplicity in factors:
        if multiplicity % 2 and factor.degree() > 0:
            inside = factor.count_roots(0, None) - (1 if factor.eval(0) == 0 else 0)
            if inside > 0:
                return None
    point = 1
    while poly.eval(point) == 0:
        point += 1
    return 1 if poly.eval(point) > 0 else -1


def _nonnegative_for_positive(expr: sympy.Expr) -> bool:
    r"""Prove :math:`f \ge 0` for every positive value of f's one symbol (False: not proved).

    f = p/q with polynomials p, q of rational coefficients in one symbol s: each keeps its
    sign on :math:`s > 0` when no factor of odd multiplicity has a root there (exact root
    counting, :func:`_sign_for_positive`), and f ≥ 0 when those signs agree.  No symbol:
    the sign of the number.
    """
    symbols = expr.free_symbols
    if not symbols:
        return bool(expr.is_nonnegative)
    if len(symbols) != 1:
        return False
    (s,) = symbols
    numerator, denominator = sympy.fraction(sympy.together(expr))
    signs = []
    for part in (numerator, denominator):
        try:
            poly = sympy.Poly(part, s, domain="QQ")
        except (sympy.PolynomialError, sympy.CoercionFailed, sympy.GeneratorsNeeded):
            return False
        if poly.is_zero:
            return part is numerator  # f = 0
        sign = _sign_for_positive(poly)
        if sign is None:
            return False
        signs.append(sign)
    return signs[0] * signs[1] > 0


def _undominated(branches: list[sympy.Expr]) -> list[sympy.Expr]:
    """Drop every branch that another is proved not to exceed for all positive gains.

    ``Min(1, l/(1 + l²))`` is ``l/(1 + l²)`` (``1 - l/(1 + l²) = (l² - l + 1)/(1 + l²)``);
    branches in several gains, or with pieces, are kept as they are.
    """
    kept = list(branches)
    for branch in branches:
        if isinstance(branch, sympy.Piecewise):
            continue
        others = [b for b in kept if b is not branch and not isinstance(b, sympy.Piecewise)]
        if any(_nonnegative_for_positive(branch - other) for other in others):
            kept.remove(branch)
    return kept
