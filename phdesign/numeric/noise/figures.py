r"""Noise: what an observer gain costs in sensor noise, computed honestly under refinement.

**The model.**  The observer receives the measurements with white noise,
:math:`y_m + \nu`, :math:`\mathbb E[\nu(t)\nu(s)^\top] = \Sigma_\nu \delta(t - s)`,
:math:`\Sigma_\nu = \operatorname{diag}(\sigma_1^2, \dots)` (one intensity per sensor).
Optionally the plant inputs carry white noise too, :math:`u + w`,
:math:`\mathbb E[w w^\top] = \Sigma_w \delta`, which the observer does not know (it is
driven by u alone).  On a discretization :math:`E \dot{\hat e} = (J - R)\hat e + B u`,
:math:`y = B^\top \hat e + D u`, with :math:`K = C_m^\top L C_m` and the observer input
:math:`\hat u = u + C_m^\top L (y_m + \nu - \hat y_m)`, the correction
:math:`\delta = \hat u - u` solves
:math:`(I + K D)\,\delta = K (B^\top \tilde e + D w) + C_m^\top L \nu`, and the error
:math:`\tilde e = \hat e - \hat e_{obs}` obeys

.. math::

    E \dot{\tilde e} = \big(J - R - B (I + KD)^{-1} K B^\top\big) \tilde e
    + B (I + KD)^{-1} \big(w - C_m^\top L \nu\big),

using :math:`I - (I + KD)^{-1} K D = (I + KD)^{-1}`.  For D = 0 (Galerkin) this is
:math:`E \dot{\tilde e} = \texttt{closed\_matrix}(K)\,\tilde e + B (w - C_m^\top L \nu)`:
the sensor noise enters through the same boundary damper as the correction,
:math:`\tilde u = -C_m^\top L C_m \tilde y - C_m^\top L \nu`, and the input noise drives the
error through what the observer does not see: the plant receives :math:`B w`, the
observer only its echo :math:`C_m D w` in the measurements.

**The figures** (the error is stationary when the error system is exponentially stable):
the covariance :math:`P` solves :math:`A P E^\top + E P A^\top + G G^\top = 0`
(:mod:`phdesign.numeric.noise.lyapunov`), :math:`G = B (I+KD)^{-1} [-C_m^\top L \Sigma_\nu^{1/2},
\Sigma_w^{1/2}]`, and

1. the variance of a performance output :math:`c(\tilde x)` is :math:`c P c^\top`
   (:mod:`phdesign.numeric.discretization.functionals`);
2. the L²-gain :math:`\gamma` from the (intensity-weighted) noise to :math:`\tilde x` in the
   energy norm :math:`\|x\|^2 = \int x^\top \mathcal H x\, dz = 2 H(x)` is the H∞ norm
   :math:`\sup_\omega \sigma_{\max}(E^{1/2}(i\omega E - A)^{-1} G)`; with unit intensities it
   is the gain from ν itself;
3. the expected error energy is :math:`\mathbb E[\tilde H] = \tfrac12 \operatorname{tr}(E P)`.

**The trap.**  White noise at the boundary of these PDEs gives an *infinite* steady-state
error energy: on a discretization E[H̃] grows about linearly with the resolution (beam,
L = diag(0.1, 1): 2.26, 3.13, 4.42 at degrees 20, 30, 45), while smooth functionals such
as the tip deflection converge (to 1e-9 by degree 30).  So every figure is computed at
three or more resolutions (the spectrum's refinement, p → ⌈1.5 p⌉) and judged by
:func:`phdesign.numeric.noise.settle.settle`: converged (a number), diverging (the growth
is reported, never a number) or not converged.  The gain γ obeys the spectrum's rule: the
unresolved high frequencies of a discretization lose the boundary damping (on the damped
wave its H∞ peak grows like p²), so γ is the peak over the *resolved band*
:math:`|\omega| \le \Omega`, Ω the largest modulus of an eigenvalue that agrees between
the two resolutions of a pair.  Ω is the edge of what the pair's *coarse* member
resolves, so that member is checked on the trimmed band :math:`(p_c/p_f)\,\Omega`, as far
inside its resolution as the fine member is at Ω.  Peaks within the tolerance of the
largest are equal, and the lowest-frequency one is reported with its frequency: the damped
wave's response has equal peaks at infinitely many frequencies (one per resonance), and
the first is both the PDE's answer and the one a discretization resolves best.
The discretization's own supremum over all frequencies is reported beside it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, MutableMapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar

from phdesign.core import limits
from phdesign.core.checks import positive_int, positive_number
from phdesign.core.defaults import current, method_or_default
from phdesign.core.errors import NumericError, ObserverError
from phdesign.core.limits import check_noise_intensity
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.functionals import Functional, parse_functionals
from phdesign.numeric.discretization.registry import DiscretePHS, discretize, feedback_matrix
from phdesign.numeric.noise.lyapunov import TriangularPencil, triangularize
from phdesign.numeric.noise.report import GainEstimate, NoiseReport
from phdesign.numeric.noise.settle import Estimate, settle
from phdesign.numeric.spectrum.converged import default_resolutions
from phdesign.numeric.spectrum.drift import match_resolved

__all__ = [
    "ErrorStatistics",
    "GainEstimate",
    "NoiseReport",
    "check_intensity",
    "error_statistics",
    "noise",
    "noise_input",
    "noise_intensities",
    "peak_gain",
    "sensor_rows",
]

#: Grid maxima this far (relative) below the largest peak are not refined as its ties.
_TIE_SCREEN = 1e-2


def check_intensity(values: Any, count: int, name: str) -> np.ndarray:
    """Return intensities as a float array of length ``count`` (one value is repeated).

    Raises
    ------
    NumericError
        A value is negative, NaN or infinite, or there are neither 1 nor ``count`` values.

    Examples
    --------
    >>> check_intensity(0.01, 2, "intensity").tolist()
    [0.01, 0.01]
    """
    try:
        arr = np.atleast_1d(np.asarray(values, dtype=float)).ravel()
    except (TypeError, ValueError):
        raise NumericError(f"{name}: expected numbers; found {values!r}") from None
    if arr.size == 1:
        arr = np.full(count, arr[0])
    if arr.size != count:
        raise NumericError(
            f"{name}: expected {count} values (one per channel) or a single one; found {arr.size}"
        )
    bad = [float(v) for v in arr if not (math.isfinite(v) and v >= 0)]
    if bad:
        raise NumericError(
            f"{name}: intensities must be finite and non-negative (variances per unit "
            f"time); found {bad[0]}"
        )
    check_noise_intensity(float(np.max(arr)) if arr.size else 0.0, name)
    return arr


def noise_intensities(
    nm: NumericModel, q: int, intensity: Any, input_intensity: Any, default: float = 1.0
) -> tuple[np.ndarray, np.ndarray | None]:
    """Return the checked sensor and input intensities (sensors: ``default`` when None).

    The input intensities stay None (no input noise) unless given.
    """
    sigma = check_intensity(default if intensity is None else intensity, q, "intensity")
    w_in = None
    if input_intensity is not None:
        w_in = check_intensity(input_intensity, nm.n_ports, "input intensity")
    return sigma, w_in


def sensor_rows(C_m: Any, what: str) -> np.ndarray:
    """Return C_m as a 2-D float array, refusing an empty one (``what`` needs sensors)."""
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    if C.size == 0:
        raise ObserverError(f"{what}: sensors needed; give C_m with at least one row")
    return C


def noise_input(
    d: DiscretePHS,
    C_m: np.ndarray,
    L: np.ndarray,
    intensity: np.ndarray,
    input_intensity: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    r"""Return ``(A, G, labels)``: :math:`E \dot{\tilde e} = A \tilde e + G n`, n unit white.

    The columns of G are the sensor channels :math:`-B(I+KD)^{-1} C_m^\top L \sigma_i`
    and the input channels :math:`B (I+KD)^{-1} e_j \sqrt{w_j}` (module docstring);
    channels of zero intensity are left out.
    """
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    Lm = np.atleast_2d(np.asarray(L, dtype=float))
    loop = d.close(feedback_matrix(C, Lm, d.n_ports))
    A, BM = loop.A, loop.B  # B M = B (I + K D)⁻¹
    columns = [-BM @ C.T @ Lm @ np.diag(np.sqrt(intensity))]
    labels = [f"nu{i + 1}" for i in range(C.shape[0])]
    keep = [bool(s > 0) for s in intensity]
    if input_intensity is not None:
        columns.append(BM @ np.diag(np.sqrt(input_intensity)))
        labels += [f"w{j + 1}" for j in range(d.n_ports)]
        keep += [bool(s > 0) for s in input_intensity]
    G = np.hstack(columns)[:, keep]
    return A, G, tuple(label for label, k in zip(labels, keep, strict=True) if k)


@dataclass(frozen=True)
class ErrorStatistics:
    """Stationary statistics of the noise-driven error system at one resolution.

    Attributes
    ----------
    discrete : DiscretePHS
    pencil : TriangularPencil
    covariance : ndarray or None
        Stationary covariance of ẽ (None when the error system is not exponentially stable).
    """

    discrete: DiscretePHS
    pencil: TriangularPencil
    covariance: np.ndarray | None

    @property
    def resolution(self) -> int:
        """The discretization's resolution."""
        return self.discrete.resolution

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of the error system."""
        return self.pencil.eigenvalues

    @property
    def stable(self) -> bool:
        """Whether every eigenvalue lies strictly left of the imaginary axis."""
        return self.covariance is not None

    def variance(self, row: np.ndarray) -> float:
        """Stationary variance of ``row @ ẽ`` (``inf`` without a steady state)."""
        if self.covariance is None:
            return math.inf
        return float(max(row @ self.covariance @ row, 0.0))

    def energy(self) -> float:
        """Return the expected error energy ½ tr(E P) (``inf`` without a steady state)."""
        if self.covariance is None:
            return math.inf
        return 0.5 * float(np.sum(self.discrete.E * self.covariance))


def error_statistics(
    d: DiscretePHS,
    C_m: np.ndarray,
    L: np.ndarray,
    intensity: np.ndarray,
    input_intensity: np.ndarray | None = None,
    triangularization: str = "auto",
) -> ErrorStatistics:
    """Triangularize the noise-driven error system of ``d`` and solve its Lyapunov equation."""
    A, G, _ = noise_input(d, C_m, L, intensity, input_intensity)
    pencil = triangularize(A, d.E, G, triangularization)
    lam = pencil.eigenvalues
    stable = bool(np.all(lam.real < -1e-12 * np.maximum(1.0, np.abs(lam))))
    return ErrorStatistics(d, pencil, pencil.covariance() if stable else None)


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


def noise(
    nm: NumericModel,
    C_m: np.ndarray,
    L: np.ndarray,
    *,
    intensity: Any = None,
    input_intensity: Any = None,
    performance: Sequence[Functional | str] | None = None,
    model: Any = None,
    method: str | None = None,
    resolution: int | None = None,
    max_resolution: int | None = None,
    tol: float | None = None,
    discretizations: MutableMapping[int, DiscretePHS] | None = None,
) -> NoiseReport:
    r"""Noise figures of an observer, each with its verdict under refinement.

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray
        Sensors (q × N n) and gain (q × q, L + Lᵀ ≻ 0).
    intensity : float or sequence of float, optional
        Sensor noise intensities σᵢ² (one per sensor, or one for all; default 1).
    input_intensity : float or sequence of float, optional
        Intensities of white noise on the plant inputs (one per input, or one for all);
        default: no input noise.
    performance : sequence of Functional or str, optional
        Outputs whose estimation-error variance is reported (``"w(1)"``, ``"e1(1)"``,
        ``"x2: sin(pi*z)"``, see :mod:`phdesign.numeric.discretization.functionals`); default: the
        displacement at b when the model defines one.
    model : BCPHS, optional
        The symbolic model, for parameters in the text of performance outputs.
    method : str, optional
        A registered discretization; default: the table's (:mod:`phdesign.core.defaults`).
    resolution, max_resolution : int, optional
        First and largest resolution (default: the spectrum's, e.g. 20 and 110).
    tol : float, optional
        Relative agreement that makes a figure converged (default: the method's row of the
        table, 1e-6 Galerkin, 1e-3 FD).
    discretizations : dict, optional
        A cache ``{resolution: DiscretePHS}`` shared between calls (filled as needed).

    Returns
    -------
    NoiseReport

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> wave = load_builtin("wave")  # string with the damper u_z(1) = -k u_t(1) - k nu
    >>> rep = noise(to_numeric(wave), np.array([[0.0, 1.0]]), np.array([[0.5]]),
    ...             performance=["x2: 1"], model=wave)
    >>> round(rep.performance[0].value, 8), rep.error_energy.diverges  # Var = k/2
    (0.25, True)
    """
    C = sensor_rows(C_m, "the noise figures")
    Lm = np.atleast_2d(np.asarray(L, dtype=float))
    feedback_matrix(C, Lm, nm.n_ports)  # shapes and L + L^T > 0, before any work
    sigma, w_in = noise_intensities(nm, C.shape[0], intensity, input_intensity)
    functionals = parse_functionals(performance, nm, model)
    method = method_or_default(method)
    row = current().discretization(method, nm.order)  # the noise's and spectrum's tolerances
    tol = row.noise_tol if tol is None else positive_number(tol, "tol")
    rtol = row.resolved_rtol
    p0, pmax = default_resolutions(nm, method)
    p = p0 if resolution is None else positive_int(resolution, "resolution")
    limits.check_noise_resolution(nm, p, "resolution")
    if max_resolution is None:
        # the default refinement stops within the budget (a size-16 model: degree 61)
        pmax = max(p, min(pmax, limits.MAX_NOISE_STATES // nm.size - 1))
    else:
        pmax = positive_int(max_resolution, "max_resolution")
        limits.check_noise_resolution(nm, pmax, "max_resolution")
        if pmax < p:
            raise NumericError(
                f"max_resolution must be at least the first resolution {p}; found {pmax}"
            )
    cache = discretizations if discretizations is not None else {}

    run = _Refinement(functionals, tol)
    while True:
        if p not in cache:
            cache[p] = discretize(nm, method, p)
        d = cache[p]
        run.add(error_statistics(d, C, Lm, sigma, w_in), [f.row(d) for f in functionals], rtol)
        nxt = math.ceil(1.5 * p)
        if run.done() or nxt > pmax:
            break
        p = nxt
    return run.report(nm, C, Lm, sigma, w_in, method)


def _gain_pair(
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


def _discrete_sup(stats: ErrorStatistics) -> tuple[float, float]:
    """Supremum of the discretization's response over all frequencies (a diagnostic)."""
    lam = stats.eigenvalues
    top = float(np.max(np.abs(lam[np.isfinite(lam)]))) if lam.size else 1.0
    return _sup(stats, 2.0 * top, refine=1)


class _Refinement:
    """The figures at each resolution so far, and their verdicts."""

    def __init__(self, functionals: Sequence[Functional], tol: float) -> None:
        self.functionals = tuple(functionals)
        self.tol = tol
        self.stats: list[ErrorStatistics] = []
        self.variances: list[list[float]] = []
        self.sups: list[tuple[float, float]] = []
        self.pairs: list[dict[str, Any]] = []

    def add(self, stats: ErrorStatistics, rows: list[np.ndarray], rtol: float) -> None:
        self.stats.append(stats)
        self.variances.append([stats.variance(r) for r in rows])
        self.sups.append(_discrete_sup(stats) if stats.stable else (math.inf, math.nan))
        if len(self.stats) >= 2:
            self.pairs.append(_gain_pair(self.stats[-2], stats, rtol, self.tol))

    @property
    def steady(self) -> bool:
        return all(s.stable for s in self.stats)

    @property
    def resolutions(self) -> tuple[int, ...]:
        return tuple(s.resolution for s in self.stats)

    def performance(self) -> list[Estimate]:
        return [
            settle(f.name, [v[i] for v in self.variances], self.resolutions, self.tol)
            for i, f in enumerate(self.functionals)
        ]

    def energy(self) -> Estimate:
        return settle("E[H~]", [s.energy() for s in self.stats], self.resolutions, self.tol)

    def gain(self) -> GainEstimate:
        res = self.resolutions
        if not self.steady:
            return GainEstimate.missing(res)
        discrete = settle("discrete sup", [v for v, _ in self.sups], res, self.tol)
        banded = [pr for pr in self.pairs if pr.get("band") is not None]
        if not banded:
            return GainEstimate.missing(res, discrete, self.sups[-1][1])
        last = banded[-1]
        estimate = settle(
            "gamma",
            [pr["fine"][0] for pr in banded],
            [pr["resolution"] for pr in banded],
            self.tol,
            pair=(last["coarse"][0], last["fine"][0]),
        )
        if last["fine"][1] >= (1 - 1e-6) * last["band"] and estimate.converged:
            # a peak at the band's edge is where the resolved frequencies end, not a maximum
            estimate = replace(estimate, converged=False)
        return GainEstimate(
            estimate=estimate,
            frequency=last["fine"][1],
            frequencies=tuple(pr["fine"][1] for pr in banded),
            band=last["band"],
            discrete=discrete,
            discrete_frequency=self.sups[-1][1],
        )

    def done(self) -> bool:
        """Every figure converged or diverging (three resolutions at least), or no steady state."""
        if not self.steady:
            return True
        figures = [*self.performance(), self.energy(), self.gain().estimate]
        return len(self.stats) >= 3 and all(f.converged or f.diverges for f in figures)

    def report(
        self,
        nm: NumericModel,
        C: np.ndarray,
        Lm: np.ndarray,
        sigma: np.ndarray,
        w_in: np.ndarray | None,
        method: str,
    ) -> NoiseReport:
        warnings: list[str] = []
        if not self.steady:
            bad = next(s for s in self.stats if not s.stable)
            worst = bad.eigenvalues[np.argmax(bad.eigenvalues.real)]
            warnings.append(
                f"the error system is not exponentially stable at resolution {bad.resolution} "
                f"(eigenvalue {worst:.6g}): no stationary error exists and the noise figures "
                "are infinite"
            )
        performance, energy, gain = self.performance(), self.energy(), self.gain()
        for est in performance:
            warnings += _figure_warnings(f"Var[{est.name}~]", est, self.tol, smooth_hint=True)
        warnings += _figure_warnings("E[H~]", energy, self.tol, smooth_hint=False)
        warnings += gain.warnings(self.tol)
        return NoiseReport(
            model=nm.name,
            sensors=C,
            gain=Lm,
            intensity=tuple(float(s) for s in sigma),
            input_intensity=None if w_in is None else tuple(float(s) for s in w_in),
            performance=tuple(performance),
            l2_gain=gain,
            error_energy=energy,
            resolutions=self.resolutions,
            method=method,
            steady_state=self.steady,
            output_labels=nm.output_labels,
            warnings=tuple(warnings),
            pencils=tuple(s.pencil for s in self.stats) if self.steady else (),
        )


def _figure_warnings(label: str, est: Estimate, tol: float, smooth_hint: bool) -> list[str]:
    values = ", ".join(f"{v:.4g}" for v in est.values)
    at = ", ".join(str(r) for r in est.resolutions)
    if est.diverges:
        why = (
            "it is not a smooth functional of the error: a boundary trace of a PDE driven "
            "by white noise at its boundary has infinite variance"
            if smooth_hint
            else "white noise entering at the boundary gives the PDE an infinite "
            "steady-state error energy; only smooth functionals of the error have a "
            "finite variance"
        )
        grows = "" if est.growth is None else f"; grows like p^{est.growth:.2f}"
        return [f"{label} diverges under refinement ({values} at resolutions {at}{grows}): {why}"]
    if not est.converged and len(est.values) >= 2 and all(map(math.isfinite, est.values)):
        return [f"{label} did not converge to {tol:g} ({values} at resolutions {at})"]
    return []
