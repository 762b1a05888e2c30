"""Chunks sized from the grid and the workers; a local cluster only where it repays its start.

No cluster starts here: the rule is checked on its own numbers, the executor that applies
it on a clock that the test advances (never on wall-clock time), and the sweep's
automatic choice end to end on grids too small to repay a cluster, or with a stand-in
for the cluster that runs in this process.  The expected numbers follow from the
formulas of :mod:`phdesign.sweep.automatic` and :func:`phdesign.sweep.plan.chunk_points`.
"""

from __future__ import annotations

import json
from contextlib import ExitStack, contextmanager

import pytest

pytest.importorskip("xarray", reason="install the sweep extra")
pytest.importorskip("zarr", reason="install the sweep extra")

from sweep_support import same_figures

import phdesign
from phdesign.cli import main
from phdesign.models import load_builtin
from phdesign.sweep import automatic, describe, schedulers
from phdesign.sweep.automatic import Automatic, cluster_repays, free_workers
from phdesign.sweep.execute import default_chunk_size
from phdesign.sweep.plan import ChunkPlan, chunk_points
from phdesign.sweep.schedulers import Executor

RUN = "phdesign_run"
WAVE = {"sensors": [2], "grid": {"l1": "0.1:0.9:9"}, "progress": False}


@pytest.mark.parametrize(
    ("shape", "workers", "nominal", "chunks", "chunk_shape"),
    [
        ((2, 2), 1, 32, 1, (2, 2)),  # the golden 2 x 2 sweep: one chunk, as recorded
        ((6, 6), 2, 32, 6, (1, 6)),  # was 2 chunks of 18: one each, no balance
        ((20, 20), 2, 32, 20, (1, 20)),  # the benchmark's map: 10 chunks per worker
        ((20, 20), 1, 32, 10, (2, 20)),  # in this process: fewer, larger chunks
        ((1000, 1000), 2, 32, 8000, (1, 125)),  # 4 nominal (128) at most, in even blocks
        ((1000, 1000), 128, 32, 2000, (1, 500)),  # 128 nominal / 8 = 512: the client keeps up
        ((20, 20), 16, 32, 20, (1, 20)),  # not 7 chunks of 64 for 16 workers: one each at least
        ((9,), 2, 4, 9, (1,)),  # no gain axis: a setting per point (nominal 4)
    ],
)
def test_chunks_are_sized_from_the_grid_and_the_workers(
    shape, workers, nominal, chunks, chunk_shape
):
    points = 1
    for n in shape:
        points *= n
    plan = ChunkPlan.for_grid(shape, chunk_points(points, workers, nominal))
    assert (plan.n_chunks, plan.chunk_shape) == (chunks, chunk_shape)


def test_a_cluster_must_save_twice_its_start_on_free_cores():
    # 2 S + ceil(R / N) t / eta < R t with S = 3 s, eta = 0.9, N = 2, R = 20:
    # 6 < (20 - 10 / 0.9) t, t > 0.675 s: from 13.5 s of work
    start, eta = automatic.LOCAL_CLUSTER_START, automatic.PARALLEL_EFFICIENCY
    assert (start, eta, automatic.FREE_CORE_SHARE) == (3.0, 0.9, 0.9)
    assert not cluster_repays(remaining=20, chunk_seconds=0.67, workers=2)  # 13.4 s
    assert cluster_repays(remaining=20, chunk_seconds=0.68, workers=2)  # 13.6 s
    busy = free_workers(2, cpu_share=0.89)  # this process lacked a core: 0.89 cores free
    assert not cluster_repays(remaining=20, chunk_seconds=100.0, workers=2, free=busy)
    assert not cluster_repays(remaining=1, chunk_seconds=100.0, workers=2)  # nothing to share
    assert not cluster_repays(remaining=100, chunk_seconds=100.0, workers=1)


class Clock:
    """A clock that each chunk advances by its cost (the chunk function calls ``spend``)."""

    def __init__(self, rate=1.0):
        self.now, self.rate = 0.0, rate

    def __call__(self):
        return self.now

    def spend(self, seconds):
        self.now += self.rate * seconds


class StandIn(Executor):
    """A cluster's executor that runs its chunks here (and says where it is)."""

    def __init__(self):
        super().__init__("stand-in cluster", 2)

    def describe(self):
        return "stand-in cluster (2 workers)"


