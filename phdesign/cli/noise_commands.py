"""Commands ``noise`` and ``tradeoff``, and the noise options of ``simulate`` and ``tune``.

Argument parsing and printing only: the figures come from the observer's noise
questions (:meth:`phdesign.Observer.noise`, :meth:`~phdesign.Observer.tradeoff`,
:meth:`~phdesign.Observer.tune_noise`), the noisy simulation from
:meth:`phdesign.Observer.simulate`.  Each command prints ``str(result)`` or
``result.to_dict()`` as JSON.

Noise options (shared):

``--intensity 0.01,0.04``
    sensor noise intensities σᵢ² (E[ν νᵀ] = diag(σ²) δ), one per sensor or one for all;
    default 1.
``--input-noise 0.5``
    white noise on the plant inputs u, of these intensities (one per input or one for
    all); the observer does not see it.
``--at 1``, ``--trace 'e1(1)'``, ``--integral 'x2: sin(pi*z)'``
    performance outputs: the displacement at points, combinations of boundary traces, and
    integrals of state components against weights (repeatable; default: the displacement
    at b when the model defines one).
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from phdesign.cli.common import (
    add_discretization_arguments,
    add_json_argument,
    add_model_argument,
    add_quiet_argument,
    check_positive,
    comma_numbers,
    emit_result,
    intensities,
    load_model,
    result_text,
    run_outputs,
    split_items,
)
from phdesign.cli.design_arguments import add_observer_arguments, observer_from_args
from phdesign.cli.disturbance_arguments import (
    add_against_arguments,
    add_disturbance_tuning_arguments,
    disturbance_tradeoff_inputs,
    disturbance_tuning,
)
from phdesign.core.errors import NumericError, ObserverError, ParameterError
from phdesign.core.limits import check_tradeoff_gains

__all__ = [
    "add_noise_arguments",
    "add_noise_tuning_arguments",
    "add_stochastic_arguments",
    "noise_options",
    "noise_tuning",
    "register",
]


def add_noise_arguments(
    parser: argparse.ArgumentParser, *, sensor_flag: str = "--intensity"
) -> None:
    """Add the sensor/input noise intensities and the performance outputs."""
    parser.add_argument(
        sensor_flag,
        metavar="S2",
        dest="intensity",
        help="sensor noise intensities sigma_i^2, one per sensor or one for all (default 1)",
    )
    parser.add_argument(
        "--input-noise",
        metavar="W",
        help="white noise on the plant inputs, of these intensities (one per input or one "
        "for all); the observer does not know it",
    )
    _add_performance_arguments(parser)


def _add_performance_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--at",
        metavar="Z",
        help="performance: the displacement at these points, e.g. 1 or 0.5,1, or a named "
        "field of the model at a point, e.g. rotation(1)",
    )
    parser.add_argument(
        "--trace",
        action="append",
        default=[],
        metavar="EXPR",
        help="performance: a boundary trace combination, e.g. 'e1(1)' (repeatable)",
    )
    parser.add_argument(
        "--integral",
        action="append",
        default=[],
        metavar="WEIGHTS",
        help="performance: the integral of state components against weights, e.g. "
        "'x2: sin(pi*z)' (repeatable)",
    )


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``noise`` and ``tradeoff`` commands."""
    nz = subparsers.add_parser(
        "noise",
        help="what a gain costs in sensor noise: error variances, L2-gain, error energy",
    )
    add_model_argument(nz)
    add_observer_arguments(nz)
    add_noise_arguments(nz)
    add_discretization_arguments(nz, "first of the refinement")
    nz.add_argument("--tol", type=float, help="relative agreement of a converged figure")
    add_json_argument(nz)
    nz.add_argument("--plot", metavar="FILE", help="draw the frequency response to FILE")
    nz.add_argument("--force", action="store_true", help="overwrite an existing plot file")
    add_quiet_argument(nz)
    nz.set_defaults(handler=_noise)

    tr = subparsers.add_parser(
        "tradeoff", help="decay rate against error RMS over a ray or a grid of gains"
    )
    add_model_argument(tr)
    group = tr.add_mutually_exclusive_group(required=True)
    group.add_argument("--sensors", metavar="I,J", help="measured outputs, 1-based")
    group.add_argument("--cm", metavar="ROWS", help="C_m in full, e.g. '[[0,0,1,0]]'")
    family = tr.add_mutually_exclusive_group()
    family.add_argument(
        "--direction", metavar="L0", help="the ray s*diag(L0), e.g. 0.1,1 (default all ones)"
    )
    family.add_argument(
        "--grid",
        metavar="AXES",
        help="a grid of diagonal gains: per sensor lo:hi:count (log-spaced) or one value, "
        "comma-separated, e.g. 0.01:1:5,0.1:10:5",
    )
    tr.add_argument(
        "--scales", metavar="LO:HI:N", help="scales s of the ray, log-spaced (default 0.1:10:12)"
    )
    add_against_arguments(tr)
    add_noise_arguments(tr)
    add_discretization_arguments(tr)
    fmt = tr.add_mutually_exclusive_group()
    fmt.add_argument("--csv", action="store_true", help="CSV table")
    fmt.add_argument("--json", action="store_true", help="JSON output")
    tr.add_argument("--output", "-o", metavar="FILE", help="write the table to FILE")
    tr.add_argument("--plot", metavar="FILE", help="draw decay rate against RMS to FILE")
    tr.add_argument("--force", action="store_true", help="overwrite existing files")
    add_quiet_argument(tr)
    tr.set_defaults(handler=_tradeoff, gain=None)  # the family gives the gains


