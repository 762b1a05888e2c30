r"""The convergence conditions of Propositions 3.1 to 3.4 as data.

Every variant of every proposition of the paper has the same form: there is
:math:`\kappa > 0` such that, for every trace vector :math:`v` of the error system,

.. math::

    \mathrm{LHS}(v) = \tfrac12\, \tilde y_m^\top (L + L^\top)\, \tilde y_m
    \;\ge\; \kappa \sum_{t \in \mathcal S} |t(v)|^2 ,

where :math:`\mathcal S` is a set of boundary traces :math:`\partial_z^k \tilde e_i`
at :math:`z = a` or :math:`z = b`.  A :class:`Variant` stores :math:`\mathcal S`
symbolically, as groups ``(derivative, side, block)``; :meth:`Variant.traces`
expands it for a given order :math:`N`, size :math:`n` and (for Proposition 3.4)
partition :math:`x = (x_1, x_2)` of the state.

The variants are numbered in the paper's order; in 3.1 and 3.2 variant 1 is
the ":math:`a`" form and variant 2 the ":math:`b`" form.

=================  ===========  ====================================================
proposition        applies to   right-hand side (norms squared, summed)
=================  ===========  ====================================================
3.1 (asymptotic)   any N        1: all :math:`e^{(k)}(a)`, k < N;  2: same at b
3.2 (exponential)  N = 1        1: :math:`e(a)`;  2: :math:`e(b)`
3.3 (exponential)  N = 2        1: e(a), e'(a), e(b);  2: e(a), e'(a), e'(b);
                                3: e(b), e'(b), e(a);  4: e(b), e'(b), e'(a)
3.4 (exponential)  N = 2 and    1: e(a), e₁'(a), e₁(b);  2: e(a), e₂'(a), e₁'(b);
                   Asm. 3.1     3: e(b), e₁'(b), e₁(a);  4: e(b), e₂'(b), e₁'(a)
=================  ===========  ====================================================

Here :math:`e_1 = \mathcal H_1 x_1` and :math:`e_2 = \mathcal H_2 x_2` are the
blocks of :math:`e` under the partition of Assumption 3.1; :meth:`Variant.describe`
writes them with the model's own components once the partition is known (for the beam's
partition :math:`x_1 = (x_2)`, :math:`e_1'(b)` is :math:`e_2'(1)`).

This module is the one table of the propositions (:data:`PROPOSITIONS`: kind of
convergence and the orders each is stated for), the one enumeration of the variants with
the partitions they are tried with (:func:`variant_cases`, used by the classifier and the
sensor search alike), and the one verdict rule (:func:`verdict_of`, :func:`strength`).

Examples
--------
>>> [f"{v.proposition}.{v.variant}" for v in applicable_variants(order=2)]
['3.1.1', '3.1.2', '3.3.1', '3.3.2', '3.3.3', '3.3.4', '3.4.1', '3.4.2', '3.4.3', '3.4.4']
>>> VARIANTS[6].describe()
"‖e(b)‖² + ‖e'(b)‖² + ‖e(a)‖²"
>>> VARIANTS[10].describe(partition=((2,), (1,)), interval=(0, 1), tilde=True)
"‖ẽ(1)‖² + ‖ẽ2'(1)‖² + ‖ẽ2(0)‖²"
>>> [t.label((0, 1)) for t in VARIANTS[6].traces(order=2, size=2)]
['e1(1)', 'e2(1)', "e1'(1)", "e2'(1)", 'e1(0)', 'e2(0)']
>>> verdict_of(["asymptotic", "exponential"])
'exponential'
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from phdesign.core.errors import ObserverError
from phdesign.symbolic.ports import trace_index
from phdesign.symbolic.traces import Trace

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.assumption import AssumptionCheck, Partition

__all__ = [
    "PROPOSITIONS",
    "VARIANTS",
    "VERDICTS",
    "Case",
    "Proposition",
    "TraceGroup",
    "Variant",
    "VariantCases",
    "applicable_variants",
    "strength",
    "variant_cases",
    "verdict_of",
]

Side = Literal["a", "b"]
Block = Literal["all", "x1", "x2"]

#: The verdicts, strongest first.
VERDICTS = ("exponential", "asymptotic", "inconclusive")


@dataclass(frozen=True)
class Proposition:
    """One proposition of the paper: what it gives and for which orders it is stated.

    Parameters
    ----------
    name : str
        ``"3.1"`` to ``"3.4"``.
    convergence : {"asymptotic", "exponential"}
        What the proposition concludes.
    orders : tuple of int or None
        The orders :math:`N` it is stated for; ``None`` for every order.
    needs_assumption : bool
        Whether it also needs Assumption 3.1 (the partition of the state).
    """

    name: str
    convergence: str
    orders: tuple[int, ...] | None
    needs_assumption: bool = False

    def applies_to(self, order: int) -> bool:
        """Whether the proposition is stated for order ``N = order``."""
        return self.orders is None or order in self.orders

    @property
    def orders_text(self) -> str:
        """The orders as text: ``"any"`` or ``"2"``."""
        return "any" if self.orders is None else ", ".join(map(str, self.orders))


#: The propositions in the paper's order: the one table the classifier and the search read.
PROPOSITIONS: dict[str, Proposition] = {
    "3.1": Proposition("3.1", "asymptotic", None),
    "3.2": Proposition("3.2", "exponential", (1,)),
    "3.3": Proposition("3.3", "exponential", (2,)),
    "3.4": Proposition("3.4", "exponential", (2,), needs_assumption=True),
}


@dataclass(frozen=True)
class TraceGroup:
    r"""A group of traces in a right-hand side, :math:`\|e_{\text{block}}^{(k)}(s)\|^2`.

    Parameters
    ----------
    derivative : int or None
        The derivative order ``k``; ``None`` means every ``k < N`` (Proposition 3.1).
    side : {"a", "b"}
        The endpoint.
    block : {"all", "x1", "x2"}
        All components, or only those of one block of the partition of Assumption 3.1.
    """

    derivative: int | None
    side: Side
    block: Block = "all"

    def describe(
        self,
        partition: tuple[Sequence[int], Sequence[int]] | None = None,
        interval: Sequence[object] | None = None,
        tilde: bool = False,
    ) -> str:
        """Return the group as text: ``‖e₁'(b)‖²``, or ``‖e2'(1)‖²`` with a partition.

        Without a partition a block is written :math:`e_1` or :math:`e_2` (subscripts);
        with one, by the model's components it holds (``e2``, or ``(e1, e3)``).
        """
        head = "ẽ" if tilde else "e"
        if self.block == "all":
            name = head
        elif partition is None:
            name = head + {"x1": "₁", "x2": "₂"}[self.block]
        else:
            components = partition[0] if self.block == "x1" else partition[1]
            names = [f"{head}{i}" for i in components]
            name = names[0] if len(names) == 1 else f"({', '.join(names)})"
        point = self.side if interval is None else str(interval[0 if self.side == "a" else 1])
        if self.derivative is None:
            return f"Σₖ ‖{name}⁽ᵏ⁾({point})‖²"
        return f"‖{name}{chr(39) * self.derivative}({point})‖²"


@dataclass(frozen=True)
class Variant:
    """One variant of one proposition: which traces its right-hand side selects.

    Parameters
    ----------
    proposition : str
        ``"3.1"`` to ``"3.4"`` (a key of :data:`PROPOSITIONS`).
    variant : int
        1-based number, in the paper's order.
    groups : tuple of TraceGroup
        The right-hand side, a sum of squared norms.
    """

    proposition: str
    variant: int
    groups: tuple[TraceGroup, ...]

    @property
    def name(self) -> str:
        """``"3.4.3"``-style name."""
        return f"{self.proposition}.{self.variant}"

    @property
    def statement(self) -> Proposition:
        """The proposition this variant belongs to."""
        return PROPOSITIONS[self.proposition]

    @property
    def convergence(self) -> str:
        """``"asymptotic"`` (3.1) or ``"exponential"`` (3.2 to 3.4)."""
        return self.statement.convergence

    def applicable_order(self, order: int) -> bool:
        """Whether the proposition is stated for a model of order ``N = order``."""
        return self.statement.applies_to(order)

    def describe(
        self,
        partition: tuple[Sequence[int], Sequence[int]] | None = None,
        interval: Sequence[object] | None = None,
        tilde: bool = False,
    ) -> str:
        """Return the right-hand side as text (without κ); see :meth:`TraceGroup.describe`."""
        return " + ".join(group.describe(partition, interval, tilde) for group in self.groups)

    def traces(
        self,
        order: int,
        size: int,
        partition: tuple[Sequence[int], Sequence[int]] | None = None,
    ) -> tuple[Trace, ...]:
        """Expand the right-hand side into the traces it selects, without repetition.

        Parameters
        ----------
        order, size : int
            :math:`N` and :math:`n` of the model.
        partition : (x1 components, x2 components), optional
            1-based state components of each block; required when a group refers to
            the blocks of Assumption 3.1.
        """
        selected: list[Trace] = []
        for group in self.groups:
            derivatives = range(order) if group.derivative is None else (group.derivative,)
            if group.block == "all":
                components: Sequence[int] = range(1, size + 1)
            elif partition is None:
                raise ObserverError(
                    f"Proposition {self.proposition} needs the partition (x1, x2) of "
                    "Assumption 3.1; found none"
                )
            else:
                components = partition[0] if group.block == "x1" else partition[1]
            for k in derivatives:
                for i in components:
                    trace = Trace(int(i), k, group.side)
                    if trace not in selected:
                        selected.append(trace)
        return tuple(selected)

    def indices(
        self,
        order: int,
        size: int,
        partition: tuple[Sequence[int], Sequence[int]] | None = None,
    ) -> tuple[int, ...]:
        """Return the indices in the trace vector :math:`v` of :meth:`traces`, same order."""
        return tuple(
            trace_index(t.component, t.derivative, t.side, order, size)
            for t in self.traces(order, size, partition)
        )


def _g(derivative: int | None, side: Side, block: Block = "all") -> TraceGroup:
    return TraceGroup(derivative, side, block)


#: Every variant of Propositions 3.1 to 3.4, in the paper's order.
VARIANTS: tuple[Variant, ...] = (
    Variant("3.1", 1, (_g(None, "a"),)),
    Variant("3.1", 2, (_g(None, "b"),)),
    Variant("3.2", 1, (_g(0, "a"),)),
    Variant("3.2", 2, (_g(0, "b"),)),
    Variant("3.3", 1, (_g(0, "a"), _g(1, "a"), _g(0, "b"))),
    Variant("3.3", 2, (_g(0, "a"), _g(1, "a"), _g(1, "b"))),
    Variant("3.3", 3, (_g(0, "b"), _g(1, "b"), _g(0, "a"))),
    Variant("3.3", 4, (_g(0, "b"), _g(1, "b"), _g(1, "a"))),
    Variant("3.4", 1, (_g(0, "a"), _g(1, "a", "x1"), _g(0, "b", "x1"))),
    Variant("3.4", 2, (_g(0, "a"), _g(1, "a", "x2"), _g(1, "b", "x1"))),
    Variant("3.4", 3, (_g(0, "b"), _g(1, "b", "x1"), _g(0, "a", "x1"))),
    Variant("3.4", 4, (_g(0, "b"), _g(1, "b", "x2"), _g(1, "a", "x1"))),
)


def applicable_variants(order: int) -> tuple[Variant, ...]:
    """Return the variants stated for order ``N`` (3.4 still needs Assumption 3.1)."""
    return tuple(v for v in VARIANTS if v.applicable_order(order))


@dataclass(frozen=True)
class Case:
    """One check of a variant on a model: the variant, its partition and selected traces.

    Attributes
    ----------
    variant : Variant
    partition : Partition or None
        The partition of Assumption 3.1 it is tried with (Proposition 3.4 only).
    selected : tuple of int
        Indices in :math:`v` of the traces the right-hand side selects.
    """

    variant: Variant
    partition: Partition | None
    selected: tuple[int, ...]

    @property
    def blocks(self) -> tuple[tuple[int, ...], tuple[int, ...]] | None:
        """The partition's components ``(x1, x2)``, or ``None``."""
        return None if self.partition is None else (self.partition.x1, self.partition.x2)


