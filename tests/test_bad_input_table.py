"""The table of bad input: every command, every field; exit 2, one stderr line, no traceback.

Each row runs the command line in-process twice: once as a user would (exit status 2,
exactly one line on stderr that names the problem, no traceback, nothing written), and
once with ``reraise=True`` to check which exception the library raises behind the message.
The summary test prints the table's size and pass count.
"""

from __future__ import annotations

import os
import re
import time
from dataclasses import dataclass

import pytest
import tomli_w
from bad_inputs import BAD_MODELS, beam_with

from phdesign.cli import main
from phdesign.core.errors import (
    CertificateError,
    ExpressionError,
    LoopError,
    ModelError,
    ModelFileError,
    NumericError,
    ObserverError,
    OutputFileError,
    ParameterError,
    RateProofError,
    SweepError,
)


@dataclass(frozen=True)
class Row:
    """One bad invocation: ``{tmp}`` in argv stands for a fresh temporary folder.

    ``seconds``: a resource row, whose refusal must come within that time (issue 12).
    """

    argv: tuple[str, ...]
    message: str
    error: type[Exception] | None  # None: an argument-parser (usage) error
    files: tuple[tuple[str, str], ...] = ()
    seconds: float | None = None

    @property
    def id(self) -> str:
        return " ".join(self.argv)[:70]


def row(argv: str, message: str, error: type[Exception] | None, seconds=None, **files: str) -> Row:
    return Row(tuple(argv.split()), message, error, tuple(files.items()), seconds)


def beams_toml(count: int) -> str:
    """``count`` uncoupled Euler-Bernoulli beams (the built-in beam's ports, per beam)."""
    n = 2 * count
    P2 = [[0] * n for _ in range(n)]
    inputs, outputs = [], []
    for k in range(count):
        a, b = 2 * k + 1, 2 * k + 2
        P2[a - 1][b - 1], P2[b - 1][a - 1] = -1, 1
        inputs += [f"e{a}(0)", f"e{a}'(0)", f"e{b}(1)", f"e{b}'(1)"]
        outputs += [f"e{b}'(0)", f"-e{b}(0)", f"e{a}'(1)", f"-e{a}(1)"]
    H = [[int(i == j) for j in range(n)] for i in range(n)]
    return tomli_w.dumps(
        {
            "name": f"{count} beams",
            "interval": [0, 1],
            "order": 2,
            "matrices": {"P2": P2, "H": H},
            "ports": {"inputs": inputs, "outputs": outputs},
        }
    )


GRADED = tomli_w.dumps(
    {
        "name": "graded string",
        "interval": [0, 1],
        "order": 1,
        "matrices": {"P1": [[0, 1], [1, 0]], "H": [[1, 0], [0, "1 + z"]]},
        "ports": {"inputs": ["e1(0)", "e2(1)"], "outputs": ["-e2(0)", "e1(1)"]},
    }
)

#: PIETOOLS' damped-tip string under a uniform force w1, ∫ e1 judged (issue 27)
DAMPED_TIP = tomli_w.dumps(
    {
        "name": "damped-tip wave",
        "interval": [0, 1],
        "order": 1,
        "parameters": {"k": 0.5},
        "matrices": {"P1": [[0, 1], [1, 0]], "H": [[1, 0], [0, 1]]},
        "ports": {"inputs": ["e1(0)", "e2(1)"], "outputs": "conjugate"},
        "feedback": {"inputs": [2], "gain": [["k"]]},
        "disturbances": {"B": [[1], [0]]},
        "performance": {"outputs": ["integral(e1)"]},
    }
)


def graded(H22: str) -> str:
    """The graded string with its tension H22 replaced (the decay-rate refusals)."""
    return GRADED.replace('"1 + z"', repr(H22).replace("'", '"'))


