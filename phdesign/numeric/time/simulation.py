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

so the error system is stepped on its own and :math:`\tilde H = \tfrac12 \tilde e^\top E
\tilde e` is computed from :math:`\tilde e` itself: no cancellation of plant minus
observer (that difference loses all relative accuracy once :math:`\tilde H` is
:math:`10^{-11}` of :math:`\tilde H(0)`).  The observer is :math:`\hat e - \tilde e`
and :math:`\hat y = y - \tilde y`, :math:`\tilde y = (I - D G) B^\top \tilde e`.
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

import csv
import io
import json
import math
import warnings as _warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.defaults import current, method_or_default
from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_simulate_arguments
from phdesign.numeric.discretization.registry import DiscretePHS, discretize, feedback_matrix
from phdesign.numeric.inputs import input_samples
from phdesign.numeric.threads import limited_threads
from phdesign.numeric.time.display import SimulationDisplay
from phdesign.numeric.time.stepping import (
    SCHEMES,
    Trajectory,
    energy_balance_residual,
    integrate,
    step_lti,
)

__all__ = [
    "ENERGY_BALANCE_RTOL",
    "RESOLVED_RTOL",
    "ResolutionWarning",
    "SimulationResult",
    "coupled_system",
    "energy_balance_residual",
    "simulate",
    "step_lti",
]

#: Largest energy-balance residual, relative to the largest energy of the run, that a
#: simulation may show before it warns. Exact stepping leaves round-off (about 1e-13).
ENERGY_BALANCE_RTOL = 1e-8
#: Relative disagreement of the error energy between the resolution p and ⌈1.5 p⌉ beyond
#: which it is not resolved.
RESOLVED_RTOL = 0.05


class ResolutionWarning(UserWarning):
    """A quantity was asked for below what the discretization resolves."""


def _finite_list(values: np.ndarray | None) -> list[Any] | None:
    """Nested list with non-finite entries as None (strict JSON)."""
    if values is None:
        return None
    arr = np.asarray(values, dtype=float)
    if np.all(np.isfinite(arr)):
        return arr.tolist()  # type: ignore[no-any-return]
    cells = arr.astype(object)
    cells[~np.isfinite(arr)] = None
    return cells.tolist()  # type: ignore[no-any-return]


def _json_safe(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, list):
        return [_json_safe(v) for v in value]
    return value


