"""The checker's enclosures of Δ and Δ′ (mpmath intervals), against what must hold.

* :func:`delta_and_slope` over the box spanned by λ ± h holds the difference quotient
  (Δ(λ+h) − Δ(λ−h))/(2h): it is the mean of Δ′ along the segment, so it lies in every
  convex enclosure of Δ′ there (an exact containment, no tolerance);
* :func:`centered_delta` over a box holds Δ at the box's corners and centre;
* the Taylor degree's remainder at ‖Y‖ = 1/4 is below 2^(10 − prec), and the degree is the
  least that is.
"""

from __future__ import annotations

import math
from fractions import Fraction

import pytest
from mpmath.libmp import libmpi as L
from mpmath.libmp import mpf_le

import phdesign as phd
from phdesign.models import load_builtin
from phdesign.proofcheck.intervals import (
    box,
    centered_delta,
    delta,
    delta_and_slope,
    taylor_terms,
)
from phdesign.proofcheck.system import derive

pytest.importorskip("flint", reason="the proof file is made by the certifier (python-flint)")

PREC = 96


@pytest.fixture(scope="module")
def beam():
    cert = phd.Observer(load_builtin("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1]).certify(
        band=5
    )
    failures: list[str] = []
    data = derive(cert.proof["system"], failures)
    assert failures == []
    return data


def point(x: Fraction, y: Fraction) -> tuple:
    return box((x, x), (y, y), PREC)


def inside(inner: tuple, outer: tuple) -> bool:
    return all(
        mpf_le(o[0], i[0]) and mpf_le(i[1], o[1]) for i, o in zip(inner, outer, strict=True)
    )


@pytest.mark.parametrize("lam", [(Fraction(-3), Fraction(5)), (Fraction(-1, 2), Fraction(300))])
def test_the_slope_holds_the_difference_quotient(beam, lam):
    h = Fraction(1, 10**4)
    x, y = lam
    _, slope = delta_and_slope(beam, box((x - h, x + h), (y, y), PREC), PREC)
    ahead, behind = delta(beam, point(x + h, y), PREC), delta(beam, point(x - h, y), PREC)
    quotient = L.mpci_mul(
        L.mpci_sub(ahead, behind, PREC), box((1 / (2 * h),) * 2, (Fraction(0),) * 2, PREC), PREC
    )
    assert inside(quotient, slope)


def test_the_centered_form_holds_the_corners(beam):
    p, q = (Fraction(-3), Fraction(4)), (Fraction(-29, 10), Fraction(41, 10))
    enclosure = centered_delta(beam, p, q, PREC)
    for corner in [p, q, (p[0], q[1]), (q[0], p[1]), ((p[0] + q[0]) / 2, (p[1] + q[1]) / 2)]:
        assert inside(delta(beam, point(*corner), PREC), enclosure)


@pytest.mark.parametrize("prec", [53, 64, 96, 128])
def test_the_taylor_degree_is_the_least_that_resolves_the_precision(prec):
    def remainder(m: int) -> Fraction:  # its leading term at ||Y|| = 1/4
        return Fraction(1, 4 ** (m + 1) * math.factorial(m + 1))

    m = taylor_terms(prec)
    assert remainder(m) <= Fraction(1, 2 ** (prec - 10)) < remainder(m - 1)
