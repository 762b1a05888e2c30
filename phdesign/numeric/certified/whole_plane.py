r"""The whole plane for an exponential polynomial: first-order systems with one travel time.

For :math:`N = 1`, :math:`P_0 = 0` the companion matrix is :math:`A(\lambda) = \lambda
P_1^{-1}H^{-1}`; put :math:`K = \ell P_1^{-1} H^{-1}`.  When every characteristic speed
has the same modulus, :math:`K^2 = \tau^2 I` (:math:`\tau = \ell/c` the travel time), and
when :math:`\tau` is rational (checked exactly),

.. math::

    e^{\lambda K} = \cosh(\lambda\tau)\, I + \sinh(\lambda\tau)\, K/\tau
    = \zeta P_+ + \zeta^{-1} P_-, \qquad \zeta = e^{\lambda\tau}, \quad
    P_\pm = \tfrac12 (I \pm K/\tau),

so :math:`\zeta^n \Delta(\lambda) = p(\zeta) = \det(B_b P_- + \zeta B_a + \zeta^2 B_b P_+)`,
a polynomial with rational coefficients.  Every eigenvalue is
:math:`\lambda = (\ln\zeta_i + 2\pi i m)/\tau` for a nonzero root :math:`\zeta_i`
(:math:`m \in \mathbb Z`; the multiplicity of the root is that of each of these zeros of
:math:`\Delta`, since :math:`d\zeta/d\lambda = \tau\zeta \ne 0`), and the spectral
abscissa over the **whole plane** is exactly :math:`\max_i \ln|\zeta_i| / \tau`.

* :math:`p` with no nonzero root (a monomial :math:`c\,\zeta^j`): :math:`\Delta` has no
  zero, the spectrum is empty (**extinction**: the string with the matched damper
  :math:`k = 1` comes to rest in finite time);
* :math:`p \equiv 0`: every :math:`\lambda` is an eigenvalue (refused);
* a multiple root is a coalescence: its multiplicity is stated.

The roots are isolated by flint (``fmpq_poly.complex_roots``: certified balls with
multiplicities), each is then put in a square of half-width :math:`2^{-40}` whose count
is proved by the argument principle on :math:`p` (:mod:`.contour`), the form the checker
re-verifies.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import sympy

from phdesign.core.errors import CertificateError
from phdesign.numeric.certified.characteristic import Characteristic, fraction_text
from phdesign.numeric.certified.contour import Segment, certify_path, closed_count
from phdesign.numeric.certified.enclosure import square_path

__all__ = ["RootSquare", "WholePlane", "certify_whole_plane", "travel_time"]

ROOT_RADIUS = Fraction(1, 2**40)
GRID = 2**60


@dataclass(frozen=True)
class RootSquare:
    """A square of the ζ-plane proved to hold ``count`` roots of p."""

    center: tuple[Fraction, Fraction]
    radius: Fraction
    count: int
    segments: tuple[Segment, ...]


@dataclass(frozen=True)
class WholePlane:
    r"""The whole-plane certificate (module docstring).

    Attributes
    ----------
    tau : Fraction
        The travel time :math:`\tau`.
    coefficients : tuple of Fraction
        :math:`p(\zeta) = \sum_j c_j \zeta^j`, ascending.
    roots : tuple of RootSquare
        The nonzero roots (empty: extinction).
    abscissa_interval : tuple of Fraction or None
        :math:`[\alpha_{lo}, \alpha_{up}] \ni \max_i \ln|\zeta_i|/\tau`; None: no eigenvalue.
    """

    tau: Fraction
    coefficients: tuple[Fraction, ...]
    roots: tuple[RootSquare, ...]
    abscissa_interval: tuple[Fraction, Fraction] | None

    @property
    def multiplicities(self) -> tuple[int, ...]:
        """The multiplicity of each root (> 1: a coalescence)."""
        return tuple(r.count for r in self.roots)

    def to_dict(self) -> dict[str, Any]:
        """Return the proof file's ``whole_plane`` section."""
        from phdesign.numeric.certified.proof import path_rows

        return {
            "tau": fraction_text(self.tau),
            "polynomial": [fraction_text(c) for c in self.coefficients],
            "roots": [
                {
                    "center": [fraction_text(r.center[0]), fraction_text(r.center[1])],
                    "radius": fraction_text(r.radius),
                    "count": r.count,
                    "path": path_rows(r.segments),
                }
                for r in self.roots
            ],
        }


def travel_time(ch: Characteristic, P0_zero: bool) -> Fraction | None:
    r"""Return :math:`\tau` when :math:`\Delta` is a polynomial in :math:`e^{\lambda\tau}`.

    Exact: :math:`N = 1`, :math:`P_0 = 0`, :math:`K^2 = \tau^2 I` with :math:`\tau` rational.
    """
    if ch.order != 1 or not P0_zero or any(any(row) for row in ch.A0):
        return None
    K = sympy.Matrix(ch.A1) * sympy.Rational(ch.length.numerator, ch.length.denominator)
    square = K * K
    tau2 = square[0, 0]
    if square != tau2 * sympy.eye(K.rows) or tau2 <= 0:
        return None
    tau = sympy.sqrt(tau2)
    if not tau.is_Rational:
        return None
    return Fraction(int(tau.p), int(tau.q))


