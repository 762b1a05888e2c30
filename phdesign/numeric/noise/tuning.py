r"""Noise-aware gain tuning: the fastest observer within a noise budget, and the reverse.

Two problems over positive diagonal gains :math:`L = \operatorname{diag}(e^{x})`:

``objective="abscissa"``, ``max_rms=R``
    minimize the converged spectral abscissa :math:`\alpha(L)` of the error system subject
    to :math:`\max_i \mathrm{rms}_i(L) \le R`, the RMS of the estimation error of every
    performance output at the given noise intensities;
``objective="rms"``, ``min_decay=a``
    minimize :math:`\max_i \mathrm{rms}_i(L)` subject to :math:`\alpha(L) \le -a`.

The abscissa is the resolved one (the drift test of :mod:`phdesign.numeric.spectrum.drift`
and the abscissa rule of :mod:`phdesign.numeric.spectrum.abscissa` on a resolution pair, with
the method's tolerances, as the plain tuning does) and the variances are the Lyapunov values at
a resolution where they converged for the starting gain.  The abscissa is not smooth
(its minimum typically sits at a coalescence of eigenvalues), so the search is a
log-grid of starts followed by Nelder-Mead on the exact penalty
:math:`f + \mu \max(0, g)` of the normalized constraint g, from the two best starts.
The optimum is then verified with the adaptive
:func:`~phdesign.numeric.spectrum.converged.spectrum`
and :func:`~phdesign.numeric.noise.figures.noise`, and the result says whether the verified
figures meet the constraint.

Damped wave check (sensor 2, gain k, output :math:`\int_0^1 x_2\,dz`): α = ½ ln|(1−k)/(1+k)|
and rms = (σ² k/2)^{1/2}, so ``max_rms=R`` gives :math:`k^* = 2R^2/\sigma^2` (for
:math:`k^* < 1`) and ``min_decay=a`` gives :math:`k^* = \tanh a`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from itertools import product
from typing import Any

import numpy as np
from scipy.optimize import minimize, minimize_scalar

from phdesign.core.defaults import OrderDefaults, current
from phdesign.core.errors import NumericError
from phdesign.core.progress import report, stage
from phdesign.core.text import gain_text, html_table
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.functionals import Functional, parse_functionals
from phdesign.numeric.discretization.registry import DiscretePHS, discretize, feedback_matrix
from phdesign.numeric.noise.figures import noise, noise_intensities, sensor_rows
from phdesign.numeric.noise.report import NoiseReport
from phdesign.numeric.noise.settle import finite_or_none
from phdesign.numeric.noise.statistics import error_statistics
from phdesign.numeric.spectrum.abscissa import estimate_abscissa
from phdesign.numeric.spectrum.converged import eigen, spectrum
from phdesign.numeric.spectrum.drift import pair_spectrum
from phdesign.numeric.spectrum.report import SpectrumReport
from phdesign.numeric.threads import limited_threads

__all__ = [
    "NoiseTuneResult",
    "PenaltyMerit",
    "SearchBest",
    "positive_bound",
    "search_gain",
    "tune_noise",
]

_PENALTY = 100.0  # weight of a normalized constraint violation in the merit function


@dataclass(frozen=True)
class NoiseTuneResult:
    """Result of :func:`tune_noise`.

    Attributes
    ----------
    objective : {"abscissa", "rms"}
    bound : float
        R (max RMS) for the abscissa objective, a (min decay) for the RMS objective.
    gain : ndarray
    spectral_abscissa : float or None
        Verified (adaptive) abscissa at ``gain``.
    rms : float or None
        Verified largest RMS over the performance outputs (None unless all converged).
    feasible : bool
        The verified figures meet the constraint.
    spectrum : SpectrumReport
    noise : NoiseReport
    evaluations : int
        Merit-function evaluations of the search.
    warnings : tuple of str
    """

    objective: str
    bound: float
    gain: np.ndarray
    spectral_abscissa: float | None
    rms: float | None
    feasible: bool
    spectrum: SpectrumReport
    noise: NoiseReport
    evaluations: int = 0
    warnings: tuple[str, ...] = field(default=())

    @property
    def constraint(self) -> str:
        """The constraint in words."""
        if self.objective == "abscissa":
            return f"error rms <= {self.bound:g}"
        return f"spectral abscissa <= {-self.bound:g} (decay rate >= {self.bound:g})"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (``phdesign tune --max-rms/--objective rms --json``)."""
        return {
            "objective": self.objective,
            "constraint": self.constraint,
            "bound": self.bound,
            "gain": self.gain.tolist(),
            "spectral_abscissa": finite_or_none(self.spectral_abscissa),
            "abscissa_converged": self.spectrum.converged,
            "rms": finite_or_none(self.rms),
            "feasible": self.feasible,
            "evaluations": self.evaluations,
            "noise": self.noise.to_dict(),
            "warnings": list(self.warnings),
        }

    def __str__(self) -> str:
        goal = (
            "minimize the spectral abscissa"
            if self.objective == "abscissa"
            else ("minimize the error rms")
        )
        alpha = (
            "unbounded below"
            if self.spectral_abscissa is None
            else (f"{self.spectral_abscissa:.10g} (converged: {self.spectrum.converged})")
        )
        lines = [
            f"model: {self.noise.model}   {goal} subject to {self.constraint}",
            f"gain L = {gain_text(self.gain)}",
            f"spectral abscissa: {alpha}",
            "error rms: " + ("not converged" if self.rms is None else f"{self.rms:.8g}"),
            f"constraint met: {self.feasible}   ({self.evaluations} evaluations)",
        ]
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (
            f"NoiseTuneResult(objective={self.objective!r}, gain={gain_text(self.gain)}, "
            f"spectral_abscissa={self.spectral_abscissa!r}, rms={self.rms!r}, "
            f"feasible={self.feasible})"
        )[:300]

    def _repr_html_(self) -> str:
        rows = [
            ("gain L", gain_text(self.gain)),
            ("spectral abscissa", f"{self.spectral_abscissa}"),
            ("error rms", f"{self.rms}"),
            ("constraint", self.constraint),
            ("met", str(self.feasible)),
        ]
        return html_table(("", "value"), rows, f"noise-aware tuning of {self.noise.model}")

    def plot(self, path: Any = None, *, force: bool = False) -> Any:
        """Draw the noise report's figure at the tuned gain."""
        return self.noise.plot(path, force=force)


