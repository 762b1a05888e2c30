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