@dataclass(frozen=True)
class VariantCases:
    """A variant with every case it is tried in, or why it does not apply.

    Attributes
    ----------
    variant : Variant
    cases : tuple of Case
        Empty when the variant does not apply.
    reason : str or None
        Why it does not apply (``None`` when it does).
    """

    variant: Variant
    cases: tuple[Case, ...]
    reason: str | None = None


def variant_cases(
    order: int, size: int, assumption: AssumptionCheck | None
) -> tuple[VariantCases, ...]:
    """Enumerate every variant of :data:`VARIANTS` with the partitions it is tried with.

    A variant of a proposition not stated for order ``N`` does not apply; a 3.4 variant
    applies only when Assumption 3.1 holds, and is then tried with every admissible
    partition (the assumption is symmetric in the blocks, the proposition is not).

    Parameters
    ----------
    order, size : int
        :math:`N` and :math:`n`.
    assumption : AssumptionCheck or None
        Assumption 3.1 of the model (:func:`~phdesign.symbolic.assumption.model_assumption`).
    """
    out: list[VariantCases] = []
    for variant in VARIANTS:
        statement = variant.statement
        if not statement.applies_to(order):
            reason = f"stated for N = {statement.orders_text}; N = {order}"
            out.append(VariantCases(variant, (), reason))
            continue
        partitions: tuple[Partition | None, ...] = (None,)
        if statement.needs_assumption:
            if assumption is None or not assumption.holds:
                why = assumption.reason if assumption is not None else "not checked"
                out.append(VariantCases(variant, (), f"Assumption 3.1 fails: {why}"))
                continue
            partitions = assumption.partitions
        cases = []
        for partition in partitions:
            blocks = None if partition is None else (partition.x1, partition.x2)
            cases.append(Case(variant, partition, variant.indices(order, size, blocks)))
        out.append(VariantCases(variant, tuple(cases)))
    return tuple(out)


def verdict_of(convergences: Iterable[str]) -> str:
    """Return the verdict from the kinds of convergence of the holding variants.

    *exponential* if a variant of 3.2, 3.3 or 3.4 holds, *asymptotic* if only 3.1 holds,
    *inconclusive* if none does: the propositions are sufficient, never "unstable".
    """
    kinds = set(convergences)
    if "exponential" in kinds:
        return "exponential"
    if "asymptotic" in kinds:
        return "asymptotic"
    return "inconclusive"


def strength(convergence: str, kappa: float | None, unbounded: bool) -> tuple[int, float]:
    r"""Sort key of a holding variant: exponential first, then the largest :math:`\kappa^*`.

    An unbounded right-hand side counts as :math:`\kappa^* = \infty`; a constant that was
    not computed (symbolic gains) as 0, so that the first such variant is preferred.
    """
    kind = 1 if convergence == "exponential" else 0
    if unbounded:
        return kind, float("inf")
    return kind, 0.0 if kappa is None else kappa