def certify_whole_plane(ch: Characteristic, tau: Fraction) -> WholePlane:
    r"""Certify the spectrum of an exponential polynomial over the whole plane.

    Raises
    ------
    CertificateError
        If :math:`p \equiv 0` (every λ an eigenvalue), or a root square cannot be proved.
    """
    from flint import acb, ctx, fmpq, fmpq_poly

    zeta = sympy.Symbol("zeta")
    n = ch.size
    K = sympy.Matrix(ch.A1) * sympy.Rational(ch.length.numerator, ch.length.denominator)
    t = sympy.Rational(tau.numerator, tau.denominator)
    plus, minus = (sympy.eye(n) + K / t) / 2, (sympy.eye(n) - K / t) / 2
    Ba, Bb = sympy.Matrix(ch.Ba), sympy.Matrix(ch.Bb)
    poly = sympy.Poly((Bb * minus + zeta * Ba + zeta**2 * Bb * plus).det(), zeta)
    coefficients = tuple(Fraction(int(c.p), int(c.q)) for c in reversed(poly.all_coeffs()))
    if not any(coefficients):
        raise CertificateError(
            "Δ vanishes identically (every λ is an eigenvalue): the closed boundary "
            "conditions do not determine the solution"
        )
    p = fmpq_poly([fmpq(c.numerator, c.denominator) for c in coefficients])
    squares = []
    bounds = []
    with ctx.workprec(128):
        roots: Any = p.complex_roots()
        for root, multiplicity in roots:
            if root.contains(acb(0)):
                continue  # ζ = 0 is no eigenvalue (ζ = e^{λτ} ≠ 0)
            x = Fraction(round(float(root.real.mid()) * GRID), GRID)
            y = Fraction(round(float(root.imag.mid()) * GRID), GRID)
            r = ROOT_RADIUS
            corners = square_path((x, y), r, symmetric=False)
            steps = {"first_step": r / 2, "max_step": 2 * r, "min_step": r / 2**12}
            segments = certify_path(_shifted(p, x, y), corners, steps)
            count = closed_count(segments)
            if count != multiplicity:
                raise CertificateError(f"the square about the root {root} holds {count} roots")
            squares.append(RootSquare((x, y), r, count, tuple(segments)))
            bounds.append(_real_part_bounds(x, y, r, tau))
    interval = None
    if bounds:
        interval = (max(b[0] for b in bounds), max(b[1] for b in bounds))
    return WholePlane(tau, coefficients, tuple(squares), interval)


def _shifted(p: Any, x: Fraction, y: Fraction) -> Any:
    r"""Enclose p over a box through its Taylor expansion about the centre :math:`c = x + iy`.

    :math:`p(c + w) = \sum_k d_k w^k` with :math:`d_k = p^{(k)}(c)/k!`: evaluated in w, the
    enclosure of a box near a multiple root is as small as p there (Horner in ζ would
    carry the size of the terms, not of their sum).
    """
    from flint import acb, arb, fmpq

    def ball(v: Fraction) -> Any:
        return arb(fmpq(v.numerator, v.denominator))

    centre = acb(ball(x), ball(y))
    taylor, derivative, factorial = [], acb_poly_of(p), 1
    for k in range(p.degree() + 1):
        taylor.append(derivative(centre) / factorial)
        derivative = derivative.derivative()
        factorial *= k + 1

    def enclose(a: tuple[Fraction, Fraction], b: tuple[Fraction, Fraction]) -> Any:
        w = acb(ball(a[0] - x).union(ball(b[0] - x)), ball(a[1] - y).union(ball(b[1] - y)))
        value = taylor[-1]
        for d in reversed(taylor[:-1]):
            value = value * w + d
        return value

    return enclose


def acb_poly_of(p: Any) -> Any:
    """Return the ``acb_poly`` of an ``fmpq_poly``."""
    from flint import acb_poly

    return acb_poly(p)


def _real_part_bounds(
    x: Fraction, y: Fraction, r: Fraction, tau: Fraction
) -> tuple[Fraction, Fraction]:
    r"""Bounds of :math:`\ln|\zeta|/\tau` over the square (arb, rounded outward to 2^-60)."""
    import math

    from flint import arb, fmpq

    near = [max(abs(c) - r, Fraction(0)) for c in (x, y)]
    far = [abs(c) + r for c in (x, y)]
    lo2 = near[0] ** 2 + near[1] ** 2
    hi2 = far[0] ** 2 + far[1] ** 2
    if lo2 == 0:
        raise CertificateError("a root square of p reaches ζ = 0")
    t = arb(fmpq(tau.numerator, tau.denominator))
    lo = (arb(fmpq(lo2.numerator, lo2.denominator)).log() / (2 * t)).lower()
    hi = (arb(fmpq(hi2.numerator, hi2.denominator)).log() / (2 * t)).upper()
    return (
        Fraction(math.floor(exact_dyadic(lo) * GRID), GRID),
        Fraction(math.ceil(exact_dyadic(hi) * GRID), GRID),
    )


def exact_dyadic(x: Any) -> Fraction:
    """Return the exact value of an exact ``arb`` (a ball's endpoint) as a Fraction."""
    man, exp = x.mid().man_exp()
    return Fraction(int(man)) * Fraction(2) ** int(exp)
