"""What a sweep computed, in a few lines: the result object the command line prints.

:class:`SweepSummary` reads a sweep's Dataset (its attributes and figures) and the run's
record (chunks computed and reused, wall time, where it ran).  For every figure it gives
what a reader checks first: how many points have a value, the extremes and where they
are, how many flags are true, how often each verdict occurs.

Examples
--------
>>> import json, numpy as np, xarray as xr
>>> ds = xr.Dataset(
...     {"converged": ("l1", np.array([True, False]))},
...     coords={"l1": [0.1, 0.2]},
...     attrs={"model": "wave", "job": "spectrum", "sensors": "2", "gain": "1 on every sensor"},
... )
>>> print(SweepSummary.from_dataset(ds).figures[0].text())
converged: true at 1 of 2 points
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.text import html_table
from phdesign.sweep.dataset import RUN_ATTRIBUTE

__all__ = ["FigureStats", "SweepSummary"]


def _value(x: Any) -> Any:
    item = x.item() if hasattr(x, "item") else x
    return float(item) if isinstance(item, float) else item


def _where(
    dataset: Any, dims: tuple[str, ...], flat: int, shape: tuple[int, ...]
) -> dict[str, Any]:
    index = np.unravel_index(flat, shape)
    return {d: _value(dataset[d].values[i]) for d, i in zip(dims, index, strict=True)}


def _point(where: dict[str, Any]) -> str:
    return ", ".join(
        f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in where.items()
    )


@dataclass(frozen=True)
class FigureStats:
    """Statistics of one figure over the points.

    Attributes
    ----------
    name : str
    kind : {"number", "flag", "text"}
    points : int
        Points of the sweep.
    present : int
        Points with a value (numbers: finite; counts: not -1; text: not empty).
    true : int or None
        Flags: points where the flag is true.
    minimum, maximum : float or None
        Numbers: extremes over the points with a value.
    at_minimum, at_maximum : dict
        Their coordinates.
    counts : dict
        Text: occurrences of each value.
    """

    name: str
    kind: str
    points: int
    present: int
    true: int | None = None
    minimum: float | None = None
    maximum: float | None = None
    at_minimum: dict[str, Any] = field(default_factory=dict)
    at_maximum: dict[str, Any] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)

    @classmethod
    def of(cls, dataset: Any, name: str) -> FigureStats:
        """Statistics of ``dataset[name]``."""
        variable = dataset[name]
        values = np.asarray(variable.values)
        dims, shape = tuple(variable.dims), values.shape
        if values.dtype == bool:
            return cls(name, "flag", values.size, values.size, true=int(values.sum()))
        if values.dtype.kind in "US":
            labels, counts = np.unique(values[values != ""], return_counts=True)
            return cls(
                name,
                "text",
                values.size,
                int(counts.sum()),
                counts={str(k): int(c) for k, c in zip(labels, counts, strict=True)},
            )
        numbers = values.astype(float)
        ok = np.isfinite(numbers) & ~((values.dtype.kind == "i") & (values == -1))
        if not ok.any():
            return cls(name, "number", values.size, 0)
        masked_low = np.where(ok, numbers, np.inf)
        masked_high = np.where(ok, numbers, -np.inf)
        low, high = int(np.argmin(masked_low)), int(np.argmax(masked_high))
        return cls(
            name,
            "number",
            values.size,
            int(ok.sum()),
            minimum=float(numbers.flat[low]),
            maximum=float(numbers.flat[high]),
            at_minimum=_where(dataset, dims, low, shape),
            at_maximum=_where(dataset, dims, high, shape),
        )

    def text(self) -> str:
        """One line."""
        if self.kind == "flag":
            return f"{self.name}: true at {self.true} of {self.points} points"
        if self.kind == "text":
            counts = ", ".join(
                f"{k} {v}" for k, v in sorted(self.counts.items(), key=lambda kv: -kv[1])
            )
            return f"{self.name}: {counts or 'none'} (of {self.points} points)"
        if self.present == 0:
            return f"{self.name}: no value at any of the {self.points} points"
        return (
            f"{self.name}: {self.present} of {self.points} points; min {self.minimum:.6g} at "
            f"{_point(self.at_minimum)}; max {self.maximum:.6g} at {_point(self.at_maximum)}"
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        out: dict[str, Any] = {"name": self.name, "kind": self.kind, "points": self.points}
        out["present"] = self.present
        if self.kind == "flag":
            out["true"] = self.true
        elif self.kind == "text":
            out["counts"] = dict(self.counts)
        else:
            out.update(
                minimum=self.minimum,
                maximum=self.maximum,
                at_minimum=self.at_minimum,
                at_maximum=self.at_maximum,
            )
        return out


@dataclass(frozen=True)
class SweepSummary:
    """A sweep in a few lines: description, run, and every figure's statistics.

    ``str()`` is the text ``phdesign sweep`` prints, :meth:`to_dict` its ``--json``.
    """

    model: str
    job: str
    sensors: str
    gain: str
    axes: tuple[tuple[str, int, Any, Any, str], ...]
    points: int
    figures: tuple[FigureStats, ...]
    run: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def from_dataset(cls, dataset: Any) -> SweepSummary:
        """Summarize a sweep's Dataset (as returned by :func:`phdesign.sweep.sweep`)."""
        names = list(dataset.data_vars)
        dims = tuple(dataset[names[0]].dims) if names else tuple(dataset.dims)
        axes = []
        for d in dims:
            values = dataset[d].values
            scale = str(dataset[d].attrs.get("scale", ""))
            axes.append((d, int(values.size), _value(values[0]), _value(values[-1]), scale))
        run_text = dataset.attrs.get(RUN_ATTRIBUTE)
        return cls(
            model=str(dataset.attrs.get("model", "")),
            job=str(dataset.attrs.get("job", "")),
            sensors=str(dataset.attrs.get("sensors", "")),
            gain=str(dataset.attrs.get("gain", "")),
            axes=tuple(axes),
            points=int(np.prod([a[1] for a in axes])) if axes else 1,
            figures=tuple(FigureStats.of(dataset, n) for n in names),
            run=json.loads(run_text) if isinstance(run_text, str) else {},
        )

    def _axes_text(self) -> str:
        parts = []
        for name, size, first, last, scale in self.axes:
            span = (
                f"{first}"
                if size == 1
                else f"{first:.4g}..{last:.4g}"
                if isinstance(first, float)
                else f"{first}..{last}"
            )
            parts.append(f"{name} ({size}: {span}{', ' + scale if scale in ('log',) else ''})")
        return ", ".join(parts)

    def __str__(self) -> str:
        observer = (
            f"sensors {self.sensors}; gain {self.gain}"
            if self.sensors
            else (
                "sensor sets on an axis"
                if any(a[0] == "sensors" for a in self.axes)
                else "plant, u = 0"
            )
        )
        lines = [
            f"sweep: {self.job} on {self.model} ({observer})",
            f"axes: {self._axes_text()}: {self.points} points",
        ]
        run = self.run
        if run:
            lines.append(
                f"run: {run.get('chunks')} chunks, {run.get('computed')} computed, "
                f"{run.get('reused')} reused from the store, {run.get('seconds', 0.0):.2f} s "
                f"(chunk compute {run.get('compute_seconds', 0.0):.2f} s) "
                f"on {run.get('scheduler')}"
            )
            if run.get("output"):
                lines.append(f"output: {run['output']}")
        lines += [f.text() for f in self.figures]
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (
            f"SweepSummary({self.job} on {self.model!r}, {self.points} points, "
            f"figures {', '.join(f.name for f in self.figures)})"
        )[:300]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (strict JSON)."""
        return {
            "model": self.model,
            "job": self.job,
            "sensors": self.sensors,
            "gain": self.gain,
            "axes": [
                {"name": n, "size": s, "first": a, "last": b, "scale": sc}
                for n, s, a, b, sc in self.axes
            ],
            "points": self.points,
            "run": dict(self.run),
            "figures": [f.to_dict() for f in self.figures],
        }

    def _repr_html_(self) -> str:
        rows = [(f.name, f.text().split(": ", 1)[1]) for f in self.figures]
        caption = str(self).splitlines()[0]
        return html_table(("figure", "over the points"), rows, caption)
