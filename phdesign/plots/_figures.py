"""Figures, axes, titles, files, labels and legends shared by the plots (matplotlib lazily).

One place makes the axes of every figure and writes it (py-pde's ``plot_on_axes``):
:func:`drawing` checks the output path before anything is drawn, makes the axes (or
draws on the caller's), titles the figure literally (:func:`literal`: a model's name
never becomes mathtext) and writes the file atomically (:func:`save_figure`, the one
figure saver, whose bytes :func:`figure_bytes` gives a command that writes several
files together).

New figures are plain :class:`~matplotlib.figure.Figure` objects on an Agg canvas, never
pyplot's: no display, no global state, safe in scripts, servers and tests.  In a Jupyter
kernel a figure is shown when it is the value of a cell (or passed to ``display``), once:
pyplot does not manage it, so the inline backend does not show it a second time at the
end of the cell (this module registers the PNG formatter for figures when the kernel has
none).
"""

from __future__ import annotations

import io
import os
import sys
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.core.errors import NumericError, OutputFileError
from phdesign.core.files import atomic_write, check_output_path
from phdesign.symbolic.units import with_unit

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

RE_LABEL = "Re λ [1/s]"
IM_LABEL = "Im λ [rad/s]"
ABSCISSA_LABEL = "spectral abscissa α [1/s]"

#: The paper's colours: plant solid blue, observer dashed orange, error solid red.
PLANT_COLOR, OBSERVER_COLOR, ERROR_COLOR = "tab:blue", "tab:orange", "tab:red"
#: Design colours of the paper's Fig. 5 (yellow, orange, violet), then matplotlib's cycle.
DESIGN_COLORS = ("goldenrod", "tab:orange", "tab:purple", "tab:green", "tab:brown", "tab:cyan")

#: Units assumed for a result that states none (built by hand; the built-in models are SI).
#: A model's own ``[units]`` section, carried by ``SimulationResult.units``, wins; a
#: quantity the model leaves without a unit gets a plain label.
SI_UNITS = {"t": "s", "z": "m", "energy": "J", "displacement": "m"}


def eigenvalue_labels(time_unit: str | None = None) -> tuple[str, str]:
    """Return the axis labels of the complex plane in the model's time unit (SI: s).

    Examples
    --------
    >>> eigenvalue_labels("ms")
    ('Re λ [1/ms]', 'Im λ [rad/ms]')
    """
    unit = time_unit or SI_UNITS["t"]
    return f"Re λ [1/{unit}]", f"Im λ [rad/{unit}]"


def frequency_label(time_unit: str | None = None) -> str:
    """Return the label of a frequency axis in the model's time unit (SI: s).

    Examples
    --------
    >>> frequency_label("ms"), frequency_label()
    ('frequency ω [rad/ms]', 'frequency ω [rad/s]')
    """
    unit = time_unit or SI_UNITS["t"]
    return f"frequency ω [rad/{unit}]"


def literal(text: str) -> str:
    r"""Return ``text`` as a figure shows it literally: never as matplotlib mathtext.

    Text from a model (its name, in every title that names the model) may hold ``$``:
    an even number of them makes matplotlib parse mathtext, and ``$\frac{1}{$`` then
    fails when the figure is drawn. An escaped dollar is drawn as a dollar.

    Examples
    --------
    >>> literal("$\\frac{1}{$ beam")
    '\\$\\frac{1}{\\$ beam'
    """
    return text.replace("$", r"\$")


def unit_label(result: Any, text: str, quantity: str) -> str:
    """``text [unit]`` with the unit of ``quantity`` that ``result``'s model states."""
    units = getattr(result, "units", None)
    return with_unit(text, SI_UNITS if units is None else units, quantity)


def _jupyter_shell() -> Any:
    """Return the Jupyter kernel's shell, or ``None`` (not merely IPython imported)."""
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    return shell if type(shell).__name__ == "ZMQInteractiveShell" else None


