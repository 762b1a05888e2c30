r"""How fragile an optimal gain is: the worst abscissa over a box of gains around it.

The abscissa-optimal gain of a boundary damper sits where eigenvalues coalesce (the
paper's beam: three real eigenvalues at L ≈ diag(0.1755, 1.0257)).  There the abscissa is
not Lipschitz in the gain: an m-fold eigenvalue splits like :math:`|\delta L|^{1/m}`, so
printing the gain with 8 digits moves the abscissa by 2e-3, and a gain realized to 5 %
loses much of the optimum.  The robustness figure is

.. math::

    \alpha_{\text{worst}}(L, \delta) = \max \{\alpha(L \circ (1 + \Delta)) :
    |\Delta_{ij}| \le \delta\},

the worst spectral abscissa when every nonzero entry of L is off by up to a relative
:math:`\delta` (5 % by default).  It is computed from the :math:`3^k` points of the box
(corners, edge and face midpoints, centre; k the number of nonzero entries, a random
subset of 64 corners beyond k = 4) and a local maximization from the worst of them
(Nelder-Mead on :math:`\Delta = \delta \sin\theta`, which stays inside the box).

``tune(..., robust=0.05)`` minimizes :math:`\alpha_{\text{worst}}` instead of α (with the
grid points only during the search, the local maximization at the end).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

__all__ = ["Robustness", "box_points", "worst_in_box"]

_FULL_GRID_ENTRIES = 4  # up to this many nonzero entries, every point of the 3^k grid
_SAMPLED_CORNERS = 64


@dataclass(frozen=True)
class Robustness:
    """The worst abscissa over a box of gains (module docstring).

    Attributes
    ----------
    delta : float
        Relative half-width of the box (0.05 for ±5 %).
    nominal : float or None
        Abscissa at the centre.
    worst_abscissa : float or None
        Largest abscissa found in the box (None when nothing is resolved anywhere).
    worst_gain : ndarray
        Where it is attained.
    evaluations : int
    """

    delta: float
    nominal: float | None
    worst_abscissa: float | None
    worst_gain: np.ndarray
    evaluations: int

    def to_dict(self) -> dict[str, object]:
        """JSON-ready dictionary."""
        from phdesign.numeric.spectrum.report import finite_or_none

        return {
            "delta": self.delta,
            "nominal": finite_or_none(self.nominal),
            "worst_abscissa": finite_or_none(self.worst_abscissa),
            "worst_gain": self.worst_gain.tolist(),
            "evaluations": self.evaluations,
        }

    def __str__(self) -> str:
        worst = "not resolved" if self.worst_abscissa is None else f"{self.worst_abscissa:.6g}"
        return f"worst abscissa over a ±{100 * self.delta:g} % box of gains: {worst}"


def box_points(k: int, rng: np.random.Generator | None = None) -> np.ndarray:
    """Points of the unit box [-1, 1]^k where the worst case is looked for (module docstring).

    Examples
    --------
    >>> box_points(2).shape
    (9, 2)
    """
    if k <= _FULL_GRID_ENTRIES:
        return np.array(list(itertools.product((-1.0, 0.0, 1.0), repeat=k)))
    rng = np.random.default_rng(0) if rng is None else rng
    corners = rng.choice((-1.0, 1.0), size=(_SAMPLED_CORNERS, k))
    axes = np.concatenate([np.eye(k), -np.eye(k)])
    return np.concatenate([np.zeros((1, k)), axes, corners])


def _value(x: float) -> float:
    """Return an abscissa as a maximization objective: unresolved (nan) never counts."""
    return -math.inf if math.isnan(x) else x


def worst_in_box(
    abscissa: Callable[[np.ndarray], float],
    L: np.ndarray,
    delta: float,
    *,
    refine: bool = True,
    maxiter: int = 60,
) -> Robustness:
    """Find the worst abscissa over the box ``L ∘ (1 + Δ)``, ``|Δ| <= delta`` (module docstring).

    ``abscissa(L)`` returns the abscissa (``-inf`` for an empty spectrum, ``nan`` when
    nothing is resolved), e.g. an
    :class:`~phdesign.numeric.spectrum.evaluator.AbscissaEvaluator`.

    Examples
    --------
    >>> import numpy as np
    >>> exact = lambda L: 0.5 * np.log(abs((1 - L[0, 0]) / (1 + L[0, 0])))  # damped wave
    >>> r = worst_in_box(exact, np.array([[0.5]]), 0.05)
    >>> bool(abs(r.worst_abscissa - exact(np.array([[0.475]]))) < 1e-12)  # the weaker damper
    True
    """
    L = np.atleast_2d(np.asarray(L, dtype=float))
    entries = np.flatnonzero(L)
    k = entries.size
    count = 0

    def at(t: np.ndarray) -> float:
        nonlocal count
        count += 1
        M = L.copy().ravel()
        M[entries] *= 1.0 + delta * t
        return _value(abscissa(M.reshape(L.shape)))

    points = box_points(k)
    values = np.array([at(t) for t in points])
    nominal_index = int(np.flatnonzero(np.all(points == 0.0, axis=1))[0])
    nominal = values[nominal_index]
    best = int(np.argmax(values))
    worst, worst_t = float(values[best]), points[best]
    if refine and k and math.isfinite(worst):
        theta0 = np.arcsin(np.clip(worst_t, -1.0, 1.0))
        res = minimize(
            lambda th: -at(np.sin(th)),
            theta0,
            method="Nelder-Mead",
            options={"maxiter": maxiter * k, "xatol": 1e-6, "fatol": 1e-10},
        )
        if -res.fun > worst:
            worst, worst_t = float(-res.fun), np.sin(res.x)
    gain = L.copy().ravel()
    gain[entries] *= 1.0 + delta * worst_t
    return Robustness(
        delta=float(delta),
        nominal=None if not math.isfinite(nominal) else float(nominal),
        worst_abscissa=None if not math.isfinite(worst) else worst,
        worst_gain=gain.reshape(L.shape),
        evaluations=count,
    )
