r"""Axes of a sweep: the values one quantity takes, read from a grid or a list.

A grid is written ``start:stop:count`` (``count`` points evenly spaced, both ends
included) or ``start:stop:count:log`` (evenly spaced in :math:`\log`), a list as
``0.03,0.1,0.2``.  Three kinds of axis exist:

``gain``
    an entry of the diagonal gain :math:`L = \operatorname{diag}(l_1, \dots, l_q)`,
    named ``l1`` .. ``lq``, or ``l`` for :math:`L = l I` (every sensor the same gain);
    values must be positive (:math:`L + L^\top \succ 0`).
``parameter``
    a model parameter, named as in the model (``d``, ``rho``, ...).
``sensors``
    the sensor sets, written ``3,4;4;2`` (1-based output indices, sets separated by
    ``;``) or ``all`` (every non-empty subset of the outputs, by size, then in
    lexicographic order).

Numeric axes are strictly increasing, so that coordinates are unique and plots and
look-ups by value are well defined.

Examples
--------
>>> parse_axis("l1", "0.1:10:3:log", "gain").values
(0.1, 1.0, 10.0)
>>> parse_axis("d", "0,0.2,0.4", "parameter").values
(0.0, 0.2, 0.4)
>>> parse_sensor_sets("3,4;4", 4).values
('3,4', '4')
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from phdesign.core.errors import SweepError
from phdesign.core.limits import MAX_MAGNITUDE, check_sweep_points

__all__ = [
    "AXIS_KINDS",
    "Axis",
    "parse_axis",
    "parse_sensor_sets",
    "sensor_set_indices",
]

AXIS_KINDS = ("gain", "parameter", "sensors")
_GAIN_NAME = re.compile(r"^l([1-9][0-9]*)?$")
_SENSOR_SET = re.compile(r"[1-9][0-9]{0,2}(,[1-9][0-9]{0,2})*", re.ASCII)


@dataclass(frozen=True)
class Axis:
    """One axis of a sweep.

    Parameters
    ----------
    name : str
        ``l1``, ``l2``, ... or ``l`` (gain), a model parameter, or ``sensors``.
    kind : {"gain", "parameter", "sensors"}
    values : tuple of float, or tuple of str for sensor sets
        The coordinates, strictly increasing for numeric axes.
    scale : {"linear", "log", "sets"}
        How the values were spaced (plots use a logarithmic axis for ``log``).
    spec : str
        The axis as the user wrote it (for messages and the store's attributes).
    """

    name: str
    kind: str
    values: tuple[Any, ...]
    scale: str = "linear"
    spec: str = ""

    def __post_init__(self) -> None:
        if self.kind not in AXIS_KINDS:
            raise SweepError(
                f"axis {self.name}: kind must be one of {AXIS_KINDS}; found {self.kind!r}"
            )
        if not self.values:
            raise SweepError(f"axis {self.name}: expected at least one value; found none")
        if self.kind == "sensors":
            return
        values = tuple(float(v) for v in self.values)
        for v in values:
            if not math.isfinite(v):
                raise SweepError(f"axis {self.name}: values must be finite numbers; found {v}")
        for first, second in itertools.pairwise(values):
            if not first < second:
                raise SweepError(
                    f"axis {self.name}: values must be strictly increasing; "
                    f"found {first!r} followed by {second!r}"
                )
        if self.kind == "gain" and values[0] <= 0:
            raise SweepError(
                f"gain axis {self.name}: gains must be positive (L + Lᵀ ≻ 0); found {values[0]!r}"
            )
        if (
            self.kind == "gain"
            and not 1 / MAX_MAGNITUDE <= values[0] <= values[-1] <= MAX_MAGNITUDE
        ):
            bad = values[0] if values[0] < 1 / MAX_MAGNITUDE else values[-1]
            raise SweepError(
                f"gain axis {self.name}: gains must lie between {1 / MAX_MAGNITUDE:g} and "
                f"{MAX_MAGNITUDE:g}, as every gain; found {bad!r}"
            )
        if self.scale == "log" and values[0] <= 0:
            raise SweepError(
                f"axis {self.name}: a log grid needs positive values; found {values[0]!r}"
            )
        object.__setattr__(self, "values", values)

    @property
    def size(self) -> int:
        """Number of values."""
        return len(self.values)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (floats exactly, through their shortest repr)."""
        return {
            "name": self.name,
            "kind": self.kind,
            "values": list(self.values),
            "scale": self.scale,
            "spec": self.spec,
        }

    @classmethod
    def from_dict(cls, data: Any) -> Axis:
        """Inverse of :meth:`to_dict`, for data read from a file: every field is checked.

        Raises
        ------
        SweepError
            Not the five fields of an axis, of their kinds: a name, kind, scale and spec of
            text, and at most :data:`~phdesign.core.limits.MAX_SWEEP_POINTS` values (numbers,
            or sensor sets such as ``"3,4"``), valid as :class:`Axis` requires.
        """
        fields = ("name", "kind", "values", "scale", "spec")
        if not isinstance(data, dict) or set(data) != set(fields):
            found = sorted(map(str, data)) if isinstance(data, dict) else type(data).__name__
            raise SweepError(
                f"a stored axis must have the fields {', '.join(fields)}; found {found}"
            )
        name, kind, values, scale, spec = (data[f] for f in fields)
        if not all(isinstance(x, str) and len(x) <= 1000 for x in (name, kind, scale, spec)):
            raise SweepError("a stored axis must have a name, kind, scale and spec of short text")
        if scale not in ("linear", "log", "sets") or not isinstance(values, list):
            raise SweepError(
                f"stored axis {name!r}: unknown scale {scale!r}, or no list of values"
            )
        check_sweep_points(len(values), f"stored axis {name!r}")
        if kind == "gain" and not _GAIN_NAME.fullmatch(name):
            raise SweepError(f"stored gain axis {name!r}: expected l1, l2, ... or l")
        if kind == "sensors":
            if not all(isinstance(v, str) and _SENSOR_SET.fullmatch(v) for v in values):
                raise SweepError(
                    f"stored axis {name!r}: sensor sets must be 1-based indices such as '3,4'"
                )
        elif not all(type(v) in (int, float) for v in values):
            raise SweepError(f"stored axis {name!r}: expected numbers as values")
        return cls(name, kind, tuple(values), scale, spec)

    def __repr__(self) -> str:
        first, last = self.values[0], self.values[-1]
        span = f"{self.size} values {first!r}..{last!r}"
        return f"Axis({self.name!r}, {self.kind}, {span}, {self.scale})"


def _number(text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise SweepError(f"{what}: expected a number; found {text!r}") from None
    if not math.isfinite(value):
        raise SweepError(f"{what}: expected a finite number; found {text!r}")
    return value


def _range(name: str, spec: str) -> tuple[tuple[float, ...], str]:
    import numpy as np

    parts = [p.strip() for p in spec.split(":")]
    if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] != "log"):
        raise SweepError(
            f"grid {name}: expected start:stop:count or start:stop:count:log; found {spec!r}"
        )
    start = _number(parts[0], f"grid {name} start")
    stop = _number(parts[1], f"grid {name} stop")
    if not re.fullmatch(r"[+]?[0-9]+", parts[2]):
        raise SweepError(
            f"grid {name}: count must be a whole number of points; found {parts[2]!r}"
        )
    count = int(parts[2])
    log = len(parts) == 4
    if count == 0:
        raise SweepError(f"grid {name}: count must be at least 1; found zero points in {spec!r}")
    check_sweep_points(count, f"grid {name}")  # before the values are built
    if log and (start <= 0 or stop <= 0):
        raise SweepError(
            f"grid {name}: a log grid needs start > 0 and stop > 0; "
            f"found start {start!r}, stop {stop!r}"
        )
    if count == 1:
        if start != stop:
            raise SweepError(
                f"grid {name}: one point needs start = stop; found {start!r} and {stop!r}"
            )
        return (start,), "log" if log else "linear"
    if not start < stop:
        kind = "log grid" if log else "grid"
        raise SweepError(
            f"grid {name}: a {kind} runs from start up to stop; expected start < stop "
            f"but found {start!r} >= {stop!r} (reversed)"
        )
    values = np.geomspace(start, stop, count) if log else np.linspace(start, stop, count)
    return tuple(float(v) for v in values), "log" if log else "linear"


