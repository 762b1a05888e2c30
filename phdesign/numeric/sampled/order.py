r"""Order selection for an exported observer: Galerkin degree, and optional reductions.

An observer that runs on a controller has a finite order. This module picks it from two
accuracy targets, both checked on the observer that will be exported:

*spectral*: each of the ``count`` rightmost eigenvalues :math:`\lambda` of the *converged*
    error spectrum (:func:`phdesign.numeric.spectrum.converged.spectrum`) has an observer pole
    within ``tol`` · max(1, |λ|) (the poles of the observer are the eigenvalues of its
    error system);
*performance*: the continuous observer run against a high-resolution plant (the
    verification plant, from the verification initial state) has a performance-output
    error floor (:func:`phdesign.numeric.sampled.samplers.error_floor`) at most ``output_tol``
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

import importlib.util
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg as sl

from phdesign.core.defaults import current
from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.registry import discretize, feedback_matrix
from phdesign.numeric.sampled.samplers import ContinuousObserver, error_floor, run_loop

__all__ = [
    "REDUCTIONS",
    "Candidate",
    "OrderSelection",
    "balanced_truncation",
    "check_order",
    "modal_truncation",
    "select_order",
]

REDUCTIONS = ("none", "modal", "balanced")
#: Records of the continuous run that measures a candidate's performance floor.
FLOOR_RECORDS = 500


@dataclass(frozen=True)
class Candidate:
    """One observer tried by :func:`select_order` and how it met the targets."""

    degree: int
    order: int
    reduction: str
    eigen_error: float | None
    floor: float
    spurious: int
    spectral: bool
    passed: bool

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return {
            "degree": self.degree,
            "order": self.order,
            "reduction": self.reduction,
            "eigen_error": self.eigen_error,
            "floor": _finite(self.floor),
            "spurious_poles": self.spurious,
            "meets_spectral_target": self.spectral,
            "passed": self.passed,
        }


def _finite(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


@dataclass(frozen=True)
class OrderSelection:
    """How the exported observer's order was chosen, and what was dropped.

    Attributes
    ----------
    degree, order : int
        Galerkin degree and number of states of the exported observer.
    reduction : str
    full_order : int
        States of the Galerkin observer of that degree, before any reduction.
    plant_degree, plant_order : int
        The verification plant the targets were checked against.
    tol, output_tol : float
        The spectral and performance targets.
    abscissa : float or None
        The converged spectral abscissa of the error system.
    eigen_error, floor : float or None
        The chosen observer's spectral error and relative continuous performance floor.
    spurious, spurious_max_real
        Poles right of the converged abscissa and the largest real part among them.
    dropped : tuple of str
    hankel : tuple of float
        Hankel singular values relative to the largest (balanced truncation only).
    candidates : tuple of Candidate
    warnings : tuple of str
    """

    degree: int
    order: int
    reduction: str
    full_order: int
    plant_degree: int
    plant_order: int
    tol: float
    output_tol: float
    abscissa: float | None
    eigen_error: float | None
    floor: float
    spurious: int
    spurious_max_real: float | None
    dropped: tuple[str, ...]
    hankel: tuple[float, ...] = ()
    candidates: tuple[Candidate, ...] = field(default=(), repr=False)
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (strict JSON: null for what is not finite)."""
        return {
            "degree": self.degree,
            "order": self.order,
            "reduction": self.reduction,
            "full_order": self.full_order,
            "plant_degree": self.plant_degree,
            "plant_order": self.plant_order,
            "tol": self.tol,
            "output_tol": self.output_tol,
            "abscissa": _finite(self.abscissa),
            "eigen_error": _finite(self.eigen_error),
            "floor": _finite(self.floor),
            "spurious_poles": self.spurious,
            "spurious_max_real": _finite(self.spurious_max_real),
            "dropped": list(self.dropped),
            "hankel": [float(s) for s in self.hankel],
            "candidates": [c.to_dict() for c in self.candidates],
            "warnings": list(self.warnings),
        }

    def __repr__(self) -> str:
        eig = "None" if self.eigen_error is None else f"{self.eigen_error:.2g}"
        return (
            f"OrderSelection(degree={self.degree}, order={self.order}, "
            f"reduction={self.reduction!r}, floor={self.floor:.3g}, eigen_error={eig})"
        )

    def __str__(self) -> str:
        eig = "n/a" if self.eigen_error is None else f"{self.eigen_error:.2g}"
        lines = [
            f"order: {self.order} states (Galerkin degree {self.degree}, reduction "
            f"{self.reduction}, from {self.full_order}); verification plant: degree "
            f"{self.plant_degree}, {self.plant_order} states",
            f"targets: rightmost eigenvalues to {self.tol:g} (reached {eig}), performance "
            f"floor {self.output_tol:g} of the peak (reached {self.floor:.3g})",
        ]
        lines += [f"dropped: {line}" for line in self.dropped]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rows = "".join(
            f"<tr><td>{c.degree}</td><td>{c.order}</td><td>{c.reduction}</td>"
            f"<td>{'n/a' if c.eigen_error is None else f'{c.eigen_error:.2g}'}</td>"
            f"<td>{c.floor:.3g}</td><td>{'yes' if c.passed else 'no'}</td></tr>"
            for c in self.candidates
        )
        return (
            f"<p>order {self.order} (degree {self.degree}, {self.reduction})</p><table>"
            "<tr><th>degree</th><th>order</th><th>reduction</th><th>eigenvalue error</th>"
            f"<th>floor</th><th>meets targets</th></tr>{rows}</table>"
        )


