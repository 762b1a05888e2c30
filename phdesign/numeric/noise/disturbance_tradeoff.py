r"""The speed/disturbance trade-off of an observer gain: decay rate against the H∞ norm.

The disturbance counterpart of :mod:`phdesign.numeric.noise.tradeoff` (the same families
of gains, :func:`~phdesign.numeric.noise.tradeoff.gain_family`, the same Pareto rule,
:func:`~phdesign.numeric.noise.tradeoff.pareto_mask`, the same figure,
:func:`phdesign.plots.noise.plot_tradeoff`): for each gain L, the converged spectral
abscissa α of the error system (decay rate −α) and the gain report of
:func:`~phdesign.numeric.noise.disturbance.disturbance_gain`, whose H∞ norm
:math:`\gamma(L)` from the disturbances and the sensor noise to the estimation error of
the performance outputs is traded against the decay rate.  A gain that damps faster lets
less of a slow disturbance through, but more sensor noise; only the figures that
converged under refinement take part in the Pareto comparison.

Damped-tip string check: the string with sensor :math:`y_2 = e_1(1)`, gain k, a uniform
force and :math:`z_p = \int_0^1 e_1`, without sensor noise: −α = ½ ln|(1+k)/(1−k)| and
:math:`\gamma(k)` is the hand-derived H∞ norm of the damped-tip string.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.defaults import method_or_default
from phdesign.core.progress import stage
from phdesign.core.text import gain_text, html_table, measured_text
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.registry import DiscretePHS, feedback_matrix
from phdesign.numeric.noise.disturbance import disturbance_gain
from phdesign.numeric.noise.disturbance_report import GainReport
from phdesign.numeric.noise.figures import sensor_rows
from phdesign.numeric.noise.pareto import ParetoFamily, pareto_mask
from phdesign.numeric.noise.settle import finite_or_none
from phdesign.numeric.noise.tradeoff import gain_family
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.spectrum.refinement import Discretizations
from phdesign.numeric.threads import limited_threads

__all__ = ["DisturbancePoint", "DisturbanceTradeoff", "disturbance_tradeoff"]


@dataclass(frozen=True)
class DisturbancePoint:
    """One gain of the trade-off: its decay and its gain report.

    Attributes
    ----------
    gain : ndarray
    scale : float or None
        s of a ray ``s L_0`` (None on a grid).
    spectral_abscissa : float or None
        Converged abscissa of the error system (None when unbounded below).
    abscissa_converged : bool
    report : GainReport
    pareto : bool
        No other point has both a faster decay and a smaller H∞ norm.
    """

    gain: np.ndarray
    scale: float | None
    spectral_abscissa: float | None
    abscissa_converged: bool
    report: GainReport
    pareto: bool = False

    @property
    def decay_rate(self) -> float | None:
        """−α, the exponential decay rate of the estimation error."""
        return None if self.spectral_abscissa is None else -self.spectral_abscissa

    @property
    def figure(self) -> float | None:
        """The H∞ norm traded against the decay rate (None unless converged)."""
        return self.report.hinf.value

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready row of the table."""
        return {
            "gain": self.gain.tolist(),
            "scale": self.scale,
            "spectral_abscissa": finite_or_none(self.spectral_abscissa),
            "abscissa_converged": self.abscissa_converged,
            "decay_rate": finite_or_none(self.decay_rate),
            "hinf": finite_or_none(self.report.hinf.value),
            "hinf_converged": self.report.hinf.converged,
            "hinf_frequency": finite_or_none(self.report.hinf.frequency),
            "h2": finite_or_none(self.report.h2.value),
            "h2_converged": self.report.h2.converged,
            "pareto": self.pareto,
        }


_COLUMNS = (
    "scale",
    "spectral_abscissa",
    "abscissa_converged",
    "decay_rate",
    "hinf",
    "hinf_converged",
    "hinf_frequency",
    "h2",
    "h2_converged",
    "pareto",
)


