"""Command ``loop``: observer-based boundary control (classify, spectrum, simulate, tune).

``phdesign loop {classify,spectrum,simulate,tune} MODEL --actuate 3 --feedback 1
--sensors 4 --gain 1 [--json]``: the plant's input u3 is driven by −K ŷ3, the observer's
estimate of its collocated output, the observer measuring y4.  Argument parsing and
printing only: the design is :class:`phdesign.design.loop.Loop`, each result prints itself.
"""

from __future__ import annotations

import argparse
from typing import Any

from phdesign.cli.common import (
    add_discretization_arguments,
    add_json_argument,
    add_model_argument,
    add_quiet_argument,
    add_simulation_outputs,
    check_finite_series,
    check_positive,
    emit_result,
    load_model,
    run_outputs,
    simulation_text,
    split_items,
    warn,
)
from phdesign.cli.design_arguments import add_observer_arguments, observer_from_args
from phdesign.core.defaults import current
from phdesign.core.errors import LoopError, NumericError

__all__ = ["register"]


def _loop_arguments(parser: argparse.ArgumentParser) -> None:
    add_model_argument(parser)
    parser.add_argument(
        "--actuate",
        required=True,
        metavar="I,J",
        help="actuated inputs, 1-based indices into the model's inputs, e.g. 3",
    )
    parser.add_argument(
        "--feedback",
        metavar="K",
        help="feedback gain K > 0 on the collocated estimates: '1' or '1,2' (diagonal) or "
        "'[[..]]' (full); default 1",
    )
    parser.add_argument(
        "--feedback-outputs",
        metavar="I,J",
        help="the outputs fed back (default: the collocated ones, the only ones allowed)",
    )
    parser.add_argument(
        "--feedback-source",
        choices=("estimate", "measured"),
        default="estimate",
        help="feed back the observer's estimate (default) or the measured output (to compare; "
        "only for measured outputs)",
    )
    add_observer_arguments(parser)
    add_quiet_argument(parser)


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``loop`` command and its four subcommands."""
    parser = subparsers.add_parser(
        "loop",
        help="observer-based boundary control: u_a = -K ŷ_a",
        description="Feed the observer's estimate of the collocated outputs back to the "
        "actuated inputs, u_a = -K ŷ_a, and ask for certificates, the converged spectrum "
        "of the assembled loop, a simulation or tuned gains.",
    )
    sub = parser.add_subparsers(dest="loop_command", metavar="SUBCOMMAND")
    sub.required = True
    for add in (_add_classify, _add_spectrum, _add_simulate, _add_tune):
        add(sub)


def _add_classify(sub: argparse._SubParsersAction) -> None:
    cl = sub.add_parser("classify", help="controlled plant, error system and loop verdicts")
    _loop_arguments(cl)
    cl.add_argument(
        "--method",
        choices=("auto", "exact", "float"),
        default="auto",
        help="how kappa* is computed (the decision is always exact)",
    )
    add_json_argument(cl)
    cl.set_defaults(handler=_classify)


def _add_spectrum(sub: argparse._SubParsersAction) -> None:
    sp = sub.add_parser("spectrum", help="converged spectrum of the assembled loop")
    _loop_arguments(sp)
    add_discretization_arguments(sp, "")
    sp.add_argument("--tol", type=float, help="required agreement of the abscissa")
    sp.add_argument(
        "--count",
        type=int,
        default=current().spectrum.count,
        help="rightmost eigenvalues to report",
    )
    add_json_argument(sp)
    sp.set_defaults(handler=_spectrum)


def _add_simulate(sub: argparse._SubParsersAction) -> None:
    sim = sub.add_parser("simulate", help="simulate plant, observer and feedback together")
    _loop_arguments(sim)
    add_discretization_arguments(sim, "")
    sim.add_argument("--x0", metavar="EXPRS", help="plant initial state, e.g. 'x1: 0, x2: z'")
    sim.add_argument("--xhat0", metavar="EXPRS", help="observer initial state (default zero)")
    sim.add_argument(
        "--u", metavar="EXPRS", help="signals on the inputs not actuated, e.g. 'u4: sin(t)'"
    )
    run = current().simulation
    sim.add_argument("--t-end", type=float, default=run.t_end, metavar="T", help="final time")
    sim.add_argument("--samples", type=int, default=run.samples, help="output samples on [0, T]")
    sim.add_argument("--scheme", choices=("expm", "midpoint"), default=run.scheme)
    add_simulation_outputs(sim)  # --csv/--json, --at, -o, --plot, --force as for simulate
    sim.set_defaults(handler=_simulate)


def _add_tune(sub: argparse._SubParsersAction) -> None:
    tn = sub.add_parser("tune", help="tune K and/or L on the loop's converged abscissa")
    _loop_arguments(tn)
    tn.add_argument(
        "--tune",
        choices=("feedback", "gain", "both"),
        default="both",
        help="what to tune: K on the controlled plant, L on the error system, or both",
    )
    tn.add_argument("--full", action="store_true", help="full gains instead of diagonal")
    tn.add_argument("--starts", type=int, default=6, help="number of starts")
    tn.add_argument("--seed", type=int, default=0, help="seed of the random starts")
    add_json_argument(tn)
    tn.set_defaults(handler=_tune)


def _loop(args: argparse.Namespace, numeric: bool = True) -> Any:
    from phdesign.cli.design_arguments import parse_gain_text
    from phdesign.design.loop import Loop
    from phdesign.symbolic.control import parse_indices

    model = load_model(args)
    observer = observer_from_args(args, model, default_gain=1)
    if observer is None:
        raise LoopError("loop needs the observer's sensors: give --sensors or --cm")
    outputs = args.feedback_outputs
    return Loop.from_parts(
        model,
        observer.C_m,
        observer.L,
        actuate=parse_indices(args.actuate, "--actuate"),
        feedback=parse_gain_text(args.feedback or "1", "--feedback"),
        feedback_source=args.feedback_source,
        feedback_outputs=None if outputs is None else parse_indices(outputs, "--feedback-outputs"),
        method=args.method if numeric else None,
        resolution=getattr(args, "resolution", None),
    )


def _print(args: argparse.Namespace, result: Any, model: str) -> int:
    return emit_result(args, result, model=model)


def _classify(args: argparse.Namespace) -> int:
    loop = _loop(args, numeric=False)
    return _print(args, loop.classify(method=args.method), loop.model.name)


def _spectrum(args: argparse.Namespace) -> int:
    check_positive("--resolution", args.resolution)
    check_positive("--tol", args.tol)
    check_positive("--count", args.count)
    loop = _loop(args)
    return _print(args, loop.spectrum(tol=args.tol, count=args.count), loop.model.name)


def _simulate(args: argparse.Namespace) -> int:
    check_positive("--resolution", args.resolution)
    check_positive("--t-end", args.t_end)
    if args.samples < 2:
        raise NumericError(f"--samples must be at least 2; found {args.samples}")
    import numpy as np

    loop = _loop(args)
    with run_outputs(args) as commit:
        with np.errstate(all="ignore"):  # an overflow is refused below, with one line
            run = loop.simulate(
                x0=args.x0,
                xhat0=args.xhat0,
                u=args.u,
                t_end=args.t_end,
                samples=args.samples,
                scheme=args.scheme,
                at=None if args.at is None else split_items(args.at),
            )
        check_finite_series(run)
        commit(simulation_text(args, loop.model.name, run), run)
    for warning in run.warnings:
        warn(warning)
    return 0


def _tune(args: argparse.Namespace) -> int:
    check_positive("--starts", args.starts)
    tuned = {"feedback": ("--feedback",), "gain": ("--gain",), "both": ("--feedback", "--gain")}
    for flag in tuned[args.tune]:  # a tuned gain starts from the grid, not from a given value
        if getattr(args, flag[2:]) is not None:
            raise LoopError(
                f"{flag} is what --tune {args.tune} tunes (its search starts from a grid, not "
                f"from a given value): drop {flag}, or keep it with --tune "
                f"{'gain' if flag == '--feedback' else 'feedback'}"
            )
    loop = _loop(args, numeric=False)
    result = loop.tune(args.tune, full=args.full, starts=args.starts, seed=args.seed)
    return _print(args, result, loop.model.name)
