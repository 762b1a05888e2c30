r"""Checking the ``band`` section: the rectangle's count, the squares, the claimed interval.

What is verified, in order:

1. the energy identity's signs (:mod:`.system`): every eigenvalue has
   :math:`\operatorname{Re}\lambda \le 0`, so the rectangle :math:`[\alpha_{\text{left}},
   \delta] \times [-\Omega, \Omega]` with :math:`\delta > 0` holds every eigenvalue of the
   band right of :math:`\alpha_{\text{left}}`;
2. the rectangle's count (its upper half path, :func:`.contour.count_zeros`);
3. each square's count, its place (inside the rectangle, in the closed upper half plane,
   symmetric squares centred on the real axis) and that no two squares overlap;
4. that the squares hold all the zeros the rectangle holds (non-real squares twice);
5. the claim: :math:`\alpha_{lo} \le \max_i (x_i - r_i)` (each square holds a zero) and
   :math:`\alpha_{up} \ge \min(\max_i (x_i + r_i), 0)`; with no square,
   :math:`\alpha_{up} \ge \alpha_{\text{left}}`.
"""

from __future__ import annotations

from fractions import Fraction

from phdesign.proofcheck.contour import (
    centered_over,
    count_zeros,
    delta_over,
    overlapping,
    read_segments,
    square_count,
)
from phdesign.proofcheck.exact import number
from phdesign.proofcheck.system import Delta

__all__ = ["check_band"]

SQUARE_PRECISION = 96


def check_band(data: Delta, section: dict, claim: list | None, failures: list[str]) -> None:
    """Verify the band section against ``claim`` (``[lo, up]`` or None)."""
    if not data.dissipative:
        failures.append("band: sym(G) ⪰ 0 and sym(P0) ⪯ 0 fail, so Re λ ≤ 0 is not proved")
        return
    left, right, omega = (number(section[k]) for k in ("left", "right", "omega"))
    if not (right > 0 and omega > 0 and left < 0):
        failures.append("band: the rectangle must have left < 0 < right and omega > 0")
        return
    vertices = [(right, Fraction(0)), (right, omega), (left, omega), (left, Fraction(0))]
    segments = read_segments(section["path"])
    evaluate = delta_over(data)
    tighter = centered_over(data)
    count = count_zeros(
        evaluate,
        segments,
        vertices,
        symmetric=True,
        failures=failures,
        what="band",
        tighter=tighter,
    )
    if count is None:
        return
    if count != section["count"]:
        failures.append(
            f"band: the rectangle holds {count} zeros, the proof says {section['count']}"
        )
        return
    squares = _squares((evaluate, tighter), section["enclosures"], left, right, omega, failures)
    if squares is None:
        return
    enclosed = sum(m * (1 if sym else 2) for *_, m, sym in squares)
    if enclosed != count:
        failures.append(f"band: the squares hold {enclosed} zeros but the rectangle {count}")
        return
    _check_claim(squares, left, claim, failures, data.conservative)


def _squares(
    evaluators: tuple, enclosures: list, left, right, omega, failures: list[str]
) -> list | None:
    """Verify the squares: each count, its place in the rectangle, no overlap.

    ``evaluators``: the direct enclosure and the mean-value one tried where it fails.
    """
    evaluate, tighter = evaluators
    squares = []
    for index, square in enumerate(enclosures):
        what = f"band: square {index + 1}"
        symmetric = bool(square["symmetric"])
        found = square_count(
            evaluate,
            square,
            symmetric=symmetric,
            failures=failures,
            what=what,
            prec=SQUARE_PRECISION,
            tighter=tighter,
        )
        if found is None:
            return None
        x, y, r, count = found
        if x - r <= left or x + r >= right or y + r >= omega or (not symmetric and y - r <= 0):
            failures.append(f"{what} is not inside the rectangle's upper half")
            return None
        squares.append((x, y, r, count, symmetric))
    clash = overlapping([(x, y, r) for x, y, r, *_ in squares])
    if clash is not None:
        failures.append(f"band: square {clash} overlaps another")
        return None
    return squares


def _check_claim(
    squares, left: Fraction, claim: list | None, failures: list[str], conservative: bool
) -> None:
    if not squares:
        if claim is not None and number(claim[1]) < left:
            failures.append("band: the claimed upper bound is left of the rectangle's left edge")
        return
    if claim is None:
        failures.append("band: the proof encloses zeros but claims no interval")
        return
    lo, up = (number(v) for v in claim)
    proved_lo = max(x - r for x, _, r, *_ in squares)
    proved_up = min(max(x + r for x, _, r, *_ in squares), Fraction(0))
    if conservative:  # every eigenvalue has Re λ = 0 exactly, and a square holds one
        proved_lo = proved_up = Fraction(0)
    if lo > proved_lo:
        failures.append(
            f"band: the claimed lower bound {float(lo):.12g} exceeds what the squares prove "
            f"({float(proved_lo):.12g})"
        )
    if up < proved_up:
        failures.append(
            f"band: the claimed upper bound {float(up):.12g} is below what the squares allow "
            f"({float(proved_up):.12g}): a zero may lie right of it"
        )
