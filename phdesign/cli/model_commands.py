"""Commands ``models``, ``show`` and ``ports``."""

from __future__ import annotations

import argparse

from phdesign.cli.common import (
    add_json_argument,
    add_model_argument,
    emit,
    emit_json,
    load_model,
    write_output,
)

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Add the model commands."""
    models = subparsers.add_parser("models", help="list the built-in models")
    add_json_argument(models)
    models.set_defaults(handler=_models)

    show = subparsers.add_parser("show", help="show a model (as TOML with --toml)")
    add_model_argument(show)
    show.add_argument("--toml", action="store_true", help="write the model as a TOML file")
    show.add_argument("--output", "-o", metavar="FILE", help="write to FILE instead of stdout")
    show.add_argument("--force", action="store_true", help="overwrite FILE if it exists")
    add_json_argument(show)
    show.set_defaults(handler=_show)

    ports = subparsers.add_parser("ports", help="derive Q, W_B, W_C and check the identities")
    add_model_argument(ports)
    add_json_argument(ports)
    ports.set_defaults(handler=_ports)


def _models(args: argparse.Namespace) -> int:
    from phdesign.models import builtin_names, load_builtin

    rows = []
    for name in builtin_names():
        model = load_builtin(name)
        rows.append(
            {
                "name": name,
                "order": model.order,
                "size": model.size,
                "description": model.description,
            }
        )
    if args.json:
        emit_json(rows)
    else:
        emit(
            "\n".join(
                f"{r['name']:<16} N={r['order']} n={r['size']}  {r['description']}" for r in rows
            )
        )
    return 0


def _show(args: argparse.Namespace) -> int:
    from phdesign.io import model_to_dict, model_to_toml

    model = load_model(args)
    if args.json:
        from phdesign.io import dumps_json

        text = dumps_json(model_to_dict(model))
    else:
        text = model_to_toml(model)
        if not args.toml:
            text += "".join(f"# check: {c}\n" for c in model.checks)
    if args.output:
        write_output(args.output, text, force=args.force)
    else:
        emit(text)
    return 0


def _ports(args: argparse.Namespace) -> int:
    from phdesign.symbolic.expressions import format_expression
    from phdesign.symbolic.ports import IDENTITY_NAMES, derive_ports

    model = load_model(args)
    ports = derive_ports(model)
    identities = {key: float(ports.identities[key]) for key in IDENTITY_NAMES}
    closed = None
    if model.feedback is not None:  # the plant's own [feedback]: the closed ports too
        from phdesign.symbolic.feedback import closed_ports

        closed = closed_ports(model)
    if args.json:
        emit_json(
            {
                "model": model.name,
                "order": model.order,
                "size": model.size,
                "traces": [format_expression(s, model.interval) for s in ports.trace_vector],
                "Q": ports.Q,
                "W_B": ports.W_B,
                "W_C": ports.W_C,
                "identities": identities,
                "feedback": None if closed is None else closed.to_dict(),
            }
        )
        return 0
    import sympy

    lines = [
        f"model {model.name}: N = {model.order}, n = {model.size}",
        f"v = ({', '.join(format_expression(s, model.interval) for s in ports.trace_vector)})",
        "Q =",
        sympy.pretty(ports.Q),
        "W_B =",
        sympy.pretty(ports.W_B),
        "W_C =",
        sympy.pretty(ports.W_C),
        *(f"max |{key}| = {value:g}" for key, value in identities.items()),
    ]
    if closed is not None:
        lines.append(str(closed))
    emit("\n".join(lines))
    return 0
