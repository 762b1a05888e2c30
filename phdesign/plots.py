r"""Plots for observer design: energies, deflections, tip errors, spectra and gain maps.

A front end: every function draws data that a lower layer computed
(:class:`phdesign.numeric.simulate.SimulationResult`, eigenvalues from
:mod:`phdesign.numeric.spectrum`, abscissas from :mod:`phdesign.numeric.tune`) and returns
the :class:`matplotlib.figure.Figure` it drew on.  Functions that draw one panel accept an
optional ``ax``; without it they make a new figure.

matplotlib is imported lazily, inside the functions, so that ``import phdesign.plots``
stays light.  New figures are plain :class:`~matplotlib.figure.Figure` objects on an Agg
canvas (no display, no pyplot global state: safe in scripts, servers and tests); inside a
Jupyter kernel they are made through pyplot instead, so that the inline backend shows them.

Units: labels carry the units the model states in its ``[units]`` section (through
``SimulationResult.units``); a quantity with no stated unit gets a plain label.  A result
built by hand (``units`` None) and the spectrum plots, which take bare arrays, use the
SI convention of the built-in models: time in s, position and deflection in m, energy
in J, eigenvalues in 1/s.

The quantities drawn are the paper's (Section V):

.. math::

    H = \tfrac12 \int_a^b x^\top \mathcal H x \, dz, \quad
    \hat H = \tfrac12 \int_a^b \hat x^\top \mathcal H \hat x \, dz, \quad
    \tilde H = \tfrac12 \int_a^b \tilde x^\top \mathcal H \tilde x \, dz, \quad
    \tilde x = x - \hat x,

the deflection :math:`w(z, t)`, its estimate :math:`\hat w(z, t)` and the end-tip error
:math:`w(b, t) - \hat w(b, t)`.

Examples
--------
>>> import numpy as np
>>> fig = plot_spectrum(np.array([-1 + 2j, -1 - 2j, -0.1 + 90j]), np.array([True, True, False]))
>>> sorted(t.get_text() for t in fig.axes[0].get_legend().get_texts())[0]
'resolved (agree at two resolutions)'
"""

from __future__ import annotations

import io
import os
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.errors import NumericError, OutputFileError
from phdesign.io import check_output_path
from phdesign.symbolic.units import with_unit

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "check_plot_path",
    "new_figure",
    "plot_abscissa_sweep",
    "plot_deflection",
    "plot_deflection_panels",
    "plot_error_energy",
    "plot_gain_map",
    "plot_hamiltonians",
    "plot_simulation",
    "plot_spectrum",
    "plot_tip",
    "plot_tip_error",
]

RE_LABEL = "Re λ [1/s]"
IM_LABEL = "Im λ [rad/s]"
ABSCISSA_LABEL = "spectral abscissa α [1/s]"

#: The paper's colours: plant solid blue, observer dashed orange, error solid orange.
PLANT_COLOR, OBSERVER_COLOR, ERROR_COLOR = "tab:blue", "tab:orange", "tab:red"
#: Design colours of the paper's Fig. 5 (yellow, orange, violet), then matplotlib's cycle.
DESIGN_COLORS = ("goldenrod", "tab:orange", "tab:purple", "tab:green", "tab:brown", "tab:cyan")

_FIELDS = {
    "w": ("deflection w(z, t)", "plant deflection w"),
    "w_hat": ("estimate ŵ(z, t)", "estimated deflection ŵ"),
    "error": ("error w − ŵ", "estimation error w − ŵ"),
}
#: Units assumed for a result that states none (the built-in models are in SI).
SI_UNITS = {"t": "s", "z": "m", "energy": "J", "displacement": "m"}


def _label(result: Any, text: str, quantity: str) -> str:
    """``text [unit]`` with the unit of ``quantity`` the result's model states."""
    units = getattr(result, "units", None)
    return with_unit(text, SI_UNITS if units is None else units, quantity)


# ----------------------------------------------------------------------------- figures
def _in_jupyter_kernel() -> bool:
    """Tell whether this runs inside a Jupyter kernel (not merely with ipykernel imported)."""
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    return type(shell).__name__ == "ZMQInteractiveShell"