def automatic_run(costs, workers=2, cpu_share=1.0, load=None, processors=None, others=None):
    """Run chunks of the given wall times through :class:`Automatic`; return what it did.

    The process gets ``cpu_share`` of each chunk's wall time as CPU time, the machine's
    load average is ``load`` and other processes keep ``others`` processors busy
    (``None``: not known; the machine's CPU ticks then read ``None``).
    """
    wall, cpu, notes, ran = Clock(), Clock(cpu_share), [], []
    cores = workers if processors is None else processors

    def ticks():  # busy and total processor-seconds so far, at the wall clock's time
        return None if others is None else ((cpu_share + others) * wall.now, cores * wall.now)

    elsewhere = StandIn()

    @contextmanager
    def start():
        ran.append("start")
        yield elsewhere

    def chunk(shared, index):
        ran.append(index)
        wall.spend(costs[index])
        cpu.spend(costs[index])
        return index

    with ExitStack() as stack:
        ex = Automatic(
            workers,
            start,
            notes.append,
            stack,
            clock=wall,
            cpu_clock=cpu,
            load=lambda: load,
            processors=cores,
            ticks=ticks,
        )
        results = list(ex.map_unordered(chunk, None, [(i,) for i in range(len(costs))]))
    assert sorted(results) == list(range(len(costs)))  # every chunk once, wherever it ran
    return ex, ran, notes


def test_cheap_chunks_stay_in_this_process_and_say_so():
    ex, ran, notes = automatic_run([0.5] * 20)  # 9.5 s left after the first
    assert ran == list(range(20))
    assert ex.started is None
    assert len(notes) == 1
    assert notes[0].startswith("sweep: running in this process: the 19 chunks left take about")
    assert notes[0].endswith(
        "would not save twice its start (about 3 s); pass `scheduler='local'` to start one"
    )
    assert ex.describe().startswith("synchronous (in this process; chosen")
    assert ex.choice["chunks_in_process"] == 20
    assert ex.choice["chunks_on_cluster"] == 0
    assert ex.choice["cpu_share"] == 1.0


def test_costly_chunks_start_the_cluster_after_the_first():
    ex, ran, notes = automatic_run([1.0] * 20)  # 19 s here against 3 + 10 / 0.9 = 14.1 s
    assert ran == [0, "start", *range(1, 20)]
    assert ex.started is not None
    assert notes == [
        "sweep: starting a local cluster of 2 workers: the 19 chunks left take about 1 s "
        "each, 19.0 s in this process against about 14.1 s there, its start (about 3 s) "
        "included"
    ]
    assert ex.choice["chunks_in_process"] == 1
    assert ex.choice["chunks_on_cluster"] == 19
    assert ex.describe() == "stand-in cluster (2 workers), started after 1 chunk in this process"


@pytest.mark.parametrize(
    ("cpu_share", "load", "said"),
    [
        (0.5, None, "(this process had 50 % of a core): a local cluster's 2 workers would find"),
        (1.0, 2.0, "(load average 2.0, this process had 100 % of a core): a local cluster's"),
    ],
)
def test_on_a_busy_machine_even_costly_chunks_stay_here(cpu_share, load, said):
    # 1 s chunks start a cluster on a quiet machine (above); with 0.5 or 1 core free,
    # 2 workers are no faster than this process: free_workers = min(2, 2 - (L - 1)), or
    # the share of a core this process had
    ex, ran, notes = automatic_run([1.0] * 20, cpu_share=cpu_share, load=load)
    assert "start" not in ran
    assert ex.choice["cpu_share"] == cpu_share
    assert ex.choice["load_average"] == load
    assert notes[0].startswith("sweep: running in this process: the machine is busy ")
    assert said in notes[0]


def test_a_machine_with_a_core_and_a_half_free_starts_a_cluster_only_for_more_work():
    # F = 2 - (1.5 - 1) = 1.5: 6 + 10 (2 / 1.5) t / 0.9 < 19 t from t = 1.432 s
    assert cluster_repays(19, 1.44, 2, free=free_workers(2, load=1.5))
    assert not cluster_repays(19, 1.42, 2, free=free_workers(2, load=1.5))
    _ex, ran, _notes = automatic_run([1.0] * 20, load=1.5)
    assert "start" not in ran
    _ex, ran, _notes = automatic_run([1.5] * 20, load=1.5)
    assert ran.index("start") == 1


def test_a_load_average_counts_the_processors_it_is_spread_over():
    # a container's load average is often its host's: 30 on 64 processors leaves 2 cores
    # free for 2 workers; on 2 processors it would leave none
    assert free_workers(2, load=30.0, processors=64) == 2.0
    assert free_workers(2, load=30.0, processors=2) == 0.0
    assert free_workers(2, load=2.5, processors=2) == 0.5
    _ex, ran, _notes = automatic_run([1.0] * 20, load=2.5, processors=2)
    assert "start" not in ran
    _ex, ran, _notes = automatic_run([1.0] * 20, load=2.5, processors=8)
    assert ran.index("start") == 1


