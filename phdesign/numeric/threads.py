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

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import wraps
from typing import ParamSpec, TypeVar

__all__ = ["limited_threads", "small_dense_threads"]

_depth = 0  # nested entries reuse the outer limit instead of paying for a new one


@contextmanager
def small_dense_threads(enabled: bool = True) -> Iterator[None]:
    """Limit BLAS to one thread inside the block (nested blocks cost nothing).

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
    global _depth
    if not enabled or _depth:
        _depth += 1
        try:
            yield
        finally:
            _depth -= 1
        return
    from threadpoolctl import threadpool_limits

    _depth += 1
    try:
        with threadpool_limits(limits=1, user_api="blas"):
            yield
    finally:
        _depth -= 1


P = ParamSpec("P")
R = TypeVar("R")


def limited_threads(function: Callable[P, R]) -> Callable[P, R]:
    """Run ``function`` inside :func:`small_dense_threads` (a decorator)."""

    @wraps(function)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        with small_dense_threads():
            return function(*args, **kwargs)

    return wrapper
