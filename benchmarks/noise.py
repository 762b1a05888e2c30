"""Benchmark: the noise figures of the paper's beam, a 40-point trade-off and the noise-aware
tuning, each against a peer run in this process (issue 24).

Targets (medians of the ratios of interleaved rounds; the machine's load is printed):

1. ``Observer(beam, sensors=[3, 4], gain=[0.1, 1]).noise()`` at most 3x its peer:
   ``scipy.linalg.solve_continuous_lyapunov`` on the standard form E^-1 A of the same
   error-system matrices (``noise_input``), at the report's resolutions;
2. a 40-point trade-off along s diag(0.1, 1), s log-spaced in [0.1, 10], at most 3x its
   peer, a Chebyshev + Lyapunov design loop written here: per gain, the same Lyapunov
   solves at that gain's noise resolutions, and the decay rate from the rectangular
   Chebyshev collocation of ``spectrum_peer.py`` (QZ eigenvalues at the degrees of
   phdesign's resolution pair for that gain, the eigenvalues that agree to 1e-8);
3. ``phdesign tune euler-bernoulli --sensors 3,4 --max-rms 0.3 --at 1`` at most 10x one
   ``phdesign noise euler-bernoulli --sensors 3,4 --gain 0.1,1`` (whole commands, as a
   user runs them).  The same ratio inside one process (``tune_noise()`` against
   ``obs.noise()``, no start-up) is printed beside it, with the search's evaluations: it
   is not the target.

How target 3 is read (issue 24: "``tune --max-rms`` <= 10x one ``noise`` report"): as
whole commands.  The issue writes its left side as the command and its option, and the
row of its table that the target answers timed the command (76 s of CPU, minutes of wall
time without progress); the targets it means inside a process name the Python call
(``obs.noise()``, ``obs.spectrum()``), and the one other target between two commands,
``export --verify`` against one spectrum command, is read the same way.  In one process
the tuning is a search (a log-grid of starts, then Nelder-Mead on an exact penalty,
:mod:`phdesign.numeric.noise.tuning`): it evaluates its merit, a resolved abscissa on a
resolution pair and the Lyapunov variances at one gain, about 500 times and verifies the
optimum with a full spectrum and noise report, so its ratio to one ``obs.noise()`` is about
90x; reaching 10x there would mean fewer evaluations, hence another tuned gain, and the
printed numbers must stay as they are (to 1e-12).

Run:  python benchmarks/noise.py   (exit 1 if a target is missed);
      python benchmarks/noise.py tune   (target 3 only, a few minutes)

Threads: default everywhere.  phdesign's entry points run BLAS on one thread inside
(``phdesign/numeric/threads.py``); the peers run with the default BLAS threads.  Printed
beside, not targets: the peers on one thread (like for like) and ``obs.noise()`` with the
thread policy switched off (``small_dense_threads(False)``: what the policy buys).
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import time
from collections.abc import Callable

import numpy as np
import scipy.linalg as sl
from _timing import PYTHON
from spectrum_peer import peer_eigenvalues

import phdesign as phd
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.noise.statistics import noise_input
from phdesign.numeric.noise.tradeoff import tradeoff
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.threads import small_dense_threads

SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
GAIN = np.diag([0.1, 1.0])
SCALES = np.geomspace(0.1, 10.0, 40)
NOISE_COMMAND = ["noise", "euler-bernoulli", "--sensors", "3,4", "--gain", "0.1,1"]
TUNE_COMMAND = ["tune", "euler-bernoulli", "--sensors", "3,4", "--max-rms", "0.3", "--at", "1"]


def policy(fn: Callable[[], object], enabled: bool = True) -> Callable[[], object]:
    """``fn`` inside the thread policy's block (one BLAS thread; ``enabled=False``: off)."""

    def limited() -> object:
        with small_dense_threads(enabled):
            return fn()

    return limited


