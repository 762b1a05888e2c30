r"""The numeric half of the z-dependent decay-rate proof: an SDP on a grid, refined.

The unknowns are the coordinates :math:`c` of :math:`\Pi(z)` in the basis
:math:`E_i(z) = T_j(\zeta) B_k(z)` of :func:`.rate_poly.polynomial_basis`, and
:math:`c_2` (:math:`c_1 = 1` fixes the scale).  Every inequality of :mod:`.rate_poly` is
linear in them at a fixed :math:`\sigma`, so at the points :math:`z_g` of a grid

.. math::

    \Pi(z_g) \succeq (1 + \epsilon)\mathcal H(z_g), \quad
    \Pi(z_g) \preceq (c_2 - \epsilon)\mathcal H(z_g), \quad
    G(z_g) \preceq -\epsilon\,\mathcal H(z_g), \quad
    K_b^\top \operatorname{diag}(\dots) K_b \preceq -\epsilon I

(:math:`\epsilon = 10^{-5}`) is a semidefinite program (cvxpy, Clarabel; SCS as the
fallback), with :math:`\sigma`
a cvxpy parameter so that a bisection re-solves without recompiling.  A grid is not
:math:`[a, b]`: after each solve the three pointwise forms are evaluated on a fine grid
(in floats), the points where one is violated join the grid, and the program is solved
again (a cutting-plane loop) until the fine check passes.  The exact proof on all of
:math:`[a, b]` is :mod:`.rate_poly`'s; this module only proposes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import sympy

from phdesign.core.errors import RateProofError
from phdesign.numeric.certified.rate_exact import boundary_form
from phdesign.numeric.certified.rate_poly import interior_form
from phdesign.numeric.certified.rate_problem import RateProblem
from phdesign.numeric.certified.rate_sdp import (
    MARGIN,
    largest_feasible,
    require_reached,
    solved,
)

__all__ = ["PolynomialCandidate", "PolynomialProgram", "search_polynomial"]

#: Chebyshev points of the first grid, points of the fine check, cutting-plane rounds.
GRID = 32
FINE = 801
ROUNDS = 16
#: The grid's margin: ten times the constant case's, it absorbs the dips between grid
#: points (on the test strings no refinement is then needed; with 10⁻⁶ three were).
GRID_MARGIN = 10 * MARGIN
#: The fine check asks for half the constant case's margin; at most this many points join.
NEW_POINTS = 8


@dataclass(frozen=True)
class PolynomialCandidate:
    """A numeric solution: the coordinates of Π in the basis, c₂ (and c₁), and its σ."""

    sigma: float
    coordinates: tuple[float, ...]
    c2: float
    c1: float = 1.0


def _values(M: sympy.MatrixBase, z: sympy.Symbol) -> Callable[[np.ndarray], np.ndarray]:
    """``M(z)`` (rational functions) as a function of an array of points: ``(m, n, n)``."""
    entries = []
    for x in M:
        num, den = sympy.fraction(sympy.cancel(x))
        entries.append(
            tuple(np.array(sympy.Poly(p, z).all_coeffs(), dtype=float) for p in (num, den))
        )

    def at(zs: np.ndarray) -> np.ndarray:
        flat = [np.polyval(num, zs) / np.polyval(den, zs) for num, den in entries]
        return np.stack(flat, axis=-1).reshape(len(zs), M.rows, M.cols)

    return at


def _sym(X: Any) -> Any:
    return (X + X.T) / 2


class PolynomialProgram:
    """The grid SDP of the module docstring for a problem and a basis."""

    def __init__(self, problem: RateProblem, basis: tuple[sympy.ImmutableMatrix, ...]) -> None:
        z = problem.z
        a, b = (float(e) for e in problem.interval)
        self.interval = (a, b)
        self.size = problem.size
        self._pi = [_values(E, z) for E in basis]
        self._interior = [_values(interior_form(problem, E), z) for E in basis]
        self._H = _values(problem.H, z)
        self._boundary = [
            np.array(boundary_form(problem, E.subs(z, b), E.subs(z, a)).tolist(), dtype=float)
            for E in basis
        ]
        nodes = np.cos(np.pi * np.arange(GRID) / (GRID - 1))
        self.grid = np.sort(a + (b - a) * (1 - nodes) / 2)
        speed = max(
            abs(np.linalg.eigvals(_floats(problem.P1) @ H)).max() for H in self._H(self.grid)
        )
        self.start = speed / (
            b - a
        )  # a first σ of the bisection (the constant case's with ln τ = 1)
        self._compile()

    def _stacks(self, zs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return Π_i, (G − 2σΠ)_i and H at the points: ``(d, m, n, n)`` twice, ``(m, n, n)``."""
        return (
            np.stack([f(zs) for f in self._pi]),
            np.stack([f(zs) for f in self._interior]),
            self._H(zs),
        )

    def _compile(self) -> None:
        import cvxpy as cp

        Pi, interior, H = self._stacks(self.grid)
        d, eps = Pi.shape[0], GRID_MARGIN
        self.coordinates, self.c2 = cp.Variable(d), cp.Variable()
        self.two_sigma = cp.Parameter(name="two_sigma")
        c = self.coordinates

        def combined(stack: np.ndarray) -> Any:  # Σ_i c_i stack_i as one affine expression
            return _sym(
                cp.reshape(
                    stack.reshape(d, -1).T @ c, (stack.shape[-2], stack.shape[-1]), order="C"
                )
            )

        boundary = np.stack(self._boundary)
        constraints = [combined(boundary) << -eps * np.eye(boundary.shape[-1])]
        for g in range(len(self.grid)):
            at = combined(Pi[:, g])
            constraints += [
                at >> (1 + eps) * H[g],
                at << (self.c2 - eps) * H[g],
                combined(interior[:, g]) + self.two_sigma * at << -eps * H[g],
            ]
        self.problem = cp.Problem(cp.Minimize(self.c2), constraints)

    def solve(self, sigma: float, *, fallback: bool = True) -> PolynomialCandidate | None:
        """Solve on the current grid at ``sigma``; ``None`` when infeasible."""
        self.two_sigma.value = 2 * sigma
        if not solved(self.problem, fallback):
            return None
        values = tuple(float(x) for x in np.asarray(self.coordinates.value))
        return PolynomialCandidate(sigma, values, float(np.asarray(self.c2.value)))

    def violations(self, found: PolynomialCandidate) -> tuple[list[float], PolynomialCandidate]:
        r"""Check ``found`` on the fine grid: the points to add (worst first), and its constants.

        A miss of :math:`G \prec 0` by half the margin, or a :math:`\Pi` that is not
        positive definite, is a point for the grid; the norm bounds are met instead by
        moving the constants: :math:`c_1` down to 0.999 of the least, :math:`c_2` up to
        1.001 of the largest eigenvalue of :math:`\mathcal H^{-1/2}\Pi\mathcal H^{-1/2}`
        seen (they only make :math:`M` larger, and the exact check decides them).
        """
        zs = np.linspace(*self.interval, FINE)
        Pi, interior, H = self._stacks(zs)
        c = np.asarray(found.coordinates)
        at = _sym_batch(np.einsum("i,imjk->mjk", c, Pi))
        G = np.einsum("i,imjk->mjk", c, interior) + 2 * found.sigma * at
        L_inv = np.linalg.inv(np.linalg.cholesky(H))
        ratios = np.linalg.eigvalsh(L_inv @ at @ np.swapaxes(L_inv, 1, 2))
        worst = np.maximum(
            np.linalg.eigvalsh(_sym_batch(G) + MARGIN / 2 * H).max(axis=1), -ratios.min(axis=1)
        )
        constants = replace(
            found,
            c1=min(found.c1, 0.999 * float(ratios.min())),
            c2=max(found.c2, 1.001 * float(ratios.max())),
        )
        peaks = [
            i
            for i in range(FINE)
            if worst[i] > 0
            and worst[i] >= worst[max(i - 1, 0)]
            and worst[i] >= worst[min(i + 1, FINE - 1)]
        ]
        peaks.sort(key=lambda i: -worst[i])
        return [float(zs[i]) for i in peaks[:NEW_POINTS]], constants

    def refine(self, points: list[float]) -> None:
        """Add ``points`` to the grid and recompile."""
        self.grid = np.unique(np.concatenate([self.grid, points]))
        self._compile()

    def best_sigma(self) -> float:
        """Return the largest σ feasible on the current grid (bisection)."""
        return largest_feasible(lambda s: self.solve(s, fallback=False) is not None, self.start)


