r"""The converged spectrum of the assembled observer-based loop, beside its two blocks.

The assembled pencil :math:`(A, E_2)` of :func:`phdesign.numeric.loop.assemble` (plant and
observer states together, in :math:`(\hat e, \hat e_{obs})`) is solved by shift and invert
(:func:`~phdesign.numeric.loop.pencil_eigen`) at resolutions p and ⌈1.5 p⌉, and only the
eigenvalues that agree are kept, with the drift rule of :mod:`phdesign.numeric.spectrum`
(:func:`~phdesign.numeric.spectrum.match_resolved`; unresolved eigenvalues inside the
resolved band kept when clustered or ill-conditioned, as near a coalescence).  The
abscissa is the resolved eigenvalue with the largest real part less its drift; the pair
refines until it agrees to ``tol``, until refinement stops helping an ill-conditioned
abscissa, or up to the largest resolution.  The two blocks, the controlled plant and the
error system, are refined on their own by :func:`~phdesign.numeric.spectrum.spectrum`;
by separation the loop's abscissa is the larger of theirs, and the report says by how
much it differs (``separation_gap``) and which block holds each eigenvalue.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import scipy.linalg as sl

from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretize import discretize
from phdesign.numeric.loop import LoopSystem, NumericLoop, assemble, pencil_eigen
from phdesign.numeric.spectrum import (
    SpectrumReport,
    default_resolutions,
    in_band_unresolved,
    match_resolved,
    spectrum,
)

__all__ = ["ILL_CONDITION", "LoopSpectrum", "loop_spectrum"]

ILL_CONDITION = 1e4  # condition number above which the rightmost eigenvalue is flagged


@dataclass(frozen=True)
class _Pair:
    """One resolution pair of the assembled loop, through the drift test."""

    resolutions: tuple[int, int]
    lam: np.ndarray
    kappa: np.ndarray
    counted: np.ndarray  # indices of resolved and kept in-band eigenvalues
    n_tight: int
    alpha: float | None
    d_alpha: float
    lead_loose: bool


def _drift_pair(
    solve: Callable[[int], tuple[np.ndarray, np.ndarray | None]],
    coarse: np.ndarray,
    p: int,
    rtol: float,
) -> _Pair:
    fine_res = math.ceil(1.5 * p)
    fine, kappa = solve(fine_res)
    assert kappa is not None  # solve computes condition numbers unless told otherwise
    idx, _ = match_resolved(fine, coarse, rtol)
    loose, _ = in_band_unresolved(fine, idx, kappa)
    counted = np.concatenate([idx, loose]).astype(int)
    alpha, d_alpha, lead_loose = None, math.inf, False
    if idx.size:
        lam = fine[counted]
        nearest = coarse[np.argmin(np.abs(coarse[None, :] - lam[:, None]), axis=1)]
        drifts = np.abs(lam.real - nearest.real)
        # as spectrum(): the largest real part less its drift stands for the abscissa
        j = int(np.argmax(lam.real - drifts))
        alpha, d_alpha = float(lam.real[j]), float(drifts[j])
        lead_loose = j >= idx.size
    return _Pair((p, fine_res), fine, kappa, counted, int(idx.size), alpha, d_alpha, lead_loose)


@dataclass(frozen=True)
class LoopSpectrum:
    """Converged spectrum of the assembled loop, with those of its two blocks.

    Attributes
    ----------
    spectral_abscissa : float or None
        Of the assembled loop (plant and observer states together).
    converged : bool
        The loop's abscissa agrees to ``tol`` between the last two resolutions.
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
            lines.append("loop spectral abscissa: unbounded below (no eigenvalue converges)")
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
        from html import escape

        rows = "".join(
            f"<tr><td>{escape(k)}</td><td>{escape(str(v))}</td></tr>"
            for k, v in (
                ("loop abscissa", self.spectral_abscissa),
                ("converged", self.converged),
                ("digits", _digits(self.digits)),
                ("controlled plant", self.plant_abscissa),
                ("error system", self.error_abscissa),
                ("separation gap", self.separation_gap),
            )
        )
        return f"<table><caption>{escape(self.model)} loop spectrum</caption>{rows}</table>"

    def plot(self, ax: Any = None) -> Any:
        """Draw the rightmost resolved loop eigenvalues, marked by the block they belong to."""
        from phdesign.plots import new_figure

        if ax is None:
            _, ax = new_figure(figsize=(5, 4))
        for kind, marker in (("plant", "o"), ("error", "x")):
            z = np.array(
                [w for w, o in zip(self.rightmost, self.origin, strict=True) if o == kind]
            )
            if z.size:
                ax.plot(z.real, z.imag, marker, ls="none", label=f"{kind} block")
        if self.spectral_abscissa is not None:
            ax.axvline(self.spectral_abscissa, color="k", lw=0.8, label="loop abscissa")
        ax.set_xlabel("Re λ")
        ax.set_ylabel("Im λ")
        ax.legend()
        return ax.figure


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


