r"""The verification plant: its degree, and whether it resolves its own outputs.

:func:`verification_plant_degree` is the Galerkin degree of the plant an exported observer
is measured against: given, or the export's default (:mod:`phdesign.core.defaults`)
raised to twice the observer's order.

The verification (:func:`phdesign.numeric.sampled.verification.verify_observer`) measures the
observer
against a Galerkin plant of high degree.  Its floor means something only if that plant
resolves the outputs it compares from the given initial state: an initial state that
violates the boundary conditions excites the plant's top frequencies, which a Galerkin
semi-discretization damps much less than the PDE does (its unresolved modes lose the
boundary damping), so on a hyperbolic model the plant's boundary traces keep an
unresolved component of the size of the signal and the floor measures that.  The check
runs the plant alone (u = 0, exactly: :math:`e(t_{j+1}) = e^{F\Delta} e(t_j)`,
:math:`F = E^{-1}(J - R)`) at the verification degree p and at
:math:`\lceil 3p/2 \rceil`, and compares the performance outputs over the window of the
floor (the last fifth of the run):

.. math::

    g = \max_{t \ge t_{4/5}} |y_p(t) - y_{3p/2}(t)| .

When g exceeds :data:`GAP_RATIO` times the continuous observer's floor (and round-off,
1e-12 of the outputs' peak), the verification says so: the floor is then the plant's
unresolved content as much as the observer's error.  On the paper's beam from its initial
state, g is 0.07 of that floor; on a wave with dampers at both ends from the default
initial state, 2.6 times it at the default order (1.9 times at 20 states).  A plant
already at the model's largest Galerkin resolution has no finer one: then nothing is
checked (``plant_gap`` None).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg as sl

from phdesign.core.defaults import current
from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.sampled.order import check_order, galerkin_offset
from phdesign.numeric.sampled.runs import FLOOR_WINDOW, plant_targets
from phdesign.numeric.sampled.samplers import ContinuousObserver
from phdesign.numeric.spectrum.converged import default_resolutions

__all__ = [
    "GAP_RATIO",
    "free_outputs",
    "gap_exceeds",
    "gap_warning",
    "plant_resolution_gap",
    "target_warning",
    "verification_plant_degree",
]


def verification_plant_degree(
    nm: NumericModel, order: int | None, plant_resolution: int | None, reduction: str = "none"
) -> int:
    """Degree of the verification plant: given, or the export's default raised to 2x the order.

    Checks the whole request first (:func:`phdesign.numeric.sampled.order.check_order`), so that a
    command refuses it before any computation.
    """
    offset = galerkin_offset(nm)
    degree = _plant_degree(nm, order, plant_resolution, offset)
    check_order(
        order,
        nm.size * (degree + 1) + offset,
        degree,
        reduction=reduction,
        size=nm.size,
        smallest=nm.size * (nm.order + 2) + offset,
        offset=offset,
    )
    return degree


def _plant_degree(
    nm: NumericModel, order: int | None, plant_resolution: int | None, offset: int = 0
) -> int:
    if plant_resolution is not None:
        if isinstance(plant_resolution, bool) or not isinstance(plant_resolution, int):
            raise NumericError(f"plant_resolution must be an integer; found {plant_resolution!r}")
        if plant_resolution < nm.order + 1:
            raise NumericError(
                f"plant_resolution must be at least N + 1 = {nm.order + 1}; found "
                f"{plant_resolution}"
            )
        return plant_resolution
    if order is None or isinstance(order, bool) or not isinstance(order, int) or order < 1:
        return current().export.plant_degree
    needed = -(-(2 * order - offset) // nm.size) - 1
    largest = default_resolutions(nm, "galerkin")[1]
    if needed > largest:
        raise NumericError(
            f"order {order} needs a verification plant of at least {2 * order} states; the "
            f"largest for this model has {nm.size * (largest + 1) + offset} (Galerkin degree "
            f"{largest}): lower the order"
        )
    return max(current().export.plant_degree, needed)


#: The plant's own resolution gap, relative to the continuous floor, above which it is said.
GAP_RATIO = 0.5


def free_outputs(
    plant: DiscretePHS, observer: ContinuousObserver, e0: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """Return the plant's performance outputs at the uniform times ``t`` from ``e0``, u = 0."""
    F = np.linalg.solve(plant.E, plant.J - plant.R)
    step = sl.expm(F * float(t[1] - t[0])) if t.size > 1 else np.eye(plant.dim)
    rows = plant_targets(plant, observer)
    out = np.empty((t.size, rows.shape[0]))
    e = np.asarray(e0, dtype=float)
    for j in range(t.size):
        out[j] = rows @ e
        e = step @ e
    return out


