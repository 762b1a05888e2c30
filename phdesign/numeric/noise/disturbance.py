r"""H∞ and H₂ norms from the disturbances (and sensor noise) to the performance outputs.

**The plant.**  With the known inputs at zero, a discretization of
:math:`\partial_t x = \sum_k P_k \partial_z^k(\mathcal H x) + B(z) w` and of the unknown
external inputs :math:`u_j = w_{b,j}` is

.. math::

    E \dot{\hat e} = (J - R)\hat e + B_d w + B_{:,\text{unknown}}\, w_b, \qquad
    z_p = C_p \hat e, \qquad
    B_d = \int_a^b \Psi^\top B\, dz

(:func:`~phdesign.numeric.discretization.functionals.disturbance_matrix`; the rows
:math:`C_p` of the performance outputs are
:meth:`~phdesign.numeric.discretization.functionals.Functional.row`).  It is the error
system of the observer that measures nothing (:math:`K = 0`): the open-loop model started
at zero estimates :math:`z_p` by 0, and its error is the plant's response.

**An observer** :math:`\hat u = u + C_m^\top L(y_m + \nu - \hat y_m)` knows u but not w,
:math:`w_b` or ν; its error obeys (:mod:`phdesign.numeric.noise.figures`, with
:math:`M = (I + KD)^{-1}`)

.. math::

    E \dot{\tilde e} = \big(J - R - B M K B^\top\big)\tilde e + B_d w
    + B M_{:,\text{unknown}}\, w_b - B M C_m^\top L \Sigma_\nu^{1/2} n_\nu ,
    \qquad \tilde z_p = C_p \tilde e .

**The norms** of :math:`G(s) = C_p (sE - A)^{-1} G_{in}` with
:math:`G_{in} = [B_d, B M_{:,\text{unknown}}, -B M C_m^\top L \Sigma_\nu^{1/2}]` (one
column per source: ``w1..wq``, ``u<j>``, ``nu<i>``): the H∞ norm (the L²-gain)
:math:`\sup_\omega \sigma_{\max} G(i\omega)` over the band a resolution pair resolves
(:mod:`phdesign.numeric.noise.gain`) with its frequency, and the H₂ norm
:math:`\|G\|_2^2 = \operatorname{tr}(C_p P C_p^\top)`, P the stationary covariance of unit
white sources, :math:`A P E^\top + E P A^\top + G_{in} G_{in}^\top = 0`
(:mod:`phdesign.numeric.noise.lyapunov`).  The H₂ norm splits exactly over the sources
(:math:`P = \sum_k P_k`); each source's H∞ norm is reported too.

**Under refinement** each figure is computed at p, ⌈1.5p⌉, ... and judged by
:func:`~phdesign.numeric.noise.settle.settle`.  The H₂ norm of a boundary trace driven at
the boundary (an unknown input or sensor noise) is infinite: its response does not decay
at high frequencies, so the discrete values grow with the resolution and the report says
it diverges, never a number.
"""

from __future__ import annotations

import math
from collections.abc import MutableMapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from phdesign.core.defaults import method_or_default
from phdesign.core.errors import NumericError
from phdesign.core.progress import report
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.functionals import (
    Functional,
    disturbance_matrix,
    performance_functional,
)
from phdesign.numeric.discretization.registry import DiscretePHS, discretize
from phdesign.numeric.disturbance_inputs import disturbance_inputs, performance_terms
from phdesign.numeric.noise.disturbance_report import GainReport, SourceFigures
from phdesign.numeric.noise.figures import check_intensity, refinement_plan
from phdesign.numeric.noise.gain import PeakSearch, banded_gain, gain_pair
from phdesign.numeric.noise.lyapunov import TriangularPencil, triangularize
from phdesign.numeric.noise.optimal import (
    OptimalEstimators,
    hinf_level,
    kalman_h2,
    optimal_filters,
)
from phdesign.numeric.noise.settle import Estimate, settle
from phdesign.numeric.noise.statistics import ErrorStatistics, noise_input
from phdesign.numeric.threads import limited_threads

__all__ = ["DisturbanceStatistics", "disturbance_gain", "disturbance_statistics"]


