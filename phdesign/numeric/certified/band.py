r"""The certified spectral abscissa in a band :math:`|\operatorname{Im}\lambda| \le \Omega`.

The proof has three parts, each an argument-principle count (:mod:`.contour`) or an
exact sign:

1. **No zero right of the imaginary axis** (the energy identity, decided exactly by
   :meth:`~.exact_system.ExactClosedSystem.dissipation`): :math:`\operatorname{Re}\lambda
   \le 0` for every eigenvalue, so the rectangle
   :math:`R = [\alpha_{\text{left}}, \delta] \times [-\Omega, \Omega]`, :math:`\delta = 1/2`,
   holds every eigenvalue of the band with :math:`\operatorname{Re}\lambda >
   \alpha_{\text{left}}`.
2. **The rightmost zeros are enclosed**: each in a square of half-width
   :math:`r = 2^{-36}` holding ``count`` zeros (:mod:`.enclosure`), the upper half plane's
   and the real axis' (their conjugates are the mirror squares).
3. **There are no others**: the count of zeros in :math:`R` equals the zeros enclosed
   (each non-real square twice), so every eigenvalue of the band right of
   :math:`\alpha_{\text{left}}` lies in a square, and the band's abscissa lies in
   :math:`[\max_i (x_i - r), \max_i (x_i + r)]` (the squares of the rightmost cluster).

:math:`\alpha_{\text{left}}` is put halfway between the rightmost estimates and the next
ones, so that no zero is near the contour.  The estimates come from the converged
spectrum (any estimate will do: a missed zero makes the count in 3 disagree, and the
certificate is refused, never wrong).  If a zero lies on the top edge the band is widened
by :math:`2^{-10}\Omega` and the count repeated.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

from phdesign.core.errors import CertificateError
from phdesign.numeric.certified.characteristic import Characteristic
from phdesign.numeric.certified.contour import Segment, certify_path, symmetric_count
from phdesign.numeric.certified.enclosure import Enclosure, enclose_zero, refine

__all__ = ["RIGHT_EDGE", "BandCount", "certify_band"]

RIGHT_EDGE = Fraction(1, 2)
CLUSTER = 1e-6  # estimates whose real parts agree to this form the rightmost cluster
GRID = 2**20  # the left edge is a multiple of 2^-20
PRECISION = 96  # bits, for the long contour
ENCLOSURE_PRECISION = 160  # bits, for the small squares
#: The long contour uses the mean-value form only on segments this short (where halving
#: no longer helps: near a multiple zero); longer ones are halved instead.
CENTERED_BELOW = Fraction(1, 2**10)


@dataclass(frozen=True)
class BandCount:
    r"""The certified band (module docstring).

    Attributes
    ----------
    band : Fraction
        :math:`\Omega` proved (the one asked for, or slightly wider).
    left, right : Fraction
        :math:`\alpha_{\text{left}}` and :math:`\delta`.
    count : int
        Zeros of :math:`\Delta` in :math:`R`.
    segments : tuple of Segment
        The upper half path of :math:`R`, counter-clockwise from :math:`\delta`.
    enclosures : tuple of Enclosure
        The squares of the zeros in :math:`R` (upper half plane and real axis).
    rightmost : tuple of Enclosure
        Those of the rightmost cluster.
    """

    band: Fraction
    left: Fraction
    right: Fraction
    count: int
    segments: tuple[Segment, ...]
    enclosures: tuple[Enclosure, ...]
    rightmost: tuple[Enclosure, ...]

    @property
    def abscissa_interval(self) -> tuple[Fraction, Fraction] | None:
        r""":math:`[\alpha_{lo}, \alpha_{up}]` for the band's abscissa; None: no zero in R."""
        if not self.rightmost:
            return None
        lo = max(e.real_interval[0] for e in self.rightmost)
        hi = max(e.real_interval[1] for e in self.rightmost)
        return lo, min(hi, Fraction(0))

    @property
    def enclosed(self) -> int:
        """Zeros in the squares, each non-real square with its mirror image."""
        return sum(e.count * (1 if e.symmetric else 2) for e in self.enclosures)


