"""The results of the sensor search: the candidates, each subset's verdict, the table.

:func:`~phdesign.symbolic.search.search_sensors` returns a :class:`SensorSearch`: every
applicable variant as a :class:`Candidate` with the unique minimal sensor set that makes it
hold, one :class:`SubsetResult` per non-empty sensor set, and the minimal sets of each
verdict.  ``str()`` is the table ``phdesign classify --all-sensors`` prints, ``to_dict()``
its JSON.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from phdesign.core.errors import ObserverError
from phdesign.core.text import REPR_LIMIT, html_table, kappa_text, shorten
from phdesign.symbolic.assumption import Partition
from phdesign.symbolic.propositions import Case

__all__ = ["Candidate", "SensorSearch", "SubsetResult"]


@dataclass(frozen=True)
class Candidate:
    r"""One case (variant, partition) with the unique minimal sensor set that makes it hold.

    Attributes
    ----------
    case : Case
        The variant, its partition and the traces it selects.
    required : tuple of int
        1-based outputs that must be measured (:math:`B_{\text{variant}}`).
    attainable : bool
        False when no sensor set makes it hold (a direction the plant's own feedback
        leaves undamped breaks it).
    """

    case: Case
    required: tuple[int, ...]
    attainable: bool = True

    @property
    def name(self) -> str:
        """``"3.4.3"``-style name."""
        return self.case.variant.name

    @property
    def partition(self) -> Partition | None:
        """The partition of Assumption 3.1 the case uses (3.4 only)."""
        return self.case.partition

    @property
    def convergence(self) -> str:
        """``"asymptotic"`` or ``"exponential"``."""
        return self.case.variant.convergence


@dataclass(frozen=True)
class SubsetResult:
    """Classification of one sensor subset.

    Attributes
    ----------
    sensors : tuple of int
        1-based measured outputs.
    verdict : str
    best : str or None
        Strongest holding variant (``"3.3.3"``), largest κ* among the same kind.
    kappa : float or None
        κ* of ``best`` (``None`` when unbounded, symbolic gains, or nothing holds).
    unbounded : bool
    holding : tuple of str
        Every holding variant.
    partition : tuple of (tuple, tuple) or None
        The partition (x1, x2) of ``best`` when it is a 3.4 variant.
    """

    sensors: tuple[int, ...]
    verdict: str
    best: str | None
    kappa: float | None
    unbounded: bool
    holding: tuple[str, ...]
    partition: tuple[tuple[int, ...], tuple[int, ...]] | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON form of one subset."""
        out: dict[str, Any] = {
            "sensors": list(self.sensors),
            "verdict": self.verdict,
            "best": self.best,
            "kappa": self.kappa,
            "unbounded": self.unbounded,
            "holding": list(self.holding),
        }
        if self.partition is not None:
            out["partition"] = {"x1": list(self.partition[0]), "x2": list(self.partition[1])}
        return out


@dataclass(frozen=True, repr=False)
class SensorSearch:
    """Result of :func:`search_sensors`; ``str()`` is the table of ``classify --all-sensors``.

    Attributes
    ----------
    model : str
    order, size : int
    gains : tuple of str
        Diagonal gain per output (reused for every subset that measures it).
    candidates : tuple of Candidate
        The variants tried, each with its minimal sensor set.
    subsets : tuple of SubsetResult
        Every non-empty subset, by size then lexicographically.
    minimal : dict
        For each verdict, the minimal sensor sets reaching it.
    """

    model: str
    order: int
    size: int
    gains: tuple[str, ...]
    candidates: tuple[Candidate, ...]
    subsets: tuple[SubsetResult, ...]
    minimal: dict[str, tuple[tuple[int, ...], ...]]

    @property
    def symbolic(self) -> bool:
        """Whether the gains are symbolic (the constants are then not computed)."""
        return all(g == "symbolic" for g in self.gains)

    def subset(self, sensors: Sequence[int]) -> SubsetResult:
        """Return the result of one sensor set."""
        key = tuple(sorted(sensors))
        for s in self.subsets:
            if s.sensors == key:
                return s
        raise ObserverError(
            f"no sensor set {list(key)}; expected distinct outputs in 1..{self.order * self.size}"
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON: every subset with its verdict, and the minimal sets per verdict."""
        return {
            "model": self.model,
            "order": self.order,
            "size": self.size,
            "gain": list(self.gains),
            "decision_path": "exact (combinatorial, gain-independent)",
            "kappa_path": None if self.symbolic else "float",
            "required": {c.name + _partition_suffix(c): list(c.required) for c in self.candidates},
            "subsets": [s.to_dict() for s in self.subsets],
            "minimal": {k: [list(s) for s in v] for k, v in self.minimal.items()},
        }

    # ------------------------------------------------------------------ display
    def _gain_text(self) -> str:
        if self.symbolic:
            return f"diag({', '.join(f'l{j + 1}' for j in range(len(self.gains)))})"
        return f"diag({', '.join(self.gains)})"

    def _kappa(self, s: SubsetResult) -> str:
        if s.best is None or s.best == "ABLV":  # the asymptotic theorem has no κ*
            return "—"
        if self.symbolic:
            return "depends on L"
        return kappa_text(None, s.kappa, s.unbounded)

    def _minimal_lines(self) -> list[str]:
        lines = []
        for verdict, sets in self.minimal.items():
            shown = ", ".join("{" + ",".join(map(str, s)) + "}" for s in sets) or "none"
            lines.append(f"minimal {verdict} sets: {shown}")
        return lines

    def __str__(self) -> str:
        lines = [
            f"model {self.model}: N = {self.order}, n = {self.size}, "
            f"{len(self.subsets)} sensor sets, gains L = {self._gain_text()} "
            "restricted to each set",
        ]
        if self.symbolic:
            lines.append(
                "κ* is not computed for symbolic gains (the verdicts do not depend on them); "
                "classify one set with symbolic gains for κ* as an expression"
            )
        lines += ["", f"{'sensors':<24} {'verdict':<13} {'best':<7} κ*"]
        for s in self.subsets:
            sensors = ",".join(map(str, s.sensors))
            lines.append(f"{sensors:<24} {s.verdict:<13} {s.best or '—':<7} {self._kappa(s)}")
        return "\n".join([*lines, "", *self._minimal_lines()])

    def __repr__(self) -> str:
        minimal = [list(s) for s in self.minimal.get("exponential", ())]
        text = (
            f"SensorSearch(model={self.model!r}, sets={len(self.subsets)}, "
            f"gains={shorten(self._gain_text(), 80)!r}, "
            f"minimal_exponential={shorten(str(minimal), 120)})"
        )
        return shorten(text, REPR_LIMIT)

    def _repr_html_(self) -> str:
        rows = [
            [",".join(map(str, s.sensors)), s.verdict, s.best or "—", self._kappa(s)]
            for s in self.subsets
        ]
        return html_table(
            ["sensors", "verdict", "best", "κ*"],
            rows,
            caption=f"{self.model}: every sensor set, gains L = {self._gain_text()}",
            footer="; ".join(self._minimal_lines()),
        )


def _partition_suffix(c: Candidate) -> str:
    if c.partition is None:
        return ""
    return f" x1={list(c.partition.x1)}"
