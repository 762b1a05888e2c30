r"""The Pareto rule of the trade-offs, and what their results share.

A trade-off (:mod:`phdesign.numeric.noise.tradeoff`: decay rate against the error RMS;
:mod:`phdesign.numeric.noise.disturbance_tradeoff`: against the H∞ norm) evaluates a
family of gains and marks those that no other gain of the family beats in both the decay
rate −α and its ``figure``: :func:`pareto_mask`.  :class:`ParetoFamily` is what their
results share: the Pareto-optimal points by increasing figure, and the figure
(:func:`phdesign.plots.noise.plot_tradeoff`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.figure import Figure

__all__ = ["ParetoFamily", "pareto_mask"]


class ParetoFamily:
    """The Pareto-optimal points and the figure of a trade-off's result (module docstring).

    A subclass has ``points``, each with ``pareto``, ``figure`` (None: not converged),
    ``decay_rate``, ``abscissa_converged`` and ``gain``, and names its figure with
    ``figure_label`` and ``figure_title``.
    """

    points: Sequence[Any]

    @property
    def pareto_points(self) -> tuple[Any, ...]:
        """The Pareto-optimal points, by increasing figure."""
        best = [p for p in self.points if p.pareto]
        return tuple(sorted(best, key=lambda p: p.figure if p.figure is not None else math.inf))

    def plot(self, path: Any = None, *, force: bool = False, annotate: str = "pareto") -> Figure:
        """Decay rate against the figure, Pareto front drawn and gains annotated."""
        from phdesign.plots.noise import plot_tradeoff

        return plot_tradeoff(self, path, force=force, annotate=annotate)


def pareto_mask(
    decay: Sequence[float | None],
    rms: Sequence[float | None],
    decay_tol: float = 1e-8,
    rms_tol: float = 1e-6,
) -> list[bool]:
    """Mark the points no other point beats in both (larger decay, smaller rms).

    Values closer than the relative tolerances (the figures' own accuracy under
    refinement) count as equal: a gain is not Pareto-optimal for a decay rate that beats
    another's by round-off.  Points with a missing figure are never Pareto-optimal.

    Examples
    --------
    >>> pareto_mask([1.0, 2.0, 1.5, None, 1.0 + 1e-12], [0.1, 0.3, 0.4, 0.0, 0.2])
    [True, True, False, False, False]
    """
    pts = [(d, r) for d, r in zip(decay, rms, strict=True)]

    def beats(a: tuple[float, float], b: tuple[float, float]) -> bool:
        td = decay_tol * max(1.0, abs(b[0]))
        tr = rms_tol * abs(b[1])
        no_worse = a[0] >= b[0] - td and a[1] <= b[1] + tr
        return no_worse and (a[0] > b[0] + td or a[1] < b[1] - tr)

    known = [(d, r) for d, r in pts if d is not None and r is not None]
    return [
        d is not None and r is not None and not any(beats(o, (d, r)) for o in known)
        for d, r in pts
    ]
