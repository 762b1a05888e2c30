r"""Weak forms of the distributed term :math:`P_0(z)\,e` for the discretizations.

:math:`P_0` (damping and coupling along the domain) may depend on z
(:class:`~phdesign.numeric.bridge.NumericModel`, ``P0``).  Each discretization asks this
module for the matrix of its term, so that the quadrature lives in one place:

* Galerkin (:mod:`phdesign.numeric.discretization.galerkin`): with the efforts
  :math:`e = \Psi \hat e` and Gauss nodes :math:`z_q`, weights :math:`w_q`,

  .. math::

      A_0 = \int_a^b \Psi^\top P_0(z) \Psi\, dz \approx
      \sum_q w_q\, \Psi(z_q)^\top P_0(z_q) \Psi(z_q),

  exact for polynomial :math:`P_0` of degree below :math:`2 n_q - 2p`; the dissipation
  is :math:`R_0 = -\operatorname{sym}(A_0) \succeq 0` because each node contributes
  :math:`-w_q \Psi^\top \operatorname{sym}(P_0(z_q)) \Psi \succeq 0`, so the discrete system
  stays port-Hamiltonian whatever the quadrature error.
* Staggered finite differences (:mod:`phdesign.numeric.discretization.staggered`): nodal values,
  :math:`P_0` evaluated at each node of the two grids, the cross blocks at the nodes of
  the first grid through the averaging operator :math:`\Pi`.  For a constant
  :math:`P_0` this is the scheme of Trenchant et al. unchanged.

Examples
--------
>>> import numpy as np
>>> from phdesign.numeric.bridge import NumericModel, constant_H
>>> nm = NumericModel("d", (0.0, 1.0), 1, 1, (np.zeros((1, 1)), np.ones((1, 1))),
...                   constant_H([[1.0]]), np.array([[0.0, 1.0]]), np.array([[1.0, 0.0]]),
...                   P0=lambda z: -np.asarray(z).reshape(-1, 1, 1))
>>> z, w = np.array([0.5]), np.array([1.0])        # one-point rule: -z at 0.5
>>> galerkin_p0(nm, z, w, np.ones((1, 1)))
array([[-0.5]])
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from phdesign.numeric.bridge import NumericModel

__all__ = ["galerkin_p0", "staggered_p0"]


def galerkin_p0(nm: NumericModel, z: np.ndarray, w: np.ndarray, V: np.ndarray) -> np.ndarray:
    r"""Return :math:`A_0 = \sum_q w_q \Psi(z_q)^\top P_0(z_q) \Psi(z_q)`, ``(n nb, n nb)``.

    Parameters
    ----------
    nm : NumericModel
    z, w : ndarray (nq,)
        Quadrature nodes and weights on the model's interval.
    V : ndarray (nq, nb)
        The scalar basis at the nodes; the effort basis is :math:`I_n \otimes V`
        (component-major, as in :mod:`phdesign.numeric.discretization.galerkin`).
    """
    P0 = nm.P0_at(z)  # (nq, n, n)
    n, nb = nm.size, V.shape[1]
    A0 = np.einsum("q,qa,qij,qb->iajb", w, V, P0, V).reshape(n * nb, n * nb)
    return np.asarray(A0)


def staggered_p0(
    nm: NumericModel,
    groups: tuple[Sequence[int], Sequence[int]],
    grids: tuple[np.ndarray, np.ndarray],
    weights: tuple[np.ndarray, np.ndarray],
    Pi: np.ndarray,
) -> np.ndarray:
    r"""Return the weak form :math:`K_0` of :math:`P_0 e` on the two staggered grids.

    Parameters
    ----------
    nm : NumericModel
    groups : (p, q)
        0-based state components of each grid.
    grids, weights : (ndarray, ndarray)
        Nodes and weights of the p grid and of the q grid (``m`` each).
    Pi : ndarray (m, m)
        Averaging from q values to p nodes.

    Returns
    -------
    ndarray (n m, n m)
        Layout ``[p block (node-major), q block (node-major)]``; its skew part goes to
        J and minus its symmetric part to R.
    """
    p, q = (list(g) for g in groups)
    (zp, zq), (wp, wq) = grids, weights
    m, r = zp.size, len(p)
    P0p, P0q = nm.P0_at(zp), nm.P0_at(zq)
    dim = 2 * r * m
    sp, sq = slice(0, r * m), slice(r * m, dim)
    K0 = np.zeros((dim, dim))

    def block_diagonal(weights: np.ndarray, values: np.ndarray) -> np.ndarray:
        out = np.zeros((r * m, r * m))
        for j in range(m):
            out[j * r : (j + 1) * r, j * r : (j + 1) * r] = weights[j] * values[j]
        return out

    K0[sp, sp] = block_diagonal(wp, P0p[:, p][:, :, p])
    K0[sq, sq] = block_diagonal(wq, P0q[:, q][:, :, q])
    WPi = np.diag(wp) @ Pi  # cross terms at the p nodes
    K0[sp, sq] = np.einsum("ij,iab->iajb", WPi, P0p[:, p][:, :, q]).reshape(r * m, r * m)
    K0[sq, sp] = np.einsum("ij,ist->jsit", WPi, P0p[:, q][:, :, p]).reshape(r * m, r * m)
    return K0
