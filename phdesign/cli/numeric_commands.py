"""Commands ``spectrum``, ``simulate`` and ``tune`` (numeric backend front end).

Argument parsing and printing only; the numbers come from :mod:`phdesign.numeric`,
imported inside the handlers so that the command line starts without numpy-heavy code.

Initial states (``--x0``, ``--xhat0``) are comma-separated ``name: expression`` items:
a state name of the model (``x1``, ``x2``, ... always work, as do the model's own state
names) or an effort ``e1``, ``e2``, ... (then x = H⁻¹ e), and an expression in ``z`` and
the model's parameters, e.g. ``--x0 'x1: 0, x2: z - 0.9'`` or ``--x0 'e1: sin(pi*z)'``.
Components not mentioned are zero.  Expressions go through the symbolic layer's safe
parser: user text is never evaluated.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from phdesign.cli.common import (
    add_json_argument,
    add_model_argument,
    add_observer_arguments,
    emit,
    emit_json,
    load_model,
    observer_matrices,
    sensor_matrix_from_args,
    write_output,
)
from phdesign.errors import NumericError

__all__ = ["register"]


def _add_discretization(parser: argparse.ArgumentParser, default_hint: str) -> None:
    parser.add_argument(
        "--method",
        choices=("galerkin", "fd"),
        default="galerkin",
        help="discretization: Legendre-Galerkin (default, spectral) or staggered finite "
        "differences (the paper's setting)",
    )
    parser.add_argument(
        "--resolution", type=int, metavar="N", help=f"degree / nodes per group ({default_hint})"
    )


def register(subparsers: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Add the numeric commands."""
    sp = subparsers.add_parser(
        "spectrum",
        help="converged spectral abscissa of the plant (u = 0) or of the error system",
    )
    add_model_argument(sp)
    add_observer_arguments(sp)
    _add_discretization(sp, "first of the refinement pairs")
    sp.add_argument(
        "--max-resolution",
        type=int,
        metavar="N",
        help="largest resolution the refinement may reach (default: 100-110 for Galerkin)",
    )
    sp.add_argument(
        "--tol",
        type=float,
        help="required accuracy of the abscissa, relative to the problem's rate "
        "(default 1e-10 Galerkin, 1e-3 FD)",
    )
    sp.add_argument("--count", type=int, default=6, help="rightmost eigenvalues to report")
    add_json_argument(sp)
    sp.set_defaults(handler=_spectrum)

    sim = subparsers.add_parser(
        "simulate", help="simulate the plant (and the observer with --sensors/--cm)"
    )
    add_model_argument(sim)
    add_observer_arguments(sim)
    _add_discretization(sim, "Galerkin 40, FD 70")
    sim.add_argument(
        "--x0", metavar="EXPRS", help="plant initial state, e.g. 'x1: 0, x2: z - 0.9'"
    )
    sim.add_argument("--xhat0", metavar="EXPRS", help="observer initial state (default zero)")
    sim.add_argument("--t-end", type=float, default=5.0, metavar="T", help="final time")
    sim.add_argument("--samples", type=int, default=501, help="output samples on [0, T]")
    sim.add_argument("--scheme", choices=("expm", "midpoint"), default="expm")
    fmt = sim.add_mutually_exclusive_group()
    fmt.add_argument("--csv", action="store_true", help="CSV output (the default)")
    fmt.add_argument("--json", action="store_true", help="JSON output")
    sim.add_argument("--output", "-o", metavar="FILE", help="write to FILE instead of stdout")
    sim.add_argument("--plot", metavar="FILE", help="also draw a summary figure to FILE")
    sim.add_argument("--force", action="store_true", help="overwrite existing files")
    sim.set_defaults(handler=_simulate)

    tn = subparsers.add_parser("tune", help="observer gain minimizing the converged abscissa")
    add_model_argument(tn)
    group = tn.add_mutually_exclusive_group(required=True)
    group.add_argument("--sensors", metavar="I,J", help="measured outputs, 1-based")
    group.add_argument("--cm", metavar="ROWS", help="C_m in full, e.g. '[[0,0,1,0]]'")
    tn.add_argument("--full", action="store_true", help="full L instead of positive diagonal")
    tn.add_argument(
        "--starts",
        type=int,
        default=2,
        help="local searches, from the best points of the grid (default 2)",
    )
    tn.add_argument(
        "--seed", type=int, default=0, help="seed of the random grid (more than 625 points)"
    )
    tn.add_argument(
        "--robust",
        metavar="PCT",
        help="minimize the worst abscissa over a box of gains, e.g. '5%%' (or 0.05) for ±5 %%",
    )
    add_json_argument(tn)
    tn.set_defaults(handler=_tune)


