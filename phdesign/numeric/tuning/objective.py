r"""The tuner's search space and objective: gains in the problem's units, the abscissa.

:class:`GainSearch` maps parameters x to gains, :math:`L = \operatorname{diag}(g\, e^{x})`
with g the natural gain of each sensor (:mod:`phdesign.numeric.scales`), or, for full
gains, :math:`L = G^{1/2} (e^{S} + W) G^{1/2}` with S symmetric and W skew (so that
:math:`L + L^\top \succ 0`), and evaluates the objective: the converged abscissa of an
:class:`~phdesign.numeric.spectrum.evaluator.AbscissaEvaluator`, or its worst case over a
box of gains.  A gain whose spectrum is empty ends the search (:class:`Extinct`): the
answer is then that gain (:mod:`phdesign.numeric.tuning.search`).  :func:`search_pair`
picks the cheap resolution pair the search runs at, :func:`grid_points` the grid it
starts from.
"""

from __future__ import annotations

import math
import time

import numpy as np
import scipy.linalg as sl

from phdesign.core.progress import report
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.spectrum.evaluator import AbscissaEvaluator
from phdesign.numeric.tuning.robustness import worst_in_box

__all__ = ["Extinct", "GainSearch", "bounded", "grid_points", "grid_size", "search_pair"]


class Extinct(Exception):
    """Raised inside the search when a gain gives an empty spectrum."""

    def __init__(self, L: np.ndarray) -> None:
        super().__init__("empty spectrum")
        self.L = L


def grid_size(q: int) -> int:
    """Return the grid's points per gain for q gains (11, 11, 7, then 5)."""
    return {1: 11, 2: 11, 3: 7}.get(q, 5)


class GainSearch:
    """The gain parametrization and the objective of one tuning run."""

    def __init__(
        self,
        C: np.ndarray,
        scale: np.ndarray,
        full: bool,
        robust: float | None,
    ) -> None:
        self.C, self.q, self.full, self.robust = C, C.shape[0], full, robust
        self.root = np.sqrt(scale)
        self.scale = scale
        self.best = math.inf
        self.evaluations = 0
        self._last_report = time.perf_counter()
        self.stage = ""

    @property
    def n_params(self) -> int:
        """Number of parameters: q diagonal gains, or q² (S symmetric and W skew)."""
        q = self.q
        return int(q if not self.full else q * q)

    def gain(self, x: np.ndarray) -> np.ndarray:
        """L for the parameters x (module docstring)."""
        q = self.q
        if not self.full:
            return np.diag(self.scale * np.exp(np.clip(x, -60.0, 60.0)))
        S = np.zeros((q, q))
        iu = np.triu_indices(q)
        S[iu] = x[: iu[0].size]
        S = S + np.triu(S, 1).T
        W = np.zeros((q, q))
        iw = np.triu_indices(q, 1)
        W[iw] = x[iu[0].size :]
        core = sl.expm(np.clip(S, -60.0, 60.0)) + W - W.T
        return np.asarray(self.root[:, None] * core * self.root[None, :])

    def diagonal_params(self, d: np.ndarray) -> np.ndarray:
        """Parameters of the diagonal gain diag(scale e^d)."""
        if not self.full:
            return np.asarray(d, dtype=float)
        x = np.zeros(self.n_params)
        S = np.diag(d)
        x[: self.q * (self.q + 1) // 2] = S[np.triu_indices(self.q)]
        return x

    def value(self, ev: AbscissaEvaluator, x: np.ndarray) -> float:
        """Return the objective at x: the abscissa, or its worst case over the box."""
        L = self.gain(x)
        if self.robust is None:
            v = ev(L)
            if v == -math.inf:
                raise Extinct(L)
        else:
            v = _nan_as_inf(worst_in_box(ev, L, self.robust, refine=False).worst_abscissa)
        self.evaluations += 1
        v = math.inf if math.isnan(v) else v
        self.best = min(self.best, v)
        self.tell()
        return v

    def tell(self, force: bool = False) -> None:
        """Report the stage and the best abscissa (:mod:`phdesign.core.progress`), every 0.2 s."""
        now = time.perf_counter()
        if force or now - self._last_report > 0.2:
            self._last_report = now
            best = "—" if not math.isfinite(self.best) else f"{self.best:.6g}"
            report(f"tune: {self.stage}, {self.evaluations} evaluations, best {best}")


def _nan_as_inf(x: float | None) -> float:
    return math.inf if x is None or math.isnan(x) else x


def bounded(v: float, penalty: float) -> float:
    """Return a finite objective for Nelder-Mead: unresolved gains get a penalty."""
    return v if math.isfinite(v) else penalty


def search_pair(
    nm: NumericModel, C: np.ndarray, L0: np.ndarray, verify: int, method: str
) -> tuple[AbscissaEvaluator, AbscissaEvaluator]:
    """Return the cheapest search evaluator that agrees with the verification one, and it.

    A pair whose band stops below the onset of the principal part while the verification
    pair's does not (:mod:`phdesign.numeric.spectrum.branches`) is not a search pair, whatever it
    gives at the starting gain: a branch may start above its band.
    """
    ev_verify = AbscissaEvaluator(nm, C, verify, method=method)
    target = ev_verify(L0)
    seen = ev_verify.abscissa(L0).kind != "lower bound"
    for fraction in (0.5, 0.6, 0.75):
        p = max(nm.order + 2, math.ceil(fraction * verify))
        if p >= verify:
            break
        ev = AbscissaEvaluator(nm, C, p, method=method)
        if seen and ev.abscissa(L0).kind == "lower bound":
            continue  # its band stops below a branch the verification pair sees
        v = ev(L0)
        same = (math.isnan(v) and math.isnan(target)) or v == target
        scale = max(ev.scales.rate, abs(target)) if math.isfinite(target) else 1.0
        if same or (
            math.isfinite(v) and math.isfinite(target) and abs(v - target) <= 1e-6 * scale
        ):
            return ev, ev_verify
    return ev_verify, ev_verify


def grid_points(search: GainSearch, log_range: tuple[float, float], seed: int) -> np.ndarray:
    """Return the starting grid of log-offsets (a seeded random sample past 625 points)."""
    q = search.q
    n = grid_size(q)
    axis = np.linspace(log_range[0], log_range[1], n)
    if n**q <= 625:
        mesh = np.meshgrid(*([axis] * q), indexing="ij")
        points = np.stack([m.ravel() for m in mesh], axis=1)
    else:
        rng = np.random.default_rng(seed)
        points = rng.uniform(log_range[0], log_range[1], size=(256, q))
        points = np.concatenate([np.zeros((1, q)), points])
    return points
