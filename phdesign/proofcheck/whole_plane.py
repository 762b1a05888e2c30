r"""Checking the ``whole_plane`` section: the polynomial in :math:`\zeta = e^{\lambda\tau}`.

Re-derived exactly from the system: :math:`N = 1`, :math:`P_0 = 0`,
:math:`K = \ell P_1^{-1}H^{-1}` with :math:`K^2 = \tau^2 I` for the proof's rational
:math:`\tau`, :math:`P_\pm = (I \pm K/\tau)/2`, and
:math:`p(\zeta) = \det(B_b P_- + \zeta B_a + \zeta^2 B_b P_+)`, found by evaluating the
determinant at :math:`\zeta = 0, 1, \dots, 2n` (exact rationals) and interpolating
(Lagrange).  Then each root square's count is proved by the argument principle on
:math:`p` in interval arithmetic (Horner in w, with p(c + w) expanded exactly about each
square's centre), the counts must add up to the degree of
:math:`p` less its roots at 0 (so no root is left out), the squares must be disjoint
and avoid 0, and the claim must contain :math:`\max_i \ln|\zeta_i|/\tau` with
:math:`\ln|\zeta|` bounded over each square (mpmath's interval logarithm).
"""

from __future__ import annotations

from fractions import Fraction

from mpmath.libmp import libmpi as L
from mpmath.libmp import mpf_lt, to_float

from phdesign.proofcheck.contour import overlapping, square_count
from phdesign.proofcheck.exact import determinant, identity, matmul, number
from phdesign.proofcheck.intervals import box, interval
from phdesign.proofcheck.system import Delta

__all__ = ["check_whole_plane", "polynomial"]

PRECISION = 96


def polynomial(data: Delta, tau: Fraction) -> list[Fraction] | None:
    """Return the coefficients of p (ascending), or None if Δ is not a polynomial in e^{λτ}."""
    n = data.size
    if data.order != 1 or any(any(row) for row in data.A0):
        return None
    K = [[x * data.length for x in row] for row in data.A1]
    if matmul(K, K) != [[tau * tau * x for x in row] for row in identity(n)]:
        return None
    eye = identity(n)
    plus = [[(eye[i][j] + K[i][j] / tau) / 2 for j in range(n)] for i in range(n)]
    minus = [[(eye[i][j] - K[i][j] / tau) / 2 for j in range(n)] for i in range(n)]
    Ba = [row[n:] for row in data.boundary]
    Bb = [row[:n] for row in data.boundary]
    low, high = matmul(Bb, minus), matmul(Bb, plus)
    nodes = list(range(2 * n + 1))
    values = [
        determinant(
            [[low[i][j] + z * Ba[i][j] + z * z * high[i][j] for j in range(n)] for i in range(n)]
        )
        for z in nodes
    ]
    return _interpolate(nodes, values)


def _interpolate(nodes: list[int], values: list[Fraction]) -> list[Fraction]:
    """Lagrange interpolation, exact: the coefficients ascending."""
    size = len(nodes)
    result = [Fraction(0)] * size
    for i, (xi, yi) in enumerate(zip(nodes, values, strict=True)):
        basis = [Fraction(1)]
        denominator = Fraction(1)
        for j, xj in enumerate(nodes):
            if j == i:
                continue
            basis = [
                a - xj * b
                for a, b in zip([Fraction(0), *basis], [*basis, Fraction(0)], strict=True)
            ]
            denominator *= xi - xj
        for k, c in enumerate(basis):
            result[k] += yi * c / denominator
    while len(result) > 1 and result[-1] == 0:
        result.pop()
    return result


def _shifted(coefficients: list[Fraction], x: Fraction, y: Fraction, prec: int):
    """Enclose p over a box through p(c + w) = Σ d_k w^k, c = x + iy (d_k exact).

    The shifted coefficients are computed exactly as complex rationals (pairs), by
    expanding each (c + w)^k with the binomial theorem.
    """
    from math import comb

    degree = len(coefficients) - 1
    powers = [(Fraction(1), Fraction(0))]  # c^j as (re, im)
    for _ in range(degree):
        re, im = powers[-1]
        powers.append((re * x - im * y, re * y + im * x))
    shifted = []
    for k in range(degree + 1):
        re = sum(
            (coefficients[j] * comb(j, k) * powers[j - k][0] for j in range(k, degree + 1)),
            Fraction(0),
        )
        im = sum(
            (coefficients[j] * comb(j, k) * powers[j - k][1] for j in range(k, degree + 1)),
            Fraction(0),
        )
        shifted.append((interval(re, prec), interval(im, prec)))

    def evaluate(p, q, prec_: int) -> tuple:
        w = box((p[0] - x, q[0] - x), (p[1] - y, q[1] - y), prec_)
        value = shifted[-1]
        for d in reversed(shifted[:-1]):
            value = L.mpci_add(L.mpci_mul(value, w, prec_), d, prec_)
        return value

    return evaluate


