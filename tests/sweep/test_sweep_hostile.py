"""Hostile input, round three (issue 30, part B): sweep stores, crafted files, resources.

Each test names the defect it pins and fails on the code before the fix; the refusals of
single command lines are rows of ``tests/test_bad_input_table.py``, these are what needs
more than one command (a user's file beside or behind a store, two sweeps at once, a
store written by someone else).  Every sweep here is synchronous and tiny: the wave with
the damper on sensor 2, whose points cost a few milliseconds.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import stat
from pathlib import Path

import pytest

pytest.importorskip("xarray", reason="install the sweep extra")
pytest.importorskip("zarr", reason="install the sweep extra")

import phdesign
from phdesign.cli import main
from phdesign.core.errors import ModelError, OutputFileError, SweepError
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


# ------------------------------------------------------------------ crafted stores
def _json(path: Path, change) -> None:
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))


def _metadata(change):
    """A change of the consolidated metadata (and of the array's own file, kept equal)."""

    def apply(store: Path) -> None:
        _json(store / ".zmetadata", lambda d: change(d["metadata"]))
        metadata = json.loads((store / ".zmetadata").read_text())["metadata"]
        for key, value in metadata.items():
            if key.endswith("/.zarray") and (store / key).parent.is_dir():
                (store / key).write_text(json.dumps(value))

    return apply


def _description(change):
    """A change of the stored description (in sweep.json and the group's attribute)."""

    def apply(store: Path) -> None:
        def edit(record):
            description = json.loads(record["description"])
            change(description)
            record["description"] = json.dumps(description)

        _json(store / ".phdesign" / "sweep.json", edit)

    return apply


def _pickled(metadata):
    array = metadata["spectral_abscissa/.zarray"]
    array.update(dtype="|O", filters=[{"id": "pickle", "protocol": 5}], fill_value=None)


def _dev_zero(store: Path) -> None:
    chunk = store / "digits" / "0"
    chunk.unlink()
    chunk.symlink_to("/dev/zero")


def _blosc_bomb(store: Path) -> None:
    import struct

    chunk = store / "digits" / "0"
    data = bytearray(chunk.read_bytes())
    data[4:8] = struct.pack("<I", 2**31 - 1)  # "decompresses to 2 GiB"
    chunk.write_bytes(bytes(data))


CRAFTED = [
    # (change, the message; each ended in a traceback or a large allocation before)
    (lambda s: (s / ".zmetadata").write_text("{"), "is not JSON"),
    (lambda s: (s / ".phdesign" / "sweep.json").write_text("[1"), "sweep.json is not JSON"),
    (
        lambda s: _json(s / ".phdesign" / "sweep.json", lambda d: d.update(chunk_shape="ab")),
        "the chunk shape must be a list of integers",
    ),
    (_description(lambda d: d.pop("job")), "a stored description must have the fields"),
    (_description(lambda d: d.update(n_outputs="2")), "n_outputs must be int; found str"),
    (
        _description(lambda d: d["axes"][0].update(values=["²", "x", "y"])),
        "expected numbers as values",
    ),
    (_description(lambda d: d.update(job="nosuch")), "unknown sweep job 'nosuch'"),
    (
        _description(lambda d: d["axes"][0].update(values=list(range(2_000_000)))),
        "stored axis 'l1' has 2,000,000 points; a sweep has at most 1,000,000",
    ),
    (_metadata(lambda m: m.pop("digits/.zarray")), "does not hold the arrays its description"),
    (_metadata(lambda m: m.update({"extra/.zarray": {}})), "does not hold the arrays"),
    (_metadata(_pickled), 'dtype must be "<f8"'),
    (
        _metadata(lambda m: m["digits/.zarray"].update(shape=[3_000_000_000])),
        r"shape must be \[3\] \(the grid the store describes\); found \[3000000000\]",
    ),
    (
        _metadata(lambda m: m["digits/.zarray"].update(compressor={"id": "pickle"})),
        "the compressor must be none or Blosc",
    ),
    (
        _metadata(lambda m: m["spectral_abscissa/.zattrs"].update(units="days since 1970-01-01")),
        "attribute units must be '1/s'",
    ),
    (_metadata(lambda m: m[".zattrs"].update(phdesign_sweep="{}")), "its attributes are not"),
    (_dev_zero, "chunk digits/0 is not a regular file"),
    (_blosc_bomb, r"chunk digits/0 declares 2147483647 bytes .*; expected 24"),
]


@pytest.mark.parametrize(("change", "message"), CRAFTED, ids=[str(i) for i in range(len(CRAFTED))])
def test_a_crafted_store_is_refused_by_plot_and_resume_in_one_line(
    change, message, tmp_path, capsys
):
    """plot and --resume read crafted stores: KeyError, JSONDecodeError, int('²'),
    TypeError, zarr's "No Zarr data type found", or 2 GiB for a 172 kB store."""
    store = tmp_path / "m.zarr"
    phdesign.sweep("wave", output=store, **WAVE)
    change(store)
    crafted = digest(store) if not (store / "digits" / "0").is_symlink() else None
    status = main(["plot", str(store), "-o", str(tmp_path / "p.png")])
    err = capsys.readouterr().err
    assert status == 2, err
    assert err.count("\n") == 1, err
    assert "Traceback" not in err
    assert re.search(message, err), err
    assert not (tmp_path / "p.png").exists()
    (store / ".phdesign" / "complete.json").unlink(missing_ok=True)  # resume, not reopen
    with pytest.raises(SweepError, match=message):
        phdesign.sweep("wave", output=store, resume=True, **WAVE)
    if crafted is not None:
        crafted.pop("m.zarr/.phdesign/complete.json", None)
        assert digest(store) == crafted  # refused before anything was written


def test_a_marker_name_that_python_calls_a_digit_is_not_a_chunk(tmp_path, capsys):
    """'0000000²'.isdigit() is true and int() of it raised: such a name is no marker."""
    store = tmp_path / "m.zarr"
    phdesign.sweep("wave", output=store, chunk_size=1, **WAVE)
    (store / ".phdesign" / "complete.json").unlink()
    (store / ".phdesign" / "chunks" / "00000001").unlink()
    (store / ".phdesign" / "chunks" / "0000000²").write_text("")
    (store / ".phdesign" / "chunks" / "99999999").write_text("")  # beyond the last chunk
    assert main(["plot", str(store), "-o", str(tmp_path / "p.png")]) == 2
    assert "is incomplete (2 of 3 chunks stored)" in capsys.readouterr().err
    resumed = phdesign.sweep("wave", output=store, resume=True, chunk_size=1, **WAVE)
    assert json.loads(resumed.attrs["phdesign_run"])["computed"] == 1


def _netcdf(tmp_path: Path, change) -> Path:
    path = tmp_path / "m.nc"
    phdesign.sweep("wave", output=path, **WAVE)
    import xarray as xr

    with xr.open_dataset(path, engine="scipy") as ds:
        crafted = change(ds.load())
    path.unlink()
    crafted.to_netcdf(path, engine="scipy")
    return path


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda ds: ds.assign(extra=ds.digits * 2), "does not hold the variables"),
        (
            lambda ds: ds.isel(l1=[0, 1, 2, 0, 1]).assign_coords(l1=[1.0, 2, 3, 4, 5]),
            r"variable .*expected dimensions \('l1',\) of shape \(3,\); found .* \(5,\)",
        ),
        (
            lambda ds: ds.assign(digits=ds.digits.assign_attrs(units="days since 1970-01-01")),
            "variable digits: expected float64; found datetime64",
        ),
    ],
)
def test_a_crafted_netcdf_file_is_refused_before_it_is_read(change, message, tmp_path):
    path = _netcdf(tmp_path, change)
    with pytest.raises(SweepError, match=message):
        phdesign.sweep.open_sweep(path)


