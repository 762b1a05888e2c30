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

Conditioning and the choice of basis.  The eigenvalues of the pencil (closed matrix, E)
do not depend on the basis, but their computed accuracy does: the QZ algorithm of
:func:`scipy.linalg.eigvals` has a backward error of order :math:`\epsilon \|A\|` and
:math:`\epsilon \|E\|`.  In the orthonormal Legendre basis E = I (for H = I) but the
trace rows of T grow like :math:`\psi_j^{(k)}(b) \sim j^{2k + 1/2}`, so an output
feedback on the (N−1)-th derivative traces puts entries of order :math:`p^{4N-3}` into
the closed matrix (airy, N = 3, all sensors, L = I, p = 40: :math:`\|A\|_2 = 7.5
\cdot 10^{14}`, cond(A) = 3.8e14, cond(E) = 1; the abscissa is then wrong by 5e-3 at
p = 40 and already by 8.5e-10 at p = 12, while in exact arithmetic (mpmath) the
discrete abscissa equals the exact root to 5e-15 for every p >= 8).

``basis="scaled"`` divides each :math:`\psi_j` by its largest boundary trace,
:math:`s_j = 1 / \max_{k<N} |\psi_j^{(k)}(b)|` (:func:`trace_scaling`): every column of
T has max-norm 1 and the same airy case has :math:`\|A\|_2 = 40.5`, cond(A) = 5.2e9,
and cond(E) = 1.5e14 for a *diagonal* E = diag(s²) (constant H; E = S M S, graded,
otherwise); the QZ error of the abscissa drops to 3e-15 … 1e-14 at every p from 8 to
140, and the spectrum converges to 1e-10 at its first pair (8, 12).
The change is the congruence ê = S ĉ, S = diag(s): E, J, R, B become S E S, S J S,
S R S, S B, so E ≻ 0, J = −Jᵀ, R ⪰ 0 and the exact energy balance are untouched, and
the matrices are assembled directly in the scaled basis (no product with S).  A
diagonal E costs nothing in the solves :math:`E^{-1} f`, which stay componentwise
accurate however large cond(E) is (the energy balance is checked to 1e-12).

Rejected alternatives (measured on the same airy case): an orthonormalization in the
E-inner product, or any orthogonal change of basis, leaves :math:`\|A\|_2` and the
QZ error unchanged (a split into E-orthonormal bubbles and their 6-dimensional
complement: error 2.6e-4 at p = 40); the boundary-adapted Babuška–Shen basis (2N low
Legendre polynomials plus bubbles :math:`(1-t^2)^N P_j^{(N,N)}` with vanishing traces)
brings the error to 1e-12…1.5e-11 but its non-diagonal E has cond ~ p^(4N−3) (1e12 at
p = 40) and a solve with it loses the energy balance to 1e-7 at p = 24; imposing the
boundary conditions strongly creates spurious real eigenvalues drifting to 0.  Powers
:math:`s_j = (1+j)^{-\alpha}` confirm the exponent: α = 1, 2, 3, 4, 4.5 give errors
1.8e-7, 5.8e-12, 1.3e-12, 1e-14, 6e-15 at p = 40; :func:`trace_scaling` is α = 2N − 3/2
with the exact constants.

The basis used when none is given comes from the registry
:data:`phdesign.numeric.discretization.defaults.GALERKIN`: the trace-scaled basis for N >= 3, where
it
turns 9 digits into 15 on the airy error abscissa, and the plain Legendre basis for
N <= 2, where both agree to round-off and the Legendre basis keeps E well conditioned for
any H(z).

