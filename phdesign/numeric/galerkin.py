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

``DEFAULT_BASIS`` selects the basis when none is given: ``"auto"`` (the default) takes
the trace-scaled basis for N >= 3, where it turns 9 digits into 15 on the airy error
abscissa, and the plain Legendre basis for N <= 2, where both agree to round-off and
the Legendre basis keeps E well conditioned for any H(z). The choice also sets the
N >= 3 degree cap of :func:`phdesign.numeric.spectrum.default_resolutions`.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.polynomial import legendre as leg

from phdesign.errors import NumericError
from phdesign.numeric.bridge import NumericModel, trace_index
from phdesign.numeric.distributed import galerkin_p0
from phdesign.numeric.phs import DiscretePHS

__all__ = [
    "BASES",
    "DEFAULT_BASIS",
    "galerkin",
    "legendre_basis",
    "resolve_basis",
    "trace_scaling",
]

BASES = ("scaled", "legendre")
#: Basis used by :func:`galerkin` (and so by :func:`phdesign.numeric.discretize.discretize`
#: and the spectrum) when none is given: "auto", "scaled" or "legendre".
DEFAULT_BASIS = "auto"


def resolve_basis(basis: str | None, order: int) -> str:
    """Return the basis :func:`galerkin` uses for a model of order ``order``.

    Examples
    --------
    >>> resolve_basis(None, 3), resolve_basis(None, 2), resolve_basis("scaled", 1)
    ('scaled', 'legendre', 'scaled')
    """
    chosen = DEFAULT_BASIS if basis is None else basis
    if chosen == "auto":
        return "scaled" if order >= 3 else "legendre"
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


