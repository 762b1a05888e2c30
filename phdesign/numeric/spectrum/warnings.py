r"""Stage 3 of the spectrum: what the chosen pair's report must say about itself.

Each check below looks at one thing and returns its warnings; :func:`report_warnings`
runs them in the order a reader needs them: the kind of the abscissa (a limit at high
frequency, a lower bound while a branch may start above the band), no uniform decay,
an ill-conditioned rightmost eigenvalue, eigenvalues right of the abscissa that do not
count, not converged.

An eigenvalue is *ill-conditioned* when its energy-norm condition number exceeds
:data:`~phdesign.numeric.spectrum.refinement.ILL_CONDITION`, when it is a kept member of
a cluster, or when it lies within a relative gap :data:`ILL_GAP` of another eigenvalue
while its condition number exceeds :data:`~phdesign.numeric.spectrum.drift.KAPPA_MIN`: near a
coalescence eigenvalues are close *and* sensitive.  A semisimple multiple eigenvalue (a
full eigenspace, condition 1, e.g. the double 0 of a clamped-clamped beam's rigid
motions) is close to its twin but not sensitive: it is not flagged.
"""

from __future__ import annotations

import numpy as np

from phdesign.numeric.spectrum.abscissa import Abscissa
from phdesign.numeric.spectrum.drift import KAPPA_MIN, PairSpectrum
from phdesign.numeric.spectrum.eigen import SHIFT, roundoff_bound
from phdesign.numeric.spectrum.refinement import ILL_CONDITION, PairResult

__all__ = [
    "ILL_GAP",
    "positive_roundoff",
    "report_warnings",
    "reported_value",
    "rightmost_order",
]

ILL_GAP = 1e-3  # relative gap to the nearest other eigenvalue below which it may be ill-posed


def rightmost_order(lam: np.ndarray, accuracy: np.ndarray | None = None) -> np.ndarray:
    r"""Return the indices of ``lam`` by decreasing real part (12 decimals), then |Im|.

    With ``accuracy`` (the absolute accuracy of each real part), real parts that tie
    within it are ordered by frequency: the rightmost remaining eigenvalue leads a
    group of every remaining one whose interval reaches its own,
    :math:`\operatorname{Re}\lambda_j + u_j \ge \operatorname{Re}\lambda_0 - u_0`, listed by
    increasing |Im|; the next group starts at the rightmost eigenvalue left.  So on an
    undamped plant, whose real parts are round-off, the list is the lowest modes, not
    those that round-off happened to push right.
    """
    order = np.lexsort((np.abs(lam.imag), -np.round(lam.real, 12)))
    if accuracy is None:
        return order
    u = np.nan_to_num(np.asarray(accuracy, dtype=float), nan=0.0)
    left = list(order)
    out: list[int] = []
    while left:
        floor = lam.real[left[0]] - u[left[0]]
        group = [j for j in left if lam.real[j] + u[j] >= floor]
        out += sorted(group, key=lambda j: abs(lam.imag[j]))
        taken = set(group)
        left = [j for j in left if j not in taken]
    return np.asarray(out, dtype=int)


def _kind(a: Abscissa, attained: float) -> list[str]:
    limit, branch = a.limit, a.branch
    if branch is not None and a.kind == "limit":
        how = "exactly" if branch.exact else "as the supremum over independent phases"
        return [
            f"the abscissa is the limit of the real parts of the root chains of the family "
            f"of {branch.label} at high frequency, {branch.limit:.10g}, derived {how} from "
            "the principal part (the high-frequency characteristic determinant); no mode "
            "attains it"
        ]
    if a.kind == "lower bound":
        return []  # the band's warning says what the value is
    if limit is not None and a.kind == "limit":
        return [
            f"the real parts of the resolved eigenvalues keep rising with frequency (to "
            f"{limit.top_real:.6g} at |λ| = {limit.top_frequency:.3g}): the abscissa is their "
            f"limit, extrapolated from {limit.modes} modes as α∞ − c|λ|^-{limit.exponent:.2g}; "
            "no mode attains it"
        ]
    if limit is not None and limit.value + limit.uncertainty > attained:
        return [
            f"the real parts rise with frequency toward {limit.value:.6g} ± "
            f"{limit.uncertainty:.2g} at the top of the resolved band: the abscissa may be a "
            "limit that no mode attains"
        ]
    return []


