"""Sweep benchmark: the beam's gain maps in this process, on 2 Dask workers, on a plain Pool(2).

Usage: ``python benchmarks/sweep.py [--repeat 3] [--pair] [--large]`` (about two minutes on
2 cores; ``--large`` adds a 3600-point map, about a minute more per round).

The maps are the README gallery's: the error system's spectral abscissa over a log grid
of (l1, l2), sensors y3, y4, in chunks of the default size (sized from the grid and the
workers).  Measured in one invocation, in interleaved rounds (a change of the machine's
load hits every route), medians over the rounds:

* 400 points (20 x 20): synchronous; on a ``LocalCluster`` of 2 single-threaded worker
  processes started before the timing (target >= 1.6x synchronous, the median of the
  rounds' paired ratios, judged when the machine gives the two workers their cores); on
  the same cluster by its address, as ``--scheduler tcp://...`` uses an existing cluster
  (a connection per sweep; target: connecting and closing within 0.2 s); on a
  ``multiprocessing.Pool(2)`` started before the timing, over the same calls
  (``run_chunk`` on the same chunks; target: the Dask route within 1.15x the Pool); the
  default route (no scheduler: the automatic choice of :mod:`phdesign.sweep.automatic`;
  target: in this process, never slower than synchronous, 1.10x allowed for noise, on
  wall time when the cores are free and on this process's CPU time otherwise); and the
  cold routes, a local cluster and a Pool started, used and closed inside the timing
  (printed, with the start cost they measure against the rule's constant);
* 36 points (6 x 6): synchronous and the default route, three pairs a round, with the
  400-point default route's target;
* ``--large``, 3600 points (60 x 60, 20 to 30 s of work: past the 14 s from which the rule
  starts a cluster on free cores): synchronous and the default route, which should start
  a cluster and beat synchronous by 1.2x (judged when the cores are free).

Also: the per-point cost, the task overhead (the round trip of a chunk that does nothing,
against the mean chunk; target < 5 %), the parallel efficiency, the Zarr store's cost per
chunk, and the cores the machine gives two workers (a fixed workload, two copies at once
against one alone: on a shared machine, the ceiling of any speed-up).  Every route must
give identical arrays (checked).  BLAS runs one thread per process.  ``--pair`` sweeps the
single resolution pair (20, 30) of notebook 02.  The load average before and after is
printed, and at the start of every round: quote it with the numbers.  Wall and CPU times
come from ``_timing.timed``.  Exit status 1 when a judged target is missed.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import shutil
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from _timing import timed

from phdesign.models import load_builtin
from phdesign.sweep import describe
from phdesign.sweep.automatic import LOCAL_CLUSTER_START
from phdesign.sweep.execute import run, run_chunk
from phdesign.sweep.plan import ChunkPlan

MAP = {"l1": "0.01:3:20:log", "l2": "0.1:10:20:log"}
SMALL = {"l1": "0.01:3:6:log", "l2": "0.1:10:6:log"}
LARGE = {"l1": "0.01:3:60:log", "l2": "0.1:10:60:log"}
FREE_CORES = 1.8  # the speed-up targets are judged when two workers get this many cores


def _noop(text: str, chunk_shape: tuple[int, ...], index: int) -> dict:
    return {"index": index, "arrays": {}, "seconds": 0.0}


def _burn(seconds_hint: float = 0.5) -> float:
    """A fixed CPU workload (dense eigenvalues, one thread); returns its wall time."""
    from threadpoolctl import threadpool_limits

    rng = np.random.default_rng(0)
    A = rng.standard_normal((62, 62))
    start = time.perf_counter()
    with threadpool_limits(limits=1):
        for _ in range(int(200 * seconds_hint)):
            np.linalg.eigvals(A)
    return time.perf_counter() - start


def capacity(client) -> float:
    """How many cores the machine gives two workers now: 2 t(one alone) / t(two at once)."""
    workers = list(client.scheduler_info()["workers"])
    alone = client.submit(_burn, pure=False, workers=workers[:1]).result()
    both = [client.submit(_burn, pure=False, workers=[w]) for w in workers[:2]]
    together = max(f.result() for f in both)
    return 2 * alone / together


def _warm() -> None:
    import phdesign.sweep.execute
    import phdesign.sweep.spectrum_job  # noqa: F401


def _pool_chunk(task: tuple[str, tuple[int, ...], int]) -> dict:
    return run_chunk(*task)


def record(ds) -> dict:
    return json.loads(ds.attrs["phdesign_run"])


def identical(a, b) -> bool:
    return all(
        np.array_equal(a[n].values, b[n].values, equal_nan=a[n].dtype.kind == "f")
        for n in a.data_vars
    )


def on_pool(pool, description, chunk_shape) -> dict[str, np.ndarray]:
    """The same chunks through ``pool.imap_unordered(run_chunk)``: the figures' arrays."""
    plan = ChunkPlan(description.shape, tuple(chunk_shape))
    text = description.to_json()
    arrays = {
        f.name: np.full(description.shape, f.fill, dtype=f.dtype)
        for f in description.job_spec.figures
    }
    tasks = [(text, plan.chunk_shape, i) for i in range(plan.n_chunks)]
    for result in pool.imap_unordered(_pool_chunk, tasks):
        for name, block in result["arrays"].items():
            arrays[name][plan.region(result["index"])] = block
    return arrays


