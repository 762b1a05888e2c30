"""Each design notebook is executed once, for the tests and the site alike (jupyter-cache).

The notebooks (``notebooks/NN_*.py``, jupytext percent scripts) are executed by the test
suite (``tests/test_notebooks.py``, which checks them) and shown executed, with their
figures, on the documentation site (myst-nb).  Executing them twice would double the
slowest part of CI, so both go through one jupyter-cache, the one myst-nb reads in its
``"cache"`` execution mode (``nb_execution_cache_path``, :data:`CACHE`): an executed
notebook is stored under the hash of its code cells and kernel, and is looked up by that
hash.  The tests store what they execute; the documentation build executes (and stores)
only what is missing or changed since, then myst-nb merges the stored outputs into the
pages.  A notebook whose code changed hashes differently, so it is never shown with stale
outputs.

The kernel is always the running interpreter on this checkout (:func:`running_kernel`): a
kernel spec written to a temporary folder on ``JUPYTER_PATH``, so that neither side
depends on which ``python3`` kernel happens to be installed.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
DOCS = HERE.parent
ROOT = DOCS.parent
NOTEBOOKS = ROOT / "notebooks"
#: The cache myst-nb reads (conf.py's ``nb_execution_cache_path``); under the build
#: folder, so that removing ``docs/_build`` clears it.
CACHE = DOCS / "_build" / ".jupyter_cache"
#: The kernel spec of the running interpreter.
KERNEL = "phdesign-notebooks"
#: Seconds a single cell may take: more is a hang, not slowness (the slowest cell,
#: notebook 02's six simulations, took 28 s on two loaded cores).
CELL_TIMEOUT = 240


def notebook_paths(folder: Path = NOTEBOOKS) -> list[Path]:
    """Return the design notebooks, in order: every ``NN_*.py`` of ``folder``."""
    return sorted(folder.glob("[0-9][0-9]_*.py"))


def read(path: Path) -> Any:
    """Return the notebook of a jupytext script, not executed, its kernel the running one."""
    import jupytext

    notebook = jupytext.read(path)
    notebook.metadata["kernelspec"] = {
        "name": KERNEL,
        "display_name": "Python 3 (phdesign)",
        "language": "python",
    }
    return notebook


@contextlib.contextmanager
def running_kernel() -> Iterator[str]:
    """Make :data:`KERNEL` the running interpreter's kernel, inside the block."""
    with tempfile.TemporaryDirectory(prefix="phdesign-kernel-") as root:
        spec = Path(root) / "kernels" / KERNEL
        spec.mkdir(parents=True)
        argv = [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"]
        # the kernel imports this checkout's phdesign, as conf.py documents this checkout
        path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
        spec.joinpath("kernel.json").write_text(
            json.dumps(
                {"argv": argv, "display_name": "phdesign", "language": "python",
                 "env": {"PYTHONPATH": path}}
            )
        )  # fmt: skip
        before = os.environ.get("JUPYTER_PATH")
        os.environ["JUPYTER_PATH"] = os.pathsep.join(filter(None, [root, before]))
        try:
            yield KERNEL
        finally:
            if before is None:
                os.environ.pop("JUPYTER_PATH", None)
            else:
                os.environ["JUPYTER_PATH"] = before


@contextlib.contextmanager
def _cache(cache: Path) -> Iterator[Any]:
    """Open the cache, one process at a time (the tests run on several workers)."""
    from jupyter_cache import get_cache

    cache.mkdir(parents=True, exist_ok=True)
    with open(cache.parent / ".jupyter_cache.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield get_cache(str(cache))
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def cached(path: Path, cache: Path = CACHE) -> Any | None:
    """Return the stored execution of the notebook as it is now, or None."""
    with _cache(cache) as store:
        try:
            _, notebook = store.merge_match_into_notebook(read(path))
        except KeyError:
            return None
    return notebook


def execute(path: Path, cache: Path = CACHE, timeout: int = CELL_TIMEOUT) -> tuple[Any, float]:
    """Execute the notebook in the running interpreter, store it, and return it with seconds.

    The kernel runs in the notebook's folder.  Any error in any cell raises nbclient's
    ``CellExecutionError`` (naming the cell), and nothing is stored.
    """
    import nbclient
    from jupyter_cache.base import CacheBundleIn

    notebook = read(path)
    with running_kernel() as kernel:
        client = nbclient.NotebookClient(
            notebook,
            kernel_name=kernel,
            timeout=timeout,
            record_timing=False,  # timings in the cells' metadata would change their hash
            resources={"metadata": {"path": str(path.parent)}},
        )
        start = time.perf_counter()
        client.execute()
        seconds = time.perf_counter() - start
    with _cache(cache) as store:
        bundle = CacheBundleIn(notebook, str(path), data={"execution_seconds": seconds})
        store.cache_notebook_bundle(bundle, check_validity=False, overwrite=True)
    return notebook, seconds