def _not_derived(a: Abscissa) -> list[str]:
    """Return the warning that the chains' limits above the band were not derived, and why."""
    b = a.branches
    if b is None or b.analysed or not b.reason:
        return []
    return [
        f"the limits of the eigenvalue chains above the resolved band are not derived "
        f"({b.reason}): the abscissa is that of the resolved band, with the rising-trend "
        "rule for real parts that keep rising toward its top"
    ]


def _band(a: Abscissa, pair: PairSpectrum, value: float) -> list[str]:
    """Return the warning of rule 6's lower bound: a band that does not reach the onset."""
    b = a.branches
    if b is None or not a.band_short(pair):
        return []
    names = "; ".join(f.label for f in b.families)
    text = (
        f"not every eigenvalue up to |λ| = {b.required_band:.3g} is resolved (the first "
        f"unresolved one lies at |λ| = {pair.complete_band:.3g}): below the onset "
        f"{b.onset:.3g} of the principal part its families ({names}) are coupled into "
        "branches that may start above the resolved band (a Timoshenko beam's "
        f"thickness-shear branch, say); the abscissa is at least {value:.10g}"
    )
    if b.limits:
        text += (
            " (the larger of the resolved value and the chains' limits "
            + ", ".join(f"{lim.limit:.6g} for {lim.label}" for lim in b.limits)
            + ")"
        )
    needed = b.resolution_for(b.required_band, pair.scale)
    return [text + f"; raise max_resolution to about {needed}"]


def _no_decay(a: Abscissa, no_decay: bool) -> list[str]:
    if not no_decay:
        return []
    rising = (a.limit is not None or a.branch is not None) and a.kind == "limit"
    return [
        "no exponential decay found: the abscissa is 0 within its accuracy"
        + (" (the real parts approach 0 at high frequency: no uniform decay)" if rising else "")
    ]


def _ill_conditioned(a: Abscissa, pair: PairSpectrum) -> tuple[list[str], bool]:
    lam, s = pair.eigenvalues, pair.scale
    counted = np.flatnonzero(a.counted)
    lead_index = counted[rightmost_order(lam[counted])[0]]
    lead = lam[lead_index]
    cond = float(pair.condition[lead_index]) if pair.condition is not None else 1.0
    others = lam[np.isfinite(lam) & (np.arange(lam.size) != lead_index)]
    gap = float(np.min(np.abs(others - lead))) / max(s, abs(lead)) if others.size else np.inf
    close_and_sensitive = gap < ILL_GAP and (pair.condition is None or cond > KAPPA_MIN)
    # at the top of a band of rising real parts the "rightmost" mode is just the last one
    ill = a.kind != "limit" and bool(
        cond > ILL_CONDITION or close_and_sensitive or pair.clustered[lead_index]
    )
    if not ill:
        return [], False
    return [
        f"the rightmost eigenvalue {lead:.6g} is ill-conditioned (condition number "
        f"{cond:.3g}, relative gap to its nearest neighbour {gap:.2g}): near a "
        "coalescence of eigenvalues (e.g. a critically damped gain); few digits are reliable"
    ], True


def _right_of_abscissa(a: Abscissa, pair: PairSpectrum, attained: float, tol: float) -> list[str]:
    lam, s = pair.eigenvalues, pair.scale
    out = []
    if a.loose_right.any():
        loose = np.flatnonzero(a.loose_right)
        worst = loose[np.argmax(lam.real[loose])]
        out.append(
            f"{loose.size} resolved eigenvalues lie right of the abscissa by no more than their "
            f"own accuracy (max Re {lam.real[worst]:.3g} ± {pair.uncertainty[worst]:.2g} at "
            f"|λ| = {abs(lam[worst]):.3g}): their real parts are not resolved to {tol:g}, "
            "so they do not count"
        )
    artefacts = np.flatnonzero(pair.artefacts & (lam.real > attained))
    if artefacts.size:
        out.append(
            f"{artefacts.size} isolated, well-conditioned eigenvalues in the resolved band do "
            f"not reproduce under refinement (max Re {float(np.max(lam.real[artefacts])):.3g}); "
            "discarded as round-off artefacts"
        )
    rest = ~(pair.resolved | pair.clustered | pair.artefacts) & np.isfinite(lam)
    right = np.flatnonzero(rest & (lam.real > attained + 1e-9 * max(s, abs(attained))))
    if right.size:
        out.append(_unresolved_right(a, pair, right))
    return out


