r"""The noise-driven error system at one resolution, and its stationary statistics.

With the observer's correction solved through the feedthrough by
:meth:`~phdesign.numeric.discretization.phs.DiscretePHS.close`, the error obeys
:math:`E \dot{\tilde e} = A \tilde e + G n` with n unit white noise and
:math:`G = B (I+KD)^{-1} [-C_m^\top L \Sigma_\nu^{1/2}, \Sigma_w^{1/2}]`
(:mod:`phdesign.numeric.noise.figures`); its stationary covariance P solves
:math:`A P E^\top + E P A^\top + G G^\top = 0` (:mod:`phdesign.numeric.noise.lyapunov`)
when the error system is exponentially stable.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from phdesign.numeric.discretization.registry import DiscretePHS, feedback_matrix
from phdesign.numeric.noise.lyapunov import TriangularPencil, triangularize

__all__ = ["ErrorStatistics", "error_statistics", "noise_input"]


def noise_input(
    d: DiscretePHS,
    C_m: np.ndarray,
    L: np.ndarray,
    intensity: np.ndarray,
    input_intensity: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    r"""Return ``(A, G, labels)``: :math:`E \dot{\tilde e} = A \tilde e + G n`, n unit white.

    The columns of G are the sensor channels :math:`-B(I+KD)^{-1} C_m^\top L \sigma_i`
    and the input channels :math:`B (I+KD)^{-1} e_j \sqrt{w_j}` (module docstring);
    channels of zero intensity are left out.
    """
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    Lm = np.atleast_2d(np.asarray(L, dtype=float))
    loop = d.close(feedback_matrix(C, Lm, d.n_ports))
    A, BM = loop.A, loop.B  # B M = B (I + K D)⁻¹
    columns = [-BM @ C.T @ Lm @ np.diag(np.sqrt(intensity))]
    labels = [f"nu{i + 1}" for i in range(C.shape[0])]
    keep = [bool(s > 0) for s in intensity]
    if input_intensity is not None:
        columns.append(BM @ np.diag(np.sqrt(input_intensity)))
        labels += [f"w{j + 1}" for j in range(d.n_ports)]
        keep += [bool(s > 0) for s in input_intensity]
    G = np.hstack(columns)[:, keep]
    return A, G, tuple(label for label, k in zip(labels, keep, strict=True) if k)


@dataclass(frozen=True)
class ErrorStatistics:
    """Stationary statistics of the noise-driven error system at one resolution.

    Attributes
    ----------
    discrete : DiscretePHS
    pencil : TriangularPencil
    covariance : ndarray or None
        Stationary covariance of ẽ (None when the error system is not exponentially stable).
    """

    discrete: DiscretePHS
    pencil: TriangularPencil
    covariance: np.ndarray | None

    @property
    def resolution(self) -> int:
        """The discretization's resolution."""
        return self.discrete.resolution

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of the error system."""
        return self.pencil.eigenvalues

    @property
    def stable(self) -> bool:
        """Whether every eigenvalue lies strictly left of the imaginary axis."""
        return self.covariance is not None

    def variance(self, row: np.ndarray) -> float:
        """Stationary variance of ``row @ ẽ`` (``inf`` without a steady state)."""
        if self.covariance is None:
            return math.inf
        return float(max(row @ self.covariance @ row, 0.0))

    def energy(self) -> float:
        """Return the expected error energy ½ tr(E P) (``inf`` without a steady state)."""
        if self.covariance is None:
            return math.inf
        return 0.5 * float(np.sum(self.discrete.E * self.covariance))


def error_statistics(
    d: DiscretePHS,
    C_m: np.ndarray,
    L: np.ndarray,
    intensity: np.ndarray,
    input_intensity: np.ndarray | None = None,
    triangularization: str = "auto",
) -> ErrorStatistics:
    """Triangularize the noise-driven error system of ``d`` and solve its Lyapunov equation."""
    A, G, _ = noise_input(d, C_m, L, intensity, input_intensity)
    pencil = triangularize(A, d.E, G, triangularization)
    lam = pencil.eigenvalues
    stable = bool(np.all(lam.real < -1e-12 * np.maximum(1.0, np.abs(lam))))
    return ErrorStatistics(d, pencil, pencil.covariance() if stable else None)
