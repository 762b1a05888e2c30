"""Where the chunks of a sweep run: in this process, on a local cluster, or on any Dask cluster.

``scheduler`` is one of

``None``
    the cluster named by ``DASK_SCHEDULER_ADDRESS`` when it is set; otherwise the chunks
    run in this process until a local cluster would repay its start, and the rest on one
    (:mod:`phdesign.sweep.automatic`: a small grid never waits for workers to start).
    With ``workers``, a local cluster of that many workers.
``"local"``
    a :class:`dask.distributed.LocalCluster` of one single-threaded worker process per
    core this process may use (or ``workers``), closed at the end.
``"synchronous"``
    every chunk in this process, one after the other (for debugging; no Dask needed).
``"tcp://HOST:PORT"`` (or any Dask address)
    an existing cluster: the address is tried at once (a refused connection is an
    error at once, an unreachable host after :data:`CONNECT_TIMEOUT` seconds) and the
    cluster must have a worker within :data:`WORKER_TIMEOUT` seconds.
a :class:`dask.distributed.Client`
    used as it is, and left open.

Workers run one BLAS thread each (the chunk function limits the thread pools, and a
local cluster starts its workers with one thread): the eigenproblems of a sweep are
small, where threads cost more than they give, and one thread makes every point's
floating-point operations the same wherever it runs.
"""

from __future__ import annotations

import os
import signal
import socket
import sys
import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit

from phdesign.core.errors import SweepError
from phdesign.core.limits import check_local_workers
from phdesign.sweep.automatic import Automatic

__all__ = [
    "CONNECT_TIMEOUT",
    "WORKER_TIMEOUT",
    "Executor",
    "check_address",
    "check_scheduler",
    "executor",
    "usable_cores",
]

CONNECT_TIMEOUT = 4.0  # seconds to reach a scheduler: an error within 10 s, imports included
WORKER_TIMEOUT = 30.0  # seconds for a reachable cluster to offer a worker


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity where the platform tells it)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - macOS, Windows
        return os.cpu_count() or 1


@dataclass
class Executor:
    """Runs tasks and yields their results as they finish.

    Attributes
    ----------
    name : str
        ``"synchronous"``, ``"LocalCluster"`` or the scheduler's address.
    workers : int
    client : distributed.Client or None
    """

    name: str
    workers: int
    client: Any = None

    def map_unordered(
        self, function: Callable[..., Any], shared: Any, tasks: Sequence[tuple[Any, ...]]
    ) -> Iterator[Any]:
        """Yield ``function(shared, *task)`` for every task, in the order they complete.

        ``shared`` (the sweep's description) is sent to each worker once, not with every
        task.
        """
        if self.client is None:
            for task in tasks:
                yield function(shared, *task)
            return
        from dask.distributed import as_completed

        common = self.client.scatter(shared, broadcast=True, hash=False)
        futures = [self.client.submit(function, common, *task, pure=False) for task in tasks]
        try:
            for future in as_completed(futures):
                yield future.result()
        finally:
            for future in futures:
                future.cancel()
            common.release()

    def describe(self) -> str:
        """One line: where the chunks ran."""
        if self.client is None:
            return "synchronous (in this process)"
        return f"{self.name} ({self.workers} workers)"


def _check_reachable(address: str) -> None:
    parts = urlsplit(address)
    if parts.scheme not in ("tcp", "tls") or parts.hostname is None or parts.port is None:
        return  # other transports: left to the client's own timeout
    try:
        with socket.create_connection((parts.hostname, parts.port), timeout=CONNECT_TIMEOUT):
            pass
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise SweepError(
            f"cannot reach the Dask scheduler at {address}: {reason}; start one with "
            "'dask scheduler' or use `scheduler='synchronous'`"
        ) from None


def _check_speaks_dask(address: str) -> None:
    """Open one Dask connection (with its handshake) within :data:`CONNECT_TIMEOUT`.

    A port that accepts connections and never answers would hold the client forever:
    Dask's own timeout covers the TCP connection, not the handshake.  The probe runs in a
    thread of its own, so that it works inside a running event loop (Jupyter) too.
    """
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    from distributed.comm import connect

    async def probe() -> None:
        comm = await asyncio.wait_for(connect(address), CONNECT_TIMEOUT)
        await comm.close()

    with ThreadPoolExecutor(max_workers=1) as pool:
        try:
            pool.submit(asyncio.run, probe()).result()
        except (OSError, TimeoutError) as error:
            reason = str(error) or f"no answer within {CONNECT_TIMEOUT:g} s"
            raise SweepError(f"cannot reach the Dask scheduler at {address}: {reason}") from None
        except Exception as error:  # whatever a service that is not Dask sends back
            raise SweepError(
                f"cannot reach the Dask scheduler at {address}: the service there does not "
                f"answer as a Dask scheduler ({type(error).__name__})"
            ) from None


