"""Command ``export`` (the observer for a controller) and the sampled-loop flags of ``simulate``.

Argument parsing and printing only: the observer comes from :meth:`phdesign.Observer.export`
(which checks the period, the sampler, the order against the verification plant and the
output points before any computation), the files from :meth:`SampledObserver.write`; the
output path and jinja2 for the rendered formats are checked first, so a bad command
writes nothing.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
from typing import Any

from phdesign.cli.common import (
    add_json_argument,
    add_model_argument,
    add_quiet_argument,
    check_positive,
    emit,
    emit_json,
    load_model,
    printable,
    result_text,
    split_items,
    warn,
)
from phdesign.cli.design_arguments import add_observer_arguments, observer_from_args
from phdesign.cli.messages import translated
from phdesign.core.checks import EXPORT_FORMATS, GAIN_DESIGNS, REDUCTIONS, SAMPLERS
from phdesign.core.defaults import current
from phdesign.core.errors import NumericError, ObserverError, OutputFileError, VerificationError

__all__ = ["add_sampling_arguments", "register", "sampling_options"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``export`` command."""
    ex = subparsers.add_parser(
        "export",
        help="the observer as a sampled-data system for a controller: JSON, C99, npz or "
        "python-control, verified against a high-resolution plant",
    )
    add_model_argument(ex)
    add_observer_arguments(ex)
    _add_design_arguments(ex)
    _add_output_arguments(ex)
    _add_verification_arguments(ex)
    add_json_argument(ex)
    add_quiet_argument(ex)
    ex.set_defaults(handler=_export)


def _add_design_arguments(ex: argparse.ArgumentParser) -> None:
    """Add the exported observer's period, front end, order and accuracy targets."""
    export = current().export
    ex.add_argument("--dt", type=float, required=True, metavar="DT", help="sampling period (s)")
    ex.add_argument(
        "--sampler",
        choices=SAMPLERS,
        default=export.sampler,
        help="the controller's front end: mean of the outputs over each period (default) "
        "or point samples",
    )
    ex.add_argument(
        "--order", type=int, metavar="P", help="observer states (default: from the targets)"
    )
    ex.add_argument(
        "--reduce",
        choices=REDUCTIONS,
        default="none",
        help="drop the unresolved modes (modal) or balance and truncate (balanced, needs "
        "slycot); default none, whose first line says how many unresolved poles it keeps "
        "that are slower than the abscissa",
    )
    ex.add_argument(
        "--design",
        choices=GAIN_DESIGNS,
        default=export.design,
        help="the gain the observer runs: auto (default) makes the passive and the Kalman "
        "design, verifies both on the initial states and keeps the lower worst F/F_c; passive "
        "re-tunes the gain inside the dissipative averaged structure; kalman is the "
        "steady-state Kalman predictor of the exact sampled model; given uses --gain as is",
    )
    ex.add_argument(
        "--process-noise",
        metavar="W,..",
        default="1",
        help="the Kalman design's noise model: intensity of white noise at each plant input "
        "(one number, or one per input; default 1)",
    )
    ex.add_argument(
        "--sensor-noise",
        metavar="R,..",
        default="1",
        help="the Kalman design's noise model: variance of each sensor sample's noise (one "
        "number, or one per sensor; default 1)",
    )
    ex.add_argument(
        "--tol",
        type=float,
        default=export.tol,
        help="relative accuracy of the rightmost error eigenvalues (default %(default)g)",
    )
    ex.add_argument(
        "--output-tol",
        type=float,
        default=export.output_tol,
        help="error floor of the performance outputs, relative to their peak (default "
        "%(default)g)",
    )


def _add_output_arguments(ex: argparse.ArgumentParser) -> None:
    """Add what is written, and where."""
    ex.add_argument(
        "--format", choices=EXPORT_FORMATS, required=True, help="what to write to -o PATH"
    )
    ex.add_argument(
        "--output", "-o", required=True, metavar="PATH", help="file (a folder for --format c)"
    )
    ex.add_argument(
        "--force",
        action="store_true",
        help="replace an existing output that phdesign wrote (a C folder only while it holds "
        "exactly the files of its marker .phdesign-export)",
    )


