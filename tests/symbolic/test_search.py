"""All-sensor search: verdicts, minimal sets, agreement with the single classifier.

For unit-row sensors, a variant holds iff every unmeasured output j has
t_j = T^{-1}(0; e_j) (error inputs 0, error outputs e_j) vanishing on the selected traces.

Beam (u = (e1(0), e1'(0), e2(1), e2'(1)), y = (e2'(0), -e2(0), e1'(1), -e1(1))):
with all inputs 0 and y = e_j, each t_j has exactly one non-zero trace:
    t_1: e2'(0),  t_2: e2(0),  t_3: e1'(1),  t_4: e1(1).
So a variant requires output j iff it selects that trace:
    3.1.1 (all traces at a)          -> {1, 2}      3.1.2 (all at b)       -> {3, 4}
    3.3.1 e(a), e'(a), e(b)          -> {1, 2, 4}   3.3.2 e(a), e'(a), e'(b) -> {1, 2, 3}
    3.3.3 e(b), e'(b), e(a)          -> {2, 3, 4}   3.3.4 e(b), e'(b), e'(a) -> {1, 3, 4}
  3.4 with x1 = momentum (e1), x2 = curvature (e2):
    v1 e(a), e1'(a), e1(b)  -> {2, 4}      v2 e(a), e2'(a), e1'(b) -> {1, 2, 3}
    v3 e(b), e1'(b), e1(a)  -> {3, 4}      v4 e(b), e2'(b), e1'(a) -> {4}
  3.4 with the blocks swapped (x1 = curvature; Assumption 3.1 holds with Q2 = -1):
    v1 e(a), e2'(a), e2(b)  -> {1, 2}      v2 e(a), e1'(a), e2'(b) -> {2}
    v3 e(b), e2'(b), e2(a)  -> {2, 4}      v4 e(b), e1'(b), e2'(a) -> {1, 3, 4}
Every exponential requirement contains output 2 or output 4, and {2}, {4} are
requirements themselves: the minimal exponential sets are {2} and {4}.  (With the
paper's partition only, they would be {4} and {1, 2, 3}.)  Proposition 3.1's sets
{1, 2} and {3, 4} are exponential anyway, so no set is merely asymptotic; the sets
without 2 and 4 ({1}, {3}, {1, 3}) are inconclusive, minimal {1} and {3}.
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import pytest
import sympy

from phdesign.core.errors import ObserverError
from phdesign.models import load_builtin
from phdesign.symbolic.classify import classify
from phdesign.symbolic.observer import sensor_matrix
from phdesign.symbolic.search import candidates, search_sensors

sys.path.insert(0, str(Path(__file__).parent))
from synthetic import coupled_beams


@pytest.fixture(scope="module")
def beam():
    return load_builtin("euler-bernoulli")


def test_beam_requirements(beam):
    # the table of the module docstring
    required = {
        (c.name, None if c.partition is None else c.partition.x1): c.required
        for c in candidates(beam)
    }
    assert required == {
        ("3.1.1", None): (1, 2),
        ("3.1.2", None): (3, 4),
        ("3.3.1", None): (1, 2, 4),
        ("3.3.2", None): (1, 2, 3),
        ("3.3.3", None): (2, 3, 4),
        ("3.3.4", None): (1, 3, 4),
        ("3.4.1", (1,)): (2, 4),
        ("3.4.2", (1,)): (1, 2, 3),
        ("3.4.3", (1,)): (3, 4),
        ("3.4.4", (1,)): (4,),
        ("3.4.1", (2,)): (1, 2),
        ("3.4.2", (2,)): (2,),
        ("3.4.3", (2,)): (2, 4),
        ("3.4.4", (2,)): (1, 3, 4),
    }


def test_beam_minimal_sets(beam):
    found = search_sensors(beam)
    assert len(found.subsets) == 15
    assert found.minimal == {
        "exponential": ((2,), (4,)),
        "asymptotic": (),
        "inconclusive": ((1,), (3,)),
    }
    # the paper's §IV-D pair is exponential, through 3.4 variant 3 among others
    assert "3.4.3" in found.subset([3, 4]).holding
    # y4 alone (tip velocity): 3.4 variant 4, RHS = e1(1)^2 + e2(1)^2 + e2'(1)^2 + e1'(0)^2
    # = (1 + l^2) e1(1)^2 with e2'(1) = l e1(1), LHS = l e1(1)^2: κ* = l/(1+l^2) = 1/2 at l = 1
    tip = found.subset([4])
    assert (tip.verdict, tip.best, tip.kappa) == ("exponential", "3.4.4", pytest.approx(0.5))


def test_search_agrees_with_classify(beam):
    gains = (sympy.Rational(1, 2), 2, 1, 3)
    found = search_sensors(beam, gain=gains)
    for sensors in itertools.chain.from_iterable(
        itertools.combinations(range(1, 5), q) for q in range(1, 5)
    ):
        single = classify(
            beam, sensor_matrix(sensors, 4), sympy.diag(*[gains[j - 1] for j in sensors])
        )
        entry = found.subset(sensors)
        assert entry.verdict == single.verdict, sensors
        holding = {f"{r.proposition}.{r.variant}" for r in single.results if r.holds}
        assert set(entry.holding) == holding
        best = single.best
        if best is not None:
            assert entry.best == f"{best.proposition}.{best.variant}"
            # batched float κ* against the exact κ* of the same variant: 1e-12 relative
            assert entry.kappa == pytest.approx(float(best.kappa), rel=1e-12)


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        # wave: u = (e1(0), e2(1)), y = (-e2(0), e1(1)); t_1 = e2(0) at a, t_2 = e1(1) at b:
        # one damper at either end is exponential (3.2)
        ("wave", {"exponential": ((1,), (2,)), "asymptotic": (), "inconclusive": ()}),
        # timoshenko: t_1 = e1(0), t_2 = e3(0), t_3 = e2(1), t_4 = e4(1): 3.2.1 needs {1, 2},
        # 3.2.2 needs {3, 4}: both sensors of one end
        (
            "timoshenko",
            {
                "exponential": ((1, 2), (3, 4)),
                "asymptotic": (),
                "inconclusive": ((1,), (2,), (3,), (4,)),
            },
        ),
        # airy (N = 3, only 3.1): t_1 = e1''(0) (a), t_2 = e1''(1) (b),
        # t_3: e1'(0) = -e1'(1) = 1/sqrt(2) touches both ends: 3.1.1 needs {1, 3}, 3.1.2 {2, 3}
        (
            "airy",
            {
                "exponential": (),
                "asymptotic": ((1, 3), (2, 3)),
                "inconclusive": ((1,), (2,), (3,)),
            },
        ),
    ],
)
def test_builtin_minimal_sets(name, expected):
    assert search_sensors(load_builtin(name)).minimal == expected


def test_minimal_sets_definition_on_synthetic_model():
    # brute force of the definition: a set is minimal for its verdict when no proper
    # subset has the same verdict
    model = coupled_beams(2, seed=3)
    found = search_sensors(model)
    verdict = {s.sensors: s.verdict for s in found.subsets}
    for v in ("exponential", "asymptotic", "inconclusive"):
        brute = sorted(
            (
                s
                for s, w in verdict.items()
                if w == v
                and not any(
                    verdict[sub] == v
                    for q in range(1, len(s))
                    for sub in itertools.combinations(s, q)
                )
            ),
            key=lambda s: (len(s), s),
        )
        assert list(found.minimal[v]) == brute


def test_gain_checks(beam):
    with pytest.raises(
        ObserverError,
        match=r"expected 4 diagonal values \(one per output\) or a single one; found 2",
    ):
        search_sensors(beam, gain=[1, 2])
    with pytest.raises(ObserverError, match=r"L \+ Lᵀ must be positive definite.*minor 2 = -8"):
        search_sensors(beam, gain=[1, -2, 1, 1])
    with pytest.raises(ObserverError, match=r"takes diagonal gains"):
        search_sensors(beam, gain=[[1, 1, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    with pytest.raises(ObserverError, match=r"write gain=\[0.1, 1\]"):
        search_sensors(beam, gain="1,2")  # text lists are the command line's
    symbolic = search_sensors(beam, gain="symbolic")  # verdicts only: they are gain-free
    assert symbolic.minimal == search_sensors(beam).minimal
    assert all(s.kappa is None for s in symbolic.subsets)


def test_progress_callback_on_long_search():
    calls = []
    search_sensors(coupled_beams(3), progress=lambda done, total: calls.append((done, total)))
    assert calls[-1] == (4095, 4095)


def test_pure_python_and_numpy_kappa_paths_agree(beam, monkeypatch):
    from phdesign.symbolic import search_kappa

    gain = [0.5, 2, 1, 3]
    pure = search_sensors(beam, gain=gain)
    monkeypatch.setattr(search_kappa, "PURE_PYTHON_JOBS", 0)  # force the batched numpy path
    batched = search_sensors(beam, gain=gain)
    for a, b in zip(pure.subsets, batched.subsets, strict=True):
        assert (a.sensors, a.verdict, a.best, a.unbounded) == (
            b.sensors,
            b.verdict,
            b.best,
            b.unbounded,
        )
        if a.kappa is not None:
            # Jacobi rotations vs LAPACK on 1x1..4x4 matrices: 1e-12 relative
            assert a.kappa == pytest.approx(b.kappa, rel=1e-12)
