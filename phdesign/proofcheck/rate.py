r"""Re-check a decay-rate proof in exact rationals, with the standard library alone.

The section written by :meth:`phdesign.numeric.certified.rate.DecayRateProof.to_json`
claims :math:`\|\tilde x(t)\| \le M e^{-\sigma t}\|\tilde x(0)\|` in the energy norm for
the closed system :math:`\partial_t x = P_1\mathcal H x_z + P_0\mathcal H x`,
:math:`\mathcal B (e(b); e(a)) = 0`, by the functional
:math:`V = \int_a^b x^\top(t^{-1}\Pi_- + t\Pi_+)x\,dz`, :math:`t = e^{\mu(z-a)}`,
:math:`\mu = \ln\tau/(b-a)`.  This module recomputes every matrix the claim rests on
from the section's primitive data and decides each inequality itself, sharing no code
with the prover (which uses sympy and mpmath):

* definiteness by an LDLᵀ factorization in :class:`fractions.Fraction` (every pivot
  positive);
* :math:`\ln\tau` by the series :math:`\ln\tau = k\ln 2 + 2\operatorname{artanh}
  \frac{r-1}{r+1}`, :math:`r = \tau/2^k \in [1, 2)`, with its tail bounded by a
  geometric series, until it decides :math:`(b-a)\mu_{lo} \le \ln\tau \le
  (b-a)\mu_{hi}`;
* the kernel: :math:`\mathcal B K_b = 0` and both of rank :math:`n`, by elimination.

The listed inequalities must be exactly the recomputed ones (a tampered matrix or a
missing one is reported).  :func:`check_rate` returns the failures; empty means verified.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

__all__ = ["check_rate"]

Matrix = list[list[Fraction]]
CLAIMS = {"positive": 1, "negative": -1}
LOG_TERMS_CAP = 400


# --------------------------------------------------------------------------- arithmetic
def _mul(A: Matrix, B: Matrix) -> Matrix:
    return [
        [
            sum((a * b for a, b in zip(row, col, strict=True)), Fraction(0))
            for col in zip(*B, strict=True)
        ]
        for row in A
    ]


def _add(*terms: tuple[Fraction, Matrix]) -> Matrix:
    rows, cols = len(terms[0][1]), len(terms[0][1][0])
    return [
        [sum((c * M[i][j] for c, M in terms), Fraction(0)) for j in range(cols)]
        for i in range(rows)
    ]


def _t(A: Matrix) -> Matrix:
    return [list(col) for col in zip(*A, strict=True)]


def _eye(n: int) -> Matrix:
    return [[Fraction(int(i == j)) for j in range(n)] for i in range(n)]


def _positive_definite(A: Matrix) -> bool:
    """LDLᵀ without pivoting: a symmetric A is positive definite iff every pivot is > 0."""
    if _t(A) != A:
        return False
    W = [row[:] for row in A]
    for k in range(len(W)):
        if W[k][k] <= 0:
            return False
        for i in range(k + 1, len(W)):
            factor = W[i][k] / W[k][k]
            for j in range(k, len(W)):
                W[i][j] -= factor * W[k][j]
    return True


def _rank(A: Matrix) -> int:
    W, rank = [row[:] for row in A], 0
    for col in range(len(W[0]) if W else 0):
        pivot = next((r for r in range(rank, len(W)) if W[r][col] != 0), None)
        if pivot is None:
            continue
        W[rank], W[pivot] = W[pivot], W[rank]
        for r in range(len(W)):
            if r != rank and W[r][col] != 0:
                f = W[r][col] / W[rank][col]
                W[r] = [x - f * y for x, y in zip(W[r], W[rank], strict=True)]
        rank += 1
    return rank


def _artanh_bounds(y: Fraction, terms: int) -> tuple[Fraction, Fraction]:
    """Bounds of artanh(y), 0 <= y < 1: the partial sum and its tail's geometric bound."""
    total, power = Fraction(0), y
    for k in range(terms):
        total += power / (2 * k + 1)
        power *= y * y
    return total, total + power / ((2 * terms + 1) * (1 - y * y))


