r"""The L²-gain from the noise to the error, over the band a resolution pair resolves.

The gain is the H∞ norm :math:`\sup_\omega \sigma_{\max}(E^{1/2}(i\omega E - A)^{-1} G)`
of the noise-driven error system (:mod:`phdesign.numeric.noise.statistics`), taken over
the *resolved band* :math:`|\omega| \le \Omega` of a pair of resolutions (the largest
modulus of an eigenvalue they agree on), because the unresolved high frequencies of a
discretization lose the boundary damping (:mod:`phdesign.numeric.noise.figures`).
:func:`peak_gain` finds a response's peak; :func:`gain_pair` the pair's banded peaks;
:func:`discrete_sup` the discretization's own supremum over all frequencies.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar

from phdesign.numeric.noise.statistics import ErrorStatistics
from phdesign.numeric.spectrum.drift import match_resolved

__all__ = ["discrete_sup", "gain_pair", "peak_gain"]

#: Grid maxima this far (relative) below the largest peak are not refined as its ties.
_TIE_SCREEN = 1e-2


def peak_gain(
    response: Callable[[np.ndarray], np.ndarray],
    response_at: Callable[[float], float],
    upper: float,
    eigenvalues: np.ndarray,
    refine: int = 3,
    rtol: float = 1e-7,
    ties: float = 0.0,
) -> tuple[float, float]:
    """Return ``(gain, frequency)``: the largest ``response`` over ``0 <= omega <= upper``.

    A sweep over 0, the eigenfrequencies in range and their half-power neighbours
    (ω ± |Re λ|), and log- and linearly spaced points, then a bounded scalar refinement
    (Brent, to ``rtol`` in ω: the peak value is then exact to about ``rtol``²
    relative to the peak's width) of the ``refine`` highest local maxima between their
    grid neighbours.

    With ``ties > 0``, peaks within ``ties`` (relative) of the largest are equal: the
    lowest-frequency one is returned, with its own value.  A PDE whose response has equal
    peaks at infinitely many frequencies (the damped wave: one per resonance) attains its
    supremum at the first; a discretization resolves that one best, while the highest it
    happens to find may lie at the edge of what it resolves.
    """
    lam = eigenvalues[np.isfinite(eigenvalues)]
    freqs = np.abs(lam.imag)
    inside = freqs <= upper
    width = np.abs(lam.real[inside])
    hints = np.concatenate([freqs[inside], freqs[inside] + width, freqs[inside] - width])
    grid = np.concatenate(
        [
            [0.0, upper],
            hints,
            np.geomspace(max(upper * 1e-6, 1e-12), upper, 100) if upper > 0 else [],
            np.linspace(0.0, upper, 40),
        ]
    )
    grid = np.unique(grid[(grid >= 0) & (grid <= upper)])
    # conjugate eigenvalues give frequencies equal to round-off: one grid point each, or a
    # local maximum would be bracketed by its own twin
    grid = grid[np.r_[True, np.diff(grid) > 1e-12 * np.maximum(1.0, grid[1:])]]
    values = response(grid)
    interior = np.r_[True, values[1:] >= values[:-1]] & np.r_[values[:-1] >= values[1:], True]
    maxima = np.flatnonzero(interior)

    def refined(k: int) -> tuple[float, float]:
        """Return the local maximum bracketed by the grid neighbours of point ``k``."""
        point = (float(values[k]), float(grid[k]))
        lo, hi = float(grid[max(k - 1, 0)]), float(grid[min(k + 1, grid.size - 1)])
        if hi <= lo:
            return point
        found = minimize_scalar(
            lambda w: -response_at(float(w)),
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": rtol * max(1.0, hi)},
        )
        return max(point, (-float(found.fun), float(found.x)))

    highest = maxima[np.argsort(-values[maxima])[:refine]]
    peaks = {int(k): refined(int(k)) for k in highest}
    best = max(peaks.values())
    if ties <= 0:
        return best
    # the lowest-frequency peak within `ties` of the largest; grid values are lower
    # bounds of their peaks, so a grid maximum below the threshold can still reach it
    threshold = (1.0 - ties) * best[0]
    for k in (int(k) for k in maxima):
        if grid[k] >= best[1]:
            break
        if values[k] < (1.0 - _TIE_SCREEN) * best[0]:
            continue
        peak = peaks.get(k) or refined(k)
        if peak[0] >= threshold:
            return peak
    return best


def _sup(
    stats: ErrorStatistics, upper: float, refine: int = 3, ties: float = 0.0
) -> tuple[float, float]:
    pencil = stats.pencil
    return peak_gain(
        pencil.response, pencil.response_at, upper, stats.eigenvalues, refine, ties=ties
    )


def _resolved_band(fine: ErrorStatistics, coarse: ErrorStatistics, rtol: float) -> float | None:
    idx, _ = match_resolved(fine.eigenvalues, coarse.eigenvalues, rtol)
    return float(np.max(np.abs(fine.eigenvalues[idx]))) if idx.size else None


def gain_pair(
    coarse: ErrorStatistics, fine: ErrorStatistics, rtol: float, tol: float
) -> dict[str, Any]:
    r"""Return the fine member's peak over the pair's resolved band, and its check.

    The band :math:`|\omega| \le \Omega` is where the two members' eigenvalues agree, so
    :math:`\Omega` is the edge of what the *coarse* member resolves, while the fine member
    is there only about :math:`p_c / p_f` of the way to its own edge.  The coarse member
    is therefore compared on the trimmed band :math:`|\omega| \le (p_c/p_f)\,\Omega`,
    where it is as far inside its resolution as the fine member is at :math:`\Omega`
    (near the edge its response lags its eigenvalues: the tails of the unresolved
    resonances just above).  Peaks within ``tol`` of the largest count as equal and the
    lowest-frequency one is taken (:func:`peak_gain`): the figure cannot tell them apart,
    and the first is the one both members resolve best.
    """
    out: dict[str, Any] = {"resolution": fine.resolution, "band": None}
    if not (coarse.stable and fine.stable):
        return out
    band = _resolved_band(fine, coarse, rtol)
    out["band"] = band
    if band is not None:
        out["fine"] = _sup(fine, band, ties=tol)
        out["coarse"] = _sup(coarse, band * coarse.resolution / fine.resolution, ties=tol)
    return out


def discrete_sup(stats: ErrorStatistics) -> tuple[float, float]:
    """Supremum of the discretization's response over all frequencies (a diagnostic)."""
    lam = stats.eigenvalues
    top = float(np.max(np.abs(lam[np.isfinite(lam)]))) if lam.size else 1.0
    return _sup(stats, 2.0 * top, refine=1)
