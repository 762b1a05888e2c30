r"""The argument principle in ball arithmetic: how many zeros of :math:`\Delta` a box holds.

Along a straight segment :math:`[p, q]`, if the enclosure of :math:`\Delta` over the whole
segment lies in one open half-plane (:math:`\operatorname{Re} > 0`,
:math:`\operatorname{Im} > 0`, :math:`\operatorname{Re} < 0` or
:math:`\operatorname{Im} < 0`: the *label* 0, 1, 2, 3, whose centre has the argument
:math:`0, \pi/2, \pi, 3\pi/2`), then :math:`\Delta \ne 0` there and its continuous
argument stays within :math:`\pi/2` of the label's centre.  Two consecutive segments
share an endpoint whose value lies in both half-planes, so their labels are never
opposite, and the lifted centres differ by exactly :math:`0` or :math:`\pm\pi/2`
(a *quarter turn*, read from the labels alone).  Around a closed path the change of
argument is therefore exactly :math:`\tfrac{\pi}{2} \sum_j t_j`, :math:`t_j \in
\{-1, 0, 1\}`, and the argument principle gives the number of zeros inside,

.. math::

    Z = \frac{1}{4} \sum_j t_j ,

with no rounding anywhere: the only numerical statement is each segment's enclosure,
made by flint (:meth:`Characteristic.evaluate`) over the rectangle of :math:`\lambda`
that the segment spans.

**Conjugate symmetry.**  The data are real, so :math:`\Delta(\bar\lambda) =
\overline{\Delta(\lambda)}`, and the change of argument along the lower half of a
rectangle symmetric about the real axis equals that along its upper half.  The upper
half path runs from a real point to a real point, where :math:`\Delta` is real: its
first and last labels are 0 or 2, whose centres are the exact arguments there, so
:math:`Z = \tfrac12 \sum_j t_j` over the upper half path (:func:`symmetric_count`).

Segments are made adaptively (:func:`certify_edge`): a segment whose enclosure meets
every half-plane's boundary is halved, an accepted one lets the next be twice as long.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from itertools import pairwise
from typing import Any

from phdesign.core.errors import CertificateError

__all__ = [
    "LABELS",
    "Point",
    "Segment",
    "certify_edge",
    "certify_path",
    "closed_count",
    "label_of",
    "quarter_turns",
    "symmetric_count",
]

#: The half-planes, by label: the argument of their centre is label · π/2.
LABELS = ("Re>0", "Im>0", "Re<0", "Im<0")

Point = tuple[Fraction, Fraction]  # λ = x + i y, exact
Enclose = Callable[[Point, Point], Any]  # (corner, corner) -> acb enclosure over the box


@dataclass(frozen=True)
class Segment:
    """A certified segment: Δ over it lies in the half-plane ``LABELS[label]``.

    ``value`` is the enclosure's text (midpoint and radius, informational).
    """

    start: Point
    end: Point
    label: int
    value: str = ""


#: A segment is accepted when its enclosure would still lie in the half-plane if its
#: radius were this many times larger: a re-check in another arithmetic (the checker's
#: interval enclosures are up to 1.2 times as wide as flint's balls) then passes first time.
MARGIN = 1.25


def label_of(enclosure: Any, margin: float = MARGIN) -> int | None:
    """Return the label of a half-plane holding the ``acb`` enclosure, or None.

    Of the half-planes that hold it with the margin, the one farthest from the
    enclosure is chosen.
    """
    re, im = enclosure.real, enclosure.imag
    x, y = float(re.mid()), float(im.mid())
    rx, ry = float(re.rad()) * margin, float(im.rad()) * margin
    margins = [(x - rx, 0), (y - ry, 1), (-x - rx, 2), (-y - ry, 3)]
    best = max(margins, key=lambda m: m[0])
    if best[0] <= 0:
        return None
    # the float margin decides the choice; the exact ball must hold it too
    exact = (re.lower() > 0, im.lower() > 0, re.upper() < 0, im.upper() < 0)[best[1]]
    return best[1] if exact else None


def quarter_turns(labels: Sequence[int], closed: bool) -> int:
    r"""Return :math:`\sum_j t_j` along ``labels`` (module docstring).

    Raises
    ------
    CertificateError
        If two consecutive labels are opposite half-planes (impossible for a valid
        enclosure: their shared endpoint would lie in both).
    """
    pairs = list(pairwise(labels))
    if closed and labels:
        pairs.append((labels[-1], labels[0]))
    total = 0
    for a, b in pairs:
        step = (b - a) % 4
        if step == 2:
            raise CertificateError("two consecutive segments lie in opposite half-planes")
        total += {0: 0, 1: 1, 3: -1}[step]
    return total


def certify_edge(
    enclose: Enclose,
    start: Point,
    end: Point,
    *,
    first_step: Fraction,
    max_step: Fraction,
    min_step: Fraction,
    tighter: Enclose | None = None,
    tighter_below: Fraction | None = None,
) -> list[Segment]:
    r"""Cover the axis-parallel edge ``start`` → ``end`` with certified segments.

    A segment that ``enclose`` does not separate from 0 is tried with ``tighter`` (the
    mean-value form, :meth:`.Characteristic.centered`: dearer, but its width shrinks with
    :math:`|\Delta'|`, which near a zero is what separates Δ from 0) before it is halved,
    once the step is at most ``tighter_below`` (None: at every step).  Where halving works
    the direct enclosure is cheaper, for the checker too, whose intervals are wider.

    Raises
    ------
    CertificateError
        If a segment shorter than ``min_step`` is still not certified (Δ vanishes on the
        edge, or the precision is too low).
    """
    length = abs(end[0] - start[0]) + abs(end[1] - start[1])
    if length == 0:
        return []
    out: list[Segment] = []
    t, step = Fraction(0), min(first_step, length)
    while t < length:
        h = min(step, length - t)
        a = _along(start, end, t / length)
        b = _along(start, end, (t + h) / length)
        enclosure = enclose(a, b)
        label = label_of(enclosure)
        if label is None and tighter is not None and (tighter_below is None or h <= tighter_below):
            enclosure = tighter(a, b)
            label = label_of(enclosure)
        if label is None:
            if h <= min_step:
                raise CertificateError(
                    f"Δ is not separated from 0 near λ = {float(a[0]):.6g} "
                    f"{float(a[1]):+.6g}i (a zero on the contour, or too little precision)"
                )
            step = h / 2
            continue
        out.append(Segment(a, b, label, enclosure.str(3, radius=True)))
        t += h
        step = min(2 * h, max_step)
    return out


def _along(p: Point, q: Point, s: Fraction) -> Point:
    return (p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1]))


def certify_path(
    enclose: Enclose,
    vertices: Sequence[Point],
    steps: dict[str, Fraction],
    tighter: Enclose | None = None,
    tighter_below: Fraction | None = None,
) -> list[Segment]:
    """Certify the polygonal path through ``vertices`` (axis-parallel edges).

    ``steps``: :func:`certify_edge`'s ``first_step``, ``max_step`` and ``min_step``.
    """
    segments: list[Segment] = []
    for p, q in pairwise(vertices):
        segments.extend(
            certify_edge(enclose, p, q, tighter=tighter, tighter_below=tighter_below, **steps)
        )
    return segments


def closed_count(segments: Sequence[Segment]) -> int:
    r"""Zeros inside a closed, counter-clockwise path: :math:`\tfrac14 \sum t_j`."""
    turns = quarter_turns([s.label for s in segments], closed=True)
    if turns % 4:
        raise CertificateError(f"the quarter turns of a closed path sum to {turns}, not 4·m")
    return turns // 4


def symmetric_count(segments: Sequence[Segment]) -> int:
    """Zeros inside the conjugate-symmetric rectangle whose upper half path is ``segments``.

    The path runs counter-clockwise from a real point to a real point (module docstring).
    """
    labels = [s.label for s in segments]
    if labels[0] not in (0, 2) or labels[-1] not in (0, 2):
        raise CertificateError("the upper half path must start and end where Δ is real")
    turns = quarter_turns(labels, closed=False)
    if turns % 2:
        raise CertificateError(f"the quarter turns of the upper half path sum to {turns}, odd")
    return turns // 2
