"""Progress of long computations: stages reported as text, one display on a terminal.

A computation that can run for seconds says where it is with :func:`report`
(``"spectrum: pair (153, 230)"``); nothing happens unless a callback is in force, put
there by :func:`reporting` (the ``progress`` argument of the design objects does it, and
the command line does it for its long commands).  Stages nest: inside
``with stage("tradeoff: gain 3 of 40"):`` a report reads
``"tradeoff: gain 3 of 40 > spectrum: pair (24, 36)"``.  As the table of defaults in
force (:func:`~phdesign.core.defaults.using`), the callback in force belongs to this
thread or task: the workers of a sweep report nothing.

:class:`Display` is the one display: a line on stderr, redrawn in place, shown only once
a run has lasted ``delay`` seconds (the table of defaults' ``progress``, 2 s) and erased
when the run ends or anything else is printed (:func:`erase`).  It draws only on a
terminal: a redrawn line means nothing in a log file or a pipe, and the command line
promises scripts that stderr holds its ``phdesign: warning:`` and ``phdesign: error:``
lines and nothing else.

Examples
--------
>>> seen = []
>>> with reporting(seen.append):
...     with stage("tradeoff: gain 1 of 2"):
...         report("spectrum: pair (20, 30)")
>>> seen
['tradeoff: gain 1 of 2', 'tradeoff: gain 1 of 2 > spectrum: pair (20, 30)']
>>> report("nobody listens")  # no callback in force: nothing happens
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from functools import wraps
from typing import ParamSpec, TextIO, TypeVar

from phdesign.core.defaults import current
from phdesign.core.errors import ArgumentError

__all__ = ["Display", "Progress", "erase", "report", "reporting", "reports_progress", "stage"]

#: A progress callback: called with one line of text at each stage.
Progress = Callable[[str], None]

_CALLBACK: ContextVar[Progress | None] = ContextVar("phdesign_progress", default=None)
_STAGES: ContextVar[tuple[str, ...]] = ContextVar("phdesign_stages", default=())
#: What separates a stage from the stages it is inside.
SEPARATOR = " > "


@contextmanager
def reporting(progress: Progress | None) -> Iterator[None]:
    """Send the stages reported inside the block to ``progress`` (None: keep the one in force).

    Raises
    ------
    ArgumentError
        ``progress`` is neither None nor callable.
    """
    if progress is None:
        yield
        return
    if not callable(progress):
        raise ArgumentError(f"progress must be callable(text) or None; found {progress!r}")
    token = _CALLBACK.set(progress)
    try:
        yield
    finally:
        _CALLBACK.reset(token)


_P = ParamSpec("_P")
_R = TypeVar("_R")


def reports_progress(method: Callable[_P, _R]) -> Callable[_P, _R]:
    """Run ``method`` with its keyword argument ``progress`` in force (:func:`reporting`).

    The design objects' long methods take ``progress`` (a callback, or None) this way: the
    stages their computations report go to it, and the method's body never reads it.
    """

    @wraps(method)
    def run(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        with reporting(kwargs.get("progress")):  # type: ignore[arg-type]
            return method(*args, **kwargs)

    return run


def report(text: str) -> None:
    """Report a stage to the callback in force, after the stages it is inside."""
    callback = _CALLBACK.get()
    if callback is not None:
        callback(SEPARATOR.join((*_STAGES.get(), text)))


@contextmanager
def stage(text: str) -> Iterator[None]:
    """Report ``text``, and put it before every report inside the block."""
    report(text)
    token = _STAGES.set((*_STAGES.get(), text))
    try:
        yield
    finally:
        _STAGES.reset(token)


def erase() -> None:
    """Erase the line of the display in force, before other output is printed."""
    callback = _CALLBACK.get()
    if isinstance(callback, Display):
        callback.erase()


class Display:
    r"""One line on a terminal: the latest stage and the seconds elapsed, redrawn in place.

    Parameters
    ----------
    stream : text stream, optional
        Where to draw (default ``sys.stderr``).
    delay : float, optional
        Seconds after which the line first shows (default: the table's ``progress.delay``).
    interval : float, optional
        Least seconds between two drawings (default: the table's ``progress.interval``).
    terminal : bool, optional
        Whether ``stream`` is a terminal (default: ``stream.isatty()``); nothing is drawn
        elsewhere (module docstring).
    clock : callable, optional
        The clock, in seconds (default :func:`time.monotonic`).

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> show = Display(out, delay=0.0, interval=0.0, terminal=True, clock=lambda: 3.0)
    >>> show("tune: grid, 12 evaluations")
    >>> show.erase()
    >>> out.getvalue().split("\r")[1]
    'tune: grid, 12 evaluations (0 s)'
    """

    def __init__(
        self,
        stream: TextIO | None = None,
        *,
        delay: float | None = None,
        interval: float | None = None,
        terminal: bool | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        defaults = current().progress
        self.stream = sys.stderr if stream is None else stream
        self.delay = defaults.delay if delay is None else float(delay)
        self.interval = defaults.interval if interval is None else float(interval)
        if terminal is None:
            isatty = getattr(self.stream, "isatty", None)
            terminal = bool(isatty()) if callable(isatty) else False
        self.terminal = terminal
        self.clock = clock
        self.start = clock()
        self._drawn = 0  # characters on the line now
        self._last = -float("inf")

    def __call__(self, text: str) -> None:
        """Draw ``text`` (after the delay, at most once per interval, on a terminal only)."""
        now = self.clock()
        elapsed = now - self.start
        if not self.terminal or elapsed < self.delay or now - self._last < self.interval:
            return
        self._last = now
        line = f"{text} ({elapsed:.0f} s)"[: self._width()]
        self.stream.write("\r" + line.ljust(self._drawn))
        self.stream.flush()
        self._drawn = len(line)

    def erase(self) -> None:
        """Erase the line drawn, if any (it is drawn again at the next stage)."""
        if self._drawn:
            self.stream.write("\r" + " " * self._drawn + "\r")
            self.stream.flush()
            self._drawn = 0
            self._last = -float("inf")

    def _width(self) -> int:
        """Characters that fit on one line of the terminal (a longer line would wrap)."""
        try:
            columns = os.get_terminal_size(self.stream.fileno()).columns
        except (AttributeError, OSError, ValueError):  # not a real terminal: 80 columns
            columns = 80
        return max(20, columns - 1)
