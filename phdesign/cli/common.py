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
    "non_negative_int",
    "parse_parameter_overrides",
    "printable",
    "warn",
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


#: Characters that would act on a terminal (escape sequences, bidirectional overrides):
#: printed escaped, so a model named "\x1b[2J" cannot clear the screen.
_CONTROL = {
    c: f"\\x{c:02x}" if c < 0x100 else f"\\u{c:04x}"
    for c in (
        *range(0x20),
        0x7F,
        *range(0x80, 0xA0),
        *range(0x202A, 0x202F),
        *range(0x2066, 0x206A),
    )
    if chr(c) not in "\n\t"
}


def printable(text: str) -> str:
    r"""Return ``text`` with terminal control characters escaped (``\x1b`` for ESC).

    Examples
    --------
    >>> printable("beam\x1b[2J")
    'beam\\x1b[2J'
    """
    return text.translate(_CONTROL)


def emit(text: str) -> None:
    """Print ``text`` on stdout (terminal control characters escaped)."""
    text = printable(text)
    sys.stdout.write(text if text.endswith("\n") else text + "\n")


def warn(message: str) -> None:
    """Print one ``phdesign: warning: ...`` line on stderr."""
    print(f"phdesign: warning: {printable(' '.join(message.split()))}", file=sys.stderr)


def emit_json(value: Any) -> None:
    """Print ``value`` as strict JSON (phdesign's one JSON writer); sympy values are text."""
    from phdesign.io import dumps_json

    emit(dumps_json(value))


def write_output(path: str, text: str | bytes, force: bool) -> None:
    """Write an output file atomically, refusing to overwrite unless ``force``."""
    from phdesign.io import atomic_write

    atomic_write(path, text, force=force)


def non_negative_int(text: str) -> int:
    """Read an integer >= 0 for argparse (a usage error names the option)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer; found {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a non-negative integer; found {value}")
    return value
