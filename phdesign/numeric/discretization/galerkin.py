r"""Legendre-Galerkin discretization with power-conjugate weak boundary inputs.

Take the efforts in a polynomial basis, :math:`e(z) \approx \Psi(z) \hat e` with
:math:`\Psi = I_n \otimes (\psi_0, \dots, \psi_p)` and :math:`\psi_j` the Legendre
polynomials orthonormal on [a, b].  Testing the PDE :math:`\partial_t x = \sum_k P_k
\partial_z^k e`, :math:`x = H^{-1} e`, with the same basis gives

.. math::

    M \dot{\hat e} = A \hat e, \quad
    M = \int_a^b \Psi^\top H^{-1} \Psi \, dz, \quad
    A = \sum_{k=0}^N \int_a^b \Psi^\top P_k \partial_z^k \Psi \, dz .

Integration by parts (the energy identity of the BC-PHS, applied to the polynomial
e = Ψê, for which it is exact) gives, with T the matrix mapping ê to the trace vector v,

.. math::

    A + A^\top = T^\top (U^\top Y + Y^\top U) T + 2 \int \Psi^\top \operatorname{sym}(P_0) \Psi,

so :math:`A - T^\top Y^\top U T = J - R` with :math:`J = -J^\top` and
:math:`R = -\int \Psi^\top \operatorname{sym}(P_0) \Psi \succeq 0`.  Replacing the
state's own input :math:`U T \hat e` by the imposed input u,

.. math::

    M \dot{\hat e} = (J - R) \hat e + B u, \quad y = B^\top \hat e, \quad B = (Y T)^\top,

a port-Hamiltonian system whose energy balance
:math:`\tfrac{d}{dt} \tfrac12 \hat e^\top M \hat e = -\hat e^\top R \hat e + u^\top y` is
exact.  The scheme is consistent: the exact solution satisfies it with u = UTe.  The
boundary conditions are imposed weakly, through the power pairing, so that no basis
function has to satisfy them and every admissible (U, Y) is covered by the same code.

Why this method: exponential convergence of the resolved eigenvalues in the degree p
(damped wave: abscissa to 1e-13 at p ≈ 40), no staggering or causality restriction,
H(z) enters only through the mass matrix.

The basis.  ``basis="legendre"`` is the orthonormal Legendre basis, ``basis="scaled"``
the same polynomials divided by their largest boundary trace; the two discretizations
are congruent by a diagonal matrix.  :mod:`phdesign.numeric.discretization.legendre`
gives the measurements behind the table's choice (:mod:`phdesign.core.defaults`): the
scaled basis for N >= 3, where the noise figures' QZ keeps 15 digits in it and loses
them in the Legendre basis, and the Legendre basis for N <= 2.

Spurious modes.  When a component has all its boundary traces among the inputs, the
weak form cannot see its top modes; they form an unobservable subspace whose
eigenvalues no feedback moves (a spurious eigenvalue 0 for the string with velocity
inputs at both ends, and also for the built-in airy model at odd degree).
:func:`galerkin` removes it by default: the method then works on the E-orthogonal
complement of that subspace, still port-Hamiltonian, with an unchanged input-output
map and the spectrum of the full discretization less the artefacts
(:mod:`phdesign.numeric.discretization.spurious`); ``info["spurious"]`` says how many
modes went and why.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Any

import numpy as np
from numpy.polynomial import legendre as leg

from phdesign.core.defaults import current
from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import DisplacementSpec, NumericModel, trace_index
from phdesign.numeric.discretization.base import Method
from phdesign.numeric.discretization.distributed import galerkin_p0
from phdesign.numeric.discretization.legendre import (
    basis_at_gauss,
    gauss_rule,
    legendre_basis,
    trace_scaling,
)
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.spurious import (
    SpuriousModes,
    e_orthogonal_complement,
    spurious_modes,
)

__all__ = ["Galerkin", "galerkin", "resolve_basis"]


class Galerkin(Method, name="galerkin"):
    """The registered method ``"galerkin"``: :func:`galerkin` at degree ``resolution``."""

    @classmethod
    def build(cls, nm: NumericModel, resolution: int, basis: str | None) -> DiscretePHS:
        """Return :func:`galerkin` of ``nm`` at degree ``resolution`` in ``basis``."""
        return galerkin(nm, resolution, basis)


def resolve_basis(basis: str | None, order: int) -> str:
    """Return the basis :func:`galerkin` uses for a model of order ``order``.

    ``None`` means the table's choice (:mod:`phdesign.core.defaults`).

    Examples
    --------
    >>> resolve_basis(None, 3), resolve_basis(None, 2), resolve_basis("scaled", 1)
    ('scaled', 'legendre', 'scaled')
    """
    if basis is not None:
        return basis
    chosen = current().discretization(Galerkin.name, order).basis
    assert chosen is not None  # every Galerkin row names its basis
    return chosen


def _trace_map(nm: NumericModel, p: int) -> np.ndarray:
    """T over orthonormal-Legendre coordinates: row trace_index(i, k, side) = e_i^T phi^(k)."""
    N, n, nb = nm.order, nm.size, p + 1
    T = np.zeros((2 * N * n, n * nb))
    for side, zs in (("b", nm.interval[1]), ("a", nm.interval[0])):
        for k in range(N):
            row = legendre_basis(np.array([zs]), p, k, nm.interval)[0]
            for i in range(n):
                T[trace_index(i + 1, k, side, N, n), i * nb : (i + 1) * nb] = row
    return T


def _mass(nm: NumericModel, p: int, s: np.ndarray) -> np.ndarray:
    """M = ∫ Ψᵀ H⁻¹ Ψ: exact for constant H, Gauss rule with extra points otherwise."""
    n, nb, iv = nm.size, p + 1, nm.interval
    if nm.H_constant:
        Hinv = np.linalg.inv(nm.H_at(np.array([iv[0]]))[0])
        return np.kron(Hinv, np.diag(s * s))
    points = 2 * nb + 20
    zm, wm = gauss_rule(points, iv)
    Vm = basis_at_gauss(p, 0, points, iv) * s
    Hinv = np.linalg.inv(nm.H_at(zm))  # (q, n, n)
    M = np.empty((n * nb, n * nb))
    for i in range(n):
        for k in range(i, n):
            block = (Vm * (wm * Hinv[:, i, k])[:, None]).T @ Vm
            M[i * nb : (i + 1) * nb, k * nb : (k + 1) * nb] = block
            M[k * nb : (k + 1) * nb, i * nb : (i + 1) * nb] = block.T
    return 0.5 * (M + M.T)


def galerkin(
    nm: NumericModel, degree: int, basis: str | None = None, *, remove_spurious: bool = True
) -> DiscretePHS:
    """Discretize ``nm`` with polynomials of degree ``degree`` in every effort.

    Parameters
    ----------
    nm : NumericModel
    degree : int
        Polynomial degree p >= N + 1; the system has n (p + 1) states, less the spurious
        modes removed.
    basis : {"scaled", "legendre"}, optional
        ``"scaled"``: the orthonormal Legendre polynomials divided by their largest
        boundary trace (module docstring); ``"legendre"``: unscaled (E = I for H = I).
        Default: the table's (:mod:`phdesign.core.defaults`).  The two discrete systems
        are congruent by a diagonal matrix: same eigenvalues in exact arithmetic, not in
        floating point (:mod:`phdesign.numeric.discretization.legendre`).
    remove_spurious : bool
        Work on the E-orthogonal complement of the unobservable subspace created by the
        weakly imposed inputs (:mod:`phdesign.numeric.discretization.spurious`); default
        True.  False keeps the full polynomial space (for comparisons).

    Returns
    -------
    DiscretePHS
        ``E = M``, ``J``, ``R``, ``B = (YT)^T``, ``D = 0`` as in the module docstring;
        ``info["spurious"]`` holds the removed
        :class:`~phdesign.numeric.discretization.spurious.SpuriousModes`
        ``info["trial_map"]`` the matrix W from the kept coordinates to the full
        polynomial coordinates (None when nothing was removed) and
        ``info["coordinates"]`` the (component, degree) behind each kept coordinate.

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> d = galerkin(to_numeric(load_builtin("airy")), 9)  # odd degree: one artefact
    >>> d.dim, d.info["spurious"].count
    (9, 1)
    """
    N, n, p = nm.order, nm.size, int(degree)
    if p < N + 1:
        raise NumericError(f"Galerkin degree must be at least N + 1 = {N + 1}; found {p}")
    basis = resolve_basis(basis, nm.order)
    bases = current().entry(Galerkin.name).bases
    if basis not in bases:
        raise NumericError(f"unknown Galerkin basis {basis!r}; expected one of {bases}")
    nb = p + 1
    s = trace_scaling(p, N, nm.interval) if basis == "scaled" else np.ones(nb)
    full, zeroth_order, T_legendre, defect = _weak_form(nm, p, s)
    spurious = (
        spurious_modes(nm, p, T_legendre, zeroth_order, _frozen(nm, zeroth_order))
        if remove_spurious
        else SpuriousModes(np.zeros((n * nb, 0)))
    )
    W: np.ndarray | None = None
    keep, kept = np.arange(n * nb), full
    if spurious.count:
        W, keep, selection = e_orthogonal_complement(
            spurious.basis / np.tile(s, n)[:, None], full.M
        )
        kept = full.on_complement(W, keep, selection)
    info: dict[str, Any] = {
        "T": kept.T,
        "A": kept.A,
        "basis": basis,
        "weak_form_symmetry_defect": defect,
        "spurious": spurious,
        "spurious_removed": spurious.count,
        "trial_map": W,
        "coordinates": tuple((int(j) // nb, int(j) % nb) for j in keep),
    }
    space = _TrialSpace(nm, p, s, W, kept.M)
    return DiscretePHS(
        model=nm,
        method=Galerkin.name,
        resolution=p,
        E=kept.M,
        J=kept.J,
        R=kept.R,
        B=kept.B,
        D=np.zeros((N * n, N * n)),
        effort_basis=space.effort_basis,
        project=space.project,
        displacement_basis=None if nm.displacement is None else space.displacement,
        field_basis=space.field,
        info=info,
    )


@dataclass(frozen=True)
class _Matrices:
    """The matrices of one trial space: E = M, J, R, B, and the weak form A with its T."""

    M: np.ndarray
    J: np.ndarray
    R: np.ndarray
    A: np.ndarray
    B: np.ndarray
    T: np.ndarray

    def on_complement(self, W: np.ndarray, keep: np.ndarray, selection: bool) -> _Matrices:
        """Restrict to the trial space Ψ W (exact sub-blocks when W selects coordinates)."""
        if selection:
            ix = np.ix_(keep, keep)
            return _Matrices(
                self.M[ix], self.J[ix], self.R[ix], self.A[ix], self.B[keep], self.T[:, keep]
            )
        M = 0.5 * (W.T @ self.M @ W + (W.T @ self.M @ W).T)
        J = W.T @ self.J @ W
        R = W.T @ self.R @ W
        return _Matrices(
            M, 0.5 * (J - J.T), 0.5 * (R + R.T), W.T @ self.A @ W, W.T @ self.B, self.T @ W
        )


def _stiffness(
    nm: NumericModel, p: int, s: np.ndarray
) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    r"""Return the stiffness :math:`A = \sum_k \int \Psi^\top P_k \partial^k \Psi`.

    Also its P0(z) part, scaled and in Legendre coordinates (both None for a constant P0,
    which the Kronecker products hold).
    """
    n, nb, iv = nm.size, p + 1, nm.interval
    # Exact Gauss rule for the polynomial products psi_j psi_l^(k) (degree <= 2p).
    wq = gauss_rule(nb + 1, iv)[1]
    V0 = basis_at_gauss(p, 0, nb + 1, iv) * s
    A = np.zeros((n * nb, n * nb))
    for k, Pk in enumerate(nm.P):
        if k == 0 and not nm.P0_constant:  # P0(z): by quadrature below
            continue
        if np.any(Pk):
            A += np.kron(Pk, (V0 * wq[:, None]).T @ (basis_at_gauss(p, k, nb + 1, iv) * s))
    if nm.P0_constant:
        return A, None, None
    # P0(z): its weak form in Legendre coordinates (numeric.distributed), then scaled
    points = 2 * nb + 20
    zd, wd = gauss_rule(points, iv)
    zeroth_order = galerkin_p0(nm, zd, wd, basis_at_gauss(p, 0, points, iv))
    scale_all = np.tile(s, n)
    A0 = zeroth_order * np.outer(scale_all, scale_all)
    A += A0
    return A, A0, zeroth_order


def _weak_form(
    nm: NumericModel, p: int, s: np.ndarray
) -> tuple[_Matrices, np.ndarray | None, np.ndarray, float]:
    """Return the full polynomial space's matrices (module docstring's J - R split).

    Also the P0(z) part in Legendre coordinates (None for a constant P0), the trace map
    over Legendre coordinates and the relative defect of the weak form's symmetry,
    sym(A - Tᵀ Yᵀ U T) + R, which integration by parts makes round-off.
    """
    A, A0, zeroth_order = _stiffness(nm, p, s)
    M = _mass(nm, p, s)
    T_legendre = _trace_map(nm, p)
    T = T_legendre * np.tile(s, nm.size)
    UT, YT = nm.U @ T, nm.Y @ T
    JR = A - YT.T @ UT
    J = 0.5 * (JR - JR.T)
    if A0 is None:
        sym0 = 0.5 * (nm.P[0] + nm.P[0].T)
        R = -np.kron(sym0, np.diag(s * s))
    else:
        R = -0.5 * (A0 + A0.T)
    defect = float(np.max(np.abs(0.5 * (JR + JR.T) + R)) / max(np.max(np.abs(A)), 1.0))
    return _Matrices(M, J, R, A, YT.T.copy(), T), zeroth_order, T_legendre, defect


def _frozen(nm: NumericModel, zeroth_order: np.ndarray | None) -> tuple[Any, Any] | None:
    """H and P0 at the midpoint, the candidates' model, when P0 depends on z (else None)."""
    if zeroth_order is None:
        return None
    middle = np.array([0.5 * (nm.interval[0] + nm.interval[1])])
    return nm.H_at(middle)[0], nm.P0_at(middle)[0]


