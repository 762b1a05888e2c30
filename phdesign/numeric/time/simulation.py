r"""Simulation of plant and observer together, exact in time for these LTI systems.

With the discretization :math:`E \dot{\hat e} = (J - R)\hat e + B u`,
:math:`y = B^\top \hat e + D u` (:mod:`phdesign.numeric.discretization.registry`), the
observer is the same system driven by :math:`\hat u = u + C_m^\top L (y_m - \hat y_m)`, i.e.
the loop :math:`\hat u = v - K \hat y` with :math:`K = C_m^\top L C_m` and
:math:`v = u + C_m^\top L y_m` (:meth:`~phdesign.numeric.discretization.phs.DiscretePHS.close`).
In the coordinates (plant :math:`\hat e`, error :math:`\tilde e = \hat e - \hat e_{obs}`) the
coupled system is block triangular,

.. math::

    E \dot{\hat e} = (J - R)\hat e + B u, \qquad
    E \dot{\tilde e} = (J - R - B G B^\top)\tilde e, \qquad G = (I + K D)^{-1} K,

and a disturbance :math:`B_w w(t)` (the model's ``[disturbances]``, :math:`B_d = \int
\Psi^\top B\, dz`, and its inputs marked unknown, :math:`B_{:,j}`:
:class:`~phdesign.numeric.disturbance_inputs.DisturbanceChannels`), which the observer
does not know, drives both rows: :math:`E \dot{\hat e} = \dots + B_w w` and :math:`E
\dot{\tilde e} = \dots + B_w w` (an unknown input with no feedthrough, :math:`D_{:,j} =
0`, reaches the error through :math:`B M e_j = B e_j`). So the error system is stepped on
its own and :math:`\tilde H = \tfrac12 \tilde e^\top E \tilde e` is computed from
:math:`\tilde e` itself: no cancellation of plant minus observer (that difference loses
all relative accuracy once :math:`\tilde H` is :math:`10^{-11}` of :math:`\tilde H(0)`).
The observer is :math:`\hat e - \tilde e` and :math:`\hat y = y - \tilde y`, :math:`\tilde
y = (I - D G) B^\top \tilde e`.
Time stepping (:mod:`phdesign.numeric.time.stepping`): exact (``"expm"``, default) or implicit
midpoint with its own step control (``"midpoint"``, error below ``tol``).

**Resolution of the error energy.**  A semi-discretization keeps unresolved modes whose
decay is an artefact (the spectrum discards them); once the resolved part of
:math:`\tilde H` has decayed, they form a floor: Timoshenko, sensors y3, y4, L = I,
:math:`\tilde H(20)/\tilde H(0)` = 3.8e-5 at degree 20 and 6.3e-6 at degree 40 against
~1e-14 from the abscissa.  The error system is stepped a second time at
:math:`\lceil 1.5 p \rceil`; where the two :math:`\tilde H` differ by more than
:data:`RESOLVED_RTOL` the error energy is no longer resolved.  The result reports the
ratio down to which it is (``resolved_floor``) and the time until which
(``resolved_until``), warns, and :meth:`SimulationResult.time_below` answers None below
that floor.

Energies: :math:`H = \tfrac12 \hat e^\top E \hat e`, :math:`\hat H` likewise for the
observer and :math:`\tilde H` for the error.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from phdesign.core.errors import ArgumentError, NumericError
from phdesign.core.progress import report
from phdesign.numeric.boundary_start import difference
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_simulate_arguments
from phdesign.numeric.discretization.coupled import boundary_series
from phdesign.numeric.discretization.functionals import Functional
from phdesign.numeric.discretization.phs import ClosedLoop
from phdesign.numeric.discretization.points import point_outputs, point_series
from phdesign.numeric.discretization.registry import DiscretePHS, discretize, feedback_matrix
from phdesign.numeric.disturbance_inputs import DisturbanceChannels
from phdesign.numeric.inputs import input_samples
from phdesign.numeric.threads import limited_threads
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.result import SimulationResult
from phdesign.numeric.time.stepping import Trajectory, energy_balance_residual, integrate

__all__ = [
    "ENERGY_BALANCE_RTOL",
    "RESOLVED_RTOL",
    "coupled_system",
    "simulate",
]

InitialState = Callable[[np.ndarray], np.ndarray]

#: Largest energy-balance residual, relative to the largest energy of the run, that a
#: simulation may show before it warns. Exact stepping leaves round-off (about 1e-13).
ENERGY_BALANCE_RTOL = 1e-8
#: Relative disagreement of the error energy between the resolution p and ⌈1.5 p⌉ beyond
#: which it is not resolved.
RESOLVED_RTOL = 0.05


def coupled_system(
    d: DiscretePHS, K: np.ndarray | None, coordinates: str = "observer"
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Descriptor matrices (E2, A2, B2) of plant + observer.

    ``coordinates="observer"``: state (ê, ê_obs); ``"error"``: state (ê, ẽ), in which
    A2 is block lower triangular (the error system does not see the plant).  Without K
    (no sensors) only the plant: (E, J − R, B).
    """
    if K is None:
        return d.E, d.J - d.R, d.B
    if coordinates not in ("observer", "error"):
        raise NumericError(f"coordinates must be 'observer' or 'error'; found {coordinates!r}")
    loop = d.close(K)
    n = d.dim
    E2 = np.zeros((2 * n, 2 * n))
    E2[:n, :n] = d.E
    E2[n:, n:] = d.E
    A2 = np.zeros((2 * n, 2 * n))
    A2[:n, :n] = d.J - d.R
    A2[n:, n:] = loop.A
    if coordinates == "error":
        return E2, A2, np.vstack([d.B, np.zeros_like(d.B)])
    A2[n:, :n] = d.J - d.R - loop.A  # B G Bᵀ: the observer's correction from y
    return E2, A2, np.vstack([d.B, d.B])