def new_figure(nrows: int = 1, ncols: int = 1, **kwargs: Any) -> tuple[Figure, Any]:
    """Return ``(fig, axes)`` as ``pyplot.subplots`` does, to compose panels.

    Outside Jupyter the figure lives on an Agg canvas (no display, no pyplot state);
    inside a Jupyter kernel it is made by pyplot so that the inline backend shows it.
    Keyword arguments go to the figure (``figsize``, ``dpi``); the layout is constrained.

    Examples
    --------
    >>> fig, axes = new_figure(1, 2, figsize=(8, 3))
    >>> plot_spectrum(np.array([-1.0 + 1j]), ax=axes[0]) is fig
    True
    """
    if _in_jupyter_kernel():
        import matplotlib.pyplot as plt

        fig = plt.figure(layout="constrained", **kwargs)
    else:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(layout="constrained", **kwargs)
        FigureCanvasAgg(fig)  # explicit Agg: never needs a display
    axes = fig.subplots(nrows, ncols, squeeze=True)
    return fig, axes


def _figure_of(ax: Axes) -> Figure:
    """Return the top-level figure an Axes belongs to (through any subfigures)."""
    from matplotlib.figure import Figure

    fig: Any = ax.get_figure()
    while fig is not None and not isinstance(fig, Figure):
        fig = fig.get_figure()
    if fig is None:
        raise NumericError("the given Axes belongs to no figure")
    return fig


def _axes(ax: Axes | None, **kwargs: Any) -> tuple[Figure, Axes]:
    if ax is not None:
        return _figure_of(ax), ax
    fig, new = new_figure(**kwargs)
    return fig, new


def _require(result: Any, name: str, why: str) -> np.ndarray:
    value = getattr(result, name, None)
    if value is None:
        raise NumericError(f"the simulation result has no {name!r}: {why}")
    return np.asarray(value, dtype=float)


def _items(results: Mapping[str, Any] | Sequence[tuple[str, Any]]) -> list[tuple[str, Any]]:
    items = list(results.items()) if isinstance(results, Mapping) else list(results)
    if not items:
        raise NumericError("expected at least one (label, simulation result) pair; found none")
    return [(str(label), res) for label, res in items]


def _tip_label(result: Any) -> str:
    z = getattr(result, "z_w", None)
    return "z = b" if z is None or len(z) == 0 else f"z = {float(np.asarray(z)[-1]):g}"


# ----------------------------------------------------------------------------- energies
def plot_hamiltonians(result: Any, axes: Sequence[Axes] | None = None) -> Figure:
    r"""Plant, observer and error Hamiltonians against time (the paper's Fig. 1).

    Left panel, linear scale: :math:`H(t)` (solid blue), :math:`\hat H(t)` (dashed
    orange) and :math:`\tilde H(t)` (solid red).  Right panel, log scale: :math:`\tilde H`
    and, for comparison, the plant's own decay :math:`H`; exponential convergence shows
    as a straight line.  Without an observer only :math:`H` is drawn.

    Parameters
    ----------
    result : SimulationResult
        From :func:`phdesign.numeric.simulate.simulate`.
    axes : pair of Axes, optional
        Where to draw (linear, log); a new 1 x 2 figure otherwise.

    Returns
    -------
    Figure
    """
    t = _require(result, "t", "no time grid")
    H = _require(result, "H", "no plant energy")
    if axes is None:
        fig, (ax_lin, ax_log) = new_figure(1, 2, figsize=(10, 3.8))
    else:
        ax_lin, ax_log = axes
        fig = _figure_of(ax_lin)
    ax_lin.plot(t, H, color=PLANT_COLOR, ls="-", label="H (plant)")
    has_observer = getattr(result, "H_err", None) is not None
    if has_observer:
        H_hat = _require(result, "H_hat", "no observer energy")
        H_err = _require(result, "H_err", "no error energy")
        ax_lin.plot(t, H_hat, color=OBSERVER_COLOR, ls="--", label="Ĥ (observer)")
        ax_lin.plot(t, H_err, color=ERROR_COLOR, ls="-", label="H̃ (estimation error)")
        ax_log.semilogy(t, H_err, color=ERROR_COLOR, ls="-", label="H̃ (estimation error)")
    ax_log.semilogy(t, H, color=PLANT_COLOR, ls=":", label="H (plant)")
    time, energy = _label(result, "time t", "t"), _label(result, "energy", "energy")
    ax_lin.set(xlabel=time, ylabel=energy, title="Hamiltonians")
    ax_log.set(xlabel=time, ylabel=f"{energy}, log scale", title="decay (log scale)")
    for ax in (ax_lin, ax_log):
        ax.grid(True, alpha=0.3)
        ax.legend()
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
    fig, ax = _axes(ax, figsize=(6, 4))
    for k, (label, res) in enumerate(_items(results)):
        t = _require(res, "t", "no time grid")
        H_err = _require(res, "H_err", "simulate with sensors and a gain to get H̃")
        if normalize:
            if not H_err[0] > 0:
                raise NumericError(f"design {label!r}: H̃(0) = {H_err[0]:g}; cannot normalize")
            H_err = H_err / H_err[0]
        ax.semilogy(t, H_err, color=DESIGN_COLORS[k % len(DESIGN_COLORS)], label=label)
    if normalize:
        for level in levels:
            ax.axhline(level, color="gray", ls=":", lw=1, label=f"level {level:g}")
    first = _items(results)[0][1]
    energy = _label(first, "H̃(t)", "energy")
    ylabel = "H̃(t) / H̃(0)  (log scale)" if normalize else f"{energy} (log scale)"
    ax.set(xlabel=_label(first, "time t", "t"), ylabel=ylabel, title="estimation-error energy")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


