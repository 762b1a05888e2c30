r"""The certificate: what is proved about a closed system's spectrum, and its proof file.

:func:`certify` chooses the proof the system admits (:class:`Certificate` says which):

* **whole plane** (:mod:`.whole_plane`): :math:`N = 1`, :math:`P_0 = 0` and one rational
  travel time, so :math:`\Delta` is a polynomial in :math:`e^{\lambda\tau}` and the
  spectral abscissa is :math:`\max_i \ln|\zeta_i|/\tau` over every eigenvalue;
* **band** (:mod:`.band`): any other constant-coefficient system, the abscissa of the
  eigenvalues with :math:`|\operatorname{Im}\lambda| \le \Omega`; beyond the band
  nothing is proved.

Either way the proof file (:mod:`.proof`) holds every ingredient, and
``phdesign check`` (:mod:`phdesign.proofcheck`) re-verifies it independently.  With
``rate=True`` the decay-rate prover of :mod:`phdesign.numeric.certified.rate` adds a
proved :math:`\sigma` and :math:`M` with :math:`\|\tilde x(t)\| \le M e^{-\sigma t}
\|\tilde x(0)\|`.  For z-dependent :math:`H` or :math:`P_0` only the rate is proved
(the spectrum needs constant coefficients): the certificate then states no abscissa and
says why.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

from phdesign.core.errors import CertificateError
from phdesign.numeric.certified.band import BandCount, certify_band
from phdesign.numeric.certified.characteristic import characteristic, fraction_text
from phdesign.numeric.certified.exact_system import ExactClosedSystem
from phdesign.numeric.certified.proof import FORMAT, VERSION, band_section
from phdesign.numeric.certified.whole_plane import (
    WholePlane,
    certify_whole_plane,
    travel_time,
)

__all__ = ["Certificate", "certify"]

COMMON = (
    "the system is the one written: every float of the model, the overrides and the gain "
    "was read through its decimal text (0.1 = 1/10), and the certificate is exact for it",
    "constant coefficients with P_N and H invertible: the eigenvalues are exactly the zeros "
    "of Δ(λ) = det(B_a + B_b e^{A(λ)ℓ}), counted with their multiplicity as zeros of Δ",
    "Re λ <= 0 for every eigenvalue: proved by the energy identity, from sym(G) ⪰ 0 and "
    "sym(P0) ⪯ 0 decided exactly (not assumed)",
    "the port matrices U, Y are those phdesign derives (their identities are checked exactly "
    "when the model is built); the checker re-derives Δ, B = U + GY and the signs from them",
)


@dataclass(frozen=True)
class Certificate:
    r"""A proved statement about the spectrum (and optionally the decay) of a closed system.

    Attributes
    ----------
    abscissa_interval : tuple of float or None
        :math:`[\alpha_{lo}, \alpha_{up}]`, outward-rounded floats of the proof's exact
        bounds, holding the spectral abscissa (of the band, or of the whole plane); None
        when no eigenvalue was found (extinction, or none right of the band's left edge).
    band : float or None
        :math:`\Omega` of the band :math:`|\operatorname{Im}\lambda| \le \Omega`; None for a
        whole-plane certificate.
    whole_plane : bool
        Whether the statement covers every eigenvalue.
    rate, M : Fraction or None
        The proved decay rate :math:`\sigma` and constant :math:`M` (``rate=True``).
    assumptions : tuple of str
        What the statement rests on, in words.
    notes : tuple of str
        Degenerate cases met: multiple zeros, extinction, zeros on the imaginary axis.
    proof : dict
        The proof file (:mod:`.proof`).
    """

    abscissa_interval: tuple[float, float] | None
    band: float | None
    whole_plane: bool
    rate: Fraction | None
    M: Fraction | None
    assumptions: tuple[str, ...]
    notes: tuple[str, ...]
    system: ExactClosedSystem = field(repr=False, compare=False)
    proof: dict[str, Any] = field(repr=False, compare=False)
    rate_proof: Any = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict[str, Any]:
        """Return the proof file's content (what ``--json`` prints and ``-o`` writes)."""
        return self.proof

    def __str__(self) -> str:
        from phdesign.numeric.certified.text import certificate_text

        return certificate_text(self)


def certify(
    system: ExactClosedSystem,
    *,
    band: float | None = None,
    rate: bool = False,
    estimates: Sequence[complex] = (),
    beyond: str = "",
) -> Certificate:
    r"""Certify the spectral abscissa of ``system`` (module docstring).

    Parameters
    ----------
    system : ExactClosedSystem
        The exact closed plant or error system.
    band : float, optional
        :math:`\Omega`; required unless the whole plane can be certified (then ignored).
    rate : bool
        Also prove a decay rate (:func:`phdesign.numeric.certified.rate.prove_decay_rate`).
    estimates : sequence of complex
        Eigenvalue estimates for the band (the converged spectrum's).
    beyond : str
        What the converged spectrum extrapolates above the band (an assumption's words).

    Raises
    ------
    CertificateError
        z-dependent data (without ``rate``), irrational data, a singular :math:`P_N`, a
        non-dissipative system, a band certificate without a band, or a failed proof.
    RateProofError
        With ``rate``: an order other than 1, or a rate that cannot be proved.
    """
    if (alone := _rate_alone(system, rate, band)) is not None:
        return alone
    ch = characteristic(system)
    _require_provable(system)
    proof: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "system": system.to_dict(),
        "characteristic": ch.to_dict(),
    }
    assumptions = list(COMMON)
    tau = travel_time(ch, system.P[0].is_zero_matrix)
    if tau is not None:
        whole = certify_whole_plane(ch, tau)
        proof["whole_plane"] = whole.to_dict()
        exact, notes, omega = whole.abscissa_interval, _whole_plane_notes(whole), None
    else:
        found = _band(ch, band, estimates)
        proof["band"] = band_section(found)
        assumptions.append(
            f"only |Im λ| <= {float(found.band):g} is proved; beyond it nothing is"
            + (f" (the converged spectrum extrapolates {beyond})" if beyond else "")
        )
        conservative = system.dissipation().conservative
        exact, notes, omega = found.abscissa_interval, _band_notes(found, conservative), found.band
    if system.dissipation().conservative and exact is not None:
        exact = (Fraction(0), Fraction(0))  # Re λ = 0 for every eigenvalue, and one exists
    claim = None if exact is None else [fraction_text(x) for x in exact]
    proof["claim"] = {
        "abscissa_interval": claim,
        "band": None if omega is None else fraction_text(omega),
        "whole_plane": tau is not None,
    }
    sigma = M = rate_proof = None
    if rate:
        rate_proof = _rate(system)
        proof["rate"] = rate_proof.to_json()
        sigma, M = rate_proof.sigma, rate_proof.M
        assumptions.extend(rate_proof.assumptions)
    proof["assumptions"] = assumptions
    return Certificate(
        abscissa_interval=None if exact is None else _outward(exact),
        band=None if omega is None else float(omega),
        whole_plane=tau is not None,
        rate=sigma,
        M=M,
        assumptions=tuple(assumptions),
        notes=tuple(notes),
        system=system,
        proof=proof,
        rate_proof=rate_proof,
    )


