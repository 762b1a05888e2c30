"""The C export's folder: written whole or not at all, replaced only when phdesign wrote it.

A folder export is staged in a temporary folder next to the target (``.phd-XXXXXXXX.tmp``)
and renamed into place. Beside the sources it holds a marker, :data:`MARKER`, that lists
them. ``force`` replaces an existing folder only while it is recognisably phdesign's own
export: it holds exactly the files its marker lists and the marker, all regular files.
Anything else is refused with the reason, even with ``force``: a folder of the user's, one
phdesign wrote that has since received other files, the working directory, a symbolic
link, a FIFO, a device. A replaced export is removed file by file (only the names its
marker lists, then the empty folder), never recursively, so nothing phdesign did not
write is deleted even if the folder changes while the export runs.

On any failure, on SIGINT and on SIGTERM, the staging folder is removed and an export
being replaced is put back.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import stat
import tempfile
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path

from phdesign.core.errors import OutputFileError
from phdesign.core.files import TEMPORARY_PREFIX, TEMPORARY_SUFFIX, terminate_as_interrupt

__all__ = ["MARKER", "check_export_folder", "write_directory"]

#: The marker file of a folder export (hidden: it is not part of the sources).
MARKER = ".phdesign-export"
#: A marker is a few hundred bytes; anything longer is not phdesign's.
_MARKER_LIMIT = 1 << 16
_NOTE = (
    "written by phdesign export, which replaces this folder (when forced) only while it "
    "holds exactly these files and this marker"
)


def _reason(error: OSError) -> str:
    return error.strerror or str(error)


def _kind(mode: int) -> str | None:
    """Name the kind of a non-folder file (None for a folder)."""
    if stat.S_ISDIR(mode):
        return None
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    if stat.S_ISREG(mode):
        return "a file"
    return "a FIFO" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode) else "a device"


def _marker_text(names: Iterable[str]) -> str:
    from phdesign import __version__

    record = {"phdesign": __version__, "files": list(names), "note": _NOTE}
    return json.dumps(record, indent=1) + "\n"


def _listed_files(folder: Path) -> list[str] | None:
    """Return the names the marker of ``folder`` lists (None: no valid marker)."""
    try:
        handle = os.open(folder / MARKER, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return None
    with os.fdopen(handle, "rb") as stream:
        if not stat.S_ISREG(os.fstat(stream.fileno()).st_mode):
            return None
        data = stream.read(_MARKER_LIMIT + 1)
    try:
        record = json.loads(data.decode("utf-8")) if len(data) <= _MARKER_LIMIT else None
    except ValueError:  # not UTF-8, not JSON
        return None
    names = record.get("files") if isinstance(record, dict) else None
    if not isinstance(names, list) or not all(_plain_name(n) for n in names):
        return None
    return names


def _plain_name(name: object) -> bool:
    return (
        isinstance(name, str)
        and name not in ("", ".", "..", MARKER)
        and "/" not in name
        and "\0" not in name
    )


def _foreign_contents(folder: Path) -> str | None:
    """Why ``folder`` is not an export phdesign wrote (None if it is one)."""
    listed = _listed_files(folder)
    if listed is None:
        return f"it holds no marker {MARKER} (phdesign did not write it)"
    try:
        entries = sorted(os.listdir(folder))
    except OSError as error:
        return f"it cannot be read ({_reason(error)})"
    extra = [name for name in entries if name != MARKER and name not in listed]
    if extra:
        shown = ", ".join(repr(name) for name in extra[:3]) + (", ..." if len(extra) > 3 else "")
        return f"it holds files phdesign did not write ({shown})"
    for name in entries:
        with contextlib.suppress(OSError):
            if not stat.S_ISREG(os.lstat(folder / name).st_mode):
                return f"its entry {name!r} is not a regular file"
    return None


def _is_working_directory(target: Path) -> bool:
    try:
        return os.path.samefile(target, os.getcwd())
    except OSError:
        return False


def check_export_folder(path: str | os.PathLike[str], force: bool = False) -> tuple[Path, bool]:
    """Check, before any work, that the folder ``path`` can receive a folder export.

    Returns
    -------
    target : Path
    replace : bool
        True when ``path`` is an earlier export that ``force`` replaces.

    Raises
    ------
    OutputFileError
        If ``path`` names no folder (``.``, ``..``), is not a folder (a file, a symbolic
        link, a FIFO, a device), is the working directory, exists without ``force``, is a
        folder phdesign did not write (module docstring), or its parent folder is missing.
    """
    target = Path(path)
    shown = str(target)
    if shown == "" or target.name in ("", ".", ".."):
        raise OutputFileError(f"output path {shown!r} names no folder; expected a new folder name")
    try:
        info = os.lstat(target)
    except FileNotFoundError:
        if not target.parent.is_dir():
            raise OutputFileError(
                f"cannot write {shown!r}: folder {str(target.parent)!r} does not exist"
            ) from None
        return target, False
    except (OSError, ValueError) as error:  # ValueError: an embedded NUL byte
        reason = _reason(error) if isinstance(error, OSError) else str(error)
        raise OutputFileError(f"cannot write {shown!r}: {reason}") from None
    kind = _kind(info.st_mode)
    if kind is not None:
        raise OutputFileError(
            f"output path {shown!r} is {kind}; format 'c' writes a folder, and replaces only "
            "a folder it wrote, even with `force=True`"
        )
    if _is_working_directory(target):
        raise OutputFileError(
            f"output folder {shown!r} is the working directory; phdesign never replaces it: "
            "name a new folder"
        )
    foreign = _foreign_contents(target)
    if foreign is not None:
        raise OutputFileError(
            f"output folder {shown!r} exists and is not an export of phdesign: {foreign}; "
            "`force=True` replaces only a folder phdesign wrote: name a new folder"
        )
    if not force:
        raise OutputFileError(f"output folder {shown!r} exists; pass `force=True` to replace it")
    return target, True


def _write_file(path: Path, data: bytes) -> None:
    """Write one file of the staging folder (new, private to this process: mode 0700)."""
    path.write_bytes(data)


def _remove_export(folder: Path, names: Iterable[str]) -> None:
    """Delete the named files of ``folder``, then the folder if that left it empty."""
    for name in names:
        with contextlib.suppress(OSError):
            os.unlink(folder / name)
    with contextlib.suppress(OSError):
        os.rmdir(folder)  # fails, and keeps everything, if anything else is in it


def _new_folder(parent: Path) -> Path:
    return Path(tempfile.mkdtemp(dir=parent, prefix=TEMPORARY_PREFIX, suffix=TEMPORARY_SUFFIX))


def write_directory(
    path: str | os.PathLike[str], files: Mapping[str, str | bytes], force: bool = False
) -> list[str]:
    """Write ``files`` (name → content) as the folder ``path``: all of them or none.

    The folder also receives :data:`MARKER`. An earlier export (``force``) is first
    renamed aside (and put back if the final rename fails), then removed file by file.
    Returns the paths of ``files`` in the new folder.

    Raises
    ------
    OutputFileError
        See :func:`check_export_folder`; or a file cannot be written.
    """
    target, replace = check_export_folder(path, force)
    names = list(files)
    if not all(_plain_name(name) for name in names):
        raise OutputFileError(f"files: expected plain file names; found {names!r}")
    with terminate_as_interrupt():
        try:
            staging = _new_folder(target.parent)
        except OSError as error:
            raise OutputFileError(f"cannot write {str(target)!r}: {_reason(error)}") from None
        try:
            for name, content in files.items():
                data = content.encode("utf-8") if isinstance(content, str) else content
                _write_file(staging / name, data)
            _write_file(staging / MARKER, _marker_text(names).encode("utf-8"))
            umask = os.umask(0)
            os.umask(umask)
            staging.chmod(0o777 & ~umask)  # mkdtemp creates 0700
            with _signals_deferred():  # the renames and the removal run to their end
                old = _put_in_place(staging, target, replace)
                if old is not None:
                    _remove_export(old, [*(_listed_files(old) or []), MARKER])
        except OSError as error:
            _remove_export(staging, [*names, MARKER])
            raise OutputFileError(f"cannot write {str(target)!r}: {_reason(error)}") from None
        except BaseException:  # SIGINT, SIGTERM, a bug: no staging folder is left behind
            _remove_export(staging, [*names, MARKER])  # (gone already if renamed into place)
            raise
    return [str(target / name) for name in names]


@contextlib.contextmanager
def _signals_deferred() -> Iterator[None]:
    """Hold SIGINT and SIGTERM back until the block ends (they are delivered then).

    Between renaming the old export aside and the new one into place, an interrupt would
    leave the target missing or the old export hidden; these steps take microseconds.
    """
    held = {signal.SIGINT, signal.SIGTERM}
    if not hasattr(signal, "pthread_sigmask"):  # Windows: no signal masks
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def _put_in_place(staging: Path, target: Path, replace: bool) -> Path | None:
    """Rename ``staging`` to ``target``; return where the replaced export now is."""
    if not replace:
        staging.rename(target)  # fails if a non-empty folder appeared meanwhile
        return None
    aside = _new_folder(target.parent)
    target.rename(aside)  # onto the empty folder: atomic, the name is ours
    try:
        foreign = _foreign_contents(aside)
        if foreign is not None:
            raise OutputFileError(
                f"output folder {str(target)!r} changed meanwhile ({foreign}); it was left "
                "as it is"
            )
        staging.rename(target)
    except BaseException:
        aside.rename(target)
        raise
    return aside