@dataclass(frozen=True, repr=False)
class SimulationResult(SimulationDisplay):
    """Time series of a plant (and observer) simulation.

    Attributes
    ----------
    t : ndarray (nt,)
    H, H_hat, H_err : ndarray (nt,)
        Plant, observer and error energies (``H_hat``/``H_err`` are None without observer).
    y, y_hat : ndarray (nt, N n)
        Plant and observer outputs.
    output_labels : tuple of str
    z_w : ndarray or None
        Points where the displacement is sampled.
    w, w_hat : ndarray (nt, len(z_w)) or None
        Displacement of the plant and its estimate (models with a displacement only).
    states, states_hat : ndarray (nt, dim)
        Discrete effort coordinates (kept for exports and checks; not written to files).
    units : mapping or None
        Units the model states (``t``, ``z``, ``energy``, ``displacement``, ...), for labels
        and JSON; ``None`` for a result built by hand (plots then assume SI).
    resolved_floor : float or None
        Smallest H_err / H_err(0) down to which the error energy agrees with the finer
        resolution (None: resolved over the whole run, or not checked).
    resolved_until : float or None
        Last sample time at which it still agrees (None likewise).
    """

    t: np.ndarray
    H: np.ndarray
    H_hat: np.ndarray | None
    H_err: np.ndarray | None
    y: np.ndarray
    y_hat: np.ndarray | None
    output_labels: tuple[str, ...]
    method: str
    resolution: int
    z_w: np.ndarray | None = None
    w: np.ndarray | None = None
    w_hat: np.ndarray | None = None
    states: np.ndarray | None = field(default=None, repr=False)
    states_hat: np.ndarray | None = field(default=None, repr=False)
    info: dict[str, Any] = field(default_factory=dict, repr=False)
    warnings: tuple[str, ...] = ()
    units: dict[str, str] | None = field(default=None, repr=False)
    resolved_floor: float | None = None
    resolved_until: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary of the time series (no discrete states; strict JSON)."""
        out: dict[str, Any] = {
            "method": self.method,
            "resolution": self.resolution,
            "t": _finite_list(self.t),
            "H": _finite_list(self.H),
            "H_hat": _finite_list(self.H_hat),
            "H_err": _finite_list(self.H_err),
            "output_labels": list(self.output_labels),
            "y": _finite_list(self.y),
            "y_hat": _finite_list(self.y_hat),
            "resolved_floor": _json_safe(self.resolved_floor),
            "resolved_until": _json_safe(self.resolved_until),
        }
        if self.w is not None and self.z_w is not None:
            out["z_w"] = _finite_list(self.z_w)
            out["w"] = _finite_list(self.w)
            out["w_hat"] = _finite_list(self.w_hat)
        out.update(
            {
                k: _json_safe(v)
                for k, v in self.info.items()
                if isinstance(v, (int, float, str)) and k not in out
            }
        )
        out["warnings"] = list(self.warnings)
        out["units"] = dict(self.units or {})
        return out

    def to_json(self) -> str:
        """Return the :meth:`to_dict` payload as JSON text."""
        return json.dumps(self.to_dict(), allow_nan=False)

    def to_csv(self) -> str:
        """CSV: t, H, H_hat, H_err, y_i, y_hat_i and the tip displacement w(b), ŵ(b)."""
        cols: list[tuple[str, np.ndarray]] = [("t", self.t), ("H", self.H)]
        if self.H_hat is not None and self.H_err is not None:
            cols += [("H_hat", self.H_hat), ("H_err", self.H_err)]
        for i in range(self.y.shape[1]):
            cols.append((f"y{i + 1}", self.y[:, i]))
        if self.y_hat is not None:
            for i in range(self.y_hat.shape[1]):
                cols.append((f"y_hat{i + 1}", self.y_hat[:, i]))
        if self.w is not None:
            cols.append(("w_tip", self.w[:, -1]))
            if self.w_hat is not None:
                cols.append(("w_hat_tip", self.w_hat[:, -1]))
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow([c[0] for c in cols])
        data = np.column_stack([c[1] for c in cols])
        for row in data:
            writer.writerow([repr(float(x)) for x in row])
        return buf.getvalue()

    def time_below(self, ratio: float) -> float | None:
        """First sample time after which H_err / H_err(0) stays below ``ratio``.

        None when it never does in this run, and None (with a
        :class:`ResolutionWarning` that says why) when ``ratio`` is below
        :attr:`resolved_floor`: the time would be that of unresolved modes.
        """
        if self.H_err is None or self.H_err[0] <= 0:
            return None
        if self.resolved_floor is not None and ratio < self.resolved_floor:
            _warnings.warn(
                f"H_err/H_err(0) = {ratio:g} is below what this discretization resolves "
                f"({self.resolved_floor:.3g}, reached at t = {self.resolved_until:g}): "
                "raise the resolution",
                ResolutionWarning,
                stacklevel=2,
            )
            return None
        rel = self.H_err / self.H_err[0]
        above = np.flatnonzero(rel >= ratio)
        if above.size == 0:
            return float(self.t[0])
        k = above[-1]
        if k + 1 >= self.t.size:
            return None
        # linear interpolation of log(rel) between the last sample above and the next
        r0, r1 = np.log(rel[k]), np.log(max(rel[k + 1], 1e-300))
        s = (np.log(ratio) - r0) / (r1 - r0) if r1 != r0 else 0.0
        return float(self.t[k] + s * (self.t[k + 1] - self.t[k]))


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
    x0: Callable[[np.ndarray], np.ndarray] | None = None,
    xhat0: Callable[[np.ndarray], np.ndarray] | None = None,
    t_end: float | None = None,
    samples: int | None = None,
    method: str | None = None,
    resolution: int | None = None,
    u: Callable[[float], np.ndarray] | None = None,
    scheme: str | None = None,
    z_w: np.ndarray | None = None,
    discrete: DiscretePHS | None = None,
    tol: float | None = None,
    check_resolution: bool = True,
) -> SimulationResult:
    """Simulate the plant, and the observer when sensors are given.

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray, optional
        Sensors and gain (both or neither).
    x0, xhat0 : callable, optional
        Initial states ``f(z) -> (m, n)`` (see
        :func:`phdesign.numeric.inputs.initial_state_function`); default zero.
    t_end : float, optional
        Final time (> 0); default 5.
    samples : int, optional
        Number of output samples on [0, t_end] (>= 2); default 501.
    method, resolution
        Discretization (see :func:`phdesign.numeric.discretization.registry.discretize`).
    u : callable, optional
        Plant input ``u(t) -> (N n,)``, sampled on the output grid and linear in between;
        default zero.
    scheme : {"expm", "midpoint"}, optional
        Exact exponential (the default), or implicit midpoint with substeps chosen so that its
        estimated error is below ``tol`` (:mod:`phdesign.numeric.time.stepping`).
    z_w : ndarray, optional
        Points where the displacement is reported (default 21 uniform points).
    discrete : DiscretePHS, optional
        A ready discretization (overrides ``method``/``resolution``).
    tol : float, optional
        Midpoint: largest estimated error of the states, relative to their largest
        energy norm (default 1e-6; the defaults are those of :mod:`phdesign.core.defaults`).
    check_resolution : bool
        With an observer, step the error system again at ⌈1.5 p⌉ to find how far
        H_err is resolved (module docstring); default True.

    Returns
    -------
    SimulationResult
    """
    t_end, samples, scheme, tol = current().simulation.fill(t_end, samples, scheme, tol)
    method = method_or_default(method)
    check_simulate_arguments(
        nm,
        C_m,
        L,
        x0=x0,
        xhat0=xhat0,
        t_end=t_end,
        samples=samples,
        method=method,
        resolution=resolution,
        u=u,
        scheme=scheme,
        z_w=z_w,
        discrete=discrete,
    )
    # t_end, samples and (C_m, L) were checked above: the scheme's name is left
    if scheme not in SCHEMES:
        raise NumericError(f"unknown time-stepping scheme {scheme!r}; expected one of {SCHEMES}")
    d = discrete if discrete is not None else discretize(nm, method, resolution)
    K = None if C_m is None or L is None else feedback_matrix(C_m, L, nm.n_ports)
    t = np.linspace(0.0, float(t_end), int(samples))
    zero = lambda z: np.zeros((np.atleast_1d(z).size, nm.size))  # noqa: E731
    U = None
    if u is not None:
        U = input_samples(u, t, nm.n_ports)
    midpoint_tol = tol if scheme == "midpoint" else None

    def run(E: np.ndarray, A: np.ndarray, B: np.ndarray, X0: np.ndarray, inp: Any) -> Trajectory:
        return integrate(E, A, B, X0, t, inp, scheme, tol=midpoint_tol)

    plant = run(d.E, d.J - d.R, d.B, d.project(x0 or zero), U)
    eh = plant.X
    y = d.output(eh, U)
    H = d.hamiltonian(eh)
    trajectories = {"plant": plant}
    H_hat = H_err = y_hat = eo = None
    floor = until = None
    warnings: list[str] = []
    loop = None
    if K is not None:
        loop = d.close(K)
        e0_err = d.project(_difference(x0 or zero, xhat0 or zero))
        error = run(d.E, loop.A, np.zeros((d.dim, 0)), e0_err, None)
        trajectories["error system"] = error
        ee = error.X
        eo = eh - ee
        H_err = d.hamiltonian(ee)
        H_hat = d.hamiltonian(eo)
        y_hat = y - ee @ loop.C.T
        if check_resolution:
            fine = discretize(nm, d.method, math.ceil(1.5 * d.resolution))
            fine_err = run(
                fine.E,
                fine.close(K).A,
                np.zeros((fine.dim, 0)),
                fine.project(_difference(x0 or zero, xhat0 or zero)),
                None,
            )
            floor, until = _resolution_check(t, H_err, fine.hamiltonian(fine_err.X))
            if floor is not None and until is not None:
                warnings.append(_floor_warning(floor, until, d.resolution, fine.resolution))
    audits: dict[str, float] = {}
    if scheme == "expm":
        if U is None:  # the plant is autonomous only without input
            audits["plant"] = energy_balance_residual(d.E, d.J - d.R, eh, t)
        if loop is not None:
            audits["error system"] = energy_balance_residual(
                d.E, loop.A, trajectories["error system"].X, t
            )
    warnings = [
        _energy_warning(name, value, d)
        for name, value in audits.items()
        if not value <= ENERGY_BALANCE_RTOL
    ] + warnings
    for name, traj in trajectories.items():
        if not traj.met_tolerance:
            warnings.append(
                f"implicit midpoint did not reach its tolerance {tol:g} on the {name} with "
                f"{traj.substeps} substeps per output interval (estimated error "
                f"{traj.error_estimate:.3g}): stiff high-frequency modes are excited; "
                "use scheme 'expm' (exact in time)"
            )
    w = w_hat = zw = None
    if d.displacement_basis is not None:
        a, b = nm.interval
        zw = np.linspace(a, b, 21) if z_w is None else np.asarray(z_w, dtype=float)
        Wd = d.displacement_basis(zw)
        w = eh @ Wd.T
        if eo is not None:
            w_hat = eo @ Wd.T
    info: dict[str, Any] = {
        "scheme": scheme,
        "states": int(d.dim),
        "spurious_removed": d.spurious_removed,
        **({"spurious_modes": str(d.info["spurious"])} if d.spurious_removed else {}),
        **{f"energy_balance_residual_{k.replace(' ', '_')}": v for k, v in audits.items()},
    }
    if scheme == "midpoint":
        info["midpoint_tol"] = tol
        for name, traj in trajectories.items():
            key = name.replace(" ", "_")
            info[f"midpoint_substeps_{key}"] = traj.substeps
            info[f"midpoint_error_estimate_{key}"] = traj.error_estimate
    return SimulationResult(
        t=t,
        H=H,
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
        info=info,
        warnings=tuple(warnings),
        resolved_floor=floor,
        resolved_until=until,
        units=dict(nm.units),
    )


def _difference(
    f: Callable[[np.ndarray], np.ndarray], g: Callable[[np.ndarray], np.ndarray]
) -> Callable[[np.ndarray], np.ndarray]:
    """Return the initial estimation error x0 - xhat0 (the projection is linear)."""

    def diff(z: np.ndarray) -> np.ndarray:
        return np.asarray(f(z), dtype=float) - np.asarray(g(z), dtype=float)

    return diff