def _max_rms(report: NoiseReport) -> float | None:
    values = [e.value for e in report.performance if e.value is not None]
    if not values or len(values) < len(report.performance):
        return None
    return math.sqrt(max(values))


@limited_threads
def tune_noise(
    nm: NumericModel,
    C_m: np.ndarray,
    *,
    objective: str = "abscissa",
    max_rms: float | None = None,
    min_decay: float | None = None,
    intensity: Any = None,
    input_intensity: Any = None,
    performance: Sequence[Functional | str] | None = None,
    model: Any = None,
    log_range: tuple[float, float] = (-4.0, 3.0),
    maxiter: int = 150,
) -> NoiseTuneResult:
    """Tune a positive diagonal gain under a noise budget or a decay requirement.

    Parameters
    ----------
    nm : NumericModel
    C_m : ndarray (q, N n)
    objective : {"abscissa", "rms"}
        What to minimize (module docstring).
    max_rms : float
        The RMS budget R (required for the abscissa objective).
    min_decay : float
        The decay rate a > 0 to guarantee, α <= −a (required for the RMS objective).
    intensity, input_intensity, performance, model
        As for :func:`phdesign.numeric.noise.figures.noise` (default performance: the
        displacement at b).
    log_range : (float, float)
        Natural-log range of the start grid per diagonal entry.
    maxiter : int
        Nelder-Mead iterations per refined start (times q).

    Returns
    -------
    NoiseTuneResult
    """
    C = sensor_rows(C_m, "noise-aware tuning")
    q = C.shape[0]
    feedback_matrix(C, np.eye(q), nm.n_ports)
    if objective == "abscissa":
        bound = positive_bound(max_rms, "max_rms", "the abscissa objective needs an RMS budget")
    elif objective == "rms":
        bound = positive_bound(min_decay, "min_decay", "the RMS objective needs a decay rate")
    else:
        raise NumericError(f"objective must be 'abscissa' or 'rms'; found {objective!r}")
    sigma, w_in = noise_intensities(nm, q, intensity, input_intensity)
    functionals = parse_functionals(performance, nm, model)
    if not functionals:
        raise NumericError(
            f"noise-aware tuning needs a performance output and the model {nm.name!r} defines "
            "no displacement: give one (a trace like e1(1) or an integral like 'x2: 1')"
        )
    problem = _Problem(nm, C, sigma, w_in, tuple(functionals), objective, bound)
    with stage("tune: the figures at L = I"):
        figures = _Figures.at_converged_resolutions(problem)
        minimized = "abscissa" if problem.objective == "abscissa" else "figure"
        merit = PenaltyMerit(figures, minimized, problem.bound)
    best = search_gain(merit, q, log_range, maxiter)
    with stage("tune: verifying the best gain"):
        return _verified(problem, best, merit.evaluations, maxiter)