class _TrialSpace:
    """Evaluation, projection and displacement of the trial space Ψ W (built lazily)."""

    def __init__(
        self,
        nm: NumericModel,
        p: int,
        s: np.ndarray,
        W: np.ndarray | None,
        mass: np.ndarray,
    ) -> None:
        self.nm, self.p, self.s, self.W, self.mass = nm, p, s, W, mass

    def _full_to_kept(self, coefficients: np.ndarray) -> np.ndarray:
        return coefficients if self.W is None else coefficients @ self.W

    def effort_basis(self, z: np.ndarray) -> np.ndarray:
        """``(m, n, dim)`` values: e(z) = effort_basis(z) @ ê."""
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        n, nb = self.nm.size, self.p + 1
        V = legendre_basis(zz, self.p, 0, self.nm.interval) * self.s
        out = np.zeros((zz.size, n, n * nb))
        for i in range(n):
            out[:, i, i * nb : (i + 1) * nb] = V
        return self._full_to_kept(out)

    @cached_property
    def _projection_rule(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        points = 2 * (self.p + 1) + 40
        zp, wp = gauss_rule(points, self.nm.interval)
        Vp = basis_at_gauss(self.p, 0, points, self.nm.interval) * self.s
        return zp, wp, Vp

    def project(self, x0: Any) -> np.ndarray:
        """L² projection in the energy pairing: M ê = Wᵀ ∫ Ψᵀ x0 dz."""
        zp, wp, Vp = self._projection_rule
        X = np.asarray(x0(zp), dtype=float).reshape(zp.size, self.nm.size)
        rhs = ((Vp * wp[:, None]).T @ X).T.reshape(-1)
        if self.W is not None:
            rhs = self.W.T @ rhs
        return np.linalg.solve(self.mass, rhs)

    @cached_property
    def _displacement(self) -> Any:
        assert self.nm.displacement is not None
        return self.field(self.nm.displacement)

    def displacement(self, z: np.ndarray) -> np.ndarray:
        """``(m, dim)`` values: w(z) = displacement(z) @ ê (built on first use)."""
        return np.asarray(self._displacement(z))

    def field(self, spec: DisplacementSpec) -> Any:
        """``basis(z) -> (m, dim)`` of a field (:func:`_field_basis`)."""
        return _field_basis(spec, self.nm, self.effort_basis, self.nm.interval)


def _field_basis(spec: DisplacementSpec, nm: NumericModel, effort_basis, iv):
    r"""f(z) = Σ_j c_j I_s^{k_j} x_{i_j}, x = H⁻¹e, as a linear map of ê.

    Each x_i is sampled at Gauss points, expanded in Legendre polynomials by the (exact
    for polynomials) discrete transform, and integrated exactly in that expansion from the
    end s: the rows that do it at given points depend on the interval alone
    (:func:`_integration_rows`).
    """
    zq, _ = gauss_rule(DISPLACEMENT_POINTS, iv)
    Eq = effort_basis(zq)  # (nq, n, dim)
    Hinv = np.linalg.inv(nm.H_at(zq))
    X = {i: np.einsum("qk,qkd->qd", Hinv[:, i - 1, :], Eq) for i, _, _ in spec.terms}

    def basis(z: np.ndarray) -> np.ndarray:
        points = tuple(float(v) for v in np.atleast_1d(np.asarray(z, dtype=float)))
        return np.asarray(
            sum(
                c * (_integration_rows(points, iv, k, spec.start) @ X[i]) for i, k, c in spec.terms
            )
        )

    return basis


#: Gauss points of the displacement's Legendre transform (exact for degree < 160).
DISPLACEMENT_POINTS = 160


@lru_cache(maxsize=256)
def _integration_rows(
    points: tuple[float, ...], iv: tuple[float, float], integrations: int, start: str = "a"
) -> np.ndarray:
    """Rows taking x_c at the Gauss points to its repeated integral at ``points`` (cached).

    The discrete Legendre transform, integrated ``integrations`` times from the end
    ``start`` (value zero there) and read at the points: it depends on the interval only,
    so every discretization and every run shares it.
    """
    nq = DISPLACEMENT_POINTS
    zq, wq = gauss_rule(nq, iv)
    t = (2 * zq - iv[0] - iv[1]) / (iv[1] - iv[0])
    norms = 2.0 / (2.0 * np.arange(nq) + 1.0)
    coef = (leg.legvander(t, nq - 1) * (wq * 2.0 / (iv[1] - iv[0]))[:, None]).T / norms[:, None]
    half = 0.5 * (iv[1] - iv[0])
    for _ in range(integrations):
        coef = leg.legint(coef, lbnd=-1 if start == "a" else 1, axis=0) * half
    tt = (2 * np.array(points) - iv[0] - iv[1]) / (iv[1] - iv[0])
    rows = leg.legvander(tt, coef.shape[0] - 1) @ coef
    rows.setflags(write=False)
    return rows
