"""Output files: checked before the work, written together, never half-written.

A command that writes several files (``simulate -o run.csv --plot run.png``) opens one
:class:`OutputFiles`, names every target with :meth:`~OutputFiles.add` *before* the work
(so a bad path costs nothing), stages each file's content in a temporary file of the
target's folder, and :meth:`~OutputFiles.commit` puts them all in place at the end. On any
failure, or on SIGINT or SIGTERM, no target is created and no temporary file is left.

Rules for a target:

* a regular file that exists is replaced only with ``force``; without it the file is
  created exclusively (a hard link, or an exclusive create where links are not
  supported), so two processes writing one path cannot both succeed;
* symbolic links (dangling or not, ``/proc/self/fd/1``), folders, FIFOs, sockets and
  devices are refused, even with ``force``: phdesign writes regular files only;
* the null device is the one exception: ``-o /dev/null`` discards the output (every check
  still runs), since writing to it replaces nothing;
* the folder must exist and be writable, and the same file may not be named twice;
* temporary names are short (``.phd-XXXXXXXX.tmp``), so any name the file system allows
  can be written (a 255-byte name included).

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> with OutputFiles() as out:
...     reserved = [out.add(folder / name) for name in ("a.txt", "b.txt")]
...     out.stage(folder / "a.txt", "one")
...     out.stage(folder / "b.txt", b"two")
...     out.commit()
>>> sorted(p.name for p in folder.iterdir())
['a.txt', 'b.txt']
"""

from __future__ import annotations

import contextlib
import errno
import os
import signal
import stat
import threading
from collections.abc import Iterator
from pathlib import Path
from types import FrameType, TracebackType
from typing import Any

from phdesign.core.errors import ArgumentError, OutputFileError

__all__ = [
    "OutputFiles",
    "Terminated",
    "atomic_write",
    "check_output_path",
    "remove_stale_temporaries",
    "terminate_as_interrupt",
]


class Terminated(KeyboardInterrupt):
    """SIGTERM while output files are being written (handled like an interrupt)."""


def _reason(error: OSError) -> str:
    return error.strerror or str(error)


def _null_device() -> tuple[int, int] | None:
    try:
        info = os.stat(os.devnull)
    except OSError:
        return None
    return (info.st_dev, info.st_rdev) if stat.S_ISCHR(info.st_mode) else None


def _classify(target: Path, force: bool) -> str:
    """Return ``"new"``, ``"replace"`` or ``"null"`` for a writable target, else raise."""
    shown = str(target)
    try:
        info = os.lstat(target)
    except FileNotFoundError:
        return "new"
    except ValueError as error:  # an embedded NUL byte
        raise OutputFileError(f"cannot write {shown!r}: {error}") from None
    except OSError as error:
        raise OutputFileError(f"cannot write {shown!r}: {_reason(error)}") from None
    mode = info.st_mode
    if stat.S_ISLNK(mode):
        raise OutputFileError(
            f"output path {shown!r} is a symbolic link; phdesign writes regular files only "
            "(name the file itself)"
        )
    if stat.S_ISDIR(mode):
        raise OutputFileError(f"output path {shown!r} is a folder; expected a file name")
    if stat.S_ISCHR(mode) and _null_device() == (info.st_dev, info.st_rdev):
        return "null"
    if not stat.S_ISREG(mode):
        kind = (
            "a FIFO" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode) else "a device"
        )
        raise OutputFileError(
            f"output path {shown!r} is {kind}; phdesign writes regular files only "
            "(the null device excepted), even with `force=True`"
        )
    if not force:
        raise OutputFileError(f"output file {shown!r} exists; pass `force=True` to overwrite it")
    return "replace"


def check_output_path(path: str | os.PathLike[str], force: bool = False) -> Path:
    """Check, before any work is done, that ``path`` can be written.

    Raises
    ------
    OutputFileError
        If ``path`` exists while ``force`` is false, is not a regular file (symbolic
        link, folder, FIFO, device other than the null device), or its folder is
        missing or not writable.
    """
    if isinstance(path, bytes) or not isinstance(path, str | os.PathLike):
        raise OutputFileError(f"an output path must be text; found {type(path).__name__}")
    target = Path(path)
    if str(path) == "" or target.name in ("", ".", ".."):
        raise OutputFileError(f"output path {str(path)!r} names no file")
    kind = _classify(target, force)
    if kind == "null":
        return target
    folder = target.parent
    if not folder.is_dir():
        raise OutputFileError(
            f"cannot write {str(target)!r}: folder {str(folder)!r} does not exist"
        )
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputFileError(
            f"cannot write {str(target)!r}: folder {str(folder)!r} is not writable"
        )
    return target


