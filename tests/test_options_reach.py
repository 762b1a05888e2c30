"""Issue 30: every documented option of every numeric command reaches the computation.

``loop spectrum --resolution 20`` and ``--resolution 50`` both ran the pair (20, 30), and
``simulate --dt`` dropped ``--u``. Each row runs a command with and without one option
(in-process, ``--json``, cheap models and small resolutions) and checks that the result
changes the way the option says. An option that only acts with another one is run with it
(``--tol`` of ``simulate`` with ``--scheme midpoint``, ``--x0`` of ``export`` with
``--verify``); an option documented to change nothing in a case (``--feedback-outputs``
naming the collocated outputs, the only ones allowed) is checked to change nothing.
"""

from __future__ import annotations

import contextlib
import functools
import io
import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest

from phdesign.cli import main


def differs(base: Any, value: Any) -> bool:
    return base != value


def same(base: Any, value: Any) -> bool:
    return base == value


def equals(expected: Any) -> Callable[[Any, Any], bool]:
    return lambda base, value: value == expected


def scaled(factor: float) -> Callable[[Any, Any], bool]:
    """Every number of ``value`` is ``factor`` times the base's (to 1e-9)."""

    def check(base: Any, value: Any) -> bool:
        return all(
            math.isclose(v, factor * b, rel_tol=1e-9) for b, v in zip(base, value, strict=True)
        )

    return check


@dataclass(frozen=True)
class Row:
    """``variant`` against ``base``: ``key`` (a dotted path into the JSON) satisfies ``expect``."""

    base: str
    variant: str
    key: str
    expect: Callable[[Any, Any], bool] = differs
    change: str = ""  # how the variant differs, for the test id (default: its extra words)

    @property
    def id(self) -> str:
        words = self.base.split()
        command = " ".join(words[:2] if words[0] == "loop" else words[:1])
        change = self.change or self.variant.removeprefix(self.base).strip()
        return f"{command}: {change} -> {self.key}"


def add(base: str, extra: str, key: str, expect: Callable[[Any, Any], bool] = differs) -> Row:
    """The base with ``extra`` appended."""
    return Row(base, f"{base} {extra}", key, expect)


def swap(
    base: str, old: str, new: str, key: str, expect: Callable[[Any, Any], bool] = differs
) -> Row:
    """The base with ``old`` replaced by ``new``."""
    assert old in base, (old, base)
    return Row(base, base.replace(old, new), key, expect, f"{old} => {new}")


def fewer(count: int) -> Callable[[Any, Any], bool]:
    return lambda base, value: len(value) == count < len(base)


def near(target: float, tol: float = 1e-5) -> Callable[[Any, Any], bool]:
    return lambda base, value: math.isclose(value, target, abs_tol=tol)


