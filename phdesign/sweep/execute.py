"""Running a sweep: chunks as tasks, results written as they arrive.

:func:`run_chunk` is the task.  It runs wherever the scheduler puts it (this process, a
local worker, a remote one) and depends on its arguments only: it rebuilds the model
from the description's TOML, applies the setting's parameter values, prepares the job's
evaluator once per setting (kept for the next chunks of the same setting in that
process), evaluates every point of the chunk with one BLAS thread, and returns the
figures.  :func:`run` plans the chunks, checks the output before anything runs, opens
the executor, and writes each chunk as it completes (Zarr) or collects it (in memory,
CSV, NetCDF), with a progress bar on a terminal.

The figures of a point do not depend on the chunk it belongs to, on the other points of
the chunk, on the order in which chunks complete or on the process that ran them: a
synchronous run, a local cluster and a remote one give identical arrays.
"""

from __future__ import annotations

import contextlib
import json
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from phdesign.core.errors import PhdesignError, SweepError
from phdesign.sweep.dataset import RUN_ATTRIBUTE, template
from phdesign.sweep.description import SweepDescription
from phdesign.sweep.export import output_format, write_export
from phdesign.sweep.plan import ChunkPlan, check_chunk_size, chunk_points

__all__ = ["default_chunk_size", "run", "run_chunk"]


def default_chunk_size(description: SweepDescription, workers: int = 1) -> int:
    """Return the points per chunk for ``workers`` workers.

    The size is :func:`~phdesign.sweep.plan.chunk_points`'s, from the job's nominal chunk
    (about 0.4 s of its work): :attr:`~phdesign.sweep.jobs.Job.points_per_chunk` when
    gains vary inside a setting, :attr:`~phdesign.sweep.jobs.Job.settings_per_chunk`
    otherwise.
    """
    job = description.job_spec
    nominal = job.points_per_chunk if description.has_gain_axes else job.settings_per_chunk
    return chunk_points(description.size, workers, nominal)


@lru_cache(maxsize=4)
def _description(text: str) -> SweepDescription:
    return SweepDescription.from_json(text)


@lru_cache(maxsize=8)
def _evaluator(text: str, setting: tuple[Any, ...]) -> Any:
    """Return the job's evaluator for one setting, built once per process and setting."""
    from phdesign.io import model_from_toml

    description = _description(text)
    sensors, params = setting
    model = model_from_toml(description.model_toml, source=f"sweep model {description.model_name}")
    if params:
        model = model.with_parameters(dict(params))
    factory = description.job_spec.evaluator_factory()
    return factory(model, sensors, dict(description.options))


def _point_label(description: SweepDescription, point: tuple[int, ...]) -> str:
    return ", ".join(
        f"{a.name}={a.values[i]!r}" for a, i in zip(description.axes, point, strict=True)
    )


def run_chunk(text: str, chunk_shape: tuple[int, ...], index: int) -> dict[str, Any]:
    """Compute one chunk: ``{"index", "arrays": {figure: block}, "seconds"}``.

    Raises
    ------
    SweepError
        The worker runs another phdesign version than the description's.
    PhdesignError
        A point the library refuses (its message names the point).
    """
    from phdesign import __version__
    from phdesign.numeric.threads import small_dense_threads

    description = _description(text)
    if description.version != __version__:
        raise SweepError(
            f"a worker runs phdesign {__version__}; the sweep was described with "
            f"{description.version}: install the same version on every worker"
        )
    plan = ChunkPlan(description.shape, tuple(chunk_shape))
    region = plan.region(index)
    figures = description.job_spec.figures
    names = {f.name for f in figures}
    block = tuple(s.stop - s.start for s in region)
    arrays = {f.name: np.full(block, f.fill, dtype=f.dtype) for f in figures}
    start = time.perf_counter()
    with small_dense_threads():  # the thread policy of every numeric entry point
        for point in plan.points(index):
            local = tuple(p - s.start for p, s in zip(point, region, strict=True))
            try:
                evaluate = _evaluator(text, description.setting_at(point))
                values = evaluate(description.gain_at(point))
            except PhdesignError as error:
                label = _point_label(description, point)
                raise type(error)(f"sweep point {label}: {error}") from None
            if set(values) != names:
                raise RuntimeError(
                    f"job {description.job} returned {sorted(values)}; expected {sorted(names)}"
                )
            for f in figures:
                value = values[f.name]
                arrays[f.name][local] = f.fill if value is None else value
    return {"index": index, "arrays": arrays, "seconds": time.perf_counter() - start}


