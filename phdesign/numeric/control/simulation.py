r"""Simulation of the observer-based loop, exact in time, with its energy balance audited.

The assembled loop (:func:`phdesign.numeric.control.assembly.assemble`) is stepped in the
coordinates
:math:`Z = (\hat e, \tilde e)` where it is block-triangular.  The error state
:math:`\tilde e` is also stepped on its own (its block is the autonomous error system):
it is never formed as the difference :math:`\hat e - \hat e_{obs}` of two large numbers,
and its round-off is the error system's own, not that of the whole loop's exponential;
:math:`\hat e_{obs} = \hat e - \tilde e`.  Stepping is
:func:`phdesign.numeric.time.stepping.step_lti` (matrix exponential, exact for inputs linear
between samples; or implicit midpoint).

Energy audit, as :func:`phdesign.numeric.time.simulation.simulate` does: without free inputs
the loop is autonomous, :math:`E_2 \dot Z = A_Z Z`, and its energy
:math:`H + \tilde H = \tfrac12 Z^\top E_2 Z` changes over each step by exactly
:math:`Z_k^\top (\int_0^{\Delta t} e^{F^\top s} \operatorname{sym}(A_Z) e^{F s} ds) Z_k`
(:func:`~phdesign.numeric.time.stepping.energy_balance_residual`); the error system is
autonomous whatever the inputs and is audited on its own.  A residual above
:data:`~phdesign.numeric.time.simulation.ENERGY_BALANCE_RTOL` of the largest energy warns.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.errors import ArgumentError, LoopError
from phdesign.core.progress import report
from phdesign.core.text import html_table
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.control.assembly import LoopSystem, NumericLoop, assemble
from phdesign.numeric.discretization.coupled import boundary_series
from phdesign.numeric.discretization.functionals import Functional
from phdesign.numeric.discretization.points import point_outputs, point_series
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.inputs import input_samples
from phdesign.numeric.threads import limited_threads
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.result import SimulationResult
from phdesign.numeric.time.simulation import ENERGY_BALANCE_RTOL
from phdesign.numeric.time.stepping import energy_balance_residual, step_lti

__all__ = ["LoopSimulation", "simulate_loop"]


@dataclass(frozen=True)
class LoopSimulation(SimulationResult):
    """Time series of the loop: a :class:`~phdesign.numeric.time.result.SimulationResult`.

    Its fields (energies H, Ĥ, H̃, outputs y, ŷ, the displacement and its estimate) have
    the meaning they have for ``simulate``; ``states_hat`` holds the observer's discrete
    state ê_obs = ê − ẽ.  The loop adds:

    Attributes
    ----------
    u : ndarray (nt, m)
        The inputs the plant receives (actuated ones: −K ŷ_a or −K y_a).
    input_labels : tuple of str
    actuated : tuple of int
        1-based indices of the actuated inputs.
    states_err : ndarray (nt, dim)
        The discrete error state ẽ, stepped on its own (not written to files).
    """

    u: np.ndarray | None = None
    input_labels: tuple[str, ...] = ()
    actuated: tuple[int, ...] = ()
    states_err: np.ndarray | None = field(default=None, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the keys of ``simulate``'s JSON, plus ``u`` and the actuation."""
        out = super().to_dict()
        out.update(
            input_labels=list(self.input_labels),
            actuated=list(self.actuated),
            u=None if self.u is None else self.u.tolist(),
        )
        return out

    def to_csv(self) -> str:
        """CSV: the columns of ``simulate`` (t, H, H_hat, H_err, y, y_hat, tip), then u."""
        lines = super().to_csv().splitlines()
        if self.u is None:
            return "\n".join(lines) + "\n"
        head = lines[0] + "".join(f",u{i + 1}" for i in range(self.u.shape[1]))
        rows = [
            line + "".join(f",{float(x)!r}" for x in row)
            for line, row in zip(lines[1:], self.u, strict=True)
        ]
        return "\n".join([head, *rows]) + "\n"

    def __str__(self) -> str:
        """Return the CSV that ``phdesign loop simulate`` prints."""
        return self.to_csv()

    def _summary(self) -> list[tuple[str, str]]:
        rows = [
            ("samples", f"{self.t.size} on [{self.t[0]:g}, {self.t[-1]:g}]"),
            ("H(0) → H(T)", f"{self.H[0]:.6g} → {self.H[-1]:.6g}"),
        ]
        if self.H_err is not None:
            rows.append(("H̃(0) → H̃(T)", f"{self.H_err[0]:.6g} → {self.H_err[-1]:.6g}"))
        rows.append(("actuated", ", ".join(f"u{a}" for a in self.actuated)))
        return rows

    @property
    def title(self) -> str:
        """Model, control law (u = −K ŷ, K), sensors and L, and the discretization."""
        design = self.info.get("design")
        if not design:
            return super().title
        return f"{self.info.get('model', 'loop')}: {design}; {self.method} {self.resolution}"

    def __repr__(self) -> str:
        body = ", ".join(f"{k}: {v}" for k, v in self._summary())
        return f"LoopSimulation({body}; {len(self.warnings)} warning(s))"[:300]

    def _repr_html_(self) -> str:
        rows = [*self._summary(), *(("warning", w) for w in self.warnings)]
        return html_table((), rows, "loop simulation")

    def plot(self, path: Any = None, *, force: bool = False, title: str | None = None) -> Any:
        """Draw the summary figure (energies, tip, estimate): :func:`.plots.plot_simulation`."""
        from phdesign.plots import plot_simulation

        return plot_simulation(self, path, force=force, title=title)


