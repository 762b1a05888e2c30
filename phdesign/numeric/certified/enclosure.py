r"""Enclosing a zero of :math:`\Delta` in a small certified box.

A zero estimate (from the converged spectrum) is refined by Newton's method on the
midpoints of flint's evaluations (the derivative by a central difference of step
:math:`10^{-15}(1 + |\lambda|)` at 128 bits: its error :math:`O(h^2)` is far below what
the refinement needs), then a square of half-width :math:`r` about it is proved by the
argument principle (:mod:`.contour`) to hold :math:`m \ge 1` zeros: the zeros lie within
:math:`r` of the centre in each coordinate, so their real parts are known to :math:`2r`.
A square on the real axis is symmetric and counted by its upper half
(:func:`~.contour.symmetric_count`).  A multiple zero (a coalescence) is found so, with
its multiplicity: Newton converges linearly there but still reaches the square, and the
square's segments are certified by the mean-value form (:meth:`.Characteristic.centered`)
where the direct enclosure, whose width carries every term's size, cannot separate
:math:`\Delta \approx c(\lambda - \lambda_0)^m` from 0.  Where no zero is found, the
square grows (by 16, up to :data:`MAX_RADIUS`) until it holds one.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from phdesign.core.errors import CertificateError
from phdesign.numeric.certified.characteristic import Characteristic
from phdesign.numeric.certified.contour import (
    Point,
    Segment,
    certify_path,
    closed_count,
    symmetric_count,
)

__all__ = ["ENCLOSURE_RADIUS", "Enclosure", "enclose_zero", "refine", "square_path"]

#: Half-width of the square about a zero: 2⁻³⁶ ≈ 1.46e-11, so a real part is known to 2.9e-11.
ENCLOSURE_RADIUS = Fraction(1, 2**36)
MAX_RADIUS = Fraction(1, 2**12)
NEWTON_STEPS = 60
REAL_AXIS = 1e-9  # |Im| below this (relative) is read as a real zero, if one is there


@dataclass(frozen=True)
class Enclosure:
    r"""A square about :math:`x_c + i y_c` of half-width r proved to hold ``count`` zeros.

    ``symmetric``: centred on the real axis and counted by its upper half (``segments``
    is then the upper half path), else a closed counter-clockwise path.
    """

    center: Point
    radius: Fraction
    count: int
    symmetric: bool
    segments: tuple[Segment, ...]

    @property
    def real_interval(self) -> tuple[Fraction, Fraction]:
        """The interval of the real parts of the zeros inside."""
        return self.center[0] - self.radius, self.center[0] + self.radius


def refine(point: Callable[[Any], Any], guess: complex) -> complex:
    """Newton's method in flint (``point``: an ``acb`` point to Δ there, at 128 bits)."""
    from flint import acb, ctx

    with ctx.workprec(128):
        z = acb(guess.real, guess.imag)
        h = acb(2) ** -60
        for _ in range(NEWTON_STEPS):
            f = point(z).mid()
            slope = ((point(z + h) - point(z - h)) / (2 * h)).mid()
            if slope == 0:
                break
            step = (f / slope).mid()
            z = (z - step).mid()
            if abs(step).mid() <= 2.0**-100 * (1 + abs(z).mid()):
                break
        return complex(float(z.real.mid()), float(z.imag.mid()))


def square_path(center: Point, r: Fraction, symmetric: bool) -> list[Point]:
    """Return the vertices of a square's path: the upper half of a symmetric one, or closed."""
    x, y = center
    if symmetric:  # upper half path of [x-r, x+r] x [-r, r], counter-clockwise
        return [(x + r, Fraction(0)), (x + r, r), (x - r, r), (x - r, Fraction(0))]
    return [(x + r, y - r), (x + r, y + r), (x - r, y + r), (x - r, y - r), (x + r, y - r)]


def enclose_zero(ch: Characteristic, estimate: complex, *, real: bool) -> Enclosure:
    """Prove a square about ``estimate`` to hold zeros (module docstring).

    Raises
    ------
    CertificateError
        If no square up to :data:`MAX_RADIUS` holds a zero.
    """
    denominator = 2**60
    x = Fraction(round(estimate.real * denominator), denominator)
    y = Fraction(0) if real else Fraction(round(estimate.imag * denominator), denominator)
    r = ENCLOSURE_RADIUS
    while r <= MAX_RADIUS:
        steps: dict[str, Any] = {"first_step": r / 2, "max_step": 2 * r, "min_step": r / 2**12}
        try:
            segments = certify_path(
                ch.box, square_path((x, y), r, real), steps, tighter=ch.centered
            )
        except CertificateError:
            r *= 16
            continue
        count = symmetric_count(segments) if real else closed_count(segments)
        if count > 0:
            return Enclosure((x, y), r, count, real, tuple(segments))
        r *= 16
    raise CertificateError(
        f"no zero of Δ could be enclosed near λ = {estimate.real:.12g} {estimate.imag:+.12g}i"
    )
