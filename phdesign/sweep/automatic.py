r"""Where a sweep runs when nobody says: here, or on a local cluster that repays its start.

A local cluster costs seconds to start (its worker processes import Dask, then phdesign
and scipy), and a small grid is done in this process before the workers are up.  So
without a scheduler (no ``scheduler``, no ``workers``, no ``DASK_SCHEDULER_ADDRESS``) a
sweep runs its first chunk here, which measures what a chunk costs, and starts a local
cluster only when the chunks left finish sooner there by more than its start once again:

.. math::

    2 S + \left\lceil \frac{R}{N} \right\rceil \frac{N}{F} \frac{t}{\eta} < R\, t,
    \qquad F = \min\bigl(N,\; P - B\bigr),

with R the chunks left, t the mean wall time of the chunks run here so far, N the workers
a local cluster would have (one per usable core), F the cores they would find free: B is
what other processes kept busy of the P processors while the chunks ran here (the
machine's CPU time, :func:`cpu_ticks`, less this process's), or where that is not known
L - 1 (L the load average of the last minute, which lags a minute behind: the workers of
a sweep that has just ended are still in it); F is at most this process's CPU share when
that is under :data:`FREE_CORE_SHARE`, :math:`\eta` = :data:`PARALLEL_EFFICIENCY` and
S = :data:`LOCAL_CLUSTER_START`, counted twice: a start costs more on a loaded machine
(15 s instead of 3 at a load average of 5 on two cores).  The rule is asked again after
every chunk run here (a grid whose later points cost more can still start a cluster
half-way), and its answer is one line, kept in the run's record (``notes``, beside
``scheduler`` and the figures it used, ``choice``) and said as it is made to whoever
asked (``notify``: the command line prints it on stderr).  On two free cores a cluster
starts from about 14 s of work: a 6 x 6 map of the beam (0.3 s) and the 20 x 20 one
(3 s) run here, a 40 x 40 one (12 to 13 s) is at the border, larger ones start a
cluster; with one core's worth of other work on two cores, never.  Every chunk's figures
are the same wherever it runs, so the choice moves no number.

An existing cluster (an address, a :class:`distributed.Client`, ``DASK_SCHEDULER_ADDRESS``)
has no start to repay (a connection is about 10 ms), and a named scheduler or a worker
count is obeyed as it is.

Examples
--------
>>> cluster_repays(remaining=19, chunk_seconds=0.15, workers=2)  # 400 points of the beam
False
>>> cluster_repays(remaining=19, chunk_seconds=0.96, workers=2)  # 20 s of work
True
>>> cluster_repays(19, 0.96, workers=2, free=free_workers(2, load=2.0))  # one core busy
False
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import AbstractContextManager, ExitStack
from dataclasses import dataclass, field
from typing import Any

__all__ = [
    "FREE_CORE_SHARE",
    "LOCAL_CLUSTER_START",
    "PARALLEL_EFFICIENCY",
    "Automatic",
    "cluster_repays",
    "cpu_ticks",
    "estimated_seconds",
    "free_workers",
    "load_average",
]

#: Seconds from asking for a local cluster to its workers computing (processes spawned,
#: Dask, phdesign and scipy imported; their close included): 2.1 to 2.5 s on a quiet
#: 2-core machine and 3.1 s at a load average of 2 (``benchmarks/sweep.py`` measures it).
LOCAL_CLUSTER_START = 3.0

#: Chunk compute over workers times wall time on a local cluster: 93 to 95 % measured on
#: 2 workers (the task round trips, the scheduling, the client's writes).
PARALLEL_EFFICIENCY = 0.9

#: The share of its wall time that a process computing alone on a core gets as CPU time
#: (at least 0.97 measured on an idle core); less means another process wanted the core.
FREE_CORE_SHARE = 0.9


def load_average() -> float | None:
    """Return the load average of the last minute (``None`` where the system has none)."""
    try:
        return os.getloadavg()[0]
    except (AttributeError, OSError):  # pragma: no cover - Windows
        return None


def cpu_ticks() -> tuple[float, float] | None:
    """Return the machine's busy and total CPU time so far, in ticks (``None`` off Linux).

    Read from the first line of ``/proc/stat`` (every processor's user, nice, system, idle,
    iowait, irq, softirq and steal time); idle and iowait are not busy.
    """
    try:
        with open("/proc/stat", encoding="ascii") as stat:
            fields = stat.readline().split()
        values = [float(x) for x in fields[1:9]]
    except (OSError, ValueError):  # pragma: no cover - not Linux
        return None
    if not fields or fields[0] != "cpu" or len(values) < 5:  # pragma: no cover
        return None
    total = sum(values)
    return total - values[3] - values[4], total


def free_workers(
    workers: int,
    cpu_share: float = 1.0,
    load: float | None = None,
    processors: int | None = None,
    others: float | None = None,
) -> float:
    """Return the cores a local cluster of ``workers`` would find free now (0 to ``workers``).

    Parameters
    ----------
    workers : int
        Workers of the cluster (one per usable core).
    cpu_share : float
        This process's CPU time over its wall time while it computed.
    load : float, optional
        The load average of the last minute, this sweep's own process in it.
    processors : int, optional
        The processors that load is spread over (:func:`os.cpu_count`: a container's
        load average is often its host's; default ``workers``).
    others : float, optional
        The processors that other processes kept busy while this one computed, measured
        (:func:`cpu_ticks`); given, it stands for ``load - 1``, which lags a minute behind.

    Examples
    --------
    >>> free_workers(2), free_workers(2, load=1.4), free_workers(2, cpu_share=0.6)
    (2.0, 1.6, 0.6)
    >>> free_workers(2, load=3.0, others=0.25)  # the load of a sweep that has ended
    1.75
    """
    free = float(workers)
    busy = max(0.0, load - 1.0) if others is None and load is not None else others
    if busy is not None:
        free = min(free, (workers if processors is None else processors) - busy)
    if cpu_share < FREE_CORE_SHARE:  # this process itself did not have a core
        free = min(free, cpu_share)
    return max(0.0, free)


def estimated_seconds(
    remaining: int,
    chunk_seconds: float,
    workers: int,
    free: float | None = None,
    start: float | None = None,
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
    free : float, optional
        The cores they would find free (:func:`free_workers`; default ``workers``).
    start : float, optional
        Seconds to start the cluster (default :data:`LOCAL_CLUSTER_START`).
    """
    start = LOCAL_CLUSTER_START if start is None else start
    free = float(workers) if free is None else free
    here = remaining * chunk_seconds
    if free <= 0:
        return here, math.inf
    rounds = math.ceil(remaining / workers) * workers / free
    return here, start + rounds * chunk_seconds / PARALLEL_EFFICIENCY


def cluster_repays(
    remaining: int,
    chunk_seconds: float,
    workers: int,
    free: float | None = None,
    start: float | None = None,
) -> bool:
    """Whether a local cluster finishes ``remaining`` chunks sooner by more than its start.

    The arguments are those of :func:`estimated_seconds`; one worker or one chunk never
    repays a cluster.
    """
    if workers < 2 or remaining < 2:
        return False
    start = LOCAL_CLUSTER_START if start is None else start
    here, there = estimated_seconds(remaining, chunk_seconds, workers, free, start)
    return there + start < here


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
    notify : callable or None
        Receives each decision as one line (``sweep: ...``) as it is made.
    stack : ExitStack
        Holds the cluster once started; closed by the caller (the cluster with it).
    clock, cpu_clock : callable
        Wall and CPU seconds of this process, for the chunks run here
        (:func:`time.perf_counter`, :func:`time.process_time`).
    load : callable
        The machine's load average of the last minute (:func:`load_average`).
    processors : int, optional
        The processors that load average counts (default :func:`os.cpu_count`).
    ticks : callable
        The machine's busy and total CPU ticks (:func:`cpu_ticks`; ``None``: not known),
        read when the first chunk starts and at every decision.

    Attributes
    ----------
    notes : list of str
        Every line given to ``notify``, in order: the run record's ``notes``.
    """

    workers: int
    start: Callable[[], AbstractContextManager[Any]]
    notify: Callable[[str], None] | None
    stack: ExitStack
    clock: Callable[[], float] = time.perf_counter
    cpu_clock: Callable[[], float] = time.process_time
    load: Callable[[], float | None] = field(default=lambda: load_average())
    processors: int | None = field(default_factory=os.cpu_count)
    ticks: Callable[[], tuple[float, float] | None] = field(default=lambda: cpu_ticks())
    started: Any = None
    choice: dict[str, Any] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    _since: tuple[float, float] | None = field(default=None, repr=False)

    @property
    def client(self) -> Any:
        """The started cluster's client (``None`` while the chunks run here)."""
        return None if self.started is None else self.started.client

    def map_unordered(
        self, function: Callable[..., Any], shared: Any, tasks: Sequence[tuple[Any, ...]]
    ) -> Iterator[Any]:
        """Yield ``function(shared, *task)`` for every task: here, then maybe on a cluster."""
        tasks = list(tasks)
        can_share = self.workers >= 2 and len(tasks) >= 3  # one left never repays
        if not can_share:
            self._say(self._alone(len(tasks)))
        wall = cpu = 0.0
        for done, task in enumerate(tasks):
            if done:
                mean, free = self._record(done, wall, cpu)
                remaining = len(tasks) - done
                if cluster_repays(remaining, mean, self.workers, free):
                    self.choice["chunks_on_cluster"] = remaining
                    self._say(self._starting(remaining, mean, free))
                    self.started = self.stack.enter_context(self.start())
                    yield from self.started.map_unordered(function, shared, tasks[done:])
                    return
                if done == 1 and can_share:
                    self._say(self._staying(remaining, mean, free))
            if not done:
                self._since = self.ticks()
            began, began_cpu = self.clock(), self.cpu_clock()
            result = function(shared, *task)
            wall += self.clock() - began
            cpu += self.cpu_clock() - began_cpu
            yield result
        if tasks:
            self._record(len(tasks), wall, cpu)

    def _say(self, line: str) -> None:
        self.notes.append(line)
        if self.notify is not None:
            self.notify(line)

    def _record(self, here: int, wall: float, cpu: float) -> tuple[float, float]:
        """Keep what ``here`` chunks measured; return their mean wall time and the free cores."""
        mean, share = wall / here, min(1.0, cpu / wall) if wall > 0 else 1.0
        load, others = self.load(), self._others(share)
        free = free_workers(self.workers, share, load, self.processors, others)
        self.choice = {
            "automatic": True,
            "chunks_in_process": here,
            "chunk_seconds": mean,
            "cpu_share": share,
            "load_average": load,
            "other_processors_busy": others,
            "free_cores": free,
            "cluster_workers": self.workers,
            "cluster_start_seconds": LOCAL_CLUSTER_START,
            "chunks_on_cluster": 0,
        }
        return mean, free

    def _others(self, share: float) -> float | None:
        """Processors that other processes kept busy since the first chunk (None: unknown)."""
        now, since = self.ticks(), self._since
        if now is None or since is None or now[1] <= since[1]:
            return None
        busy = (now[0] - since[0]) / (now[1] - since[1])
        return max(0.0, (self.processors or self.workers) * busy - share)

    def _starting(self, remaining: int, mean: float, free: float) -> str:
        here, there = estimated_seconds(remaining, mean, self.workers, free)
        return (
            f"sweep: starting a local cluster of {self.workers} workers: the {remaining} "
            f"chunks left take about {mean:.2g} s each, {here:.1f} s in this process "
            f"against about {there:.1f} s there, its start (about {LOCAL_CLUSTER_START:g} s) "
            "included"
        )

    def _staying(self, remaining: int, mean: float, free: float) -> str:
        if free * PARALLEL_EFFICIENCY <= 1:
            load, share = self.choice["load_average"], self.choice["cpu_share"]
            others = self.choice["other_processors_busy"]
            seen = (
                f"other processes kept {others:.1f} of {self.processors} processors busy, "
                if others is not None
                else (f"load average {load:.1f}, " if load is not None else "")
            )
            why = (
                f"the machine is busy ({seen}this process had {100 * share:.0f} % of a core): "
                f"a local cluster's {self.workers} workers would find about {free:.1f} cores free"
            )
        else:
            why = (
                f"the {remaining} chunks left take about {mean:.2g} s each "
                f"({remaining * mean:.1f} s): a local cluster of {self.workers} workers "
                f"would not save twice its start (about {LOCAL_CLUSTER_START:g} s)"
            )
        return f"sweep: running in this process: {why}; pass `scheduler='local'` to start one"

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
