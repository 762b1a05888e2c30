r"""Observer gain tuning: minimize the converged spectral abscissa of the error system.

The error system is :math:`E \dot{\tilde e} = (J - R - B C_m^\top L C_m B^\top)\tilde e`
(Galerkin: D = 0).  The objective is the largest real part over the eigenvalues that
are *resolved* (agree between the resolutions p and 1.5 p, see
:mod:`phdesign.numeric.spectrum`), never over all discrete eigenvalues: the unresolved
high frequencies of any semi-discretization have real parts that tend to the undamped
value and would flatten the landscape (the h² trap of DESIGN.md).

The search runs Nelder-Mead from several starts in log-space,
:math:`L = \operatorname{diag}(e^{s})` (or, with ``full=True``, :math:`L = e^{S} + W` with
S symmetric and W skew, which keeps
:math:`L + L^\top \succ 0`), then re-checks the optimum with the adaptive
:func:`~phdesign.numeric.spectrum.spectrum`.  The spectral abscissa is non-smooth where
two eigenvalue branches meet; the minimum of a boundary damper typically sits at such a
meeting (a coalescence, "critical damping"), so the result says whether it does.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg as sl
from scipy.optimize import minimize

from phdesign import limits
from phdesign.errors import NumericError, ObserverError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretize import discretize
from phdesign.numeric.spectrum import SpectrumReport, resolved_abscissa, spectrum

__all__ = ["TuneResult", "tune"]


@dataclass(frozen=True)
class TuneResult:
    """Result of :func:`tune`.

    Attributes
    ----------
    gain : ndarray
        The optimal L.
    spectral_abscissa : float or None
        Converged abscissa of the error system at ``gain``.
    converged : bool
        Whether that abscissa converged under refinement.
    at_coalescence : bool
        Whether two or more eigenvalues (not conjugates) meet at the optimum.
    active : list of complex
        Resolved eigenvalues (upper half-plane) whose real parts lie within 1e-3 |α| of α.
    report : SpectrumReport
    starts : list of dict
        Every start with its local optimum.
    """

    gain: np.ndarray
    spectral_abscissa: float | None
    converged: bool
    at_coalescence: bool
    active: list[complex]
    report: SpectrumReport
    starts: list[dict[str, Any]] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """Return a JSON-ready dictionary."""
        return {
            "gain": self.gain.tolist(),
            "spectral_abscissa": self.spectral_abscissa,
            "converged": self.converged,
            "at_coalescence": self.at_coalescence,
            "active": [[z.real, z.imag] for z in self.active],
            "rightmost": [[z.real, z.imag] for z in self.report.rightmost],
            "digits": self.report.digits,
            "resolutions": list(self.report.resolutions),
            "starts": self.starts,
            "warnings": list(self.report.warnings),
        }


def _eig_kappa(A: np.ndarray, E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues of (A, E) and their energy-norm condition numbers."""
    lam, Vl, Vr = sl.eig(A, E, left=True, right=True)
    EVr = E @ Vr
    num = np.sqrt(np.abs(np.einsum("ij,ij->j", Vr.conj(), EVr)))
    num *= np.sqrt(np.abs(np.einsum("ij,ij->j", Vl.conj(), E @ Vl)))
    den = np.abs(np.einsum("ij,ij->j", Vl.conj(), EVr))
    with np.errstate(divide="ignore", invalid="ignore"):
        return lam, np.where(den > 0, num / den, np.inf)


def _gain_from(params: np.ndarray, q: int, full: bool) -> np.ndarray:
    if not full:
        return np.diag(np.exp(np.clip(params, -30, 30)))
    S = np.zeros((q, q))
    iu = np.triu_indices(q)
    S[iu] = params[: iu[0].size]
    S = S + np.triu(S, 1).T
    W = np.zeros((q, q))
    iw = np.triu_indices(q, 1)
    W[iw] = params[iu[0].size :]
    return sl.expm(S) + W - W.T


