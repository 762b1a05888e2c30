"""The progress of long runs: stages reported as text, one display (core/progress.py)."""

from __future__ import annotations

import io

import pytest

from phdesign.core.errors import ArgumentError
from phdesign.core.progress import Display, erase, report, reporting, reports_progress, stage


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


class _Clock:
    """A clock the test moves by hand (no test depends on wall-clock time)."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_stages_nest_and_nothing_is_reported_without_a_callback():
    seen: list[str] = []
    report("before")  # no callback in force
    with reporting(seen.append), stage("tradeoff: gain 1 of 2"):
        report("spectrum: pair (20, 30)")
        with reporting(None):  # None keeps the callback in force
            report("noise: resolution 20")
    report("after")
    assert seen == [
        "tradeoff: gain 1 of 2",
        "tradeoff: gain 1 of 2 > spectrum: pair (20, 30)",
        "tradeoff: gain 1 of 2 > noise: resolution 20",
    ]


def test_a_callback_must_be_callable():
    with pytest.raises(ArgumentError, match="progress must be callable"), reporting(3):  # type: ignore[arg-type]
        pass


def test_the_display_waits_for_its_delay_then_redraws_and_erases_one_line():
    clock, out = _Clock(), _Terminal()
    show = Display(out, delay=2.0, interval=0.5, clock=clock)
    show("spectrum: pair (20, 30)")  # at 0 s: before the delay, nothing
    assert out.getvalue() == ""
    clock.now += 2.5
    show("spectrum: pair (30, 45)")
    clock.now += 0.1
    show("spectrum: pair (45, 68)")  # within the interval: not drawn
    assert out.getvalue() == "\rspectrum: pair (30, 45) (2 s)"
    clock.now += 1.0
    show("tune: 3")  # shorter: padded over the longer line
    longer = len("spectrum: pair (30, 45) (2 s)")
    assert out.getvalue().endswith("\r" + "tune: 3 (4 s)".ljust(longer))
    with reporting(show):
        erase()  # before other output: the line goes, to come back at the next stage
    assert out.getvalue().endswith("\r" + " " * len("tune: 3 (4 s)") + "\r")
    show("tune: 4")
    assert out.getvalue().endswith("\rtune: 4 (4 s)")


def test_the_display_draws_nothing_off_a_terminal():
    out = io.StringIO()  # a log file or a pipe
    show = Display(out, delay=0.0, interval=0.0)
    show("spectrum: pair (20, 30)")
    show.erase()
    assert not show.terminal
    assert out.getvalue() == ""


def test_a_decorated_method_puts_its_progress_argument_in_force():
    @reports_progress
    def work(*, progress=None):
        report("working")
        return progress is not None

    seen: list[str] = []
    assert work(progress=seen.append)
    assert not work()
    assert seen == ["working"]
