"""Hostile input, round three (issue 30, part B): sweep stores, crafted files, resources.

Each test names the defect it pins and fails on the code before the fix; the refusals of
single command lines are rows of ``tests/test_bad_input_table.py``, these are what needs
more than one command (a user's file beside or behind a store, two sweeps at once, a
store written by someone else).  Every sweep here is synchronous and tiny: the wave with
the damper on sensor 2, whose points cost a few milliseconds.
"""

from __future__ import annotations

import hashlib
import os
import stat
from pathlib import Path

import pytest

pytest.importorskip("xarray", reason="install the sweep extra")
pytest.importorskip("zarr", reason="install the sweep extra")

import phdesign
from phdesign.cli import main
from phdesign.errors import ModelError, OutputFileError, SweepError
from phdesign.sweep.lock import MARKER, StoreLock, lock_path

SYNC = {"scheduler": "synchronous", "progress": False}
WAVE = {"sensors": [2], "grid": {"l1": "0.2:0.8:3"}, **SYNC}


def digest(path: Path) -> dict[str, str]:
    """Every file below ``path`` (or ``path`` itself) by name: SHA-256 of its bytes."""
    files = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.is_file())
    return {
        str(p.relative_to(path.parent)): hashlib.sha256(p.read_bytes()).hexdigest() for p in files
    }


def user_store(folder: Path) -> Path:
    """A complete sweep store of the user's, with a note of theirs inside."""
    store = folder / "mine.zarr"
    phdesign.sweep("wave", output=store, **WAVE)
    (store / "notes.txt").write_text("the user's notes, kept inside their store\n")
    return store


# ------------------------------------------------------------------ non-regular targets
def test_force_never_replaces_a_fifo_or_a_link_to_a_users_store(tmp_path):
    """`sweep -o TARGET --force` replaced a FIFO, and followed a link into a user's store."""
    pipe = tmp_path / "pipe.zarr"
    os.mkfifo(pipe)
    with pytest.raises(OutputFileError, match="is a FIFO; a sweep writes its store only"):
        phdesign.sweep("wave", output=pipe, force=True, **WAVE)
    assert stat.S_ISFIFO(os.lstat(pipe).st_mode)

    store = user_store(tmp_path)
    before = digest(store)
    link = tmp_path / "link.zarr"
    link.symlink_to(store)
    for flags in ({"force": True}, {"resume": True}, {}):
        with pytest.raises(OutputFileError, match="is a symbolic link"):
            phdesign.sweep("wave", output=link, **flags, **WAVE)
    assert link.is_symlink()
    assert digest(store) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.zarr", "mine.zarr", "pipe.zarr"]


# ------------------------------------------------------------------ one writer per store
def test_a_sweep_on_a_locked_store_is_refused_and_changes_nothing(tmp_path):
    """Two `--force` sweeps on one store: a traceback in one, an unreadable store after.

    The lock is held here as a running sweep holds it (an flock on another open file
    description conflicts in one process too); the second sweep must leave the store as
    it was, byte for byte, whether it would replace, resume or reopen it.
    """
    store = user_store(tmp_path)
    before = digest(store)
    with StoreLock(store):
        for flags in ({"force": True}, {"resume": True}):
            with pytest.raises(
                SweepError, match=r"another sweep \(process \d+ on .*\) is writing"
            ):
                phdesign.sweep("wave", output=store, **flags, **WAVE)
        assert digest(store) == before
    assert not lock_path(store).exists()  # released and removed
    again = phdesign.sweep("wave", output=store, force=True, **WAVE)  # the lock is free again
    assert again.sizes["l1"] == 3


def test_the_cli_refuses_a_second_sweep_with_one_line(tmp_path, capsys):
    store = user_store(tmp_path)
    before = digest(store)
    argv = ["sweep", "wave", "--sensors", "2", "--grid", "l1=0.2:0.8:3"]
    argv += ["--scheduler", "synchronous", "-o", str(store), "--force"]
    with StoreLock(store):
        assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "is writing" in err
    assert "Traceback" not in err
    assert digest(store) == before


