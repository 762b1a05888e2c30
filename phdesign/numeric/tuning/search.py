r"""Observer gain tuning: minimize the converged spectral abscissa of the error system.

The error system is the closed loop :math:`\tilde u = -C_m^\top L C_m \tilde y` of the
discretization (``DiscretePHS.closed_matrix``: any feedthrough D is accounted for).  The
objective is the abscissa of :mod:`phdesign.numeric.spectrum.abscissa` at a fixed
resolution pair (:class:`~phdesign.numeric.spectrum.evaluator.AbscissaEvaluator`): the
largest real part over the eigenvalues that are resolved, never over all discrete
eigenvalues (the unresolved high frequencies of any semi-discretization would flatten the
landscape), or the limit the real parts approach at high frequency when no mode attains it.

The gain is searched in the problem's own units: :math:`L = \operatorname{diag}(g\, e^{x})`
with g the natural gain of each sensor (:mod:`phdesign.numeric.scales`: for the string
with the damper at its end, its impedance), or, with ``full=True``,
:math:`L = G^{1/2} (e^{S} + W) G^{1/2}` with S symmetric and W skew (so that
:math:`L + L^\top \succ 0`).  The stages:

1. **grid** of x over ``log_range`` (11 points per gain for one or two gains, 7 for three,
   5 beyond, a seeded random sample past 625 points) at a *search pair* of low resolution
   that reproduces the nominal gain's abscissa to 1e-6 (the rightmost modes of the
   boundary-damped systems are resolved at low degree);
2. **local searches**: Nelder-Mead from the ``starts`` best grid points, then from the
   best of them at the *verification pair* (the pair at which the spectrum of the
   nominal gain converged);
3. **coalescence**: the abscissa of a boundary damper is typically minimized where
   q + 1 eigenvalues coalesce (q gains; the paper's beam: three real eigenvalues at
   -5.83335), where the abscissa is not Lipschitz and a direct search stalls; Newton's
   method on the cluster's central moments locates the point to round-off
   (:mod:`phdesign.numeric.spectrum.coalescence`);
4. **verification**: :func:`~phdesign.numeric.spectrum.converged.spectrum` at the
   returned gain, and the **robustness figure**, the worst abscissa over a ±5 % box of
   gains around it (:mod:`phdesign.numeric.tuning.robustness`).

Questions without an optimum get an answer that says so: when the search meets an empty
spectrum (finite-time extinction, the string with the matched damper k = √(ρT)), the
result is that gain with ``status = "extinction"``; when the abscissa at the best gain is 0
within its accuracy (Timoshenko with one sensor: the real parts approach 0 at high
frequency for every gain), ``status = "no decay"``.  A local search that its iteration
limit stops is restarted (up to :data:`CONTINUATIONS` times); when every restart still
improves the abscissa (a wave with dampers at both ends, whose abscissa falls without
bound toward the boundary gain diag(0, 1)), or the search stops at an empty spectrum of
its low resolution that the verification refutes, ``status = "descending"``: no optimum
was located, and the gain is the best found.

``robust=δ`` minimizes the worst abscissa over the ±δ box instead (its grid points only
during the search).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np
import scipy.linalg as sl
from scipy.optimize import minimize

from phdesign.core.defaults import method_or_default
from phdesign.core.errors import NumericError, ObserverError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_tune_arguments
from phdesign.numeric.discretization.registry import feedback_matrix
from phdesign.numeric.scales import problem_scales
from phdesign.numeric.spectrum.coalescence import Coalescence, polish_coalescence
from phdesign.numeric.spectrum.converged import default_resolutions, spectrum
from phdesign.numeric.spectrum.evaluator import AbscissaEvaluator
from phdesign.numeric.threads import small_dense_threads
from phdesign.numeric.tuning.result import LocalSearch, TuneResult
from phdesign.numeric.tuning.robustness import Robustness, worst_in_box

__all__ = ["ROBUSTNESS_BOX", "LocalSearch", "TuneResult", "tune"]

#: Relative half-width of the box of gains of the robustness figure beside every optimum.
ROBUSTNESS_BOX = 0.05
#: Restarts of Nelder-Mead from a local search stopped by its iteration limit.
CONTINUATIONS = 6
#: A restart that improves the abscissa by less than this (relative to the rate) settles it.
CONTINUATION_GAIN = 1e-6
_DECADE = math.log(10.0)


class _Extinct(Exception):
    """Raised inside the search when a gain gives an empty spectrum."""

    def __init__(self, L: np.ndarray) -> None:
        super().__init__("empty spectrum")
        self.L = L


def _grid_size(q: int) -> int:
    return {1: 11, 2: 11, 3: 7}.get(q, 5)


class _Search:
    """The gain parametrization and the objective of one tuning run."""

    def __init__(
        self,
        C: np.ndarray,
        scale: np.ndarray,
        full: bool,
        robust: float | None,
        progress: Callable[[str], None] | None,
    ) -> None:
        self.C, self.q, self.full, self.robust = C, C.shape[0], full, robust
        self.root = np.sqrt(scale)
        self.scale = scale
        self.progress = progress
        self.best = math.inf
        self.evaluations = 0
        self._last_report = time.perf_counter()
        self.stage = ""

    @property
    def n_params(self) -> int:
        q = self.q
        return q if not self.full else q * q

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
        return self.root[:, None] * core * self.root[None, :]

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
                raise _Extinct(L)
        else:
            v = _nan_as_inf(worst_in_box(ev, L, self.robust, refine=False).worst_abscissa)
        self.evaluations += 1
        v = math.inf if math.isnan(v) else v
        self.best = min(self.best, v)
        self._tell()
        return v

    def _tell(self, force: bool = False) -> None:
        now = time.perf_counter()
        if self.progress is not None and (force or now - self._last_report > 0.2):
            self._last_report = now
            best = "—" if not math.isfinite(self.best) else f"{self.best:.6g}"
            self.progress(f"tune: {self.stage}, {self.evaluations} evaluations, best {best}")


def _nan_as_inf(x: float | None) -> float:
    return math.inf if x is None or math.isnan(x) else x


def _bounded(v: float, penalty: float) -> float:
    """Return a finite objective for Nelder-Mead: unresolved gains get a penalty."""
    return v if math.isfinite(v) else penalty


def _search_pair(
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


def _grid(search: _Search, log_range: tuple[float, float], seed: int) -> np.ndarray:
    q = search.q
    n = _grid_size(q)
    axis = np.linspace(log_range[0], log_range[1], n)
    if n**q <= 625:
        mesh = np.meshgrid(*([axis] * q), indexing="ij")
        points = np.stack([m.ravel() for m in mesh], axis=1)
    else:
        rng = np.random.default_rng(seed)
        points = rng.uniform(log_range[0], log_range[1], size=(256, q))
        points = np.concatenate([np.zeros((1, q)), points])
    return points


def _continue(
    search: _Search,
    ev: AbscissaEvaluator,
    x: np.ndarray,
    f: float,
    penalty: float,
    options: dict[str, float],
    rate: float,
) -> tuple[np.ndarray, float, bool]:
    """Restart Nelder-Mead from a search its iteration limit stopped; return (x, f, descending).

    A fresh simplex crawls along a narrow valley that a collapsed one cannot follow.  The
    search has settled when a restart converges (simplex below ``xatol``) or no longer
    improves the abscissa by :data:`CONTINUATION_GAIN` of the rate; ``descending`` is
    True when every one of :data:`CONTINUATIONS` restarts still improved it: the search
    did not settle within its budget, and no optimum was located (the abscissa may keep
    falling, toward a boundary of the gains or without bound, or lie in a valley too
    steep for the budget).
    """
    for _ in range(CONTINUATIONS):
        res = minimize(
            lambda y: _bounded(search.value(ev, y), penalty),
            x,
            method="Nelder-Mead",
            options=options,
        )
        gain = f - float(res.fun)
        if res.fun < f:
            x, f = np.asarray(res.x), float(res.fun)
        if res.success or gain <= CONTINUATION_GAIN * max(rate, abs(f)):
            return x, f, False
    return x, f, True


def _polish(
    search: _Search, ev: AbscissaEvaluator, x: np.ndarray
) -> tuple[np.ndarray, Coalescence] | None:
    """Newton on the coalescence of q + 1 eigenvalues at the rightmost (diagonal gains)."""
    if search.robust is not None:
        return None
    L = search.gain(x)
    a = ev.abscissa(L)
    if a.kind != "attained" or a.index is None:
        return None
    lead = complex(ev.pair(L).eigenvalues[a.index])
    rate = ev.scales.rate
    system = ev.systems[1]

    def eigenvalues(y: np.ndarray) -> np.ndarray:
        K = feedback_matrix(search.C, search.gain(y), ev.model.n_ports)
        return system.eigvals(K) * rate

    found = polish_coalescence(eigenvalues, x, lead, scale=rate)
    if found is None:
        return None
    # the coalesced eigenvalue must be the rightmost of the counted ones there
    L_new = search.gain(found.parameters)
    pair = ev.pair(L_new)
    near = np.abs(pair.eigenvalues - found.eigenvalue) <= 0.1 * max(rate, abs(found.eigenvalue))
    others = pair.candidates & ~near
    if others.any() and np.max(pair.eigenvalues.real[others]) > found.eigenvalue.real:
        return None
    return found.parameters, found


def tune(
    nm: NumericModel,
    C_m: np.ndarray,
    *,
    full: bool = False,
    starts: int = 3,
    seed: int = 0,
    log_range: tuple[float, float] = (-2 * _DECADE, 2 * _DECADE),
    resolution: int | None = None,
    maxiter: int = 100,
    robust: float | None = None,
    method: str | None = None,
    progress: Callable[[str], None] | None = None,
) -> TuneResult:
    """Tune the observer gain L for the sensors ``C_m`` (module docstring).

    Parameters
    ----------
    nm : NumericModel
    C_m : ndarray (q, N n)
    full : bool
        Also search full gains (``G^(1/2) (e^S + W) G^(1/2)``), from the diagonal optimum;
        a full gain is returned only when it beats that optimum by more than 0.1 %.
    starts : int
        Number of local searches, started from the best grid points.
    seed : int
        Seed of the random grid (more than 625 grid points only).
    log_range : (float, float)
        Natural-log offsets of the grid from the natural gain of each sensor (default
        ±2 decades).
    resolution : int, optional
        Coarse member of the verification pair (default: where the spectrum at the
        natural gain converges).
    maxiter : int
        Nelder-Mead iterations per start and parameter.
    robust : float, optional
        Minimize the worst abscissa over the ±robust box of gains instead (0.05 for 5 %).
    method : str, optional
    progress : callable, optional
        Called with a one-line status now and then (the command line shows it on a terminal).

    Returns
    -------
    TuneResult
    """
    method = method_or_default(method)
    check_tune_arguments(
        nm,
        C_m,
        full=full,
        starts=starts,
        seed=seed,
        log_range=log_range,
        resolution=resolution,
        maxiter=maxiter,
        method=method,
    )
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    q = C.shape[0]
    if q == 0:
        raise ObserverError("tuning needs at least one sensor")
    if C.shape[1] != nm.n_ports:
        raise ObserverError(f"C_m must have {nm.n_ports} columns; found {C.shape[1]}")
    if robust is not None and not 0 < robust < 1:
        raise NumericError(f"robust must be a fraction in (0, 1); found {robust}")
    start_time = time.perf_counter()
    with small_dense_threads():
        return _tune(
            nm,
            C,
            full,
            starts,
            seed,
            log_range,
            resolution,
            maxiter,
            robust,
            method,
            progress,
            start_time,
        )


def _tune(
    nm: NumericModel,
    C: np.ndarray,
    full: bool,
    starts: int,
    seed: int,
    log_range: tuple[float, float],
    resolution: int | None,
    maxiter: int,
    robust: float | None,
    method: str,
    progress: Callable[[str], None] | None,
    start_time: float,
) -> TuneResult:
    scales = problem_scales(nm)
    # the diagonal search always runs first; a full gain only starts from its optimum
    search = _Search(C, scales.gain_scale(C), False, robust, progress)
    L0 = search.gain(np.zeros(search.n_params))
    if resolution is None:
        nominal = spectrum(nm, C, L0, method=method)
        verify = (
            nominal.resolutions[0] if nominal.converged else default_resolutions(nm, method)[0]
        )
    else:
        verify = int(resolution)
    ev_search, ev_verify = _search_pair(nm, C, L0, verify, method)
    penalty = 1e6 * scales.rate
    records: list[LocalSearch] = []
    extinct: np.ndarray | None = None
    descending = False
    descent = ""
    x_best = np.zeros(search.n_params)
    L_best = L0
    polished: Coalescence | None = None
    try:
        search.stage = "grid"
        grid = _grid(search, log_range, seed)
        values = np.array([search.value(ev_search, search.diagonal_params(d)) for d in grid])
        order = np.argsort(values, kind="stable")
        search.stage = "local searches"
        npar = search.n_params
        # stop on the size of the simplex alone: at an optimum at a coalescence (a cusp of
        # the abscissa, like |x|^(1/3)) the values never settle, and the coalescence stage
        # locates that point exactly
        options = {"maxiter": maxiter * npar, "xatol": 1e-5, "fatol": math.inf}
        best_f = math.inf
        best_settled = True
        for i in order[: max(1, starts)]:
            x0 = search.diagonal_params(grid[i])
            before = search.evaluations
            res = minimize(
                lambda x: _bounded(search.value(ev_search, x), penalty),
                x0,
                method="Nelder-Mead",
                options=options,
            )
            records.append(
                LocalSearch(
                    start=search.gain(x0),
                    gain=search.gain(res.x),
                    spectral_abscissa=float(res.fun) if res.fun < penalty else None,
                    evaluations=search.evaluations - before,
                    settled=bool(res.success),
                )
            )
            if res.fun < best_f:
                best_f, x_best, best_settled = float(res.fun), np.asarray(res.x), res.success
        if not best_settled:
            search.stage = "continuation"
            x_best, best_f, descending = _continue(
                search, ev_search, x_best, best_f, penalty, options, scales.rate
            )
        if ev_verify is not ev_search:
            search.stage = "refinement at the verification pair"
            res = minimize(
                lambda x: _bounded(search.value(ev_verify, x), penalty),
                x_best,
                method="Nelder-Mead",
                options={**options, "maxiter": 50 * npar},
            )
            x_best = np.asarray(res.x)
        search.stage = "coalescence"
        found = None if descending else _polish(search, ev_search, x_best)
        if found is not None:
            x_best, polished = found
        L_best = search.gain(x_best)
        if full:
            wide = _Search(C, search.scale, True, robust, progress)
            wide.stage = "full gain"
            res = minimize(
                lambda x: _bounded(wide.value(ev_verify, x), penalty),
                wide.diagonal_params(x_best),
                method="Nelder-Mead",
                options={**options, "maxiter": maxiter * wide.n_params},
            )
            diagonal = search.value(ev_verify, x_best)
            # only a clear gain over the diagonal optimum counts: near a coalescence the
            # evaluated abscissa is noisy at the 1e-4 level
            if res.fun < diagonal - 1e-3 * max(scales.rate, abs(diagonal)):
                L_best, polished = wide.gain(res.x), None
    except _Extinct as stop:
        extinct = stop.L
    search.stage = "verification"
    search._tell(force=True)
    L = extinct if extinct is not None else L_best
    report = spectrum(nm, C, L, method=method)
    status = "optimum"
    if extinct is not None and report.unbounded_below:
        status = "extinction"
    elif extinct is not None or descending:
        # still improving when stopped, or stopped at an empty spectrum of the search pair
        # that the verification refutes: in neither case was an optimum located
        status = "descending"
        descent = "empty spectrum" if extinct is not None else "restarts"
    elif report.no_decay:
        status = "no decay"
    search.stage = "robustness"
    search._tell(force=True)
    box = robust if robust is not None else ROBUSTNESS_BOX
    robustness: Robustness = worst_in_box(ev_verify, L, box)
    return TuneResult.from_report(
        model=nm.name,
        gain=L,
        report=report,
        status=status,
        starts=records,
        evaluations=ev_search.evaluations
        + (ev_verify.evaluations if ev_verify is not ev_search else 0),
        robustness=robustness,
        coalescence=polished,
        search_resolutions=ev_search.resolutions,
        robust=robust,
        seconds=time.perf_counter() - start_time,
        descent=descent,
    )
