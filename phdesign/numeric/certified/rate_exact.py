r"""The exact half of the decay-rate proof: the inequalities, built and checked in the rationals.

For the functional of :mod:`.rate` (its docstring derives everything),

.. math::

    V(x) = \int_a^b x^\top \Pi(z)\, x\, dz, \qquad
    \Pi(z) = t^{-1}\Pi_- + t\,\Pi_+, \quad t = e^{\mu (z - a)}, \quad
    \mu = \frac{\ln \tau}{b - a},

with rational :math:`\Pi_\pm`, :math:`\tau`, :math:`\sigma`, :math:`c_1`, :math:`c_2`,
the decay estimate follows from finitely many strict matrix inequalities, every one
between rational matrices (:func:`inequalities`):

* :math:`\Pi_\pm` and :math:`\Pi_\pm P_1 \mathcal H` symmetric (checked exactly; the
  SDP's unknowns are coordinates in an exact rational basis of that subspace,
  :func:`lyapunov_basis`); :math:`\Pi_\pm` need not be definite each;
* the norm bounds at :math:`s \in \{1, \tau^2\}`,
  :math:`\Pi_- + s\Pi_+ - c_1\tfrac{1+s}{2}\mathcal H \succ 0` and
  :math:`c_2\big(1 + \tfrac{s-1}{\tau+1}\big)\mathcal H - \Pi_- - s\Pi_+ \succ 0`:
  they are affine in :math:`s = t^2`, and :math:`\tfrac{1+s}{2} \ge t \ge
  1 + \tfrac{s-1}{\tau+1}` on :math:`[1, \tau^2]`, so with
  :math:`\Pi(z) = t^{-1}(\Pi_- + s\Pi_+)` they give
  :math:`c_1\mathcal H \prec \Pi(z) \prec c_2\mathcal H` for every :math:`z`;
* the boundary form on the admissible traces
  :math:`K_b^\top \operatorname{diag}\big(\mathcal H^{-1}\Pi(b)P_1,
  -\mathcal H^{-1}\Pi(a)P_1\big) K_b \prec 0`,
  with :math:`\Pi(b) = \tau^{-1}\Pi_- + \tau\Pi_+` and :math:`\Pi(a) = \Pi_- + \Pi_+`;
* the pointwise form :math:`C_-(\mu) + s\,C_+(\mu) \prec 0` at the four corners
  :math:`\mu \in \{\mu_{lo}, \mu_{hi}\}`, :math:`s \in \{1, \tau^2\}`, where
  :math:`\mu_{lo} \le \ln(\tau)/(b - a) \le \mu_{hi}` is a rational enclosure
  (:func:`mu_enclosure`, mpmath's interval logarithm) and

  .. math::

      C_\mp(\mu) = \pm\mu\,\Pi_\mp P_1\mathcal H + \Pi_\mp P_0\mathcal H
      + \mathcal H P_0^\top \Pi_\mp + 2\sigma\,\Pi_\mp .

  :math:`t\,G(z) = C_-(\mu) + t^2 C_+(\mu)` is affine in :math:`s = t^2 \in [1, \tau^2]`
  and in :math:`\mu`, so negative definiteness at the corners covers every
  :math:`z \in [a, b]` and the true :math:`\mu`.

Definiteness is decided by Sylvester's criterion on exact leading principal minors
(sympy's ``DomainMatrix`` over QQ); for a matrix of rational functions of :math:`z`
(the proof of :mod:`.rate_poly`) on all of an interval, by the same criterion with
polynomial minors and Sturm's root count (:func:`positive_on`).  The independent checker
(:mod:`phdesign.proofcheck.rate`) decides it by an LDLᵀ factorization in
:class:`fractions.Fraction`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import sympy
from sympy.polys.matrices import DomainMatrix

from phdesign.numeric.certified.rate_problem import RateProblem

__all__ = [
    "CORNERS",
    "Inequality",
    "LyapunovData",
    "boundary_form",
    "failures",
    "inequalities",
    "lyapunov_basis",
    "mu_enclosure",
    "positive_on",
    "to_fraction",
]

#: The corners (mu end, s end) of the pointwise inequality, in the proof file's names.
CORNERS = (("lo", "1"), ("lo", "tau^2"), ("hi", "1"), ("hi", "tau^2"))


@dataclass(frozen=True)
class Inequality:
    """One matrix inequality of the proof: ``matrix`` is claimed ``claim`` definite.

    With an ``interval``, ``matrix`` is a rational function of ``z`` and the claim is
    for every ``z`` in the closed interval.
    """

    name: str
    claim: str  # "positive" or "negative"
    matrix: sympy.ImmutableMatrix
    meaning: str
    interval: tuple[sympy.Rational, sympy.Rational] | None = None

    @property
    def holds(self) -> bool:
        """Whether the claim holds, by Sylvester's criterion on exact minors."""
        sign = 1 if self.claim == "positive" else -1
        if self.interval is None:
            return _positive_definite(sign * self.matrix)
        return positive_on(sign * self.matrix, self.interval)