def _log_decides(tau: Fraction, low: Fraction, high: Fraction) -> bool:
    """Whether low <= ln(tau) <= high, for tau >= 1, deciding with more terms as needed."""
    halvings, r = 0, tau
    while r >= 2:
        r, halvings = r / 2, halvings + 1
    terms = 16
    while terms <= LOG_TERMS_CAP:
        lo2, hi2 = _artanh_bounds(Fraction(1, 3), terms)  # ln 2 = 2 artanh(1/3)
        lor, hir = _artanh_bounds((r - 1) / (r + 1), terms)
        lo, hi = 2 * (halvings * lo2 + lor), 2 * (halvings * hi2 + hir)
        if low <= lo and hi <= high:
            return True
        if hi < low or lo > high:
            return False
        terms *= 2
    return False


# --------------------------------------------------------------------------- reading
def _q(text: Any) -> Fraction:
    if not isinstance(text, str):
        raise TypeError(f"expected a 'p/q' string, found {text!r}")
    return Fraction(text)


def _m(rows: Any) -> Matrix:
    matrix = [[_q(x) for x in row] for row in rows]
    if not matrix or any(len(row) != len(matrix[0]) for row in matrix):
        raise ValueError("a matrix must be a non-empty list of rows of equal length")
    return matrix


def _read(section: dict[str, Any]) -> dict[str, Any]:
    matrices = ("H", "H_inv", "P0", "P1", "boundary", "kernel", "Pi_minus", "Pi_plus")
    scalars = ("tau", "sigma", "c1", "c2", "M")
    data: dict[str, Any] = {k: _m(section[k]) for k in matrices}
    data.update({k: _q(section[k]) for k in scalars})
    data["mu"] = [_q(m) for m in section["mu"]]
    data["interval"] = [_q(e) for e in section["interval"]]
    n = len(data["H"])
    shapes = dict.fromkeys(("H", "H_inv", "P0", "P1", "Pi_minus", "Pi_plus"), (n, n))
    shapes.update(boundary=(n, 2 * n), kernel=(2 * n, n))
    for key, shape in shapes.items():
        found = (len(data[key]), len(data[key][0]))
        if found != shape:
            raise ValueError(
                f"{key} must be {shape[0]} x {shape[1]}; found {found[0]} x {found[1]}"
            )
    if len(data["mu"]) != 2 or len(data["interval"]) != 2:
        raise ValueError("mu and interval must hold two rationals each")
    return data


# --------------------------------------------------------------------------- the claims
def _pointwise(d: dict[str, Any], mu: Fraction, s: Fraction) -> Matrix:
    A, B = _mul(d["P1"], d["H"]), _mul(d["P0"], d["H"])
    two_sigma = 2 * d["sigma"]

    def part(Pi: Matrix, sign: int) -> Matrix:
        PiB = _mul(Pi, B)
        one = Fraction(1)
        return _add((sign * mu, _mul(Pi, A)), (one, PiB), (one, _t(PiB)), (two_sigma, Pi))

    return _add((Fraction(1), part(d["Pi_minus"], 1)), (s, part(d["Pi_plus"], -1)))


def _boundary(d: dict[str, Any]) -> Matrix:
    n, tau, one = len(d["H"]), d["tau"], Fraction(1)
    at_b = _mul(_mul(d["H_inv"], _add((1 / tau, d["Pi_minus"]), (tau, d["Pi_plus"]))), d["P1"])
    at_a = _mul(_mul(d["H_inv"], _add((one, d["Pi_minus"]), (one, d["Pi_plus"]))), d["P1"])
    top, bottom = d["kernel"][:n], d["kernel"][n:]
    return _add(
        (one, _mul(_mul(_t(top), at_b), top)), (-one, _mul(_mul(_t(bottom), at_a), bottom))
    )


