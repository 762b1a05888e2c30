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
:math:`L + L^\top \succ 0`) (:mod:`phdesign.numeric.tuning.objective`).  The search is a
list of named stages, each a function from what was found so far to what it finds, run in
order (the progress display names them):

1. **grid** of x over ``log_range`` (11 points per gain for one or two gains, 7 for three,
   5 beyond, a seeded random sample past 625 points) at a *search pair* of low resolution
   that reproduces the nominal gain's abscissa to 1e-6 (the rightmost modes of the
   boundary-damped systems are resolved at low degree);
2. **local searches**: Nelder-Mead from the ``starts`` best grid points;
3. **continuation**: restarts of the best search when its iteration limit stopped it;
4. **refinement at the verification pair** (the pair at which the spectrum of the
   nominal gain converged), from the best point;
5. **coalescence**: the abscissa of a boundary damper is typically minimized where
   q + 1 eigenvalues coalesce (q gains; the paper's beam: three real eigenvalues at
   -5.83335), where the abscissa is not Lipschitz and a direct search stalls; Newton's
   method on the cluster's central moments locates the point to round-off
   (:mod:`phdesign.numeric.spectrum.coalescence`);
6. **full gain** (``full=True``), from the diagonal optimum.

A gain with an empty spectrum ends the stages at that gain.  Then the **verification**,
:func:`~phdesign.numeric.spectrum.converged.spectrum` at the returned gain, gives the
status, and the **robustness figure** is the worst abscissa over a ±5 % box of gains
around it (:mod:`phdesign.numeric.tuning.robustness`).

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
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import OptimizeResult, minimize

from phdesign.core.defaults import method_or_default
from phdesign.core.errors import NumericError, ObserverError
from phdesign.core.progress import Progress, reporting
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_tune_arguments
from phdesign.numeric.discretization.registry import feedback_matrix
from phdesign.numeric.scales import problem_scales
from phdesign.numeric.spectrum.coalescence import Coalescence, polish_coalescence
from phdesign.numeric.spectrum.converged import default_resolutions, spectrum
from phdesign.numeric.spectrum.evaluator import AbscissaEvaluator
from phdesign.numeric.threads import limited_threads
from phdesign.numeric.tuning.objective import (
    Extinct,
    GainSearch,
    bounded,
    grid_points,
    search_pair,
)
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


