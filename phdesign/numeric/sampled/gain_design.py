r"""Which gain the exported observer runs: designed for the sampled system, and verified.

Four designs (``design=``), all of the export's form :math:`(A, B, C, D)`:

``"given"``
    The given gain L used at the discrete level, unchanged (the export before designs
    existed; the reference every other design is compared with).
``"passive"``
    The same averaged structure, dissipative for every period, with its gain re-tuned for
    the recursion (:mod:`phdesign.numeric.sampled.passive`).
``"kalman"``
    The steady-state Kalman predictor of the exact sampled model, boundary-noise process
    model (:mod:`phdesign.numeric.sampled.kalman`). Not dissipative, fragile across orders.
``"auto"`` (the default)
    Both, verified on the set (:class:`~phdesign.numeric.sampled.state_runs.StateRuns`);
    the one with the lower worst-case ratio :math:`\max_s F_s/F_{c,s}` wins. The Kalman
    design *fails verification*, and is not taken, when its Riccati equation has no
    stabilizing solution, when its recursion is not stable, or when its worst ratio
    exceeds ``bound``; the passive design is then the fallback. The report says which and
    why.

Why a design at all: no sampled-data observer of the PDE has a uniform rate above d/2 (the
period map's essential spectrum lies on :math:`|z| = e^{-d\Delta t/2}`, and a correction
through a few sampled channels is a finite-rank change), but the floor that matters, the
error after a few seconds, depends much on the gain (docs/sampled.rst, "The sampled limit").
Each candidate carries its noise price (:mod:`phdesign.numeric.sampled.noise_price`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.checks import GAIN_DESIGNS
from phdesign.core.errors import NumericError
from phdesign.numeric.sampled.kalman import KalmanNoise, kalman_predictor
from phdesign.numeric.sampled.noise_price import noise_price
from phdesign.numeric.sampled.passive import retune_passive
from phdesign.numeric.sampled.period_maps import Realization
from phdesign.numeric.sampled.samplers import ContinuousObserver
from phdesign.numeric.sampled.state_runs import StateFloors, StateRuns

__all__ = ["DESIGNS", "Candidate", "GainDesign", "design_gain"]

#: The designs of ``export(design=...)``; the first is the default.
DESIGNS = GAIN_DESIGNS


@dataclass(frozen=True)
class Candidate:
    """One design, its floors over the verification set and its noise price.

    Attributes
    ----------
    design : str
    realization : Realization or None
        None when the design could not be made (``failure`` says why).
    gain : ndarray or None
        L of the given and passive designs, the predictor gain K of the Kalman one.
    floors : StateFloors or None
    noise : ndarray or None
        Stationary error variance of each performance output for unit sensor noise.
    failure : str or None
        Why it failed verification (None when it passed).
    """

    design: str
    realization: Realization | None = field(repr=False)
    gain: np.ndarray | None = field(repr=False)
    floors: StateFloors | None
    noise: np.ndarray | None = field(repr=False)
    failure: str | None = None

    @property
    def worst(self) -> float:
        """Worst ratio over the set (inf when it was not run)."""
        return math.inf if self.floors is None else self.floors.worst

    @property
    def noise_gain(self) -> float:
        """The noise gain: the root of the largest variance (the H2 norm from unit noise)."""
        return math.inf if self.noise is None else math.sqrt(float(np.max(self.noise)))

    def noise_text(self) -> str:
        """Return the noise price as printed: the largest variance, and its root (the gain)."""
        if self.noise is None:
            return "n/a"
        return f"{float(np.max(self.noise)):.3g} (gain {self.noise_gain:.3g})"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (strict JSON)."""
        noise = None if self.noise is None else [_number(v) for v in self.noise]
        return {
            "design": self.design,
            "gain": None if self.gain is None else np.atleast_2d(self.gain).tolist(),
            "floors": None if self.floors is None else self.floors.to_dict(),
            "worst_ratio": _number(self.worst),
            "noise_variance": noise,
            "noise_gain": _number(self.noise_gain),
            "failure": self.failure,
        }


