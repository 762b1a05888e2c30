r"""Classify a sensor set and gain against every variant of Propositions 3.1 to 3.4.

:func:`classify` builds the error system of the observer
(:mod:`phdesign.symbolic.observer`), checks Assumption 3.1 when :math:`N = 2`
(:mod:`phdesign.symbolic.assumption`), and certifies each variant of
:data:`phdesign.symbolic.propositions.VARIANTS` (:mod:`phdesign.symbolic.certificate`).

Verdict (the propositions are sufficient, not necessary):

* ``exponential`` — a variant of 3.2, 3.3 or 3.4 holds;
* ``asymptotic`` — only 3.1 holds;
* ``inconclusive`` — none holds (never "unstable").

Proposition 3.4 is tried with every partition :math:`x = (x_1, x_2)` that satisfies
Assumption 3.1 (the assumption is symmetric in the blocks, the proposition is not);
a variant holds when it holds for one of them, and the result names that partition.

The :class:`Classification` prints itself: ``str()`` is the table ``phdesign classify``
prints, ``repr()`` one line, ``_repr_html_`` a table for notebooks and :meth:`to_dict`
the JSON of the command line.

Examples
--------
>>> from phdesign.models import load_builtin
>>> from phdesign.symbolic.observer import sensor_matrix
>>> beam = load_builtin("euler-bernoulli")
>>> result = classify(beam, sensor_matrix([3, 4], 4), "symbolic")
>>> result.verdict
'exponential'
>>> r = result.result("3.4", 3)
>>> r.holds, r.kappa
(True, Min(l2, l1/(l1**2 + 1)))
>>> result.result("3.3", 3).reason
'ẽ2(0) is left free by these sensors; fails for all positive gains'
>>> classify(beam, sensor_matrix([4], 4), [0.5])  # doctest: +NORMALIZE_WHITESPACE
Classification(model='euler-bernoulli', sensors='y4', L='diag(0.5)',
               verdict='exponential', best='3.4.4', kappa=0.4)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import sympy

from phdesign.core.checks import choice
from phdesign.core.errors import ObserverError
from phdesign.core.text import (
    REPR_LIMIT,
    html_table,
    kappa_text,
    matrix_text,
    number_text,
    sensors_text,
    shorten,
)
from phdesign.symbolic.assumption import AssumptionCheck, Partition, model_assumption
from phdesign.symbolic.certificate import Certificate, certify
from phdesign.symbolic.coupled_classify import classify_coupled
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import ErrorSystem, ObserverDesign
from phdesign.symbolic.ports import trace_list
from phdesign.symbolic.propositions import (
    PROPOSITIONS,
    VERDICTS,
    Case,
    Variant,
    strength,
    variant_cases,
    verdict_of,
)
from phdesign.symbolic.traces import Trace

__all__ = ["VERDICTS", "Classification", "VariantResult", "classify", "verdict_of"]

#: Width of the κ* column of the table; longer constants move to a note below the row.
KAPPA_WIDTH = 12


@dataclass(frozen=True)
class VariantResult:
    r"""The answer for one variant.

    Attributes
    ----------
    proposition : str
        ``"3.1"`` .. ``"3.4"``.
    variant : int
        1-based, in the paper's order.
    applicable : bool
        Stated for this order (and, for 3.4, Assumption 3.1 holds).
    holds : bool or None
        ``None`` when not applicable.
    kappa : sympy.Expr or None
        Exact (or symbolic) :math:`\kappa^*`; ``None`` if not applicable, failing,
        unbounded, or computed in floating point only.
    kappa_float : float or None
        :math:`\kappa^*` as a float.
    unbounded : bool
        RHS vanishes on the admissible traces: holds for every :math:`\kappa`.
    witness : tuple of (Trace, sympy.Expr) or None
        A failing variant's counter-example :math:`v \in \mathcal K` (non-zero traces).
    free : tuple of Trace
        Selected traces the witness leaves non-zero.
    rhs : str
        The right-hand side in words, in the model's components (``ẽ2'(1)``).
    reason : str
        One sentence: why it holds, why it fails, or why it does not apply.
    path : str or None
        ``"exact"``, ``"float"`` or ``"symbolic"``.
    conditions : str or None
        Range of gains the symbolic answer covers.
    partition : Partition or None
        The partition used (3.4 only).
    certificate : Certificate or None
        The certificate behind the answer (``None`` when not applicable).
    """

    proposition: str
    variant: int
    applicable: bool
    holds: bool | None
    kappa: sympy.Expr | None
    kappa_float: float | None
    unbounded: bool
    witness: tuple[tuple[Trace, sympy.Expr], ...] | None
    free: tuple[Trace, ...]
    rhs: str
    reason: str
    path: str | None = None
    conditions: str | None = None
    partition: Partition | None = None
    certificate: Certificate | None = None

    @property
    def name(self) -> str:
        """``"3.4.3"``-style name."""
        return f"{self.proposition}.{self.variant}"

    @property
    def convergence(self) -> str:
        """``"asymptotic"`` or ``"exponential"``."""
        return PROPOSITIONS[self.proposition].convergence

    @property
    def kappa_text(self) -> str:
        r""":math:`\kappa^*` as every printout shows it (six digits, or the expression)."""
        if not self.applicable or not self.holds:
            return "—"
        return kappa_text(self.kappa, self.kappa_float, self.unbounded)

    def kappa_json(self) -> float | str | None:
        r""":math:`\kappa^*` for the JSON ``kappa`` key.

        ``None`` only when the variant is not applicable or :math:`\kappa^*` is unbounded
        (or has no closed form for symbolic gains); ``0.0`` for a failing variant (its
        witness makes the ratio zero); a float for numeric gains; the exact expression,
        as text, for symbolic gains.
        """
        if not self.applicable or self.unbounded:
            return None
        if not self.holds:
            return 0.0
        if self.kappa_float is not None:
            return self.kappa_float
        return None if self.kappa is None else str(self.kappa)

    def to_dict(self, interval: Sequence[Any] = ("a", "b")) -> dict[str, Any]:
        """JSON form of one variant (``interval`` names the endpoints of the traces)."""
        out: dict[str, Any] = {
            "proposition": self.proposition,
            "variant": self.variant,
            "applicable": self.applicable,
            "holds": self.holds,
            "kappa": self.kappa_json(),
            "kappa_exact": None if self.kappa is None else str(self.kappa),
            "unbounded": self.unbounded,
            "rhs": self.rhs,
            "reason": self.reason,
            "path": self.path,
        }
        if self.conditions is not None:
            out["conditions"] = self.conditions
        if self.partition is not None:
            out["partition"] = {"x1": list(self.partition.x1), "x2": list(self.partition.x2)}
        if self.witness is not None:
            out["witness"] = {t.label(interval, tilde=True): str(x) for t, x in self.witness}
            out["free"] = [t.label(interval, tilde=True) for t in self.free]
        return out


@dataclass(frozen=True, repr=False)
class Classification:
    """The classification of one observer design.

    ``str()`` is the table of ``phdesign classify``; :meth:`to_dict` its JSON.

    Attributes
    ----------
    model : BCPHS
    C_m, L : sympy.ImmutableMatrix
    assumption : AssumptionCheck or None
        Assumption 3.1 (``None`` unless :math:`N = 2`).
    results : tuple of VariantResult
        Every variant of every proposition, in the paper's order.
    verdict : str
        ``"exponential"``, ``"asymptotic"`` or ``"inconclusive"``.
    """

    model: BCPHS
    C_m: sympy.ImmutableMatrix
    L: sympy.ImmutableMatrix
    assumption: AssumptionCheck | None
    results: tuple[VariantResult, ...]
    verdict: str

    def result(self, proposition: str, variant: int) -> VariantResult:
        """Return the result of one variant."""
        for r in self.results:
            if r.proposition == proposition and r.variant == variant:
                return r
        known = ", ".join(r.name for r in self.results)
        raise ObserverError(f"no variant {proposition}.{variant}; expected one of {known}")

    @property
    def best(self) -> VariantResult | None:
        """The holding variant of the strongest kind with the largest constant."""
        holding = [r for r in self.results if r.holds]
        if not holding:
            return None
        return max(holding, key=_strength)

    @property
    def applicable(self) -> tuple[VariantResult, ...]:
        """The variants that apply to this model (the rows of the table)."""
        return tuple(r for r in self.results if r.applicable)

    def to_dict(self) -> dict[str, Any]:
        """Return the JSON of ``phdesign classify --json`` (every key is documented there)."""
        partitions = self.assumption.partitions if self.assumption else ()
        best = self.best
        return {
            "model": self.model.name,
            "order": self.model.order,
            "size": self.model.size,
            "sensors": _rows(self.C_m),
            "gain": _rows(self.L),
            "gain_exact": [[str(x) for x in row] for row in self.L.tolist()],
            "partitioned": bool(partitions),
            "partitions": [p.to_dict() for p in partitions],
            "results": [r.to_dict(self.model.interval) for r in self.results],
            "verdict": self.verdict,
            "best": None if best is None else best.name,
        }

    # ------------------------------------------------------------------ display
    def _header(self) -> list[str]:
        model = self.model
        lines = [
            f"model {model.name}: N = {model.order}, n = {model.size}",
        ]
        if self.C_m.rows == 0:  # the plant's own boundary dissipation is the left-hand side
            lines.append("sensors: none (the left-hand side is the plant's own dissipation)")
        else:
            lines += [f"sensors: {sensors_text(self.C_m)}", f"gain L = {matrix_text(self.L)}"]
        if model.feedback is not None:  # the plant's own dampers: part of the error boundary
            closed = ", ".join(f"u{i}" for i in model.feedback.inputs)
            lines.append(
                f"plant feedback: {closed} = -K y (K = {matrix_text(model.feedback.gain)}); "
                "sensors index the remaining outputs"
            )
        if self.assumption is not None:
            if self.assumption.holds:
                parts = "; ".join(p.label(model.state_names) for p in self.assumption.partitions)
                lines.append(f"Assumption 3.1 holds: {parts}")
            else:
                lines.append(f"Assumption 3.1 fails: {self.assumption.reason}")
        return lines

    def _verdict_line(self) -> str:
        best = self.best
        tail = ""
        if best is not None:
            tail = f" (best: Proposition {best.proposition} variant {best.variant})"
        return f"verdict: {self.verdict}{tail}"

    def __str__(self) -> str:
        names = self.model.state_names
        lines = [*self._header(), ""]
        header = f"{'prop':<5} {'var':<3} {'holds':<6} {'κ*':<{KAPPA_WIDTH}} right-hand side"
        lines += [header, "-" * len(header)]
        indent = " " * (17 + KAPPA_WIDTH)
        for r in self.applicable:
            kappa = r.kappa_text
            notes = []
            if len(kappa) > KAPPA_WIDTH:
                notes.append(f"κ* = {kappa}")
                kappa = "see below"
            lines.append(
                f"{r.proposition:<5} {r.variant:<3} {'yes' if r.holds else 'no':<6} "
                f"{kappa:<{KAPPA_WIDTH}} {r.rhs}"
            )
            if not r.holds:
                notes.append(r.reason)
            elif r.kappa is not None and r.kappa_float is not None:
                exact = number_text(r.kappa)
                if exact != kappa and "/" not in kappa and exact != f"{r.kappa_float:.6g}":
                    notes.append(f"κ* = {exact} exactly")
            if r.holds and r.conditions:
                notes.append(r.conditions)
            if r.partition is not None:
                notes.append(f"partition {r.partition.label(names)}")
            if notes:
                lines.append(f"{indent}↳ {'; '.join(notes)}")
        lines += [f"not applicable: {text}" for text in self._not_applicable()]
        lines += ["", self._verdict_line()]
        return "\n".join(lines)

    def _not_applicable(self) -> list[str]:
        """Return the variants that do not apply, grouped by proposition and reason."""
        groups: dict[tuple[str, str], list[int]] = {}
        for r in self.results:
            if not r.applicable:
                groups.setdefault((r.proposition, r.reason), []).append(r.variant)
        return [f"Proposition {prop} ({reason})" for prop, reason in groups]

    def __repr__(self) -> str:
        best = self.best
        text = (
            f"Classification(model={self.model.name!r}, "
            f"sensors={shorten(sensors_text(self.C_m), 60)!r}, "
            f"L={shorten(matrix_text(self.L), 60)!r}, verdict={self.verdict!r}, "
            f"best={None if best is None else best.name!r}, "
            f"kappa={shorten(best.kappa_text, 40) if best is not None else None})"
        )
        return shorten(text, REPR_LIMIT)

    def _repr_html_(self) -> str:
        rows = [
            [r.name, "yes" if r.holds else "no", r.kappa_text, r.rhs, "" if r.holds else r.reason]
            for r in self.applicable
        ]
        footer = "; ".join([*self._not_applicable(), self._verdict_line()])
        return html_table(
            ["variant", "holds", "κ*", "right-hand side", "reason"],
            rows,
            caption=" · ".join(self._header()),
            footer="not applicable: " + footer if self._not_applicable() else footer,
        )


def _number(x: sympy.Expr) -> Any:
    # JSON numbers where possible (exact strings go to "gain_exact"), text for symbols.
    if x.free_symbols:
        return str(x)
    if x.is_Integer:
        return int(x)
    return float(x)


def _rows(M: sympy.MatrixBase) -> list[list[Any]]:
    return [[_number(sympy.sympify(x, strict=True)) for x in row] for row in M.tolist()]


def _strength(r: VariantResult) -> tuple[int, float]:
    return strength(r.convergence, r.kappa_float, r.unbounded)


def _not_applicable(variant: Variant, interval: Sequence[Any], why: str) -> VariantResult:
    return VariantResult(
        variant.proposition,
        variant.variant,
        False,
        None,
        None,
        None,
        False,
        None,
        (),
        variant.describe(interval=interval, tilde=True),
        why,
    )


def _from_certificate(
    case: Case, cert: Certificate, es: ErrorSystem, interval: Sequence[Any]
) -> VariantResult:
    traces = trace_list(es.order, es.size)
    witness = None
    free: tuple[Trace, ...] = ()
    symbolic = bool(es.L.free_symbols)
    conditions = cert.conditions
    if cert.holds:
        if cert.unbounded:
            reason = "holds for every κ > 0: the right-hand side vanishes on the error traces"
        else:
            reason = f"holds with κ* = {kappa_text(cert.kappa, cert.kappa_float)}"
            if cert.conditions:
                reason += f" ({cert.conditions})"
    else:
        if cert.witness is None:  # pragma: no cover - a failing certificate always has one
            raise ObserverError("a failing certificate must carry its witness")
        witness = tuple((traces[i], x) for i, x in enumerate(cert.witness) if x != 0)
        free = tuple(traces[i] for i in cert.free)
        labels = ", ".join(t.label(interval, tilde=True) for t in free)
        verb = "is" if len(free) == 1 else "are"
        by = "these sensors" if es.C_m.rows else "the boundary dissipation"  # no sensors
        reason = f"{labels} {verb} left free by {by}"
        if symbolic:
            reason += "; fails for all positive gains"
            conditions = conditions or "fails for all positive gains"
    return VariantResult(
        case.variant.proposition,
        case.variant.variant,
        True,
        cert.holds,
        cert.kappa,
        cert.kappa_float,
        cert.unbounded,
        witness,
        free,
        case.variant.describe(case.blocks, interval, tilde=True),
        reason,
        cert.path,
        conditions,
        case.partition,
        cert,
    )


def classify(model: BCPHS, C_m: Any, L: Any, method: str = "auto") -> Classification:
    r"""Classify the observer with sensors ``C_m`` and gain ``L`` for ``model``.

    Parameters
    ----------
    model : BCPHS
        The plant (parameters at their defaults).
    C_m : matrix
        ``q x Nn`` sensor matrix, read by
        :func:`~phdesign.symbolic.observer.measurement_matrix` (nested lists, numpy or
        sympy; :func:`~phdesign.symbolic.observer.sensor_matrix` picks outputs by index).
    L : number, sequence, matrix or "symbolic"
        The gain, read by :func:`~phdesign.symbolic.observer.gain_matrix`:
        :math:`L + L^\top > 0`, or diagonal positive symbols.
    method : {"auto", "exact", "float"}
        How :math:`\kappa^*` is computed (the decision is always exact).

    Returns
    -------
    Classification

    Raises
    ------
    ArgumentError
        ``model`` is not a model.
    ObserverError
        Bad sensors or gain (kind, shape, rank, NaN, :math:`L + L^\top` not positive
        definite), or an unknown ``method``.
    """
    choice(method, "method", ("auto", "exact", "float"), ObserverError)
    if getattr(model, "boundary_systems", ()):  # dynamic boundary conditions: other theorems
        return classify_coupled(model, C_m, L, method, static=classify)  # type: ignore[return-value]
    design = ObserverDesign(model, C_m, L)
    es = design.error_system()
    interval = model.interval
    assumption = model_assumption(model)
    results: list[VariantResult] = []
    for entry in variant_cases(model.order, model.size, assumption):
        if not entry.cases:
            results.append(_not_applicable(entry.variant, interval, str(entry.reason)))
            continue
        tried = [
            _from_certificate(case, certify(es, case.selected, method), es, interval)
            for case in entry.cases
        ]
        holding = [c for c in tried if c.holds]
        results.append(max(holding, key=_strength) if holding else tried[0])
    verdict = verdict_of(r.convergence for r in results if r.holds)
    return Classification(model, design.C_m, design.L, assumption, tuple(results), verdict)
