"""Command ``classify``: which proposition a sensor set and gain satisfy.

``phdesign classify MODEL [--sensors 3,4 | --cm '[[..]]'] [--gain ...] [--json]``
classifies one design; ``--all-sensors`` classifies every subset of the outputs.
Printing only: the mathematics lives in :mod:`phdesign.symbolic.classify` and
:mod:`phdesign.symbolic.search`.
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
)
from phdesign.errors import ObserverError
from phdesign.symbolic.expressions import format_number

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
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
    add_observer_arguments(parser)
    parser.add_argument(
        "--all-sensors",
        action="store_true",
        help="classify every non-empty subset of the outputs (gains: identity or --gain)",
    )
    parser.add_argument(
        "--method",
        choices=("auto", "exact", "float"),
        default="auto",
        help="how kappa* is computed (the decision is always exact); default auto",
    )
    add_json_argument(parser)
    parser.set_defaults(handler=_classify)


def _classify(args: argparse.Namespace) -> int:
    model = load_model(args)
    if args.all_sensors:
        if args.sensors is not None or args.cm is not None:
            raise ObserverError("--all-sensors tries every sensor set; drop --sensors/--cm")
        return _search(args, model)
    matrices = observer_matrices(args, model)
    if matrices is None:
        raise ObserverError("classify needs --sensors, --cm or --all-sensors")
    from phdesign.symbolic.classify import classify

    result = classify(model, *matrices, method=args.method)
    if args.json:
        emit_json(result.to_json_dict())
    else:
        emit(_table(result))
    return 0


def _text(x: Any) -> str:
    return "—" if x is None else str(x)


def _table(result: Any) -> str:
    model = result.model
    sensors = "; ".join(
        " + ".join(f"{c}·y{j + 1}" if c != 1 else f"y{j + 1}" for j, c in enumerate(row) if c != 0)
        for row in result.C_m.tolist()
    )
    lines = [
        f"model {model.name}: N = {model.order}, n = {model.size}",
        f"sensors: {sensors}",
        f"gain L = {result.L.tolist()}",
    ]
    if model.feedback is not None:  # the plant's own dampers: part of the error boundary
        closed = ", ".join(f"u{i}" for i in model.feedback.inputs)
        lines.append(
            f"plant feedback: {closed} = -K y (K = {model.feedback.gain.tolist()}); "
            "sensors index the remaining outputs"
        )
    if result.assumption is not None:
        if result.assumption.holds:
            parts = "; ".join(p.label(model.state_names) for p in result.assumption.partitions)
            lines.append(f"Assumption 3.1 holds: {parts}")
        else:
            lines.append(f"Assumption 3.1 fails: {result.assumption.reason}")
    lines.append("")
    header = f"{'prop':<5} {'var':<3} {'holds':<6} {'κ*':<28} right-hand side / reason"
    lines.append(header)
    lines.append("-" * len(header))
    for r in result.results:
        holds = "n/a" if not r.applicable else ("yes" if r.holds else "no")
        if r.holds and r.unbounded:
            kappa = "unbounded"
        elif r.holds:
            kappa = _text(r.kappa if r.kappa is not None else f"{r.kappa_float:.6g}")
        else:
            kappa = "—"
        if len(kappa) > 28:
            kappa = format_number(r.kappa if r.kappa is not None else r.kappa_float)
        lines.append(f"{r.proposition:<5} {r.variant:<3} {holds:<6} {kappa:<28} {r.rhs}")
        notes = []
        if not r.applicable or not r.holds:
            notes.append(r.reason)
        else:
            if r.kappa is not None and len(str(r.kappa)) > 28:
                notes.append(f"κ* = {r.kappa}")
            if r.conditions:
                notes.append(r.conditions)
        if r.partition is not None and r.applicable:
            notes.append(f"partition {r.partition.label(model.state_names)}")
        if notes:
            lines.append(f"{'':<45}↳ {'; '.join(notes)}")
    lines.append("")
    best = result.best
    tail = ""
    if best is not None:
        tail = f" (best: Proposition {best.proposition} variant {best.variant})"
    lines.append(f"verdict: {result.verdict}{tail}")
    return "\n".join(lines)


def _progress_bar() -> Any:
    if not sys.stderr.isatty():
        return None

    def show(done: int, total: int) -> None:
        width = 30
        filled = int(width * done / total)
        end = "\n" if done >= total else ""
        sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total}{end}")
        sys.stderr.flush()

    return show


def _search(args: argparse.Namespace, model: Any) -> int:
    from phdesign.symbolic.search import search_sensors

    found = search_sensors(model, gain=args.gain, progress=_progress_bar())
    if args.json:
        emit_json(found.to_json_dict())
        return 0
    lines = [
        f"model {found.model}: N = {found.order}, n = {found.size}, "
        f"{len(found.subsets)} sensor sets, diagonal gains {', '.join(found.gains)}",
        "",
        f"{'sensors':<24} {'verdict':<13} {'best':<7} κ*",
    ]
    for s in found.subsets:
        kappa = "unbounded" if s.unbounded else ("—" if s.kappa is None else f"{s.kappa:.6g}")
        sensors = ",".join(map(str, s.sensors))
        lines.append(f"{sensors:<24} {s.verdict:<13} {_text(s.best):<7} {kappa}")
    lines.append("")
    for verdict, sets in found.minimal.items():
        shown = ", ".join("{" + ",".join(map(str, s)) + "}" for s in sets) or "none"
        lines.append(f"minimal {verdict} sets: {shown}")
    emit("\n".join(lines))
    return 0
