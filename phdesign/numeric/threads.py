"""The thread policy: small dense problems on one BLAS thread, set in one place.

phdesign's numbers come from thousands of dense problems of a few dozen to a few hundred
states: eigenproblems (spectrum, tuning, the loop), matrix exponentials (simulations),
Lyapunov equations and frequency responses (the noise figures, the trade-off), period maps
(the export and its verification).  At that size a multithreaded BLAS (OpenBLAS by default)
spends more time synchronising its threads than computing: one thread is 3 to 5 times
faster on the simulations and 17 to 69 times on the noise figures here
(``benchmarks/tune.py``, ``benchmarks/noise.py``), and on a loaded machine the threads also
compete with other processes.

The policy: every public numeric entry point (the spectrum, the four simulators, the
tuners, the noise figures and the trade-off, the export and its verification, the loop's
spectrum, simulation and tuning, a sweep's points) runs inside :func:`small_dense_threads`
(as the decorator :func:`limited_threads`), which caps every loaded BLAS library at
:data:`SMALL_DENSE_THREADS` threads for its duration and restores the previous setting
afterwards.  It respects a limit the caller set: a library already at or below the cap
(threadpoolctl's limits in force, or ``OPENBLAS_NUM_THREADS`` / ``OMP_NUM_THREADS`` in the
environment, which the libraries read when they load) is left alone, so the caller's own
setting is never raised, and the user's code outside keeps all its threads.

Re-entering costs microseconds: the libraries are found once (threadpoolctl's scan, about a
millisecond, done again only when modules were imported since, since a new extension may
bring its own BLAS: scipy's is not numpy's), nested blocks cost a counter, and the
outermost block reads and sets each library's count (a C call each).
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import wraps
from typing import Any, ParamSpec, TypeVar

__all__ = ["SMALL_DENSE_THREADS", "blas_libraries", "limited_threads", "small_dense_threads"]

#: The most BLAS threads a small dense problem runs on (module docstring).
SMALL_DENSE_THREADS = 1

_lock = threading.Lock()
_depth = 0  # blocks currently inside; the limit holds while any of them runs
_restore: list[tuple[Any, int]] = []  # (library, its count) changed by the outermost block
_found: tuple[int, list[Any]] = (-1, [])  # (len(sys.modules) at the scan, BLAS libraries)


def blas_libraries() -> list[Any]:
    """Return threadpoolctl's controllers of the BLAS libraries loaded (found once).

    The scan is repeated when ``sys.modules`` has grown since the last one (a newly imported
    extension may load its own BLAS).
    """
    global _found
    modules = len(sys.modules)
    if _found[0] != modules:
        from threadpoolctl import ThreadpoolController

        _found = (modules, ThreadpoolController().select(user_api="blas").lib_controllers)
    return _found[1]


@contextmanager
def small_dense_threads(enabled: bool = True) -> Iterator[None]:
    """Cap BLAS at :data:`SMALL_DENSE_THREADS` threads inside the block (nested: free).

    The BLAS thread count is a property of the process, so the cap holds while any block
    runs, in any thread (a sweep running spectra in a thread pool), and the previous
    setting comes back when the last block ends.  A library already within the cap is not
    touched (the caller's limit stands).

    Parameters
    ----------
    enabled : bool
        ``False`` runs the block, and every block nested in it, with the current
        setting (used by the benchmarks that measure what the cap buys).

    Examples
    --------
    >>> import numpy as np
    >>> with small_dense_threads():
    ...     float(np.linalg.eigvals(np.diag([1.0, -2.0])).min())
    -2.0
    """
    global _depth
    with _lock:
        if enabled and _depth == 0:
            for library in blas_libraries():
                count = library.num_threads
                if count > SMALL_DENSE_THREADS:
                    library.set_num_threads(SMALL_DENSE_THREADS)
                    _restore.append((library, count))
        _depth += 1
    try:
        yield
    finally:
        with _lock:
            _depth -= 1
            if _depth == 0:
                while _restore:
                    library, count = _restore.pop()
                    library.set_num_threads(count)


P = ParamSpec("P")
R = TypeVar("R")


def limited_threads(function: Callable[P, R]) -> Callable[P, R]:
    """Run ``function`` inside :func:`small_dense_threads` (the decorator of entry points)."""

    @wraps(function)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        with small_dense_threads():
            return function(*args, **kwargs)

    return wrapper