@dataclass(frozen=True)
class DisturbanceStatistics:
    r"""The disturbance-driven error system at one resolution (module docstring).

    Attributes
    ----------
    discrete : DiscretePHS
    A, G : ndarray
        :math:`E \dot{\tilde e} = A \tilde e + G n`, one column of G per source.
    rows : ndarray
        :math:`C_p`, one row per performance output.
    labels : tuple of str
        The sources: ``w1..wq`` (B's columns), ``u<j>`` (unknown inputs), ``nu<i>``.
    pencil : TriangularPencil
        The system in triangular form, its output map :math:`C_p`.
    covariance : ndarray or None
        :math:`P`, the stationary covariance driven by all sources (None when the system
        is not exponentially stable).
    energies : ndarray or None
        :math:`\operatorname{tr}(C_p P_k C_p^\top)`, the squared H₂ norm of each source
        alone (from the observability Gramian, or one covariance per source).
    plant_input : ndarray
        The plant's disturbance columns :math:`[B_d, B_{:,\text{unknown}}]` (the
        optimal estimators' model, :mod:`phdesign.numeric.noise.optimal`).
    """

    discrete: DiscretePHS
    A: np.ndarray
    G: np.ndarray
    rows: np.ndarray
    labels: tuple[str, ...]
    pencil: TriangularPencil
    covariance: np.ndarray | None
    energies: np.ndarray | None
    plant_input: np.ndarray

    @property
    def stable(self) -> bool:
        """Whether the system is exponentially stable (then the covariance exists)."""
        return self.covariance is not None

    def source(self, k: int | None = None) -> ErrorStatistics:
        """Return the system from source ``k`` (all sources: None) for the peak search."""
        pencil = self.pencil if k is None else replace(self.pencil, H=self.pencil.H[:, [k]])
        return ErrorStatistics(self.discrete, pencil, self.covariance)

    def h2(self, k: int | None = None) -> float:
        """Return the H₂ norm from source ``k`` (all: None) to the outputs (inf: unstable)."""
        if self.covariance is None or self.energies is None:
            return math.inf
        if k is None:
            return math.sqrt(max(float(np.trace(self.rows @ self.covariance @ self.rows.T)), 0))
        return math.sqrt(float(self.energies[k]))

    def output_h2(self) -> np.ndarray:
        """Return the H₂ norm from all sources to each output alone."""
        if self.covariance is None:
            return np.full(self.rows.shape[0], math.inf)
        P = self.covariance
        return np.asarray(
            np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", self.rows, P, self.rows), 0))
        )


def disturbance_statistics(
    d: DiscretePHS,
    B: Any,
    unknown: Sequence[int],
    outputs: Sequence[Functional],
    C_m: np.ndarray | None = None,
    L: np.ndarray | None = None,
    intensity: np.ndarray | None = None,
) -> DisturbanceStatistics:
    """Build and triangularize the disturbance-driven error system of ``d`` (docstring).

    Without ``C_m`` it is the plant (the observer that measures nothing, K = 0).
    """
    m = d.n_ports
    plant = C_m is None or L is None
    C = np.zeros((1, m)) if plant else np.atleast_2d(np.asarray(C_m, dtype=float))
    Lm = np.eye(1) if plant else np.atleast_2d(np.asarray(L, dtype=float))
    sigma = np.zeros(C.shape[0]) if plant or intensity is None else intensity
    marked = np.array([1.0 if j in unknown else 0.0 for j in range(m)])
    A, G_ports, port_labels = noise_input(d, C, Lm, sigma, marked)
    Bd = np.zeros((d.dim, 0)) if B is None else disturbance_matrix(d, B)
    wb = [k for k, s in enumerate(port_labels) if s.startswith("w")]
    nu = [k for k, s in enumerate(port_labels) if s.startswith("nu")]
    G = np.hstack([Bd, G_ports[:, wb], G_ports[:, nu]])
    labels = (
        *(f"w{j + 1}" for j in range(Bd.shape[1])),
        *(f"u{port_labels[k][1:]}" for k in wb),
        *(port_labels[k] for k in nu),
    )
    rows = np.vstack([f.row(d) for f in outputs])
    base = triangularize(A, d.E, G)
    pencil = replace(base, energy_map=rows @ base.to_state(np.eye(d.dim)))
    lam = pencil.eigenvalues
    covariance, energies = None, None
    if np.all(lam.real < -1e-12 * np.maximum(1.0, np.abs(lam))):
        covariance = base.covariance()
        energies = pencil.channel_energies()
        if energies is None:  # the QZ path: one covariance per source
            energies = np.array(
                [
                    np.trace(rows @ replace(base, H=base.H[:, [k]]).covariance() @ rows.T)
                    for k in range(G.shape[1])
                ]
            )
    plant_input = np.hstack([Bd, d.B[:, [j for j in range(m) if j in unknown]]])
    return DisturbanceStatistics(d, A, G, rows, labels, pencil, covariance, energies, plant_input)


