"""The exact κ* of a pencil's characteristic polynomial: its budget (certificate._root_size)
and the rational roots of a quadratic (certificate._rational_quadratic_roots).

A polynomial with rational coefficients is measured without building its expression: the
numerator of ``together`` of :math:`\\sum_i (p_i/q_i)\\mu^i` is
:math:`\\operatorname{lcm}(q_i)` times the polynomial (a common denominator :math:`d` makes
:math:`d\\,p_i/q_i` integers, so :math:`q_i \\mid d`; ``together`` takes the least one), which
``clear_denoms`` returns.  The same polynomial over sympy's expression domain goes the
general way (``together``, ``fraction``); both must say the same, under and over budget.
"""

from __future__ import annotations

import random

import sympy

from phdesign.core.limits import EXACT_KAPPA_BITS
from phdesign.symbolic.certificate import _MU, _exact_kappa, _rational_quadratic_roots, _root_size


def _general(poly: sympy.Poly) -> str | None:
    return _root_size(sympy.Poly(poly.as_expr(), _MU, domain="EX"))


def test_rational_coefficients_are_measured_as_the_general_path_does():
    rng = random.Random(24)
    polys = [
        sympy.Poly([1, sympy.Rational(-121, 10), sympy.Rational(101, 5)], _MU),  # the beam's
        sympy.Poly([6, -5, 1], _MU),  # integers
        sympy.Poly([2**300, 3, 1], _MU),  # 301 bits: over budget
        sympy.Poly([sympy.Rational(1, 3**170), 1, 1], _MU),  # 270 bits after clearing
    ]
    for _ in range(40):
        coefficients = [
            sympy.Rational(rng.randint(-(10**30), 10**30), rng.randint(1, 10**20))
            for _ in range(rng.randint(3, 6))
        ]
        polys.append(sympy.Poly([coefficients[0] or 1, *coefficients[1:]], _MU))
    for poly in polys:
        assert poly.domain.is_QQ or poly.domain.is_ZZ
        assert _root_size(poly) == _general(poly), poly
    assert _root_size(polys[2]) == f"coefficients of 301 bits > {EXACT_KAPPA_BITS}"
    assert _root_size(polys[3]) == f"coefficients of 270 bits > {EXACT_KAPPA_BITS}"
    assert _root_size(polys[0]) is None


def test_rational_quadratic_roots_are_those_real_roots_finds():
    # the beam's pencil with L = diag(0.1, 1): mu^2 - 121/10 mu + 101/5 = (mu - 2)(mu - 101/10)
    # (sum 121/10, product 101/5), so kappa* = 1/mu_max = 10/101, as classify prints
    beam = sympy.Poly([1, sympy.Rational(-121, 10), sympy.Rational(101, 5)], _MU)
    assert _rational_quadratic_roots(beam) == [2, sympy.Rational(101, 10)]
    assert _exact_kappa(beam) == sympy.Rational(10, 101)
    rng = random.Random(25)
    for _ in range(60):
        r1, r2 = (sympy.Rational(rng.randint(-50, 50), rng.randint(1, 20)) for _ in range(2))
        a = sympy.Rational(rng.randint(1, 30), rng.randint(1, 9)) * rng.choice([1, -1])
        poly = sympy.Poly(a * (_MU - r1) * (_MU - r2), _MU)
        assert _rational_quadratic_roots(poly) == sympy.real_roots(poly), poly  # a double root too
    # irrational or complex roots, and other degrees, go the general way
    for coefficients in ([1, 0, -2], [1, 0, 1], [1, -6, 11, -6], [3, 1]):
        assert _rational_quadratic_roots(sympy.Poly(coefficients, _MU)) is None
