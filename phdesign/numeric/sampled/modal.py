r"""Modal truncation of a discretized system to the eigenvalues resolved under refinement.

Every semi-discretization carries unresolved high-frequency eigenvalues whose real parts
are artefacts (the spectrum discards them, :mod:`phdesign.numeric.spectrum.converged`); an exported
state-space model that keeps them misleads anyone who computes its poles, margins or
decay rate (a variable-density string: max Re of the error system's poles -0.0002 at
degree 30 against a resolved abscissa -0.15).

The eigenvalues of :math:`F = E^{-1}A` at resolution p are compared with those at
:math:`\lceil 1.5 p \rceil` (:func:`~phdesign.numeric.spectrum.converged.match_resolved`, the
spectrum's drift rule); kept are the resolved ones, the in-band eigenvalues that are
clustered or ill-conditioned (:func:`~phdesign.numeric.spectrum.converged.in_band_unresolved`:
near a coalescence they fail the drift test but are genuine), and the conjugates of
kept ones.  With the ordered real Schur form

.. math::

    F = Q \begin{bmatrix} T_{11} & T_{12} \\ 0 & T_{22} \end{bmatrix} Q^\top, \qquad
    T_{11} X - X T_{22} = -T_{12},

(kept eigenvalues in :math:`T_{11}`), :math:`Q_1` spans the kept invariant subspace and
:math:`W^\top = Q_1^\top - X Q_2^\top` is its biorthogonal left basis; the truncated
system is :math:`(T_{11}, W^\top E^{-1} B, C Q_1, D + D_{dc})`: the spectral projection
of the discretization onto its resolved modes, whose poles are the kept eigenvalues.

The removed modes' partial fractions
:math:`G_{rem}(s) = C (Q_1 X + Q_2)(sI - T_{22})^{-1} Q_2^\top E^{-1} B` are not small at
low frequency for boundary inputs (their residues grow with the traces of high modes: on
the beam at degree 24, dropping them changes the plant's gain at s = 0.3i by a factor
2), but their sum there is nearly static, so it is kept as a feedthrough,
:math:`D_{dc} = G_{rem}(0) = -C (Q_1 X + Q_2) T_{22}^{-1} Q_2^\top E^{-1} B` (matched DC
gain, python-control's ``modred(..., "matchdc")`` idea): exact at s = 0, with an error
:math:`O(|s| / \min |\lambda_{rem}|)` of the removed part below.  ``match_dc=False``
drops it.  :math:`\|X\|` measures how well the two parts separate (large when a kept
and a removed eigenvalue nearly coincide) and is recorded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg as sl

from phdesign.core.defaults import current
from phdesign.core.text import html_table
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.registry import discretize

__all__ = ["ModalTruncation", "resolved_mask", "truncate_to_resolved"]


@dataclass(frozen=True, repr=False)
class ModalTruncation:
    """A system truncated to its resolved modes (module docstring).

    Attributes
    ----------
    A, B, C, D : ndarray
        Real state-space matrices of the truncated system (modal coordinates).
    kept, removed : tuple of complex
        Eigenvalues kept and removed.
    resolutions : tuple of int
        The resolution of the system and that of the comparison.
    separation : float
        ‖X‖ of the Sylvester equation (1 or less: well separated).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    kept: tuple[complex, ...]
    removed: tuple[complex, ...]
    resolutions: tuple[int, int]
    separation: float

    @property
    def n_removed(self) -> int:
        """Number of removed modes."""
        return len(self.removed)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (eigenvalues as ``[re, im]``)."""
        return {
            "kept": [[z.real, z.imag] for z in self.kept],
            "removed": [[z.real, z.imag] for z in self.removed],
            "n_kept": len(self.kept),
            "n_removed": self.n_removed,
            "resolutions": list(self.resolutions),
            "separation": self.separation if math.isfinite(self.separation) else None,
        }

    def __repr__(self) -> str:
        return (
            f"ModalTruncation(kept={len(self.kept)}, removed={self.n_removed}, "
            f"resolutions={self.resolutions}, separation={self.separation:.3g})"
        )

    def __str__(self) -> str:
        top = max((z.real for z in self.kept), default=float("nan"))
        return (
            f"modal truncation: {len(self.kept)} resolved modes kept, {self.n_removed} "
            f"unresolved removed (resolutions {self.resolutions[0]} and "
            f"{self.resolutions[1]}); max Re of the kept poles {top:.6g}"
        )

    def _repr_html_(self) -> str:
        data = self.to_dict()
        keys = ("n_kept", "n_removed", "resolutions", "separation")
        return html_table((), [(k, data[k]) for k in keys])


def resolved_mask(
    lam: np.ndarray, reference: np.ndarray, rtol: float, kappa: np.ndarray | None = None
) -> np.ndarray:
    """Boolean mask of the eigenvalues ``lam`` kept by the module's rule."""
    from phdesign.numeric.spectrum.drift import in_band_unresolved, match_resolved

    mask = np.zeros(lam.size, dtype=bool)
    idx, _ = match_resolved(lam, reference, rtol)
    mask[idx] = True
    if idx.size:
        kept, _ = in_band_unresolved(lam, idx, kappa)
        mask[kept] = True
    # keep conjugate pairs whole
    for i in np.flatnonzero(mask & (np.abs(lam.imag) > 0)):
        j = int(np.argmin(np.abs(lam - np.conj(lam[i]))))
        mask[j] = True
    return mask


