"""The :class:`xarray.Dataset` of a sweep: axes as coordinates, one variable per figure.

Coordinates carry the axis ``kind`` (``gain``, ``parameter``, ``sensors``), its
``scale`` and the grid as written; variables carry ``long_name`` and ``units``; the
Dataset's attributes carry the model name, the job, the sensors, the fixed gain, the
options (JSON), the package version and, under ``phdesign_sweep``, the whole description
as JSON (the model's TOML included), so that a stored sweep says exactly what it holds.
Missing values are NaN for floats and -1 for counts (see :class:`phdesign.sweep.jobs.Figure`).
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from phdesign.sweep.description import SweepDescription
from phdesign.sweep.plan import ChunkPlan

__all__ = [
    "RUN_ATTRIBUTE",
    "SWEEP_ATTRIBUTE",
    "attributes",
    "description_of",
    "normalized",
    "template",
]

SWEEP_ATTRIBUTE = "phdesign_sweep"
RUN_ATTRIBUTE = "phdesign_run"
_LONG_NAMES = {"gain": "gain {}", "parameter": "parameter {}", "sensors": "sensor set"}


def attributes(description: SweepDescription) -> dict[str, Any]:
    """Return the Dataset attributes of a sweep (strings and numbers, for Zarr and NetCDF)."""
    gain = gain_text(description)
    return {
        "title": f"phdesign sweep: {description.job} on {description.model_name}",
        "model": description.model_name,
        "job": description.job,
        "sensors": ""
        if description.sensors is None
        else ",".join(str(i) for i in description.sensors),
        "gain": gain,
        "options": json.dumps(dict(description.options), sort_keys=True),
        "phdesign_version": description.version,
        "fingerprint": description.fingerprint,
        SWEEP_ATTRIBUTE: description.to_json(),
    }


def gain_text(description: SweepDescription) -> str:
    """Return the gain as the summary and the plot titles say it, grid axes named.

    A diagonal entry of L that a gain axis sets is named by the axis (``l1``); the other
    entries are the fixed values (``1`` by default).  Examples: ``"1 on every sensor"``,
    ``"l1, l2 (the grid's axes)"``, ``"l1, 0.5 (l1: the grid's axis)"``, ``"l (the grid's
    axis) on every sensor"``.
    """
    names = [a.name for a in description.axes if a.kind == "gain"]
    fixed = ["1"] if description.gain is None else [repr(g) for g in description.gain]
    if "l" in names:
        return "l (the grid's axis) on every sensor"
    if description.sensors is None:  # sensor sets: one fixed value for every sensor
        if not names:
            return f"{fixed[0]} on every sensor"
        return f"{', '.join(names)} (the grid's axes), {fixed[0]} on the other sensors"
    size = len(description.sensors)
    entries = fixed * size if len(fixed) == 1 else fixed
    if not names:
        return f"{entries[0]} on every sensor" if len(fixed) == 1 else ",".join(entries)
    for name in names:
        entries[int(name[1:]) - 1] = name
    axes = "the grid's axes" if len(names) > 1 else "the grid's axis"
    if len(names) == size:
        return f"{', '.join(entries)} ({axes})"
    return f"{', '.join(entries)} ({', '.join(names)}: {axes})"


def time_unit(description: SweepDescription) -> str:
    """Return the time unit the sweep's model states (``[units] t``), else ``"s"`` (SI)."""
    import tomllib

    try:
        units = tomllib.loads(description.model_toml).get("units", {})
    except tomllib.TOMLDecodeError:  # pragma: no cover - the TOML was written by phdesign
        units = {}
    unit = units.get("t") if isinstance(units, dict) else None
    return unit if isinstance(unit, str) and unit else "s"


def description_of(dataset: Any) -> SweepDescription:
    """Return the description stored in a sweep's Dataset.

    Raises
    ------
    SweepError
        The Dataset is not a phdesign sweep.
    """
    from phdesign.core.errors import SweepError

    text = dataset.attrs.get(SWEEP_ATTRIBUTE)
    if not isinstance(text, str):
        raise SweepError(f"not a phdesign sweep: the attribute {SWEEP_ATTRIBUTE!r} is missing")
    return SweepDescription.from_json(text)


def _coordinate(axis: Any) -> tuple[str, np.ndarray, dict[str, str]]:
    if axis.kind == "sensors":
        width = max(len(v) for v in axis.values)
        values = np.array(axis.values, dtype=f"<U{width}")
    else:
        values = np.array(axis.values, dtype=float)
    attrs = {
        "long_name": _LONG_NAMES[axis.kind].format(axis.name),
        "kind": axis.kind,
        "scale": axis.scale,
        "spec": axis.spec,
    }
    return axis.name, values, attrs


def template(
    description: SweepDescription, plan: ChunkPlan | None = None, lazy: bool = False
) -> Any:
    """Return the sweep's Dataset with every figure at its missing value.

    Parameters
    ----------
    description : SweepDescription
    plan : ChunkPlan, optional
        With ``lazy``, the chunks of the (dask) arrays, which become the Zarr chunks.
    lazy : bool
        Dask arrays (nothing is computed: a store template) instead of numpy arrays.
    """
    import xarray as xr

    coords = {}
    for axis in description.axes:
        name, values, attrs = _coordinate(axis)
        coords[name] = xr.Variable((name,), values, attrs)
    data_vars = {}
    for figure in description.job_spec.figures:
        if lazy:
            import dask.array as da

            chunks = plan.chunk_shape if plan is not None else "auto"
            values = da.full(description.shape, figure.fill, dtype=figure.dtype, chunks=chunks)
        else:
            values = np.full(description.shape, figure.fill, dtype=figure.dtype)
        attrs = {"long_name": figure.description}
        if figure.units:
            attrs["units"] = figure.units.replace("1/s", f"1/{time_unit(description)}")
        data_vars[figure.name] = xr.Variable(description.dims, values, attrs)
    return xr.Dataset(data_vars, coords=coords, attrs=attributes(description))


def normalized(dataset: Any) -> Any:
    """Return a stored sweep as :func:`template` lays it out: figure order and dtypes.

    Zarr lists arrays by name and NetCDF gives text back as Python objects; this puts the
    figures back in the job's order, and text figures and coordinates back to fixed-width
    strings, so that a sweep read from a file equals the one computed.
    """
    description = description_of(dataset)
    figures = description.job_spec.figures
    out = dataset[[f.name for f in figures]]
    for f in figures:
        if out[f.name].dtype != np.dtype(f.dtype):
            out[f.name] = out[f.name].astype(f.dtype)
    for axis in description.axes:
        _, values, _ = _coordinate(axis)
        if out[axis.name].dtype != values.dtype:
            out = out.assign_coords({axis.name: out[axis.name].astype(values.dtype)})
    return out