def parse_axis(name: str, spec: str | Sequence[float], kind: str) -> Axis:
    """Read a numeric axis from ``start:stop:count[:log]``, ``a,b,c`` or a sequence.

    Parameters
    ----------
    name : str
        The axis name (``l1``, ``l``, or a model parameter).
    spec : str or sequence of float
        The grid text, or the values themselves.
    kind : {"gain", "parameter"}

    Raises
    ------
    SweepError
        An empty or malformed grid, zero points, a reversed range, a log grid that is not
        positive, non-increasing values, a non-positive gain or a bad gain name.
    """
    if kind == "gain" and not _GAIN_NAME.match(name):
        raise SweepError(
            f"gain axis {name!r}: expected l1, l2, ... (one diagonal entry of L) or l "
            "(the same gain on every sensor)"
        )
    if not isinstance(spec, str):
        if hasattr(spec, "__len__"):
            check_sweep_points(len(spec), f"grid {name}")
        values = tuple(float(v) for v in spec)
        text = ",".join(repr(v) for v in values)
        if not values:
            raise SweepError(f"grid {name}: expected at least one value; found none")
        return Axis(name, kind, values, "linear", text)
    text = spec.strip()
    if not text:
        raise SweepError(
            f"grid {name}: empty; expected start:stop:count[:log] or a list such as 0.03,0.1,0.2"
        )
    if ":" in text:
        values, scale = _range(name, text)
    else:
        items = text.split(",")
        check_sweep_points(len(items), f"grid {name}")
        values = tuple(_number(p.strip(), f"grid {name} value") for p in items)
        scale = "linear"
    return Axis(name, kind, values, scale, text)


