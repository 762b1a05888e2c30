r"""The problem's own scales, and the same problem in dimensionless form.

Tolerances such as "agree to 1e-10" or "a relative gap of 1e-3" mean nothing until the
problem says what 1 is.  A string of wave speed 1e-8 m/s has eigenvalues of size 1e-8 1/s,
and an absolute test of 1e-10 then calls everything converged; on an interval of length
1e300 the orthonormal polynomials and their derivatives underflow.  So the spectrum is
computed on the *dimensionless* model and scaled back:

.. math::

    z = a + \ell z', \qquad t = t' / s, \qquad x' = S x, \qquad e = S e',

with the length :math:`\ell = b - a`, the diagonal effort scale
:math:`S = \operatorname{diag}(\bar H_{ii})^{1/2}` (:math:`\bar H` the mean of H over the
interval: then :math:`H' = S^{-1} H S^{-1}` has unit diagonal and the energy density is
unchanged, :math:`x'^\top H' x' = x^\top H x`) and the rate

.. math::

    s = \max_z \rho\big(P_N H(z)\big) / \ell^N

(for N = 1 the largest wave speed over the length, for the beam
:math:`\sqrt{EI/\rho}/\ell^2`).  The PDE keeps its form with
:math:`P'_k = S P_k S / (s \ell^k)` and :math:`H'(z') = S^{-1} H(a + \ell z') S^{-1}`;
its energy is :math:`E' = E / \ell` and obeys :math:`dE'/dt' = u^\top y / (s \ell)`, so the
dimensionless ports are

.. math::

    u' = U D v' / \sigma, \quad y' = Y D v' / \sigma, \quad \sigma = \sqrt{s \ell},
    \quad D = \operatorname{diag}\big(S_{ii} \ell^{-k}\big) \text{ over the traces }
    e_i^{(k)},

and any output feedback :math:`\tilde u = -K \tilde y` reads the same,
:math:`\tilde u' = -K \tilde y'`: the closed system's eigenvalues are exactly
:math:`\lambda = s \lambda'`.  The port identities survive the change (it is a congruence
of the energy pairing), so every discretization applies to the dimensionless model
unchanged.

The natural size of a gain follows from the same scales: input i and output j carry
:math:`\sigma_{u,i} = \|U_i D\|_\infty` and :math:`\sigma_{y,j} = \|Y_j D\|_\infty`, and a
gain from output j to input j is "of order one" at :math:`\sigma_{u,j} / \sigma_{y,j}`;
for the string with the damper at its end that is its impedance :math:`\sqrt{\rho T}`,
the gain of the matched (reflection-free) damper.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from phdesign.core.cache import MODEL_WORK
from phdesign.numeric.boundary import scaled_boundaries
from phdesign.numeric.bridge import NumericModel, trace_index

__all__ = ["ProblemScales", "dimensionless_model", "problem_scales"]

_SAMPLES = 33  # points at which H is sampled for its mean and for the rate


@dataclass(frozen=True)
class ProblemScales:
    r"""Length, rate and port scales of a model (module docstring).

    Attributes
    ----------
    length : float
        :math:`\ell = b - a`.
    rate : float
        :math:`s = \max_z \rho(P_N H(z)) / \ell^N`, in 1/time: eigenvalues are measured
        against it.
    effort : ndarray
        The diagonal of S (one entry per component of e).
    input_scale, output_scale : ndarray
        :math:`\sigma_u` and :math:`\sigma_y`, one entry per external port (the ports the
        plant's own feedback closes are not sensed, and have none).

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> sc = problem_scales(to_numeric(load_builtin("wave"), {"rho": 4, "T": 9}))
    >>> round(sc.rate, 12), sc.gain_scale(np.array([[0.0, 1.0]])).round(12).tolist()
    (1.5, [6.0])
    """

    length: float
    rate: float
    effort: np.ndarray
    input_scale: np.ndarray
    output_scale: np.ndarray

    def gain_scale(self, C_m: np.ndarray) -> np.ndarray:
        r"""Natural size of each diagonal entry of L for the sensors ``C_m`` (q,).

        Row a of C_m weights the outputs with :math:`|c_a|`; its gain feeds the inputs
        along :math:`c_a^\top`, so the scale is
        :math:`(|c_a| \cdot \sigma_u) / (|c_a| \cdot \sigma_y)`.
        """
        C = np.abs(np.atleast_2d(np.asarray(C_m, dtype=float)))
        return np.asarray((C @ self.input_scale) / (C @ self.output_scale))


def _trace_scales(nm: NumericModel, effort: np.ndarray, length: float) -> np.ndarray:
    N, n = nm.order, nm.size
    D = np.zeros(2 * N * n)
    for side in ("b", "a"):
        for k in range(N):
            for i in range(n):
                D[trace_index(i + 1, k, side, N, n)] = effort[i] * length**-k
    return D


def problem_scales(nm: NumericModel) -> ProblemScales:
    """Return the :class:`ProblemScales` of ``nm`` (module docstring)."""
    a, b = nm.interval
    length = float(b - a)
    z = a + length * np.linspace(0.0, 1.0, _SAMPLES)
    Hs = nm.H_at(z)
    effort = np.sqrt(np.mean(np.diagonal(Hs, axis1=1, axis2=2), axis=0))
    speeds = np.abs(np.linalg.eigvals(nm.P[nm.order][None, :, :] @ Hs))
    rate = float(np.max(speeds)) / length**nm.order
    D = _trace_scales(nm, effort, length)
    # the ports a sensor set indexes are the external ones: the plant's own feedback has
    # closed the rest (bridge.NumericModel.n_ports), in the order of feedback.close_ports
    closed = set() if nm.feedback is None else {int(c) for c in nm.feedback.closed}
    closed |= {j for b in nm.boundary for j in b.joined}
    external = [j for j in range(nm.order * nm.size) if j not in closed]
    # a boundary system's own ports scale as u = sigma u', y = sigma y' (numeric.boundary)
    extra = np.full(sum(b.n_external for b in nm.boundary), np.sqrt(rate * length))
    return ProblemScales(
        length=length,
        rate=rate,
        effort=effort,
        input_scale=np.concatenate([np.max(np.abs(nm.U * D), axis=1)[external], extra]),
        output_scale=np.concatenate([np.max(np.abs(nm.Y * D), axis=1)[external], extra]),
    )


def dimensionless_model(nm: NumericModel) -> tuple[NumericModel, ProblemScales]:
    r"""Return the model in dimensionless form on [0, 1], and its scales.

    The eigenvalues of any closed loop :math:`\tilde u = -K \tilde y` of the returned model
    are those of ``nm`` divided by ``scales.rate`` (module docstring).

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> nd, sc = dimensionless_model(to_numeric(load_builtin("wave"), {"rho": 1e8, "T": 1e-8}))
    >>> nd.interval, sc.rate, nd.H_at(0.5)[0].round(12).tolist()
    ((0.0, 1.0), 1e-08, [[1.0, 0.0], [0.0, 1.0]])

    It is made once per model (:data:`~phdesign.core.cache.MODEL_WORK`): its
    discretizations are then built once too.
    """
    return MODEL_WORK.get(nm, "dimensionless", lambda: _dimensionless_model(nm))


def _dimensionless_model(nm: NumericModel) -> tuple[NumericModel, ProblemScales]:
    sc = problem_scales(nm)
    a = nm.interval[0]
    length, rate = sc.length, sc.rate
    S = np.diag(sc.effort)
    Sinv = np.diag(1.0 / sc.effort)
    P = tuple(S @ Pk @ S / (rate * length**k) for k, Pk in enumerate(nm.P))
    D = _trace_scales(nm, sc.effort, length)
    sigma = np.sqrt(rate * length)

    def H_dimensionless(zeta: np.ndarray) -> np.ndarray:
        zz = np.atleast_1d(np.asarray(zeta, dtype=float))
        return np.asarray(Sinv @ nm.H_at(a + length * zz) @ Sinv)

    P0_dimensionless = None
    if nm.P0 is not None:  # P0(z): scaled as the constant P0 is, at z = a + length zeta
        P0_of_z = nm.P0

        def P0_dimensionless(zeta: np.ndarray) -> np.ndarray:
            zz = np.atleast_1d(np.asarray(zeta, dtype=float))
            return np.asarray(S @ P0_of_z(a + length * zz) @ S / rate)

    dimensionless = NumericModel(
        name=nm.name,
        interval=(0.0, 1.0),
        order=nm.order,
        size=nm.size,
        P=P,
        H=H_dimensionless,
        U=nm.U * D / sigma,
        Y=nm.Y * D / sigma,
        input_labels=nm.input_labels,
        output_labels=nm.output_labels,
        state_names=nm.state_names,
        displacement=None,
        H_constant=nm.H_constant,
        # u = U v and y = Y v both scale by 1/sigma, so u_c = -K y_c keeps its K
        feedback=nm.feedback,
        P0=P0_dimensionless,
        boundary=scaled_boundaries(nm.boundary, rate),
    )
    return dimensionless, sc