def loop_spectrum(
    nm: NumericModel,
    loop: NumericLoop,
    *,
    method: str = "galerkin",
    resolution: int | None = None,
    max_resolution: int | None = None,
    tol: float | None = None,
    rtol_resolved: float | None = None,
    count: int = 6,
    design: str = "",
) -> LoopSpectrum:
    r"""Converged spectrum of the assembled loop, and of the controlled plant and error system.

    The two blocks are refined by :func:`~phdesign.numeric.spectrum.spectrum` (the
    controlled plant as the discretization closed by :math:`S_a^\top K S_a`, the same
    matrix as the model closed by ``[feedback]``).  The assembled pencil
    :math:`(A, E_2)` is refined from the finer of their starting resolutions with the same
    drift rule (:func:`~phdesign.numeric.spectrum.match_resolved`, in-band clusters kept),
    until its abscissa agrees to ``tol``.

    Parameters
    ----------
    nm : NumericModel
    loop : NumericLoop
    method, resolution, max_resolution, tol, rtol_resolved, count
        As for :func:`~phdesign.numeric.spectrum.spectrum`.
    design : str
        A label of the design for the report.

    Returns
    -------
    LoopSpectrum
    """
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
    plant = replace(
        spectrum(nm, S_a, np.asarray(loop.K, float), resolution=resolution, **options),
        system="controlled plant (u_a = -K y_a)",
    )
    error = spectrum(nm, loop.C_m, loop.L, resolution=resolution, **options)
    if tol is None:
        tol = 1e-10 if method == "galerkin" else 1e-3
    if rtol_resolved is None:
        rtol_resolved = 1e-6 if method == "galerkin" else 1e-2
    p0, pmax = default_resolutions(nm, method)
    if resolution is None:  # where both blocks converged: usually one pair suffices
        p0 = max(plant.resolutions[0], error.resolutions[0])
    p = int(resolution) if resolution is not None else p0
    pmax = int(max_resolution) if max_resolution is not None else max(pmax, p)
    systems: dict[int, LoopSystem] = {}

    def solve(res: int, condition: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        systems[res] = system = assemble(discretize(nm, method, res), loop)
        return pencil_eigen(system.A, system.E, condition)

    coarse = solve(p, condition=False)[0]
    tried: list[_Pair] = []
    previous = math.inf
    while True:
        pair = _drift_pair(solve, coarse, p, rtol_resolved)
        relative = pair.d_alpha / max(1.0, abs(pair.alpha or 0.0))
        if pair.alpha is not None:
            tried.append(pair)
        if relative <= tol or pair.resolutions[1] >= pmax or _stalled(pair, relative, previous):
            break
        p, coarse, previous = pair.resolutions[1], pair.lam, relative
    chosen = _choose(tried) if tried else pair
    fine_system = systems[chosen.resolutions[1]]
    triangular = max(systems[r].triangular_residual for r in chosen.resolutions)
    A_K, A_err = fine_system.blocks()
    E = fine_system.discrete.E
    blocks = (sl.eigvals(A_K, E), sl.eigvals(A_err, E))
    return _report(nm, chosen, blocks, plant, error, tol, count, method, triangular, design)


def _choose(tried: list[_Pair]) -> _Pair:
    """Return the pair with the most accurate abscissa, unless an earlier one saw further.

    As in :func:`phdesign.numeric.spectrum.spectrum`: an eigenvalue that agreed between
    two resolutions is an eigenvalue, so a pair whose abscissa lies clearly right of the
    most accurate pair's (by far more than both drifts) wins; the finer pair lost it.
    """

    def relative(pair: _Pair) -> float:
        return pair.d_alpha / max(1.0, abs(pair.alpha or 0.0))

    best = min(tried, key=relative)
    assert best.alpha is not None  # tried holds pairs with an abscissa only
    for pair in tried:
        assert pair.alpha is not None
        margin = 100.0 * (pair.d_alpha + best.d_alpha) + 1e-9 * max(1.0, abs(pair.alpha))
        if pair.alpha > best.alpha + margin and relative(pair) <= 1e-6:
            best = pair
    return best


def _stalled(pair: _Pair, relative: float, previous: float) -> bool:
    """Refinement no longer helps: an ill-conditioned abscissa whose drift did not shrink.

    Near a coalescence (a Jordan block of the loop: a plant and an error eigenvalue that
    coincide, coupled by K ỹ_a) round-off, not resolution, limits the digits.
    """
    if pair.alpha is None or relative < 0.1 * previous:
        return False
    lead = int(np.argmax(pair.lam[pair.counted].real))
    return bool(pair.lead_loose or pair.kappa[pair.counted][lead] > ILL_CONDITION)


def _report(
    nm: NumericModel,
    pair: _Pair,
    blocks_lam: tuple[np.ndarray, np.ndarray],
    plant: SpectrumReport,
    error: SpectrumReport,
    tol: float,
    count: int,
    method: str,
    triangular: float,
    design: str,
) -> LoopSpectrum:
    blocks = [a for a in (plant.spectral_abscissa, error.spectral_abscissa) if a is not None]
    warnings = [f"controlled plant: {w}" for w in plant.warnings]
    warnings += [f"error system: {w}" for w in error.warnings]
    if pair.alpha is None:
        warnings.append(
            f"no eigenvalue of the loop converges up to resolution {pair.resolutions[1]}: "
            "its spectral abscissa is unbounded below"
        )
        return LoopSpectrum(
            None,
            False,
            None,
            [],
            [],
            [],
            0,
            int(pair.lam.size),
            pair.resolutions,
            method,
            plant,
            error,
            None,
            triangular,
            True,
            False,
            warnings,
            nm.name,
            design,
        )
    lam, kappa = pair.lam[pair.counted], pair.kappa[pair.counted]
    order = np.lexsort((np.abs(lam.imag), -np.round(lam.real, 12)))[:count]
    rightmost = [complex(z) for z in lam[order]]
    conds = [float(c) for c in kappa[order]]
    alpha, d_alpha = pair.alpha, pair.d_alpha
    converged = d_alpha <= tol * max(1.0, abs(alpha))
    digits = float(-np.log10(max(d_alpha, 1e-17) / max(1.0, abs(alpha))))
    ill = bool(conds and (conds[0] > ILL_CONDITION or pair.lead_loose))
    if ill:
        warnings.append(
            f"the loop's rightmost eigenvalue {rightmost[0]:.6g} is ill-conditioned "
            f"(condition number {conds[0]:.3g}): near a coalescence; few digits are reliable"
        )
    unresolved = np.setdiff1d(np.arange(pair.lam.size), pair.counted)
    right = unresolved[pair.lam.real[unresolved] > alpha + 1e-9 * max(1.0, abs(alpha))]
    band = np.max(np.abs(lam))
    low = right[np.abs(pair.lam[right]) <= band]
    if low.size:
        warnings.append(
            f"{low.size} unresolved eigenvalues of the loop lie right of its abscissa within "
            f"the resolved band (max Re {float(np.max(pair.lam.real[low])):.3g}): check them"
        )
    if not converged:
        warnings.append(
            f"the loop's spectral abscissa did not converge to {tol:g}: it drifts by "
            f"{d_alpha:.2g} between resolutions {pair.resolutions[0]} and {pair.resolutions[1]}"
        )
    gap = alpha - max(blocks) if blocks else None
    if gap is not None and abs(gap) > max(10 * d_alpha, 1e-8) * max(1.0, abs(alpha)):
        warnings.append(
            f"the loop's abscissa differs from max(plant, error) by {gap:.2g}, beyond its "
            "resolved digits: the separation structure is not reproduced (report this)"
        )
    return LoopSpectrum(
        spectral_abscissa=alpha,
        converged=bool(converged),
        digits=digits,
        rightmost=rightmost,
        condition_numbers=conds,
        origin=_tag(rightmost, blocks_lam),
        n_resolved=pair.n_tight,
        n_total=int(pair.lam.size),
        resolutions=pair.resolutions,
        method=method,
        plant=plant,
        error=error,
        separation_gap=gap,
        triangular_residual=triangular,
        ill_conditioned=ill,
        warnings=warnings,
        model=nm.name,
        design=design,
    )
