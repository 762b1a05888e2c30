r"""The ``spectrum`` job: converged spectral abscissa at every gain of a chunk.

:func:`phdesign.numeric.spectrum.spectrum` discretizes the model at each resolution of
its refinement, which is four fifths of its cost on the beam (two Galerkin assemblies of
~20 ms against ~7 ms of eigenvalues).  A chunk of a gain map shares the model, so
:class:`PairAbscissa` discretizes the first resolution pair :math:`(p, \lceil 1.5 p \rceil)`
once and, for each gain, solves

.. math::

    (J - R - B (I + K D)^{-1} K B^\top)\, v = \lambda E v, \qquad K = C_m^\top L C_m,

at both resolutions exactly as ``spectrum()`` does (eigenvalues at p, eigenvalues and
energy-norm condition numbers at 1.5 p), applies the same drift rule (eigenvalues
agreeing between the two resolutions, the ill-conditioned ones inside the resolved band
kept) and the same choice of the abscissa (the kept eigenvalue with the largest real part
less its drift).  When the abscissa agrees to ``tol`` at this first pair, the figures are
those ``spectrum()`` reports (it stops at the first pair that agrees).  Otherwise the
point goes to ``spectrum()`` itself, which refines up to ``max_resolution`` with all its
safeguards; so every stored abscissa carries the ``converged`` flag and the digits that
``spectrum()`` would give, and no number that did not converge is stored as if it had.

:func:`abscissa_evaluator` is the one function to replace by the numeric layer's own
prepared evaluator once it exists.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from phdesign.numeric.bridge import NumericModel, to_numeric
from phdesign.numeric.discretize import discretize, feedback_matrix
from phdesign.numeric.spectrum import (
    SpectrumReport,
    default_resolutions,
    eigen,
    in_band_unresolved,
    match_resolved,
    spectrum,
)

__all__ = ["PairAbscissa", "abscissa_evaluator", "figures_of_report", "prepare"]

#: Returned where no eigenvalue converges (finite-time extinction, or none resolved).
_UNBOUNDED: dict[str, Any] = {
    "spectral_abscissa": None,
    "converged": False,
    "digits": None,
    "n_resolved": 0,
    "unbounded_below": True,
    "ill_conditioned": False,
}


def figures_of_report(report: SpectrumReport) -> dict[str, Any]:
    """Return the job's figures from a :class:`~phdesign.numeric.spectrum.SpectrumReport`."""
    return {
        "spectral_abscissa": report.spectral_abscissa,
        "converged": report.converged,
        "digits": report.digits,
        "n_resolved": report.n_resolved,
        "unbounded_below": report.unbounded_below,
        "ill_conditioned": report.ill_conditioned,
    }


