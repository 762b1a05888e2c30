"""The gain designs of an export side by side: F/F_c on every initial state of the set.

A front end (matplotlib only, through :func:`phdesign.plots.drawing`): it draws what
:func:`phdesign.numeric.sampled.gain_design.design_gain` computed;
:meth:`GainDesign.plot` hands itself to it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, cast

import numpy as np

from phdesign.plots._figures import drawing

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes

__all__ = ["plot_gain_design"]


def plot_gain_design(design: Any, ax: Axes | None = None) -> Axes:
    """Draw F/F_c of each verified candidate per initial state (bars, log scale).

    Parameters
    ----------
    design : GainDesign
        The designs an export compared.
    ax : Axes, optional
        Draw there (default: a new figure).
    """
    verified = [c for c in design.candidates if c.floors is not None]
    with drawing(ax=ax, figsize=(7, 3.5)) as (_, axes):
        if verified:
            count = len(verified[0].floors.states)
            width = 0.8 / len(verified)
            for j, c in enumerate(verified):
                chosen = " (exported)" if c.design == design.chosen else ""
                axes.bar(
                    np.arange(count) + (j - (len(verified) - 1) / 2) * width,
                    c.floors.ratios,
                    width,
                    label=f"{c.design}{chosen}: noise gain {c.noise_gain:.3g}",
                )
            axes.set_xticks(np.arange(count), [f"x0 #{i + 1}" for i in range(count)])
            axes.set_yscale("log")
        axes.axhline(1.0, color="k", lw=1)
        axes.set_ylabel("F / F_c")
        axes.set_title("sampled error floor over the continuous observer's, per initial state")
        axes.legend()
    return cast("Axes", axes)