def _progress(total: int, initial: int, enabled: bool | None) -> Any:
    from tqdm import tqdm

    show = sys.stderr.isatty() if enabled is None else enabled
    return tqdm(
        total=total, initial=initial, unit="chunk", desc="sweep", disable=not show, file=sys.stderr
    )


def run(
    description: SweepDescription,
    *,
    output: str | Path | None = None,
    resume: bool = False,
    force: bool = False,
    scheduler: Any = None,
    workers: int | None = None,
    chunk_size: int | None = None,
    progress: bool | None = None,
    notify: Callable[[str], None] | None = None,
) -> Any:
    """Compute a described sweep and return its :class:`xarray.Dataset`.

    See :func:`phdesign.sweep.sweep` for the parameters; ``notify`` receives the automatic
    choice of where the chunks run (:mod:`phdesign.sweep.automatic`), one line each, as it
    is made (the command line prints it on stderr); the lines are also the run record's
    ``notes``, whoever is notified.  Everything that can be refused
    (the output, the scheduler) is checked before anything is written.  A Zarr store is
    written under its lock (:class:`~phdesign.sweep.lock.StoreLock`): a second sweep on
    the same store is refused while the first runs.  When a point is refused (a
    :class:`~phdesign.core.errors.PhdesignError` from a chunk), a store this run created is
    removed again; a store it resumed is left as it was found, with the chunks it added.
    """
    from phdesign.sweep.lock import StoreLock
    from phdesign.sweep.schedulers import check_scheduler
    from phdesign.sweep.store import ZarrStore

    if chunk_size is not None:
        check_chunk_size(chunk_size)
    check_scheduler(scheduler, workers)
    kind = None if output is None else output_format(output)
    if kind != "zarr" and resume:
        raise SweepError(
            "resume continues a Zarr store; "
            + (
                "give one as output"
                if output is None
                else f"{str(output)!r} is written once, at the end"
            )
        )
    where = _Where(scheduler, workers, progress, notify)
    if kind != "zarr" or output is None:
        if output is not None:
            from phdesign.io import check_output_path

            check_output_path(output, force)
        dataset = _run_in_memory(description, chunk_size, where)
        if output is not None:
            write_export(dataset, output, force)
        return dataset
    store = ZarrStore(Path(output))
    store.check(description, resume=resume, force=force, chunk_size=chunk_size)  # no lock yet
    with StoreLock(store.path):
        # decided again under the lock: a sweep that held it may have changed the store
        action = store.check(description, resume=resume, force=force, chunk_size=chunk_size)
        return _run_in_store(description, store, action, chunk_size, where)


@dataclass(frozen=True)
class _Where:
    """Where and how the chunks run: the executor's arguments and the progress bar."""

    scheduler: Any
    workers: int | None
    progress: bool | None
    notify: Callable[[str], None] | None

    def executor(self) -> Any:
        """Open the executor (:func:`~phdesign.sweep.schedulers.executor`)."""
        from phdesign.sweep.schedulers import executor

        return executor(self.scheduler, self.workers, _beside_the_bar(self.notify))


def _beside_the_bar(notify: Callable[[str], None] | None) -> Callable[[str], None] | None:
    """``notify``, with the progress bar cleared while it writes (it writes on stderr too)."""
    if notify is None:
        return None

    def write(text: str) -> None:
        from tqdm import tqdm

        with tqdm.external_write_mode(file=sys.stderr):
            notify(text)

    return write


