r"""Gain design against disturbances: the gain report's H∞ or H₂ norm as objective or bound.

Over positive diagonal gains :math:`L = \operatorname{diag}(e^{x})`, with
:math:`\gamma(L)` the H∞ norm and :math:`\|G_L\|_2` the H₂ norm from the disturbances
and the sensor noise to the estimation error of the performance outputs (the figures of
:func:`~phdesign.numeric.noise.disturbance.disturbance_gain`, ``phdesign gain``) and
:math:`\alpha(L)` the converged spectral abscissa of the error system:

``objective="hinf"`` (or ``"h2"``), optionally ``min_decay=a``
    minimize :math:`\gamma(L)` (or :math:`\|G_L\|_2`) subject to :math:`\alpha(L) \le -a`;
``objective="abscissa"``, ``max_hinf=g``
    minimize :math:`\alpha(L)` subject to :math:`\gamma(L) \le g`.

During the search the figures are computed at fixed resolutions, those the gain report
at :math:`L = I` ended on: its finest pair :math:`(p_c, p_f)` gives the H∞ norm (the
fine member's peak over the band the pair resolves,
:func:`~phdesign.numeric.noise.gain.gain_pair`) and :math:`p_f` the H₂ norm (the
Lyapunov value); the abscissa is that of the pair ``spectrum()`` converged on at
:math:`L = I` (:class:`~phdesign.numeric.spectrum.evaluator.AbscissaEvaluator`).  The
search and its exact penalty are those of the noise-aware tuning
(:mod:`phdesign.numeric.noise.tuning`).  The tuned gain is then verified from scratch:
the adaptive gain report and spectrum at it are what the result reports, and for the
``hinf`` and ``h2`` objectives the result is never worse than :math:`L = I`: when the
verified figure is not below the start's, the start is returned, with a warning.

Damped-tip string check (``tests/numeric/noise/test_disturbance_tuning.py``): the string
with sensor :math:`y_2 = e_1(1)`, gain k, a uniform force and :math:`z_p = \int_0^1 e_1`,
without sensor noise, has for error the damped-tip string of damper k, whose
:math:`\gamma(k)` is known in closed form: its minimum lies near k = 0.96.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.defaults import current, method_or_default
from phdesign.core.errors import NumericError
from phdesign.core.progress import stage
from phdesign.core.text import gain_text, html_table
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.functionals import performance_functional
from phdesign.numeric.discretization.registry import discretize, feedback_matrix
from phdesign.numeric.disturbance_inputs import disturbance_inputs, performance_terms
from phdesign.numeric.noise.disturbance import disturbance_gain, disturbance_statistics
from phdesign.numeric.noise.disturbance_report import GainReport
from phdesign.numeric.noise.figures import refinement_plan, sensor_rows
from phdesign.numeric.noise.gain import gain_pair
from phdesign.numeric.noise.settle import finite_or_none
from phdesign.numeric.noise.tuning import PenaltyMerit, positive_bound, search_gain
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.spectrum.evaluator import AbscissaEvaluator
from phdesign.numeric.spectrum.report import SpectrumReport
from phdesign.numeric.threads import limited_threads

__all__ = ["DISTURBANCE_OBJECTIVES", "DisturbanceTuneResult", "tune_disturbance"]

#: The objectives of :func:`tune_disturbance`.
DISTURBANCE_OBJECTIVES = ("hinf", "h2", "abscissa")
#: An abscissa below this counts as this (an empty spectrum: decay in finite time).
_FASTEST = -1e6


@dataclass(frozen=True)
class DisturbanceTuneResult:
    """Result of :func:`tune_disturbance`: the tuned gain and its verified figures.

    Attributes
    ----------
    objective : {"hinf", "h2", "abscissa"}
    bound : float or None
        The decay rate a required (``hinf``, ``h2``; None: unconstrained) or the H∞ bound
        g (``abscissa``).
    gain : ndarray
    report : GainReport
        The gain report at ``gain``, computed from scratch.
    start : GainReport
        The gain report at the starting gain L = I.
    spectrum : SpectrumReport
        The converged spectrum of the error system at ``gain``.
    feasible : bool
        The verified figures meet the constraint.
    evaluations : int
        Merit evaluations of the search.
    warnings : tuple of str
    """

    objective: str
    bound: float | None
    gain: np.ndarray
    report: GainReport
    start: GainReport
    spectrum: SpectrumReport
    feasible: bool
    evaluations: int = 0
    warnings: tuple[str, ...] = field(default=())

    @property
    def hinf(self) -> float | None:
        """The verified H∞ norm at the tuned gain (None unless converged)."""
        return self.report.hinf.value

    @property
    def h2(self) -> float | None:
        """The verified H₂ norm at the tuned gain (None unless converged)."""
        return self.report.h2.value

    @property
    def spectral_abscissa(self) -> float | None:
        """The verified spectral abscissa at the tuned gain (None: unbounded below)."""
        return self.spectrum.spectral_abscissa

    @property
    def constraint(self) -> str:
        """The constraint in words."""
        if self.objective == "abscissa":
            return f"H∞ <= {self.bound:g}"
        if self.bound is None:
            return "none"
        return f"spectral abscissa <= {-self.bound:g} (decay rate >= {self.bound:g})"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (``phdesign tune --objective hinf|h2 / --max-hinf --json``)."""
        return {
            "objective": self.objective,
            "constraint": self.constraint,
            "bound": self.bound,
            "gain": self.gain.tolist(),
            "spectral_abscissa": finite_or_none(self.spectral_abscissa),
            "abscissa_converged": self.spectrum.converged,
            "hinf": finite_or_none(self.hinf),
            "h2": finite_or_none(self.h2),
            "start": {
                "gain": np.eye(self.gain.shape[0]).tolist(),
                "hinf": finite_or_none(self.start.hinf.value),
                "h2": finite_or_none(self.start.h2.value),
            },
            "feasible": self.feasible,
            "evaluations": self.evaluations,
            "report": self.report.to_dict(),
            "warnings": list(self.warnings),
        }

    def __str__(self) -> str:
        goal = {
            "hinf": "minimize the H∞ norm",
            "h2": "minimize the H2 norm",
            "abscissa": "minimize the spectral abscissa",
        }[self.objective]
        alpha = (
            "unbounded below"
            if self.spectral_abscissa is None
            else f"{self.spectral_abscissa:.10g} (converged: {self.spectrum.converged})"
        )
        lines = [
            f"model: {self.report.model}   {goal} from {', '.join(self.report.sources)} to "
            f"the error of {', '.join(self.report.outputs)}, subject to: {self.constraint}",
            f"gain L = {gain_text(self.gain)}",
            f"spectral abscissa: {alpha}",
            f"H∞: {_text(self.hinf)}   (at L = I: {_text(self.start.hinf.value)})",
            f"H2: {_text(self.h2)}   (at L = I: {_text(self.start.h2.value)})",
            f"constraint met: {self.feasible}   ({self.evaluations} evaluations)",
        ]
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (
            f"DisturbanceTuneResult(objective={self.objective!r}, gain={gain_text(self.gain)}, "
            f"hinf={self.hinf!r}, h2={self.h2!r}, feasible={self.feasible})"
        )[:300]

    def _repr_html_(self) -> str:
        rows = [
            ("gain L", gain_text(self.gain)),
            ("spectral abscissa", f"{self.spectral_abscissa}"),
            ("H∞", _text(self.hinf)),
            ("H2", _text(self.h2)),
            ("constraint", self.constraint),
            ("met", str(self.feasible)),
        ]
        return html_table(
            ("", "value"), rows, f"gain design against disturbances: {self.report.model}"
        )