def certify_band(ch: Characteristic, band: float, estimates: Sequence[complex]) -> BandCount:
    r"""Certify the abscissa of the zeros of Δ with :math:`|\operatorname{Im}| \le` band.

    Parameters
    ----------
    ch : Characteristic
        Δ's exact data.
    band : float
        :math:`\Omega > 0`.
    estimates : sequence of complex
        Eigenvalue estimates (the converged spectrum's); those in the band's upper half
        are refined and enclosed.

    Raises
    ------
    CertificateError
        If a zero cannot be enclosed, or the count in R finds zeros not enclosed.
    """
    from flint import ctx

    omega = Fraction(band).limit_denominator(2**10)
    if omega <= 0:
        raise CertificateError(f"band must be a positive number; found {band}")
    zeros = _refined(ch, estimates, float(omega))
    left = _left_edge(zeros)
    with ctx.workprec(ENCLOSURE_PRECISION):
        squares = [enclose_zero(ch, z, real=z.imag == 0) for z in zeros if z.real > left]
    corners = None
    for attempt in range(4):
        top = omega * (1 + Fraction(attempt, 2**10))
        vertices = [(RIGHT_EDGE, Fraction(0)), (RIGHT_EDGE, top), (left, top), (left, Fraction(0))]
        steps = {
            "first_step": Fraction(1, 4),
            "max_step": Fraction(64),
            "min_step": Fraction(1, 2**40),
        }
        try:
            with ctx.workprec(PRECISION):
                corners = certify_path(
                    ch.box, vertices, steps, tighter=ch.centered, tighter_below=CENTERED_BELOW
                )
            break
        except CertificateError:
            continue
    if corners is None:
        raise CertificateError(
            f"Δ could not be separated from 0 on the contour of the band {band}"
        )
    count = symmetric_count(corners)
    top_real = max((z.real for z in zeros if z.real > left), default=None)
    rightmost = tuple(
        s
        for s, z in zip(squares, [z for z in zeros if z.real > left], strict=True)
        if top_real is not None and z.real >= top_real - CLUSTER
    )
    result = BandCount(top, left, RIGHT_EDGE, count, tuple(corners), tuple(squares), rightmost)
    if count != result.enclosed:
        raise CertificateError(
            f"the band |Im λ| <= {float(top):g} holds {count} zeros of Δ right of "
            f"Re λ = {float(left):.6g} but only {result.enclosed} were enclosed: the spectrum's "
            "estimates missed some (not certified)"
        )
    return result


def _refined(ch: Characteristic, estimates: Sequence[complex], omega: float) -> list[complex]:
    """Refined estimates in the band's closed upper half, without repeats, by Re descending."""
    out: list[complex] = []
    for guess in estimates:
        if guess.imag < -1e-9 * (1 + abs(guess)) or abs(guess.imag) > omega:
            continue
        z = refine(ch.point, complex(guess.real, abs(guess.imag)))
        if abs(z.imag) <= 1e-9 * (1 + abs(z)):
            z = complex(z.real, 0.0)
        if abs(z.imag) > omega or any(abs(z - w) <= 1e-8 * (1 + abs(z)) for w in out):
            continue
        out.append(z)
    return sorted(out, key=lambda z: -z.real)


def _left_edge(zeros: Sequence[complex]) -> Fraction:
    """Halfway between the rightmost cluster and the next real part (at most 1/2 left)."""
    if not zeros:
        return Fraction(-1)
    top = zeros[0].real
    below = [z.real for z in zeros if z.real < top - CLUSTER]
    gap = min(top - below[0], 1.0) if below else 1.0
    return Fraction(round((top - gap / 2) * GRID), GRID)
