r"""Re-check a decay-rate proof with a polynomial weight (z-dependent H, P0), exactly.

The section written for z-dependent coefficients (``"weight": "polynomial"``, from
:mod:`phdesign.numeric.certified.rate_poly`) claims
:math:`\|\tilde x(t)\| \le M e^{-\sigma t}\|\tilde x(0)\|` for
:math:`\partial_t x = P_1 (\mathcal H x)_z + P_0 \mathcal H x`,
:math:`\mathcal B (e(b); e(a)) = 0`, by :math:`V = \int_a^b x^\top \Pi(z) x\,dz`.  This
module recomputes, from the section's primitive data (:math:`\mathcal H(z)`,
:math:`P_0(z)`, :math:`\Pi(z)` as rational functions, :math:`P_1`, the interval,
:math:`\mathcal B`, :math:`K_b`, :math:`\sigma, c_1, c_2, M`), every matrix of the claim,

.. math::

    G = -\operatorname{sym}(\Pi' P_1 \mathcal H) + \operatorname{sym}(\Pi P_1 \mathcal H')
    + 2\operatorname{sym}(\Pi P_0 \mathcal H) + 2\sigma\Pi, \quad
    \Pi - c_1\mathcal H, \quad c_2\mathcal H - \Pi, \quad \mathcal H ,

and the boundary form at the two ends, and decides each on all of :math:`[a, b]` with
its own arithmetic in :class:`fractions.Fraction` (sharing nothing with the prover's
sympy): polynomials as coefficient lists, the matrix over one common denominator
:math:`D(z)`, its leading principal minors by fraction-free (Bareiss) elimination in
:math:`\mathbb Q[z]`, and each minor (and :math:`D`) shown free of zeros on
:math:`[a, b]` by Sturm's theorem (the sign changes of the Sturm sequence at :math:`a`
and :math:`b` agree, the values at the ends are nonzero) and positive at :math:`a`.
:func:`check_rate_polynomial` returns the failures; empty means verified.
"""

from __future__ import annotations

from fractions import Fraction
from itertools import pairwise
from typing import Any

from phdesign.proofcheck.exact import inverse
from phdesign.proofcheck.rate import CLAIMS, _m, _mul, _q, _rank, _t

__all__ = ["check_rate_polynomial"]

Poly = list[Fraction]  # coefficients of z^0, z^1, ...; no trailing zero (zero is [])
Function = tuple[Poly, Poly]  # numerator, denominator
Matrix = list[list[Function]]
ONE: Poly = [Fraction(1)]


# --------------------------------------------------------------------------- polynomials
def _trim(p: Poly) -> Poly:
    while p and p[-1] == 0:
        p = p[:-1]
    return p


def _padd(p: Poly, q: Poly) -> Poly:
    size = max(len(p), len(q))
    return _trim(
        [
            (p[i] if i < len(p) else Fraction(0)) + (q[i] if i < len(q) else Fraction(0))
            for i in range(size)
        ]
    )


def _pscale(c: Fraction, p: Poly) -> Poly:
    return _trim([c * x for x in p])


def _pmul(p: Poly, q: Poly) -> Poly:
    out = [Fraction(0)] * max(len(p) + len(q) - 1, 0)
    for i, x in enumerate(p):
        for j, y in enumerate(q):
            out[i + j] += x * y
    return _trim(out)


def _pderiv(p: Poly) -> Poly:
    return _trim([i * p[i] for i in range(1, len(p))])


def _value(p: Poly, x: Fraction) -> Fraction:
    total = Fraction(0)
    for c in reversed(p):
        total = total * x + c
    return total


def _pdivmod(p: Poly, q: Poly) -> tuple[Poly, Poly]:
    quotient, rest = [Fraction(0)] * max(len(p) - len(q) + 1, 0), list(p)
    while len(rest) >= len(q):
        factor, shift = rest[-1] / q[-1], len(rest) - len(q)
        quotient[shift] = factor
        rest = _trim(_padd(rest, [Fraction(0)] * shift + _pscale(-factor, q))[: len(rest) - 1])
    return _trim(quotient), rest


def _zero_free(p: Poly, a: Fraction, b: Fraction) -> bool:
    """Whether ``p`` has no zero on [a, b] (Sturm: distinct zeros in (a, b] = V(a) − V(b))."""
    if not p or _value(p, a) == 0 or _value(p, b) == 0:
        return False
    sequence = [p, _pderiv(p)]
    while len(sequence[-1]) > 1:
        rest = _pdivmod(sequence[-2], sequence[-1])[1]
        if not rest:
            break  # the last entry is gcd(p, p′): the count still holds
        sequence.append(_pscale(-1 / abs(rest[-1]), rest))  # a positive scale keeps the signs

    def changes(x: Fraction) -> int:
        signs = [v > 0 for v in (_value(q, x) for q in sequence if q) if v != 0]
        return sum(s != t for s, t in pairwise(signs))

    return changes(a) == changes(b)


def _quotient(p: Poly, q: Poly) -> Poly | None:
    """P / q when q divides p exactly, else None."""
    quotient, rest = _pdivmod(p, q)
    return None if rest else quotient