def _text(value: float | None) -> str:
    """Return a verified norm to 10 digits, or why there is none."""
    return "not converged" if value is None else f"{value:.10g}"


@dataclass(frozen=True)
class _Problem:
    """What is tuned: the design's numbers, the objective and its bound."""

    nm: NumericModel
    model: Any
    C: np.ndarray
    intensity: Any
    performance: Sequence[str] | None
    objective: str
    bound: float | None
    method: str

    def report(self, L: np.ndarray) -> GainReport:
        """Return the gain report at ``L``, refined from scratch."""
        return disturbance_gain(
            self.nm,
            self.C,
            L,
            model=self.model,
            intensity=self.intensity,
            performance=self.performance,
            method=self.method,
        )

    @property
    def figure(self) -> str:
        """The norm the search reads: ``"h2"``, else the H∞ norm."""
        return "h2" if self.objective == "h2" else "hinf"

    @property
    def needs_abscissa(self) -> bool:
        """Whether the search reads the abscissa (its objective or its constraint)."""
        return self.objective == "abscissa" or self.bound is not None


class _Figures:
    """The abscissa and the norm at L = diag(e^x), at the resolutions fixed by L = I."""

    def __init__(self, problem: _Problem, start: GainReport) -> None:
        nm, model = problem.nm, problem.model
        self.problem = problem
        self.B, self.unknown = disturbance_inputs(model, nm)
        self.outputs = tuple(
            performance_functional(nm, *terms)
            for terms in performance_terms(model, nm, problem.performance)
        )
        self.sigma = np.asarray(start.intensity, dtype=float)
        _, _, self.tol, self.rtol = refinement_plan(nm, problem.method, None, None, None)
        coarse, fine = start.resolutions[-2:] if len(start.resolutions) >= 2 else (0, 0)
        if not coarse:
            coarse, fine = start.resolutions[0], math.ceil(1.5 * start.resolutions[0])
        self.pair = tuple(discretize(nm, problem.method, p) for p in (coarse, fine))
        self.abscissa = None
        if problem.needs_abscissa:  # the pair of the plain tuning
            first = spectrum(nm, problem.C, np.eye(problem.C.shape[0]), method=problem.method)
            row = current().discretization(first.method, nm.order)
            p = first.resolutions[0] if first.converged else row.tune_fallback
            self.abscissa = AbscissaEvaluator(nm, problem.C, p, method=problem.method)

    def __call__(self, x: np.ndarray) -> tuple[float | None, float]:
        """Return the resolved abscissa (None: not computed or unresolved) and the norm."""
        L = np.diag(np.exp(np.clip(x, -30.0, 30.0)))
        alpha = None
        if self.abscissa is not None:
            value = self.abscissa(L)
            alpha = None if math.isnan(value) else max(value, _FASTEST)
        return alpha, self.norm(L)

    def norm(self, L: np.ndarray) -> float:
        """Return the search's H∞ or H₂ norm at ``L`` (inf: not exponentially stable)."""
        C = self.problem.C
        args = (self.B, self.unknown, self.outputs, C, L, self.sigma)
        fine = disturbance_statistics(self.pair[1], *args)
        if not fine.stable:
            return math.inf
        if self.problem.figure == "h2":
            return fine.h2()
        coarse = disturbance_statistics(self.pair[0], *args)
        if not coarse.stable:
            return math.inf
        pair = gain_pair(coarse.source(), fine.source(), self.rtol, self.tol)
        return math.inf if pair.get("band") is None else float(pair["fine"][0])