# ----------------------------------------------------------------------------- parsing
def _performance(args: argparse.Namespace) -> list[str] | None:
    """Return the performance outputs of ``--at``, ``--trace`` and ``--integral`` as text."""
    points = split_items(args.at) if args.at is not None else []
    items = [z if "(" in z else f"w({z})" for z in points]  # rotation(1): a named field
    items += args.trace
    for weights in args.integral:
        if ":" not in weights:  # a weight without its component would read as a trace
            raise ParameterError(
                f"--integral item {weights!r}: expected 'name: expression', e.g. 'x2: sin(pi*z)'"
            )
        items.append(weights)
    return items or None


def _observer(args: argparse.Namespace, command: str) -> Any:
    """Return the :class:`phdesign.Observer` of the command; ``tradeoff`` takes no gain."""
    model = load_model(args)
    family = command == "tradeoff"  # the ray or grid gives the gains
    observer = observer_from_args(
        args,
        model,
        command="" if family else command,
        method=args.method,
        resolution=getattr(args, "resolution", None),
    )
    if observer is None:
        raise ObserverError(
            f"{command} needs --sensors or --cm: the noise enters through the observer's "
            "measurements"
        )
    return observer


def _noise_inputs(args: argparse.Namespace) -> dict[str, Any]:
    """Return the noise options as the design's arguments (intensities, performance)."""
    return {
        "intensity": intensities(args.intensity, "--intensity"),
        "input_intensity": intensities(args.input_noise, "--input-noise"),
        "performance": _performance(args),
    }


# ----------------------------------------------------------------------------- commands
def _noise(args: argparse.Namespace) -> int:
    check_positive("--resolution", args.resolution)
    check_positive("--tol", args.tol)
    observer = _observer(args, "noise")
    with run_outputs(args) as commit:  # the plot is checked now, the text printed after it
        report = observer.noise(**_noise_inputs(args), tol=args.tol)
        commit(_text(args, report), report)
    return 0


def _text(args: argparse.Namespace, result: Any) -> str:
    """Return the result as ``--json``, ``--csv`` (where a command has it) or text."""
    from phdesign.io import dumps_json

    if args.json:
        return dumps_json(result.to_dict())
    return result.to_csv() if getattr(args, "csv", False) else result_text(result)


def _range(text: str, flag: str) -> Any:
    import numpy as np

    parts = str(text).split(":")
    if len(parts) == 1:
        value = comma_numbers(parts[0], flag)[0]
        return np.array([value])
    if len(parts) != 3:
        raise NumericError(f"{flag}: expected lo:hi:count or one value; found {text!r}")
    lo, hi = (comma_numbers(p, flag)[0] for p in parts[:2])
    try:
        count = int(parts[2])
    except ValueError:
        raise NumericError(f"{flag}: the count in {text!r} must be an integer") from None
    if not (0 < lo < hi < float("inf")) or count < 2:
        raise NumericError(
            f"{flag}: expected 0 < lo < hi and a count of at least 2 in lo:hi:count; "
            f"found {text!r}"
        )
    check_tradeoff_gains(count, flag)  # before the values are built
    return np.geomspace(lo, hi, count)


def _tradeoff_inputs(args: argparse.Namespace) -> dict[str, Any]:
    """Return the figures' options: the noise's (``--against rms``) or the gain report's."""
    if args.against == "hinf":
        return disturbance_tradeoff_inputs(args)
    if args.performance is not None:
        raise NumericError("--performance goes with --against hinf; the RMS takes --at")
    return _noise_inputs(args)


def _tradeoff(args: argparse.Namespace) -> int:
    observer = _observer(args, "tradeoff")
    q = observer.q
    if args.grid is not None and args.scales is not None:
        raise NumericError("--scales belongs to a ray; a --grid gives its own values")
    direction = None
    if args.direction is not None:
        direction = comma_numbers(args.direction, "--direction")
        if len(direction) not in (1, q) or min(direction) <= 0:
            raise NumericError(
                f"--direction: expected {q} positive values (one per sensor) or one; "
                f"found {args.direction!r}"
            )
    grid = None
    if args.grid is not None:
        grid = [_range(axis, "--grid") for axis in str(args.grid).split(",")]
        check_tradeoff_gains(math.prod(len(axis) for axis in grid), "--grid")
    scales = None if args.scales is None else _range(args.scales, "--scales")
    # the table and the picture are checked now and written together: both or neither
    with run_outputs(args) as commit:
        result = observer.tradeoff(
            direction=direction, scales=scales, grid=grid, **_tradeoff_inputs(args)
        )
        commit(_text(args, result), result)
    return 0