def _connect(address: str) -> Any:
    _check_reachable(address)
    _check_speaks_dask(address)
    _quiet_interrupt_race()
    from dask.distributed import Client

    try:
        client = Client(address, timeout=f"{CONNECT_TIMEOUT}s")
    except (OSError, TimeoutError) as error:
        raise SweepError(f"cannot reach the Dask scheduler at {address}: {error}") from None
    try:
        client.wait_for_workers(1, timeout=WORKER_TIMEOUT)
    except (OSError, TimeoutError):
        client.close()
        raise SweepError(
            f"the Dask scheduler at {address} has no worker after {WORKER_TIMEOUT:g} s"
        ) from None
    return client


def check_scheduler(scheduler: Any, workers: int | None) -> None:
    """Refuse a malformed scheduler or worker count before anything starts or is written.

    Raises
    ------
    SweepError
        A worker count that is not a positive integer or exceeds the machine's cores
        (:func:`phdesign.core.limits.check_local_workers`), workers with a scheduler of its own,
        a name that is not a scheduler, or a malformed address (:func:`check_address`).
    """
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, int) or workers < 1
    ):
        raise SweepError(f"workers must be a positive integer; found {workers!r}")
    if workers is not None and scheduler not in (None, "local"):
        raise SweepError(
            "workers sizes the local cluster a sweep starts; it does not apply to "
            f"scheduler {scheduler!r}"
        )
    if workers is not None:
        check_local_workers(workers, usable_cores())
    if scheduler is None or not isinstance(scheduler, str):
        return
    if scheduler in ("synchronous", "local"):
        return
    if "://" in scheduler:
        check_address(scheduler)
        return
    raise SweepError(
        f"scheduler: expected 'synchronous', 'local' or an address such as "
        f"tcp://HOST:PORT; found {scheduler!r}"
    )


#: The transports of Dask addresses; those with a host and a port are checked in full.
_TRANSPORTS = ("tcp", "tls", "ws", "wss", "inproc", "ucx")
_NETWORK = ("tcp", "tls", "ws", "wss")


def check_address(address: str) -> None:
    """Refuse a Dask address that no scheduler can have (before any connection).

    Examples
    --------
    >>> check_address("tcp://127.0.0.1:8786")
    >>> check_address("tcp://[::1]:8786")
    >>> check_address("tcp://127.0.0.1:0")
    Traceback (most recent call last):
    ...
    phdesign.core.errors.SweepError: scheduler address 'tcp://127.0.0.1:0': the port must be from 1
    ...
    """
    shown = f"scheduler address {address!r}"
    expected = "expected tcp://HOST:PORT with a port from 1 to 65535"
    try:
        parts = urlsplit(address)
        port = parts.port
    except ValueError as error:  # an unclosed IPv6 bracket, a port that is not a number
        raise SweepError(f"{shown} is malformed ({error}); {expected}") from None
    if parts.scheme not in _TRANSPORTS:
        raise SweepError(
            f"{shown}: unknown transport {parts.scheme!r}; expected one of "
            f"{', '.join(_TRANSPORTS)}, as in tcp://HOST:PORT"
        )
    if parts.scheme not in _NETWORK:
        return
    if not parts.hostname or parts.path not in ("", "/") or parts.query or parts.fragment:
        raise SweepError(f"{shown} is malformed; {expected}")
    if parts.username is not None or parts.password is not None:
        raise SweepError(f"{shown} holds a user name; {expected}")
    if port is not None and not 1 <= port <= 65535:
        raise SweepError(f"{shown}: the port must be from 1 to 65535; found {port}")


_GUARD = (
    "a script that runs a sweep on a local cluster must call it under "
    "'if __name__ == \"__main__\":' (the worker processes import the script again), or "
    "pass scheduler='synchronous'"
)


