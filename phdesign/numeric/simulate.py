r"""Simulation of plant and observer together, exact in time for these LTI systems.

With the discretization :math:`E \dot{\hat e} = (J - R)\hat e + B u`,
:math:`y = B^\top \hat e + D u` (:mod:`phdesign.numeric.discretize`), the observer is the
same system driven by

.. math::

    \hat u = u + C_m^\top L (y_m - \hat y_m), \qquad K = C_m^\top L C_m,

which, with the feedthrough loop solved, is
:math:`\hat u = u + (I + K D)^{-1} K B^\top (\hat e - \hat e_{obs})`.  Plant and observer
form one LTI system :math:`\dot X = F X + G u`.  Time stepping (never an explicit generic
ODE solver):

``"expm"`` (default)
    exact: :math:`X_{k+1} = e^{F\Delta t} X_k + \Gamma_1 u_k + \Gamma_2 (u_{k+1}-u_k)/\Delta t`
    from one matrix exponential of the augmented matrix (exact for u = 0 and for u
    piecewise linear between output samples).
``"midpoint"``
    implicit midpoint (Gauss-Legendre order 2): the discrete energy
    :math:`\tfrac12 X^\top E X` is conserved exactly when R = 0 and u = 0, because the
    step is the Cayley transform of an E-skew operator.

Energies: :math:`H = \tfrac12 \hat e^\top E \hat e`, :math:`\hat H` likewise for the
observer and :math:`\tilde H = \tfrac12 (\hat e - \hat e_{obs})^\top E (\hat e - \hat e_{obs})`.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg as sl

from phdesign.errors import NumericError
from phdesign.numeric.arguments import check_simulate_arguments
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretize import DiscretePHS, discretize, feedback_matrix
from phdesign.numeric.display import SimulationDisplay

__all__ = [
    "ENERGY_BALANCE_RTOL",
    "SimulationResult",
    "coupled_system",
    "energy_balance_residual",
    "simulate",
    "step_lti",
]

#: Largest energy-balance residual, relative to the largest energy of the run, that a
#: simulation may show before it warns. Exact stepping leaves round-off (about 1e-13).
ENERGY_BALANCE_RTOL = 1e-8


@dataclass(frozen=True, repr=False)
class SimulationResult(SimulationDisplay):
    """Time series of a plant (and observer) simulation.

    Attributes
    ----------
    t : ndarray (nt,)
    H, H_hat, H_err : ndarray (nt,)
        Plant, observer and error energies (``H_hat``/``H_err`` are None without observer).
    y, y_hat : ndarray (nt, N n)
        Plant and observer outputs.
    output_labels : tuple of str
    z_w : ndarray or None
        Points where the displacement is sampled.
    w, w_hat : ndarray (nt, len(z_w)) or None
        Displacement of the plant and its estimate (models with a displacement only).
    states, states_hat : ndarray (nt, dim)
        Discrete effort coordinates (kept for exports and checks; not written to files).
    units : mapping or None
        Units the model states (``t``, ``z``, ``energy``, ``displacement``, ...), for labels
        and JSON; ``None`` for a result built by hand (plots then assume SI).
    """

    t: np.ndarray
    H: np.ndarray
    H_hat: np.ndarray | None
    H_err: np.ndarray | None
    y: np.ndarray
    y_hat: np.ndarray | None
    output_labels: tuple[str, ...]
    method: str
    resolution: int
    z_w: np.ndarray | None = None
    w: np.ndarray | None = None
    w_hat: np.ndarray | None = None
    states: np.ndarray | None = field(default=None, repr=False)
    states_hat: np.ndarray | None = field(default=None, repr=False)
    info: dict[str, Any] = field(default_factory=dict, repr=False)
    warnings: tuple[str, ...] = ()
    units: dict[str, str] | None = field(default=None, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary of the time series (no discrete states)."""
        out: dict[str, Any] = {
            "method": self.method,
            "resolution": self.resolution,
            "t": self.t.tolist(),
            "H": self.H.tolist(),
            "H_hat": None if self.H_hat is None else self.H_hat.tolist(),
            "H_err": None if self.H_err is None else self.H_err.tolist(),
            "output_labels": list(self.output_labels),
            "y": self.y.tolist(),
            "y_hat": None if self.y_hat is None else self.y_hat.tolist(),
        }
        if self.w is not None and self.z_w is not None:
            out["z_w"] = self.z_w.tolist()
            out["w"] = self.w.tolist()
            out["w_hat"] = None if self.w_hat is None else self.w_hat.tolist()
        out.update({k: v for k, v in self.info.items() if isinstance(v, (int, float, str))})
        out["warnings"] = list(self.warnings)
        out["units"] = dict(self.units or {})
        return out

    def to_json(self) -> str:
        """Return the :meth:`to_dict` payload as JSON text."""
        return json.dumps(self.to_dict())

    def to_csv(self) -> str:
        """CSV: t, H, H_hat, H_err, y_i, y_hat_i and the tip displacement w(b), ŵ(b)."""
        cols: list[tuple[str, np.ndarray]] = [("t", self.t), ("H", self.H)]
        if self.H_hat is not None and self.H_err is not None:
            cols += [("H_hat", self.H_hat), ("H_err", self.H_err)]
        for i in range(self.y.shape[1]):
            cols.append((f"y{i + 1}", self.y[:, i]))
        if self.y_hat is not None:
            for i in range(self.y_hat.shape[1]):
                cols.append((f"y_hat{i + 1}", self.y_hat[:, i]))
        if self.w is not None:
            cols.append(("w_tip", self.w[:, -1]))
            if self.w_hat is not None:
                cols.append(("w_hat_tip", self.w_hat[:, -1]))
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow([c[0] for c in cols])
        data = np.column_stack([c[1] for c in cols])
        for row in data:
            writer.writerow([repr(float(x)) for x in row])
        return buf.getvalue()

    def time_below(self, ratio: float) -> float | None:
        """First sample time after which H_err / H_err(0) stays below ``ratio``."""
        if self.H_err is None or self.H_err[0] <= 0:
            return None
        rel = self.H_err / self.H_err[0]
        above = np.flatnonzero(rel >= ratio)
        if above.size == 0:
            return float(self.t[0])
        k = above[-1]
        if k + 1 >= self.t.size:
            return None
        # linear interpolation of log(rel) between the last sample above and the next
        r0, r1 = np.log(rel[k]), np.log(max(rel[k + 1], 1e-300))
        s = (np.log(ratio) - r0) / (r1 - r0) if r1 != r0 else 0.0
        return float(self.t[k] + s * (self.t[k + 1] - self.t[k]))


