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

3. **Warnings** (:func:`report_warnings`): not converged and why, a limit at high
   frequency, no exponential decay, ill-conditioned rightmost eigenvalues (energy-norm
   condition number above 1e4, or a relative gap below 1e-3: near a coalescence),
   eigenvalues right of the abscissa that do not count, artefacts.

The spectrum is *unbounded below* (finite-time extinction, e.g. the string with the
matched damper) only on evidence: no eigenvalue resolved at the last two pairs and every
discrete eigenvalue outside the disk of radius 5 s (rule 5 of
:mod:`phdesign.numeric.spectrum.abscissa`).  Without that evidence an unresolved spectrum is
"not resolved at these resolutions", never a number.

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

import numpy as np

from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_spectrum_arguments
from phdesign.numeric.discretization.defaults import band_resolution, spectrum_resolutions
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.registry import feedback_matrix
from phdesign.numeric.scales import ProblemScales
from phdesign.numeric.spectrum.abscissa import estimate_abscissa
from phdesign.numeric.spectrum.drift import in_band_unresolved, match_resolved, pair_spectrum
from phdesign.numeric.spectrum.eigen import prepare
from phdesign.numeric.spectrum.evaluator import default_tolerances
from phdesign.numeric.spectrum.refinement import (
    ClosedLoopSolver,
    Discretizations,
    PairResult,
    choose_pair,
    extinct_twice,
    refine,
)
from phdesign.numeric.spectrum.report import SpectrumReport
from phdesign.numeric.spectrum.warnings import report_warnings, reported_value, rightmost_order
from phdesign.numeric.threads import small_dense_threads

