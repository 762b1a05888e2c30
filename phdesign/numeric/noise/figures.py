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
The discretization's own supremum over all frequencies (a sweep of the whole band) is
reported beside it, unless ``discrete_sup=False`` (the trade-off's points).
"""

from __future__ import annotations

import math
from collections.abc import MutableMapping, Sequence
from typing import Any

import numpy as np

from phdesign.core import limits
from phdesign.core.checks import positive_int, positive_number
from phdesign.core.defaults import current, method_or_default
from phdesign.core.errors import NumericError, ObserverError
from phdesign.core.progress import report
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_noise_intensity
from phdesign.numeric.discretization.functionals import Functional, parse_functionals
from phdesign.numeric.discretization.registry import DiscretePHS, discretize, feedback_matrix
from phdesign.numeric.noise.gain import PeakSearch, banded_gain, gain_pair
from phdesign.numeric.noise.metrics import ErrorEnergy, Metric, OutputVariance
from phdesign.numeric.noise.report import GainEstimate, NoiseReport
from phdesign.numeric.noise.settle import Estimate, settle
from phdesign.numeric.noise.statistics import ErrorStatistics, error_statistics
from phdesign.numeric.spectrum.converged import default_resolutions
from phdesign.numeric.threads import limited_threads

__all__ = [
    "GainEstimate",
    "NoiseReport",
    "check_intensity",
    "noise",
    "noise_intensities",
    "refinement_plan",
    "sensor_rows",
]


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
        w_in = check_intensity(input_intensity, nm.n_ports, "input_intensity")
    return sigma, w_in


def sensor_rows(C_m: Any, what: str) -> np.ndarray:
    """Return C_m as a 2-D float array, refusing an empty one (``what`` needs sensors)."""
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    if C.size == 0:
        raise ObserverError(f"{what}: sensors needed; give C_m with at least one row")
    return C


def refinement_plan(
    nm: NumericModel,
    method: str,
    resolution: int | None,
    max_resolution: int | None,
    tol: float | None,
) -> tuple[int, int, float, float]:
    """Return the first and largest resolution and the tolerances of a noise refinement.

    ``(p, pmax, tol, rtol)``: the spectrum's resolutions within the noise budget, the
    method's noise tolerance (unless ``tol``) and its drift tolerance.
    """
    row = current().discretization(method, nm.order)  # the noise's and spectrum's tolerances
    tol = row.noise_tol if tol is None else positive_number(tol, "tol")
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
    return p, pmax, tol, row.resolved_rtol


@limited_threads
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
    metrics: Sequence[Metric] = (),
    discrete_sup: bool = True,
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
    metrics : sequence of Metric, optional
        Further figures, one number per resolution each (:mod:`phdesign.numeric.noise.metrics`:
        a new figure is one class), judged like the others and reported in ``figures``.
    discrete_sup : bool, optional
        Also report the discretization's own supremum over all frequencies
        (``l2_gain.discrete``, and the warning when it exceeds the banded gain): a sweep of
        the whole band at every resolution.  The trade-off leaves it out.

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
    p, pmax, tol, rtol = refinement_plan(nm, method, resolution, max_resolution, tol)
    cache = discretizations if discretizations is not None else {}

    run = _Refinement(functionals, tuple(metrics), tol, discrete=discrete_sup)
    while True:
        report(f"noise: resolution {p}")
        if p not in cache:
            cache[p] = discretize(nm, method, p)
        run.add(error_statistics(cache[p], C, Lm, sigma, w_in), rtol)
        nxt = math.ceil(1.5 * p)
        if run.done() or nxt > pmax:
            break
        p = nxt
    return run.report(nm, C, Lm, sigma, w_in, method)


class _Refinement:
    """The figures at each resolution so far, and their verdicts.

    The per-resolution figures are :class:`~phdesign.numeric.noise.metrics.Metric` s: the
    variance of each performance output, the error energy, then the caller's; the L²-gain
    is computed per pair of resolutions.
    """

    def __init__(
        self,
        functionals: Sequence[Functional],
        extra: tuple[Metric, ...],
        tol: float,
        discrete: bool = True,
    ):
        self.outputs = tuple(OutputVariance(functional=f) for f in functionals)
        self.metrics = (*self.outputs, ErrorEnergy(), *extra)
        self.tol = tol
        self.discrete = discrete
        self.stats: list[ErrorStatistics] = []
        self.searches: list[PeakSearch] = []
        self.values: list[list[float]] = []
        self.sups: list[tuple[float, float]] = []
        self.pairs: list[dict[str, Any]] = []

    def add(self, stats: ErrorStatistics, rtol: float) -> None:
        search = PeakSearch(stats)  # its refined peaks serve both pairs of this resolution
        self.stats.append(stats)
        self.searches.append(search)
        self.values.append([m.value(stats) for m in self.metrics])
        if self.discrete:
            self.sups.append(search.discrete() if stats.stable else (math.inf, math.nan))
        if len(self.stats) >= 2:
            self.pairs.append(gain_pair(self.searches[-2], search, rtol, self.tol))

    @property
    def steady(self) -> bool:
        return all(s.stable for s in self.stats)

    @property
    def resolutions(self) -> tuple[int, ...]:
        return tuple(s.resolution for s in self.stats)

    def estimates(self) -> list[Estimate]:
        """Every metric's verdict over the resolutions so far, in the metrics' order."""
        return [
            settle(m.name, [v[i] for v in self.values], self.resolutions, self.tol)
            for i, m in enumerate(self.metrics)
        ]

    def performance(self) -> list[Estimate]:
        return self.estimates()[: len(self.outputs)]

    def energy(self) -> Estimate:
        return self.estimates()[len(self.outputs)]

    def gain(self) -> GainEstimate:
        return banded_gain(self.pairs, self.sups, self.resolutions, self.steady, self.tol)

    def done(self) -> bool:
        """Every figure converged or diverging (three resolutions at least), or no steady state."""
        if not self.steady:
            return True
        figures = [*self.estimates(), self.gain().estimate]
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
        estimates, gain = self.estimates(), self.gain()
        for metric, est in zip(self.metrics, estimates, strict=True):
            warnings += _figure_warnings(metric.label, est, self.tol, smooth_hint=metric.smooth)
        warnings += gain.warnings(self.tol)
        n = len(self.outputs)
        return NoiseReport(
            model=nm.name,
            sensors=C,
            gain=Lm,
            intensity=tuple(float(s) for s in sigma),
            input_intensity=None if w_in is None else tuple(float(s) for s in w_in),
            performance=tuple(estimates[:n]),
            l2_gain=gain,
            error_energy=estimates[n],
            figures=tuple(estimates[n + 1 :]),
            resolutions=self.resolutions,
            method=method,
            steady_state=self.steady,
            output_labels=nm.output_labels,
            warnings=tuple(warnings),
            pencils=tuple(s.pencil for s in self.stats) if self.steady else (),
            time_unit=dict(nm.units).get("t"),
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
