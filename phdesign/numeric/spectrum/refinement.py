r"""Refinement of the resolution pair and the choice of the pair reported (stages 1 and 2).

Stage 1, :func:`refine`: pairs (p, ⌈1.5 p⌉), p → ⌈1.5 p⌉, each through the drift test
(:mod:`phdesign.numeric.spectrum.drift`) and the abscissa rule
(:mod:`phdesign.numeric.spectrum.abscissa`),
until a pair satisfies the convergence rule (:func:`convergence_rule`), the largest
resolution is reached, or refinement stops helping (an ill-conditioned coalescence, an
empty spectrum seen twice, a high-frequency limit extrapolated alike twice).  The
eigenvalues come from a *per-resolution solver* (:class:`ResolutionSolver`): the closed
loop of one discretization (:class:`ClosedLoopSolver`, for
:func:`phdesign.numeric.spectrum.converged.spectrum`) or the assembled observer-based loop
(:func:`phdesign.numeric.control.spectrum.loop_spectrum`); both solve each resolution once,
by the shift and invert of :mod:`phdesign.numeric.spectrum.eigen`, with condition numbers, and
each resolution serves two pairs.  So one refinement, one drift rule and one choice of
the pair serve the spectrum and the loop.

Stage 2, :func:`choose_pair`: the converged pair, else the most accurate pair that no finer
pair contradicts, unless an earlier pair's resolved abscissa lies clearly to the right.
:func:`phdesign.numeric.spectrum.converged.spectrum` runs both and writes the report (stage 3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from phdesign.core.cache import MODEL_WORK, OwnerCache
from phdesign.core.errors import NumericError
from phdesign.core.limits import MAX_CACHE_BYTES, MAX_CACHED_STRUCTURES
from phdesign.core.progress import report
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.feedback import open_port_gain
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.scales import dimensionless_model
from phdesign.numeric.spectrum.abscissa import (
    MIN_MODES_ABOVE,
    Abscissa,
    estimate_abscissa,
    with_branches,
)
from phdesign.numeric.spectrum.branches import ONSET_MARGIN, Branches
from phdesign.numeric.spectrum.characteristics import CharacteristicForm, characteristic_form
from phdesign.numeric.spectrum.drift import PairSpectrum, pair_spectrum
from phdesign.numeric.spectrum.eigen import SHIFT, PreparedSystem, prepare, rescaled
from phdesign.numeric.spectrum.principal_symbol import PrincipalForm, principal_form
from phdesign.numeric.spectrum.report import RefinementStep

__all__ = [
    "ILL_CONDITION",
    "ClosedLoopSolver",
    "Discretizations",
    "PairResult",
    "ResolutionSolver",
    "choose_pair",
    "convergence_rule",
    "extinct_twice",
    "fine_resolution",
    "refine",
    "resolvable_band",
]

ILL_CONDITION = 1e4  # energy-norm condition number of an ill-conditioned rightmost eigenvalue

#: The structure above the band of each model: its form, and its structure by gain.
_STRUCTURES = OwnerCache(
    "structures above the band", entries=MAX_CACHED_STRUCTURES, nbytes=MAX_CACHE_BYTES
)


def fine_resolution(p: int) -> int:
    """Return the finer member ⌈1.5 p⌉ of the resolution pair started at ``p``."""
    return math.ceil(1.5 * int(p))


@dataclass(frozen=True)
class PairResult:
    """One resolution pair of the refinement: its drift test, abscissa and verdict.

    Attributes
    ----------
    pair : PairSpectrum
    abscissa : Abscissa
    converged : bool
        The convergence rule holds (module docstring).
    reason : str
        Why it does not ("" when it does).
    """

    pair: PairSpectrum
    abscissa: Abscissa
    converged: bool
    reason: str

    @property
    def relative_uncertainty(self) -> float:
        """Uncertainty of the abscissa over max(rate, |α|); inf when there is none."""
        a = self.abscissa
        if a.value is None or a.uncertainty is None:
            return math.inf
        return a.uncertainty / max(self.pair.scale, abs(a.value))

    def step(self) -> RefinementStep:
        """Return the summary kept in the report's history."""
        return RefinementStep(
            resolutions=self.pair.resolutions,
            n_resolved=self.pair.n_resolved,
            spectral_abscissa=self.abscissa.value,
            uncertainty=self.abscissa.uncertainty,
            kind=self.abscissa.kind,
            converged=self.converged,
            all_max_real=self.pair.all_max_real,
            n_loose=int(np.count_nonzero(self.pair.clustered)),
        )


