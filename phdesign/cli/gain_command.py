"""Command ``gain``: H∞ and H₂ norms from the disturbances to the performance outputs.

Argument parsing and printing only: the numbers come from :meth:`phdesign.Observer.gain`
(with ``--sensors``/``--cm`` and ``--gain``: the estimation error of an observer, sensor
noise of ``--noise`` included) or :meth:`phdesign.design.plant.Plant.gain` (the plant).
The disturbances are the model's ``[disturbances]`` and unknown inputs; the outputs its
``[performance]`` section, or ``--performance`` (repeatable, the same grammar).
"""

from __future__ import annotations

import argparse

from phdesign.cli.common import (
    add_discretization_arguments,
    add_json_argument,
    add_model_argument,
    add_quiet_argument,
    check_positive,
    emit_result,
    intensities,
    load_model,
)
from phdesign.cli.design_arguments import add_observer_arguments, observer_from_args
from phdesign.core.errors import ObserverError

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``gain`` command."""
    g = subparsers.add_parser(
        "gain",
        help="H-infinity and H2 norms from the disturbances (and sensor noise) to the "
        "performance outputs, of the plant or of an observer's error",
    )
    add_model_argument(g)
    add_observer_arguments(g, required=True)
    g.add_argument(
        "--noise",
        metavar="S2",
        dest="intensity",
        help="sensor noise intensities sigma_i^2 of an observer, one per sensor or one for "
        "all (default 1; 0 leaves the noise out)",
    )
    g.add_argument(
        "--performance",
        action="append",
        default=None,
        metavar="EXPR",
        help="a performance output, e.g. 'integral(e1)', 'e1(1)' or 'w(1)' (repeatable; "
        "default: the model's [performance] outputs)",
    )
    g.add_argument(
        "--optimal",
        action="store_true",
        help="also the optimal full-order estimators of the same plant, disturbances and "
        "noise: the Kalman-Bucy H2 error and the H-infinity-optimal level (an observer only)",
    )
    add_discretization_arguments(g, "first of the refinement")
    g.add_argument(
        "--max-resolution", type=int, metavar="N", help="largest resolution of the refinement"
    )
    g.add_argument("--tol", type=float, help="relative agreement of a converged figure")
    add_json_argument(g)
    add_quiet_argument(g)
    g.set_defaults(handler=_gain)


def _gain(args: argparse.Namespace) -> int:
    from phdesign.design.plant import Plant

    for option in ("--resolution", "--max-resolution", "--tol"):
        check_positive(option, getattr(args, option[2:].replace("-", "_")))
    model = load_model(args)
    observer = observer_from_args(
        args, model, command="gain", method=args.method, resolution=args.resolution
    )
    options = {
        "performance": args.performance,
        "max_resolution": args.max_resolution,
        "tol": args.tol,
    }
    if observer is None:
        if args.intensity is not None:
            raise ObserverError("--noise needs --sensors or --cm: it is the sensors' noise")
        if args.optimal:
            raise ObserverError("--optimal needs --sensors or --cm: it compares estimators")
        report = Plant(model, method=args.method, resolution=args.resolution).gain(**options)
    else:
        noise = intensities(args.intensity, "--noise")
        report = observer.gain(intensity=noise, optimal=args.optimal, **options)
    return emit_result(args, report)
