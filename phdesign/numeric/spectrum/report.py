"""The result of :func:`phdesign.numeric.spectrum.converged.spectrum`, and how it shows itself.

``str(report)`` is exactly what ``phdesign spectrum`` prints, ``report.to_dict()`` what
``phdesign spectrum --json`` prints (strict JSON: non-finite numbers are ``null``),
``report._repr_html_()`` a small table for notebooks and ``report.plot()`` the
eigenvalues in the complex plane (matplotlib imported when called).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.core.text import html_table
from phdesign.numeric.spectrum.eigen import roundoff_bound

if TYPE_CHECKING:  # pragma: no cover - typing only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from phdesign.numeric.spectrum.branches import Branches
    from phdesign.numeric.spectrum.modes import ModalTable

__all__ = ["RefinementStep", "SpectrumReport", "finite_or_none"]


def finite_or_none(x: float | None) -> float | None:
    """``x`` as a float, or None when it is None or not finite (strict JSON)."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def _complex_list(values: Sequence[complex] | np.ndarray) -> list[list[float | None]]:
    return [[finite_or_none(z.real), finite_or_none(z.imag)] for z in np.asarray(values).ravel()]


@dataclass(frozen=True)
class RefinementStep:
    """One resolution pair tried by the refinement.

    Attributes
    ----------
    resolutions : tuple of int
    n_resolved : int
        Resolved eigenvalues at the pair.
    spectral_abscissa, uncertainty : float or None
        The pair's abscissa and its accuracy.
    kind : str
        ``"attained"``, ``"limit"``, ``"extinct"`` or ``"none"``
        (:class:`phdesign.numeric.spectrum.abscissa.Abscissa`).
    converged : bool
        Whether the pair satisfies the convergence rule.
    all_max_real : float
        Max Re over every discrete eigenvalue of the finer resolution.
    n_loose : int
        Unresolved eigenvalues of the resolved band kept (members of a cluster or
        ill-conditioned).
    """

    resolutions: tuple[int, int]
    n_resolved: int
    spectral_abscissa: float | None
    uncertainty: float | None
    kind: str
    converged: bool
    all_max_real: float
    n_loose: int = 0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (``abscissa_drift`` and ``n_loose`` as in earlier versions)."""
        return {
            "resolutions": list(self.resolutions),
            "n_resolved": self.n_resolved,
            "n_loose": self.n_loose,
            "spectral_abscissa": finite_or_none(self.spectral_abscissa),
            "abscissa_drift": finite_or_none(self.uncertainty),
            "uncertainty": finite_or_none(self.uncertainty),
            "kind": self.kind,
            "converged": self.converged,
            "all_max_real": finite_or_none(self.all_max_real),
        }


@dataclass(frozen=True)
class SpectrumReport:
    """Result of :func:`phdesign.numeric.spectrum.converged.spectrum`.

    Attributes
    ----------
    spectral_abscissa : float or None
        The abscissa (:mod:`phdesign.numeric.spectrum.abscissa`): the largest real part among the
        counted eigenvalues, or the limit their real parts approach at high frequency
        (``kind == "limit"``); None when unbounded below or nothing is resolved.
    rightmost : list of complex
        Counted eigenvalues with the largest real parts (finer resolution), conjugate
        pairs kept, sorted by decreasing real part then increasing |Im|; none lies right
        of the abscissa.
    converged : bool
        The chosen pair satisfies the convergence rule (:func:`spectrum`).
    digits : float or None
        Correct digits of the abscissa, relative to max(rate, |α|).
    n_resolved, n_total : int
        Resolved eigenvalues and all eigenvalues at the finer resolution.
    resolutions : tuple of int
        The chosen resolution pair.
    method, system : str
        Discretization and which system (plant or observer error system).
    unbounded_below : bool
        Evidence of an empty spectrum (finite-time extinction).
    ill_conditioned : bool
        The rightmost eigenvalue is ill-conditioned (near a coalescence).
    condition_numbers : list of float
        Energy-norm condition numbers of ``rightmost``.
    all_eigenvalues_max_real : float or None
        max Re over ALL discrete eigenvalues at the finer resolution (the trap value).
    history : tuple of RefinementStep
        Every pair tried.
    warnings : list of str
    model : str
        Name of the model.
    uncertainty : float or None
        Accuracy of the abscissa (absolute, in the model's units).
    kind : str
        ``"attained"``, ``"limit"`` (approached at high frequency by no mode),
        ``"unbounded below"`` or ``"not resolved"``.
    no_decay : bool
        The abscissa is consistent with 0: no uniform exponential decay was found.
    rate_scale : float
        The problem's rate (:mod:`phdesign.numeric.scales`) against which tolerances and
        digits are measured.
    eigenvalues : ndarray of complex
        Every eigenvalue at the finer resolution of the chosen pair.
    resolved : ndarray of bool
        Mask of the resolved ones.
    sensors, gain : list of list of float or None
        C_m and L of the error system (None for the plant).
    branches : Branches or None
        The structure above the band (:mod:`phdesign.numeric.spectrum.branches`): the families of
        the principal part, its onset and the chains' limits.
    complete_band : float or None
        Every eigenvalue up to this modulus is resolved (``inf``: all of them).
    kept : ndarray of bool
        Mask of the unresolved eigenvalues kept in the resolved band (members of a cluster
        or ill-conditioned, near a coalescence).
    real_accuracy : ndarray of float
        Accuracy of the real part of each resolved or kept eigenvalue (``nan`` elsewhere).
    condition_all : ndarray of float
        Energy-norm condition number of every eigenvalue (empty when not computed).
    time_unit : str or None
        The model's unit of time (``[units] t``), when it states one.
    """

    spectral_abscissa: float | None
    rightmost: list[complex]
    converged: bool
    digits: float | None
    n_resolved: int
    n_total: int
    resolutions: tuple[int, int]
    method: str
    system: str
    unbounded_below: bool = False
    ill_conditioned: bool = False
    condition_numbers: list[float] = field(default_factory=list)
    all_eigenvalues_max_real: float | None = None
    history: tuple[RefinementStep, ...] = ()
    warnings: list[str] = field(default_factory=list)
    model: str = ""
    uncertainty: float | None = None
    kind: str = "attained"
    no_decay: bool = False
    rate_scale: float = 1.0
    eigenvalues: np.ndarray = field(default_factory=lambda: np.zeros(0, complex), repr=False)
    resolved: np.ndarray = field(default_factory=lambda: np.zeros(0, bool), repr=False)
    sensors: list[list[float]] | None = None
    gain: list[list[float]] | None = None
    branches: Branches | None = None
    complete_band: float | None = None
    kept: np.ndarray = field(default_factory=lambda: np.zeros(0, bool), repr=False)
    real_accuracy: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    condition_all: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    time_unit: str | None = None

    # -- text -------------------------------------------------------------------------

    def abscissa_text(self) -> str:
        """Return the abscissa as the command line prints it (value ± accuracy, or what it is)."""
        if self.unbounded_below:
            return "unbounded below (finite-time extinction: the spectrum is empty)"
        if self.spectral_abscissa is None:
            top = self.resolutions[1]
            return f"not resolved at these resolutions (up to {top})"
        text = f"{self.spectral_abscissa:.12g}"
        if self.kind == "lower bound":
            return f">= {text} (a lower bound: the band does not reach the onset)"
        if self.uncertainty is not None:
            text += f" ± {self.uncertainty:.2g}"
        if self.kind == "limit":
            text += " (limit at high frequency, attained by no mode)"
        return text

    def __str__(self) -> str:
        header = f"model: {self.model}   system: {self.system}   method: {self.method}"
        lines = [header]
        if self.sensors is not None and self.gain is not None:
            lines.append(f"sensors C_m = {self.sensors}   gain L = {self.gain}")
        line = f"spectral abscissa: {self.abscissa_text()}"
        if self.spectral_abscissa is not None:
            digits = "—" if self.digits is None else f"{self.digits:.1f}"
            line += f"   converged: {self.converged}   digits: {digits}"
        line += (
            f"   resolved: {self.n_resolved}/{self.n_total} "
            f"at resolutions {self.resolutions[0]}, {self.resolutions[1]}"
        )
        lines.append(line)
        if self.rightmost:
            lines.append("rightmost eigenvalues:")
            bounds = roundoff_bound(
                np.asarray(self.rightmost),
                np.asarray(self.condition_numbers),
                self.rate_scale,
                self.n_total,
            )
            for z, c, b in zip(self.rightmost, self.condition_numbers, bounds, strict=False):
                note = "; Re λ > 0 is round-off" if 0 < z.real <= b else ""
                lines.append(f"  {z.real:+.10g} {z.imag:+.10g}i   (condition {c:.3g}{note})")
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def __repr__(self) -> str:
        alpha = "None" if self.spectral_abscissa is None else f"{self.spectral_abscissa:.10g}"
        return (
            f"SpectrumReport(model={self.model!r}, system={self.system!r}, "
            f"spectral_abscissa={alpha}, kind={self.kind!r}, converged={self.converged}, "
            f"resolutions={self.resolutions}, warnings={len(self.warnings)})"
        )

    def _repr_html_(self) -> str:
        rows = [
            ("spectral abscissa", self.abscissa_text()),
            ("converged", str(self.converged)),
            ("digits", "—" if self.digits is None else f"{self.digits:.1f}"),
            ("resolved", f"{self.n_resolved}/{self.n_total}"),
            ("resolutions", f"{self.resolutions[0]}, {self.resolutions[1]}"),
            ("rightmost", ", ".join(f"{z:.6g}" for z in self.rightmost[:4]) or "—"),
        ]
        rows += [("warning", w) for w in self.warnings]
        return html_table((), rows, f"{self.model}: {self.system} ({self.method})")

    # -- data -------------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (complex numbers as ``[re, im]``, strict JSON)."""
        return {
            "model": self.model,
            "spectral_abscissa": finite_or_none(self.spectral_abscissa),
            "rightmost": _complex_list(self.rightmost),
            "converged": self.converged,
            "digits": finite_or_none(self.digits),
            "n_resolved": self.n_resolved,
            "n_total": self.n_total,
            "resolutions": list(self.resolutions),
            "method": self.method,
            "system": self.system,
            "unbounded_below": self.unbounded_below,
            "ill_conditioned": self.ill_conditioned,
            "condition_numbers": [finite_or_none(c) for c in self.condition_numbers],
            "all_eigenvalues_max_real": finite_or_none(self.all_eigenvalues_max_real),
            "history": [step.to_dict() for step in self.history],
            "warnings": list(self.warnings),
            "uncertainty": finite_or_none(self.uncertainty),
            "kind": self.kind,
            "no_decay": self.no_decay,
            "rate_scale": finite_or_none(self.rate_scale),
            "eigenvalues": _complex_list(self.eigenvalues),
            "resolved": [bool(r) for r in self.resolved],
            "sensors": self.sensors,
            "gain": self.gain,
            "complete_band": finite_or_none(self.complete_band),
            "branches": None if self.branches is None else self.branches.to_dict(),
        }

    def modes(self, count: int | None = None) -> ModalTable:
        """Return the first ``count`` resolved modes by frequency (ω_n, f, ζ, decay rate).

        See :func:`phdesign.numeric.spectrum.modes.modal_table`.
        """
        from phdesign.numeric.spectrum.modes import modal_table

        return modal_table(self, count)

    def plot(
        self,
        *,
        ax: Axes | None = None,
        exact: np.ndarray | None = None,
        title: str | None = None,
        xlim: tuple[float, float] | None = None,
        ylim: tuple[float, float] | None = None,
    ) -> Figure:
        """Draw the chosen pair's eigenvalues, resolved ones marked, and the abscissa.

        The default window frames the resolved eigenvalues (the unresolved ones run far
        off); see :func:`phdesign.plots.plot_spectrum` for the arguments.
        """
        from phdesign.plots.spectra import plot_spectrum_report

        return plot_spectrum_report(self, ax=ax, exact=exact, title=title, xlim=xlim, ylim=ylim)