@dataclass(frozen=True)
class LyapunovData:
    """The rational unknowns of the proof (see the module docstring)."""

    Pi_minus: sympy.ImmutableMatrix
    Pi_plus: sympy.ImmutableMatrix
    tau: sympy.Rational
    mu: tuple[sympy.Rational, sympy.Rational]
    sigma: sympy.Rational
    c1: sympy.Rational
    c2: sympy.Rational


def to_fraction(value: sympy.Rational) -> Fraction:
    """Return an exact sympy rational as a :class:`fractions.Fraction`."""
    return Fraction(int(value.p), int(value.q))


def _positive_definite(M: sympy.ImmutableMatrix) -> bool:
    dm = DomainMatrix.from_Matrix(sympy.Matrix(M)).convert_to(sympy.QQ)
    n = M.rows
    return all(dm[:k, :k].det() > 0 for k in range(1, n + 1))


def positive_on(M: sympy.MatrixBase, interval: tuple[sympy.Rational, sympy.Rational]) -> bool:
    r"""Whether the symmetric rational-function matrix :math:`M(z) \succ 0` on all of ``interval``.

    With :math:`M = M_p/d` (:math:`d` the least common denominator, :math:`M_p` a
    polynomial matrix), :math:`M(z) \succ 0` for every :math:`z \in [a, b]` iff
    :math:`d` has no zero on :math:`[a, b]` and every leading principal minor
    :math:`m_k` of :math:`\operatorname{sign}(d)\,M_p` is a polynomial without a zero on
    :math:`[a, b]` and positive at :math:`a` (Sylvester's criterion at each z; a
    polynomial that keeps its sign on the interval).  The zeros are counted exactly by
    Sturm's theorem (sympy's ``count_roots``).
    """
    a, b = interval
    z = next(iter(M.free_symbols), sympy.Symbol("z"))
    entries = [sympy.fraction(sympy.cancel(x)) for x in M]
    d = sympy.Poly(sympy.lcm([den for _, den in entries]), z)
    if d.count_roots(a, b) != 0 or M != M.T:
        return False
    sign = 1 if d.eval(a) > 0 else -1
    Mp = sympy.Matrix(M.rows, M.cols, [sign * sympy.cancel(x * d.as_expr()) for x in M])
    ring = sympy.QQ[z]
    dm = DomainMatrix.from_Matrix(Mp).convert_to(ring)
    for k in range(1, M.rows + 1):
        minor = sympy.Poly(ring.to_sympy(dm[:k, :k].det()), z)
        if minor.is_zero or minor.count_roots(a, b) != 0 or minor.eval(a) <= 0:
            return False
    return True