def _register_png_formatter(shell: Any) -> None:
    """Let the kernel show a figure that is a cell's value (what ``%matplotlib inline`` does)."""
    from matplotlib.figure import Figure

    formatter = shell.display_formatter.formatters["image/png"]
    try:
        formatter.lookup_by_type(Figure)
    except KeyError:
        from IPython.core.pylabtools import print_figure

        formatter.for_type(Figure, lambda fig: print_figure(fig, "png"))


def new_figure(nrows: int = 1, ncols: int = 1, **kwargs: Any) -> tuple[Figure, Any]:
    """Return ``(fig, axes)`` as ``pyplot.subplots`` does, to compose panels.

    The figure lives on an Agg canvas (no display, no pyplot state); in Jupyter it shows
    as the value of a cell.  Keyword arguments go to the figure (``figsize``, ``dpi``); the
    layout is constrained.

    Examples
    --------
    >>> from phdesign.plots import plot_spectrum
    >>> fig, axes = new_figure(1, 2, figsize=(8, 3))
    >>> plot_spectrum(np.array([-1.0 + 1j]), ax=axes[0]) is fig
    True
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    shell = _jupyter_shell()
    if shell is not None:
        _register_png_formatter(shell)
    fig = Figure(layout="constrained", **kwargs)
    FigureCanvasAgg(fig)  # explicit Agg: never needs a display
    axes = fig.subplots(nrows, ncols, squeeze=True)
    return fig, axes


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


#: Resolution of a written raster figure (dots per inch).
DPI = 110


def figure_bytes(fig: Figure, fmt: str) -> bytes:
    """Return the figure as a file of format ``fmt`` (``png``, ``pdf``, ``svg``, ...)."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format=fmt, dpi=DPI)
    return buffer.getvalue()


def save_figure(fig: Figure, path: str | os.PathLike[str], force: bool = False) -> None:
    """Write ``fig`` to ``path`` atomically, its suffix the format (``force`` to overwrite)."""
    atomic_write(path, figure_bytes(fig, check_plot_path(path, force=force)), force=force)


#: Font size of a figure's title (matplotlib's ``large``, at its default 10 pt).
_SUPTITLE_POINTS = 12.0
#: Average advance of a character, in units of the font size (DejaVu Sans, mixed text).
_CHAR_WIDTH = 0.62


def wrapped(title: str, width_inches: float, points: float) -> str:
    """Break ``title`` into lines that fit a figure ``width_inches`` wide (no line cut off).

    Examples
    --------
    >>> print(wrapped("spectral abscissa α: spectrum on wave, sensors 1,2", 2.5, 12))
    spectral abscissa α:
    spectrum on wave,
    sensors 1,2
    """
    import textwrap

    columns = max(int(0.94 * width_inches * 72 / (_CHAR_WIDTH * points)), 12)
    lines = (textwrap.fill(line, columns, break_on_hyphens=False) for line in title.split("\n"))
    return "\n".join(lines)


@contextmanager
def drawing(
    path: str | os.PathLike[str] | None = None,
    *,
    force: bool = False,
    title: str | None = None,
    title_size: float | None = None,
    ax: Axes | None = None,
    nrows: int = 1,
    ncols: int = 1,
    **figure: Any,
) -> Iterator[tuple[Figure, Any]]:
    r"""Yield ``(fig, axes)`` to draw on; then title the figure and write it to ``path``.

    The path is checked first (an existing file without ``force``, an unknown format:
    nothing is drawn); the axes are ``ax`` (on its figure) or new (:func:`new_figure` with
    ``nrows``, ``ncols`` and the figure's keywords); ``title`` is the figure's, drawn
    literally.

    Examples
    --------
    >>> with drawing(title="$beam$", figsize=(4, 3)) as (fig, ax):
    ...     _ = ax.plot([0, 1], [1, 0])
    >>> fig.get_suptitle()
    '\\$beam\\$'
    """
    if path is not None:
        check_plot_path(path, force=force)
    fig, axes = (figure_of(ax), ax) if ax is not None else new_figure(nrows, ncols, **figure)
    yield fig, axes
    if title:
        size = title_size if title_size is not None else _SUPTITLE_POINTS
        fig.suptitle(literal(wrapped(title, fig.get_figwidth(), size)), fontsize=size)
    if path is not None:
        save_figure(fig, path, force=force)


