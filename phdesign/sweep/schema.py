"""What a sweep's files must hold before phdesign reads them: the sweep's own schema.

A store or NetCDF file may come from anyone.  Before any array is opened, its metadata is
compared with what :func:`phdesign.sweep.dataset.template` writes for the description the
file itself carries: exactly the coordinates and figures of that description, each with
its dimensions, its shape (the grid's, so a file cannot declare arrays longer than the
grid it describes), its dtype (numbers, booleans and fixed-width text: never an object
dtype or an object codec such as pickle), its fill value and its CF attributes (a
``units`` of ``"days since ..."`` would turn a figure into dates).  Zarr chunks are
checked too: regular files (a link to ``/dev/zero`` is refused), none larger than its
chunk (the Blosc header declares the size it decompresses to).  Everything else is
refused with one :class:`~phdesign.core.errors.SweepError` that says what was found; so is
any metadata file that is not a regular file, is larger than
:data:`~phdesign.core.limits.MAX_STORE_METADATA_BYTES` or is not JSON.

Examples
--------
>>> import json, tempfile, pathlib
>>> path = pathlib.Path(tempfile.mkdtemp()) / "x.json"
>>> _ = path.write_text("[1, 2")
>>> read_json(path, "the store's sweep.json")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
phdesign.core.errors.SweepError: the store's sweep.json is not JSON: Expecting ',' delimiter...
"""

from __future__ import annotations

import itertools
import json
import math
import os
import stat
import struct
from pathlib import Path
from typing import Any

import numpy as np

from phdesign.core.errors import SweepError
from phdesign.core.limits import MAX_STORE_METADATA_BYTES
from phdesign.sweep.dataset import SWEEP_ATTRIBUTE, attributes, template
from phdesign.sweep.description import SweepDescription
from phdesign.sweep.plan import ChunkPlan

__all__ = ["check_netcdf", "check_zarr", "read_json"]

_ARRAY_KEYS = {"zarr_format", "shape", "chunks", "dtype", "compressor", "fill_value", "order"}
_ARRAY_KEYS_OPTIONAL = {"filters", "dimension_separator"}
_BLOSC_KEYS = {"id", "cname", "clevel", "shuffle", "blocksize"}
_BLOSC_NAMES = ("blosclz", "lz4", "lz4hc", "zlib", "zstd")
_FREE_TEXT = ("long_name",)  # attributes whose text may differ between versions


def read_json(path: Path, what: str) -> Any:
    """Parse a regular file of at most :data:`MAX_STORE_METADATA_BYTES` bytes as JSON.

    Raises
    ------
    SweepError
        Missing, not a regular file (a link, a FIFO, a device), too large, not UTF-8 JSON,
        or nested too deeply.
    """
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        raise SweepError(f"{what} is missing") from None
    except OSError as error:
        raise SweepError(f"cannot read {what}: {error.strerror or error}") from None
    with os.fdopen(fd, "rb") as stream:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise SweepError(f"{what} is not a regular file")
        data = stream.read(MAX_STORE_METADATA_BYTES + 1)
    if len(data) > MAX_STORE_METADATA_BYTES:
        raise SweepError(
            f"{what} is larger than {MAX_STORE_METADATA_BYTES:,} bytes "
            "(the budget phdesign.core.limits.MAX_STORE_METADATA_BYTES)"
        )
    try:
        return json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as error:
        raise SweepError(f"{what} is not JSON: {error}") from None
    except RecursionError:
        raise SweepError(f"{what} is nested too deeply") from None


def _lstat_mode(path: Path) -> int:
    try:
        return os.lstat(path).st_mode
    except OSError:
        return 0


def _expected(description: SweepDescription) -> dict[str, Any]:
    """Return the variables (coordinates, figures) of the description's Dataset, lazily."""
    plan = ChunkPlan(description.shape, description.shape)  # one chunk: nothing is built
    return dict(template(description, plan, lazy=True).variables)


def _check_attributes(where: str, found: Any, variable: Any) -> None:
    expected = {**variable.attrs, "_ARRAY_DIMENSIONS": list(variable.dims)}
    if not isinstance(found, dict) or set(found) != set(expected):
        keys = sorted(found) if isinstance(found, dict) else type(found).__name__
        raise SweepError(f"{where}: expected the attributes {sorted(expected)}; found {keys}")
    for key, value in expected.items():
        if key in _FREE_TEXT:
            if not isinstance(found[key], str) or len(found[key]) > 1000:
                raise SweepError(f"{where}: attribute {key} must be a short text")
        elif found[key] != value:
            raise SweepError(f"{where}: attribute {key} must be {value!r}; found {found[key]!r}")


def _check_compressor(where: str, compressor: Any) -> None:
    if compressor is None:
        return
    if (
        not isinstance(compressor, dict)
        or compressor.get("id") != "blosc"
        or not set(compressor) <= _BLOSC_KEYS
        or compressor.get("cname") not in _BLOSC_NAMES
    ):
        raise SweepError(
            f"{where}: the compressor must be none or Blosc, as phdesign writes; found "
            f"{json.dumps(compressor)[:80]}"
        )