def check_objective(
    objective: str, max_hinf: float | None, min_decay: float | None
) -> float | None:
    """Return the bound of ``objective`` (the module docstring), refusing what does not fit."""
    if objective not in DISTURBANCE_OBJECTIVES:
        raise NumericError(
            f"objective must be one of {', '.join(DISTURBANCE_OBJECTIVES)}; found {objective!r}"
        )
    if objective == "abscissa":
        if min_decay is not None:
            raise NumericError("min_decay is a constraint of the hinf and h2 objectives")
        return positive_bound(max_hinf, "max_hinf", "the abscissa objective needs an H∞ bound")
    if max_hinf is not None:
        raise NumericError(
            f"max_hinf is a constraint of the abscissa objective, not of {objective!r}: "
            "give min_decay to bound the decay"
        )
    return None if min_decay is None else positive_bound(min_decay, "min_decay", "")


@limited_threads
def tune_disturbance(
    nm: NumericModel,
    C_m: np.ndarray,
    *,
    model: Any,
    objective: str = "hinf",
    max_hinf: float | None = None,
    min_decay: float | None = None,
    intensity: Any = None,
    performance: Sequence[str] | None = None,
    method: str | None = None,
    log_range: tuple[float, float] = (-4.0, 3.0),
    maxiter: int = 150,
) -> DisturbanceTuneResult:
    """Tune a positive diagonal gain against the disturbances (module docstring).

    Parameters
    ----------
    nm : NumericModel
    C_m : ndarray (q, N n)
    model : BCPHS
        The symbolic model: its ``[disturbances]`` and ``[performance]``.
    objective : {"hinf", "h2", "abscissa"}
    max_hinf : float, optional
        The H∞ bound g of the abscissa objective.
    min_decay : float, optional
        The decay rate a > 0 to guarantee (``hinf`` and ``h2``; default none).
    intensity : float or sequence of float, optional
        Sensor noise intensities σᵢ² (default 1; 0 leaves the noise out).
    performance : sequence of str, optional
        Outputs in the ``[performance]`` grammar (default: the model's).
    method : str, optional
    log_range, maxiter
        As for :func:`phdesign.numeric.noise.tuning.tune_noise`.

    Returns
    -------
    DisturbanceTuneResult
    """
    C = sensor_rows(C_m, "disturbance-aware tuning")
    q = C.shape[0]
    feedback_matrix(C, np.eye(q), nm.n_ports)
    bound = check_objective(objective, max_hinf, min_decay)
    method = method_or_default(method)
    problem = _Problem(nm, model, C, intensity, performance, objective, bound, method)
    with stage("tune: the gain report at L = I"):
        start = problem.report(np.eye(q))
        _check_start(problem, start)
        minimized = "abscissa" if problem.objective == "abscissa" else "figure"
        merit = PenaltyMerit(_Figures(problem, start), minimized, bound, "disturbance-aware")
    best = search_gain(merit, q, log_range, maxiter)
    with stage("tune: verifying the best gain"):
        return _verified(problem, start, np.diag(np.exp(best.x)), merit.evaluations)


