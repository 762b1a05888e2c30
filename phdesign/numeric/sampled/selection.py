"""The report of an exported observer's order selection: each candidate, and the choice.

:func:`phdesign.numeric.sampled.order.select_order` tries Galerkin observers (and their
reductions) against two targets and returns an :class:`OrderSelection`, which says what
was chosen, how it met the targets and what was dropped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from phdesign.core.text import html_table

__all__ = ["Candidate", "OrderSelection"]


@dataclass(frozen=True)
class Candidate:
    """One observer tried by :func:`select_order` and how it met the targets."""

    degree: int
    order: int
    reduction: str
    eigen_error: float | None
    floor: float
    spurious: int
    spectral: bool
    passed: bool

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return {
            "degree": self.degree,
            "order": self.order,
            "reduction": self.reduction,
            "eigen_error": self.eigen_error,
            "floor": _finite(self.floor),
            "spurious_poles": self.spurious,
            "meets_spectral_target": self.spectral,
            "passed": self.passed,
        }


def _finite(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


@dataclass(frozen=True)
class OrderSelection:
    """How the exported observer's order was chosen, and what was dropped.

    Attributes
    ----------
    degree, order : int
        Galerkin degree and number of states of the exported observer.
    reduction : str
    full_order : int
        States of the Galerkin observer of that degree, before any reduction.
    plant_degree, plant_order : int
        The verification plant the targets were checked against.
    tol, output_tol : float
        The spectral and performance targets.
    abscissa : float or None
        The converged spectral abscissa of the error system.
    eigen_error, floor : float or None
        The chosen observer's spectral error and relative continuous performance floor.
    spurious, spurious_max_real
        Poles right of the converged abscissa and the largest real part among them.
    dropped : tuple of str
    hankel : tuple of float
        Hankel singular values relative to the largest (balanced truncation only).
    candidates : tuple of Candidate
    warnings : tuple of str
    """

    degree: int
    order: int
    reduction: str
    full_order: int
    plant_degree: int
    plant_order: int
    tol: float
    output_tol: float
    abscissa: float | None
    eigen_error: float | None
    floor: float
    spurious: int
    spurious_max_real: float | None
    dropped: tuple[str, ...]
    hankel: tuple[float, ...] = ()
    candidates: tuple[Candidate, ...] = field(default=(), repr=False)
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (strict JSON: null for what is not finite)."""
        return {
            "degree": self.degree,
            "order": self.order,
            "reduction": self.reduction,
            "full_order": self.full_order,
            "plant_degree": self.plant_degree,
            "plant_order": self.plant_order,
            "tol": self.tol,
            "output_tol": self.output_tol,
            "abscissa": _finite(self.abscissa),
            "eigen_error": _finite(self.eigen_error),
            "floor": _finite(self.floor),
            "spurious_poles": self.spurious,
            "spurious_max_real": _finite(self.spurious_max_real),
            "dropped": list(self.dropped),
            "hankel": [float(s) for s in self.hankel],
            "candidates": [c.to_dict() for c in self.candidates],
            "warnings": list(self.warnings),
        }

    def __repr__(self) -> str:
        eig = "None" if self.eigen_error is None else f"{self.eigen_error:.2g}"
        return (
            f"OrderSelection(degree={self.degree}, order={self.order}, "
            f"reduction={self.reduction!r}, floor={self.floor:.3g}, eigen_error={eig})"
        )

    def __str__(self) -> str:
        eig = "n/a" if self.eigen_error is None else f"{self.eigen_error:.2g}"
        lines = [
            f"order: {self.order} states (Galerkin degree {self.degree}, reduction "
            f"{self.reduction}, from {self.full_order}); verification plant: degree "
            f"{self.plant_degree}, {self.plant_order} states",
            f"targets: rightmost eigenvalues to {self.tol:g} (reached {eig}), performance "
            f"floor {self.output_tol:g} of the peak (reached {self.floor:.3g})",
        ]
        lines += [f"dropped: {line}" for line in self.dropped]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rows = [
            (
                c.degree,
                c.order,
                c.reduction,
                "n/a" if c.eigen_error is None else f"{c.eigen_error:.2g}",
                f"{c.floor:.3g}",
                "yes" if c.passed else "no",
            )
            for c in self.candidates
        ]
        headers = ("degree", "order", "reduction", "eigenvalue error", "floor", "meets targets")
        caption = f"order {self.order} (degree {self.degree}, {self.reduction})"
        return html_table(headers, rows, caption)
