"""Checking a whole proof file: format, system, band, whole plane, rate."""

from __future__ import annotations

from phdesign.proofcheck.band import check_band
from phdesign.proofcheck.system import derive

__all__ = ["check_all"]


def check_all(proof: dict) -> list[str]:
    """Return every failure found in ``proof`` (empty: verified)."""
    failures: list[str] = []
    if not isinstance(proof, dict) or proof.get("format") != "phdesign-proof":
        return ["not a phdesign proof file (its 'format' is not 'phdesign-proof')"]
    if proof.get("version") != 1:
        return [f"unknown proof-file version {proof.get('version')!r}; this checker reads 1"]
    try:
        claim = proof["claim"]
        if "band" not in proof and "whole_plane" not in proof:
            return _rate_only(proof, claim)
        data = derive(proof["system"], failures)
        if data is None:
            return failures
        if "band" in proof:
            check_band(data, proof["band"], claim.get("abscissa_interval"), failures)
        if "whole_plane" in proof:
            from phdesign.proofcheck.whole_plane import check_whole_plane

            check_whole_plane(data, proof["whole_plane"], claim, failures)
        if "rate" in proof:
            failures.extend(_rate(proof["rate"]))
    except (KeyError, TypeError, ValueError, ZeroDivisionError) as error:
        failures.append(f"malformed proof file: {type(error).__name__}: {error}")
    return failures


def _rate_only(proof: dict, claim: dict) -> list[str]:
    """Check a proof with no spectrum section (z-dependent coefficients): its rate alone."""
    if "rate" not in proof:
        return ["the proof file proves nothing: it has no band, whole-plane or rate section"]
    if claim.get("abscissa_interval") is not None or claim.get("whole_plane"):
        return ["the claim states a spectral abscissa, but the proof has no spectrum section"]
    return _rate(proof["rate"])


def _rate(section: dict) -> list[str]:
    if isinstance(section, dict) and section.get("weight") == "polynomial":
        from phdesign.proofcheck.rate_poly import check_rate_polynomial

        return check_rate_polynomial(section)
    try:
        from phdesign.proofcheck.rate import check_rate
    except ImportError:
        return ["the proof has a 'rate' section but this checker has no decay-rate check"]
    return list(check_rate(section))