def figure_of(ax: Axes) -> Figure:
    """Return the top-level figure an Axes belongs to (through any subfigures)."""
    from matplotlib.figure import Figure

    fig: Any = ax.get_figure()
    while fig is not None and not isinstance(fig, Figure):
        fig = fig.get_figure()
    if fig is None:
        raise NumericError("the given Axes belongs to no figure")
    return fig


def axes_or_new(ax: Axes | None, **kwargs: Any) -> tuple[Figure, Axes]:
    """Return the figure of ``ax`` and ``ax``, or a new figure with one Axes."""
    if ax is not None:
        return figure_of(ax), ax
    fig, new = new_figure(**kwargs)
    return fig, new


def require(result: Any, name: str, why: str) -> np.ndarray:
    """Return the array ``result.name``; raise :class:`NumericError` saying why it is missing."""
    value = getattr(result, name, None)
    if value is None:
        raise NumericError(f"the simulation result has no {name!r}: {why}")
    return np.asarray(value, dtype=float)


def labelled_results(
    results: Mapping[str, Any] | Sequence[tuple[str, Any]],
) -> list[tuple[str, Any]]:
    """``(label, result)`` pairs from a mapping or a sequence; at least one."""
    items = list(results.items()) if isinstance(results, Mapping) else list(results)
    if not items:
        raise NumericError("expected at least one (label, simulation result) pair; found none")
    return [(str(label), res) for label, res in items]


def tip_label(result: Any) -> str:
    """Where the tip displacement is taken: ``z = 1``."""
    z = getattr(result, "z_w", None)
    return "z = b" if z is None or len(z) == 0 else f"z = {float(np.asarray(z)[-1]):g}"


def log_scale_if_positive(ax: Axes, *curves: Any) -> bool:
    """Put the y axis on a log scale when some value drawn is positive; else keep it linear.

    A run from rest has energies and errors that are exactly zero: a log scale of nothing
    positive is what makes matplotlib warn ("Data has no positive values"), so the panel
    stays linear instead and says so in its axis label.  Returns whether it is a log scale.
    """
    positive = any(bool(np.any(np.asarray(c, dtype=float) > 0)) for c in curves)
    ax.set_yscale("log" if positive else "linear")
    if not positive:
        ax.set_ylabel(f"{ax.get_ylabel().replace(', log scale', '')} (all zero: linear scale)")
    return positive


def plain_numbers(ax: Axes) -> None:
    """Tick labels without an offset (a conserved energy reads 0.25, not 1e-13 + 2.5e-1)."""
    formatter = ax.yaxis.get_major_formatter()
    if hasattr(formatter, "set_useOffset"):
        formatter.set_useOffset(False)


def legend_in_view(ax: Axes, *, outside: bool = False, **kwargs: Any) -> None:
    """Draw a legend listing only what is drawn inside the current view.

    A marker series none of whose points lie inside the axes limits is left out (an
    "unresolved" entry for eigenvalues far outside the window would list nothing drawn).
    ``outside`` puts the legend below the axes, where it covers no point.
    """
    (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
    handles, labels = [], []
    for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
        data = getattr(handle, "get_data", None)
        if data is not None and getattr(handle, "get_linestyle", str)() in (
            "None",
            "none",
            " ",
            "",
        ):
            x, y = (np.asarray(v, dtype=float) for v in data())
            if not np.any((x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)):
                continue
        handles.append(handle)
        labels.append(label)
    if not handles:
        return
    if outside:
        kwargs = {"loc": "upper center", "bbox_to_anchor": (0.5, -0.15), "ncols": 2, **kwargs}
    ax.legend(handles, labels, **kwargs)
