r"""The speed/noise trade-off of an observer gain: decay rate against error RMS.

A larger gain L damps the error faster (up to a coalescence, beyond which the boundary
damper over-damps and the decay slows again) but feeds more sensor noise into the
estimate.  :func:`tradeoff` evaluates, for a family of gains, the converged spectral
abscissa α of the error system (:func:`phdesign.numeric.spectrum.converged.spectrum`; the decay
rate is −α) and the noise figures (:func:`phdesign.numeric.noise.figures.noise`), and marks the
Pareto-optimal gains: those that no other gain of the family beats in both the decay
rate and the RMS of the first performance output.

Families: a ray :math:`L(s) = s L_0` with log-spaced scales s, or a grid of diagonal
gains (every combination of per-sensor values).  Only figures that converged under
refinement take part in the Pareto comparison; the others are listed and flagged.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from itertools import product
from typing import Any

import numpy as np

from phdesign.core.defaults import method_or_default
from phdesign.core.errors import NumericError
from phdesign.core.limits import check_tradeoff_gains
from phdesign.core.progress import stage
from phdesign.core.text import gain_text, html_table, measured_text
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.functionals import Functional, parse_functionals
from phdesign.numeric.discretization.registry import DiscretePHS, feedback_matrix
from phdesign.numeric.noise.figures import noise, sensor_rows
from phdesign.numeric.noise.pareto import ParetoFamily, pareto_mask
from phdesign.numeric.noise.report import NoiseReport
from phdesign.numeric.noise.settle import finite_or_none
from phdesign.numeric.spectrum.converged import SpectrumReport, spectrum
from phdesign.numeric.spectrum.refinement import Discretizations
from phdesign.numeric.threads import limited_threads

__all__ = ["Tradeoff", "TradeoffPoint", "gain_family", "pareto_mask", "tradeoff"]


@dataclass(frozen=True)
class TradeoffPoint:
    """One gain of a trade-off: its decay and its noise figures.

    Attributes
    ----------
    gain : ndarray
    scale : float or None
        s of a ray ``s L_0`` (None on a grid).
    spectral_abscissa : float or None
        Converged abscissa of the error system (None when unbounded below).
    abscissa_converged : bool
    abscissa_digits : float or None
    noise : NoiseReport
    pareto : bool
        No other point has both a faster decay and a smaller error RMS.
    """

    gain: np.ndarray
    scale: float | None
    spectral_abscissa: float | None
    abscissa_converged: bool
    abscissa_digits: float | None
    noise: NoiseReport
    pareto: bool = False

    @property
    def decay_rate(self) -> float | None:
        """−α, the exponential decay rate of the estimation error."""
        return None if self.spectral_abscissa is None else -self.spectral_abscissa

    @property
    def rms(self) -> float | None:
        """RMS of the first performance output's error (None unless converged)."""
        return self.noise.rms()

    @property
    def figure(self) -> float | None:
        """The figure traded against the decay rate: the RMS."""
        return self.rms

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready row of the table."""
        g = self.noise.l2_gain
        return {
            "gain": self.gain.tolist(),
            "scale": self.scale,
            "spectral_abscissa": finite_or_none(self.spectral_abscissa),
            "abscissa_converged": self.abscissa_converged,
            "abscissa_digits": finite_or_none(self.abscissa_digits),
            "decay_rate": finite_or_none(self.decay_rate),
            "rms": {
                e.name: None if e.value is None else math.sqrt(e.value)
                for e in self.noise.performance
            },
            "rms_converged": {e.name: e.converged for e in self.noise.performance},
            "l2_gain": finite_or_none(g.value),
            "l2_gain_converged": g.converged,
            "error_energy_diverges": self.noise.error_energy.diverges,
            "pareto": self.pareto,
        }


@dataclass(frozen=True)
class Tradeoff(ParetoFamily):
    """Result of :func:`tradeoff`: one row per gain, Pareto-optimal rows marked.

    ``.pareto_points`` (by increasing RMS) and ``.plot()`` (decay rate against the RMS)
    are those of :class:`~phdesign.numeric.noise.pareto.ParetoFamily`.

    Attributes
    ----------
    model : str
    sensors : ndarray
    family : str
        ``"ray"`` or ``"grid"``.
    direction : ndarray or None
        L₀ of a ray.
    points : tuple of TradeoffPoint
    performance : str
        The performance output whose RMS is traded against the decay rate.
    intensity : tuple of float
    output_labels : tuple of str
    performance_unit : str
        The unit the model states for the performance output (``""``: none).
    time_unit : str
        The unit of time the model states (``""``: none).
    """

    model: str
    sensors: np.ndarray
    family: str
    direction: np.ndarray | None
    points: tuple[TradeoffPoint, ...]
    performance: str
    intensity: tuple[float, ...]
    output_labels: tuple[str, ...] = ()
    warnings: tuple[str, ...] = field(default=())
    performance_unit: str = ""
    time_unit: str = ""

    @property
    def figure_label(self) -> str:
        """What the figure of the points is (the plot's axis)."""
        unit = f" [{self.performance_unit}]" if self.performance_unit else ""
        return f"RMS of the estimation error of {self.performance}{unit}"

    @property
    def figure_title(self) -> str:
        """What is traded, in the plot's title."""
        return "speed against noise"

    def _columns(self) -> list[str]:
        q = self.sensors.shape[0]
        gains = [f"l{i + 1}" for i in range(q)]
        names = [e.name for e in self.points[0].noise.performance] if self.points else []
        return [
            *gains,
            "scale",
            "spectral_abscissa",
            "abscissa_converged",
            "decay_rate",
            *[f"rms {n}" for n in names],
            *[f"rms {n} converged" for n in names],
            "l2_gain",
            "l2_gain_converged",
            "pareto",
        ]

    def _row(self, p: TradeoffPoint) -> list[Any]:
        d = p.to_dict()
        diag = np.diag(p.gain).tolist()
        return [
            *diag,
            d["scale"],
            d["spectral_abscissa"],
            d["abscissa_converged"],
            d["decay_rate"],
            *d["rms"].values(),
            *d["rms_converged"].values(),
            d["l2_gain"],
            d["l2_gain_converged"],
            d["pareto"],
        ]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (``phdesign tradeoff --json``)."""
        return {
            "model": self.model,
            "sensors": self.sensors.tolist(),
            "family": self.family,
            "direction": None if self.direction is None else self.direction.tolist(),
            "performance": self.performance,
            "intensity": list(self.intensity),
            "points": [p.to_dict() for p in self.points],
            "pareto": [i for i, p in enumerate(self.points) if p.pareto],
            "warnings": list(self.warnings),
        }

    def to_csv(self) -> str:
        """Return the table as CSV (empty cells: figures that did not converge)."""
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(self._columns())
        for p in self.points:
            writer.writerow(["" if v is None else v for v in self._row(p)])
        return buf.getvalue()

    def __str__(self) -> str:
        sensors = measured_text(self.sensors)
        intensity = ", ".join(f"{s:g}" for s in self.intensity)
        head = f"model: {self.model}   sensors: {sensors}   sensor noise intensity {intensity}"
        lines = [
            head,
            f"decay rate -α against the error RMS of {self.performance} ({self.family}):",
        ]
        lines.append(f"  {'gain L':<28} {'-α':>10} {'rms':>12} {'L2-gain':>10}  Pareto")
        for p in self.points:
            rate = (
                "—"
                if p.decay_rate is None
                else f"{p.decay_rate:.6g}" + ("" if p.abscissa_converged else "*")
            )
            rms, gain = _figure_text(p, ".6g"), _figure_text(p, ".5g", l2=True)
            pareto = "  yes" if p.pareto else ""
            lines.append(f"  {gain_text(p.gain):<28} {rate:>10} {rms:>12} {gain:>10}{pareto}")
        lines.append(
            "(*: did not converge, shown to the digits that agree between the two finest "
            "resolutions (-α: to 1e-10, e.g. at a coalescence); —: diverges or not computed; "
            "Pareto: no other gain decays faster with a smaller rms)"
        )
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (
            f"Tradeoff(model={self.model!r}, {self.family} of {len(self.points)} gains, "
            f"{len(self.pareto_points)} Pareto-optimal, performance={self.performance!r})"
        )

    def _repr_html_(self) -> str:
        rows = [
            (
                gain_text(p.gain),
                "—" if p.decay_rate is None else f"{p.decay_rate:.6g}",
                "—" if p.rms is None else f"{p.rms:.6g}",
                "—" if p.noise.l2_gain.value is None else f"{p.noise.l2_gain.value:.5g}",
                "yes" if p.pareto else "",
            )
            for p in self.points
        ]
        return html_table(
            ("gain L", "decay rate −α", f"rms {self.performance}", "L2-gain", "Pareto"),
            rows,
            repr(self),
        )


def _figure_text(point: TradeoffPoint, spec: str, *, l2: bool = False) -> str:
    """Return a point's rms (or L2-gain) for the table; ``0.6095*`` if not converged."""
    noise = point.noise
    value = noise.l2_gain.value if l2 else point.rms
    if value is not None:
        return f"{value:{spec}}"
    est = noise.l2_gain.estimate if l2 else (noise.performance[0] if noise.performance else None)
    if est is None or not est.values:
        return "—"
    shown = est.rounded() if l2 else est.rounded(math.sqrt(max(est.values[-1], 0.0)))
    return "—" if shown is None else f"{shown}*"


def gain_family(
    q: int,
    *,
    direction: Any = None,
    scales: Sequence[float] | None = None,
    grid: Sequence[Sequence[float]] | None = None,
) -> tuple[list[np.ndarray], list[float | None], np.ndarray | None]:
    """Return the gains of a ray ``s L_0`` or of a diagonal grid, their scales, and L₀."""
    if grid is not None:
        if direction is not None or scales is not None:
            raise NumericError("give either a grid of gains or a ray (direction and scales)")
        if isinstance(grid, str) or not isinstance(grid, Sequence | np.ndarray):
            raise NumericError(f"grid: expected one sequence of gains per sensor; found {grid!r}")
        axes = [np.atleast_1d(_floats(a, f"grid axis {i + 1}")) for i, a in enumerate(grid)]
        if len(axes) != q:
            raise NumericError(f"grid: expected {q} axes (one per sensor); found {len(axes)}")
        for i, a in enumerate(axes):
            if a.size == 0 or not np.all(np.isfinite(a)) or np.any(a <= 0):
                raise NumericError(
                    f"grid axis {i + 1}: expected positive finite gains; found {a.tolist()}"
                )
        check_tradeoff_gains(math.prod(a.size for a in axes), "grid")  # before building them
        gains = [np.diag(np.array(c)) for c in product(*axes)]
        return gains, [None] * len(gains), None
    L0 = np.eye(q) if direction is None else _floats(direction, "direction")
    if L0.ndim == 1:
        L0 = np.diag(np.broadcast_to(L0, (q,)) if L0.size == 1 else L0)
    s = np.geomspace(0.1, 10.0, 12) if scales is None else _floats(scales, "scales").ravel()
    check_tradeoff_gains(s.size, "scales")
    if s.size == 0 or not np.all(np.isfinite(s)) or np.any(s <= 0):
        raise NumericError(f"scales: expected positive finite numbers; found {s.tolist()}")
    return [float(v) * L0 for v in s], [float(v) for v in s], L0


def _floats(values: Any, name: str) -> np.ndarray:
    """``values`` as a float array, or a :class:`NumericError` naming ``name``."""
    try:
        return np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise NumericError(f"{name}: expected numbers; found {values!r}") from None


@limited_threads
def tradeoff(
    nm: NumericModel,
    C_m: np.ndarray,
    *,
    direction: Any = None,
    scales: Sequence[float] | None = None,
    grid: Sequence[Sequence[float]] | None = None,
    intensity: Any = None,
    input_intensity: Any = None,
    performance: Sequence[Functional | str] | None = None,
    model: Any = None,
    method: str | None = None,
) -> Tradeoff:
    """Decay rate and noise figures over a family of gains, Pareto-optimal gains marked.

    Parameters
    ----------
    nm : NumericModel
    C_m : ndarray (q, N n)
    direction : array-like, optional
        L₀ of the ray ``s L_0``: q diagonal entries or a q × q matrix (default identity).
    scales : sequence of float, optional
        The scales s (default 12 log-spaced values from 0.1 to 10).
    grid : sequence of q sequences of float, optional
        Per-sensor gain values; every combination is a diagonal gain (instead of a ray).
    intensity, input_intensity, performance, model, method
        As for :func:`phdesign.numeric.noise.figures.noise`; the first performance output is the
        one traded against the decay rate.  The points' noise reports leave out the
        discretization's own supremum over all frequencies (``discrete_sup=False``: a
        diagnostic of one design, a sweep of the whole band; ask
        :func:`~phdesign.numeric.noise.figures.noise` for it).

    Returns
    -------
    Tradeoff
    """
    C = sensor_rows(C_m, "a trade-off")
    q = C.shape[0]
    functionals = parse_functionals(performance, nm, model)
    if not functionals:
        raise NumericError(
            f"the trade-off needs a performance output and the model {nm.name!r} defines no "
            "displacement: give one (a point w(z) of a displacement, a trace like e1(1), or "
            "an integral like 'x2: 1')"
        )
    gains, scale_list, L0 = gain_family(q, direction=direction, scales=scales, grid=grid)
    for L in gains:
        feedback_matrix(C, L, nm.n_ports)  # every gain valid before any work
    rows = _figures(nm, C, gains, scale_list, method, functionals, intensity, input_intensity)
    points = _points(rows)
    warnings = []
    missing = sum(1 for point in points if point.noise.rms() is None)
    if missing:
        warnings.append(
            f"{missing} of {len(points)} gains have no converged RMS of {functionals[0].name}: "
            "they take no part in the Pareto comparison"
        )
    return Tradeoff(
        model=nm.name,
        sensors=C,
        family="grid" if grid is not None else "ray",
        direction=L0,
        points=points,
        performance=functionals[0].name,
        intensity=points[0].noise.intensity,
        output_labels=nm.output_labels,
        warnings=tuple(warnings),
        performance_unit=_unit_of(functionals[0], nm),
        time_unit=dict(nm.units).get("t", ""),
    )


def _unit_of(functional: Functional, nm: NumericModel) -> str:
    """Return the unit the model states for a displacement or a named field, else ``""``."""
    if functional.kind != "displacement":
        return ""
    key = "displacement" if functional.field_name == "w" else functional.field_name
    return dict(nm.units).get(key, "")


def _figures(
    nm: NumericModel,
    C: np.ndarray,
    gains: list[np.ndarray],
    scales: list[float | None],
    method: str | None,
    functionals: Sequence[Functional],
    intensity: Any,
    input_intensity: Any,
) -> list[tuple[np.ndarray, float | None, SpectrumReport, NoiseReport]]:
    """Return the spectrum and the noise figures at every gain, on shared discretizations."""
    # the discretizations do not depend on the gain: built once, for every gain
    method = method_or_default(method)
    cache: dict[int, DiscretePHS] = {}
    shared = Discretizations(nm, method)
    rows = []
    for i, (L, s) in enumerate(zip(gains, scales, strict=True), start=1):
        with stage(f"tradeoff: gain {i} of {len(gains)}"):
            spec = spectrum(nm, C, L, method=method, discretizations=shared)
            rep = noise(
                nm,
                C,
                L,
                intensity=intensity,
                input_intensity=input_intensity,
                performance=functionals,
                method=method,
                discretizations=cache,
                discrete_sup=False,  # the report's diagnostic, not a figure of the trade-off
            )
        rows.append((L, s, spec, rep))
    return rows


def _points(
    rows: list[tuple[np.ndarray, float | None, SpectrumReport, NoiseReport]],
) -> tuple[TradeoffPoint, ...]:
    """Return each gain's figures as a point, the Pareto-optimal ones marked."""
    decay = [None if r[2].spectral_abscissa is None else -r[2].spectral_abscissa for r in rows]
    mask = pareto_mask(decay, [r[3].rms() for r in rows])
    return tuple(
        TradeoffPoint(
            gain=L,
            scale=s,
            spectral_abscissa=spec.spectral_abscissa,
            abscissa_converged=spec.converged,
            abscissa_digits=spec.digits,
            noise=rep,
            pareto=m,
        )
        for (L, s, spec, rep), m in zip(rows, mask, strict=True)
    )
