r"""An independent checker of phdesign's proof files (``phdesign check proof.json``).

A proof file (:mod:`phdesign.numeric.certified.proof`) records a certified spectrum: the
exact closed system, the construction of :math:`\Delta`, every contour segment with its
half-plane, the squares that enclose zeros, and the claims.  This package re-verifies it
with a second implementation that shares no arithmetic with the first:

* exact data are read as :class:`fractions.Fraction` and everything exact is recomputed
  from the system itself (:mod:`.exact`, :mod:`.system`): the companion matrix, the
  boundary rows :math:`U + GY`, the Cauchy-Binet weights, the signs of the energy
  identity;
* :math:`\Delta` over each segment is enclosed in mpmath's interval arithmetic (the
  functions of ``mpmath.libmp.libmpi`` that ``mpmath.iv`` is built on, :mod:`.intervals`),
  through the compounds of :math:`e^{A\ell/q}` computed by Taylor series with a rigorous
  remainder and squaring, where the certifier used flint's ball exponential of the
  additive compound;
* the counts and the claims are recomputed from the labels and the squares
  (:mod:`.contour`, :mod:`.band`).

It imports neither python-flint nor numpy nor sympy, nor anything of phdesign outside
this package (``tests/test_layers.py`` and a test that runs it with those modules
blocked); the decay-rate checks (:mod:`.rate`; :mod:`.rate_poly` for z-dependent
coefficients, with its own polynomial arithmetic and Sturm sequences) use the standard
library alone.  A mistake in the prover cannot pass the checker by sharing its code.
"""

from __future__ import annotations

__all__ = ["check_file", "check_proof"]


def check_proof(proof: dict) -> list[str]:
    """Return the failures found in ``proof`` (empty: every claim verified)."""
    from phdesign.proofcheck.check import check_all

    return check_all(proof)


def check_file(path: str) -> list[str]:
    """Read a proof file (JSON) and check it (:func:`check_proof`)."""
    import json

    with open(path, encoding="utf-8") as handle:
        return check_proof(json.load(handle))
