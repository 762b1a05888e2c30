r"""The L²-gain from the noise to the error, over the band a resolution pair resolves.

The gain is the H∞ norm :math:`\sup_\omega \sigma_{\max}(E^{1/2}(i\omega E - A)^{-1} G)`
of the noise-driven error system (:mod:`phdesign.numeric.noise.statistics`), taken over
the *resolved band* :math:`|\omega| \le \Omega` of a pair of resolutions (the largest
modulus of an eigenvalue they agree on), because the unresolved high frequencies of a
discretization lose the boundary damping (:mod:`phdesign.numeric.noise.figures`).

The response of a stable system peaks at its resonances (an eigenvalue λ gives a peak
near :math:`\omega = |\operatorname{Im}\lambda|`, of half-power width
:math:`|\operatorname{Re}\lambda|`), at :math:`\omega = 0` or at the end of the range.  So
:func:`peak_gain` evaluates the response at those frequencies (one vectorized back
substitution), brackets each local maximum between its neighbours and refines it by a
bounded scalar search (Brent).  The banded gain (:func:`gain_pair`) needs no more than
that; the discretization's own supremum over *all* frequencies (:func:`discrete_sup`, a
diagnostic that the report prints and warns with) adds log- and linearly spaced points,
a sweep of the whole band.  :class:`PeakSearch` keeps the refined peaks of one
resolution and its response at every grid frequency, so the sweep and the two pairs a
resolution belongs to share them (their grids share the resonances).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar

from phdesign.numeric.noise.report import GainEstimate
from phdesign.numeric.noise.settle import settle
from phdesign.numeric.noise.statistics import ErrorStatistics
from phdesign.numeric.spectrum.drift import match_resolved

__all__ = [
    "PeakSearch",
    "banded_gain",
    "discrete_sup",
    "frequency_grid",
    "gain_pair",
    "peak_gain",
]

#: Grid maxima this far (relative) below the largest peak are not refined as its ties.
_TIE_SCREEN = 1e-2
#: Without the sweep, local maxima of the resonance grid below this fraction of its
#: highest value are not refined: a resonance's grid value (at ω = |Im λ| and its
#: half-power neighbours) is within a factor √2 of its peak.
_RESONANCE_SCREEN = 0.5

#: A refined peak: (gain, frequency), keyed by its bracket (low, grid point, high).
Peaks = dict[tuple[float, float, float], tuple[float, float]]


def frequency_grid(upper: float, eigenvalues: np.ndarray, sweep: bool = True) -> np.ndarray:
    """Return the frequencies in ``[0, upper]`` where :func:`peak_gain` starts.

    0, ``upper``, and each eigenfrequency in range with its half-power neighbours
    (ω ± |Re λ|); with ``sweep``, also 100 log- and 40 linearly spaced points.  Distinct
    to round-off, increasing.
    """
    lam = eigenvalues[np.isfinite(eigenvalues)]
    freqs = np.abs(lam.imag)
    inside = freqs <= upper
    width = np.abs(lam.real[inside])
    hints = np.concatenate([freqs[inside], freqs[inside] + width, freqs[inside] - width])
    parts = [np.array([0.0, upper]), hints]
    if sweep:
        parts += [
            np.geomspace(max(upper * 1e-6, 1e-12), upper, 100) if upper > 0 else np.array([]),
            np.linspace(0.0, upper, 40),
        ]
    grid = np.concatenate(parts)
    grid = np.unique(grid[(grid >= 0) & (grid <= upper)])
    # conjugate eigenvalues give frequencies equal to round-off: one grid point each, or a
    # local maximum would be bracketed by its own twin
    return grid[np.r_[True, np.diff(grid) > 1e-12 * np.maximum(1.0, grid[1:])]]


def peak_gain(
    response: Callable[[np.ndarray], np.ndarray],
    response_at: Callable[[float], float],
    upper: float,
    eigenvalues: np.ndarray,
    refine: int = 3,
    rtol: float = 1e-7,
    ties: float = 0.0,
    *,
    sweep: bool = True,
    peaks: Peaks | None = None,
) -> tuple[float, float]:
    """Return ``(gain, frequency)``: the largest ``response`` over ``0 <= omega <= upper``.

    The response at :func:`frequency_grid` (``sweep``: with the whole band's spaced
    points), then a bounded scalar refinement (Brent, to ``rtol`` in ω: the peak value
    is then exact to about ``rtol``² relative to the peak's width) of the ``refine``
    highest local maxima between their grid neighbours; without ``sweep``, of those at
    least half the highest grid value.  ``peaks`` keeps the refinements by bracket, to be
    shared by the searches of one response.

    With ``ties > 0``, peaks within ``ties`` (relative) of the largest are equal: the
    lowest-frequency one is returned, with its own value.  A PDE whose response has equal
    peaks at infinitely many frequencies (the damped wave: one per resonance) attains its
    supremum at the first; a discretization resolves that one best, while the highest it
    happens to find may lie at the edge of what it resolves.
    """
    grid = frequency_grid(upper, eigenvalues, sweep)
    values = response(grid)
    interior = np.r_[True, values[1:] >= values[:-1]] & np.r_[values[:-1] >= values[1:], True]
    maxima = np.flatnonzero(interior)
    memo: Peaks = {} if peaks is None else peaks

    def refined(k: int) -> tuple[float, float]:
        """Return the local maximum bracketed by the grid neighbours of point ``k``."""
        point = (float(values[k]), float(grid[k]))
        lo, hi = float(grid[max(k - 1, 0)]), float(grid[min(k + 1, grid.size - 1)])
        if hi <= lo:
            return point
        key = (lo, point[1], hi)
        if key not in memo:
            found = minimize_scalar(
                lambda w: -response_at(float(w)),
                bounds=(lo, hi),
                method="bounded",
                options={"xatol": rtol * max(1.0, hi)},
            )
            memo[key] = (-float(found.fun), float(found.x))
        return max(point, memo[key])

    highest = maxima[np.argsort(-values[maxima])[:refine]]
    if not sweep:
        highest = highest[values[highest] >= _RESONANCE_SCREEN * values[highest[0]]]
    found = {int(k): refined(int(k)) for k in highest}
    best = max(found.values())
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
        peak = found.get(k) or refined(k)
        if peak[0] >= threshold:
            return peak
    return best


class PeakSearch:
    """The peaks of one resolution's response, each refined once (module docstring).

    Parameters
    ----------
    stats : ErrorStatistics
        The stable error system at one resolution.
    """

    def __init__(self, stats: ErrorStatistics) -> None:
        self.stats = stats
        self.peaks: Peaks = {}
        self.values: dict[float, float] = {}  # the response at each grid frequency so far
        self.evaluated = 0  # frequencies whose response was computed (a probe for tests)
        self._work: np.ndarray | None = None

    def response(self, omega: np.ndarray) -> np.ndarray:
        """Return the response at ``omega``, computing only the frequencies not seen yet.

        The searches of one resolution (its discrete supremum and the bands of its two
        pairs) start from grids that share the resonances: each frequency is solved once.
        """
        known = self.values
        points = omega.tolist()
        new = [w for w in dict.fromkeys(points) if w not in known]
        if new:
            values = self.stats.pencil.response(np.array(new)).tolist()
            known.update(zip(new, values, strict=True))
            self.evaluated += len(new)
        return np.array([known[w] for w in points])

    def response_at(self, omega: float) -> float:
        """Return the response at one frequency (a refinement's step), in a kept work array."""
        if self._work is None:
            self._work = np.empty_like(self.stats.pencil.T)
        return self.stats.pencil.response_at(omega, self._work)

    def banded(self, upper: float, ties: float, refine: int = 3) -> tuple[float, float]:
        """Return the peak over ``|ω| <= upper``, from the resonances (no sweep).

        ``refine`` grid maxima are refined (the highest first).
        """
        return self._peak(upper, refine=refine, ties=ties, sweep=False)

    def discrete(self) -> tuple[float, float]:
        """Return the supremum over all frequencies: a sweep up to twice the top eigenvalue."""
        lam = self.stats.eigenvalues
        top = float(np.max(np.abs(lam[np.isfinite(lam)]))) if lam.size else 1.0
        return self._peak(2.0 * top, refine=1, sweep=True)

    def _peak(
        self, upper: float, refine: int = 3, ties: float = 0.0, sweep: bool = False
    ) -> tuple[float, float]:
        return peak_gain(
            self.response,
            self.response_at,
            upper,
            self.stats.eigenvalues,
            refine,
            ties=ties,
            sweep=sweep,
            peaks=self.peaks,
        )


def _resolved_band(fine: ErrorStatistics, coarse: ErrorStatistics, rtol: float) -> float | None:
    idx, _ = match_resolved(fine.eigenvalues, coarse.eigenvalues, rtol)
    return float(np.max(np.abs(fine.eigenvalues[idx]))) if idx.size else None


def gain_pair(
    coarse: ErrorStatistics | PeakSearch,
    fine: ErrorStatistics | PeakSearch,
    rtol: float,
    tol: float,
    refine: int = 3,
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
    and the first is the one both members resolve best.  Give each member's
    :class:`PeakSearch` to share its refined peaks with its other pair; ``refine``
    local maxima are refined in each band.
    """
    low = coarse if isinstance(coarse, PeakSearch) else PeakSearch(coarse)
    high = fine if isinstance(fine, PeakSearch) else PeakSearch(fine)
    out: dict[str, Any] = {"resolution": high.stats.resolution, "band": None}
    if not (low.stats.stable and high.stats.stable):
        return out
    band = _resolved_band(high.stats, low.stats, rtol)
    out["band"] = band
    if band is not None:
        out["fine"] = high.banded(band, tol, refine)
        trimmed = band * low.stats.resolution / high.stats.resolution
        out["coarse"] = low.banded(trimmed, tol, refine)
    return out


def discrete_sup(stats: ErrorStatistics | PeakSearch) -> tuple[float, float]:
    """Supremum of the discretization's response over all frequencies (a diagnostic)."""
    return (stats if isinstance(stats, PeakSearch) else PeakSearch(stats)).discrete()


def banded_gain(
    pairs: Sequence[dict[str, Any]],
    sups: Sequence[tuple[float, float]],
    resolutions: Sequence[int],
    steady: bool,
    tol: float,
    name: str = "gamma",
) -> GainEstimate:
    """Judge the banded peaks of every pair (:func:`gain_pair`) under refinement.

    ``sups`` are the discretizations' own suprema ``(gain, frequency)`` per resolution
    (empty: not computed).  A peak at the band's edge is never converged: it is where the
    resolved frequencies end, not a maximum.
    """
    res = tuple(resolutions)
    if not steady:
        return GainEstimate.missing(res)
    discrete, discrete_frequency = None, None
    if sups:
        discrete = settle("discrete sup", [v for v, _ in sups], res, tol)
        discrete_frequency = sups[-1][1]
    banded = [pr for pr in pairs if pr.get("band") is not None]
    if not banded:
        return GainEstimate.missing(res, discrete, discrete_frequency)
    last = banded[-1]
    estimate = settle(
        name,
        [pr["fine"][0] for pr in banded],
        [pr["resolution"] for pr in banded],
        tol,
        pair=(last["coarse"][0], last["fine"][0]),
    )
    if last["fine"][1] >= (1 - 1e-6) * last["band"] and estimate.converged:
        estimate = replace(estimate, converged=False)
    return GainEstimate(
        estimate=estimate,
        frequency=last["fine"][1],
        frequencies=tuple(pr["fine"][1] for pr in banded),
        band=last["band"],
        discrete=discrete,
        discrete_frequency=discrete_frequency,
    )