def _continue(
    search: GainSearch,
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
            lambda y: bounded(search.value(ev, y), penalty),
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
    search: GainSearch, ev: AbscissaEvaluator, x: np.ndarray
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


@limited_threads
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
    progress: Progress | None = None,
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
        Called with a one-line status now and then (:mod:`phdesign.core.progress`; the
        command line shows it on a terminal).

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
    with reporting(progress):
        run = _setup(nm, C, full, robust, resolution, method)
        found = _search(
            run, _Found(np.zeros(run.search.n_params)), starts, seed, log_range, maxiter
        )
        return _verify(run, found, start_time)


@dataclass(frozen=True)
class _Run:
    """One tuning run's fixed parts, which every stage reads."""

    nm: NumericModel
    C: np.ndarray
    search: GainSearch
    ev_search: AbscissaEvaluator
    ev_verify: AbscissaEvaluator
    penalty: float
    rate: float
    full: bool
    method: str
    # the local searches, appended as they finish (an extinction keeps those done)
    records: list[LocalSearch] = field(default_factory=list)


@dataclass(frozen=True)
class _Found:
    """What the search stages found so far: parameters, abscissa, how the search ended."""

    x: np.ndarray
    f: float = math.inf
    settled: bool = True
    starts: tuple[np.ndarray, ...] = ()
    descending: bool = False
    polished: Coalescence | None = None
    gain: np.ndarray | None = None
    extinct: np.ndarray | None = None


def _setup(
    nm: NumericModel,
    C: np.ndarray,
    full: bool,
    robust: float | None,
    resolution: int | None,
    method: str,
) -> _Run:
    """Fix the verification pair (where the natural gain's spectrum converges) and the search's."""
    scales = problem_scales(nm)
    # the diagonal search always runs first; a full gain only starts from its optimum
    search = GainSearch(C, scales.gain_scale(C), False, robust)
    L0 = search.gain(np.zeros(search.n_params))
    if resolution is None:
        nominal = spectrum(nm, C, L0, method=method)
        verify = (
            nominal.resolutions[0] if nominal.converged else default_resolutions(nm, method)[0]
        )
    else:
        verify = int(resolution)
    ev_search, ev_verify = search_pair(nm, C, L0, verify, method)
    return _Run(nm, C, search, ev_search, ev_verify, 1e6 * scales.rate, scales.rate, full, method)


def _nelder_mead(
    run: _Run, search: GainSearch, ev: AbscissaEvaluator, x0: np.ndarray, maxiter: int
) -> OptimizeResult:
    """Nelder-Mead on the bounded objective, stopped on the size of the simplex alone.

    At an optimum at a coalescence (a cusp of the abscissa, like |x|^(1/3)) the values never
    settle, and the coalescence stage locates that point exactly.
    """
    return minimize(
        lambda x: bounded(search.value(ev, x), run.penalty),
        x0,
        method="Nelder-Mead",
        options={"maxiter": maxiter, "xatol": 1e-5, "fatol": math.inf},
    )


def _search(
    run: _Run,
    found: _Found,
    starts: int,
    seed: int,
    log_range: tuple[float, float],
    maxiter: int,
) -> _Found:
    """Run the search stages in order; an empty spectrum ends them at its gain."""
    npar = run.search.n_params
    stages: tuple[tuple[str, Callable[[_Found], _Found]], ...] = (
        ("grid", lambda f: _grid(run, f, starts, seed, log_range)),
        ("local searches", lambda f: _local_searches(run, f, maxiter * npar)),
        ("continuation", lambda f: _continuation(run, f, maxiter * npar)),
        ("refinement at the verification pair", lambda f: _refinement(run, f, 50 * npar)),
        ("coalescence", lambda f: _coalescence(run, f)),
        ("full gain", lambda f: _full_gain(run, f, maxiter)),
    )
    for name, stage in stages:
        run.search.stage = name
        try:
            found = stage(found)
        except Extinct as stop:
            return replace(found, extinct=stop.L)
    return found


def _grid(
    run: _Run, found: _Found, starts: int, seed: int, log_range: tuple[float, float]
) -> _Found:
    """Evaluate the grid at the search pair; its ``starts`` best points start the searches."""
    search = run.search
    grid = grid_points(search, log_range, seed)
    values = np.array([search.value(run.ev_search, search.diagonal_params(d)) for d in grid])
    order = np.argsort(values, kind="stable")
    return replace(found, starts=tuple(grid[i] for i in order[: max(1, starts)]))


def _local_searches(run: _Run, found: _Found, maxiter: int) -> _Found:
    """Nelder-Mead from each start at the search pair; keep the best."""
    search = run.search
    for start in found.starts:
        x0 = search.diagonal_params(start)
        before = search.evaluations
        res = _nelder_mead(run, search, run.ev_search, x0, maxiter)
        run.records.append(
            LocalSearch(
                start=search.gain(x0),
                gain=search.gain(res.x),
                spectral_abscissa=float(res.fun) if res.fun < run.penalty else None,
                evaluations=search.evaluations - before,
                settled=bool(res.success),
            )
        )
        if res.fun < found.f:
            found = replace(found, x=np.asarray(res.x), f=float(res.fun), settled=res.success)
    return found


def _continuation(run: _Run, found: _Found, maxiter: int) -> _Found:
    """Restart a best search that its iteration limit stopped (:func:`_continue`)."""
    if found.settled:
        return found
    options = {"maxiter": maxiter, "xatol": 1e-5, "fatol": math.inf}
    x, f, descending = _continue(
        run.search, run.ev_search, found.x, found.f, run.penalty, options, run.rate
    )
    return replace(found, x=x, f=f, descending=descending)


def _refinement(run: _Run, found: _Found, maxiter: int) -> _Found:
    """Go on from the best point at the verification pair (when it is not the search's)."""
    if run.ev_verify is run.ev_search:
        return found
    res = _nelder_mead(run, run.search, run.ev_verify, found.x, maxiter)
    return replace(found, x=np.asarray(res.x))


def _coalescence(run: _Run, found: _Found) -> _Found:
    """Locate the coalescence the abscissa is minimized at (:func:`_polish`)."""
    polished = None if found.descending else _polish(run.search, run.ev_search, found.x)
    if polished is not None:
        found = replace(found, x=polished[0], polished=polished[1])
    return replace(found, gain=run.search.gain(found.x))


def _full_gain(run: _Run, found: _Found, maxiter: int) -> _Found:
    """From the diagonal optimum, search full gains; keep one only for a clear gain."""
    if not run.full:
        return found
    search = run.search
    wide = GainSearch(run.C, search.scale, True, search.robust)
    wide.stage = "full gain"
    res = _nelder_mead(
        run, wide, run.ev_verify, wide.diagonal_params(found.x), maxiter * wide.n_params
    )
    diagonal = search.value(run.ev_verify, found.x)
    # only a clear gain over the diagonal optimum counts: near a coalescence the evaluated
    # abscissa is noisy at the 1e-4 level
    if res.fun < diagonal - 1e-3 * max(run.rate, abs(diagonal)):
        return replace(found, gain=wide.gain(res.x), polished=None)
    return found


def _verify(run: _Run, found: _Found, start_time: float) -> TuneResult:
    """Verify the gain found (its converged spectrum, a status) and measure its robustness."""
    search = run.search
    search.stage = "verification"
    search.tell(force=True)
    if found.extinct is not None:
        L = found.extinct
    elif found.gain is not None:
        L = found.gain
    else:
        L = search.gain(np.zeros(search.n_params))
    report = spectrum(run.nm, run.C, L, method=run.method)
    status, descent = "optimum", ""
    if found.extinct is not None and report.unbounded_below:
        status = "extinction"
    elif found.extinct is not None or found.descending:
        # still improving when stopped, or stopped at an empty spectrum of the search pair
        # that the verification refutes: in neither case was an optimum located
        status = "descending"
        descent = "empty spectrum" if found.extinct is not None else "restarts"
    elif report.no_decay:
        status = "no decay"
    search.stage = "robustness"
    search.tell(force=True)
    robust = search.robust
    robustness: Robustness = worst_in_box(
        run.ev_verify, L, robust if robust is not None else ROBUSTNESS_BOX
    )
    ev_search, ev_verify = run.ev_search, run.ev_verify
    return TuneResult.from_report(
        model=run.nm.name,
        gain=L,
        report=report,
        status=status,
        starts=run.records,
        evaluations=ev_search.evaluations
        + (ev_verify.evaluations if ev_verify is not ev_search else 0),
        robustness=robustness,
        coalescence=found.polished,
        search_resolutions=ev_search.resolutions,
        robust=robust,
        seconds=time.perf_counter() - start_time,
        descent=descent,
    )
