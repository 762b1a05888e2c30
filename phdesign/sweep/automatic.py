r"""Where a sweep runs when nobody says: here, or on a local cluster that repays its start.

A local cluster costs seconds to start (its worker processes import Dask, then phdesign
and scipy), and a small grid is done in this process before the workers are up.  So
without a scheduler (no ``scheduler``, no ``workers``, no ``DASK_SCHEDULER_ADDRESS``) a
sweep runs its first chunk here, which measures what a chunk costs, and starts a local
cluster only when the chunks left finish sooner there, its start included:

.. math::

    S + \left\lceil R / N \right\rceil \frac{t}{\eta} < R\, t,

with R the chunks left, t the mean time of the chunks run here so far, N the workers a
local cluster would have (one per usable core), :math:`\eta` = :data:`PARALLEL_EFFICIENCY`
and S = :data:`LOCAL_CLUSTER_START`.  The rule is asked again after every chunk run here
(a grid whose later points cost more can still start a cluster half-way), and its answer
is said on stderr and kept in the run's record (``scheduler``, ``choice``).  On two cores
the cluster repays its start from about 7 s of work: a 6 x 6 map of the beam (0.5 s)
runs here, a 40 x 40 one (about 19 s) on the cluster.  Every chunk's figures are the same
wherever it runs, so the choice moves no number.

An existing cluster (an address, a :class:`distributed.Client`, ``DASK_SCHEDULER_ADDRESS``)
has no start to repay (a connection is about 10 ms), and a named scheduler or a worker
count is obeyed as it is.

Examples
--------
>>> cluster_repays(remaining=19, chunk_seconds=0.24, workers=2)  # 400 points of the beam
False
>>> cluster_repays(remaining=19, chunk_seconds=0.96, workers=2)  # 1600 points
True
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import AbstractContextManager, ExitStack
from dataclasses import dataclass, field
from typing import Any

__all__ = [
    "LOCAL_CLUSTER_START",
    "PARALLEL_EFFICIENCY",
    "Automatic",
    "cluster_repays",
    "estimated_seconds",
]

#: Seconds from asking for a local cluster to its workers computing (processes spawned,
#: Dask, phdesign and scipy imported; their close included): 2.1 to 2.5 s on a quiet
#: 2-core machine and 3.1 s at a load average of 2 (``benchmarks/sweep.py`` measures it).
LOCAL_CLUSTER_START = 3.0

#: Chunk compute over workers times wall time on a local cluster: 93 to 95 % measured on
#: 2 workers (the task round trips, the scheduling, the client's writes).
PARALLEL_EFFICIENCY = 0.9


def estimated_seconds(
    remaining: int, chunk_seconds: float, workers: int, start: float | None = None
) -> tuple[float, float]:
    """Return the seconds ``remaining`` chunks take here and on a local cluster (its start in).

    Parameters
    ----------
    remaining : int
        Chunks left to compute.
    chunk_seconds : float
        Mean time of a chunk in this process.
    workers : int
        Workers of the local cluster.
    start : float, optional
        Seconds to start the cluster (default :data:`LOCAL_CLUSTER_START`).
    """
    start = LOCAL_CLUSTER_START if start is None else start
    here = remaining * chunk_seconds
    there = start + math.ceil(remaining / workers) * chunk_seconds / PARALLEL_EFFICIENCY
    return here, there


def cluster_repays(
    remaining: int, chunk_seconds: float, workers: int, start: float | None = None
) -> bool:
    """Whether ``remaining`` chunks finish sooner on a local cluster, its start included.

    The arguments are those of :func:`estimated_seconds`; one worker or one chunk never
    repays a cluster.
    """
    if workers < 2 or remaining < 2:
        return False
    here, there = estimated_seconds(remaining, chunk_seconds, workers, start)
    return there < here


@dataclass
class Automatic:
    """Runs chunks here until a local cluster repays its start, then the rest there.

    Parameters
    ----------
    workers : int
        Workers of the local cluster it may start (one per usable core).
    start : callable
        Returns the context manager of that cluster's executor
        (:func:`phdesign.sweep.schedulers.executor` with ``scheduler="local"``).
    notify : callable
        Receives each decision as one line (``sweep: ...``).
    stack : ExitStack
        Holds the cluster once started; closed by the caller (the cluster with it).
    clock : callable
        Seconds, for the chunks' times (:func:`time.perf_counter`).
    """

    workers: int
    start: Callable[[], AbstractContextManager[Any]]
    notify: Callable[[str], None]
    stack: ExitStack
    clock: Callable[[], float] = time.perf_counter
    started: Any = None
    choice: dict[str, Any] = field(default_factory=dict)

    @property
    def client(self) -> Any:
        """The started cluster's client (``None`` while the chunks run here)."""
        return None if self.started is None else self.started.client

    def map_unordered(
        self, function: Callable[..., Any], shared: Any, tasks: Sequence[tuple[Any, ...]]
    ) -> Iterator[Any]:
        """Yield ``function(shared, *task)`` for every task: here, then maybe on a cluster."""
        tasks = list(tasks)
        if self.workers < 2 or len(tasks) < 3:  # the first chunk measures; one left never repays
            self.notify(self._alone(len(tasks)))
        seconds = 0.0
        for done, task in enumerate(tasks):
            mean = seconds / done if done else 0.0
            remaining = len(tasks) - done
            if done and cluster_repays(remaining, mean, self.workers):
                self._record(done, mean, remaining)
                self.notify(self._starting(remaining, mean))
                self.started = self.stack.enter_context(self.start())
                yield from self.started.map_unordered(function, shared, tasks[done:])
                return
            if done == 1 and self.workers >= 2 and len(tasks) >= 3:
                self.notify(self._staying(remaining, mean))
            began = self.clock()
            result = function(shared, *task)
            seconds += self.clock() - began
            self._record(done + 1, seconds / (done + 1), 0)
            yield result

    def _record(self, here: int, mean: float, remaining: int) -> None:
        self.choice = {
            "automatic": True,
            "chunks_in_process": here,
            "chunk_seconds": mean,
            "cluster_workers": self.workers,
            "cluster_start_seconds": LOCAL_CLUSTER_START,
            "chunks_on_cluster": remaining,
        }

    def _starting(self, remaining: int, mean: float) -> str:
        here, there = estimated_seconds(remaining, mean, self.workers)
        return (
            f"sweep: starting a local cluster of {self.workers} workers: the {remaining} "
            f"chunks left take about {mean:.2g} s each, {here:.1f} s in this process "
            f"against about {there:.1f} s there, its start (about {LOCAL_CLUSTER_START:g} s) "
            "included"
        )

    def _staying(self, remaining: int, mean: float) -> str:
        return (
            f"sweep: running in this process: the {remaining} chunks left take about "
            f"{mean:.2g} s each ({remaining * mean:.1f} s), too little for a local cluster "
            f"of {self.workers} workers to repay its start (about {LOCAL_CLUSTER_START:g} s); "
            "pass `scheduler='local'` to start one anyway"
        )

    def _alone(self, count: int) -> str:
        if self.workers < 2:
            return "sweep: running in this process: it may use one core"
        chunks = "1 chunk" if count == 1 else f"{count} chunks"
        return f"sweep: running in this process: {chunks}, too few to share with a local cluster"

    def describe(self) -> str:
        """One line: where the chunks ran, and that the choice was automatic."""
        if self.started is not None:
            here = self.choice.get("chunks_in_process", 0)
            chunks = "1 chunk" if here == 1 else f"{here} chunks"
            return f"{self.started.describe()}, started after {chunks} in this process"
        return "synchronous (in this process; chosen: a local cluster would not repay its start)"
