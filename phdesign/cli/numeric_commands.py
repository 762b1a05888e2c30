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
    sp.add_argument("--tol", type=float, help="required agreement of the abscissa")
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
    sim.add_argument(
        "--tol",
        type=float,
        default=1e-6,
        help="midpoint: largest estimated error of the states, relative to their largest "
        "energy norm (default 1e-6); the substeps are chosen to meet it",
    )
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
    tn.add_argument("--starts", type=int, default=6, help="number of starts")
    tn.add_argument("--seed", type=int, default=0, help="seed of the random starts")
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
    model, nm, C_m, L = _numeric_setup(args)
    rep = spectrum(
        nm, C_m, L, method=args.method, resolution=args.resolution, tol=args.tol, count=args.count
    )
    if args.json:
        out = {"model": model.name, **rep.to_dict()}
        emit_json(out)
        return 0
    lines = [f"model: {model.name}   system: {rep.system}   method: {rep.method}"]
    if rep.unbounded_below:
        lines.append("spectral abscissa: unbounded below (no eigenvalue converges)")
    else:
        lines.append(
            f"spectral abscissa: {rep.spectral_abscissa:.12g}   converged: {rep.converged}   "
            f"digits: {rep.digits:.1f}   resolved: {rep.n_resolved}/{rep.n_total} "
            f"at resolutions {rep.resolutions[0]}, {rep.resolutions[1]}"
        )
        lines.append("rightmost eigenvalues:")
        for z, c in zip(rep.rightmost, rep.condition_numbers, strict=False):
            lines.append(f"  {z.real:+.10g} {z.imag:+.10g}i   (condition {c:.3g})")
    lines += [f"warning: {w}" for w in rep.warnings]
    emit("\n".join(lines))
    return 0


def _simulate(args: argparse.Namespace) -> int:
    from phdesign.numeric.bridge import initial_state_function
    from phdesign.numeric.simulate import simulate

    _check_positive("--resolution", args.resolution)
    _check_positive("--t-end", args.t_end)
    _check_positive("--tol", args.tol)
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
        tol=args.tol,
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


def _tune(args: argparse.Namespace) -> int:
    from phdesign.numeric.bridge import gain_to_numeric, to_numeric
    from phdesign.numeric.tune import tune

    _check_positive("--starts", args.starts)
    model = load_model(args)
    nm = to_numeric(model)
    C_m = sensor_matrix_from_args(args, model)  # argparse requires --sensors or --cm here
    res = tune(nm, gain_to_numeric(C_m, "C_m"), full=args.full, starts=args.starts, seed=args.seed)
    if args.json:
        emit_json({"model": model.name, **res.to_dict()})
        return 0
    lines = [f"model: {model.name}"]
    lines.append("gain L = " + str(res.gain.round(8).tolist()))
    if res.spectral_abscissa is None:
        lines.append("spectral abscissa: unbounded below at this gain")
    else:
        lines.append(
            f"spectral abscissa: {res.spectral_abscissa:.10g}   converged: {res.converged}   "
            f"at coalescence: {res.at_coalescence}"
        )
    lines += [f"warning: {w}" for w in res.report.warnings]
    emit("\n".join(lines))
    return 0