# ----------------------------------------------------------------------------- deflection
def _field(result: Any, which: str) -> np.ndarray:
    if which not in _FIELDS:
        raise NumericError(f"unknown field {which!r}; expected one of {', '.join(_FIELDS)}")
    w = _require(result, "w", "the model has no displacement (see the model's [displacement])")
    if which == "w":
        return w
    w_hat = _require(result, "w_hat", "simulate with sensors and a gain to get the estimate")
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
    t = _require(result, "t", "no time grid")
    z = _require(result, "z_w", "the deflection was not sampled")
    fig, ax = _axes(ax, figsize=(6, 3.6))
    scale = float(vmax) if vmax is not None else float(np.max(np.abs(data))) or 1.0
    mesh = ax.pcolormesh(
        t, z, data.T, shading="nearest", cmap=cmap or "RdBu_r", vmin=-scale, vmax=scale
    )
    mesh.set_label(_FIELDS[which][1])
    ax.set(
        xlabel=_label(result, "time t", "t"),
        ylabel=_label(result, "position z", "z"),
        title=_FIELDS[which][1],
    )
    if colorbar:
        fig.colorbar(mesh, ax=ax, label=_label(result, _FIELDS[which][0], "displacement"))
    return fig


def plot_tip(result: Any, ax: Axes | None = None) -> Figure:
    r"""End-tip position :math:`w(b, t)` (solid blue) and its estimate (dashed orange).

    The paper's Fig. 2 overlay: the estimate should superpose the true position once
    the observer has converged.

    Returns
    -------
    Figure
    """
    t = _require(result, "t", "no time grid")
    w = _require(result, "w", "the model has no displacement")
    fig, ax = _axes(ax, figsize=(6, 3.5))
    where = _tip_label(result)
    ax.plot(t, w[:, -1], color=PLANT_COLOR, ls="-", label=f"w({where}, t) (plant)")
    if getattr(result, "w_hat", None) is not None:
        w_hat = np.asarray(result.w_hat, dtype=float)
        ax.plot(t, w_hat[:, -1], color=OBSERVER_COLOR, ls="--", label=f"ŵ({where}, t) (observer)")
    ax.set(
        xlabel=_label(result, "time t", "t"),
        ylabel=_label(result, "end-tip deflection", "displacement"),
        title="end-tip position",
    )
    ax.grid(True, alpha=0.3)
    ax.legend()
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
    fig, ax = _axes(ax, figsize=(6, 4))
    where, res = "b", None
    for k, (label, res) in enumerate(_items(results)):
        t = _require(res, "t", "no time grid")
        err = _field(res, "error")[:, -1]
        where = _tip_label(res)
        ax.plot(t, err, color=DESIGN_COLORS[k % len(DESIGN_COLORS)], label=label)
    ax.axhline(0.0, color="black", lw=0.6)
    ax.set(
        xlabel=_label(res, "time t", "t"),
        ylabel=_label(res, f"w − ŵ at {where}", "displacement"),
        title="end-tip estimation error",
    )
    ax.grid(True, alpha=0.3)
    ax.legend()
    return fig


