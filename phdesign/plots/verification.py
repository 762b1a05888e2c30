"""The verification of an exported observer: its error against the continuous observer's.

A front end (matplotlib only, through :func:`phdesign.plots.drawing`): it draws what
:func:`phdesign.numeric.sampled.verification.verify_observer` computed,
:meth:`Verification.plot` and :meth:`SampledObserver.plot` hand themselves to it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, cast

import numpy as np

from phdesign.plots._figures import drawing, log_scale_if_positive, unit_label

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes

__all__ = ["plot_verification"]


def plot_verification(verification: Any, ax: Axes | None = None) -> Axes:
    """Draw both errors of the performance outputs over time (log scale); return the axes.

    Parameters
    ----------
    verification : Verification
        The run of the sampled observer and of the continuous one against the plant.
    ax : Axes, optional
        Draw there (default: a new figure).
    """
    with drawing(ax=ax, figsize=(7, 3.5)) as (_, axes):
        v = verification
        continuous, sampled = np.abs(v.continuous_error).max(axis=1), np.abs(v.error).max(axis=1)
        axes.plot(v.t, continuous, label="continuous")
        axes.plot(v.t, sampled, label=f"{v.sampler}, dt = {v.dt:g}")
        axes.set_xlabel(unit_label(v, "time t", "t"))
        axes.set_ylabel("|" + ", ".join(v.outputs) + " error|")
        log_scale_if_positive(axes, continuous, sampled)
        axes.legend()
    return cast("Axes", axes)