def test_measured_cpu_time_stands_for_a_load_average_that_lags():
    # a sweep that ran on 2 workers a minute ago leaves a load average of 3, which alone
    # would say "no core free"; the machine's CPU ticks while the chunks ran here say that
    # other processes kept 0.1 processors busy: 1.9 free, and 1 s chunks start a cluster
    assert free_workers(2, load=3.0) == 0.0
    assert free_workers(2, load=3.0, others=0.1) == 1.9
    ex, ran, _notes = automatic_run([1.0] * 20, load=3.0, others=0.1)
    assert ran.index("start") == 1
    assert ex.choice["other_processors_busy"] == pytest.approx(0.1)
    assert ex.choice["free_cores"] == pytest.approx(1.9)
    # and the other way round: a quiet load average, a processor busy now
    ex, ran, notes = automatic_run([1.0] * 20, load=1.0, others=1.0)
    assert "start" not in ran
    assert "(other processes kept 1.0 of 2 processors busy, this process had 100 % of" in notes[0]


def test_every_decision_is_kept_in_the_notes_whoever_is_told():
    ex, _ran, notes = automatic_run([0.1] * 10 + [4.0] * 30)
    assert ex.notes == notes
    assert len(notes) == 2
    with ExitStack() as stack:  # nobody told: the notes alone
        quiet = Automatic(
            2, None, None, stack, clock=Clock(), load=lambda: None, ticks=lambda: None
        )
        assert list(quiet.map_unordered(lambda shared, i: i, None, [(0,), (1,)])) == [0, 1]
    assert quiet.notes == [
        "sweep: running in this process: 2 chunks, too few to share with a local cluster"
    ]


def test_chunks_that_grow_costly_start_the_cluster_half_way():
    # 0.1 s each, then 4 s each.  After 11 chunks the mean is 0.455 s with 29 left: 13.2 s
    # here against 6 + 15 * 0.455 / 0.9 = 13.6 s there (its start twice); after 12,
    # 0.75 s with 28 left: 21.0 s against 6 + 14 * 0.75 / 0.9 = 17.7 s
    _ex, ran, notes = automatic_run([0.1] * 10 + [4.0] * 30)
    assert ran.index("start") == 12
    assert ran[13:] == list(range(12, 40))
    assert len(notes) == 2  # the first decision, then the change of mind


@pytest.mark.parametrize(
    ("costs", "workers", "said"),
    [
        ([5.0] * 2, 2, "2 chunks, too few to share with a local cluster"),
        ([5.0], 2, "1 chunk, too few to share with a local cluster"),
        ([5.0] * 9, 1, "it may use one core"),
    ],
)
def test_too_few_chunks_or_one_core_never_start_a_cluster(costs, workers, said):
    _ex, ran, notes = automatic_run(costs, workers)
    assert "start" not in ran
    assert notes == [f"sweep: running in this process: {said}"]


@pytest.fixture
def two_cores(monkeypatch):
    """No scheduler named anywhere, and two usable cores (what this machine has)."""
    monkeypatch.delenv("DASK_SCHEDULER_ADDRESS", raising=False)
    monkeypatch.setattr(schedulers, "usable_cores", lambda: 2)


def test_a_small_sweep_without_a_scheduler_runs_here_and_says_so_in_its_notes(two_cores, capsys):
    found = phdesign.sweep("wave", chunk_size=1, **WAVE)  # 9 chunks of one point
    same_figures(found, phdesign.sweep("wave", scheduler="synchronous", **WAVE))
    record = json.loads(found.attrs["phdesign_run"])
    assert record["scheduler"].startswith("synchronous (in this process; chosen")
    assert record["choice"]["chunks_in_process"] == 9
    assert record["choice"]["cluster_workers"] == 2
    (line,) = record["notes"]
    # "the 8 chunks left take ...", or "the machine is busy ..." when it is
    assert line.startswith("sweep: running in this process: the ")
    assert line.endswith("pass `scheduler='local'` to start one")
    assert capsys.readouterr().err == ""  # the library prints nothing
    synchronous = json.loads(phdesign.sweep("wave", scheduler="synchronous", **WAVE).attrs[RUN])
    assert "notes" not in synchronous  # nothing was chosen
    assert "choice" not in synchronous


