"""phdesign: boundary observers for 1D boundary-controlled port-Hamiltonian systems.

The public entry points of the symbolic layer are re-exported here; the numeric
backend lives in :mod:`phdesign.numeric` and is imported only when used.
"""

from phdesign.errors import PhdesignError
from phdesign.io import model_from_toml, model_to_toml, read_model, write_model
from phdesign.models import builtin_names, load_builtin
from phdesign.symbolic.model import BCPHS, Displacement
from phdesign.symbolic.ports import Ports, derive_ports

__all__ = [
    "BCPHS",
    "Displacement",
    "PhdesignError",
    "Ports",
    "builtin_names",
    "derive_ports",
    "load_builtin",
    "model_from_toml",
    "model_to_toml",
    "read_model",
    "write_model",
]
__version__ = "0.1.0"


def __getattr__(name: str) -> object:
    # PEP 562: ``phdesign.sweep(...)`` imports the sweep package (dask, xarray and zarr only
    # when a sweep runs) on first use, so that ``import phdesign`` stays light
    if name == "sweep":
        import importlib

        return importlib.import_module("phdesign.sweep")
    raise AttributeError(f"module 'phdesign' has no attribute {name!r}")