@limited_threads
def disturbance_gain(
    nm: NumericModel,
    C_m: np.ndarray | None = None,
    L: np.ndarray | None = None,
    *,
    model: Any,
    intensity: Any = None,
    performance: Sequence[str] | None = None,
    method: str | None = None,
    resolution: int | None = None,
    max_resolution: int | None = None,
    tol: float | None = None,
    discretizations: MutableMapping[int, DiscretePHS] | None = None,
    optimal: bool = False,
) -> GainReport:
    r"""H∞ and H₂ norms from the disturbances to the performance outputs, under refinement.

    Parameters
    ----------
    nm : NumericModel
    C_m, L : ndarray, optional
        Sensors and gain of an observer; without them, the plant (known inputs at zero).
    model : BCPHS
        The symbolic model: its ``[disturbances]``, unknown inputs and ``[performance]``.
    intensity : float or sequence of float, optional
        Sensor noise intensities σᵢ² of an observer (default 1; 0 leaves the noise out).
    performance : sequence of str, optional
        Outputs in the ``[performance]`` grammar (default: the model's).
    method, resolution, max_resolution, tol, discretizations
        As :func:`phdesign.numeric.noise.figures.noise`.
    optimal : bool, optional
        Also compute, for an observer, the optimal full-order estimators of the same
        plant, disturbances and noise at each resolution: the Kalman–Bucy H₂ error and
        the H∞-optimal level γ* (:mod:`phdesign.numeric.noise.optimal`; a Riccati
        equation per bisection step, so off by default).

    Returns
    -------
    GainReport

    Raises
    ------
    NumericError
        No disturbance (neither ``[disturbances]`` B nor unknown inputs) or no output.
    """
    B, unknown = disturbance_inputs(model, nm)
    outputs = tuple(
        performance_functional(nm, *terms) for terms in performance_terms(model, nm, performance)
    )
    if not outputs:
        raise NumericError(
            "the disturbance gain needs performance outputs: give `performance` (e.g. "
            "'integral(e1)') or a [performance] section in the model"
        )
    if B is None and not unknown:
        raise NumericError(
            f"model {nm.name!r} has no disturbance: add a [disturbances] section (B) or mark "
            "external inputs unknown ([ports] unknown = [j])"
        )
    sigma = None
    if C_m is not None:
        C_m = np.atleast_2d(np.asarray(C_m, dtype=float))
        sigma = check_intensity(1.0 if intensity is None else intensity, C_m.shape[0], "intensity")
    method = method_or_default(method)
    p, pmax, tol, rtol = refinement_plan(nm, method, resolution, max_resolution, tol)
    cache = discretizations if discretizations is not None else {}
    setting = _optimal_setting(C_m, sigma, unknown, cache, nm, method, p) if optimal else ""
    run = _GainRefinement(tol, rtol, setting)
    while True:
        report(f"gain: resolution {p}")
        if p not in cache:
            cache[p] = discretize(nm, method, p)
        run.add(disturbance_statistics(cache[p], B, unknown, outputs, C_m, L, sigma))
        if run.done() or math.ceil(1.5 * p) > pmax:
            break
        p = math.ceil(1.5 * p)
    return run.report(nm, outputs, C_m, L, sigma, method)


def _optimal_setting(
    C_m: np.ndarray | None,
    sigma: np.ndarray | None,
    unknown: Sequence[int],
    cache: MutableMapping[int, DiscretePHS],
    nm: NumericModel,
    method: str,
    p: int,
) -> tuple[np.ndarray, np.ndarray] | str:
    """Return what the optimal estimators need, or why they are not computed."""
    if C_m is None or sigma is None:
        return "the plant has no estimator to compare"
    if not np.all(sigma > 0):
        return "the optimal estimators need sensor noise on every sensor (intensity > 0)"
    if p not in cache:
        cache[p] = discretize(nm, method, p)
    if unknown and np.any(cache[p].D[:, list(unknown)]):
        return "unknown inputs feed through into the measurements on this discretization"
    return C_m, sigma