# ----------------------------------------------------------------------------- spectra
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
    :func:`phdesign.numeric.spectrum.match_resolved`) are filled blue dots; unresolved
    ones are grey crosses: they are artefacts of the discretization and the spectral
    abscissa ignores them.

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
    mask = np.ones(lam.size, dtype=bool)
    if resolved is not None:
        r = np.asarray(resolved)
        if r.dtype == bool:
            if r.size != lam.size:
                raise NumericError(
                    f"resolved mask has {r.size} entries; expected {lam.size} (one per eigenvalue)"
                )
            mask = r.ravel()
        else:
            mask = np.zeros(lam.size, dtype=bool)
            mask[r.astype(int).ravel()] = True
    fig, ax = _axes(ax, figsize=(6, 4.5))
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
    ax.legend(loc="best")
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
    fig, ax = _axes(ax, figsize=(6, 4))
    if exact is not None:
        fine = np.linspace(float(np.min(k)), float(np.max(k)), 801)
        with np.errstate(divide="ignore", invalid="ignore"):
            values = np.asarray(exact(fine), dtype=float)
        ax.plot(fine, np.where(np.isfinite(values), values, np.nan), "k-", lw=1, label=exact_label)
    ax.plot(k, alpha, ls="none", marker="o", color="tab:blue", label="computed (resolved)")
    ax.set(xlabel=xlabel, ylabel=ABSCISSA_LABEL, title="spectral abscissa against gain")
    ax.grid(True, alpha=0.3)
    ax.legend()
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
    fig, ax = _axes(ax, figsize=(6.2, 4.8))
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
        ax.legend(loc="lower left")
    if log:
        ax.set_xscale("log")
        ax.set_yscale("log")
    ax.set(xlabel="gain l1", ylabel="gain l2", title="spectral abscissa over (l1, l2)")
    return fig


# ----------------------------------------------------------------------------- CLI entry
def check_plot_path(path: str | os.PathLike[str], force: bool = False) -> str:
    """Check an output image path before any work is done; return its format.

    The format is the file suffix (``png``, ``pdf``, ``svg``, ...).

    Raises
    ------
    OutputFileError
        The file exists and ``force`` is false, or the suffix is not an image format
        matplotlib can write.

    Examples
    --------
    >>> check_plot_path("beam.PNG")
    'png'
    """
    from matplotlib.backend_bases import FigureCanvasBase

    target = Path(path)
    fmt = target.suffix.lstrip(".").lower()
    supported = FigureCanvasBase.get_supported_filetypes()
    if fmt not in supported:
        raise OutputFileError(
            f"plot file {str(target)!r}: unknown image format {fmt!r}; expected a suffix "
            f"among {', '.join('.' + s for s in sorted(supported))}"
        )
    check_output_path(target, force)
    return fmt


def plot_simulation(
    result: Any,
    path: str | os.PathLike[str] | None = None,
    *,
    force: bool = False,
    title: str | None = None,
) -> Figure:
    r"""Summary figure of one simulation, written to ``path`` (used by ``simulate --plot``).

    Top row: :func:`plot_hamiltonians`.  When the model has a displacement, bottom row:
    the end-tip overlay (:func:`plot_tip`) and the heat map of the estimation error
    :math:`w - \hat w` (of :math:`w` without an observer).

    Parameters
    ----------
    result : SimulationResult
    path : path-like, optional
        Output file; its suffix picks the format (``.png``, ``.pdf``, ``.svg``, ...).
        Written atomically.
    force : bool
        Overwrite an existing file.
    title : str, optional
        Figure title.

    Returns
    -------
    Figure

    Raises
    ------
    OutputFileError
        The file exists (without ``force``), its format is unknown, or it cannot be written.
    """
    fmt = None if path is None else check_plot_path(path, force=force)
    has_w = getattr(result, "w", None) is not None
    fig, axes = new_figure(2 if has_w else 1, 2, figsize=(11, 7.5 if has_w else 3.8))
    top = axes[0] if has_w else axes
    plot_hamiltonians(result, top)
    if has_w:
        plot_tip(result, axes[1, 0])
        which = "error" if getattr(result, "w_hat", None) is not None else "w"
        plot_deflection(result, which, axes[1, 1])
    if title:
        fig.suptitle(title)
    if path is not None:
        from phdesign.io import atomic_write

        buffer = io.BytesIO()
        fig.savefig(buffer, format=fmt, dpi=110)
        atomic_write(path, buffer.getvalue(), force=force)
    return fig
