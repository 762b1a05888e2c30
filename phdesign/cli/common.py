"""Arguments and output helpers shared by the commands."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from phdesign.errors import ParameterError

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.model import BCPHS

__all__ = [
    "add_json_argument",
    "add_model_argument",
    "emit",
    "emit_json",
    "load_model",
    "parse_parameter_overrides",
    "write_output",
]


def add_model_argument(parser: argparse.ArgumentParser) -> None:
    """Add MODEL (built-in name or TOML path) and the repeatable ``--param name=value``."""
    parser.add_argument("model", metavar="MODEL", help="built-in model name or TOML file path")
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="override a parameter's default value (repeatable)",
    )


def add_json_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--json``: print machine-readable JSON instead of a table."""
    parser.add_argument(
        "--json",
        action="store_true",
        help="print JSON instead of text (keys: see the command-line reference)",
    )


def parse_parameter_overrides(items: list[str]) -> dict[str, str]:
    """Split ``name=value`` items; values stay text and are checked by the model."""
    overrides: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise ParameterError(f"--param expects NAME=VALUE; found {item!r}")
        if name in overrides:
            raise ParameterError(f"--param {name} is given twice")
        overrides[name] = value
    return overrides


def load_model(args: argparse.Namespace) -> BCPHS:
    """Load MODEL (a built-in name, else a TOML file, :func:`phdesign.load`); apply ``--param``."""
    from phdesign.models import load

    overrides = parse_parameter_overrides(getattr(args, "param", []))
    return load(args.model, overrides or None)


def emit(text: str) -> None:
    """Print ``text`` on stdout."""
    sys.stdout.write(text if text.endswith("\n") else text + "\n")


def emit_json(value: Any) -> None:
    """Print ``value`` as JSON; sympy values become exact strings."""
    from phdesign.io import dumps_json

    emit(dumps_json(value))


def write_output(path: str, text: str | bytes, force: bool) -> None:
    """Write an output file atomically, refusing to overwrite unless ``force``."""
    from phdesign.io import atomic_write

    atomic_write(path, text, force=force)