def _common(p: Poly, q: Poly) -> Poly:
    """Return a common multiple of p and q (the larger if one divides the other, else p q)."""
    if _quotient(p, q) is not None:
        return p
    if _quotient(q, p) is not None:
        return q
    return _pmul(p, q)


# --------------------------------------------------------------------------- functions
def _fadd(*terms: tuple[Fraction, Function]) -> Function:
    """Σ c f over a common denominator (kept small: H′ brings powers of one denominator)."""
    den = ONE
    for _, (_, d) in terms:
        den = _common(den, d)
    num: Poly = []
    for c, (n, d) in terms:
        factor = _quotient(den, d)
        assert factor is not None  # den is a multiple of every d by construction
        num = _padd(num, _pscale(c, _pmul(n, factor)))
    return num, den


def _fmul(f: Function, g: Function) -> Function:
    return _pmul(f[0], g[0]), _pmul(f[1], g[1])


def _fderiv(f: Function) -> Function:
    n, d = f
    return _padd(_pmul(_pderiv(n), d), _pscale(Fraction(-1), _pmul(n, _pderiv(d)))), _pmul(d, d)


def _fequal(f: Function, g: Function) -> bool:
    return _pmul(f[0], g[1]) == _pmul(g[0], f[1])


def _fat(f: Function, x: Fraction) -> Fraction:
    return _value(f[0], x) / _value(f[1], x)


def _mmul(A: Matrix, B: Matrix) -> Matrix:
    return [
        [
            _fadd(*((Fraction(1), _fmul(x, y)) for x, y in zip(row, col, strict=True)))
            for col in zip(*B, strict=True)
        ]
        for row in A
    ]


def _mcomb(*terms: tuple[Fraction, Matrix]) -> Matrix:
    rows, cols = len(terms[0][1]), len(terms[0][1][0])
    return [[_fadd(*((c, M[i][j]) for c, M in terms)) for j in range(cols)] for i in range(rows)]


def _mt(A: Matrix) -> Matrix:
    return [list(col) for col in zip(*A, strict=True)]


def _msym(A: Matrix) -> Matrix:
    return _mcomb((Fraction(1, 2), A), (Fraction(1, 2), _mt(A)))


def _lift(A: list[list[Fraction]]) -> Matrix:
    return [[(_trim([x]), ONE) for x in row] for row in A]


def _mequal(A: Matrix, B: Matrix) -> bool:
    return len(A) == len(B) and all(
        len(r) == len(s) and all(_fequal(x, y) for x, y in zip(r, s, strict=True))
        for r, s in zip(A, B, strict=True)
    )


def _positive_on(M: Matrix, a: Fraction, b: Fraction) -> bool:
    """Whether the symmetric M(z) ≻ 0 for every z in [a, b] (module docstring)."""
    if not _mequal(M, _mt(M)):
        return False
    D = ONE
    for row in M:
        for _, d in row:
            D = _common(D, d)
    if not _zero_free(D, a, b):
        return False
    sign = Fraction(1 if _value(D, a) > 0 else -1)
    W = []
    for row in M:
        out = []
        for n, d in row:
            factor = _quotient(D, d)
            assert factor is not None  # D is a multiple of each denominator by construction
            out.append(_pscale(sign, _pmul(n, factor)))
        W.append(out)
    previous = ONE
    for k in range(len(W)):  # Bareiss: the k-th pivot is the leading minor of order k + 1
        pivot = W[k][k]
        if not _zero_free(pivot, a, b) or _value(pivot, a) <= 0:
            return False
        for i in range(k + 1, len(W)):
            for j in range(k + 1, len(W)):
                cross = _padd(
                    _pmul(pivot, W[i][j]), _pscale(Fraction(-1), _pmul(W[i][k], W[k][j]))
                )
                W[i][j], rest = _pdivmod(cross, previous)
                if rest:  # pragma: no cover - Bareiss divides exactly
                    return False
        previous = pivot
    return True


# --------------------------------------------------------------------------- the claims
def _function(entry: Any) -> Function:
    if not isinstance(entry, dict):
        raise TypeError(
            f"expected a rational function {{'num': [...], 'den': [...]}}, found {entry!r}"
        )
    num, den = _trim([_q(c) for c in entry["num"]]), _trim([_q(c) for c in entry["den"]])
    if not den:
        raise ValueError("a rational function has the denominator 0")
    return num, den


def _functions(rows: Any) -> Matrix:
    matrix = [[_function(x) for x in row] for row in rows]
    if not matrix or any(len(row) != len(matrix) for row in matrix):
        raise ValueError("a matrix of functions must be square and non-empty")
    return matrix