def _add_verification_arguments(ex: argparse.ArgumentParser) -> None:
    """Add the runs against the high-resolution plant: initial state, length, plant, outputs."""
    export = current().export
    ex.add_argument(
        "--verify",
        action="store_true",
        help="run the exported observer against the high-resolution plant",
    )
    ex.add_argument(
        "--strict",
        action="store_true",
        help="verify (implies --verify) and exit with status 3, writing nothing, when a "
        "check fails: the targets, the sampled against the continuous observer, the "
        "verification plant's own resolution, the worst F/F_c over the initial states "
        "against --max-ratio",
    )
    ex.add_argument(
        "--max-ratio",
        type=float,
        default=export.max_ratio,
        metavar="R",
        help="the largest worst ratio F/F_c of the sampled to the continuous error floor over "
        "the initial states that passes (default %(default)g): --strict fails above it, "
        "--design auto does not take a Kalman design above it",
    )
    ex.add_argument(
        "--x0",
        metavar="EXPRS",
        action="append",
        help="plant initial state of the verification runs, repeatable: the states given are "
        "the verification set, the first also the order selection's (default every "
        "x_i = (z-a)/(b-a) - 0.9, then two smooth states per component that meet the "
        "boundary conditions)",
    )
    ex.add_argument(
        "--t-end",
        type=float,
        default=export.t_end,
        metavar="T",
        help="verification time (default %(default)g)",
    )
    ex.add_argument(
        "--plant-resolution",
        type=int,
        metavar="Q",
        help=f"Galerkin degree of the verification plant (default {export.plant_degree}, at "
        "least twice the order)",
    )
    ex.add_argument(
        "--at",
        metavar="Z,..",
        help="point outputs: the displacement at these points, e.g. 0.5,1, or named fields "
        "at a point, e.g. rotation(1) (default b, for a model with a displacement)",
    )


def _export(args: argparse.Namespace) -> int:
    from phdesign.codegen import check_export_path

    # the output is checked before any work (the design checks the rest before computing)
    check_export_path(args.output, args.format, args.force)
    if args.format in ("c", "statespace") and importlib.util.find_spec("jinja2") is None:
        raise OutputFileError(
            f"--format {args.format} is rendered with jinja2, which is not installed: "
            "pip install 'phdesign[codegen]'"
        )
    model = load_model(args)
    observer = observer_from_args(args, model, command="export")
    if observer is None:
        raise ObserverError("export needs --sensors or --cm to say which outputs are measured")
    try:
        result = _exported(args, observer)
    except VerificationError as error:  # exit 3: the export ran and failed its checks
        line = f"{translated(str(error))}; nothing written"
        print(f"phdesign: error: {printable(line)}", file=sys.stderr)
        return 3
    written = result.write(args.output, args.format, force=args.force)
    if args.json:
        emit_json({**result.to_dict(), "files": written})
        for warning in result.warnings:
            warn(warning)
    else:
        emit(result_text(result) + "".join(f"\nwrote {path}" for path in written))
    return 0


def _exported(args: argparse.Namespace, observer: Any) -> Any:
    """Return ``observer.export(...)`` with the options of the command line."""
    return observer.export(
        dt=args.dt,
        sampler=args.sampler,
        order=args.order,
        reduction=args.reduce,
        tol=args.tol,
        output_tol=args.output_tol,
        verify=args.verify,
        strict=args.strict,
        x0=args.x0 or None,
        t_end=args.t_end,
        plant_resolution=args.plant_resolution,
        points=None if args.at is None else split_items(args.at),
        design=args.design,
        process_noise=_numbers(args.process_noise, "--process-noise"),
        sensor_noise=_numbers(args.sensor_noise, "--sensor-noise"),
        max_ratio=args.max_ratio,
    )


def _numbers(text: str, option: str) -> float | tuple[float, ...]:
    """Read ``1`` or ``1,3`` (the noise model's intensities; their values are checked there)."""
    items = split_items(text)
    try:
        values = tuple(float(item) for item in items)
    except ValueError:
        raise NumericError(
            f"{option} must be a number or comma-separated numbers; found {text!r}"
        ) from None
    return values[0] if len(values) == 1 else values


def add_sampling_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--dt``, ``--sampler`` and ``--observer-resolution`` to ``simulate``."""
    parser.add_argument(
        "--dt", type=float, metavar="DT", help="run the observer sampled every DT seconds"
    )
    parser.add_argument(
        "--sampler",
        choices=SAMPLERS,
        help="front end of the sampled observer: mean over each period (default) or point",
    )
    parser.add_argument(
        "--observer-resolution",
        type=int,
        metavar="P",
        help="Galerkin degree of the observer (default: the plant's --resolution)",
    )


def sampling_options(args: argparse.Namespace, observed: bool) -> dict[str, Any]:
    """Return the simulation options of ``--dt``, ``--sampler``, ``--observer-resolution``.

    Their values are checked by the simulation options (the messages name the options:
    :mod:`phdesign.cli.messages`); empty when none is given (the continuous observer then
    runs as before).  ``observed``: whether the command has an observer.
    """
    if args.dt is None and args.sampler is None and args.observer_resolution is None:
        return {}
    if not observed:
        raise NumericError(
            "--dt, --sampler and --observer-resolution act on the observer: give --sensors or --cm"
        )
    if args.sampler is not None and args.dt is None:
        raise NumericError("--sampler needs --dt, the sampling period")
    if args.scheme != "expm":
        raise NumericError("a sampled or lower-order observer is stepped exactly: drop --scheme")
    check_positive("--observer-resolution", args.observer_resolution)
    return {
        "dt": args.dt,
        "sampler": args.sampler,
        "observer_resolution": args.observer_resolution,
    }