#: Why a z-dependent system's certificate states no spectral abscissa.
NO_SPECTRUM = (
    "the spectrum is not certified: H or P0 depends on z, and the certified spectrum needs "
    "constant coefficients (Δ = det(B_a + B_b e^{A(λ)ℓ})); only the decay rate is proved"
)


def _rate_alone(system: ExactClosedSystem, rate: bool, band: float | None) -> Certificate | None:
    """Refuse an order other than 1 before any work; certify a z-dependent rate alone.

    Without ``rate``, and for a constant system, None: the spectrum's certificate goes on.
    """
    if not rate:
        return None
    from phdesign.numeric.certified.rate_problem import require_first_order

    require_first_order(system.name, system.order)
    return None if system.constant else _rate_only(system, band)


def _rate_only(system: ExactClosedSystem, band: float | None) -> Certificate:
    """Certify a z-dependent system: the proved decay rate alone."""
    rate_proof = _rate(system)
    notes = [NO_SPECTRUM]
    if band is not None:
        notes.append(f"the band |Im λ| <= {band:g} asked for is not certified, for that reason")
    assumptions = [COMMON[0], *rate_proof.assumptions]
    proof: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "system": system.to_dict(),
        "claim": {"abscissa_interval": None, "band": None, "whole_plane": False},
        "rate": rate_proof.to_json(),
        "assumptions": assumptions,
    }
    return Certificate(
        abscissa_interval=None,
        band=None,
        whole_plane=False,
        rate=rate_proof.sigma,
        M=rate_proof.M,
        assumptions=tuple(assumptions),
        notes=tuple(notes),
        system=system,
        proof=proof,
        rate_proof=rate_proof,
    )


