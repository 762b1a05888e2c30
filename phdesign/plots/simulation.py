"""The summary figure of one simulation (``simulate --plot``)."""

from __future__ import annotations

import os
import re
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.plots._figures import (
    DESIGN_COLORS,
    axes_or_new,
    drawing,
    legend_in_view,
    literal,
    log_scale_if_positive,
    require,
    unit_label,
)
from phdesign.plots.deflection import plot_at, plot_deflection, plot_outputs, plot_tip
from phdesign.plots.energy import plot_hamiltonians

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["plot_boundary_states", "plot_simulation"]


def plot_simulation(
    result: Any,
    path: str | os.PathLike[str] | None = None,
    *,
    force: bool = False,
    title: str | None = None,
) -> Figure:
    r"""Summary figure of one simulation, written to ``path`` (used by ``simulate --plot``).

    Top row: :func:`plot_hamiltonians`.  Bottom row, when the model has a displacement:
    the end-tip overlay (:func:`plot_tip`) and the heat map of the estimation error
    :math:`w - \hat w` (of :math:`w` without an observer), the end tip replaced by the
    point outputs (:func:`plot_at`) when the run has ``at``; otherwise the outputs
    :math:`y` and :math:`\hat y` (:func:`plot_outputs`) and the output error
    :math:`|y - \hat y|` on a log scale.  A loop's run (its ``u``) adds a row: the
    control input :math:`u_a(t) = -K \hat y_a(t)` of each actuated input; a model with
    boundary systems adds a row: their states :math:`x_c(t)` beside the observer's
    estimates :math:`\hat x_c(t)` (:func:`plot_boundary_states`).

    Parameters
    ----------
    result : SimulationResult
    path : path-like, optional
        Output file; its suffix picks the format (``.png``, ``.pdf``, ``.svg``, ...).
        Written atomically.
    force : bool
        Overwrite an existing file.
    title : str, optional
        Figure title (default: the result's ``title``: model, sensors and gain).

    Returns
    -------
    Figure

    Raises
    ------
    OutputFileError
        The file exists (without ``force``), its format is unknown, or it cannot be written.
    """
    has_w = getattr(result, "w", None) is not None
    has_at = getattr(result, "at_values", None) is not None
    wide = [
        draw
        for draw, present in (
            (_plot_control_input, getattr(result, "u", None) is not None),
            (plot_boundary_states, getattr(result, "x_c", None) is not None),
        )
        if present
    ]
    if title is None:
        title = getattr(result, "title", None)
    rows = 2 + len(wide)
    frame = drawing(
        path, force=force, title=title, nrows=rows, ncols=2, figsize=(11, 7.5 + 3.0 * len(wide))
    )
    with frame as (fig, axes):
        plot_hamiltonians(result, axes[0])
        for row, draw in enumerate(wide, start=2):
            grid = axes[row, 0].get_gridspec()
            axes[row, 0].remove()
            axes[row, 1].remove()
            draw(result, fig.add_subplot(grid[row, :]))
        measured = _measured_outputs(result)
        if has_at:
            plot_at(result, axes[1, 0])
        elif has_w:
            plot_tip(result, axes[1, 0])
        else:
            plot_outputs(result, axes[1, 0], outputs=measured)
        if has_w:
            which = "error" if getattr(result, "w_hat", None) is not None else "w"
            plot_deflection(result, which, axes[1, 1])
        else:
            _plot_output_error(result, axes[1, 1], measured)
    return fig


def _plot_control_input(result: Any, ax: Axes) -> None:
    """Draw the inputs the loop applies, u_a(t) = −K ŷ_a(t), each actuated one labelled."""
    t = require(result, "t", "no time grid")
    u = require(result, "u", "no inputs")
    labels = tuple(getattr(result, "input_labels", ()))
    actuated = tuple(getattr(result, "actuated", ())) or tuple(range(1, u.shape[1] + 1))
    feed = "y" if getattr(result, "info", {}).get("feedback_source") == "measured" else "ŷ"
    for k, a in enumerate(actuated):
        trace = f" = {labels[a - 1]}" if a - 1 < len(labels) else ""
        ax.plot(
            t,
            u[:, a - 1],
            color=DESIGN_COLORS[k % len(DESIGN_COLORS)],
            label=literal(f"u{a}{trace}  (u{a} = −K {feed}{a})"),
        )
    ax.set(
        xlabel=unit_label(result, "time t", "t"),
        ylabel="control input u",
        title="control input u(t)",
    )
    ax.grid(True, alpha=0.3)
    legend_in_view(ax, fontsize="small")


def plot_boundary_states(result: Any, ax: Axes | None = None) -> Figure:
    r"""Draw the boundary systems' states :math:`x_c(t)` (solid) and estimates (dashed).

    The states are the model's own (a mass's momentum, a winding's flux), as
    ``result.x_c`` and ``result.x_c_hat`` hold them, one colour per state.

    Returns
    -------
    Figure
    """
    t = require(result, "t", "no time grid")
    x_c = require(result, "x_c", "no boundary states (the model has no boundary systems)")
    x_c_hat = getattr(result, "x_c_hat", None)
    fig, ax = axes_or_new(ax, figsize=(6, 3.5))
    for k, label in enumerate(result.boundary_labels):
        color = DESIGN_COLORS[k % len(DESIGN_COLORS)]
        ax.plot(t, x_c[:, k], color=color, label=literal(label))
        if x_c_hat is not None:
            ax.plot(t, x_c_hat[:, k], color=color, ls="--", label=literal(f"{label}, estimate"))
    ax.set(
        xlabel=unit_label(result, "time t", "t"),
        ylabel="boundary state x_c",
        title="boundary systems: states and estimates"
        if x_c_hat is not None
        else "boundary systems: states",
    )
    ax.grid(True, alpha=0.3)
    legend_in_view(ax, fontsize="small")
    return fig


def _measured_outputs(result: Any) -> list[int] | None:
    """Return the measured outputs named by the run's sensors (``"y3, y4"``), else all."""
    sensors = getattr(result, "info", {}).get("sensors", "")
    picked = sorted({int(j) for j in re.findall(r"y(\d+)", str(sensors))})
    return picked or None


def _plot_output_error(result: Any, ax: Axes, outputs: list[int] | None) -> None:
    t = require(result, "t", "no time grid")
    y = require(result, "y", "no outputs")
    y_hat = getattr(result, "y_hat", None)
    if y_hat is None:
        ax.set_axis_off()
        ax.text(0.5, 0.5, "no observer: outputs only", ha="center", va="center")
        return
    picked = list(range(1, y.shape[1] + 1)) if outputs is None else outputs
    error = np.abs(y - np.asarray(y_hat, dtype=float))
    for k, j in enumerate(picked):
        values = np.where(error[:, j - 1] > 0, error[:, j - 1], np.nan)
        ax.plot(t, values, color=DESIGN_COLORS[k % len(DESIGN_COLORS)], label=f"|y{j} − ŷ{j}|")
    ax.set(
        xlabel=unit_label(result, "time t", "t"),
        ylabel="output error, log scale",
        title="output error",
    )
    log_scale_if_positive(ax, error[:, [j - 1 for j in picked]])
    ax.grid(True, which="both", alpha=0.3)
    legend_in_view(ax, fontsize="small")
