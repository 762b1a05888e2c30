r"""Order selection for an exported observer: Galerkin degree, and optional reductions.

An observer that runs on a controller has a finite order. This module picks it from two
accuracy targets, both checked on the observer that will be exported:

*spectral*: each of the ``count`` rightmost eigenvalues :math:`\lambda` of the *converged*
    error spectrum (:func:`phdesign.numeric.spectrum.converged.spectrum`) has an observer pole
    within ``tol`` · max(1, |λ|) (the poles of the observer are the eigenvalues of its
    error system);
*performance*: the continuous observer run against a high-resolution plant (the
    verification plant, from the verification initial state) has a performance-output
    error floor (:func:`phdesign.numeric.sampled.runs.error_floor`) at most ``output_tol``
    times the output's peak. The run lasts ``t_end``, or longer when the error's
    transient needs it: :math:`\ln(10/\text{output\_tol})/|\alpha|`, after which the
    transient is a tenth of the target (the wave with α = −0.55 needs 17 s). The
    performance outputs are the displacement points (the beam's tip w(1) by default)
    or, for a model without a displacement, every output.

The smallest Galerkin degree that meets both is taken, then reduced if asked:

``"none"``
    the Galerkin observer of that degree, n(p + 1) states. Its unresolved high
    frequencies give poles right of the converged abscissa (the paper's beam at degree
    16: real parts near −0.11, the viscous damping alone, against −2.91): they are
    reported, since the observer's own transients decay there at that rate.
``"modal"``
    drop the unresolved modes: the observer's invariant subspace of the poles that agree
    with the verification plant's error spectrum (drift test of
    :func:`phdesign.numeric.spectrum.converged.match_resolved` at ``tol``) is kept, by a real Schur
    form reordered so that they lead, block-diagonalized with the Sylvester equation
    :math:`T_{11} X - X T_{22} = -T_{12}`. Every pole is then a converged one.
``"balanced"``
    balanced truncation (square-root method on the gramians python-control computes
    through slycot) to the smallest order that still meets both targets. On the
    Galerkin observers tried (beam, wave, Timoshenko) the largest Hankel singular
    values belong to the lightly damped unresolved modes, so truncation keeps the
    artefacts and drops the physics: it then does not help, and the report says so.

The report states what was dropped: the Galerkin degrees above the chosen one, the
unresolved modes, or the balanced states with their Hankel singular values.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from phdesign.core.checks import REDUCTIONS
from phdesign.core.defaults import current
from phdesign.core.errors import NumericError
from phdesign.core.progress import report as report_stage
from phdesign.core.progress import stage
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.functionals import Functional
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.registry import discretize, feedback_matrix
from phdesign.numeric.sampled.reduction import balanced_truncation, modal_truncation
from phdesign.numeric.sampled.runs import error_floor, run_loop
from phdesign.numeric.sampled.samplers import ContinuousObserver
from phdesign.numeric.sampled.selection import Candidate, OrderSelection
from phdesign.numeric.spectrum.converged import eigen, spectrum

__all__ = [
    "REDUCTIONS",
    "check_order",
    "galerkin_offset",
    "select_order",
]

#: Records of the continuous run that measures a candidate's performance floor.
FLOOR_RECORDS = 500


def galerkin_offset(nm: NumericModel) -> int:
    """Return the states a Galerkin observer has beyond ``n (p + 1)`` at every degree p.

    A coupled model's boundary systems add their states, and a port they join as a
    velocity removes the trace it imposes (:mod:`phdesign.numeric.discretization.coupled`):
    the string with a tip mass has ``2 (p + 1)`` states (``2 p + 1`` of the field, the
    mass's one), the motor-driven string ``2 (p + 1) + 1``.  Zero for most models.
    """
    if not nm.boundary:
        return 0
    lowest = nm.order + 1
    return discretize(nm, "galerkin", lowest).dim - nm.size * (lowest + 1)


def check_order(
    order: object,
    plant_order: int,
    plant_degree: int,
    *,
    reduction: str = "balanced",
    size: int = 1,
    smallest: int = 1,
    offset: int = 0,
) -> int | None:
    """Return ``order`` as an int (or None) after checking it against the request.

    The verification plant must have at least twice the observer's states, so that the
    verification is against a model the observer cannot reproduce. Without a balanced
    truncation the order is that of a Galerkin observer, a multiple of the model's
    ``size`` efforts plus ``offset`` (:func:`galerkin_offset`) and at least ``smallest``; a
    modal reduction fixes its own order.

    Examples
    --------
    >>> check_order(34, 98, 48)
    34
    >>> check_order(60, 98, 48)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    phdesign.core.errors.NumericError: order 60 needs a verification plant of at least 120 ...
    """
    if order is None:
        return None
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 1:
        raise NumericError(f"order must be a positive integer number of states; found {order!r}")
    if 2 * int(order) > plant_order:
        raise NumericError(
            f"order {order} needs a verification plant of at least {2 * int(order)} states; "
            f"the plant (Galerkin degree {plant_degree}) has {plant_order}: lower the order "
            "or raise the plant resolution"
        )
    if reduction == "modal":
        raise NumericError(
            "an explicit order cannot be combined with the modal reduction: the converged "
            "modes fix its order; use `reduction='none'` or `reduction='balanced'`"
        )
    if reduction == "none" and ((order - offset) % size or order < smallest):
        shift = f" + {offset}" if offset > 0 else f" - {-offset}" if offset else ""
        raise NumericError(
            f"order {order} is not a Galerkin order of this model: n (p + 1){shift} with its "
            f"n = {size} efforts and degree p >= N + 1 (at least {smallest}); use "
            "`reduction='balanced'` for any order"
        )
    return int(order)


def _eigen_error(poles: np.ndarray, reference: np.ndarray) -> float | None:
    if reference.size == 0:
        return None
    gaps = np.abs(poles[None, :] - reference[:, None]).min(axis=1)
    return float(np.max(gaps / np.maximum(1.0, np.abs(reference))))


def select_order(
    nm: NumericModel,
    C_m: np.ndarray,
    L: np.ndarray,
    *,
    plant: DiscretePHS,
    x0: np.ndarray,
    t_end: float,
    points: tuple[Functional, ...] = (),
    order: int | None = None,
    reduction: str = "none",
    tol: float | None = None,
    output_tol: float | None = None,
    count: int | None = None,
) -> tuple[OrderSelection, ContinuousObserver]:
    """Choose the exported observer (module docstring) and report the choice.

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray
        Sensors and gain.
    plant : DiscretePHS
        The verification plant (Galerkin, at least twice the observer's order).
    x0 : ndarray
        The plant's initial efforts for the performance runs.
    t_end : float
        Length of the performance runs.
    points : tuple of Functional
        Point outputs (the performance outputs: ``w(1)``, ``rotation(1)``,
        :mod:`phdesign.numeric.discretization.points`), empty for the model's outputs.
    order : int, optional
        Number of states; None chooses it from the targets.
    reduction : {"none", "modal", "balanced"}
    tol, output_tol : float, optional
        Spectral and performance targets (default: the export's, :mod:`phdesign.core.defaults`).
    count : int, optional
        Number of converged rightmost eigenvalues the observer must reproduce (default:
        the spectrum's).

    Returns
    -------
    OrderSelection, ContinuousObserver
    """
    _, tol, output_tol, _ = current().export.fill(tol=tol, output_tol=output_tol)
    if reduction not in REDUCTIONS:
        raise NumericError(f"unknown reduction {reduction!r}; expected one of {REDUCTIONS}")
    for name, value in (("tol", tol), ("output_tol", output_tol)):
        if not (math.isfinite(value) and value > 0):
            raise NumericError(f"{name} must be a finite positive number; found {value!r}")
    n, N, offset = nm.size, nm.order, galerkin_offset(nm)
    order = check_order(
        order,
        plant.dim,
        plant.resolution,
        reduction=reduction,
        size=n,
        smallest=n * (N + 2) + offset,
        offset=offset,
    )
    targets = _Targets.of(nm, C_m, L, plant, t_end, output_tol, count, reduction == "modal")
    trial = _Trial(nm, C_m, L, plant, x0, points, reduction, tol, output_tol, targets)
    candidates: list[Candidate] = []
    if order is not None:
        degree = max(N + 1, -(-(order - offset) // n) - 1)  # balanced: truncated from it
        found = _Found(degree, *trial.build(degree))
    else:
        found = _smallest_degree(trial, candidates)
    return _selection(trial, found, order, candidates)


@dataclass(frozen=True)
class _Targets:
    """What a candidate is measured against: the converged error spectrum, the run's length."""

    reference: np.ndarray  # the converged rightmost error eigenvalues
    alpha: float | None  # the converged abscissa
    plant_poles: np.ndarray  # the verification plant's error spectrum (modal reduction only)
    dt_run: float  # the period of the performance run's records
    # the notes for the report, appended by the stages as they go
    warnings: list[str] = field(default_factory=list)

    @classmethod
    def of(
        cls,
        nm: NumericModel,
        C_m: np.ndarray,
        L: np.ndarray,
        plant: DiscretePHS,
        t_end: float,
        output_tol: float,
        count: int | None,
        modal: bool = False,
    ) -> _Targets:
        """Fix the targets: the converged error spectrum, the length of the runs.

        The verification plant's error spectrum is solved for a ``modal`` reduction only
        (the one that reads it).
        """
        warnings: list[str] = []
        with stage("export: the converged error spectrum"):
            report = spectrum(nm, C_m, L, count=count)
        alpha = report.spectral_abscissa
        if report.unbounded_below:
            warnings.append("the error spectrum is unbounded below: no spectral target applies")
        elif not report.converged:
            warnings.append("the error spectrum did not converge: the spectral target is loose")
        K = feedback_matrix(C_m, L, nm.n_ports)
        plant_poles = eigen(plant, K)[0] if modal else np.zeros(0, dtype=complex)
        run_length = float(t_end)
        if alpha is not None and alpha < 0:
            # long enough for the error's transient to fall to a tenth of the target, so
            # that the floor measured is the observer's and not its convergence
            run_length = max(run_length, math.log(10.0 / output_tol) / -alpha)
        elif alpha is not None:
            warnings.append(
                f"the error system is not exponentially stable (abscissa {alpha:.6g} >= 0): "
                "the performance floor is not meaningful"
            )
        reference = np.array(report.rightmost, dtype=complex)
        return cls(reference, alpha, plant_poles, run_length / FLOOR_RECORDS, warnings)


@dataclass(frozen=True)
class _Trial:
    """The observers tried: how a candidate is built and measured against the targets."""

    nm: NumericModel
    C_m: np.ndarray
    L: np.ndarray
    plant: DiscretePHS
    x0: np.ndarray
    points: tuple[Functional, ...]
    reduction: str
    tol: float
    output_tol: float
    targets: _Targets

    @property
    def alpha(self) -> float | None:
        """The converged abscissa of the error system."""
        return self.targets.alpha

    @property
    def warnings(self) -> list[str]:
        """The notes for the report (appended by the stages)."""
        return self.targets.warnings

    def right_of_abscissa(self, poles: np.ndarray) -> np.ndarray:
        """Return the poles right of the converged abscissa (beyond the tolerance)."""
        if self.alpha is None:
            return poles[:0]
        return poles[poles.real > self.alpha + self.tol * max(1, abs(self.alpha))]

    def evaluate(self, obs: ContinuousObserver, degree: int) -> Candidate:
        """Measure a candidate: its poles against the targets, its performance floor."""
        run = run_loop(
            self.plant, obs, self.C_m, x0=self.x0, dt=self.targets.dt_run, n_steps=FLOOR_RECORDS,
            sampler=None,
        )  # fmt: skip
        _, floor = error_floor(run.t, run.performance_error(obs), run.target)
        poles = np.linalg.eigvals(obs.A)
        err = _eigen_error(poles, self.targets.reference)
        spurious = int(self.right_of_abscissa(poles).size)
        spectral = err is None or err <= self.tol
        ok = spectral and floor <= self.output_tol
        return Candidate(degree, obs.order, obs.reduction, err, floor, spurious, spectral, ok)

    def build(self, p: int) -> tuple[ContinuousObserver, ContinuousObserver, np.ndarray]:
        """Return the degree-p Galerkin observer, the one exported from it, the modes lost."""
        full = ContinuousObserver.from_discretization(
            discretize(self.nm, "galerkin", p), self.C_m, self.L, self.points
        )
        if self.reduction != "modal":
            return full, full, self.targets.plant_poles[:0]
        reduced, lost = modal_truncation(full, self.targets.plant_poles, self.tol)
        return full, reduced, lost


@dataclass(frozen=True)
class _Found:
    """The chosen degree, its Galerkin observer, the observer exported, the modes lost."""

    degree: int
    full: ContinuousObserver
    chosen: ContinuousObserver
    lost: np.ndarray
    final: Candidate | None = None  # its measurement, when the search made it


def _smallest_degree(trial: _Trial, candidates: list[Candidate]) -> _Found:
    """Return the smallest degree that meets both targets, else the best compromise."""
    nm, plant = trial.nm, trial.plant
    tried: list[tuple[Candidate, _Found]] = []
    for p in range(nm.order + 1, plant.dim // (2 * nm.size)):
        report_stage(f"export: order selection, Galerkin degree {p}")
        try:
            built = trial.build(p)
        except NumericError:  # no converged mode at this degree (modal reduction)
            continue
        cand = trial.evaluate(built[1], p)
        candidates.append(cand)
        tried.append((cand, _Found(p, *built, final=cand)))
        if cand.passed:
            return tried[-1][1]
    if not tried:
        raise NumericError(
            f"the verification plant (degree {plant.resolution}, {plant.dim} states) "
            "is too small for any observer of this model: raise the plant resolution"
        )
    # the spectral target first (a floor can be set by the data, e.g. the rough boundary
    # traces of an undamped plant, whatever the degree), then the floor
    final, found = min(tried, key=lambda item: (not item[0].spectral, item[0].floor))
    why = "meets the spectral target, " if final.spectral else ""
    trial.warnings.append(
        f"no observer up to degree {candidates[-1].degree} meets both targets; "
        f"degree {found.degree} ({why}lowest performance floor) is exported"
    )
    return found


def _selection(
    trial: _Trial, found: _Found, order: int | None, candidates: list[Candidate]
) -> tuple[OrderSelection, ContinuousObserver]:
    """Reduce (balanced), measure the exported observer, and report what was dropped."""
    degree, full, chosen, final = found.degree, found.full, found.chosen, found.final
    plant, warnings = trial.plant, trial.warnings
    dropped = [
        f"Galerkin degrees {degree + 1}..{plant.resolution} of each of the {trial.nm.size} "
        f"efforts (against the verification plant)"
    ]
    if found.lost.size:
        lost = found.lost
        dropped.append(
            f"{lost.size} unresolved modes of the degree-{degree} observer (max Re "
            f"{np.max(lost.real):.3g}, |λ| {np.min(np.abs(lost)):.3g} to "
            f"{np.max(np.abs(lost)):.3g})"
        )
    hankel: tuple[float, ...] = ()
    if trial.reduction == "balanced":
        chosen, hankel, lines, notes = _balanced(full, order, trial.evaluate, degree, candidates)
        dropped += lines
        warnings += notes
        final = None
    if final is None:
        final = trial.evaluate(chosen, degree)
        candidates.append(final)
    right = trial.right_of_abscissa(np.linalg.eigvals(chosen.A))
    warnings += _selection_warnings(trial, right, final)
    selection = OrderSelection(
        degree=degree,
        order=chosen.order,
        reduction=chosen.reduction,
        full_order=full.order,
        plant_degree=plant.resolution,
        plant_order=plant.dim,
        tol=float(trial.tol),
        output_tol=float(trial.output_tol),
        abscissa=trial.alpha,
        eigen_error=final.eigen_error,
        floor=final.floor,
        spurious=int(right.size),
        spurious_max_real=float(np.max(right.real)) if right.size else None,
        dropped=tuple(dropped),
        hankel=hankel,
        candidates=tuple(candidates),
        warnings=tuple(warnings),
    )
    return selection, chosen


def _selection_warnings(trial: _Trial, right: np.ndarray, final: Candidate) -> list[str]:
    """Say which poles lie right of the abscissa and whether the targets were missed."""
    warnings = []
    if right.size:
        warnings.append(
            f"the observer has {right.size} pole{'s' if right.size > 1 else ''} right of the "
            "converged abscissa "
            f"{trial.alpha:.6g} (max Re {np.max(right.real):.3g}): unresolved high "
            "frequencies of the Galerkin basis, in which the observer's own transients decay "
            "that slowly; `reduction='modal'` drops them"
        )
    if not final.passed:
        warnings.append(
            f"the exported observer misses the targets (eigenvalue error "
            f"{final.eigen_error if final.eigen_error is None else f'{final.eigen_error:.2g}'}"
            f", floor {final.floor:.3g})"
        )
    return warnings


def _balanced(
    full: ContinuousObserver,
    order: int | None,
    evaluate: Callable[[ContinuousObserver, int], Candidate],
    degree: int,
    candidates: list[Candidate],
) -> tuple[ContinuousObserver, tuple[float, ...], list[str], list[str]]:
    """Balanced truncation to ``order``, or to the smallest order meeting the targets.

    Each candidate tried is appended to ``candidates``.  Returns the observer, the relative
    Hankel singular values, what was dropped and the notes for the report.
    """
    reduced, sigma, reduce = balanced_truncation(full, order)
    hankel = tuple(float(s) for s in sigma / sigma[0])
    notes: list[str] = []
    if reduced is None:
        for r in range(1, full.order):
            report_stage(f"export: balanced truncation, order {r}")
            trial = reduce(r)
            cand = evaluate(trial, degree)
            candidates.append(cand)
            if cand.passed:
                reduced = trial  # not reduced a second time
                break
        if reduced is None:
            notes.append(
                f"balanced truncation does not help: no order below {full.order} meets the "
                "targets (the largest Hankel singular values belong to lightly damped "
                "unresolved modes); the Galerkin observer is exported"
            )
            return full, hankel, [], notes
    r = reduced.order
    tail = sigma[r:]
    line = (
        f"{full.order - r} balanced states, Hankel singular values {tail[0] / sigma[0]:.2g} "
        f"to {tail[-1] / sigma[0]:.2g} of the largest (error bound 2 Σσ = {2 * tail.sum():.3g})"
        if tail.size
        else "nothing"
    )
    return reduced, hankel, [line], notes