def truncate_to_resolved(
    d: DiscretePHS,
    K: np.ndarray | None,
    B: np.ndarray,
    C: np.ndarray,
    D: np.ndarray,
    *,
    match_dc: bool = True,
) -> ModalTruncation:
    """Truncate ``E x' = A x + B v, y = C x + D v`` (A of the loop K) to resolved modes.

    Parameters
    ----------
    d : DiscretePHS
        The discretization (its loop ``d.close(K).A`` is the system matrix).
    K : ndarray or None
        Output feedback of the loop (None: the plant).
    B, C, D : ndarray
        Input (descriptor form, before E⁻¹), output and feedthrough matrices.
    match_dc : bool
        Keep the removed modes' static gain as a feedthrough (module docstring).

    Returns
    -------
    ModalTruncation
    """
    from phdesign.numeric.spectrum.converged import eigen

    A = d.close(K).A
    finer = discretize(d.model, d.method, math.ceil(1.5 * d.resolution), basis=_basis(d))
    reference, _ = eigen(finer, K)  # the eigen stage of the spectrum, at 1.5 p
    lam, kappa = eigen(d, K, condition=True)
    rtol = current().discretization(d.method, d.model.order).resolved_rtol
    mask = resolved_mask(lam, reference, rtol, kappa)
    F = np.linalg.solve(d.E, A)
    kept_values = lam[mask]

    def select(re: float, im: float) -> bool:
        return bool(mask[int(np.argmin(np.abs(lam - complex(re, im))))])

    T, Q, k = sl.schur(F, output="real", sort=select)
    T11, T12, T22 = T[:k, :k], T[:k, k:], T[k:, k:]
    X = sl.solve_sylvester(T11, -T22, -T12) if 0 < k < F.shape[0] else np.zeros((k, 0))
    Wt = Q[:, :k].T - X @ Q[:, k:].T
    Bs = np.linalg.solve(d.E, B)
    Dr = np.asarray(D, dtype=float).copy()
    if match_dc and k < F.shape[0] and B.shape[1] and C.shape[0]:
        removed_out = C @ (Q[:, :k] @ X + Q[:, k:])
        Dr = Dr - removed_out @ np.linalg.solve(T22, Q[:, k:].T @ Bs)
    return ModalTruncation(
        A=T11.copy(),
        B=Wt @ Bs,
        C=C @ Q[:, :k],
        D=Dr,
        kept=tuple(complex(z) for z in kept_values),
        removed=tuple(complex(z) for z in lam[~mask]),
        resolutions=(d.resolution, finer.resolution),
        separation=float(np.linalg.norm(X, 2)) if X.size else 0.0,
    )


def _basis(d: DiscretePHS) -> str | None:
    """Return the basis ``d`` was built in (a method without bases records none)."""
    return d.info.get("basis")