def _resolution_check(
    t: np.ndarray, H_err: np.ndarray, finer: np.ndarray
) -> tuple[float | None, float | None]:
    """Return (floor, until): where H_err stops agreeing with the finer resolution's."""
    with np.errstate(divide="ignore", invalid="ignore"):
        disagree = np.abs(H_err - finer) > RESOLVED_RTOL * np.maximum(np.abs(finer), 1e-300)
    bad = np.flatnonzero(disagree)
    if bad.size == 0 or H_err[0] <= 0:
        return None, None
    first = int(bad[0])
    if first == 0:
        return 1.0, float(t[0])
    return float(np.min(H_err[:first]) / H_err[0]), float(t[first - 1])


def _energy_warning(name: str, value: float, d: DiscretePHS) -> str:
    return (
        f"the {name}'s energy balance drifts by {value:.3g} of its largest energy "
        f"(tolerance {ENERGY_BALANCE_RTOL:g}): the matrix exponential of this stiff "
        f"discretization lost accuracy; what helps: scheme 'midpoint', whose step control "
        "keeps its error below tol (airy, degree 40: H_err off by 1.3e-3 with 'expm', "
        f"by 5e-6 with 'midpoint'), or a lower resolution (this run: {d.resolution})"
    )


def _floor_warning(floor: float, until: float, coarse: int, fine: int) -> str:
    return (
        f"the error energy is resolved only down to {floor:.3g} of H_err(0) (until "
        f"t = {until:g}): beyond, resolutions {coarse} and {fine} disagree by more than "
        f"{RESOLVED_RTOL:.0%} and H_err is made of modes this discretization does not "
        "resolve (time_below() returns None there); raise the resolution to lower the floor"
    )


@limited_threads  # small dense exponentials: one BLAS thread is 3-5x faster (benchmarks)
def simulate(
    nm: NumericModel,
    C_m: np.ndarray | None = None,
    L: np.ndarray | None = None,
    *,
    x0: InitialState | None = None,
    xhat0: InitialState | None = None,
    u: Callable[[float], np.ndarray] | None = None,
    options: SimulationOptions | None = None,
    discrete: DiscretePHS | None = None,
    w: Callable[[float], np.ndarray] | None = None,
    disturbance: DisturbanceChannels | None = None,
) -> SimulationResult:
    """Simulate the plant, and the continuous observer when sensors are given.

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray, optional
        Sensors and gain (both or neither).
    x0, xhat0 : callable, optional
        Initial states ``f(z) -> (m, n)`` (see
        :func:`phdesign.numeric.inputs.initial_state_function`); default zero.
    u : callable, optional
        Plant input ``u(t) -> (N n,)``, sampled on the output grid and linear in between;
        default zero.
    options : SimulationOptions, optional
        The output grid, discretization and time stepping
        (:class:`~phdesign.numeric.time.options.SimulationOptions`; default its defaults).
        Options of a sampled or noisy run are refused: ``simulate_sampled`` and
        ``simulate_noisy`` run them.
    discrete : DiscretePHS, optional
        A ready discretization (overrides ``options.method``/``options.resolution``).
    w : callable, optional
        Disturbances ``w(t)``, one value per channel, sampled like ``u``; the observer
        does not know them.
    disturbance : DisturbanceChannels, optional
        Where they enter: B's columns, then the unknown inputs
        (:func:`phdesign.numeric.disturbance_inputs.disturbance_channels`); needed with
        ``w``.

    Returns
    -------
    SimulationResult

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> nm = to_numeric(load_builtin("wave"))
    >>> x0 = lambda z: np.column_stack([np.zeros_like(z), np.ones_like(z)])
    >>> run = simulate(nm, x0=x0, options=SimulationOptions(t_end=1.0, samples=3))
    >>> [round(float(h), 12) for h in run.H]  # a lossless string keeps its energy
    [0.5, 0.5, 0.5]
    """
    opts = SimulationOptions.merged(options)
    opts.require("simulate", "continuous")
    check_simulate_arguments(nm, C_m, L, x0=x0, xhat0=xhat0, u=u, options=opts, discrete=discrete)
    at = point_outputs(nm, opts.at, "at")  # an unknown field is refused before any work
    d = discrete if discrete is not None else discretize(nm, opts.method, opts.resolution)
    step = _Stepper.of(opts)
    U = None if u is None else input_samples(u, step.t, nm.n_ports)
    forcing = _Disturbance.of(w, disturbance, step.t)
    start = x0 or _zero(nm)
    report(f"simulate: the plant, resolution {d.resolution}")
    B, V = forcing.joined(d, d.B, U)
    plant = step(d.E, d.J - d.R, B, d.project(start), V)
    error = None
    if C_m is not None and L is not None:
        K = feedback_matrix(C_m, L, nm.n_ports)
        e0 = difference(start, xhat0 or _zero(nm))
        error = _error_run(nm, d, K, e0, step, opts.check_resolution, forcing)
    return _result(nm, _Run(d, opts, step.t, U, plant, error, at, forcing.W))


