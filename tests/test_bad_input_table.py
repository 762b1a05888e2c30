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
    ExpressionError,
    ModelError,
    ModelFileError,
    NumericError,
    ObserverError,
    OutputFileError,
    ParameterError,
    SweepError,
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
BEAM_GAIN = "classify euler-bernoulli --sensors 3,4 --gain"
SIM = "simulate wave --sensors 2"
SWEEP = "sweep wave --sensors 2 --scheduler synchronous -o {tmp}/m.zarr"
MAP = "sweep wave --sensors 2 --grid l1=0.1:1:3 --scheduler synchronous"
COMMAND_ROWS = [
    # model selection and parameters
    row("ports nosuch", "unknown model 'nosuch'; expected a built-in model", ModelFileError),
    row("ports {tmp}/missing.toml", "cannot read model file", ModelFileError),
    row("ports {tmp}/bad.toml", "not valid TOML", ModelFileError, **{"bad.toml": "name = = 1"}),
    row(
        "ports {tmp}/empty.toml",
        "lacks the key(s) name, interval",
        ModelFileError,
        **{"empty.toml": ""},
    ),
    row(
        "ports {tmp}/bin.toml", "can't decode byte 0xff", ModelFileError, **{"bin.toml": "\udcff"}
    ),
    row("ports wave --param rho", "--param expects NAME=VALUE; found 'rho'", ParameterError),
    row("ports wave --param =1", "--param expects NAME=VALUE; found '=1'", ParameterError),
    row(
        "ports wave --param mass=1",
        "unknown parameter 'mass'; the model's parameters are rho, T",
        ParameterError,
    ),
    row("ports wave --param rho=-1", "H must be positive definite", ModelError),
    row("ports wave --param rho=0", r"H\[1,1\] = 1/rho is not finite .*rho = 0", ModelError),
    row("ports wave --param rho=abc", "parameter rho: unknown symbol 'abc'", ParameterError),
    row("ports wave --param rho=nan", "parameter rho: unknown symbol 'nan'", ParameterError),
    row(
        "ports wave --param rho=1e999",
        "parameter rho: number '1e999' is out of range",
        ParameterError,
    ),
    row("ports wave --param rho=1 --param rho=2", "--param rho is given twice", ParameterError),
    row("ports wave --param rho=__import__('os')", "unexpected character", ParameterError),
    row(
        "ports euler-bernoulli --param d=-1", "P0 + P0^T must be negative semidefinite", ModelError
    ),
    row("ports", "ports: the following arguments are required: MODEL", None),
    row("frobnicate", "invalid choice: 'frobnicate'", None),
    row("ports wave --nope", "unrecognized arguments: --nope", None),
    # output files: never overwritten without --force, never half-written
    row(
        "show wave --toml -o {tmp}/exists.toml",
        "exists; pass --force",
        OutputFileError,
        **{"exists.toml": "mine"},
    ),
    row(
        "show wave --toml -o {tmp}/no/such/dir/x.toml",
        "no/such/dir' does not exist",
        OutputFileError,
    ),
    row("show wave --toml -o {tmp}", "is a folder; expected a file name", OutputFileError),
    # sensors
    row(f"{BEAM_SENSORS} 5", "output index 5 is out of range; expected 1..4", ObserverError),
    row(f"{BEAM_SENSORS} 0", "output index 0 is out of range; expected 1..4", ObserverError),
    row(f"{BEAM_SENSORS} -1", "output index -1 is out of range; expected 1..4", ObserverError),
    row(f"{BEAM_SENSORS} 3,3", "output index 3 is repeated; expected distinct", ObserverError),
    row(f"{BEAM_SENSORS} 3,x", "found 'x' in '3,x'", ObserverError),
    row(f"{BEAM_SENSORS} 1.5", "found '1.5' in '1.5'", ObserverError),
    row(f"{BEAM_SENSORS} ,", "--sensors: expected comma-separated output indices", ObserverError),
    row(
        "classify euler-bernoulli",
        "classify needs --sensors, --cm or --all-sensors",
        ObserverError,
    ),
    row("classify euler-bernoulli --gain 1", "--gain needs --sensors or --cm", ObserverError),
    row(
        "classify euler-bernoulli --sensors 3 --cm [[0,0,1,0]]",
        "argument --cm: not allowed with argument --sensors",
        None,
    ),
    row(
        "classify euler-bernoulli --all-sensors --sensors 3", "drop --sensors/--cm", ObserverError
    ),
    row(
        "classify wave --all-sensors --gain 1,2,3",
        "expected 2 diagonal values (one per output) or a single one; found 3",
        ObserverError,
    ),
    # C_m in full
    row(
        "classify euler-bernoulli --cm [[0,0,1]]",
        r"C_m matrix; expected \(q, 4\) but found \(1, 3\)",
        ObserverError,
    ),
    row(
        "classify euler-bernoulli --cm [[0,0,1,0]",
        "--cm: expected a JSON list of rows",
        ObserverError,
    ),
    row(
        "classify euler-bernoulli --cm [[0,0,0,0]]",
        "C_m must have full row rank (independent measurements); expected rank 1 but found 0",
        ObserverError,
    ),
    row(
        "classify euler-bernoulli --cm [[0,0,1,0],[0,0,2,0]]",
        "expected rank 2 but found 1",
        ObserverError,
    ),
    row(
        "classify euler-bernoulli --cm [[0,0,nan,0]]",
        "--cm: expected a JSON list of rows",
        ObserverError,
    ),
    row("classify euler-bernoulli --cm []", "--cm: expected a non-empty list", ObserverError),
    # gains
    row(
        f"{BEAM_GAIN} 1,2,3",
        "expected 2 diagonal values (one per sensor) or a single one; found 3",
        ObserverError,
    ),
    row(
        f"{BEAM_GAIN} 1,-1",
        "L + Lᵀ must be positive definite; expected every leading "
        "principal minor > 0 but found minor 2 = -4",
        ObserverError,
    ),
    row(f"{BEAM_GAIN} 1,0", "but found minor 2 = 0", ObserverError),
    row(
        f"{BEAM_GAIN} 1,nan",
        "--gain: entry 2 must be a finite positive number; found 'nan'",
        ObserverError,
    ),
    row(
        f"{BEAM_GAIN} 1,inf",
        "--gain: entry 2 must be a finite positive number; found 'inf'",
        ObserverError,
    ),
    row(f"{BEAM_GAIN} [[1,3],[-3,-1]]", "L + Lᵀ must be positive definite", ObserverError),
    row(
        f"{BEAM_GAIN} [[1,0,0],[0,1,0]]",
        r"L matrix; expected \(2, 2\) \(one row and column per sensor\) but found \(2, 3\)",
        ObserverError,
    ),
    row(f"{BEAM_GAIN} [[1,0],[0,1]", "--gain: expected a JSON list of rows", ObserverError),
    row(f"{BEAM_GAIN} 1,__import__('os')", "unexpected character", ObserverError),
    row(f"{BEAM_GAIN} symbolically", "unknown symbol 'symbolically'", ObserverError),
    # spectrum
    row("spectrum wave --sensors 2 --gain -1", "L + Lᵀ must be positive definite", ObserverError),
    row(
        "spectrum wave --sensors 3", "output index 3 is out of range; expected 1..2", ObserverError
    ),
    row("spectrum euler-bernoulli --sensors 3,4 --gain symbolic", "l1", ParameterError),
    row("spectrum wave --resolution 0", "--resolution", NumericError),
    row("spectrum wave --method spectral", "argument --method: invalid choice: 'spectral'", None),
    row("spectrum airy --method fd", "N = 1 and 2", NumericError),
    row("spectrum wave --count x", "argument --count: invalid int value: 'x'", None),
    # simulate: initial states, times, outputs
    row(
        f"{SIM} --x0 x9:z",
        "initial state: unknown component 'x9'; expected one of",
        ParameterError,
    ),
    row(f"{SIM} --x0 x1:import_os", "import_os", ExpressionError),
    row(f"{SIM} --x0 x1:q*z", "unknown symbol 'q'", ExpressionError),
    row(f"{SIM} --x0 x1:(z", "expected ')'", ExpressionError),
    row(f"{SIM} --x0 x1:e1(0)", "trace 'e1(0)' is not allowed here", ExpressionError),
    row(f"{SIM} --t-end -1", "--t-end", NumericError),
    row(f"{SIM} --t-end 0", "--t-end", NumericError),
    row(f"{SIM} --t-end nan", "--t-end", NumericError),
    row(f"{SIM} --t-end abc", "argument --t-end: invalid float value: 'abc'", None),
    row(f"{SIM} --samples 1", "--samples must be at least 2; found 1", NumericError),
    row("simulate wave --xhat0 x1:z", "--xhat0 needs an observer", NumericError),
    row("simulate wave --gain 1", "--gain needs --sensors or --cm", ObserverError),
    row(
        f"{SIM} -o {{tmp}}/run.csv",
        "exists; pass --force",
        OutputFileError,
        **{"run.csv": "earlier results"},
    ),
    row(f"{SIM} -o {{tmp}}/none/run.csv", "does not exist", OutputFileError),
    row(
        f"{SIM} --plot {{tmp}}/run.png",
        "exists; pass --force",
        OutputFileError,
        **{"run.png": "an earlier picture"},
    ),
    row(f"{SIM} --plot {{tmp}}/run.xyz", "unknown image format 'xyz'", OutputFileError),
    # tune
    row("tune wave", "tune: one of the arguments --sensors --cm is required", None),
    row("tune wave --sensors 5", "output index 5 is out of range; expected 1..2", ObserverError),
    row("tune wave --sensors 2 --starts 0", "--starts", NumericError),
    # sweep (issue 17): grids, axes, jobs, outputs and stores, schedulers; then plot
    row(f"{SWEEP} --grid l1=", "grid l1: empty; expected start:stop:count", SweepError),
    row(f"{SWEEP} --grid l1=3:0.01:40:log", "a log grid runs from start up to stop", SweepError),
    row(f"{SWEEP} --grid l1=1:0.1:5", r"expected start < stop but found 1.0 >= 0.1", SweepError),
    row(f"{SWEEP} --grid l1=0.1:3:0", "count must be at least 1; found zero points", SweepError),
    row(f"{SWEEP} --grid l1=0:3:10:log", "a log grid needs start > 0 and stop > 0", SweepError),
    row(f"{SWEEP} --grid l1=0.1:3:2.5", "count must be a whole number of points", SweepError),
    row(
        f"{SWEEP} --grid l1=0.1:3", "expected start:stop:count or start:stop:count:log", SweepError
    ),
    row(f"{SWEEP} --grid l1=0.3,0.1", "values must be strictly increasing", SweepError),
    row(f"{SWEEP} --grid l1=-1:1:3", r"gains must be positive \(L \+ Lᵀ ≻ 0\)", SweepError),
    row(f"{SWEEP} --grid l1=a:1:3", "grid l1 start: expected a number; found 'a'", SweepError),
    row(f"{SWEEP} --grid k=0.1:1:3", "gain axis 'k': expected l1, l2, ...", SweepError),
    row(f"{SWEEP} --grid l1", "--grid expects NAME=VALUE such as l1=0.01:3:40:log", SweepError),
    row(f"{SWEEP} --grid l1=0.1:1:3 --grid l1=1:2:3", "--grid l1 is given twice", SweepError),
    row(
        f"{SWEEP} --grid l2=0.1:1:3",
        r"gain axis l2 is beyond the sensors \(1 sensor\); expected l1..l1",
        SweepError,
    ),
    row(
        f"{SWEEP} --param-grid mass=0:1:3",
        "unknown parameter 'mass'; the model's parameters are T, rho",
        ParameterError,
    ),
    row(f"{SWEEP} --param-grid rho=-1:1:3", "rho = -1.0: H must be positive definite", ModelError),
    row(
        f"{SWEEP} --param rho=2 --param-grid rho=1:2:3", "by --param and --param-grid", SweepError
    ),
    row(f"{SWEEP} --grid T=1:2:3", "T is a model parameter, not a gain", SweepError),
    row("sweep wave --sensors 2,x --grid l1=1:2:3 -o {tmp}/m.zarr", "found 'x'", ObserverError),
    row("sweep wave --sensors 3 --grid l1=1:2:3 -o {tmp}/m.zarr", "expected 1..2", ObserverError),
    row(f"{SWEEP}", "a sweep needs at least one axis", SweepError),
    row("sweep wave --grid l1=0.1:1:3 -o {tmp}/m.zarr", "gain axes need sensors", SweepError),
    row(
        "sweep wave --job classify --param-grid rho=1:2:3 -o {tmp}/m.zarr",
        "job classify needs sensors",
        SweepError,
    ),
    row(f"{MAP} --job classify --tol 1e-3 -o {{tmp}}/m.zarr", "has no option 'tol'", SweepError),
    row(f"{MAP} --tol -1 -o {{tmp}}/m.zarr", "option tol: expected a positive number", SweepError),
    row(f"{MAP} --job nosuch -o {{tmp}}/m.zarr", "argument --job: invalid choice: 'nosuch'", None),
    row(
        "sweep euler-bernoulli --sensors 3,4 --grid l1=0.1:1:3 --gain 1,2,3 -o {tmp}/m.zarr",
        "expected 2 diagonal values (one per sensor) or a single one; found 3",
        ObserverError,
    ),
    row(f"{MAP} --gain 0 -o {{tmp}}/m.zarr", "entry 1 must be a finite positive", ObserverError),
    row(f"{MAP} --gain nan -o {{tmp}}/m.zarr", "entry 1 must be a finite positive", ObserverError),
    row(
        "sweep wave --sensor-sets 1;3 --grid l=1:2:3 -o {tmp}/m.zarr",
        "output index 3 is out of range; expected 1..2",
        SweepError,
    ),
    row("sweep wave --sensor-sets 1;1 --grid l=1:2:3 -o {tmp}/m.zarr", "given twice", SweepError),
    row(
        "sweep wave --sensor-sets 1,2;2 --gain 1,2 --grid l=1:2:3 -o {tmp}/m.zarr",
        "with sensor sets the fixed gain is one value for every sensor",
        SweepError,
    ),
    row(
        "sweep wave --sensors 2 --sensor-sets 1 -o {tmp}/m.zarr",
        "argument --sensor-sets: not allowed with argument --sensors",
        None,
    ),
    row(f"{MAP}", "the following arguments are required: -o/--output", None),
    row(
        f"{MAP} -o {{tmp}}/m.txt", "unknown format '.txt'; expected a .zarr store", OutputFileError
    ),
    row(
        f"{MAP} -o {{tmp}}/m.zarr",
        "exists; resume the sweep it holds (--resume) or replace it (--force)",
        OutputFileError,
        **{"m.zarr": "not a store"},
    ),
    row(
        f"{MAP} -o {{tmp}}/m.csv",
        "exists; pass --force",
        OutputFileError,
        **{"m.csv": "earlier results"},
    ),
    row(
        f"{MAP} -o {{tmp}}/m.zarr --resume",
        "it is not a phdesign sweep store",
        SweepError,
        **{"m.zarr": "not a store"},
    ),
    row(f"{MAP} -o {{tmp}}/m.csv --resume", "resume continues a Zarr store", SweepError),
    row(f"{MAP} -o {{tmp}}/m.zarr --resume --force", "not allowed with argument --resume", None),
    row(f"{MAP} -o {{tmp}}/none/m.zarr", "folder .*none' does not exist", OutputFileError),
    row(
        "sweep wave --sensors 2 --grid l1=0.1:1:3 -o {tmp}/m.zarr --scheduler tcp://127.0.0.1:1",
        "cannot reach the Dask scheduler at tcp://127.0.0.1:1",
        SweepError,
    ),
    row(f"{MAP} -o {{tmp}}/m.zarr --scheduler nonsense", "expected 'synchronous'", SweepError),
    row(f"{MAP} -o {{tmp}}/m.zarr --chunk-size 0", "chunk size must be a positive", SweepError),
    row(f"{MAP} -o {{tmp}}/m.zarr --workers 0", "workers must be a positive integer", SweepError),
    row(f"{MAP} -o {{tmp}}/m.zarr --method spectral", "argument --method: invalid choice", None),
    row("plot {tmp}/none.zarr -o {tmp}/p.png", "no such file or folder", OutputFileError),
    row(
        "plot {tmp}/m.csv -o {tmp}/p.png",
        "cannot read a sweep back from .*plots read .zarr or .nc",
        SweepError,
        **{"m.csv": "l1,kappa"},
    ),
    row(
        "plot {tmp}/m.zarr -o {tmp}/p.png",
        "is not a phdesign sweep store",
        SweepError,
        **{"m.zarr": "x"},
    ),
    row("plot {tmp}/m.nc -o {tmp}/p.png", "cannot read .* as NetCDF", SweepError, **{"m.nc": "x"}),
    row("plot {tmp}/m.zarr -o {tmp}/p.xyz", "unknown image format 'xyz'", OutputFileError),
    row(
        "plot {tmp}/m.zarr -o {tmp}/p.png",
        "exists; pass --force",
        OutputFileError,
        **{"p.png": "an earlier picture"},
    ),
    row("plot {tmp}/m.zarr -o {tmp}/p.png --select d", "--select expects NAME=VALUE", SweepError),
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


def test_table_has_at_least_60_rows():
    """Issue 7 asks for 60 or more; the summary line of every run prints the pass count."""
    assert len(ROWS) >= 60