def _check_start(problem: _Problem, start: GainReport) -> None:
    """Refuse a norm that is infinite at L = I: there is nothing to minimize or bound."""
    figure = start.h2 if problem.figure == "h2" else start.hinf.estimate
    if start.unstable is not None or figure.diverges:
        name = "H2" if problem.figure == "h2" else "H∞"
        raise NumericError(
            f"the {name} norm of {problem.nm.name!r} is infinite at L = I (it diverges under "
            f"refinement or the error system is not exponentially stable): it cannot be "
            f"{'minimized' if problem.objective != 'abscissa' else 'bounded'}; "
            f"{'choose other performance outputs' if name == 'H2' else 'check the design'}"
        )


def _verified(
    problem: _Problem, start: GainReport, L: np.ndarray, evaluations: int
) -> DisturbanceTuneResult:
    """Verify the gain from scratch; for hinf and h2 keep L = I when it was not beaten."""
    q = L.shape[0]
    tuned = problem.report(L)
    warnings = []
    if problem.objective != "abscissa":
        found, initial = (_norm(r, problem.figure) for r in (tuned, start))
        if initial is not None and (found is None or found >= initial):
            warnings.append(
                "the search found no gain better than the start L = I (verified): L = I is "
                "returned"
            )
            L, tuned = np.eye(q), start
    spec = spectrum(problem.nm, problem.C, L, method=problem.method)
    feasible = _feasible(problem, tuned, spec)
    if not feasible:
        warnings.append(f"no gain found meets the constraint {_constraint(problem)}")
    if _norm(tuned, problem.figure) is None:
        warnings.append("the tuned norm did not converge under refinement")
    return DisturbanceTuneResult(
        objective=problem.objective,
        bound=problem.bound,
        gain=L,
        report=tuned,
        start=start,
        spectrum=spec,
        feasible=feasible,
        evaluations=evaluations,
        warnings=(*spec.warnings, *warnings),
    )


def _norm(report: GainReport, figure: str) -> float | None:
    return report.h2.value if figure == "h2" else report.hinf.value


def _feasible(problem: _Problem, tuned: GainReport, spec: SpectrumReport) -> bool:
    bound = problem.bound
    if bound is None:
        return True
    if problem.objective == "abscissa":
        return tuned.hinf.value is not None and tuned.hinf.value <= bound * (1 + 1e-6)
    alpha = spec.spectral_abscissa
    return bool(spec.unbounded_below or (alpha is not None and alpha <= -bound * (1 - 1e-6)))


def _constraint(problem: _Problem) -> str:
    if problem.objective == "abscissa":
        return f"H∞ <= {problem.bound:g}"
    return f"alpha <= {-(problem.bound or 0.0):g}"
