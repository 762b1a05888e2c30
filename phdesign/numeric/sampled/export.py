r"""The observer as an artefact for a controller: sampled, of finite order, verified.

:func:`export_observer` turns a design (model, sensors C_m, gain L) into a
:class:`SampledObserver`, the discrete-time system

.. math::

    \hat x_{k+1} = A \hat x_k + B v_k, \qquad \hat y_k = C \hat x_k + D v_k, \qquad
    v_k = (u_k;\ y_{m,k}), \qquad \hat x_0 = 0,

with the order chosen from accuracy targets (:mod:`phdesign.numeric.sampled.order`), the exact
discretization for the declared sampler (:mod:`phdesign.numeric.sampled.samplers`), and, when
asked, a verification run against a high-resolution plant (:class:`Verification`).

Timing, as a controller runs it (period Δt):

* ``average``: at :math:`t_{k+1}` the front end delivers :math:`\bar y_k`, the mean of
  :math:`y_m` over :math:`[t_k, t_{k+1}]`; call the step with
  :math:`v_k = (u_k; \bar y_k)`, where :math:`u_k` is the input held over that period. It
  writes :math:`\hat y_k`, the estimate at :math:`t_k`, and advances to
  :math:`\hat x_{k+1}`, the estimate at :math:`t_{k+1}` (read it as
  :math:`C \hat x_{k+1}` if the freshest estimate is wanted before the next period ends).
* ``point``: at :math:`t_k` call the step with :math:`v_k = (u_k; y_m(t_k))`; it writes
  the estimate at :math:`t_k` and advances.

Outputs: ``yhat1..`` (every model output), then ``w(z)`` for each displacement point
(the displacement at b by default, e.g. the beam's tip w(1)) and ``rotation(z)`` for each
named field asked for (:mod:`phdesign.numeric.discretization.points`). Energy:
:math:`\hat H = \tfrac12 \hat x^\top Q \hat x`, Q = ``energy_matrix`` (the Galerkin mass
matrix in the efforts, or :math:`V^\top E V` after a reduction x = V x_r).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.checks import EXPORT_FORMATS, positive_number
from phdesign.core.defaults import current
from phdesign.core.errors import ArgumentError, NumericError
from phdesign.core.progress import report
from phdesign.core.text import html_table
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_initial_state, check_periods, check_sampling
from phdesign.numeric.discretization.functionals import Functional
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.points import point_outputs
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.sampled.order import REDUCTIONS, select_order
from phdesign.numeric.sampled.plant_resolution import verification_plant_degree
from phdesign.numeric.sampled.samplers import ContinuousObserver, default_initial_state
from phdesign.numeric.sampled.selection import OrderSelection
from phdesign.numeric.sampled.verification import (
    Verification,
    check_strict,
    plant_gap,
    verify_observer,
    with_plant_gap,
    with_target_check,
)
from phdesign.numeric.signals import signal_lines
from phdesign.numeric.threads import limited_threads

__all__ = [
    "FORMATS",
    "SampledObserver",
    "Verification",
    "displacement_points",
    "export_observer",
    "verify_observer",
]

#: Export formats of :meth:`SampledObserver.write`.
FORMATS = EXPORT_FORMATS


def _matrix(a: np.ndarray) -> list[list[float]]:
    return [[float(x) for x in row] for row in np.atleast_2d(a)]


@dataclass(frozen=True)
class SampledObserver:
    """A discrete-time observer ready for a controller (module docstring).

    Attributes
    ----------
    model : str
    dt : float
        Sampling period in seconds.
    sampler : {"average", "point"}
    A, B, C, D : ndarray
        ``x[k+1] = A x[k] + B v[k]``, ``out[k] = C x[k] + D v[k]``.
    inputs, outputs : tuple of str
        Names of v (plant inputs u1.., then the measured outputs) and of the outputs.
    energy_matrix : ndarray
        Q of the observer's energy ½ x̂ᵀ Q x̂.
    selection : OrderSelection
        How the order was chosen and what was dropped.
    verification : Verification or None
    continuous : ContinuousObserver
        The continuous observer of the same design and order (``point`` steps it with
        its input held; ``average`` runs its model as a sampled-data observer).
    """

    model: str
    dt: float
    sampler: str
    A: np.ndarray = field(repr=False)
    B: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    D: np.ndarray = field(repr=False)
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    energy_matrix: np.ndarray = field(repr=False)
    selection: OrderSelection = field(repr=False)
    verification: Verification | None = field(default=None, repr=False)
    continuous: ContinuousObserver | None = field(default=None, repr=False, compare=False)

    @property
    def order(self) -> int:
        """Number of states N."""
        return int(self.A.shape[0])

    @property
    def x0(self) -> np.ndarray:
        """The initial state: zeros."""
        return np.zeros(self.order)

    def descriptions(self) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """Return what each input and output is (``y3 = e1'(1)``), else their names."""
        c = self.continuous
        if c is None or not c.input_descriptions:
            return self.inputs, self.outputs
        return c.input_descriptions, c.output_descriptions

    @property
    def renumbering(self) -> str | None:
        """How a ``[feedback]`` closure renumbered the ports (:mod:`phdesign.numeric.signals`)."""
        from phdesign.numeric.signals import renumbering

        return None if self.continuous is None else renumbering(self.continuous.discrete.model)

    @property
    def warnings(self) -> tuple[str, ...]:
        """Warnings of the order selection and of the verification."""
        extra = () if self.verification is None else self.verification.warnings
        return self.selection.warnings + extra

    def step(self, x: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One step: returns ``(x[k+1], out[k])`` from ``x[k]`` and ``v[k]``."""
        return self.A @ x + self.B @ v, self.C @ x + self.D @ v

    def run(self, V: np.ndarray, x0: np.ndarray | None = None) -> np.ndarray:
        """Return the outputs ``(nk, n_outputs)`` for inputs ``V`` of shape ``(nk, n_inputs)``."""
        V = np.atleast_2d(np.asarray(V, dtype=float))
        x = self.x0 if x0 is None else np.asarray(x0, dtype=float)
        out = np.empty((V.shape[0], len(self.outputs)))
        for k, v in enumerate(V):
            x, out[k] = self.step(x, v)
        return out

    def signal_names(self) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """Return the inputs' and outputs' names as python-control takes them.

        python-control refuses '.' in a signal name: ``w(0.5)`` is ``w(0p5)`` there
        (:func:`~phdesign.numeric.statespace.control_signal_name`).
        """
        from phdesign.numeric.statespace import control_signal_name

        return (
            tuple(control_signal_name(name) for name in self.inputs),
            tuple(control_signal_name(name) for name in self.outputs),
        )

    def statespace(self) -> Any:
        """``control.StateSpace(A, B, C, D, dt)`` with the signal names (:meth:`signal_names`)."""
        import control

        inputs, outputs = self.signal_names()
        return control.ss(
            self.A,
            self.B,
            self.C,
            self.D,
            self.dt,
            inputs=list(inputs),
            outputs=list(outputs),
            states=[f"xhat{i + 1}" for i in range(self.order)],
            name="observer",
        )

    def to_dict(self) -> dict[str, Any]:
        """Return the JSON export (strict JSON).

        Keys: model, dt, sampler, order, A, B, C, D, inputs, outputs, x0, energy_matrix,
        verification (null when not run) and order_selection; input_descriptions and
        output_descriptions say what each signal is (:meth:`descriptions`), renumbering
        how a ``[feedback]`` closure renumbered the ports (null without one).
        """
        inputs, outputs = self.descriptions()
        return {
            "model": self.model,
            "dt": self.dt,
            "sampler": self.sampler,
            "order": self.order,
            "A": _matrix(self.A),
            "B": _matrix(self.B),
            "C": _matrix(self.C),
            "D": _matrix(self.D),
            "inputs": list(self.inputs),
            "outputs": list(self.outputs),
            "x0": self.x0.tolist(),
            "energy_matrix": _matrix(self.energy_matrix),
            "verification": None if self.verification is None else self.verification.to_dict(),
            "order_selection": self.selection.to_dict(),
            "input_descriptions": list(inputs),
            "output_descriptions": list(outputs),
            "renumbering": self.renumbering,
        }

    def write(self, path: str, format: str = "json", force: bool = False) -> list[str]:
        """Write the observer as ``format`` (:data:`FORMATS`) to ``path``; returns the files.

        ``json``, ``npz`` and ``statespace`` (a Python module that rebuilds the
        ``control.StateSpace``) write one file; ``c`` writes a folder holding
        ``observer.h``, ``observer.c`` and the marker ``.phdesign-export``, all files or
        none. ``force`` replaces a file, or a folder phdesign wrote and nothing else
        (:mod:`phdesign.codegen.folder`).
        """
        from phdesign.codegen import write_observer

        return write_observer(self, path, format, force=force)

    def __repr__(self) -> str:
        return (
            f"SampledObserver(model={self.model!r}, order={self.order}, dt={self.dt:g}, "
            f"sampler={self.sampler!r}, inputs={len(self.inputs)}, outputs={len(self.outputs)})"
        )

    def __str__(self) -> str:
        how = "mean over each period" if self.sampler == "average" else "point samples"
        sel, slow = self.selection, ""
        if sel.spurious and sel.abscissa is not None and sel.spurious_max_real is not None:
            slow = (
                f" ({sel.spurious} unresolved poles slower than the abscissa {sel.abscissa:.3g}: "
                f"max Re {sel.spurious_max_real:.3g}; `reduction='modal'` drops them)"
            )
        lines = [
            f"observer for {self.model}: {self.order} states{slow}, dt = {self.dt:g} s, "
            f"sampler {self.sampler} ({how})",
            *signal_lines(*self.descriptions(), self.renumbering),
            str(self.selection),
        ]
        if self.verification is not None:
            lines.append(str(self.verification))
        lines += [f"warning: {w}" for w in self.selection.warnings]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rows = [
            ("model", self.model),
            (
                "order",
                f"{self.order} (degree {self.selection.degree}, {self.selection.reduction})",
            ),
            ("dt, sampler", f"{self.dt:g} s, {self.sampler}"),
            ("inputs", ", ".join(self.inputs)),
            ("outputs", ", ".join(self.outputs)),
        ]
        if self.verification is not None:
            v = self.verification
            rows.append(("error floor", f"{v.floor:.3g} (continuous {v.continuous_floor:.3g})"))
        return html_table((), rows)

    def plot(self, ax: Any = None) -> Any:
        """Draw the verification run (needs ``verify=True``); returns the axes."""
        if self.verification is None:
            raise NumericError("this observer was exported without verification: verify=True")
        return self.verification.plot(ax)


def displacement_points(
    nm: NumericModel, points: Any, name: str = "points"
) -> tuple[Functional, ...]:
    """Return the point outputs of the export: ``w(z)`` at numbers, named fields by name.

    Default: w(b) when the model has a displacement, none otherwise.  A number is the
    displacement there, ``"rotation(1)"`` a named field
    (:func:`~phdesign.numeric.discretization.points.point_outputs`, which refuses an
    unknown field, a point outside [a, b] and two items of one output name). ``name`` is
    how the points are called in the messages (``"--at"`` on the command line).
    """
    if points is None:
        return point_outputs(nm, nm.interval[1], name) if nm.displacement is not None else ()
    return point_outputs(nm, points, name)


@limited_threads
def export_observer(
    nm: NumericModel,
    C_m: np.ndarray,
    L: np.ndarray,
    *,
    dt: float,
    sampler: str | None = None,
    order: int | None = None,
    reduction: str = "none",
    tol: float | None = None,
    output_tol: float | None = None,
    verify: bool = False,
    strict: bool = False,
    x0: Callable[[np.ndarray], np.ndarray] | None = None,
    x0_text: str | None = None,
    t_end: float | None = None,
    plant_resolution: int | None = None,
    points: float | str | Sequence[float | str] | None = None,
    model_name: str | None = None,
) -> SampledObserver:
    """Design the observer a controller runs: order, sampled discretization, verification.

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray
        Sensors and gain.
    dt : float
        Sampling period (> 0).
    sampler : {"average", "point"}, optional
        The controller's front end (module docstring). ``average`` is the safe default.
        This and the other defaults are the export's (:mod:`phdesign.core.defaults`).
    order : int, optional
        Number of observer states; chosen from ``tol``/``output_tol`` when omitted.
    reduction : {"none", "modal", "balanced"}
        See :mod:`phdesign.numeric.sampled.order`.
    tol, output_tol : float, optional
        Spectral and performance targets of the order selection (1e-6 and 1e-3).
    verify : bool
        Run the exported observer against the verification plant.
    strict : bool
        Run the verification (``verify`` implied) and raise
        :class:`~phdesign.core.errors.VerificationError` naming every failed check
        (:func:`~phdesign.numeric.sampled.verification.failed_checks`).
    x0 : callable, optional
        Plant initial state ``x0(z) -> (m, n)`` of the performance and verification runs;
        default every component ``(z - a)/(b - a) - 0.9``.
    x0_text : str, optional
        How ``x0`` is described in reports.
    t_end : float, optional
        Length of those runs (5 s).
    plant_resolution : int, optional
        Galerkin degree of the verification plant (default the table's
        ``export.plant_degree``, raised to twice the order: :mod:`phdesign.core.defaults`).
    points : float, str or a sequence of them, optional
        Point outputs: numbers are displacement points ``w(z)``, ``"rotation(1)"`` a named
        field; default (b,) for a model with a displacement, none otherwise.
    model_name : str, optional
        Name recorded in the export (default the model's).

    Returns
    -------
    SampledObserver

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> nm = to_numeric(load_builtin("wave"))
    >>> obs = export_observer(nm, np.array([[0.0, 1.0]]), np.array([[0.5]]), dt=1e-2, order=12)
    >>> obs.order, obs.inputs, obs.outputs
    (12, ('u1', 'u2', 'y2'), ('yhat1', 'yhat2'))
    """
    sampler, tol, output_tol, t_end = current().export.fill(sampler, tol, output_tol, t_end)
    verify = _checked_flags(verify, strict)  # strict verifies
    dt = _checked_request(nm, dt, sampler, reduction, t_end, verify, tol, output_tol, x0)
    plant = discretize(
        nm, "galerkin", verification_plant_degree(nm, order, plant_resolution, reduction)
    )
    initial = default_initial_state(nm.size, nm.interval) if x0 is None else x0
    text = x0_text or ("x_i = (z - a)/(b - a) - 0.9 for every component" if x0 is None else "x0")
    e0 = plant.project(initial)
    C, Lm = (np.atleast_2d(np.asarray(M, dtype=float)) for M in (C_m, L))
    selection, continuous = select_order(
        nm, C, Lm, plant=plant, x0=e0, t_end=float(t_end), order=order, reduction=reduction,
        points=displacement_points(nm, points), tol=tol, output_tol=output_tol,
    )  # fmt: skip
    discrete = continuous.sampled(dt, sampler)
    verification = None
    if verify:
        report("export: verification against the plant")
        verification = verify_observer(
            plant, continuous, C, dt=dt, sampler=sampler, x0=e0, t_end=float(t_end),
            x0_text=text, realization=discrete,
        )  # fmt: skip
    selection, verification = _plant_checks(
        nm, plant, continuous, initial, float(t_end), text, selection, verification, strict
    )
    return SampledObserver(
        model=model_name or nm.name,
        dt=dt,
        sampler=sampler,
        A=discrete.A,
        B=discrete.B,
        C=discrete.C,
        D=discrete.D,
        inputs=continuous.inputs,
        outputs=continuous.outputs,
        energy_matrix=continuous.energy_matrix,
        selection=selection,
        verification=verification,
        continuous=continuous,
    )


def _checked_flags(verify: Any, strict: Any) -> bool:
    """Refuse ``verify`` or ``strict`` that are not booleans; return whether to verify."""
    for name, value in (("verify", verify), ("strict", strict)):
        if not isinstance(value, bool):
            raise ArgumentError(f"{name} must be True or False; found {value!r}")
    return bool(verify or strict)


def _checked_request(
    nm: NumericModel,
    dt: Any,
    sampler: str,
    reduction: str,
    t_end: Any,
    verify: bool,
    tol: Any,
    output_tol: Any,
    x0: Any,
) -> float:
    """Refuse a bad request before any work; return the sampling period."""
    period = check_sampling(dt, sampler)
    if reduction not in REDUCTIONS:
        raise NumericError(f"unknown reduction {reduction!r}; expected one of {REDUCTIONS}")
    if not (isinstance(t_end, (int, float)) and math.isfinite(t_end) and t_end > 0):
        raise NumericError(f"t_end must be a finite positive number; found {t_end!r}")
    check_periods(period, float(t_end), stepped=verify)
    positive_number(tol, "tol")
    positive_number(output_tol, "output_tol")
    check_initial_state(x0, nm, "x0")
    return period


def _plant_checks(
    nm: NumericModel,
    plant: DiscretePHS,
    continuous: ContinuousObserver,
    initial: Callable[[np.ndarray], np.ndarray],
    t_end: float,
    text: str,
    selection: OrderSelection,
    verification: Verification | None,
    strict: bool = False,
) -> tuple[OrderSelection, Verification | None]:
    """Check the verification and a missed target against a finer plant (its own resolution?).

    One finer plant serves both checks, on the verification's records when there are any.
    ``strict`` raises when a check failed (:func:`check_strict`).
    """
    missed = selection.floor > selection.output_tol  # is it the plant's own resolution?
    if verification is None and not missed:
        return selection, verification
    report("export: does the verification plant resolve its own outputs?")
    samples = current().simulation.samples
    t = np.linspace(0.0, t_end, samples) if verification is None else verification.t
    found = plant_gap(nm, plant, continuous, initial, t)
    if verification is not None:
        verification = with_plant_gap(verification, found, plant.resolution)
    if missed:
        selection = with_target_check(selection, found, plant.resolution, text)
    if strict:
        check_strict(selection, verification)
    return selection, verification
