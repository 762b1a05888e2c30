"""A sweep stored in Zarr, written chunk by chunk, resumable, and marked when complete.

Layout of ``map.zarr`` (Zarr format 2, consolidated metadata: every Zarr reader and
``xarray.open_zarr`` open it; format 3 has no specified fixed-width text type yet)::

    map.zarr/
      .zgroup, .zattrs, .zmetadata     the Dataset's metadata and attributes
      l1/, l2/, spectral_abscissa/ ... one array per coordinate and figure; one Zarr
                                       chunk per sweep chunk
      .phdesign/sweep.json             the description and the chunk layout
      .phdesign/chunks/00000012        one marker per chunk whose figures are stored
      .phdesign/complete.json          the completion marker, with the run's record

Every marker is written through a temporary file and a rename, after the data it vouches
for, so that a sweep killed at any instant resumes with exactly the chunks it had
finished (a chunk written without its marker is computed again and overwritten).  A
store is resumed only by the sweep it describes: any difference in the description (the
model, job, options, axes, sensors, gain or phdesign version) is refused.

Only a Zarr store or a regular file at the path is replaced (``force``), and only while
the store's lock is held (:mod:`phdesign.sweep.lock`, taken by
:func:`~phdesign.sweep.execute.run`); symbolic links, FIFOs, sockets and devices are
refused whatever the flags, and a folder that is not a Zarr store is never replaced.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from phdesign.core.errors import OutputFileError, PhdesignError, SweepError
from phdesign.core.files import remove_stale_temporaries
from phdesign.io import atomic_write
from phdesign.sweep.description import SweepDescription
from phdesign.sweep.plan import ChunkPlan
from phdesign.sweep.schema import check_zarr, read_json

__all__ = ["ZarrStore"]

_MARKERS = ".phdesign"
_MARKER_NAME = re.compile(r"[0-9]{8}", re.ASCII)  # '²' is a digit to str.isdigit, not here


def _kind(path: Path) -> str:
    """Say what is at ``path``, not following a symbolic link (``"missing"``, ``"folder"``...)."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return "missing"
    except (OSError, ValueError) as error:  # ValueError: an embedded NUL byte
        raise OutputFileError(f"cannot write {str(path)!r}: {error}") from None
    if stat.S_ISDIR(mode):
        return "folder"
    if stat.S_ISREG(mode):
        return "file"
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    return "a socket" if stat.S_ISSOCK(mode) else "a device"