def same_as_pool(ds, arrays: dict[str, np.ndarray]) -> bool:
    return all(
        np.array_equal(ds[n].values, arrays[n], equal_nan=ds[n].dtype.kind == "f")
        for n in ds.data_vars
    )


def fast_path_ms() -> float:
    """Median cost of one point of a chunk at (20, 30): discretized once, spectrum() per gain."""
    from threadpoolctl import threadpool_limits

    from phdesign.numeric.bridge import to_numeric
    from phdesign.sweep.spectrum_job import ChunkSpectrum

    nm = to_numeric(load_builtin("euler-bernoulli"))
    C = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    pair = ChunkSpectrum(nm, C, resolution=20, max_resolution=30)
    times = []
    with threadpool_limits(limits=1):
        for l1 in np.geomspace(0.01, 3, 8):
            for l2 in np.geomspace(0.1, 10, 8):
                start = time.perf_counter()
                pair((l1, l2))
                times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times)


class Rounds:
    """Wall times by route, and the checks and choices seen, over interleaved rounds."""

    def __init__(self) -> None:
        self.walls: dict[str, list[float]] = {}
        self.compute: dict[str, list[float]] = {}
        self.cpus: dict[str, list[float]] = {}  # this process's CPU seconds
        self.records: dict[str, dict] = {}
        self.loads: list[float] = []
        self.connect = 0.0  # seconds to connect to the running cluster by its address
        self.same = True

    def time(self, route: str, call: Callable[[], Any]) -> Any:
        out, walls, cpus = timed(call, repeat=1)
        self.walls.setdefault(route, []).append(walls[0])
        self.cpus.setdefault(route, []).append(cpus[0])
        if hasattr(out, "attrs"):
            self.records[route] = record(out)
            self.compute.setdefault(route, []).append(record(out)["compute_seconds"])
        return out

    def median(self, route: str) -> float:
        return statistics.median(self.walls[route])

    def runs(self, route: str) -> str:
        return ", ".join(f"{t:.2f}" for t in self.walls[route])

    def paired(self, slow: str, fast: str, cpu: bool = False) -> list[float]:
        """``slow / fast`` round by round (the two ran minutes apart at most)."""
        times = self.cpus if cpu else self.walls
        return [a / b for a, b in zip(times[slow], times[fast], strict=True)]


def pair(rounds: Rounds, names: tuple[str, str], calls: tuple, flip: bool) -> tuple:
    """Time two routes one after the other, in the order ``flip`` says (A B, then B A)."""
    order = (1, 0) if flip else (0, 1)
    out = [None, None]
    for i in order:
        out[i] = rounds.time(names[i], calls[i])
    return tuple(out)


