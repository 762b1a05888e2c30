"""Design sweeps: gain maps, parameter studies and sensor-set studies, on Dask.

``phdesign.sweep(...)`` evaluates a job (``spectrum``: converged spectral abscissa;
``classify``: verdict and κ*) at every point of a grid of gains, model parameters and
sensor sets, in chunks of points that run in this process, on a local cluster or on any
Dask cluster, and returns an :class:`xarray.Dataset`: one variable per
figure, the axes as coordinates, the model, options and package version as attributes.
With ``output="map.zarr"`` the chunks are stored as they complete, and an interrupted
sweep resumes where it stopped (``resume=True``).

The package is itself callable (``phdesign.sweep(...)`` is :func:`sweep`), and its heavy
dependencies (dask, xarray, zarr) are imported only when a sweep runs: install them with
the ``sweep`` extra, ``pip install "phdesign[sweep]"``.

Modules: :mod:`~phdesign.sweep.grids` (axes), :mod:`~phdesign.sweep.jobs` (the job
registry), :mod:`~phdesign.sweep.description` (what a sweep computes, its stored fields
checked by :mod:`~phdesign.sweep.fields`),
:mod:`~phdesign.sweep.plan` (chunks), :mod:`~phdesign.sweep.schedulers` (where they run,
:mod:`~phdesign.sweep.automatic` when nobody says),
:mod:`~phdesign.sweep.execute` (running them), :mod:`~phdesign.sweep.store` (Zarr),
:mod:`~phdesign.sweep.export` (CSV, NetCDF), :mod:`~phdesign.sweep.summary` (the printed
result; its pictures are drawn by :mod:`phdesign.plots.sweep`); the jobs'
evaluators live in :mod:`~phdesign.sweep.spectrum_job`,
:mod:`~phdesign.sweep.classify_job` and :mod:`~phdesign.sweep.gain_job`.

Examples
--------
>>> import numpy as np
>>> import phdesign
>>> wave = phdesign.load_builtin("wave")
>>> ds = phdesign.sweep(
...     wave, sensors=[2], grid={"l1": "0.25:0.75:3"}, scheduler="synchronous", progress=False
... )
>>> k = ds.l1.values  # the string with the damper k: α = ½ ln|(1 − k)/(1 + k)|
>>> bool(np.allclose(ds.spectral_abscissa, 0.5 * np.log((1 - k) / (1 + k)), atol=1e-9))
True
>>> ds.converged.values.tolist()
[True, True, True]
"""

from __future__ import annotations

import sys
import types
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from phdesign.sweep.description import SweepDescription, describe
from phdesign.sweep.grids import Axis
from phdesign.sweep.jobs import JOBS, Figure, Job, Option

__all__ = [
    "JOBS",
    "Axis",
    "Figure",
    "Job",
    "Option",
    "SweepDescription",
    "describe",
    "open_sweep",
    "plot_sweep",
    "summarize",
    "sweep",
]


