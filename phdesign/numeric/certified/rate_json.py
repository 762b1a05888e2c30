r"""The decay-rate proof as a proof-file section and as text.

The section holds exact rationals as ``"p/q"`` strings and everything
:func:`phdesign.proofcheck.rate.check_rate` needs to re-check the proof without
phdesign: the model's exact matrices (:math:`\\mathcal H`, its inverse, :math:`P_0`,
:math:`P_1`, the interval), the closed boundary matrix and its kernel basis,
:math:`\\Pi_\\pm`, :math:`\\tau`, the enclosure of :math:`\\mu`, :math:`\\sigma`,
:math:`c_1`, :math:`c_2`, :math:`M`, and every inequality with its matrix.

For z-dependent coefficients (:mod:`.rate_poly`) the section has ``"weight":
"polynomial"``; :math:`\\mathcal H(z)`, :math:`P_0(z)`, :math:`\\Pi(z)` and the
pointwise matrices are matrices of rational functions of z, each entry
``{"num": [...], "den": [...]}`` with the coefficients of :math:`z^0, z^1, \\dots` as
``"p/q"`` strings, re-checked by :mod:`phdesign.proofcheck.rate_poly`.
"""

from __future__ import annotations

from fractions import Fraction
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.text import number_text
from phdesign.numeric.certified.rate_exact import to_fraction

if TYPE_CHECKING:
    from phdesign.numeric.certified.rate import DecayRateProof
    from phdesign.numeric.certified.rate_poly import PolynomialLyapunov

__all__ = ["function_matrix", "proof_json", "proof_text", "rational_text"]


def rational_text(value: Fraction | sympy.Rational | int) -> str:
    """``"p/q"`` for an exact rational (``"3/1"`` for 3)."""
    q = value if isinstance(value, Fraction) else to_fraction(sympy.Rational(value))
    return f"{q.numerator}/{q.denominator}"


def _matrix(M: sympy.MatrixBase) -> list[list[str]]:
    return [[rational_text(x) for x in row] for row in M.tolist()]


def function_matrix(M: sympy.MatrixBase, z: sympy.Symbol) -> list[list[dict[str, list[str]]]]:
    """Rational functions of ``z`` as ``{"num": [...], "den": [...]}``, ascending powers."""

    def coefficients(p: sympy.Expr) -> list[str]:
        return [rational_text(c) for c in reversed(sympy.Poly(p, z).all_coeffs())]

    def entry(x: sympy.Expr) -> dict[str, list[str]]:
        num, den = sympy.fraction(sympy.cancel(x))
        return {"num": coefficients(num), "den": coefficients(den)}

    return [[entry(x) for x in M.row(i)] for i in range(M.rows)]


def _polynomial_json(proof: DecayRateProof, data: PolynomialLyapunov) -> dict[str, Any]:
    problem, z = proof.problem, proof.problem.z
    return {
        "kind": "decay rate",
        "weight": "polynomial",
        "model": problem.name,
        "order": 1,
        "norm": "energy: ||x||^2 = int_a^b x^T H(z) x dz",
        "functional": "V = int_a^b x^T Pi(z) x dz, Pi(z) a matrix of polynomials in z",
        "interval": [rational_text(e) for e in problem.interval],
        "H": function_matrix(problem.H, z),
        "P0": function_matrix(problem.P0, z),
        "P1": _matrix(problem.P1),
        "boundary": _matrix(problem.boundary),
        "kernel": _matrix(problem.kernel),
        "Pi": function_matrix(data.Pi, z),
        "sigma": rational_text(proof.sigma),
        "c1": rational_text(data.c1),
        "c2": rational_text(data.c2),
        "M": rational_text(proof.M),
        "inequalities": [
            {
                "name": q.name,
                "claim": q.claim,
                "meaning": q.meaning,
                "on": "traces" if q.interval is None else "[a, b]",
                "matrix": function_matrix(q.matrix, z),
            }
            for q in proof.inequalities
        ],
        "assumptions": list(proof.assumptions),
    }


def proof_json(proof: DecayRateProof) -> dict[str, Any]:
    """Return the proof-file section of ``proof`` (module docstring)."""
    from phdesign.numeric.certified.rate_poly import PolynomialLyapunov

    if isinstance(proof.data, PolynomialLyapunov):
        return _polynomial_json(proof, proof.data)
    problem, data = proof.problem, proof.data
    return {
        "kind": "decay rate",
        "model": problem.name,
        "order": 1,
        "norm": "energy: ||x||^2 = int_a^b x^T H x dz",
        "functional": "V = int_a^b x^T (t^-1 Pi_minus + t Pi_plus) x dz, t = exp(mu (z - a))",
        "interval": [rational_text(e) for e in problem.interval],
        "H": _matrix(problem.H),
        "H_inv": _matrix(problem.H.inv()),
        "P0": _matrix(problem.P0),
        "P1": _matrix(problem.P1),
        "boundary": _matrix(problem.boundary),
        "kernel": _matrix(problem.kernel),
        "Pi_minus": _matrix(data.Pi_minus),
        "Pi_plus": _matrix(data.Pi_plus),
        "tau": rational_text(data.tau),
        "mu": [rational_text(m) for m in data.mu],
        "sigma": rational_text(proof.sigma),
        "c1": rational_text(data.c1),
        "c2": rational_text(data.c2),
        "M": rational_text(proof.M),
        "inequalities": [
            {"name": q.name, "claim": q.claim, "meaning": q.meaning, "matrix": _matrix(q.matrix)}
            for q in proof.inequalities
        ],
        "assumptions": list(proof.assumptions),
    }


def proof_text(proof: DecayRateProof) -> str:
    """Return the text of ``phdesign certify --rate`` (and ``str(proof)``)."""
    data = proof.data
    tau = getattr(data, "tau", None)
    functional = (
        "  V = int x^T Pi(z) x dz, Pi(z) a polynomial matrix in z (the polynomial weight)"
        if tau is None
        else "  V = int x^T Pi(z) x dz, Pi(z) = exp(-mu (z-a)) Pi_- + exp(mu (z-a)) Pi_+, "
        f"tau = exp(mu (b-a)) = {rational_text(tau)}"
    )
    checked = (
        "(Sylvester's criterion)"
        if tau is not None
        else "(Sylvester's criterion; on all of [a, b] by Sturm sequences)"
    )
    lines = [
        f"decay rate of {proof.problem.name}, proved exactly:",
        "  ||x~(t)|| <= M exp(-sigma t) ||x~(0)||, energy norm ||x||^2 = int x^T H x dz",
        f"  sigma = {number_text(float(proof.sigma))} (exactly {rational_text(proof.sigma)}), "
        f"M = {number_text(float(proof.M))}",
        functional,
        f"  {len(proof.inequalities)} matrix inequalities checked in exact rationals "
        f"{checked}; re-check the proof file with `phdesign check`",
    ]
    if proof.conservatism is not None:
        lines.append(
            f"  spectral abscissa {number_text(proof.abscissa or 0.0)} "
            f"({proof.abscissa_source}): sigma/|alpha| = {proof.conservatism:.4f} "
            "(the method's conservatism; 1 is sharp)"
        )
    lines += [f"  assumes: {a}" for a in proof.assumptions]
    return "\n".join(lines)
