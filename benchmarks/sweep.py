"""Sweep benchmark: a 400-point gain map of the beam, synchronous against 2 Dask workers.

Usage: ``python benchmarks/sweep.py [--repeat 2] [--pair]`` (about a minute on 2 cores).

The map is the README gallery's: the error system's spectral abscissa over a 20 x 20 log
grid of (l1, l2), sensors y3, y4, in chunks of the default size.  Measured in one
invocation, alternating the two so that a change of the machine's load hits both:

* the synchronous run (this process): wall time, and the per-point cost (the chunks'
  own compute time over the points; a point that converges at the pair (20, 30), its
  discretizations shared by the chunk, separately as a median over single points);
* the same sweep on a ``LocalCluster`` of 2 single-threaded worker processes (started and
  warmed before the timing; its start-up is printed apart): wall time and speed-up over
  the synchronous run (target >= 1.6x on 2 cores);
* the task overhead: the round trip of a chunk that does nothing, against the mean
  chunk compute time (target < 5 %), and the parallel efficiency (chunk compute over
  workers x wall time);
* the Zarr store's cost per chunk (a synchronous run written to a store, against the same
  in memory);
* the cores the machine gives two workers at that moment (a fixed workload, two copies at
  once against one alone): on a shared machine, the ceiling of the speed-up.

Both runs must give identical arrays (checked).  BLAS runs one thread per process (the
chunk function limits it, and the workers are started with one thread).  ``--pair``
sweeps the single resolution pair (20, 30) of notebook 02 instead of the converged
default.  The load average before and after is printed: quote it with the numbers.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import sys
import tempfile
import time

import numpy as np

import phdesign
from phdesign.models import load_builtin

GRID = {"l1": "0.01:3:20:log", "l2": "0.1:10:20:log"}


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


def record(ds) -> dict:
    return json.loads(ds.attrs["phdesign_run"])


def identical(a, b) -> bool:
    return all(
        np.array_equal(a[n].values, b[n].values, equal_nan=a[n].dtype.kind == "f")
        for n in a.data_vars
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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2, help="runs of each (default 2)")
    parser.add_argument("--pair", action="store_true", help="the single pair (20, 30)")
    args = parser.parse_args(argv)
    load_before = os.getloadavg()
    beam = load_builtin("euler-bernoulli")
    options = {"resolution": 20, "max_resolution": 30} if args.pair else {}
    kwargs = {"sensors": [3, 4], "grid": GRID, "options": options, "progress": False}
    points = 400

    # warm this process: imports, the first discretizations
    phdesign.sweep(beam, sensors=[3, 4], grid={"l1": "0.1,1"}, scheduler="synchronous")

    from dask.distributed import Client, LocalCluster

    start = time.perf_counter()
    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    )
    client = Client(cluster)
    client.run(_warm)
    startup = time.perf_counter() - start
    phdesign.sweep(beam, sensors=[3, 4], grid={"l1": "0.1,1"}, scheduler=client)

    capacity_before = capacity(client)
    sync_wall, dask_wall, sync_compute, dask_compute = [], [], [], []
    chunks = 0
    for _ in range(args.repeat):
        ds_sync = phdesign.sweep(beam, scheduler="synchronous", **kwargs)
        ds_dask = phdesign.sweep(beam, scheduler=client, **kwargs)
        assert identical(ds_sync, ds_dask), "the two runs differ"
        for ds, wall, compute in (
            (ds_sync, sync_wall, sync_compute),
            (ds_dask, dask_wall, dask_compute),
        ):
            run = record(ds)
            wall.append(run["seconds"])
            compute.append(run["compute_seconds"])
            chunks = run["chunks"]
    converged = int(ds_sync.converged.sum())

    capacity_after = capacity(client)
    from phdesign.sweep.schedulers import Executor

    executor = Executor("LocalCluster", 2, client)
    tasks = [((1,), i) for i in range(200)]
    start = time.perf_counter()
    for _ in executor.map_unordered(_noop, "", tasks):
        pass
    per_task = (time.perf_counter() - start) / len(tasks)
    client.close()
    cluster.close()

    folder = tempfile.mkdtemp()
    try:
        stored = phdesign.sweep(
            beam, scheduler="synchronous", output=os.path.join(folder, "m.zarr"), **kwargs
        )
        store_run = record(stored)
    finally:
        shutil.rmtree(folder)
    fast = fast_path_ms()
    load_after = os.getloadavg()

    s, d = statistics.median(sync_wall), statistics.median(dask_wall)
    mean_point = 1e3 * statistics.median(sync_compute) / points
    mean_chunk = statistics.median(sync_compute) / chunks
    print(f"beam gain map, {points} points in {chunks} chunks, options {options or 'default'}")
    print(f"converged: {converged} of {points} points")
    print(f"per point: {mean_point:.1f} ms on average; {fast:.1f} ms (median) at (20, 30)")
    print(f"synchronous: {s:.2f} s (runs: {', '.join(f'{t:.2f}' for t in sync_wall)})")
    print(
        f"2 workers:   {d:.2f} s (runs: {', '.join(f'{t:.2f}' for t in dask_wall)}); "
        f"speed-up {s / d:.2f}x (target >= 1.6x: {'met' if s / d >= 1.6 else 'MISSED'})"
    )
    print(
        f"cores free for 2 workers (a fixed load, 2 copies against 1): "
        f"{capacity_before:.2f} before, {capacity_after:.2f} after: the speed-up's ceiling now"
    )
    print(f"local cluster start-up and warm-up: {startup:.2f} s (not in the 2-worker time)")
    efficiency = statistics.median(dask_compute) / (2 * d)
    print(
        f"task overhead: {1e3 * per_task:.1f} ms per task against {1e3 * mean_chunk:.0f} ms "
        f"per chunk ({100 * per_task / mean_chunk:.1f} %, target < 5 %); parallel "
        f"efficiency {100 * efficiency:.0f} %"
    )
    # what is not chunk compute, in the store run against the in-memory runs
    store_extra = store_run["seconds"] - store_run["compute_seconds"]
    memory_extra = statistics.median(w - c for w, c in zip(sync_wall, sync_compute, strict=True))
    print(
        f"Zarr store: {1e3 * (store_extra - memory_extra) / chunks:.1f} ms per chunk "
        f"(creation, writes and markers; {store_extra:.2f} s outside the chunks against "
        f"{memory_extra:.2f} s in memory)"
    )
    print(
        f"load average (1, 5, 15 min): before {load_before[0]:.2f}, {load_before[1]:.2f}, "
        f"{load_before[2]:.2f}; after {load_after[0]:.2f}, {load_after[1]:.2f}, "
        f"{load_after[2]:.2f}; {os.cpu_count()} cores"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
