r"""Re-checking a contour: the path, each segment's half-plane, the count of zeros.

A segment :math:`[p, q]` is verified when the interval enclosure of :math:`\Delta` over
the box spanned by p and q (:func:`.intervals.delta`) lies in an open half-plane
:math:`\operatorname{Re} > 0`, :math:`\operatorname{Im} > 0`, :math:`\operatorname{Re} <
0` or :math:`\operatorname{Im} < 0` (labels 0 to 3, centres at :math:`\text{label}\cdot
\pi/2`).  The proof's label is tried first; a segment none of whose halves fit is halved
(:data:`SPLITS` times at most), and the labels used are the checker's own.  Consecutive
labels differ by a quarter turn or none, so the change of argument is
:math:`\tfrac{\pi}{2}\sum_j t_j` exactly: around a closed path the count of zeros is
:math:`\tfrac14\sum t_j`; along the upper half of a conjugate-symmetric rectangle (from a
real point to a real point, where :math:`\Delta` is real since its data are), it is
:math:`\tfrac12\sum t_j`.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction
from itertools import pairwise

from mpmath.libmp import fzero, mpf_gt, mpf_lt

from phdesign.proofcheck.exact import number
from phdesign.proofcheck.intervals import PRECISION, box, centered_delta, delta

__all__ = [
    "SPLITS",
    "centered_over",
    "count_zeros",
    "delta_over",
    "overlapping",
    "read_segments",
    "square_count",
]

SPLITS = 4
Point = tuple[Fraction, Fraction]


def read_segments(rows: Sequence[Sequence[object]]) -> list[tuple[Point, Point, int]]:
    """Read ``[x0, y0, x1, y1, label]`` rows."""
    out = []
    for row in rows:
        x0, y0, x1, y1 = (number(v) for v in row[:4])
        out.append(((x0, y0), (x1, y1), int(row[4])))  # type: ignore[call-overload]
    return out


def _holds(value: tuple, label: int) -> bool:
    re, im = value
    return bool(
        {
            0: mpf_gt(re[0], fzero),
            1: mpf_gt(im[0], fzero),
            2: mpf_lt(re[1], fzero),
            3: mpf_lt(im[1], fzero),
        }[label]
    )


def delta_over(data):
    """Return the evaluator of Δ for :func:`count_zeros`: Δ over the box of a segment."""

    def evaluate(p: Point, q: Point, prec: int) -> tuple:
        return delta(data, box((p[0], q[0]), (p[1], q[1]), prec), prec)

    return evaluate


def centered_over(data):
    """Return the mean-value evaluator (:func:`.intervals.centered_delta`), for count_zeros."""

    def evaluate(p: Point, q: Point, prec: int) -> tuple:
        return centered_delta(data, p, q, prec)

    return evaluate


def _label(value: tuple, hint: int) -> int | None:
    return next((x for x in (hint, *range(4)) if _holds(value, x)), None)


def _labels(
    evaluate, tighter, p: Point, q: Point, hint: int, depth: int, prec: int
) -> list[int] | None:
    label = _label(evaluate(p, q, prec), hint)
    if label is None and tighter is not None:
        label = _label(tighter(p, q, prec), hint)
    if label is not None:
        return [label]
    if depth == 0:
        return None
    m = ((p[0] + q[0]) / 2, (p[1] + q[1]) / 2)
    first = _labels(evaluate, tighter, p, m, hint, depth - 1, prec)
    if first is None:
        return None
    second = _labels(evaluate, tighter, m, q, hint, depth - 1, prec)
    return None if second is None else first + second


def _on_path(segments, vertices: Sequence[Point]) -> str | None:
    """Whether the segments run along the polygon through ``vertices``, in order."""
    if not segments or segments[0][0] != vertices[0] or segments[-1][1] != vertices[-1]:
        return "the segments do not start and end at the path's ends"
    edge = 0
    for (p, q, _), following in zip(segments, [*segments[1:], None], strict=True):
        a, b = vertices[edge], vertices[edge + 1]
        if not (_between(a, p, b) and _between(a, q, b) and _forward(a, p, q, b)):
            return f"a segment leaves the edge {a} -> {b}"
        if following is not None and following[0] != q:
            return "two consecutive segments do not meet"
        if q == b:
            edge += 1
    if edge != len(vertices) - 1:
        return "the segments do not cover the path"
    return None


def _between(a: Point, p: Point, b: Point) -> bool:
    if a[0] == b[0]:
        return p[0] == a[0] and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])
    if a[1] == b[1]:
        return p[1] == a[1] and min(a[0], b[0]) <= p[0] <= max(a[0], b[0])
    return False


def _forward(a: Point, p: Point, q: Point, b: Point) -> bool:
    def distance(x: Point) -> Fraction:
        return abs(x[0] - a[0]) + abs(x[1] - a[1])

    return distance(p) < distance(q) <= distance(b)


def count_zeros(
    evaluate,
    segments,
    vertices: Sequence[Point],
    *,
    symmetric: bool,
    failures: list[str],
    what: str,
    prec: int = PRECISION,
    tighter=None,
) -> int | None:
    """Verify the path and its labels; return the number of zeros inside, or None.

    ``evaluate(p, q, prec)`` encloses the function over the box of the segment p -> q;
    ``tighter`` (same signature, e.g. :func:`centered_over`), if given, is tried on a
    segment that ``evaluate`` does not separate from 0, before the segment is halved.
    """
    problem = _on_path(segments, vertices)
    if problem:
        failures.append(f"{what}: {problem}")
        return None
    labels: list[int] = []
    for p, q, hint in segments:
        found = _labels(evaluate, tighter, p, q, hint, SPLITS, prec)
        if found is None:
            failures.append(
                f"{what}: Δ is not separated from 0 on the segment {_text(p)} -> {_text(q)}"
            )
            return None
        labels.extend(found)
    pairs = list(pairwise(labels))
    if not symmetric:
        pairs.append((labels[-1], labels[0]))
    turns = 0
    for x, y in pairs:
        step = (y - x) % 4
        if step == 2:
            failures.append(f"{what}: consecutive segments in opposite half-planes")
            return None
        turns += (0, 1, 0, -1)[step]
    if symmetric:
        if labels[0] not in (0, 2) or labels[-1] not in (0, 2) or turns % 2:
            failures.append(f"{what}: the upper half path does not end where Δ is real")
            return None
        return turns // 2
    if turns % 4:
        failures.append(f"{what}: the closed path's quarter turns do not sum to 4·m")
        return None
    return turns // 4


def square_count(
    evaluate,
    square: dict,
    *,
    symmetric: bool,
    failures: list[str],
    what: str,
    prec: int,
    tighter=None,
) -> tuple[Fraction, Fraction, Fraction, int] | None:
    """Verify a square of the proof (``center``, ``radius``, ``count``, ``path``).

    A symmetric square is centred on the real axis and counted by its upper half path;
    another is a closed counter-clockwise path from its lower right corner.  Returns
    ``(x, y, r, count)``, or None (with the failure recorded).
    """
    x, y = (number(v) for v in square["center"])
    r = number(square["radius"])
    if r <= 0 or (symmetric and y != 0):
        failures.append(f"{what}: a square must have r > 0 (and y = 0 when symmetric)")
        return None
    if symmetric:
        corners = [(x + r, Fraction(0)), (x + r, r), (x - r, r), (x - r, Fraction(0))]
    else:
        corners = [(x + r, y - r), (x + r, y + r), (x - r, y + r), (x - r, y - r)]
        corners.append(corners[0])
    found = count_zeros(
        evaluate,
        read_segments(square["path"]),
        corners,
        symmetric=symmetric,
        failures=failures,
        what=what,
        prec=prec,
        tighter=tighter,
    )
    if found is None:
        return None
    if found < 1 or found != square["count"]:
        failures.append(f"{what} holds {found} zeros, the proof says {square['count']}")
        return None
    return x, y, r, found


def overlapping(squares: Sequence[tuple[Fraction, Fraction, Fraction]]) -> int | None:
    """Return the 1-based index of a square that overlaps an earlier one, or None."""
    for i, (x, y, r) in enumerate(squares):
        if any(abs(x - u) < r + s and abs(y - v) < r + s for u, v, s in squares[:i]):
            return i + 1
    return None


def _text(p: Point) -> str:
    return f"{float(p[0]):.6g}{float(p[1]):+.6g}i"