#: Temporary files of every open transaction, removed on SIGTERM and at exit.
_LIVE: set[Path] = set()


class OutputFiles:
    """The output files of one command (module docstring).

    Parameters
    ----------
    force : bool
        Replace existing regular files.
    """

    def __init__(self, force: bool = False) -> None:
        self.force = force
        self._targets: dict[Path, str] = {}
        self._staged: dict[Path, Path | bytes] = {}
        self._signals = contextlib.ExitStack()

    # ------------------------------------------------------------------ context
    def __enter__(self) -> OutputFiles:
        self._signals.enter_context(terminate_as_interrupt())
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        try:
            self.discard()
        finally:
            self._signals.close()

    # ------------------------------------------------------------------ steps
    def add(self, path: str | os.PathLike[str]) -> Path:
        """Check ``path`` now (before the work) and reserve it for this command."""
        target = check_output_path(path, self.force)
        key = _identity(target)
        for other in self._targets:
            if _identity(other) == key:
                raise OutputFileError(
                    f"output file {str(target)!r} is named twice (as {str(other)!r}); "
                    "expected a different file for each output"
                )
        self._targets[target] = _classify(target, self.force)
        return target

    def stage(self, path: str | os.PathLike[str], data: str | bytes) -> None:
        """Write the content of a reserved target to its temporary file."""
        content = _content(data, "data")  # before anything is reserved
        target = Path(path)
        if target not in self._targets:
            target = self.add(target)
        if self._targets[target] == "null":
            self._staged[target] = content
            return
        temporary = _create_temporary(target.parent, target)
        try:
            with os.fdopen(os.open(temporary, os.O_WRONLY), "wb") as stream:
                stream.write(content)
        except OSError as error:
            self._remove(temporary)
            raise OutputFileError(f"cannot write {str(target)!r}: {_reason(error)}") from None
        except BaseException:
            self._remove(temporary)
            raise
        self._staged[target] = temporary

    def commit(self) -> None:
        """Put every staged file in place: all of them, or (on an error) none of them."""
        missing = [str(t) for t in self._targets if t not in self._staged]
        if missing:
            raise OutputFileError(f"no content was written for {', '.join(missing)}")
        created: list[tuple[Path, tuple[int, int]]] = []  # targets this commit made

        def undo() -> None:
            for path, identity in created:
                with contextlib.suppress(OSError):
                    info = os.lstat(path)
                    if (info.st_dev, info.st_ino) == identity:  # ours, not a rival's
                        path.unlink()

        try:
            # new files first (exclusive, undoable), replacements last
            for target, temporary in sorted(
                self._staged.items(), key=lambda item: self._targets[item[0]] == "replace"
            ):
                kind = self._targets[target]
                if kind == "null":
                    with open(target, "wb") as stream:
                        stream.write(temporary)  # type: ignore[arg-type]
                elif kind == "new":
                    info = os.stat(temporary)
                    created.append((target, (info.st_dev, info.st_ino)))  # before: a signal
                    _link_exclusively(temporary, target)  # type: ignore[arg-type]
                else:
                    if _classify(target, True) != "replace":  # changed since add()
                        raise OutputFileError(f"output file {str(target)!r} changed meanwhile")
                    os.replace(temporary, target)
        except OSError as error:
            undo()
            raise OutputFileError(f"cannot write {str(target)!r}: {_reason(error)}") from None
        except BaseException:
            undo()
            raise
        finally:
            self.discard()
        self._targets.clear()

    def discard(self) -> None:
        """Remove every temporary file (the targets are untouched)."""
        for staged in self._staged.values():
            if isinstance(staged, Path):
                self._remove(staged)
        self._staged.clear()

    @staticmethod
    def _remove(temporary: Path) -> None:
        with contextlib.suppress(OSError):
            temporary.unlink()
        _LIVE.discard(temporary)


def _raise_terminated(signum: int, frame: FrameType | None) -> None:
    raise Terminated


