r"""The converged spectrum of the assembled observer-based loop, beside its two blocks.

The assembled pencil :math:`(A, E_2)` of :func:`phdesign.numeric.control.assembly.assemble` (plant
and
observer states together, in :math:`(\hat e, \hat e_{obs})`) goes through the same
refinement as every spectrum (:func:`phdesign.numeric.spectrum.refinement.refine`: one
drift rule, one abscissa rule, one choice of the pair), with :class:`AssembledLoopSolver`
as its per-resolution solver: the loop assembled on the dimensionless model
(:mod:`phdesign.numeric.scales`; K, C_m and L read the same there) and solved by the shift
and invert of :mod:`phdesign.numeric.spectrum.eigen`.  Shift and invert matters here: a damper on
a derivative trace puts large entries in the coupling block :math:`B_a K \tilde C_a`, and
the QZ algorithm on the assembled pencil lost five to eight digits on the slow modes.
Every eigenvalue of the loop has :math:`\operatorname{Re}\lambda \le 0` (it is
block-triangular with two dissipative blocks), so the shift is safe and a positive
computed real part is round-off.

The two blocks, the controlled plant and the error system, are refined on their own by
:func:`~phdesign.numeric.spectrum.converged.spectrum`; by separation the loop's abscissa is the
larger of theirs, and the report says by how much it differs (``separation_gap``) and
which block holds each eigenvalue.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

import numpy as np

from phdesign.core.defaults import current, method_or_default
from phdesign.core.progress import stage
from phdesign.core.text import html_table
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.control.assembly import LoopSystem, NumericLoop, assemble
from phdesign.numeric.discretization.registry import discretize, feedback_matrix
from phdesign.numeric.scales import dimensionless_model
from phdesign.numeric.spectrum.branches import Branches, merged_branches
from phdesign.numeric.spectrum.converged import (
    RefinementPlan,
    abscissa_digits,
    rightmost_indices,
    spectrum,
)
from phdesign.numeric.spectrum.eigen import SHIFT, rescaled, shift_invert
from phdesign.numeric.spectrum.refinement import (
    Discretizations,
    PairResult,
    choose_pair,
    extinct_twice,
)
from phdesign.numeric.spectrum.report import SpectrumReport
from phdesign.numeric.spectrum.warnings import report_warnings, reported_value
from phdesign.numeric.threads import limited_threads

__all__ = ["AssembledLoopSolver", "LoopSpectrum", "loop_spectrum"]


class AssembledLoopSolver:
    """Eigenvalues of the assembled loop at each resolution (a refinement's solver).

    Assembles the loop on the discretized dimensionless model and solves the pencil
    :math:`(A, E_2)` by shift and invert at :data:`~phdesign.numeric.spectrum.eigen.SHIFT` (module
    docstring), with condition numbers; eigenvalues in the model's units.  The assembled
    systems are kept (``systems[p]``) for the blocks and the triangular residual.
    """

    dissipative = True  # block-triangular with two dissipative blocks: Re λ <= 0

    def __init__(self, nm: NumericModel, loop: NumericLoop, *, method: str) -> None:
        self.dimensionless, self.scales = dimensionless_model(nm)
        self.rate = self.scales.rate
        structure = Discretizations(nm, method)
        m = nm.n_ports
        S_a = loop.selection(m)
        self.branches: Branches | None = merged_branches(
            {
                "controlled plant": structure.branches(S_a.T @ np.asarray(loop.K, float) @ S_a),
                "error system": structure.branches(feedback_matrix(loop.C_m, loop.L, m)),
            }
        )
        self.loop, self.method = loop, method
        self.systems: dict[int, LoopSystem] = {}
        self._cache: dict[int, tuple[np.ndarray, np.ndarray | None]] = {}

    def __call__(self, p: int, condition: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Eigenvalues and energy-norm condition numbers of the loop at resolution ``p``.

        ``condition=False``: the eigenvalues alone
        (:class:`~phdesign.numeric.spectrum.refinement.ResolutionSolver`).
        """
        found = self._cache.get(p)
        if found is None or (condition and found[1] is None):
            if p not in self.systems:
                discrete = discretize(self.dimensionless, self.method, p)
                self.systems[p] = assemble(discrete, self.loop)
            system = self.systems[p]
            lam, kappa = shift_invert(system.A, system.E, shift=SHIFT, condition=condition)
            found = self._cache[p] = (rescaled(lam, self.rate), kappa)
        return found

    def blocks(self, p: int) -> tuple[np.ndarray, np.ndarray]:
        """Eigenvalues of the controlled plant's and the error system's blocks at ``p``."""
        system = self.systems[p]
        E = system.discrete.E
        plant, error = (
            rescaled(shift_invert(block, E, shift=SHIFT)[0], self.rate)
            for block in system.blocks()
        )
        return plant, error


@dataclass(frozen=True)
class LoopSpectrum:
    """Converged spectrum of the assembled loop, with those of its two blocks.

    Attributes
    ----------
    spectral_abscissa : float or None
        Of the assembled loop (plant and observer states together).
    converged : bool
        The spectrum's convergence rule holds for the loop
        (:func:`~phdesign.numeric.spectrum.refinement.convergence_rule`).
    digits : float or None
        Agreeing digits of the loop's abscissa.
    rightmost : list of complex
        Resolved loop eigenvalues with the largest real parts (conjugates kept).
    condition_numbers : list of float
        Their energy-norm condition numbers.
    origin : list of str
        For each of ``rightmost``, the block whose discrete spectrum holds it (``"plant"``
        or ``"error"``) at the same resolution.
    n_resolved, n_total : int
        Resolved and all eigenvalues of the loop at the finer resolution.
    resolutions : tuple of int
    plant, error : SpectrumReport
        The controlled plant (u_a = −K y_a) and the error system, each refined on its own.
    separation_gap : float or None
        ``spectral_abscissa − max(plant, error)``: zero to the resolved digits.
    triangular_residual : float
        The lower-left block of the loop in (ê, ẽ), relative (round-off).
    warnings : list of str
    model, design : str
    uncertainty : float or None
        Accuracy of ``spectral_abscissa`` (absolute; the spectrum's abscissa rule).
    """

    spectral_abscissa: float | None
    converged: bool
    digits: float | None
    rightmost: list[complex]
    condition_numbers: list[float]
    origin: list[str]
    n_resolved: int
    n_total: int
    resolutions: tuple[int, int]
    method: str
    plant: SpectrumReport = field(repr=False)
    error: SpectrumReport = field(repr=False)
    separation_gap: float | None
    triangular_residual: float
    unbounded_below: bool = False
    ill_conditioned: bool = False
    warnings: list[str] = field(default_factory=list)
    model: str = ""
    design: str = ""
    uncertainty: float | None = None

    @property
    def plant_abscissa(self) -> float | None:
        """Converged abscissa of the controlled plant (u_a = −K y_a)."""
        return self.plant.spectral_abscissa

    @property
    def error_abscissa(self) -> float | None:
        """Converged abscissa of the observer error system."""
        return self.error.spectral_abscissa

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (strict JSON: None for what is not a number)."""
        return {
            "model": self.model,
            "design": self.design,
            "spectral_abscissa": _finite(self.spectral_abscissa),
            "converged": self.converged,
            "digits": _finite(self.digits),
            "uncertainty": _finite(self.uncertainty),
            "plant_abscissa": _finite(self.plant_abscissa),
            "plant_converged": self.plant.converged,
            "error_abscissa": _finite(self.error_abscissa),
            "error_converged": self.error.converged,
            "separation_gap": _finite(self.separation_gap),
            "triangular_residual": _finite(self.triangular_residual),
            "rightmost": [[float(z.real), float(z.imag)] for z in self.rightmost],
            "condition_numbers": [_finite(c) for c in self.condition_numbers],
            "origin": list(self.origin),
            "n_resolved": self.n_resolved,
            "n_total": self.n_total,
            "resolutions": list(self.resolutions),
            "method": self.method,
            "unbounded_below": self.unbounded_below,
            "ill_conditioned": self.ill_conditioned,
            "warnings": list(self.warnings),
        }

    def __repr__(self) -> str:
        return (
            f"LoopSpectrum(model={self.model!r}, spectral_abscissa={self.spectral_abscissa}, "
            f"converged={self.converged}, plant={self.plant_abscissa}, "
            f"error={self.error_abscissa})"
        )[:300]

    def __str__(self) -> str:
        """Return the text ``phdesign loop spectrum`` prints."""
        lines = [f"model: {self.model}   loop: {self.design}   method: {self.method}"]
        if self.spectral_abscissa is None:
            lines.append(
                "loop spectral abscissa: "
                + (
                    "unbounded below (no eigenvalue converges)"
                    if self.unbounded_below
                    else "not resolved at these resolutions"
                )
            )
        else:
            lines.append(
                f"loop spectral abscissa: {self.spectral_abscissa:.12g}   converged: "
                f"{self.converged}   digits: {_digits(self.digits)}   resolved: "
                f"{self.n_resolved}/{self.n_total} at resolutions {self.resolutions[0]}, "
                f"{self.resolutions[1]}"
            )
        for name, rep in (
            ("controlled plant (u_a = -K y_a)", self.plant),
            ("observer error system", self.error),
        ):
            value = (
                "unbounded below"
                if rep.spectral_abscissa is None
                else (f"{rep.spectral_abscissa:.12g}")
            )
            lines.append(
                f"{name}: {value}   converged: {rep.converged}   digits: {_digits(rep.digits)}"
            )
        if self.separation_gap is not None:
            lines.append(
                f"separation: loop - max(plant, error) = {self.separation_gap:.2g}; "
                f"lower-left block in (x, x̃) {self.triangular_residual:.1g} (relative)"
            )
        if self.rightmost:
            lines.append("rightmost eigenvalues of the loop:")
            for z, c, o in zip(self.rightmost, self.condition_numbers, self.origin, strict=True):
                lines.append(f"  {z.real:+.10g} {z.imag:+.10g}i   (condition {c:.3g}, {o})")
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rows = (
            ("loop abscissa", self.spectral_abscissa),
            ("converged", self.converged),
            ("digits", _digits(self.digits)),
            ("controlled plant", self.plant_abscissa),
            ("error system", self.error_abscissa),
            ("separation gap", self.separation_gap),
        )
        return html_table((), rows, f"{self.model} loop spectrum")

    def plot(self, ax: Any = None) -> Any:
        """Draw the rightmost resolved loop eigenvalues, marked by the block they belong to."""
        from phdesign.plots.spectra import plot_loop_spectrum

        return plot_loop_spectrum(self, ax)


def _finite(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def _digits(x: float | None) -> str:
    return "—" if x is None else f"{x:.1f}"


def _tag(values: Sequence[complex], blocks: tuple[np.ndarray, np.ndarray]) -> list[str]:
    plant, error = blocks
    out = []
    for z in values:
        dp = np.min(np.abs(plant - z)) if plant.size else np.inf
        de = np.min(np.abs(error - z)) if error.size else np.inf
        out.append("plant" if dp <= de else "error")
    return out


@limited_threads
def loop_spectrum(
    nm: NumericModel,
    loop: NumericLoop,
    *,
    method: str | None = None,
    resolution: int | None = None,
    max_resolution: int | None = None,
    tol: float | None = None,
    rtol_resolved: float | None = None,
    count: int | None = None,
    design: str = "",
) -> LoopSpectrum:
    r"""Converged spectrum of the assembled loop, and of the controlled plant and error system.

    The two blocks are refined by :func:`~phdesign.numeric.spectrum.converged.spectrum` (the
    controlled plant as the discretization closed by :math:`S_a^\top K S_a`, the same
    matrix as the model closed by ``[feedback]``).  The assembled pencil
    :math:`(A, E_2)` is refined by the spectrum's own refinement (module docstring) from the
    finer of their starting resolutions.

    Parameters
    ----------
    nm : NumericModel
    loop : NumericLoop
    method, resolution, max_resolution, tol, rtol_resolved, count
        As for :func:`~phdesign.numeric.spectrum.converged.spectrum`.
    design : str
        A label of the design for the report.

    Returns
    -------
    LoopSpectrum
    """
    method = method_or_default(method)
    count = current().spectrum.count if count is None else count
    m = nm.n_ports
    loop.check(m)
    S_a = loop.selection(m)
    options: dict[str, Any] = {
        "method": method,
        "max_resolution": max_resolution,
        "tol": tol,
        "rtol_resolved": rtol_resolved,
        "count": count,
    }
    with stage("loop: the controlled plant"):
        plant = replace(
            spectrum(nm, S_a, np.asarray(loop.K, float), resolution=resolution, **options),
            system="controlled plant (u_a = -K y_a)",
        )
    with stage("loop: the error system"):
        error = spectrum(nm, loop.C_m, loop.L, resolution=resolution, **options)
    start = None
    if resolution is None:  # where both blocks converged: usually one pair suffices
        start = max(plant.resolutions[0], error.resolutions[0])
    plan = RefinementPlan.of(
        nm,
        method,
        resolution=resolution,
        max_resolution=max_resolution,
        tol=tol,
        rtol_resolved=rtol_resolved,
        start=start,
    )
    solver = AssembledLoopSolver(nm, loop, method=method)
    with stage("loop: the assembled loop"):
        trail = plan.refine(solver)
        chosen, notes = choose_pair(trail)
        blocks = solver.blocks(chosen.pair.resolutions[1])
    triangular = max(solver.systems[r].triangular_residual for r in chosen.pair.resolutions)
    return _report(
        nm, trail, chosen, notes, blocks, plant, error, plan.tol, count, method, triangular, design
    )


def _report(
    nm: NumericModel,
    trail: list[PairResult],
    chosen: PairResult,
    notes: list[str],
    blocks_lam: tuple[np.ndarray, np.ndarray],
    plant: SpectrumReport,
    error: SpectrumReport,
    tol: float,
    count: int,
    method: str,
    triangular: float,
    design: str,
) -> LoopSpectrum:
    warnings = [f"controlled plant: {w}" for w in plant.warnings]
    warnings += [f"error system: {w}" for w in error.warnings]
    a, pair = chosen.abscissa, chosen.pair
    report = partial(  # what both outcomes share: the pair, the blocks, the labels
        LoopSpectrum,
        n_total=int(pair.eigenvalues.size),
        resolutions=pair.resolutions,
        method=method,
        plant=plant,
        error=error,
        triangular_residual=triangular,
        model=nm.name,
        design=design,
    )
    if a.value is None or a.uncertainty is None or a.attained is None:
        return _unresolved(trail, pair.resolutions[1], report, warnings)
    own, ill, no_decay = report_warnings(chosen, a.value, a.uncertainty, a.attained, tol)
    value, uncertainty = reported_value(a.value, a.uncertainty, no_decay)
    warnings += [f"loop: {w}" for w in notes + own]
    lam = pair.eigenvalues
    top = rightmost_indices(chosen, count)
    kappa = pair.condition if pair.condition is not None else np.ones(lam.shape)
    rightmost = [complex(z) for z in lam[top]]
    gap = _separation_gap(value, uncertainty, pair.scale, plant, error, warnings)
    return report(
        spectral_abscissa=value,
        converged=chosen.converged,
        digits=abscissa_digits(chosen),
        rightmost=rightmost,
        condition_numbers=[float(c) for c in kappa[top]],
        origin=_tag(rightmost, blocks_lam),
        n_resolved=pair.n_resolved,
        separation_gap=gap,
        ill_conditioned=ill,
        warnings=warnings,
        uncertainty=uncertainty,
    )


def _unresolved(
    trail: list[PairResult],
    resolution: int,
    report: Callable[..., LoopSpectrum],
    warnings: list[str],
) -> LoopSpectrum:
    """Return the report of a loop whose spectrum no pair resolved (or which is empty)."""
    extinct = extinct_twice(trail)
    warnings.append(
        f"loop: no eigenvalue converges up to resolution {resolution}"
        + (
            ", and every eigenvalue runs off from the origin: the spectrum is empty, its "
            "spectral abscissa unbounded below"
            if extinct
            else ": the loop's spectrum is not resolved at these resolutions"
        )
    )
    return report(
        spectral_abscissa=None,
        converged=False,
        digits=None,
        rightmost=[],
        condition_numbers=[],
        origin=[],
        n_resolved=0,
        separation_gap=None,
        unbounded_below=extinct,
        warnings=warnings,
    )


def _separation_gap(
    value: float,
    uncertainty: float,
    scale: float,
    plant: SpectrumReport,
    error: SpectrumReport,
    warnings: list[str],
) -> float | None:
    """Return the loop's abscissa minus the slower block's; warn beyond the resolved digits.

    By separation the loop's spectrum is the union of the blocks' (module docstring).
    """
    slower = max(
        (r for r in (plant, error) if r.spectral_abscissa is not None),
        key=lambda r: r.spectral_abscissa or -math.inf,
        default=None,
    )
    if slower is None or slower.spectral_abscissa is None:
        return None
    gap = value - slower.spectral_abscissa
    allowed = max(
        10.0 * (uncertainty + (slower.uncertainty or 0.0)), 1e-8 * max(scale, abs(value))
    )
    if abs(gap) > allowed:
        warnings.append(
            f"the loop's abscissa differs from max(plant, error) by {gap:.2g}, beyond its "
            "resolved digits: the separation structure is not reproduced (report this)"
        )
    return gap
