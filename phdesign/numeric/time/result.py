r"""The result of a simulation: time series of plant, observer and error, and their exports.

:class:`SimulationResult` is what every simulator returns
(:func:`~phdesign.numeric.time.simulation.simulate`,
:func:`~phdesign.numeric.time.stochastic.simulate_noisy`,
:func:`~phdesign.numeric.sampled.simulation.simulate_sampled`; the loop's
:class:`~phdesign.numeric.control.simulation.LoopSimulation` extends it): energies
:math:`H = \tfrac12 \hat e^\top E \hat e`, :math:`\hat H` of the observer and
:math:`\tilde H` of the error, outputs, the displacement and its estimate, as JSON, CSV,
text and a figure (:class:`~phdesign.numeric.time.display.SimulationDisplay`).
"""

from __future__ import annotations

import csv
import io
import json
import math
import warnings as _warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.numeric.time.display import SimulationDisplay

__all__ = ["ResolutionWarning", "SimulationResult"]


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


def _hat(name: str) -> str:
    """Return ``rotation_hat(1)`` for the point output ``rotation(1)``."""
    field, _, point = name.partition("(")
    return f"{field}_hat({point}"


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
    at : tuple of str
        The point outputs asked for (``at``): ``"w(0.5)"``, ``"rotation(1)"``
        (:mod:`phdesign.numeric.discretization.points`).
    at_values, at_values_hat : ndarray (nt, len(at)) or None
        Their values on the plant and their estimates by the observer.
    boundary_labels : tuple of str
        A coupled model's boundary states (:mod:`phdesign.numeric.discretization.coupled`).
    x_c, x_c_hat : ndarray (nt, len(boundary_labels)) or None
        Their values :math:`x_c(t)` on the plant and the observer's estimates.
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
    at: tuple[str, ...] = ()
    at_values: np.ndarray | None = None
    at_values_hat: np.ndarray | None = None
    boundary_labels: tuple[str, ...] = ()
    x_c: np.ndarray | None = None
    x_c_hat: np.ndarray | None = None

    def at_columns(self) -> list[tuple[str, np.ndarray]]:
        """Return ``(name, series)`` of each point output, then of each estimate.

        The estimate of ``rotation(1)`` is ``rotation_hat(1)``, as ``w_hat`` is ``w``'s.
        """
        if self.at_values is None:
            return []
        cols = [(name, self.at_values[:, k]) for k, name in enumerate(self.at)]
        if self.at_values_hat is not None:
            cols += [(_hat(name), self.at_values_hat[:, k]) for k, name in enumerate(self.at)]
        return cols

    def boundary_columns(self) -> list[tuple[str, np.ndarray]]:
        """Return ``(label, series)`` of each boundary state, then of each estimate (``_hat``)."""
        if self.x_c is None:
            return []
        cols = [(label, self.x_c[:, k]) for k, label in enumerate(self.boundary_labels)]
        if self.x_c_hat is not None:
            hats = enumerate(self.boundary_labels)
            cols += [(f"{label}_hat", self.x_c_hat[:, k]) for k, label in hats]
        return cols

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
        if self.at:
            out["at"] = list(self.at)
            out["at_values"] = {name: _finite_list(v) for name, v in self.at_columns()}
        if self.x_c is not None:
            out["boundary_states"] = {n: _finite_list(v) for n, v in self.boundary_columns()}
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
        """CSV: t, H, H_hat, H_err, y_i, y_hat_i, the tip displacement w(b), ŵ(b), then ``at``.

        The point outputs ``at`` follow as ``rotation(1)``, then ``rotation_hat(1)``, and
        the boundary states as ``mass momentum``, then ``mass momentum_hat``.
        """
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
        cols += self.at_columns() + self.boundary_columns()
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
