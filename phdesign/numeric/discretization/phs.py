r"""The result type of every discretization: a finite-dimensional port-Hamiltonian system.

.. math::

    E \dot{\hat e} = (J - R) \hat e + B u, \qquad y = B^\top \hat e + D u,
    \qquad H_d = \tfrac12 \hat e^\top E \hat e,

with :math:`E = E^\top \succ 0`, :math:`J = -J^\top`, :math:`R = R^\top \succeq 0` and
:math:`D = -D^\top`, so that :math:`\dot H_d = -\hat e^\top R \hat e + u^\top y` exactly.
It lives apart from :mod:`phdesign.numeric.discretization.registry` so that the methods, which
build
it, and the dispatcher, which calls them, do not import each other.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from phdesign.core.errors import NumericError, ObserverError, check_shape
from phdesign.core.text import html_table
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.invariants import (
    require_definite,
    require_semidefinite,
    require_skew,
)

__all__ = ["ClosedLoop", "DiscretePHS", "feedback_matrix"]


#: Largest condition number of I + K D for which :meth:`DiscretePHS.close` solves the loop.
LOOP_CONDITION = 1e12


def _well_posed(loop: np.ndarray) -> np.ndarray:
    """Return ``loop`` = I + K D, refusing it when it is singular to round-off."""
    condition = float(np.linalg.cond(loop))
    if not condition <= LOOP_CONDITION:
        raise NumericError(
            "the loop u = v - K y is ill-posed: I + K D is singular for this feedthrough "
            f"(condition number {condition:.3g}, expected at most {LOOP_CONDITION:g})"
        )
    return loop


@dataclass(frozen=True, repr=False)
class DiscretePHS:
    r"""A finite-dimensional port-Hamiltonian system in effort coordinates.

    .. math::

        E \dot{\hat e} = (J - R) \hat e + B u, \quad y = B^\top \hat e + D u,
        \quad H_d = \tfrac12 \hat e^\top E \hat e .

    Parameters
    ----------
    model : NumericModel
        The model it discretizes.
    method : str
        ``"galerkin"`` or ``"fd"``.
    resolution : int
        Polynomial degree (Galerkin) or nodes per group (finite differences).
    E, J, R, B, D : ndarray
        Mass (``E ≻ 0``), structure (skew), dissipation (``⪰ 0``), input, feedthrough
        (skew) matrices.
    effort_basis : callable
        ``effort_basis(z) -> (m, n, dim)``: e(z) = effort_basis(z) @ ê.
    project : callable
        ``project(x0) -> ê`` for a vectorized initial state ``x0(z) -> (m, n)``.
    displacement_basis : callable or None
        ``displacement_basis(z) -> (m, dim)``: w(z) = displacement_basis(z) @ ê.
    field_basis : callable or None
        ``field_basis(spec)(z) -> (m, dim)``: the same for any field
        :math:`\sum_j c_j \mathcal I_s^{k_j} x_{i_j}` (a
        :class:`~phdesign.numeric.bridge.DisplacementSpec`, e.g. a named rotation).

    Raises
    ------
    NumericError
        If a shape does not fit, or an invariant fails beyond round-off
        (:mod:`phdesign.numeric.discretization.invariants`): E not symmetric positive definite, J
        or D
        not skew, R not symmetric positive semidefinite.  The message names the matrix
        and gives what was found.
    """

    model: NumericModel
    method: str
    resolution: int
    E: np.ndarray
    J: np.ndarray
    R: np.ndarray
    B: np.ndarray
    D: np.ndarray
    effort_basis: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    project: Callable[[Callable[[np.ndarray], np.ndarray]], np.ndarray] = field(repr=False)
    displacement_basis: Callable[[np.ndarray], np.ndarray] | None = field(default=None, repr=False)
    field_basis: Callable[[Any], Callable[[np.ndarray], np.ndarray]] | None = field(
        default=None, repr=False
    )
    info: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        """Check shapes and the port-Hamiltonian invariants (:mod:`.invariants`), to round-off.

        E symmetric positive definite, J and D skew, R symmetric positive semidefinite:
        what makes every closed loop ũ = −Kỹ with sym(K) ⪰ 0 dissipative.
        """
        n, m = np.shape(self.E)[0], np.shape(self.D)[0]
        for name, matrix, shape in (
            ("E", self.E, (n, n)),
            ("J", self.J, (n, n)),
            ("R", self.R, (n, n)),
            ("B", self.B, (n, m)),
            ("D", self.D, (m, m)),
        ):
            check_shape(name, np.asarray(matrix), shape, NumericError)
        require_definite("E", self.E)
        require_skew("J", self.J)
        # R's round-off is relative to the operator J - R it is part of (a lossless R is 0)
        require_semidefinite("R", self.R, reference=float(np.max(np.abs(self.J), initial=0.0)))
        require_skew("D", self.D)

    @property
    def dim(self) -> int:
        """Number of discrete states."""
        return int(self.E.shape[0])

    @property
    def n_ports(self) -> int:
        """Number of inputs (= outputs)."""
        return int(self.B.shape[1])

    @cached_property
    def explicit(self) -> tuple[np.ndarray, np.ndarray]:
        r"""``(F, G)``: the explicit form :math:`\dot{\hat e} = F\hat e + G u`, solved once.

        :math:`F = E^{-1}(J - R)`, :math:`G = E^{-1}B` (read-only): every run of this
        discretization (the order selection's trials, the verification) shares them.
        """
        F = np.linalg.solve(self.E, self.J - self.R)
        G = np.linalg.solve(self.E, self.B)
        F.setflags(write=False)
        G.setflags(write=False)
        return F, G

    def hamiltonian(self, ehat: np.ndarray) -> np.ndarray:
        """Discrete energy ½ êᵀ E ê; ``ehat`` of shape ``(dim,)`` or ``(nt, dim)``."""
        eh = np.asarray(ehat)
        return np.asarray(0.5 * np.sum((eh @ self.E) * eh, axis=-1))

    def output(self, ehat: np.ndarray, u: np.ndarray | None = None) -> np.ndarray:
        """Y = Bᵀ ê + D u (row-wise for stacked ``ehat``)."""
        y = np.asarray(ehat) @ self.B
        if u is not None:
            y = y + np.asarray(u) @ self.D.T
        return np.asarray(y)

    def close(self, K: np.ndarray | None = None) -> ClosedLoop:
        """Close the output feedback u = v − K y around the system (``K=None``: K = 0).

        The one place where the loop with a feedthrough D is solved; see
        :class:`ClosedLoop` for the equations.

        Raises
        ------
        NumericError
            If the loop is ill-posed: I + K D singular to round-off (condition number above
            :data:`LOOP_CONDITION`).
        """
        m = self.n_ports
        Km = np.zeros((m, m)) if K is None else np.asarray(K, dtype=float)
        check_shape("K = C_m^T L C_m", Km, (m, m))
        if not np.all(np.isfinite(Km)):
            raise ObserverError("the feedback K = C_m^T L C_m must be finite")
        if not np.any(self.D):
            M = np.eye(m)
            G = Km
        else:
            M = np.linalg.inv(_well_posed(np.eye(m) + Km @ self.D))
            G = M @ Km
        BG = self.B @ G
        return ClosedLoop(
            system=self,
            K=Km,
            gain=G,
            A=self.J - self.R - BG @ self.B.T,
            B=self.B @ M,
            C=self.B.T - self.D @ G @ self.B.T,
            D=self.D @ M,
        )

    def closed_matrix(self, K: np.ndarray | None = None) -> np.ndarray:
        """Right-hand matrix ``E ê' = (J − R − B (I + K D)⁻¹ K Bᵀ) ê`` of :meth:`close`."""
        return self.close(K).A

    @property
    def spurious_removed(self) -> int:
        """Number of spurious (unobservable) Galerkin modes removed from the trial space."""
        return int(self.info.get("spurious_removed", 0))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (sizes and what was removed; no matrices)."""
        spurious = self.info.get("spurious")
        return {
            "model": self.model.name,
            "method": self.method,
            "resolution": self.resolution,
            "states": self.dim,
            "ports": self.n_ports,
            "basis": self.info.get("basis"),
            "spurious_removed": self.spurious_removed,
            "spurious": None if spurious is None else spurious.describe(),
        }

    def __repr__(self) -> str:
        return (
            f"DiscretePHS(model={self.model.name!r}, method={self.method!r}, "
            f"resolution={self.resolution}, states={self.dim}, ports={self.n_ports}, "
            f"spurious_removed={self.spurious_removed})"
        )

    def __str__(self) -> str:
        lines = [
            f"discretization of {self.model.name}: {self.method}, resolution "
            f"{self.resolution}, {self.dim} states, {self.n_ports} ports"
        ]
        spurious = self.info.get("spurious")
        if spurious is not None and spurious.count:
            lines.append(spurious.describe())
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        return html_table((), self.to_dict().items())

    def check_structure(self) -> dict[str, float]:
        """Return the structural residuals: skewness of J and D, symmetry and signs."""

        def rel(x: np.ndarray, ref: np.ndarray) -> float:
            return float(np.max(np.abs(x)) / max(np.max(np.abs(ref)), 1e-300))

        return {
            "J_skew": rel(self.J + self.J.T, self.J),
            "R_sym": rel(self.R - self.R.T, self.R) if np.any(self.R) else 0.0,
            "E_sym": rel(self.E - self.E.T, self.E),
            "D_skew": rel(self.D + self.D.T, self.D) if np.any(self.D) else 0.0,
            "R_min_eig": float(np.min(np.linalg.eigvalsh(self.R))) if self.dim else 0.0,
            "E_min_eig": float(np.min(np.linalg.eigvalsh(self.E))),
        }


@dataclass(frozen=True, repr=False)
class ClosedLoop:
    r"""The loop :math:`u = v - K y` closed around a :class:`DiscretePHS`.

    With :math:`y = B^\top \hat e + D u` the loop is solved once:
    :math:`u = M (v - K B^\top \hat e)`, :math:`M = (I + K D)^{-1}`, hence

    .. math::

        E \dot{\hat e} = (J - R - B G B^\top) \hat e + B M v, \qquad
        y = (I - D G) B^\top \hat e + D M v, \qquad G = M K .

    For :math:`K = C_m^\top L C_m` with :math:`L + L^\top \succ 0` and D skew,
    :math:`\operatorname{sym}(G) \succeq 0`: the loop stays dissipative.  This is the
    observer error system (v = 0, output ỹ) and, with :math:`v = u + C_m^\top L y_m`,
    the observer itself.

    Attributes
    ----------
    system : DiscretePHS
    K, gain : ndarray
        K and G = (I + K D)⁻¹ K.
    A, B, C, D : ndarray
        Descriptor matrices of the loop: E ê' = A ê + B v, y = C ê + D v.
    """

    system: DiscretePHS
    K: np.ndarray
    gain: np.ndarray
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray

    @property
    def E(self) -> np.ndarray:
        """Mass matrix (that of the open system)."""
        return self.system.E

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary: the system and the feedback matrix."""
        return {"system": self.system.to_dict(), "K": self.K.tolist()}

    def __repr__(self) -> str:
        return f"ClosedLoop({self.system!r}, rank K={int(np.linalg.matrix_rank(self.K))})"

    def __str__(self) -> str:
        return f"closed loop u = v - K y around the {self.system}"

    def _repr_html_(self) -> str:
        return html_table((), [("system", repr(self.system)), ("K", self.K.tolist())])


def feedback_matrix(C_m: np.ndarray, L: np.ndarray, n_outputs: int) -> np.ndarray:
    """Return K = C_mᵀ L C_m, checking shapes and L + Lᵀ ≻ 0.

    Examples
    --------
    >>> feedback_matrix(np.array([[0.0, 1.0]]), np.array([[2.0]]), 2)
    array([[0., 0.],
           [0., 2.]])
    """
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    q = C.shape[0]
    check_shape("C_m", C, (q, n_outputs))
    Lm = np.atleast_2d(np.asarray(L, dtype=float))
    check_shape("L", Lm, (q, q))
    if not np.all(np.isfinite(Lm)):
        raise ObserverError("L must be finite")
    if q:
        require_definite("L + L^T", Lm + Lm.T, ObserverError)
    return np.asarray(C.T @ Lm @ C)
