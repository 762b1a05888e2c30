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

Examples
--------
>>> from phdesign.models import load_builtin
>>> from phdesign.symbolic.observer import sensor_matrix, parse_gain
>>> beam = load_builtin("euler-bernoulli")
>>> result = classify(beam, sensor_matrix([3, 4], 4), parse_gain("symbolic", 2))
>>> result.verdict
'exponential'
>>> r = result.result("3.4", 3)
>>> r.holds, r.kappa
(True, Min(l2, l1/(l1**2 + 1)))
>>> result.result("3.3", 3).reason
'ẽ2(0) is left free by these sensors; fails for all positive gains'
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import sympy

from phdesign.symbolic.assumption import AssumptionCheck, Partition, check_assumption
from phdesign.symbolic.certificate import Certificate, certify
from phdesign.symbolic.expressions import Trace
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import ErrorSystem, ObserverDesign
from phdesign.symbolic.propositions import VARIANTS, Variant

__all__ = ["Classification", "VariantResult", "classify", "verdict_of"]

VERDICTS = ("exponential", "asymptotic", "inconclusive")


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
        The right-hand side in words.
    reason : str
        One sentence: why it holds, why it fails, or why it does not apply.
    path : str or None
        ``"exact"``, ``"float"`` or ``"symbolic"``.
    conditions : str or None
        Range of gains the symbolic answer covers.
    partition : Partition or None
        The partition used (3.4 only).
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
    def convergence(self) -> str:
        """``"asymptotic"`` or ``"exponential"``."""
        return "asymptotic" if self.proposition == "3.1" else "exponential"

    def kappa_json(self) -> float | str | None:
        r""":math:`\kappa^*` for the JSON ``kappa`` key (DESIGN.md).

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


@dataclass(frozen=True)
class Classification:
    """The classification of one observer design.

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
        raise KeyError(f"no variant {proposition}.{variant}")

    @property
    def best(self) -> VariantResult | None:
        """The holding variant of the strongest kind with the largest constant."""
        holding = [r for r in self.results if r.holds]
        if not holding:
            return None
        return max(holding, key=_strength)

    def to_json_dict(self) -> dict[str, Any]:
        """Return the JSON of DESIGN.md (plus keys such as ``kappa_exact``, ``witness``)."""
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
            "partitions": [p.to_json_dict() for p in partitions],
            "results": [_result_json(r, self.model.interval) for r in self.results],
            "verdict": self.verdict,
            "best": None if best is None else f"{best.proposition}.{best.variant}",
        }


def _number(x: sympy.Expr) -> Any:
    # JSON numbers where possible (exact strings go to "gain_exact"), text for symbols.
    if x.free_symbols:
        return str(x)
    if x.is_Integer:
        return int(x)
    return float(x)


def _rows(M: sympy.MatrixBase) -> list[list[Any]]:
    return [[_number(sympy.sympify(x, strict=True)) for x in row] for row in M.tolist()]


def _result_json(r: VariantResult, interval: Sequence[Any]) -> dict[str, Any]:
    out: dict[str, Any] = {
        "proposition": r.proposition,
        "variant": r.variant,
        "applicable": r.applicable,
        "holds": r.holds,
        "kappa": r.kappa_json(),
        "kappa_exact": None if r.kappa is None else str(r.kappa),
        "unbounded": r.unbounded,
        "rhs": r.rhs,
        "reason": r.reason,
        "path": r.path,
    }
    if r.conditions is not None:
        out["conditions"] = r.conditions
    if r.partition is not None:
        out["partition"] = {"x1": list(r.partition.x1), "x2": list(r.partition.x2)}
    if r.witness is not None:
        out["witness"] = {t.label(interval, tilde=True): str(x) for t, x in r.witness}
        out["free"] = [t.label(interval, tilde=True) for t in r.free]
    return out


def _strength(r: VariantResult) -> tuple[int, float]:
    kind = 1 if r.convergence == "exponential" else 0
    if r.unbounded:
        return kind, float("inf")
    return kind, r.kappa_float if r.kappa_float is not None else 0.0


def verdict_of(results: Sequence[VariantResult]) -> str:
    """Exponential if a 3.2/3.3/3.4 variant holds, asymptotic if only 3.1, else inconclusive."""
    if any(r.holds and r.convergence == "exponential" for r in results):
        return "exponential"
    if any(r.holds for r in results):
        return "asymptotic"
    return "inconclusive"