def one_round(rounds: Rounds, grids: dict, client, pool, large: bool, flip: bool) -> None:
    """Every route once, in turn; arrays compared with the synchronous run's.

    The running cluster is used twice: through its ``Client`` and through its address, as
    ``--scheduler tcp://...`` would (a connection per sweep).
    """
    rounds.loads.append(os.getloadavg()[0])
    sync = {"scheduler": "synchronous", "progress": False}
    local = {"progress": False}  # the default route: its choice is in the record's notes
    d = grids["map"]
    ds_sync, ds_auto = pair(
        rounds, ("sync", "auto"), (lambda: run(d, **sync), lambda: run(d, **local)), flip
    )
    ds_dask = rounds.time("dask", lambda: run(d, scheduler=client, progress=False))
    address = client.scheduler.address
    ds_address = rounds.time("address", lambda: run(d, scheduler=address, progress=False))
    chunks = record(ds_dask)["chunk_shape"]
    arrays = rounds.time("pool", lambda: on_pool(pool, d, chunks))
    ds_cold = rounds.time("dask cold", lambda: run(d, scheduler="local", progress=False))

    def cold_pool() -> dict[str, np.ndarray]:
        with multiprocessing.Pool(2) as fresh:
            return on_pool(fresh, d, chunks)

    cold_arrays = rounds.time("pool cold", cold_pool)
    s = grids["small"]
    for again in range(3):  # a 36-point sweep is a fraction of a second: three pairs
        small_sync, small_auto = pair(
            rounds,
            ("small sync", "small auto"),
            (lambda: run(s, **sync), lambda: run(s, **local)),
            flip ^ (again == 1),
        )
    rounds.same &= all(identical(ds_sync, ds) for ds in (ds_dask, ds_address, ds_auto, ds_cold))
    rounds.same &= same_as_pool(ds_sync, arrays) and same_as_pool(ds_sync, cold_arrays)
    rounds.same &= identical(small_sync, small_auto)
    if large:
        g = grids["large"]
        big_sync, big_auto = pair(
            rounds,
            ("large sync", "large auto"),
            (lambda: run(g, **sync), lambda: run(g, **local)),
            flip,
        )
        rounds.same &= identical(big_sync, big_auto)


def verdict(ok: bool | None) -> str:
    return (
        "not judged (the machine does not give 2 workers their cores)"
        if ok is None
        else ("met" if ok else "MISSED")
    )


def connection_seconds(address: str, repeat: int = 5) -> float:
    """Median seconds to open and close the executor of a running cluster's address."""
    from phdesign.sweep.schedulers import executor

    def connect() -> None:
        with executor(address):
            pass

    return statistics.median(timed(connect, repeat=repeat)[1])


def overhead_and_store(client, d, chunks: int) -> tuple[float, float]:
    """Seconds per empty task on the cluster, and the Zarr store's seconds per chunk."""
    from phdesign.sweep.schedulers import Executor

    executor = Executor("LocalCluster", 2, client)
    tasks = [((1,), i) for i in range(200)]
    start = time.perf_counter()
    for _ in executor.map_unordered(_noop, "", tasks):
        pass
    per_task = (time.perf_counter() - start) / len(tasks)
    folder = tempfile.mkdtemp()
    try:
        memory = record(run(d, scheduler="synchronous", progress=False))
        stored = record(
            run(d, scheduler="synchronous", progress=False, output=os.path.join(folder, "m.zarr"))
        )
    finally:
        shutil.rmtree(folder)
    extra = (stored["seconds"] - stored["compute_seconds"]) - (
        memory["seconds"] - memory["compute_seconds"]
    )
    return per_task, extra / chunks


