"""Arguments and output helpers shared by the commands."""

from __future__ import annotations

import argparse
import gc
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from phdesign.core.checks import positive_int, positive_number
from phdesign.core.defaults import current
from phdesign.core.errors import NumericError, ParameterError
from phdesign.core.progress import Display, erase, reporting

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.model import BCPHS

__all__ = [
    "add_discretization_arguments",
    "add_json_argument",
    "add_method_argument",
    "add_model_argument",
    "add_quiet_argument",
    "add_simulation_outputs",
    "check_finite_series",
    "check_positive",
    "comma_numbers",
    "emit",
    "emit_json",
    "intensities",
    "load_model",
    "non_negative_int",
    "parse_parameter_overrides",
    "pause_collection",
    "printable",
    "progress_display",
    "result_text",
    "resume_collection",
    "run_outputs",
    "simulation_text",
    "split_items",
    "warn",
    "write_output",
]


def add_model_argument(parser: argparse.ArgumentParser) -> None:
    """Add MODEL (built-in name or TOML path) and the repeatable ``--param name=value``."""
    parser.add_argument("model", metavar="MODEL", help="built-in model name or TOML file path")
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="override a parameter's default value (repeatable)",
    )


def add_method_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--method``: the registered discretizations (the table of defaults in force)."""
    table = current()
    methods = "; ".join(f"{m.name}: {m.summary}" for m in table.methods.values())
    parser.add_argument(
        "--method",
        choices=table.method_names,
        default=table.method,
        help=f"discretization ({methods}); default: %(default)s",
    )


def add_json_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--json``: print machine-readable JSON instead of a table."""
    parser.add_argument(
        "--json",
        action="store_true",
        help="print JSON instead of text (keys: see the command-line reference)",
    )