def lyapunov_basis(problem: RateProblem) -> tuple[sympy.ImmutableMatrix, ...]:
    r"""Return a basis of the symmetric Π with :math:`\Pi P_1\mathcal H` symmetric.

    The nullspace of the linear map from the upper triangle of :math:`\Pi` to the
    antisymmetric part of :math:`\Pi P_1 \mathcal H`: over the rationals for a constant
    :math:`\mathcal H`; over the rational functions of :math:`z` for a z-dependent one,
    each vector then multiplied by the least common denominator of its entries, so that
    every :math:`B_k(z)` is a polynomial matrix (:mod:`.rate_poly`).
    """
    n = problem.size
    unknowns = [(i, j) for i in range(n) for j in range(i, n)]
    symbols = sympy.symbols(f"p0:{len(unknowns)}")
    Pi = sympy.zeros(n, n)
    for s, (i, j) in zip(symbols, unknowns, strict=True):
        Pi[i, j] = Pi[j, i] = s
    S = Pi * problem.P1 * problem.H
    rows = [S[i, j] - S[j, i] for i in range(n) for j in range(i + 1, n)]
    A = sympy.Matrix([[sympy.diff(r, s) for s in symbols] for r in rows])
    null = A.nullspace() if rows else [sympy.eye(len(symbols))[:, k] for k in range(len(symbols))]
    null = [_cleared(v, problem.z) if v.has(problem.z) else v for v in null]
    return tuple(
        sympy.ImmutableMatrix(Pi.xreplace(dict(zip(symbols, v, strict=True)))) for v in null
    )


def _cleared(v: sympy.MatrixBase, z: sympy.Symbol) -> sympy.Matrix:
    """``v`` times the least common denominator of its entries (polynomials in ``z``)."""
    v = v.applyfunc(sympy.cancel)
    scale = sympy.lcm([sympy.fraction(x)[1] for x in v])
    return v.applyfunc(lambda x: sympy.expand(sympy.cancel(x * scale)))


def mu_enclosure(
    tau: sympy.Rational, length: sympy.Rational, digits: int = 30
) -> tuple[sympy.Rational, sympy.Rational]:
    r"""Rationals :math:`\mu_{lo} \le \ln(\tau)/\ell \le \mu_{hi}`, about ``10**-digits`` apart.

    mpmath's interval logarithm (200 bits) encloses :math:`\ln\tau`; its endpoints are
    exact binary rationals, rounded outward to ``digits`` decimals.
    """
    from mpmath import iv, mp

    saved, iv.prec = iv.prec, 200  # iv has no workprec; restore what the caller had
    try:
        enclosure = iv.log(iv.mpf(int(tau.p)) / iv.mpf(int(tau.q)))
    finally:
        iv.prec = saved
    lo, hi = (_binary_fraction(mp.make_mpf(end).man_exp) for end in enclosure._mpi_)
    scale = 10**digits
    ell = to_fraction(length)
    # one more unit outward, so the enclosure is at least 10**-digits wider than the truth
    # on each side and a re-check with its own logarithm decides it quickly
    mu_lo = Fraction(math.floor(lo / ell * scale) - 1, scale)
    mu_hi = Fraction(math.ceil(hi / ell * scale) + 1, scale)
    return sympy.Rational(mu_lo.numerator, mu_lo.denominator), sympy.Rational(
        mu_hi.numerator, mu_hi.denominator
    )


def _binary_fraction(man_exp: tuple[int, int]) -> Fraction:
    mantissa, exponent = man_exp
    return Fraction(mantissa) * Fraction(2) ** exponent


def _pointwise(problem: RateProblem, data: LyapunovData, mu: sympy.Rational, s: sympy.Expr):
    A = problem.P1 * problem.H
    B = problem.P0 * problem.H

    def part(Pi: sympy.ImmutableMatrix, sign: int) -> sympy.Matrix:
        return sign * mu * Pi * A + Pi * B + (Pi * B).T + 2 * data.sigma * Pi

    return sympy.ImmutableMatrix(part(data.Pi_minus, 1) + s * part(data.Pi_plus, -1))