def test_the_command_line_says_the_choice_on_stderr_and_never_in_its_json(
    two_cores, tmp_path, capsys
):
    argv = ["sweep", "wave", "--sensors", "2", "--grid", "l1=0.1:0.9:9", "--chunk-size", "1"]
    assert main([*argv, "--no-progress", "-o", str(tmp_path / "m.csv"), "--json"]) == 0
    captured = capsys.readouterr()
    run = json.loads(captured.out)["run"]  # stdout is the JSON document alone
    assert run["choice"]["automatic"] is True
    (line,) = captured.err.splitlines()
    assert line.startswith("phdesign: sweep: running in this process: ")
    assert line.endswith("pass --scheduler local to start one")
    assert run["notes"] == [
        line.removeprefix("phdesign: ").replace("--scheduler local", "`scheduler='local'`")
    ]


class FakeClient:
    """A connected client of a cluster of ``workers`` workers (no cluster behind it)."""

    def __init__(self, workers=3):
        self.workers, self.closed = workers, False

    def scheduler_info(self):
        return {"workers": {f"tcp://10.0.0.{i}:1": {} for i in range(self.workers)}}

    def close(self):
        self.closed = True


@pytest.fixture
def no_local_cluster(two_cores, monkeypatch):
    """Starting a local cluster (at once, or later by the automatic choice) fails the test."""

    def refuse(n_workers):
        raise AssertionError(f"a local cluster of {n_workers} workers was started")

    monkeypatch.setattr(schedulers, "_local_cluster", refuse)


@pytest.mark.parametrize("by", ["argument", "environment"])
def test_an_existing_cluster_by_address_is_used_as_it_is(no_local_cluster, monkeypatch, by):
    address, connected = "tcp://10.0.0.9:8786", []

    def connect(to):
        connected.append(to)
        return FakeClient()

    monkeypatch.setattr(schedulers, "_connect", connect)
    if by == "environment":
        monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", address)
    notes = []
    with schedulers.executor(address if by == "argument" else None, None, notes.append) as ex:
        assert type(ex) is Executor  # not the automatic choice: no start to repay
        assert (ex.name, ex.workers, ex.describe()) == (address, 3, f"{address} (3 workers)")
        client = ex.client
    assert connected == [address]  # one connection, closed at the end
    assert client.closed
    assert notes == []


def test_a_client_is_used_as_it_is_and_left_open(no_local_cluster):
    client = FakeClient(workers=4)
    with schedulers.executor(client) as ex:
        assert type(ex) is Executor
        assert (ex.client, ex.workers) == (client, 4)
    assert not client.closed


def test_chunks_on_an_existing_cluster_are_sized_for_its_workers():
    # 400 points, nominal 32: 8 chunks per worker within [8, 128] points, never under
    # workers x 32 / 8 points unless a worker would go without a chunk (plan.chunk_points)
    grid = {"l1": "0.1:0.9:20", "l2": "0.1:0.9:20"}
    description = describe(load_builtin("euler-bernoulli"), sensors=[3, 4], grid=grid)
    assert [default_chunk_size(description, n) for n in (1, 2, 4, 16)] == [50, 25, 16, 25]


def test_a_cluster_started_half_way_gives_the_same_store(two_cores, monkeypatch, tmp_path):
    """With a free start (and the machine's load ignored) every grid repays a cluster: it
    takes over after the first chunk (a stand-in that runs here), and the store holds the
    synchronous run's numbers."""
    monkeypatch.setattr(automatic, "LOCAL_CLUSTER_START", 0.0)
    monkeypatch.setattr(automatic, "FREE_CORE_SHARE", 0.0)
    monkeypatch.setattr(automatic, "load_average", lambda: None)
    monkeypatch.setattr(automatic, "cpu_ticks", lambda: None)
    original = schedulers.executor
    opened = []

    @contextmanager
    def stand_in(scheduler=None, workers=None, notify=None):
        if scheduler != "local":
            with original(scheduler, workers, notify) as ex:
                yield ex
            return
        opened.append(scheduler)
        yield StandIn()

    monkeypatch.setattr(schedulers, "executor", stand_in)
    found = phdesign.sweep("wave", chunk_size=2, output=tmp_path / "m.zarr", **WAVE)
    same_figures(found, phdesign.sweep("wave", scheduler="synchronous", **WAVE))
    assert opened == ["local"]
    record = json.loads(found.attrs["phdesign_run"])
    assert (
        record["scheduler"]
        == "stand-in cluster (2 workers), started after 1 chunk in this process"
    )
    assert record["computed"] == record["chunks"] == 5
    assert record["choice"]["chunks_on_cluster"] == 4
