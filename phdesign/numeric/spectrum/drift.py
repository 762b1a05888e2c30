r"""The drift test: which eigenvalues of a discretization are eigenvalues of the PDE.

The discrete spectrum of any semi-discretization contains unresolved high-frequency
eigenvalues whose real parts are artefacts: on a damped wave they tend to 0 (like h² for
finite differences, like p⁻² … p⁻⁴ for Galerkin), so the largest real part over *all*
discrete eigenvalues converges to 0, not to the true abscissa.  Following Dedalus'
eigentools, the spectrum is computed at two resolutions p and ⌈1.5 p⌉ and an eigenvalue λ
of the finer one is *resolved* when its nearest neighbour μ at the coarser one satisfies

.. math::

    |\lambda - \mu| \le r_{tol} \max(s, |\lambda|), \qquad
    |\operatorname{Re}(\lambda - \mu)| \le r_{tol} \max(s, |\operatorname{Re}\lambda|),

the pairing is mutual, and the match is unambiguous: the drift is below
:data:`SEPARATION` times the local spacing :math:`\sigma` (the distance from λ to the
nearest other eigenvalue of the finer resolution), unless it is below
:math:`\sqrt{\varepsilon} \max(s, |\lambda|)`.  The relative test alone does not identify a
mode where the spectrum is dense: on a second-order grid the high modes of a beam lie
about :math:`2|\lambda|/k` apart (k the mode number), so at ``rtol = 1e-2`` an eigenvalue
that moved by several spacings between the resolutions (an artefact whose frequency moves
with the grid) meets *another* mode of the coarser grid within :math:`r_{tol}|\lambda|`
by chance (the fd beam's −14.8 ± 37846i at 237 nodes per group, 131 from a coarse
eigenvalue 1.1·10³ from its neighbours).  A chance offset is uniform over half a spacing,
so it passes the spacing test with probability 2 :data:`SEPARATION`, and a
coincidence within :math:`\sqrt{\varepsilon}|\lambda|` (a semisimple multiple eigenvalue, a
mode resolved to eight digits) has probability :math:`10^{-8}|\lambda|/\sigma`.
Eigentools' nearest drift ratio :math:`|\lambda - \mu|/\sigma` is the same measure.  Here s
is the problem's rate
(:mod:`phdesign.numeric.scales`): the test is the same whatever the units.  Its *drift*
is :math:`|\operatorname{Re}\lambda - \operatorname{Re}\mu|`, the accuracy of its real
part (the coarser eigenvalue's error, an upper bound of the finer one's under spectral
convergence).

Inside the resolved band (|λ| up to the largest resolved modulus) an unresolved eigenvalue
is either a member of a cluster (another eigenvalue within 5 % of its modulus) or
ill-conditioned (energy-norm condition number above 10): a genuine eigenvalue near a
coalescence, whose members move by O((ε κ)^(1/m)) between resolutions; it is *kept*.  An
isolated, well-conditioned in-band eigenvalue that does not reproduce is a round-off
artefact (e.g. N >= 3 at high degree) and is discarded.

The accuracy of a real part is its drift, at least the round-off floor.  For a
*dissipative* pencil (``dissipative=True``) it is also at least :math:`\operatorname{Re}
\lambda`: every exact eigenvalue has :math:`\operatorname{Re}\lambda \le 0`, so a
positive computed real part is round-off.  That holds for the closed loops ũ = −Kỹ
(sym K ⪰ 0) of a :class:`~phdesign.numeric.discretization.phs.DiscretePHS`, whose constructors
check
:math:`E \succ 0`, :math:`J = -J^\top`, :math:`R \succeq 0`, :math:`D = -D^\top`, of
a model with :math:`P_0 + P_0^\top \preceq 0` and dampers :math:`K + K^\top \succeq 0`
(:mod:`phdesign.numeric.discretization.invariants`: :math:`\operatorname{Re}\lambda\, x^*Ex =
-x^*Rx - \tilde y^* \operatorname{sym}(G) \tilde y`), and for the assembled
observer-based loop (block-triangular with two such blocks); the callers say so.  For
eigenvalues of anything else (``dissipative=False``, the default) a positive real part is
what it is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["PairSpectrum", "in_band_unresolved", "match_resolved", "pair_spectrum"]

CLUSTER = 5e-2  # relative distance within which two eigenvalues form a cluster
KAPPA_MIN = 10.0  # condition number above which an in-band eigenvalue is ill-conditioned
ROUNDOFF = 8.0 * np.finfo(float).eps  # backward error of one eigenvalue, per unit of |λ| κ
SEPARATION = 1e-2  # largest drift, per unit of the local spacing, of an unambiguous match
UNAMBIGUOUS = float(np.sqrt(np.finfo(float).eps))  # relative drift no chance match reaches


def _spacing(f: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Return the distance from each of ``f`` to its nearest other eigenvalue (inf: alone).

    Members within :data:`UNAMBIGUOUS` ``size`` of each other are copies of one multiple
    eigenvalue (two identical strings: whichever copy a coarse one pairs with, it is the
    same mode), not neighbours whose matches could be confused.
    """
    if f.size < 2:
        return np.full(f.shape, np.inf)
    gaps = np.abs(f[:, None] - f[None, :])
    gaps[gaps <= UNAMBIGUOUS * size[:, None]] = np.inf  # the diagonal, and multiple copies
    return np.asarray(np.min(gaps, axis=1))