def boundary_form(
    problem: RateProblem, Pi_b: sympy.MatrixBase, Pi_a: sympy.MatrixBase
) -> sympy.ImmutableMatrix:
    r"""Return the boundary term of :math:`\dot V` on the admissible traces :math:`v = K_b w`.

    :math:`K_b^\top \operatorname{diag}\big(\mathcal H(b)^{-1}\Pi(b)P_1,
    -\mathcal H(a)^{-1}\Pi(a)P_1\big) K_b`, from ``Pi_b`` :math:`= \Pi(b)` and
    ``Pi_a`` :math:`= \Pi(a)`.
    """
    a, b = problem.interval
    at_b = problem.H.subs(problem.z, b).inv() * Pi_b * problem.P1
    at_a = problem.H.subs(problem.z, a).inv() * Pi_a * problem.P1
    form = sympy.diag(at_b, -at_a)
    return sympy.ImmutableMatrix(problem.kernel.T * form * problem.kernel)


def _boundary(problem: RateProblem, data: LyapunovData) -> sympy.ImmutableMatrix:
    Pi_b = data.Pi_minus / data.tau + data.tau * data.Pi_plus
    return boundary_form(problem, Pi_b, data.Pi_minus + data.Pi_plus)


def inequalities(problem: RateProblem, data: LyapunovData) -> tuple[Inequality, ...]:
    """Every matrix inequality the decay estimate rests on (the module docstring's list)."""
    H, tau = problem.H, data.tau
    found = []
    for s_end, s in (("1", sympy.Integer(1)), ("tau^2", tau**2)):
        weighted = data.Pi_minus + s * data.Pi_plus
        chord = 1 + (s - 1) / (tau + 1)  # ≤ √s on [1, τ²]
        found += [
            Inequality(
                f"lower bound s={s_end}",
                "positive",
                sympy.ImmutableMatrix(weighted - data.c1 * (1 + s) / 2 * H),
                f"Π₋ + sΠ₊ − c₁(1 + s)/2 H ≻ 0 at s = {s_end}, so Π(z) ≻ c₁H",
            ),
            Inequality(
                f"upper bound s={s_end}",
                "positive",
                sympy.ImmutableMatrix(data.c2 * chord * H - weighted),
                f"c₂(1 + (s − 1)/(τ + 1))H − Π₋ − sΠ₊ ≻ 0 at s = {s_end}, so Π(z) ≺ c₂H",
            ),
        ]
    found += [
        Inequality(
            "boundary",
            "negative",
            _boundary(problem, data),
            "K_bᵀ diag(H⁻¹Π(b)P₁, −H⁻¹Π(a)P₁) K_b ≺ 0: the boundary term of dV/dt",
        ),
    ]
    ends = {"lo": data.mu[0], "hi": data.mu[1]}
    for mu_end, s_end in CORNERS:
        s = sympy.Integer(1) if s_end == "1" else tau**2
        found.append(
            Inequality(
                f"pointwise mu={mu_end} s={s_end}",
                "negative",
                _pointwise(problem, data, ends[mu_end], s),
                f"C₋(μ_{mu_end}) + s C₊(μ_{mu_end}) ≺ 0 at s = {s_end}: dV/dt + 2σV inside",
            )
        )
    return tuple(found)


def failures(problem: RateProblem, data: LyapunovData) -> list[str]:
    """Return what fails of the exact proof (empty: every inequality and identity holds)."""
    found = [f"{q.name}: {q.meaning} fails" for q in inequalities(problem, data) if not q.holds]
    for label, Pi in (("Pi_minus", data.Pi_minus), ("Pi_plus", data.Pi_plus)):
        if Pi != Pi.T or (Pi * problem.P1 * problem.H) != (Pi * problem.P1 * problem.H).T:
            found.append(f"{label}: Π and Π P₁ H must be symmetric")
    if not (data.sigma > 0 and data.c1 > 0 and data.tau > 1 and data.mu[0] <= data.mu[1]):
        found.append("σ > 0, c₁ > 0, τ > 1 and μ_lo ≤ μ_hi are required")
    return found