def sensor_set_indices(label: str) -> tuple[int, ...]:
    """Return the 1-based output indices of a sensor-set coordinate such as ``"3,4"``."""
    return tuple(int(p) for p in label.split(","))


def parse_sensor_sets(spec: str | Sequence[Sequence[int]], n_outputs: int) -> Axis:
    """Read the sensor sets ``"3,4;4;2"``, ``"all"``, or a sequence of index sequences.

    Raises
    ------
    SweepError
        An empty list, a set that is empty or repeats an index, an index out of
        ``1..n_outputs``, or a set given twice.
    """
    if isinstance(spec, str):
        text = spec.strip()
        if text == "all":
            check_sweep_points(2**n_outputs - 1, f"sensor sets 'all' of {n_outputs} outputs")
            sets = [
                combo
                for size in range(1, n_outputs + 1)
                for combo in itertools.combinations(range(1, n_outputs + 1), size)
            ]
        else:
            sets = []
            for part in text.split(";"):
                items = [p.strip() for p in part.split(",")]
                if not all(re.fullmatch(r"[0-9]+", p) for p in items):
                    raise SweepError(
                        "sensor sets: expected sets of 1-based output indices separated by "
                        f"';', such as 3,4;4;2, or 'all'; found {part.strip()!r} in {text!r}"
                    )
                sets.append(tuple(int(p) for p in items))
    else:
        text = ";".join(",".join(str(i) for i in s) for s in spec)
        sets = [tuple(int(i) for i in s) for s in spec]
    if not sets:
        raise SweepError("sensor sets: expected at least one set; found none")
    labels: list[str] = []
    for indices in sets:
        for index in indices:
            if not 1 <= index <= n_outputs:
                raise SweepError(
                    f"sensor sets: output index {index} is out of range; expected 1..{n_outputs}"
                )
        if len(set(indices)) != len(indices):
            raise SweepError(
                f"sensor sets: the set {','.join(map(str, indices))} repeats an output index"
            )
        label = ",".join(str(i) for i in indices)
        if label in labels:
            raise SweepError(f"sensor sets: the set {label} is given twice")
        labels.append(label)
    return Axis("sensors", "sensors", tuple(labels), "sets", text)
