r"""Converged spectra: spectral abscissa and rightmost eigenvalues under refinement.

The eigenvalues of the generalized problem :math:`(J - R - B K_{cl} B^\top) v = \lambda E v`
(closed plant, u = 0, or the observer error system, ũ = −C_mᵀ L C_m ỹ) are computed at
resolutions p and ⌈1.5 p⌉ and only those that agree are kept (the drift-ratio rule of
Dedalus' eigentools): the discrete spectrum of any semi-discretization contains
unresolved high-frequency eigenvalues whose real parts are artefacts.  On a damped wave
they tend to 0 (like h² for finite differences, like p⁻² ... p⁻⁴ for Galerkin), so the
largest real part over *all* discrete eigenvalues converges to 0, not to the true
abscissa: the unresolved modes lose the boundary damping.

An eigenvalue λ at the finer resolution is *resolved* when its nearest neighbour μ at
the coarser one satisfies :math:`|\lambda - \mu| \le r_{tol} \max(1, |\lambda|)` and the
pairing is mutual.  The resolution pair is refined (p → 1.5 p) until the rightmost
resolved eigenvalue's real part agrees to ``tol``.  Digits are
:math:`-\log_{10}(|\Delta \operatorname{Re}| / \max(1, |\alpha|))`.

Ill-conditioning (near a coalescence, e.g. a critically damped gain) is measured by the
energy-norm eigenvalue condition number
:math:`\kappa = \|x\|_E \|y\|_E / |y^* E x|` (x right, y left eigenvector of the pencil,
:math:`y^* A = \lambda y^* E`; 1 for an operator :math:`E^{-1}A` normal in the energy
inner product) and by the relative gap to the nearest other eigenvalue.  When no
eigenvalue is resolved at any resolution the spectrum is reported as unbounded below
(finite-time extinction, e.g. the wave with the matched damper k = 1), never as a number.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import scipy.linalg as sl

from phdesign import limits
from phdesign.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretize import DiscretePHS, discretize, feedback_matrix

__all__ = [
    "SpectrumReport",
    "default_resolutions",
    "eigen",
    "in_band_unresolved",
    "match_resolved",
    "resolved_abscissa",
    "spectrum",
]


@dataclass(frozen=True)
class SpectrumReport:
    """Result of :func:`spectrum`.

    Attributes
    ----------
    spectral_abscissa : float or None
        max Re over the resolved eigenvalues (None when unbounded below or none resolved).
    rightmost : list of complex
        Resolved eigenvalues with the largest real parts (finest resolution), conjugate
        pairs kept, sorted by decreasing real part then increasing |Im|.
    converged : bool
        The abscissa agrees to ``tol`` between the last two resolutions.
    digits : float or None
        Agreeing digits of the abscissa between the last two resolutions.
    n_resolved, n_total : int
        Resolved eigenvalues and all eigenvalues at the finest resolution.
    resolutions : tuple of int
        The last resolution pair.
    unbounded_below : bool
        No eigenvalue converges: empty spectrum / finite-time extinction.
    ill_conditioned : bool
        The rightmost eigenvalue is ill-conditioned (near a coalescence).
    condition_numbers : list of float
        Energy-norm condition numbers of ``rightmost``.
    all_eigenvalues_max_real : float
        max Re over ALL discrete eigenvalues at the finest resolution (the trap value; not
        an approximation of the abscissa).
    warnings : list of str
    """

    spectral_abscissa: float | None
    rightmost: list[complex]
    converged: bool
    digits: float | None
    n_resolved: int
    n_total: int
    resolutions: tuple[int, int]
    method: str
    system: str
    unbounded_below: bool = False
    ill_conditioned: bool = False
    condition_numbers: list[float] = field(default_factory=list)
    all_eigenvalues_max_real: float | None = None
    history: list[dict[str, Any]] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (complex numbers as ``[re, im]``)."""
        d = asdict(self)
        d["rightmost"] = [[float(z.real), float(z.imag)] for z in self.rightmost]
        d["resolutions"] = list(self.resolutions)
        return d


