"""Pictures of a sweep result, read from its Dataset: gain maps and parameter studies.

:func:`plot_sweep` looks at the axes that have more than one value (after ``select``):

* one axis: the figure against it (a parameter study, a gain sweep), one curve per
  sensor set when the sensor sets are a second axis;
* two numeric axes: a map (a gain map over (l1, l2), a map over (d, l)); text figures
  (the verdict) as categories;
* a third axis of at most :data:`MAX_PANELS` values: one panel per value.

Points whose spectrum did not converge (``converged`` false) are marked on every picture,
never drawn as if they had.  The Dataset is read through its coordinates, attributes and
variables only (no import of :mod:`phdesign.sweep`); matplotlib is imported only when
drawing.

Examples
--------
>>> import numpy as np, xarray as xr
>>> ds = xr.Dataset(
...     {"spectral_abscissa": (("l1", "l2"), -np.ones((3, 2))),
...      "converged": (("l1", "l2"), np.array([[True, True], [True, False], [True, True]]))},
...     coords={"l1": [0.1, 0.2, 0.3], "l2": [0.1, 1.0]},
... )
>>> fig = plot_sweep(ds)
>>> fig.axes[0].get_xlabel(), fig.axes[0].get_legend().get_texts()[0].get_text()
('l1', 'not converged (1 point)')
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.core.errors import SweepError
from phdesign.plots._figures import drawing

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["MAX_PANELS", "plot_sweep", "select_points"]

MAX_PANELS = 12
_VERDICT_COLORS = {"exponential": "tab:green", "asymptotic": "gold", "inconclusive": "0.6"}


def select_points(dataset: Any, select: Mapping[str, Any] | None) -> Any:
    """``dataset`` at the given axis values (nearest value for numeric axes).

    Raises
    ------
    SweepError
        An axis the sweep does not have, or a sensor set that is not on the axis.
    """
    if not select:
        return dataset
    picked = dataset
    for name, value in select.items():
        if name not in dataset.coords:
            axes = ", ".join(dataset[next(iter(dataset.data_vars))].dims)
            raise SweepError(f"select: the sweep has no axis {name!r}; its axes: {axes}")
        values = dataset[name].values
        if values.dtype.kind in "US":
            if str(value) not in values.tolist():
                raise SweepError(
                    f"select: {name} = {value!r} is not on the axis; expected one of "
                    f"{', '.join(values.tolist())}"
                )
            picked = picked.sel({name: str(value)})
        else:
            try:
                number = float(value)
            except (TypeError, ValueError):
                number = math.nan
            if not math.isfinite(number):  # NaN has no nearest value: a KeyError in xarray
                raise SweepError(f"select: {name} expects a finite number; found {value!r}")
            picked = picked.sel({name: number}, method="nearest")
    return picked


def _varying(data: Any) -> list[str]:
    return [d for d in data.dims if data.sizes[d] > 1]


def _is_log(dataset: Any, dim: str) -> bool:
    return bool(dataset[dim].attrs.get("scale") == "log")


def _label(dataset: Any, name: str) -> str:
    units = dataset[name].attrs.get("units")
    return f"{name} [{units}]" if units else name


def _figure_label(dataset: Any, name: str) -> str:
    """Return what a figure is, in words, with its unit: ``spectral abscissa α [1/s]``.

    The words are the variable's ``long_name`` up to its first parenthesis (the figure's
    name when it has none).
    """
    words = str(dataset[name].attrs.get("long_name") or name).split(" (")[0].strip() or name
    units = dataset[name].attrs.get("units")
    return f"{words} [{units}]" if units else words


def _unconverged(dataset: Any, figure: str) -> Any:
    """Return the ``converged`` flags when the figure depends on them, else ``None``."""
    if "converged" not in dataset.data_vars or figure == "converged":
        return None
    return dataset["converged"]


def _mark_unconverged(ax: Axes, x: np.ndarray, y: np.ndarray) -> None:
    """Red crosses on the points whose spectrum did not converge, counted in the legend."""
    count = len(x)
    label = f"not converged ({count} point{'s' if count > 1 else ''})"
    ax.plot(x, y, ls="none", marker="x", color="red", ms=6, label=label)


def _draw_map(fig: Figure, ax: Axes, data: Any, flags: Any, dims: list[str], dataset: Any) -> None:
    x, y = dims  # the first axis across, as in a gain map over (l1, l2)
    values = data.transpose(y, x).values
    xs, ys = dataset[x].values, dataset[y].values
    if values.dtype.kind in "US":
        categories = [c for c in _VERDICT_COLORS if c in values] + sorted(
            set(values.ravel().tolist()) - set(_VERDICT_COLORS) - {""}
        )
        from matplotlib.colors import ListedColormap

        codes = np.full(values.shape, np.nan)
        for k, c in enumerate(categories):
            codes[values == c] = k
        colors = [_VERDICT_COLORS.get(c, f"C{k}") for k, c in enumerate(categories)]
        ax.pcolormesh(
            xs,
            ys,
            np.ma.masked_invalid(codes),
            shading="nearest",
            cmap=ListedColormap(colors or ["white"]),
            vmin=-0.5,
            vmax=max(len(categories), 1) - 0.5,
        )
        from matplotlib.patches import Patch

        ax.legend(
            handles=[Patch(color=col, label=c) for c, col in zip(categories, colors, strict=True)],
            loc="upper left",
            fontsize="small",
        )
    else:
        from matplotlib import colormaps

        cmap = colormaps["viridis"].with_extremes(bad="0.8")
        mesh = ax.pcolormesh(
            xs, ys, np.ma.masked_invalid(values.astype(float)), shading="nearest", cmap=cmap
        )
        fig.colorbar(mesh, ax=ax, label=_figure_label(dataset, data.name))
    if flags is not None:
        bad = ~flags.transpose(y, x).values.astype(bool)
        if bad.any():
            jj, ii = np.nonzero(bad)
            _mark_unconverged(ax, xs[ii], ys[jj])
            ax.legend(loc="lower left", fontsize="small")
    ax.set(xlabel=_label(dataset, x), ylabel=_label(dataset, y))
    if _is_log(dataset, x):
        ax.set_xscale("log")
    if _is_log(dataset, y):
        ax.set_yscale("log")


def _draw_curves(ax: Axes, data: Any, flags: Any, dims: list[str], dataset: Any) -> None:
    x = next((d for d in dims if dataset[d].dtype.kind not in "US"), dims[0])
    groups = [d for d in dims if d != x]
    series: list[tuple[str | None, Any, Any]] = [(None, data, flags)]
    if groups:
        g = groups[0]
        series = [
            (str(v), data.sel({g: v}), None if flags is None else flags.sel({g: v}))
            for v in dataset[g].values
        ]
    xs = dataset[x].values
    for label, curve, flag in series:
        values = curve.values
        text = None if label is None else f"{groups[0]} {label}"
        if values.dtype.kind in "US" or values.dtype == bool:
            ax.step(xs, values.astype(str), where="mid", label=text)
            continue
        ax.plot(xs, values.astype(float), marker="o", ms=3, label=text)
        if flag is not None:
            bad = ~flag.values.astype(bool)
            if bad.any():
                _mark_unconverged(ax, xs[bad], values[bad])
    if _is_log(dataset, x):
        ax.set_xscale("log")
    ax.set(xlabel=_label(dataset, x), ylabel=_figure_label(dataset, data.name))
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")


def _draw_bars(ax: Axes, data: Any, dim: str, dataset: Any) -> None:
    """One bar per category (a sensor-set study): its height κ* (or the figure), its verdict.

    Categories have no order between them, so no line joins them.  A bar is coloured by
    the verdict when the sweep has one and labelled with the verdict and the value; a text
    figure (the verdict itself) is drawn as κ* when the sweep has it.
    """
    from matplotlib.patches import Patch

    names = [str(v) for v in dataset[dim].values]
    height_name = data.name if data.dtype.kind not in "US" else "kappa"
    heights = (
        np.asarray(dataset[height_name].values, dtype=float)
        if height_name in dataset.data_vars
        else np.ones(len(names))
    )
    verdicts = (
        [str(v) for v in dataset["verdict"].values]
        if "verdict" in dataset.data_vars
        else [""] * len(names)
    )
    colors = [_VERDICT_COLORS.get(v, "tab:blue") for v in verdicts]
    shown = np.where(np.isfinite(heights), heights, 0.0)
    bars = ax.bar(range(len(names)), shown, color=colors, edgecolor="black", lw=0.6)
    for bar, value, verdict in zip(bars, heights, verdicts, strict=True):
        number = "κ* = none" if height_name == "kappa" else "none"
        if np.isfinite(value):
            number = f"κ* = {value:.3g}" if height_name == "kappa" else f"{value:.4g}"
        text = "\n".join(t for t in (verdict, number) if t)
        ax.annotate(
            text,
            (bar.get_x() + bar.get_width() / 2, bar.get_height()),
            xytext=(0, 3),
            textcoords="offset points",
            ha="center",
            va="bottom",
            fontsize="small",
        )
    ax.set_xticks(range(len(names)), [f"{dim} {n}" for n in names])
    ylabel = _figure_label(dataset, height_name) if height_name in dataset.data_vars else ""
    ax.set(xlabel=_label(dataset, dim), ylabel=ylabel)
    top = float(np.max(shown, initial=0.0))
    ax.set_ylim(0, 1.3 * top if top > 0 else 1.0)
    ax.grid(True, axis="y", alpha=0.3)
    present = [v for v in _VERDICT_COLORS if v in verdicts]
    if present:
        ax.legend(
            handles=[Patch(color=_VERDICT_COLORS[v], label=v) for v in present],
            loc="upper left",
            fontsize="small",
        )


def _draw(fig: Figure, ax: Axes, data: Any, flags: Any, dataset: Any) -> None:
    dims = _varying(data)
    numeric = [d for d in dims if dataset[d].dtype.kind not in "US"]
    if len(dims) == 2 and len(numeric) == 2:
        _draw_map(fig, ax, data, flags, dims, dataset)
    elif len(dims) == 1 and not numeric:
        _draw_bars(ax, data, dims[0], dataset)
    else:
        _draw_curves(ax, data, flags, dims, dataset)


def plot_sweep(
    dataset: Any,
    figure: str | None = None,
    *,
    select: Mapping[str, Any] | None = None,
    title: str | None = None,
) -> Figure:
    """Draw one figure of a sweep (see the module docstring).

    Parameters
    ----------
    dataset : xarray.Dataset
        A sweep result (:func:`phdesign.sweep.sweep`, :func:`phdesign.sweep.open_sweep`).
    figure : str, optional
        The variable to draw (default: the job's first, e.g. ``spectral_abscissa``).
    select : mapping, optional
        Fix axes to values first, e.g. ``{"d": 0.2}`` (nearest value) or
        ``{"sensors": "3,4"}``.
    title : str, optional
        Default: the figure, the job, the model and the fixed sensors and gain.

    Returns
    -------
    Figure

    Raises
    ------
    SweepError
        An unknown figure or axis, a single point, or more than three varying axes (or a
        third with more than :data:`MAX_PANELS` values): select values first.
    """
    names = [str(n) for n in dataset.data_vars]
    name = figure or (names[0] if names else "")
    if name not in names:
        raise SweepError(f"the sweep has no figure {name!r}; its figures: {', '.join(names)}")
    data = select_points(dataset, select)
    dims = _varying(data[name])
    if not dims:
        raise SweepError("one point is left to plot; select fewer axes")
    panels = _panels(data, dims)
    columns = min(len(panels), 3)
    rows = math.ceil(len(panels) / columns)
    frame = drawing(
        title=_title(dataset, name) if title is None else title,
        nrows=rows,
        ncols=columns,
        figsize=(6.2 * columns, 4.6 * rows),
    )
    with frame as (fig, grid):
        axes = np.asarray(grid, dtype=object).reshape(-1)
        for k, value in enumerate(panels):
            ax = axes[k]
            part = data if value is None else data.sel({dims[0]: value})
            _draw(fig, ax, part[name], _unconverged(part, name), part)
            if value is not None:
                ax.set_title(f"{dims[0]} = {value}", fontsize="medium")
        for ax in axes[len(panels) :]:
            ax.set_visible(False)
    return fig


def _panels(data: Any, dims: list[str]) -> list[Any]:
    """Return the values of the axis drawn one panel each (``[None]``: one panel)."""
    if len(dims) >= 3 or (len(dims) == 2 and all(data[d].dtype.kind in "US" for d in dims)):
        outer = dims[0]
        if len(dims) > 3 or data.sizes[outer] > MAX_PANELS:
            raise SweepError(
                f"{len(dims)} axes vary ({', '.join(dims)}); select values of "
                f"{dims[0]} first (at most {MAX_PANELS} panels), e.g. select={{'{outer}': ...}}"
            )
        return list(data[outer].values)
    return [None]


def _title(dataset: Any, name: str) -> str:
    """Return the default title: the figure, the job, the model, the sensors and gain."""
    job, model = dataset.attrs.get("job", "sweep"), dataset.attrs.get("model", "?")
    title = f"{name.replace('_', ' ')}: {job} on {model}"
    if dataset.attrs.get("sensors"):
        title += f", sensors {dataset.attrs['sensors']}, gain {dataset.attrs.get('gain')}"
    return title