def convergence_rule(pair: PairSpectrum, a: Abscissa, tol: float) -> str:
    """Return why the pair is not converged, or "" when it is (module docstring)."""
    if a.band_short(pair):
        assert a.branches is not None  # band_short says so
        return (
            f"not every eigenvalue up to |λ| = {a.branches.required_band:.3g} "
            f"({ONSET_MARGIN:g} × the onset {a.branches.onset:.3g} of the principal part) is "
            f"resolved: the first unresolved one lies at |λ| = {pair.complete_band:.3g}, and "
            "a branch of the spectrum may start above it"
        )
    if a.kind == "limit" and a.branch is not None:
        return (
            ""
            if a.uncertainty is not None and a.uncertainty <= _accuracy(pair, a, tol)
            else (f"the chains' limit is known to {a.uncertainty:.2g} only")
        )
    if a.kind == "limit":
        return "the real parts keep rising with frequency (the abscissa is a limit)"
    if a.value is None or a.index is None or a.uncertainty is None:
        return "no eigenvalue is resolved"
    if a.limit is not None and a.limit.value + a.limit.uncertainty > a.value:
        return (
            "the real parts rise with frequency at the top of the resolved band and may "
            f"exceed the largest one attained (limit {a.limit.value:.6g} ± "
            f"{a.limit.uncertainty:.2g})"
        )
    if not a.converged_mask[a.index]:
        return (
            f"the rightmost eigenvalue agrees only to {a.uncertainty:.2g} between "
            f"resolutions {pair.resolutions[0]} and {pair.resolutions[1]}"
        )
    if a.uncertainty > tol * max(pair.scale, abs(a.value)):
        return (
            f"the abscissa is known to {a.uncertainty:.2g} only (the real parts near the top "
            "of the resolved band may still rise)"
        )
    if a.modes_above < MIN_MODES_ABOVE:
        return (
            f"only {a.modes_above} resolved modes lie above the rightmost one "
            f"({MIN_MODES_ABOVE} are needed to see the rightmost modes)"
        )
    return ""


def _accuracy(pair: PairSpectrum, a: Abscissa, tol: float) -> float:
    """Return the accuracy a converged abscissa needs: tol max(rate, |α|)."""
    return tol * max(pair.scale, abs(a.value or 0.0))


