"""The design objects' ``progress`` argument: the stages of each long method reach it."""

from __future__ import annotations

import pytest

from phdesign import Loop, Observer, Plant
from phdesign.models import load_builtin


@pytest.fixture(scope="module")
def string() -> Observer:
    return Observer(load_builtin("wave"), sensors=[2], gain=0.5)


CALLS = {
    "spectrum": (lambda o, p: o.spectrum(progress=p), "spectrum: pair ("),
    "simulate": (
        lambda o, p: o.simulate("x2: 1", t_end=0.5, samples=3, progress=p),
        "simulate: the error system",
    ),
    "noise": (lambda o, p: o.noise(performance="x2: 1", progress=p), "noise: resolution "),
    "tradeoff": (
        lambda o, p: o.tradeoff(scales=[1.0], performance="x2: 1", progress=p),
        "tradeoff: gain 1 of 1 > noise: resolution ",
    ),
    "export": (
        lambda o, p: o.export(dt=1e-2, order=12, progress=p),
        "export: the converged error spectrum > spectrum: pair (",
    ),
    "tune": (lambda o, p: o.tune(starts=1, progress=p), "tune: verification, "),
    "plant spectrum": (lambda o, p: Plant(o.model).spectrum(progress=p), "spectrum: pair ("),
    "loop spectrum": (
        lambda o, p: Loop(o.model, actuate=[2], sensors=[2]).spectrum(progress=p),
        "loop: the assembled loop > spectrum: pair (",
    ),
}


@pytest.mark.parametrize("name", sorted(CALLS))
def test_the_stages_reach_the_callback(string, name):
    call, expected = CALLS[name]
    seen: list[str] = []
    call(string, seen.append)
    assert any(line.startswith(expected) for line in seen), seen
