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
from typing import Any

import numpy as np

from phdesign.core.checks import positive_number
from phdesign.core.defaults import current
from phdesign.core.errors import ArgumentError, NumericError
from phdesign.core.progress import report
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_initial_state, check_periods, check_sampling
from phdesign.numeric.discretization.functionals import Functional
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.points import point_outputs
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.sampled.exported import FORMATS, SampledObserver
from phdesign.numeric.sampled.gain_design import DESIGNS, GainDesign, design_gain
from phdesign.numeric.sampled.kalman import KalmanNoise
from phdesign.numeric.sampled.order import REDUCTIONS, select_order
from phdesign.numeric.sampled.plant_resolution import verification_plant_degree
from phdesign.numeric.sampled.samplers import ContinuousObserver, default_initial_state
from phdesign.numeric.sampled.selection import OrderSelection
from phdesign.numeric.sampled.state_runs import StateRuns
from phdesign.numeric.sampled.state_set import InitialState, verification_states
from phdesign.numeric.sampled.verification import (
    Verification,
    check_strict,
    plant_gap,
    verify_observer,
    with_plant_gap,
    with_target_check,
)
from phdesign.numeric.threads import limited_threads

__all__ = [
    "DESIGNS",
    "FORMATS",
    "POINT_SAMPLER_WARNING",
    "KalmanNoise",
    "SampledObserver",
    "Verification",
    "displacement_points",
    "export_observer",
    "verify_observer",
]