def tune(
    nm: NumericModel,
    C_m: np.ndarray,
    *,
    full: bool = False,
    starts: int = 6,
    seed: int = 0,
    log_range: tuple[float, float] = (-3.0, 2.0),
    resolution: int | None = None,
    maxiter: int = 300,
) -> TuneResult:
    """Tune the observer gain L for the sensors ``C_m``.

    Parameters
    ----------
    nm : NumericModel
    C_m : ndarray (q, N n)
    full : bool
        Full L (``e^S + W``) instead of a positive diagonal.
    starts : int
        Number of starts (the first is L = I, the others uniform in ``log_range``
        (natural log) per diagonal entry).
    seed : int
        Seed of the random starts.
    resolution : int, optional
        Galerkin degree of the coarse member of the resolution pair (default: the one at
        which the spectrum of L = I converges).
    maxiter : int
        Nelder-Mead iterations per start.

    Returns
    -------
    TuneResult
    """
    limits.check_tuning(nm, starts, seed, maxiter, resolution)
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    q = C.shape[0]
    if q == 0:
        raise ObserverError("tuning needs at least one sensor")
    if C.shape[1] != nm.n_ports:
        raise ObserverError(f"C_m must have {nm.n_ports} columns; found {C.shape[1]}")
    if resolution is None:
        first = spectrum(nm, C, np.eye(q))
        # an unconverged or extinct start says nothing about a good pair: use a moderate one
        p_lo = first.resolutions[0] if first.converged else 30
    else:
        p_lo = int(resolution)
    p_hi = int(np.ceil(1.5 * p_lo))
    pair = []
    for p in (p_lo, p_hi):
        d = discretize(nm, "galerkin", p)
        Bc = d.B @ C.T  # E e' = (A0 - Bc L Bc^T) e
        pair.append((d.E, d.J - d.R, Bc))

    def objective(params: np.ndarray) -> float:
        L = _gain_from(params, q, full)
        (E0, A00, B0), (E1, A01, B1) = pair
        coarse = sl.eigvals(A00 - B0 @ L @ B0.T, E0)
        fine, kappa = _eig_kappa(A01 - B1 @ L @ B1.T, E1)
        alpha = resolved_abscissa(fine, coarse, kappa=kappa)
        return 1e6 if alpha is None else alpha  # nothing resolved: leave this region

    rng = np.random.default_rng(seed)
    npar = q if not full else q * (q + 1) // 2 + q * (q - 1) // 2
    x_starts: list[np.ndarray] = [np.zeros(npar)]
    for _ in range(max(0, starts - 1)):
        if not full:
            x_starts.append(np.asarray(rng.uniform(log_range[0], log_range[1], size=q)))
        else:
            x = np.zeros(npar)
            S = np.diag(rng.uniform(log_range[0], log_range[1], size=q))
            x[: q * (q + 1) // 2] = S[np.triu_indices(q)]
            x_starts.append(x)
    records = []
    best = None
    for x0 in x_starts:
        res = minimize(
            objective,
            x0,
            method="Nelder-Mead",
            options={"maxiter": maxiter * npar, "xatol": 1e-7, "fatol": 1e-11},
        )
        rec = {
            "start": _gain_from(x0, q, full).tolist(),
            "gain": _gain_from(res.x, q, full).tolist(),
            "spectral_abscissa": float(res.fun),
        }
        records.append(rec)
        if best is None or res.fun < best.fun:
            best = res
    assert best is not None
    L = _gain_from(best.x, q, full)
    report = spectrum(nm, C, L)
    if report.spectral_abscissa is None and not report.unbounded_below:
        raise NumericError("the spectrum at the tuned gain did not resolve")
    active: list[complex] = []
    coalesced = False
    if report.spectral_abscissa is not None:
        alpha = report.spectral_abscissa
        up = [z for z in report.rightmost if z.imag >= -1e-12]
        active = [z for z in up if z.real >= alpha - 1e-3 * max(1.0, abs(alpha))]
        coalesced = report.ill_conditioned or len(active) >= 2
    return TuneResult(
        gain=L,
        spectral_abscissa=report.spectral_abscissa,
        converged=report.converged,
        at_coalescence=bool(coalesced),
        active=active,
        report=report,
        starts=records,
    )
