"""Commands ``spectrum``, ``simulate`` and ``tune`` (numeric backend front end).

Argument parsing and printing only; the numbers come from the design objects
(:class:`phdesign.Observer`, :class:`phdesign.Plant`), imported inside the handlers so that
the command line starts without numpy-heavy code.

Initial states (``--x0``, ``--xhat0``) are comma-separated ``name: expression`` items:
a state name of the model (``x1``, ``x2``, ... always work, as do the model's own state
names) or an effort ``e1``, ``e2``, ... (then x = H⁻¹ e), and an expression in ``z`` and
the model's parameters, e.g. ``--x0 'x1: 0, x2: z - 0.9'`` or ``--x0 'e1: sin(pi*z)'``.
Components not mentioned are zero.  A coupled model's boundary states are named by their
labels or ``<name>.x<i>``, with a number or an expression in the parameters:
``--x0 'x1: sin(pi*z), mass momentum: 0.5'``.  Expressions go through the symbolic layer's safe
parser: user text is never evaluated.
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
    non_negative_int,
    run_outputs,
    simulation_text,
    split_items,
    warn,
)
from phdesign.cli.design_arguments import add_observer_arguments, observer_from_args
from phdesign.cli.export_command import add_sampling_arguments, sampling_options
from phdesign.cli.noise_commands import (
    add_noise_tuning_arguments,
    add_stochastic_arguments,
    noise_options,
    noise_tuning,
)
from phdesign.core.defaults import current
from phdesign.core.errors import NumericError

__all__ = ["register"]

#: Local searches of ``tune`` (the library's default is 3; two suffice from the grid).
TUNE_STARTS = 2


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the numeric commands."""
    _add_spectrum(subparsers)
    _add_modes(subparsers)
    _add_simulate(subparsers)
    _add_tune(subparsers)


def _add_spectrum(subparsers: argparse._SubParsersAction) -> None:
    sp = subparsers.add_parser(
        "spectrum",
        help="converged spectral abscissa of the plant (u = 0) or of the error system",
    )
    _add_spectrum_options(sp, "rightmost eigenvalues to report")
    sp.set_defaults(handler=_spectrum)


def _add_modes(subparsers: argparse._SubParsersAction) -> None:
    md = subparsers.add_parser(
        "modes",
        help="modal table: the resolved modes by frequency (natural frequency, damping "
        "ratio, decay rate) of the plant (u = 0) or of the error system",
    )
    _add_spectrum_options(md, "modes to list, lowest frequency first")
    md.set_defaults(handler=_modes)


def _add_spectrum_options(sp: argparse.ArgumentParser, count_help: str) -> None:
    """Add the options ``spectrum`` and ``modes`` share (``count_help`` says what --count is)."""
    add_model_argument(sp)
    add_observer_arguments(sp, required=True)
    table = current()
    add_discretization_arguments(sp, "default: the first of the refinement pairs")
    sp.add_argument(
        "--max-resolution",
        type=int,
        metavar="N",
        help="largest resolution the refinement may reach (default: "
        f"{table.describe('spectrum_max')})",
    )
    sp.add_argument(
        "--tol",
        type=float,
        help="required accuracy of the abscissa, relative to the problem's rate "
        f"(default: {table.describe('abscissa_tol')})",
    )
    sp.add_argument(
        "--count",
        type=int,
        default=table.spectrum.count,
        help=count_help + "; default: %(default)s",
    )
    add_json_argument(sp)
    add_quiet_argument(sp)


def _add_simulate(subparsers: argparse._SubParsersAction) -> None:
    sim = subparsers.add_parser(
        "simulate", help="simulate the plant (and the observer with --sensors/--cm)"
    )
    table = current()
    add_model_argument(sim)
    add_observer_arguments(sim)
    add_discretization_arguments(sim, f"default: {table.describe('resolution')}")
    sim.add_argument(
        "--x0",
        metavar="EXPRS",
        help="plant initial state, e.g. 'x1: 0, x2: z - 0.9' (a boundary system's states by "
        "name, e.g. 'mass momentum: 0.5'); default zero (then every series is zero: a "
        "warning says so)",
    )
    sim.add_argument("--xhat0", metavar="EXPRS", help="observer initial state; default zero")
    run = table.simulation
    sim.add_argument(
        "--t-end",
        type=float,
        default=run.t_end,
        metavar="T",
        help="final time; default: %(default)s",
    )
    sim.add_argument(
        "--samples",
        type=int,
        default=run.samples,
        help="output samples on [0, T]; default: %(default)s",
    )
    sim.add_argument(
        "--scheme",
        choices=("expm", "midpoint"),
        default=run.scheme,
        help="time stepping: exact matrix exponential or implicit midpoint; default: %(default)s",
    )
    sim.add_argument(
        "--u", metavar="EXPRS", help="plant inputs in t, e.g. 'u2: sin(2*t)'; default zero"
    )
    sim.add_argument(
        "--w",
        metavar="EXPRS",
        help="disturbances in t, which the observer does not know: w1..wq on the columns of "
        "the model's [disturbances] B, u<j> on its inputs marked unknown, e.g. "
        "'w1: sin(3*t)'; default zero",
    )
    sim.add_argument(
        "--tol",
        type=float,
        default=run.tol,
        help="midpoint: largest estimated error of the states, relative to their largest "
        "energy norm; the substeps are chosen to meet it; default: %(default)s",
    )
    add_simulation_outputs(sim)
    add_sampling_arguments(sim)  # --dt, --sampler, --observer-resolution (export command)
    add_stochastic_arguments(sim)
    add_quiet_argument(sim)
    sim.set_defaults(handler=_simulate)