# ----------------------------------------------------------------------------- simulate
def add_stochastic_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--noise-intensity``, ``--input-noise`` and ``--seed`` to ``simulate``."""
    parser.add_argument(
        "--noise-intensity",
        metavar="S2",
        help="sensor noise intensities sigma_i^2 (one per sensor or one for all): a "
        "stochastic run, exact at the samples",
    )
    parser.add_argument(
        "--input-noise",
        metavar="W",
        help="white noise on the plant inputs, of these intensities (one per input or one "
        "for all)",
    )
    parser.add_argument(
        "--disturbance-noise",
        metavar="W",
        help="white noise on the disturbance channels (those of --w), of these intensities "
        "(one per channel or one for all); the observer does not know it",
    )
    parser.add_argument("--seed", type=int, help="seed of the noise (with the noise options)")


def noise_options(args: argparse.Namespace) -> dict[str, Any]:
    """Return the simulation options of the noise flags (empty without them), checked here."""
    flags = (args.noise_intensity, args.input_noise, args.disturbance_noise)
    noisy = any(value is not None for value in flags)
    if not noisy:
        if args.seed is not None:
            raise NumericError("--seed needs --noise-intensity or --input-noise")
        return {}
    sampled = [
        flag
        for flag, name in (
            ("--dt", "dt"),
            ("--sampler", "sampler"),
            ("--observer-resolution", "observer_resolution"),
        )
        if getattr(args, name, None) is not None
    ]
    if sampled:
        raise NumericError(
            f"the noise options run the continuous observer; {sampled[0]} asks for a sampled "
            "one: give one or the other"
        )
    sensors = getattr(args, "sensors", None) or getattr(args, "cm", None)
    if args.noise_intensity is not None and sensors is None:
        raise ObserverError("--noise-intensity needs an observer: give --sensors or --cm")
    return {
        "noise_intensity": intensities(args.noise_intensity, "--noise-intensity"),
        "input_intensity": intensities(args.input_noise, "--input-noise"),
        "disturbance_intensity": intensities(args.disturbance_noise, "--disturbance-noise"),
        "seed": args.seed,
    }


# ----------------------------------------------------------------------------- tune
def add_noise_tuning_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the noise-aware objectives to ``tune`` (and the noise options they need)."""
    parser.add_argument(
        "--max-rms",
        type=float,
        metavar="R",
        help="minimize the abscissa subject to the error RMS of the performance outputs <= R",
    )
    parser.add_argument(
        "--objective",
        choices=("abscissa", "rms", "hinf", "h2"),
        default="abscissa",
        help="what to minimize (rms: the error RMS, with --min-decay; hinf, h2: the norms "
        "of phdesign gain from the disturbances and sensor noise to the error of the "
        "performance outputs, with --min-decay optional)",
    )
    parser.add_argument(
        "--min-decay",
        type=float,
        metavar="A",
        help="with --objective rms, hinf or h2: require the spectral abscissa <= -A",
    )
    add_disturbance_tuning_arguments(parser)
    add_noise_arguments(parser)


def noise_tuning(args: argparse.Namespace) -> int | None:
    """Run the noise- or disturbance-aware tuning when its options are given; None otherwise."""
    if args.objective in ("hinf", "h2") or args.max_hinf is not None:
        return disturbance_tuning(args)
    if args.performance is not None:
        raise NumericError("--performance needs --objective hinf or h2, or --max-hinf")
    wanted = args.max_rms is not None or args.objective == "rms" or args.min_decay is not None
    extras = [
        flag
        for flag, value in (
            ("--intensity", args.intensity),
            ("--input-noise", args.input_noise),
            ("--at", args.at),
            ("--trace", args.trace),
            ("--integral", args.integral),
        )
        if value
    ]
    if not wanted:
        if extras:
            raise NumericError(f"{extras[0]} needs --max-rms or --objective rms")
        return None
    if args.objective == "abscissa" and args.min_decay is not None:
        raise NumericError("--min-decay goes with --objective rms")
    if args.objective == "rms" and args.max_rms is not None:
        raise NumericError("--max-rms goes with the abscissa objective")
    if args.full:
        raise NumericError("noise-aware tuning searches positive diagonal gains; drop --full")
    for flag, value in (
        ("--starts", args.starts),
        ("--seed", args.seed),
        ("--robust", args.robust),
    ):
        if value is not None:  # they steer the abscissa search only
            raise NumericError(
                f"{flag} belongs to the abscissa search; the noise-aware tuning (--max-rms, "
                f"--objective rms) does not take it: drop {flag}"
            )
    check_positive("--max-rms", args.max_rms)
    check_positive("--min-decay", args.min_decay)
    if args.objective == "rms" and args.min_decay is None:
        raise NumericError("--objective rms needs --min-decay A (the decay rate to keep)")
    model = load_model(args)
    observer = observer_from_args(args, model)  # argparse requires --sensors or --cm here
    result = observer.tune_noise(
        objective=args.objective,
        max_rms=args.max_rms,
        min_decay=args.min_decay,
        **_noise_inputs(args),
    )
    return emit_result(args, result, model=model.name)