def plant_resolution_gap(
    plant: DiscretePHS,
    observer: ContinuousObserver,
    initial: Callable[[np.ndarray], np.ndarray],
    t: np.ndarray,
    largest: int,
) -> tuple[float, int, float] | None:
    """Return g (module docstring) over the last fifth of ``t``, the finer degree, the peak.

    The peak is the largest magnitude of the plant's performance outputs over ``t``.
    ``largest`` bounds the finer degree (the model's largest Galerkin resolution); None when
    the plant is already there and no finer plant exists.
    """
    finer_degree = min(-(-3 * plant.resolution // 2), largest)
    if finer_degree <= plant.resolution:
        return None
    finer = discretize(plant.model, "galerkin", finer_degree)
    coarse = free_outputs(plant, observer, plant.project(initial), t)
    gap_series = coarse - free_outputs(finer, observer, finer.project(initial), t)
    window = t >= t[0] + (1.0 - FLOOR_WINDOW) * (t[-1] - t[0]) - 1e-12 * max(1.0, abs(t[-1]))
    gap = float(np.max(np.abs(gap_series[window])))
    return gap, finer_degree, float(np.max(np.abs(coarse)))


def target_warning(
    gap: float, peak: float, degrees: tuple[int, int], output_tol: float, x0_text: str
) -> str | None:
    """Return the order selection's warning when the plant's gap exceeds the target itself.

    The performance target asks for a floor of ``output_tol`` of the peak; a plant whose
    own outputs move by more than GAP_RATIO times that when refined cannot show it met.
    """
    if not (peak > 0 and gap > GAP_RATIO * output_tol * peak):
        return None
    return (
        f"the verification plant does not resolve its own outputs from {x0_text} to the "
        f"performance target: at degrees {degrees[0]} and {degrees[1]} they differ by "
        f"{gap / peak:.3g} of their peak over the last fifth (target {output_tol:g}), so no "
        "observer can be shown to meet it; give an initial state that meets the boundary "
        "conditions (`x0`) or a higher `plant_resolution`"
    )


def gap_exceeds(gap: float, continuous_floor: float, peak: float) -> bool:
    """Whether the plant's own gap exceeds GAP_RATIO x the continuous floor (not round-off)."""
    return bool(gap > max(GAP_RATIO * continuous_floor, 1e-12 * peak))


def gap_warning(
    gap: float, degrees: tuple[int, int], continuous_floor: float, peak: float, x0_text: str
) -> str | None:
    """Return the verification's warning when ``gap`` exceeds GAP_RATIO x the floor."""
    if not gap_exceeds(gap, continuous_floor, peak):
        return None
    return (
        f"the verification plant does not resolve its own outputs from {x0_text}: at "
        f"degrees {degrees[0]} and {degrees[1]} they differ by {gap:.3g} over the last "
        f"fifth, against the continuous observer's floor {continuous_floor:.3g}, so the "
        "floors measure the plant's unresolved content as much as the observer; give an "
        "initial state that meets the boundary conditions (`x0`) or a higher "
        "`plant_resolution`"
    )