def _add_tune(subparsers: argparse._SubParsersAction) -> None:
    tn = subparsers.add_parser("tune", help="observer gain minimizing the converged abscissa")
    add_model_argument(tn)
    add_observer_arguments(tn, gain=False)
    tn.add_argument("--full", action="store_true", help="full L instead of positive diagonal")
    # None: not given (the noise-aware tuning refuses them), then the defaults below
    tn.add_argument(
        "--starts",
        type=int,
        help=f"local searches, from the best points of the grid; default: {TUNE_STARTS}",
    )
    tn.add_argument(
        "--seed",
        type=non_negative_int,
        help="seed of the random grid (more than 625 points: five or more sensors); default: 0",
    )
    tn.add_argument(
        "--robust",
        metavar="PCT",
        help="minimize the worst abscissa over a box of gains, e.g. '5%%' (or 0.05) for ±5 %%",
    )
    add_noise_tuning_arguments(tn)
    add_json_argument(tn)
    add_quiet_argument(tn)
    tn.set_defaults(handler=_tune)


def _spectrum(args: argparse.Namespace) -> int:
    return emit_result(args, _spectrum_report(args, "spectrum"))


def _modes(args: argparse.Namespace) -> int:
    return emit_result(args, _spectrum_report(args, "modes").modes(count=args.count))


def _spectrum_report(args: argparse.Namespace, command: str) -> Any:
    """Return the spectrum report of the plant, or of the error system with sensors."""
    from phdesign.design.plant import Plant

    check_positive("--resolution", args.resolution)
    check_positive("--tol", args.tol)
    check_positive("--count", args.count)
    check_positive("--max-resolution", args.max_resolution)
    model = load_model(args)
    observer = observer_from_args(
        args, model, command=command, method=args.method, resolution=args.resolution
    )
    # the error system of the observer, or the plant with u = 0 without sensors
    design = observer or Plant(model, method=args.method, resolution=args.resolution)
    return design.spectrum(max_resolution=args.max_resolution, tol=args.tol, count=args.count)


def _simulate(args: argparse.Namespace) -> int:
    import numpy as np

    from phdesign import SimulationOptions
    from phdesign.design.observer import Plant

    check_positive("--resolution", args.resolution)
    check_positive("--t-end", args.t_end)
    check_positive("--tol", args.tol)
    if args.samples < 2:
        raise NumericError(f"--samples must be at least 2; found {args.samples}")
    model = load_model(args)
    observer = observer_from_args(
        args, model, default_gain=1, method=args.method, resolution=args.resolution
    )
    if args.xhat0 and observer is None:
        raise NumericError("--xhat0 needs an observer: give --sensors or --cm")
    plant = (
        observer.plant if observer is not None else Plant(model, {}, args.method, args.resolution)
    )
    # read the initial states and inputs before the (possibly long) simulation
    x0 = plant.initial_state(args.x0, "x0")
    xhat0 = plant.initial_state(args.xhat0, "xhat0")
    u = plant.input_signal(args.u, observed=observer is not None)
    # how to run: a sampled or lower-order observer (--dt, --sampler,
    # --observer-resolution), a noisy run (--noise-intensity, --input-noise), else the
    # continuous noiseless one; the design object picks the simulator from the options
    options = SimulationOptions(
        t_end=args.t_end,
        samples=args.samples,
        scheme=args.scheme,
        tol=args.tol,
        at=None if args.at is None else split_items(args.at),
        **sampling_options(args, observed=observer is not None),
        **noise_options(args),
    )
    with run_outputs(args) as commit:
        with np.errstate(all="ignore"):  # an overflow is refused below, with one line
            if observer is not None:
                res = observer.simulate(x0, xhat0=xhat0, u=u, w=args.w, options=options)
            else:
                res = plant.simulate(x0, u=u, w=args.w, options=options)
        check_finite_series(res)
        commit(simulation_text(args, model.name, res), res)
    for warning in (*_notices(args, observer), *res.warnings):
        warn(warning)
    return 0


def _notices(args: argparse.Namespace, observer: Any) -> list[str]:
    """Return what a run left to its defaults that the user may not have meant."""
    notices = []
    driven = any(
        getattr(args, name, None)
        for name in ("u", "w", "noise_intensity", "input_noise", "disturbance_noise")
    )
    if args.x0 is None and not driven:  # at rest and undriven: every series is zero
        notices.append(
            "no --x0 given: the plant starts at rest (x0 = 0), so without an input every "
            "series is zero"
        )
    if observer is not None and args.gain is None:
        notices.append("no --gain given: the observer uses L = I (--gain 1)")
    return notices


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


def _tune(args: argparse.Namespace) -> int:
    if (noisy := noise_tuning(args)) is not None:  # --max-rms / --objective rms
        return noisy
    starts = TUNE_STARTS if args.starts is None else args.starts
    check_positive("--starts", starts)
    robust = _robust_fraction(args.robust)
    model = load_model(args)
    observer = observer_from_args(args, model)  # argparse requires --sensors or --cm here
    tuned = observer.tune(
        full=args.full, starts=starts, seed=0 if args.seed is None else args.seed, robust=robust
    )
    return emit_result(args, tuned.tuning)