def test_truncated_and_non_regular_netcdf_files_are_refused(tmp_path):
    path = tmp_path / "m.nc"
    phdesign.sweep("wave", output=path, **WAVE)
    path.write_bytes(path.read_bytes()[:200])
    with pytest.raises(SweepError, match=r"cannot read .* as NetCDF"):
        phdesign.sweep.open_sweep(path)
    path.unlink()
    os.mkfifo(path)
    with pytest.raises(SweepError, match="it is not a regular file"):
        phdesign.sweep.open_sweep(path)


def test_a_local_cluster_spawns_its_workers_with_sigint_ignored(monkeypatch):
    """The workers inherit an ignored SIGINT (the cluster test sends a real Ctrl-C); this
    process gets its own handler back as soon as the cluster is up."""
    import signal

    import dask.distributed

    from phdesign.sweep import schedulers

    seen = []

    class Cluster:
        def __init__(self, **kwargs):
            seen.append(signal.getsignal(signal.SIGINT))

    handler = signal.getsignal(signal.SIGINT)
    monkeypatch.setattr(dask.distributed, "LocalCluster", Cluster)
    schedulers._local_cluster(2)
    assert seen == [signal.SIG_IGN]
    assert signal.getsignal(signal.SIGINT) is handler


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "x"])
def test_plot_select_refuses_a_value_with_no_nearest_point(value, tmp_path, capsys):
    """`plot --select d=nan` was a KeyError traceback (NaN has no nearest value)."""
    path = tmp_path / "m.nc"
    phdesign.sweep("wave", output=path, param_grid={"rho": "1,2"}, **WAVE)
    argv = ["plot", str(path), "-o", str(tmp_path / "p.png"), "--select", f"rho={value}"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == f"phdesign: error: --select: rho expects a finite number; found {value!r}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.nc"]
