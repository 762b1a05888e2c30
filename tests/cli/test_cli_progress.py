"""Progress of the long commands: on a terminal's stderr, off with --quiet and --json.

The threshold is injected through the table of defaults (a delay of 0 s), and stderr is a
stand-in terminal: no test depends on how long a run takes.
"""

from __future__ import annotations

import contextlib
import io
from dataclasses import replace

import pytest

from phdesign.cli import build_parser, main
from phdesign.core.defaults import DEFAULTS, using

NOW = replace(DEFAULTS, progress=replace(DEFAULTS.progress, delay=0.0, interval=0.0))
SPECTRUM = ["spectrum", "wave", "--sensors", "2", "--gain", "0.5"]


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), _Terminal()
    with using(NOW), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def test_a_long_command_shows_its_stages_on_stderr_and_erases_them():
    code, out, err = _run(SPECTRUM)
    assert code == 0
    assert "spectral abscissa" in out
    drawn = [part.strip() for part in err.split("\r") if part.strip()]
    assert drawn
    assert all(d.startswith("spectrum: pair (") for d in drawn), drawn
    assert err.endswith("\r")  # erased: the terminal is left as it was
    assert "spectrum: pair" not in out  # never on stdout


@pytest.mark.parametrize("flag", ["--quiet", "--json"])
def test_quiet_and_json_show_no_progress(flag):
    code, out, err = _run([*SPECTRUM, flag])
    assert code == 0
    assert out
    assert err == ""


def test_no_progress_off_a_terminal(capsys):
    with using(NOW):
        assert main(SPECTRUM) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize(
    "command",
    [
        ["classify", "wave", "--all-sensors"],
        [*SPECTRUM],
        ["simulate", "wave"],
        ["tune", "wave", "--sensors", "2"],
        ["noise", "wave", "--sensors", "2"],
        ["tradeoff", "wave", "--sensors", "2"],
        ["export", "wave", "--sensors", "2", "--dt", "0.01", "--format", "json", "-o", "x.json"],
        *(
            ["loop", sub, "euler-bernoulli", "--actuate", "3", "--sensors", "4"]
            for sub in ("classify", "spectrum", "simulate", "tune")
        ),
    ],
)
def test_every_long_command_has_quiet(command):
    args = build_parser().parse_args([*command, "--quiet"])
    assert args.quiet