def interleaved(calls: dict[str, Callable[[], object]], rounds: int) -> dict[str, list[float]]:
    """Wall seconds of each call, one round after another (A B C A B C ...), after a warm-up."""
    for fn in calls.values():
        fn()
    walls: dict[str, list[float]] = {name: [] for name in calls}
    for _ in range(rounds):
        for name, fn in calls.items():
            start = time.perf_counter()
            fn()
            walls[name].append(time.perf_counter() - start)
    return walls


def ratio(walls: dict[str, list[float]], a: str, b: str) -> float:
    """Median over the rounds of a's time over b's (each round a pair)."""
    return statistics.median(x / y for x, y in zip(walls[a], walls[b], strict=True))


def verdict(label: str, value: float, target: float) -> bool:
    """Print one target's line; return whether it is met."""
    ok = value <= target
    print(f"  {label}: {value:.2f}x, target <= {target:g}x: {'met' if ok else 'MISSED'}")
    return ok


def lyapunov_peer(systems, L: np.ndarray) -> list[np.ndarray]:  # type: ignore[no-untyped-def]
    """The peer of the noise figures: one scipy Lyapunov solve on E^-1 A per resolution."""
    out = []
    for d in systems:
        A, G, _ = noise_input(d, SENSORS, L, np.ones(2))
        F, H = np.linalg.solve(d.E, A), np.linalg.solve(d.E, G)
        out.append(sl.solve_continuous_lyapunov(F, -H @ H.T))
    return out


def noise_report(beam) -> bool:  # type: ignore[no-untyped-def]
    """Target 1: ``obs.noise()`` against the Lyapunov peer at the report's resolutions."""
    obs = phd.Observer(beam, sensors=[3, 4], gain=[0.1, 1])
    report = obs.noise()
    nm = obs.plant.numeric
    systems = [discretize(nm, "galerkin", p) for p in report.resolutions]
    walls = interleaved(
        {
            "obs.noise()": obs.noise,
            "peer": lambda: lyapunov_peer(systems, GAIN),
            "peer, one thread": policy(lambda: lyapunov_peer(systems, GAIN)),
            "obs.noise(), no thread policy": policy(obs.noise, enabled=False),
        },
        rounds=21,
    )
    print(report)
    print(f"noise report: resolutions {report.resolutions}, load {os.getloadavg()[0]:.2f}")
    for name, times in walls.items():
        print(f"  {name}: median {1e3 * statistics.median(times):.1f} ms")
    tip = systems[-1].displacement_basis(np.array([1.0]))[0]
    var = float(tip @ lyapunov_peer(systems[-1:], GAIN)[0] @ tip)
    mine = report.performance[0].values[-1]
    print(
        f"  tip variance at degree {report.resolutions[-1]}: report {mine:.12g}, scipy {var:.12g}"
    )
    alone = ratio(walls, "obs.noise()", "peer, one thread")
    print(f"  obs.noise() against the peer on one thread (like for like): {alone:.2f}x")
    off = ratio(walls, "obs.noise(), no thread policy", "peer")
    print(f"  obs.noise() without the thread policy against the peer: {off:.2f}x")
    converged = report.performance[0].converged and report.l2_gain.converged
    return verdict("obs.noise() / peer", ratio(walls, "obs.noise()", "peer"), 3.0) and converged


def chebyshev_decay(L: np.ndarray, coarse: int, fine: int) -> float:
    """Decay rate of the Chebyshev collocation at degrees (coarse, fine): agreed eigenvalues."""
    l1, l2 = float(L[0, 0]), float(L[1, 1])
    low, high = peer_eigenvalues(coarse + 1, l1, l2), peer_eigenvalues(fine + 1, l1, l2)
    drift = np.abs(high[:, None] - low[None, :]).min(axis=1)
    agreed = high[drift <= 1e-8 * np.maximum(1.0, np.abs(high))]
    return -float(agreed.real.max()) if agreed.size else float("nan")


def tradeoff_peer(systems, pairs, gains) -> list[float]:  # type: ignore[no-untyped-def]
    """Per gain: the Lyapunov peer at its noise resolutions, the Chebyshev decay rate."""
    rates = []
    for L, resolutions, (coarse, fine) in zip(gains, pairs[0], pairs[1], strict=True):
        lyapunov_peer([systems[p] for p in resolutions], L)
        rates.append(chebyshev_decay(L, coarse, fine))
    return rates


