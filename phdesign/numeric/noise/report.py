"""The results of the noise figures (:mod:`~phdesign.numeric.noise.figures`), and how they print.

:class:`NoiseReport` is what ``phdesign noise`` prints (``str(report)``) and writes
(``report.to_dict()``, strict JSON), and what a notebook shows (``_repr_html_``,
``plot()``).  The formatting helpers at the end are shared with the trade-off and the
noise-aware tuning results.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.core.text import gain_text, html_table, measured_text
from phdesign.numeric.noise.lyapunov import TriangularPencil
from phdesign.numeric.noise.settle import Estimate, finite_or_none

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.figure import Figure

__all__ = ["GainEstimate", "NoiseReport"]


@dataclass(frozen=True)
class GainEstimate:
    """The L²-gain from the noise to the error (energy norm) with its verdict.

    Attributes
    ----------
    estimate : Estimate
        The peak over the resolved band at the fine member of each resolution pair; its
        comparison pair is the coarse member's peak over the trimmed band
        (:func:`phdesign.numeric.noise.figures.noise`).
    frequency : float or None
        Where the finest peak lies (rad per unit time): the lowest frequency among peaks
        equal to the tolerance (the damped wave's first resonance, not one of the
        infinitely many after it).
    frequencies : tuple of float
        The peak frequency of every pair.
    band : float or None
        Ω: the peak is taken over |ω| ≤ Ω, the frequencies the finest pair resolves.
    discrete : Estimate or None
        The discretization's own supremum over all frequencies, per resolution.
    discrete_frequency : float or None
        Where the finest discrete supremum lies.
    """

    estimate: Estimate
    frequency: float | None = None
    frequencies: tuple[float, ...] = ()
    band: float | None = None
    discrete: Estimate | None = None
    discrete_frequency: float | None = None

    @classmethod
    def missing(
        cls,
        resolutions: Sequence[int],
        discrete: Estimate | None = None,
        discrete_frequency: float | None = None,
    ) -> GainEstimate:
        """Return a gain that could not be computed (no steady state or no resolved band)."""
        nothing = Estimate("gamma", (), (), False, False, None)
        return cls(nothing, discrete=discrete, discrete_frequency=discrete_frequency)

    @property
    def value(self) -> float | None:
        """γ when converged, else None."""
        return self.estimate.value

    @property
    def converged(self) -> bool:
        """Whether the peak agrees between both members of the finest pair."""
        return self.estimate.converged

    @property
    def diverges(self) -> bool:
        """Whether the in-band peak grows under refinement."""
        return self.estimate.diverges

    def warnings(self, tol: float) -> list[str]:
        """Return what a user must know about this gain."""
        est = self.estimate
        if not est.values:
            if self.discrete is None:
                return []
            return [
                "no eigenvalue of the error system agrees between two resolutions: there is "
                "no resolved frequency band and the L2-gain is not computed"
            ]
        out = []
        if (
            self.frequency is not None
            and self.band is not None
            and self.frequency >= (1 - 1e-6) * self.band
        ):
            out.append(
                f"the L2-gain peaks at the edge of the resolved band (ω = {self.band:.4g}): "
                "its supremum lies at frequencies this resolution does not resolve"
            )
        elif not est.converged and not est.diverges:
            out.append(
                f"the L2-gain peak over the resolved band did not converge to {tol:g} "
                f"({est.values[-1]:.6g} at resolution {est.resolutions[-1]})"
            )
        if est.diverges:
            out.append(
                f"the L2-gain peak grows under refinement (like p^{est.growth:.2f}): the "
                "supremum is approached at ever higher frequencies, not attained"
            )
        top = est.values[-1]
        disc = self.discrete
        if disc is not None and disc.values and disc.values[-1] > top * (1 + 1e-3):
            trend = "grows under refinement" if disc.diverges else "does not converge"
            if disc.converged:
                trend = "converges"
            out.append(
                f"beyond the resolved band (|ω| > {self.band:.4g}) the discretization's own gain "
                f"reaches {disc.values[-1]:.4g} at ω = {self.discrete_frequency:.4g} and {trend}: "
                "unresolved modes, not the PDE's; an observer implemented at this resolution "
                "amplifies sensor noise there"
            )
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (the ``l2_gain`` object of ``phdesign noise --json``)."""
        out = self.estimate.to_dict()
        out.update(
            {
                "frequency": finite_or_none(self.frequency) if self.converged else None,
                "frequencies": [finite_or_none(w) for w in self.frequencies],
                "band": finite_or_none(self.band),
                "discrete_sup": None if self.discrete is None else self.discrete.to_dict(),
                "discrete_sup_frequency": finite_or_none(self.discrete_frequency),
            }
        )
        return out


