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


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the model commands."""
    models = subparsers.add_parser("models", help="list the built-in models")
    add_json_argument(models)
    models.set_defaults(handler=_models)

    show = subparsers.add_parser(
        "show", help="show a model: a summary, or the model file with --toml"
    )
    add_model_argument(show)
    show.add_argument(
        "--toml",
        action="store_true",
        help="write the model as a TOML model file (read back exactly)",
    )
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
    from phdesign.io import dumps_json, model_to_dict, model_to_toml

    model = load_model(args)
    if args.json:
        text = dumps_json(model_to_dict(model))
    elif args.toml:
        text = model_to_toml(model)
    else:
        text = str(model)
    if args.output:
        write_output(args.output, text, force=args.force)
    else:
        emit(text)
    return 0


def _ports(args: argparse.Namespace) -> int:
    ports = load_model(args).ports
    if args.json:
        emit_json(ports.to_dict())
    else:
        emit(str(ports))
    return 0
