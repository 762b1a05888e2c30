"""The fields of a stored sweep description, checked before a description is built from them.

A store or NetCDF file may come from anyone, and the description it carries (JSON) is
read back by :meth:`phdesign.sweep.description.SweepDescription.from_dict`: every field is
checked here first, by kind and range, against the job registry and the sweep budgets,
so that a file cannot describe a job, an option or a grid that phdesign would refuse
(:mod:`phdesign.sweep.schema` then checks the arrays against the description).

Examples
--------
>>> description_fields({"model": "wave"})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
phdesign.core.errors.SweepError: a stored description must have the fields axes, gain, ...
"""

from __future__ import annotations

import math
from typing import Any

from phdesign.core.errors import SweepError
from phdesign.core.limits import (
    MAX_MODEL_FILE_BYTES,
    MAX_PARAMETERS,
    MAX_PORTS,
    check_sweep_points,
)
from phdesign.sweep.grids import Axis
from phdesign.sweep.jobs import get_job

__all__ = ["description_fields"]

_FIELDS = {
    "model",
    "model_toml",
    "n_outputs",
    "parameter_names",
    "job",
    "options",
    "axes",
    "sensors",
    "gain",
    "version",
}
_MAX_TEXT = MAX_MODEL_FILE_BYTES  # the model's TOML is the longest text of a description


def _stored(data: dict[str, Any], key: str, kind: type) -> Any:
    """Return ``data[key]``, refused unless of ``kind`` (a bool is no int; text is bounded)."""
    value: Any = data[key]
    if type(value) is not kind and not (kind is float and type(value) is int):
        raise SweepError(f"the stored {key} must be {kind.__name__}; found {type(value).__name__}")
    if isinstance(value, str) and len(value) > _MAX_TEXT:
        raise SweepError(f"the stored {key} is longer than {_MAX_TEXT:,} characters")
    return value


def _stored_list(data: dict[str, Any], key: str, kind: type) -> list[Any] | None:
    """Return ``data[key]``: ``None`` or a list of at most ``MAX_PARAMETERS`` ``kind`` items."""
    value = data[key]
    if value is None and key != "parameter_names":
        return None
    items = _stored(data, key, list)
    if len(items) > MAX_PARAMETERS or not all(
        type(x) is kind or (kind is float and type(x) is int) for x in items
    ):
        raise SweepError(f"the stored {key} must be a short list of {kind.__name__}")
    return list(items)


def description_fields(data: Any) -> dict[str, Any]:
    """Check a stored description's fields; return them as :class:`SweepDescription` takes them.

    Raises
    ------
    SweepError
        A field missing, unknown, of the wrong kind or out of range (named), a job or an
        option the registry does not know, or more points than a sweep may have.
    """
    if not isinstance(data, dict) or set(data) != _FIELDS:
        found = sorted(map(str, data)) if isinstance(data, dict) else type(data).__name__
        raise SweepError(
            f"a stored description must have the fields {', '.join(sorted(_FIELDS))}; "
            f"found {found}"
        )
    text = {key: _stored(data, key, str) for key in ("model_toml", "model", "job", "version")}
    job = get_job(text["job"])
    n_outputs = _stored(data, "n_outputs", int)
    if not 1 <= n_outputs <= MAX_PORTS:
        raise SweepError(f"the stored n_outputs must be 1..{MAX_PORTS}; found {n_outputs}")
    options = _stored(data, "options", dict)
    checked = job.option_values(options)
    if checked != options:
        raise SweepError(f"the stored options of job {job.name} are not its options")
    axes = tuple(Axis.from_dict(a) for a in _stored(data, "axes", list))
    if not axes or len({a.name for a in axes}) != len(axes):
        raise SweepError("a stored description needs axes of distinct names")
    check_sweep_points(math.prod(a.size for a in axes), "the stored sweep")
    sensors = _stored_list(data, "sensors", int)
    if sensors is not None and not all(1 <= i <= n_outputs for i in sensors):
        raise SweepError(f"the stored sensors must be output indices 1..{n_outputs}")
    gain = _stored_list(data, "gain", float)
    if gain is not None and not all(math.isfinite(g) and g > 0 for g in gain):
        raise SweepError("the stored gain must be finite positive numbers")
    return {
        "model_toml": text["model_toml"],
        "model_name": text["model"],
        "n_outputs": n_outputs,
        "parameter_names": tuple(_stored_list(data, "parameter_names", str) or ()),
        "job": job.name,
        "options": tuple(sorted(checked.items())),
        "axes": axes,
        "sensors": None if sensors is None else tuple(sensors),
        "gain": None if gain is None else tuple(float(g) for g in gain),
        "version": text["version"],
    }