def check_whole_plane(data: Delta, section: dict, claim: dict, failures: list[str]) -> None:
    """Verify the whole-plane section and the claim it supports."""
    tau = number(section["tau"])
    coefficients = polynomial(data, tau) if tau > 0 else None
    if coefficients is None:
        failures.append("whole plane: Δ is not a polynomial in e^{λτ} for the proof's τ")
        return
    if [number(c) for c in section["polynomial"]] != coefficients + [Fraction(0)] * (
        len(section["polynomial"]) - len(coefficients)
    ):
        failures.append(
            "whole plane: the proof's polynomial is not det(B_b P- + ζ B_a + ζ² B_b P+)"
        )
        return
    if not any(coefficients):
        failures.append("whole plane: p vanishes identically")
        return
    shift = next(i for i, c in enumerate(coefficients) if c)
    degree = len(coefficients) - 1 - shift
    squares, total = [], 0
    for index, square in enumerate(section["roots"]):
        x, y = (number(v) for v in square["center"])
        what = f"whole plane: root square {index + 1}"
        found = square_count(
            _shifted(coefficients, x, y, PRECISION),
            square,
            symmetric=False,
            failures=failures,
            what=what,
            prec=PRECISION,
        )
        if found is None:
            return
        x, y, r, count = found
        if max(abs(x), abs(y)) <= r:
            failures.append(f"{what} reaches ζ = 0")
            return
        squares.append((x, y, r))
        total += count
    clash = overlapping(squares)
    if clash is not None:
        failures.append(f"whole plane: root square {clash} overlaps another")
        return
    if total != degree:
        failures.append(f"whole plane: the squares hold {total} roots of a degree-{degree} p")
        return
    _check_claim(squares, tau, claim.get("abscissa_interval"), failures, data.conservative)


def _check_claim(
    squares, tau: Fraction, interval_claim, failures: list[str], conservative: bool
) -> None:
    if not squares:
        if interval_claim is not None:
            failures.append(
                "whole plane: p has no nonzero root (no eigenvalue) but an interval is claimed"
            )
        return
    if interval_claim is None:
        failures.append("whole plane: eigenvalues exist but no interval is claimed")
        return
    if conservative:  # |ζ| = 1 for every root: Re λ = 0 exactly
        low, high = (number(v) for v in interval_claim)
        if not low <= 0 <= high:
            failures.append("whole plane: a conservative system's abscissa is 0 exactly")
        return
    lows, highs = [], []
    for x, y, r in squares:
        near = [max(abs(c) - r, Fraction(0)) for c in (x, y)]
        far = [abs(c) + r for c in (x, y)]
        lo2 = interval(near[0] ** 2 + near[1] ** 2, PRECISION)
        hi2 = interval(far[0] ** 2 + far[1] ** 2, PRECISION)
        two_tau = interval(2 * tau, PRECISION)
        lows.append(L.mpi_div(L.mpi_log((lo2[0], lo2[0]), PRECISION), two_tau, PRECISION)[0])
        highs.append(L.mpi_div(L.mpi_log((hi2[1], hi2[1]), PRECISION), two_tau, PRECISION)[1])
    lo, up = (interval(number(v), PRECISION) for v in interval_claim)
    best_low = max(lows, key=to_float)  # any low below the claim would do as well
    if mpf_lt(best_low, lo[1]):
        failures.append(
            f"whole plane: the claimed lower bound {to_float(lo[1]):.12g} exceeds what the "
            f"roots prove ({to_float(best_low):.12g})"
        )
    for high in highs:  # every root's bound, exactly
        if mpf_lt(up[0], high):
            failures.append(
                f"whole plane: the claimed upper bound {to_float(up[0]):.12g} is below "
                f"ln|ζ|/τ = {to_float(high):.12g} for a root"
            )
            return
