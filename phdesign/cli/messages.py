r"""The command line's words for the library's: each argument a message names becomes its option.

A library user has no flags, so the library's messages name arguments as Python spells
them (:mod:`phdesign.core.errors`): at the head of a message (``tol must be a finite
positive number``, ``gain: entry 2 ...``) or as code in backquotes (```reduction='none'```,
```force=True```, ```x0```).  The command line prints every error and warning through
:func:`with_options`, which writes each argument the running command has an option for as
that option: ``--tol must be ...``, ``--reduce none``, ``--force``, ``--x0``.  The table comes
from the command's own parser (:func:`option_table`), so an option is named as that
command spells it (``--noise-intensity`` in ``simulate``, ``--intensity`` in ``noise``).

Examples
--------
>>> table = {"reduction": "--reduce", "force": "--force", "gain": "--gain", "u": "--u"}
>>> with_options("use `reduction='none'` or pass `force=True`", table)
'use --reduce none or pass --force'
>>> with_options("gain: entry 2 must be positive; `u` drives the others", table)
'--gain: entry 2 must be positive; --u drives the others'
>>> with_options("give `parameters={'E': ...}`", {"parameters": "--param"})
'give --param E=...'
>>> with_options("raise `max_resolution`", {})  # no such option here: the library's words
'raise max_resolution'
"""

from __future__ import annotations

import argparse
import re

__all__ = ["option_table", "translated", "use", "with_options"]

#: Library arguments whose option has another name (argument -> the option's ``dest``).
ALIASES = {
    "reduction": "reduce",
    "parameters": "param",
    "C_m": "cm",
    "input_intensity": "input_noise",
    "disturbance_intensity": "disturbance_noise",
    "points": "at",
}

#: An argument at the head of a message: ``tol must be ...``, ``gain: ...``.
_LEADING = re.compile(r"^(\w+)(?=:|\s+must\b)")
#: An argument as code: ```x0```, ```reduction='none'```, ```force=True```.
_CODE = re.compile(r"`(\w+)(?:=([^`]*))?`")
#: A mapping value of one entry, ``{'E': ...}``: an option of ``NAME=VALUE`` items.
_ITEM = re.compile(r"^\{'(\w+)': (.*)\}$")


#: The running command's table (:func:`use`); empty before a command is parsed.
_OPTIONS: dict[str, str] = {}


def use(options: dict[str, str]) -> None:
    """Make ``options`` the table :func:`translated` applies (one command line runs at a time)."""
    _OPTIONS.clear()
    _OPTIONS.update(options)


def translated(message: str, leading: bool = True) -> str:
    """Return ``message`` in the running command's option names (:func:`with_options`)."""
    return with_options(message, _OPTIONS, leading)


def option_table(parser: argparse.ArgumentParser, args: argparse.Namespace) -> dict[str, str]:
    """Return ``{argument: option}`` for the command that ``args`` ran (its subcommand's parser).

    Every option is listed under its ``dest`` (``t_end`` -> ``--t-end``) and under the
    library arguments of :data:`ALIASES`; ``C_m`` is the option that gave the sensors
    (``--sensors`` or ``--cm``).
    """
    parser = _command_parser(parser, args)
    table: dict[str, str] = {}
    for action in parser._actions:
        long = [o for o in action.option_strings if o.startswith("--")]
        if long:
            table.setdefault(action.dest, long[0])
    for argument, dest in ALIASES.items():
        if dest in table:
            table.setdefault(argument, table[dest])
    if getattr(args, "sensors", None) is not None and "sensors" in table:
        table["C_m"] = table["sensors"]
    return table


def _command_parser(
    parser: argparse.ArgumentParser, args: argparse.Namespace
) -> argparse.ArgumentParser:
    """Return the parser of the (sub)command ``args`` ran (``loop spectrum``: its own)."""
    while True:
        commands = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        name = getattr(args, commands[0].dest, None) if commands else None
        if name is None:
            return parser
        parser = commands[0].choices[name]


def with_options(message: str, options: dict[str, str], leading: bool = True) -> str:
    """Return ``message`` with the arguments it names written as their options.

    ``leading``: also an argument at the head of the message (not for a model file's
    errors, which name the file's keys: ``order must be ...`` is no ``--order``).
    """
    if leading:
        match = _LEADING.match(message)
        if match and match.group(1) in options:
            message = options[match.group(1)] + message[match.end() :]
    return _CODE.sub(lambda m: _option(m.group(1), m.group(2), options), message)


def _option(argument: str, value: str | None, options: dict[str, str]) -> str:
    """``--reduce none`` for ``reduction='none'``; the library's words without an option."""
    if argument not in options:
        return argument if value is None else f"{argument}={value}"
    flag = options[argument]
    if value is None or value == "True":
        return flag
    item = _ITEM.match(value)
    if item:
        return f"{flag} {item.group(1)}={item.group(2)}"
    if value.startswith("[") and value.endswith("]") and "[" not in value[1:]:
        return f"{flag} {','.join(v.strip() for v in value[1:-1].split(','))}"
    return f"{flag} {value.strip(chr(39) + chr(34))}"
