"""Sweeps on real Dask clusters give the synchronous run's numbers, bit for bit (issue 17).

Two clusters: the ``LocalCluster`` of two worker processes that a default sweep starts,
and (started once for this module) a scheduler with two workers started as separate
``dask scheduler`` / ``dask worker`` processes on 127.0.0.1 with ephemeral ports (the
address is read from the scheduler file).  The same small sweep (beam, two damping values
times a 3 x 2 gain grid, one resolution pair, chunks of two points so that both workers
take chunks) runs on each and must equal the synchronous run exactly: every point is
computed from its own arguments with one BLAS thread, wherever it runs.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

pytest.importorskip("dask.distributed", reason="install the sweep extra")
pytest.importorskip("xarray", reason="install the sweep extra")

from paths import ROOT
from sweep_support import BEAM_MAP, same_figures

import phdesign
from phdesign.core.errors import SweepError


def run(**where):
    return phdesign.sweep("euler-bernoulli", **BEAM_MAP, **where)


@pytest.fixture(scope="module")
def synchronous():
    return run(scheduler="synchronous")


class ExternalCluster:
    """``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1, ephemeral ports.

    All three start at once (the workers wait for the scheduler file); :meth:`address`
    waits until both workers are registered.
    """

    def __init__(self, folder: Path):
        self.folder = folder
        self.file = folder / "scheduler.json"
        env = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
        dask = [sys.executable, "-m", "dask"]  # the `dask` command of this interpreter
        scheduler = [*dask, "scheduler", "--host", "127.0.0.1", "--port", "0"]
        worker = [*dask, "worker", "--nthreads", "1", "--no-nanny", "--host", "127.0.0.1"]
        worker += ["--local-directory", str(folder)]
        commands = [scheduler, worker, worker]
        # logs go to files: a pipe nobody reads would fill up and block the processes
        self.logs = [open(folder / f"process{i}.log", "wb") for i in range(3)]  # noqa: SIM115
        self.processes = [
            subprocess.Popen(
                [*command, "--no-dashboard", "--scheduler-file", str(self.file)],
                env=env,
                cwd=folder,
                stdout=subprocess.DEVNULL,
                stderr=log,
            )
            for command, log in zip(commands, self.logs, strict=True)
        ]
        self._address: str | None = None

    def address(self) -> str:
        if self._address is None:
            deadline = time.monotonic() + 60
            while not self.file.exists() and time.monotonic() < deadline:
                assert self.processes[0].poll() is None, (self.folder / "process0.log").read_text()
                time.sleep(0.05)
            address = json.loads(self.file.read_text())["address"]
            assert address.startswith("tcp://127.0.0.1:")
            from dask.distributed import Client

            with Client(address, timeout="30s") as client:
                client.wait_for_workers(2, timeout=60)
            self._address = address
        return self._address

    def stop(self) -> None:
        # only the processes it started: the workers first, so the scheduler closes at once
        for group in (self.processes[1:], self.processes[:1]):
            for process in group:
                process.terminate()
            for process in group:
                try:
                    process.wait(timeout=3)
                except subprocess.TimeoutExpired:  # a slow goodbye under load: not a failure
                    process.kill()
                    process.wait()
        for log in self.logs:
            log.close()


@pytest.fixture(scope="module")
def external(tmp_path_factory):
    cluster = ExternalCluster(tmp_path_factory.mktemp("dask"))
    yield cluster
    cluster.stop()


def test_a_local_cluster_of_two_processes_gives_the_synchronous_numbers(synchronous, monkeypatch):
    monkeypatch.delenv("DASK_SCHEDULER_ADDRESS", raising=False)
    on_cluster = run(workers=2)  # the default: a LocalCluster of worker processes
    same_figures(on_cluster, synchronous)
    record = json.loads(on_cluster.attrs["phdesign_run"])
    assert record["computed"] == record["chunks"] == 6
    assert record["scheduler"] == "LocalCluster (2 workers)"


def test_external_scheduler_and_workers_give_the_synchronous_numbers(
    synchronous, external, monkeypatch, tmp_path
):
    external_address = external.address()
    store = tmp_path / "map.zarr"
    on_cluster = run(scheduler=external_address, output=store)
    same_figures(on_cluster, synchronous)
    record = json.loads(on_cluster.attrs["phdesign_run"])
    assert record["scheduler"] == f"{external_address} (2 workers)"
    # the same cluster through DASK_SCHEDULER_ADDRESS, as the default
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", external_address)
    via_environment = run()
    same_figures(via_environment, synchronous)
    assert json.loads(via_environment.attrs["phdesign_run"])["scheduler"].startswith(
        external_address
    )


def test_a_silent_scheduler_is_an_error_within_its_timeout(tmp_path, monkeypatch):
    """A port that accepts connections but never answers: the client's timeout decides.

    The library waits CONNECT_TIMEOUT = 4 s (the issue asks for an error within 10 s);
    here it is set to 1 s to keep the test short.
    """
    from phdesign.sweep import schedulers

    assert schedulers.CONNECT_TIMEOUT <= 5  # with the imports, an error within 10 s
    monkeypatch.setattr(schedulers, "CONNECT_TIMEOUT", 1.0)
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    accepted = []
    threading.Thread(target=lambda: accepted.append(server.accept()), daemon=True).start()
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    start = time.monotonic()
    try:
        with pytest.raises(SweepError, match=f"cannot reach the Dask scheduler at {address}"):
            run(scheduler=address, output=tmp_path / "map.zarr")
    finally:
        server.close()
    assert time.monotonic() - start < 5
    assert not any(tmp_path.iterdir()), "nothing is written when the scheduler is unreachable"


@pytest.mark.slow
def test_ctrl_c_on_a_local_cluster_sweep_is_one_line_and_the_workers_end_quietly(tmp_path):
    """Ctrl-C (SIGINT to the terminal's process group) printed 34 to 68 lines of worker
    tracebacks.  The sweep runs in a session of its own, so the signal reaches it and its
    workers as a terminal's would; the child restores the default SIGINT handler, so the
    test holds when the runner ignores SIGINT (then the child would inherit that)."""
    import signal

    store = tmp_path / "m.zarr"
    argv = ["sweep", "euler-bernoulli", "--sensors", "3,4", "--grid", "l1=0.05:3:200:log"]
    argv += ["--chunk-size", "1", "--workers", "2", "--no-progress", "-o", str(store)]
    code = (
        "import signal, sys\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "from phdesign.cli import main\n"
        f"sys.exit(main({argv!r}))\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
    env.pop("DASK_SCHEDULER_ADDRESS", None)
    child = subprocess.Popen(
        [sys.executable, "-c", code],
        env=env,
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    markers = store / ".phdesign" / "chunks"
    deadline = time.monotonic() + 120  # a guard against a hung child, not a measurement
    while child.poll() is None and time.monotonic() < deadline:
        if markers.is_dir() and sum(p.name.isdigit() for p in markers.iterdir()) >= 4:
            break  # the workers are computing chunks
        time.sleep(0.01)
    assert child.poll() is None, child.stderr.read().decode()
    os.killpg(child.pid, signal.SIGINT)
    _, err = child.communicate(timeout=120)
    assert child.returncode == 2, err.decode()
    assert err.decode() == "phdesign: error: interrupted\n"
    while time.monotonic() < deadline:  # the workers leave with the cluster
        try:
            os.killpg(child.pid, 0)
        except ProcessLookupError:
            break
        time.sleep(0.05)
    else:
        pytest.fail("a process of the sweep's group outlived it")
    assert not (store / ".phdesign" / "complete.json").exists()  # resumable, not removed
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.zarr"]  # the lock file is gone


def test_the_ctrl_c_race_of_distributed_is_dropped_and_nothing_else():
    """distributed's ``sync`` schedules ``cancel`` on Ctrl-C; on a loaded machine it can
    run before the coroutine assigned its future and raise a NameError, which tornado
    logs as "Exception in callback functools.partial(<function sync.<locals>.cancel ...>)"
    (seen as 15 lines after "phdesign: error: interrupted" in the test above).  The
    filter drops that record alone: the same message with another error, or another
    callback's NameError, still reaches the log."""
    import functools
    import logging

    from phdesign.sweep.schedulers import _RACE_FILTER, _quiet_interrupt_race

    def sync():
        def cancel():
            return future  # noqa: F821 - the unassigned name of distributed's race

        return cancel

    def other():
        raise NameError("x")

    def record(callback, error):
        try:
            raise error
        except BaseException:
            info = sys.exc_info()
        return logging.LogRecord(
            "tornado.application",
            logging.ERROR,
            __file__,
            1,
            "Exception in callback %r",
            (functools.partial(callback),),
            info,
        )

    race = record(sync(), NameError("free variable 'future' referenced before assignment"))
    assert not _RACE_FILTER.filter(race)
    assert _RACE_FILTER.filter(record(sync(), RuntimeError("a real failure")))
    assert _RACE_FILTER.filter(record(other, NameError("x")))
    _quiet_interrupt_race()
    _quiet_interrupt_race()  # once, however many clusters a process starts
    logger = logging.getLogger("tornado.application")
    assert logger.filters.count(_RACE_FILTER) == 1
