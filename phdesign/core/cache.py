r"""Work built once per object: one bounded cache, keyed on an owner's identity and a key.

The work that depends only on a model and a resolution (its dimensionless form, its
discretizations, the structure of its spectrum above the band) is built once and reused
across calls: two ``obs.spectrum()`` on one design, the gains of a tuning, the points of a
trade-off or of a sweep's chunk.  Every such store of the package is an :class:`OwnerCache`
of this module (one mechanism, several instances with their own bounds), never an ad-hoc
dict.

An entry is keyed on its *owner* (the object the work depends on, by identity: a
:class:`~phdesign.numeric.bridge.NumericModel` is immutable and unhashable) and a hashable
key (method, resolution, basis, a gain's bytes).  Each cache is bounded twice, by entries
and by the bytes of the arrays its values hold (:func:`array_bytes`), and drops its least
recently used entries first.  When an owner dies its entries go (a :func:`weakref.finalize`
per owner), so a recycled ``id`` never finds a stranger's work.  A value that refers to its
owner (a discretization names its model) keeps the owner alive until the entry is dropped:
that is bounded by the cache's bounds.

Values are shared by every caller: they must not be changed in place (the discretizations
are handed out with read-only arrays).  :func:`clear_caches` empties them all (a benchmark's
cold start); a cache is safe to use from several threads (a sweep's thread pool): the work is
built outside the lock, so two threads may build the same entry once each.

Examples
--------
>>> class Model:
...     pass
>>> cache = OwnerCache("example", entries=2, nbytes=1 << 20)
>>> m = Model()
>>> cache.get(m, ("degree", 3), lambda: "built"), cache.get(m, ("degree", 3), lambda: "again")
('built', 'built')
>>> del m  # its entries go with it
>>> len(cache)
0
"""

from __future__ import annotations

import threading
import weakref
from collections import OrderedDict, deque
from collections.abc import Callable, Hashable
from dataclasses import dataclass, fields, is_dataclass
from typing import Any, TypeVar

from phdesign.core.limits import MAX_CACHE_BYTES, MAX_CACHED_MODEL_WORK

__all__ = ["MODEL_WORK", "CacheInfo", "OwnerCache", "array_bytes", "caches", "clear_caches"]

T = TypeVar("T")

_CACHES: list[OwnerCache] = []


@dataclass(frozen=True)
class CacheInfo:
    """What a cache holds and how often it served it (:meth:`OwnerCache.info`)."""

    name: str
    hits: int
    misses: int
    entries: int
    nbytes: int


def array_bytes(value: object, depth: int = 3) -> int:
    """Return the bytes of the arrays ``value`` holds (the weight of a cache entry).

    Arrays (``nbytes``), and those held by tuples, lists, dict values, dataclass fields and
    instance attributes, ``depth`` levels down; each array counted once.

    Examples
    --------
    >>> import numpy as np
    >>> array_bytes((np.zeros(10), {"a": np.zeros(2)}))
    96
    """
    seen: set[int] = set()

    def walk(item: object, level: int) -> int:
        if id(item) in seen or level < 0:
            return 0
        seen.add(id(item))
        nbytes = getattr(item, "nbytes", None)
        if isinstance(nbytes, int) and hasattr(item, "dtype"):
            return nbytes
        if isinstance(item, tuple | list):
            children: list[object] = list(item)
        elif isinstance(item, dict):
            children = list(item.values())
        elif is_dataclass(item) and not isinstance(item, type):
            children = [getattr(item, f.name) for f in fields(item)]
        else:
            children = list(getattr(item, "__dict__", {}).values())
        return sum(walk(child, level - 1) for child in children)

    return walk(value, depth)


class OwnerCache:
    """A bounded cache of work per owner object (module docstring).

    Parameters
    ----------
    name : str
        What it holds, for :meth:`info`.
    entries : int
        The most entries kept.
    nbytes : int
        The most bytes of arrays kept (:func:`array_bytes`); a value larger than this alone
        is returned and not kept.
    """

    def __init__(self, name: str, *, entries: int, nbytes: int) -> None:
        self.name, self.max_entries, self.max_bytes = name, int(entries), int(nbytes)
        self._lock = threading.Lock()
        self._entries: OrderedDict[tuple[int, Hashable], tuple[Any, int]] = OrderedDict()
        self._owners: dict[int, tuple[weakref.finalize, set[Hashable]]] = {}
        self._dead: deque[int] = deque()  # owners gone, dropped at the next call
        self._bytes = self._hits = self._misses = 0
        _CACHES.append(self)

    def get(self, owner: object, key: Hashable, build: Callable[[], T]) -> T:
        """Return the work ``build()`` of ``owner`` under ``key``, built on the first call."""
        slot = (id(owner), key)
        with self._lock:
            self._forget_dead()
            found = self._entries.get(slot)
            if found is not None:
                self._entries.move_to_end(slot)
                self._hits += 1
                return found[0]  # type: ignore[no-any-return]
            self._misses += 1
        value = build()
        weight = array_bytes(value)
        if weight <= self.max_bytes:
            with self._lock:
                self._store(owner, slot, value, weight)
        return value

    def _store(self, owner: object, slot: tuple[int, Hashable], value: Any, weight: int) -> None:
        oid, key = slot
        self._forget_dead()
        if slot in self._entries:
            return  # another thread built it meanwhile
        if oid not in self._owners:
            self._owners[oid] = (weakref.finalize(owner, self._dead.append, oid), set())
        self._owners[oid][1].add(key)
        self._entries[slot] = (value, weight)
        self._bytes += weight
        while len(self._entries) > self.max_entries or self._bytes > self.max_bytes:
            self._drop(next(iter(self._entries)))

    def _drop(self, slot: tuple[int, Hashable]) -> None:
        _, weight = self._entries.pop(slot)
        self._bytes -= weight
        finalizer, keys = self._owners[slot[0]]
        keys.discard(slot[1])
        if not keys:
            finalizer.detach()
            del self._owners[slot[0]]

    def _forget_dead(self) -> None:
        """Drop the entries of the owners that died (their finalizers queued their ids).

        Called under the lock before every lookup: a finalizer runs before its owner's
        memory is freed, so no new object can find a dead owner's entries by its ``id``.
        A finalizer only queues (it may run inside a garbage collection in this thread,
        holding the lock).
        """
        while self._dead:
            oid = self._dead.popleft()
            _, keys = self._owners.pop(oid, (None, set()))
            for key in keys:
                _, weight = self._entries.pop((oid, key))
                self._bytes -= weight

    def clear(self) -> None:
        """Drop every entry."""
        with self._lock:
            for finalizer, _ in self._owners.values():
                finalizer.detach()
            self._owners.clear()
            self._dead.clear()
            self._entries.clear()
            self._bytes = 0

    def info(self) -> CacheInfo:
        """Return the cache's counts (:class:`CacheInfo`)."""
        with self._lock:
            self._forget_dead()
            return CacheInfo(self.name, self._hits, self._misses, len(self._entries), self._bytes)

    def __len__(self) -> int:
        with self._lock:
            self._forget_dead()
            return len(self._entries)


def caches() -> tuple[OwnerCache, ...]:
    """Return every cache made so far."""
    return tuple(_CACHES)


def clear_caches() -> None:
    """Empty every cache (a cold start, for a benchmark or a test)."""
    for cache in _CACHES:
        cache.clear()


#: The work that depends only on a model and a resolution, for every numeric stage.
MODEL_WORK = OwnerCache("model work", entries=MAX_CACHED_MODEL_WORK, nbytes=MAX_CACHE_BYTES)
