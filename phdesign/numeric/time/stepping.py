r"""Time stepping of descriptor LTI systems :math:`E \dot X = A X + B u` on a uniform grid.

Never a generic explicit ODE solver: these systems are linear and time invariant.

``"expm"``
    exact: :math:`X_{k+1} = e^{F\Delta t} X_k + \Gamma_1 u_k + \Gamma_2 (u_{k+1}-u_k)/\Delta t`,
    :math:`F = E^{-1}A`, from one exponential of the augmented matrix (exact for u
    piecewise linear between output samples).
``"midpoint"``
    implicit midpoint (Gauss-Legendre of order 2), the Cayley transform
    :math:`C_h = (E - \tfrac h2 A)^{-1}(E + \tfrac h2 A)` of the augmented system: it
    conserves :math:`\tfrac12 X^\top E X` exactly when A is skew and u = 0, and obeys its
    own discrete energy balance otherwise.  It takes :math:`m = 2^j` substeps of
    :math:`h = \Delta t / m` per output interval; the map over one interval is
    :math:`C_h^{m}`, formed by j squarings, so substeps cost one matrix product each
    doubling instead of a loop.  Given a tolerance, j is raised until the step-doubling
    (Richardson) estimate of the error, :math:`\|X_{h} - X_{h/2}\|_E / 3` (order 2),
    relative to the run's largest energy norm :math:`\max_k \|X_k\|_E`, is below it.
    Round-off grows like :math:`2^j \epsilon`, so j is capped at
    :data:`MIDPOINT_MAX_DOUBLINGS`; the result says when the tolerance was not met.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sl

from phdesign.core.errors import NumericError

__all__ = [
    "MIDPOINT_MAX_DOUBLINGS",
    "SCHEMES",
    "Trajectory",
    "dissipation_integral",
    "energy_balance_residual",
    "integrate",
    "step_lti",
]

SCHEMES = ("expm", "midpoint")
#: Largest number of step doublings per output interval (2^24 substeps: round-off ~1e-9).
MIDPOINT_MAX_DOUBLINGS = 24


@dataclass(frozen=True)
class Trajectory:
    """States on the output grid and how they were obtained.

    Attributes
    ----------
    X : ndarray (nt, dim)
    scheme : str
    substeps : int
        Substeps per output interval (1 for ``"expm"``, which is exact).
    error_estimate : float or None
        Midpoint: Richardson estimate of the error relative to max ‖X‖_E; None for expm.
    tol : float or None
        The tolerance the midpoint control aimed at (None: fixed substeps).
    """

    X: np.ndarray = field(repr=False)
    scheme: str = "expm"
    substeps: int = 1
    error_estimate: float | None = None
    tol: float | None = None

    @property
    def met_tolerance(self) -> bool:
        """Whether the midpoint error estimate is within its tolerance (True for expm)."""
        if self.tol is None or self.error_estimate is None:
            return True
        return self.error_estimate <= self.tol


def _grid_step(t: np.ndarray) -> float:
    nt = t.size
    dt = float(t[1] - t[0]) if nt > 1 else 0.0
    if nt > 2 and np.max(np.abs(np.diff(t) - dt)) > 1e-9 * max(1.0, abs(dt)):
        raise NumericError("the output time grid must be uniform")
    return dt


def _augmented(E: np.ndarray, A: np.ndarray, B: np.ndarray, forced: bool):
    """(E_aug, A_aug) of the state with (u_k, du) appended: u(s) = u_k + s du is exact."""
    n, m = A.shape[0], B.shape[1]
    if not forced:
        return E, A
    Ea = np.eye(n + 2 * m)
    Ea[:n, :n] = E
    Aa = np.zeros((n + 2 * m, n + 2 * m))
    Aa[:n, :n] = A
    Aa[:n, n : n + m] = B
    Aa[n : n + m, n + m :] = np.eye(m)
    return Ea, Aa


def _run(Phi: np.ndarray, X0: np.ndarray, u: np.ndarray | None, dt: float, nt: int):
    """Apply the interval map ``Phi`` of the (augmented) state along the grid."""
    n = X0.size
    X = np.empty((nt, n))
    X[0] = X0
    if u is None:
        for k in range(nt - 1):
            X[k + 1] = Phi @ X[k]
        return X
    P, G1, G2 = Phi[:n, :n], Phi[:n, n : n + u.shape[1]], Phi[:n, n + u.shape[1] :]
    for k in range(nt - 1):
        X[k + 1] = P @ X[k] + G1 @ u[k] + G2 @ ((u[k + 1] - u[k]) / dt)
    return X


def _energy_norms(E: np.ndarray, X: np.ndarray) -> np.ndarray:
    return np.asarray(np.sqrt(np.abs(np.sum((X @ E) * X, axis=1))))


def integrate(
    E: np.ndarray,
    A: np.ndarray,
    B: np.ndarray,
    X0: np.ndarray,
    t: np.ndarray,
    u: np.ndarray | None = None,
    scheme: str = "expm",
    *,
    tol: float | None = None,
    substeps: int = 1,
) -> Trajectory:
    """Integrate ``E X' = A X + B u`` on the uniform grid ``t``.

    Parameters
    ----------
    E, A, B : ndarray
        Descriptor system (E invertible).
    X0 : ndarray (dim,)
    t : ndarray (nt,)
        Uniform output grid.
    u : ndarray (nt, m), optional
        Input at the grid points, linear in between; default zero.
    scheme : {"expm", "midpoint"}
    tol : float, optional
        Midpoint only: choose the substeps so that the estimated error, relative to the
        largest energy norm of the run, is at most ``tol`` (module docstring).
    substeps : int
        Midpoint only, without ``tol``: substeps per output interval.

    Returns
    -------
    Trajectory
    """
    if scheme not in SCHEMES:
        raise NumericError(f"unknown time-stepping scheme {scheme!r}; expected one of {SCHEMES}")
    nt = t.size
    dt = _grid_step(t)
    X0 = np.asarray(X0, dtype=float)
    forced = u is not None and bool(np.any(u))
    uu = np.asarray(u, dtype=float) if forced else None
    if nt == 1:
        return Trajectory(X0[None, :].copy(), scheme)
    Ea, Aa = _augmented(E, A, B, forced)
    if scheme == "expm":
        Phi = sl.expm(np.linalg.solve(Ea, Aa) * dt)
        return Trajectory(_run(Phi, X0, uu, dt, nt), scheme)
    if tol is None:
        m = int(substeps)
        if m < 1:
            raise NumericError(f"substeps must be at least 1; found {substeps}")
        C = _cayley(Ea, Aa, dt / m)
        return Trajectory(_run(np.linalg.matrix_power(C, m), X0, uu, dt, nt), scheme, m)
    # Step doubling: C_h^(2^j) by squaring, until the Richardson estimate meets tol.
    Phi = _cayley(Ea, Aa, dt)
    previous = _run(Phi, X0, uu, dt, nt)
    estimate = np.inf
    j = 0
    current = previous
    while j < MIDPOINT_MAX_DOUBLINGS:
        j += 1
        half = _cayley(Ea, Aa, dt / 2**j)
        Phi = half
        for _ in range(j):
            Phi = Phi @ Phi
        current = _run(Phi, X0, uu, dt, nt)
        scale = float(np.max(_energy_norms(E, current)))
        diff = float(np.max(_energy_norms(E, current - previous)))
        estimate = diff / 3.0 / scale if scale > 0 else 0.0
        if estimate <= tol:
            break
        previous = current
    return Trajectory(current, scheme, 2**j, float(estimate), float(tol))


def _cayley(E: np.ndarray, A: np.ndarray, h: float) -> np.ndarray:
    """One implicit-midpoint step (E - h A/2)^-1 (E + h A/2)."""
    return np.asarray(sl.lu_solve(sl.lu_factor(E - 0.5 * h * A), E + 0.5 * h * A))


def step_lti(
    E: np.ndarray,
    A: np.ndarray,
    B: np.ndarray,
    X0: np.ndarray,
    t: np.ndarray,
    u: np.ndarray | None = None,
    scheme: str = "expm",
    *,
    tol: float | None = None,
    substeps: int = 1,
) -> np.ndarray:
    """Integrate ``E X' = A X + B u`` on the uniform grid ``t``; returns ``(nt, dim)``.

    ``u`` holds the input at the grid points (``(nt, m)``), linear in between.  With
    ``scheme="midpoint"`` the step is ``Δt / substeps``, or chosen to meet ``tol``
    (see :func:`integrate`, which also returns the error estimate).
    """
    return integrate(E, A, B, X0, t, u, scheme, tol=tol, substeps=substeps).X


def energy_balance_residual(
    E: np.ndarray, A: np.ndarray, X: np.ndarray, t: np.ndarray, scheme: str = "expm"
) -> float:
    r"""Largest residual of the energy balance of an autonomous run, relative to max H.

    For :math:`E\dot x = A x` and :math:`H = \tfrac12 x^\top E x`,
    :math:`\dot H = x^\top \operatorname{sym}(A) x = -x^\top P x`. Over one step of the
    exact flow, :math:`H_{k+1} - H_k = -x_k^\top G x_k` with
    :math:`G = \int_0^{\Delta t} e^{F^\top s} P e^{F s} ds`, :math:`F = E^{-1}A`, which
    Van Loan's block exponential gives exactly:
    :math:`\exp\big(\Delta t \left[\begin{smallmatrix} -F^\top & P \\ 0 & F
    \end{smallmatrix}\right]\big) = \left[\begin{smallmatrix} \cdot & Z \\ 0 & \Phi
    \end{smallmatrix}\right]`, :math:`G = \Phi^\top Z`. Implicit midpoint with one step
    per output interval satisfies its own discrete balance :math:`H_{k+1} - H_k =
    \Delta t\, x_{k+1/2}^\top \operatorname{sym}(A) x_{k+1/2}` exactly. Either residual is
    round-off for a healthy run; a larger one means the stepping lost accuracy.

    Parameters
    ----------
    E, A : ndarray
        The descriptor system.
    X : ndarray (nt, dim)
        The trajectory on the uniform grid ``t``.
    t : ndarray (nt,)
        Sample times.
    scheme : {"expm", "midpoint"}
        ``"midpoint"`` checks the one-step midpoint balance; ``"expm"`` the exact flow's.
    """
    if t.size < 2:
        return 0.0
    dt = float(t[1] - t[0])
    H = 0.5 * np.sum((X @ E) * X, axis=1)
    scale = float(np.max(np.abs(H)))
    if scale == 0.0:
        return 0.0
    S = 0.5 * (A + A.T)
    if scheme == "midpoint":
        mid = 0.5 * (X[1:] + X[:-1])
        change = dt * np.sum((mid @ S) * mid, axis=1)
    else:
        G = dissipation_integral(np.linalg.solve(E, A), -S, dt)
        change = -np.sum((X[:-1] @ G) * X[:-1], axis=1)
    residual = np.abs(np.diff(H) - change)
    return float(np.max(residual) / scale)


def dissipation_integral(F: np.ndarray, P: np.ndarray, dt: float) -> np.ndarray:
    """Return G = ∫_0^dt exp(Fᵀs) P exp(Fs) ds by Van Loan's block exponential.

    Van Loan's block holds exp(-Fᵀ δ), which overflows for the stiff, strongly damped
    modes of a fine discretization; so it is applied on a step δ = dt/2^m with
    ‖F‖δ ≤ 1 and doubled back up: G(2δ) = G(δ) + exp(Fδ)ᵀ G(δ) exp(Fδ).

    G is linear in P, so it is computed for P / max|P| and scaled back: a large P (the
    covariance of a noise of intensity 1e20) would otherwise set the block exponential's
    scaling, whose squarings then overflow to NaN (and the noise was lost).
    """
    size = float(np.max(np.abs(P))) if P.size else 0.0
    if size == 0.0 or not np.isfinite(size):
        return np.zeros_like(P) if size == 0.0 else np.full_like(P, np.nan)
    if size != 1.0:
        return size * dissipation_integral(F, P / size, dt)
    n = F.shape[0]
    norm = float(np.linalg.norm(F, 1)) * dt
    doublings = max(0, int(np.ceil(np.log2(norm)))) if norm > 1 else 0
    delta = dt / 2**doublings
    block = np.zeros((2 * n, 2 * n))
    block[:n, :n] = -F.T
    block[:n, n:] = P
    block[n:, n:] = F
    exponential = sl.expm(block * delta)
    Phi = exponential[n:, n:]
    G = Phi.T @ exponential[:n, n:]
    for _ in range(doublings):
        G = G + Phi.T @ G @ Phi
        Phi = Phi @ Phi
    return np.asarray(0.5 * (G + G.T))