@limited_threads
def simulate_loop(
    nm: NumericModel,
    loop: NumericLoop,
    *,
    x0: Callable[[np.ndarray], np.ndarray] | None = None,
    xhat0: Callable[[np.ndarray], np.ndarray] | None = None,
    u: Callable[[float], np.ndarray] | None = None,
    options: SimulationOptions | None = None,
) -> LoopSimulation:
    """Simulate plant, observer and feedback together (module docstring).

    Parameters
    ----------
    nm : NumericModel
    loop : NumericLoop
    x0, xhat0 : callable, optional
        Initial plant and observer states ``f(z) -> (m, n)``; default zero.
    u : callable, optional
        ``u(t) -> (n_ports,)``: signals on the inputs that are *not* actuated (the
        actuated entries must be zero; the controller sets them).
    options : SimulationOptions, optional
        ``t_end``, ``samples``, ``method``, ``resolution``, ``scheme``, ``z_w`` and ``at``
        (point outputs of the plant and of the observer), as for
        :func:`phdesign.numeric.time.simulation.simulate`.  The loop's midpoint steps once
        per output interval (no ``tol``); a sampled or noisy loop is not simulated.

    Returns
    -------
    LoopSimulation

    Raises
    ------
    LoopError
        If ``u`` drives an actuated input.

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> from phdesign.numeric.inputs import initial_state_function
    >>> beam = load_builtin("euler-bernoulli")
    >>> nm = to_numeric(beam)
    >>> loop = NumericLoop((2,), np.eye(1), np.array([[0, 0, 0, 1.0]]), np.eye(1))
    >>> x0 = initial_state_function("x1: 0, x2: z - 0.9", nm, model=beam)
    >>> options = SimulationOptions(t_end=1.0, samples=3, resolution=12)
    >>> run = simulate_loop(nm, loop, x0=x0, options=options)
    >>> bool(run.H[-1] < run.H[0]), run.warnings
    (True, ())
    """
    opts = SimulationOptions.merged(options)
    opts.require("simulate_loop", "continuous")
    if opts.tol is not None:
        raise ArgumentError(
            f"tol: the loop's midpoint steps once per output interval, without a tolerance; "
            f"found tol={opts.tol!r}"
        )
    at = point_outputs(nm, opts.at, "at")  # an unknown field is refused before any work
    system = assemble(discretize(nm, opts.method, opts.resolution), loop)
    d, n = system.discrete, system.dim
    t = opts.times()
    V = None if u is None else _free_inputs(input_samples(u, t, d.n_ports), system)
    zero = lambda z: np.zeros((np.atleast_1d(z).size, nm.size))  # noqa: E731
    e0, eo0 = d.project(x0 or zero), d.project(xhat0 or zero)
    A_Z, B_Z = system.error_coordinates()
    report(f"loop: simulating the loop, resolution {d.resolution}")
    Z = step_lti(system.E, A_Z, B_Z, np.concatenate([e0, e0 - eo0]), t, V, opts.scheme)
    # the error block is autonomous: stepped on its own, its round-off is the error
    # system's, not that of a stiff controlled plant (a damper on a derivative trace
    # makes ‖A_K‖ ≫ ‖Ã‖, and one exponential of the whole loop carries it into ẽ)
    A_err = A_Z[n:, n:]
    report("loop: simulating the error system")
    err = step_lti(d.E, A_err, np.zeros((n, 0)), e0 - eo0, t, None, opts.scheme)
    audits = {"error system": energy_balance_residual(d.E, A_err, err, t, opts.scheme)}
    if V is None:  # the loop is autonomous only without free inputs
        audits["loop"] = energy_balance_residual(system.E, A_Z, Z, t, opts.scheme)
    return _result(nm, system, opts, t, (Z[:, :n], err), V, audits, at)