@dataclass(frozen=True)
class NoiseReport:
    """Noise figures of one observer design (see :mod:`phdesign.numeric.noise.figures`).

    Attributes
    ----------
    model : str
    sensors, gain : ndarray
        C_m and L.
    intensity : tuple of float
        Sensor noise intensities σᵢ².
    input_intensity : tuple of float or None
        Plant input noise intensities (None: no input noise).
    performance : tuple of Estimate
        Steady-state variance of each performance output's estimation error.
    l2_gain : GainEstimate
    error_energy : Estimate
        E[H̃] (diverges for white noise at the boundary).
    resolutions : tuple of int
    method : str
    steady_state : bool
        False when the error system is not exponentially stable (figures infinite).
    output_labels : tuple of str
        The model's output names (to name the sensors).
    warnings : tuple of str
    pencils : tuple of TriangularPencil
        The error system at each resolution (for :meth:`frequency_response`).
    figures : tuple of Estimate
        The caller's further figures (:mod:`phdesign.numeric.noise.metrics`), in order.
    time_unit : str or None
        The model's unit of time (``[units] t``), when it states one: the frequency
        axis of :meth:`plot` is in rad per that unit.
    """

    model: str
    sensors: np.ndarray
    gain: np.ndarray
    intensity: tuple[float, ...]
    input_intensity: tuple[float, ...] | None
    performance: tuple[Estimate, ...]
    l2_gain: GainEstimate
    error_energy: Estimate
    resolutions: tuple[int, ...]
    method: str
    steady_state: bool = True
    output_labels: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()
    pencils: tuple[TriangularPencil, ...] = field(default=(), compare=False, repr=False)
    figures: tuple[Estimate, ...] = ()
    time_unit: str | None = None

    def frequency_response(self, omega: np.ndarray | None = None) -> dict[int, np.ndarray]:
        """Energy-norm gain from the noise to the error at each resolution, at ``omega``.

        Default ``omega``: 400 log-spaced points from 1e-3 Ω to twice the largest
        eigenvalue modulus (Ω the resolved band), as :meth:`plot` draws them.
        """
        if omega is None:
            omega = self.default_frequencies()
        return {
            res: pencil.response(omega)
            for res, pencil in zip(self.resolutions, self.pencils, strict=True)
        }

    def default_frequencies(self) -> np.ndarray:
        """Return the frequency grid of :meth:`frequency_response` and :meth:`plot`."""
        top = max((float(np.max(np.abs(p.eigenvalues))) for p in self.pencils), default=1.0)
        low = 1e-3 * (self.l2_gain.band or 1.0)
        return np.geomspace(low, max(2.0 * top, 10.0 * low), 400)

    def rms(self, name: str | None = None) -> float | None:
        """RMS of a performance output's error (the first by default), None unless converged."""
        est = self.performance_named(name)
        return None if est is None or est.value is None else math.sqrt(est.value)

    def performance_named(self, name: str | None = None) -> Estimate | None:
        """Return the performance estimate called ``name`` (the first when None)."""
        if not self.performance:
            return None
        if name is None:
            return self.performance[0]
        for est in self.performance:
            if est.name == name:
                return est
        known = ", ".join(e.name for e in self.performance)
        raise KeyError(f"no performance output {name!r}; the report has {known}")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary: the contract of ``phdesign noise --json``."""
        performance = []
        for est in self.performance:
            item = {"name": est.name, **est.to_dict()}
            item["variance"] = item.pop("value")
            item["rms"] = None if est.value is None else math.sqrt(est.value)
            performance.append(item)
        return {
            "model": self.model,
            "sensors": self.sensors.tolist(),
            "gain": self.gain.tolist(),
            "intensity": list(self.intensity),
            "input_intensity": None if self.input_intensity is None else [*self.input_intensity],
            "performance": performance,
            "l2_gain": self.l2_gain.to_dict(),
            "error_energy": self.error_energy.to_dict(),
            "figures": [{"name": est.name, **est.to_dict()} for est in self.figures],
            "resolutions": list(self.resolutions),
            "method": self.method,
            "steady_state": self.steady_state,
            "warnings": list(self.warnings),
        }

    def header(self) -> str:
        """Return the first line: model, sensors, gain and intensities."""
        noise = f"sensor noise intensity {_numbers(self.intensity)}"
        if self.input_intensity is not None:
            noise += f", input noise intensity {_numbers(self.input_intensity)}"
        sensors = measured_text(self.sensors)
        gain = gain_text(self.gain)
        return f"model: {self.model}   sensors: {sensors}   gain L = {gain}   {noise}"

    def __str__(self) -> str:
        res = ", ".join(str(r) for r in self.resolutions)
        lines = [self.header(), f"steady-state error ({self.method}, resolutions {res}):"]
        if not self.performance:
            lines.append("  performance outputs: none")
        for est in self.performance:
            if est.value is not None:
                lines.append(
                    f"  Var[{est.name}~] = {est.value:.10g}   rms {math.sqrt(est.value):.6g}   "
                    f"{est.status()}"
                )
            elif est.approximate() is not None:  # its value to the digits that agree
                rms = est.rounded(math.sqrt(est.values[-1]))
                lines.append(f"  Var[{est.name}~] {est.approximate()}   rms ≈ {rms}")
            else:
                lines.append(f"  Var[{est.name}~]: {est.status()}")
        g = self.l2_gain
        if g.value is not None:
            lines.append(
                f"  L2-gain noise -> error (energy norm): {g.value:.10g} at "
                f"ω = {g.frequency:.6g}   "
                f"{g.estimate.status()}, over the resolved band |ω| <= {g.band:.4g}"
            )
        else:
            shown = g.estimate.approximate()
            lines.append(
                "  L2-gain noise -> error (energy norm)"
                + (f": {g.estimate.status()}" if shown is None else f" {shown}")
            )
        energy = self.error_energy
        values = ", ".join(f"{v:.4g}" for v in energy.values)
        verdict = "infinite for the PDE" if energy.diverges else energy.status()
        if energy.value is not None:
            verdict = f"{energy.value:.10g}   {energy.status()}"
        elif energy.approximate() is not None:
            verdict = str(energy.approximate())
        elif energy.diverges:
            verdict = f"{energy.status()}: infinite for the PDE"
        lines.append(f"  expected error energy E[H~]: {verdict} ({values} at resolutions {res})")
        lines += [f"  {est}" for est in self.figures]
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def __repr__(self) -> str:
        first = self.performance[0] if self.performance else None
        perf = f"{first.name}: {first.status()}" if first else "no performance output"
        text = (
            f"NoiseReport(model={self.model!r}, gain={gain_text(self.gain)}, {perf}, "
            f"l2_gain={self.l2_gain.estimate.status()}, error_energy="
            f"{self.error_energy.status()})"
        )
        return text if len(text) <= 300 else text[:296] + "...)"

    def _repr_html_(self) -> str:
        rows = []
        for est in self.performance:
            value = "—" if est.value is None else f"{est.value:.8g}"
            rms = "—" if est.value is None else f"{math.sqrt(est.value):.6g}"
            if est.rounded() is not None:  # not converged: to the digits that agree
                value, rms = f"≈ {est.rounded()}", f"≈ {est.rounded(math.sqrt(est.values[-1]))}"
            rows.append((f"Var[{est.name}~]", value, rms, est.status()))
        g = self.l2_gain
        where = "" if g.value is None else f" at ω = {g.frequency:.4g}"
        rows.append(
            ("L2-gain", "—" if g.value is None else f"{g.value:.8g}", where, g.estimate.status())
        )
        e = self.error_energy
        rows.append(("E[H~]", "—" if e.value is None else f"{e.value:.6g}", "", e.status()))
        return html_table(("figure", "value", "rms / where", "verdict"), rows, self.header())

    def plot(self, path: Any = None, *, force: bool = False) -> Figure:
        """Frequency response per resolution and the figures under refinement."""
        from phdesign.plots.noise import plot_noise_report

        return plot_noise_report(self, path, force=force)


def _numbers(values: Sequence[float] | np.ndarray) -> str:
    return ", ".join(f"{float(v):.6g}" for v in values)
