r"""The spectrum above the band for models of order N >= 2: families, onset, chain limits.

The principal symbol :math:`\mu^N P_N e = \lambda H^{-1} e` gives the families: the
eigenvalues :math:`\kappa_j` of :math:`H^{1/2} P_N H^{1/2}` (skew for even N, so
:math:`\pm i|\kappa_j|`), and local wavenumbers :math:`\mu = (\lambda/\kappa_j)^{1/N}`
times the N-th roots of unity.  At :math:`\lambda = i\omega` some of them are
*propagating* (nearly imaginary: the beam's :math:`e^{\pm i\beta z}`, :math:`\beta =
\sqrt{\omega/|\kappa|}`) and the others *evanescent* (boundary layers, :math:`e^{\pm
\beta z}`).  The onset follows from the lower-order terms
(:mod:`phdesign.numeric.spectrum.branches`).

**Chain limits (constant coefficients).**  With the companion form :math:`w' = M(\lambda)
w` of the traces :math:`w = (e, e', \dots, e^{(N-1)})` and its eigenvectors
:math:`V_j` (wavenumbers :math:`\mu_j`), each wave is normalized at the end where it is
largest, so the characteristic determinant is

.. math::

    \Delta(\lambda) = \det\big[\dots,\; W_{\text{near}} V_j + W_{\text{far}} V_j
    e^{\mp \mu_j L},\; \dots\big]

and the far-end factors of evanescent waves are :math:`O(e^{-|\mu| L})`, negligible at
high frequency (Birkhoff's asymptotic determinant).  Near :math:`\lambda = i\omega` a
propagating factor is :math:`e^{\pm\mu_j(\lambda) L} \approx e^{\pm\mu_j(i\omega) L}
e^{(\lambda - i\omega)\tau_j}` with the group delay :math:`\tau_j = \pm L\,
\operatorname{Re} d\mu_j/d\lambda`, so :math:`\Delta` is locally the exponential polynomial
of :mod:`phdesign.numeric.spectrum.exponential_polynomial` in :math:`e^{\sigma\tau_j}`: its chain
limits :math:`\sigma(\omega)` are the real parts of the eigenvalues near :math:`i\omega`
(for N = 1 exactly the chains of :mod:`~phdesign.numeric.spectrum.branches`; the interior damping
enters through :math:`\operatorname{Re}\mu_j(i\omega)`, the boundary's through the
coefficients).  For N >= 2 the reflections deviate from lossless by
:math:`O(\omega^{-1/N})` while the delays shrink like :math:`\omega^{-(N-1)/N}`, so
:math:`\sigma(\omega)` tends to a finite limit (the beam with a tip damper k: :math:`-2k/
(\rho L)`; with viscous damping d: :math:`-d/(2\rho)`), computed at four frequencies
:math:`\omega_0 4^k` and extrapolated in powers of :math:`\omega^{-2/N}` (the deviation
of a reflection from lossless is odd in :math:`\omega^{-1/N}`); the spread of two fits
and the residual are its uncertainty.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.spectrum.branches import (
    Branches,
    BranchLimit,
    Family,
    scaled_families,
    sqrtm_spd,
)
from phdesign.numeric.spectrum.exponential_polynomial import chain_limits, exponential_polynomial

__all__ = ["PrincipalForm", "Waves", "chain_limit_at", "principal_form", "waves_at"]

_PROPAGATING = 0.25  # |Re μ| / |μ| below which a wave propagates at λ = iω
_FAR = 30.0  # |μ| L at the first frequency: far-end factors e^-30 of evanescent waves


@dataclass(frozen=True)
class Waves:
    """The waves of the companion form at λ = iω: what a chain limit needs but the gain."""

    S: np.ndarray  # the balancing scales of the traces
    mu: np.ndarray  # wavenumbers
    V: np.ndarray  # unit eigenvectors, column by column
    delay: np.ndarray  # dμ/dλ
    at_a: np.ndarray  # normalized at a (decaying toward b), else at b
    propagating: np.ndarray


@dataclass(frozen=True)
class PrincipalForm:
    """The gain-independent structure of a dimensionless model of order N >= 2.

    ``M0`` and ``M1`` give the companion matrix M(λ) = M0 + λ M1; ``frequency`` is the
    first frequency of the chain limits' sequence (none when the coefficients depend on z),
    ``waves`` the waves at its four frequencies (what the chain limits need but the gain).
    """

    families: tuple[Family, ...]
    onset: float
    wavenumber: float
    order: int
    M0: np.ndarray
    M1: np.ndarray
    frequency: float
    reason: str = ""
    waves: tuple[Waves, ...] = field(default=(), repr=False, compare=False)

    def at(self, W: np.ndarray, rate: float, length: float) -> Branches:
        """Return the :class:`~.branches.Branches` of the closure W v = 0."""
        families = scaled_families(self.families, rate, length, self.order)
        base = Branches(
            families=families,
            onset=self.onset * rate,
            wavenumber=self.wavenumber,
            order=self.order,
        )
        if self.reason:
            return replace(base, reason=self.reason)
        values = [chain_limit_at(waves, W) for waves in self.waves]
        limit, uncertainty = _extrapolate(np.array(values), self.order)
        label = " and ".join(f.label for f in families)
        found = BranchLimit(label, limit * rate, uncertainty * rate, False)
        return replace(base, limits=(found,), analysed=True)


def waves_at(M0: np.ndarray, M1: np.ndarray, order: int, omega: float) -> Waves:
    """Return the waves of M(λ) = M0 + λ M1 at λ = iω (gain-independent)."""
    N, size = order, M0.shape[0]
    scale = omega ** (1.0 / N)
    S = np.repeat(scale ** np.arange(N), size // N)  # e^(k) scaled by ω^(k/N): M balanced
    M = (M0 + 1j * omega * M1) * S[None, :] / S[:, None] / scale
    mu, right = np.linalg.eig(M)
    left = np.linalg.inv(right)  # rows l_j with l_j r_j = 1 (distinct wavenumbers)
    dM = M1 * S[None, :] / S[:, None] / scale
    delay = np.einsum("jk,kl,lj->j", left, dM, right) * scale  # dμ/dλ, first order
    mu = mu * scale  # back to the unbalanced wavenumbers
    V = right / np.linalg.norm(right, axis=0)
    propagating = np.abs(mu.real) < _PROPAGATING * np.abs(mu)
    return Waves(S, mu, V, delay, mu.real <= 0, propagating)


def chain_limit_at(waves: Waves, W: np.ndarray) -> float:
    """Return the largest real part of the chains near λ = iω of ``waves`` (dimensionless)."""
    S, mu, V, at_a, propagating = waves.S, waves.mu, waves.V, waves.at_a, waves.propagating
    size = V.shape[0]
    WS = W * np.concatenate([S, S])[None, :]
    Wb_V, Wa_V = WS[:, :size] @ V, WS[:, size:] @ V
    sign = np.where(at_a, 1.0, -1.0)
    if not propagating.any():
        return -math.inf
    A = np.where(at_a[None, :], Wa_V, Wb_V)
    far = np.where(at_a[None, :], Wb_V, Wa_V) * np.exp(sign * mu)[None, :]  # length 1
    B = np.where(propagating[None, :], far, 0.0)
    tau = np.where(propagating, sign * waves.delay.real, 0.0)
    tau[~propagating] = tau[propagating][0]  # B is zero there: these columns never move
    limits = chain_limits(exponential_polynomial(A, B, tau))
    finite = [c.limit for c in limits if math.isfinite(c.limit)]
    return max(finite) if finite else -math.inf


def _extrapolate(values: np.ndarray, order: int) -> tuple[float, float]:
    """Return σ∞ from σ(ω₀ 4^k), k = 0..3, in powers of ω^(-2/N), and its uncertainty.

    ``-inf`` when the chains' damping grows without bound (every σ finite, falling by more
    than a factor 2 per step).  The uncertainty is the difference between the fit over
    the four and the one through the last three, and three times the fit's residual.
    """
    if not np.all(np.isfinite(values)):
        return (-math.inf, 0.0) if np.all(values == -np.inf) else (float(np.max(values)), math.inf)
    if np.all(np.diff(values) < 0) and values[-1] < 2 * values[-2] < 0:
        return -math.inf, 0.0
    # the reflections' deviation from lossless is odd in 1/beta (the beam's tip damper:
    # ln|a/b| = -2k/beta + O(beta^-3)) and the delays are 1/(2 beta): sigma(omega) is a series
    # in omega^(-2/N) (measured: the beam's error falls 4x, or 16x with viscous damping,
    # per 4x in omega)
    y = 4.0 ** (-2.0 * np.arange(4) / order)
    fit = np.polyfit(y, values, 2)
    four = fit[-1]
    three = np.polyfit(y[1:], values[1:], 2)[-1]  # the same through the last three
    noise = float(np.max(np.abs(np.polyval(fit, y) - values)))  # round-off of the values
    spread = abs(four - three) + 3.0 * noise + 1e-12 * max(1.0, abs(four))
    return float(min(four, 0.0)), float(spread)


def principal_form(nm: NumericModel) -> PrincipalForm:
    r"""Return the structure of a dimensionless model of order N >= 2.

    The families are the magnitudes :math:`|\kappa_j|` of the eigenvalues of
    :math:`H^{1/2} P_N H^{1/2}` (at z = a); the onset is the largest of
    :math:`\|H^{1/2}P_kH^{1/2}\|^{N/(N-k)}` (k < N) and
    :math:`\rho(P_N H)\,\|H^{-1/2}H'H^{-1/2}\|^N` over z
    (:mod:`phdesign.numeric.spectrum.branches`).
    """
    a, b = nm.interval
    N = nm.order
    constant = nm.H_constant and nm.P0_constant
    z = np.linspace(a, b, 2 if constant else 17)
    Hs = nm.H_at(z)
    roots = np.array([sqrtm_spd(H) for H in Hs])
    P0s = nm.P0_at(z)
    onset = 0.0
    for k in range(N):
        Pk = P0s if k == 0 else np.broadcast_to(nm.P[k], Hs.shape)
        size = np.max(np.linalg.norm(roots @ Pk @ roots, 2, axis=(1, 2)))
        onset = max(onset, float(size) ** (N / (N - k)))
    magnitude = np.abs(np.linalg.eigvals(roots[0] @ nm.P[N] @ roots[0]))
    if not nm.H_constant:
        dH = np.gradient(Hs, z, axis=0)
        inv = np.array([np.linalg.inv(R) for R in roots])
        variation = np.max(np.linalg.norm(inv @ dH @ inv, 2, axis=(1, 2)))
        onset = max(onset, float(np.max(magnitude)) * float(variation) ** N)
    groups = sorted({round(float(m), 9) for m in magnitude})
    families = tuple(Family("", m, math.nan) for m in groups)
    wavenumber = float(max(m ** (-1.0 / N) for m in groups))
    M0, M1 = _companion(nm)
    frequency = max(_FAR**N * max(groups), 100.0 * onset)
    reason = "" if constant else "the chains' limits are derived for constant coefficients"
    waves = () if reason else tuple(waves_at(M0, M1, N, frequency * 4.0**k) for k in range(4))
    return PrincipalForm(families, onset, wavenumber, N, M0, M1, frequency, reason, waves)


def _companion(nm: NumericModel) -> tuple[np.ndarray, np.ndarray]:
    """M(λ) = M0 + λ M1 of w' = M w, w = (e, ..., e^(N-1)), at z = a (constant coefficients)."""
    N, n = nm.order, nm.size
    PN_inv = np.linalg.inv(nm.P[N])
    Hinv = np.linalg.inv(nm.H_at(nm.interval[0])[0])
    P = [nm.P0_at(nm.interval[0])[0], *nm.P[1:]]
    M0 = np.zeros((N * n, N * n))
    M1 = np.zeros((N * n, N * n))
    for k in range(N - 1):
        M0[k * n : (k + 1) * n, (k + 1) * n : (k + 2) * n] = np.eye(n)
    for k in range(N):
        M0[(N - 1) * n :, k * n : (k + 1) * n] = -PN_inv @ P[k]
    M1[(N - 1) * n :, :n] = PN_inv @ Hinv
    return M0, M1