Spurious modes.  When a component has all its boundary traces among the inputs, the
weak form cannot see its top modes; they form an unobservable subspace whose
eigenvalues no feedback moves (a spurious eigenvalue 0 for the string with velocity
inputs at both ends, and also for the built-in airy model at odd degree).
:func:`galerkin` removes it by default: the method then works on the E-orthogonal
complement of that subspace, still port-Hamiltonian, with an unchanged input-output
map and the spectrum of the full discretization less the artefacts
(:mod:`phdesign.numeric.discretization.spurious`); ``info["spurious"]`` says how many modes went
and
why.
"""

from __future__ import annotations

from functools import cached_property, lru_cache
from typing import Any

import numpy as np
from numpy.polynomial import legendre as leg

from phdesign.core.defaults import current
from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel, trace_index
from phdesign.numeric.discretization.base import Method
from phdesign.numeric.discretization.distributed import galerkin_p0
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.spurious import (
    SpuriousModes,
    e_orthogonal_complement,
    spurious_modes,
)

__all__ = [
    "Galerkin",
    "galerkin",
    "gauss_rule",
    "legendre_basis",
    "resolve_basis",
    "trace_scaling",
]


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


@lru_cache(maxsize=64)
def _derivative_coefficients(p: int, k: int) -> np.ndarray:
    """Legendre coefficients (rows) of the k-th t-derivative of P_0..P_p (columns)."""
    C = np.eye(p + 1)
    if k == 0:
        return C
    Dk = leg.legder(C, k, axis=0)
    out = np.zeros((p + 1, p + 1))
    out[: Dk.shape[0], :] = Dk
    out.setflags(write=False)
    return out


def legendre_basis(z: np.ndarray, p: int, k: int, interval: tuple[float, float]) -> np.ndarray:
    r"""Values of the k-th z-derivative of the orthonormal Legendre basis on ``interval``.

    Returns an array of shape ``(len(z), p + 1)``; column j is
    :math:`\psi_j^{(k)}(z)`, :math:`\psi_j(z) = \sqrt{(2j+1)/(b-a)}\, P_j(t)`,
    :math:`t = (2z - a - b)/(b - a)`.

    Examples
    --------
    >>> import numpy as np
    >>> V = legendre_basis(np.array([0.0, 1.0]), 2, 0, (0.0, 1.0))
    >>> np.allclose(V[:, 0], 1.0)
    True
    """
    a, b = interval
    t = (2.0 * np.asarray(z, dtype=float) - a - b) / (b - a)
    V = leg.legvander(t, p) @ _derivative_coefficients(p, k)
    scale = (2.0 / (b - a)) ** k * np.sqrt((2.0 * np.arange(p + 1) + 1.0) / (b - a))
    return V * scale


def trace_scaling(p: int, order: int, interval: tuple[float, float]) -> np.ndarray:
    r"""Scale factors :math:`s_j = 1 / \max_{k<N} |\psi_j^{(k)}(b)|` of the scaled basis.

    Every basis function :math:`s_j \psi_j` then has its largest boundary trace (of order
    < N, at either end: the magnitudes agree by parity) equal to 1, so the columns of the
    trace map T are equilibrated.  For large j, :math:`s_j \sim j^{-(2N - 3/2)}`.

    Examples
    --------
    >>> trace_scaling(3, 1, (0.0, 1.0)) ** -2  # psi_j(1)^2 = 2j + 1 on [0, 1]
    array([1., 3., 5., 7.])
    """
    b = np.array([float(interval[1])])
    peak = np.max([np.abs(legendre_basis(b, p, k, interval)[0]) for k in range(order)], axis=0)
    return 1.0 / peak


@lru_cache(maxsize=64)
def gauss_rule(points: int, interval: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on ``interval`` (cached, read-only arrays).

    Examples
    --------
    >>> z, w = gauss_rule(2, (0.0, 1.0))
    >>> float(w.sum()), bool(np.allclose(z, [0.5 - 0.5 / 3**0.5, 0.5 + 0.5 / 3**0.5]))
    (1.0, True)
    """
    a, b = interval
    t, w = leg.leggauss(points)
    nodes, weights = 0.5 * (a + b) + 0.5 * (b - a) * t, 0.5 * (b - a) * w
    nodes.setflags(write=False)
    weights.setflags(write=False)
    return nodes, weights


