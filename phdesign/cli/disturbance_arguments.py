"""The disturbance options of ``tune`` and ``tradeoff`` (issue 27).

Argument parsing and printing only: ``tune --objective hinf|h2`` and ``--max-hinf`` ask
:meth:`phdesign.Observer.tune_noise` for a gain designed against the model's
``[disturbances]`` (:mod:`phdesign.numeric.noise.disturbance_tuning`), ``tradeoff
--against hinf`` asks :meth:`phdesign.Observer.tradeoff` for the decay rate against the
H∞ norm (:mod:`phdesign.numeric.noise.disturbance_tradeoff`).  Their outputs are the
model's ``[performance]`` outputs or ``--performance`` (the grammar of ``phdesign gain``),
their noise the sensors' ``--intensity``.
"""

from __future__ import annotations

import argparse
from typing import Any

from phdesign.cli.common import check_positive, emit_result, intensities, load_model
from phdesign.cli.design_arguments import observer_from_args
from phdesign.core.errors import NumericError

__all__ = [
    "add_against_arguments",
    "add_disturbance_tuning_arguments",
    "disturbance_tradeoff_inputs",
    "disturbance_tuning",
]


def _add_performance(parser: argparse.ArgumentParser, needs: str) -> None:
    parser.add_argument(
        "--performance",
        action="append",
        default=None,
        metavar="EXPR",
        help=f"with {needs}: a performance output, e.g. 'integral(e1)' (repeatable; "
        "default: the model's [performance] outputs)",
    )


def add_disturbance_tuning_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--max-hinf`` and ``--performance`` to ``tune`` (its ``--objective`` has hinf, h2)."""
    parser.add_argument(
        "--max-hinf",
        type=float,
        metavar="G",
        help="minimize the abscissa subject to the H-infinity norm of phdesign gain <= G",
    )
    _add_performance(parser, "--objective hinf/h2 or --max-hinf")


def add_against_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--against`` and ``--performance`` to ``tradeoff``."""
    parser.add_argument(
        "--against",
        choices=("rms", "hinf"),
        default="rms",
        help="the figure traded against the decay rate: the error RMS under sensor noise "
        "(default), or the H-infinity norm of phdesign gain from the model's disturbances "
        "and the sensor noise of --intensity to the error of its performance outputs",
    )
    _add_performance(parser, "--against hinf")


def disturbance_tradeoff_inputs(args: argparse.Namespace) -> dict[str, Any]:
    """Return the options of ``tradeoff --against hinf``, refusing the RMS's."""
    for flag, value in (
        ("--input-noise", args.input_noise),
        ("--at", args.at),
        ("--trace", args.trace),
        ("--integral", args.integral),
    ):
        if value:
            raise NumericError(
                f"{flag} belongs to the RMS trade-off; --against hinf judges the model's "
                "[performance] outputs (or --performance)"
            )
    return {
        "against": "hinf",
        "intensity": intensities(args.intensity, "--intensity"),
        "performance": args.performance,
    }


def disturbance_tuning(args: argparse.Namespace) -> int:
    """``tune --objective hinf|h2`` and ``--max-hinf``: against the model's disturbances."""
    refused = [
        flag
        for flag, value in (
            ("--max-rms", args.max_rms),
            ("--input-noise", args.input_noise),
            ("--at", args.at),
            ("--trace", args.trace),
            ("--integral", args.integral),
            ("--full", args.full),
            ("--starts", args.starts),
            ("--seed", args.seed),
            ("--robust", args.robust),
        )
        if value
    ]
    if refused:
        raise NumericError(
            f"{refused[0]} does not go with the disturbance objectives (--objective hinf, h2, "
            "--max-hinf); their outputs are --performance, their noise --intensity"
        )
    if args.objective == "rms":
        raise NumericError("--max-hinf goes with the abscissa objective")
    if args.objective in ("hinf", "h2") and args.max_hinf is not None:
        raise NumericError(
            f"--max-hinf bounds the abscissa objective; --objective {args.objective} takes "
            "--min-decay"
        )
    if args.objective == "abscissa" and args.min_decay is not None:
        raise NumericError("--min-decay goes with --objective rms, hinf or h2")
    check_positive("--max-hinf", args.max_hinf)
    check_positive("--min-decay", args.min_decay)
    model = load_model(args)
    observer = observer_from_args(args, model)  # argparse requires --sensors or --cm here
    result = observer.tune_noise(
        objective=args.objective,
        max_hinf=args.max_hinf,
        min_decay=args.min_decay,
        intensity=intensities(args.intensity, "--intensity"),
        performance=args.performance,
    )
    return emit_result(args, result, model=model.name)