class _GainRefinement:
    """The figures at each resolution so far and their verdicts."""

    def __init__(self, tol: float, rtol: float, optimal: tuple[np.ndarray, ...] | str) -> None:
        self.tol, self.rtol, self.optimal = tol, rtol, optimal
        self.optimal_values: list[tuple[int, float, float]] = []
        self.stats: list[DisturbanceStatistics] = []
        self.searches: list[list[PeakSearch]] = []  # [all sources, source 1, ...]
        self.pairs: list[list[dict[str, Any]]] = []
        self.sups: list[tuple[float, float]] = []

    def add(self, stats: DisturbanceStatistics) -> None:
        ks: list[int | None] = [None, *range(len(stats.labels))]
        searches = [PeakSearch(stats.source(k)) for k in ks]
        self.sups.append(searches[0].discrete() if stats.stable else (math.inf, math.nan))
        if self.searches:
            self.pairs.append([gain_pair(self.searches[-1][0], searches[0], self.rtol, self.tol)])
        self.stats.append(stats)
        self.searches.append(searches)
        if not isinstance(self.optimal, str) and stats.stable:
            C_m, sigma = self.optimal
            args = (stats.discrete, stats.plant_input, stats.rows, C_m, sigma)
            upper = self.sups[-1][0] * (1 + 1e-6)  # a level the boundary observer attains
            self.optimal_values.append(
                (stats.discrete.resolution, kalman_h2(*args), hinf_level(*args, upper=upper))
            )

    @property
    def resolutions(self) -> tuple[int, ...]:
        return tuple(s.discrete.resolution for s in self.stats)

    @property
    def steady(self) -> bool:
        return all(s.stable for s in self.stats)

    def hinf(self, k: int | None = None) -> Any:
        """Return the H∞ norm from all sources (every pair) or source ``k`` (the last pair).

        A source's peak is refined at its highest resonance of the finest pair only: its
        verdict compares that pair's members (a diverging source shows as not converged).
        """
        if k is None:
            pairs, sups = [pr[0] for pr in self.pairs], self.sups
        else:
            pairs, sups = [], []
            if len(self.searches) >= 2:
                coarse, fine = self.searches[-2][k + 1], self.searches[-1][k + 1]
                pairs = [gain_pair(coarse, fine, self.rtol, self.tol, refine=1)]
        return banded_gain(pairs, sups, self.resolutions, self.steady, self.tol, name="H∞")

    def h2(self, name: str, values: Sequence[float]) -> Estimate:
        return settle(name, values, self.resolutions, self.tol)

    def source_h2(self, k: int) -> list[float]:
        return [s.h2(k) for s in self.stats]

    def figures(self) -> tuple[Any, Estimate, list[Estimate]]:
        total = self.h2("H2", [s.h2() for s in self.stats])
        per_output = np.array([s.output_h2() for s in self.stats])
        outputs = [self.h2(f"H2 {j}", list(column)) for j, column in enumerate(per_output.T)]
        return self.hinf(), total, outputs

    def sources(self) -> list[SourceFigures]:
        return [
            SourceFigures(label, self.hinf(k), self.h2(f"H2 from {label}", self.source_h2(k)))
            for k, label in enumerate(self.stats[-1].labels)
        ]

    def done(self) -> bool:
        if not self.steady:
            return True
        hinf, total, outputs = self.figures()
        figures = [hinf.estimate, total, *outputs]
        figures += [
            settle("", self.source_h2(k), self.resolutions, self.tol)
            for k in range(len(self.stats[-1].labels))
        ]
        optimal = self.optimal_figures()
        if optimal is not None:
            figures += [f for f in (optimal.h2, optimal.hinf) if f is not None]
        return len(self.stats) >= 3 and all(f.converged or f.diverges for f in figures)

    def optimal_figures(self) -> OptimalEstimators | None:
        if self.optimal == "":
            return None  # not asked for
        note = self.optimal if isinstance(self.optimal, str) else ""
        if not note and not self.steady:
            note = "the error system is not exponentially stable"
        return optimal_filters(self.optimal_values, self.tol, note)

    def report(
        self,
        nm: NumericModel,
        outputs: Sequence[Functional],
        C_m: np.ndarray | None,
        L: np.ndarray | None,
        sigma: np.ndarray | None,
        method: str,
    ) -> GainReport:
        hinf, total, per_output = self.figures()
        sources = self.sources()
        per_output = [
            replace(e, name=f"H2 to {f.name}") for e, f in zip(per_output, outputs, strict=True)
        ]
        bad = next((s for s in self.stats if not s.stable), None)
        unstable = None
        if bad is not None:
            lam = bad.pencil.eigenvalues
            unstable = (bad.discrete.resolution, complex(lam[np.argmax(lam.real)]))
        return GainReport(
            model=nm.name,
            sensors=None if C_m is None else np.asarray(C_m),
            gain=None if L is None else np.atleast_2d(np.asarray(L, dtype=float)),
            intensity=None if sigma is None else tuple(float(s) for s in sigma),
            sources=self.stats[-1].labels,
            outputs=tuple(f.name for f in outputs),
            hinf=hinf,
            h2=total,
            h2_outputs=tuple(per_output),
            by_source=tuple(sources),
            resolutions=self.resolutions,
            method=method,
            tol=self.tol,
            unstable=unstable,
            output_labels=nm.output_labels,
            time_unit=dict(nm.units).get("t"),
            optimal=self.optimal_figures(),
        )
