r"""The spectral abscissa of a resolution pair: one definition, and its accuracy.

Given the drift test of a resolution pair (:class:`~phdesign.numeric.spectrum.drift.PairSpectrum`),
each resolved or clustered eigenvalue :math:`\lambda_i` has a real part known to
:math:`u_i` (its drift, at least the round-off floor).  With the abscissa tolerance
``tol`` and the problem's rate s:

1. the *converged* eigenvalues are the resolved ones with
   :math:`u_i \le tol \max(s, |\operatorname{Re}\lambda_i|)`;
2. an eigenvalue that is not converged *counts* when it lies right of every converged
   one by more than the uncertainties, :math:`\operatorname{Re}\lambda_i - u_i >
   \max_{\text{converged}} (\operatorname{Re}\lambda_j + u_j)`, so that a real but
   poorly resolved rightmost eigenvalue (a coalescence) is never dropped;
3. the abscissa *attained* lies between the largest real part certain to be attained,
   :math:`\ell = \max_i (\operatorname{Re}\lambda_i - u_i)`, and the bound no counted
   eigenvalue exceeds, :math:`r = \max_i (\operatorname{Re}\lambda_i + u_i)`.  Its value
   is the real part of the lowest-frequency counted eigenvalue that reaches :math:`\ell`
   (:math:`\operatorname{Re}\lambda_i + u_i \ge \ell`: where several share the
   abscissa, as every mode of the beam with viscous damping does, the best resolved one
   gives it) and its accuracy :math:`u_\alpha` covers :math:`[\ell, r]`.  The
   listed rightmost eigenvalues are the counted ones: none lies right of
   :math:`\alpha + u_\alpha`.  Eigenvalues that neither converge nor count but lie
   right of it (high frequencies whose real parts are round-off, e.g. :math:`10^{-8}`
   at :math:`|\lambda| = 6 \cdot 10^4`) are reported apart, never as the abscissa.  A
   positive real part is round-off as well when the pencil is dissipative (a closed loop
   ũ = −Kỹ with :math:`K + K^\top \succeq 0` of a port-Hamiltonian discretization,
   whose invariants :mod:`phdesign.numeric.discretization.invariants` checks): every exact
   eigenvalue
   has :math:`\operatorname{Re}\lambda \le 0`, and :math:`u_i \ge
   \max(\operatorname{Re}\lambda_i, 0)` (:mod:`phdesign.numeric.spectrum.drift`);
4. when the real parts keep rising with frequency up to the top of the resolved band,
   the supremum is not attained by any resolved mode: the largest real parts up to each
   frequency (the running maximum, in the upper half plane) are fitted by
   :math:`\alpha_\infty - c\,|\lambda|^{-q}` over the upper half of the band, and the
   abscissa is the limit :math:`\alpha_\infty` when it lies clearly above the attained
   value.  Its uncertainty is the spread between fits (free exponent q ∈ [1/2, 4], the
   exponent 2 of WKB theory for N = 1, and the fit without the top third of the points).
   For a string with a damper at z = 1, the WKB limit is
   :math:`\ln|(Z(1) - k)/(Z(1) + k)| / \tau` with the impedance
   :math:`Z = \sqrt{\rho T}` at the damper and the round-trip time
   :math:`\tau = 2 \int_a^b dz / c(z)`; ``tests/numeric/spectrum/test_spectrum_trust.py`` checks
   the
   extrapolation against it;
5. when no eigenvalue is resolved, the spectrum is *empty* (finite-time extinction, the
   abscissa unbounded below) only on evidence: at both resolutions no eigenvalue lies in
   the disk :math:`|\lambda| \le 5 s` (the first mode of a dimensionless problem lies at
   :math:`|\lambda| \sim \pi/2 \dots \pi`) and the eigenvalue nearest the origin decays
   faster than it oscillates (:math:`\operatorname{Re}\lambda < -|\lambda|/2`), as for
   the string with the matched damper.  A conservative system (lossless: every discrete
   eigenvalue on the imaginary axis) never shows it; there nothing is "not resolved at
   these resolutions".
6. the spectrum above the band (:mod:`phdesign.numeric.spectrum.branches`): the principal part's
   root chains have real parts tending to limits that no finite band sees, and below
   the onset Ω of the principal part the families are coupled into branches that start
   anywhere up to Ω (the Timoshenko beam's thickness-shear cut-off).  So
   (:func:`with_branches`) the abscissa is the larger of the attained value and every
   chain's limit (kind ``"limit"``, the family named, when a limit is larger); it is
   exact when the chains' limits are derived (N = 1) and supersedes an extrapolation of
   rule 4 that agrees with it.  When the eigenvalues are not all resolved up to
   :data:`~phdesign.numeric.spectrum.branches.ONSET_MARGIN` Ω (:attr:`PairSpectrum.complete_band
   <phdesign.numeric.spectrum.drift.PairSpectrum.complete_band>`), the value is only a lower
   bound (kind ``"lower bound"``): a branch may start above the band.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from scipy.optimize import minimize_scalar

from phdesign.numeric.spectrum.branches import Branches, BranchLimit
from phdesign.numeric.spectrum.drift import PairSpectrum

__all__ = [
    "MIN_MODES_ABOVE",
    "Abscissa",
    "HighFrequencyLimit",
    "estimate_abscissa",
    "high_frequency_limit",
    "looks_empty",
    "with_branches",
]

#: A converged report needs this many resolved modes (upper half plane) at higher
#: frequency than the mode attaining the abscissa: the band must reach beyond the
#: rightmost mode for a trend of the real parts with frequency to show.
MIN_MODES_ABOVE = 4

EMPTY_DISK = 5.0  # radius, in units of the rate, of the disk an empty spectrum leaves empty
_MIN_RECORDS = 4  # running-maximum records in the top half of the band needed for a trend
_SIGNIFICANCE = 10.0  # a rise counts when it exceeds this many uncertainties of the points


@dataclass(frozen=True)
class HighFrequencyLimit:
    r"""Real parts rising with frequency, and their extrapolated supremum.

    Attributes
    ----------
    value : float
        :math:`\alpha_\infty`, the limit of the real parts at high frequency.
    uncertainty : float
        Spread of the extrapolations (module docstring).
    exponent : float
        Fitted q in :math:`\alpha_\infty - c |\lambda|^{-q}`.
    modes : int
        Number of points fitted.
    top_frequency : float
        Largest |λ| of the resolved band.
    top_real : float
        Largest real part attained in the band (at its top).
    """

    value: float
    uncertainty: float
    exponent: float
    modes: int
    top_frequency: float
    top_real: float


@dataclass(frozen=True)
class Abscissa:
    """The abscissa of one resolution pair (module docstring).

    Attributes
    ----------
    value : float or None
        The abscissa (None when no eigenvalue is resolved).
    uncertainty : float or None
        Accuracy of ``value`` (absolute).
    kind : {"attained", "limit", "lower bound", "extinct", "none"}
        Attained by an eigenvalue, a limit approached at high frequency (rules 4 and 6),
        a lower bound (rule 6: the band does not reach the onset), nothing resolved with
        the evidence of an empty spectrum (rule 5), or nothing resolved.
    index : int or None
        Index (into the pair's eigenvalues) of the counted eigenvalue with the largest real
        part.
    attained : float or None
        Largest real part attained by a counted eigenvalue.
    attained_uncertainty : float or None
        Its accuracy, before any widening by a rising trend.
    counted : ndarray of bool
        The eigenvalues that count (rules 1 and 2).
    converged_mask : ndarray of bool
        The converged eigenvalues (rule 1).
    loose_right : ndarray of bool
        Eigenvalues that do not count but lie right of ``attained`` (rule 3).
    modes_above : int
        Resolved modes (upper half plane) at higher frequency than the eigenvalue that
        gives the abscissa.
    limit : HighFrequencyLimit or None
        The rising trend, when there is one (whatever its limit).
    branches : Branches or None
        The structure above the band (rule 6), when it was applied.
    pair_dissipative : bool
        The pencil is dissipative (no eigenvalue right of 0: rule 3), so is the abscissa.
    branch : BranchLimit or None
        The chains' limit that gives the abscissa (rule 6), when one does.
    """

    value: float | None
    uncertainty: float | None
    kind: Literal["attained", "limit", "lower bound", "extinct", "none"]
    index: int | None
    attained: float | None
    attained_uncertainty: float | None
    counted: np.ndarray
    converged_mask: np.ndarray
    loose_right: np.ndarray
    modes_above: int
    limit: HighFrequencyLimit | None
    branches: Branches | None = None
    branch: BranchLimit | None = None
    pair_dissipative: bool = False

    def band_short(self, pair: PairSpectrum) -> bool:
        """Tell whether some eigenvalue below the required band is unresolved (rule 6)."""
        return self.branches is not None and pair.complete_band < self.branches.required_band


def _fit(w: np.ndarray, r: np.ndarray, q: float) -> tuple[float, float]:
    """Least-squares α, residual of r ≈ α + c w^-q."""
    X = np.stack([np.ones_like(w), w**-q], axis=1)
    coef, *_ = np.linalg.lstsq(X, r, rcond=None)
    return float(coef[0]), float(np.sum((X @ coef - r) ** 2))


def high_frequency_limit(pair: PairSpectrum) -> HighFrequencyLimit | None:
    """Detect real parts rising with frequency up to the band's top and extrapolate them.

    Returns None when there is no significant rise (module docstring, rule 4).
    """
    lam = pair.eigenvalues[pair.resolved]
    u = pair.uncertainty[pair.resolved]
    upper = lam.imag >= 0
    lam, u = lam[upper], u[upper]
    if lam.size < 2 * _MIN_RECORDS:
        return None
    order = np.argsort(np.abs(lam))
    lam, u = lam[order], u[order]
    w, r = np.abs(lam), lam.real
    running = np.maximum.accumulate(r)
    top = w[-1]
    records = np.flatnonzero((r >= running) & (w > 0.5 * top))
    if records.size < _MIN_RECORDS or w[records[-1]] < 0.75 * top:
        return None
    below = np.flatnonzero(w <= 0.5 * top)
    if below.size == 0:
        return None
    rise = r[records[-1]] - running[below[-1]]
    noise = max(float(np.max(u[records])), float(np.max(u[below[-1:]])))
    if not rise > _SIGNIFICANCE * noise:
        return None
    ww, rr = w[records] / top, r[records]  # frequencies in units of the band's top
    best = minimize_scalar(lambda q: _fit(ww, rr, q)[1], bounds=(0.5, 4.0), method="bounded")
    q = float(best.x)
    value = _fit(ww, rr, q)[0]
    spread = [abs(value - _fit(ww, rr, 2.0)[0])]
    cut = records.size - max(1, records.size // 3)
    if cut >= 3:
        spread.append(abs(value - _fit(ww[:cut], rr[:cut], q)[0]))
    uncertainty = max(*spread, noise)
    # the limit of rising real parts is at least the last of them, and at most 0 when the
    # pencil is dissipative (no eigenvalue has a positive real part)
    value = max(value, rr[-1])
    return HighFrequencyLimit(
        value=float(min(value, 0.0) if pair.dissipative else value),
        uncertainty=float(uncertainty),
        exponent=q,
        modes=int(records.size),
        top_frequency=float(top),
        top_real=float(rr[-1]),
    )


def looks_empty(pair: PairSpectrum) -> bool:
    """Rule 5: the evidence of an empty spectrum at both resolutions of ``pair``."""
    for lam in (pair.coarse, pair.eigenvalues):
        lam = lam[np.isfinite(lam)]
        if lam.size == 0:
            continue
        nearest = lam[np.argmin(np.abs(lam))]
        if abs(nearest) <= EMPTY_DISK * pair.scale or nearest.real >= -0.5 * abs(nearest):
            return False
    return True


def _modes_above(pair: PairSpectrum, reference: float) -> int:
    lam = pair.eigenvalues[pair.resolved]
    lam = lam[lam.imag >= 0]
    return int(np.count_nonzero(np.abs(lam) > reference * (1 + 1e-9) + 1e-300))


def estimate_abscissa(pair: PairSpectrum, tol: float) -> Abscissa:
    """Return the abscissa of ``pair`` under the abscissa tolerance ``tol`` (module docstring)."""
    lam = pair.eigenvalues
    s = pair.scale
    none = np.zeros(lam.shape, dtype=bool)
    cand = pair.candidates
    if not cand.any():
        empty: Literal["extinct", "none"] = "extinct" if looks_empty(pair) else "none"
        return Abscissa(None, None, empty, None, None, None, none, none, none, 0, None)
    re = lam.real
    u = pair.uncertainty
    converged = pair.resolved & (u <= tol * np.maximum(s, np.abs(re)))
    if converged.any():
        reach = float(np.max((re + u)[converged]))
        counted = converged | (cand & ~converged & (re - u > reach))
    else:
        counted = cand.copy()
    members = np.flatnonzero(counted)
    lower = float(np.max((re - u)[members]))  # the largest real part certain to be attained
    upper = float(np.max((re + u)[members]))  # no counted eigenvalue lies right of it
    # where several eigenvalues share the abscissa within their accuracy (every mode of a
    # uniformly damped beam, a wave with a strong damper), the lowest-frequency one gives
    # its value: discretization error and round-off grow with frequency
    sharing = members[(re + u)[members] >= lower]
    idx = int(sharing[np.argmin(np.abs(lam[sharing]))])
    attained = float(re[idx])
    u_att = max(float(u[idx]), upper - attained, attained - lower)
    reference = abs(complex(lam[idx]))
    loose_right = cand & ~counted & (re > attained + u_att)
    limit = high_frequency_limit(pair)
    kind: Literal["attained", "limit"] = "attained"
    value, uncertainty = attained, u_att
    index: int | None = idx
    if limit is not None and limit.value - limit.uncertainty > attained + u_att:
        value, uncertainty, kind, index = limit.value, limit.uncertainty, "limit", None
    elif limit is not None and limit.value + limit.uncertainty > attained:
        uncertainty = max(u_att, limit.value + limit.uncertainty - attained)
    return Abscissa(
        value=value,
        uncertainty=uncertainty,
        kind=kind,
        index=index,
        attained=attained,
        attained_uncertainty=u_att,
        counted=counted,
        converged_mask=converged,
        loose_right=loose_right,
        modes_above=_modes_above(pair, reference),
        limit=limit,
        pair_dissipative=pair.dissipative,
    )


def with_branches(a: Abscissa, pair: PairSpectrum, branches: Branches | None) -> Abscissa:
    """Rule 6: combine the pair's abscissa with the chains' limits above the band.

    Returns ``a`` with ``branches`` set.  The abscissa lies in
    ``[max(lo_a, lo_c), max(hi_a, hi_c)]`` (the pair's interval and the largest chain
    limit's), capped at 0 for a dissipative pencil; its value is the chains' limit when
    that lies clearly right of the pair's value (kind ``"limit"``), else the pair's.
    While the band does not reach the onset the kind is ``"lower bound"``.
    """
    if branches is None:
        return a
    out = replace(a, branches=branches)
    if a.value is None or a.uncertainty is None or a.attained is None:
        return out
    kind = a.kind
    top = branches.limit
    if top is not None:
        out = _combine(out, top)
    if pair.complete_band < branches.required_band:
        kind = "lower bound"
    elif out.kind == "limit":
        kind = "limit"
    return replace(out, kind=kind)


def _combine(a: Abscissa, top: BranchLimit) -> Abscissa:
    """Return the abscissa of ``a`` (which has a value) together with the chains' limit ``top``."""
    assert a.value is not None
    assert a.uncertainty is not None
    limit = a.limit
    trend_agrees = limit is None or limit.value - limit.uncertainty <= top.limit + top.uncertainty
    lo = max(a.value - a.uncertainty, top.limit - top.uncertainty)
    hi = max(a.value + a.uncertainty, top.limit + top.uncertainty)
    if a.kind == "limit" and trend_agrees:  # rule 4 extrapolated what rule 6 derives
        lo, hi = top.limit - top.uncertainty, top.limit + top.uncertainty
    cap = 0.0 if a.pair_dissipative else math.inf
    hi = max(min(hi, cap), lo)
    # the limit gives the value when it lies certainly right of the pair's value (its
    # interval may still overlap the pair's, e.g. a lossless family above damped modes)
    wins = top.limit - top.uncertainty > a.value or (a.kind == "limit" and trend_agrees)
    value = top.limit if wins else a.value
    value = min(max(value, lo), hi)
    return replace(
        a,
        value=value,
        uncertainty=max(value - lo, hi - value),
        kind="limit" if wins else a.kind,
        index=None if wins else a.index,
        limit=limit if not trend_agrees else None,
        branch=top if wins else None,
    )
