r"""The plant run once from every initial state of a verification set; observers replayed on it.

A design's verification compares many candidate observers on the same data, so the plant's
part of every run is computed once (:class:`StateRuns`): from each initial state of the set
the plant's exact sampled trajectory (:func:`~phdesign.numeric.sampled.period_maps.sample_plant`,
inputs at rest) gives the measured samples :math:`y_{m,k}` of every period and the plant's
performance outputs at the records. Any discrete observer :math:`(A, B, C, D)` driven by
:math:`v_k = (0;\ y_{m,k})` from :math:`\hat x_0 = 0` is then one recursion
(:meth:`StateRuns.floors`), and the continuous observer of the design (the reference
:math:`F_c`) one exact exponential of the plant and observer together
(:class:`~phdesign.numeric.sampled.runs.LoopMaps`), both on the same records.

The floor of a state is :math:`F = \max_k |w(t_k) - \hat w_k|` over the records of the
window, the last fifth of the run (``FLOOR_WINDOW``; [4, 5] s for the default 5 s), maximum
over the performance outputs; records are every ``stride`` periods, about ``samples`` of
them (every 10 ms for the default 501 over 5 s).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.defaults import current
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.sampled.period_maps import Realization, sample_plant
from phdesign.numeric.sampled.runs import FLOOR_WINDOW, LoopMaps, plant_targets
from phdesign.numeric.sampled.samplers import ContinuousObserver
from phdesign.numeric.sampled.state_set import InitialState

__all__ = ["StateFloors", "StateRuns"]

#: Records advanced together before the floors' window (:meth:`StateRuns.window_errors`).
CHUNK = 20


@dataclass(frozen=True)
class StateFloors:
    r"""One design's error floors over a verification set, against the continuous observer.

    Attributes
    ----------
    design : str
        Which design (``"passive"``, ``"kalman"``, ``"paper gain"``).
    states : tuple of str
        The initial states, as the reports name them.
    floors, continuous_floors : ndarray (s,)
        :math:`F` of the design and :math:`F_c` of the continuous observer with the given
        gain, per state, over ``window``.
    window : tuple of float
        The records' span the floors are taken over (s).
    """

    design: str
    states: tuple[str, ...]
    floors: np.ndarray = field(repr=False)
    continuous_floors: np.ndarray = field(repr=False)
    window: tuple[float, float]

    @property
    def ratios(self) -> np.ndarray:
        """:math:`F / F_c` per state (inf where :math:`F_c = 0 < F`, 1 where both vanish)."""
        F, Fc = self.floors, self.continuous_floors
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(Fc > 0, F / np.where(Fc > 0, Fc, 1.0), np.where(F > 0, np.inf, 1.0))
        return np.asarray(r, dtype=float)

    @property
    def worst(self) -> float:
        """The worst ratio over the set (inf when a floor is not finite)."""
        r = self.ratios
        return float(np.max(r)) if np.all(np.isfinite(self.floors)) else math.inf

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (strict JSON: a non-finite number is null)."""

        def number(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None

        return {
            "design": self.design,
            "window": list(self.window),
            "states": [
                {"x0": s, "floor": number(F), "continuous_floor": number(Fc), "ratio": number(r)}
                for s, F, Fc, r in zip(
                    self.states, self.floors, self.continuous_floors, self.ratios, strict=True
                )
            ],
            "worst_ratio": number(self.worst),
        }

    def __str__(self) -> str:
        t0, t1 = self.window
        lines = [
            f"{self.design}: error floor F over t = {t0:g}..{t1:g} s against the continuous "
            f"observer's F_c, per initial state (worst F/F_c {self.worst:.3g}):"
        ]
        for s, F, Fc, r in zip(
            self.states, self.floors, self.continuous_floors, self.ratios, strict=True
        ):
            lines.append(f"  F = {F:.3g}, F_c = {Fc:.3g}, F/F_c = {r:.3g}: {s}")
        return "\n".join(lines)


@dataclass(frozen=True)
class StateRuns:
    """The plant's runs from every state of the set, shared by every candidate observer.

    Attributes
    ----------
    states : tuple of InitialState
    dt : float
    n_steps, stride : int
    measured : ndarray (n_steps + 1, n_sensors, s)
        :math:`y_{m,k}` (the sampler's reading of period k) for each state.
    targets : ndarray (nr, n_performance, s)
        The plant's performance outputs at the records.
    t : ndarray (nr,)
    continuous_floors : ndarray (s,)
        :math:`F_c` of the continuous observer ``observer`` over the window.
    n_inputs : int
        Plant inputs u at the head of v (zero in these runs).
    """

    states: tuple[InitialState, ...]
    dt: float
    n_steps: int
    stride: int
    measured: np.ndarray = field(repr=False)
    targets: np.ndarray = field(repr=False)
    t: np.ndarray = field(repr=False)
    continuous_floors: np.ndarray = field(repr=False)
    performance: tuple[int, ...]
    n_inputs: int

    @classmethod
    def run(
        cls,
        plant: DiscretePHS,
        observer: ContinuousObserver,
        C_m: np.ndarray,
        *,
        states: Sequence[InitialState],
        dt: float,
        sampler: str,
        t_end: float,
        samples: int | None = None,
    ) -> StateRuns:
        """Run ``plant`` from every state once (u = 0), and the continuous ``observer`` on it."""
        samples = current().simulation.samples if samples is None else samples
        n_steps = max(1, round(t_end / dt))
        stride = max(1, round(t_end / ((max(samples, 2) - 1) * dt)))
        X0 = np.column_stack([plant.project(s.function) for s in states])
        F, G = plant.explicit
        sp = sample_plant(F, G, plant.B.T, plant.D, dt, sampler)
        C = np.atleast_2d(np.asarray(C_m, dtype=float))
        sense = C @ sp.C_s
        rows = plant_targets(plant, observer)
        measured = np.empty((n_steps + 1, C.shape[0], X0.shape[1]))
        targets = np.empty((n_steps // stride + 1, rows.shape[0], X0.shape[1]))
        x = X0
        for k in range(n_steps + 1):
            measured[k] = sense @ x
            if k % stride == 0:
                targets[k // stride] = rows @ x
            x = sp.Phi @ x
        t = np.arange(targets.shape[0]) * stride * dt
        runs = cls(
            tuple(states), dt, n_steps, stride, measured, targets, t, np.zeros(X0.shape[1]),
            observer.performance, plant.n_ports,
        )  # fmt: skip
        continuous = runs._continuous_errors(plant, observer, C, X0)
        return _with_continuous(runs, runs._window_max(continuous))

    @property
    def window(self) -> tuple[float, float]:
        """The records' span of the floors: the last ``FLOOR_WINDOW`` of the run."""
        return (float(self.t[self._window_mask()][0]), float(self.t[-1]))

    def _window_mask(self) -> np.ndarray:
        start = self.t[0] + (1.0 - FLOOR_WINDOW) * (self.t[-1] - self.t[0])
        return np.asarray(self.t >= start - 1e-12 * max(1.0, abs(self.t[-1])))

    def _window_max(self, errors: np.ndarray) -> np.ndarray:
        """Largest |error| over the window and the outputs, per state: ``(s,)``."""
        e = np.abs(errors[self._window_mask()])
        return np.asarray(e.max(axis=(0, 1)))

    def _continuous_errors(
        self, plant: DiscretePHS, observer: ContinuousObserver, C: np.ndarray, X0: np.ndarray
    ) -> np.ndarray:
        """Return the continuous observer's performance errors at the records: ``(nr, np, s)``."""
        maps = LoopMaps.of(plant, observer, C, self.dt, None)
        jump = np.linalg.matrix_power(maps.step, self.stride)
        n, perf = plant.dim, list(self.performance)
        real = maps.observer
        X = np.vstack([X0, np.zeros((observer.order, X0.shape[1]))])
        errors = np.empty_like(self.targets)
        By = real.D[perf, self.n_inputs :] @ C  # u = 0: the feedthrough of the measurement
        for r in range(self.targets.shape[0]):
            estimate = real.C[perf] @ X[n:] + By @ (maps.C_s @ X[:n])
            errors[r] = self.targets[r] - estimate
            X = jump @ X
        return errors

    def window_errors(self, realization: Realization) -> np.ndarray:
        r"""Return the errors of a discrete observer replayed on the runs, in the window.

        ``(nw, n_performance, s)`` at the window's records. The observer is
        :math:`\hat x_{k+1} = A\hat x_k + B_y y_{m,k}` with estimate
        :math:`C\hat x_k + D_y y_{m,k}` (:math:`B_y, D_y` the sensors' columns), advanced
        one record (s = ``stride`` periods) at a time,
        :math:`\hat x_{r+1} = J\hat x_r + b_r`, :math:`J = A^s`,
        :math:`b_r = [A^{s-1}B_y, \dots, B_y]\,(y_{m,rs}; \dots; y_{m,rs+s-1})`, and before
        the window ``CHUNK`` records at a time,
        :math:`\hat x_{r+c} = J^c\hat x_r + [J^{c-1}, \dots, I]\,(b_r; \dots; b_{r+c-1})`.
        """
        m, perf, s = self.n_inputs, list(self.performance), self.stride
        A, By = realization.A, realization.B[:, m:]
        n, count = A.shape[0], self.measured.shape[2]
        records = self.targets.shape[0]
        lifted = [By]
        for _ in range(s - 1):
            lifted.insert(0, A @ lifted[0])
        J = np.linalg.matrix_power(A, s)
        blocks = self.measured[: (records - 1) * s].reshape(records - 1, -1, count)
        with np.errstate(over="ignore", invalid="ignore"):
            b = np.matmul(np.hstack(lifted), blocks)
            first = int(np.flatnonzero(self._window_mask())[0])
            x = self._chunked(J, b, first, np.zeros((n, count)))
            states = np.empty((records - first, n, count))
            for r in range(first, records):
                states[r - first] = x
                if r < records - 1:
                    x = J @ x + b[r]
            Cp, Dp = realization.C[perf], realization.D[perf, m:]
            estimate = np.matmul(Cp, states) + np.matmul(
                Dp, self.measured[first * s :: s][: records - first]
            )
        return np.asarray(self.targets[first:] - estimate)

    @staticmethod
    def _chunked(J: np.ndarray, b: np.ndarray, first: int, x: np.ndarray) -> np.ndarray:
        """Advance ``x`` over records 0..first-1, ``CHUNK`` at a time; returns it at ``first``."""
        n, count = x.shape
        powers = [np.eye(n)]
        for _ in range(CHUNK - 1):
            powers.insert(0, J @ powers[0])
        stacked, jump = np.hstack(powers), J @ powers[0]
        r = 0
        while r + CHUNK <= first:
            x = jump @ x + stacked @ b[r : r + CHUNK].reshape(CHUNK * n, count)
            r += CHUNK
        for rest in range(r, first):
            x = J @ x + b[rest]
        return x

    def floors(self, realization: Realization, design: str) -> StateFloors:
        """Return the floors of ``realization`` over the set (:class:`StateFloors`)."""
        found = np.abs(self.window_errors(realization)).max(axis=(0, 1))
        found = np.where(np.isfinite(found), found, np.inf)
        names = tuple(s.text for s in self.states)
        return StateFloors(design, names, found, self.continuous_floors, self.window)


def _with_continuous(runs: StateRuns, floors: np.ndarray) -> StateRuns:
    import dataclasses

    return dataclasses.replace(runs, continuous_floors=floors)
