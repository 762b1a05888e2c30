r"""Exact discretizations under a sampler: the plant it measures, and the observer it feeds.

Three exact one-period maps, each read off one matrix exponential of an augmented matrix:

* :func:`hold_discretization`: :math:`\dot x = A x + B v` with v held over the period
  (the plant's inputs; the continuous observer under the ``point`` sampler).
* :func:`sample_plant`: a plant under a sampler, with the exact mean of its outputs over
  the period for the ``average`` sampler (Van Loan's augmented exponential).
* :meth:`ObserverModel.averaged`: the observer of the ``average`` sampler, the exact
  sampled-data observer below.

**The averaged observer.** The observer runs a copy of the model,
:math:`E\dot{\hat e} = (J - R)\hat e + B\hat u`,
:math:`\hat y = B^\top\hat e + D\hat u`; in its coordinates
:math:`\dot{\hat x} = F\hat x + G\hat u`, :math:`\hat y = H\hat x + D\hat u`
(:class:`ObserverModel`: :math:`F = E^{-1}(J - R)`, :math:`G = E^{-1}B`,
:math:`H = B^\top` for a Galerkin observer). The ``average`` front end delivers
:math:`\bar y_{m,k} = C_m\bar y_k`, the mean of the sensors over
:math:`[t_k, t_{k+1}]`, at :math:`t_{k+1}`. Over that period the observer's input is
held, :math:`\hat u = u_k + w_k`, and the correction compares interval *means* on both
sides:

.. math::

    w_k = C_m^\top L\,(\bar y_{m,k} - C_m \bar{\hat y}_k), \qquad
    \bar{\hat y}_k = \frac{1}{\Delta t}\int_{t_k}^{t_{k+1}} \hat y\,dt
    = C_s \hat x_k + D_s \hat u_k,

with :math:`\hat x_{k+1} = \Phi\hat x_k + \Gamma\hat u_k` and
:math:`(\Phi, \Gamma, C_s, D_s)` from :func:`sample_plant` applied to the model. The
correction appears on both sides (through :math:`D_s`); with
:math:`K = C_m^\top L C_m`, :math:`(I + K D_s)\hat u_k = u_k + C_m^\top L\bar y_{m,k}
- K C_s \hat x_k`, hence, with :math:`M = (I + K D_s)^{-1}` and
:math:`v_k = (u_k; \bar y_{m,k})`,

.. math::

    \hat u_k = M\big([I,\ C_m^\top L]\,v_k - K C_s \hat x_k\big), \qquad
    \hat x_{k+1} = (\Phi - \Gamma M K C_s)\,\hat x_k + \Gamma M [I,\ C_m^\top L]\,v_k,

and the outputs at :math:`t_k` are the model's, :math:`\hat y_k = H\hat x_k + D\hat u_k`.
The continuous observer (:meth:`ObserverModel.continuous`) is the same closure with
:math:`(\Phi, \Gamma; C_s, D_s)` replaced by :math:`(F, G; H, D)`, its limit as
:math:`\Delta t \to 0`.

Dissipativity (for a Galerkin observer, :math:`E \succ 0`, :math:`R \succeq 0`,
:math:`D = -D^\top`, which a model's own ``[feedback]`` preserves,
:mod:`phdesign.numeric.discretization.feedback`). *A period is passive.* With :math:`\hat u`
constant,
:math:`\frac{d}{dt}\tfrac12\hat e^\top E\hat e = -\hat e^\top R\hat e + \hat u^\top
B^\top\hat e = -\hat e^\top R\hat e + \hat u^\top\hat y` because
:math:`\hat u^\top D\hat u = 0`; integrating over the period,

.. math::

    H(\hat e_{k+1}) - H(\hat e_k) = -\int_{t_k}^{t_{k+1}}\hat e^\top R\hat e\,dt
    + \Delta t\,\hat u_k^\top \bar{\hat y}_k .

*The loop is solvable.* From :math:`\hat e_k = 0` the identity gives
:math:`\Delta t\,\hat u^\top D_s\hat u \ge 0` for every :math:`\hat u`. If
:math:`(I + K D_s) z = 0`, put :math:`q = D_s z`; then :math:`z = -Kq` and
:math:`0 \le z^\top D_s z = z^\top q = -q^\top K q = -(C_m q)^\top L (C_m q) \le 0`
(:math:`L + L^\top \succ 0`), so :math:`C_m q = 0`, :math:`Kq = 0`, :math:`z = 0`:
:math:`I + K D_s` is invertible for every :math:`\Delta t`.
*The error is dissipated.* Let the plant equal the observer's model. Its input is
:math:`u_k`, so :math:`\tilde e = e - \hat e` solves the same model with the input
:math:`-w_k`, and by linearity :math:`\bar y_k - \bar{\hat y}_k` is the mean of its
output :math:`\bar{\tilde y}_k`; :math:`w_k = K\bar{\tilde y}_k`. The plant's input
cancels: :math:`\tilde e_{k+1} = (\Phi - \Gamma M K C_s)\tilde e_k` exactly (a perfect
estimate stays perfect, whatever u), and

.. math::

    \tilde H_{k+1} - \tilde H_k = -\int_{t_k}^{t_{k+1}}\tilde e^\top R\tilde e\,dt
    - \Delta t\,(C_m\bar{\tilde y}_k)^\top L\,(C_m\bar{\tilde y}_k) \le 0

for *every* :math:`\Delta t`: the sampled error system is dissipative, as the
continuous one is (:math:`\dot{\tilde H} = -\tilde e^\top R\tilde e - \tilde y_m^\top
L\tilde y_m`). What the period costs is visible in the identity: only the *mean* of the
error output is damped, so error modes near the frequencies :math:`2\pi j/\Delta t`,
whose means vanish, decay at their own damping. After a Petrov-Galerkin reduction
(:meth:`ObserverModel.project`) the map is still exact for the reduced model, but the
energy identity, and with it the proof, is lost.

Holding the mean :math:`\bar y_{m,k}` as the input of the *continuous* observer instead
compares it with the observer's output as it evolves inside the period: zero error is
then not invariant (the mismatch is of the order of the output's variation over a
period, large for modes with :math:`|\lambda|\Delta t \gtrsim 1`), and the error energy
can grow.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sl

from phdesign.core.errors import NumericError
from phdesign.numeric.discretization.phs import LOOP_CONDITION, DiscretePHS, feedback_matrix

__all__ = [
    "ObserverModel",
    "Realization",
    "SampledPlant",
    "hold_discretization",
    "sample_plant",
]


def hold_discretization(A: np.ndarray, B: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    r"""Exact discretization of :math:`\dot x = A x + B v` with v held over each step.

    .. math::

        \exp\left(\begin{bmatrix} A & B \\ 0 & 0 \end{bmatrix}\Delta t\right) =
        \begin{bmatrix} A_d & B_d \\ 0 & I \end{bmatrix}.

    Examples
    --------
    >>> Ad, Bd = hold_discretization(np.array([[-2.0]]), np.array([[1.0]]), 0.5)
    >>> exact = np.exp(-1.0), (1 - np.exp(-1.0)) / 2  # e^{a dt}, (e^{a dt} - 1) / a
    >>> bool(np.isclose(Ad[0, 0], exact[0])), bool(np.isclose(Bd[0, 0], exact[1]))
    (True, True)
    """
    n, m = B.shape
    block = np.zeros((n + m, n + m))
    block[:n, :n] = A
    block[:n, n:] = B
    exponential = sl.expm(block * dt)
    return exponential[:n, :n], exponential[:n, n:]


@dataclass(frozen=True)
class SampledPlant:
    r"""One period of a plant under a sampler: :math:`x_{k+1} = \Phi x_k + \Gamma u_k`.

    The sampler reads :math:`C_s x_k + D_s u_k`: :math:`y(t_k)` for ``"point"``, the exact
    mean over :math:`[t_k, t_{k+1}]` for ``"average"`` (:func:`sample_plant`).
    """

    Phi: np.ndarray
    Gamma: np.ndarray
    C_s: np.ndarray
    D_s: np.ndarray


def sample_plant(
    F: np.ndarray, G: np.ndarray, C: np.ndarray, D: np.ndarray, dt: float, sampler: str
) -> SampledPlant:
    r"""Return the exact one-period map and measurement of a plant under ``sampler``.

    For :math:`\dot x = F x + G u`, :math:`y = C x + D u` with u held at :math:`u_k`, the
    state :math:`(x, \xi, u)` with the running integral :math:`\dot\xi = x` obeys a
    linear ODE whose exponential (Van Loan) holds the map and the integral:

    .. math::

        \exp\left(\begin{bmatrix} F & 0 & G \\ I & 0 & 0 \\ 0 & 0 & 0 \end{bmatrix}
        \Delta t\right) = \begin{bmatrix} \Phi & 0 & \Gamma \\ S_x & I & S_u \\
        0 & 0 & I \end{bmatrix}, \qquad
        \bar y_k = \tfrac{1}{\Delta t} C (S_x x_k + S_u u_k) + D u_k .

    Examples
    --------
    The mean of x(t) = exp(-a t) x0 over [0, dt] is x0 (1 - exp(-a dt)) / (a dt):

    >>> s = sample_plant(np.array([[-2.0]]), np.zeros((1, 1)), np.eye(1), np.zeros((1, 1)),
    ...                  0.5, "average")
    >>> bool(np.isclose(s.C_s[0, 0], (1 - np.exp(-1.0)) / 1.0))
    True
    """
    n, m = G.shape
    if sampler == "point":
        Phi, Gamma = hold_discretization(F, G, dt)
        return SampledPlant(Phi, Gamma, C.copy(), D.copy())
    block = np.zeros((2 * n + m, 2 * n + m))
    block[:n, :n] = F
    block[:n, 2 * n :] = G
    block[n : 2 * n, :n] = np.eye(n)
    exponential = sl.expm(block * dt)
    Phi, Gamma = exponential[:n, :n], exponential[:n, 2 * n :]
    S_x, S_u = exponential[n : 2 * n, :n], exponential[n : 2 * n, 2 * n :]
    return SampledPlant(Phi, Gamma, C @ S_x / dt, C @ S_u / dt + D)


@dataclass(frozen=True)
class Realization:
    r"""A closed observer :math:`(A, B, C, D)` driven by :math:`v = (u; y_m)`.

    Continuous (:math:`\dot{\hat x} = A\hat x + Bv`) or one period
    (:math:`\hat x_{k+1} = A\hat x_k + Bv_k`); the outputs :math:`C\hat x + Dv` are the
    model's outputs :math:`\hat y`.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray


@dataclass(frozen=True)
class ObserverModel:
    r"""The model an observer runs and its output injection (module docstring).

    .. math::

        \dot{\hat x} = F\hat x + G\hat u, \quad \hat y = H\hat x + D\hat u, \quad
        \hat u = u + C_m^\top L\,(y_m - C_m \hat y).

    Parameters
    ----------
    F, G, H, D : ndarray
        The model in the observer's coordinates (``D`` the model's feedthrough).
    C_m, L : ndarray
        Sensors and gain.
    """

    F: np.ndarray
    G: np.ndarray
    H: np.ndarray
    D: np.ndarray
    C_m: np.ndarray
    L: np.ndarray

    @classmethod
    def from_discretization(cls, d: DiscretePHS, C_m: np.ndarray, L: np.ndarray) -> ObserverModel:
        r"""Return a Galerkin observer's model: :math:`F = E^{-1}(J - R)`, :math:`G = E^{-1}B`."""
        C = np.atleast_2d(np.asarray(C_m, dtype=float))
        Lm = np.atleast_2d(np.asarray(L, dtype=float))
        feedback_matrix(C, Lm, d.n_ports)  # checks the shapes and L + Lᵀ ≻ 0
        F, G = d.explicit
        return cls(
            F=F,
            G=G,
            H=d.B.T.copy(),
            D=d.D.copy(),
            C_m=C,
            L=Lm,
        )

    def project(self, V: np.ndarray, W: np.ndarray) -> ObserverModel:
        r"""Return the model in coordinates :math:`\hat x = V x_r`, projected by :math:`W^\top`."""
        return ObserverModel(W.T @ self.F @ V, W.T @ self.G, self.H @ V, self.D, self.C_m, self.L)

    def continuous(self) -> Realization:
        """Return the continuous observer: the output injection closed at every instant."""
        return self._close(self.F, self.G, self.H, self.D)

    def averaged(self, dt: float, period: SampledPlant | None = None) -> Realization:
        r"""Return the exact sampled-data observer of the ``average`` sampler at period ``dt``.

        One period of the model with its input held (:func:`sample_plant`, or ``period``
        when the caller has it: it does not depend on the gain), closed by the correction
        that compares interval means (module docstring).

        Examples
        --------
        The integrator :math:`\dot x = \hat u`, :math:`y = x`, gain l: the error map is
        :math:`(1 - l\Delta t/2)/(1 + l\Delta t/2)`, the trapezoidal rule's, below 1 in
        modulus for every period:

        >>> model = ObserverModel(np.zeros((1, 1)), np.eye(1), np.eye(1), np.zeros((1, 1)),
        ...                       np.eye(1), np.array([[4.0]]))
        >>> [round(float(model.averaged(dt).A[0, 0]), 12) for dt in (0.1, 1.0, 100.0)]
        [0.666666666667, -0.333333333333, -0.990049751244]
        """
        s = (
            sample_plant(self.F, self.G, self.H, self.D, dt, "average")
            if period is None
            else period
        )
        return self._close(s.Phi, s.Gamma, s.C_s, s.D_s)

    def _close(
        self,
        evolve_x: np.ndarray,
        evolve_u: np.ndarray,
        measure_x: np.ndarray,
        measure_u: np.ndarray,
    ) -> Realization:
        r"""Close the injection on the measured output :math:`m = m_x\hat x + m_u\hat u`.

        The injection :math:`\hat u = u + C_m^\top L(y_m - C_m m)`, with
        :math:`(m_x, m_u)` = (``measure_x``, ``measure_u``). Solving the loop,
        :math:`\hat u = U_x\hat x + U_v v` with :math:`M = (I + K m_u)^{-1}`,
        :math:`U_x = -MK m_x`, :math:`U_v = M[I,\ C_m^\top L]`; the state goes to
        ``evolve_x`` x̂ + ``evolve_u`` û and the outputs are :math:`H\hat x + D\hat u`.
        """
        m = self.G.shape[1]
        K = feedback_matrix(self.C_m, self.L, m)
        loop = np.eye(m) + K @ measure_u
        condition = float(np.linalg.cond(loop))
        # refused where close() refuses I + K D: never for a Galerkin observer, for which
        # I + K D_s is invertible for every period
        if not condition <= LOOP_CONDITION:
            raise NumericError(
                "the observer's correction loop I + C_m^T L C_m D_s is singular (condition "
                f"number {condition:.3g}, expected at most {LOOP_CONDITION:g}): a reduced "
                "model need not be passive; use the Galerkin observer (`reduction='none'`)"
            )
        inject = np.hstack([np.eye(m), self.C_m.T @ self.L])
        U_x = -np.linalg.solve(loop, K @ measure_x)
        U_v = np.linalg.solve(loop, inject)
        return Realization(
            A=evolve_x + evolve_u @ U_x,
            B=evolve_u @ U_v,
            C=self.H + self.D @ U_x,
            D=self.D @ U_v,
        )