def add_quiet_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--quiet``: no progress line (:func:`progress_display`)."""
    parser.add_argument(
        "--quiet",
        action="store_true",
        help="no progress line on stderr (a terminal shows one once a run lasts "
        f"{current().progress.delay:g} s; never with --json)",
    )


@contextmanager
def progress_display(args: argparse.Namespace) -> Iterator[None]:
    """Show the stages of the run inside the block on stderr (:mod:`phdesign.core.progress`).

    For the commands that have ``--quiet``, unless it or ``--json`` is given; the line
    shows on a terminal only, once the run has lasted the table's delay, and is erased
    before anything else is printed (:func:`emit`, :func:`warn`) and when the block ends.
    """
    if not hasattr(args, "quiet") or args.quiet or getattr(args, "json", False):
        yield
        return
    display = Display()
    try:
        with reporting(display):
            yield
    finally:
        display.erase()


def add_discretization_arguments(
    parser: argparse.ArgumentParser, resolution_default: str | None = None
) -> None:
    """Add ``--method`` (:func:`add_method_argument`) and, unless ``None``, ``--resolution``.

    ``resolution_default`` says what the command uses without ``--resolution`` (empty: not
    stated).
    """
    add_method_argument(parser)
    if resolution_default is not None:
        hint = f" ({resolution_default})" if resolution_default else ""
        parser.add_argument(
            "--resolution", type=int, metavar="N", help=f"degree / nodes per group{hint}"
        )


def parse_parameter_overrides(items: list[str]) -> dict[str, str]:
    """Split ``name=value`` items; values stay text and are checked by the model."""
    overrides: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise ParameterError(f"--param expects NAME=VALUE; found {item!r}")
        if name in overrides:
            raise ParameterError(f"--param {name} is given twice")
        overrides[name] = value
    return overrides


def load_model(args: argparse.Namespace) -> BCPHS:
    """Load MODEL (a built-in name, else a TOML file, :func:`phdesign.load`); apply ``--param``.

    The start-up of a run ends here: the garbage collector paused by :func:`pause_collection`
    resumes.
    """
    from phdesign.models import load

    overrides = parse_parameter_overrides(getattr(args, "param", []))
    try:
        return load(args.model, overrides or None)
    finally:
        resume_collection()


#: Whether :func:`pause_collection` paused the garbage collector (and so may resume it).
_PAUSED = [False]


def pause_collection() -> None:
    """Pause Python's cyclic garbage collector for the start-up of a command-line run.

    The start-up (sympy's import, phdesign's modules, the model) creates about 6e4 objects
    that live as long as the process; every collection meanwhile scans them and finds
    nothing to free.  Paused, ``import sympy`` alone takes about 0.89x its CPU seconds
    (benchmarks/cli_startup.py).  :func:`resume_collection` ends the pause; the library
    (:func:`phdesign.cli.main` called in a process of one's own) never pauses.
    """
    if gc.isenabled():
        gc.disable()
        _PAUSED[0] = True


def resume_collection() -> None:
    """End :func:`pause_collection`'s pause: the start-up's objects are frozen, then collect.

    Frozen (:func:`gc.freeze`), the objects made so far are left out of later collections,
    which therefore cost what the run itself allocates.  Nothing happens without a pause.
    """
    if _PAUSED[0]:
        _PAUSED[0] = False
        gc.freeze()
        gc.enable()


#: Characters that would act on a terminal (escape sequences, bidirectional overrides):
#: printed escaped, so a model named "\x1b[2J" cannot clear the screen.
_CONTROL = {
    c: f"\\x{c:02x}" if c < 0x100 else f"\\u{c:04x}"
    for c in (
        *range(0x20),
        0x7F,
        *range(0x80, 0xA0),
        *range(0x202A, 0x202F),
        *range(0x2066, 0x206A),
    )
    if chr(c) not in "\n\t"
}


def printable(text: str) -> str:
    r"""Return ``text`` with terminal control characters escaped (``\x1b`` for ESC).

    Examples
    --------
    >>> printable("beam\x1b[2J")
    'beam\\x1b[2J'
    """
    return text.translate(_CONTROL)


def emit(text: str) -> None:
    """Print ``text`` on stdout (terminal control characters escaped), the progress line erased."""
    erase()
    text = printable(text)
    sys.stdout.write(text if text.endswith("\n") else text + "\n")


def warn(message: str) -> None:
    """Print one ``phdesign: warning: ...`` line on stderr, in the command's option names."""
    from phdesign.cli.messages import translated

    erase()
    text = printable(" ".join(translated(message).split()))
    print(f"phdesign: warning: {text}", file=sys.stderr)


def note(message: str) -> None:
    """Print one ``phdesign: ...`` line on stderr (``sweep: ...``), in the command's options."""
    from phdesign.cli.messages import translated

    text = printable(" ".join(translated(message, leading=False).split()))
    print(f"phdesign: {text}", file=sys.stderr)


def emit_json(value: Any) -> None:
    """Print ``value`` as strict JSON (phdesign's one JSON writer); sympy values are text."""
    from phdesign.io import dumps_json

    emit(dumps_json(value))


def comma_numbers(text: str, flag: str) -> list[float]:
    """Return the comma-separated numbers of option ``flag`` (``0.01,0.04``), or refuse."""
    values = []
    for part in str(text).split(","):
        try:
            values.append(float(part))
        except ValueError:
            raise NumericError(
                f"{flag}: expected comma-separated numbers like 0.01,0.04; found {part.strip()!r}"
            ) from None
    return values


def intensities(text: str | None, flag: str) -> list[float] | None:
    """Return the numbers of a noise intensity option (the design checks count and signs)."""
    return None if text is None else comma_numbers(text, flag)


def check_positive(option: str, value: float | int | None) -> None:
    """Refuse a given option value that is not a positive integer or finite number.

    ``None`` (not given) is accepted; the checks are the library's
    (:func:`~phdesign.core.checks.positive_int`, :func:`~phdesign.core.checks.positive_number`).
    """
    if isinstance(value, int):
        positive_int(value, option)
    elif value is not None:
        positive_number(value, option)


def result_text(result: Any) -> str:
    """Return the text a result prints itself, the arguments it names as options."""
    from phdesign.cli.messages import translated

    return translated(str(result), leading=False)


def emit_result(args: argparse.Namespace, result: Any, model: str | None = None) -> int:
    """Print a result as JSON with ``--json``, else the text it prints itself; return 0.

    The JSON is ``result.to_dict()``, after a ``"model"`` key when ``model`` is given.
    """
    if getattr(args, "json", False):
        emit_json({**({} if model is None else {"model": model}), **result.to_dict()})
    else:
        emit(result_text(result))
    return 0


def write_output(path: str, text: str | bytes, force: bool) -> None:
    """Write an output file atomically, refusing to overwrite unless ``force``."""
    from phdesign.io import atomic_write

    atomic_write(path, text, force=force)


def split_items(text: str) -> list[str]:
    """Split a comma-separated option value (``--at 0.5,1``) into its stripped items."""
    return [item.strip() for item in str(text).split(",")]


def non_negative_int(text: str) -> int:
    """Read an integer >= 0 for argparse (a usage error names the option)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer; found {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a non-negative integer; found {value}")
    return value


@contextmanager
def run_outputs(args: argparse.Namespace) -> Iterator[Callable[[str, Any], None]]:
    """Reserve ``-o`` and ``--plot`` before a run; yield ``commit(text, result)``.

    Every output is checked before the (possibly long) work and written together at the
    end (:class:`phdesign.core.files.OutputFiles`): on any failure or interrupt none is left,
    and no temporary file.  ``commit`` stages the text (or prints it without ``-o``) and
    ``result.plot()``'s figure, then writes them; warnings raised during the block (e.g.
    matplotlib's) are printed afterwards as ``phdesign: warning:`` lines.
    """
    import warnings

    from phdesign.core.files import OutputFiles

    with OutputFiles(args.force) as out, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fmt = ""
        output = getattr(args, "output", None)  # noise has a --plot only
        if output:
            out.add(output)
        if args.plot:
            from phdesign.plots import check_plot_path

            fmt = check_plot_path(args.plot, args.force)
            out.add(args.plot)
        printed: list[str] = []

        def commit(text: str, result: Any) -> None:
            if args.plot:
                from phdesign.plots import figure_bytes

                out.stage(args.plot, figure_bytes(result.plot(), fmt))
            if output:
                out.stage(output, text)
            out.commit()
            if not output:
                printed.append(text)

        yield commit
    for text in printed:
        emit(text)
    for warning in dict.fromkeys(str(w.message) for w in caught):
        warn(warning)


def check_finite_series(result: Any) -> None:
    """Refuse a simulation whose series overflowed (NaN or infinity), naming the first one.

    Large initial states, tiny parameters or huge gains can overflow double precision;
    such a run is an error, never rows of NaN.
    """
    import numpy as np

    for name in ("H", "H_hat", "H_err", "y", "y_hat", "w", "w_hat", "at_values", "at_values_hat"):
        series = getattr(result, name, None)
        if series is None:
            continue
        values = np.asarray(series, dtype=float)
        bad = ~np.isfinite(values.reshape(values.shape[0], -1)).all(axis=1)
        if bad.any():
            first = float(result.t[int(np.argmax(bad))])
            raise NumericError(
                f"the simulation overflowed: {name} is not finite from t = {first:.6g} on; "
                "the initial state, parameters or gain are too large for double precision"
            )


def simulation_text(args: argparse.Namespace, model: str, result: Any) -> str:
    """Return the text a simulation prints: strict JSON with ``--json``, else its CSV."""
    if args.json:
        from phdesign.io import dumps_json

        return dumps_json({"model": model, **result.to_dict()}, indent=None)
    return str(result)


def add_simulation_outputs(sim: argparse.ArgumentParser) -> None:
    """Add what a simulation writes (``simulate``, ``loop simulate``).

    CSV or JSON, the point outputs ``--at``, the output file and the figure.
    """
    fmt = sim.add_mutually_exclusive_group()
    fmt.add_argument("--csv", action="store_true", help="CSV output (the default)")
    fmt.add_argument(
        "--json", action="store_true", help="JSON output (keys: see the command-line reference)"
    )
    sim.add_argument(
        "--at",
        metavar="Z,..",
        help="also report the displacement at these points, e.g. 0.5,1, or named fields "
        "of the model at a point, e.g. rotation(1) (CSV columns rotation(1), rotation_hat(1))",
    )
    sim.add_argument("--output", "-o", metavar="FILE", help="write to FILE instead of stdout")
    sim.add_argument("--plot", metavar="FILE", help="also draw a summary figure to FILE")
    sim.add_argument("--force", action="store_true", help="overwrite existing files")