def report(rounds: Rounds, cores: tuple[float, float], per_task: float, store: float) -> bool:
    """Print every figure and judge the targets; return whether all judged ones hold."""
    r = rounds.records
    points, chunks = 400, r["sync"]["chunks"]
    dask = rounds.median("dask")
    free = min(cores) >= FREE_CORES
    compute = statistics.median(rounds.compute["sync"])
    print(
        f"beam gain map, {points} points: {chunks} chunks of {r['sync']['chunk_shape']} in this "
        f"process, {r['dask']['chunks']} of {r['dask']['chunk_shape']} on 2 workers"
    )
    fast = fast_path_ms()
    print(f"per point: {1e3 * compute / points:.1f} ms on average; {fast:.1f} ms at (20, 30)")
    print(f"cores free for 2 workers: {cores[0]:.2f} before, {cores[1]:.2f} after (the ceiling)")
    for route in ("sync", "dask", "address", "pool", "auto", "dask cold", "pool cold"):
        print(f"  {route:>10}: {rounds.median(route):6.2f} s  (runs {rounds.runs(route)})")
    ok_speed, ok_address, ok_pool = report_running(rounds, free)
    ok_auto, ok_small = report_default(rounds, free)
    ok_large = report_large(rounds, free)
    efficiency = statistics.median(rounds.compute["dask"]) / (2 * dask)
    ok_task = per_task < 0.05 * compute / chunks
    print(
        f"task overhead: {1e3 * per_task:.1f} ms per task against {1e3 * compute / chunks:.0f} ms "
        f"per chunk ({100 * per_task * chunks / compute:.1f} %, target < 5 %: "
        f"{verdict(ok_task)}); parallel efficiency {100 * efficiency:.0f} %"
    )
    print(f"Zarr store: {1e3 * store:.1f} ms per chunk (creation, writes and markers)")
    print(f"identical arrays on every route: {rounds.same}")
    checks = (ok_speed, ok_address, ok_pool, ok_auto, ok_small, ok_large, ok_task, rounds.same)
    return all(ok is not False for ok in checks)


def rounds_text(ratios: list[float]) -> str:
    return ", ".join(f"{x:.2f}" for x in ratios)


def report_running(rounds: Rounds, free: bool) -> tuple[bool | None, bool, bool | None]:
    """The running cluster, by its Client and by its address, against synchronous and Pool."""
    s, dask, pool = rounds.median("sync"), rounds.median("dask"), rounds.median("pool")
    paired = rounds.paired("sync", "dask")
    speedup = statistics.median(paired)
    ok_speed = (speedup >= 1.6) if free else None
    print(
        f"2 Dask workers: {speedup:.2f}x synchronous, median of the rounds "
        f"({rounds_text(paired)}; ratio of the medians {s / dask:.2f}x; "
        f"target >= 1.6x: {verdict(ok_speed)})"
    )
    ok_address = rounds.connect <= 0.2
    print(
        f"the running cluster by its address (a connection per sweep): "
        f"{statistics.median(rounds.paired('sync', 'address')):.2f}x synchronous (rounds "
        f"{rounds_text(rounds.paired('sync', 'address'))}); opening and closing its "
        f"connection {1e3 * rounds.connect:.0f} ms (target <= 0.2 s per sweep: "
        f"{verdict(ok_address)})"
    )
    ok_pool = (dask / pool <= 1.15) if free else None
    print(
        f"Dask route: {dask / pool:.2f}x the Pool(2) over the same chunks "
        f"(target <= 1.15x: {verdict(ok_pool)}); Pool {s / pool:.2f}x synchronous"
    )
    cold = rounds.median("dask cold")
    print(
        f"cold routes: a local cluster started, used and closed {cold:.2f} s "
        f"({cold / rounds.median('pool cold'):.2f}x a fresh Pool(2)): its start costs "
        f"{cold - dask:.2f} s here (the rule assumes {LOCAL_CLUSTER_START:g} s)"
    )
    return ok_speed, ok_address, ok_pool