def _check_array(where: str, meta: Any, variable: Any) -> tuple[int, ...]:
    """Check one ``.zarray`` against its variable; return its chunk shape."""
    if (
        not isinstance(meta, dict)
        or not _ARRAY_KEYS <= set(meta) <= _ARRAY_KEYS | _ARRAY_KEYS_OPTIONAL
    ):
        raise SweepError(f"{where}: not the metadata of a Zarr format 2 array")
    shape = list(variable.shape)
    dtype = np.dtype(variable.dtype).str
    fill = "NaN" if variable.dtype.kind == "f" else None
    for key, value in (("zarr_format", 2), ("shape", shape), ("dtype", dtype), ("order", "C")):
        if meta[key] != value or isinstance(meta[key], bool):
            raise SweepError(
                f"{where}: {key} must be {json.dumps(value)} (the grid the store describes); "
                f"found {json.dumps(meta[key])[:80]}"
            )
    if meta["fill_value"] != fill or meta.get("filters") not in (None, []):
        raise SweepError(f"{where}: the fill value must be {fill} and there may be no filters")
    if meta.get("dimension_separator", ".") != ".":
        raise SweepError(f"{where}: the dimension separator must be '.'")
    _check_compressor(where, meta["compressor"])
    chunks = meta["chunks"]
    if not isinstance(chunks, list) or len(chunks) != len(shape):
        raise SweepError(f"{where}: chunks must be positive and fit the shape {shape}")
    if not all(type(c) is int and 1 <= c <= max(n, 1) for c, n in zip(chunks, shape, strict=True)):
        raise SweepError(f"{where}: chunks must be positive and fit the shape {shape}")
    return tuple(chunks)


def _check_chunk_files(folder: Path, variable: Any, chunks: tuple[int, ...], blosc: bool) -> None:
    """Every chunk file regular, and no larger than its chunk once decompressed."""
    size = math.prod(chunks) * np.dtype(variable.dtype).itemsize
    blocks = [range(math.ceil(n / c)) for n, c in zip(variable.shape, chunks, strict=True)]
    for index in itertools.product(*blocks):
        name = ".".join(map(str, index)) or "0"
        try:
            info = os.lstat(folder / name)
        except FileNotFoundError:
            continue  # never written: Zarr gives the fill value
        where = f"chunk {folder.name}/{name}"
        if not stat.S_ISREG(info.st_mode):
            raise SweepError(f"{where} is not a regular file")
        if not blosc:
            if info.st_size != size:
                raise SweepError(f"{where} holds {info.st_size} bytes; expected {size}")
            continue
        with open(folder / name, "rb") as stream:
            header = stream.read(16)
        if len(header) < 16:
            raise SweepError(f"{where} is not a Blosc chunk")
        nbytes, _, cbytes = struct.unpack("<III", header[4:16])
        if nbytes != size or cbytes != info.st_size:
            raise SweepError(
                f"{where} declares {nbytes} bytes ({cbytes} compressed); expected {size} "
                f"({info.st_size} in the file)"
            )


def check_zarr(path: Path, description: SweepDescription) -> None:
    """Refuse a Zarr store whose metadata or chunks are not the description's (module doc).

    Raises
    ------
    SweepError
        The first difference found.
    """
    where = f"store {str(path)!r}"
    consolidated = read_json(path / ".zmetadata", f"{where}'s .zmetadata")
    if not isinstance(consolidated, dict) or not isinstance(consolidated.get("metadata"), dict):
        raise SweepError(f"{where}: .zmetadata is not consolidated Zarr metadata")
    metadata = consolidated["metadata"]
    variables = _expected(description)
    names = {".zgroup", ".zattrs"} | {
        f"{n}/{k}" for n in variables for k in (".zarray", ".zattrs")
    }
    if set(metadata) != names:
        extra = sorted(set(metadata) - names) or sorted(names - set(metadata))
        raise SweepError(
            f"{where} does not hold the arrays its description names (found or missing: "
            f"{', '.join(extra[:4])})"
        )
    group = metadata[".zattrs"]
    expected = attributes(description)
    if metadata[".zgroup"] != {"zarr_format": 2} or not isinstance(group, dict):
        raise SweepError(f"{where}: not a Zarr format 2 group")
    if set(group) != set(expected) or group[SWEEP_ATTRIBUTE] != expected[SWEEP_ATTRIBUTE]:
        raise SweepError(f"{where}: its attributes are not those of the sweep it describes")
    for name, variable in variables.items():
        if not stat.S_ISDIR(_lstat_mode(path / name)):  # a link would take writes elsewhere
            raise SweepError(f"{where}: {name} is not a folder of the store")
        meta = metadata[f"{name}/.zarray"]
        if read_json(path / name / ".zarray", f"{where}'s {name}/.zarray") != meta:
            raise SweepError(f"{where}: {name}/.zarray differs from the consolidated metadata")
        chunks = _check_array(f"{where}, array {name}", meta, variable)
        _check_attributes(f"{where}, array {name}", metadata[f"{name}/.zattrs"], variable)
        _check_chunk_files(path / name, variable, chunks, meta["compressor"] is not None)


def check_netcdf(dataset: Any, description: SweepDescription, where: str) -> None:
    """Refuse a lazily opened NetCDF sweep whose variables are not the description's.

    Only names, dimensions, shapes and dtype kinds are compared (NetCDF-3 stores booleans as
    bytes and text as characters, which xarray decodes); nothing has been read yet.
    """
    variables = _expected(description)
    if set(map(str, dataset.variables)) != set(variables):
        raise SweepError(f"{where} does not hold the variables its description names")
    for name, variable in variables.items():
        found = dataset.variables[name]
        text = variable.dtype.kind == "U"
        kinds = "OUS" if text else variable.dtype.kind
        if tuple(found.dims) != tuple(variable.dims) or tuple(found.shape) != variable.shape:
            raise SweepError(
                f"{where}, variable {name}: expected dimensions {variable.dims} of shape "
                f"{variable.shape}; found {tuple(found.dims)} of shape {tuple(found.shape)}"
            )
        if found.dtype.kind not in kinds:
            raise SweepError(
                f"{where}, variable {name}: expected {variable.dtype}; found {found.dtype}"
            )
