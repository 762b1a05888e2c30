r"""Simulation of the observer-based loop, exact in time, with its energy balance audited.

The assembled loop (:func:`phdesign.numeric.loop.assemble`) is stepped in the coordinates
:math:`Z = (\hat e, \tilde e)` where it is block-triangular.  The error state
:math:`\tilde e` is also stepped on its own (its block is the autonomous error system):
it is never formed as the difference :math:`\hat e - \hat e_{obs}` of two large numbers,
and its round-off is the error system's own, not that of the whole loop's exponential;
:math:`\hat e_{obs} = \hat e - \tilde e`.  Stepping is
:func:`phdesign.numeric.simulate.step_lti` (matrix exponential, exact for inputs linear
between samples; or implicit midpoint).

Energy audit, as :func:`phdesign.numeric.simulate.simulate` does: without free inputs
the loop is autonomous, :math:`E_2 \dot Z = A_Z Z`, and its energy
:math:`H + \tilde H = \tfrac12 Z^\top E_2 Z` changes over each step by exactly
:math:`Z_k^\top (\int_0^{\Delta t} e^{F^\top s} \operatorname{sym}(A_Z) e^{F s} ds) Z_k`
(:func:`~phdesign.numeric.simulate.energy_balance_residual`); the error system is
autonomous whatever the inputs and is audited on its own.  A residual above
:data:`~phdesign.numeric.simulate.ENERGY_BALANCE_RTOL` of the largest energy warns.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.errors import LoopError, NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretize import discretize
from phdesign.numeric.loop import NumericLoop, assemble
from phdesign.numeric.simulate import ENERGY_BALANCE_RTOL, energy_balance_residual, step_lti

__all__ = ["LoopSimulation", "simulate_loop"]


@dataclass(frozen=True)
class LoopSimulation:
    """Time series of the loop: energies, inputs, outputs, estimates and the displacement.

    Attributes
    ----------
    t : ndarray (nt,)
    H, H_hat, H_err : ndarray (nt,)
        Plant, observer and error energies.
    u : ndarray (nt, m)
        The inputs the plant receives (actuated ones: −K ŷ_a or −K y_a).
    y, y_hat : ndarray (nt, m)
        Plant and observer outputs.
    input_labels, output_labels : tuple of str
    actuated : tuple of int
        1-based indices of the actuated inputs.
    z_w, w, w_hat : ndarray or None
        Displacement points and the displacement of the plant and its estimate.
    states, states_err : ndarray (nt, dim)
        Discrete plant and error states (not written to files).
    info : dict
        Scheme, sizes and the energy-balance residuals.
    """

    t: np.ndarray
    H: np.ndarray
    H_hat: np.ndarray
    H_err: np.ndarray
    u: np.ndarray
    y: np.ndarray
    y_hat: np.ndarray
    input_labels: tuple[str, ...]
    output_labels: tuple[str, ...]
    actuated: tuple[int, ...]
    method: str
    resolution: int
    z_w: np.ndarray | None = None
    w: np.ndarray | None = None
    w_hat: np.ndarray | None = None
    states: np.ndarray | None = field(default=None, repr=False)
    states_err: np.ndarray | None = field(default=None, repr=False)
    info: dict[str, Any] = field(default_factory=dict, repr=False)
    warnings: tuple[str, ...] = ()
    units: dict[str, str] | None = field(default=None, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (the keys of ``simulate``'s JSON, plus ``u`` and the actuation)."""
        out: dict[str, Any] = {
            "method": self.method,
            "resolution": self.resolution,
            "t": self.t.tolist(),
            "H": self.H.tolist(),
            "H_hat": self.H_hat.tolist(),
            "H_err": self.H_err.tolist(),
            "input_labels": list(self.input_labels),
            "output_labels": list(self.output_labels),
            "actuated": list(self.actuated),
            "u": self.u.tolist(),
            "y": self.y.tolist(),
            "y_hat": self.y_hat.tolist(),
        }
        if self.w is not None and self.z_w is not None and self.w_hat is not None:
            out.update(z_w=self.z_w.tolist(), w=self.w.tolist(), w_hat=self.w_hat.tolist())
        out.update({k: v for k, v in self.info.items() if isinstance(v, (int, float, str))})
        out["warnings"] = list(self.warnings)
        out["units"] = dict(self.units or {})
        return out

    def to_json(self) -> str:
        """Return :meth:`to_dict` as JSON text."""
        return json.dumps(self.to_dict())

    def to_csv(self) -> str:
        """CSV: t, H, H_hat, H_err, u_i, y_i, y_hat_i and the tip displacement w(b), ŵ(b)."""
        cols: list[tuple[str, np.ndarray]] = [
            ("t", self.t),
            ("H", self.H),
            ("H_hat", self.H_hat),
            ("H_err", self.H_err),
        ]
        cols += [(f"u{i + 1}", self.u[:, i]) for i in range(self.u.shape[1])]
        cols += [(f"y{i + 1}", self.y[:, i]) for i in range(self.y.shape[1])]
        cols += [(f"y_hat{i + 1}", self.y_hat[:, i]) for i in range(self.y_hat.shape[1])]
        if self.w is not None and self.w_hat is not None:
            cols += [("w_tip", self.w[:, -1]), ("w_hat_tip", self.w_hat[:, -1])]
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow([name for name, _ in cols])
        for row in np.column_stack([c for _, c in cols]):
            writer.writerow([repr(float(x)) for x in row])
        return buffer.getvalue()

    def __str__(self) -> str:
        """Return the CSV that ``phdesign loop simulate`` prints."""
        return self.to_csv()

    def _summary(self) -> list[tuple[str, str]]:
        return [
            ("samples", f"{self.t.size} on [{self.t[0]:g}, {self.t[-1]:g}]"),
            ("H(0) → H(T)", f"{self.H[0]:.6g} → {self.H[-1]:.6g}"),
            ("H̃(0) → H̃(T)", f"{self.H_err[0]:.6g} → {self.H_err[-1]:.6g}"),
            ("actuated", ", ".join(f"u{a}" for a in self.actuated)),
        ]

    def __repr__(self) -> str:
        body = ", ".join(f"{k}: {v}" for k, v in self._summary())
        return f"LoopSimulation({body}; {len(self.warnings)} warning(s))"[:300]

    def _repr_html_(self) -> str:
        from html import escape

        rows = "".join(
            f"<tr><td>{escape(k)}</td><td>{escape(v)}</td></tr>"
            for k, v in [*self._summary(), *(("warning", w) for w in self.warnings)]
        )
        return f"<table><caption>loop simulation</caption>{rows}</table>"

    def plot(self, path: Any = None, *, force: bool = False, title: str | None = None) -> Any:
        """Draw the summary figure (energies, tip, estimate): :func:`.plots.plot_simulation`."""
        from phdesign.plots import plot_simulation

        return plot_simulation(self, path, force=force, title=title)


