r"""One resolution pair prepared once: the spectral abscissa of the error system for any gain.

:class:`AbscissaEvaluator` serves everything that needs the abscissa at many gains: the
tuner (:mod:`phdesign.numeric.tuning.search`), gain maps in notebooks and the README gallery, and
the robustness figure.  For sensors :math:`C_m` and gain L the error system is the closed
loop :math:`\tilde u = -C_m^\top L C_m \tilde y` of the discretization
(``DiscretePHS.closed_matrix``, which also handles a feedthrough D ≠ 0).  The evaluator

* discretizes the dimensionless model (:mod:`phdesign.numeric.scales`) at the two
  resolutions of the pair once;
* per gain, computes eigenvalues only (no eigenvectors) at both resolutions by the shift
  and invert of :mod:`phdesign.numeric.spectrum.eigen` (the eigen stage of ``spectrum``, so both
  see the same eigenvalues), runs the drift test (:mod:`phdesign.numeric.spectrum.drift`; the
  closed loops are dissipative) and takes the abscissa of
  :mod:`phdesign.numeric.spectrum.abscissa`;
* computes condition numbers only when the rule needs them: when an unresolved eigenvalue
  inside the resolved band lies right of the resolved ones and is isolated, only its
  condition number tells a coalescence (kept) from a round-off artefact (discarded).

The value is the same abscissa that :func:`phdesign.numeric.spectrum.converged.spectrum` reports at
this pair; ``spectrum`` additionally refines the pair until the abscissa converges.

Examples
--------
>>> import math
>>> import numpy as np
>>> from phdesign.models import load_builtin
>>> from phdesign.numeric.bridge import to_numeric
>>> ev = AbscissaEvaluator(to_numeric(load_builtin("wave")), np.array([[0.0, 1.0]]), (20, 30))
>>> round(ev(np.array([[0.5]])), 10), round(0.5 * math.log(1 / 3), 10)  # the exact damper
(-0.5493061443, -0.5493061443)
>>> ev.evaluations
1
>>> ev.abscissas([np.array([[k]]) for k in (0.25, 3.0)]).round(10).tolist()  # many gains
[-0.2554128119, -0.3465735903]
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from phdesign.core.defaults import current, method_or_default
from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.registry import feedback_matrix
from phdesign.numeric.spectrum.abscissa import Abscissa, estimate_abscissa, with_branches
from phdesign.numeric.spectrum.branches import Branches
from phdesign.numeric.spectrum.drift import CLUSTER, PairSpectrum, pair_spectrum
from phdesign.numeric.spectrum.eigen import PreparedSystem, rescaled
from phdesign.numeric.spectrum.refinement import (
    Discretizations,
    fine_resolution,
    resolvable_band,
)
from phdesign.numeric.threads import limited_threads

__all__ = ["AbscissaEvaluator"]


class AbscissaEvaluator:
    """The spectral abscissa of the error system at a fixed resolution pair (module docstring).

    Parameters
    ----------
    nm : NumericModel
    C_m : ndarray (q, N n) or None
        Sensors; None evaluates the plant with u = 0 (then call with ``L=None``).
    resolutions : (int, int) or int
        The pair (p, p_fine), or p alone for (p, ⌈1.5 p⌉).
    method : str, optional
        A registered discretization; default: the table's (:mod:`phdesign.core.defaults`).
    tol, rtol_resolved : float, optional
        Abscissa tolerance and drift tolerance, relative to the problem's rate
        (:mod:`phdesign.numeric.scales`); default: the method's row of the table (Galerkin
        1e-10 and 1e-6, finite differences 1e-3 and 1e-2).

    Attributes
    ----------
    scales : ProblemScales
        Length, rate and port scales of the model.
    evaluations : int
        Number of gains evaluated so far.
    """

    @limited_threads
    def __init__(
        self,
        nm: NumericModel,
        C_m: np.ndarray | None,
        resolutions: tuple[int, int] | int,
        *,
        method: str | None = None,
        tol: float | None = None,
        rtol_resolved: float | None = None,
    ) -> None:
        if isinstance(resolutions, tuple | list):
            p, p_fine = (int(r) for r in resolutions)
        else:
            p, p_fine = int(resolutions), fine_resolution(int(resolutions))
        method = method_or_default(method)
        row = current().discretization(method, nm.order)
        self.model = nm
        self.method = method
        self.resolutions = (p, p_fine)
        self.tol = row.abscissa_tol if tol is None else float(tol)
        self.rtol_resolved = row.resolved_rtol if rtol_resolved is None else float(rtol_resolved)
        self.C_m = None if C_m is None else np.atleast_2d(np.asarray(C_m, dtype=float))
        self.discretizations = Discretizations(nm, method)
        self.scales = self.discretizations.scales
        self.systems: tuple[PreparedSystem, PreparedSystem] = (
            self.discretizations(p),
            self.discretizations(p_fine),
        )
        self.evaluations = 0

    def feedback(self, L: np.ndarray | None) -> np.ndarray | None:
        """K = C_mᵀ L C_m (checked), or None for the plant."""
        if L is None:
            if self.C_m is not None:
                raise NumericError("this evaluator has sensors C_m: give the gain L")
            return None
        if self.C_m is None:
            raise NumericError("this evaluator evaluates the plant (C_m = None): give no gain")
        return feedback_matrix(
            self.C_m, np.atleast_2d(np.asarray(L, dtype=float)), self.model.n_ports
        )

    @limited_threads
    def pair(self, L: np.ndarray | None = None, *, condition: bool | None = None) -> PairSpectrum:
        """Run the drift test at gain L (eigenvalues in the model's own units).

        ``condition=None`` computes condition numbers only when the rule needs them,
        ``True`` always (a report), ``False`` never (conservative: every in-band
        unresolved eigenvalue kept).
        """
        K = self.feedback(L)
        self.evaluations += 1
        rate = self.scales.rate
        coarse = rescaled(self.systems[0].eigvals(K), rate)
        if condition:
            fine, kappa = self.systems[1].eigen_condition(K)
            return self._pair(coarse, rescaled(fine, rate), kappa, K)
        pair = self._pair(coarse, rescaled(self.systems[1].eigvals(K), rate), None, K)
        if condition is None and _needs_condition(pair):
            fine, kappa = self.systems[1].eigen_condition(K)
            pair = self._pair(coarse, rescaled(fine, rate), kappa, K)
        return pair

    def _pair(
        self, coarse: np.ndarray, fine: np.ndarray, kappa: np.ndarray | None, K: np.ndarray | None
    ) -> PairSpectrum:
        rate = self.scales.rate
        return pair_spectrum(
            fine,
            coarse,
            resolutions=self.resolutions,
            rtol=self.rtol_resolved,
            scale=rate,
            kappa=kappa,
            dissipative=True,
            band_limit=resolvable_band(
                self.discretizations.branches(K), self.resolutions[1], rate
            ),
        )

    def branches(self, L: np.ndarray | None = None) -> Branches:
        """Return the structure above the band at gain L (:mod:`~.branches`)."""
        return self.discretizations.branches(self.feedback(L))

    def abscissa(self, L: np.ndarray | None = None) -> Abscissa:
        """Return the abscissa at gain L (:mod:`phdesign.numeric.spectrum.abscissa`, rules 1-6).

        The chains' limits above the band count (rule 6): on a steel Timoshenko beam the
        abscissa may lie on the thickness-shear branch, not among the bending modes.
        """
        pair = self.pair(L)
        return with_branches(estimate_abscissa(pair, self.tol), pair, self.branches(L))

    @limited_threads
    def abscissas(self, gains: Iterable[np.ndarray]) -> np.ndarray:
        """Return the abscissas at many gains (a gain map), inside one thread policy block."""
        return np.array([self(L) for L in gains], dtype=float)

    def __call__(self, L: np.ndarray | None = None) -> float:
        """Return the abscissa as a number (``-inf``: empty spectrum, ``nan``: unresolved)."""
        a = self.abscissa(L)
        if a.value is not None:
            return a.value
        return -math.inf if a.kind == "extinct" else math.nan


def _needs_condition(pair: PairSpectrum) -> bool:
    """Tell whether an isolated in-band unresolved eigenvalue lies right: then κ decides."""
    if not pair.clustered.any() or not pair.resolved.any():
        return False
    lam = pair.eigenvalues
    right = pair.clustered & (lam.real > np.max(lam.real[pair.resolved]))
    if not right.any():
        return False
    idx = np.flatnonzero(right)
    dist = np.abs(lam[idx][:, None] - lam[None, :])
    dist[np.arange(idx.size), idx] = np.inf
    nearest = np.min(np.where(np.isfinite(dist), dist, np.inf), axis=1)
    return bool(np.any(nearest > CLUSTER * np.maximum(pair.scale, np.abs(lam[idx]))))
