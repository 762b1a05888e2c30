r"""Converged spectra: spectral abscissa and rightmost eigenvalues under refinement.

The eigenvalues of the generalized problem :math:`(J - R - B K_{cl} B^\top) v = \lambda E v`
(closed plant, u = 0, or the observer error system, ũ = −C_mᵀ L C_m ỹ) are computed on the
dimensionless model (:mod:`phdesign.numeric.scales`: tolerances and digits are relative
to the problem's own rate s, whatever its units) by shift and invert
(:mod:`phdesign.numeric.spectrum.eigen`: accurate on the slow modes whatever the norm of the
Galerkin matrix), in three stages:

1. **Refinement** (:func:`~phdesign.numeric.spectrum.refinement.refine`): resolution pairs
   (p, ⌈1.5 p⌉), p → ⌈1.5 p⌉, each through the drift test (:mod:`phdesign.numeric.spectrum.drift`)
   and the abscissa rule (:mod:`phdesign.numeric.spectrum.abscissa`), until a pair satisfies the
   *convergence rule*:

   * the abscissa is attained by an eigenvalue converged to ``tol``, i.e. its real part
     agrees to :math:`tol \max(s, |\alpha|)` between the two resolutions;
   * at least :data:`~phdesign.numeric.spectrum.abscissa.MIN_MODES_ABOVE` resolved modes lie at
     higher frequency than the rightmost one, so that the band reaches beyond it;
   * the real parts do not keep rising with frequency (else the abscissa is a limit that
     no mode attains, which no pair "converges" to).

   It also stops when refinement no longer helps an ill-conditioned abscissa (round-off,
   not resolution, limits it at a coalescence), when two pairs in a row show the evidence
   of an empty spectrum, and when the last two pairs extrapolate the same high-frequency
   limit within their uncertainties.

2. **Choice of the pair** (:func:`~phdesign.numeric.spectrum.refinement.choose_pair`): the
   converged pair, else the pair whose abscissa is the most accurate among those no finer
   pair contradicts (a finer pair that attains a real part clearly right of a coarser
   pair's abscissa supersedes it: its wider band saw modes the coarser one did not); an
   earlier pair whose resolved abscissa lies clearly right of the chosen one wins
   (round-off at high degree can make a true eigenvalue fail the drift test at a finer
   pair).

3. **Warnings** (:func:`~phdesign.numeric.spectrum.warnings.report_warnings`): not
   converged and why, a limit at high frequency, no exponential decay, ill-conditioned
   rightmost eigenvalues (energy-norm condition number above 1e4, or a relative gap below
   1e-3: near a coalescence), eigenvalues right of the abscissa that do not count,
   artefacts.

The spectrum is *unbounded below* (finite-time extinction, e.g. the string with the
matched damper) only on evidence: no eigenvalue resolved at the last two pairs and every
discrete eigenvalue outside the disk of radius 5 s (rule 5 of
:mod:`phdesign.numeric.spectrum.abscissa`).  Without that evidence an unresolved spectrum is
"not resolved at these resolutions", never a number.

Where the refinement starts and stops and its tolerances come from the method's row of
the table of defaults (:class:`RefinementPlan`, :mod:`phdesign.core.defaults`).

Examples
--------
>>> import numpy as np
>>> from phdesign.models import load_builtin
>>> from phdesign.numeric.bridge import to_numeric
>>> rep = spectrum(to_numeric(load_builtin("wave")), np.array([[0.0, 1.0]]), np.array([[0.5]]))
>>> round(rep.spectral_abscissa, 10), rep.converged  # exactly 1/2 ln(1/3)
(-0.5493061443, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from phdesign.core.defaults import current, method_or_default
from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_spectrum_arguments
from phdesign.numeric.discretization.phs import DiscretePHS, feedback_matrix
from phdesign.numeric.spectrum.drift import PairSpectrum
from phdesign.numeric.spectrum.eigen import prepare
from phdesign.numeric.spectrum.refinement import (
    ClosedLoopSolver,
    Discretizations,
    PairResult,
    ResolutionSolver,
    choose_pair,
    extinct_twice,
    refine,
)
from phdesign.numeric.spectrum.report import SpectrumReport
from phdesign.numeric.spectrum.warnings import report_warnings, reported_value, rightmost_order
from phdesign.numeric.threads import limited_threads

__all__ = [
    "RefinementPlan",
    "abscissa_digits",
    "default_resolutions",
    "eigen",
    "rightmost_indices",
    "spectrum",
]


def eigen(
    d: DiscretePHS, K: np.ndarray | None = None, condition: bool = False
) -> tuple[np.ndarray, np.ndarray | None]:
    """Eigenvalues of ``E v' = closed_matrix(K) v`` and, optionally, condition numbers.

    The eigen stage of :mod:`phdesign.numeric.spectrum.eigen` (shift and invert at the rate of
    ``d``'s model).

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> from phdesign.numeric.discretization.registry import discretize
    >>> d = discretize(to_numeric(load_builtin("wave")), "galerkin", 8)
    >>> lam, kappa = eigen(d, condition=True)
    >>> bool(np.all(np.abs(lam.real) < 1e-12)), bool(np.all(kappa < 1 + 1e-9))  # lossless
    (True, True)
    """
    system = prepare(d)
    if not condition:
        return system.eigvals(K), None
    return system.eigen_condition(K)


def default_resolutions(nm: NumericModel, method: str) -> tuple[int, int]:
    """Return the first and largest resolution of the spectrum's refinement for ``method``.

    The method's row of the table of defaults (:mod:`phdesign.core.defaults`) for the
    model's order.
    """
    row = current().discretization(method, nm.order)
    return row.spectrum_start, row.spectrum_max


@dataclass(frozen=True)
class RefinementPlan:
    """Where the refinement of the resolution pairs starts and stops, and its tolerances.

    Attributes
    ----------
    start, stop : int
        First and largest resolution (degree or nodes per group).
    band_stop : int
        Largest resolution while the band does not reach the onset of the principal part.
    tol, rtol_resolved : float
        Abscissa agreement and drift of a resolved eigenvalue, relative to the rate.
    """

    start: int
    stop: int
    band_stop: int
    tol: float
    rtol_resolved: float

    @classmethod
    def of(
        cls,
        nm: NumericModel,
        method: str,
        *,
        resolution: int | None = None,
        max_resolution: int | None = None,
        tol: float | None = None,
        rtol_resolved: float | None = None,
        start: int | None = None,
    ) -> RefinementPlan:
        """Return the plan of the arguments given, the method's row of the table elsewhere.

        ``start`` replaces the row's first resolution when ``resolution`` is None.  A
        band short of the onset refines up to the row's band cap, within a cap the
        user gives (``max_resolution``).
        """
        row = current().discretization(method, nm.order)
        if resolution is not None:
            start = int(resolution)
        p = row.spectrum_start if start is None else start
        stop = int(max_resolution) if max_resolution is not None else max(row.spectrum_max, p)
        band_stop = stop if max_resolution is not None else max(row.band_max, row.spectrum_max)
        return cls(
            start=p,
            stop=stop,
            band_stop=band_stop,
            tol=row.abscissa_tol if tol is None else float(tol),
            rtol_resolved=row.resolved_rtol if rtol_resolved is None else float(rtol_resolved),
        )

    def refine(self, solver: ResolutionSolver) -> list[PairResult]:
        """Run :func:`~phdesign.numeric.spectrum.refinement.refine` by this plan."""
        return refine(
            solver,
            start=self.start,
            stop=self.stop,
            tol=self.tol,
            rtol_resolved=self.rtol_resolved,
            band_stop=self.band_stop,
        )


def rightmost_indices(chosen: PairResult, count: int) -> np.ndarray:
    """Return the indices (into the pair's eigenvalues) of the ``count`` rightmost listed.

    Listed are the counted eigenvalues and every resolved one that does not lie right of
    the abscissa (a resolved mode whose real part is not converged to the abscissa's
    tolerance is still a mode); real parts that tie within their accuracy are ordered by
    frequency (:func:`~phdesign.numeric.spectrum.warnings.rightmost_order`).
    """
    pair, a = chosen.pair, chosen.abscissa
    listed = np.flatnonzero(a.counted | (pair.resolved & ~a.loose_right))
    order = rightmost_order(pair.eigenvalues[listed], pair.uncertainty[listed])
    return np.asarray(listed[order[:count]])


def abscissa_digits(chosen: PairResult) -> float:
    """Digits of the chosen pair's abscissa, relative to max(rate, |α|), at most ε's."""
    a = chosen.abscissa
    if a.value is None or a.uncertainty is None:
        raise NumericError("the pair has no abscissa: no digits")
    scale = max(chosen.pair.scale, abs(a.value))
    return -math.log10(max(a.uncertainty, np.finfo(float).eps * scale) / scale)


@dataclass(frozen=True)
class _Labels:
    """What a report says it is about: method, system, model, rate, sensors and gain."""

    method: str
    system: str
    model: str
    rate: float
    sensors: list[list[float]] | None
    gain: list[list[float]] | None
    time_unit: str | None = None


def _unresolved_report(trail: list[PairResult], labels: _Labels) -> SpectrumReport:
    """Stage 3 without a number: an empty spectrum (seen twice) or one not resolved."""
    last = trail[-1]
    extinct = extinct_twice(trail)
    p, q = last.pair.resolutions
    if extinct:
        warning = (
            f"no eigenvalue converges under refinement up to resolution {q} and every discrete "
            f"eigenvalue stays outside |λ| <= {5 * labels.rate:.3g} (5 times the rate) at every "
            "resolution, the nearest ones decaying faster than they oscillate: the spectrum is "
            "empty (finite-time extinction); the spectral abscissa is unbounded below"
        )
    else:
        warning = (
            f"no eigenvalue agrees between the resolutions tried (up to {q}), yet discrete "
            "eigenvalues lie near the origin: the spectrum is not resolved at these resolutions "
            "(raise `max_resolution`); no number is reported"
        )
    return SpectrumReport(
        spectral_abscissa=None,
        rightmost=[],
        converged=False,
        digits=None,
        n_resolved=0,
        n_total=int(last.pair.eigenvalues.size),
        resolutions=(p, q),
        method=labels.method,
        system=labels.system,
        unbounded_below=extinct,
        all_eigenvalues_max_real=last.pair.all_max_real,
        history=tuple(r.step() for r in trail),
        warnings=[warning],
        model=labels.model,
        kind="unbounded below" if extinct else "not resolved",
        rate_scale=labels.rate,
        eigenvalues=last.pair.eigenvalues,
        resolved=last.pair.resolved,
        sensors=labels.sensors,
        gain=labels.gain,
        **_mode_data(last.pair, labels),
    )


@limited_threads
def spectrum(
    nm: NumericModel,
    C_m: np.ndarray | None = None,
    L: np.ndarray | None = None,
    *,
    method: str | None = None,
    resolution: int | None = None,
    max_resolution: int | None = None,
    tol: float | None = None,
    rtol_resolved: float | None = None,
    count: int | None = None,
    basis: str | None = None,
    discretizations: Discretizations | None = None,
) -> SpectrumReport:
    """Converged spectral abscissa and rightmost eigenvalues (module docstring).

    Every default is the method's row of the table of defaults
    (:mod:`phdesign.core.defaults`).

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray, optional
        Sensors and gain; when given the error system (ũ = −C_mᵀ L C_m ỹ) is analysed,
        otherwise the closed plant with u = 0.
    method : str, optional
        A registered discretization (``"galerkin"``, ``"fd"``); default: the table's.
    resolution, max_resolution : int, optional
        First and largest resolution (degree or nodes per group).
    tol : float, optional
        Required accuracy of the abscissa, relative to max(rate, abs(α)) with the problem's
        rate (:mod:`phdesign.numeric.scales`); default 1e-10 for Galerkin, 1e-3 for the
        second-order finite differences.
    rtol_resolved : float, optional
        Relative drift under which an eigenvalue counts as resolved; default 1e-6 for
        Galerkin, 1e-2 for finite differences.
    count : int, optional
        How many rightmost eigenvalues to report (default 6).
    basis : str, optional
        The basis of a method that has several (Galerkin: ``"scaled"`` or
        ``"legendre"``); default: the row's.
    discretizations : Discretizations, optional
        The model's discretizations by ``method`` and ``basis``, shared by many calls at
        different gains (:class:`~phdesign.numeric.spectrum.refinement.Discretizations`):
        the report is the same, without discretizing again.

    Returns
    -------
    SpectrumReport
    """
    method = method_or_default(method)
    count = current().spectrum.count if count is None else count
    check_spectrum_arguments(
        nm,
        C_m,
        L,
        method=method,
        resolution=resolution,
        max_resolution=max_resolution,
        tol=tol,
        rtol_resolved=rtol_resolved,
        count=count,
        basis=basis,
    )
    K = None if C_m is None or L is None else feedback_matrix(C_m, L, nm.n_ports)
    plan = RefinementPlan.of(
        nm,
        method,
        resolution=resolution,
        max_resolution=max_resolution,
        tol=tol,
        rtol_resolved=rtol_resolved,
    )
    solver = ClosedLoopSolver(nm, K, method=method, basis=basis, discretizations=discretizations)
    trail = plan.refine(solver)
    labels = _Labels(
        method=method,
        system="plant (u = 0)" if K is None else "observer error system",
        model=nm.name,
        rate=solver.scales.rate,
        sensors=None if C_m is None else np.atleast_2d(np.asarray(C_m, float)).tolist(),
        gain=None if L is None else np.atleast_2d(np.asarray(L, float)).tolist(),
        time_unit=dict(nm.units).get("t"),
    )
    chosen, notes = choose_pair(trail)
    a = chosen.abscissa
    if a.value is None or a.uncertainty is None or a.attained is None:
        return _unresolved_report(trail, labels)
    warnings, ill, no_decay = report_warnings(chosen, a.value, a.uncertainty, a.attained, plan.tol)
    value, uncertainty = reported_value(a.value, a.uncertainty, no_decay)
    return _report(
        chosen, trail, (value, uncertainty), (notes + warnings, ill, no_decay), count, labels
    )


def _report(
    chosen: PairResult,
    trail: list[PairResult],
    abscissa: tuple[float, float],
    verdict: tuple[list[str], bool, bool],
    count: int,
    labels: _Labels,
) -> SpectrumReport:
    """Stage 3: the report of the chosen pair, its abscissa (value, uncertainty) a number.

    ``verdict`` holds the warnings, whether the rightmost eigenvalues are ill-conditioned
    and whether the spectrum shows no decay.
    """
    a, pair = chosen.abscissa, chosen.pair
    value, uncertainty = abscissa
    warnings, ill, no_decay = verdict
    lower_bound = a.kind == "lower bound"
    lam = pair.eigenvalues
    top = rightmost_indices(chosen, count)
    kappa = pair.condition if pair.condition is not None else np.ones(lam.shape)
    scale = max(pair.scale, abs(value))
    digits = -math.log10(max(uncertainty, np.finfo(float).eps * scale) / scale)
    return SpectrumReport(
        spectral_abscissa=value,
        rightmost=[complex(z) for z in lam[top]],
        converged=chosen.converged,
        digits=None if lower_bound else float(digits),
        n_resolved=pair.n_resolved,
        n_total=int(lam.size),
        resolutions=pair.resolutions,
        method=labels.method,
        system=labels.system,
        unbounded_below=False,
        ill_conditioned=ill,
        condition_numbers=[float(c) for c in kappa[top]],
        all_eigenvalues_max_real=pair.all_max_real,
        history=tuple(r.step() for r in trail),
        warnings=warnings,
        model=labels.model,
        uncertainty=None if lower_bound else uncertainty,
        kind=a.kind,
        no_decay=no_decay,
        rate_scale=labels.rate,
        eigenvalues=lam,
        resolved=pair.resolved,
        sensors=labels.sensors,
        gain=labels.gain,
        branches=a.branches,
        complete_band=pair.complete_band,
        **_mode_data(pair, labels),
    )


def _mode_data(pair: PairSpectrum, labels: _Labels) -> dict[str, Any]:
    """Return the report's fields of the modal table: masks, accuracies, units."""
    return {
        "kept": pair.clustered,
        "real_accuracy": pair.uncertainty,
        "condition_all": np.zeros(0) if pair.condition is None else pair.condition,
        "time_unit": labels.time_unit,
    }
