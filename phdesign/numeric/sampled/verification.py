r"""The verification of an exported observer: a high-resolution plant, sampled and continuous.

:func:`verify_observer` runs the discrete observer and its continuous counterpart against a
Galerkin plant of at least twice its order, both stepped exactly, the sampler applied to the
plant's outputs, and reports the performance-output error over time and its floor
(:class:`Verification`).  :func:`with_plant_gap` and :func:`with_target_check` add what the
plant's own resolution says about those floors (:mod:`phdesign.numeric.sampled.plant_resolution`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.defaults import current
from phdesign.core.errors import VerificationError
from phdesign.core.text import html_table
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.checks import check_periods, check_sampling
from phdesign.numeric.sampled.order import check_order
from phdesign.numeric.sampled.period_maps import Realization
from phdesign.numeric.sampled.runs import ALIASING_RATIO, aliasing_warning, run_against_continuous
from phdesign.numeric.sampled.samplers import ContinuousObserver
from phdesign.numeric.sampled.selection import OrderSelection
from phdesign.numeric.threads import limited_threads

__all__ = [
    "Verification",
    "check_strict",
    "failed_checks",
    "plant_gap",
    "verify_observer",
    "with_plant_gap",
    "with_target_check",
]


def _fmt(value: float | None) -> str:
    return "n/a" if value is None or not math.isfinite(value) else f"{value:.3g}"


@dataclass(frozen=True)
class Verification:
    """The exported observer against a high-resolution plant, and the continuous one.

    Attributes
    ----------
    plant_degree, plant_order : int
        The plant: Galerkin degree and states (at least twice the observer's order).
    dt : float
    sampler : str
    x0 : str
        The plant's initial state (the observer starts from zero).
    outputs : tuple of str
        The performance outputs compared.
    t : ndarray (nr,)
        Record times (multiples of dt).
    error, continuous_error : ndarray (nr, n_performance)
        Plant minus observer for the sampled and for the continuous observer.
    peak : float
        Largest magnitude of the plant's performance outputs over the run.
    floor, continuous_floor : float
        Largest error over the last fifth of the run, absolute.
    warnings : tuple of str
    plant_gap : float or None
        How far the plant's own performance outputs move over that window when its degree
        is raised by half (:mod:`phdesign.numeric.sampled.plant_resolution`); None when unchecked.
    """

    plant_degree: int
    plant_order: int
    dt: float
    sampler: str
    x0: str
    outputs: tuple[str, ...]
    t: np.ndarray = field(repr=False)
    error: np.ndarray = field(repr=False)
    continuous_error: np.ndarray = field(repr=False)
    peak: float
    floor: float
    continuous_floor: float
    warnings: tuple[str, ...] = ()
    plant_gap: float | None = None

    @property
    def ratio(self) -> float:
        """Sampled floor over the continuous observer's (inf when that one is zero)."""
        if self.continuous_floor > 0:
            return self.floor / self.continuous_floor
        return math.inf if self.floor > 0 else 1.0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (strict JSON)."""
        ratio = self.ratio
        return {
            "plant_degree": self.plant_degree,
            "plant_order": self.plant_order,
            "dt": self.dt,
            "sampler": self.sampler,
            "x0": self.x0,
            "outputs": list(self.outputs),
            "t": self.t.tolist(),
            "error": self.error.tolist(),
            "continuous_error": self.continuous_error.tolist(),
            "peak": self.peak,
            "floor": self.floor,
            "relative_floor": self.floor / self.peak if self.peak > 0 else None,
            "continuous_floor": self.continuous_floor,
            "ratio": ratio if math.isfinite(ratio) else None,
            "plant_gap": self.plant_gap,
            "warnings": list(self.warnings),
        }

    def failures(self) -> tuple[str, ...]:
        """Return the checks this run failed, one phrase each (empty when it passed).

        Two checks: the sampled observer's error floor against the continuous observer's
        (at most ALIASING_RATIO x, :func:`~phdesign.numeric.sampled.runs.aliasing_warning`)
        and the verification plant's own resolution (its outputs move under refinement by
        at most GAP_RATIO x the continuous floor,
        :func:`~phdesign.numeric.sampled.plant_resolution.gap_exceeds`).
        """
        from phdesign.numeric.sampled.plant_resolution import GAP_RATIO, gap_exceeds

        out = []
        if aliasing_warning(self.floor, self.continuous_floor, self.peak, self.sampler, self.dt):
            out.append(
                f"sampled against continuous observer: error floor {self.floor:.3g} is "
                f"{self.ratio:.3g}x the continuous observer's {self.continuous_floor:.3g} "
                f"(at most {ALIASING_RATIO:g}x)"
            )
        gap = self.plant_gap
        if gap is not None and gap_exceeds(gap, self.continuous_floor, self.peak):
            out.append(
                f"plant resolution: the verification plant's outputs move by {gap:.3g} when "
                f"it is refined, {gap / max(self.continuous_floor, 1e-300):.3g}x the "
                f"continuous floor {self.continuous_floor:.3g} (at most {GAP_RATIO:g}x)"
            )
        return tuple(out)

    def __repr__(self) -> str:
        return (
            f"Verification(sampler={self.sampler!r}, dt={self.dt:g}, floor={self.floor:.3g}, "
            f"continuous_floor={self.continuous_floor:.3g}, ratio={self.ratio:.3g})"
        )

    def __str__(self) -> str:
        rel = self.floor / self.peak if self.peak > 0 else math.nan
        lines = [
            f"verification: plant of degree {self.plant_degree} ({self.plant_order} states) "
            f"from {self.x0}, t = 0..{self.t[-1]:g}, outputs {', '.join(self.outputs)}",
            f"error floor (max over the last fifth): {self.floor:.3g} ({_fmt(rel)} of the "
            f"peak); continuous observer: {self.continuous_floor:.3g}; ratio {self.ratio:.3g}",
        ]
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rows = (
            (f"{self.sampler}, dt = {self.dt:g}", f"{self.floor:.3g}"),
            ("continuous", f"{self.continuous_floor:.3g}"),
        )
        return html_table(("observer", "error floor"), rows)

    def plot(self, ax: Any = None) -> Any:
        """Draw both errors over time (log scale); returns the axes (:mod:`phdesign.plots`)."""
        from phdesign.plots.verification import plot_verification

        return plot_verification(self, ax)


@limited_threads
def verify_observer(
    plant: Any,
    observer: ContinuousObserver,
    C_m: np.ndarray,
    *,
    dt: float,
    sampler: str,
    x0: np.ndarray,
    t_end: float,
    samples: int | None = None,
    x0_text: str = "x0",
    realization: Realization | None = None,
) -> Verification:
    """Run the sampled and the continuous observer against ``plant`` from ``x0``.

    Both are stepped exactly (:func:`phdesign.numeric.sampled.runs.run_loop`) over
    round(t_end / dt) periods, the sampler applied to the plant's outputs, and recorded
    on the same instants (every ``stride`` periods, about ``samples`` records; default
    the simulations', :mod:`phdesign.core.defaults`).  ``realization`` is the sampled
    observer's one-period map when the caller has it (the export: computed once).
    """
    samples = current().simulation.samples if samples is None else samples
    dt = check_sampling(dt, sampler)
    check_periods(dt, t_end)
    check_order(observer.order, plant.dim, plant.resolution)
    n_steps = max(1, round(t_end / dt))
    stride = max(1, round(t_end / ((max(samples, 2) - 1) * dt)))
    sampled, continuous, (floor, cont), warning = run_against_continuous(
        plant, observer, C_m, sampler=sampler, x0=x0, dt=dt, n_steps=n_steps, stride=stride,
        realization=realization,
    )  # fmt: skip
    errors = [r.performance_error(observer) for r in (sampled, continuous)]
    peak = float(np.max(np.abs(sampled.target)))
    return Verification(
        plant_degree=plant.resolution,
        plant_order=plant.dim,
        dt=dt,
        sampler=sampler,
        x0=x0_text,
        outputs=tuple(observer.outputs[i] for i in observer.performance),
        t=sampled.t,
        error=errors[0],
        continuous_error=errors[1],
        peak=peak,
        floor=floor,
        continuous_floor=cont,
        warnings=() if warning is None else (warning,),
    )


def plant_gap(
    nm: NumericModel, plant: Any, observer: ContinuousObserver, initial: Any, t: np.ndarray
) -> tuple[float, int, float] | None:
    """Return the plant's own resolution gap over ``t``, the finer degree and the peak.

    :func:`~phdesign.numeric.sampled.plant_resolution.plant_resolution_gap` with this model's
    largest Galerkin resolution; None when the plant is already there.
    """
    from phdesign.numeric.sampled.plant_resolution import plant_resolution_gap
    from phdesign.numeric.spectrum.converged import default_resolutions

    largest = default_resolutions(nm, "galerkin")[1]
    return plant_resolution_gap(plant, observer, initial, t, largest)


def with_plant_gap(
    v: Verification, found: tuple[float, int, float] | None, plant_degree: int
) -> Verification:
    """Add the plant's own resolution gap ``found`` (:func:`plant_gap`) to the verification."""
    from phdesign.numeric.sampled.plant_resolution import gap_warning

    if found is None:
        unchecked = (
            f"the verification plant (degree {plant_degree}) is at this model's largest "
            "Galerkin resolution: whether it resolves its own outputs from the initial "
            "state is not checked"
        )
        return dataclasses.replace(v, warnings=(*v.warnings, unchecked))
    gap, finer, _ = found
    warning = gap_warning(gap, (plant_degree, finer), v.continuous_floor, v.peak, v.x0)
    extra = () if warning is None else (warning,)
    return dataclasses.replace(v, plant_gap=gap, warnings=v.warnings + extra)


def with_target_check(
    selection: OrderSelection,
    found: tuple[float, int, float] | None,
    plant_degree: int,
    x0_text: str,
) -> OrderSelection:
    """Add the warning of :func:`~phdesign.numeric.sampled.plant_resolution.target_warning`."""
    from phdesign.numeric.sampled.plant_resolution import target_warning

    if found is None:
        return selection
    gap, finer, peak = found
    warning = target_warning(gap, peak, (plant_degree, finer), selection.output_tol, x0_text)
    if warning is None:
        return selection
    return dataclasses.replace(selection, warnings=(*selection.warnings, warning))


def failed_checks(
    selection: OrderSelection, verification: Verification | None, extra: tuple[str, ...] = ()
) -> tuple[str, ...]:
    """Return every failed check of an export: its targets, its verification's, then ``extra``.

    The targets are the order selection's (rightmost eigenvalues to ``tol``, performance
    floor to ``output_tol`` of the peak, as its first line reports them); a verification
    that was not run has no failures of its own.
    """
    out = []
    eig = selection.eigen_error
    if eig is None or not eig <= selection.tol or not selection.floor <= selection.output_tol:
        reached = "none converged" if eig is None else f"{eig:.2g}"
        out.append(
            f"targets: rightmost eigenvalues to {selection.tol:g} (reached {reached}), "
            f"performance floor {selection.output_tol:g} of the peak (reached "
            f"{selection.floor:.3g})"
        )
    return tuple(out) + (() if verification is None else verification.failures()) + extra


def check_strict(
    selection: OrderSelection, verification: Verification | None, extra: tuple[str, ...] = ()
) -> None:
    """Raise :class:`~phdesign.core.errors.VerificationError` naming the failed checks.

    ``extra``: failed checks found elsewhere (the verification set's worst ratio).
    """
    failed = failed_checks(selection, verification, extra)
    if failed:
        raise VerificationError(
            "`strict=True`: the export failed its checks: " + "; ".join(failed)
        )
