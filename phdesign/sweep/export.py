"""Sweep results in and out of files: Zarr stores, CSV and NetCDF for small sweeps.

CSV has one row per point (C order over the axes) and one column per axis, then one per
figure, named as in the job's JSON; floats are written with their shortest exact
representation, booleans as ``true``/``false``, missing values as empty fields.
NetCDF is NetCDF-3 written by scipy (no further dependency); booleans are stored as
bytes with xarray's ``dtype: bool`` encoding and read back as booleans.

Examples
--------
>>> import numpy as np, xarray as xr
>>> ds = xr.Dataset({"a": ("l1", np.array([0.5, np.nan]))}, coords={"l1": [0.1, 0.2]})
>>> print(to_csv(ds), end="")
l1,a
0.1,0.5
0.2,
"""

from __future__ import annotations

import csv
import io
import itertools
from pathlib import Path
from typing import Any

import numpy as np

from phdesign.core.errors import OutputFileError, SweepError

__all__ = ["FORMATS", "open_sweep", "output_format", "to_csv", "write_export"]

FORMATS = {".zarr": "zarr", ".csv": "csv", ".nc": "netcdf"}


def output_format(path: str | Path) -> str:
    """``"zarr"``, ``"csv"`` or ``"netcdf"`` from the suffix of ``path``.

    Raises
    ------
    OutputFileError
        Any other suffix.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise OutputFileError(
            f"output {str(path)!r}: unknown format {suffix or '(no suffix)'!r}; expected a "
            ".zarr store, a .csv file or a .nc (NetCDF) file"
        )
    return FORMATS[suffix]


def _cell(value: Any) -> str:
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, float | np.floating):
        return "" if not np.isfinite(value) else repr(float(value))
    if isinstance(value, int | np.integer):
        return str(int(value))
    return str(value)


def to_csv(dataset: Any) -> str:
    """One row per point: the axes, then the figures (see the module docstring)."""
    names = list(dataset.data_vars)
    dims = list(dataset[names[0]].dims) if names else list(dataset.dims)
    columns = [np.asarray(dataset[name].transpose(*dims).values) for name in names]
    coords = [np.asarray(dataset[d].values) for d in dims]
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(dims + names)
    for index in itertools.product(*(range(len(c)) for c in coords)):
        row = [_cell(c[i].item()) for c, i in zip(coords, index, strict=True)]
        row += [_cell(col[index].item()) for col in columns]
        writer.writerow(row)
    return buffer.getvalue()


def write_export(dataset: Any, path: str | Path, force: bool) -> None:
    """Write a CSV or NetCDF file atomically (refusing to overwrite without ``force``)."""
    from phdesign.io import atomic_write

    kind = output_format(path)
    if kind == "csv":
        atomic_write(path, to_csv(dataset), force=force)
    elif kind == "netcdf":
        data = dataset.to_netcdf(engine="scipy")
        atomic_write(path, bytes(data), force=force)
    else:
        raise SweepError(f"{str(path)!r} is a Zarr store: it is written chunk by chunk")


def open_sweep(path: str | Path) -> Any:
    """Open a stored sweep (``.zarr`` or ``.nc``) as an :class:`xarray.Dataset`.

    Raises
    ------
    OutputFileError
        The path does not exist or has another suffix.
    SweepError
        A store or file that is not a complete phdesign sweep, or whose metadata is not
        its own description's (:mod:`phdesign.sweep.schema`: checked before any array
        is read).
    """
    from phdesign.sweep.dataset import normalized

    target = Path(path)
    if not target.exists():
        raise OutputFileError(f"cannot read {str(target)!r}: no such file or folder")
    kind = output_format(target)
    if kind == "zarr":
        from phdesign.sweep.store import ZarrStore

        store = ZarrStore(target)
        if store.stored() is None:
            raise SweepError(f"{str(target)!r} is not a phdesign sweep store")
        if not store.complete:
            done, total = len(store.done()), store.plan().n_chunks
            raise SweepError(
                f"{str(target)!r} is incomplete ({done} of {total} chunks stored); "
                "finish it with `resume=True`"
            )
        dataset = store.dataset()
    elif kind == "netcdf":
        dataset = _read_netcdf(target)
    else:
        raise SweepError(f"cannot read a sweep back from {str(target)!r}: plots read .zarr or .nc")
    return normalized(dataset)  # refuses a file that is not a phdesign sweep


def _read_netcdf(target: Path) -> Any:
    """Open a NetCDF sweep lazily, check it against its own description, then read it."""
    import os
    import stat

    import xarray as xr

    from phdesign.core.errors import PhdesignError
    from phdesign.sweep.dataset import description_of
    from phdesign.sweep.schema import check_netcdf

    shown = repr(str(target))
    if not stat.S_ISREG(os.stat(target).st_mode):  # a FIFO would block the reader
        raise SweepError(f"cannot read {shown} as NetCDF: it is not a regular file")
    try:
        dataset = xr.open_dataset(target, engine="scipy")  # the header only: lazy
    except Exception as error:  # whatever scipy's parser makes of foreign bytes
        raise SweepError(f"cannot read {shown} as NetCDF: {error}") from None
    try:
        check_netcdf(dataset, description_of(dataset), f"NetCDF file {shown}")
        return dataset.load()
    except PhdesignError:
        raise
    except Exception as error:  # the data section of a crafted file
        raise SweepError(
            f"cannot read {shown} as NetCDF: {type(error).__name__}: {error}"
        ) from None
    finally:
        dataset.close()
