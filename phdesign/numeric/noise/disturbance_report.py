"""What ``phdesign gain`` prints and writes: :class:`GainReport` (:mod:`.disturbance`).

The H∞ norm (the L²-gain, with its frequency) and the H₂ norm from the disturbances (and
sensor noise) to the performance outputs, each with its verdict under refinement, split
per source; ``str(report)`` is the command's text, ``report.to_dict()`` its ``--json``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from phdesign.core.text import gain_text, html_table, measured_text
from phdesign.numeric.noise.optimal import OptimalEstimators
from phdesign.numeric.noise.report import GainEstimate
from phdesign.numeric.noise.settle import Estimate

__all__ = ["GainReport", "SourceFigures"]


@dataclass(frozen=True)
class SourceFigures:
    """The H∞ and H₂ norms from one source (``w1``, ``u2``, ``nu1``) to the outputs."""

    source: str
    hinf: GainEstimate
    h2: Estimate

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return {"source": self.source, "hinf": self.hinf.to_dict(), "h2": self.h2.to_dict()}


def _norm_text(est: Estimate) -> str:
    """``0.5773502692   converged (9.3 digits)``, ``≈ 0.577, ...`` or the verdict."""
    if est.value is not None:
        return f"{est.value:.10g}   {est.status()}"
    shown = est.approximate()
    return shown if shown is not None else est.status()


def _hinf_text(g: GainEstimate) -> str:
    if g.value is None:
        shown = g.estimate.approximate()
        return shown if shown is not None else g.estimate.status()
    return (
        f"{g.value:.10g} at ω = {g.frequency:.6g}   {g.estimate.status()}, "
        f"over the resolved band |ω| <= {g.band:.4g}"
    )


@dataclass(frozen=True)
class GainReport:
    """H∞ and H₂ norms from the disturbances to the performance outputs (one design).

    Attributes
    ----------
    model : str
    sensors, gain : ndarray or None
        C_m and L of the observer; None for the plant.
    intensity : tuple of float or None
        Sensor noise intensities σᵢ² (None for the plant).
    sources, outputs : tuple of str
        The disturbance sources (``w1..wq`` of B, ``u<j>`` unknown inputs, ``nu<i>``
        sensor noise) and the performance outputs.
    hinf : GainEstimate
        The H∞ norm from all sources (unit white, σᵢ-weighted noise) to the outputs.
    h2 : Estimate
        The H₂ norm from all sources to the outputs.
    h2_outputs : tuple of Estimate
        The H₂ norm from all sources to each output alone.
    by_source : tuple of SourceFigures
    resolutions : tuple of int
    method : str
    tol : float
    unstable : (int, complex) or None
        A resolution at which the system is not exponentially stable, and its eigenvalue.
    output_labels : tuple of str
        The model's outputs (to name the sensors).
    time_unit : str or None
    optimal : OptimalEstimators or None
        The Kalman–Bucy filter's H₂ error and the H∞-optimal level γ* of the same plant,
        disturbances and sensor noise (:mod:`phdesign.numeric.noise.optimal`).
    """

    model: str
    sensors: np.ndarray | None
    gain: np.ndarray | None
    intensity: tuple[float, ...] | None
    sources: tuple[str, ...]
    outputs: tuple[str, ...]
    hinf: GainEstimate
    h2: Estimate
    h2_outputs: tuple[Estimate, ...]
    by_source: tuple[SourceFigures, ...]
    resolutions: tuple[int, ...]
    method: str
    tol: float
    unstable: tuple[int, complex] | None = None
    output_labels: tuple[str, ...] = ()
    time_unit: str | None = None
    optimal: OptimalEstimators | None = None

    @property
    def plant(self) -> bool:
        """Whether the report is the plant's (no observer)."""
        return self.sensors is None

    @property
    def warnings(self) -> tuple[str, ...]:
        """What a user must know: no steady state, diverging or unconverged figures."""
        out = []
        if self.unstable is not None:
            res, lam = self.unstable
            what = "plant" if self.plant else "error system"
            out.append(
                f"the {what} is not exponentially stable at resolution {res} (eigenvalue "
                f"{lam:.6g}): the H∞ and H₂ norms are infinite"
            )
            return tuple(out)
        out += self.hinf.warnings(self.tol)
        for est in (*self.h2_outputs, *(s.h2 for s in self.by_source)):
            out += _h2_warning(est)
        return tuple(out)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary: the contract of ``phdesign gain --json``."""
        h2_outputs = [
            {"name": n, **e.to_dict()} for n, e in zip(self.outputs, self.h2_outputs, strict=True)
        ]
        return {
            "model": self.model,
            "sensors": None if self.sensors is None else self.sensors.tolist(),
            "gain": None if self.gain is None else self.gain.tolist(),
            "intensity": None if self.intensity is None else list(self.intensity),
            "sources": list(self.sources),
            "outputs": list(self.outputs),
            "hinf": self.hinf.to_dict(),
            "h2": self.h2.to_dict(),
            "h2_outputs": h2_outputs,
            "by_source": [s.to_dict() for s in self.by_source],
            "resolutions": list(self.resolutions),
            "method": self.method,
            "steady_state": self.unstable is None,
            "optimal": None if self.optimal is None else self.optimal.to_dict(),
            "warnings": list(self.warnings),
        }

    def header(self) -> str:
        """Return the first line: the model, the design and the sources."""
        if self.sensors is None:
            design = "plant (known inputs at zero)"
        else:
            noise = ", ".join(f"{s:.6g}" for s in self.intensity or ())
            design = (
                f"sensors: {measured_text(self.sensors)}   gain L = {gain_text(self.gain)}   "
                f"sensor noise intensity {noise}"
            )
        return f"model: {self.model}   {design}   sources: {', '.join(self.sources)}"

    def __str__(self) -> str:
        res = ", ".join(str(r) for r in self.resolutions)
        target = "z_p" if self.plant else "the error of z_p"
        lines = [
            self.header(),
            f"performance outputs z_p: {', '.join(self.outputs)} "
            f"({self.method}, resolutions {res})",
            f"  H∞ (L2-gain) sources -> {target}: {_hinf_text(self.hinf)}",
            f"  H2 sources -> {target}: {_norm_text(self.h2)}",
        ]
        if len(self.outputs) > 1:
            lines += [
                f"    H2 to {name}: {_norm_text(e)}"
                for name, e in zip(self.outputs, self.h2_outputs, strict=True)
            ]
        if len(self.by_source) > 1:
            lines.append("  by source:")
            for s in self.by_source:
                lines.append(f"    {s.source}: H∞ {_hinf_text(s.hinf)}")
                lines.append(f"    {' ' * len(s.source)}  H2 {_norm_text(s.h2)}")
        lines += self._optimal_lines()
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def _optimal_lines(self) -> list[str]:
        """Return the optimal full-order estimators' lines (none for the plant)."""
        opt = self.optimal
        if self.plant or opt is None:
            return []
        if opt.h2 is None or opt.hinf is None:
            return [f"  optimal full-order estimators: not computed ({opt.note})"]
        lines = ["  optimal full-order estimators of the same plant, disturbances and noise:"]
        for label, est, mine in (
            ("Kalman-Bucy H2 error", opt.h2, self.h2),
            ("H∞-optimal level γ*", opt.hinf, self.hinf.estimate),
        ):
            ratio = ""
            if est.value and mine.value is not None:
                ratio = f"; this observer: {mine.value / est.value:.4g} x"
            lines.append(f"    {label}: {_norm_text(est)}{ratio}")
        return lines

    def __repr__(self) -> str:
        return (
            f"GainReport(model={self.model!r}, sources={list(self.sources)}, "
            f"hinf={self.hinf.estimate.status()}, h2={self.h2.status()})"
        )

    def _repr_html_(self) -> str:
        rows = [("H∞", _hinf_text(self.hinf)), ("H2", _norm_text(self.h2))]
        rows += [
            (f"H2 to {n}", _norm_text(e))
            for n, e in zip(self.outputs, self.h2_outputs, strict=True)
        ]
        rows += [(f"H∞ from {s.source}", _hinf_text(s.hinf)) for s in self.by_source]
        rows += [(f"H2 from {s.source}", _norm_text(s.h2)) for s in self.by_source]
        return html_table(("figure", "value and verdict"), rows, self.header())


def _h2_warning(est: Estimate) -> list[str]:
    values = ", ".join(f"{v:.4g}" for v in est.values)
    at = ", ".join(str(r) for r in est.resolutions)
    if est.diverges:
        grows = "" if est.growth is None else f", grows like p^{est.growth:.2f}"
        return [
            f"{est.name} diverges under refinement ({values} at resolutions {at}{grows}): its "
            "response does not decay at high frequencies (a boundary trace driven at the "
            "boundary), so white disturbances give it an infinite variance"
        ]
    if not est.converged and all(map(math.isfinite, est.values)) and len(est.values) >= 2:
        return [f"{est.name} did not converge ({values} at resolutions {at})"]
    return []
