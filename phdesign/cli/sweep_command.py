"""Commands ``sweep`` (a job over a grid, on Dask) and ``plot`` (a picture of a sweep result).

Argument parsing and printing only: the sweep lives in :mod:`phdesign.sweep`, imported in
the handlers (dask, xarray and zarr only when a sweep runs).  The job options are the
flags of the registered jobs (:data:`phdesign.sweep.jobs.JOBS`): a new job's options
become flags here without a change to this module.  They are added when ``sweep`` is
parsed or its help shown (the registry is in the sweep package, which no other command
imports).
"""

from __future__ import annotations

import argparse
from typing import Any

from phdesign.cli.common import (
    add_json_argument,
    add_model_argument,
    emit,
    emit_json,
    emit_result,
    load_model,
    note,
)
from phdesign.core.errors import SweepError

__all__ = ["register"]

_TYPES = {"int": int, "float": float, "choice": str}


def _job_options() -> dict[str, Any]:
    """Every option of every registered job, by name (the first definition wins)."""
    from phdesign.sweep.jobs import JOBS

    options: dict[str, Any] = {}
    for job in JOBS.values():
        for option in job.options:
            options.setdefault(option.name, (option, job.name))
    return options


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``sweep`` and ``plot`` commands."""
    _add_sweep(subparsers)
    _add_plot(subparsers)


def _add_sweep(subparsers: argparse._SubParsersAction) -> None:
    sp = subparsers.add_parser(
        "sweep",
        help="evaluate a job over a grid of gains, parameters and sensor sets (on Dask)",
        description="Evaluate a job at every point of a grid of gains (--grid), model "
        "parameters (--param-grid) and sensor sets (--sensor-sets), in chunks that run on a "
        "local Dask cluster (default), an existing one, or in this process; write the result "
        "to a Zarr store (resumable), a CSV or a NetCDF file.",
    )
    add_model_argument(sp)
    _add_grid_arguments(sp)
    _add_run_arguments(sp)
    add_json_argument(sp)
    sp.defer(_add_job_arguments)
    sp.set_defaults(handler=_sweep)


def _add_grid_arguments(sp: argparse.ArgumentParser) -> None:
    """Add the points of a sweep: sensors or sensor sets, fixed gain, gain and parameter axes."""
    sensors = sp.add_mutually_exclusive_group()
    sensors.add_argument(
        "--sensors", metavar="I,J", help="measured outputs, 1-based indices, e.g. 3,4"
    )
    sensors.add_argument(
        "--sensor-sets",
        metavar="SETS",
        help="an axis of sensor sets: 'all' or sets separated by ';', e.g. '3,4;4;2'",
    )
    sp.add_argument(
        "--gain",
        metavar="L",
        help="fixed diagonal of L for the entries not on a grid, e.g. 0.1,1 (default 1)",
    )
    sp.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="NAME=SPEC",
        help="gain axis (repeatable): l1=0.01:3:40:log (start:stop:count[:log]) or "
        "l2=0.03,0.1,0.2; l=... sets every entry",
    )
    sp.add_argument(
        "--param-grid",
        action="append",
        default=[],
        metavar="NAME=SPEC",
        help="model parameter axis (repeatable), e.g. d=0:0.4:9",
    )


def _add_run_arguments(sp: argparse.ArgumentParser) -> None:
    """Add where a sweep goes and runs: the output, resume or force, the scheduler, chunks."""
    sp.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUT",
        help="map.zarr (written chunk by chunk, resumable), map.csv or map.nc",
    )
    mode = sp.add_mutually_exclusive_group()
    mode.add_argument("--resume", action="store_true", help="continue the sweep a store holds")
    mode.add_argument("--force", action="store_true", help="replace an existing output")
    sp.add_argument(
        "--scheduler",
        metavar="WHERE",
        help="'local' (a LocalCluster sized to the machine), 'synchronous' (in this "
        "process) or an address such as tcp://HOST:PORT; default: DASK_SCHEDULER_ADDRESS "
        "when set, else this process until a local cluster would repay its start",
    )
    sp.add_argument("--workers", type=int, metavar="N", help="workers of the local cluster")
    sp.add_argument(
        "--chunk-size",
        type=int,
        metavar="N",
        help="points per task (default: from the grid and the workers)",
    )
    sp.add_argument(
        "--no-progress", action="store_true", help="no progress bar (shown on a terminal)"
    )


def _add_plot(subparsers: argparse._SubParsersAction) -> None:
    pl = subparsers.add_parser(
        "plot", help="draw a sweep result: a gain map, a parameter study, a sensor-set study"
    )
    pl.add_argument("input", metavar="SWEEP", help="a sweep store (.zarr) or NetCDF file (.nc)")
    pl.add_argument(
        "-o", "--output", required=True, metavar="FILE", help="image file (.png, .pdf, .svg)"
    )
    pl.add_argument("--figure", metavar="NAME", help="the figure to draw (default: the first)")
    pl.add_argument(
        "--select",
        action="append",
        default=[],
        metavar="AXIS=VALUE",
        help="fix an axis at a value (nearest), e.g. d=0.2 or sensors=3,4 (repeatable)",
    )
    pl.add_argument("--force", action="store_true", help="overwrite an existing image")
    add_json_argument(pl)
    pl.set_defaults(handler=_plot)


def _add_job_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--job`` and the options of the registered jobs (on first use of ``sweep``)."""
    from phdesign.sweep.jobs import JOBS

    parser.add_argument(
        "--job",
        choices=sorted(JOBS),
        default="spectrum",
        help="what to compute (default spectrum)",
    )
    for name, (option, job) in _job_options().items():
        flag = "--" + name.replace("_", "-")
        kwargs: dict[str, Any] = {"help": f"{option.help} (job {job})"}
        if option.kind == "choice":
            kwargs["choices"] = option.allowed
        else:
            kwargs["type"] = _TYPES[option.kind]
            kwargs["metavar"] = "N" if option.kind == "int" else "X"
        parser.add_argument(flag, dest=f"option_{name}", **kwargs)