def _gauss(nq: int, interval: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    a, b = interval
    t, w = leg.leggauss(nq)
    return 0.5 * (a + b) + 0.5 * (b - a) * t, 0.5 * (b - a) * w


def galerkin(nm: NumericModel, degree: int, basis: str | None = None) -> DiscretePHS:
    """Discretize ``nm`` with polynomials of degree ``degree`` in every effort.

    Parameters
    ----------
    nm : NumericModel
    degree : int
        Polynomial degree p >= N + 1; the system has n (p + 1) states.
    basis : {"scaled", "legendre"}, optional
        ``"scaled"``: the orthonormal Legendre polynomials divided by their largest
        boundary trace (module docstring); ``"legendre"``: unscaled (E = I for H = I).
        Default :data:`DEFAULT_BASIS`.  The two discrete systems are congruent by a diagonal
        matrix: same eigenvalues in exact arithmetic, not in floating point.

    Returns
    -------
    DiscretePHS
        ``E = M``, ``J``, ``R``, ``B = (YT)^T``, ``D = 0`` as in the module docstring.
    """
    N, n, p = nm.order, nm.size, int(degree)
    if p < N + 1:
        raise NumericError(f"Galerkin degree must be at least N + 1 = {N + 1}; found {p}")
    basis = resolve_basis(basis, nm.order)
    if basis not in BASES:
        raise NumericError(f"unknown Galerkin basis {basis!r}; expected one of {BASES}")
    iv = nm.interval
    nb = p + 1
    s = trace_scaling(p, N, iv) if basis == "scaled" else np.ones(nb)
    # Exact Gauss rule for the polynomial products psi_j psi_l^(k) (degree <= 2p).
    zq, wq = _gauss(nb + 1, iv)
    V0 = legendre_basis(zq, p, 0, iv) * s
    A = np.zeros((n * nb, n * nb))
    for k, Pk in enumerate(nm.P):
        if not np.any(Pk) or (k == 0 and not nm.P0_constant):  # P0(z): quadrature below
            continue
        Dk = (V0 * wq[:, None]).T @ (legendre_basis(zq, p, k, iv) * s)
        A += np.kron(Pk, Dk)
    if not nm.P0_constant:  # P0(z): its weak form by Gauss quadrature (numeric.distributed)
        zd, wd = _gauss(2 * nb + 20, iv)
        A0 = galerkin_p0(nm, zd, wd, legendre_basis(zd, p, 0, iv) * s)
        A += A0
    # Gram matrix of the working basis: diag(s^2), exactly.
    G = np.diag(s * s)
    # Mass matrix: exact for constant H, Gauss rule with extra points else.
    M: np.ndarray
    if nm.H_constant:
        Hinv = np.linalg.inv(nm.H_at(np.array([iv[0]]))[0])
        M = np.kron(Hinv, G)
    else:
        zm, wm = _gauss(2 * nb + 20, iv)
        Vm = legendre_basis(zm, p, 0, iv) * s
        Hinv = np.linalg.inv(nm.H_at(zm))  # (q, n, n)
        M = np.einsum("q,qj,qik,ql->ijkl", wm, Vm, Hinv, Vm).reshape(n * nb, n * nb)
    M = 0.5 * (M + M.T)
    # Trace map T: row trace_index(i, k, side) = e_i^T kron phi^(k)(side).
    T = np.zeros((2 * N * n, n * nb))
    for side, zs in (("b", iv[1]), ("a", iv[0])):
        for k in range(N):
            row = legendre_basis(np.array([zs]), p, k, iv)[0] * s
            for i in range(n):
                T[trace_index(i + 1, k, side, N, n), i * nb : (i + 1) * nb] = row
    UT, YT = nm.U @ T, nm.Y @ T
    JR = A - YT.T @ UT
    J = 0.5 * (JR - JR.T)
    if nm.P0_constant:
        sym0 = 0.5 * (nm.P[0] + nm.P[0].T)
        R = -np.kron(sym0, G)
    else:
        R = -0.5 * (A0 + A0.T)
    B = YT.T.copy()
    sym_defect = 0.5 * (JR + JR.T) + R
    info = {
        "T": T,
        "A": A,
        "basis": basis,
        "weak_form_symmetry_defect": float(
            np.max(np.abs(sym_defect)) / max(np.max(np.abs(A)), 1.0)
        ),
    }

    def effort_basis(z: np.ndarray) -> np.ndarray:
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        V = legendre_basis(zz, p, 0, iv) * s
        out = np.zeros((zz.size, n, n * nb))
        for i in range(n):
            out[:, i, i * nb : (i + 1) * nb] = V
        return out

    zp, wp = _gauss(2 * nb + 40, iv)
    Vp = legendre_basis(zp, p, 0, iv) * s

    def project(x0) -> np.ndarray:  # type: ignore[no-untyped-def]
        # L2 projection in the energy pairing: M ê = ∫ Ψᵀ x0 dz.
        X = np.asarray(x0(zp), dtype=float).reshape(zp.size, n)
        rhs = np.concatenate([(Vp * wp[:, None]).T @ X[:, i] for i in range(n)])
        return np.linalg.solve(M, rhs)

    disp_basis = None
    if nm.displacement is not None:
        disp_basis = _displacement_basis(nm, effort_basis, iv)
    return DiscretePHS(
        model=nm,
        method="galerkin",
        resolution=p,
        E=M,
        J=J,
        R=R,
        B=B,
        D=np.zeros((N * n, N * n)),
        effort_basis=effort_basis,
        project=project,
        displacement_basis=disp_basis,
        info=info,
    )


def _displacement_basis(nm: NumericModel, effort_basis, iv):  # type: ignore[no-untyped-def]
    """w(z) = repeated integral from a of x_c = (H^-1 e)_c, as a linear map of ê.

    x_c is sampled at Gauss points, expanded in Legendre polynomials by the (exact for
    polynomials) discrete transform, and integrated exactly in that expansion.
    """
    spec = nm.displacement
    assert spec is not None
    c = spec.component - 1
    nq = 160
    zq, wq = _gauss(nq, iv)
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