def check_order(
    order: object,
    plant_order: int,
    plant_degree: int,
    *,
    reduction: str = "balanced",
    size: int = 1,
    smallest: int = 1,
) -> int | None:
    """Return ``order`` as an int (or None) after checking it against the request.

    The verification plant must have at least twice the observer's states, so that the
    verification is against a model the observer cannot reproduce. Without a balanced
    truncation the order is that of a Galerkin observer, a multiple of the model's
    ``size`` efforts and at least ``smallest``; a modal reduction fixes its own order.

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
            "modes fix its order; use --reduce none or --reduce balanced"
        )
    if reduction == "none" and (order % size or order < smallest):
        raise NumericError(
            f"order {order} is not a Galerkin order of this model: n (p + 1) with its n = "
            f"{size} efforts and degree p >= N + 1 (at least {smallest}); use --reduce "
            "balanced for any order"
        )
    return int(order)


def _eigen_error(poles: np.ndarray, reference: np.ndarray) -> float | None:
    if reference.size == 0:
        return None
    gaps = np.abs(poles[None, :] - reference[:, None]).min(axis=1)
    return float(np.max(gaps / np.maximum(1.0, np.abs(reference))))


def modal_truncation(
    observer: ContinuousObserver, reference: np.ndarray, tol: float
) -> tuple[ContinuousObserver, np.ndarray]:
    """Keep the observer's modes that agree with ``reference`` (drift test at ``tol``).

    Returns the reduced observer and the dropped poles.
    """
    from phdesign.numeric.spectrum.drift import match_resolved

    poles = np.linalg.eigvals(observer.A)
    kept_idx, _ = match_resolved(poles, reference, tol)
    kept = poles[kept_idx]
    if kept.size == 0:
        raise NumericError(
            f"no pole of the degree-{observer.discrete.resolution} observer agrees with the "
            "converged error spectrum: raise the order before a modal reduction"
        )

    def keep(re: float, im: float) -> bool:
        z = complex(re, im)
        return bool(np.min(np.abs(kept - z)) <= 1e-8 * max(1.0, abs(z)))

    T, Q, sdim = sl.schur(observer.A, output="real", sort=keep)
    k = int(sdim)
    if k != kept.size:
        raise NumericError(
            f"the modal reduction could not separate the {kept.size} converged poles "
            f"(the Schur reordering kept {k}); use --reduce none"
        )
    T11, T12, T22 = T[:k, :k], T[:k, k:], T[k:, k:]
    X = sl.solve_sylvester(T11, -T22, -T12)
    Q1, Q2 = Q[:, :k], Q[:, k:]
    reduced = observer.project(Q1, Q1 - Q2 @ X.T, "modal")
    dropped = np.delete(poles, kept_idx)
    return reduced, dropped


def _slycot_available() -> bool:
    return importlib.util.find_spec("slycot") is not None


def balanced_truncation(
    observer: ContinuousObserver, order: int | None = None
) -> tuple[ContinuousObserver | None, np.ndarray, Any]:
    r"""Balanced truncation of ``observer`` (square-root method).

    With the gramians :math:`W_c = S S^\top`, :math:`W_o = R R^\top` (python-control's
    ``gram``, through slycot) and :math:`R^\top S = U \Sigma V^\top`, the reduced observer
    is :math:`x = T x_r`, :math:`T = S V_r \Sigma_r^{-1/2}`,
    :math:`\dot x_r = W^\top(A T x_r + B v)`, :math:`W = R U_r \Sigma_r^{-1/2}`
    (:math:`W^\top T = I`). Returns the reduced observer (None when ``order`` is None),
    the Hankel singular values and a function ``reduce(r)``.

    Raises
    ------
    NumericError
        When slycot is not installed.
    """
    if not _slycot_available():
        raise NumericError(
            "balanced truncation needs slycot (python-control computes its gramians with "
            "it): pip install slycot, or use --reduce none or --reduce modal"
        )
    import control

    system = control.ss(observer.A, observer.B, observer.C, observer.D)
    factors = []
    for kind in ("c", "o"):
        gramian = control.gram(system, kind)
        w, U = np.linalg.eigh(0.5 * (gramian + gramian.T))
        factors.append(U * np.sqrt(np.clip(w, 0.0, None)))
    S, R = factors
    U, sigma, Vt = np.linalg.svd(R.T @ S)

    def reduce(r: int) -> ContinuousObserver:
        scale = 1.0 / np.sqrt(sigma[:r])
        return observer.project(S @ Vt[:r].T * scale, R @ U[:, :r] * scale, "balanced")

    reduced = None if order is None else reduce(order)
    return reduced, sigma, reduce


def select_order(
    nm: NumericModel,
    C_m: np.ndarray,
    L: np.ndarray,
    *,
    plant: DiscretePHS,
    x0: np.ndarray,
    t_end: float,
    points: tuple[float, ...] = (),
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
    points : tuple of float
        Displacement points (the performance outputs), empty for the model's outputs.
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
    from phdesign.numeric.spectrum.converged import eigen, spectrum

    _, tol, output_tol, _ = current().export.fill(tol=tol, output_tol=output_tol)
    if reduction not in REDUCTIONS:
        raise NumericError(f"unknown reduction {reduction!r}; expected one of {REDUCTIONS}")
    for name, value in (("tol", tol), ("output_tol", output_tol)):
        if not (math.isfinite(value) and value > 0):
            raise NumericError(f"{name} must be a finite positive number; found {value!r}")
    n, N = nm.size, nm.order
    order = check_order(
        order, plant.dim, plant.resolution, reduction=reduction, size=n, smallest=n * (N + 2)
    )
    warnings: list[str] = []
    report = spectrum(nm, C_m, L, count=count)
    reference = np.array(report.rightmost, dtype=complex)
    alpha = report.spectral_abscissa
    if report.unbounded_below:
        warnings.append("the error spectrum is unbounded below: no spectral target applies")
    elif not report.converged:
        warnings.append("the error spectrum did not converge: the spectral target is loose")
    K = feedback_matrix(C_m, L, nm.n_ports)
    plant_poles = eigen(plant, K)[0]
    run_length = float(t_end)
    if alpha is not None and alpha < 0:
        # long enough for the error's transient to fall to a tenth of the target, so that
        # the floor measured is the observer's and not its convergence
        run_length = max(run_length, math.log(10.0 / output_tol) / -alpha)
    elif alpha is not None:
        warnings.append(
            f"the error system is not exponentially stable (abscissa {alpha:.6g} >= 0): "
            "the performance floor is not meaningful"
        )
    dt_run = run_length / FLOOR_RECORDS

    def evaluate(obs: ContinuousObserver, degree: int) -> Candidate:
        run = run_loop(plant, obs, C_m, x0=x0, dt=dt_run, n_steps=FLOOR_RECORDS, sampler=None)
        _, floor = error_floor(run.t, run.performance_error(obs), run.target)
        poles = np.linalg.eigvals(obs.A)
        err = _eigen_error(poles, reference)
        spurious = (
            0 if alpha is None else int(np.sum(poles.real > alpha + tol * max(1, abs(alpha))))
        )
        spectral = err is None or err <= tol
        ok = spectral and floor <= output_tol
        return Candidate(degree, obs.order, obs.reduction, err, floor, spurious, spectral, ok)

    def build(p: int) -> tuple[ContinuousObserver, ContinuousObserver, np.ndarray]:
        full = ContinuousObserver.from_discretization(
            discretize(nm, "galerkin", p), C_m, L, points
        )
        if reduction != "modal":
            return full, full, plant_poles[:0]
        reduced, lost = modal_truncation(full, plant_poles, tol)
        return full, reduced, lost

    candidates: list[Candidate] = []
    final: Candidate | None = None
    if order is not None:
        degree = max(N + 1, -(-order // n) - 1)  # balanced: truncated from this degree
        full, chosen, lost = build(degree)
    else:
        found: tuple[int, ContinuousObserver, ContinuousObserver, np.ndarray] | None = None
        best_seen: list[tuple[Candidate, Any]] = []
        for p in range(N + 1, plant.dim // (2 * n)):
            try:
                built = build(p)
            except NumericError:  # no converged mode at this degree (modal reduction)
                continue
            cand = evaluate(built[1], p)
            candidates.append(cand)
            best_seen.append((cand, (p, *built)))
            if cand.passed:
                found, final = (p, *built), cand
                break
        if found is None:
            if not best_seen:
                raise NumericError(
                    f"the verification plant (degree {plant.resolution}, {plant.dim} states) "
                    "is too small for any observer of this model: raise the plant resolution"
                )
            # the spectral target first (a floor can be set by the data, e.g. the rough
            # boundary traces of an undamped plant, whatever the degree), then the floor
            final, found = min(best_seen, key=lambda item: (not item[0].spectral, item[0].floor))
            why = "meets the spectral target, " if final.spectral else ""
            warnings.append(
                f"no observer up to degree {candidates[-1].degree} meets both targets; "
                f"degree {found[0]} ({why}lowest performance floor) is exported"
            )
        degree, full, chosen, lost = found
    hankel: tuple[float, ...] = ()
    dropped = [
        f"Galerkin degrees {degree + 1}..{plant.resolution} of each of the {n} efforts "
        f"(against the verification plant)"
    ]
    if lost.size:
        dropped.append(
            f"{lost.size} unresolved modes of the degree-{degree} observer (max Re "
            f"{np.max(lost.real):.3g}, |λ| {np.min(np.abs(lost)):.3g} to "
            f"{np.max(np.abs(lost)):.3g})"
        )
    if reduction == "balanced":
        chosen, hankel, dropped_line, note = _balanced(full, order, evaluate, degree, candidates)
        dropped += dropped_line
        warnings += note
        final = None
    if final is None:
        final = evaluate(chosen, degree)
        candidates.append(final)
    poles = np.linalg.eigvals(chosen.A)
    right = (
        poles[poles.real > alpha + tol * max(1, abs(alpha))] if alpha is not None else poles[:0]
    )
    if right.size:
        warnings.append(
            f"the observer has {right.size} pole{'s' if right.size > 1 else ''} right of the "
            "converged abscissa "
            f"{alpha:.6g} (max Re {np.max(right.real):.3g}): unresolved high frequencies of "
            "the Galerkin basis, in which the observer's own transients decay that slowly; "
            "--reduce modal drops them"
        )
    if not final.passed:
        warnings.append(
            f"the exported observer misses the targets (eigenvalue error "
            f"{final.eigen_error if final.eigen_error is None else f'{final.eigen_error:.2g}'}"
            f", floor {final.floor:.3g})"
        )
    selection = OrderSelection(
        degree=degree,
        order=chosen.order,
        reduction=chosen.reduction,
        full_order=full.order,
        plant_degree=plant.resolution,
        plant_order=plant.dim,
        tol=float(tol),
        output_tol=float(output_tol),
        abscissa=alpha,
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


def _balanced(
    full: ContinuousObserver,
    order: int | None,
    evaluate: Callable[[ContinuousObserver, int], Candidate],
    degree: int,
    candidates: list[Candidate],
) -> tuple[ContinuousObserver, tuple[float, ...], list[str], list[str]]:
    """Balanced truncation to ``order``, or to the smallest order meeting the targets."""
    reduced, sigma, reduce = balanced_truncation(full, order)
    hankel = tuple(float(s) for s in sigma / sigma[0])
    notes: list[str] = []
    if reduced is None:
        for r in range(1, full.order):
            cand = evaluate(reduce(r), degree)
            candidates.append(cand)
            if cand.passed:
                reduced = reduce(r)
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