class ResolutionSolver(Protocol):
    """What :func:`refine` needs: the eigenvalues of the problem at a resolution.

    Attributes
    ----------
    rate : float
        The problem's rate s (:mod:`phdesign.numeric.scales`): the drift test's scale.
    dissipative : bool
        Every exact eigenvalue has Re λ <= 0 (:mod:`phdesign.numeric.spectrum.drift`).
    branches : Branches or None
        The structure above the band (:mod:`phdesign.numeric.spectrum.branches`).
    """

    rate: float
    dissipative: bool
    branches: Branches | None

    def __call__(self, p: int, condition: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Eigenvalues (in the model's units) and energy-norm condition numbers at p.

        ``condition=False``: the eigenvalues alone (the coarse member of the first pair,
        whose condition numbers nothing reads), the same numbers without eigenvectors.
        """
        ...


class Discretizations:
    """The dimensionless model's discretizations, once per resolution, for any gain.

    They do not depend on the gain, so a gain map shares one (the sweep's ``spectrum`` job
    gives one to :func:`phdesign.numeric.spectrum.converged.spectrum` for every gain of a chunk);
    :func:`refine` makes its own when given none.

    Parameters
    ----------
    nm : NumericModel
    method : {"galerkin", "fd"}
    basis : {"scaled", "legendre"}, optional
        The Galerkin basis (default: the defaults table's, for the order).
    """

    def __init__(self, nm: NumericModel, method: str, basis: str | None = None) -> None:
        self.model, self.method, self.basis = nm, method, basis
        self.dimensionless, self.scales = dimensionless_model(nm)

    def branches(self, K: np.ndarray | None) -> Branches:
        """Return the structure above the band of the loop ũ = −Kỹ (K on the external ports).

        It depends on the model and the gain only: it is kept (:data:`_STRUCTURES`), the
        gain-independent characteristic form once per model, each gain's structure beside it.
        """
        gain = b"" if K is None else np.ascontiguousarray(K, dtype=float).tobytes()
        return _STRUCTURES.get(self.model, ("branches", gain), lambda: self._branches(K))

    def _branches(self, K: np.ndarray | None) -> Branches:
        nd, sc = self.dimensionless, self.scales
        form = _STRUCTURES.get(self.model, "form", lambda: _form(nd))
        W = nd.U + open_port_gain(nd, K) @ nd.Y
        return form.at(W, sc.rate, sc.length)

    def serves(self, nm: NumericModel, method: str, basis: str | None) -> bool:
        """Tell whether these discretizations are those of ``nm`` by ``method`` and ``basis``."""
        return self.model is nm and self.method == method and self.basis == basis

    def __call__(self, p: int) -> PreparedSystem:
        """Return the discretization at resolution ``p``, prepared for the eigen stage (cached).

        Shift and invert (:mod:`phdesign.numeric.spectrum.eigen`) at
        :data:`~phdesign.numeric.spectrum.eigen.SHIFT`, the rate of the dimensionless model.
        """
        key = ("prepared", self.method, p, self.basis, SHIFT)
        return MODEL_WORK.get(self.dimensionless, key, lambda: self._prepare(p))

    def _prepare(self, p: int) -> PreparedSystem:
        discrete = discretize(self.dimensionless, self.method, p, basis=self.basis)
        return prepare(discrete, shift=SHIFT)


def _form(nd: NumericModel) -> CharacteristicForm | PrincipalForm:
    """Return the gain-independent form of the structure above the band of ``nd``."""
    return characteristic_form(nd) if nd.order == 1 else principal_form(nd)


class ClosedLoopSolver:
    r"""Eigenvalues of the closed loop ũ = −Kỹ of the dimensionless model, once per resolution.

    Shift and invert (:mod:`phdesign.numeric.spectrum.eigen`) on the discretizations of
    :class:`Discretizations` (made here unless given: a gain map shares them), scaled back
    by the rate.  The closed loop is dissipative: the model and its discretizations check
    their invariants and ``K`` comes from
    :func:`~phdesign.numeric.discretization.registry.feedback_matrix` (:math:`L + L^\top \succ 0`).

    Raises
    ------
    NumericError
        If ``discretizations`` are not those of ``nm`` by ``method`` and ``basis``.
    """

    dissipative = True

    def __init__(
        self,
        nm: NumericModel,
        K: np.ndarray | None,
        *,
        method: str,
        basis: str | None = None,
        discretizations: Discretizations | None = None,
    ) -> None:
        if discretizations is None:
            discretizations = Discretizations(nm, method, basis)
        elif not discretizations.serves(nm, method, basis):
            raise NumericError(
                "discretizations: expected those of this model, method and basis; found "
                f"{discretizations.model.name!r} by {discretizations.method!r} "
                f"(basis {discretizations.basis!r})"
            )
        self.discretizations, self.scales, self.K = discretizations, discretizations.scales, K
        self.rate = self.scales.rate
        self.branches: Branches | None = discretizations.branches(K)
        self._cache: dict[int, tuple[np.ndarray, np.ndarray | None]] = {}

    def __call__(self, p: int, condition: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Eigenvalues and condition numbers at resolution ``p`` (cached; see the protocol)."""
        found = self._cache.get(p)
        if found is None or (condition and found[1] is None):
            prepared = self.discretizations(p)
            lam, kappa = (
                prepared.eigen_condition(self.K) if condition else (prepared.eigvals(self.K), None)
            )
            found = self._cache[p] = (rescaled(lam, self.rate), kappa)
        return found


def refine(
    solver: ResolutionSolver,
    *,
    start: int,
    stop: int,
    tol: float,
    rtol_resolved: float,
    band_stop: int | None = None,
) -> list[PairResult]:
    """Stage 1: pairs (p, ⌈1.5 p⌉) from ``start`` until one converges or p_fine >= ``stop``.

    ``solver(p)`` gives the eigenvalues and condition numbers at resolution p.  While the
    band does not reach the onset of the principal part
    (:mod:`phdesign.numeric.spectrum.branches`),
    the refinement goes on up to ``band_stop`` (default ``stop``), jumping to the
    resolution the slowest family needs.
    """
    trail: list[PairResult] = []
    p = int(start)
    band_stop = stop if band_stop is None else max(int(band_stop), stop)
    while True:
        p_fine = fine_resolution(p)
        report(f"spectrum: pair ({p}, {p_fine})")
        coarse, _ = solver(p, condition=False)
        fine, kappa = solver(p_fine)
        pair = pair_spectrum(
            fine,
            coarse,
            resolutions=(p, p_fine),
            rtol=rtol_resolved,
            scale=solver.rate,
            kappa=kappa,
            dissipative=solver.dissipative,
            band_limit=resolvable_band(solver.branches, p_fine, solver.rate),
        )
        a = with_branches(estimate_abscissa(pair, tol), pair, solver.branches)
        reason = convergence_rule(pair, a, tol)
        trail.append(PairResult(pair, a, not reason, reason))
        short = a.band_short(pair)
        settled = not short and (_degrading(trail) or _limit_settled(trail))
        if (
            not reason
            or p_fine >= (band_stop if short else stop)
            or settled
            or extinct_twice(trail)
        ):
            return trail
        p = _next_resolution(p_fine, a, solver.rate, band_stop) if short else p_fine


def resolvable_band(branches: Branches | None, resolution: int, rate: float) -> float:
    """Return the band the slowest family can reach at ``resolution`` (inf: no structure)."""
    return math.inf if branches is None else branches.resolvable_band(resolution, rate)


def _next_resolution(p_fine: int, a: Abscissa, rate: float, band_stop: int) -> int:
    """Return the next coarse resolution: the finer one, or one whose band reaches the onset.

    The finer member of the next pair should resolve the required band
    (:meth:`~phdesign.numeric.spectrum.branches.Branches.resolution_for`), within ``band_stop``.
    """
    assert a.branches is not None  # called for a short band only
    needed = a.branches.resolution_for(a.branches.required_band, rate)
    jump = math.ceil(min(needed, band_stop) / 1.5)
    return max(p_fine, jump)


def extinct_twice(trail: list[PairResult]) -> bool:
    """Tell whether the last two pairs (three resolutions) both show an empty spectrum."""
    return len(trail) >= 2 and all(r.abscissa.kind == "extinct" for r in trail[-2:])


def _limit_settled(trail: list[PairResult]) -> bool:
    """Tell whether the last two pairs extrapolate the same high-frequency limit.

    A limit approached by no mode is never "converged"; once two pairs agree on it within
    their uncertainties, finer pairs only cost time.
    """
    if len(trail) < 2 or not all(r.abscissa.kind == "limit" for r in trail[-2:]):
        return False
    (a, ua), (b, ub) = ((r.abscissa.value, r.abscissa.uncertainty) for r in trail[-2:])
    if a is None or b is None or ua is None or ub is None:
        return False
    return abs(a - b) <= ua + ub


def _degrading(trail: list[PairResult]) -> bool:
    """Tell whether refinement stopped helping an ill-conditioned abscissa.

    At an ill-conditioned coalescence the accuracy is set by round-off, not resolution
    (finer pairs have larger norms and feed more round-off into the cluster): when the
    last two pairs are both ill-conditioned at the abscissa and the finer one is not ten
    times more accurate, the refinement stops and the best pair is chosen.  Resolution-
    limited accuracy improves by far more than ten times per pair (spectral convergence);
    a well-conditioned abscissa is left alone.
    """
    if len(trail) < 2 or not all(_ill_conditioned_at(r) for r in trail[-2:]):
        return False
    before, last = (r.relative_uncertainty for r in trail[-2:])
    return bool(math.isfinite(before) and last > 0.1 * before)


def _ill_conditioned_at(result: PairResult) -> bool:
    """Tell whether the eigenvalue giving the pair's abscissa is clustered or ill-conditioned."""
    a, pair = result.abscissa, result.pair
    if a.index is None:
        return False
    kappa = pair.condition
    cond = float(kappa[a.index]) if kappa is not None else 1.0
    return bool(pair.clustered[a.index] or cond > ILL_CONDITION)


def _lost_rightmost(trail: list[PairResult], chosen: PairResult) -> PairResult | None:
    """Return an earlier pair whose resolved abscissa lies clearly right of ``chosen``'s.

    Round-off at high degree (N >= 3) can make a true eigenvalue fail the drift test at a
    fine pair although it agreed to many digits at a coarser one; the finer pair's
    abscissa is then the next eigenvalue to the left, a wrong answer.  "Clearly" means by
    far more than both pairs' own uncertainties, so that the ordinary convergence of one
    eigenvalue under refinement never triggers this.
    """
    a = chosen.abscissa
    if a.value is None or a.uncertainty is None:
        return None
    agreed = [
        r
        for r in trail
        if r.abscissa.kind == "attained"
        and r.abscissa.index is not None
        and r.pair.resolved[r.abscissa.index]
    ]
    if not agreed:
        return None
    right = max(agreed, key=lambda r: r.abscissa.value or -math.inf)
    value, uncertainty = right.abscissa.value or 0.0, right.abscissa.uncertainty or 0.0
    margin = 100.0 * (uncertainty + a.uncertainty) + 1e-9 * max(right.pair.scale, abs(value))
    return right if value > a.value + margin else None


def _superseded(result: PairResult, finer: list[PairResult]) -> bool:
    """Tell whether a finer pair attains a real part clearly right of ``result``'s abscissa.

    A wider resolved band can show modes above the coarser band whose real parts lie
    further right (real parts rising with frequency): the coarser value is then wrong,
    however well it agreed.
    """
    a = result.abscissa
    if a.attained is None or a.attained_uncertainty is None:
        return False
    top = a.attained + a.attained_uncertainty
    return any(
        r.abscissa.attained is not None
        and r.abscissa.attained_uncertainty is not None
        and r.abscissa.attained - r.abscissa.attained_uncertainty > top
        for r in finer
    )


def choose_pair(trail: list[PairResult]) -> tuple[PairResult, list[str]]:
    """Stage 2: the pair reported, and the warnings the choice itself raises."""
    last = trail[-1]
    notes: list[str] = []
    if last.converged:
        chosen = last
    else:
        valued = [r for r in trail if r.abscissa.value is not None]
        if not valued:
            return last, []
        eligible = [r for i, r in enumerate(valued) if not _superseded(r, valued[i + 1 :])]
        best = min(reversed(eligible), key=lambda r: r.relative_uncertainty)
        chosen = best
        if best is not valued[-1] and best.relative_uncertainty < valued[-1].relative_uncertainty:
            p, q = best.pair.resolutions
            notes.append(
                f"agreement degraded beyond resolutions {p}, {q} (round-off at high degree); "
                "that pair is reported"
            )
    lost = _lost_rightmost(trail, chosen)
    if lost is not None:
        lp, lq = lost.pair.resolutions
        cp, cq = chosen.pair.resolutions
        notes.append(
            f"the eigenvalue {lost.abscissa.value:.10g} agreed between resolutions {lp} and "
            f"{lq} but not at the pair first chosen ({cp}, {cq}), whose abscissa "
            f"{chosen.abscissa.value:.6g} lies to its left; an eigenvalue that once agreed "
            "is real, so that pair is reported"
        )
        chosen = lost
    return chosen, notes
