"""How a :class:`~.certificate.Certificate` prints itself (the command line's text)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.numeric.certified.certificate import Certificate

__all__ = ["certificate_text"]


def _system_line(cert: Certificate) -> str:
    s = cert.system
    if s.kind == "plant":
        return f"certificate: {s.name}, the plant (u = 0 on its external inputs)"
    rows = [[str(x) for x in s.C_m.row(i)] for i in range(s.C_m.rows)] if s.C_m is not None else []
    gain = [[str(x) for x in s.L.row(i)] for i in range(s.L.rows)] if s.L is not None else []
    return f"certificate: {s.name}, the observer's error system (C_m = {rows}, L = {gain})"


def _scope(cert: Certificate) -> str:
    if "band" not in cert.proof and not cert.whole_plane:
        return "proved for: the decay rate only (no spectrum section)"
    if cert.whole_plane:
        section = cert.proof["whole_plane"]
        return (
            "proved for: the whole plane (Δ is a polynomial p in ζ = e^(λτ), τ = "
            f"{section['tau']}; {len(section['roots'])} root square(s) hold all its nonzero roots)"
        )
    section = cert.proof["band"]
    return (
        f"proved for: the band |Im λ| <= {cert.band:g}: {section['count']} zero(s) of Δ right "
        f"of Re λ = {float(eval_fraction(section['left'])):.6g}, each in a proved square"
    )


def eval_fraction(text: str) -> float:
    """Return the float of a ``"p/q"`` text."""
    from fractions import Fraction

    return float(Fraction(text))


def certificate_text(cert: Certificate) -> str:
    """Return the certificate as the command line prints it."""
    lines = [_system_line(cert)]
    interval = cert.abscissa_interval
    if "band" not in cert.proof and not cert.whole_plane:
        lines.append("spectral abscissa: not certified (see the notes)")
    elif interval is None:
        lines.append("spectral abscissa: no eigenvalue found (see the notes)")
    else:
        lo, hi = interval
        lines.append(f"spectral abscissa in [{lo:.12g}, {hi:.12g}] (proved; width {hi - lo:.2g})")
    lines.append(_scope(cert))
    if cert.rate is not None:
        lines.append(
            f"decay rate: ‖x̃(t)‖ <= M e^(-σt) ‖x̃(0)‖ with σ = {float(cert.rate):.6g}, "
            f"M = {float(cert.M or 0):.6g} (proved, exact rationals in the proof)"
        )
    else:
        lines.append("decay rate: not asked for")
    lines.extend(f"note: {n}" for n in cert.notes)
    lines.append("assumptions:")
    lines.extend(f"  - {a}" for a in cert.assumptions)
    lines.append("re-check the proof file with: phdesign check PROOF.json")
    return "\n".join(lines)
