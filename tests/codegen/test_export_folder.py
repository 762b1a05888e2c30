"""Issue 30: the C export's ``force`` replaces only a folder phdesign wrote.

Every test puts a user's file where phdesign must not touch it and checks that it is
still there, byte for byte, and that no staging folder (``.phd-*.tmp``) is left behind.
"""

from __future__ import annotations

import json
import os
import signal
import time
from pathlib import Path

import numpy as np
import pytest

import phdesign.codegen.folder as folder_module
from phdesign.cli import main
from phdesign.codegen import MARKER, write_directory
from phdesign.core.errors import OutputFileError
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.sampled.export import SampledObserver, export_observer

PRECIOUS = b"the user's own notes\n\x00\xff"


@pytest.fixture(scope="module")
def observer() -> SampledObserver:
    pytest.importorskip("jinja2", reason="the C export needs the codegen extra")
    nm = to_numeric(load_builtin("wave"))
    return export_observer(nm, np.array([[0.0, 1.0]]), np.array([[0.5]]), dt=1e-2, order=6)


def _tree(root: Path) -> dict[str, bytes | str]:
    """Every entry below ``root``: file contents, or the kind of anything else."""
    found: dict[str, bytes | str] = {}
    for path in sorted(root.rglob("*")):
        key = str(path.relative_to(root))
        if path.is_symlink():
            found[key] = "link to " + os.readlink(path)
        elif path.is_file():
            found[key] = path.read_bytes()
        else:
            found[key] = "folder"
    return found


def test_force_refuses_a_users_folder_and_keeps_every_file(observer, tmp_path):
    user = tmp_path / "mine"
    (user / "sub").mkdir(parents=True)
    (user / "precious.txt").write_bytes(PRECIOUS)
    (user / "sub" / "deep.txt").write_bytes(PRECIOUS)
    before = _tree(tmp_path)
    with pytest.raises(OutputFileError, match=r"holds no marker \.phdesign-export"):
        observer.write(str(user), "c", force=True)
    assert _tree(tmp_path) == before


def test_force_refuses_an_export_that_received_a_users_file(observer, tmp_path):
    target = tmp_path / "obs"
    observer.write(str(target), "c")
    (target / "precious.txt").write_bytes(PRECIOUS)
    before = _tree(tmp_path)
    with pytest.raises(OutputFileError, match=r"holds files phdesign did not write \('precious"):
        observer.write(str(target), "c", force=True)
    assert _tree(tmp_path) == before


def test_force_replaces_phdesigns_own_export_and_leaves_nothing_else(observer, tmp_path):
    target = tmp_path / "obs"
    (tmp_path / "precious.txt").write_bytes(PRECIOUS)
    written = observer.write(str(target), "c")
    assert written == [str(target / "observer.h"), str(target / "observer.c")]
    marker = json.loads((target / MARKER).read_text())
    assert marker["files"] == ["observer.h", "observer.c"]
    (target / "observer.c").write_text("edited by hand")  # still phdesign's file by name
    observer.write(str(target), "c", force=True)
    assert sorted(p.name for p in target.iterdir()) == [MARKER, "observer.c", "observer.h"]
    assert "phd_observer_step" in (target / "observer.c").read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["obs", "precious.txt"]
    assert (tmp_path / "precious.txt").read_bytes() == PRECIOUS


@pytest.mark.parametrize("spelling", ["absolute", "relative", "dot"])
def test_the_working_directory_is_never_replaced(observer, tmp_path, monkeypatch, spelling):
    # even when it is an export phdesign wrote (a user who ran cd into it)
    target = tmp_path / "obs"
    observer.write(str(target), "c")
    monkeypatch.chdir(target)
    before = _tree(tmp_path)
    path = {"absolute": str(target), "relative": "../obs", "dot": "."}[spelling]
    message = "names no folder" if spelling == "dot" else "is the working directory"
    with pytest.raises(OutputFileError, match=message):
        observer.write(path, "c", force=True)
    assert _tree(tmp_path) == before


