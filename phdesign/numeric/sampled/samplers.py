r"""Sampled-data observers: samplers and the continuous observer they sample.

A controller sees the plant's outputs through a sampler at period :math:`\Delta t`, and
holds its own inputs u over each period (zero-order hold). Two samplers are modelled:

``"average"`` (the default: an integrate-and-dump front end, which is what an
    anti-aliasing filter approximates)
    :math:`\bar y_k = \frac{1}{\Delta t}\int_{t_k}^{t_k + \Delta t} y_m(t)\,dt`, known at
    :math:`t_{k+1}`. The observer step from :math:`t_k` to :math:`t_{k+1}` is computed at
    :math:`t_{k+1}`, when :math:`\bar y_k` has arrived. The observer is the exact
    sampled-data observer of :meth:`ObserverModel.averaged
    <phdesign.numeric.sampled.period_maps.ObserverModel.averaged>`: its model runs with
    the correction held over the period, and the correction compares the measured mean
    with the exact mean of the model's own outputs over the same period. On a plant equal
    to a Galerkin observer's model the error energy never increases, whatever the period
    (the proof is in :mod:`phdesign.numeric.sampled.period_maps`), and a perfect
    estimate stays perfect.
``"point"``
    :math:`y_m(t_k)`, held over :math:`[t_k, t_{k+1})` (zero-order hold). The continuous
    observer :math:`\dot{\hat x} = A_o \hat x + B_o v`, :math:`v = (u; y_m)`, with v held,
    is advanced exactly by :math:`\hat x_{k+1} = A_d \hat x_k + B_d v_k`,
    :math:`[A_d\ B_d]` the top block row of
    :math:`\exp\left(\begin{smallmatrix} A_o & B_o \\ 0 & 0\end{smallmatrix}\right)\Delta t`
    (:func:`hold_discretization`).

:meth:`ContinuousObserver.sampled` returns either discrete observer; the outputs of step
k are the estimate at :math:`t_k`.

Plant and observer run together, continuous or sampled: :mod:`phdesign.numeric.sampled.runs`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from phdesign.core.errors import NumericError, check_shape
from phdesign.numeric.checks import check_sampling
from phdesign.numeric.discretization.functionals import Functional
from phdesign.numeric.discretization.phs import DiscretePHS, feedback_matrix
from phdesign.numeric.discretization.points import point_rows
from phdesign.numeric.sampled.period_maps import (
    ObserverModel,
    Realization,
    SampledPlant,
    hold_discretization,
    sample_plant,
)
from phdesign.numeric.signals import estimate_descriptions, input_descriptions

__all__ = [
    "ContinuousObserver",
    "SampledPlant",
    "default_initial_state",
    "hold_discretization",
    "sample_plant",
    "sensor_names",
]


def displacement_label(z: float) -> str:
    """Return the name of the output ``w(z)``: the point with 6 significant digits.

    >>> displacement_label(0.5), displacement_label(1.0)
    ('w(0.5)', 'w(1)')
    """
    return f"w({z:g})"


def _point_output(point: float | Functional) -> Functional:
    """Return a point output: a number is the displacement ``w`` there."""
    if isinstance(point, Functional):
        return point
    z = float(point)
    return Functional(displacement_label(z), "displacement", point=z)


def sensor_names(C_m: np.ndarray) -> tuple[str, ...]:
    """``y<i>`` for a row of C_m that picks output i, ``y_m<j>`` for a combination.

    Examples
    --------
    >>> sensor_names(np.array([[0, 0, 1, 0], [0, 0, 0, 1], [1, 1, 0, 0]]))
    ('y3', 'y4', 'y_m3')
    """
    names = []
    for j, row in enumerate(np.atleast_2d(C_m)):
        hits = np.flatnonzero(row)
        unit = hits.size == 1 and row[hits[0]] == 1
        names.append(f"y{hits[0] + 1}" if unit else f"y_m{j + 1}")
    return tuple(names)


@dataclass(frozen=True)
class ContinuousObserver:
    r"""A continuous observer :math:`\dot{\hat x} = A\hat x + Bv`, :math:`\hat y = C\hat x + Dv`.

    Parameters
    ----------
    A, B, C, D : ndarray
        The realization; v = (u; y_m), outputs ŷ of every model output then the
        performance points.
    energy_matrix : ndarray
        Q with :math:`\hat H = \tfrac12 \hat x^\top Q \hat x`.
    basis : ndarray
        V mapping the state to the efforts of ``discrete``: ê ≈ V x̂ (identity for a
        Galerkin observer, the kept subspace after a reduction).
    discrete : DiscretePHS
        The discretization it comes from.
    model : ObserverModel
        The model the observer runs and its output injection, in its coordinates (what
        the ``average`` sampler's discretization needs).
    inputs, outputs : tuple of str
        Signal names.
    performance : tuple of int
        Indices of the performance outputs in ``outputs``.
    points : tuple of Functional
        The point outputs, ``w(z)`` or a named field such as ``rotation(1)``
        (:mod:`phdesign.numeric.discretization.points`); empty for the model's outputs.
    reduction : str
        ``"none"``, ``"modal"`` or ``"balanced"``.
    input_descriptions, output_descriptions : tuple of str
        What each signal is, as a trace of the model (``y3 = e1'(1)``,
        :mod:`phdesign.numeric.signals`); empty when unknown.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    energy_matrix: np.ndarray
    basis: np.ndarray = field(repr=False)
    discrete: DiscretePHS = field(repr=False)
    model: ObserverModel = field(repr=False)
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    performance: tuple[int, ...]
    points: tuple[Functional, ...] = ()
    reduction: str = "none"
    input_descriptions: tuple[str, ...] = ()
    output_descriptions: tuple[str, ...] = ()

    @property
    def order(self) -> int:
        """Number of states."""
        return int(self.A.shape[0])

    @property
    def n_plant_inputs(self) -> int:
        """Number of plant inputs u at the head of v."""
        return int(self.discrete.n_ports)

    @classmethod
    def from_discretization(
        cls,
        d: DiscretePHS,
        C_m: np.ndarray,
        L: np.ndarray,
        points: Sequence[float | Functional] = (),
    ) -> ContinuousObserver:
        r"""Build the observer of :math:`\hat u = u + C_m^\top L (y_m - \hat y_m)` on ``d``.

        With :math:`K = C_m^\top L C_m` and :math:`M = (I + K D)^{-1}` (the feedthrough
        loop solved), :math:`\hat u = M (u + C_m^\top L y_m - K B^\top \hat e)`, hence in
        the efforts ê of :math:`E \dot{\hat e} = (J - R)\hat e + B \hat u`:

        .. math::

            A = E^{-1}(J - R - B M K B^\top), \quad B_o = E^{-1} B M [I,\ C_m^\top L],
            \quad C_y = B^\top - D M K B^\top, \quad D_y = D M [I,\ C_m^\top L],

        (:meth:`ObserverModel.continuous
        <phdesign.numeric.sampled.period_maps.ObserverModel.continuous>`) and the
        point outputs :math:`f(z) = W_f(z)\hat e` (the displacement at a number, a named
        field given as a :class:`Functional`).
        """
        C = np.atleast_2d(np.asarray(C_m, dtype=float))
        m = d.n_ports
        model = ObserverModel.from_discretization(d, C, L)
        closed = model.continuous()
        outputs = [f"yhat{i + 1}" for i in range(m)]
        rows, feed = [closed.C], [closed.D]
        pts = tuple(_point_output(p) for p in points)
        if pts:
            if any(f.field_name == "w" for f in pts) and d.displacement_basis is None:
                raise NumericError(
                    f"model {d.model.name!r} has no displacement: drop the displacement points"
                )
            rows.append(point_rows(d, pts))
            feed.append(np.zeros((len(pts), closed.B.shape[1])))
            outputs += [f.name for f in pts]
        performance = tuple(range(m, m + len(pts))) if pts else tuple(range(m))
        return cls(
            A=closed.A,
            B=closed.B,
            C=np.vstack(rows),
            D=np.vstack(feed),
            energy_matrix=d.E.copy(),
            basis=np.eye(d.dim),
            discrete=d,
            model=model,
            inputs=tuple(f"u{i + 1}" for i in range(m)) + sensor_names(C),
            outputs=tuple(outputs),
            performance=performance,
            points=pts,
            input_descriptions=input_descriptions(d.model, C),
            output_descriptions=estimate_descriptions(d.model, pts),
        )

    def project(self, V: np.ndarray, W: np.ndarray, reduction: str) -> ContinuousObserver:
        r"""Petrov-Galerkin reduction :math:`x = V x_r`, :math:`\dot x_r = W^\top(A V x_r + B v)`.

        ``W^T V = I`` is required; the energy matrix becomes :math:`V^\top Q V`, and the
        model the observer runs is projected alike (:meth:`ObserverModel.project
        <phdesign.numeric.sampled.period_maps.ObserverModel.project>`).
        """
        check_shape("W", W, V.shape)
        return ContinuousObserver(
            A=W.T @ self.A @ V,
            B=W.T @ self.B,
            C=self.C @ V,
            D=self.D.copy(),
            energy_matrix=V.T @ self.energy_matrix @ V,
            basis=self.basis @ V,
            discrete=self.discrete,
            model=self.model.project(V, W),
            inputs=self.inputs,
            outputs=self.outputs,
            performance=self.performance,
            points=self.points,
            reduction=reduction,
            input_descriptions=self.input_descriptions,
            output_descriptions=self.output_descriptions,
        )

    def with_gain(self, L: np.ndarray) -> ContinuousObserver:
        r"""Return this observer with the gain L instead (same model, sensors and outputs).

        The model's closure :meth:`ObserverModel.continuous
        <phdesign.numeric.sampled.period_maps.ObserverModel.continuous>` with L, the point
        rows kept; refused as :func:`~phdesign.numeric.discretization.phs.feedback_matrix`
        refuses a gain (shape, :math:`L + L^\top \succ 0`).
        """
        Lm = np.atleast_2d(np.asarray(L, dtype=float))
        feedback_matrix(self.model.C_m, Lm, self.n_plant_inputs)
        model = dataclasses.replace(self.model, L=Lm)
        closed, m = model.continuous(), self.n_plant_inputs
        return dataclasses.replace(
            self,
            A=closed.A,
            B=closed.B,
            C=np.vstack([closed.C, self.C[m:]]),
            D=np.vstack([closed.D, self.D[m:]]),
            model=model,
        )

    def sampled(self, dt: float, sampler: str, period: SampledPlant | None = None) -> Realization:
        r"""Return the discrete observer for ``sampler`` at period ``dt`` (module docstring).

        ``period``: the model's own one-period map under the ``average`` sampler
        (:func:`sample_plant` of ``model``), when the caller has it.

        ``"point"``: this observer with v held (:func:`hold_discretization`), outputs
        :math:`C\hat x_k + Dv_k`. ``"average"``: the exact sampled-data observer
        (:meth:`ObserverModel.averaged
        <phdesign.numeric.sampled.period_maps.ObserverModel.averaged>`), with the
        model's outputs at :math:`t_k` and the performance rows of C below them.
        """
        dt = check_sampling(dt, sampler)
        if sampler == "point":
            A_d, B_d = hold_discretization(self.A, self.B, dt)
            return Realization(A_d, B_d, self.C.copy(), self.D.copy())
        closed = self.model.averaged(dt, period)
        m = self.n_plant_inputs
        extra = self.C[m:]
        return Realization(
            A=closed.A,
            B=closed.B,
            C=np.vstack([closed.C, extra]),
            D=np.vstack([closed.D, np.zeros((extra.shape[0], closed.D.shape[1]))]),
        )


def default_initial_state(
    size: int, interval: tuple[float, float]
) -> Callable[[np.ndarray], np.ndarray]:
    r"""Every state component :math:`x_i(z) = (z - a)/(b - a) - 0.9`.

    The paper's beam curvature :math:`z - 0.9`, applied to every component: it violates
    the boundary conditions, so the plant's high frequencies are excited (the hard case
    for a sampler), and it is the same for every model.
    """
    a, b = interval

    def x0(z: np.ndarray) -> np.ndarray:
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        return np.repeat(((zz - a) / (b - a) - 0.9)[:, None], size, axis=1)

    return x0