__all__ = [
    "PairResult",
    "SpectrumReport",
    "abscissa_digits",
    "choose_pair",
    "default_resolutions",
    "eigen",
    "in_band_unresolved",
    "match_resolved",
    "refine",
    "report_warnings",
    "resolved_abscissa",
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


def resolved_abscissa(
    fine: np.ndarray,
    coarse: np.ndarray,
    rtol: float = 1e-6,
    kappa: np.ndarray | None = None,
    scale: float = 1.0,
    tol: float = 1e-10,
    dissipative: bool = True,
) -> float | None:
    """Return the abscissa of two sets of eigenvalues, or None.

    The abscissa is that of :mod:`phdesign.numeric.spectrum.abscissa`.

    Kept for callers of earlier versions;
    :class:`phdesign.numeric.spectrum.evaluator.AbscissaEvaluator`
    prepares a resolution pair once and evaluates it for many gains.  Without condition
    numbers ``kappa`` every in-band unresolved eigenvalue is kept (an upper bound).
    ``dissipative=True`` (the default: a closed loop ũ = −Kỹ of a discretization) states
    that every exact eigenvalue has Re λ <= 0 (:mod:`phdesign.numeric.spectrum.drift`).
    """
    pair = pair_spectrum(
        fine,
        coarse,
        resolutions=(0, 0),
        rtol=rtol,
        scale=scale,
        kappa=kappa,
        dissipative=dissipative,
    )
    return estimate_abscissa(pair, tol).value


def default_resolutions(nm: NumericModel, method: str) -> tuple[int, int]:
    """Return the starting and maximal resolution for ``method`` (degree or nodes per group).

    The values live in one table,
    :func:`phdesign.numeric.discretization.defaults.spectrum_resolutions`.
    """
    return spectrum_resolutions(nm.order, method)


def rightmost_indices(chosen: PairResult, count: int) -> np.ndarray:
    """Return the indices (into the pair's eigenvalues) of the ``count`` rightmost counted."""
    lam = chosen.pair.eigenvalues
    counted = np.flatnonzero(chosen.abscissa.counted)
    return counted[rightmost_order(lam[counted])[:count]]


def abscissa_digits(chosen: PairResult) -> float:
    """Digits of the chosen pair's abscissa, relative to max(rate, |α|), at most ε's."""
    a = chosen.abscissa
    if a.value is None or a.uncertainty is None:
        raise NumericError("the pair has no abscissa: no digits")
    scale = max(chosen.pair.scale, abs(a.value))
    return -math.log10(max(a.uncertainty, np.finfo(float).eps * scale) / scale)


def _unresolved_report(
    trail: list[PairResult],
    method: str,
    system: str,
    model: str,
    scales: ProblemScales,
    sensors: list[list[float]] | None,
    gain: list[list[float]] | None,
) -> SpectrumReport:
    last = trail[-1]
    extinct = extinct_twice(trail)
    p, q = last.pair.resolutions
    if extinct:
        warning = (
            f"no eigenvalue converges under refinement up to resolution {q} and every discrete "
            f"eigenvalue stays outside |λ| <= {5 * scales.rate:.3g} (5 times the rate) at every "
            "resolution, the nearest ones decaying faster than they oscillate: the spectrum is "
            "empty (finite-time extinction); the spectral abscissa is unbounded below"
        )
    else:
        warning = (
            f"no eigenvalue agrees between the resolutions tried (up to {q}), yet discrete "
            "eigenvalues lie near the origin: the spectrum is not resolved at these resolutions "
            "(raise max_resolution / --max-resolution); no number is reported"
        )
    return SpectrumReport(
        spectral_abscissa=None,
        rightmost=[],
        converged=False,
        digits=None,
        n_resolved=0,
        n_total=int(last.pair.eigenvalues.size),
        resolutions=(p, q),
        method=method,
        system=system,
        unbounded_below=extinct,
        all_eigenvalues_max_real=last.pair.all_max_real,
        history=tuple(r.step() for r in trail),
        warnings=[warning],
        model=model,
        kind="unbounded below" if extinct else "not resolved",
        rate_scale=scales.rate,
        eigenvalues=last.pair.eigenvalues,
        resolved=last.pair.resolved,
        sensors=sensors,
        gain=gain,
    )


def spectrum(
    nm: NumericModel,
    C_m: np.ndarray | None = None,
    L: np.ndarray | None = None,
    *,
    method: str = "galerkin",
    resolution: int | None = None,
    max_resolution: int | None = None,
    tol: float | None = None,
    rtol_resolved: float | None = None,
    count: int = 6,
    basis: str | None = None,
    discretizations: Discretizations | None = None,
) -> SpectrumReport:
    """Converged spectral abscissa and rightmost eigenvalues (module docstring).

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray, optional
        Sensors and gain; when given the error system (ũ = −C_mᵀ L C_m ỹ) is analysed,
        otherwise the closed plant with u = 0.
    method : {"galerkin", "fd"}
    resolution, max_resolution : int, optional
        First and largest resolution (degree or nodes per group).
    tol : float, optional
        Required accuracy of the abscissa, relative to max(rate, abs(α)) with the problem's
        rate (:mod:`phdesign.numeric.scales`); default 1e-10 for Galerkin, 1e-3 for the
        second-order finite differences.
    rtol_resolved : float, optional
        Relative drift under which an eigenvalue counts as resolved; default 1e-6 for
        Galerkin, 1e-2 for finite differences.
    count : int
        How many rightmost eigenvalues to report.
    basis : {"scaled", "legendre"}, optional
        The Galerkin basis (default: the defaults table's for the model's order,
        :mod:`phdesign.numeric.discretization.defaults`); the plain Legendre basis lowers the
        largest
        resolution for N >= 3, where its round-off grows with the degree.
    discretizations : Discretizations, optional
        The model's discretizations by ``method`` and ``basis``, shared by many calls at
        different gains (:class:`~phdesign.numeric.spectrum.refinement.Discretizations`):
        the report is the same, without discretizing again.

    Returns
    -------
    SpectrumReport
    """
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
    )
    if (C_m is None) != (L is None):
        raise NumericError("give both the sensors C_m and the gain L, or neither")
    K = None if C_m is None or L is None else feedback_matrix(C_m, L, nm.n_ports)
    default_tol, default_rtol = default_tolerances(method)
    tol = default_tol if tol is None else float(tol)
    rtol_resolved = default_rtol if rtol_resolved is None else float(rtol_resolved)
    if basis is not None and method != "galerkin":
        raise NumericError(f"basis applies to method='galerkin' only; found basis={basis!r}")
    p0, pmax = spectrum_resolutions(nm.order, method, basis)
    p = int(resolution) if resolution is not None else p0
    pmax = int(max_resolution) if max_resolution is not None else max(pmax, p)
    # a band short of the onset of the principal part refines further, within the user's cap
    band_stop = pmax if max_resolution is not None else band_resolution(nm.order, method, basis)
    system = "plant (u = 0)" if K is None else "observer error system"
    with small_dense_threads():
        solver = ClosedLoopSolver(
            nm, K, method=method, basis=basis, discretizations=discretizations
        )
        trail = refine(
            solver,
            start=p,
            stop=pmax,
            tol=tol,
            rtol_resolved=rtol_resolved,
            band_stop=band_stop,
        )
    scales = solver.scales
    sensors = None if C_m is None else np.atleast_2d(np.asarray(C_m, float)).tolist()
    gain = None if L is None else np.atleast_2d(np.asarray(L, float)).tolist()
    chosen, notes = choose_pair(trail)
    a, pair = chosen.abscissa, chosen.pair
    if a.value is None or a.uncertainty is None or a.attained is None:
        return _unresolved_report(trail, method, system, nm.name, scales, sensors, gain)
    warnings, ill, no_decay = report_warnings(chosen, a.value, a.uncertainty, a.attained, tol)
    value, uncertainty = reported_value(a.value, a.uncertainty, no_decay)
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
        method=method,
        system=system,
        unbounded_below=False,
        ill_conditioned=ill,
        condition_numbers=[float(c) for c in kappa[top]],
        all_eigenvalues_max_real=pair.all_max_real,
        history=tuple(r.step() for r in trail),
        warnings=notes + warnings,
        model=nm.name,
        uncertainty=None if lower_bound else uncertainty,
        kind=a.kind,
        no_decay=no_decay,
        rate_scale=scales.rate,
        eigenvalues=lam,
        resolved=pair.resolved,
        sensors=sensors,
        gain=gain,
        branches=a.branches,
        complete_band=pair.complete_band,
    )