def simulate_loop(
    nm: NumericModel,
    loop: NumericLoop,
    *,
    x0: Callable[[np.ndarray], np.ndarray] | None = None,
    xhat0: Callable[[np.ndarray], np.ndarray] | None = None,
    t_end: float = 5.0,
    samples: int = 501,
    method: str = "galerkin",
    resolution: int | None = None,
    u: Callable[[float], np.ndarray] | None = None,
    scheme: str = "expm",
    z_w: np.ndarray | None = None,
) -> LoopSimulation:
    """Simulate plant, observer and feedback together (module docstring).

    Parameters
    ----------
    nm : NumericModel
    loop : NumericLoop
    x0, xhat0 : callable, optional
        Initial plant and observer states ``f(z) -> (m, n)``; default zero.
    t_end, samples, method, resolution, scheme, z_w
        As for :func:`phdesign.numeric.simulate.simulate`.
    u : callable, optional
        ``u(t) -> (n_ports,)``: signals on the inputs that are *not* actuated (the
        actuated entries must be zero; the controller sets them).

    Returns
    -------
    LoopSimulation

    Raises
    ------
    LoopError
        If ``u`` drives an actuated input.
    """
    if not (np.isfinite(t_end) and t_end > 0):
        raise NumericError(f"t_end must be a positive number; found {t_end}")
    if int(samples) < 2:
        raise NumericError(f"samples must be at least 2; found {samples}")
    system = assemble(discretize(nm, method, resolution), loop)
    d, n, m = system.discrete, system.dim, system.discrete.n_ports
    t = np.linspace(0.0, float(t_end), int(samples))
    V = None
    if u is not None:
        U = np.array([np.asarray(u(float(tk)), dtype=float).reshape(m) for tk in t])
        driven = [a + 1 for a in loop.actuated if np.any(U[:, a])]
        if driven:
            raise LoopError(
                f"u{driven[0]} is actuated by the feedback; --u drives only the other inputs "
                f"({', '.join(f'u{j + 1}' for j in system.others) or 'none'})"
            )
        V = U[:, list(system.others)] if np.any(U) else None
    zero = lambda z: np.zeros((np.atleast_1d(z).size, nm.size))  # noqa: E731
    e0, eo0 = d.project(x0 or zero), d.project(xhat0 or zero)
    A_Z, B_Z = system.error_coordinates()
    Z = step_lti(system.E, A_Z, B_Z, np.concatenate([e0, e0 - eo0]), t, V, scheme)
    # the error block is autonomous: stepped on its own, its round-off is the error
    # system's, not that of a stiff controlled plant (a damper on a derivative trace
    # makes ‖A_K‖ ≫ ‖Ã‖, and one exponential of the whole loop carries it into ẽ)
    A_err = A_Z[n:, n:]
    err = step_lti(d.E, A_err, np.zeros((n, 0)), e0 - eo0, t, None, scheme)
    eh = Z[:, :n]
    X = np.hstack([eh, eh - err])
    inputs = X @ system.C_u.T + (0.0 if V is None else V @ system.D_u.T)
    y = X @ system.C_y.T + (0.0 if V is None else V @ system.D_y.T)
    y_hat = X @ system.C_yhat.T + (0.0 if V is None else V @ system.D_yhat.T)
    audits = {"error system": energy_balance_residual(d.E, A_err, err, t, scheme)}
    if V is None:  # the loop is autonomous only without free inputs
        audits["loop"] = energy_balance_residual(system.E, A_Z, Z, t, scheme)
    warnings = tuple(
        f"the {name}'s energy balance drifts by {value:.3g} of its largest energy "
        f"(tolerance {ENERGY_BALANCE_RTOL:g}): the time stepping lost accuracy; "
        "lower the resolution or use --scheme midpoint"
        for name, value in audits.items()
        if not value <= ENERGY_BALANCE_RTOL
    )
    w = w_hat = zw = None
    if d.displacement_basis is not None:
        a, b = nm.interval
        zw = np.linspace(a, b, 21) if z_w is None else np.asarray(z_w, dtype=float)
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
        states_err=err,
        info={
            "scheme": scheme,
            "states": int(2 * n),
            "feedback_source": loop.source,
            **{f"energy_balance_residual_{k.replace(' ', '_')}": v for k, v in audits.items()},
        },
        warnings=warnings,
        units=dict(nm.units),
    )