@dataclass(frozen=True)
class _Problem:
    """What is tuned: sensors, noise, performance outputs, objective and its bound."""

    nm: NumericModel
    C: np.ndarray
    sigma: np.ndarray
    w_in: np.ndarray | None
    functionals: tuple[Functional, ...]
    objective: str
    bound: float

    def report(self, L: np.ndarray, discrete_sup: bool = True) -> NoiseReport:
        """Return the noise figures at ``L``, refined (:func:`~.figures.noise`)."""
        return noise(
            self.nm,
            self.C,
            L,
            intensity=self.sigma,
            input_intensity=self.w_in,
            performance=list(self.functionals),
            discrete_sup=discrete_sup,
        )


@dataclass(frozen=True)
class _Figures:
    """The search's abscissa (one resolution pair) and largest RMS (one resolution)."""

    problem: _Problem
    row: OrderDefaults  # the method's tolerances (the table's row)
    pair: tuple[DiscretePHS, DiscretePHS]
    d_rms: DiscretePHS
    rows: tuple[np.ndarray, ...]

    @classmethod
    def at_converged_resolutions(cls, problem: _Problem) -> _Figures:
        """Fix the resolutions where the figures converged for the starting gain L = I."""
        nm, C, q = problem.nm, problem.C, problem.C.shape[0]
        start = problem.report(np.eye(q), discrete_sup=False)  # its variances are read
        first = spectrum(nm, C, np.eye(q))
        row = current().discretization(first.method, nm.order)
        p_lo = first.resolutions[0] if first.converged else row.tune_fallback
        # the agreement the starting figures were judged with: the method's noise tolerance
        p_rms = max(
            _first_agreeing(e, row.noise_tol) or row.tune_fallback for e in start.performance
        )
        # the variance is solved at the coarse member of the abscissa pair when it has
        # converged there (one triangularization then gives both), else at its own resolution
        p_lo = p_rms if p_rms <= p_lo else p_lo
        coarse, fine = (discretize(nm, first.method, p) for p in (p_lo, math.ceil(1.5 * p_lo)))
        d_rms = coarse if p_rms <= p_lo else discretize(nm, first.method, p_rms)
        rows = tuple(f.row(d_rms) for f in problem.functionals)
        return cls(problem, row, (coarse, fine), d_rms, rows)

    def __call__(self, x: np.ndarray) -> tuple[float | None, float]:
        """Return the resolved abscissa and the largest RMS at L = diag(e^x)."""
        p, row = self.problem, self.row
        L = np.diag(np.exp(np.clip(x, -30.0, 30.0)))
        K = feedback_matrix(p.C, L, p.nm.n_ports)
        stats = error_statistics(self.d_rms, p.C, L, p.sigma, p.w_in)
        coarse = stats.eigenvalues if self.d_rms is self.pair[0] else eigen(self.pair[0], K)[0]
        fine, kappa = eigen(self.pair[1], K, condition=True)
        drift = pair_spectrum(
            fine,
            coarse,
            resolutions=(0, 0),
            rtol=row.resolved_rtol,
            scale=1.0,
            kappa=kappa,
            dissipative=True,
        )
        alpha = estimate_abscissa(drift, row.abscissa_tol).value
        return alpha, math.sqrt(max(stats.variance(r) for r in self.rows))


class PenaltyMerit:
    r"""The exact penalty f + μ max(0, g) of the normalized constraint g (module docstring).

    ``figures(x)`` returns the abscissa α (None: unresolved or not computed) and a figure
    (an RMS, an H∞ or H₂ norm; inf: no steady state) at L = diag(e^x).  ``minimized``
    ``"abscissa"`` minimizes α subject to figure <= ``bound``; ``"figure"`` minimizes the
    figure subject to α <= -``bound`` (unconstrained when ``bound`` is None).  Each call
    is counted and reported as a ``label`` search's progress.
    """

    def __init__(
        self,
        figures: Callable[[np.ndarray], tuple[float | None, float]],
        minimized: str,
        bound: float | None,
        label: str = "noise-aware",
    ) -> None:
        self.figures, self.minimized, self.bound, self.label = figures, minimized, bound, label
        self.evaluations = 0

    def __call__(self, x: np.ndarray) -> float:
        """Return the merit at L = diag(e^x), counting the evaluation."""
        self.evaluations += 1
        report(f"tune: {self.label} search, {self.evaluations} evaluations")
        alpha, value = self.figures(x)
        bound = self.bound
        if not math.isfinite(value):  # no steady state: leave the region
            return 1e6
        if self.minimized == "figure" and bound is None:
            return value
        if alpha is None or bound is None:  # nothing resolved: leave the region
            return 1e6
        if self.minimized == "abscissa":
            return alpha + _PENALTY * max(1.0, abs(alpha)) * max(0.0, value / bound - 1.0)
        return value + _PENALTY * max(value, 1e-300) * max(0.0, (alpha + bound) / bound)