def _read(section: dict[str, Any]) -> dict[str, Any]:
    d: dict[str, Any] = {k: _functions(section[k]) for k in ("H", "P0", "Pi")}
    d.update({k: _m(section[k]) for k in ("P1", "boundary", "kernel")})
    d.update({k: _q(section[k]) for k in ("sigma", "c1", "c2", "M")})
    d["interval"] = [_q(e) for e in section["interval"]]
    n = len(d["H"])
    shapes = {
        "P0": (n, n),
        "Pi": (n, n),
        "P1": (n, n),
        "boundary": (n, 2 * n),
        "kernel": (2 * n, n),
    }
    for key, (rows, cols) in shapes.items():
        if (len(d[key]), len(d[key][0])) != (rows, cols):
            raise ValueError(f"{key} must be {rows} x {cols}")
    if len(d["interval"]) != 2:
        raise ValueError("interval must hold two rationals")
    return d


def _at(M: Matrix, x: Fraction) -> list[list[Fraction]]:
    return [[_fat(f, x) for f in row] for row in M]


def _boundary(d: dict[str, Any]) -> list[list[Fraction]] | None:
    n, (a, b) = len(d["H"]), d["interval"]
    H_b, H_a = inverse(_at(d["H"], b)), inverse(_at(d["H"], a))
    if H_b is None or H_a is None:
        return None
    at_b = _mul(_mul(H_b, _at(d["Pi"], b)), d["P1"])
    at_a = _mul(_mul(H_a, _at(d["Pi"], a)), d["P1"])
    top, bottom = d["kernel"][:n], d["kernel"][n:]
    upper, lower = _mul(_mul(_t(top), at_b), top), _mul(_mul(_t(bottom), at_a), bottom)
    return [[x - y for x, y in zip(r, s, strict=True)] for r, s in zip(upper, lower, strict=True)]


def _inequalities(d: dict[str, Any]) -> dict[str, tuple[str, Matrix]]:
    """Recompute the claims: name -> (claim, matrix)."""
    H, Pi, P1, one = d["H"], d["Pi"], _lift(d["P1"]), Fraction(1)
    dH = [[_fderiv(f) for f in row] for row in H]
    dPi = [[_fderiv(f) for f in row] for row in Pi]
    G = _mcomb(
        (-one, _msym(_mmul(_mmul(dPi, P1), H))),
        (one, _msym(_mmul(_mmul(Pi, P1), dH))),
        (2 * one, _msym(_mmul(_mmul(Pi, d["P0"]), H))),
        (2 * d["sigma"], Pi),
    )
    boundary = _boundary(d)
    found = {
        "energy": ("positive", H),
        "lower bound": ("positive", _mcomb((one, Pi), (-d["c1"], H))),
        "upper bound": ("positive", _mcomb((d["c2"], H), (-one, Pi))),
        "pointwise": ("negative", G),
    }
    if boundary is not None:
        found["boundary"] = ("negative", _lift(boundary))
    return found


def _structure(d: dict[str, Any]) -> list[str]:
    n, bad, (a, b) = len(d["H"]), [], d["interval"]
    if not _mequal(d["H"], _mt(d["H"])):
        bad.append("H(z) must be symmetric")
    S = _mmul(_mmul(d["Pi"], _lift(d["P1"])), d["H"])
    if not (_mequal(d["Pi"], _mt(d["Pi"])) and _mequal(S, _mt(S))):
        bad.append(
            "Pi(z) and Pi(z) P1 H(z) must be symmetric for every z (the integration by parts)"
        )
    if any(x != 0 for row in _mul(d["boundary"], d["kernel"]) for x in row):
        bad.append(
            "boundary · kernel ≠ 0: the kernel basis does not satisfy the boundary condition"
        )
    if _rank(d["kernel"]) != n or _rank(d["boundary"]) != n:
        bad.append(f"the boundary matrix and its kernel basis must both have rank n = {n}")
    if not (b > a and d["sigma"] > 0 and d["c1"] > 0 and d["M"] > 0):
        bad.append("b > a, sigma > 0, c1 > 0 and M > 0 are required")
    if _boundary(d) is None:
        bad.append("H(a) or H(b) is singular")
    if d["M"] * d["M"] * d["c1"] < d["c2"]:
        bad.append("M² < c2/c1: the constant M does not follow from the norm bounds")
    return bad


def check_rate_polynomial(section: dict[str, Any]) -> list[str]:
    """Re-check a decay-rate section with a polynomial weight; the failures (empty: verified)."""
    try:
        d = _read(section)
        listed = {
            q["name"]: (q["claim"], _functions(q["matrix"])) for q in section["inequalities"]
        }
    except KeyError as missing:
        return [f"rate: the section is malformed: missing key {missing}"]
    except (TypeError, ValueError, ZeroDivisionError, IndexError) as error:
        return [f"rate: the section is malformed: {error}"]
    failures = [f"rate: {text}" for text in _structure(d)]
    a, b = d["interval"]
    for name, (claim, matrix) in _inequalities(d).items():
        given = listed.get(name)
        if given is None or given[0] != claim or not _mequal(given[1], matrix):
            failures.append(f"rate: inequality '{name}' is missing or differs from its data")
        sign = Fraction(CLAIMS[claim])
        if not _positive_on(_mcomb((sign, matrix)), a, b):
            failures.append(
                f"rate: inequality '{name}': the matrix is not {claim} definite on [a, b]"
            )
    return failures
