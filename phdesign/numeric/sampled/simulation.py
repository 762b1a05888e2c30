r"""Simulation of the sampled loop: a plant and a (sampled, or lower-order) observer.

:func:`simulate_sampled` is :func:`phdesign.numeric.time.simulation.simulate` for the
implementation questions: the observer may have its own Galerkin degree (lower than the
plant's, as on a controller) and may be sampled at a period Δt by a declared sampler
(:mod:`phdesign.numeric.sampled.samplers`), so that continuous, averaged and point-sampled
observers can be compared on the same plant. Everything is stepped exactly
(:func:`phdesign.numeric.sampled.samplers.run_loop`); plant inputs are held over each period.

Energies: :math:`H = \tfrac12 \hat e^\top E \hat e` (plant),
:math:`\hat H = \tfrac12 \hat x^\top Q \hat x` (observer) and
:math:`\tilde H = \tfrac12 (\hat e - P\hat x)^\top E (\hat e - P\hat x)`, where P maps the
observer's efforts into the plant's space. Galerkin spaces of lower degree are contained
in those of higher degree, so P is exact (it is found by least squares on Gauss points
and checked); discretizations that do not nest are refused.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from phdesign.core.defaults import current
from phdesign.core.errors import NumericError
from phdesign.core.limits import check_periods
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.inputs import input_samples
from phdesign.numeric.sampled.samplers import (
    ContinuousObserver,
    check_sampling,
    run_against_continuous,
    run_loop,
)
from phdesign.numeric.time.simulation import SimulationResult

__all__ = ["embedding", "simulate_sampled"]


def embedding(observer: DiscretePHS, plant: DiscretePHS) -> np.ndarray:
    """Return P with ``plant.effort_basis(z) @ P == observer.effort_basis(z)``.

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
    return P


def simulate_sampled(
    nm: NumericModel,
    C_m: np.ndarray,
    L: np.ndarray,
    *,
    x0: Callable[[np.ndarray], np.ndarray] | None = None,
    xhat0: Callable[[np.ndarray], np.ndarray] | None = None,
    t_end: float | None = None,
    samples: int | None = None,
    dt: float | None = None,
    sampler: str | None = None,
    method: str | None = None,
    resolution: int | None = None,
    observer_resolution: int | None = None,
    u: Callable[[float], np.ndarray] | None = None,
    z_w: np.ndarray | None = None,
) -> SimulationResult:
    """Simulate the plant with a continuous or sampled observer of its own resolution.

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray
        Sensors and gain.
    x0, xhat0 : callable, optional
        Initial states ``f(z) -> (m, n)`` of plant and observer; default zero.
    t_end : float, optional
        Final time (default 5).
    samples : int, optional
        About this many records (default 501): every ``s`` periods,
        ``s = round(T / ((samples - 1) dt))`` (every one of ``samples - 1`` equal steps for
        a continuous observer).
    dt : float, optional
        Sampling period; None runs the continuous observer.
    sampler : {"average", "point"}, optional
        The observer's front end when ``dt`` is given (default ``"average"``, the
        exported observer's; the defaults are those of :mod:`phdesign.core.defaults`).
    method, resolution
        The plant's discretization (:func:`phdesign.numeric.discretization.registry.discretize`).
    observer_resolution : int, optional
        The observer's resolution (default the plant's).
    u : callable, optional
        Plant input ``u(t)``, held over each period (default zero).
    z_w : ndarray, optional
        Points of the displacement (default 21 uniform points).

    Returns
    -------
    SimulationResult
        With ``info`` holding ``dt``, ``sampler`` and ``observer_resolution``.
    """
    t_end, samples, _, _ = current().simulation.fill(t_end, samples)
    sampler = current().export.sampler if sampler is None else sampler
    if not (np.isfinite(t_end) and t_end > 0):
        raise NumericError(f"t_end must be a positive number; found {t_end}")
    if int(samples) < 2:
        raise NumericError(f"samples must be at least 2; found {samples}")
    if dt is not None:
        check_periods(check_sampling(dt, sampler), t_end)
    plant = discretize(nm, method, resolution)
    same = observer_resolution is None or int(observer_resolution) == plant.resolution
    d_obs = plant if same else discretize(nm, method, observer_resolution)
    if dt is not None and u is not None:  # every period is stepped, with its input
        check_periods(float(dt), t_end, states=plant.dim + d_obs.dim)
    P = embedding(d_obs, plant)
    points: tuple[float, ...] = ()
    if plant.displacement_basis is not None:
        a, b = nm.interval
        zw = np.linspace(a, b, 21) if z_w is None else np.asarray(z_w, dtype=float)
        points = tuple(float(z) for z in zw)
    observer = ContinuousObserver.from_discretization(d_obs, C_m, L, points)
    if dt is None:
        step, n_steps, stride = t_end / (int(samples) - 1), int(samples) - 1, 1
    else:
        step = check_sampling(dt, sampler)
        n_steps = max(1, round(t_end / step))
        stride = max(1, round(t_end / ((int(samples) - 1) * step)))
    zero = lambda z: np.zeros((np.atleast_1d(z).size, nm.size))  # noqa: E731
    U = None
    if u is not None:
        U = input_samples(u, step * np.arange(n_steps + 1), nm.n_ports)
    e0 = plant.project(x0 or zero)
    xh0 = d_obs.project(xhat0 or zero)
    kind = None if dt is None else sampler
    warnings: tuple[str, ...] = ()
    if kind is None:
        run = run_loop(plant, observer, C_m, x0=e0, xhat0=xh0, dt=step, n_steps=n_steps, u=U)
    else:
        run, _, _, warning = run_against_continuous(
            plant, observer, C_m, sampler=kind, x0=e0, xhat0=xh0, dt=step, n_steps=n_steps,
            stride=stride, u=U,
        )  # fmt: skip
        warnings = () if warning is None else (warning,)
    m = nm.n_ports
    gap = run.x - run.xhat @ P.T
    has_w = bool(points)
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
        z_w=np.array(points) if has_w else None,
        w=run.target if has_w else None,
        w_hat=run.yhat[:, m:] if has_w else None,
        states=run.x,
        states_hat=run.xhat,
        info={
            "scheme": "exact, sampled" if kind else "exact",
            "states": int(plant.dim),
            "observer_resolution": int(d_obs.resolution),
            "observer_states": int(d_obs.dim),
            **({"dt": step, "sampler": sampler} if kind else {}),
        },
        warnings=warnings,
    )