@lru_cache(maxsize=64)
def _basis_at_gauss(p: int, k: int, points: int, interval: tuple[float, float]) -> np.ndarray:
    """``legendre_basis`` at the nodes of ``gauss_rule(points, interval)`` (cached)."""
    values = legendre_basis(gauss_rule(points, interval)[0], p, k, interval)
    values.setflags(write=False)
    return values


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
    Vm = _basis_at_gauss(p, 0, points, iv) * s
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
        Default: the registry's (:data:`phdesign.numeric.discretization.defaults.GALERKIN`).  The
        two
        discrete systems are congruent by a diagonal matrix: same eigenvalues in exact
        arithmetic, not in floating point.
    remove_spurious : bool
        Work on the E-orthogonal complement of the unobservable subspace created by the
        weakly imposed inputs (:mod:`phdesign.numeric.discretization.spurious`); default True.
        False
        keeps the full polynomial space (for comparisons).

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
    iv, nb = nm.interval, p + 1
    s = trace_scaling(p, N, iv) if basis == "scaled" else np.ones(nb)
    # Exact Gauss rule for the polynomial products psi_j psi_l^(k) (degree <= 2p).
    wq = gauss_rule(nb + 1, iv)[1]
    V0 = _basis_at_gauss(p, 0, nb + 1, iv) * s
    A = np.zeros((n * nb, n * nb))
    for k, Pk in enumerate(nm.P):
        if k == 0 and not nm.P0_constant:  # P0(z): by quadrature below
            continue
        if np.any(Pk):
            A += np.kron(Pk, (V0 * wq[:, None]).T @ (_basis_at_gauss(p, k, nb + 1, iv) * s))
    scale_all = np.tile(s, n)
    zeroth_order = None  # P0(z): its weak form in Legendre coordinates (numeric.distributed)
    if not nm.P0_constant:
        points = 2 * nb + 20
        zd, wd = gauss_rule(points, iv)
        zeroth_order = galerkin_p0(nm, zd, wd, _basis_at_gauss(p, 0, points, iv))
        A0 = zeroth_order * np.outer(scale_all, scale_all)
        A += A0
    M = _mass(nm, p, s)
    T_legendre = _trace_map(nm, p)
    T = T_legendre * scale_all
    UT, YT = nm.U @ T, nm.Y @ T
    JR = A - YT.T @ UT
    J = 0.5 * (JR - JR.T)
    if zeroth_order is None:
        sym0 = 0.5 * (nm.P[0] + nm.P[0].T)
        R = -np.kron(sym0, np.diag(s * s))
    else:
        R = -0.5 * (A0 + A0.T)
    B = YT.T.copy()
    defect = float(np.max(np.abs(0.5 * (JR + JR.T) + R)) / max(np.max(np.abs(A)), 1.0))
    spurious = (
        spurious_modes(nm, p, T_legendre, zeroth_order, _frozen(nm, zeroth_order))
        if remove_spurious
        else SpuriousModes(np.zeros((n * nb, 0)))
    )
    W: np.ndarray | None = None
    keep = np.arange(n * nb)
    if spurious.count:
        W, keep, selection = e_orthogonal_complement(spurious.basis / scale_all[:, None], M)
        if selection:  # a plain selection of coordinates: exact sub-blocks
            ix = np.ix_(keep, keep)
            M, J, R, A, B, T = M[ix], J[ix], R[ix], A[ix], B[keep], T[:, keep]
        else:
            M = 0.5 * (W.T @ M @ W + (W.T @ M @ W).T)
            J = W.T @ J @ W
            J = 0.5 * (J - J.T)
            R = W.T @ R @ W
            R = 0.5 * (R + R.T)
            A, B, T = W.T @ A @ W, W.T @ B, T @ W
    info: dict[str, Any] = {
        "T": T,
        "A": A,
        "basis": basis,
        "weak_form_symmetry_defect": defect,
        "spurious": spurious,
        "spurious_removed": spurious.count,
        "trial_map": W,
        "coordinates": tuple((int(j) // nb, int(j) % nb) for j in keep),
    }
    space = _TrialSpace(nm, p, s, W, M)
    return DiscretePHS(
        model=nm,
        method=Galerkin.name,
        resolution=p,
        E=M,
        J=J,
        R=R,
        B=B,
        D=np.zeros((N * n, N * n)),
        effort_basis=space.effort_basis,
        project=space.project,
        displacement_basis=None if nm.displacement is None else space.displacement,
        info=info,
    )


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
        Vp = _basis_at_gauss(self.p, 0, points, self.nm.interval) * self.s
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
        return _displacement_basis(self.nm, self.effort_basis, self.nm.interval)

    def displacement(self, z: np.ndarray) -> np.ndarray:
        """``(m, dim)`` values: w(z) = displacement(z) @ ê (built on first use)."""
        return np.asarray(self._displacement(z))


def _displacement_basis(nm: NumericModel, effort_basis, iv):  # type: ignore[no-untyped-def]
    """w(z) = repeated integral from a of x_c = (H^-1 e)_c, as a linear map of ê.

    x_c is sampled at Gauss points, expanded in Legendre polynomials by the (exact for
    polynomials) discrete transform, and integrated exactly in that expansion.
    """
    spec = nm.displacement
    assert spec is not None
    c = spec.component - 1
    nq = 160
    zq, wq = gauss_rule(nq, iv)
    Eq = effort_basis(zq)  # (nq, n, dim)
    Hinv = np.linalg.inv(nm.H_at(zq))
    X = np.einsum("qk,qkd->qd", Hinv[:, c, :], Eq)  # x_c at Gauss points
    t = (2 * zq - iv[0] - iv[1]) / (iv[1] - iv[0])
    Vt = leg.legvander(t, nq - 1)
    norms = 2.0 / (2.0 * np.arange(nq) + 1.0)
    coef = (Vt * (wq * 2.0 / (iv[1] - iv[0]))[:, None]).T @ X / norms[:, None]
    half = 0.5 * (iv[1] - iv[0])
    for _ in range(spec.integrations):
        coef = leg.legint(coef, lbnd=-1, axis=0) * half

    def basis(z: np.ndarray) -> np.ndarray:
        tt = (2 * np.atleast_1d(np.asarray(z, dtype=float)) - iv[0] - iv[1]) / (iv[1] - iv[0])
        return leg.legvander(tt, coef.shape[0] - 1) @ coef

    return basis
