r"""Export of plant, observer and error system as ``control.StateSpace`` objects.

All three are written in standard form with the discrete efforts ê as states
(:mod:`phdesign.numeric.discretize`): from :math:`E \dot{\hat e} = (J - R)\hat e + B u`,

* plant: :math:`A = E^{-1}(J - R)`, :math:`B_s = E^{-1} B`, :math:`C = B^\top`, :math:`D`;
  inputs ``u1..``, outputs ``y1..``.
* observer: inputs (u, y_m), outputs (ŷ, ê_obs).  With :math:`K = C_m^\top L C_m`,
  :math:`M = (I + K D)^{-1}`: :math:`\hat u = M (u + C_m^\top L y_m - K B^\top \hat e_{obs})`,
  so :math:`A_o = E^{-1}(J - R - B M K B^\top)`, :math:`B_o = E^{-1} B M [I, C_m^\top L]`,
  :math:`C_o = [B^\top - D M K B^\top; I]`, :math:`D_o = [D M [I, C_m^\top L]; 0]`.
* error system: :math:`A_e = E^{-1}(J - R - B M K B^\top)`, no input, output ỹ.

``control`` is imported lazily, inside the functions, so importing phdesign never pays
for it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from phdesign.numeric.phs import DiscretePHS, feedback_matrix

__all__ = ["error_statespace", "observer_statespace", "plant_statespace", "state_labels"]


def state_labels(d: DiscretePHS, prefix: str = "") -> list[str]:
    """Names of the discrete states: ``<prefix>e<i>[<j>]`` (effort i, basis index/node j)."""
    n = d.model.size
    per = d.dim // n
    if d.method == "galerkin":
        return [f"{prefix}e{i + 1}[{j}]" for i in range(n) for j in range(per)]
    p, q = d.info["groups"]
    r = len(p)
    labels = [f"{prefix}e{p[c] + 1}[{j}]" for j in range(per) for c in range(r)]
    labels += [f"{prefix}e{q[c] + 1}[{j}]" for j in range(per) for c in range(r)]
    return labels


def _ss(A: Any, B: Any, C: Any, D: Any, **names: Any) -> Any:
    import control

    return control.ss(A, B, C, D, **names)


def plant_statespace(d: DiscretePHS, name: str = "plant") -> Any:
    """Return the discretized plant as ``control.StateSpace`` (inputs u, outputs y)."""
    m = d.n_ports
    A = np.linalg.solve(d.E, d.J - d.R)
    B = np.linalg.solve(d.E, d.B)
    return _ss(
        A,
        B,
        d.B.T.copy(),
        d.D.copy(),
        inputs=[f"u{i + 1}" for i in range(m)],
        outputs=[f"y{i + 1}" for i in range(m)],
        states=state_labels(d),
        name=name,
    )


def _observer_parts(d: DiscretePHS, C_m: np.ndarray, L: np.ndarray):  # type: ignore[no-untyped-def]
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    Lm = np.atleast_2d(np.asarray(L, dtype=float))
    K = feedback_matrix(C, Lm, d.n_ports)
    M = np.linalg.inv(np.eye(d.n_ports) + K @ d.D)
    return C, Lm, K, M


def observer_statespace(
    d: DiscretePHS, C_m: np.ndarray, L: np.ndarray, name: str = "observer"
) -> Any:
    """Return the observer as ``control.StateSpace``: inputs (u, y_m), outputs (ŷ, ê_obs)."""
    C, Lm, K, M = _observer_parts(d, C_m, L)
    m, q, n = d.n_ports, C.shape[0], d.dim
    In = np.hstack([np.eye(m), C.T @ Lm])  # û = M (In [u; y_m] - K Bᵀ ê)
    A = np.linalg.solve(d.E, d.J - d.R - d.B @ M @ K @ d.B.T)
    B = np.linalg.solve(d.E, d.B @ M @ In)
    Cy = d.B.T - d.D @ M @ K @ d.B.T
    Dy = d.D @ M @ In
    Cout = np.vstack([Cy, np.eye(n)])
    Dout = np.vstack([Dy, np.zeros((n, m + q))])
    return _ss(
        A,
        B,
        Cout,
        Dout,
        inputs=[f"u{i + 1}" for i in range(m)] + [f"y_m{i + 1}" for i in range(q)],
        outputs=[f"y_hat{i + 1}" for i in range(m)] + state_labels(d, "hat_"),
        states=state_labels(d, "hat_"),
        name=name,
    )


def error_statespace(d: DiscretePHS, C_m: np.ndarray, L: np.ndarray, name: str = "error") -> Any:
    """Return the observer error system as ``control.StateSpace`` (no input, output ỹ)."""
    _C, _Lm, K, M = _observer_parts(d, C_m, L)
    m, n = d.n_ports, d.dim
    A = np.linalg.solve(d.E, d.J - d.R - d.B @ M @ K @ d.B.T)
    Cy = d.B.T - d.D @ M @ K @ d.B.T
    return _ss(
        A,
        np.zeros((n, 0)),
        Cy,
        np.zeros((m, 0)),
        inputs=[],
        outputs=[f"y_err{i + 1}" for i in range(m)],
        states=state_labels(d, "err_"),
        name=name,
    )
