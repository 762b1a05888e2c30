r"""The characteristic form of a first-order (N = 1) model: the chains above the band.

:mod:`phdesign.numeric.spectrum.branches` derives it: in the energy-normalized characteristic
variables :math:`e = H^{1/2} Q w` the closed boundary gives the high-frequency
determinant :math:`\Delta_\infty(\lambda) = \det(W_a T(a) + W_b T(b)
\operatorname{diag}(e^{\lambda\tau_j - \gamma_j}))`, whose chains' real parts
:mod:`phdesign.numeric.spectrum.exponential_polynomial` computes.  Here are the numbers: the
speeds and eigenvectors at 65 Chebyshev-Lobatto points (one point for constant
coefficients), their derivative from the Chebyshev interpolant, the travel times and the
transport by Clenshaw-Curtis quadrature of the interpolant.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.polynomial import chebyshev
from scipy.linalg import expm

from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.spectrum.branches import (
    Branches,
    BranchLimit,
    Family,
    scaled_families,
    sqrtm_spd,
)
from phdesign.numeric.spectrum.exponential_polynomial import (
    MAX_COLUMNS,
    ChainLimit,
    chain_limits,
    exponential_polynomial,
    rational_basis,
)

__all__ = ["CharacteristicForm", "characteristic_form"]

_NODES = 65  # Chebyshev-Lobatto points for z-dependent coefficients
_TAIL = 1e-9  # relative size of the last Chebyshev coefficients of a resolved coefficient
_SAME_SPEED = 1e-9  # relative difference under which two speeds form one family
_SHARE = 0.1  # energy share of a component that names a family


@dataclass(frozen=True)
class CharacteristicForm:
    """The gain-independent part of the structure of a dimensionless model (N = 1).

    ``W`` of a closure gives the determinant's matrices ``W_a @ Ta`` and ``W_b @ Tb``
    (``Tb`` holds the transport along the characteristics), with exponents ``tau``.
    """

    families: tuple[Family, ...]
    family_of: tuple[int, ...]  # family index of each characteristic variable
    onset: float
    tau: np.ndarray = field(repr=False)
    Ta: np.ndarray = field(repr=False)
    Tb: np.ndarray = field(repr=False)
    wavenumber: float = 1.0
    reason: str = ""

    def at(self, W: np.ndarray, rate: float, length: float) -> Branches:
        """Return the :class:`Branches` of the closure ``W v = 0`` (dimensionless W).

        ``rate`` and ``length`` are the model's scales (:mod:`phdesign.numeric.scales`).
        """
        n = self.Ta.shape[0]
        families = scaled_families(self.families, rate, length)
        base = Branches(
            families=families,
            onset=self.onset * rate,
            wavenumber=self.wavenumber,
        )
        if self.reason:
            return replace(base, reason=self.reason)
        F = exponential_polynomial(W[:, n:] @ self.Ta, W[:, :n] @ self.Tb, self.tau)
        _, n_int = rational_basis(self.tau)
        limits = []
        for chain in chain_limits(F):
            members = sorted({self.family_of[j] for j in _variables_members(n_int, chain)})
            label = " and ".join(families[i].label for i in members)
            limits.append(_limit_in_units(chain, label, rate))
        return replace(base, limits=tuple(limits), analysed=True)


def _variables_members(n_int: np.ndarray, chain: ChainLimit) -> list[int]:
    return [j for j in range(n_int.shape[0]) if np.any(n_int[j, list(chain.variables)] != 0)]


def _limit_in_units(chain: ChainLimit, label: str, rate: float) -> BranchLimit:
    return BranchLimit(label, chain.limit * rate, chain.uncertainty * rate, chain.exact)


def _lobatto(a: float, b: float, points: int) -> np.ndarray:
    x = -np.cos(np.pi * np.arange(points) / (points - 1))
    return a + (b - a) * (x + 1) / 2


def _energy_label(Q: np.ndarray, names: tuple[str, ...], cols: list[int]) -> str:
    share = np.sum(Q[:, cols] ** 2, axis=1) / len(cols)
    picked = [names[i] for i in np.flatnonzero(share >= _SHARE)]
    return f" ({', '.join(picked)})" if picked else ""


def _families(
    speeds: np.ndarray, Q: np.ndarray, names: tuple[str, ...], length: float
) -> tuple[tuple[Family, ...], tuple[int, ...]]:
    """Group the characteristic variables by |speed| (±c travel as one family)."""
    magnitude = np.abs(speeds)
    order = np.argsort(magnitude)
    family_of = [0] * speeds.size
    families: list[Family] = []
    members: list[list[int]] = []
    for j in order:
        if members and abs(magnitude[j] - families[-1].speed) <= _SAME_SPEED * magnitude[j]:
            members[-1].append(int(j))
        else:
            members.append([int(j)])
            families.append(Family("", float(magnitude[j]), length / float(magnitude[j])))
        family_of[j] = len(families) - 1
    labelled = tuple(
        Family(_energy_label(Q, names, cols), f.speed, f.travel_time)
        for f, cols in zip(families, members, strict=True)
    )
    return labelled, tuple(family_of)


def characteristic_form(nm: NumericModel) -> CharacteristicForm:
    """Return the characteristic form of a dimensionless N = 1 model (module docstring).

    When a step of the derivation does not apply (characteristic speeds that cross or
    repeat along z, coefficients that 65 Chebyshev points do not resolve, too many
    components) the form carries the reason, and :meth:`CharacteristicForm.at` returns a
    structure without limits.
    """
    a, b = nm.interval
    length = b - a
    constant = nm.H_constant and nm.P0_constant
    z = np.array([a]) if constant else _lobatto(a, b, _NODES)
    Hs, P0s = nm.H_at(z), nm.P0_at(z)
    P1 = nm.P[1]
    roots = np.array([sqrtm_spd(H) for H in Hs])
    speeds = np.empty((z.size, nm.size))
    Q = np.empty((z.size, nm.size, nm.size))
    for i, R in enumerate(roots):
        speeds[i], Q[i] = np.linalg.eigh(R @ P1 @ R)
        if i:  # the same sign from node to node: eigenvectors that vary smoothly
            Q[i] *= np.where(np.sum(Q[i] * Q[i - 1], axis=0) < 0, -1.0, 1.0)
    families, family_of = _families(speeds[0], Q[0], nm.state_names, length)
    T = roots @ Q
    reason = _form_reason(nm, speeds, T, family_of)
    if reason:
        nan = np.full((nm.size, nm.size), np.nan)
        return CharacteristicForm(
            families, family_of, 0.0, np.ones(nm.size), nan, nan, 1.0, reason
        )
    if constant:
        G = Q[0].T @ roots[0] @ P0s[0] @ T[0]
        onset = float(np.linalg.norm(G, 2))
        tau = length / speeds[0]
        transport = _block_transport(G, speeds[0], tau, family_of)
        Ta, Tb = T[0], T[0] @ transport
    else:
        coeffs = chebyshev.chebfit(2 * (z - a) / length - 1, T.reshape(z.size, -1), _NODES - 1)
        dT = chebyshev.chebval(2 * (z - a) / length - 1, chebyshev.chebder(coeffs)).T
        dT = dT.reshape(z.size, nm.size, nm.size) * 2 / length
        G = np.einsum("kji,kjl->kil", Q, roots @ (P0s @ T + P1[None] @ dT))
        onset = float(np.max(np.linalg.norm(G, 2, axis=(1, 2))))
        tau = _integral(z, 1.0 / speeds)
        gamma = _integral(z, np.diagonal(G, axis1=1, axis2=2) / speeds)
        Ta, Tb = T[0], T[-1] @ np.diag(np.exp(-gamma))
    wavenumber = float(np.max(np.abs(tau)))
    return CharacteristicForm(families, family_of, onset, tau, Ta, Tb, wavenumber)


def _form_reason(
    nm: NumericModel, speeds: np.ndarray, T: np.ndarray, family_of: tuple[int, ...]
) -> str:
    if nm.size > MAX_COLUMNS:
        return f"{nm.size} components: the determinant's expansion is limited to {MAX_COLUMNS}"
    if speeds.shape[0] == 1:
        return ""
    ordered = np.sort(speeds, axis=1)
    gaps = np.diff(ordered, axis=1)
    scale = np.max(np.abs(ordered))
    if np.any(np.sign(ordered) != np.sign(ordered[0])):
        return "a characteristic speed changes sign along z"
    if np.any(gaps < 1e-6 * scale):
        return "characteristic speeds repeat or cross along z"
    x = -np.cos(np.pi * np.arange(T.shape[0]) / (T.shape[0] - 1))
    c = chebyshev.chebfit(x, T.reshape(T.shape[0], -1), T.shape[0] - 1)
    tail = np.max(np.abs(c[-4:]))
    if tail > _TAIL * max(float(np.max(np.abs(c))), 1e-300):
        return f"H(z) or P0(z) is not resolved by {_NODES} Chebyshev points"
    return ""


def _integral(z: np.ndarray, values: np.ndarray) -> np.ndarray:
    """∫_a^b of each column of ``values`` sampled at the Lobatto points ``z``."""
    a, b = z[0], z[-1]
    x = 2 * (z - a) / (b - a) - 1
    c = chebyshev.chebfit(x, values, z.size - 1)
    integral = chebyshev.chebint(c, lbnd=-1)
    return np.asarray(np.asarray(chebyshev.chebval(1.0, integral)) * (b - a) / 2)


def _block_transport(
    G: np.ndarray, speeds: np.ndarray, tau: np.ndarray, family_of: tuple[int, ...]
) -> np.ndarray:
    """exp(-G_II tau_I) on each group of equal signed speed (constant coefficients)."""
    n = speeds.size
    out = np.zeros((n, n))
    done: set[int] = set()
    for j in range(n):
        if j in done:
            continue
        group = [
            i
            for i in range(n)
            if family_of[i] == family_of[j] and np.sign(speeds[i]) == np.sign(speeds[j])
        ]
        done.update(group)
        out[np.ix_(group, group)] = expm(-G[np.ix_(group, group)] * tau[j])
    return out
