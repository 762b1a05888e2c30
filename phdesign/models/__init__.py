"""The built-in models, shared by tests, notebooks and the command line.

``wave``, ``timoshenko``, ``euler-bernoulli`` and ``airy`` are the paper's and the
design notes' models; ``wave-damper`` (the string with a damper at z = 1) and
``beam-tip-damper`` (the clamped beam with a damper at its tip) close one input with a
boundary feedback (``[feedback]``).  Each is stored as a TOML model file in this package.

Examples
--------
>>> builtin_names()
('airy', 'beam-tip-damper', 'euler-bernoulli', 'timoshenko', 'wave', 'wave-damper')
>>> load_builtin("euler-bernoulli").order
2
"""

from __future__ import annotations

from functools import cache
from importlib import resources

from phdesign.errors import ModelFileError
from phdesign.symbolic.model import BCPHS

__all__ = ["builtin_names", "builtin_toml", "load_builtin"]


def builtin_names() -> tuple[str, ...]:
    """Return the names of the built-in models, sorted."""
    files = resources.files(__package__).iterdir()
    return tuple(sorted(f.name.removesuffix(".toml") for f in files if f.name.endswith(".toml")))


def builtin_toml(name: str) -> str:
    """Return the TOML text of built-in model ``name``.

    Raises
    ------
    ModelFileError
        If there is no such built-in model.
    """
    if not isinstance(name, str) or name not in builtin_names():
        raise ModelFileError(
            f"unknown model {name!r}; expected a built-in model ({', '.join(builtin_names())}) "
            "or the path of a TOML file"
        )
    return resources.files(__package__).joinpath(f"{name}.toml").read_text(encoding="utf-8")


def load_builtin(name: str) -> BCPHS:
    """Return built-in model ``name`` (validated; cached)."""
    return _load_builtin(builtin_toml(name) and name)  # a bad name is refused first


@cache
def _load_builtin(name: str) -> BCPHS:
    from phdesign.io import model_from_toml

    return model_from_toml(builtin_toml(name), source=f"built-in model {name!r}")