def _number(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


@dataclass(frozen=True)
class GainDesign:
    """The design the export chose, the candidates it compared, and why.

    Attributes
    ----------
    requested, chosen : str
    reason : str
    candidates : tuple of Candidate
        The given gain first, then the designs made.
    noise_model : KalmanNoise
    bound : float
        The largest worst-case ratio a verified design may have.
    """

    requested: str
    chosen: str
    reason: str
    candidates: tuple[Candidate, ...]
    noise_model: KalmanNoise
    bound: float

    def candidate(self, design: str) -> Candidate:
        """Return the candidate of ``design`` (KeyError-free: NumericError when not made)."""
        for c in self.candidates:
            if c.design == design:
                return c
        made = ", ".join(c.design for c in self.candidates)
        raise NumericError(f"no {design!r} design was made; made: {made}")

    @property
    def selected(self) -> Candidate:
        """The candidate the export runs."""
        return self.candidate(self.chosen)

    def plot(self, ax: Any = None) -> Any:
        """Draw F/F_c per initial state of each design; return the axes (:mod:`phdesign.plots`)."""
        from phdesign.plots.gain_design import plot_gain_design

        return plot_gain_design(self, ax)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return {
            "requested": self.requested,
            "chosen": self.chosen,
            "reason": self.reason,
            "bound": self.bound,
            "noise_model": self.noise_model.to_dict(),
            "candidates": [c.to_dict() for c in self.candidates],
        }

    def __str__(self) -> str:
        lines = [f"design: {self.chosen} ({self.reason})"]
        for c in self.candidates:
            worst = "not verified" if c.floors is None else f"worst F/F_c {c.worst:.3g}"
            floor = "" if c.floors is None else f", F on the first state {c.floors.floors[0]:.3g}"
            failed = "" if c.failure is None else f"; failed verification: {c.failure}"
            lines.append(f"  {c.design}: {worst}{floor}, noise variance {c.noise_text()}{failed}")
        selected = self.selected
        if selected.floors is not None:
            lines.append(str(selected.floors))
        return "\n".join(lines)


def design_gain(
    observer: ContinuousObserver,
    runs: StateRuns | None,
    *,
    design: str,
    dt: float,
    sampler: str,
    noise_model: KalmanNoise,
    bound: float,
) -> GainDesign:
    """Make the ``design`` (module docstring) of ``observer``'s model; ``runs`` verifies.

    ``runs`` may be None only for ``"given"`` and ``"kalman"`` (nothing is then verified).
    """
    if design not in DESIGNS:
        raise NumericError(f"unknown design {design!r}; expected one of {DESIGNS}")
    if runs is None and design in ("auto", "passive"):
        raise NumericError(f"design {design!r} needs the verification runs")
    m, perf = observer.n_plant_inputs, observer.performance
    given_real = observer.sampled(dt, sampler)
    given = _candidate("given", given_real, observer.model.L, runs, m, perf, dt)
    made = [given]
    if design in ("passive", "auto"):
        assert runs is not None  # checked above
        p = retune_passive(observer, runs, dt, sampler)
        noise = noise_price(p.realization, m, perf, dt)
        made.append(Candidate("passive", p.realization, p.gain, p.floors, noise))
    if design in ("kalman", "auto"):
        made.append(
            _kalman(observer, runs, dt, sampler, noise_model, bound, strict=design == "kalman")
        )
    chosen, reason = _choice(design, made)
    return GainDesign(design, chosen, reason, tuple(made), noise_model, bound)


def _candidate(
    name: str,
    realization: Realization,
    gain: np.ndarray,
    runs: StateRuns | None,
    m: int,
    perf: tuple[int, ...],
    dt: float,
    failure: str | None = None,
) -> Candidate:
    floors = None if runs is None else runs.floors(realization, name)
    return Candidate(
        name, realization, gain, floors, noise_price(realization, m, perf, dt), failure
    )


def _kalman(
    observer: ContinuousObserver,
    runs: StateRuns | None,
    dt: float,
    sampler: str,
    noise_model: KalmanNoise,
    bound: float,
    strict: bool,
) -> Candidate:
    """Return the Kalman candidate, verified; ``strict``: a failed Riccati solve raises."""
    m, perf = observer.n_plant_inputs, observer.performance
    try:
        realization, K = kalman_predictor(observer, dt, sampler, noise_model)
    except NumericError as error:
        if strict:
            raise
        return Candidate("kalman", None, None, None, None, str(error))
    c = _candidate("kalman", realization, K, runs, m, perf, dt)
    radius = float(np.max(np.abs(np.linalg.eigvals(realization.A))))
    failure = None
    if not radius < 1.0:
        failure = f"its recursion is not stable (spectral radius {radius:.6g})"
    elif c.floors is not None and not c.worst <= bound:
        failure = f"its worst F/F_c {c.worst:.3g} exceeds the bound {bound:g}"
    return Candidate(c.design, c.realization, c.gain, c.floors, c.noise, failure)


def _choice(design: str, made: list[Candidate]) -> tuple[str, str]:
    """Return the chosen design and the reason, as the report says it."""
    if design != "auto":
        return design, "as requested"
    passive = next(c for c in made if c.design == "passive")
    kalman = next(c for c in made if c.design == "kalman")
    if kalman.failure is not None:
        return "passive", f"the Kalman design failed verification: {kalman.failure}"
    if kalman.worst < passive.worst:
        return "kalman", (
            f"auto: the lower worst F/F_c over the verification set, {kalman.worst:.3g} "
            f"against the passive design's {passive.worst:.3g}"
        )
    return "passive", (
        f"auto: the lower worst F/F_c over the verification set, {passive.worst:.3g} "
        f"against the Kalman design's {kalman.worst:.3g}"
    )
