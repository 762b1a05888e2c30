"""The thread policy (phdesign.numeric.threads) holds at every public numeric entry point.

Each entry point runs with the caller's BLAS at two threads; a probe inside the work it
builds (``MODEL_WORK.get``: every discretization, dimensionless model and eigen stage is
fetched there) records the BLAS threads in force, read by threadpoolctl's own scan (not
the policy's cached list of libraries).  The policy allows ``SMALL_DENSE_THREADS``: an
entry point that forgot it runs its small dense problems on two threads, and fails.
"""

from __future__ import annotations

import numpy as np
import pytest
from threadpoolctl import ThreadpoolController, threadpool_info, threadpool_limits

import phdesign as phd
import phdesign.numeric.threads as threads
from phdesign.core.cache import MODEL_WORK
from phdesign.numeric.spectrum.evaluator import AbscissaEvaluator
from phdesign.numeric.threads import SMALL_DENSE_THREADS, small_dense_threads

CALLER_THREADS = 2  # the caller's setting, above the policy's


def blas_threads() -> int:
    """The most threads any loaded BLAS library runs on now (a fresh threadpoolctl scan)."""
    return max(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas")


@pytest.fixture
def probe(monkeypatch):
    """Record the BLAS threads in force each time the work of a computation is fetched."""
    seen: list[int] = []
    fetch = MODEL_WORK.get

    def recording(owner, key, build):
        if len(seen) < 3:  # a scan costs a millisecond; a few calls tell
            seen.append(blas_threads())
        return fetch(owner, key, build)

    monkeypatch.setattr(MODEL_WORK, "get", recording)
    return seen


def wave_observer(resolution: int | None = 8) -> phd.Observer:
    return phd.Observer(phd.load("wave"), sensors=[2], gain=0.5, resolution=resolution)


def tip_force_observer() -> phd.Observer:
    """The string observed through its tip velocity, pushed by an unknown tip force."""
    from phdesign.io import model_from_dict, model_to_dict

    data = model_to_dict(phd.load("wave"))
    data["ports"]["unknown"] = [2]
    return phd.Observer(model_from_dict(data), sensors=[2], gain=0.5)


def beam_loop() -> phd.Loop:
    beam = phd.Observer(phd.load("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    return phd.Loop(beam, actuate=3)


def evaluator() -> None:
    wave = phd.to_numeric(phd.load("wave"))
    AbscissaEvaluator(wave, np.array([[0.0, 1.0]]), 12)(np.array([[0.5]]))


def sweep_point() -> None:
    pytest.importorskip("xarray", reason="install the sweep extra")
    pytest.importorskip("zarr", reason="install the sweep extra")
    phd.sweep("wave", sensors=[2], grid={"l1": [0.5]}, scheduler="synchronous", progress=False)


SIMULATION = {"t_end": 0.2, "samples": 3}
ENTRY_POINTS = {
    "spectrum": lambda: wave_observer(None).spectrum(),
    "plant spectrum": lambda: phd.Plant(phd.load("wave")).spectrum(),
    "abscissa evaluator": evaluator,
    "simulate": lambda: wave_observer().simulate("x2: 1", **SIMULATION),
    "simulate noisy": lambda: wave_observer().simulate("x2: 1", noise_intensity=0.1, **SIMULATION),
    "simulate sampled": lambda: wave_observer().simulate(
        "x2: 1", dt=0.05, sampler="point", **SIMULATION
    ),
    "tune": lambda: wave_observer().tune(starts=1),
    "noise": lambda: wave_observer(None).noise(),
    "gain": lambda: tip_force_observer().gain(performance="integral(e1)", intensity=0.1),
    "tradeoff": lambda: wave_observer(None).tradeoff(scales=[1.0], performance="x2: 1"),
    "export": lambda: wave_observer().export(dt=0.01, order=6),
    "export verified": lambda: wave_observer().export(dt=0.01, order=6, verify=True, t_end=0.5),
    "loop spectrum": lambda: beam_loop().spectrum(),
    "loop simulate": lambda: beam_loop().simulate(x0="x2: z", **SIMULATION),
    "loop tune": lambda: beam_loop().tune("feedback", starts=1),
    "sweep point": sweep_point,
}


@pytest.mark.parametrize("name", sorted(ENTRY_POINTS))
def test_every_entry_point_runs_its_small_dense_problems_within_the_policy(name, probe):
    with threadpool_limits(limits=CALLER_THREADS, user_api="blas"):
        if blas_threads() < CALLER_THREADS:
            pytest.skip("this BLAS cannot run two threads, so the policy cannot be seen")
        ENTRY_POINTS[name]()
        assert probe, f"{name}: the probe was never reached"
        assert max(probe) <= SMALL_DENSE_THREADS, (
            f"{name} ran its work on {max(probe)} BLAS threads; the policy allows "
            f"{SMALL_DENSE_THREADS}"
        )
        assert blas_threads() == CALLER_THREADS  # the caller's setting comes back


def test_the_probe_sees_the_callers_threads_outside_an_entry_point(probe):
    with threadpool_limits(limits=CALLER_THREADS, user_api="blas"):
        if blas_threads() < CALLER_THREADS:
            pytest.skip("this BLAS cannot run two threads")
        phd.discretize(phd.to_numeric(phd.load("wave")), "galerkin", 5)
    assert probe == [CALLER_THREADS]


def test_a_callers_limit_within_the_policy_is_left_alone(monkeypatch):
    calls = []
    for library in threads.blas_libraries():
        original = library.set_num_threads
        monkeypatch.setattr(
            library, "set_num_threads", lambda n, f=original: (calls.append(n), f(n))[1]
        )
    with threadpool_limits(limits=1, user_api="blas"), small_dense_threads():
        assert blas_threads() == 1
    assert calls == []  # nothing to cap, nothing to restore


def test_re_entering_the_policy_scans_the_libraries_once(monkeypatch):
    scans = []

    class Counting(ThreadpoolController):
        def __init__(self):
            scans.append(1)
            super().__init__()

    monkeypatch.setattr("threadpoolctl.ThreadpoolController", Counting)
    monkeypatch.setattr(threads, "_found", (-1, []))
    for _ in range(20):
        with small_dense_threads(), small_dense_threads():
            np.linalg.eigvals(np.eye(3))
    assert len(scans) == 1