def _numeric_setup(args: argparse.Namespace) -> tuple[Any, Any, Any, Any]:
    """Return (model, NumericModel, C_m, L) with C_m/L as float arrays or None.

    ``--param`` is applied by :func:`load_model`; the bridge then substitutes defaults.
    """
    from phdesign.numeric.bridge import gain_to_numeric, to_numeric

    model = load_model(args)
    nm = to_numeric(model)
    obs = observer_matrices(args, model)
    if obs is None:
        return model, nm, None, None
    C_m, L = obs
    return model, nm, gain_to_numeric(C_m, "C_m"), gain_to_numeric(L, "L")


def _check_positive(name: str, value: float | int | None) -> None:
    if value is not None and not value > 0:
        raise NumericError(f"{name} must be positive; found {value}")


def _spectrum(args: argparse.Namespace) -> int:
    from phdesign.numeric.spectrum import spectrum

    _check_positive("--resolution", args.resolution)
    _check_positive("--tol", args.tol)
    _check_positive("--count", args.count)
    _check_positive("--max-resolution", args.max_resolution)
    _model, nm, C_m, L = _numeric_setup(args)
    rep = spectrum(
        nm,
        C_m,
        L,
        method=args.method,
        resolution=args.resolution,
        max_resolution=args.max_resolution,
        tol=args.tol,
        count=args.count,
    )
    if args.json:
        emit_json(rep.to_dict())
    else:
        emit(str(rep))
    return 0


def _simulate(args: argparse.Namespace) -> int:
    from phdesign.numeric.bridge import initial_state_function
    from phdesign.numeric.simulate import simulate

    _check_positive("--resolution", args.resolution)
    _check_positive("--t-end", args.t_end)
    if args.samples < 2:
        raise NumericError(f"--samples must be at least 2; found {args.samples}")
    model, nm, C_m, L = _numeric_setup(args)
    if args.xhat0 and C_m is None:
        raise NumericError("--xhat0 needs an observer: give --sensors or --cm")
    x0 = initial_state_function(args.x0, nm, model=model)
    xh0 = initial_state_function(args.xhat0, nm, model=model)
    # refuse unwritable or existing outputs before the (possibly long) simulation
    if args.output:
        from phdesign.io import check_output_path

        check_output_path(args.output, args.force)
    if args.plot:
        from phdesign.plots import check_plot_path

        check_plot_path(args.plot, args.force)
    res = simulate(
        nm,
        C_m,
        L,
        x0=x0,
        xhat0=xh0,
        t_end=args.t_end,
        samples=args.samples,
        method=args.method,
        resolution=args.resolution,
        scheme=args.scheme,
    )
    if args.json:
        import json

        text = json.dumps({"model": model.name, **res.to_dict()})
    else:
        text = res.to_csv()
    if args.output:
        write_output(args.output, text, args.force)
    else:
        emit(text)
    if args.plot:
        from phdesign.plots import plot_simulation

        plot_simulation(res, args.plot, force=args.force, title=model.name)
    for warning in res.warnings:
        print(f"phdesign: warning: {warning}", file=sys.stderr)
    return 0


def _robust_fraction(text: str | None) -> float | None:
    """``--robust``: '5%' or 0.05 for ±5 %."""
    if text is None:
        return None
    body = text.strip()
    percent = body.endswith("%")
    try:
        value = float(body[:-1] if percent else body)
    except ValueError:
        raise NumericError(
            f"--robust expects a percentage such as 5% or a fraction such as 0.05; found {text!r}"
        ) from None
    fraction = value / 100 if percent else value
    if not 0 < fraction < 1:
        raise NumericError(f"--robust must lie strictly between 0 % and 100 %; found {text!r}")
    return fraction


class _Progress:
    """A one-line progress display on a terminal, shown once a run passes 2 seconds."""

    DELAY = 2.0

    def __init__(self) -> None:
        import time

        self._clock = time.perf_counter
        self._start = self._clock()
        self._shown = 0

    def __call__(self, line: str) -> None:
        if self._clock() - self._start < self.DELAY:
            return
        text = f"{line}   ({self._clock() - self._start:.0f} s)"
        sys.stderr.write("\r" + text.ljust(self._shown))
        sys.stderr.flush()
        self._shown = len(text)

    def clear(self) -> None:
        if self._shown:
            sys.stderr.write("\r" + " " * self._shown + "\r")
            sys.stderr.flush()


def _tune(args: argparse.Namespace) -> int:
    from phdesign.numeric.bridge import gain_to_numeric, to_numeric
    from phdesign.numeric.tune import tune

    _check_positive("--starts", args.starts)
    robust = _robust_fraction(args.robust)
    model = load_model(args)
    nm = to_numeric(model)
    C_m = sensor_matrix_from_args(args, model)  # argparse requires --sensors or --cm here
    progress = _Progress() if sys.stderr.isatty() else None
    try:
        res = tune(
            nm,
            gain_to_numeric(C_m, "C_m"),
            full=args.full,
            starts=args.starts,
            seed=args.seed,
            robust=robust,
            progress=progress,
        )
    finally:
        if progress is not None:
            progress.clear()
    if args.json:
        emit_json(res.to_dict())
    else:
        emit(str(res))
    return 0