def test_the_command_line_refuses_the_working_directory(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "precious.txt").write_bytes(PRECIOUS)
    argv = ["export", "wave", "--sensors", "2", "--gain", "1", "--dt", "1e-2", "--format", "c"]
    for target in (".", str(tmp_path), "./"):
        assert main([*argv, "-o", target, "--force"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1
        assert "Traceback" not in err
    assert _tree(tmp_path) == {"precious.txt": PRECIOUS}


@pytest.mark.parametrize("kind", ["link to an export", "dangling link", "fifo"])
def test_force_refuses_a_target_that_is_not_a_folder(observer, tmp_path, kind):
    real = tmp_path / "real"
    observer.write(str(real), "c")
    target = tmp_path / "target"
    if kind == "fifo":
        os.mkfifo(target)
    else:
        target.symlink_to(real if kind == "link to an export" else tmp_path / "none")
    before = _tree(tmp_path)
    with pytest.raises(OutputFileError, match=r"is a (symbolic link|FIFO); format 'c' writes a"):
        observer.write(str(target), "c", force=True)
    assert _tree(tmp_path) == before


def test_a_forged_marker_cannot_list_a_users_file(observer, tmp_path):
    target = tmp_path / "obs"
    target.mkdir()
    (target / "precious.txt").write_bytes(PRECIOUS)
    for files in (["../precious.txt"], [MARKER], "precious.txt", [1]):
        (target / MARKER).write_text(json.dumps({"files": files}))
        with pytest.raises(OutputFileError, match="holds no marker"):
            observer.write(str(target), "c", force=True)
    assert (target / "precious.txt").read_bytes() == PRECIOUS


def _interrupt_at(monkeypatch, name: str, calls: int = 1) -> None:
    """Raise KeyboardInterrupt at the ``calls``-th call of the folder module's ``name``."""
    original = getattr(folder_module, name)
    seen = []

    def interrupted(*args, **kwargs):
        seen.append(args)
        if len(seen) == calls:
            raise KeyboardInterrupt
        return original(*args, **kwargs)

    monkeypatch.setattr(folder_module, name, interrupted)


@pytest.mark.parametrize(
    ("point", "calls"),
    [("_write_file", 1), ("_write_file", 2), ("_write_file", 3), ("_put_in_place", 1)],
)
@pytest.mark.parametrize("replace", [False, True], ids=["new", "replace"])
def test_an_interrupt_while_staging_leaves_no_staging_folder(
    observer, tmp_path, monkeypatch, point, calls, replace
):
    target = tmp_path / "obs"
    (tmp_path / "precious.txt").write_bytes(PRECIOUS)
    if replace:
        observer.write(str(target), "c")
    before = _tree(tmp_path)
    _interrupt_at(monkeypatch, point, calls)
    with pytest.raises(KeyboardInterrupt):
        observer.write(str(target), "c", force=replace)
    assert _tree(tmp_path) == before  # the old export (if any) untouched, no .phd-*.tmp


def test_an_interrupt_between_the_renames_puts_the_old_export_back(tmp_path, monkeypatch):
    target = tmp_path / "obs"
    write_directory(target, {"a.h": "old"})
    before = _tree(tmp_path)
    original = Path.rename
    renames = []

    def rename(self, other):
        renames.append(self.name)
        if len(renames) == 2:  # obs -> aside, then staging -> obs: interrupted
            raise KeyboardInterrupt
        return original(self, other)

    monkeypatch.setattr(Path, "rename", rename)
    with pytest.raises(KeyboardInterrupt):
        write_directory(target, {"a.h": "new"}, force=True)
    assert _tree(tmp_path) == before
    assert len(renames) == 3  # the third put the old export back


def test_a_file_added_during_the_export_stops_the_replacement(tmp_path, monkeypatch):
    target = tmp_path / "obs"
    write_directory(target, {"a.h": "old"})
    original = folder_module._write_file

    def and_meanwhile(path, data):
        original(path, data)
        if path.name == MARKER:  # the user saves a file into the old export now
            (target / "precious.txt").write_bytes(PRECIOUS)

    monkeypatch.setattr(folder_module, "_write_file", and_meanwhile)
    with pytest.raises(OutputFileError, match=r"changed meanwhile .*precious\.txt"):
        write_directory(target, {"a.h": "new"}, force=True)
    assert _tree(tmp_path) == {
        "obs": "folder",
        f"obs/{MARKER}": (target / MARKER).read_bytes(),
        "obs/a.h": b"old",
        "obs/precious.txt": PRECIOUS,
    }


def test_sigint_while_staging_leaves_no_staging_folder(observer, tmp_path):
    """A real SIGINT in a forked child (issue 30: ``.cx.*.tmp/observer.{c,h}`` was left)."""
    target = tmp_path / "cx"
    observer.write(str(target), "c")
    (tmp_path / "precious.txt").write_bytes(PRECIOUS)
    before = _tree(tmp_path)
    pid = os.fork()
    if pid == 0:  # the child: never returns into pytest
        try:
            # a runner that ignores SIGINT (nohup, a background job) passes that on:
            # restore Python's own handler so that the signal interrupts the write
            signal.signal(signal.SIGINT, signal.default_int_handler)
            original = folder_module._write_file

            def write_then_signal(path, data):
                original(path, data)
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(5)  # the handler raises here

            folder_module._write_file = write_then_signal
            try:
                observer.write(str(target), "c", force=True)
            except KeyboardInterrupt:
                os._exit(2)
            os._exit(0)
        except BaseException:
            os._exit(99)
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 2
    assert _tree(tmp_path) == before