#: The export's warning for the point sampler, whether or not it verifies.
POINT_SAMPLER_WARNING = (
    "point samples alias: a boundary velocity is not a function of time at each instant for "
    "the plant's unresolved content, so the observer's error floor grows with the plant's "
    "resolution (the paper's beam at 1 ms: 6.4e-4 for 50 modes, 1.6e-2 for 1000); use "
    "`sampler='average'` (an integrate-and-dump front end)"
)


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
    x0: Callable[[np.ndarray], np.ndarray] | Sequence[InitialState] | None = None,
    x0_text: str | None = None,
    t_end: float | None = None,
    plant_resolution: int | None = None,
    points: float | str | Sequence[float | str] | None = None,
    model_name: str | None = None,
    design: str | None = None,
    noise: KalmanNoise | None = None,
    max_ratio: float | None = None,
) -> SampledObserver:
    """Design the observer a controller runs: order, gain, sampled discretization, checks.

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray
        Sensors and gain.
    dt : float
        Sampling period (> 0).
    sampler : {"average", "point"}, optional
        The controller's front end (module docstring). ``average`` is the safe default;
        ``point`` always warns (:data:`POINT_SAMPLER_WARNING`). This and the other
        defaults are the export's (:mod:`phdesign.core.defaults`).
    order : int, optional
        Number of observer states; chosen from ``tol``/``output_tol`` when omitted.
    reduction : {"none", "modal", "balanced"}
        See :mod:`phdesign.numeric.sampled.order`.
    tol, output_tol : float, optional
        Spectral and performance targets of the order selection (1e-6 and 1e-3).
    verify : bool
        Run the exported observer against the verification plant: the first initial state
        over time (:class:`Verification`), every state of the set for the floors.
    strict : bool
        Run the verification (``verify`` implied) and raise
        :class:`~phdesign.core.errors.VerificationError` naming every failed check
        (:func:`~phdesign.numeric.sampled.verification.failed_checks`), among them a worst
        ratio over the set above ``max_ratio``.
    x0 : callable or sequence of InitialState, optional
        Plant initial state ``x0(z) -> (m, n)`` of the order selection, or the whole
        verification set (its first state then serves the order selection); default
        every component ``(z - a)/(b - a) - 0.9`` followed by smooth states that meet the
        boundary conditions (:mod:`phdesign.numeric.sampled.state_set`).
    x0_text : str, optional
        How a callable ``x0`` is described in reports.
    t_end : float, optional
        Length of those runs (5 s); the floors are taken over its last fifth.
    plant_resolution : int, optional
        Galerkin degree of the verification plant (default the table's
        ``export.plant_degree``, raised to twice the order: :mod:`phdesign.core.defaults`).
    points : float, str or a sequence of them, optional
        Point outputs: numbers are displacement points ``w(z)``, ``"rotation(1)"`` a named
        field; default (b,) for a model with a displacement, none otherwise.
    model_name : str, optional
        Name recorded in the export (default the model's).
    design : {"auto", "passive", "kalman", "given"}, optional
        The gain the observer runs (:mod:`phdesign.numeric.sampled.gain_design`).
    noise : KalmanNoise, optional
        The Kalman design's noise model (default unit intensities).
    max_ratio : float, optional
        The largest worst ratio F/F_c over the set a design may have to pass verification.

    Returns
    -------
    SampledObserver

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> nm = to_numeric(load_builtin("wave"))
    >>> obs = export_observer(nm, np.array([[0.0, 1.0]]), np.array([[0.5]]), dt=1e-2, order=12,
    ...                       design="given")
    >>> obs.order, obs.inputs, obs.outputs
    (12, ('u1', 'u2', 'y2'), ('yhat1', 'yhat2'))
    """
    d = current().export
    sampler, tol, output_tol, t_end = d.fill(sampler, tol, output_tol, t_end)
    design = d.design if design is None else design
    max_ratio = d.max_ratio if max_ratio is None else max_ratio
    verify = _checked_flags(verify, strict)  # strict verifies
    states = _states(nm, x0, x0_text)
    dt = _checked_request(nm, dt, sampler, reduction, t_end, verify, tol, output_tol, states)
    C, Lm = (np.atleast_2d(np.asarray(M, dtype=float)) for M in (C_m, L))
    _checked_design(design, noise, max_ratio, nm.n_ports, C.shape[0])
    plant = discretize(
        nm, "galerkin", verification_plant_degree(nm, order, plant_resolution, reduction)
    )
    e0 = plant.project(states[0].function)
    selection, continuous = select_order(
        nm, C, Lm, plant=plant, x0=e0, t_end=float(t_end), order=order, reduction=reduction,
        points=displacement_points(nm, points), tol=tol, output_tol=output_tol,
    )  # fmt: skip
    gains = _designed(plant, continuous, C, states, design, dt, sampler, float(t_end), verify,
                      noise or KalmanNoise(), float(max_ratio))  # fmt: skip
    discrete = gains.selected.realization
    assert discrete is not None  # the chosen design was made (design_gain raises otherwise)
    verification = _verified(plant, continuous, C, dt, sampler, e0, float(t_end), states[0],
                             discrete) if verify else None  # fmt: skip
    selection, verification = _plant_checks(
        nm, plant, continuous, states[0], float(t_end), selection, verification,
        _design_failures(gains, verify) if strict else None,
    )  # fmt: skip
    return SampledObserver(
        model=model_name or nm.name, dt=dt, sampler=sampler,
        A=discrete.A, B=discrete.B, C=discrete.C, D=discrete.D,
        inputs=continuous.inputs, outputs=continuous.outputs,
        energy_matrix=continuous.energy_matrix, selection=selection,
        verification=verification, continuous=continuous, design=gains,
        notes=(POINT_SAMPLER_WARNING,) if sampler == "point" else (),
    )  # fmt: skip


def _verified(
    plant: DiscretePHS,
    continuous: ContinuousObserver,
    C: np.ndarray,
    dt: float,
    sampler: str,
    e0: np.ndarray,
    t_end: float,
    state: InitialState,
    realization: Any,
) -> Verification:
    """Run the exported observer from the first state over time (:func:`verify_observer`)."""
    report("export: verification against the plant")
    return verify_observer(
        plant, continuous, C, dt=dt, sampler=sampler, x0=e0, t_end=t_end, x0_text=state.text,
        realization=realization,
    )  # fmt: skip