@dataclass(frozen=True)
class _Disturbance:
    """The disturbance channels and their samples ``W`` on the output grid (or none)."""

    channels: DisturbanceChannels | None = None
    W: np.ndarray | None = None

    @classmethod
    def of(cls, w: Any, channels: DisturbanceChannels | None, t: np.ndarray) -> _Disturbance:
        """Sample ``w`` on ``t`` (the channels are needed with it)."""
        if w is None:
            return cls()
        if channels is None:
            raise NumericError("w needs the model's disturbance channels ([disturbances] B)")
        if not callable(w):
            raise ArgumentError(
                f"w must be a function of t returning the disturbances; found {w!r}"
            )
        return cls(channels, input_samples(w, t, len(channels.names), "w"))

    def joined(
        self, d: DiscretePHS, B: np.ndarray, U: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """Return the input matrix ``[B, B_w]`` and samples ``[U, W]`` (unchanged without w)."""
        if self.channels is None or self.W is None:
            return B, U
        inputs = np.zeros((self.W.shape[0], B.shape[1])) if U is None else U
        return np.hstack([B, self.channels.columns(d)]), np.hstack([inputs, self.W])


def _zero(nm: NumericModel) -> InitialState:
    """Return the state at rest, a function of z."""
    return lambda z: np.zeros((np.atleast_1d(z).size, nm.size))


@dataclass(frozen=True)
class _Stepper:
    """The stepping of one run on its output grid ``t`` (midpoint: with its tolerance)."""

    t: np.ndarray
    scheme: str
    tol: float | None

    @classmethod
    def of(cls, options: SimulationOptions) -> _Stepper:
        """Return the stepping the options ask for, on their output grid."""
        tol = options.midpoint_tol if options.scheme == "midpoint" else None
        return cls(options.times(), options.scheme, tol)

    def __call__(
        self, E: np.ndarray, A: np.ndarray, B: np.ndarray, X0: np.ndarray, U: Any
    ) -> Trajectory:
        """Integrate ``E X' = A X + B u`` from ``X0`` with the inputs ``U`` on the grid."""
        return integrate(E, A, B, X0, self.t, U, self.scheme, tol=self.tol)


@dataclass(frozen=True)
class _ErrorRun:
    """The error system ẽ stepped on its own, and how far its energy is resolved."""

    loop: ClosedLoop
    trajectory: Trajectory
    floor: float | None = None
    until: float | None = None
    warning: str | None = None


def _error_run(
    nm: NumericModel,
    d: DiscretePHS,
    K: np.ndarray,
    e0: InitialState,
    step: _Stepper,
    check_resolution: bool,
    forcing: _Disturbance,
) -> _ErrorRun:
    """Step the error system (module docstring), and again at ⌈1.5 p⌉ to find its floor."""
    loop = d.close(K)
    report("simulate: the error system")
    Bw, W = forcing.joined(d, np.zeros((d.dim, 0)), None)
    error = step(d.E, loop.A, Bw, d.project(e0), W)
    if not check_resolution:
        return _ErrorRun(loop, error)
    fine = discretize(nm, d.method, math.ceil(1.5 * d.resolution))
    report(f"simulate: the error system at resolution {fine.resolution}, to check the first")
    Bf, Wf = forcing.joined(fine, np.zeros((fine.dim, 0)), None)
    finer = step(fine.E, fine.close(K).A, Bf, fine.project(e0), Wf)
    floor, until = _resolution_check(step.t, d.hamiltonian(error.X), fine.hamiltonian(finer.X))
    if floor is None or until is None:
        return _ErrorRun(loop, error)
    warning = _floor_warning(floor, until, d.resolution, fine.resolution)
    return _ErrorRun(loop, error, floor, until, warning)


@dataclass(frozen=True)
class _Run:
    """What the result's stages read: discretization, options, grid, inputs, trajectories."""

    d: DiscretePHS
    options: SimulationOptions
    t: np.ndarray
    U: np.ndarray | None
    plant: Trajectory
    error: _ErrorRun | None
    at: tuple[Functional, ...] = ()
    W: np.ndarray | None = None

    @property
    def trajectories(self) -> dict[str, Trajectory]:
        """The trajectories stepped, by the name warnings and ``info`` give them."""
        named = {"plant": self.plant}
        if self.error is not None:
            named["error system"] = self.error.trajectory
        return named


def _result(nm: NumericModel, run: _Run) -> SimulationResult:
    """Assemble the result: energies, outputs, displacement, audits and warnings."""
    d, error = run.d, run.error
    eh = run.plant.X
    y = d.output(eh, run.U)
    H_hat = H_err = y_hat = eo = None
    if error is not None:
        ee = error.trajectory.X
        eo = eh - ee
        H_err, H_hat = d.hamiltonian(ee), d.hamiltonian(eo)
        y_hat = y - ee @ error.loop.C.T
    audits = _audits(run)
    w = w_hat = zw = None
    if d.displacement_basis is not None:
        zw = run.options.displacement_points(nm.interval)
        Wd = d.displacement_basis(zw)
        w = eh @ Wd.T
        w_hat = None if eo is None else eo @ Wd.T
    return SimulationResult(
        t=run.t,
        H=d.hamiltonian(eh),
        H_hat=H_hat,
        H_err=H_err,
        y=y,
        y_hat=y_hat,
        output_labels=nm.output_labels,
        method=d.method,
        resolution=d.resolution,
        z_w=zw,
        w=w,
        w_hat=w_hat,
        states=eh,
        states_hat=eo,
        info=_info(run, audits),
        warnings=_warnings(run, audits),
        resolved_floor=None if error is None else error.floor,
        resolved_until=None if error is None else error.until,
        units=dict(nm.units),
        **point_series(run.at, d, eh, eo),
        **boundary_series(d, eh, eo),
    )


def _audits(run: _Run) -> dict[str, float]:
    """Energy-balance residuals of the exact stepping (module docstring of ``stepping``)."""
    d, error = run.d, run.error
    audits: dict[str, float] = {}
    if run.options.scheme != "expm":
        return audits
    if run.U is None and run.W is None:  # the plant is autonomous only without input
        audits["plant"] = energy_balance_residual(d.E, d.J - d.R, run.plant.X, run.t)
    if error is not None and run.W is None:
        audits["error system"] = energy_balance_residual(
            d.E, error.loop.A, error.trajectory.X, run.t
        )
    return audits


def _warnings(run: _Run, audits: dict[str, float]) -> tuple[str, ...]:
    """Return the energy drifts, the error energy's floor, the midpoint's missed tolerances."""
    warnings = [
        _energy_warning(name, value, run.d)
        for name, value in audits.items()
        if not value <= ENERGY_BALANCE_RTOL
    ]
    if run.error is not None and run.error.warning is not None:
        warnings.append(run.error.warning)
    for name, traj in run.trajectories.items():
        if not traj.met_tolerance:
            warnings.append(
                f"implicit midpoint did not reach its tolerance {run.options.midpoint_tol:g} "
                f"on the {name} with {traj.substeps} substeps per output interval (estimated "
                f"error {traj.error_estimate:.3g}): stiff high-frequency modes are excited; "
                "use scheme 'expm' (exact in time)"
            )
    return tuple(warnings)


def _info(run: _Run, audits: dict[str, float]) -> dict[str, Any]:
    """How the run went: scheme, size, removed modes, residuals, midpoint substeps."""
    d, options = run.d, run.options
    info: dict[str, Any] = {
        "scheme": options.scheme,
        "states": int(d.dim),
        "spurious_removed": d.spurious_removed,
        **({"spurious_modes": str(d.info["spurious"])} if d.spurious_removed else {}),
        **{f"energy_balance_residual_{k.replace(' ', '_')}": v for k, v in audits.items()},
    }
    if options.scheme == "midpoint":
        info["midpoint_tol"] = options.midpoint_tol
        for name, traj in run.trajectories.items():
            key = name.replace(" ", "_")
            info[f"midpoint_substeps_{key}"] = traj.substeps
            info[f"midpoint_error_estimate_{key}"] = traj.error_estimate
    return info
