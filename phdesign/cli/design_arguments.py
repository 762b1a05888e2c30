"""The design options of the commands: ``--sensors``, ``--cm`` and ``--gain``.

The text of the options is read here, into plain Python (lists of indices, rows of numbers,
``"symbolic"``), and handed to :class:`phdesign.Observer`, whose validation every command
shares (so ``spectrum``, ``simulate`` and ``tune`` refuse what ``classify`` refuses).  The
library's messages name its arguments (``gain: ...``); the command line prints them with
the option the user typed (``--gain: ...``, :mod:`phdesign.cli.messages`).

Forms:

* ``--sensors 3,4``: the unit rows that pick y3 and y4 (1-based);
* ``--cm '[[0,0,1,0]]'``: C_m in full (JSON rows);
* ``--gain 0.1,1``: L = diag(0.1, 1); one value is used for every sensor;
  ``--gain '[[..]]'``: L in full; ``--gain symbolic``: positive symbols (classify only).
  Negative entries are accepted as written: ``--gain -1,1`` (refused as not positive
  definite, with that reason) is the same as ``--gain=-1,1``.
"""

from __future__ import annotations

import argparse
import re
from typing import Any

from phdesign.core.errors import ObserverError

__all__ = [
    "add_observer_arguments",
    "join_negative_values",
    "observer_from_args",
    "parse_gain_text",
    "parse_rows_text",
    "parse_sensors_text",
]


def add_observer_arguments(
    parser: argparse.ArgumentParser,
    *,
    symbolic: bool = False,
    gain: bool = True,
    required: bool = False,
) -> None:
    """Add ``--sensors`` / ``--cm`` (exclusive) and, with ``gain``, ``--gain``.

    ``symbolic`` says whether the command accepts ``--gain symbolic`` (classify does; the
    numeric commands need numbers); ``required`` whether sensors need an explicit gain.
    """
    group = parser.add_mutually_exclusive_group(required=not gain)
    group.add_argument(
        "--sensors", metavar="I,J", help="measured outputs, 1-based indices, e.g. 3,4"
    )
    group.add_argument("--cm", metavar="ROWS", help="C_m in full, e.g. '[[0,0,1,0]]'")
    if not gain:
        return
    forms = "'0.1,1' (diagonal, one value per sensor or one for all), '[[..]]' (full)"
    if symbolic:
        help_text = f"observer gain L: {forms} or 'symbolic' (positive symbols); default identity"
    elif required:
        help_text = f"observer gain L (required with --sensors/--cm): {forms}"
    else:
        help_text = f"observer gain L: {forms}; default identity (with a warning)"
    parser.add_argument("--gain", metavar="L", help=help_text)


def parse_sensors_text(text: str) -> list[int]:
    """Read ``"3,4"`` into ``[3, 4]`` (the indices are checked by the observer)."""
    from phdesign.symbolic.observer import parse_sensor_indices  # sympy: on first use

    return parse_sensor_indices(text, "--sensors")


def parse_rows_text(text: str, option: str) -> Any:
    """Read a JSON list of rows (``--cm``, ``--gain '[[..]]'``); the entries stay as given."""
    import json  # rows only: ``--sensors 3,4 --gain 0.1,1`` starts without it

    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise ObserverError(
            f"{option}: expected a JSON list of rows like [[0, 1], [1, 0]]; found {text!r} "
            f"({error.msg} at character {error.pos})"
        ) from None
    except RecursionError:
        raise ObserverError(f"{option}: the rows are nested too deeply") from None


def parse_gain_text(text: str, option: str = "--gain") -> Any:
    """Read ``--gain`` (or ``--feedback``): ``"symbolic"``, JSON rows, or diagonal entries."""
    text = str(text).strip()
    if text == "symbolic":
        return text
    if text.startswith("["):
        return parse_rows_text(text, option)
    return [p.strip() for p in text.split(",")]


def observer_from_args(
    args: argparse.Namespace,
    model: Any,
    *,
    default_gain: Any = None,
    command: str = "",
    method: str | None = None,
    resolution: int | None = None,
    unobserved: bool = False,
) -> Any:
    """Return the :class:`phdesign.Observer` of ``--sensors``/``--cm`` and ``--gain``.

    ``None`` without sensors (the plant alone).  ``default_gain`` is used when ``--gain``
    is absent (classify: the identity); without one, a ``command`` that needs a gain
    (spectrum, simulate) refuses sensors given without ``--gain``, and ``--gain`` without
    sensors is always refused.  ``method`` and ``resolution`` are the discretization.
    ``unobserved`` admits ``--cm '[]'`` (no sensors, no gain: classify only).
    """
    from phdesign.design.observer import Observer

    sensors = getattr(args, "sensors", None)
    cm = getattr(args, "cm", None)
    gain_text = getattr(args, "gain", None)
    if sensors is None and cm is None:
        if gain_text is not None:
            raise ObserverError("--gain needs --sensors or --cm to say which outputs are measured")
        return None
    observer = Observer(
        model,
        sensors=None if sensors is None else parse_sensors_text(sensors),
        C_m=None if cm is None else parse_rows_text(cm, "--cm"),
        method=method,
        resolution=resolution,
    )
    if observer.q == 0:  # C_m with no rows: classify certifies the plant's own dampers
        if gain_text is not None:
            observer.with_gain(parse_gain_text(gain_text))  # refused: no sensors, no gain
        if not unobserved:
            raise ObserverError(
                "--cm: no sensors ([]) is for classify, which certifies the plant by its own "
                "boundary dissipation; without --sensors/--cm, spectrum and simulate act on "
                "the plant"
            )
        return observer
    if gain_text is not None:
        return observer.with_gain(parse_gain_text(gain_text))
    if default_gain is not None:
        return observer.with_gain(default_gain)
    if command:
        raise ObserverError(
            f"{command} --sensors/--cm needs --gain: the gain L of the observer, e.g. --gain 1,1"
        )
    return observer


def join_negative_values(argv: list[str], parser: argparse.ArgumentParser) -> list[str]:
    """Write ``--gain -1,1`` as ``--gain=-1,1`` so that argparse takes the value.

    argparse reads a token that starts with ``-`` as an option unless it is a plain
    negative number; a value such as ``-1,1`` or ``-0.5,[..]`` is glued to the option that
    takes it (only options that take a value, so flags are never changed).
    """
    takes_value: set[str] = set()
    actions = list(parser._actions)
    while actions:
        action = actions.pop()
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                actions.extend(sub._actions)
        elif action.option_strings and action.nargs is None:
            takes_value.update(action.option_strings)
    out: list[str] = []
    i = 0
    while i < len(argv):
        token = argv[i]
        following = argv[i + 1] if i + 1 < len(argv) else ""
        if token in takes_value and re.match(r"-[\d.]", following):
            out.append(f"{token}={following}")
            i += 2
            continue
        out.append(token)
        i += 1
    return out