def positive_roundoff(pair: PairSpectrum, idx: np.ndarray) -> str:
    """Say which of the eigenvalues ``idx`` have positive real parts, and whether round-off.

    A positive real part within :func:`~phdesign.numeric.spectrum.eigen.roundoff_bound` is
    round-off of the eigen stage, not an instability of the discretization.  Returns ""
    when none of them has a positive real part.
    """
    lam = pair.eigenvalues
    pos = idx[lam.real[idx] > 0]
    if pos.size == 0:
        return ""
    kappa = np.ones(lam.size) if pair.condition is None else pair.condition
    bound = roundoff_bound(lam[pos], kappa[pos], pair.scale, lam.size)
    within = lam.real[pos] <= bound
    top = pos[np.argmax(lam.real[pos])]
    text = (
        f"{int(np.count_nonzero(within))} of them have positive real parts within round-off "
        f"(Re λ <= n ε κ max(|λ|, |λ − σ|²/σ), n = {lam.size}, σ = {SHIFT * pair.scale:.3g}: "
        f"the largest, {lam.real[top]:.3g} at |λ| = {abs(lam[top]):.3g}, is "
        f"{lam.real[top] / bound[np.flatnonzero(pos == top)[0]]:.2g} of its bound): "
        "round-off of the eigenvalue computation, not an instability of the discretization"
    )
    if not within.all():
        worst = pos[~within][np.argmax(lam.real[pos[~within]])]
        text += (
            f"; {int(np.count_nonzero(~within))} lie beyond it (max Re {lam.real[worst]:.3g} "
            f"at |λ| = {abs(lam[worst]):.3g})"
        )
    return text


def _unresolved_right(a: Abscissa, pair: PairSpectrum, right: np.ndarray) -> str:
    lam = pair.eigenvalues
    head = (
        f"{right.size} unresolved eigenvalues lie to the right of the abscissa (max Re "
        f"{float(np.max(lam.real[right])):.3g}), above the resolved frequency band "
        f"(|λ| > {pair.band:.3g})"
    )
    roundoff = positive_roundoff(pair, right)
    tail = f"; {roundoff}" if roundoff else ""
    b = a.branches
    if b is not None and a.band_short(pair):
        return (
            head + ": not discarded; the band does not reach the onset of the principal part"
        ) + tail
    if b is not None and b.analysed:
        top = b.limit
        bound = "no chain" if top is None else f"the chains' limits (at most {top.limit:.6g})"
        return (
            head + f": unresolved high frequencies, where {bound} account for the spectrum" + tail
        )
    return head + ": unresolved high frequencies, discarded" + tail


def report_warnings(
    chosen: PairResult, value: float, uncertainty: float, attained: float, tol: float
) -> tuple[list[str], bool, bool]:
    """Stage 3: warnings for the chosen pair; also (ill_conditioned, no_decay).

    ``value``, ``uncertainty`` and ``attained`` are the chosen pair's abscissa.
    """
    pair, a = chosen.pair, chosen.abscissa
    no_decay = value + uncertainty >= 0.0
    ill_text, ill = _ill_conditioned(a, pair)
    warnings = (
        _kind(a, attained)
        + _band(a, pair, value)
        + _not_derived(a)
        + _no_decay(a, no_decay)
        + ill_text
        + _right_of_abscissa(a, pair, attained, tol)
    )
    if not chosen.converged:
        warnings.append(
            f"the spectral abscissa did not converge to {tol:g} (relative to the rate "
            f"{pair.scale:.3g}): {chosen.reason}"
        )
    return warnings, ill, no_decay


def reported_value(value: float, uncertainty: float, no_decay: bool) -> tuple[float, float]:
    """Return the abscissa as reported: 0 when no decay is found, with the interval it covers.

    A dissipative loop has no eigenvalue right of 0, so when value + uncertainty >= 0 the
    abscissa lies in [value - uncertainty, 0]: it is reported as 0 with that width, not
    as a negative number with an uncertainty larger than itself.
    """
    if not no_decay:
        return float(value), float(uncertainty)
    return 0.0, float(max(uncertainty - value, uncertainty))