def sweep(
    model: Any,
    *,
    job: str = "spectrum",
    sensors: str | Sequence[int] | None = None,
    sensor_sets: str | Sequence[Sequence[int]] | None = None,
    gain: str | float | Sequence[float] | None = None,
    grid: Mapping[str, str | Sequence[float]] | None = None,
    param_grid: Mapping[str, str | Sequence[float]] | None = None,
    parameters: Mapping[str, Any] | None = None,
    options: Mapping[str, Any] | None = None,
    output: str | Path | None = None,
    resume: bool = False,
    force: bool = False,
    scheduler: Any = None,
    workers: int | None = None,
    chunk_size: int | None = None,
    progress: bool | None = None,
) -> Any:
    r"""Evaluate ``job`` over a grid of gains, parameters and sensor sets.

    Parameters
    ----------
    model : BCPHS or str
        The model, or a built-in name / TOML path.
    job : {"spectrum", "classify", "gain"}
        ``spectrum``: ``spectral_abscissa``, ``converged``, ``digits``, ``n_resolved``,
        ``unbounded_below``, ``ill_conditioned`` of the error system
        :math:`\tilde u = -C_m^\top L C_m \tilde y` (of the plant, u = 0, without
        sensors); ``classify``: ``verdict``, ``kappa`` (κ* of the best variant), ``best``;
        ``gain``: ``hinf``, ``hinf_converged``, ``hinf_frequency``, ``h2``,
        ``h2_converged``, ``h2_diverges``, ``steady_state`` from the model's
        ``[disturbances]`` to its ``[performance]`` outputs (:mod:`~phdesign.sweep.gain_job`).
    sensors : str or sequence of int, optional
        Measured outputs (1-based), the same at every point: ``[3, 4]`` or ``"3,4"``.
    sensor_sets : str or sequence, optional
        An axis of sensor sets: ``"3,4;4;2"``, ``"all"`` or ``[(3, 4), (4,)]``.
    gain : str, float or sequence of float, optional
        Fixed diagonal of :math:`L` for the entries not on a gain axis (default 1).
    grid : mapping, optional
        Gain axes, ``{"l1": "0.01:3:40:log", "l2": "0.1,1,10"}`` (``start:stop:count``
        with ``:log`` for a geometric grid, or a list; ``l`` for every entry at once).
    param_grid : mapping, optional
        Model parameter axes, ``{"d": "0:0.4:9"}``.
    parameters : mapping, optional
        Fixed parameter values (as ``--param``).
    options : mapping, optional
        Job options: ``method``, ``resolution``, ``max_resolution``, ``tol`` (spectrum and
        gain), ``intensity`` (gain: the sensor noise).
    output : path, optional
        ``map.zarr`` (written chunk by chunk, resumable), ``map.csv`` or ``map.nc``
        (written at the end); nothing is written without it.
    resume, force : bool
        Continue the sweep an existing store holds, or replace an existing output.
    scheduler : None, "local", "synchronous", address or distributed.Client
        Where the chunks run (:mod:`phdesign.sweep.schedulers`); default: the cluster of
        ``DASK_SCHEDULER_ADDRESS``, else this process until a local cluster would repay
        its start (:mod:`phdesign.sweep.automatic`; the choice is the run record's
        ``notes``, and ``phdesign sweep`` prints it on stderr).
    workers : int, optional
        Workers of the local cluster (given, a local cluster of that size starts).
    chunk_size : int, optional
        Points per chunk (default: from the grid and the workers,
        :func:`~phdesign.sweep.plan.chunk_points`).
    progress : bool, optional
        Progress bar on stderr (default: when stderr is a terminal).

    Returns
    -------
    xarray.Dataset
        One variable per figure over the axes; attributes ``model``, ``job``,
        ``sensors``, ``gain``, ``options``, ``phdesign_version``, ``phdesign_sweep``
        (the description as JSON) and ``phdesign_run`` (the run's record, JSON: chunks,
        seconds, ``scheduler``; after an automatic choice, ``choice`` and ``notes``, the
        lines that say where the chunks ran and why).

    Raises
    ------
    SweepError
        A malformed grid or option, an unreachable scheduler, a store of another sweep.
    OutputFileError
        An existing output without ``resume``/``force``, or an unknown format.
    ParameterError, ObserverError, ModelError
        A parameter or sensor the model does not have, or a refused value.
    """
    from phdesign.sweep.execute import run

    if isinstance(model, str):
        from phdesign.io import read_model
        from phdesign.models import builtin_names, load_builtin

        model = load_builtin(model) if model in builtin_names() else read_model(model)
    if parameters:
        overlap = sorted(set(parameters) & set(param_grid or {}))
        if overlap:
            from phdesign.core.errors import SweepError

            raise SweepError(f"parameter {overlap[0]} is both fixed and on an axis; give it once")
        model = model.with_parameters(dict(parameters))
    description = describe(
        model,
        job=job,
        sensors=sensors,
        sensor_sets=sensor_sets,
        gain=gain,
        grid=grid,
        param_grid=param_grid,
        options=options,
    )
    return run(
        description,
        output=output,
        resume=resume,
        force=force,
        scheduler=scheduler,
        workers=workers,
        chunk_size=chunk_size,
        progress=progress,
    )


def open_sweep(path: str | Path) -> Any:
    """Open a stored sweep (``.zarr`` or ``.nc``); see :func:`phdesign.sweep.export.open_sweep`."""
    from phdesign.sweep.export import open_sweep as _open

    return _open(path)


def summarize(dataset: Any) -> Any:
    """Return the :class:`~phdesign.sweep.summary.SweepSummary` of a sweep's Dataset."""
    from phdesign.sweep.summary import SweepSummary

    return SweepSummary.from_dataset(dataset)


def plot_sweep(dataset: Any, figure: str | None = None, **kwargs: Any) -> Any:
    """Draw a sweep's Dataset; see :func:`phdesign.plots.sweep.plot_sweep`."""
    from phdesign.plots.sweep import plot_sweep as _plot

    return _plot(dataset, figure, **kwargs)


class _CallableModule(types.ModuleType):
    """``phdesign.sweep`` is both this package and the function :func:`sweep`."""

    __call__ = staticmethod(sweep)


sys.modules[__name__].__class__ = _CallableModule
