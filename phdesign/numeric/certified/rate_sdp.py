r"""The numeric half of the decay-rate proof: a semidefinite program found by cvxpy.

At fixed :math:`\tau > 1` (so :math:`\mu = \ln\tau/(b - a)`) and :math:`\sigma`, the
inequalities of :mod:`.rate_exact` are linear matrix inequalities in the coordinates of
:math:`\Pi_\pm` in the exact basis of :func:`.rate_exact.lyapunov_basis` and in
:math:`c_2` (with :math:`c_1 = 1` fixing the scale): a feasibility problem, solved with
Clarabel (an interior-point conic solver; SCS, a first-order one, if Clarabel fails).
Every strict inequality is asked with a margin, so that the solution survives rounding
to rationals.  The problem is built once with cvxpy parameters (its DPP rule: one
parameter times an affine expression), so each :math:`(\tau, \sigma)` re-solves without
recompiling.

Feasibility is monotone in :math:`\sigma` (lowering :math:`\sigma` subtracts
:math:`2\Delta\sigma\,(\Pi_- + s\Pi_+) \succ 0`, positive by the lower norm bound,
from the pointwise forms), so the largest
:math:`\sigma(\tau)` is found by bisection; :math:`\ln\tau` is chosen by a geometric scan
and a golden-section refinement around the best point (:func:`search`).  Nothing here is
trusted: :mod:`.rate` rounds the result and proves it exactly.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy

from phdesign.core.errors import RateProofError
from phdesign.numeric.certified.rate_problem import RateProblem

__all__ = [
    "Candidate",
    "LyapunovProgram",
    "largest_feasible",
    "require_reached",
    "search",
    "solved",
]

#: Margin of every strict inequality, relative to the problem's scale (c₁ = 1).
MARGIN = 1e-6
#: ln τ scanned before the refinement (μ(b − a) = ln τ).
LOG_TAU_GRID = tuple(2.0**k for k in range(-4, 4))
BISECTION_STEPS = 10
GOLDEN_STEPS = 10


@dataclass(frozen=True)
class Candidate:
    """A numeric solution: coordinates of Π₋, Π₊ in the exact basis, and c₂."""

    tau: float
    sigma: float
    minus: tuple[float, ...]
    plus: tuple[float, ...]
    c2: float


def _floats(M: sympy.MatrixBase) -> np.ndarray:
    return np.array(M.tolist(), dtype=float)


class LyapunovProgram:
    """The parametrized SDP of the module docstring, compiled once for a problem."""

    def __init__(self, problem: RateProblem, basis: tuple[sympy.ImmutableMatrix, ...]) -> None:
        import cvxpy as cp

        self._cp = cp
        H, P1 = _floats(problem.H), _floats(problem.P1)
        A, B = P1 @ H, _floats(problem.P0) @ H
        E = [_floats(b) for b in basis]
        n, d = H.shape[0], len(E)
        self.length = float(problem.length)
        self.speed = float(max(abs(np.linalg.eigvals(A))))
        names = ("mu", "tau", "inv_tau", "s", "s_mu", "two_sigma", "s_two_sigma")
        self.p = {k: cp.Parameter(name=k) for k in names}
        self.minus, self.plus, self.c2 = cp.Variable(d), cp.Variable(d), cp.Variable()
        Pm = sum(self.minus[j] * E[j] for j in range(d))
        Pp = sum(self.plus[j] * E[j] for j in range(d))
        p, eps = self.p, MARGIN

        def sym(X: Any) -> Any:
            return (X + X.T) / 2

        def pointwise(s: Any, s_mu: Any, s_two_sigma: Any) -> Any:
            minus = p["mu"] * (Pm @ A) + 2 * sym(Pm @ B) + p["two_sigma"] * Pm
            plus = -s_mu * (Pp @ A) + s * (2 * sym(Pp @ B)) + s_two_sigma * Pp
            return sym(minus + plus)

        H_inv = np.linalg.inv(H)
        K = _floats(problem.kernel)
        at_b = H_inv @ (p["inv_tau"] * Pm + p["tau"] * Pp) @ P1
        at_a = H_inv @ (Pm + Pp) @ P1
        boundary = K[:n].T @ at_b @ K[:n] - K[n:].T @ at_a @ K[n:]
        constraints = [
            # the norm bounds at s = 1 and s = τ² (c₁ = 1; chord = 1 + (s − 1)/(τ + 1))
            sym(Pm + Pp) >> (1 + eps) * H,
            sym(Pm + p["s"] * Pp) >> ((1 + p["s"]) / 2 + eps) * H,
            sym(Pm + Pp) << (self.c2 - eps) * H,
            sym(Pm + p["s"] * Pp) << (p["tau"] * self.c2 - eps) * H,
            sym(boundary) << -eps * np.eye(K.shape[1]),
            pointwise(1.0, p["mu"], p["two_sigma"]) << -eps * H,
            pointwise(p["s"], p["s_mu"], p["s_two_sigma"]) << -eps * H,
        ]
        # minimizing c₂ (the constant M) also keeps the interior-point path well posed
        self.problem = cp.Problem(cp.Minimize(self.c2), constraints)

    def solve(self, tau: float, sigma: float, *, fallback: bool = True) -> Candidate | None:
        """Solve at ``(tau, sigma)``; ``None`` when the solvers find it infeasible.

        Without ``fallback`` (the search's many solves) a Clarabel failure counts as
        infeasible instead of asking SCS, which is a hundred times slower here.
        """
        mu = math.log(tau) / self.length
        values = {
            "mu": mu,
            "tau": tau,
            "inv_tau": 1 / tau,
            "s": tau * tau,
            "s_mu": tau * tau * mu,
            "two_sigma": 2 * sigma,
            "s_two_sigma": 2 * sigma * tau * tau,
        }
        for key, value in values.items():
            self.p[key].value = value
        if not self._solved(fallback):
            return None
        minus, plus = np.asarray(self.minus.value), np.asarray(self.plus.value)
        return Candidate(
            tau,
            sigma,
            tuple(map(float, minus)),
            tuple(map(float, plus)),
            float(np.asarray(self.c2.value)),
        )

    def _solved(self, fallback: bool) -> bool:
        return solved(self.problem, fallback)

    def best_sigma(self, tau: float) -> float:
        """Return the largest feasible σ at ``tau`` (bisection; 0 when none is found)."""
        start = math.log(tau) / self.length * self.speed
        return largest_feasible(lambda s: self.solve(tau, s, fallback=False) is not None, start)


def solved(problem: Any, fallback: bool) -> bool:
    """Solve the cvxpy ``problem`` with Clarabel (then SCS with ``fallback``): optimal or not.

    An inaccurate answer counts as infeasible, so a bisection stays on the safe side.
    """
    import cvxpy as cp

    solvers: tuple[tuple[str, dict[str, Any]], ...] = (
        (cp.CLARABEL, {}),
        (cp.SCS, {"eps": 1e-7, "max_iters": 2000}),
    )
    for solver, options in solvers[: 2 if fallback else 1]:
        try:
            with warnings.catch_warnings():  # an inaccurate status is judged below
                warnings.simplefilter("ignore", UserWarning)
                problem.solve(solver=solver, **options)
        except cp.SolverError:
            continue  # Clarabel failed (it does on the feasibility boundary): SCS tries
        return bool(problem.status == cp.OPTIMAL)
    return False


def largest_feasible(feasible: Callable[[float], bool], start: float) -> float:
    """Return the largest σ with ``feasible(σ)``: doubling from ``start``, then bisection."""
    lo, hi = 0.0, start
    for _ in range(6):
        if not feasible(hi):
            break
        lo, hi = hi, 2 * hi
    else:
        return lo
    for _ in range(BISECTION_STEPS):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if feasible(mid) else (lo, mid)
    return lo


def search(program: LyapunovProgram, target: float | None = None) -> tuple[float, float]:
    """Maximize σ over τ (scan and golden section); the best ``(tau, sigma)``.

    Raises
    ------
    RateProofError
        No τ gives a positive σ, or ``target`` is above the best σ found.
    """
    if target is not None:  # one solve per weight ratio, while none reaches the target
        for x in LOG_TAU_GRID:
            if program.solve(math.exp(x), target, fallback=False) is not None:
                return math.exp(x), target
    scores = [(program.best_sigma(math.exp(x)), x) for x in LOG_TAU_GRID]
    best_sigma, best_x = max(scores)
    i = LOG_TAU_GRID.index(best_x)
    lo = math.log(LOG_TAU_GRID[max(i - 1, 0)])
    hi = math.log(LOG_TAU_GRID[min(i + 1, len(LOG_TAU_GRID) - 1)])
    best_sigma, best_x = _golden(program, lo, hi, (best_sigma, best_x))
    require_reached(
        best_sigma,
        target,
        "of the Bastin–Coron form",
        " for every weight ratio τ tried",
        f" (at ln τ = {best_x:.4g})",
    )
    return math.exp(best_x), best_sigma if target is None else target


def require_reached(best: float, target: float | None, form: str, tried: str, at: str) -> None:
    """Refuse when the search found no positive σ, or when ``target`` is above ``best``.

    Raises
    ------
    RateProofError
        With the functional's ``form``, what was ``tried`` and where the best σ is ``at``.
    """
    if best <= 0:
        raise RateProofError(
            f"no Lyapunov functional {form} was found: the SDP is infeasible{tried}, even at σ = 0"
        )
    if target is not None and target > best:
        raise RateProofError(
            f"the decay rate target = {target:g} is above the best rate the SDP reaches, "
            f"σ = {best:.6g}{at}"
        )


def _golden(
    program: LyapunovProgram, lo: float, hi: float, best: tuple[float, float]
) -> tuple[float, float]:
    """Golden-section search of σ(τ) over y = ln ln τ in [lo, hi]; the best (σ, ln τ) seen."""
    ratio = (math.sqrt(5) - 1) / 2

    def score(y: float) -> float:
        return program.best_sigma(math.exp(math.exp(y)))

    a, b = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
    fa, fb = score(a), score(b)
    for _ in range(GOLDEN_STEPS if hi > lo else 0):
        best = max(best, (fa, math.exp(a)), (fb, math.exp(b)))
        if fa >= fb:
            hi, b, fb = b, a, fa
            a = hi - ratio * (hi - lo)
            fa = score(a)
        else:
            lo, a, fa = a, b, fb
            b = lo + ratio * (hi - lo)
            fb = score(b)
    return max(best, (fa, math.exp(a)), (fb, math.exp(b)))