def _trace_of_index(index: int, order: int, size: int) -> Trace:
    side = "b" if index < order * size else "a"
    rest = index % (order * size)
    return Trace(rest % size + 1, rest // size, side)  # type: ignore[arg-type]


def _not_applicable(variant: Variant, order: int, why: str) -> VariantResult:
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
        variant.describe(),
        why,
    )


def _from_certificate(
    variant: Variant,
    cert: Certificate,
    es: ErrorSystem,
    interval: Sequence[Any],
    partition: Partition | None,
) -> VariantResult:
    order, size = es.order, es.size
    witness = None
    free: tuple[Trace, ...] = ()
    if cert.holds:
        if cert.unbounded:
            reason = "holds for every κ > 0: the right-hand side vanishes on the error traces"
        else:
            value = cert.kappa if cert.kappa is not None else cert.kappa_float
            reason = f"holds with κ* = {value}"
            if cert.conditions:
                reason += f" ({cert.conditions})"
    else:
        assert cert.witness is not None  # a failing certificate always has one
        witness = tuple(
            (_trace_of_index(i, order, size), x) for i, x in enumerate(cert.witness) if x != 0
        )
        free = tuple(_trace_of_index(i, order, size) for i in cert.free)
        labels = ", ".join(t.label(interval, tilde=True) for t in free)
        verb = "is" if len(free) == 1 else "are"
        reason = f"{labels} {verb} left free by these sensors"
        if es.L.free_symbols:
            reason += "; fails for all positive gains"
    return VariantResult(
        variant.proposition,
        variant.variant,
        True,
        cert.holds,
        cert.kappa,
        cert.kappa_float,
        cert.unbounded,
        witness,
        free,
        variant.describe(),
        reason,
        cert.path,
        cert.conditions
        if cert.conditions
        else ("fails for all positive gains" if es.L.free_symbols and not cert.holds else None),
        partition,
        cert,
    )


def classify(
    model: BCPHS,
    C_m: sympy.MatrixBase,
    L: sympy.MatrixBase,
    method: str = "auto",
) -> Classification:
    r"""Classify the observer with sensors ``C_m`` and gain ``L`` for ``model``.

    Parameters
    ----------
    model : BCPHS
        The plant (parameters at their defaults).
    C_m : sympy matrix
        ``q x Nn`` sensor matrix (:func:`~phdesign.symbolic.observer.sensor_matrix`).
    L : sympy matrix
        ``q x q`` gain with :math:`L + L^\top > 0`, or diagonal positive symbols.
    method : {"auto", "exact", "float"}
        How :math:`\kappa^*` is computed (the decision is always exact).

    Returns
    -------
    Classification

    Raises
    ------
    ObserverError
        Bad sensors or gain (shape, rank, NaN, :math:`L + L^\top` not positive definite).
    """
    if method not in ("auto", "exact", "float"):
        raise ValueError(f"method must be 'auto', 'exact' or 'float'; found {method!r}")
    design = ObserverDesign(model, C_m, L)
    es = design.error_system()
    order, size = model.order, model.size
    assumption = None
    if order == 2:
        assumption = check_assumption(model.P[1], model.P[2], model.H, model.parameter_defaults)
    results: list[VariantResult] = []
    for variant in VARIANTS:
        if not variant.applicable_order(order):
            results.append(
                _not_applicable(variant, order, f"stated for N = {_orders(variant)}; N = {order}")
            )
            continue
        if variant.needs_partition:
            assert assumption is not None  # order == 2 here
            if not assumption.holds:
                results.append(
                    _not_applicable(variant, order, f"Assumption 3.1 fails: {assumption.reason}")
                )
                continue
            candidates = []
            for partition in assumption.partitions:
                indices = variant.indices(order, size, (partition.x1, partition.x2))
                cert = certify(es, indices, method)
                candidates.append(_from_certificate(variant, cert, es, model.interval, partition))
            holding = [c for c in candidates if c.holds]
            results.append(max(holding, key=_strength) if holding else candidates[0])
            continue
        cert = certify(es, variant.indices(order, size), method)
        results.append(_from_certificate(variant, cert, es, model.interval, None))
    return Classification(
        model, design.C_m, design.L, assumption, tuple(results), verdict_of(results)
    )


def _orders(variant: Variant) -> str:
    return {"3.1": "any", "3.2": "1", "3.3": "2", "3.4": "2"}[variant.proposition]