def eigen(
    d: DiscretePHS, K: np.ndarray | None = None, condition: bool = False
) -> tuple[np.ndarray, np.ndarray | None]:
    """Eigenvalues of ``E v' = closed_matrix(K) v`` and, optionally, condition numbers."""
    A = d.closed_matrix(K)
    if not condition:
        return sl.eigvals(A, d.E), None
    lam, Vl, Vr = sl.eig(A, d.E, left=True, right=True)
    EVr = d.E @ Vr
    num = np.sqrt(np.abs(np.einsum("ij,ij->j", Vr.conj(), EVr)))
    num *= np.sqrt(np.abs(np.einsum("ij,ij->j", Vl.conj(), d.E @ Vl)))
    den = np.abs(np.einsum("ij,ij->j", Vl.conj(), EVr))
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = np.where(den > 0, num / den, np.inf)
    return lam, kappa


def match_resolved(
    fine: np.ndarray, coarse: np.ndarray, rtol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Return the indices of ``fine`` eigenvalues resolved against ``coarse`` and their drifts.

    An eigenvalue is kept when its nearest coarse eigenvalue is within
    ``rtol * max(1, |λ|)``, the real parts agree within ``rtol * max(1, |Re λ|)``, and
    the nearest-neighbour pairing is mutual.

    Examples
    --------
    >>> import numpy as np
    >>> idx, drift = match_resolved(np.array([-1 + 1j, 50j]), np.array([-1 + 1j, 20j]), 1e-8)
    >>> idx.tolist()
    [0]
    """
    fine = np.asarray(fine)
    coarse = np.asarray(coarse)
    finite_f = np.isfinite(fine)
    finite_c = np.isfinite(coarse)
    if not finite_f.any() or not finite_c.any():
        return np.array([], dtype=int), np.array([])
    f_idx = np.flatnonzero(finite_f)
    c = coarse[finite_c]
    dist = np.abs(fine[f_idx][:, None] - c[None, :])
    nearest_c = np.argmin(dist, axis=1)
    nearest_f = np.argmin(dist, axis=0)
    drift = dist[np.arange(f_idx.size), nearest_c]
    mutual = nearest_f[nearest_c] == np.arange(f_idx.size)
    scale = np.maximum(1.0, np.abs(fine[f_idx]))
    # The real part decides the abscissa: it must agree on its own scale too, or a
    # high-frequency pair with a loose |λ| match could carry a meaningless real part.
    d_re = np.abs(fine[f_idx].real - c[nearest_c].real)
    keep = (
        mutual
        & (drift <= rtol * scale)
        & (d_re <= rtol * np.maximum(1.0, np.abs(fine[f_idx].real)))
    )
    return f_idx[keep], drift[keep] / scale[keep]


def in_band_unresolved(
    fine: np.ndarray,
    tight: np.ndarray,
    kappa: np.ndarray | None = None,
    cluster: float = 5e-2,
    kappa_min: float = 10.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Split the unresolved ``fine`` eigenvalues inside the resolved band.

    The band is |λ| ≤ max |λ| over the resolved ones; unresolved eigenvalues above it are
    the high-frequency artefacts of the semi-discretization.  Inside it, an eigenvalue
    that belongs to a cluster (another eigenvalue within ``cluster max(1, |λ|)``) or is
    ill-conditioned (``kappa > kappa_min``) is a genuine eigenvalue near a coalescence:
    its members move by O((eps κ)^(1/m)) between resolutions and fail the drift test, but
    they must never be dropped.  An isolated, well-conditioned in-band eigenvalue that
    does not reproduce is a round-off artefact (e.g. N >= 3 at high degree).

    Returns
    -------
    kept, artefacts : ndarray of int
        Indices kept as (ill-conditioned) eigenvalues and indices discarded.
    """
    fine = np.asarray(fine)
    empty = np.array([], dtype=int)
    if tight.size == 0:
        return empty, empty
    band = np.max(np.abs(fine[tight]))
    rest = np.setdiff1d(np.flatnonzero(np.isfinite(fine)), tight)
    rest = rest[np.abs(fine[rest]) <= band]
    keep = []
    for i in rest:
        lam = fine[i]
        others = np.abs(np.delete(fine, i) - lam)
        clustered = others.size > 0 and np.nanmin(others) <= cluster * max(1.0, abs(lam))
        ill = kappa is not None and kappa[i] > kappa_min
        keep.append(bool(clustered or ill))
    mask = np.array(keep, dtype=bool)
    return rest[mask], rest[~mask]


def resolved_abscissa(
    fine: np.ndarray,
    coarse: np.ndarray,
    rtol: float = 1e-6,
    kappa: np.ndarray | None = None,
) -> float | None:
    """Max real part over the resolved and the kept in-band eigenvalues, or None.

    Without condition numbers ``kappa`` every in-band unresolved eigenvalue is kept (an
    upper bound that an optimizer cannot exploit by driving eigenvalues into a cluster).
    """
    idx, _ = match_resolved(fine, coarse, rtol)
    if idx.size == 0:
        return None
    if kappa is None:
        kept = in_band_unresolved(fine, idx, np.full(fine.shape, np.inf))[0]
    else:
        kept = in_band_unresolved(fine, idx, kappa)[0]
    both = np.concatenate([idx, kept]).astype(int)
    return float(np.max(fine[both].real))


def default_resolutions(nm: NumericModel, method: str) -> tuple[int, int]:
    """Return the starting and maximal resolution for ``method`` (degree or nodes per group)."""
    if method == "fd":
        return 70, 240
    from phdesign.numeric import galerkin

    if nm.order >= 3:
        # Unscaled Legendre basis: the weakly imposed feedback on derivative traces puts
        # entries of order p^(4N-3) into the closed matrix and round-off grows with p:
        # start low, cap low, and let the best-agreeing pair win.  The trace-scaled basis
        # keeps the airy abscissa to ~1e-14 up to degree 140 (galerkin module docstring).
        return (8, 110) if galerkin.resolve_basis(None, nm.order) == "scaled" else (8, 48)
    return 20, {1: 100, 2: 110}[nm.order]


def _rightmost(lam: np.ndarray, count: int) -> np.ndarray:
    order = np.lexsort((np.abs(lam.imag), -np.round(lam.real, 12)))
    return lam[order][:count]


def _lost_rightmost(
    tried: list[dict[str, Any]], chosen: dict[str, Any], rtol_resolved: float
) -> dict[str, Any] | None:
    """Return an earlier pair whose resolved abscissa lies clearly right of ``chosen``.

    Round-off at high degree (N >= 3) can make a true eigenvalue fail the drift test at a
    fine pair although it agreed to many digits at a coarser one; the finer pair's
    abscissa is then the next eigenvalue to the left, a wrong answer. "Clearly" means by
    far more than both pairs' own drifts, so that the ordinary convergence of one
    eigenvalue under refinement never triggers this.
    """
    agreed = [r for r in tried if r["d_alpha"] <= rtol_resolved * max(1.0, abs(r["alpha"]))]
    if not agreed:
        return None
    right = max(agreed, key=lambda r: r["alpha"])
    margin = 100.0 * (right["d_alpha"] + chosen["d_alpha"]) + 1e-9 * max(1.0, abs(right["alpha"]))
    return right if right["alpha"] > chosen["alpha"] + margin else None


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
) -> SpectrumReport:
    """Converged spectral abscissa and rightmost eigenvalues.

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
        Required agreement of the abscissa (absolute, times max(1, |α|)); default 1e-10
        for Galerkin, 1e-3 for the second-order finite differences.
    rtol_resolved : float, optional
        Relative drift under which an eigenvalue counts as resolved; default 1e-6 for
        Galerkin, 1e-2 for finite differences.
    count : int
        How many rightmost eigenvalues to report.

    Returns
    -------
    SpectrumReport
    """
    limits.check_discretization(nm, method, resolution, max_resolution)
    if (C_m is None) != (L is None):
        raise NumericError("give both the sensors C_m and the gain L, or neither")
    K = None if C_m is None or L is None else feedback_matrix(C_m, L, nm.n_ports)
    if tol is None:
        tol = 1e-10 if method == "galerkin" else 1e-3
    if rtol_resolved is None:
        rtol_resolved = 1e-6 if method == "galerkin" else 1e-2
    p0, pmax = default_resolutions(nm, method)
    p = int(resolution) if resolution is not None else p0
    pmax = int(max_resolution) if max_resolution is not None else max(pmax, p)
    system = "plant (u = 0)" if K is None else "observer error system"

    def solve(res: int) -> np.ndarray:
        return eigen(discretize(nm, method, res), K)[0]

    history: list[dict[str, Any]] = []
    tried: list[dict[str, Any]] = []
    coarse = solve(p)
    prev_alpha: float | None = None
    result: dict[str, Any] = {}
    best: dict[str, Any] | None = None
    while True:
        fine_res = math.ceil(1.5 * p)
        d_fine = discretize(nm, method, fine_res)
        fine, kappa = eigen(d_fine, K, condition=True)
        idx, _drift = match_resolved(fine, coarse, rtol_resolved)
        loose, artefacts = in_band_unresolved(fine, idx, kappa)
        n_tight = int(idx.size)
        idx = np.concatenate([idx, loose]).astype(int)
        entry: dict[str, Any] = {
            "resolutions": [p, fine_res],
            "n_resolved": n_tight,
            "n_loose": int(loose.size),
            "all_max_real": float(np.max(fine.real[np.isfinite(fine)])),
        }
        if idx.size:
            res_lam = fine[idx]
            # drift of each resolved eigenvalue's real part between the two resolutions
            nearest = coarse[np.argmin(np.abs(coarse[None, :] - res_lam[:, None]), axis=1)]
            drifts = np.abs(res_lam.real - nearest.real)
            # the abscissa is the eigenvalue with the largest real part *less its drift*:
            # where many eigenvalues share the abscissa (a wave damper with k > 1), a
            # noisy high frequency must not stand for an exactly resolved low one
            j = int(np.argmax(res_lam.real - drifts))
            alpha = float(res_lam.real[j])
            d_alpha = float(drifts[j])
            entry.update({"spectral_abscissa": alpha, "abscissa_drift": d_alpha})
            result = {
                "lam": fine,
                "kappa": kappa,
                "idx": idx,
                "n_tight": n_tight,
                "loose": loose,
                "artefacts": artefacts,
                "alpha": alpha,
                "d_alpha": d_alpha,
                "res": (p, fine_res),
                "prev_alpha": prev_alpha,
            }
            prev_alpha = alpha
            tried.append(result)
            rel = d_alpha / max(1.0, abs(alpha))
            if best is None or rel < best["d_alpha"] / max(1.0, abs(best["alpha"])):
                best = result
            if d_alpha <= tol * max(1.0, abs(alpha)):
                history.append(entry)
                break
        history.append(entry)
        if fine_res >= pmax:
            break
        p, coarse = fine_res, fine
    if not result:
        return SpectrumReport(
            spectral_abscissa=None,
            rightmost=[],
            converged=False,
            digits=None,
            n_resolved=0,
            n_total=int(fine.size),
            resolutions=(p, fine_res),
            method=method,
            system=system,
            unbounded_below=True,
            all_eigenvalues_max_real=float(np.max(fine.real)),
            history=history,
            warnings=[
                "no eigenvalue converges under refinement up to resolution "
                f"{fine_res}: the spectrum is empty or runs off to -infinity "
                "(finite-time extinction); the spectral abscissa is unbounded below"
            ],
        )
    warnings: list[str] = []
    if best is not None and best is not result:
        # Refinement made agreement worse (round-off at high degree): keep the best pair.
        warnings.append(
            f"agreement degraded beyond resolutions {best['res'][0]}, {best['res'][1]} "
            "(round-off at high degree); that pair is reported"
        )
        result = best
    lost = _lost_rightmost(tried, result, rtol_resolved)
    if lost is not None:
        warnings.append(
            f"the eigenvalue {lost['alpha']:.10g} agreed between resolutions {lost['res'][0]} "
            f"and {lost['res'][1]} but not at the pair first chosen ({result['res'][0]}, "
            f"{result['res'][1]}), whose abscissa {result['alpha']:.6g} lies to its left; "
            "an eigenvalue that once agreed is real, so that pair is reported"
        )
        result = lost
    lam, kap, idx = result["lam"], result["kappa"], result["idx"]
    loose_set = {int(i) for i in result["loose"]}
    alpha, d_alpha = result["alpha"], result["d_alpha"]
    res_lam, res_kap = lam[idx], kap[idx]
    order = np.lexsort((np.abs(res_lam.imag), -np.round(res_lam.real, 12)))
    top = order[:count]
    rightmost = [complex(z) for z in res_lam[top]]
    conds = [float(c) for c in res_kap[top]]
    converged = bool(d_alpha <= tol * max(1.0, abs(alpha)))
    digits = float(-np.log10(max(d_alpha, 1e-17) / max(1.0, abs(alpha))))
    arte = result["artefacts"]
    arte = arte[lam.real[arte] > alpha]
    if arte.size:
        warnings.append(
            f"{arte.size} isolated, well-conditioned eigenvalues in the resolved band do not "
            f"reproduce under refinement (max Re {float(np.max(lam.real[arte])):.3g}); "
            "discarded as round-off artefacts"
        )
    # Rightmost eigenvalue conditioning and neighbour gap (coalescence detector).
    lead = res_lam[top[0]]
    others = lam[np.abs(lam - lead) > 0]
    gap = float(np.min(np.abs(others - lead))) / max(1.0, abs(lead)) if others.size else np.inf
    lead_loose = int(idx[top[0]]) in loose_set
    ill = bool(conds[0] > 1e4 or gap < 1e-3 or lead_loose)
    if ill:
        warnings.append(
            f"the rightmost eigenvalue {lead:.6g} is ill-conditioned (condition number "
            f"{conds[0]:.3g}, relative gap to its nearest neighbour {gap:.2g}): near a "
            "coalescence of eigenvalues (e.g. a critically damped gain); few digits are reliable"
        )
    # Never drop the rightmost silently: unresolved eigenvalues to the right.
    unresolved = np.setdiff1d(np.arange(lam.size), idx)
    right_unres = unresolved[lam.real[unresolved] > alpha + 1e-9 * max(1.0, abs(alpha))]
    if right_unres.size:
        low = right_unres[np.abs(lam[right_unres]) <= np.max(np.abs(res_lam))]
        warnings.append(
            f"{right_unres.size} unresolved eigenvalues lie to the right of the abscissa (max Re "
            f"{float(np.max(lam.real[right_unres])):.3g}); {low.size} of them within the "
            "resolved frequency band"
            + (": check them" if low.size else " (unresolved high frequencies, discarded)")
        )
    if not converged:
        warnings.append(
            f"the spectral abscissa did not converge to {tol:g}: it drifts by {d_alpha:.2g} "
            f"between resolutions {result['res'][0]} and {result['res'][1]}"
        )
    return SpectrumReport(
        spectral_abscissa=alpha,
        rightmost=rightmost,
        converged=converged,
        digits=digits,
        n_resolved=int(result["n_tight"]),
        n_total=int(lam.size),
        resolutions=tuple(result["res"]),
        method=method,
        system=system,
        unbounded_below=False,
        ill_conditioned=ill,
        condition_numbers=conds,
        all_eigenvalues_max_real=float(np.max(lam.real)),
        history=history,
        warnings=warnings,
    )