def _floats(M: sympy.MatrixBase) -> np.ndarray:
    return np.array(M.tolist(), dtype=float)


def _sym_batch(X: np.ndarray) -> np.ndarray:
    return np.asarray((X + np.swapaxes(X, 1, 2)) / 2)


def search_polynomial(
    program: PolynomialProgram, target: float | None = None
) -> PolynomialCandidate:
    """Find the best σ (or ``target``) whose solution passes the fine check (cutting planes).

    Raises
    ------
    RateProofError
        No positive σ is feasible, ``target`` is above the best σ, or the cutting-plane
        loop does not settle in ``ROUNDS`` rounds.
    """
    best = program.best_sigma()
    require_reached(best, target, "with a polynomial weight", "", "")
    # the bisection's σ sits on the feasibility boundary: step inside
    sigma = target if target is not None else best * (1 - 1e-4)
    misses = 0
    for _ in range(ROUNDS):
        found = program.solve(sigma)
        if found is None:  # the points added cut σ off, or the solver is inaccurate there
            if target is not None:
                raise RateProofError(
                    f"the decay rate target = {target:g} is not feasible once the grid is "
                    f"refined ({len(program.grid)} points); no rate is claimed"
                )
            sigma *= 1 - 0.01 * 2**misses
            misses += 1
            continue
        extra, found = program.violations(found)
        if not extra:
            return found
        program.refine(extra)
    raise RateProofError(
        f"the polynomial weight's SDP did not settle in {ROUNDS} refinements of its grid "
        f"({len(program.grid)} points{', at the target' if target is not None else ''}); "
        "no rate is claimed"
    )
