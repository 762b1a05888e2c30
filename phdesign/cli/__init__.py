"""The ``phdesign`` command line: argument parsing and printing only.

Each command lives in a module of this package that exposes ``register(subparsers)``;
the heavy numeric imports happen inside the command handlers, so ``phdesign ports``
and ``phdesign classify`` start without numpy-heavy backends, control or matplotlib.
What a command's options need from a package of its own (the sweep's job registry) is
added when that command is parsed or its help is shown (:meth:`_Parser.defer`), so
building the parser imports no command's package.

Exit status: 0 on success, 2 on bad input with exactly one line on stderr
(``phdesign: error: ...``), never a traceback.  Bad input is what phdesign's own errors
(:class:`~phdesign.core.errors.PhdesignError`) report; any other exception is a bug and is
not disguised as bad input.  The library's messages name its arguments; every error and
warning is printed with the running command's option names instead
(:mod:`phdesign.cli.messages`).  A long command shows its stages on one line of stderr
when it is a terminal, off with ``--quiet`` and never with ``--json``
(:func:`~phdesign.cli.common.progress_display`).
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Callable, Sequence
from typing import Any

from phdesign.cli import messages
from phdesign.cli.common import pause_collection, progress_display, resume_collection
from phdesign.cli.design_arguments import join_negative_values
from phdesign.core.errors import ModelError, ModelFileError, PhdesignError, PortError

__all__ = ["build_parser", "main", "run"]

#: The module that registers each command, in the order of ``phdesign --help``.  A run
#: of one command builds only its own module's parsers (argparse's option tables of the
#: other commands are a tenth of ``phdesign ports``'s start); help and unknown commands
#: build them all.
COMMAND_MODULES = {
    "models": "phdesign.cli.model_commands",
    "show": "phdesign.cli.model_commands",
    "ports": "phdesign.cli.model_commands",
    "classify": "phdesign.cli.classify_command",
    "spectrum": "phdesign.cli.numeric_commands",
    "modes": "phdesign.cli.numeric_commands",
    "simulate": "phdesign.cli.numeric_commands",
    "tune": "phdesign.cli.numeric_commands",
    "noise": "phdesign.cli.noise_commands",
    "tradeoff": "phdesign.cli.noise_commands",
    "gain": "phdesign.cli.gain_command",
    "export": "phdesign.cli.export_command",
    "certify": "phdesign.cli.certify_command",
    "check": "phdesign.cli.certify_command",
    "loop": "phdesign.cli.loop_command",
    "sweep": "phdesign.cli.sweep_command",
    "plot": "phdesign.cli.sweep_command",
}


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line and exit status 2.

    Options whose definition needs a package of its own are added by :meth:`defer`, when
    the command is parsed or its help or usage is shown, never when the parser is built.
    Negative values are glued to their options before parsing
    (:func:`~phdesign.cli.design_arguments.join_negative_values`).
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._deferred: list[Callable[[argparse.ArgumentParser], None]] = []

    def defer(self, add: Callable[[argparse.ArgumentParser], None]) -> None:
        """Call ``add(self)`` to add options before this parser is first used."""
        self._deferred.append(add)

    def complete(self) -> None:
        """Add the deferred options now (the documentation's reference lists them all)."""
        while self._deferred:
            self._deferred.pop(0)(self)

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        self.complete()
        argv = list(sys.argv[1:] if args is None else args)
        return super().parse_known_args(join_negative_values(argv, self), namespace)

    def format_usage(self) -> str:
        self.complete()
        return super().format_usage()

    def format_help(self) -> str:
        self.complete()
        return super().format_help()

    def error(self, message: str) -> None:  # type: ignore[override]
        command = self.prog.removeprefix("phdesign").strip()
        raise _UsageError(f"{command}: {message}" if command else message)


class _UsageError(Exception):
    pass


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """Return the parser with every available command registered.

    With ``command`` (a key of :data:`COMMAND_MODULES`) only the module that registers it
    is imported and registered: the parser of a run of that command.
    """
    parser = _Parser(
        prog="phdesign",
        description="Boundary observers for boundary-controlled port-Hamiltonian systems.",
    )
    from phdesign import __version__

    parser.add_argument("--version", action="version", version=f"phdesign {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    subparsers.required = True
    if command in COMMAND_MODULES:
        names = [COMMAND_MODULES[command]]
    else:
        names = list(dict.fromkeys(COMMAND_MODULES.values()))
    for name in names:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as error:
            if error.name != name:  # a missing dependency is a real failure
                raise
            continue
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None, *, reraise: bool = False) -> int:
    """Run the command line and return the exit status.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default: ``sys.argv[1:]``).
    reraise : bool
        Let library errors propagate instead of printing them (for tests that check
        which exception the library raises behind a message).
    """
    messages.use({})
    try:
        arguments = sys.argv[1:] if argv is None else list(argv)
        parser = build_parser(arguments[0] if arguments else None)
        args = parser.parse_args(arguments)
        messages.use(messages.option_table(parser, args))
        with progress_display(args):  # the stages of a long run, on a terminal's stderr
            return int(args.handler(args) or 0)
    except _UsageError as error:
        return _fail(str(error))
    except PhdesignError as error:  # bad input; any other exception is a bug and surfaces
        if reraise:
            raise
        # a model file's errors name its keys (``order must be ...``), never an option
        leading = not isinstance(error, ModelError | ModelFileError | PortError)
        return _fail(messages.translated(str(error), leading))
    except OSError as error:
        return _fail(
            f"{error.strerror or error}: {error.filename}" if error.filename else str(error)
        )
    except KeyboardInterrupt:
        return _fail("interrupted")
    except RecursionError:
        return _fail("input is nested too deeply")


def _fail(message: str) -> int:
    from phdesign.cli.common import printable

    line = f"phdesign: error: {printable(' '.join(message.split()))}"
    print(line, file=sys.stderr)
    return 2


def run() -> None:
    """Console-script entry point (``phdesign``, ``python -m phdesign``).

    The garbage collector is paused while the command starts up, until its model is loaded
    (:func:`~phdesign.cli.common.pause_collection`).
    """
    pause_collection()
    try:
        status = main()
    finally:
        resume_collection()
    sys.exit(status)