def _new_plan(description: SweepDescription, chunk_size: int | None, workers: int) -> ChunkPlan:
    size = default_chunk_size(description, workers) if chunk_size is None else chunk_size
    return ChunkPlan.for_grid(description.shape, size)


def _record(plan: ChunkPlan, output: Any) -> dict[str, Any]:
    return {
        "chunks": plan.n_chunks,
        "chunk_shape": list(plan.chunk_shape),
        "computed": 0,
        "reused": 0,
        "seconds": 0.0,
        "compute_seconds": 0.0,
        "scheduler": "none (the store was complete)",
        "output": None if output is None else str(output),
    }


def _compute(
    description: SweepDescription,
    plan: ChunkPlan,
    ex: Any,
    done: set[int],
    write: Callable[[dict[str, Any], tuple[slice, ...]], None],
    record: dict[str, Any],
    progress: bool | None,
) -> None:
    """Run every chunk not in ``done`` and ``write`` each result as it arrives."""
    text = description.to_json()
    todo = [(plan.chunk_shape, i) for i in range(plan.n_chunks) if i not in done]
    record["reused"] = len(done)
    if ex.client is None:  # chunks run here: the job's imports before the first is timed
        description.job_spec.evaluator_factory()
    results = ex.map_unordered(run_chunk, text, todo)
    # closed at once on an error or Ctrl-C (its finally cancels the futures and releases the
    # scattered description), not when a traceback that holds it is collected
    with contextlib.closing(results), _progress(plan.n_chunks, len(done), progress) as bar:
        for result in results:
            write(result, plan.region(result["index"]))
            record["computed"] += 1
            record["compute_seconds"] += result["seconds"]
            bar.update(1)
    record["scheduler"] = ex.describe()
    if getattr(ex, "choice", None):
        record["choice"] = ex.choice
    if getattr(ex, "notes", None):
        record["notes"] = list(ex.notes)


def _run_in_memory(description: SweepDescription, chunk_size: int | None, where: _Where) -> Any:
    started = time.perf_counter()
    arrays = template(description)

    def write(result: dict[str, Any], region: tuple[slice, ...]) -> None:
        for name, block in result["arrays"].items():
            arrays[name].values[region] = block

    with where.executor() as ex:
        plan = _new_plan(description, chunk_size, ex.workers)
        record = _record(plan, None)
        _compute(description, plan, ex, set(), write, record, where.progress)
    record["seconds"] = time.perf_counter() - started
    arrays.attrs[RUN_ATTRIBUTE] = json.dumps(record)
    return arrays


def _run_in_store(
    description: SweepDescription, store: Any, action: str, chunk_size: int | None, where: _Where
) -> Any:
    """Create, replace, resume or reopen ``store`` (its lock held) and fill it."""
    if action == "complete":
        plan = store.plan()
        record = _record(plan, store.path)
        record["reused"] = plan.n_chunks
        return _finished(store, record)
    started = time.perf_counter()
    with where.executor() as ex:
        created = action in ("create", "replace")
        plan = _new_plan(description, chunk_size, ex.workers) if created else store.plan()
        record = _record(plan, store.path)
        if created:
            store.create(template(description, plan, lazy=True), description, plan, action)
        else:
            store.remove_stale_markers()
        group = store.writer()

        def write(result: dict[str, Any], region: tuple[slice, ...]) -> None:
            store.write_chunk(group, result["index"], region, result["arrays"])

        try:
            _compute(description, plan, ex, store.done(), write, record, where.progress)
        except PhdesignError:
            if created:  # a refused point: this sweep can never complete; it was ours
                store.remove()
            raise
    record["seconds"] = time.perf_counter() - started
    store.mark_complete(record)
    return _finished(store, record)


def _finished(store: Any, record: dict[str, Any]) -> Any:
    """Return the complete store's Dataset, read while its lock is held (a sweep may follow)."""
    dataset = store.dataset()
    dataset.attrs[RUN_ATTRIBUTE] = json.dumps(record)
    return dataset
