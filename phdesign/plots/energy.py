"""Energies against time: the Hamiltonians of plant, observer and error (Figs. 1 and 6)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.core.errors import NumericError
from phdesign.plots._figures import (
    DESIGN_COLORS,
    ERROR_COLOR,
    OBSERVER_COLOR,
    PLANT_COLOR,
    axes_or_new,
    figure_of,
    labelled_results,
    legend_in_view,
    log_scale_if_positive,
    new_figure,
    plain_numbers,
    require,
    unit_label,
)

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["plot_error_energy", "plot_hamiltonians"]


def plot_hamiltonians(result: Any, axes: Sequence[Axes] | None = None) -> Figure:
    r"""Plant, observer and error Hamiltonians against time (the paper's Fig. 1).

    Left panel, linear scale from zero: :math:`H(t)` (solid blue), :math:`\hat H(t)`
    (dashed orange) and :math:`\tilde H(t)` (solid red).  Right panel, log scale: :math:`\tilde H`
    and, for comparison, the plant's own decay :math:`H`; exponential convergence shows
    as a straight line.  Without an observer only :math:`H` is drawn.

    Parameters
    ----------
    result : SimulationResult
        From :func:`phdesign.numeric.time.simulation.simulate`.
    axes : pair of Axes, optional
        Where to draw (linear, log); a new 1 x 2 figure otherwise.

    Returns
    -------
    Figure
    """
    t = require(result, "t", "no time grid")
    H = require(result, "H", "no plant energy")
    if axes is None:
        fig, (ax_lin, ax_log) = new_figure(1, 2, figsize=(10, 3.8))
    else:
        ax_lin, ax_log = axes
        fig = figure_of(ax_lin)
    ax_lin.plot(t, H, color=PLANT_COLOR, ls="-", label="H (plant)")
    drawn = [H]
    if getattr(result, "H_err", None) is not None:
        H_hat = require(result, "H_hat", "no observer energy")
        H_err = require(result, "H_err", "no error energy")
        drawn += [H_hat, H_err]
        ax_lin.plot(t, H_hat, color=OBSERVER_COLOR, ls="--", label="Ĥ (observer)")
        ax_lin.plot(t, H_err, color=ERROR_COLOR, ls="-", label="H̃ (estimation error)")
        ax_log.plot(t, H_err, color=ERROR_COLOR, ls="-", label="H̃ (estimation error)")
    ax_log.plot(t, H, color=PLANT_COLOR, ls=":", label="H (plant)")
    time, energy = unit_label(result, "time t", "t"), unit_label(result, "energy", "energy")
    ax_lin.set(xlabel=time, ylabel=energy, title="Hamiltonians")
    ax_log.set(xlabel=time, ylabel=f"{energy}, log scale", title="decay (log scale)")
    if not log_scale_if_positive(ax_log, *drawn[::2]):  # H and H̃, the curves drawn there
        ax_log.set_title("decay (all zero: linear scale)")
    # energies are >= 0: from zero and without offset, a conserved energy is a flat line
    ax_lin.set_ylim(0.0, 1.05 * max(float(np.max(curve)) for curve in drawn) or 1.0)
    plain_numbers(ax_lin)
    for ax in (ax_lin, ax_log):
        ax.grid(True, alpha=0.3)
        legend_in_view(ax)
    return fig


def plot_error_energy(
    results: Mapping[str, Any] | Sequence[tuple[str, Any]],
    ax: Axes | None = None,
    *,
    normalize: bool = True,
    levels: Sequence[float] = (1e-2, 1e-4),
) -> Figure:
    r"""Error Hamiltonian :math:`\tilde H(t)` of several designs on a log scale (Fig. 6).

    Parameters
    ----------
    results : mapping label -> SimulationResult, or sequence of (label, result)
        One curve per design; the label names it in the legend.
    ax : Axes, optional
    normalize : bool
        Draw :math:`\tilde H(t)/\tilde H(0)` (dimensionless) instead of :math:`\tilde H`.
    levels : sequence of float
        Reference levels drawn as dotted horizontal lines (only when ``normalize``).

    Returns
    -------
    Figure
    """
    fig, ax = axes_or_new(ax, figsize=(6, 4))
    drawn = []
    for k, (label, res) in enumerate(labelled_results(results)):
        t = require(res, "t", "no time grid")
        H_err = require(res, "H_err", "simulate with sensors and a gain to get H̃")
        if normalize:
            if not H_err[0] > 0:
                raise NumericError(f"design {label!r}: H̃(0) = {H_err[0]:g}; cannot normalize")
            H_err = H_err / H_err[0]
        ax.plot(t, H_err, color=DESIGN_COLORS[k % len(DESIGN_COLORS)], label=label)
        drawn.append(H_err)
    if normalize:
        for level in levels:
            ax.axhline(level, color="gray", ls=":", lw=1, label=f"level {level:g}")
    first = labelled_results(results)[0][1]
    energy = unit_label(first, "H̃(t)", "energy")
    ylabel = "H̃(t) / H̃(0)  (log scale)" if normalize else f"{energy} (log scale)"
    ax.set(xlabel=unit_label(first, "time t", "t"), ylabel=ylabel, title="estimation-error energy")
    log_scale_if_positive(ax, *drawn)
    ax.grid(True, which="both", alpha=0.3)
    legend_in_view(ax)
    return fig
