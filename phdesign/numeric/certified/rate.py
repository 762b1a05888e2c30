r"""A proved decay rate for first-order closed systems: a Lyapunov functional checked exactly.

For an :math:`N = 1` closed system with constant coefficients (strings, Timoshenko
beams, coupled strings, transport; :mod:`.rate_problem`; for :math:`z`-dependent
:math:`\mathcal H(z)`, :math:`P_0(z)` the functional has a polynomial weight instead,
:mod:`.rate_poly`),

.. math::

    \partial_t x = P_1 \mathcal H\, \partial_z x + P_0 \mathcal H x, \qquad
    \mathcal B\, (e(b); e(a)) = 0, \qquad e = \mathcal H x ,

take the Bastin–Coron functional with exponential weights

.. math::

    V(x) = \int_a^b x^\top \Pi(z)\, x\, dz, \qquad
    \Pi(z) = e^{-\mu(z-a)}\Pi_- + e^{\mu(z-a)}\Pi_+, \qquad
    \Pi_\pm P_1 \mathcal H = (\Pi_\pm P_1 \mathcal H)^\top .

On the Riemann invariants of a string the weight :math:`e^{-\mu z}` goes with the wave
travelling to the right and :math:`e^{\mu z}` with the one travelling to the left, so a
reflection at an end (a damper) meets a heavier weight on the way in than on the way
out: the boundary term becomes dissipative.  With :math:`S = \Pi P_1 \mathcal H`
symmetric, :math:`2 x^\top S x_z = (x^\top S x)_z - x^\top S_z x`, so along classical
solutions

.. math::

    \dot V + 2\sigma V = \Big[x^\top S x\Big]_a^b + \int_a^b x^\top G(z)\, x\, dz ,
    \qquad G = -\Pi' P_1\mathcal H + \Pi P_0 \mathcal H + \mathcal H P_0^\top \Pi
    + 2\sigma \Pi .

The boundary term is the quadratic form :math:`v^\top \operatorname{diag}(\mathcal
H^{-1}\Pi(b) P_1, -\mathcal H^{-1}\Pi(a) P_1)\, v` (with :math:`x = \mathcal H^{-1}e`)
on the admissible traces :math:`v = K_b w`; and :math:`e^{\mu(z-a)} G(z) = C_-(\mu) +
e^{2\mu(z-a)} C_+(\mu)` (:mod:`.rate_exact`).  If the boundary form and :math:`G` are
negative definite, :math:`\dot V \le -2\sigma V`; with :math:`c_1 \|x\|^2 \le V \le c_2
\|x\|^2` in the energy norm :math:`\|x\|^2 = \int_a^b x^\top \mathcal H x\, dz` (twice
the Hamiltonian)

.. math::

    \|\tilde x(t)\| \le M e^{-\sigma t} \|\tilde x(0)\|, \qquad M \ge \sqrt{c_2/c_1} .

:func:`prove_decay_rate` finds :math:`\Pi_\pm, \tau = e^{\mu(b-a)}, \sigma` by the SDP
of :mod:`.rate_sdp`, rounds them to rationals, and proves every inequality exactly
(:mod:`.rate_exact`); the numbers it prints are proved, not the solver's claim.  The
proof file (:meth:`DecayRateProof.to_json`) is re-checked by
:mod:`phdesign.proofcheck.rate` with the standard library alone.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import Any

import sympy

from phdesign.core.checks import choice
from phdesign.core.errors import RateProofError
from phdesign.numeric.certified.exact_system import ExactClosedSystem
from phdesign.numeric.certified.rate_exact import (
    Inequality,
    LyapunovData,
    failures,
    inequalities,
    lyapunov_basis,
    mu_enclosure,
    to_fraction,
)
from phdesign.numeric.certified.rate_poly import PolynomialLyapunov, polynomial_basis
from phdesign.numeric.certified.rate_problem import RateProblem, read_system
from phdesign.numeric.certified.rate_sdp import Candidate, LyapunovProgram, search

__all__ = [
    "ASSUMPTIONS",
    "POLYNOMIAL_ASSUMPTIONS",
    "DecayRateProof",
    "prove_decay_rate",
    "prove_rate",
]

#: What every proved rate rests on besides the exact inequalities.
ASSUMPTIONS = (
    "the closed system is the model's PDE with the exact matrices read here (parameter "
    "defaults substituted) and constant H and P0",
    "the closed boundary condition generates a C0 contraction semigroup on the energy "
    "space (Le Gorrec, Zwart and Maschke, SIAM J. Control Optim. 44, 2005: a dissipative "
    "boundary of full rank); dV/dt is computed on classical solutions (initial states in "
    "the generator's domain) and the estimate extends to every initial state by density",
    "the norm is the energy norm ‖x‖² = ∫ xᵀ H x dz (twice the Hamiltonian)",
)
#: The same for z-dependent coefficients (:mod:`.rate_poly`).
POLYNOMIAL_ASSUMPTIONS = (
    "the closed system is the model's PDE with the exact matrices read here (parameter "
    "defaults substituted): H(z) and P0(z) the rational functions of z written, smooth on "
    "[a, b] (the proof shows that no denominator vanishes there)",
    "the closed boundary condition generates a C0 semigroup on the energy space (Le Gorrec, "
    "Zwart and Maschke, SIAM J. Control Optim. 44, 2005, for z-dependent H; a z-dependent "
    "P0 is a bounded perturbation, Pazy 1983, Thm 3.1.1); dV/dt is computed on classical "
    "solutions and the estimate extends to every initial state by density",
    ASSUMPTIONS[2],
)
RETRIES = 5
#: The Lyapunov weights of :func:`prove_decay_rate`.
WEIGHTS = ("best", "exponential", "polynomial")
TAU_DENOMINATOR = 1000
SIGMA_DIGITS = 6


@dataclass(frozen=True)
class DecayRateProof:
    r"""A proved estimate :math:`\|\tilde x(t)\| \le M e^{-\sigma t}\|\tilde x(0)\|`.

    Attributes
    ----------
    problem : RateProblem
        The exact closed system the proof is about.
    sigma, M : fractions.Fraction
        The proved rate and constant.
    data : LyapunovData or PolynomialLyapunov
        :math:`\Pi_\pm`, :math:`\tau`, the enclosure of :math:`\mu`, :math:`\sigma`,
        :math:`c_1`, :math:`c_2` (exact rationals); for z-dependent coefficients the
        polynomial :math:`\Pi(z)`, :math:`\sigma`, :math:`c_1`, :math:`c_2`.
    inequalities : tuple of Inequality
        Every matrix inequality checked (all hold, exactly).
    assumptions : tuple of str
        What the estimate assumes besides them.
    abscissa : float or None
        A spectral abscissa to compare with (:meth:`compared`), and its source.
    """

    problem: RateProblem
    sigma: Fraction
    M: Fraction
    data: LyapunovData | PolynomialLyapunov
    inequalities: tuple[Inequality, ...]
    assumptions: tuple[str, ...] = ASSUMPTIONS
    abscissa: float | None = None
    abscissa_source: str = ""

    @property
    def conservatism(self) -> float | None:
        r""":math:`\sigma / |\alpha|` against the abscissa compared with (1 is exact)."""
        if self.abscissa is None or self.abscissa >= 0:
            return None
        return float(self.sigma) / abs(self.abscissa)

    def compared(self, abscissa: float, source: str) -> DecayRateProof:
        """Return a copy that prints σ/|α| against ``abscissa`` (and its ``source``)."""
        return replace(self, abscissa=float(abscissa), abscissa_source=source)

    def to_json(self) -> dict[str, Any]:
        """Everything the independent checker needs, exact rationals as "p/q" strings."""
        from phdesign.numeric.certified.rate_json import proof_json

        return proof_json(self)

    def __str__(self) -> str:
        """Return the text ``phdesign certify --rate`` prints."""
        from phdesign.numeric.certified.rate_json import proof_text

        return proof_text(self)


def prove_decay_rate(
    system: ExactClosedSystem, *, target: float | None = None, weight: str = "best"
) -> DecayRateProof:
    r"""Prove :math:`\|\tilde x(t)\| \le M e^{-\sigma t}\|\tilde x(0)\|` for a closed system.

    Parameters
    ----------
    system : ExactClosedSystem
        The exact closed plant or error system (:func:`~.exact_system.closed_system`), of
        order 1 with rational coefficients (:math:`H`, :math:`P_0`: rational functions of
        z allowed).
    target : float, optional
        Prove this rate (rounded down to 6 decimals) instead of the best one found.
    weight : {"best", "exponential", "polynomial"}
        The Lyapunov weight Π(z): the exponential one of Bastin and Coron
        (:math:`t^{-1}\Pi_- + t\Pi_+`, constant coefficients only), the polynomial one
        (:mod:`.rate_poly`, decided exactly by Sturm sequences), or ``"best"``: for
        constant coefficients both, keeping the larger proved σ (on strings they agree to
        2e-4; on the Timoshenko beam with tip dampers the polynomial weight proves twice
        the exponential one's σ), with a ``target`` the first that proves it; for
        z-dependent ones the polynomial weight.

    Raises
    ------
    ArgumentError
        ``system`` is not an :class:`~.exact_system.ExactClosedSystem`.
    RateProofError
        Order 2 or more (the message says what is proved instead: the spectral bound),
        an irrational coefficient or one that is not a rational function of z, no
        functional found, or ``target`` out of reach.

    Examples
    --------
    The string with the damper :math:`e_2(1) = -\tfrac12 e_1(1)`, whose every mode
    decays like :math:`e^{-t\ln(3)/2}`, :math:`\ln(3)/2 \approx 0.5493`:

    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.certified.exact_system import closed_system
    >>> proof = prove_decay_rate(closed_system(load_builtin("wave-damper")), target=0.5)
    >>> proof.sigma
    Fraction(1, 2)
    """
    return prove_rate(read_system(system), target=target, weight=weight)


def prove_rate(
    problem: RateProblem, *, target: float | None = None, weight: str = "best"
) -> DecayRateProof:
    """Find and prove exactly the best rate of ``weight`` (or ``target``); see prove_decay_rate.

    Raises
    ------
    RateProofError
        An unknown ``weight``, the exponential weight for z-dependent coefficients, the
        SDP finds no functional, ``target`` is out of reach, or the rounded solution fails
        the exact check ``RETRIES`` times (each retry lowers σ).
    """
    choice(weight, "weight", WEIGHTS, RateProofError)
    if target is not None and not (math.isfinite(target) and target > 0):
        raise RateProofError(f"target must be a finite positive rate; found {target!r}")
    if not problem.constant:
        if weight == "exponential":
            raise RateProofError(
                f"{problem.name}: the exponential weight needs constant H and P0; H or P0 "
                "depends on z here: use weight 'polynomial' (or 'best')"
            )
        return _prove_polynomial(problem, target)
    if weight != "best":
        return (_prove_exponential if weight == "exponential" else _prove_polynomial)(
            problem, target
        )
    proofs, refusals = [], []
    for prove in (_prove_exponential, _prove_polynomial):
        try:
            proofs.append(prove(problem, target))
        except RateProofError as error:
            refusals.append(str(error))
        if proofs and target is not None:
            break  # the target is proved: another weight cannot prove more of it
    if not proofs:
        raise RateProofError(" / ".join(refusals))
    return max(proofs, key=lambda proof: proof.sigma)


def _prove_exponential(problem: RateProblem, target: float | None) -> DecayRateProof:
    """Prove the constant case with the Bastin–Coron weight: search, round, decide exactly."""
    basis = lyapunov_basis(problem)
    program = LyapunovProgram(problem, basis)
    best_tau, best_sigma = search(program, target)
    tau = sympy.Rational(Fraction(best_tau).limit_denominator(TAU_DENOMINATOR))
    # the bisection's σ sits on the feasibility boundary: step inside before rounding
    sigma = _round_down(best_sigma if target is not None else best_sigma * (1 - 1e-4))

    def rounded(sigma: sympy.Rational, attempt: int) -> LyapunovData | None:
        candidate = program.solve(float(tau), float(sigma))
        return None if candidate is None else _rational_data(problem, basis, candidate, tau, sigma)

    return _first_proved(problem, sigma, target, rounded, "the SDP is infeasible at the rounded τ")


def _first_proved(
    problem: RateProblem,
    sigma: sympy.Rational,
    target: float | None,
    rounded: Callable[[sympy.Rational, int], Any],
    infeasible: str,
) -> DecayRateProof:
    """Prove the first of up to ``RETRIES`` rounded solutions that the exact check passes.

    ``rounded(σ, attempt)`` is the rational data of the SDP's solution at σ (``None``:
    infeasible); each retry lowers σ (a ``target`` is tried once).

    Raises
    ------
    RateProofError
        Every attempt fails the exact check (the last failures are named).
    """
    from phdesign.numeric.certified.rate_poly import failures as polynomial_failures

    last: list[str] = []
    for attempt in range(RETRIES):
        data = rounded(sigma, attempt)
        if data is not None:
            found = failures if isinstance(data, LyapunovData) else polynomial_failures
            last = found(problem, data)
            if not last:
                return _proof(problem, data)
        if target is not None:
            break
        sigma = _round_down(float(sigma) * (1 - 1e-3 * 4**attempt))
    raise RateProofError(
        f"{problem.name}: the SDP's functional, rounded to rationals, fails the exact "
        f"check ({'; '.join(last) or infeasible}); no rate is claimed"
    )


def _prove_polynomial(problem: RateProblem, target: float | None) -> DecayRateProof:
    """Prove with the polynomial weight (:mod:`.rate_poly`): search, round, decide exactly.

    Any first-order problem; the only weight for z-dependent coefficients.
    """
    from phdesign.numeric.certified.rate_poly_sdp import PolynomialProgram, search_polynomial

    basis = polynomial_basis(problem)
    program = PolynomialProgram(problem, basis)
    found = search_polynomial(program, target)

    def rounded(sigma: sympy.Rational, attempt: int) -> PolynomialLyapunov | None:
        # the first attempt keeps the search's solution: a rounded-down σ stays feasible
        # (lowering σ subtracts 2Δσ Π ≻ 0 from G)
        candidate = found if attempt == 0 else program.solve(float(sigma))
        if candidate is None:
            return None
        if attempt:  # the constants c₁, c₂ that the fine grid asks for
            candidate = program.violations(candidate)[1]
        Pi = _combine(problem, basis, candidate.coordinates, 2**36)
        c1 = sympy.Rational(math.floor(candidate.c1 * 10**9), 10**9)
        return PolynomialLyapunov(Pi, sigma, c1, _round_up(candidate.c2))

    return _first_proved(
        problem, _round_down(found.sigma), target, rounded, "the SDP is infeasible"
    )


def _combine(
    problem: RateProblem,
    basis: tuple[sympy.ImmutableMatrix, ...],
    coordinates: tuple[float, ...],
    common: int | None = None,
) -> sympy.ImmutableMatrix:
    """Return the rational combination of ``basis`` near the float ``coordinates``.

    Each coordinate is the nearest rational of denominator at most 2⁴⁰, or with
    ``common`` the nearest multiple of ``1/common`` (one denominator keeps the
    polynomial weight's coefficients short).
    """

    def rational(c: float) -> sympy.Rational:
        if common is None:
            return sympy.Rational(Fraction(c).limit_denominator(2**40))
        return sympy.Rational(round(c * common), common)

    total = sympy.zeros(problem.size, problem.size)
    for c, E in zip(coordinates, basis, strict=True):
        total += rational(c) * E
    return sympy.ImmutableMatrix(total.applyfunc(sympy.expand))


def _round_up(c2: float) -> sympy.Rational:
    return sympy.Rational(math.ceil(c2 * 10**9), 10**9)


def _round_down(value: float) -> sympy.Rational:
    scale = 10**SIGMA_DIGITS
    return sympy.Rational(math.floor(value * scale), scale)


def _rational_data(
    problem: RateProblem,
    basis: tuple[sympy.ImmutableMatrix, ...],
    found: Candidate,
    tau: sympy.Rational,
    sigma: sympy.Rational,
) -> LyapunovData:
    mu = mu_enclosure(tau, problem.length)
    Pi_minus, Pi_plus = (_combine(problem, basis, c) for c in (found.minus, found.plus))
    one = sympy.Integer(1)
    return LyapunovData(Pi_minus, Pi_plus, tau, mu, sigma, one, _round_up(found.c2))


def _proof(problem: RateProblem, data: LyapunovData | PolynomialLyapunov) -> DecayRateProof:
    ratio = to_fraction(data.c2) / to_fraction(data.c1)
    M = Fraction(math.ceil(math.sqrt(ratio) * 10**6), 10**6)
    while ratio > M * M:  # round up: M ≥ √(c₂/c₁), exactly
        M += Fraction(1, 10**6)
    if isinstance(data, PolynomialLyapunov):
        from phdesign.numeric.certified.rate_poly import inequalities as polynomial_inequalities

        checked = polynomial_inequalities(problem, data)
    else:
        checked = inequalities(problem, data)
    return DecayRateProof(
        problem=problem,
        sigma=to_fraction(data.sigma),
        M=M,
        data=data,
        inequalities=checked,
        assumptions=ASSUMPTIONS if problem.constant else POLYNOMIAL_ASSUMPTIONS,
    )
