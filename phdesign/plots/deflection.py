"""The displacement: space-time maps of w, its estimate and the error; the end tip (Figs. 2-5)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.core.errors import NumericError
from phdesign.plots._figures import (
    DESIGN_COLORS,
    OBSERVER_COLOR,
    PLANT_COLOR,
    axes_or_new,
    labelled_results,
    legend_in_view,
    new_figure,
    plain_numbers,
    require,
    tip_label,
    unit_label,
)

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "plot_at",
    "plot_deflection",
    "plot_deflection_panels",
    "plot_outputs",
    "plot_tip",
    "plot_tip_error",
]

_FIELDS = {
    "w": ("deflection w(z, t)", "plant deflection w"),
    "w_hat": ("estimate ŵ(z, t)", "estimated deflection ŵ"),
    "error": ("error w − ŵ", "estimation error w − ŵ"),
}


def _field(result: Any, which: str) -> np.ndarray:
    if which not in _FIELDS:
        raise NumericError(f"unknown field {which!r}; expected one of {', '.join(_FIELDS)}")
    w = require(result, "w", "the model has no displacement (see the model's [displacement])")
    if which == "w":
        return w
    w_hat = require(result, "w_hat", "simulate with sensors and a gain to get the estimate")
    return w_hat if which == "w_hat" else w - w_hat


def plot_deflection(
    result: Any,
    which: str = "w",
    ax: Axes | None = None,
    *,
    vmax: float | None = None,
    colorbar: bool = True,
    cmap: str | None = None,
) -> Figure:
    r"""Space-time heat map of the deflection, its estimate or their difference (Figs. 2-4).

    The colour at (t, z) is :math:`w(z, t)` (``which="w"``), :math:`\hat w(z, t)`
    (``"w_hat"``) or :math:`w - \hat w` (``"error"``), with a symmetric colour scale
    :math:`[-v_{max}, v_{max}]` (default: the largest magnitude drawn).

    Parameters
    ----------
    result : SimulationResult
        Needs ``z_w`` and ``w`` (and ``w_hat`` unless ``which="w"``).
    which : {"w", "w_hat", "error"}
    ax : Axes, optional
    vmax : float, optional
        Half-range of the colour scale (share it between panels to compare them).
    colorbar : bool
    cmap : str, optional
        Colormap (default ``"RdBu_r"``, diverging around zero).

    Returns
    -------
    Figure
    """
    data = _field(result, which)
    t = require(result, "t", "no time grid")
    z = require(result, "z_w", "the deflection was not sampled")
    fig, ax = axes_or_new(ax, figsize=(6, 3.6))
    scale = float(vmax) if vmax is not None else float(np.max(np.abs(data))) or 1.0
    mesh = ax.pcolormesh(
        t, z, data.T, shading="nearest", cmap=cmap or "RdBu_r", vmin=-scale, vmax=scale
    )
    mesh.set_label(_FIELDS[which][1])
    ax.set(
        xlabel=unit_label(result, "time t", "t"),
        ylabel=unit_label(result, "position z", "z"),
        title=_FIELDS[which][1],
    )
    if colorbar:
        fig.colorbar(mesh, ax=ax, label=unit_label(result, _FIELDS[which][0], "displacement"))
    return fig


def plot_tip(result: Any, ax: Axes | None = None) -> Figure:
    r"""End-tip position :math:`w(b, t)` (solid blue) and its estimate (dashed orange).

    The paper's Fig. 2 overlay: the estimate should superpose the true position once
    the observer has converged.

    Returns
    -------
    Figure
    """
    t = require(result, "t", "no time grid")
    w = require(result, "w", "the model has no displacement")
    fig, ax = axes_or_new(ax, figsize=(6, 3.5))
    where = tip_label(result)
    ax.plot(t, w[:, -1], color=PLANT_COLOR, ls="-", label=f"w({where}, t) (plant)")
    if getattr(result, "w_hat", None) is not None:
        w_hat = np.asarray(result.w_hat, dtype=float)
        ax.plot(t, w_hat[:, -1], color=OBSERVER_COLOR, ls="--", label=f"ŵ({where}, t) (observer)")
    ax.set(
        xlabel=unit_label(result, "time t", "t"),
        ylabel=unit_label(result, "end-tip deflection", "displacement"),
        title="end-tip position",
    )
    ax.grid(True, alpha=0.3)
    legend_in_view(ax)
    return fig


def plot_at(result: Any, ax: Axes | None = None) -> Figure:
    """Draw the point outputs ``at`` (``rotation(1)``, ``w(0.5)``), estimates dashed.

    Each is labelled with its field's unit where the model states one; the axis carries
    the unit when every output shares it.

    Returns
    -------
    Figure
    """
    t = require(result, "t", "no time grid")
    values = require(result, "at_values", "simulate with at=[...] to get point outputs")
    estimates = getattr(result, "at_values_hat", None)
    fig, ax = axes_or_new(ax, figsize=(6, 3.5))
    parts = [name.partition("(") for name in result.at]
    keys = ["displacement" if field == "w" else field for field, _, _ in parts]
    units = getattr(result, "units", None) or {}
    shared = len({units.get(key) for key in keys}) == 1
    for k, (name, (field, _, point)) in enumerate(zip(result.at, parts, strict=True)):
        color = f"C{k % 10}"  # matplotlib's cycle: one distinct colour per output
        label = name if shared else unit_label(result, name, keys[k])
        ax.plot(t, values[:, k], color=color, ls="-", label=f"{label} (plant)")
        if estimates is not None:
            hat = f"{field}_hat({point}"
            ax.plot(t, estimates[:, k], color=color, ls="--", label=f"{hat} (observer)")
    ylabel = unit_label(result, "point outputs", keys[0]) if shared else "point outputs"
    ax.set(xlabel=unit_label(result, "time t", "t"), ylabel=ylabel, title="point outputs")
    ax.grid(True, alpha=0.3)
    legend_in_view(ax, fontsize="small")
    return fig


def plot_deflection_panels(result: Any) -> Figure:
    """Deflection, estimate (shared colour scale), their difference, and the tip overlay.

    A 2 x 2 figure: :func:`plot_deflection` for ``"w"``, ``"w_hat"`` and ``"error"``, and
    :func:`plot_tip`: the paper's Figs. 2, 3 and 4 side by side.

    Returns
    -------
    Figure
    """
    w = _field(result, "w")
    w_hat = _field(result, "w_hat")
    fig, axes = new_figure(2, 2, figsize=(11, 7))
    shared = float(max(np.max(np.abs(w)), np.max(np.abs(w_hat)))) or 1.0
    plot_deflection(result, "w", axes[0, 0], vmax=shared)
    plot_deflection(result, "w_hat", axes[0, 1], vmax=shared)
    plot_deflection(result, "error", axes[1, 0])
    plot_tip(result, axes[1, 1])
    return fig


def plot_tip_error(
    results: Mapping[str, Any] | Sequence[tuple[str, Any]], ax: Axes | None = None
) -> Figure:
    r"""End-tip error :math:`w(b, t) - \hat w(b, t)` of several designs (the paper's Fig. 5).

    Parameters
    ----------
    results : mapping label -> SimulationResult, or sequence of (label, result)
    ax : Axes, optional

    Returns
    -------
    Figure
    """
    fig, ax = axes_or_new(ax, figsize=(6, 4))
    where = "b"
    for k, (label, res) in enumerate(labelled_results(results)):
        t = require(res, "t", "no time grid")
        err = _field(res, "error")[:, -1]
        where = tip_label(res)
        ax.plot(t, err, color=DESIGN_COLORS[k % len(DESIGN_COLORS)], label=label)
    ax.axhline(0.0, color="black", lw=0.6)
    ax.set(
        xlabel=unit_label(res, "time t", "t"),
        ylabel=unit_label(res, f"w − ŵ at {where}", "displacement"),
        title="end-tip estimation error",
    )
    ax.grid(True, alpha=0.3)
    legend_in_view(ax)
    return fig


def plot_outputs(
    result: Any, ax: Axes | None = None, *, outputs: Sequence[int] | None = None
) -> Figure:
    r"""Boundary outputs :math:`y_j(t)` (solid) and their estimates :math:`\hat y_j(t)` (dashed).

    The panel of models without a displacement: what the sensors see, and how the
    observer's outputs join them.

    Parameters
    ----------
    result : SimulationResult
    ax : Axes, optional
    outputs : sequence of int, optional
        1-based outputs to draw (default: all).

    Returns
    -------
    Figure
    """
    t = require(result, "t", "no time grid")
    y = require(result, "y", "no outputs")
    y_hat = getattr(result, "y_hat", None)
    labels = list(getattr(result, "output_labels", ()) or [])
    picked = list(range(1, y.shape[1] + 1)) if outputs is None else [int(j) for j in outputs]
    for j in picked:
        if not 1 <= j <= y.shape[1]:
            raise NumericError(f"outputs: index {j} is out of range; expected 1..{y.shape[1]}")
    fig, ax = axes_or_new(ax, figsize=(6, 3.5))
    for k, j in enumerate(picked):
        color = DESIGN_COLORS[k % len(DESIGN_COLORS)]
        meaning = f" = {labels[j - 1]}" if len(labels) >= j else ""
        ax.plot(t, y[:, j - 1], color=color, ls="-", label=f"y{j}{meaning}")
        if y_hat is not None:
            ax.plot(t, np.asarray(y_hat)[:, j - 1], color=color, ls="--", label=f"ŷ{j}")
    ax.set(
        xlabel=unit_label(result, "time t", "t"),
        ylabel="outputs y, ŷ",
        title="boundary outputs (dashed: observer)",
    )
    plain_numbers(ax)
    ax.grid(True, alpha=0.3)
    legend_in_view(ax, fontsize="small")
    return fig
