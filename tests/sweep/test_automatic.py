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
from phdesign.sweep import automatic, schedulers
from phdesign.sweep.automatic import Automatic, cluster_repays
from phdesign.sweep.plan import ChunkPlan, chunk_points
from phdesign.sweep.schedulers import Executor

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


def test_a_cluster_repays_its_start_from_about_seven_seconds_of_work_on_two_cores():
    # S + ceil(R / N) t / eta < R t with S = 3 s, eta = 0.9, N = 2: R t > 6.75 s for even R
    start, eta = automatic.LOCAL_CLUSTER_START, automatic.PARALLEL_EFFICIENCY
    assert (start, eta) == (3.0, 0.9)
    assert not cluster_repays(remaining=20, chunk_seconds=0.33, workers=2)  # 6.6 s
    assert cluster_repays(remaining=20, chunk_seconds=0.35, workers=2)  # 7.0 s
    assert not cluster_repays(remaining=1, chunk_seconds=100.0, workers=2)  # nothing to share
    assert not cluster_repays(remaining=100, chunk_seconds=100.0, workers=1)


class Clock:
    """A clock that each chunk advances by its cost (the chunk function calls ``spend``)."""

    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now

    def spend(self, seconds):
        self.now += seconds


class StandIn(Executor):
    """A cluster's executor that runs its chunks here (and says where it is)."""

    def __init__(self):
        super().__init__("stand-in cluster", 2)

    def describe(self):
        return "stand-in cluster (2 workers)"


def automatic_run(costs, workers=2):
    """Run chunks of the given costs through :class:`Automatic`; return what it did."""
    clock, notes, ran = Clock(), [], []
    elsewhere = StandIn()

    @contextmanager
    def start():
        ran.append("start")
        yield elsewhere

    def chunk(shared, index):
        ran.append(index)
        clock.spend(costs[index])
        return index

    with ExitStack() as stack:
        ex = Automatic(workers, start, notes.append, stack, clock=clock)
        results = list(ex.map_unordered(chunk, None, [(i,) for i in range(len(costs))]))
    assert sorted(results) == list(range(len(costs)))  # every chunk once, wherever it ran
    return ex, ran, notes


def test_cheap_chunks_stay_in_this_process_and_say_so():
    ex, ran, notes = automatic_run([0.1] * 20)  # 1.9 s left after the first
    assert ran == list(range(20))
    assert ex.started is None
    assert len(notes) == 1
    assert notes[0].startswith("sweep: running in this process: the 19")
    assert "`scheduler='local'`" in notes[0]
    assert ex.describe().startswith("synchronous (in this process; chosen")
    assert ex.choice["chunks_in_process"] == 20
    assert ex.choice["chunks_on_cluster"] == 0


def test_costly_chunks_start_the_cluster_after_the_first():
    ex, ran, notes = automatic_run([1.0] * 20)  # 19 s here against 3 + 10 / 0.9 = 14.1 s
    assert ran == [0, "start", *range(1, 20)]
    assert ex.started is not None
    assert notes[-1].startswith("sweep: starting a local cluster of 2 workers: the 19 chunks")
    assert ex.choice["chunks_in_process"] == 1
    assert ex.choice["chunks_on_cluster"] == 19
    assert ex.describe() == "stand-in cluster (2 workers), started after 1 chunk in this process"


def test_chunks_that_grow_costly_start_the_cluster_half_way():
    # 0.1 s each, then 4 s each.  After 13 chunks the mean is 1.0 s with 7 left: 7.0 s
    # here against 3 + 4 * 1.0 / 0.9 = 7.4 s there; after 14, 1.21 s with 6 left: 7.29 s
    # against 3 + 3 * 1.21 / 0.9 = 7.05 s, so the cluster takes the last 6
    _ex, ran, notes = automatic_run([0.1] * 10 + [4.0] * 10)
    assert ran.index("start") == 14
    assert ran[15:] == list(range(14, 20))
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


def test_a_small_sweep_without_a_scheduler_runs_here_and_says_so(two_cores, capsys):
    found = phdesign.sweep("wave", chunk_size=1, **WAVE)  # 9 chunks of one point
    same_figures(found, phdesign.sweep("wave", scheduler="synchronous", **WAVE))
    record = json.loads(found.attrs["phdesign_run"])
    assert record["scheduler"].startswith("synchronous (in this process; chosen")
    assert record["choice"]["chunks_in_process"] == 9
    assert record["choice"]["cluster_workers"] == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("phdesign: sweep: running in this process: the 8 chunks left")
    assert line.endswith("pass `scheduler='local'` to start one anyway")


def test_the_command_line_names_the_option_that_starts_a_cluster(two_cores, tmp_path, capsys):
    argv = ["sweep", "wave", "--sensors", "2", "--grid", "l1=0.1:0.9:9", "--chunk-size", "1"]
    assert main([*argv, "--no-progress", "-o", str(tmp_path / "m.csv"), "--json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["run"]["choice"]["automatic"] is True
    (line,) = captured.err.splitlines()
    assert line.endswith("pass --scheduler local to start one anyway")


def test_a_cluster_started_half_way_gives_the_same_store(two_cores, monkeypatch, tmp_path):
    """With a free start every grid repays a cluster: it takes over after the first chunk
    (a stand-in that runs here under the local cluster's name), and the store holds the
    synchronous run's numbers."""
    monkeypatch.setattr(automatic, "LOCAL_CLUSTER_START", 0.0)
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
