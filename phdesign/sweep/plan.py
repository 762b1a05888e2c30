"""How the points of a sweep are cut into chunks: the unit of work and of storage.

A chunk is a block of the grid (one slice per axis), at most ``chunk_size`` points,
filled from the last axis outwards, with blocks of even size along each axis: a gain
map's chunk is a run of rows of gains at one model and sensor set.  Chunks are numbered
in C order over the grid of blocks.  The layout depends on the grid and the chunk size
only, and each point's figures depend on the point only, so a sweep's results are the
same however its chunks are scheduled, and a stored sweep (which keeps the layout it was
written with) can be resumed chunk by chunk.

The default chunk size (:func:`chunk_points`) is sized from the grid and the workers
that will run it: enough chunks that every worker takes several (the last chunks to
finish leave workers idle), none so small that the round trip of a task or the client's
writes count.

Examples
--------
>>> plan = ChunkPlan.for_grid((3, 20, 20), 48)
>>> plan.chunk_shape, plan.n_chunks
((1, 2, 20), 30)
>>> plan.region(1)
(slice(0, 1, None), slice(2, 4, None), slice(0, 20, None))
>>> ChunkPlan.for_grid((36, 36), 32).chunk_shape
(1, 18)
>>> chunk_points(36, workers=2, nominal=32)  # a 6 x 6 map on 2 workers: 6 chunks of 6
8
>>> ChunkPlan.for_grid((6, 6), chunk_points(36, workers=2, nominal=32)).n_chunks
6
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

from phdesign.core.errors import SweepError

__all__ = ["CHUNKS_PER_WORKER", "ChunkPlan", "check_chunk_size", "chunk_points"]

#: Chunks per worker that the default chunk size aims at.  With chunks handed out as
#: workers free up, the last ones to finish leave the others idle for about half a chunk
#: each: 1/16 of a worker's share at 8 chunks per worker.
CHUNKS_PER_WORKER = 8


def check_chunk_size(chunk_size: object) -> int:
    """Return ``chunk_size`` if it is a positive integer.

    Raises
    ------
    SweepError
        Anything else.
    """
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1:
        raise SweepError(f"chunk size must be a positive integer; found {chunk_size!r}")
    return chunk_size


def chunk_points(points: int, workers: int, nominal: int) -> int:
    """Return the default points per chunk of a grid of ``points`` run by ``workers``.

    Parameters
    ----------
    points : int
        Points of the grid.
    workers : int
        Processes that will run the chunks (1 in this process).
    nominal : int
        Points of about 0.4 s of the job's work
        (:attr:`~phdesign.sweep.jobs.Job.points_per_chunk`, or
        :attr:`~phdesign.sweep.jobs.Job.settings_per_chunk` without a gain axis).

    Returns
    -------
    int
        :data:`CHUNKS_PER_WORKER` chunks per worker where the grid allows, within
        ``nominal / 4`` (about 0.1 s of work, against a task's round trip of 6 to 8 ms)
        and ``4 nominal`` (about 1.6 s: what a killed sweep recomputes, what the progress
        bar waits for); never under ``workers nominal / 8`` (about 50 ms of work per
        worker), so that the client, which writes every chunk (about 30 ms each to a
        Zarr store), keeps up with the workers, unless that would leave a worker
        without a chunk (a small grid on many workers: a chunk each).

    Examples
    --------
    >>> [chunk_points(p, 2, 32) for p in (4, 36, 400, 10**6)]
    [4, 8, 25, 128]
    >>> chunk_points(10**6, workers=128, nominal=32)  # the client's writes decide
    512
    >>> chunk_points(400, workers=16, nominal=32)  # 16 chunks of 25, not 7 of 64
    25
    """
    writes = min(math.ceil(workers * nominal / 8), math.ceil(points / max(workers, 1)))
    floor = max(math.ceil(nominal / 4), writes, 1)
    ceiling = max(4 * nominal, floor)
    balanced = math.ceil(points / (CHUNKS_PER_WORKER * max(workers, 1)))
    return max(1, min(points, max(floor, min(balanced, ceiling))))


@dataclass(frozen=True)
class ChunkPlan:
    """The chunk layout of a grid.

    Parameters
    ----------
    shape : tuple of int
        Points per axis.
    chunk_shape : tuple of int
        Points per axis in one chunk (the last chunk along an axis may be smaller).
    """

    shape: tuple[int, ...]
    chunk_shape: tuple[int, ...]

    def __post_init__(self) -> None:
        if len(self.shape) != len(self.chunk_shape) or any(
            c < 1 or c > max(n, 1) for n, c in zip(self.shape, self.chunk_shape, strict=True)
        ):
            raise SweepError(f"chunk shape {self.chunk_shape} does not fit the grid {self.shape}")

    @classmethod
    def for_grid(cls, shape: tuple[int, ...], chunk_size: int) -> ChunkPlan:
        """Blocks of at most ``chunk_size`` points, filled from the last axis outwards.

        Raises
        ------
        SweepError
            ``chunk_size`` is not a positive integer.
        """
        budget = check_chunk_size(chunk_size)
        chunk: list[int] = []
        for n in reversed(shape):
            # as many blocks as the budget needs along this axis, then blocks of even size
            # (36 points in budgets of 32: two blocks of 18, not 32 and a straggler of 4)
            extent = math.ceil(n / math.ceil(n / budget)) if n else 1
            chunk.append(extent)
            budget = max(1, budget // extent)
        return cls(tuple(shape), tuple(reversed(chunk)))

    @property
    def blocks(self) -> tuple[int, ...]:
        """Chunks per axis."""
        return tuple(math.ceil(n / c) for n, c in zip(self.shape, self.chunk_shape, strict=True))

    @property
    def n_chunks(self) -> int:
        """Number of chunks."""
        return math.prod(self.blocks)

    @property
    def chunk_size(self) -> int:
        """Points in a full chunk."""
        return math.prod(self.chunk_shape)

    def region(self, index: int) -> tuple[slice, ...]:
        """Return the slices of chunk ``index`` (C order over the blocks)."""
        if not 0 <= index < self.n_chunks:
            raise IndexError(f"chunk {index} out of range 0..{self.n_chunks - 1}")
        position = []
        for blocks in reversed(self.blocks):
            index, rest = divmod(index, blocks)
            position.append(rest)
        return tuple(
            slice(b * c, min((b + 1) * c, n))
            for b, c, n in zip(reversed(position), self.chunk_shape, self.shape, strict=True)
        )

    def points(self, index: int) -> list[tuple[int, ...]]:
        """Return the grid indices of chunk ``index``, in C order."""
        ranges = [range(s.start, s.stop) for s in self.region(index)]
        return list(itertools.product(*ranges))