def test_a_lock_left_by_a_dead_sweep_is_taken_over(tmp_path):
    """SIGKILL leaves the lock file, never the lock: the next sweep proceeds and removes it."""
    store = tmp_path / "m.zarr"
    lock_path(store).write_text(f"{MARKER}\nprocess 999999 on a-dead-host\n")
    phdesign.sweep("wave", output=store, **WAVE)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.zarr"]


def test_a_users_file_at_the_lock_path_is_never_touched(tmp_path):
    store = tmp_path / "m.zarr"
    theirs = lock_path(store)
    theirs.write_bytes(b"not a lock: the user's own file\n")
    with pytest.raises(OutputFileError, match="exists and it was not written by phdesign"):
        phdesign.sweep("wave", output=store, **WAVE)
    assert theirs.read_bytes() == b"not a lock: the user's own file\n"
    assert not store.exists()
    theirs.unlink()
    theirs.symlink_to(tmp_path / "elsewhere")
    with pytest.raises(OutputFileError, match="move it away"):
        phdesign.sweep("wave", output=store, **WAVE)
    assert theirs.is_symlink()
    assert not (tmp_path / "elsewhere").exists()


# ------------------------------------------------------------------ refused points
PRODUCT = """
name = "string whose stiffness 1 - p q vanishes at p = 1, q = 2"
interval = [0, 1]
order = 1
[parameters]
p = 0.0
q = 0.0
[matrices]
P1 = [[0, 1], [1, 0]]
H = [["1 - p*q", 0], [0, 1]]
[ports]
inputs = ["e1(0)", "e2(1)"]
outputs = ["-e2(0)", "e1(1)"]
"""


def test_a_sweep_refused_at_a_point_removes_only_what_it_created(tmp_path):
    """A point refused in a chunk left `x.zarr/.phdesign/...` behind.

    Every value of each axis is accepted with the other parameter at its default (0), so
    the description cannot see it; the point p = 1, q = 2 (H = diag(-1, 1)) is refused in
    its chunk.  The store the sweep created goes; the user's files beside it stay.
    """
    from phdesign.io import model_from_toml

    model = model_from_toml(PRODUCT)
    grids = {"param_grid": {"p": "0,1", "q": "0,2"}, "chunk_size": 1, **SYNC}
    mine = tmp_path / "mine.txt"
    mine.write_text("the user's file beside the store\n")
    for name in ("new.zarr", "file.zarr"):
        store = tmp_path / name
        if name == "file.zarr":  # replaced with --force: what existed before was asked for
            store.write_text("an old file the user let --force replace\n")
        with pytest.raises(ModelError, match=r"sweep point p=1.0, q=2.0: H must be positive"):
            phdesign.sweep(model, output=store, force=name == "file.zarr", **grids)
        assert not store.exists()
        assert not lock_path(store).exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.txt"]
    assert mine.read_text() == "the user's file beside the store\n"


def test_a_resumed_store_is_kept_when_a_point_is_refused(tmp_path, monkeypatch):
    """A store the user had (a resumed one) is never removed: only its new chunks differ."""
    store = tmp_path / "m.zarr"
    kwargs = {**WAVE, "chunk_size": 1}
    phdesign.sweep("wave", output=store, **kwargs)
    (store / ".phdesign" / "complete.json").unlink()
    (store / ".phdesign" / "chunks" / "00000002").unlink()
    kept = digest(store)
    from phdesign.sweep import execute

    def refuse(*args):
        raise ModelError("refused here, as a point the library refuses")

    monkeypatch.setattr(execute, "run_chunk", refuse)
    with pytest.raises(ModelError, match="refused here"):
        phdesign.sweep("wave", output=store, resume=True, **kwargs)
    assert digest(store) == kept
