r"""The spectrum above the resolved band: characteristic families, their onset and limits.

A discretization resolves the eigenvalues up to some frequency, the *band*.  What lies
above it is not unknown: it is governed by the principal part of the PDE, and it can hold
the abscissa.  A Timoshenko beam's second branch starts at the thickness-shear cut-off
:math:`\sqrt{K/I_\rho}` (2.03e5 rad/s for a steel bar of 5 cm): a band below it sees the
bending modes only, however well they agree.  This module derives, for the closed loop
:math:`\tilde u = -K\tilde y` (plant feedback and observer injection included), what the
refinement needs before it may call an abscissa converged
(:mod:`phdesign.numeric.spectrum.refinement`):

* the **onset** Ω, above which the principal part governs;
* the **families** of the principal part and, for N = 1, the **limits** of the real
  parts of their root chains.

**Characteristic form (N = 1).**  With :math:`e = Hx`, the eigenproblem
:math:`\lambda H^{-1} e = P_1 e' + P_0 e` reads, in the energy-normalized characteristic
variables :math:`e = T w`, :math:`T = H^{1/2} Q` with
:math:`H^{1/2} P_1 H^{1/2} = Q C Q^\top` (C = diag(c), the characteristic speeds, Q
orthogonal; then :math:`\tfrac12 x^\top H x = \tfrac12 |w|^2`),

.. math::

    w' = C^{-1} (\lambda - \hat G)\, w, \qquad
    \hat G = Q^\top H^{1/2} \big(P_0 T + P_1 T'\big).

Off the diagonal blocks (between different speeds), :math:`\hat G` couples the families
at a rate that the growing phase difference averages out at high frequency (its effect
on a chain is of order :math:`\|\hat G\|/|\lambda|`); on the diagonal, it damps each
family along its characteristic.  So, with :math:`\tau_j = \int_a^b dz/c_j` (signed) and
:math:`\gamma_j = \int_a^b \hat G_{jj}/c_j\,dz` (a block propagator for equal speeds),
:math:`w_j(b) = e^{\lambda\tau_j - \gamma_j} w_j(a)`.  The closed boundary condition
:math:`(U + KY)v = 0`, :math:`v = (e(b); e(a))`, i.e. :math:`W_b e(b) + W_a e(a) = 0`,
gives the high-frequency characteristic determinant

.. math::

    \Delta_\infty(\lambda) = \det\big(W_a T(a) + W_b T(b)\, \operatorname{diag}
    (e^{\lambda \tau_j - \gamma_j})\big),

an exponential polynomial (:mod:`phdesign.numeric.spectrum.exponential_polynomial`): the
reflections at the ends (impedances, dampers, the observer's injection) are in its
coefficients, the travel times in its exponents.  Its zeros form chains whose real parts
are, for commensurate travel times, exactly :math:`\ln|\zeta_l| / r`; for the string with
a damper k at z = b, :math:`\ln|(Z(b) - k)/(Z(b) + k)| / (2\int dz/c)`, the impedance
:math:`Z = \sqrt{\rho T}` of the end (the WKB limit).  The zeros of the true
determinant approach these chains as :math:`|\lambda| \to \infty`.

**Onset.**  The lower-order part couples the families below a frequency of the size of
:math:`\hat G`: by Weyl's inequality the local dispersion branches
:math:`\omega_j(k)` of :math:`k H^{1/2}P_1H^{1/2} - iH^{1/2}P_0H^{1/2}` lie within
:math:`\|H^{1/2}P_0H^{1/2}\|` of :math:`k c_j`, so above that every family propagates:

.. math::

    \Omega = \max_z \big\|\hat G(z)\big\|_2

(for the Timoshenko beam exactly the cut-off :math:`\sqrt{K/I_\rho}`).  For N >= 2 the
same scale follows from the principal symbol: a term :math:`P_k \partial^k` competes with
:math:`\lambda` while :math:`|\lambda| \lesssim \|H^{1/2}P_kH^{1/2}\|^{N/(N-k)}` (in units
where the principal symbol is 1), and the coefficients' variation while
:math:`|\lambda| \lesssim \rho(P_N H)\,\|H^{-1/2}H'H^{-1/2}\|^N`.  Between Ω and about
1.5 Ω lie the transitional modes (the least damped of the steel beam at 1.02 Ω, at
1.33 Ω already within 3 1/s of the shear family's limit): the refinement requires every
eigenvalue up to :data:`ONSET_MARGIN` Ω to be resolved.

The characteristic form is :mod:`phdesign.numeric.spectrum.characteristics` (N = 1), the
principal symbol's :mod:`phdesign.numeric.spectrum.principal_symbol` (N >= 2).  All of it is
computed on the dimensionless model (:mod:`phdesign.numeric.scales`) and
returned in the model's units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "ONSET_MARGIN",
    "BranchLimit",
    "Branches",
    "Family",
    "merged_branches",
    "scaled_families",
    "sqrtm_spd",
]

#: Every eigenvalue up to this multiple of the onset must be resolved (module docstring).
ONSET_MARGIN = 1.5


@dataclass(frozen=True)
class Family:
    r"""One family of the principal part: the waves of one characteristic speed (or symbol).

    Attributes
    ----------
    label : str
        ``"speed 2.93e+03 (shear strain, momentum)"``: the speed (N = 1, largest over z)
        or the principal symbol's size (N >= 2), and the state components that hold most
        of the family's energy.
    speed : float
        |c| (N = 1) or |κ| of the principal symbol, in the model's units.
    travel_time : float
        One-way time :math:`\\int_a^b dz/|c|` (N = 1; ``nan`` otherwise).
    """

    label: str
    speed: float
    travel_time: float


@dataclass(frozen=True)
class BranchLimit:
    """The limit of the real parts of a factor's root chains, in the model's units.

    Attributes
    ----------
    label : str
        The families the factor belongs to.
    limit, uncertainty : float
    exact : bool
        Commensurate travel times: the chains' real parts tend exactly to ``limit``;
        otherwise ``limit`` is the supremum over independent phases.
    """

    label: str
    limit: float
    uncertainty: float
    exact: bool


@dataclass(frozen=True)
class Branches:
    """The high-frequency structure of one closed loop (module docstring).

    Attributes
    ----------
    families : tuple of Family
    onset : float
        Ω in the model's units: every eigenvalue up to ``ONSET_MARGIN * onset`` must be
        resolved.
    limits : tuple of BranchLimit
        One per factor of the exponential polynomial (N = 1); empty when not derived.
    analysed : bool
        The limits were derived (else ``reason`` says why).
    reason : str
    wavenumber : float
        Largest wavenumber per unit frequency over the families (dimensionless: times
        ω^(1/N) it is the number of radians a mode of frequency ω spans on the interval);
        the resolution a band needs grows with it.
    """

    families: tuple[Family, ...]
    onset: float
    limits: tuple[BranchLimit, ...] = ()
    analysed: bool = False
    reason: str = ""
    wavenumber: float = 1.0
    order: int = 1

    @property
    def limit(self) -> BranchLimit | None:
        """The factor with the largest limit (None when there is none)."""
        finite = [b for b in self.limits if math.isfinite(b.limit)]
        return max(finite, key=lambda b: b.limit) if finite else None

    def to_dict(self) -> dict[str, object]:
        """JSON-ready dictionary (non-finite limits are null)."""

        def finite(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None

        return {
            "onset": finite(self.onset),
            "required_band": finite(self.required_band),
            "families": [
                {"label": f.label, "speed": finite(f.speed), "travel_time": finite(f.travel_time)}
                for f in self.families
            ],
            "limits": [
                {
                    "label": b.label,
                    "limit": finite(b.limit),
                    "uncertainty": finite(b.uncertainty),
                    "exact": b.exact,
                }
                for b in self.limits
            ],
            "analysed": self.analysed,
            "reason": self.reason,
        }

    @property
    def required_band(self) -> float:
        """|λ| up to which every eigenvalue must be resolved (model units)."""
        return ONSET_MARGIN * self.onset

    def resolvable_band(self, resolution: int, rate: float) -> float:
        """Return the frequency up to which the slowest family can be resolved at ``resolution``.

        Inverse of :meth:`resolution_for` (without its margin): p radians of the slowest
        family's wave over the interval.  Infinite for one family: there the resolved band
        itself says how far the spectrum is known.
        """
        if len({round(f.speed, 9) for f in self.families}) <= 1:
            return math.inf
        return rate * (resolution / self.wavenumber) ** self.order

    def resolution_for(self, frequency: float, rate: float) -> int:
        """Return a resolution whose band reaches ``frequency`` (model units).

        A Galerkin degree p resolves about p radians of the slowest family's wave over the
        interval (measured on the steel Timoshenko beam: 0.97); 10 % is added.
        """
        radians = self.wavenumber * (frequency / rate) ** (1.0 / self.order)
        return math.ceil(1.1 * float(radians))


def merged_branches(parts: dict[str, Branches]) -> Branches:
    """Return the structure of a block-triangular loop: the union of its (named) blocks'.

    Its spectrum is the union of the blocks' spectra (separation), so its onset is the
    largest and its chains are all of theirs, labelled by block.
    """
    blocks = list(parts.values())
    families = {f.label: f for b in blocks for f in b.families}
    limits = tuple(
        BranchLimit(f"{name}: {lim.label}", lim.limit, lim.uncertainty, lim.exact)
        for name, b in parts.items()
        for lim in b.limits
    )
    reasons = [f"{name}: {b.reason}" for name, b in parts.items() if b.reason]
    return Branches(
        families=tuple(families.values()),
        onset=max(b.onset for b in blocks),
        limits=limits,
        analysed=all(b.analysed for b in blocks),
        reason="; ".join(reasons),
        wavenumber=max(b.wavenumber for b in blocks),
        order=blocks[0].order,
    )


def scaled_families(
    families: tuple[Family, ...], rate: float, length: float, order: int = 1
) -> tuple[Family, ...]:
    """Return the families of the dimensionless model in the model's units (c' = c/(s ℓ^N))."""
    unit = rate * length**order
    word = "speed" if order == 1 else "symbol"
    return tuple(
        Family(f"{word} {f.speed * unit:.3g}{f.label}", f.speed * unit, f.travel_time / rate)
        for f in families
    )


def sqrtm_spd(H: np.ndarray) -> np.ndarray:
    """Return the symmetric square root of a symmetric positive definite matrix."""
    w, V = np.linalg.eigh(0.5 * (H + H.T))
    return np.asarray((V * np.sqrt(w)) @ V.T)
