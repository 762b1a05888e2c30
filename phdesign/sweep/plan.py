"""How the points of a sweep are cut into chunks: the unit of work and of storage.

A chunk is a block of the grid (one slice per axis), at most ``chunk_size`` points,
filled from the last axis outwards, with blocks of even size along each axis: a gain
map's chunk is a run of rows of gains at one model and sensor set.  Chunks are numbered
in C order over the grid of blocks.  The layout depends on the grid and the chunk size
only (never on the scheduler or the number of workers), and each point's figures depend
on the point only, so a sweep's results are the same however its chunks are scheduled,
and a stored sweep can be resumed chunk by chunk.

Examples
--------
>>> plan = ChunkPlan.for_grid((3, 20, 20), 48)
>>> plan.chunk_shape, plan.n_chunks
((1, 2, 20), 30)
>>> plan.region(1)
(slice(0, 1, None), slice(2, 4, None), slice(0, 20, None))
>>> ChunkPlan.for_grid((36, 36), 32).chunk_shape
(1, 18)
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

from phdesign.core.errors import SweepError

__all__ = ["ChunkPlan", "check_chunk_size"]


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