def coupled_system(
    d: DiscretePHS, K: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Descriptor matrices (E2, A2, B2) of plant + observer, state (ê, ê_obs).

    Without K (no sensors) only the plant: (E, J − R, B).
    """
    A = d.J - d.R
    if K is None:
        return d.E, A, d.B
    Gk = np.linalg.solve(np.eye(d.n_ports) + K @ d.D, K)
    BGB = d.B @ Gk @ d.B.T
    n = d.dim
    E2 = np.zeros((2 * n, 2 * n))
    E2[:n, :n] = d.E
    E2[n:, n:] = d.E
    A2 = np.zeros((2 * n, 2 * n))
    A2[:n, :n] = A
    A2[n:, :n] = BGB
    A2[n:, n:] = A - BGB
    return E2, A2, np.vstack([d.B, d.B])


def step_lti(
    E: np.ndarray,
    A: np.ndarray,
    B: np.ndarray,
    X0: np.ndarray,
    t: np.ndarray,
    u: np.ndarray | None = None,
    scheme: str = "expm",
) -> np.ndarray:
    """Integrate ``E X' = A X + B u`` on the uniform grid ``t``; returns ``(nt, dim)``.

    ``u`` holds the input at the grid points (``(nt, m)``), linear in between.
    """
    nt = t.size
    dt = float(t[1] - t[0]) if nt > 1 else 0.0
    if nt > 2 and np.max(np.abs(np.diff(t) - dt)) > 1e-9 * max(1.0, abs(dt)):
        raise NumericError("the output time grid must be uniform")
    X = np.empty((nt, X0.size))
    X[0] = X0
    if nt == 1:
        return X
    m = B.shape[1]
    if scheme == "expm":
        F = np.linalg.solve(E, A)
        if u is None or not np.any(u):
            Phi = sl.expm(F * dt)
            for k in range(nt - 1):
                X[k + 1] = Phi @ X[k]
            return X
        G = np.linalg.solve(E, B)
        n = F.shape[0]
        Maug = np.zeros((n + 2 * m, n + 2 * m))
        Maug[:n, :n] = F
        Maug[:n, n : n + m] = G
        Maug[n : n + m, n + m :] = np.eye(m)
        Ex = sl.expm(Maug * dt)
        Phi, G1, G2 = Ex[:n, :n], Ex[:n, n : n + m], Ex[:n, n + m :]
        for k in range(nt - 1):
            X[k + 1] = Phi @ X[k] + G1 @ u[k] + G2 @ ((u[k + 1] - u[k]) / dt)
        return X
    if scheme == "midpoint":
        lu = sl.lu_factor(E - 0.5 * dt * A)
        Mp = E + 0.5 * dt * A
        for k in range(nt - 1):
            rhs = Mp @ X[k]
            if u is not None:
                rhs = rhs + dt * B @ (0.5 * (u[k] + u[k + 1]))
            X[k + 1] = sl.lu_solve(lu, rhs)
        return X
    raise NumericError(f"unknown time-stepping scheme {scheme!r}; expected 'expm' or 'midpoint'")


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
    \end{smallmatrix}\right]`, :math:`G = \Phi^\top Z`. Implicit midpoint satisfies its
    own discrete balance :math:`H_{k+1} - H_k = \Delta t\, x_{k+1/2}^\top
    \operatorname{sym}(A) x_{k+1/2}` exactly. Either residual is round-off for a healthy
    run; a larger one means the stepping lost accuracy (ill-conditioned ``E`` or ``A``).

    Parameters
    ----------
    E, A : ndarray
        The descriptor system.
    X : ndarray (nt, dim)
        The trajectory on the uniform grid ``t``.
    t : ndarray (nt,)
        Sample times.
    scheme : {"expm", "midpoint"}
        The scheme that produced ``X``.
    """
    if t.size < 2:
        return 0.0
    dt = float(t[1] - t[0])
    H = 0.5 * np.einsum("ki,ij,kj->k", X, E, X)
    scale = float(np.max(np.abs(H)))
    if scale == 0.0:
        return 0.0
    S = 0.5 * (A + A.T)
    if scheme == "midpoint":
        mid = 0.5 * (X[1:] + X[:-1])
        change = dt * np.einsum("ki,ij,kj->k", mid, S, mid)
    else:
        G = _dissipation_integral(np.linalg.solve(E, A), -S, dt)
        change = -np.einsum("ki,ij,kj->k", X[:-1], G, X[:-1])
    residual = np.abs(np.diff(H) - change)
    return float(np.max(residual) / scale)


def _dissipation_integral(F: np.ndarray, P: np.ndarray, dt: float) -> np.ndarray:
    """Return G = ∫_0^dt exp(Fᵀs) P exp(Fs) ds by Van Loan's block exponential.

    Van Loan's block holds exp(-Fᵀ δ), which overflows for the stiff, strongly damped
    modes of a fine discretization; so it is applied on a step δ = dt/2^m with
    ‖F‖δ ≤ 1 and doubled back up: G(2δ) = G(δ) + exp(Fδ)ᵀ G(δ) exp(Fδ).
    """
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
    return 0.5 * (G + G.T)


def simulate(
    nm: NumericModel,
    C_m: np.ndarray | None = None,
    L: np.ndarray | None = None,
    *,
    x0: Callable[[np.ndarray], np.ndarray] | None = None,
    xhat0: Callable[[np.ndarray], np.ndarray] | None = None,
    t_end: float = 5.0,
    samples: int = 501,
    method: str = "galerkin",
    resolution: int | None = None,
    u: Callable[[float], np.ndarray] | None = None,
    scheme: str = "expm",
    z_w: np.ndarray | None = None,
    discrete: DiscretePHS | None = None,
) -> SimulationResult:
    """Simulate the plant, and the observer when sensors are given.

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray, optional
        Sensors and gain (both or neither).
    x0, xhat0 : callable, optional
        Initial states ``f(z) -> (m, n)`` (see
        :func:`phdesign.numeric.bridge.initial_state_function`); default zero.
    t_end : float
        Final time (> 0).
    samples : int
        Number of output samples on [0, t_end] (>= 2).
    method, resolution
        Discretization (see :func:`phdesign.numeric.discretize.discretize`).
    u : callable, optional
        Plant input ``u(t) -> (N n,)``, sampled on the output grid and linear in between;
        default zero.
    scheme : {"expm", "midpoint"}
    z_w : ndarray, optional
        Points where the displacement is reported (default 21 uniform points).
    discrete : DiscretePHS, optional
        A ready discretization (overrides ``method``/``resolution``).

    Returns
    -------
    SimulationResult
    """
    check_simulate_arguments(
        nm,
        C_m,
        L,
        x0=x0,
        xhat0=xhat0,
        t_end=t_end,
        samples=samples,
        method=method,
        resolution=resolution,
        u=u,
        scheme=scheme,
        z_w=z_w,
        discrete=discrete,
    )
    if not (np.isfinite(t_end) and t_end > 0):
        raise NumericError(f"t_end must be a positive number; found {t_end}")
    if int(samples) < 2:
        raise NumericError(f"samples must be at least 2; found {samples}")
    if (C_m is None) != (L is None):
        raise NumericError("give both the sensors C_m and the gain L, or neither")
    d = discrete if discrete is not None else discretize(nm, method, resolution)
    K = None if C_m is None or L is None else feedback_matrix(C_m, L, nm.n_ports)
    t = np.linspace(0.0, float(t_end), int(samples))
    zero = lambda z: np.zeros((np.atleast_1d(z).size, nm.size))  # noqa: E731
    e0 = d.project(x0 or zero)
    E2, A2, B2 = coupled_system(d, K)
    U = None
    if u is not None:
        U = np.array([np.asarray(u(float(tk)), dtype=float).reshape(nm.n_ports) for tk in t])
    X0 = e0 if K is None else np.concatenate([e0, d.project(xhat0 or zero)])
    X = step_lti(E2, A2, B2, X0, t, U, scheme)
    n = d.dim
    eh = X[:, :n]
    y = d.output(eh, U)
    H = d.hamiltonian(eh)
    H_hat = H_err = y_hat = eo = None
    if K is not None:
        eo = X[:, n:]
        Gk = np.linalg.solve(np.eye(d.n_ports) + K @ d.D, K)
        uo = (eh - eo) @ (d.B @ Gk.T)
        if U is not None:
            uo = uo + U
        y_hat = d.output(eo, uo)
        H_hat = d.hamiltonian(eo)
        H_err = d.hamiltonian(eh - eo)
    audits = {}
    if U is None:  # the plant is autonomous only without input
        audits["plant"] = energy_balance_residual(d.E, d.J - d.R, eh, t, scheme)
    if K is not None:
        # the error ẽ = ê − ê_obs obeys E ẽ' = (A − B G Bᵀ) ẽ whatever u is
        error_A = A2[n:, n:]
        audits["error system"] = energy_balance_residual(d.E, error_A, eh - eo, t, scheme)
    warnings = tuple(
        f"the {name}'s energy balance drifts by {value:.3g} of its largest energy "
        f"(tolerance {ENERGY_BALANCE_RTOL:g}): the time stepping lost accuracy; "
        "lower the resolution or use --scheme midpoint"
        for name, value in audits.items()
        if not value <= ENERGY_BALANCE_RTOL
    )
    w = w_hat = zw = None
    if d.displacement_basis is not None:
        a, b = nm.interval
        zw = np.linspace(a, b, 21) if z_w is None else np.asarray(z_w, dtype=float)
        Wd = d.displacement_basis(zw)
        w = eh @ Wd.T
        if eo is not None:
            w_hat = eo @ Wd.T
    return SimulationResult(
        t=t,
        H=H,
        H_hat=H_hat,
        H_err=H_err,
        y=y,
        y_hat=y_hat,
        output_labels=nm.output_labels,
        method=d.method,
        resolution=d.resolution,
        z_w=zw,
        w=w,
        w_hat=w_hat,
        states=eh,
        states_hat=eo,
        info={
            "scheme": scheme,
            "states": int(n),
            **{f"energy_balance_residual_{k.replace(' ', '_')}": v for k, v in audits.items()},
        },
        warnings=warnings,
        units=dict(nm.units),
    )