def default_line(rounds: Rounds, route: str, base: str, label: str, free: bool) -> bool:
    """Print the default route's ratios to synchronous; judge its choice and its time.

    Both must run in this process; the wall ratio is judged when the cores are free, the
    process's CPU time (the work done, which a busy machine's noise moves less) otherwise.
    """
    where = rounds.records[route]["scheduler"]
    wall = rounds.paired(route, base)
    cpu = statistics.median(rounds.paired(route, base, cpu=True))
    judged = statistics.median(wall) if free else cpu
    ok = judged <= 1.10 and where.startswith("synchronous")
    print(
        f"default route, {label}: {statistics.median(wall):.2f}x synchronous (rounds "
        f"{rounds_text(wall)}; CPU time of this process {cpu:.2f}x), on {where} (target: "
        f"this process, {'wall' if free else 'CPU time, the machine busy,'} <= 1.10x: "
        f"{verdict(ok)})"
    )
    return ok


def report_default(rounds: Rounds, free: bool) -> tuple[bool, bool]:
    """The default route (the automatic choice) against synchronous, round by round."""
    return (
        default_line(rounds, "auto", "sync", "400 points", free),
        default_line(rounds, "small auto", "small sync", "36 points", free),
    )


def report_large(rounds: Rounds, free: bool) -> bool | None:
    if "large sync" not in rounds.walls:
        return None
    ratio = rounds.median("large sync") / rounds.median("large auto")
    where = rounds.records["large auto"]["scheduler"]
    ok = (ratio >= 1.2 and "LocalCluster" in where) if free else None
    print(
        f"default route, 3600 points: {ratio:.2f}x faster than synchronous "
        f"({rounds.median('large sync'):.2f} s), on {where} (target >= 1.2x: {verdict(ok)})"
    )
    return ok


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="rounds (default 3)")
    parser.add_argument("--pair", action="store_true", help="the single pair (20, 30)")
    parser.add_argument("--large", action="store_true", help="also a 3600-point map")
    args = parser.parse_args(argv)
    os.environ.pop("DASK_SCHEDULER_ADDRESS", None)  # the default route decides by itself
    load_before = os.getloadavg()
    beam = load_builtin("euler-bernoulli")
    options = {"resolution": 20, "max_resolution": 30} if args.pair else {}
    grids = {
        name: describe(beam, job="spectrum", sensors=[3, 4], grid=grid, options=options)
        for name, grid in (("map", MAP), ("small", SMALL), ("large", LARGE))
    }
    warm = describe(beam, job="spectrum", sensors=[3, 4], grid={"l1": "0.1,1"})
    run(warm, scheduler="synchronous", progress=False)  # imports, first discretizations

    from dask.distributed import Client, LocalCluster

    pool = multiprocessing.Pool(2)  # forked now: warm, without the maps' evaluators
    pool.map(_burn, [0.01, 0.01])
    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    )
    client = Client(cluster)
    client.run(_warm)
    run(warm, scheduler=client, progress=False)
    cores_before = capacity(client)
    rounds = Rounds()
    for index in range(args.repeat):
        one_round(rounds, grids, client, pool, args.large, flip=index % 2 == 1)
    cores_after = capacity(client)
    rounds.connect = connection_seconds(client.scheduler.address)
    per_task, store = overhead_and_store(client, grids["map"], rounds.records["sync"]["chunks"])
    client.close()
    cluster.close()
    pool.close()
    pool.join()
    print(f"options {options or 'default'}; {args.repeat} rounds")
    ok = report(rounds, (cores_before, cores_after), per_task, store)
    for route in ("auto", "small auto", "large auto"):  # the last round's choices
        for note in rounds.records.get(route, {}).get("notes", []):
            print(f"the default route said ({route}): {note}")
    load_after = os.getloadavg()
    print(
        "load average (1 min) at each round's start: "
        + ", ".join(f"{x:.2f}" for x in rounds.loads)
    )
    print(
        f"load average (1, 5, 15 min): before {load_before[0]:.2f}, {load_before[1]:.2f}, "
        f"{load_before[2]:.2f}; after {load_after[0]:.2f}, {load_after[1]:.2f}, "
        f"{load_after[2]:.2f}; {os.cpu_count()} cores"
    )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
