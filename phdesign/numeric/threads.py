"""One BLAS thread for small dense eigenproblems.

The spectrum, the abscissa evaluator and the tuner solve thousands of dense eigenproblems
of a few dozen to a few hundred states.  At that size a multithreaded BLAS (OpenBLAS by
default) spends more time synchronising its threads than computing, and on a loaded
machine the threads also compete with other processes: ``benchmarks/tune.py`` measures the
cost (one thread halves the CPU time everywhere and the wall time under load).  Every
numeric entry point of this package that solves many small problems runs inside
:func:`small_dense_threads`, which limits BLAS to one thread for its duration and restores
the previous setting afterwards (threadpoolctl; the user's own code outside keeps all its
threads).

Entering the limit costs about a millisecond (threadpoolctl inspects the loaded
libraries), so it wraps whole computations, never a single solve.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import wraps
from typing import Any, ParamSpec, TypeVar

__all__ = ["limited_threads", "small_dense_threads"]

_lock = threading.Lock()
_depth = 0  # blocks currently inside; the limit holds while any of them runs
_limiter: Any = None  # the threadpoolctl limiter applied by the outermost block


@contextmanager
def small_dense_threads(enabled: bool = True) -> Iterator[None]:
    """Limit BLAS to one thread inside the block (nested blocks cost nothing).

    The BLAS thread count is a property of the process, so the limit holds while any block
    runs, in any thread (a sweep running spectra in a thread pool), and the previous
    setting comes back when the last block ends.

    Parameters
    ----------
    enabled : bool
        ``False`` runs the block, and every block nested in it, with the current
        setting (used by the benchmark that measures what the limit buys).

    Examples
    --------
    >>> import numpy as np
    >>> with small_dense_threads():
    ...     float(np.linalg.eigvals(np.diag([1.0, -2.0])).min())
    -2.0
    """
    global _depth, _limiter
    with _lock:
        if enabled and _depth == 0:
            from threadpoolctl import threadpool_limits

            _limiter = threadpool_limits(limits=1, user_api="blas")
        _depth += 1
    try:
        yield
    finally:
        with _lock:
            _depth -= 1
            if _depth == 0 and _limiter is not None:
                _limiter.restore_original_limits()
                _limiter = None


P = ParamSpec("P")
R = TypeVar("R")


def limited_threads(function: Callable[P, R]) -> Callable[P, R]:
    """Run ``function`` inside :func:`small_dense_threads` (a decorator)."""

    @wraps(function)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        with small_dense_threads():
            return function(*args, **kwargs)

    return wrapper
