r"""The passive design: the gain re-tuned for the discrete recursion, inside the same structure.

The exported observer of the ``average`` sampler
(:meth:`~phdesign.numeric.sampled.period_maps.ObserverModel.averaged`) is dissipative for
every period and every gain with :math:`L + L^\top \succ 0`: its error energy obeys

.. math::

    \tilde H_{k+1} - \tilde H_k = -\int_{t_k}^{t_{k+1}}\tilde e^\top R\tilde e\,dt
    - \Delta t\,(C_m\bar{\tilde y}_k)^\top L\,(C_m\bar{\tilde y}_k) \le 0,

so :math:`\|Q^{1/2} A_d Q^{-1/2}\|_2 \le 1` with Q the observer's energy matrix (the proof is
in :mod:`phdesign.numeric.sampled.period_maps`; it needs only :math:`\operatorname{sym} L
\succ 0`, which the parametrization below keeps). The gain that is best for the continuous
observer is not best for the recursion: error modes near :math:`2\pi j/\Delta t` are damped
only through their interval means. :func:`retune_passive` searches the gains of this
structure for the lowest worst-case ratio :math:`\max_s F_s / F_{c,s}` over the
verification set (:class:`~phdesign.numeric.sampled.state_runs.StateRuns`), with

.. math::

    L = S S^\top + N, \qquad S \text{ lower triangular with } S_{ii} = e^{\theta_i},
    \qquad N = -N^\top,

(:math:`q^2` numbers for q sensors), by Nelder–Mead from the given gain; the result is never
worse on the set than the given gain (the search returns the best gain it evaluated). The
floors it reports are the ones it was tuned on: the set is its training set, and the
gain is as good elsewhere as the set is representative. With the ``point`` sampler the same
search runs on the zero-order-hold observer, for which no dissipativity is proved.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.optimize as so

from phdesign.numeric.sampled.period_maps import Realization, sample_plant
from phdesign.numeric.sampled.samplers import ContinuousObserver
from phdesign.numeric.sampled.state_runs import StateFloors, StateRuns

__all__ = ["PassiveDesign", "gain_parameters", "parameters_gain", "retune_passive"]

#: Evaluations of the search per free number of the gain (q**2 of them).
EVALUATIONS_PER_PARAMETER = 40


def gain_parameters(L: np.ndarray) -> np.ndarray:
    r"""Return θ of L: the log-Cholesky factor of sym(L), then the upper part of skew(L).

    Examples
    --------
    >>> L = np.array([[2.0, 0.5], [-0.3, 1.0]])
    >>> bool(np.allclose(parameters_gain(gain_parameters(L), 2), L))
    True
    """
    q = L.shape[0]
    S = np.linalg.cholesky(0.5 * (L + L.T))
    lower = S[np.tril_indices(q)].copy()
    diagonal = [i * (i + 1) // 2 + i for i in range(q)]
    lower[diagonal] = np.log(lower[diagonal])
    N = 0.5 * (L - L.T)
    return np.concatenate([lower, N[np.triu_indices(q, 1)]])


def parameters_gain(theta: np.ndarray, q: int) -> np.ndarray:
    """Return the gain of θ (:func:`gain_parameters`): sym part positive definite."""
    count = q * (q + 1) // 2
    lower = np.array(theta[:count], dtype=float)
    diagonal = [i * (i + 1) // 2 + i for i in range(q)]
    lower[diagonal] = np.exp(np.clip(lower[diagonal], -50.0, 50.0))
    S = np.zeros((q, q))
    S[np.tril_indices(q)] = lower
    N = np.zeros((q, q))
    N[np.triu_indices(q, 1)] = theta[count:]
    return np.asarray(S @ S.T + N - N.T)


@dataclass(frozen=True)
class PassiveDesign:
    """The re-tuned gain, its sampled observer and its floors over the verification set."""

    gain: np.ndarray = field(repr=False)
    observer: ContinuousObserver = field(repr=False)
    realization: Realization = field(repr=False)
    floors: StateFloors
    evaluations: int


def retune_passive(
    observer: ContinuousObserver, runs: StateRuns, dt: float, sampler: str
) -> PassiveDesign:
    """Re-tune the gain of ``observer`` for the recursion at ``dt`` (module docstring)."""
    model = observer.model
    q = model.C_m.shape[0]
    best: dict[str, object] = {}
    period = sample_plant(model.F, model.G, model.H, model.D, dt, sampler)  # gain-free

    def evaluate(theta: np.ndarray) -> float:
        L = parameters_gain(theta, q)
        tuned = observer.with_gain(L)
        realization = tuned.sampled(dt, sampler, period if sampler == "average" else None)
        floors = runs.floors(realization, "passive")
        worst = floors.worst
        if not best or worst < best["worst"]:  # type: ignore[operator]
            best.update(worst=worst, L=L, observer=tuned, realization=realization, floors=floors)
        return worst if np.isfinite(worst) else 1e300

    start = gain_parameters(observer.model.L)
    simplex = np.vstack([start, start + 0.5 * np.eye(start.size)])
    result = so.minimize(
        evaluate,
        start,
        method="Nelder-Mead",
        options={
            "maxfev": EVALUATIONS_PER_PARAMETER * start.size,
            "initial_simplex": simplex,
            "xatol": 1e-3,
            "fatol": 1e-4,
        },
    )
    return PassiveDesign(
        gain=best["L"],  # type: ignore[arg-type]
        observer=best["observer"],  # type: ignore[arg-type]
        realization=best["realization"],  # type: ignore[arg-type]
        floors=best["floors"],  # type: ignore[arg-type]
        evaluations=int(result.nfev),
    )
