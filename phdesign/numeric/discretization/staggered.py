r"""Staggered-grid finite differences (Trenchant, Ramirez, Kotyczka, Le Gorrec, JCP 2018).

The paper's own setting (140 states for the beam).  Supported models: order N = 1 or 2,
the state splits into a group p whose traces at a are the inputs there and a group q
whose traces at b are the inputs there (mixed causality), H is block diagonal in (p, q),
P_N couples only p and q, and 0 < k < N gives P_k = 0:

.. math::

    N = 1:\; \dot x_p = G^\top \partial_z e_q,\; \dot x_q = G \partial_z e_p; \qquad
    N = 2:\; \dot x_p = -G^\top \partial_z^2 e_q,\; \dot x_q = G \partial_z^2 e_p,

plus P_0 (coupling between the grids through an averaging operator and its adjoint).
This covers wave, Timoshenko and Euler-Bernoulli.  Other models raise NumericError (use
the Galerkin default, which covers every model).

Grids, with h = (b - a)/m and m nodes per group:

* N = 1: e_p at a + i h (i = 1..m, weight h, last h/2), e_q at a + (j + 1/2) h
  (j = 0..m-1, weight h); native inputs e_p(a), e_q(b), outputs −Gᵀ e_q(a), G e_p(b).
* N = 2: e_p at a + i h (i = 1..m, weight h, last h/2), e_q at a + j h (j = 0..m-1,
  weight h, first h/2); ghost values from the derivative inputs; native inputs
  e_p(a), e_p'(a), e_q(b), e_q'(b), outputs Gᵀ e_q'(a), −Gᵀ e_q(a), G e_p'(b), −G e_p(b).

The weighted equations read W ẋ = K ê + F u with the difference operator of q
the negative transpose of that of p, so J is skew by construction and the discrete
energy ½ Σ w_i e_iᵀ H_i⁻¹ e_i obeys the exact balance.  The model's own (U, Y) are
related to the native ports by u = S u_nat, y = S⁻ᵀ y_nat + K_d u_nat; the result has
B = B_nat S⁻¹ and skew feedthrough D = K_d S⁻¹.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel, trace_index
from phdesign.numeric.discretization.base import Method
from phdesign.numeric.discretization.distributed import staggered_p0
from phdesign.numeric.discretization.phs import DiscretePHS

__all__ = ["StaggeredFD", "staggered_fd"]


class StaggeredFD(Method, name="fd"):
    """The registered method ``"fd"``: :func:`staggered_fd` with ``resolution`` nodes per group."""

    @classmethod
    def build(cls, nm: NumericModel, resolution: int, basis: str | None) -> DiscretePHS:
        """Return :func:`staggered_fd` of ``nm`` (finite differences have no ``basis``)."""
        return staggered_fd(nm, resolution)


def _groups(nm: NumericModel) -> tuple[list[int], list[int]]:
    """Components whose traces at a (group p) and at b (group q) carry the inputs."""
    N, n = nm.order, nm.size
    at_a, at_b = set(), set()
    for i in range(n):
        for k in range(N):
            if np.any(nm.U[:, trace_index(i + 1, k, "a", N, n)]):
                at_a.add(i)
            if np.any(nm.U[:, trace_index(i + 1, k, "b", N, n)]):
                at_b.add(i)
    p, q = sorted(at_a), sorted(at_b)
    if at_a & at_b or len(p) != len(q) or len(p) + len(q) != n:
        raise NumericError(
            "staggered finite differences need mixed causality (inputs at a on one half of the "
            f"components, at b on the other); found inputs at a on {[i + 1 for i in p]} and "
            f"at b on {[i + 1 for i in q]}; use method='galerkin'"
        )
    return p, q


def _native_ports(N: int, n: int, p: list[int], q: list[int], G: np.ndarray):
    """Native (U_nat, Y_nat) over the trace vector, rows ordered as the native inputs."""
    r = len(p)
    U = np.zeros((N * n, 2 * N * n))
    Y = np.zeros((N * n, 2 * N * n))
    row = 0

    def tr(i: int, k: int, side: str) -> int:
        return trace_index(i + 1, k, side, N, n)

    if N == 1:
        for a_ in range(r):  # u = e_p(a), y = -G^T e_q(a)
            U[row, tr(p[a_], 0, "a")] = 1.0
            for b_ in range(r):
                Y[row, tr(q[b_], 0, "a")] = -G[b_, a_]
            row += 1
        for b_ in range(r):  # u = e_q(b), y = G e_p(b)
            U[row, tr(q[b_], 0, "b")] = 1.0
            for a_ in range(r):
                Y[row, tr(p[a_], 0, "b")] = G[b_, a_]
            row += 1
    else:
        for k, sign, kk in (
            (0, 1.0, 1),
            (1, -1.0, 0),
        ):  # e_p(a)->G^T e_q'(a); e_p'(a)->-G^T e_q(a)
            for a_ in range(r):
                U[row, tr(p[a_], k, "a")] = 1.0
                for b_ in range(r):
                    Y[row, tr(q[b_], kk, "a")] = sign * G[b_, a_]
                row += 1
        for k, sign, kk in ((0, 1.0, 1), (1, -1.0, 0)):  # e_q(b)->G e_p'(b); e_q'(b)->-G e_p(b)
            for b_ in range(r):
                U[row, tr(q[b_], k, "b")] = 1.0
                for a_ in range(r):
                    Y[row, tr(p[a_], kk, "b")] = sign * G[b_, a_]
                row += 1
    return U, Y


def staggered_fd(nm: NumericModel, m: int) -> DiscretePHS:
    """Discretize ``nm`` by staggered finite differences with ``m`` nodes per group.

    The system has n m states (the paper's beam: m = 70, 140 states).  Its stages: the
    supported structure, the grids, the skew difference operator with the P0 coupling,
    the mass matrix, the native input matrix and the change to the model's own ports.
    """
    if nm.order not in (1, 2):
        raise NumericError(
            f"staggered finite differences support N = 1 and 2; found N = {nm.order}"
        )
    if m < 3:
        raise NumericError(f"finite-difference resolution must be at least 3 nodes; found {m}")
    n = nm.size
    p, q, G = _supported(nm)
    grids = _Grids.of(nm, m)
    J, R = _structure(nm, grids, p, q, G)
    E, Hp, Hq = _mass(nm, grids, p, q)
    B, D = _model_ports(nm, _native_inputs(nm, grids, len(p), G), p, q, G)
    space = _NodalSpace(n, grids, p, q, Hp, Hq)
    r, dim = len(p), n * m
    fields = functools.partial(_fd_field, nm, p, q, grids.zp, grids.zq, Hp, Hq, r, m, dim)
    disp = None if nm.displacement is None else fields(nm.displacement)
    return DiscretePHS(
        model=nm,
        method=StaggeredFD.name,
        resolution=m,
        E=E,
        J=0.5 * (J - J.T),
        R=0.5 * (R + R.T),
        B=B,
        D=D,
        effort_basis=space.effort_basis,
        project=space.project,
        displacement_basis=disp,
        field_basis=fields,
        info={
            "h": grids.h,
            "groups": (p, q),
            # (component, node) of each state: node-major within the p block, then the q block
            "coordinates": tuple((g[c], j) for g in (p, q) for j in range(m) for c in range(r)),
        },
    )


def _supported(nm: NumericModel) -> tuple[list[int], list[int], np.ndarray]:
    """Return the groups (p, q) and G of a supported model (module docstring), else raise."""
    N = nm.order
    for k in range(1, N):
        if np.any(nm.P[k]):
            raise NumericError(f"staggered finite differences need P{k} = 0 for this order")
    p, q = _groups(nm)
    PN = nm.P[N]
    G = PN[np.ix_(q, p)]
    if np.any(PN[np.ix_(p, p)]) or np.any(PN[np.ix_(q, q)]) or abs(np.linalg.det(G)) < 1e-12:
        raise NumericError(
            "staggered finite differences need P_N = [[0, *], [G, 0]] in (p, q) with G invertible"
        )
    return p, q, G


@dataclass(frozen=True)
class _Grids:
    """The two staggered grids of m nodes: points, weights, difference and averaging maps."""

    m: int
    h: float
    zp: np.ndarray
    zq: np.ndarray
    wp: np.ndarray
    wq: np.ndarray
    Dm: np.ndarray  # (W_q ∂^N e_p) at the q nodes, from the p nodes
    Pi: np.ndarray  # q values at the p nodes

    @classmethod
    def of(cls, nm: NumericModel, m: int) -> _Grids:
        """Return the grids of ``nm``'s order (module docstring)."""
        a, b = nm.interval
        h = (b - a) / m
        zp = a + np.arange(1, m + 1) * h
        wp = np.full(m, h)
        wp[-1] = h / 2
        if nm.order == 1:
            zq = a + (np.arange(m) + 0.5) * h
            wq = np.full(m, h)
            Dm = np.eye(m) - np.eye(m, k=-1)  # (W_q ∂e_p)_j = p_{j+1} - p_j, p_0 -> input
            Pi = 0.5 * (np.eye(m) + np.eye(m, k=1))  # q values at p nodes (averaging)
            Pi[-1, -1] = 1.0
        else:
            zq = a + np.arange(m) * h
            wq = np.full(m, h)
            wq[0] = h / 2
            Dm = (np.eye(m) - 2 * np.eye(m, k=-1) + np.eye(m, k=-2)) / h
            Dm[0, :] = 0.0
            Dm[0, 0] = 1.0 / h
            Pi = np.eye(m, k=1)  # q_i at p node i; last p node takes q_{m-1}
            Pi[-1, -1] = 1.0
        return cls(m, h, zp, zq, wp, wq, Dm, Pi)


def _structure(
    nm: NumericModel, grids: _Grids, p: list[int], q: list[int], G: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Return J (the difference operator of q the negative transpose of p's) and R."""
    r, m = len(p), grids.m
    Kpq = np.kron(grids.Dm, G)  # W_q x_q' = Kpq e_p + ...
    # Layout: [p block (node-major, r comps), q block (node-major, r comps)].
    dim = nm.size * m
    sp, sq = slice(0, r * m), slice(r * m, dim)
    J0 = np.zeros((dim, dim))
    J0[sq, sp] = Kpq
    J0[sp, sq] = -Kpq.T
    # P0(z) in weak form, nodal; cross blocks through the averaging Pi (q values at p nodes)
    K0 = staggered_p0(nm, (p, q), (grids.zp, grids.zq), (grids.wp, grids.wq), grids.Pi)
    J = J0 + 0.5 * (K0 - K0.T)
    R = -0.5 * (K0 + K0.T)
    if np.min(np.linalg.eigvalsh(R)) < -1e-12 * max(1.0, np.max(np.abs(R))):
        raise NumericError(
            "staggered finite differences: the discrete P0 coupling is not dissipative"
        )
    return J, R


def _mass(
    nm: NumericModel, grids: _Grids, p: list[int], q: list[int]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the mass matrix E (weights times H⁻¹ at the nodes) and H at both grids."""
    Hp, Hq = nm.H_at(grids.zp), nm.H_at(grids.zq)
    if np.any(np.abs(Hp[:, p][:, :, q]) > 0) or np.any(np.abs(Hq[:, p][:, :, q]) > 0):
        raise NumericError(
            "staggered finite differences need H block diagonal in the (p, q) groups"
        )
    r, m = len(p), grids.m
    E = np.zeros((nm.size * m, nm.size * m))
    for j in range(m):
        E[j * r : (j + 1) * r, j * r : (j + 1) * r] = grids.wp[j] * np.linalg.inv(
            Hp[j][np.ix_(p, p)]
        )
        o = r * m + j * r
        E[o : o + r, o : o + r] = grids.wq[j] * np.linalg.inv(Hq[j][np.ix_(q, q)])
    return E, Hp, Hq


def _native_inputs(nm: NumericModel, grids: _Grids, r: int, G: np.ndarray) -> np.ndarray:
    """Return the native input matrix, columns ordered as in :func:`_native_ports`."""
    N, m, h = nm.order, grids.m, grids.h
    Bn = np.zeros((nm.size * m, N * nm.size))
    qo, GT = r * m, G.T
    if N == 1:
        Bn[qo : qo + r, 0:r] = -G  # q node 0 gets -G e_p(a)
        Bn[(m - 1) * r : m * r, r : 2 * r] = GT  # p node m gets G^T e_q(b)
    else:
        Bn[qo : qo + r, 0:r] = -G / h
        Bn[qo + r : qo + 2 * r, 0:r] = G / h
        Bn[qo : qo + r, r : 2 * r] = -G
        Bn[(m - 2) * r : (m - 1) * r, 2 * r : 3 * r] = -GT / h
        Bn[(m - 1) * r : m * r, 2 * r : 3 * r] = GT / h
        Bn[(m - 1) * r : m * r, 3 * r : 4 * r] = -GT
    return Bn


def _model_ports(
    nm: NumericModel, Bn: np.ndarray, p: list[int], q: list[int], G: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Return B and the skew feedthrough D of the model's own ports (module docstring)."""
    N, n = nm.order, nm.size
    Un, Yn = _native_ports(N, n, p, q, G)
    S = nm.U @ np.linalg.pinv(Un)
    if np.max(np.abs(S @ Un - nm.U)) > 1e-10 * max(1.0, np.max(np.abs(nm.U))):
        raise NumericError(
            "staggered finite differences: the model's inputs are not combinations of the "
            "inputs this grid imposes; use method='galerkin'"
        )
    KT = nm.Y @ np.linalg.inv(np.vstack([Un, Yn]))
    Kd, T = KT[:, : N * n], KT[:, N * n :]
    Sinv = np.linalg.inv(S)
    if np.max(np.abs(T - Sinv.T)) > 1e-9 * max(1.0, np.max(np.abs(T))):
        raise NumericError(
            "staggered finite differences: the model's outputs are not power conjugate"
        )
    D = Kd @ Sinv
    return Bn @ Sinv, 0.5 * (D - D.T)


class _NodalSpace:
    """Evaluation (piecewise linear between the nodes) and nodal projection of the efforts."""

    def __init__(
        self,
        n: int,
        grids: _Grids,
        p: list[int],
        q: list[int],
        Hp: np.ndarray,
        Hq: np.ndarray,
    ) -> None:
        self.n, self.grids, self.p, self.q, self.Hp, self.Hq = n, grids, p, q, Hp, Hq

    def effort_basis(self, z: np.ndarray) -> np.ndarray:
        """``(len(z), n, dim)`` values: e(z) = effort_basis(z) @ ê."""
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        r, m = len(self.p), self.grids.m
        out = np.zeros((zz.size, self.n, self.n * m))
        for grid, comps, off in ((self.grids.zp, self.p, 0), (self.grids.zq, self.q, r * m)):
            Wt = _linear_interp_matrix(grid, zz)
            for c_, comp in enumerate(comps):
                out[:, comp, off + c_ : off + r * m : r] = Wt
        return out

    def project(self, x0: Any) -> np.ndarray:
        """Return the efforts e = H x0 at the nodes of each group."""
        r, m, n = len(self.p), self.grids.m, self.n
        eh = np.zeros(n * m)
        X = np.asarray(x0(self.grids.zp), dtype=float).reshape(m, n)
        Xp = np.einsum("qij,qj->qi", self.Hp, X)
        X = np.asarray(x0(self.grids.zq), dtype=float).reshape(m, n)
        Xq = np.einsum("qij,qj->qi", self.Hq, X)
        eh[: r * m] = Xp[:, self.p].reshape(-1)
        eh[r * m :] = Xq[:, self.q].reshape(-1)
        return eh


def _linear_interp_matrix(grid: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Matrix of piecewise-linear interpolation from ``grid`` values (constant outside)."""
    W = np.zeros((z.size, grid.size))
    idx = np.clip(np.searchsorted(grid, z) - 1, 0, grid.size - 2)
    t = np.clip((z - grid[idx]) / (grid[idx + 1] - grid[idx]), 0.0, 1.0)
    W[np.arange(z.size), idx] = 1 - t
    W[np.arange(z.size), idx + 1] = t
    return W


def _fd_field(nm, p, q, zp, zq, Hp, Hq, r, m, dim, spec):
    """f(z) = Σ_j c_j I_s^{k_j} x_{i_j}: repeated trapezoidal integration of nodal x_i."""
    parts = [
        (c, _fd_term(nm, p, q, zp, zq, Hp, Hq, r, m, dim, i - 1, k, spec.start))
        for i, k, c in spec.terms
    ]

    def basis(z: np.ndarray) -> np.ndarray:
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        return np.asarray(
            sum(c * (_linear_interp_matrix(pts, zz) @ vals) for c, (pts, vals) in parts)
        )

    return basis


def _fd_term(nm, p, q, zp, zq, Hp, Hq, r, m, dim, c, integrations, start):
    """Nodes and values (as maps of ê) of I_s^k x_c, x = H⁻¹ e, from the end ``start``."""
    in_p = c in p
    grid, Hg, comps, off = (zp, Hp, p, 0) if in_p else (zq, Hq, q, r * m)
    cc = comps.index(c)
    Hinv = np.linalg.inv(Hg[:, comps][:, :, comps])
    X = np.zeros((m, dim))  # x_c at the group's nodes as a map of ê
    for j in range(m):
        for d_ in range(r):
            X[j, off + j * r + d_] = Hinv[j, cc, d_]
    a, b = nm.interval
    # Extend to both ends (constant extrapolation) and integrate with the trapezoid rule.
    pts = np.concatenate([[a], grid, [b]]) if grid[-1] < b else np.concatenate([[a], grid])
    vals = np.vstack([X[:1], X, X[-1:]]) if grid[-1] < b else np.vstack([X[:1], X])
    if grid[0] == a:
        pts, vals = pts[1:], vals[1:]
    if start == "b":  # integrate from b: the same rule on the reversed nodes
        pts, vals = pts[::-1], vals[::-1]
    for _ in range(integrations):
        dz = np.diff(pts)[:, None]
        vals = np.vstack(
            [np.zeros((1, dim)), np.cumsum(0.5 * dz * (vals[1:] + vals[:-1]), axis=0)]
        )
    if start == "b":
        pts, vals = pts[::-1], vals[::-1]
    return pts, vals