def _inequalities(d: dict[str, Any]) -> dict[str, tuple[str, Matrix]]:
    """Recompute the claims: name -> (claim, matrix)."""
    tau, one = d["tau"], Fraction(1)
    Pm, Pp, H = d["Pi_minus"], d["Pi_plus"], d["H"]
    found: dict[str, tuple[str, Matrix]] = {}
    for s_end, s in (("1", one), ("tau^2", tau * tau)):
        # Π(z) = t⁻¹(Π₋ + sΠ₊), s = t²: (1 + s)/2 ≥ √s ≥ the chord 1 + (s − 1)/(τ + 1)
        lower = _add((one, Pm), (s, Pp), (-d["c1"] * (1 + s) / 2, H))
        upper = _add((d["c2"] * (1 + (s - 1) / (tau + 1)), H), (-one, Pm), (-s, Pp))
        found[f"lower bound s={s_end}"] = ("positive", lower)
        found[f"upper bound s={s_end}"] = ("positive", upper)
    found["boundary"] = ("negative", _boundary(d))
    for mu_end, mu in (("lo", d["mu"][0]), ("hi", d["mu"][1])):
        for s_end, s in (("1", one), ("tau^2", tau * tau)):
            found[f"pointwise mu={mu_end} s={s_end}"] = ("negative", _pointwise(d, mu, s))
    return found


def _structure(d: dict[str, Any]) -> list[str]:
    """Check the identities and scalar conditions the derivation uses."""
    n, bad = len(d["H"]), []
    if not _positive_definite(d["H"]):
        bad.append("H must be symmetric positive definite (it defines the energy norm)")
    if _mul(d["H"], d["H_inv"]) != _eye(n):
        bad.append("H_inv is not the inverse of H")
    if any(x != 0 for row in _mul(d["boundary"], d["kernel"]) for x in row):
        bad.append(
            "boundary · kernel ≠ 0: the kernel basis does not satisfy the boundary condition"
        )
    if _rank(d["kernel"]) != n or _rank(d["boundary"]) != n:
        bad.append(f"the boundary matrix and its kernel basis must both have rank n = {n}")
    for key in ("Pi_minus", "Pi_plus"):
        S = _mul(_mul(d[key], d["P1"]), d["H"])
        if d[key] != _t(d[key]) or _t(S) != S:
            bad.append(f"{key} and {key} P1 H must be symmetric (the integration by parts)")
    a, b = d["interval"]
    if not (b > a and d["tau"] > 1 and d["sigma"] > 0 and d["c1"] > 0 and d["M"] > 0):
        bad.append("b > a, tau > 1, sigma > 0, c1 > 0 and M > 0 are required")
    elif not _log_decides(d["tau"], (b - a) * d["mu"][0], (b - a) * d["mu"][1]):
        bad.append("mu = ln(tau)/(b - a) is not inside the interval [mu_lo, mu_hi] given")
    if d["M"] * d["M"] * d["c1"] < d["c2"]:
        bad.append("M² < c2/c1: the constant M does not follow from the norm bounds")
    return bad


def check_rate(section: dict[str, Any]) -> list[str]:
    """Re-check a decay-rate section; the failures (empty: the rate is verified).

    Examples
    --------
    >>> check_rate({"kind": "decay rate"})[0]
    "rate: the section is malformed: missing key 'H'"
    """
    try:
        d = _read(section)
        listed = {q["name"]: (q["claim"], _m(q["matrix"])) for q in section["inequalities"]}
    except KeyError as missing:
        return [f"rate: the section is malformed: missing key {missing}"]
    except (TypeError, ValueError, ZeroDivisionError, IndexError) as error:
        return [f"rate: the section is malformed: {error}"]
    failures = [f"rate: {text}" for text in _structure(d)]
    for name, (claim, matrix) in _inequalities(d).items():
        if listed.get(name) != (claim, matrix):
            failures.append(f"rate: inequality '{name}' is missing or differs from its data")
        sign = Fraction(CLAIMS[claim])
        if not _positive_definite(_add((sign, matrix))):
            failures.append(f"rate: inequality '{name}': the matrix is not {claim} definite")
    return failures