@dataclass(frozen=True)
class SearchBest:
    """The best point of the search, its merit, and whether its search was cut short."""

    x: np.ndarray
    merit: float
    unsettled: bool = False


def search_gain(
    merit: Callable[[np.ndarray], float], q: int, log_range: tuple[float, float], maxiter: int
) -> SearchBest:
    """Grid of starts, then Brent (one gain) or Nelder-Mead from the two best starts."""
    grid = _start_grid(q, log_range)
    scores = [merit(x) for x in grid]
    order = np.argsort(scores)
    best = SearchBest(grid[int(order[0])], float(scores[int(order[0])]))
    if q == 1:  # Brent between the grid neighbours of the best start
        k = int(order[0])
        lo, hi = grid[max(k - 1, 0)][0], grid[min(k + 1, len(grid) - 1)][0]
        found = minimize_scalar(
            lambda v: merit(np.array([v])),
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": 1e-6},
        )
        if found.fun < best.merit:
            best = SearchBest(np.array([found.x]), float(found.fun))
        return best
    for i in order[:2]:
        found = minimize(
            merit,
            grid[int(i)],
            method="Nelder-Mead",
            options={"maxiter": maxiter * q, "xatol": 1e-5, "fatol": 1e-9},
        )
        if found.fun < best.merit:  # unsettled: stopped by its iteration limit
            best = SearchBest(found.x, float(found.fun), not found.success)
    return best


def _verified(
    problem: _Problem, best: SearchBest, evaluations: int, maxiter: int
) -> NoiseTuneResult:
    """Verify the best gain with the adaptive spectrum and noise figures; say what failed."""
    L = np.diag(np.exp(best.x))
    spec = spectrum(problem.nm, problem.C, L)
    report = problem.report(L)
    rms = _max_rms(report)
    alpha, bound = spec.spectral_abscissa, problem.bound
    if problem.objective == "abscissa":
        feasible = rms is not None and rms <= bound * (1 + 1e-6)
    else:
        feasible = spec.unbounded_below or (alpha is not None and alpha <= -bound * (1 - 1e-6))
    warnings = list(spec.warnings)
    if not feasible:
        warnings.append(
            "no gain found meets the constraint "
            + (f"rms <= {bound:g}" if problem.objective == "abscissa" else f"alpha <= {-bound:g}")
            + f"; the best compromise found is reported (merit {best.merit:.6g})"
        )
    if rms is None:
        warnings.append("the error variance did not converge at the tuned gain")
    if best.unsettled:
        q = problem.C.shape[0]
        warnings.append(
            f"the local search stopped at its iteration limit ({maxiter * q} steps) while "
            "still moving: the gain is the best found, possibly not a local optimum; raise "
            "maxiter"
        )
    return NoiseTuneResult(
        objective=problem.objective,
        bound=bound,
        gain=L,
        spectral_abscissa=alpha,
        rms=rms,
        feasible=bool(feasible),
        spectrum=spec,
        noise=report,
        evaluations=evaluations,
        warnings=tuple(warnings),
    )


def _first_agreeing(est: Any, tol: float) -> int | None:
    """Return the coarsest resolution whose value agrees with the next one to ``tol``."""
    for k in range(len(est.values) - 1):
        a, b = est.values[k], est.values[k + 1]
        if math.isfinite(a + b) and abs(b - a) <= tol * abs(b):
            return int(est.resolutions[k])
    return None


def positive_bound(value: float | None, name: str, why: str) -> float:
    """Return ``value`` as a positive finite float; refuse None (saying ``why``) or others."""
    if value is None:
        raise NumericError(f"{why}: give {name}")
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise NumericError(f"{name} must be a positive number; found {value}")
    return v


def _start_grid(q: int, log_range: tuple[float, float]) -> list[np.ndarray]:
    """Log-spaced starts: 15 for one sensor, 7 per axis for two, 40 seeded random beyond."""
    lo, hi = log_range
    if q == 1:
        return [np.array([v]) for v in np.linspace(lo, hi, 15)]
    if q == 2:
        axis = np.linspace(lo, hi, 7)
        return [np.array(c) for c in product(axis, axis)]
    rng = np.random.default_rng(0)
    return [np.zeros(q)] + [rng.uniform(lo, hi, size=q) for _ in range(39)]