@contextmanager
def _workers_ignore_sigint() -> Iterator[None]:
    """Ignore SIGINT while a local cluster spawns its workers, so that they ignore it too.

    Ctrl-C reaches every process of the terminal's process group: the workers died of it
    with 34 to 68 lines of tracebacks, and the scheduler logged the data they lost.  An
    ignored signal stays ignored across the spawn (a handler or a blocked mask does not),
    and Python leaves a SIGINT it finds ignored alone, so the workers never see Ctrl-C;
    this process alone handles it once its handler is back, and closes the cluster, whose
    workers then shut down quietly.  A Ctrl-C while the workers start (a second or two)
    is lost.  Only the main thread may change a handler: elsewhere nothing changes.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _refuse_in_a_spawned_worker() -> None:
    """Refuse a sweep that a worker process reached by importing the user's script again."""
    import multiprocessing

    if getattr(multiprocessing.current_process(), "_inheriting", False):
        raise SweepError(_GUARD)


class _SyncCancelRace:
    """A logging filter: drop distributed's own race on Ctrl-C, keep everything else.

    ``distributed.utils.sync`` answers a KeyboardInterrupt by scheduling ``cancel`` on the
    client's event loop, which reads the future that the coroutine assigns once it has
    started; on a loaded machine the interrupt can come first, ``cancel`` raises a
    NameError, and tornado logs it as an application error: fifteen lines of traceback
    after the sweep's one line "interrupted" (distributed 2026.8).  Nothing is lost with
    it: the sweep is interrupted either way.
    """

    def filter(self, record: Any) -> bool:
        """Return False for exactly that record."""
        error = record.exc_info[1] if record.exc_info else None
        return not (isinstance(error, NameError) and "sync.<locals>.cancel" in record.getMessage())


_RACE_FILTER = _SyncCancelRace()


def _quiet_interrupt_race() -> None:
    """Put :class:`_SyncCancelRace` on tornado's application logger (once)."""
    import logging

    logger = logging.getLogger("tornado.application")
    if _RACE_FILTER not in logger.filters:
        logger.addFilter(_RACE_FILTER)


def _local_cluster(n_workers: int) -> Any:
    """Start a LocalCluster of single-threaded worker processes (spawned, as Dask does)."""
    import logging

    _refuse_in_a_spawned_worker()
    _quiet_interrupt_race()
    from dask.distributed import LocalCluster

    try:
        with _workers_ignore_sigint():
            return LocalCluster(
                n_workers=n_workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",  # any free port: never a clash with another 8787
                silence_logs=logging.ERROR,
            )
    except RuntimeError as error:
        main = sys.modules.get("__main__")
        if getattr(main, "__file__", None) and getattr(main, "__spec__", None) is None:
            raise SweepError(f"the local cluster's workers did not start: {_GUARD}") from error
        raise


@contextmanager
def executor(
    scheduler: Any = None,
    workers: int | None = None,
    notify: Callable[[str], None] | None = None,
) -> Iterator[Executor | Automatic]:
    """Open the executor named by ``scheduler`` (see the module docstring).

    Parameters
    ----------
    scheduler : None, str or distributed.Client
    workers : int, optional
        Workers of a local cluster (default: :func:`usable_cores`).
    notify : callable, optional
        Receives the automatic choice's decisions, one line each, as they are made
        (default: nobody; they are the :class:`~phdesign.sweep.automatic.Automatic`
        executor's ``notes`` either way).

    Raises
    ------
    SweepError
        A malformed scheduler, an unreachable one, or a cluster without workers.
    """
    check_scheduler(scheduler, workers)
    if scheduler == "synchronous":
        yield Executor("synchronous", 1)
        return
    if scheduler is None and workers is None and not os.environ.get("DASK_SCHEDULER_ADDRESS"):
        _refuse_in_a_spawned_worker()
        with ExitStack() as stack:
            yield Automatic(usable_cores(), lambda: executor("local"), notify, stack)
        return
    if scheduler is not None and not isinstance(scheduler, str):
        n = len(scheduler.scheduler_info().get("workers", {}))
        yield Executor(
            str(getattr(scheduler, "scheduler", None) and scheduler.scheduler.address),
            n,
            scheduler,
        )
        return
    address = scheduler if scheduler not in (None, "local") else None
    if scheduler is None:
        address = os.environ.get("DASK_SCHEDULER_ADDRESS") or None
    if address is not None:
        if workers is not None:
            raise SweepError(
                f"workers sizes a local cluster; the scheduler at {address} has its own "
                "(drop workers, or pass scheduler='local')"
            )
        client = _connect(address)
        try:
            yield Executor(address, len(client.scheduler_info().get("workers", {})), client)
        finally:
            client.close()
        return
    from dask.distributed import Client

    cluster = client = None
    try:  # one finally for both: a Ctrl-C between the two starts closes the cluster too
        cluster = _local_cluster(workers or usable_cores())
        client = Client(cluster)
        yield Executor("LocalCluster", len(cluster.workers), client)
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
