"""Spectra: eigenvalues in the complex plane, abscissa against gain, gain maps."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.core.errors import NumericError
from phdesign.plots._figures import (
    ABSCISSA_LABEL,
    IM_LABEL,
    RE_LABEL,
    axes_or_new,
    drawing,
    eigenvalue_labels,
    legend_in_view,
    literal,
)

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "plot_abscissa_sweep",
    "plot_gain_map",
    "plot_loop_spectrum",
    "plot_spectrum",
    "plot_spectrum_report",
]


def _resolved_mask(lam: np.ndarray, resolved: np.ndarray | None) -> np.ndarray:
    """Return the mask of the resolved eigenvalues from a mask or indices (all: none given)."""
    if resolved is None:
        return np.ones(lam.size, dtype=bool)
    r = np.asarray(resolved)
    if r.dtype != bool:
        mask = np.zeros(lam.size, dtype=bool)
        mask[r.astype(int).ravel()] = True
        return mask
    if r.size != lam.size:
        raise NumericError(
            f"resolved mask has {r.size} entries; expected {lam.size} (one per eigenvalue)"
        )
    return r.ravel()


def plot_spectrum(
    eigenvalues: np.ndarray,
    resolved: np.ndarray | None = None,
    *,
    ax: Axes | None = None,
    abscissa: float | None = None,
    exact: np.ndarray | None = None,
    title: str = "spectrum",
    xlim: tuple[float, float] | None = None,
    ylim: tuple[float, float] | None = None,
) -> Figure:
    """Eigenvalues in the complex plane, resolved and unresolved ones marked differently.

    Resolved eigenvalues (those that agree between two resolutions, see
    :func:`phdesign.numeric.spectrum.drift.match_resolved`) are filled blue dots; unresolved
    ones are grey crosses: they are artefacts of the discretization and the spectral
    abscissa ignores them.  The legend lists only what the view shows: below the axes,
    or inside them when they are one panel of several.

    Parameters
    ----------
    eigenvalues : array of complex
        The eigenvalues at the finer resolution.
    resolved : array of bool or of int, optional
        Mask (or indices) of the resolved eigenvalues; default: no distinction is
        made and every eigenvalue is drawn as a blue dot labelled "eigenvalues".
    ax : Axes, optional
    abscissa : float, optional
        Drawn as a vertical dashed line.
    exact : array of complex, optional
        Exact eigenvalues, drawn as black plus signs.
    title : str
    xlim, ylim : pair of float, optional
        View window (the unresolved eigenvalues usually run far off).

    Returns
    -------
    Figure
    """
    lam = np.asarray(eigenvalues, dtype=complex).ravel()
    lam = lam[np.isfinite(lam)]
    mask = _resolved_mask(lam, resolved)
    fig, ax = axes_or_new(ax, figsize=(6, 4.5))
    ax.plot(
        lam[mask].real,
        lam[mask].imag,
        ls="none",
        marker="o",
        color="tab:blue",
        label="eigenvalues" if resolved is None else "resolved (agree at two resolutions)",
    )
    if not mask.all():
        ax.plot(
            lam[~mask].real,
            lam[~mask].imag,
            ls="none",
            marker="x",
            color="0.6",
            label="unresolved (discretization artefacts)",
        )
    if exact is not None:
        ex = np.asarray(exact, dtype=complex).ravel()
        ax.plot(ex.real, ex.imag, ls="none", marker="+", ms=10, color="black", label="exact")
    if abscissa is not None:
        ax.axvline(
            float(abscissa),
            color="tab:red",
            ls="--",
            label=f"spectral abscissa α = {abscissa:.4g}",
        )
    ax.axvline(0.0, color="black", lw=0.6)
    ax.set(xlabel=RE_LABEL, ylabel=IM_LABEL, title=title)
    if xlim is not None:
        ax.set_xlim(*xlim)
    if ylim is not None:
        ax.set_ylim(*ylim)
    ax.grid(True, alpha=0.3)
    # below the axes when the spectrum has its figure to itself; inside when it is one
    # panel of several (each legend below its panel would squeeze the panels to nothing)
    alone = len([a for a in fig.axes if a.get_visible()]) == 1
    legend_in_view(ax, outside=alone, **({} if alone else {"loc": "lower left", "fontsize": 7}))
    return fig


def plot_abscissa_sweep(
    gains: np.ndarray,
    abscissa: np.ndarray,
    *,
    ax: Axes | None = None,
    exact: Callable[[np.ndarray], np.ndarray] | None = None,
    exact_label: str = "exact",
    xlabel: str = "gain k",
) -> Figure:
    """Spectral abscissa against a scalar gain, with an optional exact curve overlaid.

    Parameters
    ----------
    gains, abscissa : array of float
        Computed abscissa per gain (NaN where none converged).
    ax : Axes, optional
    exact : callable, optional
        ``exact(k)``, drawn as a line on a fine grid spanning ``gains``.
    exact_label : str
        Its legend text (e.g. ``"exact ½ ln|(1−k)/(1+k)|"``).
    xlabel : str

    Returns
    -------
    Figure
    """
    k = np.asarray(gains, dtype=float)
    alpha = np.asarray(abscissa, dtype=float)
    if k.shape != alpha.shape:
        raise NumericError(f"gains and abscissa differ in shape: {k.shape} against {alpha.shape}")
    fig, ax = axes_or_new(ax, figsize=(6, 4))
    if exact is not None:
        fine = np.linspace(float(np.min(k)), float(np.max(k)), 801)
        with np.errstate(divide="ignore", invalid="ignore"):
            values = np.asarray(exact(fine), dtype=float)
        ax.plot(fine, np.where(np.isfinite(values), values, np.nan), "k-", lw=1, label=exact_label)
    ax.plot(k, alpha, ls="none", marker="o", color="tab:blue", label="computed (resolved)")
    ax.set(xlabel=xlabel, ylabel=ABSCISSA_LABEL, title="spectral abscissa against gain")
    ax.grid(True, alpha=0.3)
    legend_in_view(ax)
    return fig


def plot_gain_map(
    l1: np.ndarray,
    l2: np.ndarray,
    abscissa: np.ndarray,
    *,
    ax: Axes | None = None,
    optimum: tuple[float, float] | None = None,
    optimum_abscissa: float | None = None,
    designs: Mapping[str, tuple[float, float]] | None = None,
    log: bool = True,
) -> Figure:
    """Spectral abscissa of the error system over a grid of diagonal gains (l1, l2).

    Parameters
    ----------
    l1, l2 : array of float
        Grid values, lengths m1 and m2.
    abscissa : array of float, shape (m2, m1)
        ``abscissa[j, i]`` at ``(l1[i], l2[j])``; NaN where nothing converged (grey).
    ax : Axes, optional
    optimum : (l1, l2), optional
        The tuned gain, drawn as a white star.
    optimum_abscissa : float, optional
        Its abscissa, quoted in the legend.
    designs : mapping label -> (l1, l2), optional
        Other designs, drawn as labelled circles.
    log : bool
        Logarithmic gain axes.

    Returns
    -------
    Figure
    """
    x = np.asarray(l1, dtype=float)
    y = np.asarray(l2, dtype=float)
    a = np.asarray(abscissa, dtype=float)
    if a.shape != (y.size, x.size):
        raise NumericError(
            f"abscissa grid must have shape (len(l2), len(l1)) = {(y.size, x.size)}; "
            f"found {a.shape}"
        )
    fig, ax = axes_or_new(ax, figsize=(6.2, 4.8))
    from matplotlib import colormaps

    cmap = colormaps["viridis"].with_extremes(bad="0.8")  # unresolved cells in grey
    mesh = ax.pcolormesh(x, y, np.ma.masked_invalid(a), shading="nearest", cmap=cmap)
    fig.colorbar(mesh, ax=ax, label=ABSCISSA_LABEL)
    if designs:
        for label, (g1, g2) in designs.items():
            ax.plot(g1, g2, ls="none", marker="o", mfc="none", mec="white", ms=9, mew=1.5)
            ax.annotate(label, (g1, g2), xytext=(6, 4), textcoords="offset points", color="white")
    if optimum is not None:
        text = f"tuned optimum ({optimum[0]:.3g}, {optimum[1]:.3g})"
        if optimum_abscissa is not None:
            text += f", α = {optimum_abscissa:.3g}"
        ax.plot(*optimum, ls="none", marker="*", ms=16, color="white", mec="black", label=text)
        legend_in_view(ax, loc="lower left")
    if log:
        ax.set_xscale("log")
        ax.set_yscale("log")
    ax.set(xlabel="gain l1", ylabel="gain l2", title="spectral abscissa over (l1, l2)")
    return fig


def plot_spectrum_report(
    report: Any,
    *,
    ax: Axes | None = None,
    exact: np.ndarray | None = None,
    title: str | None = None,
    xlim: tuple[float, float] | None = None,
    ylim: tuple[float, float] | None = None,
) -> Figure:
    """Draw a converged spectrum's chosen pair: resolved eigenvalues marked, the abscissa.

    The default window frames the resolved eigenvalues (the unresolved ones run far
    off); the default title names the model and the system.  The arguments are those
    of :func:`plot_spectrum` (:meth:`SpectrumReport.plot` hands itself here).
    """
    lam = report.eigenvalues
    if xlim is None and ylim is None and report.resolved.any():
        shown = lam[report.resolved]
        width = max(float(np.ptp(shown.real)), abs(float(np.min(shown.real))), 1e-300)
        height = max(float(np.max(np.abs(shown.imag))), width)
        xlim = (
            float(np.min(shown.real)) - 0.1 * width,
            max(0.0, float(np.max(shown.real))) + 0.1 * width,
        )
        ylim = (-1.1 * height, 1.1 * height)
    return plot_spectrum(
        lam,
        report.resolved,
        ax=ax,
        abscissa=report.spectral_abscissa,
        exact=exact,
        title=title if title is not None else literal(f"{report.model}: {report.system}"),
        xlim=xlim,
        ylim=ylim,
    )


def plot_loop_spectrum(result: Any, ax: Axes | None = None) -> Figure:
    """Draw a loop's rightmost resolved eigenvalues, marked by the block they belong to.

    The controlled plant's eigenvalues are circles, the error system's crosses, the loop's
    abscissa a vertical line (:meth:`LoopSpectrum.plot` hands itself here).  The title
    names the model and the design; the axes are in the model's time unit (SI: s).
    """
    title = f"{result.model}: {result.design}"
    unit = getattr(getattr(result, "plant", None), "time_unit", None)
    re_label, im_label = eigenvalue_labels(unit)
    with drawing(ax=ax, title=title if ax is None else None, figsize=(6, 4.5)) as (fig, axes):
        for kind, marker in (("plant", "o"), ("error", "x")):
            z = np.array(
                [w for w, o in zip(result.rightmost, result.origin, strict=True) if o == kind]
            )
            if z.size:
                axes.plot(z.real, z.imag, marker, ls="none", label=f"{kind} block")
        if result.spectral_abscissa is not None:
            label = f"loop abscissa α = {result.spectral_abscissa:.4g}"
            axes.axvline(result.spectral_abscissa, color="k", lw=0.8, label=label)
        axes.set(xlabel=re_label, ylabel=im_label, title="loop spectrum (rightmost, resolved)")
        axes.grid(True, alpha=0.3)
        axes.legend(fontsize="small")
    return fig
