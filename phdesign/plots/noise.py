"""Plots of the noise figures: the speed/noise trade-off and a noise report.

A front end (matplotlib only, imported lazily): it draws what
:mod:`phdesign.numeric.noise.tradeoff` and :mod:`phdesign.numeric.noise.figures` computed.  Figures
come from :func:`phdesign.plots.drawing` (the one place that makes the axes and writes
the file) and are written atomically when a path is given.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.core.text import gain_text, measured_text
from phdesign.plots._figures import drawing, frequency_label, literal

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["plot_noise_report", "plot_tradeoff"]


def plot_tradeoff(
    result: Any,
    path: str | os.PathLike[str] | None = None,
    *,
    force: bool = False,
    annotate: str = "pareto",
) -> Figure:
    """Decay rate −α against a figure of the error; Pareto-optimal gains joined and annotated.

    The figure is each point's ``figure`` (the RMS of a :class:`~phdesign.numeric.noise.
    tradeoff.Tradeoff`, the H∞ norm of a :class:`~phdesign.numeric.noise.
    disturbance_tradeoff.DisturbanceTradeoff`), named by the result's ``figure_label``.

    Parameters
    ----------
    result : Tradeoff or DisturbanceTradeoff
    path : path-like, optional
        Write the figure there (suffix picks the format).
    force : bool
        Overwrite an existing file.
    annotate : {"pareto", "all", "none"}
        Which points carry their gain as a label.
    """
    with drawing(path, force=force, figsize=(7.5, 5.0)) as (fig, ax):
        _draw_tradeoff(ax, result, annotate)
    return fig


def _draw_tradeoff(ax: Axes, result: Any, annotate: str) -> None:
    pts = [p for p in result.points if p.figure is not None and p.decay_rate is not None]
    others = [p for p in pts if not p.pareto]
    front = sorted((p for p in pts if p.pareto), key=lambda p: p.figure)
    if others:
        ax.scatter(
            [p.figure for p in others],
            [p.decay_rate for p in others],
            color="0.6",
            label="dominated",
            zorder=2,
        )
    if front:
        ax.plot(
            [p.figure for p in front],
            [p.decay_rate for p in front],
            "-o",
            color="tab:red",
            label="Pareto-optimal",
            zorder=3,
        )
    loose = [p for p in pts if not p.abscissa_converged]
    if loose:
        ax.scatter(
            [p.figure for p in loose],
            [p.decay_rate for p in loose],
            facecolors="none",
            edgecolors="black",
            s=120,
            label="abscissa not converged (coalescence)",
            zorder=4,
        )
    labelled = {"pareto": front, "all": pts, "none": []}.get(annotate, front)
    for p in _spread(labelled):
        ax.annotate(
            gain_text(p.gain),
            (p.figure, p.decay_rate),
            textcoords="offset points",
            xytext=(6, 4),
            fontsize=8,
        )
    ax.set_xscale("log")
    rate = getattr(result, "time_unit", "") or "s"
    ax.set(
        xlabel=literal(result.figure_label),
        ylabel=f"decay rate −α [1/{rate}]",
        title=literal(
            f"{result.model}, sensors {measured_text(result.sensors)}: {result.figure_title}"
        ),
    )
    ax.grid(True, which="both", alpha=0.3)
    if pts:
        ax.legend(loc="best")


def _spread(points: list[Any], gap: float = 0.035) -> list[Any]:
    """Drop labels that would overlap the previous one (log figure, linear decay, relative)."""
    if not points:
        return []
    lx = np.log10([p.figure for p in points])
    y = np.array([p.decay_rate for p in points])
    sx, sy = max(float(np.ptp(lx)), 1e-12), max(float(np.ptp(y)), 1e-12)
    kept = [0]
    for i in range(1, len(points)):
        j = kept[-1]
        if abs(lx[i] - lx[j]) / sx > gap * 3 or abs(y[i] - y[j]) / sy > gap * 2:
            kept.append(i)
    return [points[i] for i in kept]


def plot_noise_report(
    report: Any, path: str | os.PathLike[str] | None = None, *, force: bool = False
) -> Figure:
    """Draw the frequency response per resolution, and every figure under refinement.

    Left: the energy-norm gain from the noise to the error at each resolution, the
    unresolved frequencies shaded and the peak γ starred.  Right: each figure divided by
    its finest value against the resolution (flat when it converges, rising when it
    diverges).
    """
    frame = drawing(
        path, force=force, title=report.header(), title_size=9, ncols=2, figsize=(11, 4.2)
    )
    with frame as (fig, (left, right)):
        _draw_frequency_response(left, report)
        _draw_refinement(right, report)
    return fig


def _draw_frequency_response(left: Axes, report: Any) -> None:
    if report.pencils:
        omega = report.default_frequencies()
        band = report.l2_gain.band
        if band and omega[0] < band < omega[-1]:  # the axis ends where the resolved band does
            omega = np.append(omega[omega < band], band)
        for res, values in report.frequency_response(omega).items():
            left.loglog(omega, values, lw=1, label=f"resolution {res}")
        left.set_xlim(float(omega[0]), float(omega[-1]))
        g = report.l2_gain
        if g.value is not None and g.frequency:
            left.plot(g.frequency, g.value, "k*", ms=12, label=f"γ = {g.value:.4g}")
        disc = g.discrete
        shown = g.discrete_frequency is not None and g.discrete_frequency <= omega[-1]
        if disc is not None and disc.values and g.discrete_frequency and shown:
            # a sharp resonance of an unresolved mode falls between the plotted samples
            left.plot(
                g.discrete_frequency,
                disc.values[-1],
                "rx",
                ms=9,
                label=f"discretization's supremum {disc.values[-1]:.3g}",
            )
        left.legend(loc="lower left", fontsize=8)
    left.set(
        xlabel=frequency_label(getattr(report, "time_unit", None)),
        ylabel="gain noise → error (energy norm)",
        title="frequency response",
    )


def _draw_refinement(right: Axes, report: Any) -> None:
    figures = [*report.performance, report.error_energy]
    for est in figures:
        values = np.asarray(est.values, dtype=float)
        if values.size and np.all(np.isfinite(values)) and values[-1] > 0:
            label = f"{'Var ' if est is not report.error_energy else ''}{est.name}: {est.status()}"
            right.plot(est.resolutions, values / values[-1], "-o", label=label)
    right.set(xlabel="resolution", ylabel="value / finest value", title="figures under refinement")
    right.legend(loc="best", fontsize=8)
