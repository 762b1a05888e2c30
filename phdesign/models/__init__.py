"""The built-in models, shared by tests, notebooks and the command line.

``wave``, ``timoshenko``, ``euler-bernoulli`` and ``airy`` (described in the documentation's
model gallery); ``wave-damper`` (the string with a damper at z = 1) and
``beam-tip-damper`` (the clamped beam with a damper at its tip) close one input with a
boundary feedback (``[feedback]``); ``string-tip-mass``, ``beam-tip-body``, ``flexible-arm``
and ``string-motor`` join boundary systems (a tip mass, a tip body, a hub, a DC motor:
``[[boundary_systems]]``).  Each is stored as a TOML model file in this package;
:func:`load` reads a built-in model by name or a model file by path.

Examples
--------
>>> builtin_names()  # doctest: +NORMALIZE_WHITESPACE
('airy', 'beam-tip-body', 'beam-tip-damper', 'euler-bernoulli', 'flexible-arm',
 'string-motor', 'string-tip-mass', 'timoshenko', 'wave', 'wave-damper')
>>> load_builtin("euler-bernoulli").order
2
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from functools import cache
from importlib import resources
from pathlib import Path

from phdesign.core.errors import ArgumentError, ModelFileError, ParameterError
from phdesign.core.text import did_you_mean
from phdesign.symbolic.model import BCPHS

__all__ = ["builtin_names", "builtin_toml", "load", "load_builtin"]


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
            f"unknown model {name!r}{did_you_mean(name, builtin_names())}; expected a built-in "
            f"model ({', '.join(builtin_names())}) or the path of a TOML file"
        )
    return resources.files(__package__).joinpath(f"{name}.toml").read_text(encoding="utf-8")


def load_builtin(name: str) -> BCPHS:
    """Return built-in model ``name`` (validated; cached)."""
    return _load_builtin(builtin_toml(name) and name)  # a bad name is refused first


@cache
def _load_builtin(name: str) -> BCPHS:
    from phdesign.io import model_from_toml

    return model_from_toml(builtin_toml(name), source=f"built-in model {name!r}")


def load(source: str | os.PathLike[str], parameters: Mapping[str, object] | None = None) -> BCPHS:
    """Return a model: a built-in one by name, or the model file at a path.

    Parameters
    ----------
    source : str or path
        A built-in name (:func:`builtin_names`) or the path of a TOML model file.
    parameters : mapping of str to number, optional
        New defaults for some parameters (``{"d": 0.5}``).

    Raises
    ------
    ModelFileError
        Neither a built-in name nor a readable model file.

    Examples
    --------
    >>> load("wave", parameters={"rho": 2}).parameter_defaults
    {rho: 2, T: 1}
    """
    from phdesign.io import read_model

    if not isinstance(source, str | os.PathLike):
        raise ArgumentError(
            f"source: expected a built-in model name or the path of a TOML file; found "
            f"{type(source).__name__}"
        )
    if parameters is not None and not isinstance(parameters, Mapping):
        raise ParameterError(
            f"parameters must be a mapping of names to values; found {type(parameters).__name__}"
        )
    name = os.fspath(source)
    if isinstance(source, str) and name in builtin_names():
        model = load_builtin(name)
    elif Path(name).suffix == ".toml" or Path(name).exists():
        model = read_model(name)
    else:
        model = load_builtin(name)  # raises the error listing the built-in names
    return model.with_parameters(parameters) if parameters else model