BEAM_SENSORS = "classify euler-bernoulli --sensors"
BEAM_GAIN = "classify euler-bernoulli --sensors 3,4 --gain"
SIM = "simulate wave --sensors 2"
TIP = "simulate string-tip-mass --sensors 2"
NOISE = "noise euler-bernoulli --sensors 3,4 --gain 0.1,1"
TRADE = "tradeoff euler-bernoulli --sensors 3,4"
TUNE_BEAM = "tune euler-bernoulli --sensors 3,4"
EXPORT = "export euler-bernoulli --sensors 3,4 --gain 0.1,1 --format json"
EXPORT_C = "export wave --sensors 2 --gain 1 --dt 1e-3 --format c"
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
        "--cm must have full row rank (independent measurements); expected rank 1 but found 0",
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
    # --cm [] (no sensors) is classify's, without a gain (issue 28: it classifies the plant)
    row("classify euler-bernoulli --cm [] --gain 1", "--gain: no sensors", ObserverError),
    row("spectrum euler-bernoulli --cm []", "--cm: no sensors ([]) is for", ObserverError),
    row("classify euler-bernoulli --cm [[]]", "--cm: expected a non-empty list", ObserverError),
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
    row("spectrum euler-bernoulli --sensors 3,4 --gain symbolic", "l1", ObserverError),
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
    # issue 26: a coupled model's boundary states in --x0 / --xhat0
    row(
        f"{TIP} --x0 mass.x1:z",
        "boundary state 'mass.x1' is one number, not a function of z",
        ParameterError,
    ),
    row(
        f"{TIP} --x0 mass.x2:1",
        "unknown component 'mass.x2'; expected one of .*mass.x1",
        ParameterError,
    ),
    row(f"{TIP} --x0 mass.x1:1,mass.x1:2", "boundary state 'mass.x1' given twice", ParameterError),
    row(f"{TIP} --xhat0 mass.x1:q", "unknown symbol 'q'", ExpressionError),
    row(f"{SIM} --x0 mass.x1:1", "unknown component 'mass.x1'", ParameterError),
    row(
        "export string-motor --sensors 2 --gain 1 --dt 0.01 --order 42 --format json "
        "--output {tmp}/o.json",
        r"order 42 is not a Galerkin order of this model: n \(p \+ 1\) \+ 1 with its n = 2",
        NumericError,
    ),
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
    # noise figures, trade-off, noise-aware tuning and stochastic simulation (issue 14)
    row("noise wave", "noise needs --sensors or --cm", ObserverError),
    row(f"{NOISE} --intensity -1", "--intensity: intensities must be finite and", NumericError),
    row(
        f"{NOISE} --intensity nan,1",
        "non-negative (variances per unit time); found nan",
        NumericError,
    ),
    row(f"{NOISE} --intensity 1,2,3", "expected 2 values (one per channel)", NumericError),
    row(f"{NOISE} --intensity x", "--intensity: expected comma-separated numbers", NumericError),
    row(f"{NOISE} --input-noise -0.5", "--input-noise: intensities must be finite", NumericError),
    row(f"{NOISE} --at 2", "displacement point 2 is outside the interval [0, 1]", NumericError),
    row(
        "noise wave --sensors 2 --gain 1 --at 1",
        "the model 'wave' defines no displacement",
        NumericError,
    ),
    row(f"{NOISE} --integral x9:1", "integral weight: unknown component 'x9'", ParameterError),
    row(f"{NOISE} --integral e1:1", "'e1' is an effort; weigh state components", ParameterError),
    row(
        f"{NOISE} --integral x2:q*z",
        "integral weight expression: unknown symbol 'q'",
        ExpressionError,
    ),
    row(f"{NOISE} --trace e9(1)", "component index in 'e9(1)' is out of range", ExpressionError),
    row(f"{NOISE} --trace e1(0.5)", "is at an interior or outside point 0.5", ExpressionError),
    row(f"{NOISE} --tol 0", "--tol must be a finite positive number; found 0.0", NumericError),
    row(
        f"{NOISE} --plot {{tmp}}/noise.png",
        "exists; pass --force",
        OutputFileError,
        **{"noise.png": "an earlier picture"},
    ),
    row("tradeoff wave", "one of the arguments --sensors --cm is required", None),
    row("tradeoff wave --sensors 2", "the trade-off needs a performance output", NumericError),
    row(f"{TRADE} --grid 0.1:1", "--grid: expected lo:hi:count or one value", NumericError),
    row(
        f"{TRADE} --grid 1:0.1:3,1", "expected 0 < lo < hi and a count of at least 2", NumericError
    ),
    row(
        f"{TRADE} --grid 0.1:1:3", "grid: expected 2 axes (one per sensor); found 1", NumericError
    ),
    row(f"{TRADE} --direction 0.1,-1", "--direction: expected 2 positive values", NumericError),
    row(f"{TRADE} --grid 1,1 --scales 1:2:3", "--scales belongs to a ray", NumericError),
    row(
        f"{TRADE} -o {{tmp}}/trade.csv",
        "exists; pass --force",
        OutputFileError,
        **{"trade.csv": "earlier results"},
    ),
    row("simulate wave --noise-intensity 1", "--noise-intensity needs an observer", ObserverError),
    row(
        f"{SIM} --noise-intensity -1",
        "--noise-intensity: intensities must be finite",
        NumericError,
    ),
    row(f"{SIM} --noise-intensity 1,1", "intensity: expected 1 values", NumericError),
    row(f"{SIM} --seed 3", "--seed needs --noise-intensity or --input-noise", NumericError),
    # ---- issue 30: a negative seed and intensities beyond the range of the computation
    row(
        f"{SIM} --noise-intensity 1 --seed -1",
        "seed must be an integer >= 0; found -1",
        NumericError,
    ),
    row(
        f"{SIM} --noise-intensity 1e101",
        r"--noise-intensity: intensities must be at most 1e\+100 \(variances per unit time\); "
        r"found 1e\+101 \(the budget phdesign.core.limits.MAX_NOISE_INTENSITY\)",
        NumericError,
    ),
    row(
        f"{NOISE} --intensity 1e308",
        r"--intensity: intensities must be at most 1e\+100 .*found 1e\+308",
        NumericError,
    ),
    row(f"{TRADE} --intensity 1,1e200", r"at most 1e\+100 .*found 1e\+200", NumericError),
    row(f"{SIM} --noise-intensity 1 --scheme midpoint", "scheme does not apply", NumericError),
    row(f"{SIM} --noise-intensity 1 --dt 0.01", "--dt asks for a sampled one", NumericError),
    row(
        "tune wave --sensors 2 --max-rms -1",
        "--max-rms must be a finite positive number; found -1.0",
        NumericError,
    ),
    row(
        "tune wave --sensors 2 --objective rms", "--objective rms needs --min-decay", NumericError
    ),
    row("tune wave --sensors 2 --intensity 2", "--intensity needs --max-rms", NumericError),
    row(
        "tune euler-bernoulli --sensors 4 --max-rms 0.3 --starts 3",
        "--starts belongs to the abscissa search; the noise-aware tuning .* drop --starts",
        NumericError,
    ),
    row(
        "tune euler-bernoulli --sensors 4 --objective rms --min-decay 1 --seed 2",
        "drop --seed",
        NumericError,
    ),
    row(
        "tune euler-bernoulli --sensors 4 --max-rms 0.3 --robust 5%", "drop --robust", NumericError
    ),
    row("tune wave --sensors 2 --max-rms 0.5", "needs a performance output", NumericError),
    row(f"{TUNE_BEAM} --max-rms 0.1 --full", "drop --full", NumericError),
    # export and the sampled simulation (issue 15): checked before any work, nothing written
    row(
        f"{EXPORT} --dt 0 -o {{tmp}}/o.json", "--dt must be a finite positive number", NumericError
    ),
    row(f"{EXPORT} --dt=-1e-3 -o {{tmp}}/o.json", "seconds; found -0.001", NumericError),
    row(f"{EXPORT} --dt nan -o {{tmp}}/o.json", "seconds; found nan", NumericError),
    row(f"{EXPORT} --dt inf -o {{tmp}}/o.json", "seconds; found inf", NumericError),
    row(f"{EXPORT} --dt 1ms -o {{tmp}}/o.json", "argument --dt: invalid float value: '1ms'", None),
    # ---- issue 30: a period longer than the run, more periods than a run may step
    row(
        f"{EXPORT} --dt 1e300 -o {{tmp}}/o.json",
        r"--dt = 1e\+300 s is longer than --t-end = 5 s; expected a sampling period at most",
        NumericError,
    ),
    row(
        f"{EXPORT} --dt 1e-300 --verify -o {{tmp}}/o.json",
        r"--t-end / --dt = 5e\+300 sampling periods; expected at most 1e\+09 \(the budget "
        r"phdesign.core.limits.MAX_PERIODS\)",
        NumericError,
    ),
    row(f"{SIM} --dt 1e300", r"--dt = 1e\+300 s is longer than --t-end = 5 s", NumericError),
    row(f"{SIM} --dt 1e-300", r"--t-end / --dt = 5e\+300 sampling periods", NumericError),
    row(
        f"{SIM} --dt 1e-6 --u u1:sin(t) --resolution 6",
        r"--t-end / --dt = 5e\+06 periods, each stepped with an input, times 28 states is "
        r"1.4e\+08 values; expected at most 20,000,000",
        NumericError,
    ),
    row(
        f"{EXPORT} --dt 1e-3 --sampler spline -o {{tmp}}/o.json",
        "argument --sampler: invalid choice: 'spline' (choose from 'average', 'point')",
        None,
    ),
    # ---- issue 29: the gain design and its noise model, checked before any work
    row(
        f"{EXPORT} --dt 1e-3 --design lqr -o {{tmp}}/o.json",
        "argument --design: invalid choice: 'lqr' (choose from 'auto', 'passive', 'kalman', "
        "'given')",
        None,
    ),
    row(
        f"{EXPORT} --dt 1e-3 --process-noise 1,x -o {{tmp}}/o.json",
        "--process-noise must be a number or comma-separated numbers; found '1,x'",
        NumericError,
    ),
    row(
        f"{EXPORT} --dt 1e-3 --sensor-noise 1,2,3 -o {{tmp}}/o.json",
        r"sensor noise variance must be a positive number or 2 positive numbers \(one per "
        r"channel\); found \(1.0, 2.0, 3.0\)",
        NumericError,
    ),
    row(
        f"{EXPORT} --dt 1e-3 --process-noise=-1 -o {{tmp}}/o.json",
        "process noise intensity must be finite and positive; found -1.0",
        NumericError,
    ),
    row(
        f"{EXPORT} --dt 1e-3 --max-ratio 0 -o {{tmp}}/o.json",
        "--max-ratio must be a finite positive number; found 0.0",
        NumericError,
    ),
    row(
        f"{EXPORT} --dt 1e-3 --order 60 --plant-resolution 48 -o {{tmp}}/o.json",
        "order 60 needs a verification plant of at least 120 states; the plant "
        "(Galerkin degree 48) has 98",
        NumericError,
    ),
    row(
        f"{EXPORT} --dt 1e-3 --order 500 -o {{tmp}}/o.json",
        "the largest for this model has 222 (Galerkin degree 110)",
        NumericError,
    ),
    row(f"{EXPORT} --dt 1e-3 --order 0 -o {{tmp}}/o.json", "found 0", NumericError),
    row(
        f"{EXPORT} --dt 1e-3 --order 33 -o {{tmp}}/o.json",
        "order 33 is not a Galerkin order of this model",
        NumericError,
    ),
    row(
        f"{EXPORT} --dt 1e-3 --order 34 --reduce modal -o {{tmp}}/o.json",
        "cannot be combined with the modal reduction",
        NumericError,
    ),
    row(
        f"{EXPORT} --dt 1e-3 -o {{tmp}}/o.json",
        "output file .*o.json' exists; pass --force",
        OutputFileError,
        **{"o.json": "an earlier export"},
    ),
    row(
        "export wave --sensors 2 --gain 1 --dt 1e-3 --format c -o {tmp}",
        "output folder .* exists and is not an export of phdesign: it holds no marker "
        r"\.phdesign-export",
        OutputFileError,
    ),
    row(
        "export wave --sensors 2 --gain 1 --dt 1e-3 --format c -o {tmp}/obs",
        "is a file; format 'c' writes a folder",
        OutputFileError,
        obs="a file",
    ),
    # ---- issue 30: --force replaces only an export phdesign wrote (a user's folder survives)
    row(
        f"{EXPORT_C} -o {{tmp}} --force",
        "is not an export of phdesign: it holds no marker .*--force replaces only a folder "
        "phdesign wrote",
        OutputFileError,
        **{"precious.txt": "mine"},
    ),
    row(f"{EXPORT_C} -o . --force", "output path '.' names no folder", OutputFileError),
    row(f"{EXPORT_C} -o {{tmp}}/.. --force", "names no folder", OutputFileError),
    row(
        f"{EXPORT_C} -o {{tmp}}/link --force",
        "is a symbolic link; format 'c' writes a folder, and replaces only a folder it "
        "wrote, even with --force",
        OutputFileError,
        link="symlink:.",
    ),
    row(
        f"{EXPORT_C} -o {{tmp}}/fifo --force",
        "is a FIFO; format 'c'",
        OutputFileError,
        fifo="fifo:",
    ),
    row(f"{EXPORT_C} -o /dev/null --force", "is a device; format 'c'", OutputFileError),
    row(f"{EXPORT} --dt 1e-3 -o {{tmp}}/none/o.json", "none' does not exist", OutputFileError),
    row(
        f"{EXPORT} --dt 1e-3 -o /proc/phdesign-export.json",
        "cannot write '/proc/phdesign-export.json'",
        OutputFileError,
    ),
    row(
        "export wave --sensors 2 --gain 1 --dt 1e-3 --format c -o /proc/phdesign-export",
        "cannot write '/proc/phdesign-export'",
        OutputFileError,
    ),
    row(
        "export euler-bernoulli --dt 1e-3 --format json -o {tmp}/o.json",
        "export needs --sensors or --cm",
        ObserverError,
    ),
    row(
        f"{EXPORT} --dt 1e-3 --at 2 -o {{tmp}}/o.json",
        r"--at: expected numbers in \[0, 1\]; found 2$",
        NumericError,
    ),
    # ---- issue 30: two points, one output name
    row(
        f"{EXPORT} --dt 1e-3 --at 1,1 -o {{tmp}}/o.json",
        r"--at: 1.0 and 1.0 both give the output w\(1\); expected distinct points",
        NumericError,
    ),
    row(
        f"{EXPORT} --dt 1e-3 --at 0.5,1,0.5000001 -o {{tmp}}/o.json",
        r"--at: 0.5 and 0.5000001 both give the output w\(0.5\)",
        NumericError,
    ),
    row(
        "export wave --sensors 2 --gain 1 --dt 1e-3 --at 1 --format json -o {tmp}/o.json",
        "--at: model 'wave' has no displacement",
        NumericError,
    ),
    row(f"{EXPORT} --dt 1e-3 --t-end 0 -o {{tmp}}/o.json", "--t-end must be", NumericError),
    row(f"{EXPORT} --dt 1e-3 --output-tol=-1 -o {{tmp}}/o.json", "--output-tol", NumericError),
    row(
        "export wave --sensors 2 --gain 1 --dt 1e-3 -o {tmp}/o.json",
        "the following arguments are required: --format",
        None,
    ),
    # point outputs of the sampled, noisy and loop simulations: read before any work
    row(
        "simulate euler-bernoulli --sensors 3,4 --dt 1e-2 --at 2",
        r"--at: expected numbers in \[0, 1\]; found 2$",
        NumericError,
    ),
    row(
        "simulate timoshenko --sensors 3,4 --noise-intensity 1 --at rotaton(1)",
        r"--at: rotaton\(1\): .*no field 'rotaton' \(did you mean 'rotation'\?\)",
        NumericError,
    ),
    row(
        "loop simulate wave --actuate 2 --sensors 2 --at 1",
        "--at: model 'wave' has no displacement",
        NumericError,
    ),
    row(f"{SIM} --dt 0", "--dt must be a finite positive number of seconds", NumericError),
    row(f"{SIM} --sampler point", "--sampler needs --dt, the sampling period", NumericError),
    row("simulate wave --dt 1e-3", "act on the observer: give --sensors or --cm", NumericError),
    row(f"{SIM} --dt 1e-3 --scheme midpoint", "stepped exactly: drop --scheme", NumericError),
    row(
        f"{SIM} --observer-resolution 0",
        "--observer-resolution must be a positive integer; found 0",
        NumericError,
    ),
    row(
        f"{SIM} --method fd --resolution 20 --observer-resolution 10",
        "is not contained in the plant's",
        NumericError,
    ),
    # --- issue 13 (model): plant inputs --u, closed plants ([feedback])
    row(
        "simulate wave --u u3:sin(t)",
        "--u: unknown input 'u3'; the model's inputs are u1, u2",
        ParameterError,
    ),
    row(
        "simulate wave-damper --u u2:t",
        "unknown input 'u2'; the model's inputs are u1",
        ParameterError,
    ),
    row("simulate wave --u u1", "--u item 'u1': expected 'u<i>: expression in t'", ParameterError),
    row("simulate wave --u u1:1,u1:2", "--u: input 'u1' given twice", ParameterError),
    row(
        "simulate wave --u u1:sin(q*t)",
        "unknown symbol 'q' in 'sin(q*t)'; expected t",
        ExpressionError,
    ),
    row("simulate wave --u u1:__import__('os')", "unexpected character", ExpressionError),
    row("simulate wave --u u1:log(t-1)", "--u: input u1 is not finite at t = 0", NumericError),
    row(
        "simulate wave --u u1:exp(exp(1000*t))", "input u1 is not finite at t = 0.01", NumericError
    ),
    row(
        "classify wave-damper --sensors 2",
        "output index 2 is out of range; expected 1..1",
        ObserverError,
    ),
    row("spectrum wave-damper --param k=-1", "K + K^T must be positive semidefinite", ModelError),
    row(
        "spectrum beam-tip-damper --cm [[0,0,0,1]]",
        r"expected \(q, 3\) but found \(1, 4\)",
        ObserverError,
    ),
    # ---- issue 12, item 2: every input's cost is bounded, refused before the work
    row(
        "spectrum wave --resolution 20000",
        "about 40,002 states; expected at most 2,000",
        NumericError,
        seconds=10,
    ),
    row("spectrum wave --resolution 1999", "expected at most 2,000", NumericError, seconds=10),
    row("simulate wave --resolution 5000", "about 10,002 states", NumericError, seconds=10),
    row(
        "simulate wave --method fd --resolution 2000",
        "fd discretization of a size-2 model about 4,002 states",
        NumericError,
        seconds=10,
    ),
    row(
        "simulate wave --samples 100000000",
        "values; expected at most 20,000,000",
        NumericError,
        seconds=10,
    ),
    row(
        f"{SIM} --t-end 1.7e308",
        "--t-end must be a positive number at most 1e+12",
        NumericError,
        seconds=10,
    ),
    row(f"{SIM} --t-end 1e13", "at most 1e+12; found 1e+13", NumericError, seconds=10),
    row(
        "simulate wave --t-end 5e-324 --samples 3",
        "the time stamps would not be distinct",
        NumericError,
    ),
    row("simulate wave --t-end 1e-320 --samples 2", "below 1e-300", NumericError),
    row(
        "tune wave --sensors 2 --starts 1000000000",
        "starts must be an integer from 1 to 100; found 1000000000",
        NumericError,
        seconds=10,
    ),
    row(
        "tune wave --sensors 2 --starts 101", "from 1 to 100; found 101", NumericError, seconds=10
    ),
    row(
        "classify wave --sensors 2 --gain exp(1e300)",
        "in 'exp(1e300)' is out of range",
        ObserverError,
        seconds=10,
    ),
    row(
        "classify wave --sensors 2 --gain exp(exp(exp(5)))",
        "in 'exp(exp(exp(5)))' is out of range",
        ObserverError,
        seconds=10,
    ),
    # a tower of exponentials that overflows floats: nan and 0 (a 'failing' κ*) before
    row(
        "classify wave --all-sensors --gain exp(exp(7))",
        "exp(exp(7)) in 'exp(exp(7))' is out of range",
        ObserverError,
    ),
    row(
        "classify wave --sensors 2 --gain exp(exp(7))",
        "exp(exp(7)) in 'exp(exp(7))' is out of range",
        ObserverError,
    ),
    row(
        "classify wave --sensors 2 --gain exp(690)*exp(690)",
        "is out of range; expected magnitudes between 1e-300 and 1e300 (or 0); found exp(1380)",
        ObserverError,
    ),
    row(
        "ports wave --param rho=exp(1000)",
        "exp(1000) in 'exp(1000)' is out of range",
        ParameterError,
    ),
    row(
        "classify {tmp}/beams.toml --all-sensors",
        "2^32 - 1 = 4294967295 sensor sets for 32 outputs; expected at most 16",
        ObserverError,
        seconds=10,
        **{"beams.toml": beams_toml(8)},
    ),
    row(
        "show {tmp}/big.toml",
        "is larger than 1,048,576 bytes",
        ModelFileError,
        seconds=10,
        **{"big.toml": "bytes:2000000"},
    ),
    row("show /dev/zero", "is larger than 1,048,576 bytes", ModelFileError, seconds=10),
    # ---- item 3: an overflow is an error line, never rows of NaN or bare NaN in JSON
    row(
        f"{SIM} --x0 x1:1e300*z",
        "the simulation overflowed: H is not finite from t = 0 on",
        NumericError,
    ),
    row(f"{SIM} --x0 x1:z --json --xhat0 x1:1e300*z", "overflowed: H_hat", NumericError),
    row("simulate wave --param rho=1e-300 --x0 x1:z", "overflowed", NumericError),
    row(f"{SIM} --gain 1e200 --x0 x1:z", "simulation overflowed", NumericError),
    row(f"{SIM} --x0 x1:exp(800)*z", "exp(800) in 'exp(800)*z' is out of range", ExpressionError),
    # ---- items 4 and 5: outputs checked together before the work; no non-regular targets
    row(
        f"{SIM} -o {{tmp}}/same.png --plot {{tmp}}/same.png",
        "is named twice",
        OutputFileError,
    ),
    row(f"{SIM} -o {{tmp}}/a.png --plot {{tmp}}/./a.png", "is named twice", OutputFileError),
    row(
        "show wave --toml -o {tmp}/out.toml --force",
        "is a symbolic link; phdesign writes regular files only",
        OutputFileError,
        **{"out.toml": "symlink:/proc/self/fd/1"},
    ),
    row(
        "show wave --toml -o {tmp}/dangling.toml",
        "is a symbolic link",
        OutputFileError,
        **{"dangling.toml": "symlink:nowhere/at/all"},
    ),
    row(
        "show wave --toml -o {tmp}/pipe --force",
        "is a FIFO; phdesign writes regular files only",
        OutputFileError,
        **{"pipe": "fifo:"},
    ),
    row(
        f"{SIM} -o {{tmp}}/run.csv --plot {{tmp}}/pipe.png --force",
        "is a FIFO",
        OutputFileError,
        **{"pipe.png": "fifo:"},
    ),
    # ---- item 9
    row(
        "tune wave --sensors 2 --seed -1",
        "argument --seed: expected a non-negative integer; found -1",
        None,
    ),
    # --- issue 16 (loop): observer-based boundary control
    row(
        "loop classify euler-bernoulli --actuate 7 --sensors 4",
        r"actuate: u7 is not an input of the model; expected an index in 1\.\.4 "
        r"\(u1 = e1\(0\), u2 = e1'\(0\), u3 = e2\(1\), u4 = e2'\(1\)\)",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 0 --sensors 4",
        "actuate: u0 is not an input of the model",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3,3 --sensors 4",
        "actuate: input u3 is repeated",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate x --sensors 4",
        "--actuate: expected comma-separated 1-based indices",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3 --feedback -1 --sensors 4",
        # Sylvester on K + Kᵀ = -2 (1 x 1)
        r"feedback K \+ Kᵀ must be positive definite; expected every leading principal "
        r"minor > 0 but found minor 1 = -2",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3 --feedback 0 --sensors 4",
        r"found minor 1 = 0",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3,4 --feedback [[1,3],[3,1]] --sensors 4",
        # K + Kᵀ = [[2, 6], [6, 2]]: minor 1 = 2 > 0, minor 2 = 4 - 36 = -32
        r"positive definite; expected every leading principal minor > 0 but found minor 2 = -32",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3 --feedback 1,2 --sensors 4",
        "expected 1 diagonal values",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3 --feedback nan --sensors 4",
        "feedback K: entry 1 must be a finite positive number",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3 --feedback symbolic --sensors 4",
        "symbolic feedback gains",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3 --feedback-outputs 4 --sensors 4",
        r"feedback: y4 = -e1\(1\) is not collocated with the actuated input u3; its power "
        r"conjugate is y3 = e1'\(1\)",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3 --feedback-source measured --sensors 4",
        r"feedback source measured: y3 = e1'\(1\) \(collocated with the actuated u3\) is not "
        "measured by these sensors",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3",
        "loop needs the observer's sensors: give --sensors or --cm",
        LoopError,
    ),
    row(
        "loop classify euler-bernoulli --actuate 3 --sensors 5",
        "output index 5 is out of range; expected 1..4",
        ObserverError,
    ),
    row("loop classify euler-bernoulli --sensors 4", "required: --actuate", None),
    row("loop euler-bernoulli --actuate 3", "invalid choice: 'euler-bernoulli'", None),
    row("loop spectrum wave --actuate 2 --sensors 2 --count 0", "--count", NumericError),
    row(
        "loop simulate euler-bernoulli --actuate 3 --sensors 4 --u u3:sin(t) --resolution 8",
        "u3 is actuated by the feedback; --u drives only the other inputs (u1, u2, u4)",
        LoopError,
    ),
    row(
        "loop tune wave --actuate 2 --sensors 2 --tune everything",
        "argument --tune: invalid choice: 'everything'",
        None,
    ),
    # ---- issue 30: options that would do nothing are refused
    row(
        "loop tune wave --actuate 2 --sensors 2 --gain 0.5",
        "--gain is what --tune both tunes .*: drop --gain, or keep it with --tune feedback",
        LoopError,
    ),
    row(
        "loop tune wave --actuate 2 --sensors 2 --tune feedback --feedback 2",
        "--feedback is what --tune feedback tunes",
        LoopError,
    ),
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
    row(
        f"{MAP} --tol -1 -o {{tmp}}/m.zarr",
        "option tol must be a finite positive number; found -1.0",
        SweepError,
    ),
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
    # ---- issue 30 (part B): sweep targets, refused points, addresses, caps
    row(
        f"{TRADE} --scales 0.1:10:100000000",
        "--scales gives 100,000,000 gains; a trade-off evaluates at most 1,000",
        NumericError,
        seconds=10,
    ),
    row(
        f"{TRADE} --grid 0.1:1:1000,0.1:1:1000",
        "--grid gives 1,000,000 gains; a trade-off evaluates at most 1,000",
        NumericError,
        seconds=10,
    ),
    row(
        f"{NOISE} --resolution 999",
        "resolution 999 gives the noise figures of a size-2 model about 2,000 states; expected "
        "at most 1,000 (the budget phdesign.core.limits.MAX_NOISE_STATES: dense Lyapunov",
        NumericError,
        seconds=10,
    ),
    row(
        f"{MAP} -o {{tmp}}/pipe.zarr --force",
        "output .*pipe.zarr' is a FIFO; a sweep writes its store only where there is nothing",
        OutputFileError,
        **{"pipe.zarr": "fifo:"},
    ),
    row(
        f"{MAP} -o {{tmp}}/link.zarr --force",
        "is a symbolic link; a sweep writes its store only",
        OutputFileError,
        **{"link.zarr": "symlink:nowhere/at/all"},
    ),
    row(
        f"{MAP} --resolution 100000 -o {{tmp}}/m.zarr",
        "resolution 100000 gives the galerkin discretization of a size-2 model about 200,002 "
        "states; expected at most 2,000",
        NumericError,
    ),
    row(
        f"{SWEEP} --grid l1=1e-320,1",
        r"gain axis l1: gains must lie between 1e-300 and 1e\+300, as every gain; found 1e-320",
        SweepError,
    ),
    row(
        "sweep {tmp}/m.toml --param-grid c=0:1:3 --scheduler synchronous -o {tmp}/m.zarr",
        # H11 = 1 - 5 c (1 - c) is 1 at both ends and -1/4 at the interior value c = 1/2
        r"parameter grid c = 0.5: H must be positive definite .*found eigenvalues \[-0.25, 1\]",
        ModelError,
        **{
            "m.toml": tomli_w.dumps(
                {
                    "name": "string stiffer at both ends of c",
                    "interval": [0, 1],
                    "order": 1,
                    "parameters": {"c": 0.0},
                    "matrices": {"P1": [[0, 1], [1, 0]], "H": [["1 - 5*c*(1 - c)", 0], [0, 1]]},
                    "ports": {"inputs": ["e1(0)", "e2(1)"], "outputs": ["-e2(0)", "e1(1)"]},
                }
            )
        },
    ),
    row(
        f"{SWEEP} --grid l1=0.1:1:3 --scheduler tcp://127.0.0.1:99999",
        "Port out of range",
        SweepError,
    ),
    row(
        f"{SWEEP} --grid l1=0.1:1:3 --scheduler tcp://127.0.0.1:0",
        "the port must be from 1 to 65535; found 0",
        SweepError,
    ),
    row(
        f"{SWEEP} --grid l1=0.1:1:3 --scheduler tcp://host:port", "malformed .*'port'", SweepError
    ),
    row(f"{SWEEP} --grid l1=0.1:1:3 --scheduler tcp://[::1:8786", "Invalid IPv6 URL", SweepError),
    row(f"{SWEEP} --grid l1=0.1:1:3 --scheduler tcp://h:1:2", "malformed .*'1:2'", SweepError),
    row(f"{SWEEP} --grid l1=0.1:1:3 --scheduler udp://h:1", "unknown transport 'udp'", SweepError),
    row(
        f"{SWEEP} --grid l1=0.1:1:100000000",
        "grid l1 has 100,000,000 points; a sweep has at most 1,000,000",
        SweepError,
        seconds=10,
    ),
    row(
        f"{SWEEP} --grid l1=0.1:1:1000 --param-grid rho=1:2:1001",
        "the sweep has 1,001,000 points; a sweep has at most 1,000,000",
        SweepError,
        seconds=10,
    ),
    row(
        "sweep {tmp}/beams.toml --job classify --sensor-sets all -o {tmp}/m.zarr",
        "sensor sets 'all' of 32 outputs has 4,294,967,295 points; a sweep has at most",
        SweepError,
        seconds=10,
        **{"beams.toml": beams_toml(8)},
    ),
    row(
        "sweep wave --sensors 2 --grid l1=0.1:1:3 --workers 100000 -o {tmp}/m.zarr",
        r"workers: a local cluster has at most \d+ workers on this machine .*found 100000",
        SweepError,
    ),
    # certify and check (issue 25); the certificate's own refusals come before any work
    row(
        "certify euler-bernoulli --sensors 3,4 --gain 0.1,1",
        "--band is needed: Δ is not a polynomial",
        CertificateError,
    ),
    row(
        "certify euler-bernoulli --sensors 3,4",
        "certify --sensors/--cm needs --gain",
        ObserverError,
    ),
    row("certify airy --band 5", "irrational entries", CertificateError),
    row("certify wave --sensors 2 --gain 1 --band 0", "--band must be", NumericError),
    row(
        "certify {tmp}/graded.toml --sensors 2 --gain 1 --band 5",
        "z-dependent coefficients",
        CertificateError,
        **{"graded.toml": GRADED},
    ),
    # the decay rate (issue 25, part 2): z-dependence only as rational functions of z with
    # rational coefficients, order 1 only; refused before the SDP's work
    row(
        "certify {tmp}/sqrt.toml --sensors 2 --gain 1 --rate",
        r"H\[2,2\] = sqrt\(z \+ 1\) is not a rational function of z",
        RateProofError,
        **{"sqrt.toml": graded("sqrt(1 + z)")},
    ),
    row(
        "certify {tmp}/irrational.toml --sensors 2 --gain 1 --rate",
        r"H\[2,2\] = .*sqrt\(2\).* has a coefficient that is not a rational number",
        RateProofError,
        **{"irrational.toml": graded("1 + sqrt(2)*z")},
    ),
    row(
        "certify euler-bernoulli --sensors 3,4 --gain 0.1,1 --band 3 --rate",
        "this model has order N = 2. For it phdesign proves the spectral bound",
        RateProofError,
        seconds=10,
    ),
    row("check {tmp}/missing.json", "cannot read the proof file", OutputFileError),
    row("check {tmp}/bad.json", "is not JSON", OutputFileError, **{"bad.json": "{not json"}),
    # ---- issue 27, the remainder: disturbances in simulate, tune and sweep
    row(
        "simulate wave --w w1:1",
        "--w: model 'wave' has no disturbance channel",
        ParameterError,
    ),
    row(
        "simulate {tmp}/dtw.toml --w w2:sin(3*t)",
        "--w: unknown disturbance 'w2'; the model's disturbances are w1",
        ParameterError,
        **{"dtw.toml": DAMPED_TIP},
    ),
    row(
        "simulate {tmp}/dtw.toml --disturbance-noise 1,2",
        "--disturbance-noise: expected 1 values",
        NumericError,
        **{"dtw.toml": DAMPED_TIP},
    ),
    row(
        "simulate wave --disturbance-noise 1",
        "--disturbance-noise: model 'wave' has no disturbance channel",
        ParameterError,
    ),
    row(
        "tune {tmp}/dtw.toml --sensors 1 --objective unknown",
        "argument --objective: invalid choice: 'unknown'",
        None,
        **{"dtw.toml": DAMPED_TIP},
    ),
    row(
        "tune {tmp}/dtw.toml --sensors 1 --max-hinf -1",
        "--max-hinf must be a finite positive number; found -1.0",
        NumericError,
        **{"dtw.toml": DAMPED_TIP},
    ),
    row(
        "tune {tmp}/dtw.toml --sensors 1 --max-hinf 0",
        "--max-hinf must be a finite positive number; found 0.0",
        NumericError,
        **{"dtw.toml": DAMPED_TIP},
    ),
    row(
        "tune {tmp}/dtw.toml --sensors 1 --objective hinf --max-hinf 1",
        "--max-hinf bounds the abscissa objective; --objective hinf takes --min-decay",
        NumericError,
        **{"dtw.toml": DAMPED_TIP},
    ),
    row(
        "tune {tmp}/dtw.toml --sensors 1 --objective h2 --at 1",
        "--at does not go with the disturbance objectives",
        NumericError,
        **{"dtw.toml": DAMPED_TIP},
    ),
    row(
        "tune {tmp}/dtw.toml --sensors 1 --performance integral(e1)",
        "--performance needs --objective hinf or h2, or --max-hinf",
        NumericError,
        **{"dtw.toml": DAMPED_TIP},
    ),
    row(
        "tune wave --sensors 2 --objective hinf --performance integral(e1)",
        "model 'wave' has no disturbance",
        NumericError,
    ),
    row(
        "tradeoff wave --sensors 2 --against hinf --at 1",
        "--at belongs to the RMS trade-off",
        NumericError,
    ),
    row(
        "tradeoff wave --sensors 2 --against hinf --scales 0.5:1:2",
        "the disturbance gain needs performance outputs",
        NumericError,
    ),
    row(
        "simulate {tmp}/dtw.toml --disturbance-noise -1",
        "--disturbance-noise: intensities must be finite and non-negative",
        NumericError,
        **{"dtw.toml": DAMPED_TIP},
    ),
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
        elif text.startswith("symlink:"):
            path.symlink_to(text.removeprefix("symlink:"))
        elif text.startswith("fifo:"):
            os.mkfifo(path)
        elif text.startswith("bytes:"):  # a TOML file of that many bytes (comments)
            path.write_text(("# filler\n" * (int(text[6:]) // 9 + 1))[: int(text[6:])])
        else:
            path.write_text(text)
    return [arg.replace("{tmp}", str(tmp_path)) for arg in row.argv]


def _snapshot(folder) -> dict[str, int]:
    return {p.name: p.lstat().st_mtime_ns for p in folder.iterdir()}


@pytest.mark.parametrize("bad", ROWS, ids=[r.id for r in ROWS])
def test_bad_input(bad: Row, tmp_path, capsys):
    argv = _materialize(bad, tmp_path)
    before = _snapshot(tmp_path)
    start = time.perf_counter()
    status = main(argv)
    elapsed = time.perf_counter() - start
    out, err = capsys.readouterr()
    if bad.seconds is not None:
        assert elapsed <= bad.seconds, f"refused after {elapsed:.1f} s; expected <= {bad.seconds}"
    assert status == 2, f"exit status {status}; stderr {err!r}"
    assert err.count("\n") == 1, f"expected one stderr line; found {err!r}"
    assert bad.message in err or re.search(bad.message, err), err
    assert "Traceback" not in err
    assert out == ""
    after = _snapshot(tmp_path)
    assert after == before, "a bad command must not write or touch any file"
    if bad.error is not None:
        with pytest.raises(bad.error):
            main(argv, reraise=True)
        capsys.readouterr()


def test_table_has_more_than_160_rows():
    """Issue 7 asked for 60, issue 12 for more than 160; the summary prints the pass count."""
    assert len(ROWS) > 160
