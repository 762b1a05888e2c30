r"""The description of a sweep: model, job, axes, sensors and fixed options.

A :class:`SweepDescription` is everything that decides the numbers of a sweep, and
nothing else: the model (as its TOML text, with the fixed parameter values applied),
the job and its options, the axes in storage order, the fixed sensor set and gain, and
the phdesign version.  It is validated when built, frozen and hashable, and it
serializes to JSON; its :attr:`~SweepDescription.fingerprint` (SHA-256 of that JSON) is
what a store compares before it accepts to be resumed.

The grid of points is the Cartesian product of the axes, in the order

.. math::

    \text{sensor sets} \times \text{parameters} \times \text{gains},

so that neighbouring points share a model and a sensor set, and a chunk of points
needs to build them once.  At a point, the gain is
:math:`L = \operatorname{diag}(l_1, \dots, l_q)` with the entries on a gain axis taken
from the point and the others from the fixed gain (1 when not given); an axis ``l``
sets every entry.

Examples
--------
>>> from phdesign.models import load_builtin
>>> d = describe(load_builtin("wave"), job="spectrum", sensors=[2], grid={"l1": "0.5:2:4"})
>>> d.dims, d.shape
(('l1',), (4,))
>>> d.gain_at((1,))
(1.0,)
>>> SweepDescription.from_json(d.to_json()) == d
True
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from phdesign.core.checks import positive_number
from phdesign.core.errors import ParameterError, PhdesignError, SweepError
from phdesign.core.limits import MAX_STORE_METADATA_BYTES, check_sweep_points
from phdesign.core.text import did_you_mean
from phdesign.sweep.fields import description_fields
from phdesign.sweep.grids import Axis, parse_axis, parse_sensor_sets, sensor_set_indices
from phdesign.sweep.jobs import Job, get_job

__all__ = ["SweepDescription", "describe"]

#: Gain axes, parameter axes or sensor sets given as text or values, by name.
GridSpec = Mapping[str, "str | Sequence[float]"]


@dataclass(frozen=True)
class SweepDescription:
    """What a sweep computes (see the module docstring).

    Parameters
    ----------
    model_toml : str
        The model as a TOML model file, fixed parameter values applied.
    model_name : str
    n_outputs : int
        Number of outputs of the model (N n).
    parameter_names : tuple of str
        The model's parameters.
    job : str
        A key of :data:`phdesign.sweep.jobs.JOBS`.
    options : tuple of (str, object)
        The job's options, validated, sorted by name.
    axes : tuple of Axis
        In storage order: sensor sets, then parameters, then gains.
    sensors : tuple of int or None
        The fixed sensor set (``None`` with sensor sets, or without sensors).
    gain : tuple of float or None
        Fixed diagonal entries of L (``None``: 1 on every sensor); with sensor sets, one
        value for every sensor.
    version : str
        The phdesign version that computes the figures.
    """

    model_toml: str
    model_name: str
    n_outputs: int
    parameter_names: tuple[str, ...]
    job: str
    options: tuple[tuple[str, Any], ...]
    axes: tuple[Axis, ...]
    sensors: tuple[int, ...] | None
    gain: tuple[float, ...] | None
    version: str

    # ------------------------------------------------------------------ structure
    @property
    def dims(self) -> tuple[str, ...]:
        """Axis names in storage order."""
        return tuple(a.name for a in self.axes)

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of values on each axis."""
        return tuple(a.size for a in self.axes)

    @property
    def size(self) -> int:
        """Number of points."""
        count = 1
        for n in self.shape:
            count *= n
        return count

    @property
    def job_spec(self) -> Job:
        """The registered job."""
        return get_job(self.job)

    @property
    def has_gain_axes(self) -> bool:
        """Whether gains vary inside a setting (then a chunk reuses its setting)."""
        return any(a.kind == "gain" for a in self.axes)

    def axis(self, name: str) -> Axis:
        """Return the axis called ``name``."""
        for a in self.axes:
            if a.name == name:
                return a
        raise KeyError(name)

    def setting_at(
        self, index: Sequence[int]
    ) -> tuple[tuple[int, ...] | None, tuple[tuple[str, float], ...]]:
        """``(sensors, parameter values)`` at a point: what a chunk prepares once."""
        sensors = self.sensors
        params: list[tuple[str, float]] = []
        for a, i in zip(self.axes, index, strict=True):
            if a.kind == "sensors":
                sensors = sensor_set_indices(a.values[i])
            elif a.kind == "parameter":
                params.append((a.name, a.values[i]))
        return sensors, tuple(params)

    def gain_at(self, index: Sequence[int]) -> tuple[float, ...] | None:
        """Return the diagonal of L at a point (``None`` without sensors)."""
        sensors, _ = self.setting_at(index)
        if sensors is None:
            return None
        q = len(sensors)
        entries = list(self.gain) if self.gain is not None else [1.0]
        diag = entries * q if len(entries) == 1 else entries
        for a, i in zip(self.axes, index, strict=True):
            if a.kind != "gain":
                continue
            if a.name == "l":
                diag = [a.values[i]] * q
            else:
                diag[int(a.name[1:]) - 1] = a.values[i]
        return tuple(float(x) for x in diag)

    # ------------------------------------------------------------------ serialization
    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (strict JSON: every float is finite)."""
        return {
            "model": self.model_name,
            "model_toml": self.model_toml,
            "n_outputs": self.n_outputs,
            "parameter_names": list(self.parameter_names),
            "job": self.job,
            "options": dict(self.options),
            "axes": [a.to_dict() for a in self.axes],
            "sensors": None if self.sensors is None else list(self.sensors),
            "gain": None if self.gain is None else list(self.gain),
            "version": self.version,
        }

    def to_json(self) -> str:
        """Canonical JSON (sorted keys, no spaces): equal descriptions, equal text."""
        return json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"), allow_nan=False)

    @classmethod
    def from_dict(cls, data: Any) -> SweepDescription:
        """Inverse of :meth:`to_dict`, for data read from a file: every field is checked.

        Raises
        ------
        SweepError
            A field missing, unknown, of the wrong kind or out of range (named), a job or
            an option the registry does not know, or more points than a sweep may have
            (:func:`phdesign.sweep.fields.description_fields`).
        """
        return cls(**description_fields(data))

    @classmethod
    def from_json(cls, text: str) -> SweepDescription:
        """Inverse of :meth:`to_json` (refusing, as :meth:`from_dict` does, what is not one).

        Raises
        ------
        SweepError
            Not text, not JSON, or not a description.
        """
        if not isinstance(text, str) or len(text) > MAX_STORE_METADATA_BYTES:
            raise SweepError("a stored description must be JSON text of bounded size")
        try:
            data = json.loads(text)
        except ValueError as error:
            raise SweepError(f"a stored description is not JSON: {error}") from None
        except RecursionError:
            raise SweepError("a stored description is nested too deeply") from None
        return cls.from_dict(data)

    @property
    def fingerprint(self) -> str:
        """SHA-256 of :meth:`to_json`, in hex."""
        return hashlib.sha256(self.to_json().encode()).hexdigest()

    def difference(self, other: SweepDescription) -> str | None:
        """Name the first entry in which two descriptions differ, or ``None``."""
        mine, theirs = self.to_dict(), other.to_dict()
        for key in sorted(mine):
            if mine[key] != theirs.get(key):
                if key == "axes":
                    return _axes_difference(self.axes, other.axes)
                if key == "model_toml":
                    return "the models differ"
                return f"{key}: {_short(mine[key])} against {_short(theirs.get(key))}"
        return None

    def __repr__(self) -> str:
        axes = ", ".join(f"{a.name}[{a.size}]" for a in self.axes)
        return f"SweepDescription({self.job} on {self.model_name!r}: {axes}; {self.size} points)"


def _short(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _axes_difference(mine: tuple[Axis, ...], theirs: tuple[Axis, ...]) -> str:
    names, other_names = [a.name for a in mine], [a.name for a in theirs]
    if names != other_names:
        return f"axes {', '.join(names)} against {', '.join(other_names)}"
    for a, b in zip(mine, theirs, strict=True):
        if a != b:
            return f"axis {a.name}: {a.spec or a.size} against {b.spec or b.size}"
    return "the axes differ"


def _sensor_indices(sensors: str | Sequence[int], n_outputs: int) -> tuple[int, ...]:
    """Read ``"3,4"`` or ``[3, 4]`` as 1-based output indices, checked against the model."""
    import operator

    from phdesign.core.errors import ObserverError
    from phdesign.symbolic.observer import parse_sensor_indices, sensor_matrix

    if isinstance(sensors, str):
        indices = tuple(parse_sensor_indices(sensors))
        sensor_matrix(indices, n_outputs)  # range and repetition
        return indices
    try:
        indices = tuple(operator.index(i) for i in sensors)
    except TypeError:
        raise ObserverError(
            f"sensors: expected integer output indices such as [3, 4]; found {sensors!r}"
        ) from None
    sensor_matrix(indices, n_outputs)  # range and repetition
    return indices


def _fixed_gain(gain: str | Sequence[float] | float, count: int, per: str) -> tuple[float, ...]:
    """Read fixed diagonal entries of L (``count`` of them, or one for all) exactly."""
    from phdesign.core.errors import ObserverError
    from phdesign.symbolic.observer import diagonal_values

    if isinstance(gain, str):
        entries: list[object] = [p.strip() for p in gain.split(",")]
    elif isinstance(gain, int | float):
        entries = [gain]
    else:
        entries = list(gain)
    values = [float(v) for v in diagonal_values(entries, count, per)]
    return tuple(
        positive_number(v, f"gain: entry {i + 1}", ObserverError) for i, v in enumerate(values)
    )


#: A parameter axis of at most this many values is checked at every value before the sweep
#: starts (5 to 10 ms each); a longer one at its ends, and a chunk that meets a refused
#: value names its point (and a store the sweep created is removed again).
_CHECKED_PARAMETER_VALUES = 256


def _parameter_axis(name: str, text: Any, known: tuple[str, ...]) -> Axis:
    if name not in known:
        raise ParameterError(
            f"unknown parameter {name!r}{did_you_mean(name, known)}; the model's parameters "
            f"are {', '.join(known) if known else 'none'}"
        )
    return parse_axis(name, text, "parameter")


def _check_parameter_values(model: Any, axis: Axis) -> None:
    """Refuse a value of a parameter axis the model refuses (the others at their values)."""
    values = axis.values
    if len(values) > _CHECKED_PARAMETER_VALUES:
        values = (values[0], values[-1])
    for value in values:
        try:
            model.with_parameters({axis.name: value})
        except PhdesignError as error:
            raise type(error)(f"parameter grid {axis.name} = {value!r}: {error}") from None


def describe(
    model: Any,
    *,
    job: str = "spectrum",
    sensors: str | Sequence[int] | None = None,
    sensor_sets: str | Sequence[Sequence[int]] | None = None,
    gain: str | Sequence[float] | float | None = None,
    grid: GridSpec | None = None,
    param_grid: GridSpec | None = None,
    options: Mapping[str, Any] | None = None,
) -> SweepDescription:
    """Validate a sweep against its model and job and return its description.

    Parameters
    ----------
    model : BCPHS
        The model, fixed parameter values already applied (``model.with_parameters``).
    job : str
        ``"spectrum"``, ``"classify"`` or ``"gain"`` (see :data:`phdesign.sweep.jobs.JOBS`).
    sensors : str or sequence of int, optional
        The measured outputs (1-based), the same at every point: ``[3, 4]`` or ``"3,4"``.
    sensor_sets : str or sequence of sequences of int, optional
        An axis of sensor sets instead: ``"3,4;4;2"``, ``"all"`` or ``[(3, 4), (4,)]``.
    gain : str, float or sequence of float, optional
        Fixed diagonal entries of L (one per sensor, or one for all); default 1.
    grid : mapping, optional
        Gain axes: ``{"l1": "0.01:3:40:log", "l2": [0.1, 1]}`` (``l`` for every entry).
    param_grid : mapping, optional
        Parameter axes: ``{"d": "0:0.4:9"}``.
    options : mapping, optional
        The job's options (``method``, ``resolution``, ``max_resolution``, ``tol`` for
        ``spectrum``).

    Raises
    ------
    SweepError
        A malformed grid, no axis, a gain axis without sensors or beyond their count.
    ParameterError
        A parameter the model does not have, or an axis value the model refuses.
    ObserverError
        A sensor index out of range or repeated.
    """
    from phdesign import __version__
    from phdesign.io import model_to_toml

    spec = get_job(job)
    n_outputs = int(model.order * model.size)
    fixed_sensors, set_axis = _sensor_axes(spec, sensors, sensor_sets, n_outputs)
    fixed_gain = _fixed_gains(gain, fixed_sensors, set_axis)
    known = tuple(sorted(str(s) for s in model.parameter_names))
    gain_axes = _gain_axes(grid or {}, known, fixed_sensors, set_axis)
    param_axes = [_parameter_axis(name, text, known) for name, text in (param_grid or {}).items()]
    axes = _checked_axes(([set_axis] if set_axis else []) + param_axes + gain_axes)
    for axis in param_axes:
        _check_parameter_values(model, axis)
    option_values = spec.option_values(options)
    spec.check_options(model, option_values)
    return SweepDescription(
        model_toml=model_to_toml(model),
        model_name=str(model.name),
        n_outputs=n_outputs,
        parameter_names=known,
        job=job,
        options=tuple(sorted(option_values.items())),
        axes=axes,
        sensors=fixed_sensors,
        gain=fixed_gain,
        version=__version__,
    )


def _sensor_axes(
    spec: Job, sensors: Any, sensor_sets: Any, n_outputs: int
) -> tuple[tuple[int, ...] | None, Axis | None]:
    """Return the fixed sensor set or the axis of sensor sets (at most one of them)."""
    if sensors is not None and sensor_sets is not None:
        raise SweepError("give either sensors (one set) or sensor_sets (an axis), not both")
    fixed = None if sensors is None else _sensor_indices(sensors, n_outputs)
    set_axis = None if sensor_sets is None else parse_sensor_sets(sensor_sets, n_outputs)
    if spec.needs_sensors and fixed is None and set_axis is None:
        raise SweepError(f"job {spec.name} needs sensors: give sensors or sensor_sets")
    return fixed, set_axis


def _set_sizes(fixed: tuple[int, ...] | None, set_axis: Axis | None) -> list[int]:
    """Return the number of sensors of the fixed set, or of each set of the axis."""
    if fixed is not None:
        return [len(fixed)]
    if set_axis is not None:
        return [len(sensor_set_indices(v)) for v in set_axis.values]
    return []


def _fixed_gains(
    gain: Any, fixed: tuple[int, ...] | None, set_axis: Axis | None
) -> tuple[float, ...] | None:
    """Return the fixed diagonal of L (``None``: 1 on every sensor; one with sensor sets)."""
    if gain is None:
        return None
    if set_axis is not None:
        if isinstance(gain, str) and "," in gain:
            raise SweepError(
                f"with sensor sets the fixed gain is one value for every sensor; found {gain!r}"
            )
        return _fixed_gain(gain, 1, "sensor of every set")
    if fixed is None:
        raise SweepError("a gain needs sensors: give sensors or sensor_sets")
    return _fixed_gain(gain, len(fixed), "sensor")


def _gain_axes(
    grid: GridSpec, known: tuple[str, ...], fixed: tuple[int, ...] | None, set_axis: Axis | None
) -> list[Axis]:
    """Return the gain axes ``l1``, ``l2``, ... or ``l``, within the smallest sensor set."""
    for name in grid:
        if name in known:
            raise SweepError(
                f"grid {name}: {name} is a model parameter, not a gain; give it as a "
                f"parameter axis (`param_grid={{{name!r}: ...}}`)"
            )
    gain_axes = [parse_axis(name, text, "gain") for name, text in grid.items()]
    if gain_axes and fixed is None and set_axis is None:
        raise SweepError("gain axes need sensors: give sensors or sensor_sets")
    names = [a.name for a in gain_axes]
    if "l" in names and len(names) > 1:
        raise SweepError(
            "gain axis l sets every entry of L; it cannot be combined with l1, l2, ..."
        )
    sizes = _set_sizes(fixed, set_axis)
    q_min = min(sizes) if sizes else 0
    for a in gain_axes:
        if a.name != "l" and int(a.name[1:]) > q_min:
            what = "the sensors" if fixed else "the smallest sensor set"
            count = f"{q_min} sensor{'s' if q_min > 1 else ''}"
            raise SweepError(
                f"gain axis {a.name} is beyond {what} ({count}); expected l1..l{q_min} "
                "(or l for every entry)"
            )
    return gain_axes


def _checked_axes(axes: list[Axis]) -> tuple[Axis, ...]:
    """Return the axes: at least one, of distinct names, within the sweep's point budget."""
    if not axes:
        raise SweepError(
            "a sweep needs at least one axis: a gain grid, a parameter grid or sensor sets"
        )
    if len({a.name for a in axes}) != len(axes):
        raise SweepError("an axis is given twice")
    check_sweep_points(math.prod(a.size for a in axes), "the sweep")
    return tuple(axes)
