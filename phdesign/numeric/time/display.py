r"""How a simulation shows itself: ``str`` is the CSV of ``phdesign simulate``, ``.plot()``.

A mixin of :class:`~phdesign.numeric.time.result.SimulationResult` (which owns the numbers):
a one-line ``repr`` with the energies at both ends, ``str`` as the command line prints it
(CSV: t, H, H_hat, H_err, the outputs and the tip displacement), ``_repr_html_`` for
notebooks, and :meth:`SimulationDisplay.plot`, the summary figure of ``simulate --plot``.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from phdesign.core.text import REPR_LIMIT, html_table, shorten

if TYPE_CHECKING:  # pragma: no cover - typing only
    import numpy as np
    from matplotlib.figure import Figure

__all__ = ["SimulationDisplay"]


class SimulationDisplay:
    """Printing and plotting of a simulation result (reads its fields only)."""

    t: np.ndarray
    H: np.ndarray
    H_err: np.ndarray | None
    method: str
    resolution: int
    info: dict[str, Any]
    warnings: tuple[str, ...]

    to_csv: Callable[[], str]
    time_below: Callable[[float], float | None]

    @property
    def title(self) -> str:
        """Model, sensors and gain of the run, as the plots' titles state them."""
        parts = [str(self.info.get("model", "simulation"))]
        if "sensors" in self.info:
            parts.append(f"sensors {self.info['sensors']}")
        if "gain" in self.info:
            parts.append(f"L = {self.info['gain']}")
        parts.append(f"{self.method} {self.resolution}")
        return ", ".join(parts)

    def _summary(self) -> list[tuple[str, str]]:
        rows = [
            ("samples", f"{self.t.size} on [{self.t[0]:g}, {self.t[-1]:g}]"),
            ("H(0) → H(T)", f"{self.H[0]:.6g} → {self.H[-1]:.6g}"),
        ]
        if self.H_err is not None:
            rows.append(("H̃(0) → H̃(T)", f"{self.H_err[0]:.6g} → {self.H_err[-1]:.6g}"))
            below = self.time_below(1e-2)
            rows.append(
                ("H̃/H̃(0) < 1e-2 after", "not reached" if below is None else f"{below:.4g}")
            )
            floor = getattr(self, "resolved_floor", None)
            if floor is not None:  # below it, H̃ is made of modes the resolution does not hold
                rows.append(("H̃/H̃(0) resolved down to", f"{floor:.3g}"))
        return rows

    def __str__(self) -> str:
        return self.to_csv()

    def __repr__(self) -> str:
        body = ", ".join(f"{k}: {v}" for k, v in self._summary())
        text = f"SimulationResult({self.title}; {body}; {len(self.warnings)} warning(s))"
        return shorten(text, REPR_LIMIT)

    def _repr_html_(self) -> str:
        rows = [list(row) for row in self._summary()]
        rows += [["warning", w] for w in self.warnings]
        return html_table(["simulation", ""], rows, caption=self.title)

    def plot(
        self,
        path: str | os.PathLike[str] | None = None,
        *,
        force: bool = False,
        title: str | None = None,
    ) -> Figure:
        """Draw the summary figure (:func:`phdesign.plots.plot_simulation`), saved to ``path``."""
        from phdesign.plots import plot_simulation

        return plot_simulation(
            self, path, force=force, title=self.title if title is None else title
        )