@dataclass(frozen=True)
class ZarrStore:
    """A sweep's Zarr store at ``path``."""

    path: Path

    @property
    def _markers(self) -> Path:
        return self.path / _MARKERS

    @property
    def is_zarr(self) -> bool:
        """The folder holds a Zarr hierarchy (format 2 or 3)."""
        return any((self.path / name).exists() for name in (".zgroup", "zarr.json"))

    def stored(self) -> tuple[SweepDescription, ChunkPlan] | None:
        """Return the stored description and chunk layout (``None``: no ``sweep.json``).

        Raises
        ------
        SweepError
            A ``sweep.json`` that is not a regular file, too large, not JSON, or not a
            description and a chunk layout that fits it (the message says which).
        """
        where = f"{str(self.path)!r}'s {_MARKERS}/sweep.json"
        if not os.path.lexists(self._markers / "sweep.json"):
            return None
        data = read_json(self._markers / "sweep.json", where)
        if not isinstance(data, dict) or set(data) != {"description", "chunk_shape"}:
            raise SweepError(f"{where} must hold a description and a chunk shape")
        description = SweepDescription.from_json(data["description"])
        chunks = data["chunk_shape"]
        if not isinstance(chunks, list) or not all(type(c) is int for c in chunks):
            raise SweepError(f"{where}: the chunk shape must be a list of integers")
        return description, ChunkPlan(description.shape, tuple(chunks))

    @property
    def complete(self) -> bool:
        """The completion marker exists (a regular file)."""
        return _kind(self._markers / "complete.json") == "file"

    def done(self) -> set[int]:
        """Return the indices of the chunks whose figures are stored (their markers' names)."""
        folder = self._markers / "chunks"
        if _kind(folder) != "folder":
            return set()
        n_chunks = self.plan().n_chunks
        names = (p.name for p in folder.iterdir())
        return {int(n) for n in names if _MARKER_NAME.fullmatch(n) and int(n) < n_chunks}

    def remove_stale_markers(self) -> int:
        """Delete the half-written markers a killed sweep left (they vouch for nothing)."""
        folders = (self._markers, self._markers / "chunks")
        return sum(remove_stale_temporaries(f) for f in folders if _kind(f) == "folder")

    def check(
        self,
        description: SweepDescription,
        *,
        resume: bool,
        force: bool,
        chunk_size: int | None,
    ) -> str:
        """Decide, before anything is written, what to do with the path.

        Returns
        -------
        {"create", "replace", "resume", "complete"}

        Raises
        ------
        OutputFileError
            The path exists and neither ``resume`` nor ``force`` is given, is a folder that
            is not a Zarr store, or its folder is missing.
        SweepError
            ``resume`` of something that is not this sweep, or both flags.
        """
        where = str(self.path)
        if resume and force:
            raise SweepError("choose one of resume (continue the store) and force (replace it)")
        kind = _kind(self.path)
        if kind == "missing":
            if not self.path.parent.is_dir():
                raise OutputFileError(
                    f"cannot write {where!r}: folder {str(self.path.parent)!r} does not exist"
                )
            return "create"
        if kind not in ("folder", "file"):
            raise OutputFileError(
                f"output {where!r} is {kind}; a sweep writes its store only where there is "
                "nothing, a file or a Zarr store, even with `force=True` (name the store itself)"
            )
        if force:
            if kind == "folder" and not self.is_zarr:
                raise OutputFileError(
                    f"output {where!r} is a folder that is not a Zarr store; "
                    "refusing to replace it"
                )
            return "replace"
        if not resume:
            raise OutputFileError(
                f"output {where!r} exists; resume the sweep it holds (`resume=True`) "
                "or replace it (`force=True`)"
            )
        if kind != "folder":
            raise SweepError(
                f"cannot resume {where!r}: it is not a phdesign sweep store (it is a file); "
                "replace it with `force=True`"
            )
        self._check_resumable(description, chunk_size)
        return "complete" if self.complete else "resume"

    def _check_resumable(self, description: SweepDescription, chunk_size: int | None) -> None:
        """Refuse to resume a folder that is not this sweep's store, exactly as written."""
        where = str(self.path)
        try:
            stored = self.stored()
        except SweepError as error:
            raise SweepError(
                f"cannot resume {where!r}: {error}; replace it with `force=True`"
            ) from None
        if stored is None:
            raise SweepError(
                f"cannot resume {where!r}: it is not a phdesign sweep store "
                f"(no {_MARKERS}/sweep.json); replace it with `force=True`"
            )
        old, plan = stored
        difference = old.difference(description)
        if difference is not None:
            raise SweepError(
                f"cannot resume {where!r}: it holds a different sweep ({difference}); "
                "replace it with `force=True` or choose another output"
            )
        if chunk_size is not None and chunk_size != plan.chunk_size:
            raise SweepError(
                f"cannot resume {where!r} with chunk size {chunk_size}: it was written in "
                f"chunks of {plan.chunk_size} points (drop the chunk size)"
            )
        for folder in (self._markers, self._markers / "chunks"):
            if _kind(folder) != "folder":  # a link would take the markers elsewhere
                raise SweepError(f"cannot resume {where!r}: {str(folder)!r} is not a folder")
        check_zarr(self.path, old)  # its arrays are the description's before one is written

    def plan(self) -> ChunkPlan:
        """Return the stored chunk layout."""
        stored = self.stored()
        if stored is None:
            raise SweepError(f"{str(self.path)!r} is not a phdesign sweep store")
        return stored[1]

    def create(
        self, template: Any, description: SweepDescription, plan: ChunkPlan, action: str
    ) -> None:
        """Write the metadata (no figures yet); ``action`` is :meth:`check`'s answer.

        With ``"replace"`` the store or file at the path goes first; :meth:`check` has
        refused anything else (a folder that is not a Zarr store, a link, a FIFO, a device),
        and the caller holds the store's lock.
        """
        if action == "replace":
            self.remove()
        template.to_zarr(self.path, mode="w-", compute=False, zarr_format=2, consolidated=True)
        (self._markers / "chunks").mkdir(parents=True)
        record = {"description": description.to_json(), "chunk_shape": list(plan.chunk_shape)}
        atomic_write(self._markers / "sweep.json", json.dumps(record, indent=1), force=True)

    def remove(self) -> None:
        """Delete the store (or the file) at the path: only one :meth:`check` accepted."""
        kind = _kind(self.path)
        if kind == "folder":
            shutil.rmtree(self.path)
        elif kind == "file":
            self.path.unlink()

    def writer(self) -> Any:
        """Open the Zarr group once for the chunk writes."""
        import zarr

        return zarr.open_group(str(self.path), mode="r+", zarr_format=2, use_consolidated=True)

    def write_chunk(
        self, group: Any, index: int, region: tuple[slice, ...], arrays: dict[str, np.ndarray]
    ) -> None:
        """Store one chunk's figures, then its marker."""
        for name, block in arrays.items():
            group[name][region] = block
        atomic_write(self._markers / "chunks" / f"{index:08d}", b"", force=True)

    def mark_complete(self, record: dict[str, Any]) -> None:
        """Write the completion marker (with the run's record)."""
        atomic_write(self._markers / "complete.json", json.dumps(record, indent=1), force=True)

    def dataset(self) -> Any:
        """Read the stored sweep as an :class:`xarray.Dataset`, after checking its schema.

        Raises
        ------
        SweepError
            Not a sweep store, metadata or chunks that are not its description's
            (:func:`~phdesign.sweep.schema.check_zarr`), or chunk bytes Zarr cannot decode.
        """
        import xarray as xr

        from phdesign.sweep.dataset import normalized

        stored = self.stored()
        if stored is None:
            raise SweepError(f"{str(self.path)!r} is not a phdesign sweep store")
        check_zarr(self.path, stored[0])
        try:
            raw = xr.open_zarr(self.path, chunks=None, consolidated=True, zarr_format=2)
            return normalized(raw).load()
        except PhdesignError:
            raise
        except Exception as error:  # corrupt chunk bytes: the decoders' own errors
            raise SweepError(
                f"cannot read {str(self.path)!r}: {type(error).__name__}: {error}"
            ) from None