def _states(nm: NumericModel, x0: Any, x0_text: str | None) -> tuple[InitialState, ...]:
    """Return the verification set: the given states, else x0 and the smooth states."""
    if isinstance(x0, (list, tuple)):
        if not x0 or not all(isinstance(s, InitialState) for s in x0):
            raise NumericError(
                f"x0 must be a function of z or a non-empty sequence of InitialState; found {x0!r}"
            )
        return tuple(x0)
    if x0 is None:
        default = InitialState(
            "x_i = (z - a)/(b - a) - 0.9 for every component",
            default_initial_state(nm.size, nm.interval),
        )
        return verification_states(nm, (), default)
    return (InitialState(x0_text or "x0", x0),)


def _checked_design(design: Any, noise: Any, max_ratio: Any, inputs: int, sensors: int) -> None:
    """Refuse an unknown design, a bad noise model (its intensities), a bound not > 0."""
    if design not in DESIGNS:
        raise NumericError(f"unknown design {design!r}; expected one of {DESIGNS}")
    if noise is not None and not isinstance(noise, KalmanNoise):
        raise NumericError(f"noise must be a KalmanNoise; found {type(noise).__name__}")
    if noise is not None:
        noise.matrices(inputs, sensors)
    positive_number(max_ratio, "max_ratio")


def _designed(
    plant: DiscretePHS,
    continuous: ContinuousObserver,
    C: np.ndarray,
    states: tuple[InitialState, ...],
    design: str,
    dt: float,
    sampler: str,
    t_end: float,
    verify: bool,
    noise: KalmanNoise,
    max_ratio: float,
) -> GainDesign:
    """Run the set against the plant when a design or the verification needs it; design."""
    runs = None
    if verify or design in ("auto", "passive"):
        report(f"export: the plant from {len(states)} initial states")
        runs = StateRuns.run(
            plant, continuous, C, states=states, dt=dt, sampler=sampler, t_end=t_end
        )
    report(f"export: gain design {design!r}")
    return design_gain(
        continuous, runs, design=design, dt=dt, sampler=sampler, noise_model=noise,
        bound=max_ratio,
    )  # fmt: skip


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" + ("" if n == 1 else "s")


def _design_failures(gains: GainDesign, verify: bool) -> tuple[str, ...]:
    """Return the strict check of the set: the exported design's worst ratio over the bound."""
    c = gains.selected
    if not verify or c.floors is None or c.worst <= gains.bound:
        return ()
    return (
        f"verification set: the {c.design} design's worst F/F_c over "
        f"{_count(len(c.floors.states), 'initial state')} is {c.worst:.3g} "
        f"(at most {gains.bound:g}x)",
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
    states: tuple[InitialState, ...],
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
    for state in states:
        check_initial_state(state.function, nm, "x0")
    return period


def _plant_checks(
    nm: NumericModel,
    plant: DiscretePHS,
    continuous: ContinuousObserver,
    initial: InitialState,
    t_end: float,
    selection: OrderSelection,
    verification: Verification | None,
    strict: tuple[str, ...] | None = None,
) -> tuple[OrderSelection, Verification | None]:
    """Check the verification and a missed target against a finer plant (its own resolution?).

    One finer plant serves both checks, on the verification's records when there are any.
    ``strict`` (the design's failed checks, None when not strict) raises when a check
    failed (:func:`check_strict`).
    """
    missed = selection.floor > selection.output_tol  # is it the plant's own resolution?
    if verification is None and not missed:
        if strict is not None:
            check_strict(selection, verification, strict)
        return selection, verification
    report("export: does the verification plant resolve its own outputs?")
    samples = current().simulation.samples
    t = np.linspace(0.0, t_end, samples) if verification is None else verification.t
    found = plant_gap(nm, plant, continuous, initial.function, t)
    if verification is not None:
        verification = with_plant_gap(verification, found, plant.resolution)
    if missed:
        selection = with_target_check(selection, found, plant.resolution, initial.text)
    if strict is not None:
        check_strict(selection, verification, strict)
    return selection, verification