@dataclass(frozen=True)
class DisturbanceTradeoff(ParetoFamily):
    """Result of :func:`disturbance_tradeoff`: one row per gain, Pareto-optimal rows marked.

    ``.pareto_points`` (by increasing H∞ norm) and ``.plot()`` (decay rate against the H∞
    norm) are those of :class:`~phdesign.numeric.noise.pareto.ParetoFamily`.

    Attributes
    ----------
    model : str
    sensors : ndarray
    family : str
        ``"ray"`` or ``"grid"``.
    direction : ndarray or None
        L₀ of a ray.
    points : tuple of DisturbancePoint
    sources, outputs : tuple of str
        The disturbance sources and the performance outputs of the gain reports.
    intensity : tuple of float
        Sensor noise intensities σᵢ².
    time_unit : str
    warnings : tuple of str
    """

    model: str
    sensors: np.ndarray
    family: str
    direction: np.ndarray | None
    points: tuple[DisturbancePoint, ...]
    sources: tuple[str, ...]
    outputs: tuple[str, ...]
    intensity: tuple[float, ...]
    time_unit: str = ""
    warnings: tuple[str, ...] = field(default=())

    @property
    def figure_label(self) -> str:
        """What the figure of the points is (the plot's axis)."""
        return f"H∞ norm from {', '.join(self.sources)} to the error of {', '.join(self.outputs)}"

    @property
    def figure_title(self) -> str:
        """What is traded, in the plot's title."""
        return "speed against disturbances"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (``phdesign tradeoff --against hinf --json``)."""
        return {
            "model": self.model,
            "sensors": self.sensors.tolist(),
            "against": "hinf",
            "family": self.family,
            "direction": None if self.direction is None else self.direction.tolist(),
            "sources": list(self.sources),
            "outputs": list(self.outputs),
            "intensity": list(self.intensity),
            "points": [p.to_dict() for p in self.points],
            "pareto": [i for i, p in enumerate(self.points) if p.pareto],
            "warnings": list(self.warnings),
        }

    def to_csv(self) -> str:
        """Return the table as CSV (empty cells: figures that did not converge)."""
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        gains = [f"l{i + 1}" for i in range(self.sensors.shape[0])]
        writer.writerow([*gains, *_COLUMNS])
        for p in self.points:
            row = p.to_dict()
            cells = [*np.diag(p.gain).tolist(), *(row[c] for c in _COLUMNS)]
            writer.writerow(["" if v is None else v for v in cells])
        return buf.getvalue()

    def __str__(self) -> str:
        noise = ", ".join(f"{s:g}" for s in self.intensity)
        lines = [
            f"model: {self.model}   sensors: {measured_text(self.sensors)}   sensor noise "
            f"intensity {noise}",
            f"decay rate -α against the H∞ norm from {', '.join(self.sources)} to the error "
            f"of {', '.join(self.outputs)} ({self.family}):",
            f"  {'gain L':<28} {'-α':>10} {'H∞':>12} {'H2':>12}  Pareto",
        ]
        for p in self.points:
            rate = "—" if p.decay_rate is None else f"{p.decay_rate:.6g}"
            rate += "" if p.abscissa_converged or p.decay_rate is None else "*"
            hinf, h2 = (_cell(e) for e in (p.report.hinf.estimate, p.report.h2))
            pareto = "  yes" if p.pareto else ""
            lines.append(f"  {gain_text(p.gain):<28} {rate:>10} {hinf:>12} {h2:>12}{pareto}")
        lines.append(
            "(*: did not converge, shown to the digits that agree; —: diverges or not "
            "computed; Pareto: no other gain decays faster with a smaller H∞ norm)"
        )
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (
            f"DisturbanceTradeoff(model={self.model!r}, {self.family} of {len(self.points)} "
            f"gains, {len(self.pareto_points)} Pareto-optimal)"
        )

    def _repr_html_(self) -> str:
        rows = [
            (
                gain_text(p.gain),
                "—" if p.decay_rate is None else f"{p.decay_rate:.6g}",
                _cell(p.report.hinf.estimate),
                _cell(p.report.h2),
                "yes" if p.pareto else "",
            )
            for p in self.points
        ]
        return html_table(("gain L", "decay rate −α", "H∞", "H2", "Pareto"), rows, repr(self))


def _cell(est: Any) -> str:
    """Return a norm for the table: its value, ``0.5352*`` to the agreeing digits, or ``—``."""
    if est.value is not None:
        return f"{est.value:.6g}"
    shown = est.rounded() if est.values and not est.diverges else None
    return "—" if shown is None else f"{shown}*"


@limited_threads
def disturbance_tradeoff(
    nm: NumericModel,
    C_m: np.ndarray,
    *,
    model: Any,
    direction: Any = None,
    scales: Sequence[float] | None = None,
    grid: Sequence[Sequence[float]] | None = None,
    intensity: Any = None,
    performance: Sequence[str] | None = None,
    method: str | None = None,
) -> DisturbanceTradeoff:
    """Decay rate and H∞ norm over a family of gains, Pareto-optimal gains marked.

    Parameters
    ----------
    nm : NumericModel
    C_m : ndarray (q, N n)
    model : BCPHS
        The symbolic model: its ``[disturbances]`` and ``[performance]``.
    direction, scales, grid
        The family, as for :func:`phdesign.numeric.noise.tradeoff.tradeoff`.
    intensity : float or sequence of float, optional
        Sensor noise intensities σᵢ² (default 1; 0 leaves the noise out).
    performance : sequence of str, optional
        Outputs in the ``[performance]`` grammar (default: the model's).
    method : str, optional

    Returns
    -------
    DisturbanceTradeoff
    """
    C = sensor_rows(C_m, "a trade-off")
    gains, scale_list, L0 = gain_family(C.shape[0], direction=direction, scales=scales, grid=grid)
    for L in gains:
        feedback_matrix(C, L, nm.n_ports)  # every gain valid before any work
    method = method_or_default(method)
    shared = Discretizations(nm, method)  # built once, for every gain
    cache: dict[int, DiscretePHS] = {}
    rows: list[tuple[np.ndarray, float | None, Any, GainReport]] = []
    for i, (L, s) in enumerate(zip(gains, scale_list, strict=True), start=1):
        with stage(f"tradeoff: gain {i} of {len(gains)}"):
            report = disturbance_gain(
                nm,
                C,
                L,
                model=model,
                intensity=intensity,
                performance=performance,
                method=method,
                discretizations=cache,
            )
            spec = spectrum(nm, C, L, method=method, discretizations=shared)
        rows.append((L, s, spec, report))
    decay = [None if r[2].spectral_abscissa is None else -r[2].spectral_abscissa for r in rows]
    mask = pareto_mask(decay, [r[3].hinf.value for r in rows])
    points = tuple(
        DisturbancePoint(L, s, spec.spectral_abscissa, spec.converged, report, m)
        for (L, s, spec, report), m in zip(rows, mask, strict=True)
    )
    missing = sum(1 for p in points if p.figure is None)
    warnings = []
    if missing:
        warnings.append(
            f"{missing} of {len(points)} gains have no converged H∞ norm: they take no part "
            "in the Pareto comparison"
        )
    first = rows[0][3]
    return DisturbanceTradeoff(
        model=nm.name,
        sensors=C,
        family="grid" if grid is not None else "ray",
        direction=L0,
        points=points,
        sources=first.sources,
        outputs=first.outputs,
        intensity=first.intensity or (),
        time_unit=dict(nm.units).get("t", ""),
        warnings=tuple(warnings),
    )