def _named(items: list[str], flag: str, example: str = "l1=0.01:3:40:log") -> dict[str, str]:
    """Split ``NAME=SPEC`` items; each name once."""
    named: dict[str, str] = {}
    for item in items:
        name, sep, spec = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise SweepError(f"{flag} expects NAME=VALUE such as {example}; found {item!r}")
        if name in named:
            raise SweepError(f"{flag} {name} is given twice")
        named[name] = spec
    return named


def _sweep(args: argparse.Namespace) -> int:
    from phdesign.cli.common import parse_parameter_overrides
    from phdesign.sweep import describe, summarize
    from phdesign.sweep.execute import run

    grid = _named(args.grid, "--grid")
    param_grid = _named(args.param_grid, "--param-grid")
    fixed = parse_parameter_overrides(args.param)
    both = sorted(set(fixed) & set(param_grid))
    if both:
        raise SweepError(f"parameter {both[0]} is given by --param and --param-grid; give it once")
    model = load_model(args)
    options = {
        name: getattr(args, f"option_{name}")
        for name in _job_options()
        if getattr(args, f"option_{name}") is not None
    }
    description = describe(
        model,
        job=args.job,
        sensors=args.sensors,
        sensor_sets=args.sensor_sets,
        gain=args.gain,
        grid=grid,
        param_grid=param_grid,
        options=options,
    )
    dataset = run(
        description,
        output=args.output,
        resume=args.resume,
        force=args.force,
        scheduler=args.scheduler,
        workers=args.workers,
        chunk_size=args.chunk_size,
        progress=False if args.no_progress else None,
        notify=note,
    )
    summary = summarize(dataset)
    return emit_result(args, summary)


def _plot(args: argparse.Namespace) -> int:
    from phdesign.plots import check_plot_path, save_figure
    from phdesign.plots.sweep import plot_sweep
    from phdesign.sweep import open_sweep

    check_plot_path(args.output, args.force)
    select = _named(args.select, "--select", "d=0.2")
    dataset = open_sweep(args.input)
    names = [str(n) for n in dataset.data_vars]
    figure = args.figure or (names[0] if names else None)
    fig = plot_sweep(dataset, figure, select=select)
    save_figure(fig, args.output, args.force)
    if args.json:
        emit_json({"input": args.input, "output": args.output, "figure": figure, "select": select})
    else:
        emit(f"wrote {args.output}: {figure} of {args.input}")
    return 0