def _require_provable(system: ExactClosedSystem) -> None:
    """Refuse irrational data and a system whose energy identity gives no Re λ <= 0."""
    if not system.rational:
        raise CertificateError(
            f"model {system.name!r} has irrational entries (such as sqrt(2)) in H, P_k or the "
            "boundary rows; a certificate needs rational data"
        )
    if not system.dissipation().dissipative:
        raise CertificateError(
            "the closed system is not dissipative (sym(G) ⪰ 0 and sym(P0) ⪯ 0 fail), so no "
            "right edge Re λ <= 0 is proved"
        )


def _band(ch: Any, band: float | None, estimates: Sequence[complex]) -> BandCount:
    if band is None:
        raise CertificateError(
            "`band` is needed: Δ is not a polynomial in e^{λτ} (N > 1, P0 ≠ 0 or several "
            "travel times), so only a band |Im λ| <= `band` can be certified"
        )
    return certify_band(ch, band, estimates)


def _outward(exact: tuple[Fraction, Fraction]) -> tuple[float, float]:
    import math

    lo, hi = float(exact[0]), float(exact[1])
    if Fraction(lo) > exact[0]:
        lo = math.nextafter(lo, -math.inf)
    if Fraction(hi) < exact[1]:
        hi = math.nextafter(hi, math.inf)
    return lo, hi


def _rate(system: ExactClosedSystem) -> Any:
    # the semidefinite program needs cvxpy, which the extra `certify` installs beside flint
    try:
        import cvxpy  # noqa: F401
    except ImportError:
        raise CertificateError(
            "the decay-rate proof needs cvxpy (with Clarabel or SCS): "
            "pip install 'phdesign[certify]', or certify without `rate=True`"
        ) from None
    from phdesign.numeric.certified.rate import prove_decay_rate

    return prove_decay_rate(system)


def _whole_plane_notes(found: WholePlane) -> list[str]:
    notes = []
    if not found.roots:
        notes.append(
            "extinction: Δ has no zero (p(ζ) is a monomial), the spectrum is empty and the "
            "solutions vanish in finite time"
        )
    for root in found.roots:
        if root.count > 1:
            x, y = float(root.center[0]), float(root.center[1])
            notes.append(
                f"a multiple root of p: ζ = {x:.12g} {y:+.12g}i of multiplicity {root.count}"
                " (a coalescence: every eigenvalue of its chain has that multiplicity)"
            )
    return notes


def _band_notes(found: BandCount, conservative: bool) -> list[str]:
    notes = []
    if not found.enclosures:
        notes.append(
            f"no zero of Δ with Re λ > {float(found.left):.6g} in the band (the estimates "
            "found none and the count confirms it)"
        )
    for e in found.enclosures:
        if e.count > 1:
            notes.append(
                f"a multiple zero: {e.count} zeros within {float(e.radius):.2g} of "
                f"{float(e.center[0]):.12g} {float(e.center[1]):+.12g}i (a coalescence)"
            )
    interval = found.abscissa_interval
    if interval is not None and interval[1] >= 0:
        notes.append(
            "a zero on the imaginary axis: Re λ = 0 exactly (the system is conservative)"
            if conservative
            else "a zero within the enclosure radius of the imaginary axis: the abscissa is "
            "in [-r, 0], and 0 is not excluded"
        )
    return notes