def _drift_test(
    fine: np.ndarray, coarse: np.ndarray, rtol: float, scale: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the resolved mask over ``fine``, each one's nearest coarse eigenvalue, |λ - μ|."""
    finite_f = np.isfinite(fine)
    c = coarse[np.isfinite(coarse)]
    resolved = np.zeros(fine.shape, dtype=bool)
    nearest = np.full(fine.shape, complex(np.nan, np.nan))
    dist_out = np.full(fine.shape, np.inf)
    if not finite_f.any() or c.size == 0:
        return resolved, nearest, dist_out
    f_idx = np.flatnonzero(finite_f)
    f = fine[f_idx]
    dist = np.abs(f[:, None] - c[None, :])
    nearest_c = np.argmin(dist, axis=1)
    nearest_f = np.argmin(dist, axis=0)
    drift = dist[np.arange(f_idx.size), nearest_c]
    mutual = nearest_f[nearest_c] == np.arange(f_idx.size)
    # The real part decides the abscissa: it must agree on its own scale too, or a
    # high-frequency pair with a loose |λ| match could carry a meaningless real part.
    d_re = np.abs(f.real - c[nearest_c].real)
    # ... and the match must be unambiguous where the spectrum is dense (module docstring)
    size = np.maximum(scale, np.abs(f))
    unambiguous = (drift <= SEPARATION * _spacing(f, size)) | (drift <= UNAMBIGUOUS * size)
    resolved[f_idx] = (
        mutual
        & unambiguous
        & (drift <= rtol * size)
        & (d_re <= rtol * np.maximum(scale, np.abs(f.real)))
    )
    nearest[f_idx] = c[nearest_c]
    dist_out[f_idx] = drift
    return resolved, nearest, dist_out


def match_resolved(
    fine: np.ndarray, coarse: np.ndarray, rtol: float, scale: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Return the indices of ``fine`` eigenvalues resolved against ``coarse`` and their drifts.

    An eigenvalue is kept when its nearest coarse eigenvalue is within
    ``rtol * max(scale, |λ|)``, the real parts agree within
    ``rtol * max(scale, |Re λ|)``, and the nearest-neighbour pairing is mutual.  The
    drifts are returned relative to ``max(scale, |λ|)``.

    Examples
    --------
    >>> import numpy as np
    >>> idx, drift = match_resolved(np.array([-1 + 1j, 50j]), np.array([-1 + 1j, 20j]), 1e-8)
    >>> idx.tolist()
    [0]
    """
    fine = np.asarray(fine, dtype=complex)
    resolved, _, dist = _drift_test(fine, np.asarray(coarse, dtype=complex), rtol, scale)
    idx = np.flatnonzero(resolved)
    return idx, dist[idx] / np.maximum(scale, np.abs(fine[idx]))


def in_band_unresolved(
    fine: np.ndarray,
    tight: np.ndarray,
    kappa: np.ndarray | None = None,
    cluster: float = CLUSTER,
    kappa_min: float = KAPPA_MIN,
    scale: float = 1.0,
    band_limit: float = math.inf,
) -> tuple[np.ndarray, np.ndarray]:
    """Split the unresolved ``fine`` eigenvalues inside the resolved band.

    The band is |λ| ≤ max |λ| over the resolved ones (indices ``tight``), at most
    ``band_limit``; unresolved
    eigenvalues above it are the high-frequency artefacts of the semi-discretization.
    Inside it, an eigenvalue within ``cluster * max(scale, |λ|)`` of another one, or with
    ``kappa > kappa_min``, is kept (module docstring); without ``kappa`` only clustering
    decides.

    Returns
    -------
    kept, artefacts : ndarray of int
        Indices kept as (ill-conditioned) eigenvalues and indices discarded.
    """
    fine = np.asarray(fine)
    empty = np.array([], dtype=int)
    if tight.size == 0:
        return empty, empty
    band = min(float(np.max(np.abs(fine[tight]))), band_limit)
    outside = ~np.isfinite(fine)
    outside[tight] = True
    rest = np.flatnonzero(~outside & (np.abs(np.where(outside, 0, fine)) <= band))
    if rest.size == 0:
        return empty, empty
    others = np.abs(fine[rest][:, None] - fine[None, :])
    others[np.arange(rest.size), rest] = np.inf
    nearest = np.min(np.where(np.isfinite(others), others, np.inf), axis=1)
    clustered = nearest <= cluster * np.maximum(scale, np.abs(fine[rest]))
    keep = clustered if kappa is None else clustered | (kappa[rest] > kappa_min)
    return rest[keep], rest[~keep]


@dataclass(frozen=True)
class PairSpectrum:
    """Eigenvalues at a resolution pair, and the drift test between them.

    Attributes
    ----------
    resolutions : tuple of int
        (p, ⌈1.5 p⌉).
    eigenvalues : ndarray of complex
        Every eigenvalue at the finer resolution (``inf`` for infinite ones).
    coarse : ndarray of complex
        Every eigenvalue at the coarser resolution.
    resolved : ndarray of bool
        Mask over ``eigenvalues``: agrees with the coarser resolution.
    clustered : ndarray of bool
        Unresolved, inside the resolved band, kept (cluster or ill-conditioned).
    artefacts : ndarray of bool
        Unresolved, inside the resolved band, isolated and well conditioned: discarded.
    uncertainty : ndarray of float
        For resolved and clustered eigenvalues, the accuracy of the real part: the
        drift, at least the round-off floor 8 ε κ max(s, |λ|) and, for a dissipative
        pencil, at least Re λ (module docstring); ``nan`` elsewhere.
    condition : ndarray of float or None
        Energy-norm condition numbers (None when not computed).
    scale : float
        The problem's rate s.
    dissipative : bool
        Every exact eigenvalue has Re λ <= 0 (module docstring).
    """

    resolutions: tuple[int, int]
    eigenvalues: np.ndarray
    coarse: np.ndarray
    resolved: np.ndarray
    clustered: np.ndarray
    artefacts: np.ndarray
    uncertainty: np.ndarray
    condition: np.ndarray | None
    scale: float
    dissipative: bool = False

    @property
    def candidates(self) -> np.ndarray:
        """Mask of the eigenvalues that may carry the abscissa (resolved or clustered)."""
        return np.asarray(self.resolved | self.clustered)

    @property
    def n_resolved(self) -> int:
        """Number of resolved eigenvalues."""
        return int(np.count_nonzero(self.resolved))

    @property
    def all_max_real(self) -> float:
        """Max Re over every finite eigenvalue (the trap value, not the abscissa)."""
        lam = self.eigenvalues[np.isfinite(self.eigenvalues)]
        return float(np.max(lam.real)) if lam.size else float("nan")

    @property
    def band(self) -> float:
        """Largest modulus of a resolved eigenvalue (0 when none is resolved)."""
        lam = self.eigenvalues[self.resolved]
        return float(np.max(np.abs(lam))) if lam.size else 0.0

    @property
    def complete_band(self) -> float:
        """Smallest modulus of an eigenvalue neither resolved nor kept (inf when none).

        Every eigenvalue below it is accounted for.  The band above can be far larger: a
        fast family resolved to high frequency beside a slow one that is not (the
        Timoshenko beam's thickness-shear branch), so this, not :attr:`band`, says how
        far the spectrum is known (:mod:`phdesign.numeric.spectrum.branches`).
        """
        lam = self.eigenvalues
        gaps = np.isfinite(lam) & ~(self.resolved | self.clustered)
        return float(np.min(np.abs(lam[gaps]))) if gaps.any() else math.inf


def pair_spectrum(
    fine: np.ndarray,
    coarse: np.ndarray,
    *,
    resolutions: tuple[int, int],
    rtol: float,
    scale: float,
    kappa: np.ndarray | None = None,
    dissipative: bool = False,
    band_limit: float = math.inf,
) -> PairSpectrum:
    """Run the drift test between two resolutions (module docstring).

    ``band_limit`` caps the resolved band inside which unresolved eigenvalues may be kept:
    where a fast family is resolved far above the frequency a slow one can be at this
    resolution (:meth:`phdesign.numeric.spectrum.branches.Branches.resolvable_band`), the slow
    family's unresolved modes in between are high frequencies, not a coalescence.

    ``dissipative=True`` states that every exact eigenvalue has Re λ <= 0, so that a
    positive computed real part counts as round-off (module docstring).

    Examples
    --------
    >>> import numpy as np
    >>> fine = np.array([-1 + 1j, -1 - 1j, -0.1 + 90j])
    >>> pair = pair_spectrum(fine, np.array([-1 + 1j, -1 - 1j, -0.3 + 40j]),
    ...                      resolutions=(4, 6), rtol=1e-6, scale=1.0)
    >>> pair.resolved.tolist(), pair.n_resolved
    ([True, True, False], 2)
    """
    fine = np.asarray(fine, dtype=complex)
    coarse = np.asarray(coarse, dtype=complex)
    resolved, nearest, _ = _drift_test(fine, coarse, rtol, scale)
    # without condition numbers every in-band eigenvalue is kept: an upper bound that an
    # optimizer cannot exploit by driving eigenvalues into a cluster
    conservative = np.full(fine.shape, np.inf) if kappa is None else kappa
    kept, artefacts = in_band_unresolved(
        fine, np.flatnonzero(resolved), conservative, scale=scale, band_limit=band_limit
    )
    clustered = np.zeros(fine.shape, dtype=bool)
    clustered[kept] = True
    discarded = np.zeros(fine.shape, dtype=bool)
    discarded[artefacts] = True
    uncertainty = np.full(fine.shape, np.nan)
    both = np.flatnonzero(resolved | clustered)
    if both.size:
        drift = np.abs(fine[both].real - nearest[both].real)
        k = np.ones(both.size) if kappa is None else np.minimum(kappa[both], 1e300)
        floor = ROUNDOFF * k * np.maximum(scale, np.abs(fine[both]))
        uncertainty[both] = np.maximum(drift, floor)
        if dissipative:  # Re λ <= 0 exactly: a positive real part is round-off
            uncertainty[both] = np.maximum(uncertainty[both], fine[both].real)
    return PairSpectrum(
        resolutions=(int(resolutions[0]), int(resolutions[1])),
        eigenvalues=fine,
        coarse=coarse,
        resolved=resolved,
        clustered=clustered,
        artefacts=discarded,
        uncertainty=uncertainty,
        condition=kappa,
        scale=float(scale),
        dissipative=bool(dissipative),
    )