@functools.cache
def run(argv: str) -> dict[str, Any]:
    """The JSON a command prints (cached: the bases are shared by many rows)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(argv.split())
    assert status == 0, f"{argv}: exit {status}: {err.getvalue()}"
    return json.loads(out.getvalue())


def pick(data: Any, key: str) -> Any:
    for part in key.split("."):
        data = data[int(part)] if isinstance(data, list) else data[part]
    return data


# spectrum: the damped string, ½ ln|(1 - k)/(1 + k)| (k = 0.5 and k = 2 give the same)
S = "spectrum wave --resolution 8 --json"
SD = f"{S} --sensors 2 --gain 0.5"
# simulate
M = "simulate wave --resolution 6 --samples 5 --x0 x1:z --json"
MD = f"{M} --sensors 2 --gain 0.5"
MID = f"{MD} --scheme midpoint"
DT = f"{MD} --dt 0.5"
NOISY = f"{MD} --noise-intensity 1 --seed 1"
# tune: the beam with one sensor is a 1-D search
T = "tune euler-bernoulli --starts 1 --json"
T4 = f"{T} --sensors 4"
RMS = "tune euler-bernoulli --sensors 4 --json --max-rms 0.3"  # the noise-aware search
DECAY = "tune euler-bernoulli --sensors 4 --json --objective rms --min-decay 1"
# noise and tradeoff: a smooth functional of the string converges (its variance is 1/2)
N = "noise wave --sensors 2 --gain 1 --integral x2:1 --resolution 8 --json"
R = "tradeoff wave --sensors 2 --integral x2:1 --scales 0.1 --json"  # one gain, 0.1
# export: the string's observer of 6 states; the null device takes the file
E = "export wave --sensors 2 --gain 0.5 --dt 0.01 --format json -o /dev/null --json"
E6 = f"{E} --order 6"
EV = f"{E6} --verify"
EB = "export euler-bernoulli --sensors 3,4 --gain 0.1,1 --dt 0.01 --order 8 --format json"
EB += " -o /dev/null --json"
# the loop: u2 = -0.3 ŷ2 on the string, the observer measuring y2 with gain 0.5
LOOP = "wave --actuate 2 --sensors 2 --gain 0.5 --feedback 0.3"
LS = f"loop spectrum {LOOP} --resolution 8 --json"
LM = f"loop simulate {LOOP} --resolution 6 --samples 5 --x0 x1:z --json"
LT = "loop tune euler-bernoulli --actuate 3 --sensors 4 --starts 1 --json"
LT4 = "loop tune euler-bernoulli --actuate 4 --sensors 4 --starts 1 --tune feedback --json"
RMS_OK = 0.3 + 1e-6

ROWS = [
    # ------------------------------------------------------------------- spectrum
    add(SD, "--param rho=2", "spectral_abscissa"),
    swap(SD, "--sensors 2", "--cm [[0,3]]", "spectral_abscissa"),
    swap(SD, "--gain 0.5", "--gain 0.3", "spectral_abscissa"),
    Row(S, SD, "spectral_abscissa"),  # --sensors: the error system instead of the plant
    add(SD, "--method fd", "spectral_abscissa"),
    swap(SD, "--resolution 8", "--resolution 20", "resolutions.0", equals(20)),
    add(SD, "--max-resolution 9", "resolutions", equals([8, 12])),
    add(SD, "--tol 1e-15", "converged", equals(False)),
    add(SD, "--count 2", "rightmost", fewer(2)),
    # ------------------------------------------------------------------- simulate
    add(MD, "--param rho=2", "H"),
    swap(MD, "--sensors 2", "--cm [[0,3]]", "H_hat"),
    swap(MD, "--gain 0.5", "--gain 0.3", "H_hat"),
    Row(M, MD, "H_hat", lambda b, v: b is None and v is not None),
    add(MD, "--method fd", "method", equals("fd")),
    add(MD, "--method fd", "H_err"),
    swap(MD, "--resolution 6", "--resolution 8", "states", equals(18)),
    swap(MD, "--x0 x1:z", "--x0 x1:1", "H"),
    add(MD, "--xhat0 x1:1", "H_hat.0", lambda b, v: b == 0 < v),
    add(MD, "--t-end 2", "t", equals([0.0, 0.5, 1.0, 1.5, 2.0])),
    swap(MD, "--samples 5", "--samples 7", "t", lambda b, v: len(v) == 7),
    Row(MD, MID, "scheme", lambda b, v: b == "expm" and v.startswith("midpoint")),
    Row(MD, MID, "H_err"),
    add(MD, "--u u1:sin(t)", "H"),
    add(MID, "--tol 1e-2", "H_err"),  # --tol steers the midpoint rule's substeps
    Row(MD, DT, "H_hat"),
    add(DT, "--sampler point", "H_hat"),
    add(DT, "--u u1:sin(t)", "H"),  # --u was dropped by the sampled run
    add(MD, "--observer-resolution 4", "H_hat"),
    Row(MD, NOISY, "H_err"),
    swap(NOISY, "--seed 1", "--seed 2", "H_err"),
    swap(NOISY, "--noise-intensity 1", "--noise-intensity 4", "H_err"),
    add(MD, "--input-noise 1 --seed 1", "H"),
    # ------------------------------------------------------------------- tune
    add(T4, "--param d=0.5", "spectral_abscissa"),
    swap(T4, "--sensors 4", "--sensors 3", "gain"),
    # C_m = 2 e4ᵀ: the correction C_mᵀ L C_m = 4 L, so the tuned L is a quarter
    swap(
        T4,
        "--sensors 4",
        "--cm [[0,0,0,2]]",
        "gain.0.0",
        lambda b, v: math.isclose(v, b / 4, rel_tol=1e-4),
    ),
    add(f"{T} --sensors 3,4", "--full", "evaluations", lambda b, v: v > b),
    swap(T4, "--starts 1", "--starts 2", "starts", lambda b, v: len(b) == 1 and len(v) == 2),
    add(T4, "--robust 5%", "gain"),
    Row(T4, RMS, "spectral_abscissa", lambda b, v: b < v, "--max-rms 0.3"),  # slower
    add(RMS, "--intensity 4", "gain"),
    add(RMS, "--intensity 4", "rms", lambda b, v: b <= RMS_OK and v <= RMS_OK),
    add(RMS, "--input-noise 0.01", "gain"),
    add(RMS, "--at 0.5", "noise.performance.0.name", equals("w(0.5)")),
    add(RMS, "--trace e1(1)", "noise.performance.0.name", equals("e1(1)")),
    add(RMS, "--integral x2:1", "noise.performance.0.name", equals("int(x2:1)")),
    Row(
        T4, DECAY, "spectral_abscissa", lambda b, v: b < -1.5 and near(-1)(b, v), "--objective rms"
    ),
    swap(DECAY, "--min-decay 1", "--min-decay 2", "spectral_abscissa", near(-2)),
    # ------------------------------------------------------------------- noise
    add(N, "--param rho=2", "performance.0.values"),
    swap(N, "--sensors 2", "--cm [[0,3]]", "performance.0.values"),
    swap(N, "--gain 1", "--gain 0.5", "performance.0.values"),
    add(N, "--intensity 2", "performance.0.values", scaled(2.0)),
    add(N, "--input-noise 1", "performance.0.values"),
    Row(
        N,
        "noise euler-bernoulli --sensors 3,4 --gain 0.1,1 --at 0.5 --resolution 8 --json",
        "performance.0.name",
        equals("w(0.5)"),
        "--at 0.5 (the beam)",
    ),
    add(N, "--trace e1(1)", "performance.0.name", equals("e1(1)")),
    swap(N, "--integral x2:1", "--integral x2:z", "performance.0.values"),
    add(N, "--method fd", "method", equals("fd")),
    swap(N, "--resolution 8", "--resolution 10", "resolutions.0", equals(10)),
    add(N, "--tol 1e-15", "performance.0.converged", lambda b, v: b and not v),
    # ------------------------------------------------------------------- tradeoff
    add(R, "--param rho=2", "points.0.rms"),
    swap(R, "--sensors 2", "--cm [[0,3]]", "points.0.rms"),
    add(R, "--direction 2", "points.0.gain", equals([[0.2]])),
    swap(R, "--scales 0.1", "--grid 0.1:1:2", "family", equals("grid")),
    swap(R, "--scales 0.1", "--scales 0.1:10:3", "points", lambda b, v: len(b) == 1 == len(v) - 2),
    add(R, "--intensity 4", "points.0.rms.int(x2:1)", lambda b, v: math.isclose(v, 2 * b)),
    add(R, "--input-noise 1", "points.0.rms"),
    swap(R, "--integral x2:1", "--trace e1(1)", "performance", equals("e1(1)")),
    Row(
        R,
        "tradeoff euler-bernoulli --sensors 3,4 --at 0.5 --scales 0.1 --json",
        "performance",
        equals("w(0.5)"),
        "--at 0.5 (the beam)",
    ),
    add(R, "--method fd", "points.0.spectral_abscissa"),
    # ------------------------------------------------------------------- export
    add(E6, "--param rho=2", "A"),
    swap(E6, "--sensors 2", "--cm [[0,3]]", "B"),
    # the gain as given reaches A; the designed gains start from it (issue 29)
    swap(f"{E6} --design given", "--gain 0.5", "--gain 0.3", "A"),
    add(E6, "--design passive", "design.chosen", equals("passive")),
    add(f"{E6} --design kalman", "--process-noise 0.01", "A"),
    add(f"{E6} --design kalman", "--sensor-noise 10", "A"),
    add(E6, "--max-ratio 0.5", "design.bound", equals(0.5)),
    add(
        EV,
        "--x0 x1:z --x0 x2:z",
        "design.candidates.0.floors.states",
        lambda b, v: len(b) == 5 and [s["x0"] for s in v] == ["x1:z", "x2:z"],
    ),
    swap(E6, "--dt 0.01", "--dt 0.02", "dt", equals(0.02)),
    add(E6, "--sampler point", "A"),
    add(E, "--order 8", "order", equals(8)),
    add(E, "--reduce modal", "order_selection.reduction", equals("modal")),
    add(E, "--tol 1e-2", "order", lambda b, v: v < b),
    add(E, "--output-tol 0.5", "order", lambda b, v: v < b),
    Row(E6, EV, "verification", lambda b, v: b is None and v is not None),
    add(EV, "--x0 x1:z", "verification.x0", equals("x1:z")),
    add(EV, "--t-end 2", "verification.t", lambda b, v: b[-1] == 5.0 and v[-1] == 2.0),
    add(EV, "--plant-resolution 20", "verification.plant_degree", equals(20)),
    add(
        EB,
        "--at 0.5,1",
        "outputs",
        lambda b, v: b[-1:] == ["w(1)"] and v[-2:] == ["w(0.5)", "w(1)"],
    ),
    # ------------------------------------------------------------------- loop spectrum
    add(LS, "--param rho=2", "spectral_abscissa"),
    swap(LS, "--actuate 2", "--actuate 1", "design", lambda b, v: v.startswith("u1 = -K ŷ1")),
    swap(LS, "--feedback 0.3", "--feedback 0.6", "plant_abscissa"),
    add(LS, "--feedback-outputs 2", "spectral_abscissa", same),  # the collocated one
    add(LS, "--feedback-source measured", "design", lambda b, v: v.startswith("u2 = -K y2")),
    swap(LS, "--sensors 2", "--cm [[0,3]]", "error_abscissa"),
    swap(LS, "--gain 0.5", "--gain 0.2", "error_abscissa"),
    add(LS, "--method fd", "plant_abscissa"),
    swap(LS, "--resolution 8", "--resolution 20", "resolutions.0", equals(20)),
    add(LS, "--tol 1e-15", "converged", lambda b, v: b and not v),
    add(LS, "--count 2", "rightmost", fewer(2)),
    # ------------------------------------------------------------------- loop simulate
    add(LM, "--param rho=2", "H"),
    swap(LM, "--actuate 2", "--actuate 1", "H"),
    swap(LM, "--feedback 0.3", "--feedback 0.6", "H"),
    add(LM, "--feedback-source measured", "H"),
    swap(LM, "--sensors 2", "--cm [[0,3]]", "H_err"),
    swap(LM, "--gain 0.5", "--gain 0.2", "H_err"),
    add(LM, "--method fd", "H"),
    swap(LM, "--resolution 6", "--resolution 8", "states", lambda b, v: v > b),
    swap(LM, "--x0 x1:z", "--x0 x1:1", "H"),
    add(LM, "--xhat0 x1:1", "H_hat.0", lambda b, v: b == 0 < v),
    add(LM, "--u u1:sin(t)", "H"),
    add(LM, "--t-end 2", "t", lambda b, v: v[-1] == 2.0),
    swap(LM, "--samples 5", "--samples 7", "t", lambda b, v: len(v) == 7),
    add(LM, "--scheme midpoint", "H_err"),
    # ------------------------------------------------------------------- loop tune
    add(LT, "--param d=0.5", "spectral_abscissa"),
    add(LT, "--tune gain", "feedback", equals([[1.0]])),
    add(f"{LT} --tune gain", "--feedback 2", "plant_abscissa"),
    add(f"{LT} --tune feedback", "--gain 2", "error_abscissa"),
    swap(LT, "--sensors 4", "--sensors 3", "gain"),
    swap(LT, "--sensors 4", "--cm [[0,0,0,2]]", "gain"),
    swap(LT, "--actuate 3", "--actuate 4", "feedback"),
    add(LT4, "--feedback-source measured", "feedback_source", equals("measured")),
]


@pytest.mark.parametrize("row", ROWS, ids=[r.id for r in ROWS])
def test_the_option_reaches_the_computation(row: Row):
    base, value = pick(run(row.base), row.key), pick(run(row.variant), row.key)
    assert row.expect(base, value), f"{row.key}: {base!r} -> {value!r}"


def test_tune_seed_reaches_the_random_grid(monkeypatch):
    """``--seed`` acts on the random grid of more than 625 points (five or more gains)."""
    import types

    import phdesign.numeric.tuning.search as tune_module

    original, seeds = tune_module.grid_points, []

    def recording(search, log_range, seed):
        seeds.append(seed)
        return original(search, log_range, seed)

    monkeypatch.setattr(tune_module, "grid_points", recording)
    run.__wrapped__(f"{T4} --seed 7")
    run.__wrapped__("loop tune euler-bernoulli --actuate 4 --sensors 4 --starts 1 --seed 5 --json")
    assert seeds == [7, 5, 5]  # loop tune: K on the controlled plant, then L
    five = types.SimpleNamespace(q=5)  # 5^5 grid points: a seeded sample instead
    assert not np.array_equal(original(five, (-1.0, 1.0), 1), original(five, (-1.0, 1.0), 2))
    assert np.array_equal(original(five, (-1.0, 1.0), 1), original(five, (-1.0, 1.0), 1))


def test_loop_tune_passes_full_and_starts_to_both_searches(monkeypatch):
    import phdesign.numeric.control.tuning as loop_tune

    original, calls = loop_tune.tune, []

    def recording(nm, C_m, **options):
        calls.append({k: options[k] for k in ("full", "starts", "seed")})
        return original(nm, C_m, **options)

    monkeypatch.setattr(loop_tune, "tune", recording)
    run.__wrapped__("loop tune wave --actuate 2 --sensors 2 --starts 2 --seed 3 --full --json")
    assert calls == [{"full": True, "starts": 2, "seed": 3}] * 2


SIM_FILE = "simulate wave --sensors 2 --gain 0.5 --resolution 6 --samples 5 --x0 x1:z"
FILE_COMMANDS = [
    (SIM_FILE, "csv"),
    (f"loop simulate {LOOP} --resolution 6 --samples 5 --x0 x1:z", "csv"),
    ("tradeoff wave --sensors 2 --integral x2:1 --scales 0.1 --csv", "csv"),
    ("export wave --sensors 2 --gain 0.5 --dt 0.01 --order 6 --format npz", "npz"),
]


@pytest.mark.parametrize(
    ("argv", "suffix"), FILE_COMMANDS, ids=[a.split()[0] for a, _ in FILE_COMMANDS]
)
def test_output_and_force_write_and_replace_the_file(argv, suffix, tmp_path, capsys):
    target = tmp_path / f"out.{suffix}"
    target.write_bytes(b"an earlier run")
    command = [*argv.split(), "-o", str(target)]
    assert main(command) == 2  # exists: kept without --force
    assert target.read_bytes() == b"an earlier run"
    assert main([*command, "--force"]) == 0
    assert target.stat().st_size > 0
    assert target.read_bytes() != b"an earlier run"
    if suffix == "csv":
        assert target.read_text().splitlines()[0].split(",")[0] in ("t", "l1")
    capsys.readouterr()
