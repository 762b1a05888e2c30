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

================  ==========  ====================================================
proposition       applies to  right-hand side (norms squared, summed)
================  ==========  ====================================================
3.1 (asymptotic)  any N       1: all :math:`e^{(k)}(a)`, k < N;  2: same at b
3.2 (exponential) N = 1       1: :math:`e(a)`;  2: :math:`e(b)`
3.3 (exponential) N = 2       1: e(a), e'(a), e(b);  2: e(a), e'(a), e'(b);
                              3: e(b), e'(b), e(a);  4: e(b), e'(b), e'(a)
3.4 (exponential) N = 2 and   1: e(a), e₁'(a), e₁(b);  2: e(a), e₂'(a), e₁'(b);
                  Asm. 3.1    3: e(b), e₁'(b), e₁(a);  4: e(b), e₂'(b), e₁'(a)
================  ==========  ====================================================

Here :math:`e_1 = \mathcal H_1 x_1` and :math:`e_2 = \mathcal H_2 x_2` are the
blocks of :math:`e` under the partition of Assumption 3.1.

Examples
--------
>>> [f"{v.proposition}.{v.variant}" for v in applicable_variants(order=2)]
['3.1.1', '3.1.2', '3.3.1', '3.3.2', '3.3.3', '3.3.4', '3.4.1', '3.4.2', '3.4.3', '3.4.4']
>>> VARIANTS[6].describe()
"‖e(b)‖² + ‖e'(b)‖² + ‖e(a)‖²"
>>> [t.label((0, 1)) for t in VARIANTS[6].traces(order=2, size=2)]
['e1(1)', 'e2(1)', "e1'(1)", "e2'(1)", 'e1(0)', 'e2(0)']
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

from phdesign.symbolic.expressions import Trace
from phdesign.symbolic.ports import trace_index

__all__ = [
    "PROPOSITIONS",
    "VARIANTS",
    "TraceGroup",
    "Variant",
    "applicable_variants",
]

Side = Literal["a", "b"]
Block = Literal["all", "x1", "x2"]

#: The propositions in the paper's order, with the kind of convergence each gives.
PROPOSITIONS: dict[str, str] = {
    "3.1": "asymptotic",
    "3.2": "exponential",
    "3.3": "exponential",
    "3.4": "exponential",
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

    def describe(self) -> str:
        """Return the group as text, e.g. ``‖e₁'(b)‖²``."""
        name = {"all": "e", "x1": "e₁", "x2": "e₂"}[self.block]
        if self.derivative is None:
            return f"Σₖ ‖{name}⁽ᵏ⁾({self.side})‖²"
        return f"‖{name}{chr(39) * self.derivative}({self.side})‖²"


@dataclass(frozen=True)
class Variant:
    """One variant of one proposition: which traces its right-hand side selects.

    Parameters
    ----------
    proposition : str
        ``"3.1"`` to ``"3.4"``.
    variant : int
        1-based number, in the paper's order.
    groups : tuple of TraceGroup
        The right-hand side, a sum of squared norms.
    """

    proposition: str
    variant: int
    groups: tuple[TraceGroup, ...]

    @property
    def convergence(self) -> str:
        """``"asymptotic"`` (3.1) or ``"exponential"`` (3.2 to 3.4)."""
        return PROPOSITIONS[self.proposition]

    @property
    def needs_partition(self) -> bool:
        """Whether the right-hand side refers to the blocks of Assumption 3.1."""
        return any(group.block != "all" for group in self.groups)

    def applicable_order(self, order: int) -> bool:
        """Whether the proposition is stated for a model of order ``N = order``."""
        return {"3.1": True, "3.2": order == 1, "3.3": order == 2, "3.4": order == 2}[
            self.proposition
        ]

    def describe(self) -> str:
        """Return the right-hand side as text (without κ)."""
        return " + ".join(group.describe() for group in self.groups)

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
            1-based state components of each block; required when
            :attr:`needs_partition`.
        """
        if self.needs_partition and partition is None:
            raise ValueError(f"Proposition {self.proposition} needs the partition (x1, x2)")
        selected: list[Trace] = []
        for group in self.groups:
            derivatives = range(order) if group.derivative is None else (group.derivative,)
            if group.block == "all":
                components: Sequence[int] = range(1, size + 1)
            else:
                assert partition is not None  # checked above; tells mypy
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
