r"""Simulation of the sampled loop: a plant and a (sampled, or lower-order) observer.

:func:`simulate_sampled` is :func:`phdesign.numeric.time.simulation.simulate` for the
implementation questions: the observer may have its own Galerkin degree (lower than the
plant's, as on a controller) and may be sampled at a period Δt by a declared sampler
(:mod:`phdesign.numeric.sampled.samplers`), so that continuous, averaged and point-sampled
observers can be compared on the same plant. Everything is stepped exactly
(:func:`phdesign.numeric.sampled.runs.run_loop`); plant inputs are held over each period.

Energies: :math:`H = \tfrac12 \hat e^\top E \hat e` (plant),
:math:`\hat H = \tfrac12 \hat x^\top Q \hat x` (observer) and
:math:`\tilde H = \tfrac12 (\hat e - P\hat x)^\top E (\hat e - P\hat x)`, where P maps the
observer's efforts into the plant's space. Galerkin spaces of lower degree are contained
in those of higher degree, so P is exact (it is found by least squares on Gauss points
and checked); discretizations that do not nest are refused.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from phdesign.core.errors import NumericError
from phdesign.core.progress import report
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_periods
from phdesign.numeric.discretization.coupled import boundary_series
from phdesign.numeric.discretization.functionals import Functional
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.points import point_outputs, point_series
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.inputs import input_samples
from phdesign.numeric.sampled.runs import LoopRun, run_against_continuous, run_loop
from phdesign.numeric.sampled.samplers import ContinuousObserver
from phdesign.numeric.threads import limited_threads
from phdesign.numeric.time.options import SAMPLED_SCHEME, SimulationOptions
from phdesign.numeric.time.result import SimulationResult

__all__ = ["embedding", "simulate_sampled"]


def embedding(observer: DiscretePHS, plant: DiscretePHS) -> np.ndarray:
    """Return P with ``plant.effort_basis(z) @ P == observer.effort_basis(z)``.

    A coupled model's boundary states are no part of the field bases: they map to each
    other by the identity (:mod:`phdesign.numeric.discretization.coupled`).

    Raises
    ------
    NumericError
        When the observer's effort space is not contained in the plant's.
    """
    a, b = plant.model.interval
    nodes, _ = np.polynomial.legendre.leggauss(plant.dim + 8)
    z = 0.5 * (a + b) + 0.5 * (b - a) * nodes
    Pq = plant.effort_basis(z).reshape(-1, plant.dim)
    Pp = observer.effort_basis(z).reshape(-1, observer.dim)
    P, *_ = np.linalg.lstsq(Pq, Pp, rcond=None)
    residual = float(np.max(np.abs(Pq @ P - Pp)))
    if residual > 1e-9 * max(1.0, float(np.max(np.abs(Pp)))):
        raise NumericError(
            f"the observer's discretization ({observer.method}, resolution "
            f"{observer.resolution}) is not contained in the plant's ({plant.method}, "
            f"resolution {plant.resolution}): use Galerkin, or equal resolutions"
        )
    if "boundary_states" in observer.info and "boundary_states" in plant.info:
        (fo, k), (fp, _) = observer.info["boundary_states"], plant.info["boundary_states"]
        P[fp : fp + k, fo : fo + k] = np.eye(k)
    return np.asarray(P)


@limited_threads
def simulate_sampled(
    nm: NumericModel,
    C_m: np.ndarray,
    L: np.ndarray,
    *,
    x0: Callable[[np.ndarray], np.ndarray] | None = None,
    xhat0: Callable[[np.ndarray], np.ndarray] | None = None,
    u: Callable[[float], np.ndarray] | None = None,
    options: SimulationOptions | None = None,
) -> SimulationResult:
    """Simulate the plant with a continuous or sampled observer of its own resolution.

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray
        Sensors and gain.
    x0, xhat0 : callable, optional
        Initial states ``f(z) -> (m, n)`` of plant and observer; default zero.
    u : callable, optional
        Plant input ``u(t)``, held over each period (default zero).
    options : SimulationOptions, optional
        As for :func:`phdesign.numeric.time.simulation.simulate`, with the sampling:
        ``dt`` (the sampling period; None runs the continuous observer), ``sampler``
        (the observer's front end) and ``observer_resolution`` (the observer's degree,
        default the plant's).  About ``samples`` records are kept: every ``s`` periods,
        ``s = round(T / ((samples - 1) dt))`` (every one of ``samples - 1`` equal steps for
        a continuous observer).  ``method`` and ``resolution`` are the plant's; ``at``
        (point outputs, as for ``simulate``) is read on the plant's and on the observer's
        own discretization.

    Returns
    -------
    SimulationResult
        With ``info`` holding ``dt``, ``sampler`` and ``observer_resolution``.
    """
    opts = SimulationOptions.merged(options)
    opts.require("simulate_sampled", "sampled", "continuous")
    if opts.scheme != "expm":
        raise NumericError(SAMPLED_SCHEME.format(scheme=opts.scheme))
    at = point_outputs(nm, opts.at, "at")  # an unknown field is refused before any work
    if opts.dt is not None:
        check_periods(opts.dt, opts.t_end)
    plant = discretize(nm, opts.method, opts.resolution)
    same = opts.observer_resolution in (None, plant.resolution)
    d_obs = plant if same else discretize(nm, opts.method, opts.observer_resolution)
    if opts.dt is not None and u is not None:  # every period is stepped, with its input
        check_periods(opts.dt, opts.t_end, states=plant.dim + d_obs.dim)
    P = embedding(d_obs, plant)
    points: tuple[float, ...] = ()
    if plant.displacement_basis is not None:
        points = tuple(float(z) for z in opts.displacement_points(nm.interval))
    observer = ContinuousObserver.from_discretization(d_obs, C_m, L, points)
    grid = _Grid.of(opts)
    U = None if u is None else input_samples(u, grid.step * np.arange(grid.steps + 1), nm.n_ports)
    zero = lambda z: np.zeros((np.atleast_1d(z).size, nm.size))  # noqa: E731
    e0, xh0 = plant.project(x0 or zero), d_obs.project(xhat0 or zero)
    warnings: tuple[str, ...] = ()
    report(f"simulate: plant (resolution {plant.resolution}) and observer stepped together")
    if opts.dt is None:
        run = run_loop(
            plant, observer, C_m, x0=e0, xhat0=xh0, dt=grid.step, n_steps=grid.steps, u=U
        )
    else:
        run, _, _, warning = run_against_continuous(
            plant, observer, C_m, sampler=opts.sampler_name, x0=e0, xhat0=xh0, dt=grid.step,
            n_steps=grid.steps, stride=grid.stride, u=U,
        )  # fmt: skip
        warnings = () if warning is None else (warning,)
    return _result(nm, (plant, d_obs), observer, P, run, opts, warnings, at)


@dataclass(frozen=True)
class _Grid:
    """The periods of a run: ``steps`` of length ``step``, a record every ``stride``."""

    step: float
    steps: int
    stride: int

    @classmethod
    def of(cls, options: SimulationOptions) -> _Grid:
        """Return the continuous observer's output grid, or the sampling periods."""
        t_end, samples = options.t_end, int(options.samples)
        if options.dt is None:
            return cls(t_end / (samples - 1), samples - 1, 1)
        steps = max(1, round(t_end / options.dt))
        return cls(options.dt, steps, max(1, round(t_end / ((samples - 1) * options.dt))))


def _result(
    nm: NumericModel,
    discretizations: tuple[DiscretePHS, DiscretePHS],
    observer: ContinuousObserver,
    P: np.ndarray,
    run: LoopRun,
    options: SimulationOptions,
    warnings: tuple[str, ...],
    at: tuple[Functional, ...],
) -> SimulationResult:
    """Return the run's series as a :class:`SimulationResult` (module docstring's energies).

    The point outputs ``at`` of the observer are read on its own discretization (its
    states are its efforts there), those of the plant on the plant's.
    """
    plant, d_obs = discretizations
    m = nm.n_ports
    gap = run.x - run.xhat @ P.T
    has_w = bool(observer.points)
    sampled = options.dt is not None
    return SimulationResult(
        t=run.t,
        H=plant.hamiltonian(run.x),
        H_hat=0.5 * np.einsum("ki,ij,kj->k", run.xhat, observer.energy_matrix, run.xhat),
        H_err=plant.hamiltonian(gap),
        y=run.y,
        y_hat=run.yhat[:, :m],
        output_labels=nm.output_labels,
        method=plant.method,
        resolution=plant.resolution,
        z_w=np.array([f.point for f in observer.points]) if has_w else None,
        w=run.target if has_w else None,
        w_hat=run.yhat[:, m:] if has_w else None,
        states=run.x,
        states_hat=run.xhat,
        info={
            "scheme": "exact, sampled" if sampled else "exact",
            "states": int(plant.dim),
            "observer_resolution": int(d_obs.resolution),
            "observer_states": int(d_obs.dim),
            **({"dt": options.dt, "sampler": options.sampler_name} if sampled else {}),
        },
        warnings=warnings,
        **point_series(at, plant, run.x, run.xhat, d_obs),
        **boundary_series(plant, run.x, run.xhat, d_obs),
    )