@contextlib.contextmanager
def terminate_as_interrupt() -> Iterator[None]:
    """Raise :class:`Terminated` on SIGTERM inside the block, so that cleanups run.

    Python's default for SIGTERM is to die at once, leaving temporary files behind; only
    the main thread can install a handler, so elsewhere the block runs unchanged.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        if previous is not None:  # None: a handler installed outside Python
            signal.signal(signal.SIGTERM, previous)


def _identity(path: Path) -> tuple[Any, ...]:
    """Return one identity for a file under two spellings (``a.png``, ``./a.png``)."""
    try:
        info = os.stat(path)
        return (info.st_dev, info.st_ino)
    except OSError:
        return (os.path.realpath(path.parent), path.name)


#: How the staged files are named (``.phd-`` and eight hex digits, ``.tmp``).
TEMPORARY_PREFIX, TEMPORARY_SUFFIX = ".phd-", ".tmp"
#: A staged file older than this (seconds) belongs to no live write: a write stages and
#: links in milliseconds, so only a process killed by SIGKILL leaves one this old.
STALE_AFTER = 60.0


def _is_temporary(name: str) -> bool:
    core = name[len(TEMPORARY_PREFIX) : -len(TEMPORARY_SUFFIX)]
    return (
        name.startswith(TEMPORARY_PREFIX)
        and name.endswith(TEMPORARY_SUFFIX)
        and len(core) == 8
        and all(c in "0123456789abcdef" for c in core)
    )


def remove_stale_temporaries(folder: Path, now: float | None = None) -> int:
    """Delete the staged files a killed write left in ``folder``; return how many.

    Only names of the staging pattern (``.phd-XXXXXXXX.tmp``, :func:`_create_temporary`)
    older than :data:`STALE_AFTER` seconds are removed: SIGTERM and interrupts clean their
    own, SIGKILL cannot, and a younger one may belong to a write in progress.
    """
    import time

    limit = (time.time() if now is None else now) - STALE_AFTER
    removed = 0
    try:
        entries = list(folder.iterdir())
    except OSError:
        return 0
    for entry in entries:
        if not _is_temporary(entry.name):
            continue
        try:
            if entry.is_file() and entry.stat().st_mtime < limit:
                entry.unlink()
                removed += 1
        except OSError:  # gone meanwhile, or not ours to delete: leave it
            continue
    return removed


def _create_temporary(folder: Path, target: Path) -> Path:
    # os.urandom is what secrets.token_hex reads; the secrets module would bring hashlib
    # and hmac into every command's start-up
    for _ in range(100):
        temporary = folder / f"{TEMPORARY_PREFIX}{os.urandom(4).hex()}{TEMPORARY_SUFFIX}"
        _LIVE.add(temporary)
        try:
            os.close(os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
            return temporary
        except FileExistsError:
            _LIVE.discard(temporary)
        except OSError as error:
            _LIVE.discard(temporary)
            raise OutputFileError(f"cannot write {str(target)!r}: {_reason(error)}") from None
    raise OutputFileError(f"cannot write {str(target)!r}: no free temporary name")


def _link_exclusively(temporary: Path, target: Path) -> None:
    """Give ``target`` the staged content, failing if it exists (no check-then-write race)."""
    try:
        os.link(temporary, target)
    except FileExistsError:
        raise OutputFileError(
            f"output file {str(target)!r} exists (created meanwhile); pass `force=True` to "
            "overwrite it"
        ) from None
    except OSError as error:
        if error.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EXDEV):
            raise
        # no hard links here: claim the name exclusively, then move the content over it
        try:
            os.close(os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
        except FileExistsError:
            raise OutputFileError(
                f"output file {str(target)!r} exists (created meanwhile); pass `force=True` "
                "to overwrite it"
            ) from None
        os.replace(temporary, target)
        return
    OutputFiles._remove(temporary)


def atomic_write(path: str | os.PathLike[str], text: str | bytes, force: bool = False) -> None:
    """Write one file through a temporary file and an exclusive link or a rename.

    Raises
    ------
    ArgumentError
        If ``text`` is neither text nor bytes.
    OutputFileError
        If the target is refused (see :func:`check_output_path`) or cannot be written.
    """
    _content(text, "text")  # refused before the path is looked at
    with OutputFiles(force) as out:
        out.add(path)
        out.stage(path, text)
        out.commit()


def _content(data: object, name: str) -> bytes:
    """Return ``data`` as bytes: text (UTF-8) or bytes-like; refuse anything else by name.

    ``bytes(123)`` is 123 zero bytes, and ``None`` a TypeError from CPython: neither may
    reach a file.
    """
    if isinstance(data, str):
        return data.encode("utf-8")
    if isinstance(data, bytes | bytearray | memoryview):
        return bytes(data)
    raise ArgumentError(f"{name}: expected text or bytes to write; found {type(data).__name__}")
