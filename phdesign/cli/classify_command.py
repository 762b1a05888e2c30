"""Command ``classify``: which proposition a sensor set and gain satisfy.

``phdesign classify MODEL [--sensors 3,4 | --cm '[[..]]'] [--gain ...] [--json]``
classifies one design; ``--all-sensors`` classifies every subset of the outputs.
Printing only: the mathematics lives in :mod:`phdesign.symbolic.classify` and
:mod:`phdesign.symbolic.search`, and the text is the results' own (``str(result)``).
"""

from __future__ import annotations

import argparse
from typing import Any

from phdesign.cli.common import (
    add_json_argument,
    add_model_argument,
    add_quiet_argument,
    emit_result,
    load_model,
)
from phdesign.cli.design_arguments import (
    add_observer_arguments,
    observer_from_args,
    parse_gain_text,
)
from phdesign.core.errors import ObserverError

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``classify`` command."""
    parser = subparsers.add_parser(
        "classify",
        help="classify sensors and gain against Propositions 3.1-3.4",
        description=(
            "Classify an observer design (sensors and gain) against every variant of "
            "Propositions 3.1-3.4, with the best constant kappa* or a counter-example; "
            "--all-sensors tries every subset of the outputs."
        ),
    )
    add_model_argument(parser)
    add_observer_arguments(parser, symbolic=True)
    parser.add_argument(
        "--all-sensors",
        action="store_true",
        help="classify every non-empty subset of the outputs (gains: identity, or --gain "
        "with one value for all outputs or one per output)",
    )
    parser.add_argument(
        "--method",
        choices=("auto", "exact", "float"),
        default="auto",
        help="how kappa* is computed (the decision is always exact); default: %(default)s",
    )
    add_json_argument(parser)
    add_quiet_argument(parser)
    parser.set_defaults(handler=_classify)


def _classify(args: argparse.Namespace) -> int:
    model = load_model(args)
    if args.all_sensors:
        if args.sensors is not None or args.cm is not None:
            raise ObserverError("--all-sensors tries every sensor set; drop --sensors/--cm")
        return _search(args, model)
    observer = observer_from_args(args, model, default_gain=1, unobserved=True)
    if observer is None:
        raise ObserverError("classify needs --sensors, --cm or --all-sensors")
    result = observer.classify(method=args.method)
    return emit_result(args, result)


def _search(args: argparse.Namespace, model: Any) -> int:
    from phdesign.symbolic.search import search_sensors

    gain = None if args.gain is None else parse_gain_text(args.gain)
    found = search_sensors(model, gain=gain)  # its progress: the command's display
    return emit_result(args, found)
