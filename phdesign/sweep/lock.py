"""One writer per sweep store: an advisory lock held from the store's check to its completion.

Two sweeps writing one store at once (``--force`` twice, or ``--force`` beside
``--resume``) would delete each other's arrays and leave a store nobody can read.  Before a
sweep decides what to do with its store, it takes an exclusive :func:`fcntl.flock` on a
lock file beside it, ``.NAME.phdesign-lock`` in the store's folder (not inside the store:
``--force`` deletes the store, and a new one does not exist yet), and keeps it until the
store is complete or the sweep fails.  A second sweep finds the lock held and is refused
at once, naming the process that holds it; it writes nothing.

The kernel drops the lock of a process that dies, even by SIGKILL, so there is no stale
lock to break: a lock file left by a killed sweep is taken over by the next one (its
content names the dead process, and is rewritten).  A file of that name that phdesign did
not write (its first line is not :data:`MARKER`) is a user's and is refused, never
truncated or removed.  The lock file is removed when the lock is released; a rival that
opened it meanwhile sees that it was removed (another inode at the path) and tries again.

Examples
--------
>>> import tempfile, pathlib
>>> store = pathlib.Path(tempfile.mkdtemp()) / "map.zarr"
>>> with StoreLock(store):
...     sorted(p.name for p in store.parent.iterdir())
['.map.zarr.phdesign-lock']
>>> sorted(p.name for p in store.parent.iterdir())
[]
"""

from __future__ import annotations

import contextlib
import os
import socket
import stat
from pathlib import Path
from types import TracebackType

from phdesign.core.errors import OutputFileError, SweepError

__all__ = ["MARKER", "StoreLock", "lock_path"]

#: The first line of every lock file phdesign writes.
MARKER = "phdesign sweep lock"
_ATTEMPTS = 20  # the lock file was removed between a rival's open and its lock: try again


def lock_path(store: Path) -> Path:
    """Return the lock file of the store at ``store``."""
    return store.parent / f".{store.name}.phdesign-lock"


def _holder(fd: int) -> str:
    """Return who holds a lock file (``process 1234 on host``), or ``another process``."""
    try:
        lines = os.pread(fd, 512, 0).decode("utf-8", "replace").splitlines()
    except OSError:
        return "another process"
    return lines[1] if len(lines) > 1 and lines[0] == MARKER else "another process"


class StoreLock:
    """The exclusive lock of one sweep store (module docstring); a context manager.

    Parameters
    ----------
    store : Path
        The store's path (it need not exist yet).

    Raises
    ------
    SweepError
        Another sweep holds the lock.
    OutputFileError
        The lock file's name is taken by something phdesign did not write, or the folder
        cannot hold it.
    """

    def __init__(self, store: Path) -> None:
        self.store = Path(store)
        self.path = lock_path(self.store)
        self._fd: int | None = None

    def __enter__(self) -> StoreLock:
        self.acquire()
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.release()

    def acquire(self) -> None:
        """Take the lock, or raise (see the class docstring)."""
        import fcntl

        for _ in range(_ATTEMPTS):
            fd = self._open()
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = _holder(fd)
                os.close(fd)
                raise SweepError(
                    f"another sweep ({holder}) is writing {str(self.store)!r}; wait until it "
                    "ends, or choose another output"
                ) from None
            if self._still_at_path(fd):
                self._fd = fd
                self._write_owner(fd)
                return
            os.close(fd)  # removed by its holder between our open and our lock
        raise SweepError(f"cannot lock {str(self.store)!r}: its lock file keeps changing")

    def _open(self) -> int:
        """Open the lock file, creating it if needed; refuse a file phdesign did not write."""
        flags = os.O_RDWR | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
        try:
            return os.open(self.path, flags | os.O_CREAT | os.O_EXCL, 0o644)
        except FileExistsError:
            pass
        except OSError as error:
            raise OutputFileError(
                f"cannot write {str(self.store)!r}: cannot create its lock file "
                f"{str(self.path)!r} ({error.strerror or error})"
            ) from None
        try:
            fd = os.open(self.path, flags)
        except FileNotFoundError:  # released and removed meanwhile: create it again
            return self._open()
        except OSError as error:  # a symbolic link (ELOOP), a folder, no permission
            raise self._foreign(error.strerror or str(error)) from None
        info = os.fstat(fd)
        first = os.pread(fd, len(MARKER) + 1, 0).decode("utf-8", "replace")
        # empty: a rival created it and has not written its name yet (it holds the lock)
        if not stat.S_ISREG(info.st_mode) or first not in ("", MARKER + "\n"):
            os.close(fd)
            raise self._foreign("it was not written by phdesign")
        return fd

    def _foreign(self, reason: str) -> OutputFileError:
        return OutputFileError(
            f"cannot lock {str(self.store)!r}: {str(self.path)!r} exists and {reason}; "
            "move it away (phdesign keeps its lock there)"
        )

    def _still_at_path(self, fd: int) -> bool:
        try:
            here = os.lstat(self.path)
        except OSError:
            return False
        mine = os.fstat(fd)
        return (here.st_dev, here.st_ino) == (mine.st_dev, mine.st_ino)

    @staticmethod
    def _write_owner(fd: int) -> None:
        text = f"{MARKER}\nprocess {os.getpid()} on {socket.gethostname()}\n".encode()
        os.ftruncate(fd, 0)
        os.pwrite(fd, text, 0)

    def release(self) -> None:
        """Remove the lock file and drop the lock (a no-op when not held)."""
        if self._fd is None:
            return
        fd, self._fd = self._fd, None
        try:
            if self._still_at_path(fd):
                with contextlib.suppress(OSError):
                    self.path.unlink()  # while still locked: a rival then sees another inode
        finally:
            os.close(fd)

    @property
    def held(self) -> bool:
        """Whether this object holds the lock."""
        return self._fd is not None