def trade_off(beam) -> bool:  # type: ignore[no-untyped-def]
    """Target 2: the 40-point trade-off against its peer over the same gains."""
    nm = phd.Plant(beam).numeric
    run = lambda: tradeoff(nm, SENSORS, direction=[0.1, 1.0], scales=SCALES)  # noqa: E731
    curve = run()
    gains = [p.gain for p in curve.points]
    spans = [spectrum(nm, SENSORS, L).resolutions[-2:] for L in gains]
    pairs = ([p.noise.resolutions for p in curve.points], spans)
    needed = {r for p in curve.points for r in p.noise.resolutions}
    systems = {r: discretize(nm, "galerkin", r) for r in sorted(needed)}
    rates = tradeoff_peer(systems, pairs, gains)
    mine = [p.decay_rate for p in curve.points]
    agree = [abs(a - b) / max(1.0, abs(b)) for a, b in zip(rates, mine, strict=True) if b]
    walls = interleaved(
        {
            "tradeoff": run,
            "peer": lambda: tradeoff_peer(systems, pairs, gains),
            "peer, one thread": policy(lambda: tradeoff_peer(systems, pairs, gains)),
        },
        rounds=3,
    )
    best = max(curve.points, key=lambda p: p.decay_rate or 0.0)
    print(
        f"trade-off: {len(curve.points)} gains, {len(curve.pareto_points)} Pareto-optimal; "
        f"fastest s = {best.scale:.4g}: decay rate {best.decay_rate:.4g}, tip-error rms "
        f"{best.rms:.4g}; load {os.getloadavg()[0]:.2f}"
    )
    print(
        f"  the peer's Chebyshev decay rates agree with phdesign's to {max(agree):.1e} "
        f"(relative, {len(agree)} gains with a converged rate)"
    )
    for name, times in walls.items():
        print(f"  {name}: median {statistics.median(times):.3f} s")
    alone = ratio(walls, "tradeoff", "peer, one thread")
    print(f"  against the peer on one thread (like for like): {alone:.2f}x")
    return verdict("tradeoff / peer", ratio(walls, "tradeoff", "peer"), 3.0)


def command(argv: list[str]) -> Callable[[], object]:
    """A whole ``phdesign`` command in a fresh process, with the default threads."""
    line = [PYTHON, "-m", "phdesign", *argv]
    return lambda: subprocess.run(line, check=True, capture_output=True)


def tuning(beam) -> bool:  # type: ignore[no-untyped-def]
    """Target 3: ``tune --max-rms`` against one ``noise`` report (whole commands)."""
    obs = phd.Observer(beam, sensors=[3, 4], gain=[0.1, 1])
    walls = interleaved({"tune": command(TUNE_COMMAND), "noise": command(NOISE_COMMAND)}, 3)
    tuned: list = []  # the in-process results, for the search's evaluations
    inside = interleaved(
        {
            "tune_noise()": lambda: tuned.append(obs.tune_noise(max_rms=0.3, performance="w(1)")),
            "obs.noise()": obs.noise,
        },
        rounds=3,
    )
    print(f"phdesign {' '.join(TUNE_COMMAND)}; load {os.getloadavg()[0]:.2f}")
    for name, times in walls.items():
        print(f"  {name} command: median {statistics.median(times):.2f} s")
    within = ratio(inside, "tune_noise()", "obs.noise()")
    evaluations = tuned[-1].evaluations
    print(
        f"  in one process (no start-up; not the target): tune_noise() {within:.1f}x "
        f"obs.noise(), {evaluations} evaluations of the search"
    )
    return verdict("tune --max-rms / noise (commands)", ratio(walls, "tune", "noise"), 10.0)


def main() -> int:
    beam = phd.load("euler-bernoulli")
    if sys.argv[1:] == ["tune"]:
        return 0 if tuning(beam) else 1
    ok = noise_report(beam)
    ok = trade_off(beam) and ok
    ok = tuning(beam) and ok
    print("targets:", "met" if ok else "MISSED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
