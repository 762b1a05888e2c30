"""The table of bad input: every command, every field; exit 2, one stderr line, no traceback.

Each row runs the command line in-process twice: once as a user would (exit status 2,
exactly one line on stderr that names the problem, no traceback, nothing written), and
once with ``reraise=True`` to check which exception the library raises behind the message.
The summary test prints the table's size and pass count.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import pytest
import tomli_w
from bad_inputs import BAD_MODELS, beam_with

from phdesign.cli import main
from phdesign.errors import (
    ModelError,
    ModelFileError,
    ObserverError,
    OutputFileError,
    ParameterError,
)


@dataclass(frozen=True)
class Row:
    """One bad invocation: ``{tmp}`` in argv stands for a fresh temporary folder."""

    argv: tuple[str, ...]
    message: str
    error: type[Exception] | None  # None: an argument-parser (usage) error
    files: tuple[tuple[str, str], ...] = ()

    @property
    def id(self) -> str:
        return " ".join(self.argv)[:70]


def row(argv: str, message: str, error: type[Exception] | None, **files: str) -> Row:
    return Row(tuple(argv.split()), message, error, tuple(files.items()))


BEAM_SENSORS = "classify euler-bernoulli --sensors"
COMMAND_ROWS = [
    # model selection and parameters
    row("ports nosuch", "unknown model 'nosuch'", ModelFileError),
    row("ports {tmp}/missing.toml", "cannot read model file", ModelFileError),
    row("ports {tmp}/bad.toml", "not valid TOML", ModelFileError, **{"bad.toml": "name = = 1"}),
    row(
        "ports {tmp}/empty.toml",
        "lacks the key(s) name, interval",
        ModelFileError,
        **{"empty.toml": ""},
    ),
    row(
        "ports {tmp}/bin.toml", "cannot read model file", ModelFileError, **{"bin.toml": "\udcff"}
    ),
    row("ports wave --param rho", "--param expects NAME=VALUE; found 'rho'", ParameterError),
    row("ports wave --param =1", "--param expects NAME=VALUE", ParameterError),
    row("ports wave --param mass=1", "unknown parameter 'mass'", ParameterError),
    row("ports wave --param rho=-1", "H must be positive definite", ModelError),
    row("ports wave --param rho=0", r"H\[1,1\] = 1/rho is not finite .*rho = 0", ModelError),
    row("ports wave --param rho=abc", "unknown symbol 'abc'", ParameterError),
    row("ports wave --param rho=nan", "unknown symbol 'nan'", ParameterError),
    row("ports wave --param rho=1 --param rho=2", "given twice", ParameterError),
    row("ports wave --param rho=__import__('os')", "unexpected character", ParameterError),
    row("ports euler-bernoulli --param d=-1", "negative semidefinite", ModelError),
    row("ports", "required", None),
    row("frobnicate", "invalid choice", None),
    row("ports wave --nope", "unrecognized arguments", None),
    # output files
    row(
        "show wave --toml -o {tmp}/exists.toml",
        "exists; pass --force",
        OutputFileError,
        **{"exists.toml": "mine"},
    ),
    row("show wave --toml -o {tmp}/no/such/dir/x.toml", "cannot write", OutputFileError),
    row("show wave --toml -o {tmp}", "is a folder", OutputFileError),
    # sensors
    row(f"{BEAM_SENSORS} 5", "5", ObserverError),
    row(f"{BEAM_SENSORS} 0", "0", ObserverError),
    row(f"{BEAM_SENSORS} -1", "-1", ObserverError),
    row(f"{BEAM_SENSORS} 3,3", "3", ObserverError),
    row(f"{BEAM_SENSORS} 3,x", "x", ObserverError),
    row(f"{BEAM_SENSORS} 1.5", "1.5", ObserverError),
    row(f"{BEAM_SENSORS} ,", "sensors", ObserverError),
    row("classify euler-bernoulli", "needs --sensors", ObserverError),
    row("classify euler-bernoulli --gain 1", "--gain needs --sensors", ObserverError),
    row("classify euler-bernoulli --sensors 3 --cm [[0,0,1,0]]", "not allowed with", None),
    row("classify euler-bernoulli --all-sensors --sensors 3", "drop --sensors", ObserverError),
    # C_m in full
    row("classify euler-bernoulli --cm [[0,0,1]]", "C_m", ObserverError),
    row("classify euler-bernoulli --cm [[0,0,1,0]", "--cm", ObserverError),
    row("classify euler-bernoulli --cm [[0,0,0,0]]", "C_m", ObserverError),
    row("classify euler-bernoulli --cm [[0,0,1,0],[0,0,2,0]]", "C_m", ObserverError),
    row(
        "classify euler-bernoulli --cm [[0,0,nan,0]]", "--cm: expected a JSON list", ObserverError
    ),
    row("classify euler-bernoulli --cm []", "--cm: expected a non-empty list", ObserverError),
    # gains
    row(f"{BEAM_SENSORS} 3,4 --gain 1,2,3", "gain", ObserverError),
    row(f"{BEAM_SENSORS} 3,4 --gain 1,-1", "L + Lᵀ must be positive definite", ObserverError),
    row(f"{BEAM_SENSORS} 3,4 --gain 1,0", "L + Lᵀ must be positive definite", ObserverError),
    row(f"{BEAM_SENSORS} 3,4 --gain 1,nan", "gain", ObserverError),
    row(f"{BEAM_SENSORS} 3,4 --gain 1,inf", "gain", ObserverError),
    row(f"{BEAM_SENSORS} 3,4 --gain [[1,3],[-3,-1]]", "L + L", ObserverError),
    row(f"{BEAM_SENSORS} 3,4 --gain [[1,0,0],[0,1,0]]", "gain", ObserverError),
    row(f"{BEAM_SENSORS} 3,4 --gain [[1,0],[0,1]", "gain", ObserverError),
    row(f"{BEAM_SENSORS} 3,4 --gain 1,__import__('os')", "gain", ObserverError),
    row(f"{BEAM_SENSORS} 3,4 --gain symbolically", "gain", ObserverError),
]


def model_file_rows() -> list[Row]:
    """Every bad model of the library table, written to a file and given to the CLI."""
    rows = []
    for index, (changes, error, message) in enumerate(BAD_MODELS):
        text = tomli_w.dumps(beam_with(**changes))
        rows.append(
            Row(
                ("classify", f"{{tmp}}/m{index}.toml", "--sensors", "3,4"),
                message,
                error,
                ((f"m{index}.toml", text),),
            )
        )
    return rows


ROWS = COMMAND_ROWS + model_file_rows()
_passed: list[str] = []


def _materialize(row: Row, tmp_path) -> list[str]:
    for name, text in row.files:
        path = tmp_path / name
        if "\udcff" in text:
            path.write_bytes(b"\xff\xfe\x00bad")
        else:
            path.write_text(text)
    return [arg.replace("{tmp}", str(tmp_path)) for arg in row.argv]


@pytest.mark.parametrize("bad", ROWS, ids=[r.id for r in ROWS])
def test_bad_input(bad: Row, tmp_path, capsys):
    argv = _materialize(bad, tmp_path)
    before = {p.name: p.stat().st_mtime_ns for p in tmp_path.iterdir()}
    status = main(argv)
    out, err = capsys.readouterr()
    assert status == 2, f"exit status {status}; stderr {err!r}"
    assert err.count("\n") == 1, f"expected one stderr line; found {err!r}"
    assert bad.message in err or re.search(bad.message, err), err
    assert "Traceback" not in err
    assert out == ""
    after = {p.name: p.stat().st_mtime_ns for p in tmp_path.iterdir()}
    assert after == before, "a bad command must not write or touch any file"
    if bad.error is not None:
        with pytest.raises(bad.error):
            main(argv, reraise=True)
        capsys.readouterr()
    _passed.append(bad.id)


def test_table_size_and_pass_count():
    """Printed for the CI log: how many rows the table has and how many passed here."""
    print(f"\nbad-input table: {len(ROWS)} rows, {len(_passed)} passed in this run")
    assert len(ROWS) >= 60