class PairAbscissa:
    """Spectrum figures at many gains from one resolution pair, discretized once.

    Parameters
    ----------
    nm : NumericModel
    C_m : ndarray or None
        Sensor matrix (``None``: the plant with u = 0, gains ignored).
    method : {"galerkin", "fd"}
    resolution, max_resolution : int, optional
        As for :func:`~phdesign.numeric.spectrum.spectrum`.
    tol : float, optional
        As for :func:`~phdesign.numeric.spectrum.spectrum`.

    Examples
    --------
    >>> import numpy as np
    >>> from phdesign.models import load_builtin
    >>> evaluate = PairAbscissa(to_numeric(load_builtin("wave")), np.array([[0.0, 1.0]]))
    >>> figures = evaluate((0.5,))
    >>> bool(abs(figures["spectral_abscissa"] - 0.5 * np.log(1 / 3)) < 1e-12)  # ½ ln((1-k)/(1+k))
    True
    >>> figures["converged"]
    True
    """

    def __init__(
        self,
        nm: NumericModel,
        C_m: np.ndarray | None,
        *,
        method: str = "galerkin",
        resolution: int | None = None,
        max_resolution: int | None = None,
        tol: float | None = None,
    ) -> None:
        p0, pmax = default_resolutions(nm, method)
        self.nm, self.C_m, self.method = nm, C_m, method
        self.resolution = int(resolution) if resolution is not None else p0
        self.max_resolution = (
            int(max_resolution) if max_resolution is not None else max(pmax, self.resolution)
        )
        # the defaults of spectrum(), so that a first-pair answer is the one it gives
        self.tol = tol if tol is not None else (1e-10 if method == "galerkin" else 1e-3)
        self.rtol = 1e-6 if method == "galerkin" else 1e-2
        self.fine_resolution = math.ceil(1.5 * self.resolution)
        self.coarse = discretize(nm, method, self.resolution)
        self.fine = discretize(nm, method, self.fine_resolution)

    @property
    def refinable(self) -> bool:
        """Whether ``spectrum()`` would go on to a finer pair."""
        return self.fine_resolution < self.max_resolution

    def __call__(self, gain: tuple[float, ...] | None) -> dict[str, Any]:
        """Return the figures at the gain ``diag(gain)`` (ignored without sensors)."""
        L, K = None, None
        if self.C_m is not None and gain is not None:
            L = np.diag(np.asarray(gain, dtype=float))
            K = feedback_matrix(self.C_m, L, self.nm.n_ports)
        coarse = eigen(self.coarse, K)[0]
        fine, kappa = eigen(self.fine, K, condition=True)
        assert kappa is not None  # condition=True
        tight, _ = match_resolved(fine, coarse, self.rtol)
        if tight.size == 0:
            return self._full(L) if self.refinable else dict(_UNBOUNDED)
        loose, _ = in_band_unresolved(fine, tight, kappa)
        kept = np.concatenate([tight, loose]).astype(int)
        lam = fine[kept]
        nearest = coarse[np.argmin(np.abs(coarse[None, :] - lam[:, None]), axis=1)]
        drifts = np.abs(lam.real - nearest.real)
        j = int(np.argmax(lam.real - drifts))
        alpha, d_alpha = float(lam.real[j]), float(drifts[j])
        scale = max(1.0, abs(alpha))
        converged = d_alpha <= self.tol * scale
        if not converged and self.refinable:
            return self._full(L)
        # coalescence: the rightmost kept eigenvalue, its condition number and its gap
        order = np.lexsort((np.abs(lam.imag), -np.round(lam.real, 12)))
        lead = lam[order[0]]
        others = fine[np.abs(fine - lead) > 0]
        gap = float(np.min(np.abs(others - lead))) / max(1.0, abs(lead)) if others.size else np.inf
        lead_loose = int(kept[order[0]]) in {int(i) for i in loose}
        ill = bool(kappa[kept[order[0]]] > 1e4 or gap < 1e-3 or lead_loose)
        return {
            "spectral_abscissa": alpha,
            "converged": bool(converged),
            "digits": float(-np.log10(max(d_alpha, 1e-17) / scale)),
            "n_resolved": int(tight.size),
            "unbounded_below": False,
            "ill_conditioned": ill,
        }

    def _full(self, L: np.ndarray | None) -> dict[str, Any]:
        report = spectrum(
            self.nm,
            self.C_m,
            L,
            method=self.method,
            resolution=self.resolution,
            max_resolution=self.max_resolution,
            tol=self.tol,
        )
        return figures_of_report(report)


def abscissa_evaluator(
    nm: NumericModel, C_m: np.ndarray | None, options: Mapping[str, Any]
) -> Callable[[tuple[float, ...] | None], dict[str, Any]]:
    """Prepare the spectrum figures of many gains for one model and sensor set."""
    return PairAbscissa(
        nm,
        C_m,
        method=options.get("method") or "galerkin",
        resolution=options.get("resolution"),
        max_resolution=options.get("max_resolution"),
        tol=options.get("tol"),
    )


def prepare(
    model: Any, sensors: tuple[int, ...] | None, options: Mapping[str, Any]
) -> Callable[[tuple[float, ...] | None], dict[str, Any]]:
    """Prepare the job's evaluator (see :mod:`phdesign.sweep.jobs`)."""
    nm = to_numeric(model)
    C_m = None
    if sensors is not None:
        C_m = np.zeros((len(sensors), nm.n_ports))
        C_m[np.arange(len(sensors)), np.asarray(sensors) - 1] = 1.0
    return abscissa_evaluator(nm, C_m, options)