def _free_inputs(U: np.ndarray, system: LoopSystem) -> np.ndarray | None:
    """Return the samples of the inputs not actuated (None when all are zero).

    Raises
    ------
    LoopError
        If ``U`` drives an actuated input.
    """
    driven = [a + 1 for a in system.loop.actuated if np.any(U[:, a])]
    if driven:
        raise LoopError(
            f"u{driven[0]} is actuated by the feedback; `u` drives only the other inputs "
            f"({', '.join(f'u{j + 1}' for j in system.others) or 'none'})"
        )
    return U[:, list(system.others)] if np.any(U) else None


def _result(
    nm: NumericModel,
    system: LoopSystem,
    options: SimulationOptions,
    t: np.ndarray,
    states: tuple[np.ndarray, np.ndarray],
    V: np.ndarray | None,
    audits: dict[str, float],
    at: tuple[Functional, ...],
) -> LoopSimulation:
    """Return the loop's series: inputs and outputs from the assembled maps, energies.

    ``states`` are the plant's ê and the error's ẽ; the observer's is ê − ẽ.
    """
    d, loop = system.discrete, system.loop
    eh, err = states
    X = np.hstack([eh, eh - err])
    inputs = X @ system.C_u.T + (0.0 if V is None else V @ system.D_u.T)
    y = X @ system.C_y.T + (0.0 if V is None else V @ system.D_y.T)
    y_hat = X @ system.C_yhat.T + (0.0 if V is None else V @ system.D_yhat.T)
    warnings = tuple(
        f"the {name}'s energy balance drifts by {value:.3g} of its largest energy "
        f"(tolerance {ENERGY_BALANCE_RTOL:g}): the time stepping lost accuracy; "
        "lower the resolution or use `scheme='midpoint'`"
        for name, value in audits.items()
        if not value <= ENERGY_BALANCE_RTOL
    )
    w = w_hat = zw = None
    if d.displacement_basis is not None:
        zw = options.displacement_points(nm.interval)
        W = d.displacement_basis(zw)
        w, w_hat = eh @ W.T, (eh - err) @ W.T
    return LoopSimulation(
        t=t,
        H=d.hamiltonian(eh),
        H_hat=d.hamiltonian(eh - err),
        H_err=d.hamiltonian(err),
        u=inputs,
        y=y,
        y_hat=y_hat,
        input_labels=nm.input_labels,
        output_labels=nm.output_labels,
        actuated=tuple(a + 1 for a in loop.actuated),
        method=d.method,
        resolution=d.resolution,
        z_w=zw,
        w=w,
        w_hat=w_hat,
        states=eh,
        states_hat=eh - err,
        states_err=err,
        info={
            "scheme": options.scheme,
            "states": int(2 * d.dim),
            "feedback_source": loop.source,
            **{f"energy_balance_residual_{k.replace(' ', '_')}": v for k, v in audits.items()},
        },
        warnings=warnings,
        units=dict(nm.units),
        **point_series(at, d, eh, eh - err),
        **boundary_series(d, eh, eh - err),
    )
